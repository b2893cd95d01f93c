//! The description every output carries: model, axes, grid, samples, errors, provenance.

use crate::table::axis::{Axis, Grid};
use crate::table::{Quantity, Table, TableSpec};
use serde::{Deserialize, Serialize};

/// kiln's version, recorded in every table.
pub const KILN_VERSION: &str = env!("CARGO_PKG_VERSION");

/// What one axis is, in words and numbers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisMetadata {
    /// `mu`, `r` or `alpha`.
    pub name: String,
    pub size: usize,
    /// `centers` or `nodes`.
    pub grid: Grid,
    /// `linear`, `sqrt` or `adaptive` for `mu`; `r` (alpha = r^2) or `alpha` for roughness.
    pub mapping: String,
    /// Index to value, e.g. `t_i = (i + 0.5) / N, mu = t`.
    pub formula: String,
    /// The coordinate of every sample, in the axis' own unit (`mu`, `r` or `alpha`); for the
    /// `adaptive` mu mapping, whose `mu` depends on the row's roughness, the lookup coordinate
    /// `t` (the formula gives `mu` from `t` and `alpha`).
    pub values: Vec<f64>,
}

impl AxisMetadata {
    #[must_use]
    pub fn new(axis: &Axis) -> Self {
        let mapping = match *axis {
            Axis::Mu { mapping, .. } => mapping.name().to_string(),
            Axis::Roughness { convention, .. } => convention.describe().to_string(),
            Axis::Ior { mapping, .. } => mapping.name().to_string(),
        };
        Self {
            name: axis.name().to_string(),
            size: axis.size(),
            grid: axis.grid(),
            mapping,
            formula: axis.formula(),
            values: axis.listed_values(),
        }
    }
}

/// A table's metadata, as stored in the JSON sidecar, the EXR header and generated sources.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metadata {
    pub kiln_version: String,
    /// `E` or `E_avg`.
    pub quantity: String,
    pub description: String,
    /// `ggx` or `beckmann`.
    pub ndf: String,
    /// `height-correlated` or `separable`.
    pub masking: String,
    pub fresnel: String,
    /// The dielectric tables' transmission convention
    /// ([`crate::model::dielectric::TransmissionConvention`]); absent for the other tables.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmission: Option<String>,
    /// `r` (perceptual, alpha = r^2) or `alpha`.
    pub roughness_convention: String,
    /// The shape, slowest-varying axis first.
    pub shape: Vec<usize>,
    /// How the flat data is laid out.
    pub layout: String,
    /// The axes, slowest-varying first.
    pub axes: Vec<AxisMetadata>,
    /// The channels, in storage order.
    pub channels: Vec<String>,
    /// How the values were computed.
    pub estimator: String,
    /// QMC evaluations per texel (0 for the reference quadrature, which adapts per texel).
    pub samples_per_texel: u64,
    /// QMC's independent scrambles and their base seed (absent for the quadrature).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scrambles: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// The largest per-texel standard error (the table's measured error).
    pub max_std_error: f64,
    pub rms_std_error: f64,
    /// The error of the stored values against the deterministic reference (in `1 - E`), as
    /// measured by `kiln bake`: largest, RMS, and over how many texels (all of an `E` table; five
    /// evenly spaced entries of an `E_avg` table, each of which costs the reference ~0.5 s CPU).
    pub node_max_error: Option<f64>,
    pub node_rms_error: Option<f64>,
    pub node_error_texels: Option<usize>,
    /// What the texels are ([`crate::table::Texels::describe`]): point samples, or fitted for
    /// the lookup (absent from files kiln wrote before it said).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texels: Option<String>,
    /// For texels fitted for the lookup: the lookup's error over the fit's points (largest and
    /// RMS, against the reference), the point samples' lookup error at the same points, and the
    /// largest correction of a texel from its point sample. The node errors above then bound
    /// the fitted texels' distance from the truth at their nodes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lookup_fit: Option<crate::table::lookup_fit::LookupFitReport>,
    /// The `--max-error` the table was baked to meet, and the quadrature tolerance kiln chose for
    /// it (with the reference method); the measured error is `node_max_error`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub requested_max_error: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_tolerance: Option<f64>,
    /// `f32` or `f16`: how the value channels are stored in the binary formats.
    pub precision: String,
    /// With `f16` precision: per value channel, how many values were clamped into f16's range
    /// (never stored as infinity or zero) and how many are subnormals (below 6.1e-5, absolute
    /// spacing 6e-8). See [`crate::format::f16`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f16_storage: Option<std::collections::BTreeMap<String, super::f16::Counts>>,
    /// The command that reproduces the values.
    pub command: String,
    /// The same facts in machine form, for reading a table back ([`crate::TableSpec`]).
    pub spec: TableSpec,
}

impl Metadata {
    #[must_use]
    pub fn new(table: &Table, precision: &str) -> Self {
        let spec = &table.spec;
        let mut axes: Vec<AxisMetadata> = spec.axes().iter().map(AxisMetadata::new).collect();
        if let (Some(refined), [axis]) = (spec.refined_start, &mut axes[..]) {
            // An f_ms_norm's nodes with a refined start (crate::table::normalisation).
            let line = crate::table::normalisation::NodeLine::of(spec);
            let roughness = spec.roughness_axis();
            let nodes = format!(
                "t_i the solution of min({} t, {} t + {}) = i (its first {} cells of the E \
                 table's rows hold {} nodes each, the others {}: t_i = i / {} up to i = {}, then \
                 (i - {}) / {})",
                line.steep,
                line.shallow,
                line.offset,
                refined.cells,
                refined.subdivisions,
                crate::table::normalisation::SUBDIVISIONS,
                line.steep,
                refined.cells * refined.subdivisions,
                line.offset,
                line.shallow
            );
            axis.formula = axis.formula.replacen(Grid::Nodes.formula(), &nodes, 1);
            axis.values = (0..axis.size)
                .map(|i| roughness.roughness_at_coordinate(line.coordinate(i as f64)))
                .collect();
        }
        let layout = match &axes[..] {
            [e, r, m] => format!(
                "row-major, slowest axis first: value[({e}_index * {nr} + {r}_index) * {nm} + \
                 {m}_index]; as an image, x (columns) = {m}, y (rows, top to bottom) = \
                 {e}_index * {nr} + {r}_index (one {r} x {m} slice per {e}, stacked)",
                e = e.name,
                r = r.name,
                m = m.name,
                nr = r.size,
                nm = m.size
            ),
            [slow, fast] => format!(
                "row-major, slowest axis first: value[{s}_index * {n} + {f}_index]; as an image, \
                 x (columns) = {f}, y (rows, top to bottom) = {s}",
                s = slow.name,
                f = fast.name,
                n = fast.size
            ),
            _ => format!("value[{}_index]", axes[0].name),
        };
        Self {
            kiln_version: KILN_VERSION.to_string(),
            quantity: spec.quantity.symbol().to_string(),
            description: spec.quantity.describe().to_string(),
            // F_avg depends on the Fresnel model alone.
            ndf: if spec.quantity == Quantity::FAvg {
                "none (F_avg does not depend on the microfacet model)".to_string()
            } else {
                spec.model.ndf.name().to_string()
            },
            masking: if spec.quantity == Quantity::FAvg {
                "none".to_string()
            } else {
                spec.model.masking.name().to_string()
            },
            fresnel: match (spec.quantity.weight(), spec.quantity.has_ior()) {
                (None, false) => match spec.fresnel {
                    Some(fresnel) => serde_json::to_string(&fresnel)
                        .unwrap_or_else(|_| fresnel.name().to_string()),
                    None => "none (F = 1)".to_string(),
                },
                (Some(_), _) => {
                    "Schlick weight Fc = (1 - o.h)^5 (or 1 - Fc) on F = 1; see description"
                        .to_string()
                }
                (None, true) => match spec.fixed_ior() {
                    Some(ior) => format!(
                        "exact dielectric at one IOR, {ior}: relative index {}",
                        if spec.quantity.from_inside() {
                            format!("1 / {ior}")
                        } else {
                            ior.to_string()
                        }
                    ),
                    None => format!(
                        "exact dielectric, relative index {} (eta from the eta axis)",
                        if spec.quantity.from_inside() {
                            "1 / eta"
                        } else {
                            "eta"
                        }
                    ),
                },
            },
            transmission: spec
                .quantity
                .is_glass_albedo()
                .then(|| spec.transmission.describe().to_string()),
            roughness_convention: match spec.roughness {
                Some(_) => spec.roughness_convention().name().to_string(),
                None => "none (no roughness axis)".to_string(),
            },
            shape: spec.shape(),
            layout,
            axes,
            channels: table.channel_names().to_vec(),
            estimator: spec.method.describe().to_string(),
            samples_per_texel: match spec.method {
                crate::table::Method::Qmc => spec.qmc.samples,
                crate::table::Method::Reference => 0,
            },
            scrambles: (spec.method == crate::table::Method::Qmc).then_some(spec.qmc.scrambles),
            seed: (spec.method == crate::table::Method::Qmc).then_some(spec.qmc.seed),
            max_std_error: table.max_std_error(),
            rms_std_error: table.rms_std_error(),
            node_max_error: table.node_errors.map(|e| e.max),
            node_rms_error: table.node_errors.map(|e| e.rms),
            node_error_texels: table.node_errors.map(|e| e.texels),
            texels: Some(spec.texels.describe().to_string()),
            lookup_fit: table.lookup_fit,
            requested_max_error: table.requested_max_error,
            reference_tolerance: spec
                .reference_digits
                .map(|_| spec.reference_settings().tolerance),
            precision: precision.to_string(),
            f16_storage: (precision == "f16").then(|| {
                let names = table.channel_names();
                let channels = table.channels();
                (0..2)
                    .map(|c| (names[c].clone(), super::f16::counts(channels[c])))
                    .collect()
            }),
            command: table.command.clone(),
            spec: table.spec.clone(),
        }
    }
}

/// What starts the comment line of a C header or Rust source that carries the table's metadata
/// as one line of JSON, so that `kiln verify` can read those files without their sidecar.
pub const EMBEDDED_PREFIX: &str = "kiln-metadata: ";

/// The metadata as one line of JSON (for [`EMBEDDED_PREFIX`] comments).
#[must_use]
pub fn embedded_json(metadata: &Metadata) -> String {
    serde_json::to_string(metadata).unwrap_or_default()
}

/// Finds the metadata line of a generated C header or Rust source (see [`EMBEDDED_PREFIX`]).
pub fn find_embedded(text: &str) -> Option<crate::Result<Metadata>> {
    let line = text
        .lines()
        .take_while(|line| {
            line.starts_with("//") || line.starts_with("/*") || line.starts_with(" *")
        })
        .find_map(|line| line.split_once(EMBEDDED_PREFIX).map(|(_, json)| json))?;
    Some(
        serde_json::from_str(line.trim())
            .map_err(|e| crate::Error::Malformed(format!("bad kiln metadata comment: {e}"))),
    )
}

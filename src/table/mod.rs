//! Tables: what was computed (the spec), the values with their errors, and how to look them up.

pub mod anisotropic;
pub mod axis;
pub mod balanced_layout;
pub mod check;
pub mod compensation;
pub mod glass_compensation;
pub mod glass_layout;
pub mod lookup_fit;
pub mod normalisation;
pub mod one_ior_layout;
pub mod split_sum_layout;

use crate::integrate::QmcSettings;
use crate::model::dielectric::TransmissionConvention;
use crate::model::{Model, RoughnessConvention};
use axis::{Axis, Grid, IorMapping, MuMapping};
use serde::{Deserialize, Serialize};

pub use crate::integrate::quantity::{Quantity, schlick_weight};

/// The most texels kiln reads from any file or accepts in any metadata (checked by
/// [`TableSpec::check`]): 2^26, four times a 4096 x 4096 table (the largest 2-D table kiln
/// bakes, [`crate::BakeOptions::MAX_SIZE`]). A header that
/// claims more is refused before anything is allocated or decompressed.
pub const MAX_TEXELS: usize = 1 << 26;

/// How a table's values are computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Quasi-Monte Carlo: VNDF sampling with Owen-scrambled Sobol points; `std_error` from
    /// independent scrambles.
    #[default]
    Qmc,
    /// The deterministic reference quadrature (nested adaptive Gauss-Kronrod,
    /// `integrate::reference`): absolute error at most 1e-10; `std_error` holds its error
    /// estimate.
    Reference,
}

impl Method {
    /// The name on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Method::Qmc => "qmc",
            Method::Reference => "reference",
        }
    }

    /// A sentence for metadata and generated docs.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Method::Qmc => {
                "quasi-Monte Carlo: visible-normal (VNDF) importance sampling driven by \
                 Owen-scrambled Sobol points (Burley 2020); std_error from independent scrambles"
            }
            Method::Reference => {
                "deterministic nested adaptive Gauss-Kronrod quadrature (kiln's reference); \
                 std_error holds its error estimate"
            }
        }
    }
}

/// What a table's texels are: point samples of the quantity at the nodes, or values fitted so
/// that the lookup is closest to the quantity everywhere ([`lookup_fit`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Texels {
    /// Each texel is the quantity at its node (exact to the bake's max error): right for a
    /// renderer that reads nodes (point sampling, or its own interpolation).
    #[default]
    Nodes,
    /// Texels fitted for the bilinear lookup in the maximum norm: the lookup's largest error
    /// over the whole domain is minimised, at the cost of nodes off the truth by about as much.
    LookupFit,
}

impl Texels {
    /// The name on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Texels::Nodes => "nodes",
            Texels::LookupFit => "lookup-fit",
        }
    }

    /// A sentence for metadata.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Texels::Nodes => "point samples: each texel is the quantity at its node",
            Texels::LookupFit => {
                "fitted for the lookup: texels chosen so that the bilinear lookup (with this \
                 file's coordinate mapping) is closest to the quantity over the whole domain in \
                 the maximum norm (Lawson's algorithm); node_max_error bounds the texels' distance \
                 from the truth at their nodes (the point samples' measured error plus \
                 lookup_fit.max_correction)"
            }
        }
    }

    fn is_nodes(&self) -> bool {
        *self == Texels::Nodes
    }

    /// The texels laid out with the `mu` axis `mapping` when none are named: fitted for the
    /// lookup on the balanced axis (kiln's layout for `E`, chosen by its measured lookup error:
    /// 2.1e-4 at 32 x 32 against the adaptive axis' point samples' 6.5e-4) and on the one-IOR
    /// glass axis, point samples on every other axis (the engines' layouts, the split-sum axis,
    /// glass over the IOR).
    #[must_use]
    pub fn paired_with(mapping: MuMapping) -> Self {
        match mapping {
            MuMapping::Balanced | MuMapping::OneIor => Texels::LookupFit,
            _ => Texels::Nodes,
        }
    }
}

/// Everything that determines a table's values.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct TableSpec {
    pub model: Model,
    pub quantity: Quantity,
    /// The index-of-refraction axis, the slowest-varying, of the dielectric tables and `F_avg`;
    /// `None` otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ior: Option<Axis>,
    /// The roughness axis (rows of a 2-D table; the only axis of `E_avg`); `None` for `F_avg`.
    pub roughness: Option<Axis>,
    /// The `mu` axis (columns, the fastest-varying index); `None` for the averages.
    pub mu: Option<Axis>,
    /// The Fresnel model of an `E_F` table; `None` for every other quantity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fresnel: Option<crate::model::Fresnel>,
    /// How the values are computed.
    #[serde(default)]
    pub method: Method,
    /// Sample count, scrambles and seed of each texel's QMC estimate (with [`Method::Qmc`]).
    pub qmc: QmcSettings,
    /// With [`Method::Reference`]: the quadrature's tolerance is `10^-digits` (absent: the
    /// reference's own 1e-11).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_digits: Option<u32>,
    /// For a table derived from another table's lookup (`f_ms_norm`): that table's spec.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lookup_of: Option<Box<TableSpec>>,
    /// How a dielectric table counts a refraction that ends on the incident side (single
    /// scattering, the default, loses it; Cycles' convention keeps it); absent from files and
    /// from every other quantity's spec.
    #[serde(default, skip_serializing_if = "TransmissionConvention::is_default")]
    pub transmission: TransmissionConvention,
    /// Point samples (the default, absent from files) or texels fitted for the lookup.
    #[serde(default, skip_serializing_if = "Texels::is_nodes")]
    pub texels: Texels,
    /// `f_ms_norm` storing `(1 - Ē) / x` only: its first cells with more nodes
    /// ([`normalisation::REFINED_START`]); absent elsewhere, and in older files (every cell
    /// then holds [`normalisation::SUBDIVISIONS`] nodes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refined_start: Option<normalisation::RefinedStart>,
}

impl TableSpec {
    /// What the table's values integrate ([`crate::integrate::value`]: the one place that
    /// evaluates a quantity at a point, by the reference or by QMC).
    #[must_use]
    pub fn integral(&self) -> crate::integrate::value::Integral {
        crate::integrate::value::Integral {
            model: self.model,
            quantity: self.quantity,
            fresnel: self.fresnel,
            transmission: self.transmission,
        }
    }

    /// The quadrature settings of [`Method::Reference`]: tolerance `10^-reference_digits`.
    #[must_use]
    pub fn reference_settings(&self) -> crate::integrate::reference::ReferenceSettings {
        let mut settings = crate::integrate::reference::ReferenceSettings::default();
        if let Some(digits) = self.reference_digits {
            settings.tolerance = 10f64.powi(-(digits as i32));
        }
        settings
    }

    /// The axes, slowest-varying first: `[eta, roughness, mu]` with the absent ones left out.
    #[must_use]
    pub fn axes(&self) -> Vec<Axis> {
        self.ior
            .into_iter()
            .chain(self.roughness)
            .chain(self.mu)
            .collect()
    }

    /// The shape, slowest-varying first.
    #[must_use]
    pub fn shape(&self) -> Vec<usize> {
        self.axes().iter().map(Axis::size).collect()
    }

    /// The number of texels.
    #[must_use]
    pub fn len(&self) -> usize {
        self.shape().iter().fold(1, |n, &s| n.saturating_mul(s))
    }

    /// Whether the table has no texels (never, for a validated spec).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The material's index of refraction of a glass albedo at one IOR: a dielectric table
    /// (`E_dielectric` from either side, or their averages) without an IOR axis, whose Fresnel
    /// model names the index (the table's relative index is that, or its inverse from inside,
    /// [`crate::integrate::value::Integral::fixed_eta`]). `None` for every other table.
    #[must_use]
    pub fn fixed_ior(&self) -> Option<f64> {
        match (self.quantity.is_dielectric(), self.ior, self.fresnel) {
            (true, None, Some(crate::model::Fresnel::Dielectric { eta })) => Some(eta),
            _ => None,
        }
    }

    /// The index the axes' mappings read for a lookup at `eta`: the IOR axis' index
    /// `max(eta, 1 / eta)`, or for a glass table at one IOR its relative index, whatever `eta`
    /// (its `mu` axis, [`MuMapping::OneIor`], tells the sides apart by it).
    #[must_use]
    pub fn mapping_eta(&self, eta: f64) -> f64 {
        match self.fixed_ior() {
            Some(ior) => self.relative_eta(ior),
            None => axis_index(eta),
        }
    }

    /// The roughness convention of the roughness axis (`r` for `F_avg`, which has none).
    #[must_use]
    pub fn roughness_convention(&self) -> RoughnessConvention {
        match self.roughness {
            Some(Axis::Roughness { convention, .. }) => convention,
            _ => RoughnessConvention::Perceptual,
        }
    }

    /// The roughness axis. Panics for `F_avg`, the only table without one.
    #[must_use]
    pub fn roughness_axis(&self) -> Axis {
        self.roughness
            .expect("every table but F_avg has a roughness axis")
    }

    /// A file-name stem naming the table: `ggx-height-correlated-E` (`dielectric-F_avg` for
    /// `F_avg`, which is the same for every model), then the Fresnel model's tag for `E_F`
    /// (`-dielectric-1.5`) or the index of a glass table at one IOR (`-ior-1.5`), then
    /// a tag for each axis convention that differs from kiln's layout for the quantity, so that
    /// tables a lookup reads differently never share a name: `-alpha` (roughness axis alpha),
    /// `-mu-linear`, `-mu-adaptive` ... (a `mu` axis other than
    /// [`MuMapping::kiln_default`]), `-rows-linear` or `-rows-balanced` (rows other than those
    /// of the `mu` axis, [`axis::RoughnessSpacing::paired_with`]), `-centers` (texel-centre
    /// grid), `-nodes` or `-lookup-fit` (texels other than those of the `mu` axis,
    /// [`Texels::paired_with`]), `-ior-linear`. Sizes, ranges and accuracy
    /// are not in the name: a bake refuses to replace a table of the same name made to another
    /// spec (`format::replace`).
    #[must_use]
    pub fn id(&self) -> String {
        let mut id = self.base_id();
        for tag in self.layout_tags() {
            id = format!("{id}-{tag}");
        }
        id
    }

    /// [`TableSpec::id`] without the layout tags: model, quantity and Fresnel model.
    #[must_use]
    pub fn base_id(&self) -> String {
        let id = if self.quantity == Quantity::FAvg {
            "dielectric-F_avg".to_string()
        } else {
            format!(
                "{}-{}-{}",
                self.model.ndf,
                self.model.masking,
                self.quantity.symbol()
            )
        };
        let id = match (self.fixed_ior(), self.fresnel) {
            (Some(ior), _) => format!("{id}-ior-{ior}"),
            (None, Some(fresnel)) => format!("{id}-{}", fresnel.tag()),
            (None, None) => id,
        };
        match self.transmission {
            TransmissionConvention::SingleScattering => id,
            convention => format!("{id}-transmission-{}", convention.name()),
        }
    }

    /// The axis conventions that differ from kiln's default layout, as name tags (see
    /// [`TableSpec::id`]).
    #[must_use]
    pub fn layout_tags(&self) -> Vec<&'static str> {
        // A derived table is named after the layout of the table it derives from.
        if let Some(source) = &self.lookup_of {
            return source.layout_tags();
        }
        let mut tags = Vec::new();
        if let Some(Axis::Roughness {
            convention: RoughnessConvention::Alpha,
            ..
        }) = self.roughness
        {
            tags.push("alpha");
        }
        let mu_mapping = match self.mu {
            Some(Axis::Mu { mapping, .. }) => Some(mapping),
            _ => None,
        };
        // The rows and texels are tagged against those that go with the table's mu axis (kiln's
        // axis for the quantity when the table has none, as E_avg).
        let kiln_mu = MuMapping::kiln_default(self.quantity, self.ior.is_some());
        match mu_mapping {
            // The glass layout's axis and the product grid's adaptive one: the IOR tag tells.
            Some(MuMapping::Glass | MuMapping::Adaptive) if self.ior.is_some() => {}
            Some(mapping) if mapping != kiln_mu => tags.push(mapping.tag()),
            _ => {}
        }
        let paired_mu = mu_mapping.unwrap_or(kiln_mu);
        if let Some(Axis::Roughness { spacing, .. }) = self.roughness
            && spacing != axis::RoughnessSpacing::paired_with(paired_mu)
        {
            tags.push(spacing.tag());
        }
        if self.axes().iter().any(|axis| axis.grid() == Grid::Centers) {
            tags.push("centers");
        }
        let texels_paired = match (mu_mapping, self.roughness) {
            // Over the IOR: point samples unless a fit was asked for.
            _ if self.ior.is_some() => Texels::Nodes,
            (Some(mapping), _) => Texels::paired_with(mapping),
            // A table without a mu axis (E_avg) takes its texels' baseline from its rows:
            // fitted with balanced rows, point samples with linear ones.
            (
                None,
                Some(Axis::Roughness {
                    spacing: axis::RoughnessSpacing::Balanced,
                    ..
                }),
            ) => Texels::LookupFit,
            (None, _) => Texels::Nodes,
        };
        if self.texels != texels_paired {
            tags.push(self.texels.name());
        }
        match self.ior {
            Some(Axis::Ior {
                mapping: IorMapping::Linear,
                ..
            }) => tags.push("ior-linear"),
            // Cycles' axis is the default of F_avg and the reflection-only albedos; kiln's
            // glass layout the glass albedos'.
            Some(Axis::Ior {
                mapping: IorMapping::Cycles,
                ..
            }) if self.quantity.is_glass_albedo() => tags.push("ior-cycles"),
            Some(Axis::Ior {
                mapping: IorMapping::Blender,
                ..
            }) => tags.push("ior-blender"),
            _ => {}
        }
        tags
    }

    /// Texel `index` (row-major, slowest axis first) split into its `[eta, roughness, mu]`
    /// indices, each `None` where the axis is absent.
    #[must_use]
    pub fn texel_indices(&self, index: usize) -> [Option<usize>; 3] {
        let mut rest = index;
        let mut out = [None; 3];
        // Fastest axis first.
        for (slot, axis) in [(2, self.mu), (1, self.roughness), (0, self.ior)] {
            if let Some(axis) = axis {
                out[slot] = Some(rest % axis.size());
                rest /= axis.size();
            }
        }
        out
    }

    /// The `(alpha, mu)` at which texel `index` (row-major, slowest axis first) is computed;
    /// `mu` is `None` for the averages, `alpha` is 0 for `F_avg`.
    #[must_use]
    pub fn texel_coordinates(&self, index: usize) -> (f64, Option<f64>) {
        let (alpha, mu, _) = self.texel_point(index);
        (alpha, mu)
    }

    /// The relative index of refraction at which texel `index` is computed: the IOR axis' `eta`,
    /// or `1 / eta` for light arriving from inside; `None` without an IOR axis.
    #[must_use]
    pub fn texel_eta(&self, index: usize) -> Option<f64> {
        self.texel_point(index).2
    }

    /// The point `(alpha, mu, eta)` at which texel `index` (row-major, slowest axis first) is
    /// computed: `mu` is `None` for the averages, `alpha` is 0 for `F_avg`, `eta` (the relative
    /// index, `1 / eta` for light from inside) is `None` without an IOR axis. In kiln's glass
    /// layout the IOR of a texel depends on its roughness, a `mu` on both, and the `eta = 1`
    /// slice holds the one-sided limit `eta -> 1+`
    /// ([`glass_layout::GlassLayout::limit_slice_point`]).
    #[must_use]
    pub fn texel_point(&self, index: usize) -> (f64, Option<f64>, Option<f64>) {
        let [k, r, m] = self.texel_indices(index);
        let row = match (self.roughness, r) {
            (Some(roughness), Some(r)) => Some(roughness.coordinate(r)),
            _ => None,
        };
        let row_alpha = row.map_or(0.0, |t_r| self.row_alpha(t_r));
        let t_eta = match (self.ior, k) {
            (Some(ior), Some(k)) => Some(ior.coordinate(k)),
            _ => None,
        };
        let mut eta_up = t_eta.map(|t| self.ior_at(t, row_alpha));
        if let (Some(mu_axis @ Axis::Mu { mapping, .. }), Some(m)) = (self.mu, m)
            && t_eta == Some(0.0)
            && self.is_glass_layout()
        {
            let t_mu = mu_axis.coordinate(m);
            let (alpha, eta_limit) =
                glass_layout::GlassLayout::KILN.limit_slice_point(t_mu, row_alpha);
            if eta_limit > 1.0 {
                // Inside the eta layer: its profile, at the slice's own point.
                let mu = mapping.mu_at(t_mu, alpha, eta_limit, mu_axis.size());
                return (alpha, Some(mu), Some(self.relative_eta(eta_limit)));
            }
            eta_up = Some(eta_limit);
        }
        let eta = eta_up.map(|eta| self.relative_eta(eta));
        let Some(t_r) = row else {
            return (0.0, None, eta);
        };
        match (self.mu, m) {
            (Some(mu), Some(m)) => {
                let (alpha, mu) = self.point_at(t_r, mu.coordinate(m), eta_up.unwrap_or(1.0));
                (alpha, mu, eta)
            }
            _ if self.row_limit_alpha().is_some() => (row_alpha, None, eta),
            _ => (self.roughness_axis().alpha_at_coordinate(t_r), None, eta),
        }
    }

    /// Whether the table is an albedo in kiln's glass layout: a `glass` IOR axis and a mu axis
    /// (an average on a `glass` IOR axis has no layer in mu to follow).
    #[must_use]
    pub fn is_glass_layout(&self) -> bool {
        matches!(
            self.ior,
            Some(Axis::Ior {
                mapping: IorMapping::Glass,
                ..
            })
        ) && self.mu.is_some()
    }

    /// Whether a lookup's texture coordinates depend on the roughness as well as on their own
    /// variable (the `adaptive` mu axis, kiln's glass layout): a generated lookup then computes
    /// `alpha` first.
    #[must_use]
    pub fn coordinates_depend_on_roughness(&self) -> bool {
        self.mu
            .into_iter()
            .chain(self.ior)
            .any(|axis| axis.depends_on_row())
    }

    /// The `alpha` at which the row at roughness coordinate `t_roughness` is computed: its
    /// `alpha`, or on the row `alpha = 0` of a layout that follows layers shrinking with `alpha`
    /// their limit's ([`TableSpec::row_limit_alpha`]).
    #[must_use]
    pub fn row_alpha(&self, t_roughness: f64) -> f64 {
        let alpha = self.roughness_axis().alpha_at_coordinate(t_roughness);
        match self.row_limit_alpha() {
            Some(limit) if alpha == 0.0 => limit,
            _ => alpha,
        }
    }

    /// The IOR axis' index `eta >= 1` at its texture coordinate `t_eta` on the row of
    /// `row_alpha` ([`TableSpec::row_alpha`]): on a `glass` axis the slice `eta = 1` is its
    /// one-sided limit, computed at [`glass_layout::limit_slice_eta`]. 1 without an IOR axis.
    #[must_use]
    pub fn ior_at(&self, t_eta: f64, row_alpha: f64) -> f64 {
        match self.ior {
            Some(Axis::Ior { mapping, max, .. }) => {
                let eta = mapping.eta(t_eta, max.0, row_alpha);
                if mapping == IorMapping::Glass && eta <= 1.0 {
                    glass_layout::limit_slice_eta(row_alpha)
                } else {
                    eta
                }
            }
            _ => 1.0,
        }
    }

    /// The `alpha` at which a row at `alpha = 0` is computed when the layout's coordinates
    /// follow layers that shrink with `alpha` (its limit `alpha -> 0+` at fixed texture
    /// coordinates): [`glass_layout::ROW_LIMIT_ALPHA`] on a `glass` IOR axis with a mu axis,
    /// [`axis::LAYER_LIMIT_ALPHA`] on an `adaptive` mu axis; `None` otherwise.
    #[must_use]
    pub fn row_limit_alpha(&self) -> Option<f64> {
        // An average has no layer in mu to follow: its row alpha = 0 is the smooth interface's
        // exact 1, at every index.
        if self.is_glass_layout() {
            return Some(glass_layout::ROW_LIMIT_ALPHA);
        }
        match self.mu {
            Some(Axis::Mu { mapping, .. }) if mapping.depends_on_roughness() => {
                Some(axis::LAYER_LIMIT_ALPHA)
            }
            _ => None,
        }
    }

    /// The relative index a table of this quantity is computed at for the IOR axis value `eta`
    /// (`1 / eta` from inside).
    #[must_use]
    pub fn relative_eta(&self, eta: f64) -> f64 {
        if self.quantity.from_inside() {
            1.0 / eta
        } else {
            eta
        }
    }

    /// The physical point `(alpha, mu)` at texture coordinates `t_roughness` and `t_mu` (the
    /// latter ignored for `E_avg`). On the row `alpha = 0` of an `adaptive` mu axis this is the
    /// boundary layer's limit, taken at [`axis::LAYER_LIMIT_ALPHA`] (see [`axis`]), except at
    /// `t_mu = 1`, where the limit is the mirror at normal incidence (`alpha = 0`, `mu = 1`).
    /// A `glass` mu axis is read at `eta = 1` ([`TableSpec::point_at`] names the IOR).
    #[must_use]
    pub fn point(&self, t_roughness: f64, t_mu: f64) -> (f64, Option<f64>) {
        self.point_at(t_roughness, t_mu, 1.0)
    }

    /// [`TableSpec::point`] at the IOR axis' index `eta_up >= 1` (only a `glass` mu axis
    /// depends on it; a glass table at one IOR is at its own, [`TableSpec::fixed_ior`]).
    #[must_use]
    pub fn point_at(&self, t_roughness: f64, t_mu: f64, eta_up: f64) -> (f64, Option<f64>) {
        debug_assert!(self.roughness.is_some(), "F_avg has no roughness axis");
        // A glass table at one IOR is laid out at its own index, whatever the caller's.
        let eta_up = self.mapping_eta(eta_up);
        let alpha = self.roughness_axis().alpha_at_coordinate(t_roughness);
        match self.mu {
            Some(Axis::Mu { mapping, size, .. }) => {
                if alpha == 0.0
                    && let Some(limit) = self.row_limit_alpha()
                {
                    // The layer's limit at fixed t; at t = 1 (mu = 1 for every alpha > 0) that
                    // limit is the mirror's: loss exactly 0, not the 2e-14 of alpha = 1e-7.
                    if t_mu >= 1.0 {
                        return (0.0, Some(1.0));
                    }
                    return (limit, Some(mapping.mu_at(t_mu, limit, eta_up, size)));
                }
                (alpha, Some(mapping.mu_at(t_mu, alpha, eta_up, size)))
            }
            _ => (alpha, None),
        }
    }
}

/// A baked table: its spec, per-texel values and standard errors, and where it came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Table {
    pub spec: TableSpec,
    /// The quantity's value per texel, row-major with the slowest axis first.
    pub value: Vec<f64>,
    /// One minus the value, estimated directly (keeps relative precision near 1).
    pub one_minus_value: Vec<f64>,
    /// The standard error of each texel's estimate.
    pub std_error: Vec<f64>,
    /// The command that reproduces this table.
    pub command: String,
    /// The error of the stored values against the deterministic reference, where measured.
    pub node_errors: Option<NodeErrors>,
    /// The `--max-error` the table was baked to meet, if any.
    pub requested_max_error: Option<f64>,
    /// For texels fitted for the lookup: what the fit measured ([`lookup_fit`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lookup_fit: Option<lookup_fit::LookupFitReport>,
}

impl Table {
    /// The largest per-texel standard error (NaN if any is NaN; infinite where a quadrature
    /// did not converge, [`crate::bake::estimate_texel`]).
    #[must_use]
    pub fn max_std_error(&self) -> f64 {
        crate::stats::max_or_nan(self.std_error.iter().copied())
    }

    /// The root-mean-square per-texel standard error.
    #[must_use]
    pub fn rms_std_error(&self) -> f64 {
        (self.std_error.iter().map(|e| e * e).sum::<f64>() / self.std_error.len() as f64).sqrt()
    }

    /// Channel names, in storage order: `E`, `one_minus_E`, `std_error` (or the `E_avg` forms).
    #[must_use]
    pub fn channel_names(&self) -> [String; 3] {
        let q = self.spec.quantity.symbol();
        [
            q.to_string(),
            format!("one_minus_{q}"),
            "std_error".to_string(),
        ]
    }

    /// A table of `spec` with these channels and nothing measured of it yet (no node errors,
    /// no requested bound, no lookup fit): what a bake, a merge or a reader starts from.
    #[must_use]
    pub fn unmeasured(
        spec: TableSpec,
        [value, one_minus_value, std_error]: [Vec<f64>; 3],
        command: String,
    ) -> Self {
        Self {
            spec,
            value,
            one_minus_value,
            std_error,
            command,
            node_errors: None,
            requested_max_error: None,
            lookup_fit: None,
        }
    }

    /// [`Table::unmeasured`] of values read without their other channels (an engine's file, an
    /// external table): `1 - value` computed from them, no standard errors.
    #[must_use]
    pub fn of_values(spec: TableSpec, value: Vec<f64>, command: String) -> Self {
        let one_minus_value = value.iter().map(|v| 1.0 - v).collect();
        let std_error = vec![0.0; value.len()];
        Self::unmeasured(spec, [value, one_minus_value, std_error], command)
    }

    /// A table of `spec` whose channels are zero: its layout, for looking up channels laid out
    /// like it ([`Table::lookup_channel`]) that it does not hold.
    #[must_use]
    pub fn layout_of(spec: TableSpec) -> Self {
        let zeros = vec![0.0; spec.len()];
        Self::unmeasured(spec, [zeros.clone(), zeros.clone(), zeros], String::new())
    }

    /// The channels in storage order, matching [`Table::channel_names`].
    #[must_use]
    pub fn channels(&self) -> [&[f64]; 3] {
        [&self.value, &self.one_minus_value, &self.std_error]
    }

    /// The value a renderer's bilinear lookup returns at `(mu, roughness)` (roughness in the
    /// table's convention; `mu` is ignored for a 1-D table), with clamp-to-edge.
    /// For a dielectric table, [`Table::lookup_eta`] names the IOR too (here it is 1).
    #[must_use]
    pub fn lookup(&self, mu: f64, roughness: f64) -> f64 {
        self.lookup_channel(&self.value, mu, roughness)
    }

    /// As [`Table::lookup`], of `one_minus_value`.
    #[must_use]
    pub fn lookup_one_minus(&self, mu: f64, roughness: f64) -> f64 {
        self.lookup_channel(&self.one_minus_value, mu, roughness)
    }

    /// As [`Table::lookup`], of any channel laid out like the table (one of [`Table::channels`]).
    #[must_use]
    pub fn lookup_channel(&self, channel: &[f64], mu: f64, roughness: f64) -> f64 {
        self.lookup_channel_eta(channel, mu, roughness, 1.0)
    }

    /// The bilinear (trilinear with an IOR axis) lookup of `channel` at `(mu, roughness, eta)`,
    /// clamp-to-edge; `eta` may be given as listed on the axis or as the relative index of an
    /// inside table (`eta < 1` is looked up at `1 / eta`). Absent axes ignore their coordinate.
    #[must_use]
    pub fn lookup_channel_eta(&self, channel: &[f64], mu: f64, roughness: f64, eta: f64) -> f64 {
        self.lookup_along_mu(channel, roughness, eta)(mu)
    }

    /// [`Table::lookup_channel_eta`] as a function of `mu` at a fixed `(roughness, eta)`: the
    /// slower axes' corners are found once, each call finds only `mu`'s (the same operations
    /// per lookup, so the same bits). For the integrals of a lookup over `mu` (`f_ms_norm`).
    pub fn lookup_along_mu<'a>(
        &'a self,
        channel: &'a [f64],
        roughness: f64,
        eta: f64,
    ) -> impl Fn(f64) -> f64 + 'a {
        let alpha = self.spec.roughness_convention().to_alpha(roughness);
        let eta_up = self.spec.mapping_eta(eta);
        let corner =
            move |axis: Axis, x: f64, stride: usize| self.corner(axis, x, alpha, eta_up, stride);
        // Per axis, slowest first: the two samples to blend, the second's weight, the stride
        // (the product of the faster axes' sizes). In place: a lookup allocates nothing (the
        // audits and `f_ms_norm` make millions).
        let (roughness_stride, ior_stride) = self.strides();
        let mut corners = [Corner::default(); 3];
        let mut slower = 0;
        for (axis, x, stride) in [
            (self.spec.ior, eta, ior_stride),
            (self.spec.roughness, roughness, roughness_stride),
        ] {
            if let Some(axis) = axis {
                corners[slower] = corner(axis, x, stride);
                slower += 1;
            }
        }
        move |mu: f64| {
            let mut corners = corners;
            let mut count = slower;
            if let Some(axis) = self.spec.mu {
                corners[count] = corner(axis, mu, 1);
                count += 1;
            }
            blend(channel, &corners[..count], 0)
        }
    }

    /// Where a lookup of `axis` at `x` falls ([`Corner::new`]), but on the roughness axis of an
    /// `f_ms_norm` with a refined start, at its node line
    /// ([`normalisation::NodeLine::position`]).
    fn corner(&self, axis: Axis, x: f64, alpha: f64, eta_up: f64, stride: usize) -> Corner {
        match (self.spec.refined_start, axis) {
            (
                Some(_),
                Axis::Roughness {
                    convention,
                    spacing,
                    size,
                    ..
                },
            ) => Corner::at(
                normalisation::NodeLine::of(&self.spec).position(spacing.coordinate(x, convention)),
                size,
                stride,
            ),
            _ => Corner::new(axis, x, alpha, eta_up, stride),
        }
    }

    /// The index strides of the roughness and IOR axes: the product of the faster axes' sizes.
    fn strides(&self) -> (usize, usize) {
        let size = |axis: Option<Axis>| axis.map_or(1, |axis| axis.size());
        let roughness_stride = size(self.spec.mu);
        (
            roughness_stride,
            roughness_stride * size(self.spec.roughness),
        )
    }

    /// The texels and weights of [`Table::lookup_channel_eta`] at `(mu, roughness, eta)`:
    /// the same corners, so `weights.apply(channel)` is the lookup up to rounding.
    #[must_use]
    pub fn lookup_weights(&self, mu: f64, roughness: f64, eta: f64) -> LookupWeights {
        let alpha = self.spec.roughness_convention().to_alpha(roughness);
        let eta_up = self.spec.mapping_eta(eta);
        let (roughness_stride, ior_stride) = self.strides();
        let mut out = LookupWeights {
            terms: [(0, 1.0); 8],
            count: 1,
        };
        for (axis, x, stride) in [
            (self.spec.ior, eta, ior_stride),
            (self.spec.roughness, roughness, roughness_stride),
            (self.spec.mu, mu, 1),
        ] {
            let Some(axis) = axis else { continue };
            let c = self.corner(axis, x, alpha, eta_up, stride);
            let n = out.count;
            for k in 0..n {
                let (index, weight) = out.terms[k];
                out.terms[k] = (index + c.low * stride, weight * (1.0 - c.weight));
                out.terms[n + k] = (index + c.high * stride, weight * c.weight);
            }
            out.count = 2 * n;
        }
        out
    }

    /// As [`Table::lookup`] with the IOR coordinate of a dielectric table.
    #[must_use]
    pub fn lookup_eta(&self, mu: f64, roughness: f64, eta: f64) -> f64 {
        self.lookup_channel_eta(&self.value, mu, roughness, eta)
    }
}

/// One axis of a lookup: the two samples blended, the second's weight, the index stride.
#[derive(Clone, Copy, Default)]
struct Corner {
    low: usize,
    high: usize,
    weight: f64,
    stride: usize,
}

impl Corner {
    /// Where a lookup of `axis` at the physical coordinate `x` (on the row of roughness
    /// `alpha`, at the IOR axis' index `eta_up`) falls, for an axis of index stride `stride`.
    fn new(axis: Axis, x: f64, alpha: f64, eta_up: f64, stride: usize) -> Self {
        Corner::at(axis.position(x, alpha, eta_up), axis.size(), stride)
    }

    /// The corner at the continuous sample position `p` (in `[0, size - 1]`) of an axis of
    /// `size` samples.
    fn at(p: f64, size: usize, stride: usize) -> Self {
        let i = (p.floor() as usize).min(size.saturating_sub(2));
        Corner {
            low: i,
            high: (i + 1).min(size - 1),
            weight: p - i as f64,
            stride,
        }
    }
}

/// The IOR axis' index `eta >= 1` of a lookup's `eta` (an inside table's relative index
/// `eta < 1` is read at `1 / eta`).
fn axis_index(eta: f64) -> f64 {
    if eta < 1.0 { 1.0 / eta } else { eta }
}

/// The texels a lookup blends and their weights: the lookup is `sum weight * texel` (up to
/// eight terms, trilinear; a weight may be 0). What a fit of the texels for the lookup solves
/// for ([`lookup_fit`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct LookupWeights {
    pub terms: [(usize, f64); 8],
    pub count: usize,
}

impl LookupWeights {
    /// The terms.
    #[must_use]
    pub fn terms(&self) -> &[(usize, f64)] {
        &self.terms[..self.count]
    }

    /// The lookup of `channel` these weights give.
    #[must_use]
    pub fn apply(&self, channel: &[f64]) -> f64 {
        crate::numerics::minimax::dot(self.terms(), channel)
    }
}

impl AsRef<[(usize, f64)]> for LookupWeights {
    fn as_ref(&self) -> &[(usize, f64)] {
        self.terms()
    }
}

/// Blends the fastest axis first, then each slower one, as a GPU's filter does (for a 2-D table:
/// two rows along `mu`, then between the rows).
fn blend(channel: &[f64], corners: &[Corner], base: usize) -> f64 {
    match corners.split_first() {
        None => channel[base],
        Some((c, rest)) => {
            let a = blend(channel, rest, base + c.low * c.stride);
            let b = blend(channel, rest, base + c.high * c.stride);
            a * (1.0 - c.weight) + b * c.weight
        }
    }
}

/// The node errors `kiln bake` measures against the reference and records with a table
/// ([`crate::verify::node_errors`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodeErrors {
    /// The largest error (NaN if any texel is NaN).
    pub max: f64,
    pub rms: f64,
    /// How many texels were checked.
    pub texels: usize,
    /// How many of them had a reference that did not converge within its evaluation budget
    /// (their error is the difference plus the reference's own error estimate).
    #[serde(default)]
    pub unconverged: usize,
}

/// A GGX height-correlated `E` spec of `rows` x `columns` on perceptual roughness, for the
/// unit tests of the table modules.
#[cfg(test)]
pub(crate) fn test_e_spec(
    rows: usize,
    columns: usize,
    grid: Grid,
    mapping: MuMapping,
) -> TableSpec {
    TableSpec {
        model: Model {
            ndf: crate::model::Ndf::Ggx,
            masking: crate::model::Masking::HeightCorrelated,
        },
        quantity: Quantity::E,
        ior: None,
        roughness: Some(Axis::Roughness {
            size: rows,
            convention: RoughnessConvention::Perceptual,
            grid,
            spacing: crate::table::axis::RoughnessSpacing::Linear,
        }),
        mu: Some(Axis::Mu {
            size: columns,
            mapping,
            grid,
        }),
        fresnel: None,
        method: Method::Qmc,
        qmc: QmcSettings::default(),
        reference_digits: None,
        lookup_of: None,
        refined_start: None,
        texels: Texels::Nodes,
        transmission: TransmissionConvention::SingleScattering,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use axis::{Grid, MuMapping};

    fn synthetic(grid: Grid, mapping: MuMapping) -> Table {
        let spec = test_e_spec(5, 4, grid, mapping);
        // value = 10 * row + column, so that interpolation is easy to predict.
        let value: Vec<f64> = (0..20).map(|k| (10 * (k / 4) + k % 4) as f64).collect();
        Table {
            one_minus_value: value.iter().map(|v| 1.0 - v).collect(),
            std_error: vec![0.0; 20],
            value,
            spec,
            command: String::new(),
            node_errors: None,
            requested_max_error: None,
            lookup_fit: None,
        }
    }

    /// The weights a lookup fit solves with give the lookup itself, on 2-D tables of every
    /// grid and mapping (an adaptive axis moves `mu` with the row) and a 3-D one.
    #[test]
    fn lookup_weights_give_the_lookup() {
        let mut tables: Vec<Table> = [Grid::Nodes, Grid::Centers]
            .into_iter()
            .flat_map(|g| {
                [MuMapping::Linear, MuMapping::Sqrt, MuMapping::Adaptive].map(|m| synthetic(g, m))
            })
            .collect();
        let mut glass = synthetic(Grid::Nodes, MuMapping::Linear);
        glass.spec.ior = Some(Axis::Ior {
            size: 3,
            mapping: IorMapping::Cycles,
            max: axis::IorBound(3.0),
            grid: Grid::Nodes,
        });
        glass.value = (0..60).map(|k| (k * k % 17) as f64).collect();
        tables.push(glass);
        for table in &tables {
            for k in 0..200 {
                let x = |m: usize| ((k * m) % 101) as f64 / 100.0;
                let (mu, r, eta) = (x(37), x(53), 1.0 + 2.0 * x(71));
                let w = table.lookup_weights(mu, r, eta);
                let want = table.lookup_eta(mu, r, eta);
                assert!(
                    (w.apply(&table.value) - want).abs() < 1e-12,
                    "{mu} {r} {eta}"
                );
                let total: f64 = w.terms().iter().map(|t| t.1).sum();
                assert!((total - 1.0).abs() < 1e-12);
            }
        }
    }

    /// A 3-D lookup (IOR, roughness, `mu`) at every node and between them: the values are
    /// `100 eta_index + 10 row + column`, linear in each index, so the trilinear blend anywhere
    /// is the same form of the texture coordinates, and a wrong stride of either slower axis
    /// reads another texel.
    #[test]
    fn a_lookup_over_ior_finds_every_axis_by_its_stride() {
        let mut t = synthetic(Grid::Nodes, MuMapping::Linear);
        t.spec.ior = Some(Axis::Ior {
            size: 3,
            mapping: IorMapping::Linear,
            max: axis::IorBound(3.0),
            grid: Grid::Nodes,
        });
        t.value = (0..60)
            .map(|k| (100 * (k / 20) + 10 * (k % 20 / 4) + k % 4) as f64)
            .collect();
        let etas = t.spec.ior.unwrap().listed_values();
        assert_eq!(etas, [1.0, 2.0, 3.0]);
        for (e, &eta) in etas.iter().enumerate() {
            for row in 0..5 {
                for col in 0..4 {
                    let (r, mu) = (row as f64 / 4.0, col as f64 / 3.0);
                    let want = (100 * e + 10 * row + col) as f64;
                    let got = t.lookup_eta(mu, r, eta);
                    assert!((got - want).abs() < 1e-9, "{e} {row} {col}: {got}");
                }
            }
        }
        // Halfway along every axis: index positions 1.5, 2.5 and 0.5.
        let got = t.lookup_eta(0.5 / 3.0, 2.5 / 4.0, 2.5);
        assert!((got - 175.5).abs() < 1e-9, "{got}");
    }

    /// `synthetic`'s table with an IOR axis of 3 nodes in front: shape 3 x 5 x 4.
    fn synthetic_over_ior(quantity: Quantity) -> TableSpec {
        let mut spec = synthetic(Grid::Nodes, MuMapping::Linear).spec;
        spec.quantity = quantity;
        spec.ior = Some(Axis::Ior {
            size: 3,
            mapping: IorMapping::Linear,
            max: axis::IorBound(3.0),
            grid: Grid::Nodes,
        });
        spec
    }

    /// Texel indices by hand: row-major, the IOR axis slowest and `mu` fastest, so texel
    /// `20 e + 4 row + col` is `[e, row, col]`.
    #[test]
    fn a_spec_counts_and_splits_its_texels_slowest_axis_first() {
        let spec = synthetic_over_ior(Quantity::EDielectric);
        assert_eq!(spec.shape(), [3, 5, 4]);
        assert_eq!(spec.len(), 60);
        assert!(!spec.is_empty());
        assert_eq!(spec.texel_indices(0), [Some(0), Some(0), Some(0)]);
        assert_eq!(spec.texel_indices(37), [Some(1), Some(4), Some(1)]);
        assert_eq!(spec.texel_indices(59), [Some(2), Some(4), Some(3)]);
        let flat = synthetic(Grid::Nodes, MuMapping::Linear).spec;
        assert_eq!(flat.texel_indices(13), [None, Some(3), Some(1)]);
        let mut average = flat.clone();
        average.mu = None;
        assert_eq!(average.len(), 5);
        assert_eq!(average.texel_indices(3), [None, Some(3), None]);
        let mut empty = flat;
        empty.mu = Some(Axis::Mu {
            size: 0,
            mapping: MuMapping::Linear,
            grid: Grid::Nodes,
        });
        assert_eq!(empty.len(), 0);
        assert!(empty.is_empty());
    }

    /// Where each texel is computed, from the axis formulas in `axis`'s docs worked by hand:
    /// rows on nodes of `r` with `alpha = r^2`, columns `mu = t` or the adaptive
    /// `mu = s k / (1 + k - s)`, `s = t^2.5`, `k = 4 alpha`, and at `alpha = 0` the boundary
    /// layer's limit at `alpha = 1e-7`, except the mirror at `t = 1`.
    #[test]
    fn texels_are_computed_where_the_axis_formulas_put_them() {
        let linear = synthetic(Grid::Nodes, MuMapping::Linear).spec;
        // Texel 9: row 2 of 5 nodes (r = 0.5, alpha = 0.25), column 1 of 4 (mu = 1/3).
        let (alpha, mu) = linear.texel_coordinates(9);
        assert_eq!(alpha, 0.25);
        assert!((mu.unwrap() - 1.0 / 3.0).abs() < 1e-15);
        // A linear axis has no layer: alpha = 0 stays 0.
        assert_eq!(linear.point(0.0, 0.5), (0.0, Some(0.5)));
        let mut average = linear.clone();
        average.mu = None;
        assert_eq!(average.texel_coordinates(3), (0.5625, None));
        let mut f_avg = average;
        f_avg.roughness = None;
        assert_eq!(f_avg.texel_coordinates(0), (0.0, None));

        let adaptive = synthetic(Grid::Nodes, MuMapping::Adaptive).spec;
        let mu_of = |t: f64, alpha: f64| {
            let (s, k) = (t.powf(2.5), 4.0 * alpha);
            s * k / (1.0 + k - s)
        };
        let (alpha, mu) = adaptive.point(0.5, 0.5);
        assert_eq!(alpha, 0.25);
        assert!((mu.unwrap() - mu_of(0.5, 0.25)).abs() < 1e-15);
        let (alpha, mu) = adaptive.point(0.0, 0.5);
        assert_eq!(alpha, 1e-7);
        assert!((mu.unwrap() / mu_of(0.5, 1e-7) - 1.0).abs() < 1e-12);
        assert_eq!(adaptive.point(0.0, 1.0), (0.0, Some(1.0)));
    }

    /// The IOR axis lists `eta = 1, 2, 3`; light from inside is computed at `1 / eta`.
    #[test]
    fn a_texel_of_light_from_inside_is_computed_at_the_inverse_index() {
        let outside = synthetic_over_ior(Quantity::EDielectric);
        let inside = synthetic_over_ior(Quantity::EDielectricInside);
        assert_eq!(outside.texel_eta(37), Some(2.0));
        assert_eq!(inside.texel_eta(37), Some(0.5));
        assert_eq!(inside.texel_eta(59), Some(1.0 / 3.0));
        assert_eq!(outside.relative_eta(1.5), 1.5);
        assert_eq!(inside.relative_eta(1.5), 1.0 / 1.5);
        assert_eq!(
            synthetic(Grid::Nodes, MuMapping::Linear).spec.texel_eta(3),
            None
        );
    }

    /// File names: kiln's layout for the quantity adds no tag; every other convention adds
    /// its own, in the documented order (`TableSpec::id`).
    #[test]
    fn a_table_is_named_by_its_model_quantity_and_layout() {
        // E's layout: the balanced axis and rows, fitted texels.
        let mut balanced = synthetic(Grid::Nodes, MuMapping::Balanced).spec;
        balanced.roughness = Some(Axis::Roughness {
            size: 5,
            convention: RoughnessConvention::Perceptual,
            grid: Grid::Nodes,
            spacing: crate::table::axis::RoughnessSpacing::Balanced,
        });
        balanced.texels = Texels::LookupFit;
        assert_eq!(balanced.id(), "ggx-height-correlated-E");
        let mut nodes = balanced.clone();
        nodes.texels = Texels::Nodes;
        assert_eq!(nodes.id(), "ggx-height-correlated-E-nodes");
        let mut average = balanced.clone();
        average.quantity = Quantity::EAvg;
        average.mu = None;
        assert_eq!(average.id(), "ggx-height-correlated-E_avg");
        // The adaptive axis goes with linear rows and point samples, which its tag implies;
        // an E_avg (no mu axis) laid out so is tagged by its rows, which imply its texels.
        let default = synthetic(Grid::Nodes, MuMapping::Adaptive).spec;
        assert_eq!(default.id(), "ggx-height-correlated-E-mu-adaptive");
        let mut average = default.clone();
        average.quantity = Quantity::EAvg;
        average.mu = None;
        assert_eq!(average.id(), "ggx-height-correlated-E_avg-rows-linear");
        average.texels = Texels::LookupFit;
        assert_eq!(
            average.id(),
            "ggx-height-correlated-E_avg-rows-linear-lookup-fit"
        );
        let mut fitted = default.clone();
        fitted.texels = Texels::LookupFit;
        assert_eq!(
            fitted.id(),
            "ggx-height-correlated-E-mu-adaptive-lookup-fit"
        );
        // The split-sum channels' axis is theirs: untagged for them, tagged for E.
        let mut split_sum = synthetic(Grid::Nodes, MuMapping::SplitSum).spec;
        assert_eq!(split_sum.id(), "ggx-height-correlated-E-mu-split-sum");
        split_sum.quantity = Quantity::EBias;
        assert_eq!(split_sum.id(), "ggx-height-correlated-E_bias");
        let mut other = synthetic(Grid::Centers, MuMapping::Linear).spec;
        other.roughness = Some(Axis::Roughness {
            size: 5,
            convention: RoughnessConvention::Alpha,
            grid: Grid::Centers,
            spacing: crate::table::axis::RoughnessSpacing::Linear,
        });
        assert_eq!(
            other.id(),
            "ggx-height-correlated-E-alpha-mu-linear-centers"
        );
        let sqrt = synthetic(Grid::Nodes, MuMapping::Sqrt).spec;
        assert_eq!(sqrt.id(), "ggx-height-correlated-E-mu-sqrt");
        let mut glass = synthetic_over_ior(Quantity::EDielectric);
        glass.mu = default.mu;
        assert!(glass.id().ends_with("-ior-linear"), "{}", glass.id());
        if let Some(Axis::Ior { mapping, .. }) = &mut glass.ior {
            *mapping = IorMapping::Blender;
        }
        assert!(glass.id().ends_with("-ior-blender"), "{}", glass.id());
        if let Some(Axis::Ior { mapping, .. }) = &mut glass.ior {
            *mapping = IorMapping::Cycles;
        }
        // Cycles' product grid is the default of F_avg alone: a dielectric albedo on it is tagged.
        assert!(glass.id().ends_with("-ior-cycles"), "{}", glass.id());
        let mut f_avg = glass.clone();
        f_avg.quantity = Quantity::FAvg;
        assert!(f_avg.base_id() == "dielectric-F_avg", "{}", f_avg.base_id());
        assert!(!f_avg.id().contains("ior"), "{}", f_avg.id());
        // kiln's glass layout is the dielectric albedos' default: no tag.
        if let Some(Axis::Ior { mapping, .. }) = &mut glass.ior {
            *mapping = IorMapping::Glass;
        }
        glass.mu = Some(Axis::Mu {
            size: 4,
            mapping: MuMapping::Glass,
            grid: Grid::Nodes,
        });
        assert_eq!(glass.id(), "ggx-height-correlated-E_dielectric");
        // A derived table takes the layout of its source.
        let mut norm = default.clone();
        norm.lookup_of = Some(Box::new(sqrt));
        assert_eq!(norm.layout_tags(), ["mu-sqrt"]);
    }

    /// The error summaries of `std_error = [3, 4, 0, 0]`: max 4, root-mean-square
    /// `sqrt(25 / 4) = 2.5`.
    #[test]
    fn the_error_summaries_are_the_max_and_the_root_mean_square() {
        let mut t = synthetic(Grid::Nodes, MuMapping::Linear);
        t.std_error = vec![3.0, 4.0, 0.0, 0.0];
        assert_eq!(t.max_std_error(), 4.0);
        assert_eq!(t.rms_std_error(), 2.5);
        t.std_error[2] = f64::NAN;
        assert!(t.max_std_error().is_nan());
    }

    /// The names on the command line and in files are serde's (the names files are read by),
    /// and the reference's tolerance is `10^-digits`, its own 1e-11 without digits.
    #[test]
    fn methods_are_named_as_files_read_them_and_digits_set_the_tolerance() {
        for method in [Method::Qmc, Method::Reference] {
            assert_eq!(serde_json::to_value(method).unwrap(), method.name());
        }
        assert!(Method::Qmc.describe().contains("Sobol"));
        assert!(Method::Reference.describe().contains("Gauss-Kronrod"));
        let mut spec = synthetic(Grid::Nodes, MuMapping::Linear).spec;
        assert_eq!(spec.reference_settings().tolerance, 1e-11);
        spec.reference_digits = Some(7);
        assert!((spec.reference_settings().tolerance / 1e-7 - 1.0).abs() < 1e-15);
        assert_eq!(spec.roughness_convention(), RoughnessConvention::Perceptual);
        spec.roughness = Some(Axis::Roughness {
            size: 5,
            convention: RoughnessConvention::Alpha,
            grid: Grid::Nodes,
            spacing: crate::table::axis::RoughnessSpacing::Linear,
        });
        assert_eq!(spec.roughness_convention(), RoughnessConvention::Alpha);
    }

    /// The channels in the order the files store them, each named, and the one-minus lookup
    /// reading its own channel (`synthetic` stores `1 - value` there).
    #[test]
    fn channels_come_in_storage_order_and_each_lookup_reads_its_own() {
        let mut t = synthetic(Grid::Nodes, MuMapping::Linear);
        t.std_error = vec![0.5; 20];
        assert_eq!(t.channel_names(), ["E", "one_minus_E", "std_error"]);
        let [value, one_minus, error] = t.channels();
        assert_eq!((value[5], one_minus[5], error[5]), (11.0, -10.0, 0.5));
        assert_eq!(value.len() + one_minus.len() + error.len(), 60);
        // Halfway between rows 1 and 2 and columns 2 and 3: 1 - 17.5.
        assert!((t.lookup_one_minus(2.5 / 3.0, 0.375) + 16.5).abs() < 1e-9);
    }

    /// A 4096 x 4096 table, the largest the bake makes, passes the size check; a spec of more
    /// than 2^26 texels does not.
    #[test]
    fn the_size_check_admits_the_largest_bake_and_refuses_more_than_2_to_the_26() {
        let mut spec = synthetic(Grid::Nodes, MuMapping::Linear).spec;
        let axes = |spec: &mut TableSpec, rows: usize, columns: usize| {
            if let Some(Axis::Roughness { size, .. }) = &mut spec.roughness {
                *size = rows;
            }
            if let Some(Axis::Mu { size, .. }) = &mut spec.mu {
                *size = columns;
            }
        };
        axes(&mut spec, 4096, 4096);
        assert!(spec.check().is_ok());
        axes(&mut spec, 4 * 4096, 4096);
        assert!(spec.check().is_ok());
        axes(&mut spec, 4 * 4096 + 1, 4096);
        let message = spec.check().unwrap_err();
        assert!(message.to_string().contains("67112960 texels"), "{message}");
    }

    #[test]
    fn lookup_returns_stored_values_at_sample_coordinates_and_lerps_between() {
        for grid in [Grid::Centers, Grid::Nodes] {
            for mapping in [MuMapping::Linear, MuMapping::Sqrt, MuMapping::Adaptive] {
                let t = synthetic(grid, mapping);
                let (r_axis, mu_axis) = (t.spec.roughness_axis(), t.spec.mu.unwrap());
                // At alpha = 0 the adaptive mapping sends every mu > 0 to the last column.
                let first_row = usize::from(grid == Grid::Nodes && mapping == MuMapping::Adaptive);
                for row in first_row..5 {
                    let r = r_axis.coordinate(row);
                    for col in 0..4 {
                        let mu = mu_axis.value_at(col, r * r, 1.0);
                        let got = t.lookup(mu, r);
                        assert!(
                            (got - t.value[row * 4 + col]).abs() < 1e-9,
                            "{grid:?} {mapping:?} {row} {col}: {got}"
                        );
                    }
                }
                // Halfway between two rows and two columns (in texture coordinates).
                let r = (r_axis.coordinate(1) + r_axis.coordinate(2)) / 2.0;
                let t_mu = (mu_axis.coordinate(2) + mu_axis.coordinate(3)) / 2.0;
                let mu = mapping.mu(t_mu, r * r, mu_axis.size());
                assert!(
                    (t.lookup(mu, r) - 17.5).abs() < 1e-9,
                    "{grid:?} {mapping:?}"
                );
                // Clamp to edge beyond the outermost samples.
                assert_eq!(t.lookup(0.0, 0.0), t.value[0]);
                assert_eq!(t.lookup(1.0, 1.0), t.value[19]);
                if first_row == 1 {
                    // The mirror row: E = 1 for every mu > 0 is the last column.
                    assert_eq!(t.lookup(0.3, 0.0), t.value[3]);
                }
            }
        }
    }
}

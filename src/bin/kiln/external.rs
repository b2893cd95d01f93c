//! The flags that describe a table kiln did not write (its shape, axes, grid, texels and
//! model), shared by `kiln verify` and `kiln furnace`, and the one place that reads a table
//! from a file with them: a kiln file carries its own layout, any other needs them.

use crate::fresnel_args::FresnelArgs;
use clap::Args;
use kiln::format::Precision;
use kiln::verify::input::{AxisName, Encoding, Layout, read_external, read_kiln};
use kiln::{Grid, Masking, Model, MuMapping, Ndf, Quantity, RoughnessConvention, Table};
use std::path::Path;

/// The layout of a table kiln did not write. Errors with a kiln file, which carries its own.
#[derive(Args, Debug, Clone)]
#[group(id = "external_layout", multiple = true)]
pub struct ExternalLayout {
    /// External tables: raw little-endian floats of this type (otherwise text is expected).
    #[arg(long, value_enum)]
    dtype: Option<Precision>,
    /// External tables: read this channel of an EXR file.
    #[arg(long, conflicts_with = "dtype")]
    channel: Option<String>,
    /// External tables: sizes, slowest-varying axis first: 32x32 for E, 32 for E_avg (one size
    /// means an E_avg table unless --quantity says otherwise).
    #[arg(long, value_parser = parse_shape)]
    shape: Option<Shape>,
    /// External tables: the axes, slowest-varying first [default: r,mu for E; r for E_avg].
    #[arg(long, value_enum, value_delimiter = ',')]
    order: Option<Vec<AxisName>>,
    /// External tables: where samples sit [default: centers, as GPU textures are sampled].
    #[arg(long, value_enum)]
    grid: Option<Grid>,
    /// External tables: the roughness axis, r (alpha = r^2) or alpha [default: r].
    #[arg(long, value_enum)]
    roughness_axis: Option<RoughnessConvention>,
    /// External tables: the mu axis spacing [default: linear, as engines' tables are].
    #[arg(long, value_enum)]
    mu_axis: Option<MuMapping>,
    /// External tables: the rows, linear or balanced [default: balanced with --mu-axis balanced].
    #[arg(long, value_enum, hide_possible_values = true)]
    roughness_spacing: Option<kiln::RoughnessSpacing>,
    /// External tables: nodes, or lookup-fit to judge the lookup (as kiln's fitted tables).
    #[arg(long, value_enum, hide_possible_values = true)]
    texels: Option<kiln::table::Texels>,
    /// External tables: the normal distribution [default: ggx].
    #[arg(long, value_enum)]
    ndf: Option<Ndf>,
    /// External tables: the Smith G2 form [default: height-correlated].
    #[arg(long, value_enum)]
    masking: Option<Masking>,
    /// External tables: what the numbers are (e-f: the Fresnel-weighted albedo of the model
    /// the Fresnel flags name) [default: e-avg for a one-size --shape, else e].
    #[arg(long, value_enum)]
    quantity: Option<Quantity>,
    #[command(flatten)]
    fresnel: FresnelArgs,
}

/// Table sizes, slowest-varying axis first.
#[derive(Clone, Debug)]
struct Shape(Vec<usize>);

fn parse_shape(text: &str) -> Result<Shape, String> {
    let sizes: Result<Vec<usize>, _> = text
        .split(['x', 'X'])
        .map(|s| s.trim().parse::<usize>())
        .collect();
    match sizes {
        Ok(sizes)
            if (1..=2).contains(&sizes.len())
                && sizes.iter().all(|&n| (2..=65536).contains(&n)) =>
        {
            Ok(Shape(sizes))
        }
        _ => Err(format!(
            "shape must be like 32x32 or 32, each size 2 to 65536 (got {text})"
        )),
    }
}

impl ExternalLayout {
    /// The external-layout flags given on the command line: a kiln file carries its own layout,
    /// so these are errors with one.
    fn layout_flags_given(&self) -> Vec<&'static str> {
        crate::args::given(&[
            ("--shape", self.shape.is_some()),
            ("--order", self.order.is_some()),
            ("--grid", self.grid.is_some()),
            ("--roughness-axis", self.roughness_axis.is_some()),
            ("--mu-axis", self.mu_axis.is_some()),
            ("--roughness-spacing", self.roughness_spacing.is_some()),
            ("--texels", self.texels.is_some()),
            ("--ndf", self.ndf.is_some()),
            ("--masking", self.masking.is_some()),
            ("--quantity", self.quantity.is_some()),
            ("the Fresnel flags", self.fresnel.given()),
        ])
    }

    fn quantity(&self, shape: &[usize]) -> Quantity {
        self.quantity.unwrap_or(if shape.len() == 1 {
            Quantity::EAvg
        } else {
            Quantity::E
        })
    }

    fn layout(&self, path: &Path) -> kiln::Result<Layout> {
        // kiln's pictures and lookup code are not tables: say which file is.
        let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let what = match extension {
            "png" => Some("an 8-bit heat map (a picture of the table)"),
            "wgsl" | "glsl" | "hlsl" => Some("shader code that samples the table's texture"),
            _ => None,
        };
        if let (Some(what), None) = (what, &self.shape) {
            let sidecar = path.with_extension("json");
            let stem = path.with_extension("");
            return Err(kiln::Error::InvalidInput(if sidecar.is_file() {
                format!(
                    "{} is {what}, not the table's numbers, which kiln does not read back: \
                     verify the table itself, {} (or its .exr, .bin, .ktx2, .rs or .h)",
                    path.display(),
                    sidecar.display()
                )
            } else {
                format!(
                    "{} is {what} if kiln wrote it, not a table kiln reads: verify the table \
                     it was made from ({}.json, .exr, ...); an engine's PNG table is read with \
                     --preset games202",
                    path.display(),
                    stem.display()
                )
            }));
        }
        let Shape(shape) = self.shape.clone().ok_or_else(|| {
            kiln::Error::InvalidInput(format!(
                "{} is not a kiln table (no kiln metadata in it or a sidecar beside it): give \
                 its layout, at least --shape (e.g. --shape 32x32 --order mu,r for an E table, \
                 --shape 32 for E_avg), or --preset NAME for an engine's file",
                path.display()
            ))
        })?;
        let quantity = self.quantity(&shape);
        let order = self.order.clone().unwrap_or(if quantity.has_mu() {
            vec![AxisName::R, AxisName::Mu]
        } else {
            vec![AxisName::R]
        });
        let fresnel = match (quantity, self.fresnel.given()) {
            (Quantity::EF, true) => {
                let model = self.fresnel.model()?;
                if !model.is_grey() {
                    return Err(kiln::Error::InvalidInput(
                        "--quantity e-f audits one channel: give one value per Fresnel \
                         parameter (that channel's)"
                            .into(),
                    ));
                }
                Some(model)
            }
            (Quantity::EF, false) => {
                return Err(kiln::Error::InvalidInput(
                    "--quantity e-f needs the Fresnel model the table was computed for, e.g. \
                     --f0 0.04 or --ior 1.5"
                        .into(),
                ));
            }
            (_, true) => {
                return Err(kiln::Error::InvalidInput(format!(
                    "the Fresnel flags apply to --quantity e-f only (a {} table is for F = 1)",
                    quantity.symbol()
                )));
            }
            (_, false) => None,
        };
        let mu_mapping = self.mu_axis.unwrap_or(MuMapping::Linear);
        Ok(Layout {
            model: Model {
                ndf: self.ndf.unwrap_or(Ndf::Ggx),
                masking: self.masking.unwrap_or(Masking::HeightCorrelated),
            },
            quantity,
            fresnel,
            shape,
            order,
            grid: self.grid.unwrap_or(Grid::Centers),
            roughness: self
                .roughness_axis
                .unwrap_or(RoughnessConvention::Perceptual),
            mu_mapping,
            roughness_spacing: self
                .roughness_spacing
                .unwrap_or_else(|| kiln::RoughnessSpacing::paired_with(mu_mapping)),
            texels: self.texels.unwrap_or_default(),
        })
    }

    pub fn load(&self, path: &Path) -> kiln::Result<Table> {
        if self.channel.is_none()
            && self.dtype.is_none()
            && let Some(table) = read_kiln(path)?
        {
            let given = self.layout_flags_given();
            if !given.is_empty() {
                return Err(kiln::Error::InvalidInput(format!(
                    "{} is a kiln table and carries its own layout ({} {}, {}); {} describe \
                     external tables and would be ignored: drop {}",
                    path.display(),
                    table.spec.model,
                    table.spec.quantity.symbol(),
                    table
                        .spec
                        .shape()
                        .iter()
                        .map(ToString::to_string)
                        .collect::<Vec<_>>()
                        .join("x"),
                    given.join(", "),
                    if given.len() == 1 { "it" } else { "them" }
                )));
            }
            return Ok(table);
        }
        let is_exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if is_exr && self.channel.is_none() {
            return Err(kiln::Error::InvalidInput(format!(
                "{} is an EXR without kiln's metadata: name the channel to read with --channel \
                 and give the layout (--shape, --order, ...)",
                path.display()
            )));
        }
        let encoding = match (&self.channel, self.dtype) {
            (Some(name), _) => Encoding::ExrChannel(name.clone()),
            (None, Some(dtype)) => Encoding::Raw(dtype),
            (None, None) => Encoding::Text,
        };
        read_external(path, &encoding, &self.layout(path)?)
    }
}

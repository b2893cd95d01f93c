//! Rust source output: `pub const` arrays with doc comments stating the model, axes, grid and
//! measured error, for an engine to `include!`.
//!
//! Values are written as f32 literals (the shortest that round-trip), whatever `--precision`
//! says: Rust has no stable f16 type for constants.

use super::metadata::{KILN_VERSION, Metadata};
use crate::model::RoughnessConvention;
use crate::table::Table;
use crate::table::axis::{
    ADAPTIVE_POWER, ADAPTIVE_SCALE, Axis, Grid, IorMapping, MuMapping, RoughnessSpacing,
};
use crate::table::balanced_layout::BalancedLayout;
use crate::table::glass_layout;
use crate::table::one_ior_layout::OneIorLayout;
use crate::table::split_sum_layout::SplitSumLayout;
use std::fmt::Write as _;

/// The glass layout the `glass` mappings stand for.
const GLASS: glass_layout::GlassLayout = glass_layout::GlassLayout::KILN;

/// On every generated array: a measured value may happen to print like a mathematical constant
/// (`1 - E(1, alpha = 1) = ln 2`), which clippy would flag in the including crate.
const ALLOW: &str = "#[allow(clippy::approx_constant)]";

/// The constant name of a table's values: `GGX_HEIGHT_CORRELATED_E`; every character of the
/// table's name that cannot be in an identifier becomes `_` (`..._E_DIELECTRIC_IOR_1_5` for
/// `...-E_dielectric-ior-1.5`: the dot of a parameter in the name, as in `E_F`'s
/// `-dielectric-1.5`, made the generated Rust, C and shaders fail to compile before).
#[must_use]
pub fn const_prefix(table: &Table) -> String {
    table
        .spec
        .id()
        .to_uppercase()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// The constant name of a table's `1 - value` channel: `GGX_HEIGHT_CORRELATED_E_ONE_MINUS`
/// (the table's name and a suffix, like `_STD_ERROR`; the C header's name too).
#[must_use]
pub fn one_minus_name(table: &Table) -> String {
    format!("{}_ONE_MINUS", const_prefix(table))
}

fn write_array(out: &mut String, values: &[f64], shape: &[usize]) {
    let literal = |v: f64| format!("{:?}", v as f32);
    match shape {
        [n] => {
            out.push('[');
            for (k, &v) in values.iter().enumerate().take(*n) {
                if k % 8 == 0 {
                    out.push_str("\n    ");
                } else {
                    out.push(' ');
                }
                let _ = write!(out, "{},", literal(v));
            }
            out.push_str("\n]");
        }
        [slices, rows, columns] => {
            out.push('[');
            let slice = rows * columns;
            for k in 0..*slices {
                let mut inner = String::new();
                write_array(
                    &mut inner,
                    &values[k * slice..(k + 1) * slice],
                    &[*rows, *columns],
                );
                out.push('\n');
                out.push_str(&inner.replace('\n', "\n    "));
                out.push(',');
            }
            out.push_str("\n]");
        }
        [rows, columns] => {
            out.push('[');
            for r in 0..*rows {
                out.push_str("\n    [");
                for (k, &v) in values[r * columns..(r + 1) * columns].iter().enumerate() {
                    if k % 8 == 0 {
                        out.push_str("\n        ");
                    } else {
                        out.push(' ');
                    }
                    let _ = write!(out, "{},", literal(v));
                }
                out.push_str("\n    ],");
            }
            out.push_str("\n]");
        }
        _ => unreachable!("tables are 1-D, 2-D or 3-D"),
    }
}

/// The generated lookup function's name: `ggx_height_correlated_e_lookup`.
#[must_use]
pub fn lookup_name(table: &Table) -> String {
    format!("{}_lookup", const_prefix(table).to_lowercase())
}

/// Rust for the texture coordinate `t` of one axis, from `mu` or the roughness (`alpha` bound).
fn coordinate_code(axis: &Axis) -> String {
    match *axis {
        Axis::Mu { mapping, size, .. } => match mapping {
            MuMapping::Linear => "mu".to_string(),
            MuMapping::Sqrt => "mu.max(0.0).sqrt()".to_string(),
            MuMapping::Adaptive => format!(
                "if mu <= 0.0 {{\n        0.0\n    }} else {{\n        let k = {ADAPTIVE_SCALE:?} * alpha;\n        \
                 (mu * (1.0 + k) / (mu + k)).min(1.0).powf({ADAPTIVE_POWER:?})\n    }}"
            ),
            MuMapping::Balanced => {
                let l = BalancedLayout::KILN;
                let eps0 = l.offset_at(0.0, size);
                format!(
                    "if mu <= 0.0 {{\n        0.0\n    }} else {{\n        \
                     let k = {:?} * alpha * (1.0 + {:?} * alpha);\n        \
                     let u = if k > 0.0 {{ (mu * (1.0 + k) / (mu + k)).min(1.0) }} else {{ 1.0 }};\n        \
                     let eps = {:?} * (-{:?} * alpha).exp();\n        \
                     let low = eps.powf({p:?});\n        \
                     ((u + eps).powf({p:?}) - low) / ((1.0 + eps).powf({p:?}) - low)\n    }}",
                    l.scale as f32,
                    l.scale_growth as f32,
                    eps0 as f32,
                    l.offset_decay as f32,
                    p = l.power as f32,
                )
            }
            MuMapping::SplitSum => {
                let l = SplitSumLayout::KILN;
                format!(
                    "{{\n        {SATURATION}\n        \
                     {:?} * a(mu, {:?}, {:?}) + {:?} * a(mu, {ADAPTIVE_SCALE:?} * alpha, {ADAPTIVE_POWER:?})\n    }}",
                    l.share as f32,
                    l.scale as f32,
                    l.power as f32,
                    (1.0 - l.share) as f32,
                )
            }
            MuMapping::OneIor => {
                // `critical_share`, `critical_mu` and `top_share` come from the lookup (its one
                // IOR; both shares 0 from outside).
                let l = OneIorLayout::KILN;
                let b = l.base();
                format!(
                    "{{\n        let k = {:?} * alpha * (1.0 + {:?} * alpha);\n        \
                     let u = if mu <= 0.0 {{ 0.0 }} else if k > 0.0 {{ (mu * (1.0 + k) / (mu + k)).min(1.0) }} else {{ 1.0 }};\n        \
                     let eps = {:?} * (-{:?} * alpha).exp();\n        \
                     let low = eps.powf({p:?});\n        \
                     let base = ((u + eps).powf({p:?}) - low) / ((1.0 + eps).powf({p:?}) - low);\n        \
                     let s = {:?} * alpha + {:?};\n        \
                     let at = |x: f32| ((x - critical_mu) / s).atan();\n        \
                     let step = ((at(mu.clamp(0.0, 1.0)) - at(0.0)) / (at(1.0) - at(0.0))).clamp(0.0, 1.0);\n        \
                     let w_t = top_share * alpha.min(1.0) * alpha.min(1.0);\n        \
                     let top_at = |x: f32| ((x - 1.0) / {:?}).atan();\n        \
                     let top = ((top_at(mu.clamp(0.0, 1.0)) - top_at(0.0)) / (top_at(1.0) - top_at(0.0))).clamp(0.0, 1.0);\n        \
                     (1.0 - critical_share - w_t) * base + critical_share * step + w_t * top\n    }}",
                    b.scale as f32,
                    b.scale_growth as f32,
                    b.offset_at(0.0, size) as f32,
                    b.offset_decay as f32,
                    l.critical_scale as f32,
                    l.critical_floor as f32,
                    l.top_width as f32,
                    p = b.power as f32,
                )
            }
            MuMapping::Glass => {
                let share = if GLASS.layer_share_decay > 0.0 {
                    format!(
                        "{:?} / (1.0 + e / ({:?} * alpha * alpha).max(1e-30))",
                        GLASS.layer_share as f32, GLASS.layer_share_decay as f32
                    )
                } else {
                    format!("{:?}", GLASS.layer_share as f32)
                };
                format!(
                    "{{\n        {SATURATION}\n        let e = (eta - 1.0).max(0.0);\n        \
                     let kappa = {:?} * e / (alpha + {:?} * e.sqrt()).max(1e-30);\n        \
                     let w = {share};\n        \
                     w * a(mu, kappa, {:?}) + (1.0 - w) * a(mu, {ADAPTIVE_SCALE:?} * alpha, {ADAPTIVE_POWER:?})\n    }}",
                    GLASS.layer_scale as f32,
                    GLASS.layer_sqrt_weight as f32,
                    GLASS.layer_power as f32,
                )
            }
        },
        Axis::Roughness {
            spacing: RoughnessSpacing::Linear,
            ..
        } => "roughness".to_string(),
        Axis::Roughness {
            spacing: RoughnessSpacing::Balanced,
            convention,
            ..
        } => {
            let l = BalancedLayout::KILN;
            let r = match convention {
                RoughnessConvention::Perceptual => "roughness.clamp(0.0, 1.0)",
                RoughnessConvention::Alpha => "roughness.clamp(0.0, 1.0).sqrt()",
            };
            let p = l.roughness_power_terms();
            // P's numerator as d^2h ((1 + s)^h - 1), s = r^2 / d^2, by ln_1p and exp_m1: the
            // difference of the powers cancels in f32 below r ~ d.
            format!(
                "{{\n        let r = {r};\n        \
                 let rise = ((r * r / {:?}).ln_1p() * {:?}).exp_m1();\n        \
                 {:?} * rise + {:?} * r * r * (3.0 - 2.0 * r)\n    }}",
                p.offset_squared as f32,
                p.half_power as f32,
                ((1.0 - l.roughness_knee) * p.low / p.scale) as f32,
                l.roughness_knee as f32,
            )
        }
        Axis::Ior { mapping, max, .. } => match mapping {
            IorMapping::Linear => format!("(eta - 1.0) / ({:?}_f32 - 1.0)", max.0 as f32),
            IorMapping::Cycles => {
                let z_max = ((max.0 - 1.0) / (max.0 + 1.0)).sqrt();
                format!(
                    "((eta - 1.0) / (eta + 1.0)).max(0.0).sqrt() / {:?}_f32",
                    z_max as f32
                )
            }
            IorMapping::Blender => "((eta - 1.0) / (eta + 1.0)).max(0.0).sqrt()".to_string(),
            IorMapping::Glass => format!(
                "{{\n        {SATURATION}\n        \
                 let x = (((eta - 1.0) / (eta + 1.0)).max(0.0) / {:?}_f32).min(1.0);\n        \
                 {:?} * a(x, {:?} * alpha * alpha, {:?}) + {:?} * x.powf({:?})\n    }}",
                glass_layout::reflectance_root(max.0) as f32,
                GLASS.ior_share as f32,
                GLASS.ior_scale as f32,
                GLASS.ior_power as f32,
                (1.0 - GLASS.ior_share) as f32,
                GLASS.ior_power as f32,
            ),
        },
    }
}

/// The glass layout's `A(y; k, p)` ([`glass_layout::saturation`]) as a local closure.
const SATURATION: &str = "let a = |y: f32, k: f32, p: f32| if y <= 0.0 { 0.0 } else { \
                          (y * (1.0 + k) / (y + k).max(1e-30)).min(1.0).powf(p) };";

/// Each axis with its formula, for the lookups' doc comments.
fn axis_formulas(spec: &crate::table::TableSpec) -> String {
    spec.axes()
        .iter()
        .map(|a| format!("`{}` axis {}", a.name(), a.formula()))
        .collect::<Vec<_>>()
        .join("; ")
}

/// Rust for the continuous sample position of texture coordinate `t` on an axis of `n` samples.
fn position_code(grid: Grid, t: &str, n: usize) -> String {
    let last = n - 1;
    match grid {
        Grid::Nodes => format!("({t} * {last}.0_f32).clamp(0.0, {last}.0)"),
        Grid::Centers => format!("({t} * {n}.0_f32 - 0.5).clamp(0.0, {last}.0)"),
    }
}

/// The generated lookup: the table's axis mapping and grid, bilinear, clamp to edge; the same
/// arithmetic as [`Table::lookup`] in f32.
fn write_lookup(out: &mut String, table: &Table, prefix: &str, ty: &str) {
    let spec = &table.spec;
    if spec.ior.is_some() {
        write_ior_lookup(out, table, prefix, ty);
        return;
    }
    let name = lookup_name(table);
    let roughness_name = spec.roughness_convention().name();
    let alpha = match spec.roughness_convention() {
        RoughnessConvention::Perceptual => "roughness * roughness",
        RoughnessConvention::Alpha => "roughness",
    };
    let n_r = spec.roughness_axis().size();
    // The roughness' texture coordinate: the value itself on a linear spacing.
    let (t_r_line, t_r_name) = match spec.roughness_axis() {
        axis @ Axis::Roughness {
            spacing: RoughnessSpacing::Balanced,
            ..
        } => (
            Some(format!("    let t_r = {};", coordinate_code(&axis))),
            "t_r",
        ),
        _ => (None, "roughness"),
    };
    let _ = writeln!(out);
    let _ = writeln!(
        out,
        "/// Bilinear lookup of [`{prefix}`] (or a table laid out like it: its `ONE_MINUS` and \
         `STD_ERROR`\n/// twins) the way kiln's `Table::lookup` does it, in f32: {}.",
        axis_formulas(spec)
    );
    let _ = writeln!(
        out,
        "/// `roughness` is `{roughness_name}`{}; out-of-range coordinates clamp to the edge.",
        if spec.mu.is_some() {
            ", `mu = cos(theta_o)`"
        } else {
            ""
        }
    );
    let _ = writeln!(out, "#[allow(clippy::all)]");
    let t_r = match spec.refined_start {
        // An f_ms_norm with a refined start: its node line (crate::table::normalisation).
        Some(_) => {
            let line = crate::table::normalisation::NodeLine::of(spec);
            format!(
                "({:?}_f32 * {t_r_name}).min({:?}_f32 * {t_r_name} + {:?}).clamp(0.0, {:?})",
                line.steep, line.shallow, line.offset, line.last
            )
        }
        None => position_code(spec.roughness_axis().grid(), t_r_name, n_r),
    };
    match spec.mu {
        None => {
            let _ = writeln!(out, "pub fn {name}(table: &{ty}, roughness: f32) -> f32 {{");
            if let Some(line) = &t_r_line {
                let _ = writeln!(out, "{line}");
            }
            let _ = writeln!(out, "    let p = {t_r};");
            let _ = writeln!(out, "    let i = (p as usize).min({});", n_r - 2);
            let _ = writeln!(out, "    let f = p - i as f32;");
            if crate::table::normalisation::stores_per_roughness(spec) {
                // (1 - Ē) / x is stored: give back 1 - Ē (crate::table::normalisation).
                let _ = writeln!(
                    out,
                    "    {t_r_name}.clamp(0.0, 1.0) * (table[i] * (1.0 - f) + table[i + 1] * f)"
                );
            } else {
                let _ = writeln!(out, "    table[i] * (1.0 - f) + table[i + 1] * f");
            }
            let _ = writeln!(out, "}}");
        }
        Some(mu_axis) => {
            let n_mu = mu_axis.size();
            let _ = writeln!(
                out,
                "pub fn {name}(table: &{ty}, mu: f32, roughness: f32) -> f32 {{"
            );
            if spec.coordinates_depend_on_roughness() {
                let _ = writeln!(out, "    let alpha = {alpha};");
            }
            if let (
                Some(ior),
                Axis::Mu {
                    mapping: MuMapping::OneIor,
                    ..
                },
            ) = (spec.fixed_ior(), mu_axis)
            {
                // The one-IOR layout's critical angle, from inside only (its share 0 outside).
                let eta = spec.relative_eta(ior);
                let l = OneIorLayout::KILN;
                let _ = writeln!(
                    out,
                    "    let (critical_share, critical_mu, top_share) = ({:?}_f32, {:?}_f32, {:?}_f32);",
                    l.critical_share_at(eta) as f32,
                    OneIorLayout::critical_mu(eta.min(1.0)) as f32,
                    l.top_share_for(eta) as f32
                );
            }
            let _ = writeln!(out, "    let t_mu = {};", coordinate_code(&mu_axis));
            if let Some(line) = &t_r_line {
                let _ = writeln!(out, "{line}");
            }
            let _ = writeln!(out, "    let p_r = {t_r};");
            let _ = writeln!(
                out,
                "    let p_mu = {};",
                position_code(mu_axis.grid(), "t_mu", n_mu)
            );
            let _ = writeln!(
                out,
                "    let (i, j) = ((p_r as usize).min({}), (p_mu as usize).min({}));",
                n_r - 2,
                n_mu - 2
            );
            let _ = writeln!(out, "    let (f, g) = (p_r - i as f32, p_mu - j as f32);");
            write_bilinear(out, "table", "    ");
            let _ = writeln!(out, "}}");
        }
    }
}

/// The generated lookup of a table with an IOR axis (`F_avg`, the dielectric tables): the same
/// blend order as [`Table::lookup_eta`] (fastest axis first), in f32; `eta < 1` (an inside
/// table's relative index) is looked up at `1 / eta`.
fn write_ior_lookup(out: &mut String, table: &Table, prefix: &str, ty: &str) {
    let spec = &table.spec;
    let name = lookup_name(table);
    let ior = spec.ior.expect("an IOR axis");
    let n_eta = ior.size();
    let mut params = Vec::new();
    if spec.mu.is_some() {
        params.push("mu: f32");
    }
    if spec.roughness.is_some() {
        params.push("roughness: f32");
    }
    params.push("eta: f32");
    let _ = writeln!(out);
    let _ = writeln!(
        out,
        "/// Lookup of [`{prefix}`] (or its `ONE_MINUS` and `STD_ERROR` twins) the way kiln's \
         `Table::lookup_eta`\n/// does it, in f32, clamp to edge: {}.",
        axis_formulas(spec)
    );
    let _ = writeln!(
        out,
        "/// `eta` is the index of refraction as listed on the axis (an `eta < 1` is read at \
         `1 / eta`){}.",
        match spec.roughness {
            Some(_) => format!(", `roughness` is `{}`", spec.roughness_convention().name()),
            None => String::new(),
        }
    );
    let _ = writeln!(out, "#[allow(clippy::all)]");
    let _ = writeln!(
        out,
        "pub fn {name}(table: &{ty}, {}) -> f32 {{",
        params.join(", ")
    );
    let _ = writeln!(
        out,
        "    let eta = if eta < 1.0 {{ 1.0 / eta }} else {{ eta }};"
    );
    let alpha = match spec.roughness_convention() {
        RoughnessConvention::Perceptual => "roughness * roughness",
        RoughnessConvention::Alpha => "roughness",
    };
    if spec.coordinates_depend_on_roughness() {
        let _ = writeln!(out, "    let alpha = {alpha};");
    }
    let _ = writeln!(out, "    let t_eta = {};", coordinate_code(&ior));
    let _ = writeln!(
        out,
        "    let p_eta = {};",
        position_code(ior.grid(), "t_eta", n_eta)
    );
    let _ = writeln!(out, "    let k = (p_eta as usize).min({});", n_eta - 2);
    let _ = writeln!(out, "    let h = p_eta - k as f32;");
    match (spec.roughness, spec.mu) {
        (None, _) => {
            let _ = writeln!(out, "    table[k] * (1.0 - h) + table[k + 1] * h");
        }
        (Some(roughness), mu) => {
            let n_r = roughness.size();
            let _ = writeln!(
                out,
                "    let p_r = {};",
                position_code(roughness.grid(), "roughness", n_r)
            );
            let _ = writeln!(out, "    let i = (p_r as usize).min({});", n_r - 2);
            let _ = writeln!(out, "    let f = p_r - i as f32;");
            match mu {
                None => {
                    let _ = writeln!(
                        out,
                        "    let slice = |s: &[f32; {n_r}]| s[i] * (1.0 - f) + s[i + 1] * f;"
                    );
                }
                Some(mu_axis) => {
                    let n_mu = mu_axis.size();
                    let _ = writeln!(out, "    let t_mu = {};", coordinate_code(&mu_axis));
                    let _ = writeln!(
                        out,
                        "    let p_mu = {};",
                        position_code(mu_axis.grid(), "t_mu", n_mu)
                    );
                    let _ = writeln!(out, "    let j = (p_mu as usize).min({});", n_mu - 2);
                    let _ = writeln!(out, "    let g = p_mu - j as f32;");
                    let _ = writeln!(out, "    let slice = |s: &[[f32; {n_mu}]; {n_r}]| {{");
                    write_bilinear(out, "s", "        ");
                    let _ = writeln!(out, "    }};");
                }
            }
            let _ = writeln!(
                out,
                "    slice(&table[k]) * (1.0 - h) + slice(&table[k + 1]) * h"
            );
        }
    }
    let _ = writeln!(out, "}}");
}

/// The bilinear blend of `array[i..=i + 1][j..=j + 1]` with weights `f` (rows) and `g`
/// (columns), `mu` first as in [`Table::lookup`].
fn write_bilinear(out: &mut String, array: &str, indent: &str) {
    let a = array;
    let _ = writeln!(
        out,
        "{indent}let row0 = {a}[i][j] * (1.0 - g) + {a}[i][j + 1] * g;"
    );
    let _ = writeln!(
        out,
        "{indent}let row1 = {a}[i + 1][j] * (1.0 - g) + {a}[i + 1][j + 1] * g;"
    );
    let _ = writeln!(out, "{indent}row0 * (1.0 - f) + row1 * f");
}

fn array_type(shape: &[usize]) -> String {
    match shape {
        [n] => format!("[f32; {n}]"),
        [rows, columns] => format!("[[f32; {columns}]; {rows}]"),
        [slices, rows, columns] => format!("[[[f32; {columns}]; {rows}]; {slices}]"),
        _ => unreachable!("tables are 1-D, 2-D or 3-D"),
    }
}

/// Generates the Rust source for a table.
#[must_use]
pub fn encode(table: &Table) -> String {
    let meta = Metadata::new(table, "f32");
    let prefix = const_prefix(table);
    let shape = table.spec.shape();
    let ty = array_type(&shape);
    let q = &meta.quantity;
    let index = match &meta.axes[..] {
        [e, r, mu] => format!(
            "`{prefix}[{}_index][{}_index][{}_index]`",
            e.name, r.name, mu.name
        ),
        [r, mu] => format!("`{prefix}[{}_index][{}_index]`", r.name, mu.name),
        [r] => format!("`{prefix}[{}_index]`", r.name),
        _ => unreachable!(),
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// Generated by kiln {KILN_VERSION}. Do not edit: regenerate with"
    );
    let _ = writeln!(out, "// `{}`.", super::comment::safe(&meta.command));
    // The metadata in machine form, for `kiln verify`.
    let _ = writeln!(
        out,
        "// {}{}",
        super::metadata::EMBEDDED_PREFIX,
        super::metadata::embedded_json(&meta)
    );
    let _ = writeln!(out);
    let _ = writeln!(
        out,
        "/// {} {}, {} masking, {}: {}.",
        meta.ndf.to_uppercase(),
        q,
        meta.masking,
        meta.fresnel,
        meta.description
    );
    let _ = writeln!(out, "///");
    let _ = writeln!(out, "/// - Indexing: {index}.");
    for axis in &meta.axes {
        let _ = writeln!(
            out,
            "/// - Axis `{}` ({} samples, {} grid): {}; values in `{prefix}_{}`.",
            axis.name,
            axis.size,
            axis.grid.name(),
            axis.formula,
            axis.name.to_uppercase()
        );
    }
    let _ = match meta.spec.method {
        crate::table::Method::Qmc => writeln!(
            out,
            "/// - Measured error: max standard error {:.2e}, rms {:.2e}, from {} samples per \
             texel in {} scrambles.",
            meta.max_std_error, meta.rms_std_error, meta.samples_per_texel, meta.spec.qmc.scrambles
        ),
        crate::table::Method::Reference => writeln!(
            out,
            "/// - Error: at most {:.2e} (the quadrature's own estimate, largest over texels).",
            meta.max_std_error
        ),
    };
    if let (Some(max), Some(texels)) = (meta.node_max_error, meta.node_error_texels) {
        let _ = writeln!(
            out,
            "/// - Against kiln's deterministic reference: max error {max:.2e} over {texels} texels."
        );
    }
    let _ = writeln!(out, "/// - Estimator: {}.", meta.estimator);
    let _ = writeln!(out, "{ALLOW}");
    let _ = write!(out, "pub const {prefix}: {ty} = ");
    write_array(&mut out, &table.value, &shape);
    let _ = writeln!(out, ";\n");
    let _ = writeln!(
        out,
        "/// `1 - {q}` for [`{prefix}`], estimated directly: keeps its relative precision where `{q}`"
    );
    let _ = writeln!(out, "/// is close to 1 (`1.0 - {q}` in f32 would not).");
    let one_minus = one_minus_name(table);
    let _ = writeln!(out, "{ALLOW}");
    let _ = write!(out, "pub const {one_minus}: {ty} = ");
    write_array(&mut out, &table.one_minus_value, &shape);
    let _ = writeln!(out, ";\n");
    let _ = writeln!(out, "/// The standard error of each texel of [`{prefix}`].");
    let _ = writeln!(out, "{ALLOW}");
    let _ = write!(out, "pub const {prefix}_STD_ERROR: {ty} = ");
    write_array(&mut out, &table.std_error, &shape);
    let _ = writeln!(out, ";");
    for (axis, spec_axis) in meta.axes.iter().zip(table.spec.axes()) {
        let _ = writeln!(out);
        let what = match spec_axis {
            Axis::Mu { mapping, .. } if mapping.depends_on_roughness() => {
                "lookup coordinate `t` of each `mu` sample (their `mu` depends on the row)"
                    .to_string()
            }
            _ => format!("`{}` coordinate of each sample", axis.name),
        };
        let _ = writeln!(out, "/// The {what} of [`{prefix}`] ({}).", axis.formula);
        let _ = write!(
            out,
            "pub const {prefix}_{}: [f32; {}] = ",
            axis.name.to_uppercase(),
            axis.size
        );
        write_array(&mut out, &axis.values, &[axis.size]);
        let _ = writeln!(out, ";");
    }
    write_lookup(&mut out, table, &prefix, &ty);
    write_compensation(&mut out, table, &ty);
    out
}

/// Energy compensation beside the lookups (`crate::model::kulla_conty`): for an `f_ms_norm`
/// table the Kulla-Conty lobe normalised by it and the lobe's Fresnel colour; for an `E` table
/// (F = 1) Turquin's factor.
fn write_compensation(out: &mut String, table: &Table, ty: &str) {
    let stem = const_prefix(table).to_lowercase();
    let lookup = lookup_name(table);
    match table.spec.quantity {
        crate::table::Quantity::FMsNorm => {
            let _ = writeln!(
                out,
                "\n/// The Kulla-Conty lobe `f_ms(o, i) = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - Ebar))`, \
                 normalised by this\n/// table (the average of the E table's own lookup): 0 on a \
                 mirror, where `1 - Ebar` is 0.\n#[allow(clippy::all)]\npub fn {stem}_f_ms(table: \
                 &{ty}, one_minus_e_o: f32, one_minus_e_i: f32, roughness: f32) -> f32 {{\n    \
                 let norm = {lookup}(table, roughness);\n    if norm > 1e-30 {{\n        \
                 one_minus_e_o * one_minus_e_i / (core::f32::consts::PI * norm)\n    }} else \
                 {{\n        0.0\n    }}\n}}"
            );
            let _ = writeln!(
                out,
                "\n/// The colour of the lobe for a Fresnel model, per channel: `F_avg^2 E_avg / (1 - \
                 F_avg (1 - E_avg))`\n/// (`E_avg` from the E_avg table).\n#[allow(clippy::all)]\n\
                 pub fn {stem}_fresnel_colour(f_avg: [f32; 3], e_avg: f32) -> [f32; 3] {{\n    \
                 f_avg.map(|f| f * f * e_avg / (1.0 - f * (1.0 - e_avg)).max(1e-30))\n}}"
            );
        }
        crate::table::Quantity::E if table.spec.fresnel.is_none() => {
            let _ = writeln!(
                out,
                "\n/// Turquin's energy compensation: scale single scattering by `1 + F0 (1 / E - 1)`, \
                 `E` from this table.\n#[allow(clippy::all)]\npub fn {stem}_turquin(e: f32, f0: \
                 [f32; 3]) -> [f32; 3] {{\n    f0.map(|f| 1.0 + f * (1.0 / e.max(1e-30) - 1.0))\n}}"
            );
        }
        _ => {}
    }
}

/// kiln's compensation (issue 60, [`crate::table::compensation::CompensationTable`]) as Rust
/// source: its four coefficient arrays over the `E` layout and `M_avg`'s four over the `E_avg`
/// layout, the layouts' bilinear lookups (as for any table laid out like them), and the
/// coefficients' lookup, `M_avg`'s, the basis in `F0`, the albedo `M(mu, F0)` per channel and the
/// lobe `M(mu_o) M(mu_i) / (pi M_avg)`, all in f32. `command` made the table.
#[must_use]
pub fn encode_compensation(
    table: &crate::table::compensation::CompensationTable,
    command: &str,
) -> String {
    use crate::integrate::compensation::KILN_POLE;
    let stem = super::compensation::stem(table);
    let constant = stem.to_uppercase();
    let layout = Table::layout_of(table.spec.clone());
    let average_layout = Table::layout_of(table.average_spec.clone());
    let shape = table.spec.shape();
    let average_shape = table.average_spec.shape();
    let (ty, average_ty) = (array_type(&shape), array_type(&average_shape));
    let mut out = String::new();
    for line in super::compensation::description(table, command) {
        let _ = writeln!(out, "{}", format!("// {line}").trim_end());
    }
    for j in 0..4 {
        let _ = writeln!(
            out,
            "\n/// Coefficient c_{j} at every texel of the E layout ({}).\n{ALLOW}\npub const \
             {constant}_C{j}: {ty} = ",
            axis_formulas(&table.spec)
        );
        write_array(&mut out, &table.coefficients[j], &shape);
        out.push_str(";\n");
    }
    for j in 0..4 {
        let _ = writeln!(
            out,
            "\n/// M_avg's coefficient c_{j} at every roughness of the E_avg layout: the \
             cosine-weighted mean of c_{j}'s lookup.\n{ALLOW}\npub const \
             {constant}_AVERAGE_C{j}: {average_ty} = "
        );
        write_array(&mut out, &table.average[j], &average_shape);
        out.push_str(";\n");
    }
    write_lookup(&mut out, &layout, &format!("{constant}_C0"), &ty);
    write_lookup(
        &mut out,
        &average_layout,
        &format!("{constant}_AVERAGE_C0"),
        &average_ty,
    );
    let (lookup, average_lookup) = (lookup_name(&layout), lookup_name(&average_layout));
    let _ = writeln!(
        out,
        "\n/// The coefficients c_0 .. c_3 at (mu, roughness).\npub fn {stem}_coefficients(mu: \
         f32, roughness: f32) -> [f32; 4] {{\n    [\n{}    ]\n}}",
        (0..4)
            .map(|j| format!("        {lookup}(&{constant}_C{j}, mu, roughness),\n"))
            .collect::<String>()
    );
    let _ = writeln!(
        out,
        "\n/// M_avg's coefficients at roughness.\npub fn {stem}_average(roughness: f32) -> [f32; \
         4] {{\n    [\n{}    ]\n}}",
        (0..4)
            .map(|j| format!("        {average_lookup}(&{constant}_AVERAGE_C{j}, roughness),\n"))
            .collect::<String>()
    );
    let _ = writeln!(
        out,
        "\n/// The basis at F0: (1 - F0)^3, 3 F0 (1 - F0)^2, 3 F0^2 (1 - F0), F0^3, over 1 - \
         {KILN_POLE} F0.\npub fn {stem}_basis(f0: f32) -> [f32; 4] {{\n    let g = 1.0 - f0;\n    \
         let pole = 1.0 - {:?}_f32 * f0;\n    [g * g * g / pole, 3.0 * f0 * g * g / pole, 3.0 * f0 \
         * f0 * g / pole, f0 * f0 * f0 / pole]\n}}",
        KILN_POLE as f32
    );
    let _ = writeln!(
        out,
        "\n/// M(mu, F0) per channel from the coefficients at mu (or M_avg from the average's).\n\
         pub fn {stem}_albedo(c: [f32; 4], f0: [f32; 3]) -> [f32; 3] {{\n    f0.map(|f| {{\n        \
         let b = {stem}_basis(f);\n        c[0] * b[0] + c[1] * b[1] + c[2] * b[2] + c[3] * b[3]\n    \
         }})\n}}"
    );
    let _ = writeln!(
        out,
        "\n/// The lobe f_ms(o, i) = M(mu_o) M(mu_i) / (pi M_avg) per channel, 0 where M_avg is 0.\n\
         pub fn {stem}_lobe(m_o: [f32; 3], m_i: [f32; 3], m_avg: [f32; 3]) -> [f32; 3] {{\n    \
         std::array::from_fn(|k| m_o[k] * m_i[k] / (std::f32::consts::PI * m_avg[k].max(1e-30)))\n}}"
    );
    out
}

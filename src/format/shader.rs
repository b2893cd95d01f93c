//! Shader lookup code for a table, in WGSL, GLSL (4.50) and HLSL (Shader Model 5): the axis
//! mappings and texel convention kiln's [`Table::lookup`] applies, written so that a GPU's
//! bilinear (trilinear for an IOR table) filter with clamp-to-edge returns the same blend.
//!
//! - 2-D and 3-D tables are textures (the `.ktx2` or `.dds` kiln writes, R = value,
//!   G = `1 - value`): `NAME_uv(...)` gives the texture coordinate, `NAME_lookup(...)` samples
//!   it (level 0) and returns both channels. Texture x is the fastest axis (`mu`), y the
//!   roughness (row 0 at `v = 0`, the first row uploaded), z the IOR.
//! - 1-D tables (`E_avg`, `F_avg`) are arrays in the shader (WGSL `var<private>`, a GLSL global,
//!   HLSL `static const`) with their own linear interpolation, usable in any stage.
//!
//! Texel conventions: with `centers`, sample `i` sits at `t_i = (i + 0.5) / N`, where the GPU
//! puts texel centres, so `u = t`; with `nodes`, `t_i = i / (N - 1)`, and the lookup must remap
//! `u = (t (N - 1) + 0.5) / N` (the half-texel remap engines often forget, README).

use super::metadata::{KILN_VERSION, Metadata};
use crate::integrate::compensation::KILN_POLE;
#[cfg(doc)]
use crate::integrate::compensation::KilnCompensation;
use crate::model::RoughnessConvention;
use crate::table::Table;
use crate::table::axis::{
    ADAPTIVE_POWER, ADAPTIVE_SCALE, Axis, Grid, IorMapping, MuMapping, RoughnessSpacing,
};
use crate::table::balanced_layout::BalancedLayout;
use crate::table::compensation::CompensationTable;
use crate::table::glass_layout;
use crate::table::one_ior_layout::OneIorLayout;
use crate::table::split_sum_layout::SplitSumLayout;
use std::fmt::Write as _;

/// The glass layout the `glass` mappings stand for.
const GLASS: glass_layout::GlassLayout = glass_layout::GlassLayout::KILN;

/// A shading language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Language {
    Wgsl,
    Glsl,
    Hlsl,
}

impl Language {
    fn float(self) -> &'static str {
        match self {
            Language::Wgsl => "f32",
            Language::Glsl | Language::Hlsl => "float",
        }
    }

    fn vector(self, n: usize) -> String {
        match self {
            Language::Wgsl => format!("vec{n}<f32>"),
            Language::Glsl => format!("vec{n}"),
            Language::Hlsl => format!("float{n}"),
        }
    }

    /// A local constant: `let x = e;` / `float x = e;`.
    fn local(self, name: &str, value: &str) -> String {
        match self {
            Language::Wgsl => format!("    let {name} = {value};\n"),
            Language::Glsl | Language::Hlsl => format!("    float {name} = {value};\n"),
        }
    }

    /// `cond ? a : b`.
    fn select(self, cond: &str, a: &str, b: &str) -> String {
        match self {
            Language::Wgsl => format!("select({b}, {a}, {cond})"),
            Language::Glsl | Language::Hlsl => format!("(({cond}) ? ({a}) : ({b}))"),
        }
    }

    /// A function header.
    fn function(self, name: &str, params: &[(&str, String)], ret: &str) -> String {
        let list: Vec<String> = params
            .iter()
            .map(|(n, ty)| match self {
                Language::Wgsl => format!("{n}: {ty}"),
                Language::Glsl | Language::Hlsl => format!("{ty} {n}"),
            })
            .collect();
        match self {
            Language::Wgsl => format!("fn {name}({}) -> {ret} {{\n", list.join(", ")),
            Language::Glsl | Language::Hlsl => format!("{ret} {name}({}) {{\n", list.join(", ")),
        }
    }
}

/// A float literal every language accepts.
fn literal(v: f64) -> String {
    let text = format!("{:?}", v as f32);
    if text.contains(['.', 'e', 'E']) {
        text
    } else {
        format!("{text}.0")
    }
}

/// The texture coordinate `t` of an axis from its physical coordinate (`alpha` bound for the
/// adaptive mu mapping).
fn coordinate(language: Language, axis: &Axis) -> String {
    match *axis {
        Axis::Mu { mapping, .. } => match mapping {
            MuMapping::Linear => "mu".to_string(),
            MuMapping::Sqrt => "sqrt(max(mu, 0.0))".to_string(),
            MuMapping::Adaptive => {
                let k = format!("{} * alpha", literal(ADAPTIVE_SCALE));
                let t = format!(
                    "pow(min(mu * (1.0 + {k}) / max(mu + {k}, 1e-30), 1.0), {})",
                    literal(ADAPTIVE_POWER)
                );
                language.select("mu <= 0.0", "0.0", &t)
            }
            // `balanced_k` and `balanced_eps` come from the preamble.
            MuMapping::Balanced => balanced_coordinate(language, BalancedLayout::KILN),
            MuMapping::SplitSum => {
                let l = SplitSumLayout::KILN;
                format!(
                    "{} * {} + {} * {}",
                    literal(l.share),
                    saturation(language, "mu", &literal(l.scale), l.power),
                    literal(1.0 - l.share),
                    saturation(
                        language,
                        "mu",
                        &format!("{} * alpha", literal(ADAPTIVE_SCALE)),
                        ADAPTIVE_POWER
                    )
                )
            }
            MuMapping::OneIor => {
                // `balanced_k`, `balanced_eps`, `critical_share`, `critical_mu`, `critical_s`
                // and `top_share` come from the preamble.
                let base = balanced_coordinate(language, OneIorLayout::KILN.base());
                let at = |x: &str| format!("atan(({x} - critical_mu) / critical_s)");
                let step = format!(
                    "min(max(({} - {}) / ({} - {}), 0.0), 1.0)",
                    at("min(max(mu, 0.0), 1.0)"),
                    at("0.0"),
                    at("1.0"),
                    at("0.0")
                );
                // The step at normal incidence, its share `top_share` (from the preamble).
                let top_at = |x: &str| {
                    format!(
                        "atan(({x} - 1.0) / {})",
                        literal(OneIorLayout::KILN.top_width)
                    )
                };
                let top = format!(
                    "min(max(({} - {}) / ({} - {}), 0.0), 1.0)",
                    top_at("min(max(mu, 0.0), 1.0)"),
                    top_at("0.0"),
                    top_at("1.0"),
                    top_at("0.0")
                );
                format!(
                    "(1.0 - critical_share - top_share) * ({base}) + critical_share * {step} + \
                     top_share * {top}"
                )
            }
            MuMapping::Glass => {
                // `layer_share` and `kappa` come from the preamble.
                format!(
                    "layer_share * {} + (1.0 - layer_share) * {}",
                    saturation(language, "mu", "kappa", GLASS.layer_power),
                    saturation(
                        language,
                        "mu",
                        &format!("{} * alpha", literal(ADAPTIVE_SCALE)),
                        ADAPTIVE_POWER
                    )
                )
            }
        },
        Axis::Roughness {
            spacing: RoughnessSpacing::Linear,
            ..
        } => "roughness".to_string(),
        Axis::Roughness {
            spacing: RoughnessSpacing::Balanced,
            ..
        } => {
            // `rows_r` and `rows_s` come from the preamble.
            let l = BalancedLayout::KILN;
            let p = l.roughness_power_terms();
            // P's numerator (r^2 + d^2)^h - d^2h as d^2h ((1 + s)^h - 1), s = r^2 / d^2: the
            // difference of the powers cancels in f32 below r ~ d (a relative error of 2.4e-5
            // at r = 0.0012, which f_ms_norm's x g(x) inherits), so below s = 0.1 the rise is
            // summed as its binomial series.
            let rise = language.select(
                "rows_s < 0.1",
                &binomial_rise("rows_s", p.half_power),
                &format!("pow(1.0 + rows_s, {}) - 1.0", literal(p.half_power)),
            );
            format!(
                "{} * ({rise}) + {} * rows_r * rows_r * (3.0 - 2.0 * rows_r)",
                literal((1.0 - l.roughness_knee) * p.low / p.scale),
                literal(l.roughness_knee)
            )
        }
        Axis::Ior { mapping, max, .. } => match mapping {
            IorMapping::Linear => format!("(eta_up - 1.0) / {}", literal(max.0 - 1.0)),
            IorMapping::Cycles => {
                let z_max = ((max.0 - 1.0) / (max.0 + 1.0)).sqrt();
                format!(
                    "sqrt(max((eta_up - 1.0) / (eta_up + 1.0), 0.0)) / {}",
                    literal(z_max)
                )
            }
            IorMapping::Blender => "sqrt(max((eta_up - 1.0) / (eta_up + 1.0), 0.0))".to_string(),
            IorMapping::Glass => {
                // `ior_x`, the preamble's x = u(eta) / u(eta_max).
                let x = "ior_x";
                let share = GLASS.ior_share;
                format!(
                    "{} * {} + {} * pow({x}, {})",
                    literal(share),
                    saturation(
                        language,
                        x,
                        &format!("{} * alpha * alpha", literal(GLASS.ior_scale)),
                        GLASS.ior_power
                    ),
                    literal(1.0 - share),
                    literal(GLASS.ior_power)
                )
            }
        },
    }
}

/// `(1 + s)^h - 1` by its binomial series to `s^6`, in Horner form: `h s (1 + (h - 1)/2 s (1 +
/// (h - 2)/3 s (...)))`. For `s < 0.1` the first term left out is below 1e-7 of the sum.
fn binomial_rise(s: &str, h: f64) -> String {
    let mut inner = String::from("1.0");
    for k in (1..6).rev() {
        inner = format!(
            "1.0 + {} * {s} * ({inner})",
            literal((h - f64::from(k)) / f64::from(k + 1))
        );
    }
    format!("{} * {s} * ({inner})", literal(h))
}

/// `A(y; k, p) = (y (1 + k) / (y + k))^p`, 0 at `y <= 0` (1 at `k = 0`, `y > 0`):
/// [`glass_layout::saturation`].
fn saturation(language: Language, y: &str, k: &str, p: f64) -> String {
    let t = format!(
        "pow(min(({y}) * (1.0 + {k}) / max(({y}) + {k}, 1e-30), 1.0), {})",
        literal(p)
    );
    language.select(&format!("({y}) <= 0.0"), "0.0", &t)
}

/// The GPU texture coordinate of texture coordinate `t` on an axis of `n` samples.
fn gpu_coordinate(grid: Grid, t: &str, n: usize) -> String {
    match grid {
        Grid::Centers => t.to_string(),
        Grid::Nodes => format!(
            "(clamp({t}, 0.0, 1.0) * {} + 0.5) / {}",
            literal((n - 1) as f64),
            literal(n as f64)
        ),
    }
}

/// The lookup's parameters, in the order of the Rust lookup: `mu`, `roughness`, `eta`.
fn parameters(language: Language, table: &Table) -> Vec<(&'static str, String)> {
    let mut params = Vec::new();
    let f = language.float().to_string();
    if table.spec.mu.is_some() {
        params.push(("mu", f.clone()));
    }
    if table.spec.roughness.is_some() {
        params.push(("roughness", f.clone()));
    }
    if table.spec.ior.is_some() {
        params.push(("eta", f));
    }
    params
}

/// Lines that define `alpha`, `eta_up` and each axis' `t_*` as the axes need them.
fn preamble(language: Language, table: &Table) -> String {
    let spec = &table.spec;
    let mut out = String::new();
    if spec.coordinates_depend_on_roughness() {
        let alpha = match spec.roughness_convention() {
            RoughnessConvention::Perceptual => "roughness * roughness",
            RoughnessConvention::Alpha => "roughness",
        };
        out += &language.local("alpha", alpha);
    }
    if spec.ior.is_some() {
        out += &language.local("eta_up", &language.select("eta < 1.0", "1.0 / eta", "eta"));
    }
    if let Some(Axis::Roughness {
        spacing: RoughnessSpacing::Balanced,
        convention,
        ..
    }) = spec.roughness
    {
        // Perceptual roughness and s = r^2 / d^2 of the balanced rows' P(r).
        let r = match convention {
            RoughnessConvention::Perceptual => "clamp(roughness, 0.0, 1.0)",
            RoughnessConvention::Alpha => "sqrt(clamp(roughness, 0.0, 1.0))",
        };
        out += &language.local("rows_r", r);
        out += &language.local(
            "rows_s",
            &format!(
                "rows_r * rows_r / {}",
                literal(BalancedLayout::KILN.roughness_power_terms().offset_squared)
            ),
        );
    }
    if let Some(Axis::Ior {
        mapping: IorMapping::Glass,
        max,
        ..
    }) = spec.ior
    {
        // x = u(eta) / u(eta_max), u = (eta - 1) / (eta + 1) (table::glass_layout).
        out += &language.local(
            "ior_x",
            &format!(
                "min(max((eta_up - 1.0) / (eta_up + 1.0), 0.0) / {}, 1.0)",
                literal(glass_layout::reflectance_root(max.0))
            ),
        );
    }
    if let Some(Axis::Mu {
        mapping: MuMapping::Balanced,
        size,
        ..
    }) = spec.mu
    {
        // The balanced layout's scale and grazing offset (BalancedLayout::scale_at, offset_at).
        out += &balanced_locals(language, BalancedLayout::KILN, size);
    }
    if let (
        Some(ior),
        Some(Axis::Mu {
            mapping: MuMapping::OneIor,
            size,
            ..
        }),
    ) = (spec.fixed_ior(), spec.mu)
    {
        // The one-IOR layout's base (balanced, its offset scaled) and critical angle (from
        // inside only: its share is 0 outside), at the table's relative index.
        let l = OneIorLayout::KILN;
        let b = l.base();
        let eta = spec.relative_eta(ior);
        out += &balanced_locals(language, b, size);
        out += &language.local("critical_share", &literal(l.critical_share_at(eta)));
        out += &language.local(
            "top_share",
            &format!(
                "{} * min(alpha, 1.0) * min(alpha, 1.0)",
                literal(l.top_share_for(eta))
            ),
        );
        out += &language.local(
            "critical_mu",
            &literal(OneIorLayout::critical_mu(eta.min(1.0))),
        );
        out += &language.local(
            "critical_s",
            &format!(
                "{} * alpha + {}",
                literal(l.critical_scale),
                literal(l.critical_floor)
            ),
        );
    }
    if matches!(spec.mu, Some(Axis::Mu { mapping, .. }) if mapping.depends_on_ior()) {
        // The eta layer's width (GlassLayout::layer_width).
        out += &language.local(
            "kappa",
            &format!(
                "{} * max(eta_up - 1.0, 0.0) / max(alpha + {} * sqrt(max(eta_up - 1.0, 0.0)), 1e-30)",
                literal(GLASS.layer_scale),
                literal(GLASS.layer_sqrt_weight)
            ),
        );
        // The eta layer's share of the mu coordinate (GlassLayout::layer_share_at).
        let share = if GLASS.layer_share_decay > 0.0 {
            format!(
                "{} / (1.0 + max(eta_up - 1.0, 0.0) / max({} * alpha * alpha, 1e-30))",
                literal(GLASS.layer_share),
                literal(GLASS.layer_share_decay)
            )
        } else {
            literal(GLASS.layer_share)
        };
        out += &language.local("layer_share", &share);
    }
    out
}

/// The balanced coordinate of `mu` for `layout` (`BalancedLayout::mu_coordinate`), from the
/// locals of [`balanced_locals`].
fn balanced_coordinate(language: Language, layout: BalancedLayout) -> String {
    let p = literal(layout.power);
    let u = language.select(
        "mu <= 0.0",
        "0.0",
        "min(mu * (1.0 + balanced_k) / max(mu + balanced_k, 1e-30), 1.0)",
    );
    format!(
        "(pow({u} + balanced_eps, {p}) - pow(balanced_eps, {p})) / (pow(1.0 + balanced_eps, \
         {p}) - pow(balanced_eps, {p}))"
    )
}

/// The balanced coordinate's scale and grazing offset at the lookup's `alpha`
/// (`BalancedLayout::scale_at`, `offset_at`) as the locals `balanced_k` and `balanced_eps`, for
/// `layout` on an axis of `size` samples.
fn balanced_locals(language: Language, layout: BalancedLayout, size: usize) -> String {
    language.local(
        "balanced_k",
        &format!(
            "{} * alpha * (1.0 + {} * alpha)",
            literal(layout.scale),
            literal(layout.scale_growth)
        ),
    ) + &language.local(
        "balanced_eps",
        &format!(
            "{} * exp(-{} * alpha)",
            literal(layout.offset_at(0.0, size)),
            literal(layout.offset_decay)
        ),
    )
}

/// The function name stem: `ggx_height_correlated_e`.
#[must_use]
pub fn name(table: &Table) -> String {
    super::rust::const_prefix(table).to_lowercase()
}

/// Generates the lookup code for a table.
#[must_use]
pub fn encode(table: &Table, language: Language) -> String {
    let meta = Metadata::new(table, "f32");
    let spec = &table.spec;
    let stem = name(table);
    let c = "//"; // every language's line comment
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{c} Generated by kiln {KILN_VERSION}. Do not edit: regenerate with\n{c} `{}`\n{c}",
        super::comment::safe(&meta.command)
    );
    let _ = writeln!(
        out,
        "{c} {} {}, {} masking: {}",
        meta.ndf.to_uppercase(),
        meta.quantity,
        meta.masking,
        meta.description
    );
    for axis in &meta.axes {
        let _ = writeln!(
            out,
            "{c} axis {} ({} samples, {} grid): {}",
            axis.name,
            axis.size,
            axis.grid.name(),
            axis.formula
        );
    }
    let axes = spec.axes();
    let params = parameters(language, table);
    if axes.len() == 1 {
        write_array_lookup(&mut out, language, table, &stem, &params);
        if spec.quantity == crate::table::Quantity::FMsNorm {
            write_lobe(&mut out, language, &stem);
        }
        return out;
    }
    let _ = writeln!(
        out,
        "{c} Texture: the table's .ktx2 or .dds (R = value, G = 1 - value), x = {}, y = {}{}, \
         sampled with a linear filter and clamp-to-edge addressing; row 0 at v = 0.",
        axes[axes.len() - 1].name(),
        axes[axes.len() - 2].name(),
        if axes.len() == 3 {
            format!(", z = {}", axes[0].name())
        } else {
            String::new()
        }
    );
    if language == Language::Wgsl {
        let _ = writeln!(
            out,
            "{c} WebGPU filters the default f32 texture (RG32Float) linearly only with the \
             optional float32-filterable feature;\n{c} kiln bake --precision f16 writes \
             RG16Float, which every adapter filters (1 - value keeps the grazing digits)."
        );
    }
    let dims = axes.len();
    out += &uv_function(language, table, &stem, &params);
    // The sampling function.
    let call_args: Vec<&str> = params.iter().map(|(n, _)| *n).collect();
    let uv = format!("{stem}_uv({})", call_args.join(", "));
    let mut sample_params: Vec<(&str, String)> = Vec::new();
    let body = match language {
        Language::Wgsl => {
            sample_params.push(("table", format!("texture_{dims}d<f32>")));
            sample_params.push(("linear_clamp", "sampler".to_string()));
            format!("    return textureSampleLevel(table, linear_clamp, {uv}, 0.0).rg;\n")
        }
        Language::Glsl => {
            // OpenGL's combined sampler; Vulkan GLSL (define KILN_NO_COMBINED_SAMPLERS) samples
            // `sampler2D(texture, sampler)` at `NAME_uv` itself.
            out.push_str("#ifndef KILN_NO_COMBINED_SAMPLERS\n");
            sample_params.push(("table", format!("sampler{dims}D")));
            format!("    return textureLod(table, {uv}, 0.0).rg;\n}}\n#endif\n")
        }
        Language::Hlsl => {
            sample_params.push(("table", format!("Texture{dims}D<float2>")));
            sample_params.push(("linear_clamp", "SamplerState".to_string()));
            format!("    return table.SampleLevel(linear_clamp, {uv}, 0).rg;\n")
        }
    };
    sample_params.extend(params.iter().cloned());
    let _ = writeln!(
        out,
        "{c} Returns (value, 1 - value); use .y near 1 in half precision."
    );
    out += &language.function(
        &format!("{stem}_lookup"),
        &sample_params,
        &language.vector(2),
    );
    out += &body;
    if language != Language::Glsl {
        out += "}\n";
    }
    if spec.quantity == crate::table::Quantity::E && spec.fresnel.is_none() {
        write_turquin(&mut out, language, &stem);
    }
    out
}

/// The texture coordinate function `STEM_uv(...)` of a 2-D or 3-D table: fastest axis first
/// (x, y, z).
fn uv_function(
    language: Language,
    table: &Table,
    stem: &str,
    params: &[(&'static str, String)],
) -> String {
    let axes = table.spec.axes();
    let dims = axes.len();
    let mut out = language.function(&format!("{stem}_uv"), params, &language.vector(dims));
    out += &preamble(language, table);
    let mut components = Vec::new();
    for (k, axis) in axes.iter().rev().enumerate() {
        let t = format!("t{k}");
        out += &language.local(&t, &coordinate(language, axis));
        components.push(gpu_coordinate(axis.grid(), &t, axis.size()));
    }
    let _ = writeln!(
        out,
        "    return {}({});\n}}\n",
        language.vector(dims),
        components.join(", ")
    );
    out
}

/// kiln's compensation (issue 60, [`CompensationTable`]) as shader code: the texture
/// coordinate of its RGBA texture (the `E` layout's, as the `E` table's `_uv`), the coefficients' lookup,
/// `M_avg`'s coefficients as arrays with their interpolation over the roughness, the basis in
/// `F0` ([`KilnCompensation::basis`]), the albedo `M(mu, F0)` per channel and the lobe
/// `M(mu_o) M(mu_i) / (pi M_avg)` ([`crate::table::compensation`]). `command` made the table.
#[must_use]
pub fn encode_compensation(table: &CompensationTable, language: Language, command: &str) -> String {
    let stem = super::compensation::stem(table);
    let layout = Table::layout_of(table.spec.clone());
    let f = language.float();
    let v3 = language.vector(3);
    let v4 = language.vector(4);
    let mut out = String::new();
    for line in super::compensation::description(table, command) {
        let _ = writeln!(out, "{}", format!("// {line}").trim_end());
    }
    let meta = Metadata::new(&layout, "f32");
    for axis in &meta.axes {
        let _ = writeln!(
            out,
            "// axis {} ({} samples, {} grid): {}",
            axis.name,
            axis.size,
            axis.grid.name(),
            axis.formula
        );
    }
    let _ = writeln!(
        out,
        "// Texture: the .ktx2 or .dds beside this file (RGBA = c_0 .. c_3), x = mu, y = \
         roughness, sampled with a\n// linear filter and clamp-to-edge addressing; row 0 at \
         v = 0."
    );
    let params = parameters(language, &layout);
    out += &uv_function(language, &layout, &stem, &params);
    let uv = format!("{stem}_uv(mu, roughness)");
    let mut sample_params: Vec<(&str, String)> = Vec::new();
    let body = match language {
        Language::Wgsl => {
            sample_params.push(("table", "texture_2d<f32>".to_string()));
            sample_params.push(("linear_clamp", "sampler".to_string()));
            format!("    return textureSampleLevel(table, linear_clamp, {uv}, 0.0);\n}}\n")
        }
        Language::Glsl => {
            out.push_str("#ifndef KILN_NO_COMBINED_SAMPLERS\n");
            sample_params.push(("table", "sampler2D".to_string()));
            format!("    return textureLod(table, {uv}, 0.0);\n}}\n#endif\n")
        }
        Language::Hlsl => {
            sample_params.push(("table", "Texture2D<float4>".to_string()));
            sample_params.push(("linear_clamp", "SamplerState".to_string()));
            format!("    return table.SampleLevel(linear_clamp, {uv}, 0);\n}}\n")
        }
    };
    sample_params.extend(params.iter().cloned());
    let _ = writeln!(out, "// The coefficients c_0 .. c_3 at (mu, roughness).");
    out += &language.function(&format!("{stem}_coefficients"), &sample_params, &v4);
    out += &body;
    // M_avg's coefficients: four arrays over the roughness, and their lookup together.
    let average_layout = Table::layout_of(table.average_spec.clone());
    let average_params = parameters(language, &average_layout);
    for (j, values) in table.average.iter().enumerate() {
        let channel = Table {
            value: values.clone(),
            ..average_layout.clone()
        };
        write_array_lookup(
            &mut out,
            language,
            &channel,
            &format!("{stem}_average_c{j}"),
            &average_params,
        );
    }
    let _ = writeln!(
        out,
        "// M_avg's coefficients at roughness: the cosine-weighted mean over mu of the \
         texture's own lookup."
    );
    out += &language.function(&format!("{stem}_average"), &average_params, &v4);
    let calls: Vec<String> = (0..4)
        .map(|j| format!("{stem}_average_c{j}_lookup(roughness)"))
        .collect();
    let _ = writeln!(out, "    return {v4}({});\n}}", calls.join(", "));
    // The basis, the albedo and the lobe.
    let _ = writeln!(
        out,
        "\n// The basis at F0: (1 - F0)^3, 3 F0 (1 - F0)^2, 3 F0^2 (1 - F0), F0^3, over 1 - {} \
         F0.",
        KILN_POLE
    );
    out += &language.function(&format!("{stem}_basis"), &[("f0", f.to_string())], &v4);
    out += &language.local("g", "1.0 - f0");
    let _ = writeln!(
        out,
        "    return {v4}(g * g * g, 3.0 * f0 * g * g, 3.0 * f0 * f0 * g, f0 * f0 * f0) / (1.0 - \
         {} * f0);\n}}",
        literal(KILN_POLE)
    );
    let _ = writeln!(
        out,
        "\n// M(mu, F0) per channel from the coefficients at mu (or M_avg from the average's)."
    );
    out += &language.function(
        &format!("{stem}_albedo"),
        &[("c", v4.clone()), ("f0", v3.clone())],
        &v3,
    );
    let _ = writeln!(
        out,
        "    return {v3}(dot(c, {stem}_basis(f0.x)), dot(c, {stem}_basis(f0.y)), dot(c, \
         {stem}_basis(f0.z)));\n}}"
    );
    let _ = writeln!(
        out,
        "\n// The lobe f_ms(o, i) = M(mu_o) M(mu_i) / (pi M_avg) per channel, 0 where M_avg is 0 \
         (a mirror loses nothing)."
    );
    out += &language.function(
        &format!("{stem}_lobe"),
        &[
            ("m_o", v3.clone()),
            ("m_i", v3.clone()),
            ("m_avg", v3.clone()),
        ],
        &v3,
    );
    let _ = writeln!(
        out,
        "    return m_o * m_i / (3.14159265 * max(m_avg, {v3}(1e-30, 1e-30, 1e-30)));\n}}"
    );
    out
}

/// The Kulla-Conty lobe and its Fresnel colour term, beside an `f_ms_norm` lookup
/// (`crate::model::kulla_conty`): `NAME_f_ms(1 - E(mu_o), 1 - E(mu_i), roughness)` normalised
/// by this table's `1 - Ē` (0 where that is 0: a mirror loses nothing), and
/// `NAME_fresnel_colour(F_avg, E_avg)` = `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))` per channel.
fn write_lobe(out: &mut String, language: Language, stem: &str) {
    let f = language.float();
    let v3 = language.vector(3);
    let _ = writeln!(
        out,
        "\n// The Kulla-Conty lobe f_ms(o, i) = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - Ebar)), \
         normalised by this table\n// (the average of the E table's own lookup), 0 on a mirror."
    );
    let params = [
        ("one_minus_e_o", f.to_string()),
        ("one_minus_e_i", f.to_string()),
        ("roughness", f.to_string()),
    ];
    *out += &language.function(&format!("{stem}_f_ms"), &params, f);
    *out += &language.local("norm", &format!("{stem}_lookup(roughness)"));
    let _ = writeln!(
        out,
        "    return {};\n}}",
        language.select(
            "norm > 1e-30",
            "one_minus_e_o * one_minus_e_i / (3.14159265 * norm)",
            "0.0"
        )
    );
    let _ = writeln!(
        out,
        "\n// The colour of the lobe for a Fresnel model: F_avg^2 E_avg / (1 - F_avg (1 - E_avg)) \
         per channel\n// (E_avg from the E_avg table, F_avg per channel)."
    );
    let params = [("f_avg", v3.clone()), ("e_avg", f.to_string())];
    *out += &language.function(&format!("{stem}_fresnel_colour"), &params, &v3);
    let _ = writeln!(
        out,
        "    return f_avg * f_avg * e_avg / max({v3}(1.0, 1.0, 1.0) - f_avg * (1.0 - e_avg), \
         {v3}(1e-30, 1e-30, 1e-30));\n}}"
    );
}

/// Turquin's compensation factor beside an `E` lookup: single scattering times
/// `1 + F0 (1 / E - 1)` (Turquin 2019; Fdez-Aguera 2019 for the split-sum form).
fn write_turquin(out: &mut String, language: Language, stem: &str) {
    let f = language.float();
    let v3 = language.vector(3);
    let _ = writeln!(
        out,
        "\n// Turquin's energy compensation: scale single scattering by 1 + F0 (1 / E - 1), E \
         from this table."
    );
    let params = [("e", f.to_string()), ("f0", v3.clone())];
    *out += &language.function(&format!("{stem}_turquin"), &params, &v3);
    let _ = writeln!(
        out,
        "    return {v3}(1.0, 1.0, 1.0) + f0 * (1.0 / max(e, 1e-30) - 1.0);\n}}"
    );
}

/// A 1-D table as a constant array with its linear interpolation (no texture).
fn write_array_lookup(
    out: &mut String,
    language: Language,
    table: &Table,
    stem: &str,
    params: &[(&'static str, String)],
) {
    let axis = table.spec.axes()[0];
    let n = axis.size();
    let values: Vec<String> = table.value.iter().map(|&v| literal(v)).collect();
    let constant = stem.to_uppercase();
    let list = values.join(", ");
    // WGSL and GLSL: a private (per-invocation, never written) array rather than a `const`, which
    // naga (wgpu's compiler) copies into a local at every dynamic index: on Mesa's lavapipe a
    // compute pipeline over the 497-value f_ms_norm then took 7.1-8.6 s (WGSL) and 24-27 s
    // (GLSL) to build, 4.4-5.6 s as a private array (tests/gpu_shaders.rs, 2026-12-03).
    let _ = match language {
        Language::Wgsl => writeln!(
            out,
            "var<private> {constant}: array<f32, {n}> = array<f32, {n}>({list});"
        ),
        Language::Glsl => writeln!(out, "float {constant}[{n}] = float[{n}]({list});"),
        Language::Hlsl => writeln!(out, "static const float {constant}[{n}] = {{ {list} }};"),
    };
    *out += &language.function(&format!("{stem}_lookup"), params, language.float());
    *out += &preamble(language, table);
    *out += &language.local("t", &coordinate(language, &axis));
    let last = literal((n - 1) as f64);
    let position = match (axis.grid(), table.spec.refined_start) {
        // An f_ms_norm with a refined start: its node line (crate::table::normalisation).
        (_, Some(_)) => {
            let line = crate::table::normalisation::NodeLine::of(&table.spec);
            format!(
                "clamp(min({} * t, {} * t + {}), 0.0, {last})",
                literal(line.steep),
                literal(line.shallow),
                literal(line.offset)
            )
        }
        (Grid::Nodes, None) => format!("clamp(t * {last}, 0.0, {last})"),
        (Grid::Centers, None) => format!("clamp(t * {} - 0.5, 0.0, {last})", literal(n as f64)),
    };
    *out += &language.local("p", &position);
    let int = match language {
        Language::Wgsl => "i32",
        Language::Glsl | Language::Hlsl => "int",
    };
    let i_value = format!("min({int}(floor(p)), {})", n - 2);
    let scale = array_scale(table);
    match language {
        Language::Wgsl => {
            let _ = writeln!(out, "    let i = {i_value};");
            let _ = writeln!(out, "    let f = p - f32(i);");
        }
        Language::Glsl | Language::Hlsl => {
            let _ = writeln!(out, "    {int} i = {i_value};");
            let _ = writeln!(out, "    float f = p - float(i);");
        }
    }
    let _ = writeln!(
        out,
        "    return {scale}({constant}[i] * (1.0 - f) + {constant}[i + 1] * f);\n}}"
    );
}

/// What the interpolated value of a 1-D table is multiplied by: the roughness coordinate for an
/// `f_ms_norm` that stores `(1 - Ē) / r` ([`crate::table::normalisation`]), nothing otherwise.
fn array_scale(table: &Table) -> &'static str {
    if crate::table::normalisation::stores_per_roughness(&table.spec) {
        "clamp(t, 0.0, 1.0) * "
    } else {
        ""
    }
}

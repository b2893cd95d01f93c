//! A polynomial fit ([`super::polynomial`]) as text: a formula file kiln audits
//! (`kiln verify --fit FILE.toml`) and functions in WGSL, GLSL, HLSL, Rust and C that compute
//! the same formula in f32.

use super::polynomial::PolynomialFit;

/// The languages a fit is written in, with their file extensions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum FitFormat {
    /// The formula file (`kiln verify --fit` reads it).
    Toml,
    Wgsl,
    Glsl,
    Hlsl,
    /// Rust source.
    Rs,
    /// A C header.
    H,
}

impl FitFormat {
    pub const ALL: [FitFormat; 6] = [
        FitFormat::Toml,
        FitFormat::Wgsl,
        FitFormat::Glsl,
        FitFormat::Hlsl,
        FitFormat::Rs,
        FitFormat::H,
    ];

    /// The file extension.
    #[must_use]
    pub fn extension(self) -> &'static str {
        match self {
            FitFormat::Toml => "toml",
            FitFormat::Wgsl => "wgsl",
            FitFormat::Glsl => "glsl",
            FitFormat::Hlsl => "hlsl",
            FitFormat::Rs => "rs",
            FitFormat::H => "h",
        }
    }
}

/// The file stem and function name: `ggx_height_correlated_e_fit_t5_r4`.
#[must_use]
pub fn function_name(fit: &PolynomialFit) -> String {
    format!(
        "{}_{}_e_fit_t{}_r{}",
        fit.model.ndf,
        fit.model.masking.name().replace('-', "_"),
        fit.degrees.t,
        fit.degrees.r
    )
}

/// What every emitted file says of the fit: what it approximates, in which coordinates, and
/// its audited maximum error with the command that reproduces it.
#[must_use]
pub fn description(fit: &PolynomialFit, max_error: f64, command: &str) -> String {
    format!(
        "E of {} (F = 1) as a polynomial of degree {} in u = 2 t - 1 and {} in v = 2 r - 1 \
         ({} coefficients), t = (mu (1 + 4 alpha) / (mu + 4 alpha))^0.4, alpha = r^2 (kiln's \
         adaptive axis); max error {max_error:.2e} over mu in [0, 1], r in [0, 1] against kiln's \
         reference (kiln verify --fit); made by `{command}`",
        fit.model,
        fit.degrees.t,
        fit.degrees.r,
        fit.degrees.coefficients()
    )
}

/// One language's spelling of the statements a fit needs.
struct Syntax {
    /// The signature with `{name}` and `{params}` to fill.
    signature: &'static str,
    params: &'static str,
    /// `let` of an immutable f32, a mutable one.
    constant: &'static str,
    variable: &'static str,
    /// The adaptive `t` of `mu` given `k = 4 alpha`.
    t: &'static str,
    comment: &'static str,
    close: &'static str,
    /// How a number is written.
    number: fn(f64) -> String,
}

/// Shading languages need a decimal point or an exponent; `{:e}` always gives one.
fn shader_number(c: f64) -> String {
    format!("{:e}", c as f32)
}

fn c_number(c: f64) -> String {
    format!("{:e}f", c as f32)
}

fn rust_number(c: f64) -> String {
    format!("{:e}_f32", c as f32)
}

const WGSL: Syntax = Syntax {
    signature: "fn {name}({params}) -> f32 {",
    params: "mu: f32, r: f32",
    constant: "let",
    variable: "var",
    t: "pow(min(mu * (1.0 + k) / max(mu + k, 1e-30), 1.0), 0.4)",
    comment: "//",
    close: "}",
    number: shader_number,
};

const GLSL: Syntax = Syntax {
    signature: "float {name}({params}) {",
    params: "float mu, float r",
    constant: "float",
    variable: "float",
    t: "pow(min(mu * (1.0 + k) / max(mu + k, 1e-30), 1.0), 0.4)",
    comment: "//",
    close: "}",
    number: shader_number,
};

const RUST: Syntax = Syntax {
    signature: "pub fn {name}({params}) -> f32 {",
    params: "mu: f32, r: f32",
    constant: "let",
    variable: "let mut",
    t: "(mu * (1.0 + k) / (mu + k).max(1e-30)).min(1.0).powf(0.4)",
    comment: "//",
    close: "}",
    number: rust_number,
};

const C: Syntax = Syntax {
    signature: "static inline float {name}({params}) {",
    params: "float mu, float r",
    constant: "const float",
    variable: "float",
    t: "powf(fminf(mu * (1.0f + k) / fmaxf(mu + k, 1e-30f), 1.0f), 0.4f)",
    comment: "//",
    close: "}",
    number: c_number,
};

/// `c_0 + v (c_1 + v (...))` of one row of coefficients.
fn horner(coefficients: &[f64], variable: &str, number: fn(f64) -> String) -> String {
    let mut out = String::new();
    for (k, &c) in coefficients.iter().enumerate() {
        if k > 0 {
            out += &format!(" + {variable} * (");
        }
        out += &number(c);
    }
    out + &")".repeat(coefficients.len().saturating_sub(1))
}

fn code(fit: &PolynomialFit, syntax: &Syntax, header: &str, text: &str) -> String {
    let name = function_name(fit);
    let number = syntax.number;
    let nr = fit.degrees.r + 1;
    let rows: Vec<&[f64]> = fit.coefficients.chunks(nr).collect();
    let mut out = String::new();
    for line in text.split(". ") {
        out += &format!("{} {line}\n", syntax.comment);
    }
    out += header;
    out += &syntax
        .signature
        .replace("{name}", &name)
        .replace("{params}", syntax.params);
    out += "\n";
    let c = syntax.constant;
    let one = number(1.0);
    let two = number(2.0);
    out += &format!("    {c} k = {} * r * r;\n", number(4.0));
    out += &format!("    {c} t = {};\n", syntax.t);
    out += &format!("    {c} u = {two} * t - {one};\n");
    out += &format!("    {c} v = {two} * r - {one};\n");
    let last = rows.len() - 1;
    out += &format!(
        "    {} e = {};\n",
        syntax.variable,
        horner(rows[last], "v", number)
    );
    for row in rows[..last].iter().rev() {
        out += &format!("    e = e * u + {};\n", horner(row, "v", number));
    }
    out += "    return e;\n";
    out += syntax.close;
    out += "\n";
    out
}

/// The fit in `format`; `description` (from [`description`]) heads the file.
#[must_use]
pub fn emit(fit: &PolynomialFit, format: FitFormat, description: &str) -> String {
    match format {
        FitFormat::Toml => formula_file(fit, description),
        FitFormat::Wgsl => code(fit, &WGSL, "", description),
        FitFormat::Glsl | FitFormat::Hlsl => {
            // HLSL spells GLSL's float functions the same way (pow, min, max); its `float` is
            // the same type.
            code(fit, &GLSL, "", description)
        }
        FitFormat::Rs => code(fit, &RUST, "#[allow(clippy::all)]\n", description),
        FitFormat::H => code(fit, &C, "#pragma once\n#include <math.h>\n", description),
    }
}

/// The formula file: the same polynomial in kiln's formula language ([`super::formula`]),
/// coefficients with every digit of their f64 value.
fn formula_file(fit: &PolynomialFit, description: &str) -> String {
    let number = |c: f64| format!("{c:?}");
    let nr = fit.degrees.r + 1;
    let rows: Vec<&[f64]> = fit.coefficients.chunks(nr).collect();
    let mut defines = vec![
        "k = 4 * alpha".to_string(),
        "t = pow(min(mu * (1 + k) / max(mu + k, 1e-30), 1), 0.4)".to_string(),
        "u = 2 * t - 1".to_string(),
        "v = 2 * r - 1".to_string(),
    ];
    for (i, row) in rows.iter().enumerate() {
        defines.push(format!("p{i} = {}", horner(row, "v", number)));
    }
    let mut e = format!("p{}", rows.len() - 1);
    for i in (0..rows.len() - 1).rev() {
        e = format!("p{i} + u * ({e})");
    }
    let mut out = format!("# {description}\n");
    out += &format!("name = \"{}\"\n", function_name(fit));
    out += &format!(
        "source = \"kiln fit: {} coefficients, degrees {} in u and {} in v\"\n",
        fit.degrees.coefficients(),
        fit.degrees.t,
        fit.degrees.r
    );
    out += "define = [\n";
    for d in &defines {
        out += &format!("  \"{d}\",\n");
    }
    out += "]\n";
    out += &format!("E = \"{e}\"\n");
    out
}

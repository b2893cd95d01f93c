//! A fit kiln made ([`super::polynomial`], [`super::rational`]) as text: a formula file kiln
//! audits (`kiln verify-fit FILE.toml`) and functions in WGSL, GLSL, HLSL, Rust and C that
//! compute the same formula in f32.

use super::polynomial::PolynomialFit;
use super::rational::{R_POWER, RationalFit, T_POWER};

/// The languages a fit is written in, with their file extensions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum FitFormat {
    /// The formula file (`kiln verify-fit` reads it).
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

/// What a fit kiln made says of itself in the files it is written to.
pub trait FitText {
    /// The file stem and function name: `ggx_height_correlated_e_fit_t5_r4`.
    fn function_name(&self) -> String;
    /// What the fit is, in which coordinates, with its audited maximum error and the command
    /// that made it.
    fn description(&self, max_error: f64, command: &str) -> String;
    /// The function's body in `syntax`, after its signature.
    fn body(&self, syntax: &Syntax) -> String;
    /// The formula file's `source`, `define` lines and `E`.
    fn formula(&self) -> (String, Vec<String>, String);
}

fn model_stem(model: crate::model::Model) -> String {
    format!("{}_{}", model.ndf, model.masking.name().replace('-', "_"))
}

impl FitText for PolynomialFit {
    fn function_name(&self) -> String {
        format!(
            "{}_e_fit_t{}_r{}",
            model_stem(self.model),
            self.degrees.t,
            self.degrees.r
        )
    }

    fn description(&self, max_error: f64, command: &str) -> String {
        format!(
            "E of {} (F = 1) as a polynomial of degree {} in u = 2 t - 1 and {} in v = 2 r - 1 \
             ({} coefficients), t = (mu (1 + 4 alpha) / (mu + 4 alpha))^0.4, alpha = r^2 \
             (kiln's adaptive axis); max error {max_error:.2e} over mu in [0, 1], r in [0, 1] \
             against kiln's reference (kiln verify-fit); made by `{command}`",
            self.model,
            self.degrees.t,
            self.degrees.r,
            self.degrees.coefficients()
        )
    }

    fn body(&self, syntax: &Syntax) -> String {
        let number = syntax.number;
        let c = syntax.constant;
        let (one, two) = (number(1.0), number(2.0));
        let mut out = format!("    {c} k = {} * r * r;\n", number(4.0));
        out += &format!("    {c} t = {};\n", syntax.t.replace("{p}", "0.4"));
        out += &format!("    {c} u = {two} * t - {one};\n");
        out += &format!("    {c} v = {two} * r - {one};\n");
        out += &polynomial_lines(syntax, "e", &self.coefficients, self.degrees.r + 1, "v");
        out + "    return e;\n"
    }

    fn formula(&self) -> (String, Vec<String>, String) {
        let number = |c: f64| format!("{c:?}");
        let nr = self.degrees.r + 1;
        let rows: Vec<&[f64]> = self.coefficients.chunks(nr).collect();
        let mut defines = vec![
            "k = 4 * alpha".to_string(),
            "t = pow(min(mu * (1 + k) / max(mu + k, 1e-30), 1), 0.4)".to_string(),
            "u = 2 * t - 1".to_string(),
            "v = 2 * r - 1".to_string(),
        ];
        for (i, row) in rows.iter().enumerate() {
            defines.push(format!("p{i} = {}", horner(row, "v", number)));
        }
        let source = format!(
            "kiln fit: {} coefficients, degrees {} in u and {} in v",
            self.degrees.coefficients(),
            self.degrees.t,
            self.degrees.r
        );
        (source, defines, nested("p", rows.len()))
    }
}

impl FitText for RationalFit {
    fn function_name(&self) -> String {
        let (p, q) = (self.shape.numerator, self.shape.denominator);
        format!(
            "{}_e_fit_p{}{}{}_q{}_{}",
            model_stem(self.model),
            p.t,
            if self.shape.additive { "_plus_" } else { "_" },
            p.r,
            q.t,
            q.r
        )
    }

    fn description(&self, max_error: f64, command: &str) -> String {
        let (p, q) = (self.shape.numerator, self.shape.denominator);
        format!(
            "E of {} (F = 1) as the rational 1 - t^2 P(u, s) / Q(u, s), P {}of degree {} in \
             u = 2 t - 1 and {} in s = 2 r^{R_POWER} - 1, Q of degrees {} and {} with constant \
             term 1 ({} coefficients), t = (mu (1 + alpha) / (mu + alpha))^{T_POWER}, \
             alpha = r^2; max error {max_error:.2e} over mu in [0, 1], r in \
             [0, 1] against kiln's reference (kiln verify-fit); made by `{command}`",
            self.model,
            if self.shape.additive {
                "= A(u) + B(s) (no cross terms) "
            } else {
                ""
            },
            p.t,
            p.r,
            q.t,
            q.r,
            self.shape.coefficients()
        )
    }

    fn body(&self, syntax: &Syntax) -> String {
        let number = syntax.number;
        let c = syntax.constant;
        let (one, two) = (number(1.0), number(2.0));
        let mut out = format!("    {c} k = r * r;\n");
        out += &format!(
            "    {c} t = {};\n",
            syntax.t.replace("{p}", &format!("{T_POWER:?}"))
        );
        out += &format!("    {c} u = {two} * t - {one};\n");
        out += &format!(
            "    {c} s = {two} * {} - {one};\n",
            syntax.power_of_r.replace("{p}", &format!("{R_POWER:?}"))
        );
        let (p, q) = (self.shape.numerator, self.shape.denominator);
        out += &polynomial_lines(syntax, "n", &self.numerator, p.r + 1, "s");
        out += &polynomial_lines(syntax, "d", &self.denominator, q.r + 1, "s");
        out + &format!("    return {one} - t * t * n / d;\n")
    }

    fn formula(&self) -> (String, Vec<String>, String) {
        let number = |c: f64| format!("{c:?}");
        let mut defines = vec![
            "k = alpha".to_string(),
            format!("t = pow(min(mu * (1 + k) / max(mu + k, 1e-30), 1), {T_POWER:?})"),
            "u = 2 * t - 1".to_string(),
            format!("s = 2 * pow(r, {R_POWER:?}) - 1"),
        ];
        let (p, q) = (self.shape.numerator, self.shape.denominator);
        let numerator: Vec<&[f64]> = self.numerator.chunks(p.r + 1).collect();
        let denominator: Vec<&[f64]> = self.denominator.chunks(q.r + 1).collect();
        for (i, row) in numerator.iter().enumerate() {
            defines.push(format!("n{i} = {}", horner(row, "s", number)));
        }
        for (i, row) in denominator.iter().enumerate() {
            defines.push(format!("d{i} = {}", horner(row, "s", number)));
        }
        defines.push(format!("n = {}", nested("n", numerator.len())));
        defines.push(format!("d = {}", nested("d", denominator.len())));
        let source = format!(
            "kiln fit: {} coefficients, P {}of degrees {} in u and {} in s, Q of degrees {} and {}",
            self.shape.coefficients(),
            if self.shape.additive {
                "= A(u) + B(s) "
            } else {
                ""
            },
            p.t,
            p.r,
            q.t,
            q.r
        );
        (source, defines, "1 - t * t * n / d".to_string())
    }
}

/// `{name}0 + u * ({name}1 + u * (...))` of `rows` named rows.
fn nested(name: &str, rows: usize) -> String {
    let mut e = format!("{name}{}", rows - 1);
    for i in (0..rows - 1).rev() {
        e = format!("{name}{i} + u * ({e})");
    }
    e
}

/// `variable` as a polynomial in `u` (outer) and `inner` by Horner's rule, rows of `width`
/// coefficients, one statement per row.
fn polynomial_lines(
    syntax: &Syntax,
    variable: &str,
    coefficients: &[f64],
    width: usize,
    inner: &str,
) -> String {
    let number = syntax.number;
    let rows: Vec<&[f64]> = coefficients.chunks(width).collect();
    let last = rows.len() - 1;
    let mut out = format!(
        "    {} {variable} = {};\n",
        syntax.variable,
        horner(rows[last], inner, number)
    );
    for row in rows[..last].iter().rev() {
        out += &format!(
            "    {variable} = {variable} * u + {};\n",
            horner(row, inner, number)
        );
    }
    out
}

/// One language's spelling of the statements a fit needs.
pub struct Syntax {
    /// The signature with `{name}` and `{params}` to fill.
    signature: &'static str,
    params: &'static str,
    /// `let` of an immutable f32, a mutable one.
    constant: &'static str,
    variable: &'static str,
    /// The adaptive `t` of `mu` given `k` (`c alpha`), its power `{p}`.
    t: &'static str,
    /// `r^{p}`.
    power_of_r: &'static str,
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
    t: "pow(min(mu * (1.0 + k) / max(mu + k, 1e-30), 1.0), {p})",
    power_of_r: "pow(r, {p})",
    comment: "//",
    close: "}",
    number: shader_number,
};

const GLSL: Syntax = Syntax {
    signature: "float {name}({params}) {",
    params: "float mu, float r",
    constant: "float",
    variable: "float",
    t: "pow(min(mu * (1.0 + k) / max(mu + k, 1e-30), 1.0), {p})",
    power_of_r: "pow(r, {p})",
    comment: "//",
    close: "}",
    number: shader_number,
};

const RUST: Syntax = Syntax {
    signature: "pub fn {name}({params}) -> f32 {",
    params: "mu: f32, r: f32",
    constant: "let",
    variable: "let mut",
    t: "(mu * (1.0 + k) / (mu + k).max(1e-30)).min(1.0).powf({p})",
    power_of_r: "r.powf({p})",
    comment: "//",
    close: "}",
    number: rust_number,
};

const C: Syntax = Syntax {
    signature: "static inline float {name}({params}) {",
    params: "float mu, float r",
    constant: "const float",
    variable: "float",
    t: "powf(fminf(mu * (1.0f + k) / fmaxf(mu + k, 1e-30f), 1.0f), {p}f)",
    power_of_r: "powf(r, {p}f)",
    comment: "//",
    close: "}",
    number: c_number,
};

/// `c_0 + v (c_1 + v (...))` of one row of coefficients.
fn horner(coefficients: &[f64], variable: &str, number: fn(f64) -> String) -> String {
    // Trailing zeros (an additive numerator's cross terms, exactly 0) are left out.
    let kept = coefficients
        .iter()
        .rposition(|&c| c != 0.0)
        .map_or(1, |last| last + 1);
    let coefficients = &coefficients[..kept.min(coefficients.len())];
    let mut out = String::new();
    for (k, &c) in coefficients.iter().enumerate() {
        if k > 0 {
            out += &format!(" + {variable} * (");
        }
        out += &number(c);
    }
    out + &")".repeat(coefficients.len().saturating_sub(1))
}

fn code(fit: &impl FitText, syntax: &Syntax, header: &str, text: &str) -> String {
    let mut out = String::new();
    for line in text.split(". ") {
        out += &format!("{} {line}\n", syntax.comment);
    }
    out += header;
    out += &syntax
        .signature
        .replace("{name}", &fit.function_name())
        .replace("{params}", syntax.params);
    out += "\n";
    out += &fit.body(syntax);
    out += syntax.close;
    out += "\n";
    out
}

/// The fit in `format`; `description` (from [`FitText::description`]) heads the file.
#[must_use]
pub fn emit(fit: &impl FitText, format: FitFormat, description: &str) -> String {
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

/// The formula file: the same fit in kiln's formula language ([`super::formula`]),
/// coefficients with every digit of their f64 value.
fn formula_file(fit: &impl FitText, description: &str) -> String {
    let (source, defines, e) = fit.formula();
    let mut out = format!("# {description}\n");
    out += &format!("name = \"{}\"\n", fit.function_name());
    out += &format!("source = \"{source}\"\n");
    out += "define = [\n";
    for d in &defines {
        out += &format!("  \"{d}\",\n");
    }
    out += "]\n";
    out += &format!("E = \"{e}\"\n");
    out
}

/// Either kind of fit kiln makes.
#[derive(Clone, Debug, PartialEq)]
pub enum MadeFit {
    Polynomial(PolynomialFit),
    Rational(RationalFit),
}

impl MadeFit {
    /// The number of coefficients.
    #[must_use]
    pub fn coefficients(&self) -> usize {
        match self {
            MadeFit::Polynomial(fit) => fit.degrees.coefficients(),
            MadeFit::Rational(fit) => fit.shape.coefficients(),
        }
    }

    /// The shape as `--degrees` spells it: `T,R` or `PT,PR/QT,QR`.
    #[must_use]
    pub fn degrees_text(&self) -> String {
        match self {
            MadeFit::Polynomial(fit) => format!("{},{}", fit.degrees.t, fit.degrees.r),
            MadeFit::Rational(fit) => {
                let (p, q) = (fit.shape.numerator, fit.shape.denominator);
                let join = if fit.shape.additive { '+' } else { ',' };
                format!("{}{join}{}/{},{}", p.t, p.r, q.t, q.r)
            }
        }
    }

    /// The value at `mu` and the perceptual roughness `r`, in f64.
    #[must_use]
    pub fn value(&self, mu: f64, r: f64) -> f64 {
        match self {
            MadeFit::Polynomial(fit) => fit.value(mu, r),
            MadeFit::Rational(fit) => fit.value(mu, r),
        }
    }
}

impl FitText for MadeFit {
    fn function_name(&self) -> String {
        match self {
            MadeFit::Polynomial(fit) => fit.function_name(),
            MadeFit::Rational(fit) => fit.function_name(),
        }
    }

    fn description(&self, max_error: f64, command: &str) -> String {
        match self {
            MadeFit::Polynomial(fit) => fit.description(max_error, command),
            MadeFit::Rational(fit) => fit.description(max_error, command),
        }
    }

    fn body(&self, syntax: &Syntax) -> String {
        match self {
            MadeFit::Polynomial(fit) => fit.body(syntax),
            MadeFit::Rational(fit) => fit.body(syntax),
        }
    }

    fn formula(&self) -> (String, Vec<String>, String) {
        match self {
            MadeFit::Polynomial(fit) => fit.formula(),
            MadeFit::Rational(fit) => fit.formula(),
        }
    }
}

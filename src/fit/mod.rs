//! Texture-free fits of the directional albedo: the ones engines ship ([`engine`]) and any given
//! as a formula file ([`FormulaFit`], in the language of [`formula`]), each a function of `mu`
//! and the perceptual roughness `r` (`alpha = r^2`) for some of `E`, `E_scale`, `E_bias`.
//! `kiln verify-fit` audits them ([`crate::verify::fit`]). The fits kiln makes itself are
//! [`polynomial`] and [`rational`], written out by [`emit`].

pub mod emit;
pub mod engine;
pub mod formula;
pub mod polynomial;
pub mod rational;

use crate::error::{Error, Result};
use crate::integrate::quantity::Quantity;
use engine::EngineFit;
use formula::{Expr, MAX_DEFINITIONS, VARIABLES};
use serde::Deserialize;
use std::path::Path;

/// A fit to audit.
#[derive(Clone, Debug)]
pub enum Fit {
    Engine(EngineFit),
    Formula(FormulaFit),
}

impl Fit {
    /// The fit's name.
    #[must_use]
    pub fn name(&self) -> &str {
        match self {
            Fit::Engine(fit) => fit.name(),
            Fit::Formula(fit) => &fit.name,
        }
    }

    /// Where it comes from.
    #[must_use]
    pub fn source(&self) -> &str {
        match self {
            Fit::Engine(fit) => fit.source(),
            Fit::Formula(fit) => &fit.source,
        }
    }

    /// The quantities it gives, `E` first when it gives `E`.
    #[must_use]
    pub fn quantities(&self) -> Vec<Quantity> {
        match self {
            Fit::Engine(fit) => fit.quantities().to_vec(),
            Fit::Formula(fit) => fit.quantities(),
        }
    }

    /// Its value of `quantity` at `mu` and the perceptual roughness `r`.
    #[must_use]
    pub fn value(&self, quantity: Quantity, mu: f64, r: f64) -> f64 {
        match self {
            Fit::Engine(fit) => fit.value(quantity, mu, r),
            Fit::Formula(fit) => fit.value(quantity, mu, r),
        }
    }
}

/// The largest formula file read, in bytes.
pub const MAX_FORMULA_FILE_BYTES: u64 = 64 * 1024;

/// A fit given as a TOML file of formulas:
///
/// ```toml
/// name = "Unreal 5 analytic E"                        # required
/// source = "ShadingEnergyConservation.ush"            # optional, printed with the audit
/// define = ["k = max(r, 1e-3)", "p = pow(k, mu / k)"] # optional, in order
/// E = "1 - saturate(p * (k * mu + 0.0266916) / (0.466495 + mu))"
/// # E_scale = "...", E_bias = "..."  (at least one of the three; E is E_scale + E_bias when
/// # only those two are given)
/// ```
///
/// Formulas use `mu`, `r` (perceptual roughness), `alpha = r^2` and the names defined before
/// them ([`formula`]).
#[derive(Clone, Debug)]
pub struct FormulaFit {
    pub name: String,
    pub source: String,
    /// `name = expression` in order; each slot after [`VARIABLES`].
    definitions: Vec<Expr>,
    e: Option<Expr>,
    e_scale: Option<Expr>,
    e_bias: Option<Expr>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FormulaFile {
    name: String,
    #[serde(default)]
    source: String,
    #[serde(default)]
    define: Vec<String>,
    #[serde(rename = "E")]
    e: Option<String>,
    #[serde(rename = "E_scale")]
    e_scale: Option<String>,
    #[serde(rename = "E_bias")]
    e_bias: Option<String>,
}

impl FormulaFit {
    /// Reads a formula file.
    ///
    /// # Errors
    /// The file is unreadable, too large, not TOML of the form above, or a formula is bad
    /// (which one, and where in it).
    pub fn read(path: &Path) -> Result<Self> {
        let bad = |message: String| Error::InvalidInput(format!("{}: {message}", path.display()));
        let bytes = crate::format::read_file(path)?;
        if bytes.len() as u64 > MAX_FORMULA_FILE_BYTES {
            return Err(bad(format!(
                "{} bytes; a formula file has at most {MAX_FORMULA_FILE_BYTES}",
                bytes.len()
            )));
        }
        let text = String::from_utf8(bytes)
            .map_err(|_| bad("not UTF-8 text: a formula file is TOML".into()))?;
        Self::parse(&text).map_err(|e| bad(e.to_string()))
    }

    /// Parses a formula file's text (see [`FormulaFit`]); errors without the file's name.
    ///
    /// # Errors
    /// As [`FormulaFit::read`].
    pub fn parse(text: &str) -> crate::Result<Self> {
        let file: FormulaFile = toml::from_str(text).map_err(|e| {
            crate::Error::InvalidInput(format!(
                "not a formula file ({}); it holds name = \"...\" and at least one of E, \
                 E_scale, E_bias as formulas in mu, r and alpha",
                e.message()
            ))
        })?;
        if file.define.len() > MAX_DEFINITIONS {
            return Err(crate::Error::InvalidInput(format!(
                "{} definitions; at most {MAX_DEFINITIONS}",
                file.define.len()
            )));
        }
        let mut names: Vec<String> = VARIABLES.iter().map(ToString::to_string).collect();
        let mut definitions = Vec::new();
        for (k, line) in file.define.iter().enumerate() {
            let Some((name, formula)) = line.split_once('=') else {
                return Err(crate::Error::InvalidInput(format!(
                    "define[{k}] is {}: write it as name = formula",
                    crate::error::quoted(line)
                )));
            };
            let name = name.trim();
            let valid = name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
                && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !valid || name.len() > 64 {
                return Err(crate::Error::InvalidInput(format!(
                    "define[{k}]: {} is not a name (letters, digits and _, at most 64)",
                    crate::error::quoted(name)
                )));
            }
            if names.iter().any(|n| n == name) {
                return Err(crate::Error::InvalidInput(format!(
                    "define[{k}]: {} is already defined",
                    crate::error::quoted(name)
                )));
            }
            let expr = Expr::parse(formula, &names)
                .map_err(|e| crate::Error::InvalidInput(format!("define[{k}] ({name}): {e}")))?;
            definitions.push(expr);
            names.push(name.to_string());
        }
        let parse = |key: &str, formula: &Option<String>| {
            formula
                .as_deref()
                .map(|f| {
                    Expr::parse(f, &names)
                        .map_err(|e| crate::Error::InvalidInput(format!("{key}: {e}")))
                })
                .transpose()
        };
        let fit = FormulaFit {
            name: file.name,
            source: file.source,
            definitions,
            e: parse("E", &file.e)?,
            e_scale: parse("E_scale", &file.e_scale)?,
            e_bias: parse("E_bias", &file.e_bias)?,
        };
        if fit.quantities().is_empty() {
            return Err(crate::Error::InvalidInput(
                "no formula: give at least one of E, E_scale, E_bias".into(),
            ));
        }
        Ok(fit)
    }

    fn quantities(&self) -> Vec<Quantity> {
        let has_e = self.e.is_some() || (self.e_scale.is_some() && self.e_bias.is_some());
        [
            (Quantity::E, has_e),
            (Quantity::EScale, self.e_scale.is_some()),
            (Quantity::EBias, self.e_bias.is_some()),
        ]
        .into_iter()
        .filter_map(|(q, given)| given.then_some(q))
        .collect()
    }

    fn value(&self, quantity: Quantity, mu: f64, r: f64) -> f64 {
        let mut slots = vec![mu, r, r * r];
        for definition in &self.definitions {
            let value = definition.eval(&slots);
            slots.push(value);
        }
        let eval = |e: &Option<Expr>| e.as_ref().map_or(f64::NAN, |e| e.eval(&slots));
        match quantity {
            Quantity::EScale => eval(&self.e_scale),
            Quantity::EBias => eval(&self.e_bias),
            _ => match &self.e {
                Some(e) => e.eval(&slots),
                None => eval(&self.e_scale) + eval(&self.e_bias),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unreal's `E` written as a formula file gives the built-in's values: two independent
    /// transcriptions of the same published formula.
    #[test]
    fn a_formula_file_evaluates_as_the_built_in_fit() {
        let fit = FormulaFit::parse(
            "name = \"ue5\"\n\
             define = [\"k = max(r, 1e-3)\", \"p = pow(k, mu / k)\"]\n\
             E = \"1 - saturate(p * (k * mu + 0.0266916) / (0.466495 + mu))\"\n\
             E_bias = \"(1 - mu)^5 * pow(2.36651 * pow(mu, 4.7703 * k) + 0.0387332, k)\"\n",
        )
        .unwrap();
        assert_eq!(fit.quantities(), [Quantity::E, Quantity::EBias]);
        for (mu, r) in [(0.5, 0.5), (0.01, 0.9), (1.0, 0.1), (0.3, 0.0)] {
            for q in [Quantity::E, Quantity::EBias] {
                let (a, b) = (fit.value(q, mu, r), EngineFit::Unreal.value(q, mu, r));
                assert!((a - b).abs() < 1e-15, "{q:?} at {mu}, {r}: {a} vs {b}");
            }
        }
    }

    /// `E` is the sum when only the split-sum pair is given; bad files say what is wrong.
    #[test]
    fn formula_files_are_checked() {
        let fit = FormulaFit::parse("name = \"x\"\nE_scale = \"mu\"\nE_bias = \"alpha\"").unwrap();
        assert_eq!(fit.value(Quantity::E, 0.25, 0.5), 0.5);
        let err = |t: &str| FormulaFit::parse(t).unwrap_err();
        assert!(err("name = \"x\"").to_string().contains("no formula"));
        assert!(err("E = \"mu\"").to_string().contains("not a formula file"));
        assert!(
            err("name = \"x\"\nE = \"mu\"\nF = \"1\"")
                .to_string()
                .contains("unknown field")
        );
        assert!(
            err("name = \"x\"\nE = \"nu\"")
                .to_string()
                .contains("E: at character 1: unknown name")
        );
        assert!(
            err("name = \"x\"\ndefine = [\"k\"]\nE = \"mu\"")
                .to_string()
                .contains("name = formula")
        );
        assert!(
            err("name = \"x\"\ndefine = [\"mu = 1\"]\nE = \"mu\"")
                .to_string()
                .contains("already")
        );
        assert!(
            err("name = \"x\"\ndefine = [\"2k = 1\"]\nE = \"mu\"")
                .to_string()
                .contains("not a name")
        );
        // A definition sees only what comes before it.
        assert!(
            err("name = \"x\"\ndefine = [\"a = b\", \"b = 1\"]\nE = \"a\"")
                .to_string()
                .contains("define[0] (a): at character 2: unknown name 'b'")
        );
    }
}

//! The Fresnel flags, shared by every command that names a model.

use clap::{Args, ValueEnum};
use kiln::Fresnel;

/// Which Fresnel model (`--fresnel`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FresnelKind {
    /// F = 1 (the energy-compensation tables proper).
    None,
    /// Schlick's approximation: --f0 (and --f90, default 1).
    Schlick,
    /// Exact dielectric Fresnel with relative index --ior (n_inside / n_outside; < 1 for light
    /// leaving the denser medium, with total internal reflection).
    Dielectric,
    /// Conductor with complex index --eta + i --k per RGB channel.
    Conductor,
}

/// Fresnel flags. RGB values are one number (all channels) or three, comma-separated.
#[derive(Args, Debug, Clone)]
pub struct FresnelArgs {
    /// Fresnel model [default: none, or schlick when --f0 is given, dielectric with --ior,
    /// conductor with --eta/--k].
    #[arg(long, value_enum)]
    pub fresnel: Option<FresnelKind>,
    /// Schlick's reflectance at normal incidence, in [0, 1]: F0 or R,G,B. Alone it means
    /// --fresnel schlick.
    #[arg(long, value_parser = parse_rgb, allow_negative_numbers = true)]
    pub f0: Option<[f64; 3]>,
    /// Schlick's reflectance at grazing incidence, in [0, 1] [default: 1].
    #[arg(long, value_parser = parse_rgb, allow_negative_numbers = true)]
    pub f90: Option<[f64; 3]>,
    /// Dielectric relative index of refraction, in [0.01, 100] (1.5: glass seen from air).
    /// Beside a glass quantity (e-dielectric, ...) the tables at that IOR alone, 2-D.
    #[arg(long, value_parser = crate::args::parse_number, allow_negative_numbers = true)]
    pub ior: Option<f64>,
    /// Conductor: real part of the complex index, in [0.01, 100], per channel.
    #[arg(long, value_parser = parse_rgb, allow_negative_numbers = true)]
    pub eta: Option<[f64; 3]>,
    /// Conductor: imaginary part (extinction), in [0, 100], per channel.
    #[arg(long, value_parser = parse_rgb, allow_negative_numbers = true)]
    pub k: Option<[f64; 3]>,
}

/// One number for all three channels, or three comma-separated.
fn parse_rgb(text: &str) -> Result<[f64; 3], String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|part| crate::args::parse_number(part.trim()))
        .collect::<Result<_, _>>()?;
    match values[..] {
        [v] => Ok([v; 3]),
        [r, g, b] => Ok([r, g, b]),
        _ => Err(format!(
            "expected one number or three comma-separated (R,G,B), got {} values in '{text}'",
            values.len()
        )),
    }
}

impl FresnelArgs {
    /// Whether any Fresnel flag was given.
    pub fn given(&self) -> bool {
        self.fresnel.is_some()
            || self.f0.is_some()
            || self.f90.is_some()
            || self.ior.is_some()
            || self.eta.is_some()
            || self.k.is_some()
    }

    /// The model the flags name, validated; a flag that belongs to another model, or a missing
    /// one, is an error that says which.
    pub fn model(&self) -> kiln::Result<Fresnel> {
        let bad = |message: String| kiln::Error::InvalidInput(message);
        let kind = match self.fresnel {
            Some(kind) => kind,
            None if self.f0.is_some() || self.f90.is_some() => FresnelKind::Schlick,
            None if self.ior.is_some() => FresnelKind::Dielectric,
            None if self.eta.is_some() || self.k.is_some() => FresnelKind::Conductor,
            None => FresnelKind::None,
        };
        let foreign: Vec<&str> = [
            ("--f0", self.f0.is_some(), kind == FresnelKind::Schlick),
            ("--f90", self.f90.is_some(), kind == FresnelKind::Schlick),
            ("--ior", self.ior.is_some(), kind == FresnelKind::Dielectric),
            ("--eta", self.eta.is_some(), kind == FresnelKind::Conductor),
            ("--k", self.k.is_some(), kind == FresnelKind::Conductor),
        ]
        .iter()
        .filter(|(_, given, belongs)| *given && !belongs)
        .map(|(name, _, _)| *name)
        .collect();
        if !foreign.is_empty() {
            return Err(bad(format!(
                "{} do{} not apply to --fresnel {} (schlick takes --f0 --f90, dielectric --ior, \
                 conductor --eta --k)",
                foreign.join(", "),
                if foreign.len() == 1 { "es" } else { "" },
                kind.to_possible_value().expect("named").get_name()
            )));
        }
        let missing = |flag: &str| {
            bad(format!(
                "--fresnel {} needs {flag}",
                kind.to_possible_value().expect("named").get_name()
            ))
        };
        let model = match kind {
            FresnelKind::None => Fresnel::None,
            FresnelKind::Schlick => Fresnel::Schlick {
                f0: self.f0.ok_or_else(|| missing("--f0"))?,
                f90: self.f90.unwrap_or([1.0; 3]),
            },
            FresnelKind::Dielectric => Fresnel::Dielectric {
                eta: self.ior.ok_or_else(|| missing("--ior"))?,
            },
            FresnelKind::Conductor => Fresnel::Conductor {
                eta: self.eta.ok_or_else(|| missing("--eta"))?,
                k: self.k.ok_or_else(|| missing("--k"))?,
            },
        };
        model.validate()?;
        Ok(model)
    }
}

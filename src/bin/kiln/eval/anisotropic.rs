//! `kiln eval` for anisotropic GGX (`--alpha-x/--alpha-y`, or a roughness with `--anisotropy`):
//! `E(mu, phi)` or its azimuthal average (`kiln::integrate::anisotropic`).

use super::{EvalArgs, EvalQuantity, Method, print_json};
use kiln::integrate::QmcSettings;
use kiln::integrate::anisotropic::{
    anisotropic_albedo, check_anisotropic, check_azimuth, reference_anisotropic_albedo,
    reference_anisotropic_fourier,
};
use kiln::integrate::reference::ReferenceSettings;
use kiln::model::{AnisotropicGgx, Masking, Ndf};
use std::time::Instant;

/// The flags of an anisotropic lobe.
#[derive(clap::Args, Debug)]
pub struct AnisotropyArgs {
    /// Anisotropic GGX: slope-space roughness along the tangent (x), in (0, 1000]; give
    /// --alpha-y too (or --anisotropy with --alpha or --roughness).
    #[arg(long, value_parser = crate::args::parse_alpha, requires = "alpha_y",
          conflicts_with_all = ["alpha", "roughness", "anisotropy"], allow_negative_numbers = true)]
    pub alpha_x: Option<f64>,
    /// Anisotropic GGX: slope-space roughness along the bitangent (y), in (0, 1000].
    #[arg(long, value_parser = crate::args::parse_alpha, requires = "alpha_x",
          allow_negative_numbers = true)]
    pub alpha_y: Option<f64>,
    /// Anisotropy a of --alpha or --roughness, turned into alpha_x and alpha_y by
    /// --anisotropy-convention.
    #[arg(long, allow_negative_numbers = true)]
    pub anisotropy: Option<f64>,
    /// How --anisotropy makes alpha_x and alpha_y: kulla-conty (alpha (1 +- a): Filament,
    /// Unreal), disney (alpha / sqrt(1 - 0.9 a), alpha sqrt(1 - 0.9 a): Cycles), gltf
    /// (KHR_materials_anisotropy: alpha + (1 - alpha) a^2, alpha), openpbr (root mean square
    /// alpha).
    #[arg(
        long,
        value_enum,
        default_value = "kulla-conty",
        requires = "anisotropy"
    )]
    pub anisotropy_convention: kiln::model::AnisotropyConvention,
    /// Azimuth of the view in radians from the tangent (x), in [-2 pi, 2 pi]; without it, E is
    /// averaged over the view's azimuth.
    #[arg(long, allow_negative_numbers = true)]
    pub phi: Option<f64>,
}

impl AnisotropyArgs {
    /// Whether the lobe is anisotropic (any anisotropy flag given).
    pub fn given(&self) -> bool {
        self.alpha_x.is_some() || self.anisotropy.is_some() || self.phi.is_some()
    }
}

/// `kiln eval` of an anisotropic lobe.
pub fn run(args: &EvalArgs) -> kiln::Result<()> {
    let invalid = |message: String| kiln::Error::InvalidInput(message);
    let lobe = &args.anisotropy;
    if args.quantity != EvalQuantity::E {
        return Err(invalid(format!(
            "anisotropic GGX is evaluated for --quantity e (E at --mu, at --phi or averaged \
             over it); --quantity {} is isotropic in this version",
            clap::ValueEnum::to_possible_value(&args.quantity)
                .expect("named")
                .get_name()
        )));
    }
    if args.ndf != Ndf::Ggx || args.masking != Masking::HeightCorrelated {
        return Err(invalid(
            "the anisotropic lobe is GGX with height-correlated masking (--ndf ggx --masking \
             height-correlated)"
                .into(),
        ));
    }
    if args.fresnel.given() {
        return Err(invalid(
            "the anisotropic E is for F = 1: drop the Fresnel flags".into(),
        ));
    }
    let (alpha_x, alpha_y) = match (lobe.alpha_x, lobe.alpha_y, lobe.anisotropy) {
        (Some(x), Some(y), _) => (x, y),
        (_, _, Some(a)) => {
            let Some(alpha) = args.alpha_given()? else {
                return Err(invalid(
                    "--anisotropy needs the lobe's roughness: --alpha A or --roughness R".into(),
                ));
            };
            lobe.anisotropy_convention.checked_alphas(alpha, a)?
        }
        _ => {
            return Err(invalid(
                "--phi is the view's azimuth on an anisotropic lobe: give --alpha-x and \
                 --alpha-y, or --anisotropy with --alpha or --roughness"
                    .into(),
            ));
        }
    };
    let ndf = AnisotropicGgx { alpha_x, alpha_y };
    let Some(mu) = args.mu else {
        return Err(invalid(
            "--quantity e needs --mu (cos(theta) in [0, 1])".into(),
        ));
    };
    check_anisotropic(ndf, mu)?;
    if let Some(phi) = lobe.phi {
        check_azimuth(phi)?;
    }
    let start = Instant::now();
    let (value, error, samples, converged) = match args.method {
        Method::Qmc => {
            let settings = QmcSettings {
                samples: args.samples.unwrap_or(QmcSettings::DEFAULT_SAMPLES),
                scrambles: args.scrambles.unwrap_or(QmcSettings::DEFAULT_SCRAMBLES),
                seed: args.seed,
            };
            settings.validate()?;
            let e = anisotropic_albedo(ndf, mu, lobe.phi, &settings);
            (e.value, e.std_error, e.samples, true)
        }
        Method::Reference => {
            args.no_samples_for_reference()?;
            let settings = ReferenceSettings::default();
            match lobe.phi {
                Some(phi) => {
                    let r = reference_anisotropic_albedo(ndf, mu, phi, &settings);
                    (r.value, r.error, r.evaluations, r.converged)
                }
                None => {
                    let r = reference_anisotropic_fourier(ndf, mu, 1, &settings);
                    (r.coefficients[0], r.error, r.evaluations, r.converged)
                }
            }
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    if args.json {
        let object = serde_json::json!({
            "quantity": "E",
            "ndf": "ggx-anisotropic",
            "masking": Masking::HeightCorrelated.name(),
            "alpha_x": alpha_x,
            "alpha_y": alpha_y,
            "anisotropy": lobe.anisotropy,
            "anisotropy_convention": lobe.anisotropy.map(|_| lobe.anisotropy_convention.name()),
            "mu": mu,
            "phi": lobe.phi,
            "azimuthal_average": lobe.phi.is_none(),
            "value": value,
            "one_minus_value": 1.0 - value,
            "std_error": error,
            "method": args.method.name(),
            "samples": samples,
            "seconds": seconds,
            "converged": converged,
            "kiln_version": kiln::format::metadata::KILN_VERSION,
        });
        print_json(args, object);
    } else {
        let at = match lobe.phi {
            Some(phi) => format!("phi = {}", kiln::error::brief(phi)),
            None => "averaged over phi".to_string(),
        };
        let what = match args.method {
            Method::Qmc => format!("{samples} samples"),
            Method::Reference => format!("reference quadrature, {samples} evaluations"),
        };
        println!(
            "E(mu = {}, {at}; alpha_x = {}, alpha_y = {}) = {value:.12} ± {error:.1e} (ggx \
             anisotropic height-correlated, {what}, {seconds:.3} s)",
            kiln::error::brief(mu),
            kiln::error::brief(alpha_x),
            kiln::error::brief(alpha_y),
        );
        if !converged {
            eprintln!(
                "kiln: warning: the quadrature did not reach its tolerance; the error estimate is what it reached"
            );
        }
    }
    Ok(())
}

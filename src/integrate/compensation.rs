//! The albedo a renderer gets from the single-scattering BRDF plus an energy compensation, for
//! a Fresnel model: what the microsurface walk ([`crate::integrate::walk`]) measures them
//! against.
//!
//! Both forms are computed from kiln's deterministic reference (`E`, `E_avg` and the
//! Fresnel-weighted `E_F` to 1e-10, `F_avg` to 1e-14), not from a table's lookup: what is
//! measured is the compensation's model error (percents), not a table's interpolation (its
//! lookups are within 2.1e-4: `kiln verify`).

use crate::integrate::reference::{
    ReferenceSettings, reference_albedo, reference_average_albedo, reference_weighted_albedo,
};
use crate::integrate::walk::{SchlickPolynomial, WalkError, WalkSettings, walk_schlick_polynomial};
use crate::model::Model;
use crate::model::fresnel::{Fresnel, Rgb};
use crate::model::kulla_conty::fresnel_colour;

/// An energy compensation of the single-scattering BRDF.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Compensation {
    /// Kulla and Conty 2017: the added lobe `(1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))`
    /// times `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))` per channel (kiln's
    /// `model::kulla_conty`); its albedo is `E_F(mu) + colour (1 - E(mu))`.
    KullaConty,
    /// Turquin 2019, "Practical multiple scattering compensation for microfacet models"
    /// (Filament, Unreal 5, Bevy, three.js): the single-scattering BRDF scaled by
    /// `1 + F0 (1 / E(mu) - 1)`, `F0` the reflectance at normal incidence; its albedo is
    /// `E_F(mu) (1 + F0 (1 - E) / E)`.
    Turquin,
    /// kiln's: the reciprocal lobe `M(mu_o) M(mu_i) / (pi M_avg)` per channel, `M(mu, F0)`
    /// the walk's albedo less single scattering's, held as four coefficients in `F0`
    /// (`KilnCompensation`, tabulated by `table::compensation`); its albedo is
    /// `E_F(mu) + M(mu, F0)`. Schlick's Fresnel with `F90 = 1` only.
    Kiln,
}

impl Compensation {
    /// Both forms, in a fixed order.
    pub const ALL: [Compensation; 3] = [
        Compensation::KullaConty,
        Compensation::Turquin,
        Compensation::Kiln,
    ];

    /// The name on the command line and in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Compensation::KullaConty => "kulla-conty",
            Compensation::Turquin => "turquin",
            Compensation::Kiln => "kiln",
        }
    }

    /// The compensated albedo per channel from the single-scattering quantities `s` (for
    /// [`Compensation::Kiln`], with `s.kiln` set: NaN without it).
    #[must_use]
    pub fn albedo(self, s: &SingleScattering) -> Rgb {
        match self {
            Compensation::KullaConty => std::array::from_fn(|j| {
                s.e_f[j] + fresnel_colour(s.f_avg[j], s.e_avg) * s.one_minus_e
            }),
            Compensation::Turquin => std::array::from_fn(|j| {
                if s.e > 0.0 {
                    s.e_f[j] * (1.0 + s.f0[j] * s.one_minus_e / s.e)
                } else {
                    0.0
                }
            }),
            Compensation::Kiln => std::array::from_fn(|j| match &s.kiln {
                Some(kiln) => s.e_f[j] + kiln.multiple(s.f0[j]),
                None => f64::NAN,
            }),
        }
    }
}

/// What the lobes the compensations add are computed from, at one view, exit and Fresnel
/// ([`Compensation::added_lobe`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeInputs {
    /// `E` at the view's and at the exit's cosine, and `E_avg`.
    pub e_view: f64,
    pub e_exit: f64,
    pub e_avg: f64,
    /// The single-scattering BRDF with the Fresnel factor at the half vector, `f_ss F(v.h)`,
    /// from the view to the exit (or its average over the azimuth, for the averaged lobe).
    pub single: f64,
    /// Schlick's `F0` and the Fresnel's hemispherical average `F_avg`.
    pub f0: f64,
    pub f_avg: f64,
    /// kiln's `M` at the view and at the exit and `M_avg`, from its table at this `F0`.
    pub kiln: Option<[f64; 3]>,
}

impl Compensation {
    /// The lobe this compensation adds to the single-scattering BRDF, from the view to the exit:
    /// what the walk's orders after the first are ([`crate::integrate::walk::walk_lobe`]).
    ///
    /// Kulla-Conty: `(1 - E(mu_i)) (1 - E(mu_o)) / (pi (1 - E_avg))` times its colour
    /// `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))` (1 at `F = 1`). Turquin: the
    /// single-scattering lobe with its Fresnel times `F0 (1 - E(mu_i)) / E(mu_i)`. kiln's:
    /// `M(mu_i) M(mu_o) / (pi M_avg)` (NaN without `inputs.kiln`); with `M(mu, 1) = 1 - E`
    /// pinned, at `F = 1` it is Kulla-Conty's lobe.
    #[must_use]
    pub fn added_lobe(self, inputs: &LobeInputs) -> f64 {
        let LobeInputs {
            e_view,
            e_exit,
            e_avg,
            single,
            f0,
            f_avg,
            kiln,
        } = *inputs;
        match self {
            Compensation::KullaConty => {
                fresnel_colour(f_avg, e_avg) * (1.0 - e_view) * (1.0 - e_exit)
                    / (std::f64::consts::PI * (1.0 - e_avg))
            }
            Compensation::Turquin => {
                if e_view > 0.0 {
                    single * f0 * (1.0 - e_view) / e_view
                } else {
                    0.0
                }
            }
            Compensation::Kiln => match kiln {
                Some([m_view, m_exit, m_avg]) => m_view * m_exit / (std::f64::consts::PI * m_avg),
                None => f64::NAN,
            },
        }
    }
}

/// The pole of kiln's basis in `F0`: each Bernstein polynomial over `1 - KILN_POLE F0`, the
/// shape of the bounces' geometric series (`e_2 F^2 / (1 - q F)`). Chosen over 0.2 to 0.5 with
/// `examples/compensation_basis` (degree 3: 0.54 % at 0.2, 0.13 % at 0.35, 0.58 % at 0.5;
/// 1.1 % without a pole).
pub const KILN_POLE: f64 = 0.35;

/// kiln's compensation at one view: the multiple-scattering albedo
/// `M(F0) = Σ_j c_j B_j(F0) / (1 - KILN_POLE F0)` with the cubic Bernstein polynomials `B_j`,
/// fitted to the walk's albedo less single scattering's (Schlick, `F90 = 1`) by least squares
/// relative to the walk's albedo over `F0` in [0.02, 1], with `c_3` pinned so that `F0 = 1` is
/// the white furnace exactly (`M(1) = 1 - E`). Four coefficients: one RGBA texel.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct KilnCompensation {
    pub coefficients: [f64; 4],
}

impl KilnCompensation {
    /// The basis at `f0`.
    #[must_use]
    pub fn basis(f0: f64) -> [f64; 4] {
        let g = 1.0 - f0;
        let pole = 1.0 - KILN_POLE * f0;
        [
            g * g * g / pole,
            3.0 * f0 * g * g / pole,
            3.0 * f0 * f0 * g / pole,
            f0 * f0 * f0 / pole,
        ]
    }

    /// `M(f0)`.
    #[must_use]
    pub fn multiple(&self, f0: f64) -> f64 {
        Self::basis(f0)
            .iter()
            .zip(&self.coefficients)
            .map(|(b, c)| b * c)
            .sum()
    }

    /// The fit (see the type) to `walk(F0)`, the walk's albedo, given single scattering's
    /// split-sum parts: `E_F(F0) = F0 E_scale + E_bias` (`F90 = 1`).
    #[must_use]
    pub fn fit(walk: impl Fn(f64) -> f64, e_scale: f64, e_bias: f64) -> Self {
        let f0s: Vec<f64> = (0..=49)
            .map(|k| 0.02 + 0.98 * f64::from(k) / 49.0)
            .collect();
        let single = |f: f64| f * e_scale + e_bias;
        // B_3(1) = 1 and the others vanish there: c_3 = M(1) (1 - KILN_POLE).
        let pinned = (walk(1.0) - single(1.0)) * (1.0 - KILN_POLE);
        let mut normal = [[0.0; 3]; 3];
        let mut right = [0.0; 3];
        for &f in &f0s {
            let w = walk(f);
            let weight = 1.0 / (w * w);
            let b = Self::basis(f);
            let target = w - single(f) - pinned * b[3];
            for i in 0..3 {
                right[i] += weight * b[i] * target;
                for j in 0..3 {
                    normal[i][j] += weight * b[i] * b[j];
                }
            }
        }
        let [c0, c1, c2] = solve3(normal, right);
        Self {
            coefficients: [c0, c1, c2, pinned],
        }
    }
}

/// The seed of the walks kiln's compensation is fitted to: other than the audit's (seed 0 by
/// default), so that the audit measures it against independent walks.
pub const KILN_FIT_SEED: u64 = 0x6b69_6c6e;

impl KilnCompensation {
    /// Fitted at `(alpha, mu)` to the walk with `settings` (Schlick, `F90 = 1`; give
    /// [`KILN_FIT_SEED`] as the seed to stay independent of an audit's walks).
    pub fn at(
        model: Model,
        alpha: f64,
        mu: f64,
        settings: &WalkSettings,
        reference: &ReferenceSettings,
    ) -> Result<Self, WalkError> {
        Self::fitted(model, alpha, mu, settings, reference).map(|(fit, _)| fit)
    }

    /// [`KilnCompensation::at`], with the walk's albedo it was fitted to.
    pub fn fitted(
        model: Model,
        alpha: f64,
        mu: f64,
        settings: &WalkSettings,
        reference: &ReferenceSettings,
    ) -> Result<(Self, SchlickPolynomial), WalkError> {
        let polynomial = walk_schlick_polynomial(model, alpha, mu, 1.0, settings, &|_| {})?;
        let schlick = |c: f64| (1.0 - c.clamp(0.0, 1.0)).powi(5);
        let e_scale =
            reference_weighted_albedo(model, alpha, mu, |c| 1.0 - schlick(c), reference).value;
        let e_bias = reference_weighted_albedo(model, alpha, mu, schlick, reference).value;
        let fit = Self::fit(|f| polynomial.albedo(f).value, e_scale, e_bias);
        Ok((fit, polynomial))
    }
}

/// `A x = b` for a symmetric positive definite 3 x 3 `A` (Cramer's rule).
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    std::array::from_fn(|k| {
        let mut m = a;
        for (row, value) in m.iter_mut().zip(b) {
            row[k] = value;
        }
        det(m) / d
    })
}

/// What the compensations are computed from at one view: the single-scattering albedos.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SingleScattering {
    /// `E(mu)` (F = 1) and `1 - E(mu)`.
    pub e: f64,
    pub one_minus_e: f64,
    /// `E_avg`.
    pub e_avg: f64,
    /// The Fresnel-weighted `E_F(mu)` per channel.
    pub e_f: Rgb,
    /// `F_avg` per channel.
    pub f_avg: Rgb,
    /// The reflectance at normal incidence per channel.
    pub f0: Rgb,
    /// kiln's compensation at this view, where it was fitted ([`Compensation::Kiln`]).
    pub kiln: Option<KilnCompensation>,
}

impl SingleScattering {
    /// The quantities at `(alpha, mu)` for `fresnel`, given `E_avg` at `alpha` (computed once
    /// per roughness by the caller: [`reference_average_albedo`]).
    #[must_use]
    pub fn at(
        model: Model,
        alpha: f64,
        mu: f64,
        e_avg: f64,
        fresnel: &Fresnel,
        settings: &ReferenceSettings,
    ) -> Self {
        let e = reference_albedo(model, alpha, mu, settings);
        let f = *fresnel;
        let channel = |j: usize| {
            reference_weighted_albedo(model, alpha, mu, move |c| f.reflectance(c)[j], settings)
                .value
        };
        let e_f = if fresnel.is_grey() {
            [channel(0); 3]
        } else {
            std::array::from_fn(channel)
        };
        Self {
            e: e.value,
            one_minus_e: e.one_minus_value,
            e_avg,
            e_f,
            f_avg: fresnel.average(),
            f0: fresnel.reflectance(1.0),
            kiln: None,
        }
    }
}

/// The directional albedo, per channel, of the single-scattering BRDF of `model` at `alpha`
/// with `fresnel` plus `compensation`, viewed at `mu` (see the module docs); kiln's is fitted
/// to the default walks seeded [`KILN_FIT_SEED`] and needs Schlick's Fresnel with `F90 = 1`.
pub fn compensated_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    fresnel: &Fresnel,
    compensation: Compensation,
    settings: &ReferenceSettings,
) -> Result<Rgb, WalkError> {
    let e_avg = reference_average_albedo(model, alpha, settings).value;
    let mut single = SingleScattering::at(model, alpha, mu, e_avg, fresnel, settings);
    if compensation == Compensation::Kiln {
        if !matches!(fresnel, Fresnel::Schlick { f90, .. } if *f90 == [1.0; 3]) {
            return Err(WalkError::KilnFresnel(format!(
                "{} Fresnel",
                fresnel.flags()
            )));
        }
        let walks = WalkSettings {
            seed: KILN_FIT_SEED,
            ..WalkSettings::default()
        };
        single.kiln = Some(KilnCompensation::at(model, alpha, mu, &walks, settings)?);
    }
    Ok(compensation.albedo(&single))
}

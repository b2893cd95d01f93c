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
}

impl Compensation {
    /// Both forms, in a fixed order.
    pub const ALL: [Compensation; 2] = [Compensation::KullaConty, Compensation::Turquin];

    /// The name on the command line and in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Compensation::KullaConty => "kulla-conty",
            Compensation::Turquin => "turquin",
        }
    }

    /// The compensated albedo per channel from the single-scattering quantities `s`.
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
        }
    }
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
        }
    }
}

/// The directional albedo, per channel, of the single-scattering BRDF of `model` at `alpha`
/// with `fresnel` plus `compensation`, viewed at `mu` (see the module docs).
#[must_use]
pub fn compensated_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    fresnel: &Fresnel,
    compensation: Compensation,
    settings: &ReferenceSettings,
) -> Rgb {
    let e_avg = reference_average_albedo(model, alpha, settings).value;
    compensation.albedo(&SingleScattering::at(
        model, alpha, mu, e_avg, fresnel, settings,
    ))
}

//! One home for "the value of this quantity at this point by this method": an [`Integral`]
//! (model, quantity, Fresnel weight, transmission convention) evaluated at a [`Point`] by the
//! deterministic reference ([`Integral::reference`]) or by QMC ([`Integral::qmc`]). `bake`,
//! `verify`, `eval` and `study` all ask here; a table's spec names its integral
//! ([`crate::table::TableSpec::integral`]), so that the layers point one way: the tables above
//! the integration, the audit above both.
//!
//! What each quantity is integrated by:
//!
//! - `E` and the split-sum channels (`E_scale`, `E_bias`, the weight `h(o.h)` of
//!   [`Quantity::weight`]): the reference ([`super::reference`]) or VNDF QMC
//!   ([`super::albedo`](mod@super::albedo));
//! - `E_F` for a grey Fresnel model: for a dielectric the reflected part of the dielectric
//!   quadrature (it splits at the critical angle, where `F` has a square-root kink that misleads
//!   the generic rule's error estimate), otherwise the reference weighted by `F(o.h)`;
//! - `E_avg`: the fixed Gauss-Legendre rule whose measured bound is within half the tolerance,
//!   where one is ([`average_albedo_to`]), else the composite rule in smooth variables
//!   ([`super::average_quadrature::quadrature_average_albedo`], within
//!   1e-10 of the nested reference), or 3-D QMC;
//! - the dielectric tables: their own quadrature or QMC ([`super::dielectric`]) in the
//!   integral's [`TransmissionConvention`], light from inside at `1 / eta` for the `_inside`
//!   quantities (the [`Point`]'s `eta` is the relative index itself, already inverted);
//! - a coat's reflection (`E_reflection`, `E_avg_reflection`): the reflected part of the
//!   dielectric quadrature, its QMC the Fresnel-weighted albedo's (the average by the
//!   quadrature whatever the method);
//! - `F_avg`: Gauss-Kronrod to 1e-14 whatever the method (a 1-D integral).

use super::albedo::{albedo, average_albedo, weighted_albedo};
use super::average_quadrature::average_albedo_to;
use super::dielectric::{
    dielectric_albedo_with, dielectric_average_albedo_with, reference_dielectric_albedo_with,
    reference_dielectric_average_albedo_with,
};
use super::estimate::Estimate;
use super::qmc::QmcSettings;
use super::quantity::Quantity;
use super::reference::{
    ReferenceSettings, ReferenceValue, reference_albedo, reference_weighted_albedo,
};
use crate::model::dielectric::TransmissionConvention;
use crate::model::{Fresnel, Model};

/// What is integrated: everything but the point and the method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integral {
    pub model: Model,
    pub quantity: Quantity,
    /// The grey Fresnel model of an `E_F` integral; for a glass albedo at one IOR its
    /// dielectric (the material's IOR, [`Integral::fixed_eta`]); `None` for every other
    /// integral.
    pub fresnel: Option<Fresnel>,
    /// How a dielectric integral counts a refraction that ends on the incident side (ignored by
    /// the other quantities).
    pub transmission: TransmissionConvention,
}

/// Where an integral is evaluated: slope-space `alpha`, and `mu` and the relative index `eta`
/// where the quantity has those axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub alpha: f64,
    pub mu: Option<f64>,
    pub eta: Option<f64>,
}

impl Integral {
    /// `E` of `model`, F = 1, single scattering.
    #[must_use]
    pub fn albedo(model: Model) -> Self {
        Self {
            model,
            quantity: Quantity::E,
            fresnel: None,
            transmission: TransmissionConvention::SingleScattering,
        }
    }

    /// The relative index of a glass albedo at one IOR (a table without an IOR axis, whose
    /// Fresnel model names the material's index): that index from outside, its inverse from
    /// inside; `None` for every other integral, whose `eta` (if any) comes with the point.
    #[must_use]
    pub fn fixed_eta(&self) -> Option<f64> {
        match self.fresnel {
            Some(Fresnel::Dielectric { eta }) if self.quantity.is_dielectric() => {
                Some(if self.quantity.from_inside() {
                    1.0 / eta
                } else {
                    eta
                })
            }
            _ => None,
        }
    }

    /// The reference value at `at` (see the module docs for the rule of each quantity).
    ///
    /// # Panics
    /// If `at` lacks a coordinate the quantity needs (`eta` for the tables over IOR, unless the
    /// integral fixes it, [`Integral::fixed_eta`]; `mu` for `E_F`).
    #[must_use]
    pub fn reference(&self, at: Point, settings: &ReferenceSettings) -> ReferenceValue {
        let Point { alpha, mu, eta } = at;
        if self.quantity.has_ior() {
            let eta = eta
                .or(self.fixed_eta())
                .expect("an integral over IOR needs eta");
            let convention = self.transmission;
            return match (self.quantity, mu) {
                (Quantity::FAvg, _) => {
                    let f = Fresnel::Dielectric { eta }.average_report();
                    ReferenceValue {
                        value: f.value[0],
                        one_minus_value: 1.0 - f.value[0],
                        error: f.error,
                        evaluations: f.evaluations,
                        converged: true,
                    }
                }
                (Quantity::EReflection, Some(mu)) => fresnel_weighted_reference(
                    self.model,
                    Fresnel::Dielectric { eta },
                    alpha,
                    mu,
                    settings,
                ),
                (Quantity::EAvgReflection, _) => {
                    reflection_of(reference_dielectric_average_albedo_with(
                        self.model,
                        alpha,
                        eta,
                        TransmissionConvention::SingleScattering,
                        settings,
                    ))
                }
                (_, Some(mu)) => reference_dielectric_albedo_with(
                    self.model, alpha, mu, eta, convention, settings,
                )
                .as_reference_value(),
                (_, None) => reference_dielectric_average_albedo_with(
                    self.model, alpha, eta, convention, settings,
                )
                .as_reference_value(),
            };
        }
        if let Some(fresnel) = self.fresnel {
            let mu = mu.expect("E_F has a mu axis");
            return fresnel_weighted_reference(self.model, fresnel, alpha, mu, settings);
        }
        match (mu, self.quantity.weight()) {
            (Some(mu), None) => reference_albedo(self.model, alpha, mu, settings),
            (Some(mu), Some(h)) => reference_weighted_albedo(self.model, alpha, mu, h, settings),
            (None, _) => average_albedo_to(self.model, alpha, settings),
        }
    }

    /// The QMC estimate at `at` (`F_avg`, a 1-D integral, by its quadrature instead).
    ///
    /// # Panics
    /// As [`Integral::reference`]; and if the settings are invalid (callers validate first).
    #[must_use]
    pub fn qmc(&self, at: Point, settings: &QmcSettings) -> Estimate {
        let Point { alpha, mu, eta } = at;
        let eta = eta.or(self.fixed_eta());
        if let (Quantity::EReflection, Some(eta), Some(mu)) = (self.quantity, eta, mu) {
            // A coat's reflection: the Fresnel-weighted albedo's estimator.
            return fresnel_weighted_qmc(
                self.model,
                Fresnel::Dielectric { eta },
                alpha,
                mu,
                settings,
            );
        }
        // F_avg (a 1-D integral) and the coat's average reflection (no QMC estimator of the
        // reflection alone over both directions) by their quadratures.
        if matches!(self.quantity, Quantity::FAvg | Quantity::EAvgReflection) {
            let r = self.reference(at, &ReferenceSettings::default());
            return Estimate {
                value: r.value,
                one_minus_value: r.one_minus_value,
                std_error: r.error,
                samples: r.evaluations,
            };
        }
        if let Some(eta) = eta {
            let convention = self.transmission;
            return match mu {
                Some(mu) => {
                    dielectric_albedo_with(self.model, alpha, mu, eta, convention, settings)
                }
                None => {
                    dielectric_average_albedo_with(self.model, alpha, eta, convention, settings)
                }
            };
        }
        if let Some(fresnel) = self.fresnel {
            let mu = mu.expect("E_F has a mu axis");
            return fresnel_weighted_qmc(self.model, fresnel, alpha, mu, settings);
        }
        match (mu, self.quantity.weight()) {
            (Some(mu), None) => albedo(self.model, alpha, mu, settings),
            (Some(mu), Some(h)) => weighted_albedo(self.model, alpha, mu, h, settings),
            (None, _) => average_albedo(self.model, alpha, settings),
        }
    }
}

/// The QMC Fresnel-weighted albedo `E_F(mu)` of channel 0 of `fresnel`.
fn fresnel_weighted_qmc(
    model: Model,
    fresnel: Fresnel,
    alpha: f64,
    mu: f64,
    settings: &QmcSettings,
) -> Estimate {
    weighted_albedo(
        model,
        alpha,
        mu,
        move |c| fresnel.reflectance(c)[0],
        settings,
    )
}

/// The reflected part `R` of a dielectric reference, as a value (`one_minus_value` is `1 - R`).
fn reflection_of(r: crate::integrate::dielectric_reference::DielectricReference) -> ReferenceValue {
    ReferenceValue {
        value: r.reflection,
        one_minus_value: 1.0 - r.reflection,
        error: r.error,
        evaluations: r.evaluations,
        converged: r.converged,
    }
}

/// The reference Fresnel-weighted albedo `E_F(mu)` of channel 0 of `fresnel`: for a dielectric
/// the reflected part of the dielectric quadrature (single scattering), otherwise the reference
/// with the weight `F(o.h)`. `one_minus_value` is `1 - E_F`.
#[must_use]
pub fn fresnel_weighted_reference(
    model: Model,
    fresnel: Fresnel,
    alpha: f64,
    mu: f64,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    if let Fresnel::Dielectric { eta } = fresnel {
        let r = reference_dielectric_albedo_with(
            model,
            alpha,
            mu,
            eta,
            TransmissionConvention::SingleScattering,
            settings,
        );
        return reflection_of(r);
    }
    reference_weighted_albedo(model, alpha, mu, |c| fresnel.reflectance(c)[0], settings)
}

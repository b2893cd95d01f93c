//! A reference value of a rough dielectric's energy albedo with its two parts
//! ([`DielectricReference`]): what the quadratures of [`super::dielectric`] and
//! [`super::dielectric_average`] return, in a module of its own so that neither imports the
//! other's.

use super::gauss_kronrod::Quadrature;
use super::reference::ReferenceValue;
use crate::model::fresnel::dielectric;
use serde::Serialize;

/// A reference value of the dielectric energy albedo, its two parts and the energy lost.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DielectricReference {
    /// The reflected part `R`.
    pub reflection: f64,
    /// The transmitted part `T` (energy; the radiance albedo's is `T / eta^2`).
    pub transmission: f64,
    /// `1 - R - T`, integrated directly.
    pub one_minus_value: f64,
    /// The quadrature's error estimate (absolute), for any of them.
    pub error: f64,
    /// Integrand evaluations spent.
    pub evaluations: u64,
    /// Whether every adaptive integral met its tolerance within its budget.
    pub converged: bool,
}

impl DielectricReference {
    /// From the outer integral of `[R, T, 1 - E, the inner integrals' error estimates]`, each
    /// times `scale`; the stated error adds the outer rule's estimate to the inner ones', and
    /// the inner integrals' evaluations and convergence are the caller's tally.
    pub(crate) fn from_outer(
        outer: &Quadrature<4>,
        scale: f64,
        inner_evaluations: u64,
        inner_converged: bool,
    ) -> Self {
        Self {
            reflection: scale * outer.value[0],
            transmission: scale * outer.value[1],
            one_minus_value: scale * outer.value[2],
            error: scale * (outer.error + outer.value[3]),
            evaluations: inner_evaluations + outer.evaluations,
            converged: inner_converged && outer.converged,
        }
    }

    /// `E = R + T`.
    #[must_use]
    pub fn value(&self) -> f64 {
        (self.reflection + self.transmission).clamp(0.0, 1.0)
    }

    /// The radiance albedo `R + T / eta^2` for the relative index `eta` it was computed at
    /// (see [`crate::model::dielectric`]).
    #[must_use]
    pub fn radiance_albedo(&self, eta: f64) -> f64 {
        self.reflection + self.transmission / (eta * eta)
    }

    /// As a [`ReferenceValue`] of `E`.
    #[must_use]
    pub fn as_reference_value(&self) -> ReferenceValue {
        ReferenceValue {
            value: self.value(),
            one_minus_value: self.one_minus_value.clamp(0.0, 1.0),
            error: self.error,
            evaluations: self.evaluations,
            converged: self.converged,
        }
    }

    /// A smooth interface at the cosine `mu`: `R = F(mu)`, `T = 1 - F(mu)`, nothing lost.
    pub(crate) fn exact(mu: f64, eta: f64) -> Self {
        let reflection = dielectric(eta, mu);
        Self {
            reflection,
            transmission: 1.0 - reflection,
            one_minus_value: 0.0,
            error: 0.0,
            evaluations: 0,
            converged: true,
        }
    }
}

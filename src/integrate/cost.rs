//! What one value costs by each method, in seconds of one core: the rates measured on kiln's
//! integrators, from which the bake, the audits and `kiln eval` say how long they will take.

use super::quantity::Quantity;
use crate::model::{Model, Ndf};

/// The estimated cost of one QMC estimate of `quantity` for `model` with `samples` samples, in
/// seconds of one core, at the kernel rates measured for [`crate::bake::estimated_core_seconds`]: for `kiln
/// eval` to say how long a point will take.
#[must_use]
pub fn qmc_seconds_per_point(quantity: Quantity, model: Model, samples: u64) -> f64 {
    let beckmann = model.ndf == Ndf::Beckmann;
    let rate = match (quantity, beckmann) {
        (Quantity::E, false) => 75e6,
        (Quantity::EAvg, false) => 50e6,
        (Quantity::E, true) => 3.5e6,
        (Quantity::EAvg, true) => 1.7e6,
        _ => 20e6,
    };
    samples as f64 / rate
}

/// The estimated cost of one reference value of `quantity` for `model` at tolerance
/// `10^-digits`, in seconds of one core (the per-texel figures of
/// [`crate::bake::estimated_core_seconds`]): for the audits and `kiln verify-fit` to say how long
/// they will take.
#[must_use]
pub fn reference_seconds(quantity: Quantity, model: Model, digits: u32) -> f64 {
    let beckmann = model.ndf == Ndf::Beckmann;
    let per_texel = match (quantity, beckmann) {
        (Quantity::E, false) => 0.3e-3,
        (Quantity::E, true) => 0.6e-3,
        (Quantity::EAvg, false) => 4e-3,
        (Quantity::EAvg, true) => 25e-3,
        // kiln's glass layout at 1e-7, numerics version 13 (16^3 and 16^2 tables on 2 cores:
        // 1.4 s, 3.1 s, 2.5 s, 2.7 s), scaled to 8 digits.
        // A coat's reflection is the same quadrature's reflected part.
        (Quantity::EDielectric | Quantity::EReflection, _) => 0.8e-3,
        (Quantity::EDielectricInside, _) => 1.7e-3,
        (Quantity::EAvgDielectric | Quantity::EAvgReflection, _) => 22e-3,
        (Quantity::EAvgDielectricInside, _) => 24e-3,
        (Quantity::FAvg, _) => 1e-5,
        // Integrals of the E table's lookup, not of the BRDF.
        (Quantity::FMsNorm, _) => 0.15e-3,
        _ => 0.15e-3,
    };
    per_texel * f64::from(digits) / 8.0
}

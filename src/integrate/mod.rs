//! Integration: Owen-scrambled Sobol points and the QMC albedo estimators.

pub mod albedo;
pub mod anisotropic;
pub mod average_quadrature;
pub mod beckmann_albedo;
pub mod compensation;
pub mod cost;
pub mod dielectric;
pub mod dielectric_average;
pub mod dielectric_reference;
pub mod estimate;
pub mod grazing;
pub mod qmc;
pub mod quantity;
pub mod reference;
pub mod sheen;
pub mod sobol;
pub mod value;
pub mod walk;

/// The quadrature rules, at home in [`crate::numerics`].
pub use crate::numerics::{gauss_kronrod, gauss_legendre};

pub use albedo::{albedo, average_albedo};
pub use estimate::Estimate;
pub use qmc::QmcSettings;

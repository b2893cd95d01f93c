//! Integration: Owen-scrambled Sobol points and the QMC albedo estimators.

pub mod albedo;
pub mod average_quadrature;
pub mod dielectric;
pub mod estimate;
pub mod gauss_kronrod;
pub mod gauss_legendre;
pub mod quantity;
pub mod reference;
pub mod sheen;
pub mod sobol;
pub mod value;

pub use albedo::{QmcSettings, albedo, average_albedo};
pub use estimate::Estimate;

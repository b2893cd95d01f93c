//! Numerics below the physics: quadrature rules that the models (the Fresnel average, the
//! Disney diffuse albedo), the integrators and the tables all use. Nothing here knows about
//! microfacets.

pub mod bisection;
pub mod elementary;
pub mod gauss_kronrod;
pub mod gauss_legendre;
pub mod minimax;
pub mod simplex;

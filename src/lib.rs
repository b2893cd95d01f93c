//! kiln: bakes the lookup tables energy-conserving microfacet materials need.
pub mod integrate;
pub mod model;

//! The lobe of the microsurface walk: the BRDF of each order of scattering at given exit
//! directions, by next-event estimation.
//!
//! At every vertex of a walk the ray, arriving from `v` (unit; below the horizon when it was
//! travelling up) at a height with `ln C1 = l`, reflects into a direction `o` with the density
//! of the phase function `p(v -> o) = D(m) / (4 A(v))`, `m` the half vector of `v` and `o` and
//! `A(v) = v.z (1 + Lambda(v))` the microsurface's area projected along `v` (visible normals
//! `(v.m)+ D(m) / A(v)` times the reflection's Jacobian `1 / (4 o.m)`, `o.m = v.m`), and leaves
//! from there with probability `C1^Lambda(o)` (Heitz, Hanika, d'Eon and Dachsbacher 2016,
//! "Multiple-Scattering Microfacet BSDFs with the Smith Model", sections 4 and 5). The energy
//! leaving after vertex `k` per unit solid angle is the expectation of the throughput before the
//! vertex times `p(v -> o) C1^Lambda(o)`, and the BRDF of order `k` is that over `o.z`. The walk
//! itself goes on as [`super::conductor`] draws it: next-event estimation only reads it.
//!
//! The first order is the height-correlated Smith BRDF `D G2 / (4 mu_i mu_o)` exactly (the
//! expectation of `C1^Lambda(o)` over the first hit's height is `(1 + Lambda(i)) G2`); the test
//! measures it against that closed form.
//!
//! Two kinds of exit direction: fixed ones, `(mu_o, phi)` with `phi` the azimuth from the
//! view's plane (0: back towards the light's side, `pi`: the mirror direction's side); and the
//! average over the azimuth at each `mu_o`, taken over `strata` azimuths `pi (j + u) / strata`
//! with one uniform `u` per walk (stratified, so its expectation is the average exactly: the
//! lobe is even in `phi`).

use super::random::WalkRandom;
use crate::model::fresnel::Fresnel;
use crate::model::ndf::MicrofacetDistribution;
use crate::model::vector::Vec3;
use std::f64::consts::PI;

/// Where to evaluate the lobe.
#[derive(Clone, Debug, PartialEq)]
pub struct LobeGrid {
    /// Exit cosines, each in `(0, 1]`.
    pub mus: Vec<f64>,
    /// Exit azimuths in `[0, pi]` (radians) from the view's plane, 0 on the view's side.
    pub azimuths: Vec<f64>,
    /// Azimuths per walk for the averages over the azimuth (at least 1).
    pub strata: u32,
}

impl LobeGrid {
    /// Most exit directions a walk may evaluate at each vertex.
    pub const MAX_DIRECTIONS: usize = 4096;

    /// Fixed directions, then averaged cosines: how many sums each order needs.
    #[must_use]
    pub fn slots(&self) -> usize {
        self.mus.len() * self.azimuths.len() + self.mus.len()
    }
}

/// A grid made ready for the walk: each exit direction and its `Lambda`.
#[derive(Clone, Debug)]
pub struct LobeTargets {
    fixed: Vec<(Vec3, f64)>,
    /// `(mu_o, sin theta_o, Lambda(o))` for each averaged cosine.
    averaged: Vec<(f64, f64, f64)>,
    strata: u32,
    /// The Fresnel factor at the last vertex (its first channel), or `None` for `F = 1`.
    fresnel: Option<Fresnel>,
}

impl LobeTargets {
    /// The exit directions of `grid` for `ndf`, with `fresnel` at every vertex (its first
    /// channel; [`Fresnel::None`] for `F = 1`).
    pub fn new<N: MicrofacetDistribution>(ndf: &N, grid: &LobeGrid, fresnel: &Fresnel) -> Self {
        let fixed = grid
            .mus
            .iter()
            .flat_map(|&mu| {
                grid.azimuths.iter().map(move |&phi| {
                    let s = ((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt();
                    Vec3::new(s * phi.cos(), s * phi.sin(), mu)
                })
            })
            .map(|o| (o, ndf.lambda(o)))
            .collect();
        let averaged = grid
            .mus
            .iter()
            .map(|&mu| {
                let o = Vec3::from_mu(mu);
                (mu, o.x, ndf.lambda(o))
            })
            .collect();
        Self {
            fixed,
            averaged,
            strata: grid.strata.max(1),
            fresnel: (*fresnel != Fresnel::None).then_some(*fresnel),
        }
    }

    /// Sums per order (`slots` for the first order, then as many for the later ones).
    #[must_use]
    pub fn slots(&self) -> usize {
        self.fixed.len() + self.averaged.len()
    }

    /// This walk's azimuths for the averages: `(cos, sin)` of `pi (j + u) / strata`, `u` drawn
    /// from the walk's own key so that the walk's numbers are untouched.
    #[must_use]
    pub fn rotations(&self, random: &WalkRandom<'_>) -> Vec<(f64, f64)> {
        let u = random.side_uniform(0x4c4f_4245);
        (0..self.strata)
            .map(|j| {
                let phi = PI * (f64::from(j) + u) / f64::from(self.strata);
                (phi.cos(), phi.sin())
            })
            .collect()
    }

    /// Whether the lobe carries a Fresnel factor (the walk then passes its Fresnel-weighted
    /// throughput).
    #[must_use]
    pub fn has_fresnel(&self) -> bool {
        self.fresnel.is_some()
    }

    /// Adds the next-event estimates of vertex `vertex` (1 for the first) to `sums`: arriving
    /// from `v` with throughput `throughput` (Fresnel-weighted if [`Self::has_fresnel`]) at
    /// `ln C1 = log_c1`; the reflection towards `o` picks up the Fresnel factor at the half
    /// vector's cosine `v.m = sqrt((1 + v.o) / 2)`.
    #[allow(clippy::too_many_arguments)]
    pub fn add<N: MicrofacetDistribution>(
        &self,
        ndf: &N,
        v: Vec3,
        log_c1: f64,
        throughput: f64,
        vertex: u32,
        rotations: &[(f64, f64)],
        sums: &mut [f64],
    ) {
        // 4 A(v), signed: v.z (1 + Lambda(v)) above the horizon, |v.z| Lambda(v) below.
        let area = 4.0 * ndf.projected_area(v.z);
        if area <= 0.0 || !area.is_finite() {
            return;
        }
        let slots = self.slots();
        let sums = if vertex == 1 {
            &mut sums[..slots]
        } else {
            &mut sums[slots..]
        };
        let weight = throughput / area;
        let contribution = |o: Vec3, lambda: f64| {
            let z = v.z + o.z;
            if z <= 0.0 {
                return 0.0;
            }
            // tan^2 of the half vector from its unnormalised components: no cancellation.
            let (x, y) = (v.x + o.x, v.y + o.y);
            let d = ndf.d_from_tan2((x * x + y * y) / (z * z));
            let escape = if log_c1 == 0.0 {
                1.0
            } else {
                (lambda * log_c1).exp()
            };
            let reflectance = self
                .fresnel
                .as_ref()
                .map_or(1.0, |f| reflectance_at_half(f, v, o));
            weight * d * escape * reflectance
        };
        let (fixed, averaged) = sums.split_at_mut(self.fixed.len());
        for (sum, &(o, lambda)) in fixed.iter_mut().zip(&self.fixed) {
            *sum += contribution(o, lambda) / o.z;
        }
        let share = 1.0 / rotations.len() as f64;
        for (sum, &(mu, s, lambda)) in averaged.iter_mut().zip(&self.averaged) {
            let total: f64 = rotations
                .iter()
                .map(|&(c, sn)| contribution(Vec3::new(s * c, s * sn, mu), lambda))
                .sum();
            *sum += total * share / mu;
        }
    }
}

/// The height-correlated Smith BRDF `D(h) / (4 mu_i mu_o (1 + Lambda(i) + Lambda(o)))` from `i`
/// to `o` (both above the surface; Heitz 2014, eq. 99), the walk's first order in closed form.
#[must_use]
pub fn single_scattering<N: MicrofacetDistribution>(ndf: &N, i: Vec3, o: Vec3) -> f64 {
    let (x, y, z) = (i.x + o.x, i.y + o.y, i.z + o.z);
    let d = ndf.d_from_tan2((x * x + y * y) / (z * z));
    d / (4.0 * i.z * o.z * (1.0 + ndf.lambda(i) + ndf.lambda(o)))
}

/// [`single_scattering`] times `fresnel`'s first channel at the half vector's cosine, averaged
/// over the exit's azimuth (midpoint rule on `[0, pi]` with `nodes` nodes: the lobe is even and
/// periodic in the azimuth, so the rule converges geometrically once it resolves the specular
/// peak, about `alpha` wide).
#[must_use]
pub fn single_scattering_averaged<N: MicrofacetDistribution>(
    ndf: &N,
    mu_i: f64,
    mu_o: f64,
    fresnel: &Fresnel,
    nodes: usize,
) -> f64 {
    let i = Vec3::from_mu(mu_i);
    let s = ((1.0 - mu_o) * (1.0 + mu_o)).max(0.0).sqrt();
    (0..nodes)
        .map(|k| {
            let phi = PI * (k as f64 + 0.5) / nodes as f64;
            let o = Vec3::new(s * phi.cos(), s * phi.sin(), mu_o);
            single_scattering(ndf, i, o) * reflectance_at_half(fresnel, i, o)
        })
        .sum::<f64>()
        / nodes as f64
}

/// `fresnel`'s first channel at the cosine of `i` and the half vector of `i` and `o`,
/// `sqrt((1 + i.o) / 2)` (1 for [`Fresnel::None`]).
#[must_use]
pub fn reflectance_at_half(fresnel: &Fresnel, i: Vec3, o: Vec3) -> f64 {
    match fresnel {
        Fresnel::None => 1.0,
        f => f.reflectance((0.5 * (1.0 + i.dot(o))).max(0.0).sqrt())[0],
    }
}

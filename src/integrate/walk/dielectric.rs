//! One random walk on a rough dielectric interface (Heitz, Hanika, d'Eon and Dachsbacher 2016,
//! "Multiple-Scattering Microfacet BSDFs with the Smith Model", ACM TOG 35(4), section 6 and
//! algorithm 3): the truth that a glass material's energy compensation stands for.
//!
//! The ray starts above the interface travelling down along `-w_i`. At each vertex it meets a
//! microfacet, draws its normal `m` from the normals visible from `v = -w` (below the horizon
//! when the ray was travelling up), and is reflected with probability `F(v.m)`, the exact
//! dielectric Fresnel of the relative index `eta = n_other / n_current`
//! ([`crate::model::fresnel::dielectric`]), or refracted ([`crate::model::dielectric::refract`]).
//! A refracted ray goes on in the other medium, where it sees the same microsurface from the
//! other side: the walk turns its frame over (`w -> -w`: for an isotropic distribution a half
//! turn about a tangent axis), the relative index becomes `1 / eta`, and a point at which a
//! fraction `C1` of the surface lies below it on one side has `1 - C1` below it on the other.
//! The walk therefore carries `l = ln C1` of the side it is on and turns it over as
//! `l -> ln(1 - e^l)` (`ln(-expm1(l))`, exact at both ends): no height distribution appears at
//! all (the conductor's walk is the same for every one, [`super::heights`]). Travelling up
//! from `l` on its side the ray leaves with probability `e^(Lambda(w) l)`, tallied as reflected
//! on the light's side and transmitted on the other (the expected-value estimator of
//! [`super::conductor`], with its Russian roulette); travelling down it always hits, at
//! `l + ln(u) / (1 + Lambda(w))`.
//!
//! Every choice is drawn with its probability (reflect or refract, where the light goes on), so
//! the walk carries energy, not radiance: what it measures is the *energy* albedo, the
//! convention of kiln's glass tables (`model::dielectric`), and with no absorption what leaves on
//! both sides sums to 1. Its first order is the single scattering of the Smith microsurface:
//! reflection `F G2 / G1(o)` with `G2 = 1 / (1 + Lambda(o) + Lambda(i))`, as renderers and kiln's
//! tables evaluate it, but transmission `(1 - F) (1 + Lambda(o)) B(1 + Lambda(o), 1 + Lambda(i))`
//! (Heitz 2014, "Understanding the Masking-Shadowing Function", section 6: a refracted ray must
//! leave through the part of the surface *above* its height), where renderers (and kiln's
//! tables, for them) use `1 / (1 + Lambda(o) + Lambda(i))`: at an index-matched interface
//! (`eta = 1`, every ray straight through) with `Lambda = 1` the walk's first order transmits
//! `2 B(2, 2) = 1/3`, the renderers' form `2/3`.

use super::conductor::{ROULETTE, survives};
use super::heights::{log_c1_of_hit_above, log_c1_of_hit_below};
use super::random::WalkRandom;
use crate::model::dielectric::refract;
use crate::model::fresnel::dielectric as fresnel;
use crate::model::ndf::MicrofacetDistribution;
use crate::model::vector::Vec3;

/// The sides of the interface a walk leaves on.
pub const REFLECTED: usize = 0;
/// See [`REFLECTED`].
pub const TRANSMITTED: usize = 1;

/// What a set of dielectric walks leaves: sums over the walks, `[reflected, transmitted]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DielectricTallies {
    /// The energy that left after the first vertex, on each side.
    pub single: [f64; 2],
    /// The energy that left after any number of vertices, on each side.
    pub all: [f64; 2],
    /// Vertices visited, over all walks.
    pub vertices: u64,
}

impl DielectricTallies {
    /// Adds `other`'s sums to these.
    pub fn add(&mut self, other: &DielectricTallies) {
        for side in [REFLECTED, TRANSMITTED] {
            self.single[side] += other.single[side];
            self.all[side] += other.all[side];
        }
        self.vertices += other.vertices;
    }
}

/// The closest `ln C1` below 0 a walk keeps: at `l = 0` (the very top of one side) the other
/// side's `ln(1 - e^l)` would be `-inf`, from which no ray could climb.
const TOP: f64 = -1e-300;

/// `ln C1` of the same point seen from the other side of the surface: `ln(1 - e^l)`, in the
/// form that keeps every digit at both ends (Maechler 2012, "Accurately Computing
/// log(1 - exp(-|a|))": `ln(-expm1(l))` near the top, `ln_1p(-e^l)` below `-ln 2`).
#[inline]
fn turned_over(l: f64) -> f64 {
    let l = l.min(TOP);
    let other = if l > -std::f64::consts::LN_2 {
        (-l.exp_m1()).ln()
    } else {
        (-l.exp()).ln_1p()
    };
    other.min(TOP)
}

/// Walks once from the incident direction `wi` (unit, `wi.z > 0`) through an interface of
/// relative index `eta = n_inside / n_outside` (the light arrives from outside; `eta < 1` is
/// light leaving a denser medium) and adds what leaves to `tallies`. Returns whether the walk
/// reached [`super::conductor::MAX_VERTICES`] (the caller then refuses the point).
pub fn walk<N: MicrofacetDistribution>(
    ndf: &N,
    wi: Vec3,
    eta: f64,
    random: &mut WalkRandom<'_>,
    tallies: &mut DielectricTallies,
) -> bool {
    let mirror = ndf.alpha() == 0.0;
    let mut side = REFLECTED;
    let mut relative = eta;
    let mut throughput = 1.0;
    let mut w = Vec3::new(-wi.x, -wi.y, -wi.z);
    let mut l = log_c1_of_hit_below(0.0, ndf.lambda(wi), random.uniform()).min(TOP);
    let mut vertex: u32 = 0;
    loop {
        vertex += 1;
        tallies.vertices += 1;
        let v = Vec3::new(-w.x, -w.y, -w.z);
        let normal = [random.uniform(), random.uniform()];
        let m = if mirror {
            Vec3::new(0.0, 0.0, 1.0)
        } else {
            ndf.sample_visible_normal(v, normal)
        };
        let cosine = v.dot(m).clamp(0.0, 1.0);
        let reflectance = fresnel(relative, cosine);
        let refracted = if random.uniform() < reflectance {
            None
        } else {
            refract(v, m, cosine, relative)
        };
        match refracted {
            None => w = v.reflect(m).normalize(),
            Some(t) => {
                // The other side's frame: turned over.
                w = Vec3::new(-t.x, -t.y, -t.z).normalize();
                l = turned_over(l);
                side = 1 - side;
                relative = 1.0 / relative;
            }
        }
        if w.z > 0.0 || mirror {
            let lambda = ndf.lambda(w);
            let escape = if mirror { 1.0 } else { (lambda * l).exp() };
            if vertex == 1 {
                tallies.single[side] += throughput * escape;
            }
            tallies.all[side] += throughput * escape;
            if escape >= 1.0 {
                return false;
            }
            throughput *= 1.0 - escape;
            // A hit above l given no escape (as the conductor's walk).
            let u = random.uniform();
            l = log_c1_of_hit_above(l, lambda, escape, u).min(TOP);
        } else {
            l = log_c1_of_hit_below(l, ndf.lambda(w), random.uniform()).min(TOP);
        }
        // A walk this long refuses its point (`WalkError::Unresolved`): nothing is set aside.
        if vertex >= super::conductor::MAX_VERTICES {
            return true;
        }
        if throughput < ROULETTE {
            if survives(throughput, random).is_none() {
                return false;
            }
            throughput = ROULETTE;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Turning over twice gives the point back, and the two sides' fractions sum to 1 (a slip
    /// in the sign or in `expm1` moves every refracted ray).
    #[test]
    fn turning_over_is_an_involution_of_the_two_fractions() {
        for l in [
            -1e-200,
            -1e-12,
            -1e-3,
            -0.3,
            -std::f64::consts::LN_2,
            -2.0,
            -30.0,
            -400.0,
        ] {
            let other = turned_over(l);
            assert!((l.exp() + other.exp() - 1.0).abs() < 1e-15, "{l}: {other}");
            // Deep on one side is near the top of the other, to every digit.
            // (`ln(1 - x) = -x - x^2 / 2 - x^3 / 3 - ...`, to 1e-16 at x = e^-8).
            if l < -8.0 {
                let x = l.exp();
                let series = -x * (1.0 + x * (0.5 + x / 3.0));
                assert!((other / series - 1.0).abs() < 1e-15, "{l}: {other}");
            }
            // Back again, to the rounding of `exp` at the other side's `ln C1` (its condition
            // number is the argument: 460 at l = -1e-200).
            let back = turned_over(other);
            assert!(
                (back - l).abs() <= 4e-16 * other.abs().max(1.0) * l.abs(),
                "{l} -> {other} -> {back}"
            );
        }
        // The middle of the surface is the middle from both sides.
        assert!((turned_over(0.5f64.ln()) - 0.5f64.ln()).abs() < 1e-15);
    }
}

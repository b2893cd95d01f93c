//! One random walk on a conductor's microsurface (Heitz, Hanika, d'Eon and Dachsbacher 2016,
//! "Multiple-Scattering Microfacet BSDFs with the Smith Model", ACM TOG 35(4), algorithm 2),
//! with the escape taken as its expectation at every vertex.
//!
//! The ray starts above the surface travelling down along `-w_i`. At each vertex it meets a
//! microfacet at height `h`, draws the facet's normal `m` from the normals visible from
//! `v = -w` (the direction it came from; **below the horizon** when the ray was travelling up,
//! which [`crate::model::Ggx::sample_visible_normal`]'s spherical cap accepts), reflects about
//! `m` and picks up `F(v.m)`. Travelling up from `h` it escapes with probability
//! `P = C1(h)^Lambda(w)` (section 4.2); the walk tallies `P` times its throughput to the order
//! just completed (the expected-value estimator: no escape is ever sampled, so every order's
//! estimate is smooth in the walk's numbers) and goes on with the throughput times `1 - P`, to
//! a hit drawn from the heights below `h` given that it does not escape. Travelling down it
//! always hits, at `ln C1(h') = ln C1(h) + ln(u) / (1 + Lambda(-w))` (`Lambda(w) = -1 -
//! Lambda(-w)` for a downward `w`, section 4.1).

use super::heights::{Heights, log_c1_of_hit_above, log_c1_of_hit_below};
use super::lobe::LobeTargets;
use super::random::WalkRandom;
use crate::model::fresnel::{Fresnel, Rgb};
use crate::model::ndf::MicrofacetDistribution;
use crate::model::vector::Vec3;

/// Below this throughput (with `F = 1`) a walk that must go on plays Russian roulette: it ends
/// with probability `1 - t / ROULETTE`, else goes on with its throughput raised to `ROULETTE`.
/// Unbiased; the tail beyond it is at most a thousandth of the energy.
pub const ROULETTE: f64 = 1e-3;

/// Russian roulette for a walk whose throughput `t` fell below [`ROULETTE`]: `Some` of its
/// probability of going on, `t / ROULETTE`, when it goes on (the caller raises its throughput
/// to [`ROULETTE`], dividing what it carries beside by that probability), `None` when it ends.
/// Both walks play it.
#[inline]
pub(super) fn survives(t: f64, random: &mut WalkRandom<'_>) -> Option<f64> {
    let survive = t / ROULETTE;
    (random.uniform() < survive).then_some(survive)
}

/// The most vertices a walk may have: far beyond any walk that ends (at `alpha = 1000` and
/// normal incidence walks average 3,100 vertices and none of 2^18 reached 2^16, `kiln eval
/// --quantity e-multiple --f0 1 --alpha 1000 --mu 1 --walks 2^18`, 2026-12-07; Russian roulette
/// ends the rest). A walk that reaches it is a ray skimming a near-mirror surface (`mu` and
/// `alpha` both near 0, every bounce leaving it nearly tangent), which the walk cannot resolve:
/// the point is refused ([`super::WalkError::Unresolved`]) at the first such walk, rather than
/// answered with the energy set aside after minutes.
pub const MAX_VERTICES: u32 = 1 << 16;

/// The highest power of `F0` the walk's albedo polynomial keeps (see [`Tallies::polynomial`]);
/// a walk with more vertices sets the higher powers aside as dropped (at `F0 = 1`).
pub const MAX_DEGREE: usize = 64;

/// What a set of walks leaves: sums over the walks.
#[derive(Clone, Debug, PartialEq)]
pub struct Tallies {
    /// `orders[k - 1]`: the energy that left after exactly `k` vertices (`F = 1`).
    pub orders: Vec<f64>,
    /// The energy that left after more vertices than `orders` holds (`F = 1`).
    pub beyond: f64,
    /// The energy that left, every order, with the Fresnel factor of every vertex (per channel).
    pub albedo: Rgb,
    /// With Schlick's Fresnel of unknown `F0` (and a given `F90`): the albedo of every order
    /// as a polynomial in `F0`, `polynomial[j]` the coefficient of `F0^j` (Hill 2019, "A
    /// Multi-Faceted Exploration (Part 4)": one throughput per power of `F0`); empty when not
    /// asked for. All coefficients are non-negative.
    pub polynomial: Vec<f64>,
    /// The throughput set aside by [`MAX_VERTICES`] (per channel, with Fresnel), and by
    /// [`MAX_DEGREE`] in the polynomial (at `F0 = 1`, in channel 0).
    pub dropped: Rgb,
    /// Vertices visited, over all walks.
    pub vertices: u64,
    /// With exit directions asked for ([`LobeTargets`]): the next-event sums of the first order
    /// at each direction, then those of every later order; empty when not asked for.
    pub lobe: Vec<f64>,
}

impl Tallies {
    /// Empty tallies for `orders` orders, with the `F0` polynomial or not, and `lobe_slots`
    /// exit directions (0 for none).
    #[must_use]
    pub fn new(orders: usize, polynomial: bool, lobe_slots: usize) -> Self {
        Self {
            orders: vec![0.0; orders],
            beyond: 0.0,
            albedo: [0.0; 3],
            polynomial: if polynomial {
                vec![0.0; MAX_DEGREE + 1]
            } else {
                Vec::new()
            },
            dropped: [0.0; 3],
            vertices: 0,
            lobe: vec![0.0; 2 * lobe_slots],
        }
    }

    /// Adds `other`'s sums to these.
    pub fn add(&mut self, other: &Tallies) {
        for (a, b) in self.orders.iter_mut().zip(&other.orders) {
            *a += b;
        }
        self.beyond += other.beyond;
        for (a, b) in self.polynomial.iter_mut().zip(&other.polynomial) {
            *a += b;
        }
        for (a, b) in self.lobe.iter_mut().zip(&other.lobe) {
            *a += b;
        }
        for j in 0..3 {
            self.albedo[j] += other.albedo[j];
            self.dropped[j] += other.dropped[j];
        }
        self.vertices += other.vertices;
    }
}

/// The probability that an upward direction with `Lambda = lambda` leaves the microsurface from
/// the height of `ln C1 = log_c1`: `C1^Lambda` (Heitz et al. 2016). At the very top (a grazing
/// entry that met the surface at once) and on a mirror every upward direction leaves; `inf * 0`
/// would say otherwise.
#[inline(always)]
fn escape_probability(lambda: f64, log_c1: f64, mirror: bool) -> f64 {
    if log_c1 == 0.0 || mirror {
        1.0
    } else {
        (lambda * log_c1).exp()
    }
}

/// What is tallied as leaving at an upward vertex whose escape has `probability`: the
/// probability itself ([`super::Escape::Expected`]), or, for the analog walk, all of the
/// throughput or none of it, drawn.
#[inline(always)]
fn escaped_share(escape: super::Escape, probability: f64, random: &mut WalkRandom<'_>) -> f64 {
    match escape {
        super::Escape::Expected => probability,
        super::Escape::Sampled if probability >= 1.0 => 1.0,
        super::Escape::Sampled => {
            if random.uniform() < probability {
                1.0
            } else {
                0.0
            }
        }
    }
}

/// What a walk tallies beside the orders.
#[derive(Clone, Copy, Debug)]
pub struct Asked<'a> {
    /// The Fresnel model at every vertex, for the albedo ([`Fresnel::None`]: `F = 1` only).
    pub fresnel: &'a Fresnel,
    /// Schlick's `F90`, to carry the albedo as a polynomial in `F0`.
    pub schlick_f90: Option<f64>,
    /// Exit directions at which to estimate the lobe ([`super::lobe`]).
    pub lobe: Option<&'a LobeTargets>,
    /// Escapes tallied as their expectation or drawn.
    pub escape: super::Escape,
}

/// Walks once from the incident direction `wi` (unit, `wi.z > 0`) and adds what leaves to
/// `tallies`. With `asked.fresnel` equal to [`Fresnel::None`] (and no polynomial or lobe) the
/// walk stops after the last order tallied and puts what it still carries into `beyond` (with
/// `F = 1` every walk leaves in the end, so that is exactly the expected energy of the later
/// orders); otherwise it goes on to the end for the Fresnel-weighted albedo. With
/// `asked.schlick_f90`, and `tallies` made with a polynomial, the walk also carries Schlick's
/// Fresnel `F0 + (F90 - F0) (1 - c)^5` as a polynomial in `F0`; with `asked.lobe` it adds the
/// next-event estimates of the lobe at every vertex. Returns whether the walk reached
/// [`MAX_VERTICES`].
pub fn walk<N: MicrofacetDistribution>(
    ndf: &N,
    wi: Vec3,
    asked: &Asked<'_>,
    heights: Heights,
    random: &mut WalkRandom<'_>,
    tallies: &mut Tallies,
) -> bool {
    let fresnel = asked.fresnel;
    let polynomial = asked.schlick_f90.filter(|_| !tallies.polynomial.is_empty());
    let lobe = asked.lobe.filter(|_| !tallies.lobe.is_empty());
    let rotations = lobe.map(|l| l.rotations(random)).unwrap_or_default();
    let to_the_end = *fresnel != Fresnel::None || polynomial.is_some() || lobe.is_some();
    // The throughput's coefficients of F0^0 ..= F0^degree.
    let mut coefficients = [0.0; MAX_DEGREE + 1];
    coefficients[0] = 1.0;
    let mut degree = 0;
    let tallied = tallies.orders.len() as u32;
    // Throughput with F = 1 (for the orders) and with the Fresnel factors (per channel).
    let mut plain = 1.0;
    let mut coloured: Rgb = [1.0; 3];
    // The first hit, travelling down from above the surface (ln C1 = 0).
    let mut w = Vec3::new(-wi.x, -wi.y, -wi.z);
    let mut h = heights.height(log_c1_of_hit_below(0.0, ndf.lambda(wi), random.uniform()));
    let mut vertex = 0;
    loop {
        vertex += 1;
        tallies.vertices += 1;
        let log_c1 = heights.log_c1(h);
        let v = Vec3::new(-w.x, -w.y, -w.z);
        if let Some(lobe) = lobe {
            let throughput = if lobe.has_fresnel() {
                coloured[0]
            } else {
                plain
            };
            lobe.add(
                ndf,
                v,
                log_c1,
                throughput,
                vertex,
                &rotations,
                &mut tallies.lobe,
            );
        }
        let mirror = ndf.alpha() == 0.0;
        let m = if mirror {
            // Every microfacet faces up (and a tangent view has no visible normal to sample).
            let _ = [random.uniform(), random.uniform()];
            Vec3::new(0.0, 0.0, 1.0)
        } else {
            ndf.sample_visible_normal(v, [random.uniform(), random.uniform()])
        };
        let cosine = v.dot(m);
        if let Some(f90) = polynomial {
            // Times F0 (1 - s) + F90 s, s = (1 - c)^5: every coefficient moves up a power.
            let s = (1.0 - cosine.clamp(0.0, 1.0)).powi(5);
            let (a, b) = (1.0 - s, f90 * s);
            if degree == MAX_DEGREE {
                tallies.dropped[0] += a * coefficients[MAX_DEGREE];
            } else {
                degree += 1;
                coefficients[degree] = 0.0;
            }
            for j in (1..=degree).rev() {
                coefficients[j] = a * coefficients[j - 1] + b * coefficients[j];
            }
            coefficients[0] *= b;
        }
        if *fresnel != Fresnel::None {
            let f = fresnel.reflectance(cosine);
            for (c, f) in coloured.iter_mut().zip(f) {
                *c *= f;
            }
        }
        w = v.reflect(m).normalize();
        // A mirror (alpha = 0) reflects once, and the reflection leaves: at `mu = 0` it runs
        // along the surface (`w.z = 0`), which the walk would otherwise follow for
        // `MAX_VERTICES` steps.
        if w.z > 0.0 || mirror {
            let lambda = ndf.lambda(w);
            let probability = escape_probability(lambda, log_c1, mirror);
            let escape = escaped_share(asked.escape, probability, random);
            if vertex <= tallied {
                tallies.orders[vertex as usize - 1] += plain * escape;
            } else {
                tallies.beyond += plain * escape;
            }
            for (a, c) in tallies.albedo.iter_mut().zip(coloured) {
                *a += c * escape;
            }
            if polynomial.is_some() {
                for (t, c) in tallies.polynomial.iter_mut().zip(&coefficients[..=degree]) {
                    *t += c * escape;
                }
            }
            if escape >= 1.0 {
                return false;
            }
            plain *= 1.0 - escape;
            for c in &mut coloured {
                *c *= 1.0 - escape;
            }
            for c in &mut coefficients[..=degree] {
                *c *= 1.0 - escape;
            }
            // A hit below h given no escape: C1(h') = C1(h) / (1 - u (1 - P))^(1 / Lambda),
            // with P the escape's probability (also when the escape was drawn).
            let u = random.uniform();
            h = heights.height(log_c1_of_hit_above(log_c1, lambda, probability, u));
        } else {
            h = heights.height(log_c1_of_hit_below(log_c1, ndf.lambda(w), random.uniform()));
        }
        if !to_the_end && vertex == tallied {
            tallies.beyond += plain;
            return false;
        }
        if vertex >= MAX_VERTICES {
            for (d, c) in tallies.dropped.iter_mut().zip(coloured) {
                *d += c;
            }
            if polynomial.is_some() {
                tallies.dropped[0] += coefficients[..=degree].iter().sum::<f64>();
            }
            return true;
        }
        if plain < ROULETTE {
            let Some(survive) = survives(plain, random) else {
                return false;
            };
            plain = ROULETTE;
            for c in &mut coloured {
                *c /= survive;
            }
            for c in &mut coefficients[..=degree] {
                *c /= survive;
            }
        }
    }
}

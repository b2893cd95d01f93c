//! The microsurface random walk: the light a microfacet conductor reflects after any number of
//! bounces between its facets, the ground truth that energy compensation stands for.
//!
//! Heitz, Hanika, d'Eon and Dachsbacher 2016, "Multiple-Scattering Microfacet BSDFs with the
//! Smith Model" (ACM TOG 35(4)): under Smith's assumptions (uncorrelated heights and normals)
//! a ray on the microsurface is a walk in height whose free paths follow from `Lambda` and
//! whose vertices draw visible normals. Its first order is exactly the height-correlated Smith
//! BRDF (`E`); the orders after it are what the single-scattering BRDF loses and Kulla-Conty's
//! lobe (or Turquin's scaling) puts back. `docs/multiple-scattering.md` says what the walk
//! measures; [`conductor`] is one walk, [`walk_albedo`] many, in parallel and deterministic.
//!
//! Estimates: each scramble of the Owen-scrambled Sobol points (the first two vertices; a
//! counter-seeded generator after them) is an independent replicate, and the standard error is
//! their spread ([`crate::integrate::Estimate::from_replicates`]), as for kiln's QMC. Walks are
//! summed in fixed chunks in a fixed order: the same settings give the same bits on any number
//! of threads.

pub mod conductor;
pub mod dielectric;
pub mod heights;
pub mod lobe;
pub mod random;

pub use conductor::Tallies;
pub use heights::Heights;

use crate::integrate::sobol::{OwenSobol, mix_seed};
use crate::model::fresnel::Fresnel;
use crate::model::ndf::{Beckmann, Ggx};
use crate::model::vector::Vec3;
use crate::model::{Masking, Model, Ndf};
use rayon::prelude::*;

/// The largest order `e_k` kiln tallies one by one (later ones are summed as `beyond`).
pub const MAX_ORDER: usize = 64;

/// Walks per chunk: the unit of parallel work and of the fixed summation order.
const CHUNK: u32 = 4096;

/// How many walks, and from which numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkSettings {
    /// Walks in all, a power of two, split evenly over the scrambles.
    pub walks: u64,
    /// Independent scrambles (replicates) for the standard error: a power of two, 2 to 1024.
    pub scrambles: u32,
    /// Base seed of the scrambles.
    pub seed: u64,
    /// The microsurface's height distribution (the walk's result does not depend on it).
    pub heights: Heights,
    /// The walk's numbers: scrambled Sobol for the first vertices, or pseudorandom throughout
    /// (the benchmark's comparison).
    pub numbers: Numbers,
    /// How an escape is tallied: its expectation at every vertex, or sampled (the benchmark's
    /// comparison).
    pub escape: Escape,
}

/// Where a walk's numbers come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Numbers {
    /// An Owen-scrambled Sobol point for the first two vertices (a depth and a normal each),
    /// then a counter-seeded generator ([`random::WalkRandom`]).
    #[default]
    Sobol,
    /// The counter-seeded generator for every number.
    Pseudorandom,
}

/// How a walk tallies the light that leaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Escape {
    /// At every upward vertex the escape probability times the throughput is tallied and the
    /// walk goes on with the rest (the expected-value estimator: every order smooth in the
    /// walk's numbers).
    #[default]
    Expected,
    /// The escape is drawn: the walk leaves with all it carries, or goes on with all of it
    /// (the analog walk of Heitz et al. 2016).
    Sampled,
}

impl WalkSettings {
    /// `2^22` walks: a standard error of about `1e-4` on the multiple-scattering albedo of the
    /// roughest GGX (`alpha = 1`), well below it on `e_1`.
    pub const DEFAULT_WALKS: u64 = 1 << 22;
    /// Replicates for the standard error.
    pub const DEFAULT_SCRAMBLES: u32 = 16;
    /// Most walks one request may ask for: `2^36`, hours on two cores.
    pub const MAX_WALKS: u64 = 1 << 36;

    /// Checks the counts, naming the bad one and the range.
    pub fn validate(&self) -> Result<(), WalkError> {
        let s = u64::from(self.scrambles);
        if !self.scrambles.is_power_of_two() || !(2..=1024).contains(&self.scrambles) {
            return Err(WalkError::Scrambles(self.scrambles));
        }
        if !self.walks.is_power_of_two() || self.walks < s || self.walks > Self::MAX_WALKS {
            return Err(WalkError::Walks {
                walks: self.walks,
                scrambles: self.scrambles,
            });
        }
        Ok(())
    }
}

impl Default for WalkSettings {
    fn default() -> Self {
        Self {
            walks: Self::DEFAULT_WALKS,
            scrambles: Self::DEFAULT_SCRAMBLES,
            seed: 0,
            heights: Heights::default(),
            numbers: Numbers::default(),
            escape: Escape::default(),
        }
    }
}

/// Why a walk cannot be run; each names the value and the range.
#[derive(Clone, Debug, PartialEq)]
pub enum WalkError {
    /// `walks` is not a power of two in `[scrambles, 2^36]`.
    Walks { walks: u64, scrambles: u32 },
    /// `scrambles` is not a power of two in `[2, 1024]`.
    Scrambles(u32),
    /// The order asked for is not in `[1, MAX_ORDER]`.
    Order(u64),
    /// `mu` is not in `[0, 1]`.
    Mu(f64),
    /// `alpha` is not in `[0, 1000]` (or is NaN).
    Alpha(f64),
    /// The walk is written for this model's distribution and masking only.
    Model(Model),
    /// `F0` is not in `[0, 1]`.
    F0(f64),
    /// `F90` is not in `[0, 1]`.
    F90(f64),
    /// kiln's compensation is fitted for Schlick's Fresnel with `F90 = 1`; this is another.
    KilnFresnel(String),
    /// A walk from this view did not end within [`conductor::MAX_VERTICES`] vertices.
    Unresolved { alpha: f64, mu: f64 },
    /// A lobe asked of a mirror or from a tangent view: a delta, not a function.
    DeltaLobe { alpha: f64, mu: f64 },
    /// An exit cosine of a lobe not in `(0, 1]`.
    ExitMu(f64),
    /// An exit azimuth of a lobe not in `[0, pi]`.
    Azimuth(f64),
    /// More exit directions than a walk evaluates at each vertex, or none.
    Directions(usize),
    /// kiln's lobe asked for without the table its `M_avg` comes from.
    KilnLobeTable,
    /// A dielectric's relative index not in `[0.01, 100]` (or NaN).
    Eta(f64),
}

impl std::fmt::Display for WalkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use crate::error::shown;
        match self {
            WalkError::Walks { walks, scrambles } => write!(
                f,
                "walks {walks} must be a power of two from the scrambles' {scrambles} to 2^36 \
                 (68719476736)"
            ),
            WalkError::Scrambles(s) => {
                write!(f, "scrambles {s} must be a power of two from 2 to 1024")
            }
            WalkError::Order(k) => write!(
                f,
                "order {k} is out of range: the walk tallies orders 1 to {MAX_ORDER} one by one"
            ),
            WalkError::Mu(mu) => write!(f, "mu {} is out of range [0, 1]", shown(*mu)),
            WalkError::Alpha(a) => write!(f, "alpha {} is out of range [0, 1000]", shown(*a)),
            WalkError::F0(v) => write!(f, "f0 {} is out of range [0, 1]", shown(*v)),
            WalkError::KilnFresnel(what) => write!(
                f,
                "kiln's compensation is fitted for Schlick's Fresnel with F90 = 1 (got {what}): \
                 give --f0 (and --f90 1), or measure kulla-conty and turquin only"
            ),
            WalkError::F90(v) => write!(f, "f90 {} is out of range [0, 1]", shown(*v)),
            WalkError::Unresolved { alpha, mu } => write!(
                f,
                "the walk at alpha {}, mu {} did not end within {} vertices: a ray skimming a \
                 near-mirror surface (mu and alpha both near 0) stays nearly tangent at every \
                 bounce; the walk cannot resolve it (take alpha 0, a mirror, or a larger mu or \
                 alpha)",
                shown(*alpha),
                shown(*mu),
                conductor::MAX_VERTICES
            ),
            WalkError::DeltaLobe { alpha, mu } => write!(
                f,
                "the lobe at alpha {}, mu {} is a delta (a mirror, or light along the surface): \
                 take alpha and mu above 0",
                shown(*alpha),
                shown(*mu)
            ),
            WalkError::ExitMu(mu) => write!(
                f,
                "exit cosine {} is out of range (0, 1]: the lobe is measured above the surface",
                shown(*mu)
            ),
            WalkError::Azimuth(phi) => write!(
                f,
                "exit azimuth {} degrees is out of range [0, 180] (the lobe is even in the \
                 azimuth)",
                shown(phi.to_degrees())
            ),
            WalkError::KilnLobeTable => write!(
                f,
                "kiln's lobe divides by M_avg, which comes from its baked table: give --table \
                 FILE (kiln compensation --bake DIR writes it), or measure kulla-conty and \
                 turquin only"
            ),
            WalkError::Directions(n) => write!(
                f,
                "{n} exit directions a vertex: take 1 to {} (exit cosines times azimuths and \
                 strata)",
                lobe::LobeGrid::MAX_DIRECTIONS
            ),
            WalkError::Eta(eta) => write!(
                f,
                "relative index {} is out of range [0.01, 100] (n_inside / n_outside: 1.5 is \
                 glass seen from air, 1 / 1.5 the same glass seen from inside)",
                shown(*eta)
            ),
            WalkError::Model(model) => write!(
                f,
                "the microsurface walk's masking is its own, height-correlated (uncorrelated \
                 heights and normals, Smith's assumption); {} {} has no walk: take --masking \
                 height-correlated",
                model.ndf, model.masking
            ),
        }
    }
}

impl std::error::Error for WalkError {}

impl From<WalkError> for crate::Error {
    fn from(e: WalkError) -> Self {
        crate::Error::InvalidInput(e.to_string())
    }
}

/// A value the walk estimated, with its standard error.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Measured {
    pub value: f64,
    pub std_error: f64,
}

impl Measured {
    /// The mean and standard error of independent replicate means (`R >= 2`), as kiln's QMC
    /// ([`crate::integrate::estimate::mean_and_std_error`]) but without its clamp to [0, 1].
    #[must_use]
    pub fn from_replicates(means: &[f64]) -> Self {
        let (value, std_error) = crate::integrate::estimate::mean_and_std_error(means);
        Self { value, std_error }
    }
}

/// The mean per walk of what `get` reads from each scramble's sums, with its standard error
/// ([`Measured::from_replicates`]): how every walk's estimate is read from its replicates.
fn per_walk<T>(replicates: &[T], settings: &WalkSettings, get: impl Fn(&T) -> f64) -> Measured {
    let per_scramble = (settings.walks / u64::from(settings.scrambles)) as f64;
    let means: Vec<f64> = replicates.iter().map(|t| get(t) / per_scramble).collect();
    Measured::from_replicates(&means)
}

/// What [`walk_albedo`] measured at one view.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct WalkEstimate {
    /// `e_k` for `k = 1 ..= orders.len()`: the energy (`F = 1`) that leaves after exactly `k`
    /// scattering events.
    pub orders: Vec<Measured>,
    /// The energy of every later order (`F = 1`), so that the orders with it sum to 1.
    pub beyond: Measured,
    /// The directional albedo with the Fresnel model at every vertex, per channel (`E` of the
    /// whole microsurface, every order); with `F = 1`, 1.
    pub albedo: [Measured; 3],
    /// The most energy any channel had set aside by the vertex cap (0 unless a walk reached
    /// `MAX_VERTICES`): a bound on what the albedo is missing.
    pub dropped: f64,
    /// Walks run.
    pub walks: u64,
    /// Mean vertices per walk.
    pub mean_vertices: f64,
}

/// Runs `$body` with `$ndf` bound to the distribution of `$model` at `$alpha` (GGX or
/// Beckmann): each arm is compiled for its distribution.
macro_rules! on_surface {
    ($model:expr, $alpha:expr, |$ndf:ident| $body:expr) => {
        match $model.ndf {
            Ndf::Ggx => {
                let $ndf = &Ggx { alpha: $alpha };
                $body
            }
            Ndf::Beckmann => {
                let $ndf = &Beckmann { alpha: $alpha };
                $body
            }
        }
    };
}

/// Checks a dielectric's relative index: in `[0.01, 100]` (the range `kiln bake --ior` takes).
pub fn check_eta(eta: f64) -> Result<(), WalkError> {
    if (0.01..=100.0).contains(&eta) {
        Ok(())
    } else {
        Err(WalkError::Eta(eta))
    }
}

/// Checks a walk's inputs.
pub fn check_inputs(model: Model, alpha: f64, mu: f64, orders: usize) -> Result<(), WalkError> {
    if model.masking != Masking::HeightCorrelated {
        return Err(WalkError::Model(model));
    }
    if !(0.0..=1000.0).contains(&alpha) {
        return Err(WalkError::Alpha(alpha));
    }
    if !(0.0..=1.0).contains(&mu) {
        return Err(WalkError::Mu(mu));
    }
    if orders > MAX_ORDER {
        return Err(WalkError::Order(orders as u64));
    }
    Ok(())
}

/// Walks `settings.walks` times from the view `mu` on the microsurface of `model` at roughness
/// `alpha` (GGX), tallying orders `1 ..= orders` one by one (at most [`MAX_ORDER`]) and, for a
/// Fresnel model other than [`Fresnel::None`], the Fresnel-weighted albedo of every order.
/// `progress` is told how many walks are done as chunks finish (in any order).
pub fn walk_albedo(
    model: Model,
    alpha: f64,
    mu: f64,
    fresnel: &Fresnel,
    orders: usize,
    settings: &WalkSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<WalkEstimate, WalkError> {
    let replicates = run(
        model, alpha, mu, fresnel, None, None, orders, settings, progress,
    )?;
    let measure = |get: &dyn Fn(&Tallies) -> f64| per_walk(&replicates, settings, get);
    let with_fresnel = *fresnel != Fresnel::None;
    let albedo = std::array::from_fn(|j| {
        if with_fresnel {
            measure(&|t| t.albedo[j])
        } else {
            Measured {
                value: 1.0,
                std_error: 0.0,
            }
        }
    });
    Ok(WalkEstimate {
        orders: (0..orders).map(|k| measure(&|t| t.orders[k])).collect(),
        beyond: measure(&|t| t.beyond),
        albedo,
        dropped: dropped(&replicates, settings),
        walks: settings.walks,
        mean_vertices: replicates.iter().map(|t| t.vertices).sum::<u64>() as f64
            / settings.walks as f64,
    })
}

/// The most any channel set aside, per walk.
fn dropped(replicates: &[Tallies], settings: &WalkSettings) -> f64 {
    (0..3)
        .map(|j| replicates.iter().map(|t| t.dropped[j]).sum::<f64>() / settings.walks as f64)
        .fold(0.0, f64::max)
}

/// The albedo of every order with Schlick's Fresnel `F0 + (F90 - F0) (1 - c)^5` at every
/// vertex, as a polynomial in `F0` for one `F90`: one set of walks for every `F0`.
#[derive(Clone, Debug, PartialEq)]
pub struct SchlickPolynomial {
    /// Each replicate's mean coefficients of `F0^0 ..= F0^MAX_DEGREE`.
    pub replicates: Vec<Vec<f64>>,
    /// `F90`.
    pub f90: f64,
    /// As [`WalkEstimate::dropped`].
    pub dropped: f64,
    /// Walks run.
    pub walks: u64,
}

impl SchlickPolynomial {
    /// The albedo at `f0` in `[0, 1]`, with its standard error.
    #[must_use]
    pub fn albedo(&self, f0: f64) -> Measured {
        let means: Vec<f64> = self
            .replicates
            .iter()
            .map(|c| c.iter().rev().fold(0.0, |sum, &c| sum * f0 + c))
            .collect();
        Measured::from_replicates(&means)
    }
}

/// Walks as [`walk_albedo`] with Schlick's Fresnel of every `F0` at once (see
/// [`SchlickPolynomial`]).
pub fn walk_schlick_polynomial(
    model: Model,
    alpha: f64,
    mu: f64,
    f90: f64,
    settings: &WalkSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<SchlickPolynomial, WalkError> {
    let replicates = run(
        model,
        alpha,
        mu,
        &Fresnel::None,
        Some(f90),
        None,
        0,
        settings,
        progress,
    )?;
    let per_scramble = (settings.walks / u64::from(settings.scrambles)) as f64;
    Ok(SchlickPolynomial {
        replicates: replicates
            .iter()
            .map(|t| t.polynomial.iter().map(|c| c / per_scramble).collect())
            .collect(),
        f90,
        dropped: dropped(&replicates, settings),
        walks: settings.walks,
    })
}

/// The lobe the walk measured from one view ([`walk_lobe`]): BRDF values `f(w_i, w_o)` (not
/// times the cosine), each with its standard error.
#[derive(Clone, Debug, PartialEq)]
pub struct LobeEstimate {
    /// The view's cosine.
    pub mu: f64,
    /// Where the lobe was measured.
    pub grid: lobe::LobeGrid,
    /// The first order at each fixed direction, `grid.mus`-major: `[i_mu * azimuths + i_phi]`.
    pub single: Vec<Measured>,
    /// Every later order, as `single`.
    pub multiple: Vec<Measured>,
    /// The first order averaged over the azimuth, at each of `grid.mus`.
    pub single_averaged: Vec<Measured>,
    /// Every later order averaged over the azimuth, at each of `grid.mus`.
    pub multiple_averaged: Vec<Measured>,
    /// Walks run.
    pub walks: u64,
}

/// Walks as [`walk_albedo`] from the view `mu` and estimates the lobe of the first and of every
/// later order at `grid`'s exit directions by next-event estimation ([`lobe`]), with
/// `fresnel` at every vertex (its first channel; [`Fresnel::None`] for `F = 1`). A mirror's
/// lobe is a delta and is refused.
pub fn walk_lobe(
    model: Model,
    alpha: f64,
    mu: f64,
    grid: &lobe::LobeGrid,
    fresnel: &Fresnel,
    settings: &WalkSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<LobeEstimate, WalkError> {
    check_inputs(model, alpha, mu, 0)?;
    if alpha == 0.0 || mu == 0.0 {
        return Err(WalkError::DeltaLobe { alpha, mu });
    }
    if let Some(&m) = grid.mus.iter().find(|m| !(**m > 0.0 && **m <= 1.0)) {
        return Err(WalkError::ExitMu(m));
    }
    if let Some(&phi) = grid
        .azimuths
        .iter()
        .find(|p| !(0.0..=std::f64::consts::PI).contains(*p))
    {
        return Err(WalkError::Azimuth(phi));
    }
    let directions = grid.mus.len() * (grid.azimuths.len() + grid.strata as usize);
    if grid.mus.is_empty() || directions > lobe::LobeGrid::MAX_DIRECTIONS {
        return Err(WalkError::Directions(directions));
    }
    let replicates = run(
        model,
        alpha,
        mu,
        fresnel,
        None,
        Some(grid),
        0,
        settings,
        progress,
    )?;
    let slots = grid.slots();
    let measure = |slot: usize| per_walk(&replicates, settings, |t| t.lobe[slot]);
    let fixed = grid.mus.len() * grid.azimuths.len();
    Ok(LobeEstimate {
        mu,
        grid: grid.clone(),
        single: (0..fixed).map(measure).collect(),
        multiple: (0..fixed).map(|k| measure(slots + k)).collect(),
        single_averaged: (fixed..slots).map(measure).collect(),
        multiple_averaged: (fixed..slots).map(|k| measure(slots + k)).collect(),
        walks: settings.walks,
    })
}

/// Where the light of a dielectric walk comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// One direction, at the cosine `mu` in `[0, 1]`.
    Mu(f64),
    /// Every direction above the interface, cosine-weighted (`mu = sqrt(u)`, the walk's first
    /// number): the walk then measures the hemispherical averages `2 ∫ x(mu) mu dmu`.
    CosineWeighted,
}

/// What [`walk_dielectric`] measured: energies (fractions of the incident power), each
/// `[reflected, transmitted]`, with standard errors.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DielectricEstimate {
    /// What leaves after the first vertex: the Smith microsurface's single scattering.
    pub single: [Measured; 2],
    /// What leaves after any number of vertices.
    pub all: [Measured; 2],
    /// Walks run.
    pub walks: u64,
    /// Mean vertices per walk.
    pub mean_vertices: f64,
}

/// Walks `settings.walks` times from `view` into a rough dielectric interface of relative
/// index `eta = n_inside / n_outside` (the light arrives from outside; `eta < 1` is light
/// leaving a denser medium) with the microsurface of `model` at roughness `alpha` (GGX), and
/// measures the energy reflected and transmitted ([`dielectric`]).
pub fn walk_dielectric(
    model: Model,
    alpha: f64,
    view: View,
    eta: f64,
    settings: &WalkSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<DielectricEstimate, WalkError> {
    settings.validate()?;
    let mu = match view {
        View::Mu(mu) => mu,
        View::CosineWeighted => 0.5,
    };
    check_inputs(model, alpha, mu, 0)?;
    check_eta(eta)?;
    let replicates = on_surface!(model, alpha, |ndf| scrambled(
        settings,
        &dielectric::DielectricTallies::default,
        &|random, tallies| {
            let wi = match view {
                View::Mu(mu) => Vec3::from_mu(mu),
                View::CosineWeighted => Vec3::from_mu(random.uniform().sqrt()),
            };
            dielectric::walk(ndf, wi, eta, random, tallies)
        },
        dielectric::DielectricTallies::add,
        progress,
    ))
    .ok_or(WalkError::Unresolved { alpha, mu })?;
    let measure =
        |get: &dyn Fn(&dielectric::DielectricTallies) -> f64| per_walk(&replicates, settings, get);
    Ok(DielectricEstimate {
        single: std::array::from_fn(|side| measure(&|t| t.single[side])),
        all: std::array::from_fn(|side| measure(&|t| t.all[side])),
        walks: settings.walks,
        mean_vertices: replicates.iter().map(|t| t.vertices).sum::<u64>() as f64
            / settings.walks as f64,
    })
}

/// Runs the walks and returns each scramble's sums.
#[allow(clippy::too_many_arguments)]
fn run(
    model: Model,
    alpha: f64,
    mu: f64,
    fresnel: &Fresnel,
    schlick_f90: Option<f64>,
    lobe: Option<&lobe::LobeGrid>,
    orders: usize,
    settings: &WalkSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<Tallies>, WalkError> {
    settings.validate()?;
    check_inputs(model, alpha, mu, orders)?;
    if let Some(f90) = schlick_f90
        && !(0.0..=1.0).contains(&f90)
    {
        return Err(WalkError::F90(f90));
    }
    let wi = Vec3::from_mu(mu);
    let replicates = on_surface!(model, alpha, |ndf| {
        let targets = lobe.map(|grid| lobe::LobeTargets::new(ndf, grid, fresnel));
        let lobe_slots = targets.as_ref().map_or(0, lobe::LobeTargets::slots);
        let asked = conductor::Asked {
            fresnel,
            schlick_f90,
            lobe: targets.as_ref(),
            escape: settings.escape,
        };
        scrambled(
            settings,
            &|| Tallies::new(orders, schlick_f90.is_some(), lobe_slots),
            &|random, tallies| conductor::walk(ndf, wi, &asked, settings.heights, random, tallies),
            Tallies::add,
            progress,
        )
    });
    replicates.ok_or(WalkError::Unresolved { alpha, mu })
}

/// Runs `settings.walks` walks, each scramble's in fixed chunks, and returns each scramble's
/// sums in chunk order (the same bits on any number of threads): `walk_once` walks with the
/// numbers it is given and adds to the chunk's tallies (made by `empty`), returning whether the
/// walk reached the vertex cap; `None` if any did (the rest need not run). `progress` is told
/// how many walks are done as chunks finish.
fn scrambled<T: Clone + Send>(
    settings: &WalkSettings,
    empty: &(dyn Fn() -> T + Sync),
    walk_once: &(dyn Fn(&mut random::WalkRandom<'_>, &mut T) -> bool + Sync),
    add: fn(&mut T, &T),
    progress: &(dyn Fn(u64) + Sync),
) -> Option<Vec<T>> {
    let per_scramble = settings.walks / u64::from(settings.scrambles);
    let chunks = per_scramble.div_ceil(u64::from(CHUNK));
    let tasks: Vec<(u32, u64)> = (0..settings.scrambles)
        .flat_map(|s| (0..chunks).map(move |c| (s, c)))
        .collect();
    let done = std::sync::atomic::AtomicU64::new(0);
    let capped = std::sync::atomic::AtomicBool::new(false);
    let sums: Vec<T> = tasks
        .par_iter()
        .map(|&(s, c)| {
            let seed = mix_seed(&[settings.seed, 0x5741_4c4b, u64::from(s)]);
            let sobol = OwenSobol::new(seed);
            let mut tallies = empty();
            let start = c * u64::from(CHUNK);
            let end = (start + u64::from(CHUNK)).min(per_scramble);
            for index in start..end {
                // One walk that cannot end refuses the point: the rest need not run.
                if capped.load(std::sync::atomic::Ordering::Relaxed) {
                    break;
                }
                let sobol = (settings.numbers == Numbers::Sobol).then_some(&sobol);
                let mut random = random::WalkRandom::new(sobol, seed, index as u32);
                if walk_once(&mut random, &mut tallies) {
                    capped.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            }
            let total = done.fetch_add(end - start, std::sync::atomic::Ordering::Relaxed);
            progress(total + end - start);
            tallies
        })
        .collect();
    if capped.into_inner() {
        return None;
    }
    let mut replicates = vec![empty(); settings.scrambles as usize];
    for (&(s, _), chunk) in tasks.iter().zip(&sums) {
        add(&mut replicates[s as usize], chunk);
    }
    Some(replicates)
}

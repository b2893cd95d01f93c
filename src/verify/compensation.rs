//! The audit of energy compensations against the microsurface walk: over a grid of roughness,
//! view and Schlick `F0`, the albedo Kulla-Conty's lobe and Turquin's scaling give
//! ([`crate::integrate::compensation`]) beside the albedo of every order of scattering on the
//! microsurface ([`crate::integrate::walk`], one set of walks per view for every `F0`).
//!
//! kiln's own compensation ([`Compensation::Kiln`]) is fitted at each view to walks of another
//! seed ([`KILN_FIT_SEED`]) than the audit's, so that it is measured against independent walks.
//!
//! Each figure is the relative deviation `compensated / walk - 1` with its 95 % confidence
//! half-width `1.96 (compensated / walk) (sigma_walk / walk)` (the compensations come from the
//! reference to 1e-10, so the walk's standard error is all the uncertainty there is).

use crate::integrate::compensation::{
    Compensation, KILN_FIT_SEED, KilnCompensation, LobeInputs, SingleScattering,
};
use crate::integrate::reference::{ReferenceSettings, reference_average_albedo};
use crate::integrate::walk::{Measured, WalkError, WalkSettings, walk_schlick_polynomial};
use crate::model::{Fresnel, Model};
use crate::table::compensation::CompensationTable;
use serde::Serialize;

/// Where to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct CompensationGrid {
    /// Slope-space roughness values (`alpha`).
    pub alphas: Vec<f64>,
    /// View cosines.
    pub mus: Vec<f64>,
    /// Schlick `F0` values, in `[0, 1]`.
    pub f0s: Vec<f64>,
    /// Schlick's `F90`, in `[0, 1]`.
    pub f90: f64,
}

/// One point of the audit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationPoint {
    pub alpha: f64,
    pub mu: f64,
    pub f0: f64,
    /// The walk's albedo (every order).
    pub walk: Measured,
    /// Single scattering alone, `E_F(mu)`.
    pub single: f64,
    /// Each compensation's albedo, in the order asked for.
    pub compensated: Vec<f64>,
}

impl CompensationPoint {
    /// `compensated / walk - 1` for compensation `k`, and its 95 % confidence half-width.
    #[must_use]
    pub fn deviation(&self, k: usize) -> (f64, f64) {
        let ratio = self.compensated[k] / self.walk.value;
        (
            ratio - 1.0,
            1.96 * ratio * self.walk.std_error / self.walk.value,
        )
    }
}

/// The largest deviation of one sign, where it is, and its confidence half-width.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Extreme {
    pub deviation: f64,
    pub confidence: f64,
    pub alpha: f64,
    pub mu: f64,
    pub f0: f64,
}

/// One compensation's figures over the grid.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationSummary {
    pub compensation: Compensation,
    /// The most it gives too much (the largest `compensated / walk - 1`).
    pub highest: Extreme,
    /// The most it gives too little (the smallest).
    pub lowest: Extreme,
    /// The root mean square deviation over the grid's points.
    pub rms: f64,
}

/// The audit: every point, and a summary per compensation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompensationAudit {
    pub points: Vec<CompensationPoint>,
    pub summaries: Vec<CompensationSummary>,
    /// Walks per view.
    pub walks: u64,
    pub f90: f64,
}

/// The estimated wall time of [`audit_compensations`] on two cores, in seconds: about 0.5 s a
/// view (roughness and `mu`) per 2^20 walks, walks and references (measured 2026-12-07: 16 s
/// for the default 32 views), twice that when kiln's own compensation is fitted to walks
/// first (`fits_kiln`).
#[must_use]
pub fn audit_seconds(views: u64, walks: u64, fits_kiln: bool) -> f64 {
    let fits = if fits_kiln { 2.0 } else { 1.0 };
    views as f64 * 0.5 * fits * walks as f64 / f64::from(1 << 20)
}

/// The estimated wall time of [`audit_lobes`] on two cores, in seconds, for `views` views each
/// evaluated at `directions` exit directions: 2^20 walks from a view evaluated at 8 exits x (5
/// azimuths + 8 strata) take about 1.5 s (measured 2026-12-07), of which 0.3 s the walks.
#[must_use]
pub fn lobe_audit_seconds(views: u64, directions: usize, walks: u64) -> f64 {
    views as f64 * (0.3 + 1.2 * directions as f64 / 104.0) * walks as f64 / f64::from(1 << 20)
}

/// Measures `compensations` against the walk over `grid` (GGX, height-correlated). kiln's is
/// `table`'s lookup where a table is given (what a renderer reads, its interpolation included),
/// else fitted at each view. `progress` hears the number of views done.
pub fn audit_compensations(
    model: Model,
    grid: &CompensationGrid,
    compensations: &[Compensation],
    settings: &WalkSettings,
    table: Option<&CompensationTable>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<CompensationAudit, WalkError> {
    if let Some(&f0) = grid.f0s.iter().find(|f| !(0.0..=1.0).contains(*f)) {
        return Err(WalkError::F0(f0));
    }
    let reference = ReferenceSettings::default();
    let mut points = Vec::new();
    let mut done = 0;
    for &alpha in &grid.alphas {
        crate::integrate::walk::check_inputs(model, alpha, 0.5, 0)?;
        let e_avg = reference_average_albedo(model, alpha, &reference).value;
        for &mu in &grid.mus {
            let polynomial =
                walk_schlick_polynomial(model, alpha, mu, grid.f90, settings, &|_| {})?;
            let kiln = if compensations.contains(&Compensation::Kiln) {
                if grid.f90 != 1.0 {
                    return Err(WalkError::KilnFresnel(format!("F90 {}", grid.f90)));
                }
                match table {
                    Some(table) => {
                        let roughness = table.spec.roughness_convention().from_alpha(alpha);
                        Some(table.lookup(mu, roughness))
                    }
                    None => {
                        let fit_walks = WalkSettings {
                            seed: KILN_FIT_SEED,
                            ..*settings
                        };
                        Some(KilnCompensation::at(
                            model, alpha, mu, &fit_walks, &reference,
                        )?)
                    }
                }
            } else {
                None
            };
            for &f0 in &grid.f0s {
                let fresnel = Fresnel::Schlick {
                    f0: [f0; 3],
                    f90: [grid.f90; 3],
                };
                let single = SingleScattering {
                    kiln,
                    ..SingleScattering::at(model, alpha, mu, e_avg, &fresnel, &reference)
                };
                points.push(CompensationPoint {
                    alpha,
                    mu,
                    f0,
                    walk: polynomial.albedo(f0),
                    single: single.e_f[0],
                    compensated: compensations.iter().map(|c| c.albedo(&single)[0]).collect(),
                });
            }
            done += 1;
            progress(done);
        }
    }
    let summaries = compensations
        .iter()
        .enumerate()
        .map(|(k, &compensation)| summarise(&points, k, compensation))
        .collect();
    Ok(CompensationAudit {
        points,
        summaries,
        walks: settings.walks,
        f90: grid.f90,
    })
}

/// The largest and the smallest of `all` by `deviation`, and the root mean square deviation;
/// `None` for no points.
pub(crate) fn spread<T: Copy>(all: &[T], deviation: impl Fn(&T) -> f64) -> Option<(T, T, f64)> {
    let highest = *all
        .iter()
        .max_by(|a, b| deviation(a).total_cmp(&deviation(b)))?;
    let lowest = *all
        .iter()
        .min_by(|a, b| deviation(a).total_cmp(&deviation(b)))?;
    let rms = (all.iter().map(|e| deviation(e).powi(2)).sum::<f64>() / all.len() as f64).sqrt();
    Some((highest, lowest, rms))
}

fn summarise(
    points: &[CompensationPoint],
    k: usize,
    compensation: Compensation,
) -> CompensationSummary {
    let extreme = |p: &CompensationPoint| {
        let (deviation, confidence) = p.deviation(k);
        Extreme {
            deviation,
            confidence,
            alpha: p.alpha,
            mu: p.mu,
            f0: p.f0,
        }
    };
    let all: Vec<Extreme> = points.iter().map(extreme).collect();
    let (highest, lowest, rms) = spread(&all, |e| e.deviation).expect("a grid has points");
    CompensationSummary {
        compensation,
        highest,
        lowest,
        rms,
    }
}

/// Where to measure the lobes ([`audit_lobes`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LobeAuditGrid {
    /// Slope-space roughness values (`alpha`, above 0).
    pub alphas: Vec<f64>,
    /// View cosines (above 0).
    pub views: Vec<f64>,
    /// Exit cosines (above 0).
    pub exits: Vec<f64>,
    /// Exit azimuths in `[0, pi]` from the view's plane (0: the view's side; `pi`: the mirror
    /// direction's side), for the lobe in full.
    pub azimuths: Vec<f64>,
    /// Schlick `F0` values (`F90` = 1) at every vertex; 1 is the white furnace.
    pub f0s: Vec<f64>,
}

/// Azimuths a walk averages the lobe over (stratified): see [`crate::integrate::walk::lobe`].
pub const LOBE_STRATA: u32 = 8;

/// Nodes of the azimuthal average of the single-scattering BRDF (Turquin's lobe).
const AZIMUTH_NODES: usize = 4096;

/// One point of the lobe audit: the multiple-scattering lobe at a view, an exit and an `F0`,
/// in full (at an azimuth) or averaged over the azimuth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LobePoint {
    pub alpha: f64,
    pub view: f64,
    pub exit: f64,
    pub f0: f64,
    /// The exit's azimuth in radians, or `None` for the average over the azimuth.
    pub azimuth: Option<f64>,
    /// The walk's BRDF of the second and later orders.
    pub walk: Measured,
    /// Each compensation's added lobe, in the order asked for.
    pub added: Vec<f64>,
}

impl LobePoint {
    /// `added / walk - 1` for compensation `k`, and its 95 % confidence half-width.
    #[must_use]
    pub fn deviation(&self, k: usize) -> (f64, f64) {
        let ratio = self.added[k] / self.walk.value;
        (
            ratio - 1.0,
            1.96 * ratio * self.walk.std_error / self.walk.value,
        )
    }
}

/// The largest lobe deviation of one sign, where it is, and its confidence half-width.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LobeExtreme {
    pub deviation: f64,
    pub confidence: f64,
    pub alpha: f64,
    pub view: f64,
    pub exit: f64,
    pub f0: f64,
    pub azimuth: Option<f64>,
}

/// Highest, lowest and RMS deviation over a set of lobe points.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LobeFigures {
    pub highest: LobeExtreme,
    pub lowest: LobeExtreme,
    pub rms: f64,
    /// The widest confidence half-width among the points.
    pub widest_confidence: f64,
}

/// One compensation's lobe figures at one roughness: averaged over the azimuth, and in full.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LobeSummary {
    pub compensation: Compensation,
    pub alpha: f64,
    pub averaged: LobeFigures,
    pub full: Option<LobeFigures>,
}

/// The lobe audit: every point and a summary per compensation and roughness.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LobeAudit {
    pub points: Vec<LobePoint>,
    pub summaries: Vec<LobeSummary>,
    /// Walks per view and `F0`.
    pub walks: u64,
}

/// What the compensations' lobes need at one roughness and `F0`: `E` and kiln's `M` at a
/// cosine, `E_avg`, `F_avg` and kiln's `M_avg`.
struct LobeContext<'a> {
    model: Model,
    alpha: f64,
    f0: f64,
    fresnel: Fresnel,
    e_avg: f64,
    f_avg: f64,
    table: Option<&'a CompensationTable>,
    reference: ReferenceSettings,
}

impl LobeContext<'_> {
    fn e(&self, mu: f64) -> f64 {
        crate::integrate::reference::reference_albedo(self.model, self.alpha, mu, &self.reference)
            .value
    }

    /// The inputs at (view, exit) given `f_ss F` there.
    fn inputs(&self, view: f64, exit: f64, e_view: f64, e_exit: f64, single: f64) -> LobeInputs {
        let kiln = self.table.map(|t| {
            let r = t.spec.roughness_convention().from_alpha(self.alpha);
            [
                t.lookup(view, r).multiple(self.f0),
                t.lookup(exit, r).multiple(self.f0),
                t.lookup_average(r).multiple(self.f0),
            ]
        });
        LobeInputs {
            e_view,
            e_exit,
            e_avg: self.e_avg,
            single,
            f0: self.f0,
            f_avg: self.f_avg,
            kiln,
        }
    }
}

/// Schlick's Fresnel at `F0 = 1` (with `F90 = 1`) is 1 everywhere: the walk then runs without
/// a Fresnel (the same lobe, and the same bits as the white furnace's).
fn white_as_none(fresnel: &Fresnel, f0: f64) -> Fresnel {
    if f0 == 1.0 { Fresnel::None } else { *fresnel }
}

/// Checks the lobe audit's `F0` values and that kiln's lobe has its table.
fn check_lobe_request(
    f0s: &[f64],
    compensations: &[Compensation],
    table: Option<&CompensationTable>,
) -> Result<(), WalkError> {
    if let Some(&f0) = f0s.iter().find(|f| !(0.0..=1.0).contains(*f)) {
        return Err(WalkError::F0(f0));
    }
    if compensations.contains(&Compensation::Kiln) && table.is_none() {
        return Err(WalkError::KilnLobeTable);
    }
    Ok(())
}

/// Measures the lobes `compensations` add against the walk's multiple-scattering lobe over
/// `grid` (GGX, height-correlated, Schlick's Fresnel with `F90 = 1` at every vertex):
/// next-event estimates at every exit direction from one set of walks per view and `F0`
/// ([`crate::integrate::walk::walk_lobe`]); the compensations from kiln's reference `E` and
/// `E_avg`, the closed-form single-scattering BRDF and, for kiln's, `table`'s lookup
/// ([`Compensation::added_lobe`]). `progress` hears the number of views done.
pub fn audit_lobes(
    model: Model,
    grid: &LobeAuditGrid,
    compensations: &[Compensation],
    table: Option<&CompensationTable>,
    settings: &WalkSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<LobeAudit, WalkError> {
    use crate::integrate::walk::lobe::{self, LobeGrid};
    use crate::integrate::walk::walk_lobe;
    use crate::model::ndf::Ggx;
    use crate::model::vector::Vec3;
    check_lobe_request(&grid.f0s, compensations, table)?;
    let reference = ReferenceSettings::default();
    let walk_grid = LobeGrid {
        mus: grid.exits.clone(),
        azimuths: grid.azimuths.clone(),
        strata: LOBE_STRATA,
    };
    let mut points = Vec::new();
    let mut done = 0;
    for &alpha in &grid.alphas {
        let ndf = Ggx { alpha };
        let e_avg = reference_average_albedo(model, alpha, &reference).value;
        for &f0 in &grid.f0s {
            let fresnel = Fresnel::Schlick {
                f0: [f0; 3],
                f90: [1.0; 3],
            };
            let context = LobeContext {
                model,
                alpha,
                f0,
                fresnel,
                e_avg,
                f_avg: fresnel.average()[0],
                table,
                reference,
            };
            let e_exits: Vec<f64> = grid.exits.iter().map(|&mu| context.e(mu)).collect();
            for &view in &grid.views {
                let walked = walk_lobe(
                    model,
                    alpha,
                    view,
                    &walk_grid,
                    &white_as_none(&fresnel, f0),
                    settings,
                    &|_| {},
                )?;
                let e_view = context.e(view);
                let i = Vec3::from_mu(view);
                for (j, (&exit, &e_exit)) in grid.exits.iter().zip(&e_exits).enumerate() {
                    let added = |single: f64| {
                        let inputs = context.inputs(view, exit, e_view, e_exit, single);
                        compensations
                            .iter()
                            .map(|c| c.added_lobe(&inputs))
                            .collect()
                    };
                    let averaged = lobe::single_scattering_averaged(
                        &ndf,
                        view,
                        exit,
                        &context.fresnel,
                        AZIMUTH_NODES,
                    );
                    points.push(LobePoint {
                        alpha,
                        view,
                        exit,
                        f0,
                        azimuth: None,
                        walk: walked.multiple_averaged[j],
                        added: added(averaged),
                    });
                    let s = ((1.0 - exit) * (1.0 + exit)).max(0.0).sqrt();
                    for (k, &phi) in grid.azimuths.iter().enumerate() {
                        let o = Vec3::new(s * phi.cos(), s * phi.sin(), exit);
                        let single = lobe::single_scattering(&ndf, i, o)
                            * lobe::reflectance_at_half(&context.fresnel, i, o);
                        points.push(LobePoint {
                            alpha,
                            view,
                            exit,
                            f0,
                            azimuth: Some(phi),
                            walk: walked.multiple[j * grid.azimuths.len() + k],
                            added: added(single),
                        });
                    }
                }
                done += 1;
                progress(done);
            }
        }
    }
    let figures = |k: usize, alpha: f64, full: bool| {
        let all: Vec<LobeExtreme> = points
            .iter()
            .filter(|p| p.alpha == alpha && p.azimuth.is_some() == full)
            .map(|p| {
                let (deviation, confidence) = p.deviation(k);
                LobeExtreme {
                    deviation,
                    confidence,
                    alpha: p.alpha,
                    view: p.view,
                    exit: p.exit,
                    f0: p.f0,
                    azimuth: p.azimuth,
                }
            })
            .collect();
        let (highest, lowest, rms) = spread(&all, |e| e.deviation)?;
        let widest_confidence = all.iter().map(|e| e.confidence).fold(0.0, f64::max);
        Some(LobeFigures {
            highest,
            lowest,
            rms,
            widest_confidence,
        })
    };
    let summaries = compensations
        .iter()
        .enumerate()
        .flat_map(|(k, &compensation)| {
            grid.alphas
                .iter()
                .map(move |&alpha| (k, compensation, alpha))
        })
        .map(|(k, compensation, alpha)| LobeSummary {
            compensation,
            alpha,
            averaged: figures(k, alpha, false).expect("every exit has its average"),
            full: figures(k, alpha, true),
        })
        .collect();
    Ok(LobeAudit {
        points,
        summaries,
        walks: settings.walks,
    })
}

/// The lobes in the plane of incidence from one view, for a picture ([`lobe_profile`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LobeProfile {
    pub alpha: f64,
    pub view: f64,
    pub f0: f64,
    /// Signed exit angles in degrees: negative on the view's side (azimuth 0), positive on the
    /// mirror direction's side (azimuth 180).
    pub angles: Vec<f64>,
    /// The walk's lobe of the second and later orders at each angle.
    pub walk: Vec<Measured>,
    /// Each compensation's added lobe at each angle, in the order asked for.
    pub added: Vec<Vec<f64>>,
}

/// Exit angles of a profile, in degrees from the normal.
pub const PROFILE_ANGLES: [f64; 19] = [
    1.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0, 60.0, 65.0, 70.0, 75.0,
    80.0, 85.0, 89.0,
];

/// The lobes in the plane of incidence from `view` at `alpha` with Schlick's `f0` (`F90` = 1),
/// at [`PROFILE_ANGLES`] on both sides: the walk's (as [`audit_lobes`] measures it) and each
/// compensation's.
#[allow(clippy::too_many_arguments)]
pub fn lobe_profile(
    model: Model,
    alpha: f64,
    view: f64,
    f0: f64,
    compensations: &[Compensation],
    table: Option<&CompensationTable>,
    settings: &WalkSettings,
) -> Result<LobeProfile, WalkError> {
    use crate::integrate::walk::lobe::{self, LobeGrid};
    use crate::integrate::walk::walk_lobe;
    use crate::model::ndf::Ggx;
    use crate::model::vector::Vec3;
    check_lobe_request(&[f0], compensations, table)?;
    let reference = ReferenceSettings::default();
    let exits: Vec<f64> = PROFILE_ANGLES
        .iter()
        .map(|a| a.to_radians().cos())
        .collect();
    let grid = LobeGrid {
        mus: exits.clone(),
        azimuths: vec![0.0, std::f64::consts::PI],
        strata: 1,
    };
    let fresnel = Fresnel::Schlick {
        f0: [f0; 3],
        f90: [1.0; 3],
    };
    let walked = walk_lobe(
        model,
        alpha,
        view,
        &grid,
        &white_as_none(&fresnel, f0),
        settings,
        &|_| {},
    )?;
    let ndf = Ggx { alpha };
    let context = LobeContext {
        model,
        alpha,
        f0,
        fresnel,
        e_avg: reference_average_albedo(model, alpha, &reference).value,
        f_avg: fresnel.average()[0],
        table,
        reference,
    };
    let e_view = context.e(view);
    let i = Vec3::from_mu(view);
    let mut rows: Vec<(f64, Measured, Vec<f64>)> = Vec::new();
    for (j, (&angle, &exit)) in PROFILE_ANGLES.iter().zip(&exits).enumerate() {
        let e_exit = context.e(exit);
        let s = ((1.0 - exit) * (1.0 + exit)).max(0.0).sqrt();
        for (k, side) in [(0, -1.0), (1, 1.0)] {
            let o = Vec3::new(-side * s, 0.0, exit);
            let single = lobe::single_scattering(&ndf, i, o)
                * lobe::reflectance_at_half(&context.fresnel, i, o);
            let inputs = context.inputs(view, exit, e_view, e_exit, single);
            rows.push((
                side * angle,
                walked.multiple[2 * j + k],
                compensations
                    .iter()
                    .map(|c| c.added_lobe(&inputs))
                    .collect(),
            ));
        }
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(LobeProfile {
        alpha,
        view,
        f0,
        angles: rows.iter().map(|r| r.0).collect(),
        walk: rows.iter().map(|r| r.1).collect(),
        added: (0..compensations.len())
            .map(|c| rows.iter().map(|r| r.2[c]).collect())
            .collect(),
    })
}

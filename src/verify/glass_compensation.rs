//! The audit of a glass material's energy compensation against the dielectric microsurface walk
//! ([`crate::integrate::walk::dielectric`]): over a grid of relative index, roughness and view,
//! where the light a rough dielectric interface scatters goes, reflected or transmitted, beside
//! what a renderer's single-scattering BSDF sends each way (kiln's dielectric reference, the
//! BSDF pbrt-v4, Cycles and Mitsuba evaluate: `model::dielectric`) and what Turquin's scaling
//! makes of it.
//!
//! Turquin's compensation for glass (Turquin 2019, "Practical multiple scattering compensation
//! for microfacet models", section 4; Cycles' `microfacet_ggx_glass_E` tables since Blender 4.0)
//! divides the whole BSDF by its energy albedo `E = R + T` (kiln's `e-dielectric` tables), so
//! that no energy is lost and the multiply scattered light is split as the single scattering
//! is: `R / E` reflected, `T / E` transmitted. The walk loses no energy either (what leaves on
//! both sides sums to 1), so the whole question is the split.
//!
//! Each figure is the relative deviation `compensated / walk - 1` of one side with its 95 %
//! confidence half-width `1.96 (compensated / walk) (sigma_walk / walk)` (the renderer's single
//! scattering comes from the reference to 1e-10).

use crate::integrate::dielectric::reference_dielectric_albedo;
use crate::integrate::reference::ReferenceSettings;
use crate::integrate::walk::{
    DielectricEstimate, View, WalkError, WalkSettings, dielectric::REFLECTED,
    dielectric::TRANSMITTED, walk_dielectric,
};
use crate::model::Model;
use crate::table::glass_compensation::GlassCompensationTable;
use serde::Serialize;

/// Where to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct GlassGrid {
    /// Relative indices `n_inside / n_outside` of the light's side (`eta < 1`: light from
    /// inside a denser medium), each in `[0.01, 100]`.
    pub etas: Vec<f64>,
    /// Slope-space roughness values (`alpha`).
    pub alphas: Vec<f64>,
    /// View cosines.
    pub mus: Vec<f64>,
}

/// One point of the audit: energies `[reflected, transmitted]`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GlassPoint {
    pub eta: f64,
    pub alpha: f64,
    pub mu: f64,
    /// What the walk measured: the first order and every order.
    pub walk: DielectricEstimate,
    /// The renderer's single-scattering BSDF, `[R, T]` (kiln's reference).
    pub single: [f64; 2],
    /// Turquin's compensation, `[R / E, T / E]` with `E = R + T` of `single`.
    pub turquin: [f64; 2],
    /// kiln's, from its table's lookup (`[k_R R, k_T T]`), when a table is measured.
    pub kiln: Option<[f64; 2]>,
}

impl GlassPoint {
    /// `turquin / walk - 1` on `side` ([`REFLECTED`] or [`TRANSMITTED`]) and its 95 %
    /// confidence half-width; `(0, 0)` where neither sends anything that way (an index-matched
    /// interface reflects nothing).
    #[must_use]
    pub fn deviation(&self, side: usize) -> (f64, f64) {
        let walk = self.walk.all[side];
        if walk.value == 0.0 && self.turquin[side] == 0.0 {
            return (0.0, 0.0);
        }
        let ratio = self.turquin[side] / walk.value;
        (ratio - 1.0, 1.96 * ratio * walk.std_error / walk.value)
    }

    /// kiln's energy on `side` over the walk's, less 1, and its 95 % confidence half-width,
    /// when a table is measured.
    #[must_use]
    pub fn kiln_deviation(&self, side: usize) -> Option<(f64, f64)> {
        let kiln = self.kiln?;
        let walk = self.walk.all[side];
        if walk.value == 0.0 && kiln[side] == 0.0 {
            return Some((0.0, 0.0));
        }
        let ratio = kiln[side] / walk.value;
        Some((ratio - 1.0, 1.96 * ratio * walk.std_error / walk.value))
    }

    /// Turquin's reflected energy less the walk's (a fraction of the incident power; the
    /// transmitted energy is off by as much the other way, since both sum to 1), and its 95 %
    /// confidence half-width.
    #[must_use]
    pub fn reflected_energy_deviation(&self) -> (f64, f64) {
        let walk = self.walk.all[REFLECTED];
        (self.turquin[REFLECTED] - walk.value, 1.96 * walk.std_error)
    }

    /// The renderer's single-scattering transmission less the walk's first order (a fraction
    /// of the incident power): how far the BSDF renderers evaluate is from the Smith
    /// microsurface's own single scattering (see [`crate::integrate::walk::dielectric`]), with
    /// its 95 % confidence half-width.
    #[must_use]
    pub fn single_transmission_deviation(&self) -> (f64, f64) {
        let walk = self.walk.single[TRANSMITTED];
        (self.single[TRANSMITTED] - walk.value, 1.96 * walk.std_error)
    }
}

/// The largest deviation of one sign, where it is, and its confidence half-width.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GlassExtreme {
    pub deviation: f64,
    pub confidence: f64,
    pub alpha: f64,
    pub mu: f64,
}

/// Figures of one kind at one relative index.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SideSummary {
    /// The largest deviation (too much).
    pub highest: GlassExtreme,
    /// The smallest (too little).
    pub lowest: GlassExtreme,
    /// The root mean square deviation.
    pub rms: f64,
}

/// The figures at one relative index.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GlassSummary {
    pub eta: f64,
    /// Turquin's reflected energy against the walk's, relative.
    pub reflected: SideSummary,
    /// Turquin's transmitted energy against the walk's, relative.
    pub transmitted: SideSummary,
    /// Turquin's reflected energy less the walk's, absolute.
    pub reflected_energy: SideSummary,
    /// The renderer's single-scattering transmission less the walk's first order, absolute.
    pub single_transmission: SideSummary,
    /// kiln's reflected and transmitted energy against the walk's, relative, when a table is
    /// measured.
    pub kiln: Option<[SideSummary; 2]>,
}

/// The audit: every point, and a summary per relative index.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GlassAudit {
    pub points: Vec<GlassPoint>,
    pub summaries: Vec<GlassSummary>,
    /// Walks per view.
    pub walks: u64,
}

/// The estimated cost of [`audit_glass`] over `views` views (index, roughness and `mu`) with
/// `walks` walks each, in seconds of one core: about 1.1 s a view per 2^20 walks (0.54 s on two
/// cores at r = 0.7, mu = 0.5, 2.6 vertices a walk; 0.65 s at r = 1, mu = 0.2; measured
/// 2026-12-07).
#[must_use]
pub fn audit_core_seconds(views: u64, walks: u64) -> f64 {
    views as f64 * 1.1 * walks as f64 / f64::from(1 << 20)
}

/// Measures Turquin's glass compensation against the dielectric walk over `grid` (GGX,
/// height-correlated), and kiln's as `table`'s lookup where one is given (at its own index:
/// `grid.etas` are then its `eta` and `1 / eta`). `progress` hears the number of views done.
pub fn audit_glass(
    model: Model,
    grid: &GlassGrid,
    settings: &WalkSettings,
    table: Option<&GlassCompensationTable>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<GlassAudit, WalkError> {
    let views: Vec<(f64, f64, f64)> = grid
        .etas
        .iter()
        .flat_map(|&eta| {
            grid.alphas
                .iter()
                .flat_map(move |&alpha| grid.mus.iter().map(move |&mu| (eta, alpha, mu)))
        })
        .collect();
    let done = std::sync::atomic::AtomicU64::new(0);
    let reference = ReferenceSettings::default();
    let points = views
        .iter()
        .map(|&(eta, alpha, mu)| {
            let walk = walk_dielectric(model, alpha, View::Mu(mu), eta, settings, &|_| {})?;
            let single = reference_dielectric_albedo(model, alpha, mu, eta, &reference);
            let parts = [single.reflection, single.transmission];
            let energy = parts[REFLECTED] + parts[TRANSMITTED];
            let turquin = parts.map(|p| if energy > 0.0 { p / energy } else { 0.0 });
            let kiln = table.map(|t| {
                let inside = (eta - t.eta).abs() > (eta - 1.0 / t.eta).abs();
                let roughness = t.spec.roughness_convention().from_alpha(alpha);
                let [k_r, k_t] = t.lookup(mu, roughness, inside);
                [k_r * parts[REFLECTED], k_t * parts[TRANSMITTED]]
            });
            progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
            Ok(GlassPoint {
                eta,
                alpha,
                mu,
                walk,
                single: parts,
                turquin,
                kiln,
            })
        })
        .collect::<Result<Vec<_>, WalkError>>()?;
    let summaries = grid
        .etas
        .iter()
        .map(|&eta| {
            let at: Vec<&GlassPoint> = points.iter().filter(|p| p.eta == eta).collect();
            let side = |deviation: &dyn Fn(&GlassPoint) -> (f64, f64)| -> SideSummary {
                let all: Vec<GlassExtreme> = at
                    .iter()
                    .map(|p| {
                        let (deviation, confidence) = deviation(p);
                        GlassExtreme {
                            deviation,
                            confidence,
                            alpha: p.alpha,
                            mu: p.mu,
                        }
                    })
                    .collect();
                let (highest, lowest, rms) =
                    super::compensation::spread(&all, |e| e.deviation).expect("a grid has points");
                SideSummary {
                    highest,
                    lowest,
                    rms,
                }
            };
            GlassSummary {
                eta,
                reflected: side(&|p| p.deviation(REFLECTED)),
                transmitted: side(&|p| p.deviation(TRANSMITTED)),
                reflected_energy: side(&GlassPoint::reflected_energy_deviation),
                single_transmission: side(&GlassPoint::single_transmission_deviation),
                kiln: table.map(|_| {
                    [REFLECTED, TRANSMITTED].map(|lobe| {
                        side(&|p| p.kiln_deviation(lobe).expect("a table was measured"))
                    })
                }),
            }
        })
        .collect();
    Ok(GlassAudit {
        points,
        summaries,
        walks: settings.walks,
    })
}

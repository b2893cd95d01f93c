//! Texels fitted for the lookup: the stored values chosen so that what a renderer reads, the
//! bilinear lookup of the table with its own coordinate mapping ([`Table::lookup`]), is closest
//! to the true function over the whole domain in the maximum norm, rather than exact at the
//! nodes.
//!
//! A lookup is linear in the texels (`sum w_k(x) texel_k`, [`Table::lookup_weights`]), so the
//! fit is a linear Chebyshev problem: over a dense set of points `x_j` covering every cell of
//! the texture (the axis ends included), find the corrections `d` to the node values that
//! minimise `max_j |sum_k w_k(x_j) d_k - (f(x_j) - lookup(x_j))|`, with `f` the deterministic
//! reference. It is solved by Lawson's iteratively reweighted least squares
//! ([`crate::numerics::minimax`]), whose normal equations are banded because a lookup blends
//! neighbouring texels only (bandwidth one row plus one).
//!
//! No point's weight may exceed [`LookupFitSettings::weight_cap`] (30) times the mean, so the
//! fit minimises, in effect, the mean of the worst few percent of errors rather than the single
//! worst. Where the layout resolves the function that is the maximum within about 1% (the
//! 32 x 32 `E`: 3.28e-4 against 3.24e-4 uncapped) with a third less RMS (8.2e-5 against
//! 1.17e-4). Where a layer is narrower than a texel (the split-sum `E_bias`'s near-mirror
//! grazing layer on a `sqrt` mu axis), an uncapped fit lowers the maximum only by moving error
//! into the bulk (p99 6.8e-3 to 1.7e-2), while the capped fit improves all three against the
//! point samples (max 9.6e-2 to 8.3e-2, RMS 2.3e-3 to 2.0e-3, p99 6.8e-3 to 5.1e-3; `kiln
//! verify --density 4`, 2026-12-04). Where the capped fit's maximum is above the point
//! samples' (some engines' linear `mu` axes), the fit blends it with the uncapped minimax, as
//! much of the capped as keeps the maximum at or below the point samples': a fitted table is
//! never worse than point samples at its points, kiln verify's among them. For that `E_bias`
//! table the blend is what is stored: `kiln verify` finds max 7.50e-2 to 7.02e-2, RMS 2.39e-3
//! to 2.27e-3, p99 7.09e-3 to 7.67e-3.
//!
//! Over the IOR (the glass tables, on request) the lookup is trilinear and the fit's points
//! are the texture's points and the midpoints between them, each where the table's texels are
//! computed ([`crate::table::TableSpec::point_at`]: a glass layout's row `alpha = 0` and slice
//! `eta = 1` hold limits taken at a small `alpha` and `eta - 1`, which the lookup reads there);
//! [`LookupFitSettings::over_ior`]. At 16^3 the fit lowers Turquin's furnace of the glass `E`
//! tables by 1.2x to 2.3x per IOR band, and the 16 x 16 averages' lookups to 5.8e-4 and
//! 8.2e-4 (from 1.21e-3 and 1.71e-3; docs/verify.md, "Fitted glass tables").
//!
//! The fitted values stay within `[0, 1]` (clamped after the fit; the error stated is measured
//! after clamping), and `one_minus_value` moves by the same correction, so that it keeps its
//! relative precision near 1.

use super::Table;
use crate::integrate::reference::ReferenceSettings;
use crate::integrate::value::Point;
use crate::numerics::minimax::{Lawson, lawson};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How densely and how long to fit.
#[derive(Clone, Copy, Debug)]
pub struct LookupFitSettings {
    /// Points per cell and axis (each cell of a 2-D table gets `per_cell^2`, the cell edges
    /// shared).
    pub per_cell: usize,
    /// The roughness axis' first cells, next to the mirror row, that get
    /// [`LookupFitSettings::per_mirror_cell`] points instead: there `E` at a grazing view falls
    /// from the mirror's 1 to the grazing layer's value within a cell, and the lookup's worst
    /// error between sparser points hides from the fit (see [`LookupFitSettings::for_cells`]).
    pub mirror_cells: usize,
    /// Points per cell along the roughness axis in the [`LookupFitSettings::mirror_cells`].
    pub per_mirror_cell: usize,
    /// Lawson iterations.
    pub iterations: usize,
    /// The reference's tolerance at the fit's points.
    pub tolerance: f64,
    /// The largest weight a point may take, as a multiple of the mean weight (see the module
    /// docs; infinite for the pure minimax).
    pub weight_cap: f64,
}

impl LookupFitSettings {
    /// Settings for a table of `cells` cells along its longest axis: `64 / cells` points per
    /// cell and axis, within `[2, 6]` (2 from 32 cells up: a cell's ends and its middle, where
    /// the bilinear lookup's error of a smooth function peaks), and 6 per cell in the two
    /// roughness cells next to the mirror row; the truth at those points to about a
    /// two-hundredth of the lookup error a fit of that size reaches (2e-4 at 31 cells, falling
    /// as `cells^-2`): 1e-6 from 31 cells down, within `[1e-9, 1e-6]`. At 32 x 32 a truth at
    /// 1e-8 instead gave the same fit to its audit's three digits (`kiln verify` of the balanced
    /// fitted `E`: 2.09e-4 both) and took 1.5 times as long (3.0 s against 2.0 s, one run each,
    /// 2026-12-05).
    ///
    /// The density was 6 per cell everywhere up to 32 cells (46,000 reference evaluations at
    /// 32 x 32, nearly all of `kiln bake`'s time). Measured on the balanced 32 x 32 `E`
    /// (2026-12-07, `kiln bake --quantity e` then `kiln verify --density 5` and `--density 7`,
    /// whose points the fit never saw): 6 everywhere 2.22e-4 and 2.13e-4; 2 everywhere
    /// 2.74e-4 and 2.35e-4, the worst at `r = 0.0003`, `mu = 1e-6`, in the first roughness
    /// cell; 2 with 6 in the first two roughness cells 2.16e-4 and 2.12e-4 at 12,400 points
    /// (6 in the first two `mu` cells instead: 2.74e-4; in the first roughness cell only:
    /// 2.22e-4). At 16 x 16, 4 a cell: 8.15e-4 and 8.51e-4 (6 everywhere: 8.22e-4, 8.52e-4).
    #[must_use]
    pub fn for_cells(cells: usize) -> Self {
        let shrink = 31.0 / cells.max(1) as f64;
        Self {
            per_cell: (64 / cells.max(1)).clamp(2, 6),
            mirror_cells: 2,
            per_mirror_cell: 6,
            iterations: 60,
            tolerance: (1e-6 * shrink * shrink).clamp(1e-9, 1e-6),
            weight_cap: 30.0,
        }
    }

    /// Settings for a table over the IOR (the glass tables, three axes): the texture's points
    /// and the midpoints between them, 2 per cell and axis (31^3 points at 16^3, about a
    /// minute of one core's reference evaluations), the truth at 1e-6 (the lookup errs by
    /// 1e-3 and more), 30 Lawson iterations (each a banded solve of bandwidth `n^2 + n + 1`).
    /// 3 points per cell gave the same furnace to two digits at 16^3 and took 1.6 times as long
    /// (43 s against 27 s, one run each, 2026-12-06).
    #[must_use]
    pub fn over_ior() -> Self {
        Self {
            per_cell: 2,
            mirror_cells: 0,
            per_mirror_cell: 2,
            iterations: 30,
            tolerance: 1e-6,
            weight_cap: 30.0,
        }
    }
}

/// What a fit did: the lookup's error at the fit's points before and after, and how far the
/// fitted texels moved from the node values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LookupFitReport {
    /// Points the fit compared.
    pub points: usize,
    /// The node table's lookup error, largest over the points.
    pub node_lookup_max_error: f64,
    /// The fitted table's lookup error, largest over the points.
    pub lookup_max_error: f64,
    /// Its root mean square over the points.
    pub lookup_rms_error: f64,
    /// The largest correction of a texel from its node value.
    pub max_correction: f64,
}

/// One point of the fit: where the lookup is made (the table's own coordinates) and the
/// physical point the truth is computed at.
#[derive(Clone, Copy, Debug)]
struct FitPoint {
    mu: f64,
    roughness: f64,
    eta: f64,
    at: Point,
}

/// The cells of an axis of the fit's points: between its ends `t = 0` and `t = 1`, the half
/// texels a clamped `centers` lookup reads included.
fn cells_of(axis: super::Axis) -> usize {
    match axis.grid() {
        super::Grid::Nodes => axis.size().saturating_sub(1).max(1),
        super::Grid::Centers => axis.size(),
    }
}

/// The coordinates of the fit's points along `axis` (`[0]` without one): `per_cell` points per
/// cell from `t = 0` to `t = 1`, the first `first_cells` cells `per_first_cell` each.
fn axis_points(
    axis: Option<super::Axis>,
    per_cell: usize,
    first_cells: usize,
    per_first_cell: usize,
) -> Vec<f64> {
    let Some(axis) = axis else {
        return vec![0.0];
    };
    let cells = cells_of(axis);
    let mut ts = Vec::with_capacity(axis_point_count(
        Some(axis),
        per_cell,
        first_cells,
        per_first_cell,
    ));
    for cell in 0..cells {
        let k = if cell < first_cells {
            per_first_cell
        } else {
            per_cell
        };
        // `(cell k + j) / (cells k)`, exact in the integers: with one density throughout, the
        // points `j / n` of a uniform ladder, bit for bit.
        let n = (cells * k) as f64;
        ts.extend((0..k).map(|j| (cell * k + j) as f64 / n));
    }
    ts.push(1.0);
    ts
}

/// How many points [`axis_points`] makes, counted without making them (saturating).
fn axis_point_count(
    axis: Option<super::Axis>,
    per_cell: usize,
    first_cells: usize,
    per_first_cell: usize,
) -> usize {
    axis.map_or(1, |axis| {
        let cells = cells_of(axis);
        let first = first_cells.min(cells);
        first
            .saturating_mul(per_first_cell)
            .saturating_add((cells - first).saturating_mul(per_cell))
            .saturating_add(1)
    })
}

/// The points over which [`fit_for_lookup`] compares: on each axis, [`axis_points`] at the
/// settings' density (the roughness axis' first cells denser, [`LookupFitSettings::mirror_cells`]),
/// as physical coordinates; with a `mu` axis, every row also at the grazing probes (`mu` = 0,
/// 1e-12, 1e-6 to 1), where a boundary layer can fall between texture points.
fn fit_points(spec: &super::TableSpec, settings: &LookupFitSettings) -> Vec<FitPoint> {
    let ts = |axis: Option<super::Axis>| axis_points(axis, settings.per_cell, 0, 0);
    let roughness_ts = axis_points(
        spec.roughness,
        settings.per_cell,
        settings.mirror_cells,
        settings.per_mirror_cell,
    );
    let convention = spec.roughness_convention();
    let mut points = Vec::new();
    if spec.ior.is_some() {
        // Over the IOR the points are where the texels are computed (`TableSpec::point_at`,
        // `TableSpec::ior_at`): a glass layout's row `alpha = 0` and slice `eta = 1` hold
        // limits taken at a small `alpha` and `eta - 1`, which the lookup reads there.
        for &t_eta in &ts(spec.ior) {
            for &t_r in &roughness_ts {
                let eta_up = spec.ior_at(t_eta, spec.row_alpha(t_r));
                for &t_mu in &ts(spec.mu) {
                    let (alpha, mu) = spec.point_at(t_r, t_mu, eta_up);
                    points.push(FitPoint {
                        mu: mu.unwrap_or(0.0),
                        roughness: convention.from_alpha(alpha),
                        eta: eta_up,
                        at: Point {
                            alpha,
                            mu,
                            eta: Some(spec.relative_eta(eta_up)),
                        },
                    });
                }
            }
        }
        return points;
    }
    for &t_eta in &ts(spec.ior) {
        for &t_r in &roughness_ts {
            let roughness = spec
                .roughness
                .map_or(t_r, |axis| axis.roughness_at_coordinate(t_r));
            let alpha = convention.to_alpha(roughness);
            let eta = match spec.ior {
                Some(super::Axis::Ior { mapping, max, .. }) => mapping.eta(t_eta, max.0, alpha),
                _ => 1.0,
            };
            let mus: Vec<Option<f64>> = match spec.mu {
                // The texture's points, then the grazing probes `verify` audits every row at.
                Some(super::Axis::Mu { mapping, size, .. }) => ts(spec.mu)
                    .iter()
                    .map(|&t_mu| Some(mapping.mu_at(t_mu, alpha, eta, size)))
                    .chain(super::axis::grazing_probes().into_iter().map(Some))
                    .collect(),
                _ => vec![None],
            };
            for mu in mus {
                points.push(FitPoint {
                    mu: mu.unwrap_or(0.0),
                    roughness,
                    eta,
                    at: Point {
                        alpha,
                        mu,
                        eta: spec.ior.map(|_| spec.relative_eta(eta)),
                    },
                });
            }
        }
    }
    points
}

/// The reference evaluations [`fit_for_lookup`] makes for a table of `spec` with `extra`
/// points of the caller's: what a progress bar and a cost estimate count.
#[must_use]
pub fn planned_evaluations(
    spec: &super::TableSpec,
    settings: &LookupFitSettings,
    extra: usize,
) -> usize {
    fit_point_count(spec, settings).saturating_add(extra)
}

/// The band of the fit's normal equations: a lookup blends texels up to one step along every
/// axis, so the band is the sum of the row-major strides (`mu + 1` for rows of `mu` texels,
/// `n^2 + n + 1` for an `n^3` table).
#[must_use]
pub fn band(spec: &super::TableSpec) -> usize {
    let shape = spec.shape();
    (0..shape.len())
        .map(|d| shape[d + 1..].iter().product::<usize>())
        .sum()
}

/// The memory [`fit_for_lookup`] holds for a table of `spec` with `extra` points of the
/// caller's, in bytes, counted without allocating (saturating): the banded normal equations
/// (`texels x (band + 1)` numbers, [`crate::numerics::minimax`]) and, per point, its
/// coordinates, its lookup weights twice (all texels and the free ones), the truth, the
/// residual, the error and Lawson's weight.
#[must_use]
pub fn memory_bytes(spec: &super::TableSpec, settings: &LookupFitSettings, extra: usize) -> u64 {
    let matrix = (spec.len() as u64)
        .saturating_mul(band(spec) as u64 + 1)
        .saturating_mul(8);
    let per_point = (std::mem::size_of::<FitPoint>()
        + 2 * std::mem::size_of::<super::LookupWeights>()
        + 4 * 8) as u64;
    let points = planned_evaluations(spec, settings, extra) as u64;
    matrix.saturating_add(points.saturating_mul(per_point))
}

/// How many points [`fit_points`] makes, counted without making them (saturating).
fn fit_point_count(spec: &super::TableSpec, settings: &LookupFitSettings) -> usize {
    let ts = |axis: Option<super::Axis>| axis_point_count(axis, settings.per_cell, 0, 0);
    let mus = match spec.mu {
        Some(_) if spec.ior.is_none() => {
            ts(spec.mu).saturating_add(super::axis::grazing_probes().len())
        }
        _ => ts(spec.mu),
    };
    let roughness = axis_point_count(
        spec.roughness,
        settings.per_cell,
        settings.mirror_cells,
        settings.per_mirror_cell,
    );
    ts(spec.ior).saturating_mul(roughness).saturating_mul(mus)
}

/// Fits `table`'s texels for its lookup (see the module docs), in place: `value` and
/// `one_minus_value` move by the fitted corrections; `std_error` (the node estimates') stays.
/// `extra` are physical points compared as well (the caller's audit points, so that the error
/// stated is never below what that audit finds). `progress` hears of each reference
/// evaluation.
pub fn fit_for_lookup(
    table: &mut Table,
    settings: &LookupFitSettings,
    extra: &[Point],
    progress: &(dyn Fn() + Sync),
) -> LookupFitReport {
    let convention = table.spec.roughness_convention();
    let mut points = fit_points(&table.spec, settings);
    points.extend(extra.iter().map(|&at| FitPoint {
        mu: at.mu.unwrap_or(0.0),
        roughness: convention.from_alpha(at.alpha),
        eta: at.eta.unwrap_or(1.0),
        at,
    }));
    let integral = table.spec.integral();
    let reference = ReferenceSettings {
        tolerance: settings.tolerance,
        ..ReferenceSettings::default()
    };
    let truth: Vec<f64> = points
        .par_iter()
        .map(|p| {
            let v = integral.reference(p.at, &reference).value;
            progress();
            v
        })
        .collect();
    let weights: Vec<super::LookupWeights> = points
        .iter()
        .map(|p| table.lookup_weights(p.mu, p.roughness, p.eta))
        .collect();
    let residual: Vec<f64> = weights
        .iter()
        .zip(&truth)
        .map(|(w, f)| f - w.apply(&table.value))
        .collect();
    let node_lookup_max_error = residual.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
    // The texels the mirror's lookup reads keep their node values: the fit solves for the
    // others only.
    let pinned = mirror_texels(table);
    let free: Vec<super::LookupWeights> = weights
        .iter()
        .map(|w| {
            let mut kept = super::LookupWeights::default();
            for &(k, weight) in w.terms() {
                if !pinned.contains(&k) {
                    kept.terms[kept.count] = (k, weight);
                    kept.count += 1;
                }
            }
            kept
        })
        .collect();
    let correction = blend_capped(
        &free,
        &residual,
        node_lookup_max_error,
        table.value.len(),
        settings,
    );
    let mut max_correction: f64 = 0.0;
    for (k, d) in correction.iter().enumerate() {
        let value = (table.value[k] + d).clamp(0.0, 1.0);
        let moved = value - table.value[k];
        max_correction = max_correction.max(moved.abs());
        table.value[k] = value;
        table.one_minus_value[k] = (table.one_minus_value[k] - moved).clamp(0.0, 1.0);
    }
    let errors: Vec<f64> = weights
        .iter()
        .zip(&truth)
        .map(|(w, f)| (w.apply(&table.value) - f).abs())
        .collect();
    LookupFitReport {
        points: points.len(),
        node_lookup_max_error,
        lookup_max_error: crate::stats::max_or_nan(errors.iter().copied()),
        lookup_rms_error: (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt(),
        max_correction,
    }
}

/// The texels a lookup at the mirror (`roughness = 0`) and normal incidence reads, which the
/// fit leaves at their node values: the mirror's value is exact (`E = 1`: a mirror loses
/// nothing), and on the axes that follow the grazing layer every `mu > 0` reads them at
/// `roughness = 0`, so that the lookup's loss `1 - Ē` starts from 0 there, as `f_ms_norm`'s
/// `(1 - Ē) / x` needs ([`super::normalisation`]).
fn mirror_texels(table: &Table) -> Vec<usize> {
    table
        .lookup_weights(1.0, 0.0, 1.0)
        .terms()
        .iter()
        .filter(|&&(_, w)| w > 0.0)
        .map(|&(k, _)| k)
        .collect()
}

/// The corrections: the capped fit's where its maximum is no worse than the point samples'
/// (`nodes = max_j |b_j|`), else the blend `l capped + (1 - l) uncapped` with the largest `l` in steps
/// of 1/20 that is (the uncapped minimax is; the errors are linear in `l`), else none.
fn blend_capped(
    rows: &[super::LookupWeights],
    b: &[f64],
    nodes: f64,
    unknowns: usize,
    settings: &LookupFitSettings,
) -> Vec<f64> {
    let solve = |weight_cap| {
        let lawson_settings = Lawson {
            iterations: settings.iterations,
            weight_cap,
            regularisation: 1e-12,
        };
        lawson(rows, b, unknowns, &lawson_settings)
    };
    let capped = solve(settings.weight_cap);
    let max_error = |x: &[f64]| {
        rows.iter()
            .zip(b)
            .map(|(row, bj)| (row.apply(x) - bj).abs())
            .fold(0.0_f64, f64::max)
    };
    if max_error(&capped) <= nodes || settings.weight_cap.is_infinite() {
        return capped;
    }
    let uncapped = solve(f64::INFINITY);
    for step in (0..20).rev() {
        let l = f64::from(step) / 20.0;
        let blend: Vec<f64> = capped
            .iter()
            .zip(&uncapped)
            .map(|(c, u)| l * c + (1.0 - l) * u)
            .collect();
        if max_error(&blend) <= nodes {
            return blend;
        }
    }
    vec![0.0; unknowns]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::quantity::Quantity;
    use crate::table::axis::{Axis, IorBound, IorMapping, MuMapping};
    use crate::table::{Grid, TableSpec, test_e_spec};

    /// `spec` over an IOR axis of 2 nodes: a 2 x rows x columns glass table.
    fn glass_of(spec: TableSpec) -> TableSpec {
        TableSpec {
            quantity: Quantity::EDielectric,
            ior: Some(Axis::Ior {
                size: 2,
                mapping: IorMapping::Linear,
                max: IorBound(3.0),
                grid: Grid::Nodes,
            }),
            ..spec
        }
    }

    /// What a cost estimate and the bake's memory bound read is counted from the axes, not
    /// made: the count must be what the fit then makes, for every kind of axis.
    #[test]
    fn the_fit_points_are_counted_without_being_made() {
        let glass = glass_of(test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear));
        for spec in [
            test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear),
            test_e_spec(5, 2, Grid::Centers, MuMapping::Sqrt),
            test_e_spec(1, 7, Grid::Nodes, MuMapping::Adaptive),
            glass.clone(),
        ] {
            for per_cell in [1, 2, 3, 6] {
                for (mirror_cells, per_mirror_cell) in [(0, 0), (1, 6), (2, 6), (9, 3)] {
                    let settings = LookupFitSettings {
                        per_cell,
                        mirror_cells,
                        per_mirror_cell,
                        ..LookupFitSettings::for_cells(32)
                    };
                    let points = fit_points(&spec, &settings);
                    assert_eq!(
                        fit_point_count(&spec, &settings),
                        points.len(),
                        "{} {settings:?}",
                        spec.id()
                    );
                }
            }
        }
        let at = |per_cell, mirror_cells, per_mirror_cell| LookupFitSettings {
            per_cell,
            mirror_cells,
            per_mirror_cell,
            ..LookupFitSettings::for_cells(32)
        };
        // By hand: 3 x 4 nodes at 2 a cell: 5 roughness rungs of 7 mu points and 27 probes;
        // with the first roughness cell at 6, 6 + 2 + 1 = 9 rungs.
        let spec = test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear);
        assert_eq!(fit_point_count(&spec, &at(2, 0, 0)), 5 * (7 + 27));
        assert_eq!(fit_point_count(&spec, &at(2, 1, 6)), 9 * (7 + 27));
        // The rungs of that axis: 0, 1/12, ..., 5/12 in the first cell, 1/2, 3/4 in the
        // second, and the end; one density throughout gives the uniform ladder bit for bit.
        let rungs = axis_points(spec.roughness, 2, 1, 6);
        let by_hand = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0].map(|k| k / 12.0);
        assert_eq!(rungs[..6], by_hand);
        assert_eq!(rungs[6..], [0.5, 0.75, 1.0]);
        assert_eq!(
            axis_points(spec.roughness, 3, 0, 0),
            (0..=6).map(|k| f64::from(k) / 6.0).collect::<Vec<_>>()
        );
        // The band of a 3 x 4 table is a row and one; of a 2 x 3 x 4 one, 12 + 4 + 1.
        assert_eq!(band(&spec), 5);
        assert_eq!(band(&glass), 17);
    }
}

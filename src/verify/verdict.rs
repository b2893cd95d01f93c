//! A verdict on a table stored in fixed point (an 8-bit or 16-bit PNG, as the GAMES202 homework
//! writes its `E` and `E_avg`): is it as good as its storage allows, and if not, which of the
//! usual mistakes does the pattern of its errors show?
//!
//! The audit measures the file against the truth and against the floor of its storage (the true
//! values rounded to the storage, [`super::StorageCost`]). A correct file sits on that floor:
//! rounding to nearest is off by at most half a step. Above it, each usual mistake leaves a
//! fingerprint that a few hundred reference values read (independently of how the file was made):
//!
//! - **rows flipped** (the image written top-down where the layout wants the roughest row on
//!   top, or the other way): the file matches the truth with its roughness rows reversed;
//! - **alpha = r** (roughness used as `alpha` where the layout's axis is perceptual, `alpha =
//!   r^2`): the file matches the truth computed at `alpha = r`;
//! - **truncation** (`floor(255 v)` instead of `round(255 v)`): every error lies in `[-1, 0]`
//!   steps, half a step low on average;
//! - **noise** (too few Monte Carlo samples per texel): the error changes sign from one sampled
//!   texel to the next, where a wrong model's error keeps its sign along a row.
//!
//! The hypotheses are read on a lattice of texels (every 8th row and column, with each row's
//! mirror row, and the last column), so the verdict costs a few hundred reference values.

use super::{Coordinates, Report, Storage};
use crate::integrate::reference::ReferenceSettings;
use crate::model::RoughnessConvention;
use crate::table::Table;
use rayon::prelude::*;
use serde::Serialize;

/// What the verdict found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Finding {
    /// The file is as good as its storage allows.
    AsGoodAsStorage,
    /// The roughness rows are in the reverse order.
    RowsFlipped,
    /// Computed at `alpha = r` on a perceptual axis (`alpha = r^2`).
    AlphaIsR,
    /// Values truncated to the storage instead of rounded.
    Truncated,
    /// Noisy values (too few samples per texel).
    Noisy,
    /// Above the floor, by no pattern the verdict knows.
    Unexplained,
}

/// The verdict and the figures behind it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    pub finding: Finding,
    /// The file's largest node error, and the storage's floor of it.
    pub node_max_error: f64,
    pub floor: f64,
    /// The storage's step (`1 / 255` for 8 bits).
    pub step: f64,
    /// The file's largest error on the lattice under the finding's hypothesis (none for
    /// [`Finding::AsGoodAsStorage`] and [`Finding::Unexplained`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub explained_error: Option<f64>,
    /// One sentence for a person.
    pub sentence: String,
}

/// The lattice the hypotheses are read on: row indices closed under mirroring, column indices.
fn lattice(rows: usize, columns: usize) -> (Vec<usize>, Vec<usize>) {
    let mut r: Vec<usize> = (0..rows)
        .step_by(8)
        .flat_map(|i| [i, rows - 1 - i])
        .collect();
    r.sort_unstable();
    r.dedup();
    let mut c: Vec<usize> = (0..columns).step_by(8).chain([columns - 1]).collect();
    c.sort_unstable();
    c.dedup();
    (r, c)
}

/// The verdict on `table` (as read from a file in `storage`) from its audit `report`; `None`
/// for a floating-point storage, an audit against another table or one without the storage's
/// floor, or a table with an IOR axis.
#[must_use]
pub fn verdict(table: &Table, report: &Report, storage: &Storage) -> Option<Verdict> {
    let floor = report.storage_cost.as_ref()?.node_max_error;
    let spec = &table.spec;
    if storage.step <= 0.0 || report.against != "reference" || spec.ior.is_some() {
        return None;
    }
    let step = storage.step;
    let shape = spec.shape();
    let (rows, columns) = (shape[0], shape.get(1).copied().unwrap_or(1));
    let node_max_error = report.node_max_error;
    // On the floor: rounding to nearest is half a step; a little room for the reference.
    let on_floor = |e: f64| e <= floor.max(0.5 * step) * 1.02 + 1e-6;
    let done = |finding, explained_error, sentence: String| {
        Some(Verdict {
            finding,
            node_max_error,
            floor,
            step,
            explained_error,
            sentence,
        })
    };
    if on_floor(node_max_error) {
        return done(
            Finding::AsGoodAsStorage,
            None,
            format!(
                "as good as {} storage allows: the nodes' max error {node_max_error:.2e} is the \
                 floor's {floor:.2e} (half a step, {:.2e})",
                storage.name,
                0.5 * step
            ),
        );
    }
    let (lattice_rows, lattice_columns) = lattice(rows, columns);
    let convention = spec.roughness_convention();
    let points: Vec<(usize, usize)> = lattice_rows
        .iter()
        .flat_map(|&i| lattice_columns.iter().map(move |&j| (i, j)))
        .collect();
    let truth_at = lattice_truths(spec, &points, step);
    let at = |i: usize, j: usize| truth_at[&(i, j)];
    let file = |i: usize, j: usize| table.value[i * columns + j];
    let max_over = |f: &dyn Fn(usize, usize) -> f64| {
        points
            .iter()
            .map(|&(i, j)| f(i, j).abs())
            .fold(0.0_f64, f64::max)
    };
    let flipped = max_over(&|i, j| file(i, j) - at(rows - 1 - i, j).0);
    let alpha_r = (convention == RoughnessConvention::Perceptual)
        .then(|| max_over(&|i, j| file(i, j) - at(i, j).1.expect("perceptual")));
    let differences: Vec<f64> = points
        .iter()
        .map(|&(i, j)| file(i, j) - at(i, j).0)
        .collect();
    // A hypothesis explains the file if the file sits on the storage's floor under it.
    let explains = |e: f64| e <= (floor * 1.5).max(step) + 1e-6;
    if rows > 1 && explains(flipped) {
        return done(
            Finding::RowsFlipped,
            Some(flipped),
            format!(
                "the roughness rows are flipped: the nodes are off by up to {node_max_error:.2e} \
                 (the floor is {floor:.2e}), but against the truth with the rows reversed only \
                 {flipped:.2e}: write the rows in the other order"
            ),
        );
    }
    if let Some(e) = alpha_r.filter(|&e| explains(e)) {
        return done(
            Finding::AlphaIsR,
            Some(e),
            format!(
                "computed at alpha = r: the nodes are off by up to {node_max_error:.2e}, but \
                 against the truth at alpha = r only {e:.2e}. The roughness axis is perceptual \
                 (alpha = r^2): square the roughness before evaluating the BRDF"
            ),
        );
    }
    let lowest = differences.iter().copied().fold(f64::INFINITY, f64::min);
    let highest = differences
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let mean = differences.iter().sum::<f64>() / differences.len() as f64;
    let slack = 0.01 * step + 1e-6;
    if highest <= slack && lowest >= -step - slack && mean < -0.25 * step {
        return done(
            Finding::Truncated,
            Some(-lowest),
            format!(
                "truncated, not rounded: every error lies between -1 and 0 steps of {} storage \
                 (from {lowest:.2e} to {highest:.2e}, mean {mean:.2e}, where rounding gives \
                 +-{:.2e} around 0): store round({:.0} v), not floor",
                storage.name,
                0.5 * step,
                1.0 / step
            ),
        );
    }
    // Noise: the error's sign changes between neighbours on the lattice's rows far more often
    // than a smooth (model) error's would; only differences above the floor count.
    let significant = |d: f64| d.abs() > floor.max(0.5 * step) * 1.5;
    let (changes, pairs) = sign_changes(&lattice_rows, &lattice_columns, &|i, j| {
        Some(file(i, j) - at(i, j).0).filter(|&d| significant(d))
    });
    if pairs >= 8 && changes * 10 >= pairs * 3 {
        let rms =
            (differences.iter().map(|d| d * d).sum::<f64>() / differences.len() as f64).sqrt();
        return done(
            Finding::Noisy,
            Some(rms),
            format!(
                "noisy: the error (rms {rms:.2e} on the lattice, max {node_max_error:.2e}) \
                 changes sign between neighbouring texels {changes} times in {pairs}, like \
                 Monte Carlo noise; take more samples per texel (the floor is {floor:.2e})"
            ),
        );
    }
    done(
        Finding::Unexplained,
        None,
        format!(
            "not as good as {} storage allows: the nodes are off by up to {node_max_error:.2e}, \
             the floor is {floor:.2e}; the errors fit no usual mistake (flipped rows, alpha = r, \
             truncation, noise): check the model (masking, Fresnel) the layout wants",
            storage.name
        ),
    )
}

/// The truth at each lattice texel of `spec`'s table, and at `alpha = r` there (perceptual axes
/// only), with the reference to a hundredth of the storage's `step` (at most 1e-9).
fn lattice_truths(
    spec: &crate::table::TableSpec,
    points: &[(usize, usize)],
    step: f64,
) -> std::collections::HashMap<(usize, usize), (f64, Option<f64>)> {
    let settings = ReferenceSettings {
        tolerance: (0.01 * step).max(1e-9),
        ..ReferenceSettings::default()
    };
    let convention = spec.roughness_convention();
    let columns = spec.shape().get(1).copied().unwrap_or(1);
    // The truth at each lattice texel, and at `alpha = r` there (perceptual axes only).
    let truths: Vec<(f64, Option<f64>)> = points
        .par_iter()
        .map(|&(i, j)| {
            let k = i * columns + j;
            let (alpha, mu) = spec.texel_coordinates(k);
            let integral = spec.integral();
            let truth = integral
                .reference(
                    Coordinates {
                        alpha,
                        mu,
                        eta: None,
                    },
                    &settings,
                )
                .value;
            let alpha_is_r = (convention == RoughnessConvention::Perceptual).then(|| {
                let r = convention.from_alpha(alpha);
                integral
                    .reference(
                        Coordinates {
                            alpha: r,
                            mu,
                            eta: None,
                        },
                        &settings,
                    )
                    .value
            });
            (truth, alpha_is_r)
        })
        .collect();
    points.iter().copied().zip(truths).collect()
}

/// Sign changes between neighbours along each lattice row of the significant differences
/// (`difference(i, j)`, `None` where not significant), and the neighbouring pairs counted.
fn sign_changes(
    rows: &[usize],
    columns: &[usize],
    difference: &dyn Fn(usize, usize) -> Option<f64>,
) -> (usize, usize) {
    let (mut changes, mut pairs) = (0usize, 0usize);
    for &i in rows {
        let row: Vec<f64> = columns.iter().filter_map(|&j| difference(i, j)).collect();
        for w in row.windows(2) {
            pairs += 1;
            changes += usize::from(w[0].signum() != w[1].signum());
        }
    }
    (changes, pairs)
}

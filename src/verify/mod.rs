//! Auditing a table: its stored values against the deterministic reference (or another table) at
//! the coordinates it says it was computed at, and what a renderer's bilinear lookup of it returns
//! between those coordinates.

pub mod anisotropic_table;
pub mod anisotropy;
pub mod compensation;
pub mod error_map;
pub mod fit;
pub mod furnace;
pub mod glass_compensation;
pub mod input;
pub mod verdict;

pub use error_map::{ErrorMap, MAX_MAP_CELLS, error_maps};

use crate::integrate::reference::ReferenceSettings;
use crate::integrate::value::Integral;
use crate::model::RoughnessConvention;
use crate::table::{Table, TableSpec};
use rayon::prelude::*;
use serde::Serialize;

/// What the table is compared with.
#[derive(Clone, Copy, Debug)]
pub enum Against<'a> {
    /// The deterministic reference quadrature ([`crate::integrate::reference`]) at a tolerance
    /// tied to the errors measured ([`audit`]), never finer than these settings'.
    Reference(ReferenceSettings),
    /// The reference at exactly these settings' tolerance at every point, in one pass (what
    /// `kiln study` compares sizes with, so that its work is known in advance).
    ReferenceAt(ReferenceSettings),
    /// Another table, through its own bilinear lookup.
    Table(&'a Table),
}

/// How to audit.
#[derive(Clone, Copy, Debug)]
pub struct AuditSettings {
    /// The smallest coordinate the table's author actually computed at, on either axis (Cycles
    /// clamps `r` and `mu` to 1e-4): nodes below it are compared with the truth at this value.
    pub clamp_min: f64,
    /// Lookup points per texel along each axis (the axis ends are always included).
    pub density: usize,
    /// How the audited file stores its numbers, when that costs accuracy worth showing (an
    /// 8-bit image): the report then says what the storage alone costs ([`StorageCost`]).
    pub storage: Option<Storage>,
}

impl Default for AuditSettings {
    fn default() -> Self {
        Self {
            clamp_min: 0.0,
            density: 2,
            storage: None,
        }
    }
}

/// A way of storing numbers: its name and what it makes of a value.
#[derive(Clone, Copy, Debug)]
pub struct Storage {
    /// `8-bit`, say.
    pub name: &'static str,
    /// A value as stored, widened back.
    pub round: fn(f64) -> f64,
    /// The spacing of a fixed-point storage (`1 / 255` for 8 bits), 0 for a floating one: what
    /// [`verdict`] compares a file's errors with.
    pub step: f64,
}

/// What storing the truth itself would cost: the table of the true node values as the storage
/// holds them, audited at the same points against the same truth (no new reference values).
/// The floor of any table kept in that storage, to read beside the measured errors.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StorageCost {
    /// The storage's name.
    pub storage: String,
    pub node_max_error: f64,
    pub node_rms_error: f64,
    pub lookup_max_error: f64,
    pub lookup_rms_error: f64,
}

/// One compared point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Point {
    /// `mu` (absent for the averages).
    pub mu: Option<f64>,
    /// The relative index of refraction (tables with an IOR axis only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eta: Option<f64>,
    /// Roughness in the table's own convention (`r` or `alpha`).
    pub roughness: f64,
    pub alpha: f64,
    /// What the table gives there.
    pub table: f64,
    /// What the truth is.
    pub reference: f64,
    /// `|table - reference|`.
    pub error: f64,
}

/// The audit's findings.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    pub quantity: String,
    pub ndf: String,
    pub masking: String,
    pub roughness_axis: String,
    pub mu_axis: Option<String>,
    pub grid: String,
    pub shape: Vec<usize>,
    pub clamp_min: f64,
    /// `reference` or the other table's description.
    pub against: String,
    /// Stored values against the truth at their own coordinates.
    pub nodes: usize,
    pub node_max_error: f64,
    pub node_rms_error: f64,
    /// The reference tolerance the nodes were measured at (0 against a table; see [`audit`]).
    pub node_reference_tolerance: f64,
    pub worst_node: Point,
    /// The bilinear lookup against the truth on a dense grid that includes the axis ends, plus
    /// grazing probes down to `mu = 0` ([`lookup_coordinates`]).
    pub lookup_points: usize,
    pub lookup_max_error: f64,
    pub lookup_rms_error: f64,
    pub lookup_p99_error: f64,
    /// The reference tolerance the lookups were measured at (0 against a table).
    pub lookup_reference_tolerance: f64,
    pub worst_lookup: Point,
    /// The largest error estimate of the reference values used (0 against a table).
    pub reference_error_estimate: f64,
    /// Whether every reference quadrature met its tolerance.
    pub reference_converged: bool,
    /// What the file's storage alone costs ([`AuditSettings::storage`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub storage_cost: Option<StorageCost>,
    /// Every compared node, in texel order (for [`error_maps`]; not in the JSON).
    #[serde(skip)]
    pub node_points: Vec<Point>,
    /// Every lookup point, in [`lookup_coordinates`]' order (for [`error_maps`]).
    #[serde(skip)]
    pub lookup_points_compared: Vec<Point>,
}

/// Where a value is compared: `alpha`, and `mu` and the relative `eta` where the table has them
/// (the integration layer's [`crate::integrate::value::Point`]).
pub use crate::integrate::value::Point as Coordinates;

/// The audit's reference aims at this fraction of the smallest figure it reports for a group
/// of points (the nodes; the lookups), and settles anywhere between it and twice it: a lookup
/// error of 1e-4 does not need the truth to 1e-11. Gauss-Kronrod's estimate runs about a
/// hundred times above the quadrature's actual error (`integrate::reference`), so figures
/// stated to three digits keep them.
pub const REFERENCE_FRACTION: f64 = 1e-2;

/// The tolerance at which a sample of each group is scouted first to size its errors.
pub const SCOUT_TOLERANCE: f64 = 1e-6;

/// The coarsest tolerance a group is measured at: beyond it the reference's cost no longer
/// falls (GGX dielectric `E`: 15.9 k evaluations a point at 1e-4, 15.1 k at 1e-3, 22.6 k at
/// 1e-6), and its actual error stays far inside it (at most 1.3e-6 on a 1287-point grid over
/// eta, roughness and mu, against the reference at 1e-12: `cargo run --release --example
/// reference_margin`).
pub const COARSEST_TOLERANCE: f64 = 1e-4;

/// One point in this many is scouted (groups of fewer than four times as many are not scouted:
/// they start at the finest tolerance).
const SCOUT_STRIDE: usize = 8;

/// What [`audit`] tells its progress callback.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// This many more comparisons are planned (a pass over a group begins).
    Planned(u64),
    /// One comparison is done.
    Compared,
}

/// The compared points of one group with their truth's error estimates and convergence, and the
/// reference tolerance they were measured at (0 against a table).
struct Measured {
    points: Vec<(Point, f64, bool)>,
    tolerance: f64,
}

impl Measured {
    fn max(&self) -> f64 {
        crate::stats::max_or_nan(self.points.iter().map(|p| p.0.error))
    }

    fn rms(&self) -> f64 {
        let n = self.points.len() as f64;
        (self
            .points
            .iter()
            .map(|p| p.0.error * p.0.error)
            .sum::<f64>()
            / n)
            .sqrt()
    }

    /// The 99th percentile of the errors.
    fn p99(&self) -> f64 {
        let mut errors: Vec<f64> = self.points.iter().map(|p| p.0.error).collect();
        errors.sort_by(f64::total_cmp);
        errors[((0.99 * errors.len() as f64).ceil() as usize).clamp(1, errors.len()) - 1]
    }

    fn worst(&self) -> Point {
        self.points
            .iter()
            .map(|p| p.0)
            .max_by(|a, b| a.error.total_cmp(&b.error))
            .expect("points")
    }

    /// The smallest figure the report states for this group.
    fn smallest_figure(&self, with_p99: bool) -> f64 {
        let smallest = self.max().min(self.rms());
        if with_p99 {
            smallest.min(self.p99())
        } else {
            smallest
        }
    }
}

/// The reference tolerance for a group whose smallest figure is `figure`: [`REFERENCE_FRACTION`]
/// of it, within `[finest, COARSEST_TOLERANCE]` (the finest when the figure is 0).
fn tolerance_for(figure: f64, finest: f64) -> f64 {
    (REFERENCE_FRACTION * figure).clamp(finest, COARSEST_TOLERANCE.max(finest))
}

/// Compares the stored values with the truth at the nodes ([`node_errors`]) and the table's
/// lookup with the truth on a dense grid. Reference evaluations run in parallel (deterministic:
/// each point is a pure function of its coordinates and the tolerance).
///
/// Against the reference, each group (nodes, lookups) is measured at a tolerance tied to the
/// errors it reports ([`REFERENCE_FRACTION`] of its smallest figure), never finer than the
/// given settings' tolerance: every eighth point is scouted at [`SCOUT_TOLERANCE`], the group is
/// measured at the tolerance the scout's figures call for, and again at a finer one if its own
/// figures call for that. The report states the tolerances used.
/// `progress` hears of each pass as it is planned and of each comparison.
#[must_use]
pub fn audit(
    table: &Table,
    against: &Against,
    settings: &AuditSettings,
    progress: &(dyn Fn(Progress) + Sync),
) -> Report {
    let spec = &table.spec;
    let integral = spec.integral();
    let convention = spec.roughness_convention();
    let clamp = |x: f64| x.max(settings.clamp_min);

    // Nodes: each stored value against the truth where the table says it was computed (with
    // the roughness and mu clamped as the author says they clamped them).
    let nodes: Vec<(Coordinates, f64)> = (0..spec.len())
        .map(|k| {
            let (alpha, mu, eta) = spec.texel_point(k);
            let at = Coordinates {
                alpha: convention.to_alpha(clamp(convention.from_alpha(alpha))),
                mu: mu.map(clamp),
                eta,
            };
            (at, table.value[k])
        })
        .collect();
    // Lookups at every point of `lookup_coordinates`.
    let lookups: Vec<(Coordinates, f64)> = lookup_coordinates(spec, settings)
        .into_iter()
        .map(|at| {
            let value = table.lookup_eta(
                at.mu.unwrap_or(1.0),
                convention.from_alpha(at.alpha),
                at.eta.unwrap_or(1.0),
            );
            (at, value)
        })
        .collect();

    let comparison = Comparison {
        against,
        integral,
        convention,
        progress,
    };
    let mut node_group = comparison.measure(&nodes, false);
    // Against a table of the same layout, node k is compared with its node k (a lookup at the
    // physical point of the `alpha = 0` row of an adaptive axis, computed at alpha = 1e-7, would
    // sit a hair off that row).
    if let Against::Table(other) = against
        && other.spec.axes() == spec.axes()
    {
        for (k, p) in node_group.points.iter_mut().enumerate() {
            p.0.reference = other.value[k];
            p.0.error = (p.0.table - p.0.reference).abs();
        }
    }
    let lookup_group = comparison.measure(&lookups, true);

    let storage_cost = settings
        .storage
        .map(|storage| storage_cost(table, storage, &node_group, &lookup_group, &lookups));
    let all = node_group.points.iter().chain(&lookup_group.points);
    let reference_error_estimate = crate::stats::max_or_nan(all.clone().map(|p| p.1));
    let reference_converged = all.clone().all(|p| p.2);
    let (worst_node, worst_lookup) = (node_group.worst(), lookup_group.worst());
    Report {
        quantity: spec.quantity.symbol().to_string(),
        ndf: spec.model.ndf.name().to_string(),
        masking: spec.model.masking.name().to_string(),
        roughness_axis: match spec.roughness {
            Some(_) => convention.name().to_string(),
            None => "none".to_string(),
        },
        mu_axis: spec.mu.map(|axis| match axis {
            crate::table::axis::Axis::Mu { mapping, .. } => mapping.name().to_string(),
            _ => unreachable!(),
        }),
        grid: spec.axes()[0].grid().name().to_string(),
        shape: spec.shape(),
        clamp_min: settings.clamp_min,
        against: match against {
            Against::Reference(_) | Against::ReferenceAt(_) => "reference".to_string(),
            Against::Table(other) => format!("table {}", other.spec.id()),
        },
        nodes: node_group.points.len(),
        node_max_error: worst_node.error,
        node_rms_error: node_group.rms(),
        node_reference_tolerance: node_group.tolerance,
        worst_node,
        lookup_points: lookup_group.points.len(),
        lookup_max_error: worst_lookup.error,
        lookup_rms_error: lookup_group.rms(),
        lookup_p99_error: lookup_group.p99(),
        lookup_reference_tolerance: lookup_group.tolerance,
        worst_lookup,
        reference_error_estimate,
        reference_converged,
        storage_cost,
        node_points: node_group.points.iter().map(|p| p.0).collect(),
        lookup_points_compared: lookup_group.points.iter().map(|p| p.0).collect(),
    }
}

/// What [`audit`] compares a group of values with, and how: the truth of the table's integral
/// (or another table), its roughness convention, and the caller's progress.
struct Comparison<'a> {
    against: &'a Against<'a>,
    integral: Integral,
    convention: RoughnessConvention,
    progress: &'a (dyn Fn(Progress) + Sync),
}

impl Comparison<'_> {
    /// One group's values against the truth, with its error estimate, at `tolerance`.
    fn compare(&self, group: &[(Coordinates, f64)], tolerance: f64) -> Measured {
        (self.progress)(Progress::Planned(group.len() as u64));
        let points = group
            .par_iter()
            .map(|&(at, value)| {
                let (reference, error_estimate, converged) = match self.against {
                    Against::Reference(finest) | Against::ReferenceAt(finest) => {
                        let settings = ReferenceSettings {
                            tolerance,
                            ..*finest
                        };
                        let r = self.integral.reference(at, &settings);
                        (r.value, r.error, r.converged)
                    }
                    Against::Table(other) => {
                        let theirs = other.spec.roughness_convention().from_alpha(at.alpha);
                        let eta = at.eta.unwrap_or(1.0);
                        let v = other.lookup_eta(at.mu.unwrap_or(1.0), theirs, eta);
                        (v, 0.0, true)
                    }
                };
                (self.progress)(Progress::Compared);
                let Coordinates { alpha, mu, eta } = at;
                let point = Point {
                    mu,
                    eta,
                    roughness: self.convention.from_alpha(alpha),
                    alpha,
                    table: value,
                    reference,
                    error: (value - reference).abs(),
                };
                (point, error_estimate, converged)
            })
            .collect();
        Measured { points, tolerance }
    }

    /// A group against the reference at the tolerance its figures call for: a scout of every
    /// `SCOUT_STRIDE`-th point first, then the whole group, refined until the tolerance is
    /// within a factor of two of what its figures call for.
    fn measure(&self, group: &[(Coordinates, f64)], with_p99: bool) -> Measured {
        let finest = match self.against {
            Against::Reference(finest) => finest,
            Against::ReferenceAt(fixed) => return self.compare(group, fixed.tolerance),
            Against::Table(_) => return self.compare(group, 0.0),
        };
        let finest = finest.tolerance;
        let mut tolerance = finest;
        let mut scouted = None;
        if group.len() >= 4 * SCOUT_STRIDE && finest < SCOUT_TOLERANCE {
            let sample: Vec<(Coordinates, f64)> =
                group.iter().copied().step_by(SCOUT_STRIDE).collect();
            let scout = self.compare(&sample, SCOUT_TOLERANCE);
            let figure = scout.smallest_figure(with_p99);
            tolerance = if figure.is_finite() {
                tolerance_for(figure, finest)
            } else {
                SCOUT_TOLERANCE
            };
            scouted = Some(scout);
        }
        loop {
            let measured = match scouted.take() {
                // The scouted points already hold the truth at this tolerance or a finer one:
                // only the rest.
                Some(scout) if tolerance >= scout.tolerance => {
                    let rest: Vec<(Coordinates, f64)> = group
                        .iter()
                        .enumerate()
                        .filter(|(k, _)| k % SCOUT_STRIDE != 0)
                        .map(|(_, p)| *p)
                        .collect();
                    let (mut scout_points, mut rest_points) = (
                        scout.points.into_iter(),
                        self.compare(&rest, tolerance).points.into_iter(),
                    );
                    let points = (0..group.len())
                        .map(|k| {
                            if k % SCOUT_STRIDE == 0 {
                                scout_points.next()
                            } else {
                                rest_points.next()
                            }
                            .expect("every point measured once")
                        })
                        .collect();
                    Measured { points, tolerance }
                }
                _ => self.compare(group, tolerance),
            };
            let figure = measured.smallest_figure(with_p99);
            let needed = tolerance_for(figure, finest);
            // Settled within a factor of two of what the figures call for (or NaN: nothing to
            // refine).
            if !figure.is_finite() || needed >= 0.5 * tolerance {
                return measured;
            }
            tolerance = needed;
        }
    }
}

/// [`StorageCost`]: the true node values as `storage` holds them, compared with the truth at the
/// nodes and, through the table's own lookup, at the lookup points.
fn storage_cost(
    table: &Table,
    storage: Storage,
    nodes: &Measured,
    lookups: &Measured,
    lookup_points: &[(Coordinates, f64)],
) -> StorageCost {
    let stored: Vec<f64> = nodes
        .points
        .iter()
        .map(|p| (storage.round)(p.0.reference))
        .collect();
    let truth = Table {
        one_minus_value: stored.iter().map(|v| 1.0 - v).collect(),
        value: stored,
        ..table.clone()
    };
    let convention = table.spec.roughness_convention();
    let rms = |errors: &[f64]| {
        (errors.iter().map(|e| e * e).sum::<f64>() / errors.len().max(1) as f64).sqrt()
    };
    let node_errors: Vec<f64> = nodes
        .points
        .iter()
        .zip(&truth.value)
        .map(|(p, v)| (v - p.0.reference).abs())
        .collect();
    let lookup_errors: Vec<f64> = lookups
        .points
        .iter()
        .zip(lookup_points)
        .map(|(p, (at, _))| {
            let value = truth.lookup_eta(
                at.mu.unwrap_or(1.0),
                convention.from_alpha(at.alpha),
                at.eta.unwrap_or(1.0),
            );
            (value - p.0.reference).abs()
        })
        .collect();
    StorageCost {
        storage: storage.name.to_string(),
        node_max_error: crate::stats::max_or_nan(node_errors.iter().copied()),
        node_rms_error: rms(&node_errors),
        lookup_max_error: crate::stats::max_or_nan(lookup_errors.iter().copied()),
        lookup_rms_error: rms(&lookup_errors),
    }
}

/// The grazing probes [`audit`] adds on every roughness of its ladder.
pub(crate) use crate::table::axis::grazing_probes;

/// The points at which [`audit`] compares lookups: a ladder over each axis' texture coordinate
/// `t` in [0, 1], in steps of `1 / (density N)` (texel centres or nodes, the points halfway
/// between, and the axis ends), and for a table with a `mu` axis the grazing probes on every
/// rung of the roughness ladder.
#[must_use]
pub fn lookup_coordinates(spec: &TableSpec, settings: &AuditSettings) -> Vec<Coordinates> {
    let ladder = |n: usize| -> Vec<f64> {
        let steps = settings.density.max(1) * n;
        (0..=steps).map(|j| j as f64 / steps as f64).collect()
    };
    // The IOR ladder in the axis' own coordinate: on a `glass` axis the index at a coordinate
    // depends on the roughness (the rung's alpha, or the layer limit's on the row alpha = 0).
    let t_etas: Vec<Option<f64>> = match spec.ior {
        Some(axis) => ladder(axis.size()).into_iter().map(Some).collect(),
        None => vec![None],
    };
    let eta_up_at = |t_eta: Option<f64>, row_alpha: f64| t_eta.map(|t| spec.ior_at(t, row_alpha));
    let mut points = Vec::new();
    for t_eta in t_etas {
        let Some(roughness) = spec.roughness else {
            points.push(Coordinates {
                alpha: 0.0,
                mu: None,
                eta: eta_up_at(t_eta, 0.0).map(|eta| spec.relative_eta(eta)),
            });
            continue;
        };
        for t_r in ladder(roughness.size()) {
            let eta_up = eta_up_at(t_eta, spec.row_alpha(t_r));
            let eta = eta_up.map(|eta| spec.relative_eta(eta));
            let at = |(alpha, mu): (f64, Option<f64>)| Coordinates { alpha, mu, eta };
            match spec.mu {
                Some(axis) => {
                    for t_mu in ladder(axis.size()) {
                        points.push(at(spec.point_at(t_r, t_mu, eta_up.unwrap_or(1.0))));
                    }
                    let alpha = roughness.alpha_at_coordinate(t_r);
                    points.extend(grazing_probes().into_iter().map(|mu| at((alpha, Some(mu)))));
                }
                None => points.push(at(spec.point(t_r, 0.0))),
            }
        }
    }
    points
}

/// How many points [`lookup_coordinates`] makes, counted without making them (saturating): what
/// a cost estimate and [`check_audit_size`] read before anything is allocated.
#[must_use]
pub fn lookup_coordinate_count(spec: &TableSpec, settings: &AuditSettings) -> u64 {
    let ladder = |n: usize| (settings.density.max(1) as u64).saturating_mul(n as u64) + 1;
    let etas = spec.ior.map_or(1, |axis| ladder(axis.size()));
    let Some(roughness) = spec.roughness else {
        return etas;
    };
    let per_rung = spec.mu.map_or(1, |axis| {
        ladder(axis.size()).saturating_add(grazing_probes().len() as u64)
    });
    etas.saturating_mul(ladder(roughness.size()))
        .saturating_mul(per_rung)
}

/// How many points one pass of [`audit`] compares: every node and every [`lookup_coordinates`]
/// point (against the reference, the scouts and any refining pass come on top:
/// [`Progress::Planned`] announces each). Counted, not built.
#[must_use]
pub fn audit_points(spec: &TableSpec, settings: &AuditSettings) -> u64 {
    (spec.len() as u64).saturating_add(lookup_coordinate_count(spec, settings))
}

/// The most points (nodes and lookups) one [`audit`] compares. The audit holds every point in
/// memory for its figures, its 99th percentile and its error maps, about 220 bytes each (the
/// point, its coordinates and its measurement, and the report's copy): 2^22 points are about
/// 0.9 GB. A 128 x 128 table at `--density 8` is 1.1 M points, a 1024 x 1024 one at density 1
/// 2.1 M.
pub const MAX_AUDIT_POINTS: u64 = 1 << 22;

/// Refuses, by name and before anything is allocated, an audit of more than
/// [`MAX_AUDIT_POINTS`] points, saying which density would fit.
pub fn check_audit_size(spec: &TableSpec, settings: &AuditSettings) -> crate::Result<()> {
    let points = audit_points(spec, settings);
    if points <= MAX_AUDIT_POINTS {
        return Ok(());
    }
    let shape: Vec<String> = spec.shape().iter().map(ToString::to_string).collect();
    let fits = (1..settings.density.max(1)).rev().find(|&density| {
        let smaller = AuditSettings {
            density,
            ..*settings
        };
        audit_points(spec, &smaller) <= MAX_AUDIT_POINTS
    });
    let advice = match fits {
        Some(density) => format!("take --density {density} or less"),
        None => "no density fits: audit a table baked at a smaller --size (the lookups between \
                 its texels stay as close as its nodes' errors allow)"
            .to_string(),
    };
    Err(crate::Error::InvalidInput(format!(
        "auditing the {} table ({} texels) at --density {} compares {points} points, more than \
         the {MAX_AUDIT_POINTS} (2^22, about 0.9 GB) an audit holds in memory: {advice}",
        shape.join(" x "),
        spec.len(),
        settings.density.max(1),
    )))
}

/// The largest number of `E_avg` entries [`node_errors`] checks: each costs the reference a
/// few hundredths of a second of CPU at 1e-9, and up to half a second where no fixed rule
/// serves ([`crate::integrate::average_quadrature::average_albedo_to`]).
pub const MAX_AVERAGE_ENTRIES_CHECKED: usize = 5;

/// Node errors of a freshly baked table against the reference, in `1 - E` (which both carry
/// directly): on every texel of an `E` table, and on at most [`MAX_AVERAGE_ENTRIES_CHECKED`]
/// evenly spaced entries of an `E_avg` table, first and last included (by
/// [`crate::integrate::average_quadrature::average_albedo_to`]: the fixed rule whose measured
/// bound is within half the tolerance, or the composite rule). What `kiln bake` records.
#[must_use]
pub fn node_errors(table: &Table, settings: &ReferenceSettings) -> NodeErrors {
    node_errors_at(table, &node_error_indices(&table.spec), settings)
}

/// At most `count` indices of `0..n`, evenly spread with both ends (all of them if `n <= count`).
#[must_use]
pub fn spread_indices(n: usize, count: usize) -> Vec<usize> {
    if n <= count {
        return (0..n).collect();
    }
    let last = count - 1;
    (0..=last)
        .map(|j| (j * (n - 1) + last / 2) / last)
        .collect()
}

/// The texels [`node_errors`] checks.
#[must_use]
pub fn node_error_indices(spec: &TableSpec) -> Vec<usize> {
    if spec.quantity.has_mu() {
        (0..spec.len()).collect()
    } else {
        spread_indices(spec.len(), MAX_AVERAGE_ENTRIES_CHECKED)
    }
}

/// As [`node_errors`], at the given texel indices only.
#[must_use]
pub fn node_errors_at(
    table: &Table,
    indices: &[usize],
    settings: &ReferenceSettings,
) -> NodeErrors {
    summarise_node_errors(&node_error_terms(
        &table.spec,
        indices,
        &|k| (table.value[k], table.one_minus_value[k]),
        settings,
    ))
}

/// One term per texel of `indices`: the error of the stored `(value, one_minus_value)` that
/// `stored` gives against the reference, and whether the reference converged (if not, the
/// error is the difference plus the reference's own estimate, so that it stays a bound). In
/// parallel, in the order of `indices`. A sharded bake measures each shard's texels where they
/// were computed and [`summarise_node_errors`] the concatenation, as the unsharded bake does.
#[must_use]
pub fn node_error_terms(
    spec: &TableSpec,
    indices: &[usize],
    stored: &(dyn Fn(usize) -> (f64, f64) + Sync),
    settings: &ReferenceSettings,
) -> Vec<(f64, bool)> {
    indices
        .par_iter()
        .map(|&k| {
            let (alpha, mu, eta) = spec.texel_point(k);
            let at = Coordinates { alpha, mu, eta };
            let reference = spec.integral().reference(at, settings);
            let (value, one_minus_value) = stored(k);
            // `1 - E` where both carry it directly; the split-sum channels and `E_F` by value.
            let difference = if spec.quantity.varies_on_a_mirror() {
                (value - reference.value).abs()
            } else {
                (one_minus_value - reference.one_minus_value).abs()
            };
            // A reference that ran out of budget is only known to within its own error
            // estimate: the error stated is the difference plus that, never less.
            if reference.converged {
                (difference, true)
            } else {
                (difference + reference.error, false)
            }
        })
        .collect()
}

/// The summary of [`node_error_terms`] (in their order, so that the sum is the same however
/// they were computed).
#[must_use]
pub fn summarise_node_errors(measured: &[(f64, bool)]) -> NodeErrors {
    NodeErrors {
        max: crate::stats::max_or_nan(measured.iter().map(|m| m.0)),
        rms: (measured.iter().map(|m| m.0 * m.0).sum::<f64>() / measured.len() as f64).sqrt(),
        texels: measured.len(),
        unconverged: measured.iter().filter(|m| !m.1).count(),
    }
}

/// The node errors `kiln bake` measures and records (a table's own record).
pub use crate::table::NodeErrors;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Quantity;
    use crate::table::axis::{Grid, MuMapping};
    use crate::table::test_e_spec;

    /// A compared point with only its error (and `mu`, to tell points apart) set.
    fn point(mu: f64, error: f64) -> Point {
        Point {
            mu: Some(mu),
            eta: None,
            roughness: 0.5,
            alpha: 0.25,
            table: 0.0,
            reference: 0.0,
            error,
        }
    }

    fn measured(errors: &[f64]) -> Measured {
        Measured {
            points: errors
                .iter()
                .enumerate()
                .map(|(k, &e)| (point(k as f64, e), 0.0, true))
                .collect(),
            tolerance: 0.0,
        }
    }

    pub(super) fn table(spec: TableSpec, value: Vec<f64>) -> Table {
        input::table_from_channel(spec, value, String::new())
    }

    /// Two tables of `spec`'s layout: ours holds `0.5 + 0.01 k` at texel `k`, theirs that less
    /// `1e-3 (k + 1)`.
    pub(super) fn tables_apart(spec: &TableSpec) -> (Table, Table) {
        let ours: Vec<f64> = (0..spec.len()).map(|k| 0.5 + 0.01 * k as f64).collect();
        let theirs = ours
            .iter()
            .enumerate()
            .map(|(k, v)| v - 1e-3 * (k + 1) as f64)
            .collect();
        (table(spec.clone(), ours), table(spec.clone(), theirs))
    }

    #[test]
    fn a_groups_figures_are_worked_by_hand() {
        let m = measured(&[3.0, 0.0, 4.0, 0.0]);
        assert_eq!(m.max(), 4.0);
        assert_eq!(m.rms(), 2.5);
        assert_eq!(m.worst().mu, Some(2.0));
        // Sorted [0, 0, 3, 4]: the 99th percentile of four is the fourth.
        assert_eq!(m.p99(), 4.0);
        assert_eq!(m.smallest_figure(false), 2.5);
        assert_eq!(m.smallest_figure(true), 2.5);
        // 1, 2, ..., 200: the 99th percentile is the 198th.
        let ramp: Vec<f64> = (1..=200).map(f64::from).collect();
        assert_eq!(measured(&ramp).p99(), 198.0);
        // 99 zeros and 100: max 100, rms 10, p99 0.
        let mut spike = vec![0.0; 99];
        spike.push(100.0);
        let m = measured(&spike);
        assert_eq!((m.max(), m.rms(), m.p99()), (100.0, 10.0, 0.0));
        assert_eq!(m.smallest_figure(false), 10.0);
        assert_eq!(m.smallest_figure(true), 0.0);
        assert!(measured(&[1.0, f64::NAN]).max().is_nan());
    }

    #[test]
    fn the_reference_tolerance_is_a_hundredth_of_the_figure_within_its_bounds() {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-15 * b;
        assert!(close(tolerance_for(1e-6, 1e-11), 1e-8));
        assert!(close(tolerance_for(3e-7, 1e-11), 3e-9));
        // Coarser than the coarsest: the coarsest.
        assert!(close(tolerance_for(1e-3, 1e-11), 1e-5));
        assert_eq!(tolerance_for(0.5, 1e-11), COARSEST_TOLERANCE);
        // Finer than the finest allowed, or 0: the finest.
        assert_eq!(tolerance_for(1e-9, 1e-10), 1e-10);
        assert_eq!(tolerance_for(0.0, 1e-11), 1e-11);
        // A finest coarser than the coarsest wins.
        assert_eq!(tolerance_for(1e-3, 1e-3), 1e-3);
        assert!(close(tolerance_for(1e-3, 1e-6), 1e-5));
        assert_eq!(tolerance_for(1e-12, 1e-5), 1e-5);
    }

    #[test]
    fn spread_indices_take_both_ends_and_even_steps() {
        assert_eq!(spread_indices(10, 5), vec![0, 2, 5, 7, 9]);
        assert_eq!(spread_indices(17, 5), vec![0, 4, 8, 12, 16]);
        assert_eq!(spread_indices(100, 2), vec![0, 99]);
        assert_eq!(spread_indices(5, 5), vec![0, 1, 2, 3, 4]);
        assert_eq!(spread_indices(3, 5), vec![0, 1, 2]);
        // Every texel of an E table; five of seventeen E_avg entries.
        let e = test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear);
        assert_eq!(node_error_indices(&e), (0..12).collect::<Vec<_>>());
        let e_avg = e_avg_spec(17);
        assert_eq!(node_error_indices(&e_avg), vec![0, 4, 8, 12, 16]);
    }

    /// A glass table's spec: `quantity` over a linear IOR axis of `iors` nodes to 3, then
    /// `rows` x `columns` as [`test_e_spec`]'s.
    pub(super) fn glass_spec(
        quantity: Quantity,
        iors: usize,
        rows: usize,
        columns: usize,
    ) -> TableSpec {
        TableSpec {
            quantity,
            ior: Some(crate::table::axis::Axis::Ior {
                size: iors,
                mapping: crate::table::axis::IorMapping::Linear,
                max: crate::table::axis::IorBound(3.0),
                grid: Grid::Nodes,
            }),
            ..test_e_spec(rows, columns, Grid::Nodes, MuMapping::Linear)
        }
    }

    pub(super) fn e_avg_spec(rows: usize) -> TableSpec {
        TableSpec {
            quantity: Quantity::EAvg,
            mu: None,
            ..test_e_spec(rows, 2, Grid::Nodes, MuMapping::Linear)
        }
    }

    #[test]
    fn grazing_probes_reach_zero_and_climb_in_quarter_decades() {
        let probes = grazing_probes();
        assert_eq!(probes.len(), 27);
        assert_eq!(&probes[..3], &[0.0, 1e-12, 1e-6]);
        for (k, decade) in [
            (6, 1e-5),
            (10, 1e-4),
            (14, 1e-3),
            (18, 1e-2),
            (22, 0.1),
            (26, 1.0),
        ] {
            assert!(
                (probes[k] / decade - 1.0).abs() < 1e-14,
                "{k}: {}",
                probes[k]
            );
        }
        assert!((probes[3] / 10f64.powf(-5.75) - 1.0).abs() < 1e-14);
        assert!(probes.windows(2).all(|w| w[0] < w[1]));
    }

    /// The audit's size is counted from the axes (what `kiln verify` and a fitted bake read
    /// before anything is allocated) and is what the audit then makes; past
    /// [`MAX_AUDIT_POINTS`] it is refused, naming the largest density that fits.
    #[test]
    fn the_audit_is_counted_without_being_made_and_bounded() {
        for density in [0, 1, 2, 3, 7] {
            let settings = AuditSettings {
                density,
                ..AuditSettings::default()
            };
            for spec in [
                test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear),
                test_e_spec(6, 2, Grid::Centers, MuMapping::Sqrt),
                e_avg_spec(6),
                glass_spec(Quantity::EDielectric, 3, 3, 4),
            ] {
                assert_eq!(
                    lookup_coordinate_count(&spec, &settings),
                    lookup_coordinates(&spec, &settings).len() as u64,
                    "{} at density {density}",
                    spec.id()
                );
            }
        }
        // A 128 x 128 table at density 64: 8193 rungs of 8193 mu points and 27 probes, and
        // its 16384 nodes; 2^22 points hold density 15 (1921 x 1948 + 16384 = 3758492), not
        // 16 (2049 x 2076 + 16384 = 4270108).
        let big = test_e_spec(128, 128, Grid::Centers, MuMapping::Linear);
        let at = |density| AuditSettings {
            density,
            ..AuditSettings::default()
        };
        assert_eq!(audit_points(&big, &at(64)), 16384 + 8193 * (8193 + 27));
        let message = check_audit_size(&big, &at(64)).unwrap_err().to_string();
        assert!(
            message.contains("--density 64") && message.contains("take --density 15 or less"),
            "{message}"
        );
        check_audit_size(&big, &at(15)).expect("density 15 fits");
        assert!(check_audit_size(&big, &at(16)).is_err());
        // A table whose nodes alone are past the bound: no density fits, and it says so.
        let huge = test_e_spec(4096, 4096, Grid::Centers, MuMapping::Linear);
        let message = check_audit_size(&huge, &at(1)).unwrap_err().to_string();
        assert!(message.contains("no density fits"), "{message}");
    }

    #[test]
    fn lookup_coordinates_are_the_ladders_and_the_probes() {
        let spec = test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear);
        let settings = AuditSettings::default();
        let points = lookup_coordinates(&spec, &settings);
        // Roughness: 2 x 3 steps, 7 rungs; each 2 x 4 steps of mu (9 points) and 27 probes.
        assert_eq!(points.len(), 7 * (9 + 27));
        assert_eq!(audit_points(&spec, &settings), 12 + 7 * 36);
        // The rung t = 1/2 of a perceptual axis is alpha = 1/4; its mu ladder is linear in t.
        let rung = &points[3 * 36..4 * 36];
        assert!(rung.iter().all(|p| p.alpha == 0.25 && p.eta.is_none()));
        let mus: Vec<f64> = rung.iter().map(|p| p.mu.unwrap()).collect();
        assert_eq!(
            mus[..9],
            [0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0]
        );
        assert_eq!(mus[9..], grazing_probes()[..]);
        assert_eq!(points[0].alpha, 0.0);
        assert_eq!(points.last().unwrap().alpha, 1.0);
        // Density 3 and density 0 (taken as 1).
        let dense = AuditSettings {
            density: 3,
            ..settings
        };
        assert_eq!(lookup_coordinates(&spec, &dense).len(), 10 * (13 + 27));
        let sparse = AuditSettings {
            density: 0,
            ..settings
        };
        assert_eq!(lookup_coordinates(&spec, &sparse).len(), 4 * (5 + 27));
        // Over an IOR axis: the ladders at each rung of the IOR ladder, `eta = 1 + 2 t` on a
        // linear axis to 3 (its reciprocal for light from inside).
        for (quantity, at_half) in [
            (Quantity::EDielectric, 2.0),
            (Quantity::EDielectricInside, 0.5),
        ] {
            let glass = glass_spec(quantity, 3, 3, 4);
            let points = lookup_coordinates(&glass, &settings);
            assert_eq!(points.len(), 7 * 7 * 36);
            assert!(points[..7 * 36].iter().all(|p| p.eta == Some(1.0)));
            assert!(
                points[3 * 7 * 36..4 * 7 * 36]
                    .iter()
                    .all(|p| p.eta == Some(at_half))
            );
            assert_eq!(points[3 * 7 * 36 + 36 * 3 + 4].mu, Some(0.5));
        }
        // A table without mu: the roughness ladder alone, with no mu.
        let points = lookup_coordinates(&e_avg_spec(5), &settings);
        assert_eq!(points.len(), 11);
        assert!(points.iter().all(|p| p.mu.is_none()));
        assert_eq!(points[5].alpha, 0.25);
    }

    #[test]
    fn node_errors_are_summarised_with_nan_and_unconverged_kept() {
        let s = summarise_node_errors(&[(3.0, true), (4.0, false), (0.0, true)]);
        assert_eq!(s.max, 4.0);
        assert!((s.rms - (25.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!((s.texels, s.unconverged), (3, 1));
        assert!(
            summarise_node_errors(&[(1.0, true), (f64::NAN, true)])
                .max
                .is_nan()
        );
    }

    /// The stored values against the reference worked separately: `1 - E` for E, the value
    /// for a split-sum channel, and an unconverged reference's estimate added on.
    #[test]
    fn node_error_terms_compare_the_channel_that_carries_the_quantity() {
        let settings = ReferenceSettings {
            tolerance: 1e-10,
            ..ReferenceSettings::default()
        };
        let truth = |spec: &TableSpec, k: usize, settings: &ReferenceSettings| {
            let (alpha, mu) = spec.texel_coordinates(k);
            spec.integral().reference(
                Coordinates {
                    alpha,
                    mu,
                    eta: None,
                },
                settings,
            )
        };
        let e = test_e_spec(2, 3, Grid::Centers, MuMapping::Linear);
        let indices = [0, 4, 5];
        // E: an error in `1 - E` counts, one in E alone does not.
        let terms = node_error_terms(
            &e,
            &indices,
            &|k| {
                let r = truth(&e, k, &settings);
                (r.value + 0.5, r.one_minus_value + 1e-3 * k as f64)
            },
            &settings,
        );
        for (term, k) in terms.iter().zip(indices) {
            assert!(term.1);
            assert!((term.0 - 1e-3 * k as f64).abs() < 1e-12, "{k}: {term:?}");
        }
        // A split-sum channel: the value counts.
        let scale = TableSpec {
            quantity: Quantity::EScale,
            ..e.clone()
        };
        let terms = node_error_terms(
            &scale,
            &indices,
            &|k| {
                let r = truth(&scale, k, &settings);
                (r.value - 1e-3 * k as f64, r.one_minus_value + 0.5)
            },
            &settings,
        );
        for (term, k) in terms.iter().zip(indices) {
            assert!((term.0 - 1e-3 * k as f64).abs() < 1e-12, "{k}: {term:?}");
        }
        // A reference out of budget: the difference plus its own estimate, flagged.
        let starved = ReferenceSettings {
            tolerance: 1e-15,
            max_intervals: 1,
        };
        let terms = node_error_terms(
            &e,
            &[0],
            &|k| (0.0, truth(&e, k, &starved).one_minus_value + 1e-3),
            &starved,
        );
        let r = truth(&e, 0, &starved);
        assert!(!r.converged && r.error > 0.0);
        assert!(!terms[0].1);
        assert!(
            (terms[0].0 - (1e-3 + r.error)).abs() < 1e-15,
            "{terms:?} {r:?}"
        );
        assert_eq!(
            summarise_node_errors(&terms).unconverged,
            1,
            "counted as unconverged"
        );
    }

    /// Two tables of the same layout a known amount apart: every figure of the audit follows.
    #[test]
    fn an_audit_against_a_table_reports_the_differences_node_by_node() {
        let spec = test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear);
        let (ours, theirs) = tables_apart(&spec);
        let storage = Storage {
            name: "plus",
            round: |x| x + 2e-3,
            step: 0.0,
        };
        let settings = AuditSettings {
            storage: Some(storage),
            ..AuditSettings::default()
        };
        let planned = std::sync::Mutex::new(Vec::new());
        let compared = std::sync::atomic::AtomicU64::new(0);
        let report = audit(&ours, &Against::Table(&theirs), &settings, &|p| match p {
            Progress::Planned(n) => planned.lock().unwrap().push(n),
            Progress::Compared => {
                compared.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
        });
        // Against a table: one pass per group, no scouting.
        assert_eq!(*planned.lock().unwrap(), vec![12, 7 * 36]);
        assert_eq!(compared.into_inner(), 12 + 7 * 36);
        assert_eq!(report.nodes, 12);
        assert!((report.node_max_error - 12e-3).abs() < 1e-12);
        let rms = 1e-3 * ((1..=12).map(|k| k * k).sum::<i32>() as f64 / 12.0).sqrt();
        assert!((report.node_rms_error - rms).abs() < 1e-12);
        // The worst node is the last: roughness 1, mu 1.
        assert_eq!(report.worst_node.mu, Some(1.0));
        assert_eq!(
            (report.worst_node.roughness, report.worst_node.alpha),
            (1.0, 1.0)
        );
        assert!((report.worst_node.table - 0.61).abs() < 1e-12);
        assert!((report.worst_node.reference - 0.598).abs() < 1e-12);
        // Lookups interpolate the differences; the largest is at the corner.
        assert_eq!(report.lookup_points, 7 * 36);
        assert!((report.lookup_max_error - 12e-3).abs() < 1e-12);
        assert!(report.lookup_rms_error < report.lookup_max_error);
        assert!(report.lookup_rms_error > 1e-3);
        assert!(report.lookup_p99_error <= report.lookup_max_error);
        assert_eq!(
            (
                report.node_reference_tolerance,
                report.lookup_reference_tolerance
            ),
            (0.0, 0.0)
        );
        assert_eq!(report.reference_error_estimate, 0.0);
        assert!(report.reference_converged);
        assert_eq!(report.against, format!("table {}", theirs.spec.id()));
        assert_eq!(report.shape, vec![3, 4]);
        assert_eq!(report.mu_axis.as_deref(), Some("linear"));
        assert_eq!(report.roughness_axis, "r");
        assert_eq!(report.grid, "nodes");
        assert_eq!(report.node_points.len(), 12);
        assert_eq!(report.lookup_points_compared.len(), 7 * 36);
        for (k, p) in report.node_points.iter().enumerate() {
            assert!((p.error - 1e-3 * (k + 1) as f64).abs() < 1e-12);
        }
        // The storage adds 2e-3 to the truth (their values) everywhere.
        let cost = report.storage_cost.expect("a storage was named");
        assert_eq!(cost.storage, "plus");
        for figure in [
            cost.node_max_error,
            cost.node_rms_error,
            cost.lookup_max_error,
            cost.lookup_rms_error,
        ] {
            assert!((figure - 2e-3).abs() < 1e-12, "{cost:?}");
        }
    }

    /// Against a table of another layout, nodes are compared through its lookup.
    #[test]
    fn an_audit_against_another_layout_looks_the_other_table_up() {
        let ours_spec = test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear);
        let theirs_spec = test_e_spec(2, 2, Grid::Nodes, MuMapping::Linear);
        // Theirs is bilinear in (mu, r): E = 0.2 + 0.3 mu + 0.4 r, reproduced exactly by any
        // lookup; ours holds the same plane less 1e-3 everywhere.
        let plane = |spec: &TableSpec, k: usize| {
            let (alpha, mu) = spec.texel_coordinates(k);
            0.2 + 0.3 * mu.unwrap() + 0.4 * alpha.sqrt()
        };
        let theirs = table(
            theirs_spec.clone(),
            (0..4).map(|k| plane(&theirs_spec, k)).collect(),
        );
        let ours = table(
            ours_spec.clone(),
            (0..12).map(|k| plane(&ours_spec, k) - 1e-3).collect(),
        );
        let report = audit(
            &ours,
            &Against::Table(&theirs),
            &AuditSettings::default(),
            &|_| {},
        );
        for p in &report.node_points {
            assert!((p.error - 1e-3).abs() < 1e-12, "{p:?}");
        }
        assert!((report.lookup_max_error - 1e-3).abs() < 1e-12);
    }

    /// A 4 x 8 E table (32 nodes: the smallest group that is scouted) holding the reference at
    /// 1e-12 less `offset` at every node.
    fn offset_table(offset: f64) -> Table {
        offset_table_of(4, offset)
    }

    /// As [`offset_table`], with `rows` rows of 8.
    fn offset_table_of(rows: usize, offset: f64) -> Table {
        let spec = test_e_spec(rows, 8, Grid::Nodes, MuMapping::Linear);
        let fine = ReferenceSettings {
            tolerance: 1e-12,
            ..ReferenceSettings::default()
        };
        let values = (0..spec.len())
            .map(|k| {
                let (alpha, mu) = spec.texel_coordinates(k);
                let at = Coordinates {
                    alpha,
                    mu,
                    eta: None,
                };
                spec.integral().reference(at, &fine).value - offset
            })
            .collect();
        table(spec, values)
    }

    /// The passes an audit plans, and its report.
    fn planned(table: &Table, against: &Against) -> (Vec<u64>, Report) {
        let planned = std::sync::Mutex::new(Vec::new());
        let report = audit(table, against, &AuditSettings::default(), &|p| {
            if let Progress::Planned(n) = p {
                planned.lock().unwrap().push(n);
            }
        });
        (planned.into_inner().unwrap(), report)
    }

    /// Node errors of 1e-3 call for 1e-5: the scout (4 of the 32 nodes, at 1e-6) already holds
    /// the truth more closely, so only the other 28 are compared, at 1e-5; errors of 0.1 stop
    /// at the coarsest tolerance. Errors of 1e-7 call for 1e-9: all 32 again, once. A finest
    /// tolerance coarser than the scout's, or a fixed one, is one pass.
    #[test]
    fn the_scout_sets_the_tolerance_of_each_group() {
        let coarse = offset_table(1e-3);
        let (passes, report) = planned(&coarse, &Against::Reference(ReferenceSettings::default()));
        assert_eq!(passes[..2], [4, 28], "{passes:?}");
        let tolerance = report.node_reference_tolerance;
        assert!((0.9e-5..1.1e-5).contains(&tolerance), "{tolerance:e}");
        assert!((report.node_max_error - 1e-3).abs() < 1e-6);
        // The lookups too were measured at a coarse tolerance: their truth's error estimates
        // are above the scout's, far above the finest tolerance's.
        assert!(report.reference_error_estimate > 1e-8);
        assert!(report.lookup_reference_tolerance > SCOUT_TOLERANCE);
        let rough = offset_table(0.1);
        let (passes, report) = planned(&rough, &Against::Reference(ReferenceSettings::default()));
        assert_eq!(passes[..2], [4, 28], "{passes:?}");
        assert_eq!(report.node_reference_tolerance, COARSEST_TOLERANCE);
        assert_eq!(report.lookup_reference_tolerance, COARSEST_TOLERANCE);
        assert!((report.node_max_error - 0.1).abs() < 1e-4);
        let fine = offset_table(1e-7);
        let (passes, report) = planned(&fine, &Against::Reference(ReferenceSettings::default()));
        assert_eq!(passes[..2], [4, 32], "{passes:?}");
        let tolerance = report.node_reference_tolerance;
        assert!((0.9e-9..1.1e-9).contains(&tolerance), "{tolerance:e}");
        assert!((report.node_max_error - 1e-7).abs() < 1e-10);
        let loose = ReferenceSettings {
            tolerance: 1e-5,
            ..ReferenceSettings::default()
        };
        let (passes, report) = planned(&coarse, &Against::Reference(loose));
        assert_eq!(passes[0], 32, "{passes:?}");
        assert_eq!(report.node_reference_tolerance, 1e-5);
        // Errors of 1e-5 on the scouted nodes only: the scout calls for 1e-7, where all 32 are
        // measured; their RMS (1e-5 / sqrt(8)) calls for 3.5e-8, where all 32 are measured
        // again.
        let mut uneven = offset_table(0.0);
        for k in (0..32).step_by(SCOUT_STRIDE) {
            uneven.value[k] -= 1e-5;
            uneven.one_minus_value[k] += 1e-5;
        }
        let (passes, report) = planned(&uneven, &Against::Reference(ReferenceSettings::default()));
        assert_eq!(passes[..3], [4, 32, 32], "{passes:?}");
        let tolerance = report.node_reference_tolerance;
        assert!((3e-8..4e-8).contains(&tolerance), "{tolerance:e}");
        // A finest tolerance of exactly the scout's: nothing to gain by scouting.
        let scout = ReferenceSettings {
            tolerance: SCOUT_TOLERANCE,
            ..ReferenceSettings::default()
        };
        assert_eq!(planned(&coarse, &Against::Reference(scout)).0[0], 32);
        // 24 nodes: too few to scout.
        let few = offset_table_of(3, 1e-3);
        assert_eq!(
            planned(&few, &Against::Reference(ReferenceSettings::default())).0[0],
            24
        );
        let fixed = ReferenceSettings {
            tolerance: 1e-8,
            ..ReferenceSettings::default()
        };
        let (passes, report) = planned(&coarse, &Against::ReferenceAt(fixed));
        assert_eq!(passes, [32, report.lookup_points as u64]);
        assert_eq!(
            (
                report.node_reference_tolerance,
                report.lookup_reference_tolerance
            ),
            (1e-8, 1e-8)
        );
        assert_eq!(report.against, "reference");
    }
}

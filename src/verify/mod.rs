//! Auditing a table: its stored values against the deterministic reference (or another table) at
//! the coordinates it says it was computed at, and what a renderer's bilinear lookup of it returns
//! between those coordinates.

pub mod furnace;
pub mod input;

use crate::integrate::average_quadrature::quadrature_average_albedo;
use crate::integrate::dielectric::{
    reference_dielectric_albedo, reference_dielectric_average_albedo,
};
use crate::integrate::reference::{
    ReferenceSettings, ReferenceValue, reference_albedo, reference_weighted_albedo,
};
use crate::model::Fresnel;
use crate::table::axis::Axis;
use crate::table::{Quantity, Table, TableSpec};
use rayon::prelude::*;
use serde::Serialize;

/// What the table is compared with.
#[derive(Clone, Copy, Debug)]
pub enum Against<'a> {
    /// The deterministic reference quadrature ([`crate::integrate::reference`]).
    Reference(ReferenceSettings),
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
}

impl Default for AuditSettings {
    fn default() -> Self {
        Self {
            clamp_min: 0.0,
            density: 2,
        }
    }
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
    pub worst_node: Point,
    /// The bilinear lookup against the truth on a dense grid that includes the axis ends, plus
    /// grazing probes down to `mu = 0` ([`lookup_coordinates`]).
    pub lookup_points: usize,
    pub lookup_max_error: f64,
    pub lookup_rms_error: f64,
    pub lookup_p99_error: f64,
    pub worst_lookup: Point,
    /// The largest error estimate of the reference values used (0 against a table).
    pub reference_error_estimate: f64,
    /// Whether every reference quadrature met its tolerance.
    pub reference_converged: bool,
}

/// The reference value of `spec`'s quantity at `(alpha, mu)` and, for the tables with an IOR
/// axis, the relative index `eta` ([`TableSpec::texel_eta`]): `E` by the reference, `E_avg` by
/// the composite rule ([`quadrature_average_albedo`], within 1e-10 of the nested reference), the
/// split-sum channels by the reference with their weight, the dielectric tables by their own
/// quadrature ([`crate::integrate::dielectric`]), `F_avg` by Gauss-Kronrod to 1e-14.
///
/// # Panics
/// If a table with an IOR axis is given no `eta`.
#[must_use]
pub fn reference_value(
    spec: &TableSpec,
    alpha: f64,
    mu: Option<f64>,
    eta: Option<f64>,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    if spec.quantity.has_ior() {
        let eta = eta.expect("a table with an IOR axis needs eta");
        return match (spec.quantity, mu) {
            (Quantity::FAvg, _) => {
                let f = Fresnel::Dielectric { eta }.average_report();
                ReferenceValue {
                    value: f.value[0],
                    one_minus_value: 1.0 - f.value[0],
                    error: f.error,
                    evaluations: f.evaluations,
                    converged: true,
                }
            }
            (_, Some(mu)) => reference_dielectric_albedo(spec.model, alpha, mu, eta, settings)
                .as_reference_value(),
            (_, None) => reference_dielectric_average_albedo(spec.model, alpha, eta, settings)
                .as_reference_value(),
        };
    }
    if let (Some(fresnel), Some(mu)) = (spec.fresnel, mu) {
        return fresnel_weighted_reference(spec.model, fresnel, alpha, mu, settings);
    }
    match (mu, spec.quantity.weight()) {
        (Some(mu), None) => reference_albedo(spec.model, alpha, mu, settings),
        (Some(mu), Some(h)) => reference_weighted_albedo(spec.model, alpha, mu, h, settings),
        (None, _) => quadrature_average_albedo(spec.model, alpha, settings),
    }
}

/// The reference Fresnel-weighted albedo `E_F(mu)` of channel 0 of `fresnel`: for a dielectric
/// the reflected part of [`reference_dielectric_albedo`] (its quadrature splits at the critical
/// angle, where `F` has a square-root kink that misleads the generic rule's error estimate),
/// otherwise the reference with the weight `F(o.h)`. `one_minus_value` is `1 - E_F`.
#[must_use]
pub fn fresnel_weighted_reference(
    model: crate::model::Model,
    fresnel: Fresnel,
    alpha: f64,
    mu: f64,
    settings: &ReferenceSettings,
) -> ReferenceValue {
    if let Fresnel::Dielectric { eta } = fresnel {
        let r = reference_dielectric_albedo(model, alpha, mu, eta, settings);
        return ReferenceValue {
            value: r.reflection,
            one_minus_value: 1.0 - r.reflection,
            error: r.error,
            evaluations: r.evaluations,
            converged: r.converged,
        };
    }
    reference_weighted_albedo(model, alpha, mu, |c| fresnel.reflectance(c)[0], settings)
}

/// The truth at `(mu, alpha, eta)`: value, error estimate and whether it converged.
fn truth(against: &Against, table: &Table, at: Coordinates) -> (f64, f64, bool) {
    match against {
        Against::Reference(settings) => {
            let r = reference_value(&table.spec, at.alpha, at.mu, at.eta, settings);
            (r.value, r.error, r.converged)
        }
        Against::Table(other) => {
            let theirs = other.spec.roughness_convention().from_alpha(at.alpha);
            let eta = at.eta.unwrap_or(1.0);
            (
                other.lookup_eta(at.mu.unwrap_or(1.0), theirs, eta),
                0.0,
                true,
            )
        }
    }
}

/// Where a value is compared: `alpha`, and `mu` and the relative `eta` where the table has them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coordinates {
    pub alpha: f64,
    pub mu: Option<f64>,
    pub eta: Option<f64>,
}

/// Compares the stored values with the truth at the nodes ([`node_errors`]) and the table's
/// lookup with the truth on a dense grid. Reference evaluations run in parallel (deterministic:
/// each point is a pure function of its coordinates).
/// `progress` is called once per compared point (see [`audit_points`] for the count).
#[must_use]
pub fn audit(
    table: &Table,
    against: &Against,
    settings: &AuditSettings,
    progress: &(dyn Fn() + Sync),
) -> Report {
    let spec = &table.spec;
    let convention = spec.roughness_convention();
    let clamp = |x: f64| x.max(settings.clamp_min);

    // One table value against the truth at (mu, alpha), with the truth's error estimate.
    let compare = |at: Coordinates, value: f64| {
        let (reference, error_estimate, converged) = truth(against, table, at);
        progress();
        let error = (value - reference).abs();
        let Coordinates { alpha, mu, eta } = at;
        let roughness = convention.from_alpha(alpha);
        (
            Point {
                mu,
                eta,
                roughness,
                alpha,
                table: value,
                reference,
                error,
            },
            error_estimate,
            converged,
        )
    };

    // Nodes: each stored value against the truth where the table says it was computed (with
    // the roughness and mu clamped as the author says they clamped them).
    // Against a table of the same layout, node k is compared with its node k (a lookup at the
    // physical point of the `alpha = 0` row of an adaptive axis, computed at alpha = 1e-7, would
    // sit a hair off that row).
    let same_layout = match against {
        Against::Table(other) => other.spec.axes() == spec.axes(),
        Against::Reference(_) => false,
    };
    let nodes: Vec<(Point, f64, bool)> = (0..spec.len())
        .into_par_iter()
        .map(|k| {
            let (alpha, mu) = spec.texel_coordinates(k);
            let at = Coordinates {
                alpha: convention.to_alpha(clamp(convention.from_alpha(alpha))),
                mu: mu.map(clamp),
                eta: spec.texel_eta(k),
            };
            let (mut point, estimate, converged) = compare(at, table.value[k]);
            if let (true, Against::Table(other)) = (same_layout, against) {
                point.reference = other.value[k];
                point.error = (point.table - point.reference).abs();
            }
            (point, estimate, converged)
        })
        .collect();

    // Lookups at every point of `lookup_coordinates`.
    let lookups: Vec<(Point, f64, bool)> = lookup_coordinates(spec, settings)
        .into_par_iter()
        .map(|at| {
            let value = table.lookup_eta(
                at.mu.unwrap_or(1.0),
                convention.from_alpha(at.alpha),
                at.eta.unwrap_or(1.0),
            );
            compare(at, value)
        })
        .collect();

    let worst = |points: &[(Point, f64, bool)]| {
        points
            .iter()
            .map(|p| p.0)
            .max_by(|a, b| a.error.total_cmp(&b.error))
            .expect("points")
    };
    let rms = |points: &[(Point, f64, bool)]| {
        (points.iter().map(|p| p.0.error * p.0.error).sum::<f64>() / points.len() as f64).sqrt()
    };
    let mut lookup_errors: Vec<f64> = lookups.iter().map(|p| p.0.error).collect();
    lookup_errors.sort_by(f64::total_cmp);
    let p99 = lookup_errors
        [((0.99 * lookup_errors.len() as f64).ceil() as usize).clamp(1, lookup_errors.len()) - 1];
    let all = nodes.iter().chain(&lookups);
    let reference_error_estimate = crate::stats::max_or_nan(all.clone().map(|p| p.1));
    let reference_converged = all.clone().all(|p| p.2);
    let (worst_node, worst_lookup) = (worst(&nodes), worst(&lookups));
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
            Against::Reference(_) => "reference".to_string(),
            Against::Table(other) => format!("table {}", other.spec.id()),
        },
        nodes: nodes.len(),
        node_max_error: worst_node.error,
        node_rms_error: rms(&nodes),
        worst_node,
        lookup_points: lookups.len(),
        lookup_max_error: worst_lookup.error,
        lookup_rms_error: rms(&lookups),
        lookup_p99_error: p99,
        worst_lookup,
        reference_error_estimate,
        reference_converged,
    }
}

/// The `mu` of the grazing probes [`audit`] adds on every roughness of its ladder, whatever the
/// table's axis: exactly 0, 1e-12, and 1e-6 to 1 in 24 log steps (the boundary layer `mu ~ alpha`
/// that a coarse texture-space ladder can step over).
pub(crate) fn grazing_probes() -> Vec<f64> {
    let mut probes = vec![0.0, 1e-12];
    probes.extend((0..=24).map(|k| 10f64.powf(-6.0 + f64::from(k) / 4.0)));
    probes
}

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
    let etas: Vec<Option<f64>> = match spec.ior {
        Some(axis @ Axis::Ior { mapping, max, .. }) => ladder(axis.size())
            .into_iter()
            .map(|t| Some(spec.relative_eta(mapping.eta(t, max.0))))
            .collect(),
        _ => vec![None],
    };
    let mut points = Vec::new();
    for eta in etas {
        let Some(roughness) = spec.roughness else {
            points.push(Coordinates {
                alpha: 0.0,
                mu: None,
                eta,
            });
            continue;
        };
        for t_r in ladder(roughness.size()) {
            let at = |(alpha, mu): (f64, Option<f64>)| Coordinates { alpha, mu, eta };
            match spec.mu {
                Some(axis) => {
                    for t_mu in ladder(axis.size()) {
                        points.push(at(spec.point(t_r, t_mu)));
                    }
                    let alpha = spec.roughness_convention().to_alpha(t_r);
                    points.extend(grazing_probes().into_iter().map(|mu| at((alpha, Some(mu)))));
                }
                None => points.push(at(spec.point(t_r, 0.0))),
            }
        }
    }
    points
}

/// How many points [`audit`] compares: every node and every [`lookup_coordinates`] point.
#[must_use]
pub fn audit_points(spec: &TableSpec, settings: &AuditSettings) -> u64 {
    (spec.len() + lookup_coordinates(spec, settings).len()) as u64
}

/// The largest number of `E_avg` entries [`node_errors`] checks: each costs the reference about
/// 0.5 s of CPU ([`quadrature_average_albedo`]).
pub const MAX_AVERAGE_ENTRIES_CHECKED: usize = 5;

/// Node errors of a freshly baked table against the reference, in `1 - E` (which both carry
/// directly): on every texel of an `E` table, and on at most [`MAX_AVERAGE_ENTRIES_CHECKED`]
/// evenly spaced entries of an `E_avg` table, first and last included (by
/// [`quadrature_average_albedo`], within 1e-10 of the nested reference at half its cost). What
/// `kiln bake` records.
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
            let (alpha, mu) = spec.texel_coordinates(k);
            let reference = reference_value(spec, alpha, mu, spec.texel_eta(k), settings);
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

/// The node errors `kiln bake` measures and records.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct NodeErrors {
    /// The largest error (NaN if any texel is NaN).
    pub max: f64,
    pub rms: f64,
    /// How many texels were checked.
    pub texels: usize,
    /// How many of them had a reference that did not converge within its evaluation budget
    /// (their error is the difference plus the reference's own error estimate).
    #[serde(default)]
    pub unconverged: usize,
}

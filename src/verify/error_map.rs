//! Where a table is wrong, as a picture's data: the audit's node and lookup errors placed on the
//! table's texture coordinates (`kiln verify --plot`).

use super::{Point, Report};
use crate::table::TableSpec;
use crate::table::axis::Axis;

/// One group's errors over a table's texture coordinates, for a picture of where the table is
/// wrong ([`error_maps`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorMap {
    /// `nodes` or `lookups`.
    pub group: &'static str,
    /// Cells across (the `mu` coordinate; the roughness coordinate for a 1-D table).
    pub columns: usize,
    /// Cells down (the roughness coordinate; 1 for a 1-D table).
    pub rows: usize,
    /// The largest error of the points in each cell, row-major from roughness 0 (`None`: no
    /// point there; NaN if any point there is NaN).
    pub cells: Vec<Option<f64>>,
    /// The worst point: its coordinates `(x, y)` in [0, 1] and its error.
    pub worst: (f64, f64, f64),
    /// For a table with an IOR axis, the relative `eta` of the slice shown (the worst point's).
    pub eta: Option<f64>,
    /// What the axes are.
    pub x_axis: String,
    pub y_axis: String,
}

/// The largest cells per axis of an [`ErrorMap`].
pub const MAX_MAP_CELLS: usize = 64;

/// Where a compared point sits in the table's texture coordinates: `(x, y)` = (`mu`'s
/// coordinate, roughness' coordinate) for a 2-D table, (roughness', 0) for a 1-D one.
fn map_position(spec: &TableSpec, p: &Point) -> (f64, f64) {
    let t_r = p.roughness.clamp(0.0, 1.0);
    match (spec.mu, p.mu) {
        (Some(Axis::Mu { mapping, .. }), Some(mu)) => {
            (mapping.coordinate(mu, p.alpha).clamp(0.0, 1.0), t_r)
        }
        _ => (t_r, 0.0),
    }
}

/// The audit's node and lookup errors drawn over the table's axes ([`ErrorMap`]): each point in
/// the cell of its texture coordinates (at most [`MAX_MAP_CELLS`] per axis), each cell the
/// largest error there; for a table with an IOR axis, the slice of `eta` that holds the group's
/// worst point.
#[must_use]
pub fn error_maps(spec: &TableSpec, report: &Report) -> Vec<ErrorMap> {
    let names = |spec: &TableSpec| -> (String, String) {
        let roughness = format!("roughness {}", spec.roughness_convention().name());
        match spec.mu {
            Some(Axis::Mu { mapping, .. }) => (
                format!("mu's texture coordinate ({})", mapping.name()),
                roughness,
            ),
            _ => (roughness, "error".to_string()),
        }
    };
    let map = |group: &'static str,
               points: &[Point],
               worst: &Point,
               cells_per: &dyn Fn(usize) -> usize| {
        let slice: Vec<&Point> = points.iter().filter(|p| p.eta == worst.eta).collect();
        let roughness_size = spec.roughness.map_or(1, |a| a.size());
        let (columns, rows) = match spec.mu {
            Some(mu) => (cells_per(mu.size()), cells_per(roughness_size)),
            None => (cells_per(roughness_size), 1),
        };
        let mut cells: Vec<Option<f64>> = vec![None; rows * columns];
        let cell = |t: f64, n: usize| ((t * n as f64) as usize).min(n - 1);
        for p in slice {
            let (x, y) = map_position(spec, p);
            let k = cell(y, rows) * columns + cell(x, columns);
            cells[k] = Some(match cells[k] {
                Some(e) if e.is_nan() || p.error.is_nan() => f64::NAN,
                Some(e) => e.max(p.error),
                None => p.error,
            });
        }
        let (x, y) = map_position(spec, worst);
        let (x_axis, y_axis) = names(spec);
        ErrorMap {
            group,
            columns,
            rows,
            cells,
            worst: (x, y, worst.error),
            eta: worst.eta,
            x_axis,
            y_axis,
        }
    };
    // A cell per node; for the lookups, per point of the half-texel ladder.
    let node_cells = |n: usize| n.clamp(1, MAX_MAP_CELLS);
    let lookup_cells = |n: usize| (2 * n + 1).clamp(1, MAX_MAP_CELLS);
    vec![
        map(
            "nodes",
            &report.node_points,
            &report.worst_node,
            &node_cells,
        ),
        map(
            "lookups",
            &report.lookup_points_compared,
            &report.worst_lookup,
            &lookup_cells,
        ),
    ]
}

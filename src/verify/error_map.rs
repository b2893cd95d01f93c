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
    let t_r = match spec.roughness {
        Some(Axis::Roughness {
            convention,
            spacing,
            ..
        }) => spacing.coordinate(p.roughness, convention),
        _ => p.roughness,
    }
    .clamp(0.0, 1.0);
    match (spec.mu, p.mu) {
        (Some(Axis::Mu { mapping, size, .. }), Some(mu)) => {
            (mapping.coordinate(mu, p.alpha, size).clamp(0.0, 1.0), t_r)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::axis::{Grid, MuMapping};
    use crate::table::test_e_spec;
    use crate::verify::tests::{e_avg_spec, tables_apart};
    use crate::verify::{Against, AuditSettings, audit};

    /// The audit of a 3 x 4 table against one that differs by `1e-3 (k + 1)` at texel `k`.
    fn report(spec: &TableSpec) -> Report {
        let (ours, theirs) = tables_apart(spec);
        audit(
            &ours,
            &Against::Table(&theirs),
            &AuditSettings::default(),
            &|_| {},
        )
    }

    #[test]
    fn points_sit_at_their_texture_coordinates() {
        let spec = test_e_spec(3, 4, Grid::Nodes, MuMapping::Sqrt);
        let at = |mu: Option<f64>, roughness: f64| Point {
            mu,
            eta: None,
            roughness,
            alpha: roughness * roughness,
            table: 0.0,
            reference: 0.0,
            error: 0.0,
        };
        // A square-root axis puts mu = 1/4 at t = 1/2.
        assert_eq!(map_position(&spec, &at(Some(0.25), 0.3)), (0.5, 0.3));
        assert_eq!(map_position(&spec, &at(Some(1.0), 1.5)), (1.0, 1.0));
        assert_eq!(map_position(&spec, &at(Some(0.0), -0.5)), (0.0, 0.0));
        // No mu: the roughness across.
        assert_eq!(map_position(&spec, &at(None, 0.3)), (0.3, 0.0));
        assert_eq!(
            map_position(&e_avg_spec(5), &at(Some(0.25), 0.7)),
            (0.7, 0.0)
        );
    }

    #[test]
    fn each_node_has_its_cell_and_each_lookup_cell_its_worst() {
        let spec = test_e_spec(3, 4, Grid::Nodes, MuMapping::Linear);
        let mut report = report(&spec);
        let maps = error_maps(&spec, &report);
        let nodes = &maps[0];
        assert_eq!((nodes.group, nodes.columns, nodes.rows), ("nodes", 4, 3));
        for (k, cell) in nodes.cells.iter().enumerate() {
            let e = cell.expect("every node has a cell");
            assert!((e - 1e-3 * (k + 1) as f64).abs() < 1e-12, "{k}: {e}");
        }
        assert_eq!((nodes.worst.0, nodes.worst.1), (1.0, 1.0));
        assert!((nodes.worst.2 - 12e-3).abs() < 1e-12);
        assert_eq!(nodes.eta, None);
        assert_eq!(nodes.x_axis, "mu's texture coordinate (linear)");
        assert_eq!(nodes.y_axis, "roughness r");
        let lookups = &maps[1];
        assert_eq!(
            (lookups.group, lookups.columns, lookups.rows),
            ("lookups", 9, 7)
        );
        // The ladder puts one point in each cell; each cell is the largest error there.
        let cells: Vec<f64> = lookups.cells.iter().map(|c| c.expect("filled")).collect();
        let max = cells.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!((max - report.lookup_max_error).abs() < 1e-15);
        assert_eq!(cells.last(), Some(&max));
        // The lowest row is roughness 0, where the differences run `1e-3 + 3e-3 mu`. Each cell
        // holds its largest: the first has the grazing probes up to mu = 0.1, the middle one
        // the ladder's mu = 1/2 alone, the last mu = 1.
        assert!((cells[0] - 1.3e-3).abs() < 1e-12, "{}", cells[0]);
        assert!((cells[8] - 4e-3).abs() < 1e-12, "{}", cells[8]);
        assert!((cells[4] - 2.5e-3).abs() < 1e-12, "{}", cells[4]);
        // A NaN error marks its cell, whatever else is there.
        report.node_points[5].error = f64::NAN;
        report.lookup_points_compared[0].error = f64::NAN;
        let maps = error_maps(&spec, &report);
        assert!(maps[0].cells[5].unwrap().is_nan());
        assert!(maps[0].cells[4].unwrap() > 0.0);
        assert!(maps[1].cells[0].unwrap().is_nan());
        assert!(!maps[1].cells[1].unwrap().is_nan());
    }

    #[test]
    fn a_table_without_mu_is_one_row_along_the_roughness() {
        let spec = e_avg_spec(5);
        let maps = error_maps(&spec, &report(&spec));
        assert_eq!((maps[0].columns, maps[0].rows), (5, 1));
        assert_eq!((maps[1].columns, maps[1].rows), (11, 1));
        for (k, cell) in maps[0].cells.iter().enumerate() {
            assert!((cell.unwrap() - 1e-3 * (k + 1) as f64).abs() < 1e-12);
        }
        assert_eq!(maps[0].x_axis, "roughness r");
        assert_eq!(maps[0].y_axis, "error");
        assert_eq!((maps[0].worst.0, maps[0].worst.1), (1.0, 0.0));
    }

    #[test]
    fn large_tables_share_cells() {
        let spec = test_e_spec(100, 3, Grid::Centers, MuMapping::Linear);
        let maps = error_maps(&spec, &report(&spec));
        assert_eq!((maps[0].columns, maps[0].rows), (3, MAX_MAP_CELLS));
        assert_eq!((maps[1].columns, maps[1].rows), (7, MAX_MAP_CELLS));
        assert!(maps[0].cells.iter().all(Option::is_some));
    }
}

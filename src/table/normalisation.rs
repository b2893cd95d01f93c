//! The lookup-consistent normalisation of the Kulla-Conty lobe (`f_ms_norm`).
//!
//! Kulla and Conty 2017 ("Revisiting Physically Based Shading at Imageworks"; `docs/physics.md`,
//! "Kulla-Conty quantities") normalise `f_ms(o, i) = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 -
//! E_avg))` so that its albedo is exactly `1 - E(mu_o)` when `1 - E_avg = 2 ∫ (1 - E(mu)) mu
//! dmu`. A renderer evaluates `E` through a table's bilinear lookup, whose average `Ē` differs
//! from the true `E_avg`; at low roughness, where `1 - E_avg` is tiny (7.4e-6 at `alpha = 1e-3`)
//! while `1 - E(mu_o)` stays near 0.11 in the grazing layer, that relative mismatch becomes an
//! energy error of up to 0.12 (`kiln furnace` with `E_avg`, `docs/verify.md`). The
//! normalisation that closes the furnace for the lookup the renderer really uses is
//! `1 - Ē(r) = 2 ∫ (1 - E_lookup(mu, r)) mu dmu`.
//!
//! Its table: over the E table's roughness coordinate `x` (`r` or `alpha` on linear rows; the
//! rows' texture coordinate on balanced rows, whose spacing it shares), on nodes that
//! subdivide every cell of the E table's roughness axis [`SUBDIVISIONS`] times (497 entries for a
//! 32-row table; 817 with the first form's refined start, below; so the kinks of the bilinear
//! lookup, at the E table's rows, fall on nodes and the linear interpolation between them is
//! smooth), one of two forms
//! ([`divides_by_roughness`]):
//!
//! - `g(x) = (1 - Ē(x)) / x` for an E table on the adaptive or balanced `mu` axis with its rows
//!   on nodes (kiln's default). There the lookup's columns move with `alpha`, and between the first two
//!   rows `1 - Ē` starts linearly in `x` (3.4e-5 x for the default GGX table) and then grows
//!   like `alpha`; divided by `x` it bends far less over the first cell than `1 - Ē`, which
//!   varies over orders of magnitude there. `g(0)` is the limit, the slope of `1 - Ē` at 0;
//!   the product `x g(x)` is 0 at `x = 0` (a mirror loses nothing).
//! - `g(x) = 1 - Ē(x)` for every other E table (linear or square-root `mu` axis, or rows on
//!   texel centres, as the engines' tables are). Its columns do not move with roughness, so the
//!   bilinear lookup is linear in `x` between rows and so is its average: the linear
//!   interpolation of `g` on nodes that include the rows is exact, where dividing by `x` would
//!   bend it (a relative error of `h / (2 x_0)` next to a row `x_0` where `1 - Ē` starts from
//!   0, 6 % for Enterprise PBR's half-float table), and below the first row centre, where the
//!   clamped lookup is constant, `(1 - Ē) / x` would diverge.
//!
//! In the first form the first [`REFINED_START`]`.cells` cells of the E table's rows hold
//! [`REFINED_START`]`.subdivisions` nodes each instead of [`SUBDIVISIONS`]: there `g` bends
//! most (in the first cell `1 - Ē` is `x` times the average of row 1's texels read at
//! columns that move with `alpha`, which changes 16-fold over the cell; in the next ones the
//! division by `x` bends a lookup that starts from a non-zero loss), and with 16 nodes per cell
//! the interpolation's relative error there was 1.1e-3 (kiln's default E table) and 2.2e-3 (the
//! balanced layout with fitted texels); with 96 it is 3.8e-5 and 6.5e-5, the other cells' at
//! most 2.8e-5 and 5.7e-5 (`kiln verify` on the f_ms_norm file). The node position of the
//! roughness coordinate `t` is [`NodeLine::position`], one `min` of two lines: rows stay on
//! nodes.
//!
//! The lookup is [`normalisation_lookup`]: the linear interpolation of `g`, times `x` in the
//! first form.

use super::axis::{Axis, Grid};
use super::{Quantity, Table, TableSpec};
use crate::numerics::gauss_kronrod::integrate_pieces;
use rayon::prelude::*;

/// Nodes of the normalisation table per cell of the E table's roughness axis (beyond the
/// refined start of the first form, [`REFINED_START`]).
pub const SUBDIVISIONS: usize = 16;

/// The first cells of the E table's roughness axis, from `x = 0`, holding more nodes of the
/// normalisation table than [`SUBDIVISIONS`] (see the module docs). Recorded in the spec
/// ([`TableSpec::refined_start`]); a file without it has [`SUBDIVISIONS`] nodes in every cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct RefinedStart {
    /// How many cells, from the first row, are refined (at most the table's cells).
    pub cells: usize,
    /// Nodes per refined cell.
    pub subdivisions: usize,
}

/// kiln's refined start: the first 4 cells with 96 nodes each (the measurements in the module
/// docs; 3 cells left the balanced layout's fourth at 8.6e-5, 64 nodes its first at 1.4e-4).
pub const REFINED_START: RefinedStart = RefinedStart {
    cells: 4,
    subdivisions: 96,
};

/// Where the roughness coordinate `t` in [0, 1] falls among a normalisation table's nodes:
/// `p = min(steep t, shallow t + offset)`, clamped to `[0, last]`; node `i` holds `t` with
/// `p(t) = i`. Without a refined start both lines are `(n - 1) t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeLine {
    /// Nodes per unit of `t` in the refined cells (`cells * subdivisions`).
    pub steep: f64,
    /// Nodes per unit of `t` beyond them (`cells * SUBDIVISIONS`).
    pub shallow: f64,
    /// `refined cells * (subdivisions - SUBDIVISIONS)`: where the second line starts.
    pub offset: f64,
    /// The last node's index, `n - 1`.
    pub last: f64,
}

impl NodeLine {
    /// The line of the normalisation table `norm` (a table of [`spec_for`]).
    #[must_use]
    pub fn of(norm: &TableSpec) -> NodeLine {
        let last = (norm.len().max(2) - 1) as f64;
        let cells = norm
            .lookup_of
            .as_deref()
            .map_or(1, |e| e.roughness_axis().size().max(2) - 1) as f64;
        match norm.refined_start {
            Some(RefinedStart {
                cells: refined,
                subdivisions,
            }) => NodeLine {
                steep: cells * subdivisions as f64,
                shallow: cells * SUBDIVISIONS as f64,
                offset: (refined as f64) * (subdivisions as f64 - SUBDIVISIONS as f64),
                last,
            },
            None => NodeLine {
                steep: last,
                shallow: last,
                offset: 0.0,
                last,
            },
        }
    }

    /// The continuous node position of the roughness coordinate `t` (clamped to the table).
    #[must_use]
    pub fn position(&self, t: f64) -> f64 {
        (self.steep * t)
            .min(self.shallow * t + self.offset)
            .clamp(0.0, self.last)
    }

    /// The roughness coordinate of node `i` (the inverse of [`NodeLine::position`]: the
    /// larger of the two lines' inverses, as the position is the smaller of the lines).
    #[must_use]
    pub fn coordinate(&self, i: f64) -> f64 {
        (i / self.steep).max((i - self.offset) / self.shallow)
    }
}

/// `1 - Ē(roughness) = 2 ∫ (1 - E_lookup(mu, roughness)) mu dmu` of an E table's bilinear
/// lookup ([`Table::lookup_one_minus`], taken along `mu` by [`Table::lookup_along_mu`]),
/// integrated by adaptive Gauss-Kronrod over `mu`, split at the `mu` of the table's columns at
/// that roughness (where the lookup has kinks), to an absolute accuracy of 1e-16. Returns the
/// value and the quadrature's error estimate.
#[must_use]
pub fn one_minus_lookup_average(e: &Table, roughness: f64) -> (f64, f64) {
    let Some(Axis::Mu {
        size,
        mapping,
        grid,
    }) = e.spec.mu
    else {
        return (0.0, 0.0);
    };
    let alpha = e.spec.roughness_convention().to_alpha(roughness);
    let mut breaks: Vec<f64> = (0..size)
        .map(|i| mapping.mu(grid.coordinate(i, size), alpha, size))
        .chain([0.0, 1.0])
        .collect();
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let lookup = e.lookup_along_mu(&e.one_minus_value, roughness, 1.0);
    let integral = integrate_pieces(
        &mut |mu: f64| [2.0 * mu * lookup(mu)],
        &breaks,
        1e-16,
        20_000,
    );
    (integral.value[0], integral.error)
}

/// Whether the normalisation table of the E table `e` stores `(1 - Ē) / x` (true: an adaptive
/// `mu` axis with rows on nodes) or `1 - Ē` itself (see the module docs).
#[must_use]
pub fn divides_by_roughness(e: &TableSpec) -> bool {
    matches!(
        e.mu,
        Some(Axis::Mu {
            mapping: super::axis::MuMapping::Adaptive | super::axis::MuMapping::Balanced,
            ..
        })
    ) && e.roughness_axis().grid() == Grid::Nodes
}

/// Whether the normalisation table `norm` stores `(1 - Ē) / x` ([`divides_by_roughness`] of
/// the E table it was derived from).
#[must_use]
pub fn stores_per_roughness(norm: &TableSpec) -> bool {
    norm.lookup_of.as_deref().is_some_and(divides_by_roughness)
}

/// The spec of the normalisation table of the E table `e`.
#[must_use]
pub fn spec_for(e: &TableSpec) -> TableSpec {
    let rows = e.roughness_axis();
    let refined_start = refined_start_for(e);
    let size = size_of(e, refined_start);
    TableSpec {
        quantity: Quantity::FMsNorm,
        ior: None,
        mu: None,
        fresnel: None,
        roughness: Some(Axis::Roughness {
            size,
            convention: e.roughness_convention(),
            grid: Grid::Nodes,
            // The E table's rows are nodes of this axis (every SUBDIVISIONS-th).
            spacing: match rows {
                Axis::Roughness { spacing, .. } => spacing,
                _ => unreachable!("a roughness axis"),
            },
        }),
        lookup_of: Some(Box::new(e.clone())),
        refined_start,
        // Derived exactly from the lookup (of fitted texels or not), not fitted itself.
        texels: crate::table::Texels::Nodes,
        ..e.clone()
    }
}

/// kiln's refined start of the normalisation of the E table `e`: [`REFINED_START`] (at most
/// all its cells) where it stores `(1 - Ē) / x` ([`divides_by_roughness`]), none otherwise.
#[must_use]
pub fn refined_start_for(e: &TableSpec) -> Option<RefinedStart> {
    let cells = e.roughness_axis().size().max(2) - 1;
    divides_by_roughness(e).then_some(RefinedStart {
        cells: REFINED_START.cells.min(cells),
        ..REFINED_START
    })
}

/// The entries of the normalisation table of the E table `e` with the refined start
/// `refined_start` (or without one, as in files older than it).
#[must_use]
pub fn size_of(e: &TableSpec, refined_start: Option<RefinedStart>) -> usize {
    let rows = e.roughness_axis();
    let cells = rows.size().max(2) - 1;
    match (rows.grid(), refined_start) {
        (Grid::Nodes, Some(refined)) => {
            refined.cells * refined.subdivisions
                + cells.saturating_sub(refined.cells) * SUBDIVISIONS
                + 1
        }
        (Grid::Nodes, None) => cells * SUBDIVISIONS + 1,
        // Row j at (j + 0.5) / N is node (j + 1/2) * SUBDIVISIONS of N * SUBDIVISIONS.
        (Grid::Centers, _) => rows.size() * SUBDIVISIONS + 1,
    }
}

/// The normalisation table of `spec` (an `f_ms_norm` spec) derived from the E table it is the
/// lookup of (`spec.lookup_of`), found among `tables`, and checked
/// ([`Table::check_computed`]): the one path of the bake and of the merge of shards.
///
/// # Errors
/// The derived table fails its checks.
///
/// # Panics
/// If `tables` holds no E table of `spec.lookup_of` (callers bake or merge it first).
pub fn derive_from(
    spec: &TableSpec,
    tables: &[Table],
    command: String,
) -> crate::error::Result<Table> {
    let source = spec.lookup_of.as_deref();
    let e = tables
        .iter()
        .find(|t| Some(&t.spec) == source)
        .expect("validate() requires E, and specs() orders it first");
    let table = derive(e, command);
    table.check_computed()?;
    Ok(table)
}

/// The normalisation table of the E table `e` (see the module docs); `command` is recorded in
/// it. Its `std_error` holds the quadrature's error estimate divided by `x`.
#[must_use]
pub fn derive(e: &Table, command: String) -> Table {
    let spec = spec_for(&e.spec);
    let n = spec.len();
    let line = NodeLine::of(&spec);
    let per_x = divides_by_roughness(&e.spec);
    // Entries are independent: in parallel, the same bytes on any thread count.
    let entries: Vec<(f64, f64)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let x = line.coordinate(i as f64);
            // In the first form g(0) is the limit of (1 - Ē(x)) / x, the slope of 1 - Ē at 0:
            // taken at a point 1e-4 of the first interval in (where the next term of 1 - Ē, of
            // order x^2, is 1e-4 times smaller).
            let at = if per_x && i == 0 {
                1e-4 * line.coordinate(1.0)
            } else {
                x
            };
            let roughness = spec.roughness_axis().roughness_at_coordinate(at);
            let (loss, error) = one_minus_lookup_average(e, roughness);
            // The node's coordinate is the E table's row coordinate there (shared spacing):
            // what `divisor` gives at `roughness`.
            let scale = if per_x { at } else { 1.0 };
            (loss / scale, error / scale)
        })
        .collect();
    let (value, std_error): (Vec<f64>, Vec<f64>) = entries.into_iter().unzip();
    let one_minus_value = value.iter().map(|v| 1.0 - v).collect();
    Table::unmeasured(spec, [value, one_minus_value, std_error], command)
}

/// What a normalisation table that stores `(1 - Ē) / x` divides by at `roughness` (in the
/// table's convention): `x`, the rows' coordinate at `roughness` (the roughness itself on
/// linear rows), which it shares with its E table. Below the E table's first row the lookup
/// blends row 0 and row 1 with the weight `x / x_1`, so that `1 - Ē` grows like `x` there,
/// whatever the rows' spacing.
#[must_use]
fn divisor(norm: &TableSpec, roughness: f64) -> f64 {
    match norm.roughness_axis() {
        Axis::Roughness {
            spacing,
            convention,
            ..
        } => spacing.coordinate(roughness, convention),
        _ => roughness,
    }
}

/// `1 - Ē` at `roughness` (in the table's convention) from a normalisation table: its linear
/// interpolation, times `roughness` if it stores `(1 - Ē) / x` ([`stores_per_roughness`]). The
/// denominator of `f_ms` is `pi` times this
/// ([`crate::model::kulla_conty::normalisation`]).
#[must_use]
pub fn normalisation_lookup(norm: &Table, roughness: f64) -> f64 {
    let g = norm.lookup(0.0, roughness);
    if stores_per_roughness(&norm.spec) {
        divisor(&norm.spec, roughness.clamp(0.0, 1.0)) * g
    } else {
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::axis::MuMapping;

    /// A 5 x 4 E table over `r` and `mu` whose one-minus channel is `loss(r, t)` at each texel,
    /// `t` the column's texture coordinate.
    fn e_table(grid: Grid, mapping: MuMapping, loss: impl Fn(f64, f64) -> f64) -> Table {
        let spec = crate::table::test_e_spec(5, 4, grid, mapping);
        let one_minus_value: Vec<f64> = (0..20)
            .map(|k| loss(grid.coordinate(k / 4, 5), grid.coordinate(k % 4, 4)))
            .collect();
        Table {
            value: one_minus_value.iter().map(|w| 1.0 - w).collect(),
            one_minus_value,
            std_error: vec![0.0; 20],
            spec,
            command: String::new(),
            node_errors: None,
            requested_max_error: None,
            lookup_fit: None,
        }
    }

    /// On rows and columns at nodes of a linear or square-root `mu` axis, a loss linear in the
    /// texture coordinates is what the bilinear lookup returns everywhere, so its average is a
    /// closed form: `2 ∫ (a + b mu) mu dmu = a + 2b/3`, and with `t = sqrt(mu)`,
    /// `2 ∫ (a + b sqrt(mu)) mu dmu = a + 4b/5`.
    #[test]
    fn the_lookups_average_loss_is_the_closed_form_of_a_linear_lookup() {
        let a = |r: f64| 0.1 + 0.4 * r;
        let loss = |r: f64, t: f64| a(r) + 0.2 * t;
        let linear = e_table(Grid::Nodes, MuMapping::Linear, loss);
        let sqrt = e_table(Grid::Nodes, MuMapping::Sqrt, loss);
        for r in [0.0, 0.3, 0.5, 0.9, 1.0] {
            let (value, error) = one_minus_lookup_average(&linear, r);
            assert!((value - (a(r) + 0.4 / 3.0)).abs() < 1e-14, "{r}: {value}");
            assert!((0.0..1e-14).contains(&error), "{error}");
            let (value, _) = one_minus_lookup_average(&sqrt, r);
            assert!((value - (a(r) + 0.16)).abs() < 1e-14, "{r}: {value}");
        }
        // Neither is derived per roughness: the lookup of the derived table is exact between
        // its nodes too, since the average is linear in r.
        let norm = derive(&linear, String::new());
        assert!(!stores_per_roughness(&norm.spec));
        for r in [0.0, 0.01, 0.3, 0.77, 1.0] {
            let got = normalisation_lookup(&norm, r);
            assert!((got - (a(r) + 0.4 / 3.0)).abs() < 1e-13, "{r}: {got}");
        }
        assert!(norm.max_std_error() < 1e-14);
        // The one-minus channel the files store beside it.
        for (v, w) in norm.value.iter().zip(&norm.one_minus_value) {
            assert!((v + w - 1.0).abs() < 1e-15, "{v} {w}");
        }
    }

    /// The normalisation table's axis: every cell of the E table's rows subdivided 16 times,
    /// the first four 96 times where it stores `(1 - Ē) / x`, on nodes, in the E table's
    /// convention (`5` rows on nodes: 385 entries; 32 rows: 817; on centres, whose rows sit
    /// half a cell in: 81).
    #[test]
    fn the_normalisation_subdivides_every_cell_of_the_rows() {
        let loss = |_: f64, _: f64| 0.5;
        let nodes = spec_for(&e_table(Grid::Nodes, MuMapping::Adaptive, loss).spec);
        let centers = spec_for(&e_table(Grid::Centers, MuMapping::Adaptive, loss).spec);
        assert_eq!(nodes.shape(), [385]);
        assert_eq!(centers.shape(), [81]);
        assert_eq!(centers.refined_start, None);
        let mut rows_32 = e_table(Grid::Nodes, MuMapping::Adaptive, loss).spec;
        if let Some(Axis::Roughness { size, .. }) = &mut rows_32.roughness {
            *size = 32;
        }
        let line = NodeLine::of(&spec_for(&rows_32));
        assert_eq!(spec_for(&rows_32).shape(), [817]);
        // Rows j / 31 on nodes: 96 j up to row 4, then 384 + 16 (j - 4); and back.
        for (row, node) in [(0, 0.0), (1, 96.0), (4, 384.0), (5, 400.0), (31, 816.0)] {
            let t = f64::from(row) / 31.0;
            assert!((line.position(t) - node).abs() < 1e-12, "row {row}");
            assert!((line.coordinate(node) - t).abs() < 1e-15, "row {row}");
        }
        assert_eq!((line.position(-0.5), line.position(2.0)), (0.0, 816.0));
        assert_eq!(nodes.roughness_axis().grid(), Grid::Nodes);
        assert_eq!(centers.roughness_axis().grid(), Grid::Nodes);
        assert_eq!(nodes.quantity, Quantity::FMsNorm);
        assert!(nodes.check().is_ok());
        // Row 1 of 5 centres, t = 0.3, is node 0.3 * 80 = 24 of 81.
        assert_eq!(
            Grid::Nodes.coordinate(24, 81),
            Grid::Centers.coordinate(1, 5)
        );
    }

    /// Only the adaptive `mu` axis with rows on nodes stores `(1 - Ē) / x`; its lookup
    /// multiplies back by `x`, so at every node but the first it returns `1 - Ē` itself (a
    /// loss of 0.3 at every texel: `1 - Ē = 0.3` at every `r > 0`, 0 at the mirror).
    #[test]
    fn only_the_adaptive_axis_on_nodes_is_stored_per_roughness() {
        let loss = |_: f64, _: f64| 0.3;
        let adaptive = e_table(Grid::Nodes, MuMapping::Adaptive, loss);
        assert!(divides_by_roughness(&adaptive.spec));
        assert!(!divides_by_roughness(
            &e_table(Grid::Centers, MuMapping::Adaptive, loss).spec
        ));
        assert!(!divides_by_roughness(
            &e_table(Grid::Nodes, MuMapping::Linear, loss).spec
        ));
        let norm = derive(&adaptive, String::new());
        assert!(stores_per_roughness(&norm.spec));
        let line = NodeLine::of(&norm.spec);
        for i in [1, 2, 16, 33, 64, 97, 384] {
            let x = line.coordinate(i as f64);
            assert!(
                (norm.value[i] * x - 0.3).abs() < 1e-13,
                "{i}: {}",
                norm.value[i]
            );
            let got = normalisation_lookup(&norm, x);
            assert!((got - 0.3).abs() < 1e-13, "{i}: {got}");
        }
        assert_eq!(normalisation_lookup(&norm, 0.0), 0.0);
        // Its error estimates are divided by x as well (a loss that varies along the row,
        // which the quadrature does not integrate exactly).
        let varying = e_table(Grid::Nodes, MuMapping::Adaptive, |r, t| 0.2 + 0.1 * r * t);
        let varying_norm = derive(&varying, String::new());
        for i in [1, 7, 64, 384] {
            let x = line.coordinate(i as f64);
            let (_, error) = one_minus_lookup_average(&varying, x);
            assert!(error > 0.0, "{i}");
            assert!(
                (varying_norm.std_error[i] * x / error - 1.0).abs() < 1e-12,
                "{i}"
            );
        }
        // The first entry is the slope at 1e-4 of the first interval: 0.3 / (1e-4 / 384).
        assert!((norm.value[0] / (0.3 * 384e4) - 1.0).abs() < 1e-12);
    }
}

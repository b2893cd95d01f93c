//! Linear programs `min c . x` subject to `G x <= h` over free `x` with few unknowns and many
//! constraints, solved through their dual `max -h . y` subject to `G^T y = -c`, `y >= 0` by the
//! revised simplex method with a dense basis inverse (Dantzig, "Linear programming and
//! extensions", 1963, ch. 6 and 9; two phases with artificial columns, Harris' two-pass ratio
//! test, P. M. J. Harris, Math. Programming 5 (1973) 1-28, and Bland's rule against cycling,
//! R. G. Bland, Math. Oper. Res. 2 (1977) 103-107). The dual has as many rows as the primal has
//! unknowns (a few dozen for a fit's coefficients), so a basis is a small dense matrix however
//! many constraints there are; the primal solution is read off the optimal basis' simplex
//! multipliers. What the rational minimax fits ([`crate::fit::rational`]) solve at each step of
//! their differential correction.

use rayon::prelude::*;

/// Why a linear program has no solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LpError {
    /// No `x` satisfies every constraint (the dual is unbounded).
    Infeasible,
    /// The objective decreases without bound, or no `x` is feasible either (the dual is
    /// infeasible).
    Unbounded,
    /// The pivot limit was reached (a symptom of numerical trouble, not of the problem).
    IterationLimit,
}

impl std::fmt::Display for LpError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LpError::Infeasible => "the constraints admit no solution",
            LpError::Unbounded => "the objective is unbounded below",
            LpError::IterationLimit => "the simplex method reached its pivot limit",
        })
    }
}

/// Feasibility and optimality tolerance of the dual simplex steps.
const TOLERANCE: f64 = 1e-11;
/// The right side's perturbation, relative to the largest objective coefficient.
const PERTURBATION: f64 = 1e-9;
/// Columns per block of the parallel pricing.
const PRICING_BLOCK: usize = 2048;
/// Pivots between refactorisations of the basis inverse.
const REFACTOR_EVERY: usize = 64;
/// Consecutive degenerate pivots after which Bland's rule chooses (until progress resumes).
const DEGENERATE_RUN: usize = 30;

/// `min c . x` subject to `G x <= h`, `x` free; `g` holds `G` row by row (`h.len()` rows of
/// `c.len()` entries). Returns the minimiser.
///
/// # Errors
/// [`LpError`] when there is no minimiser.
///
/// # Panics
/// When `g` is not `h.len() * c.len()` long.
pub fn minimize(c: &[f64], g: &[f64], h: &[f64]) -> Result<Vec<f64>, LpError> {
    minimize_from(c, g, h, None).map(|solution| solution.x)
}

/// A minimiser and the optimal basis it was read from (indices of the constraints, and
/// `h.len() + i` for a redundant dual row `i`), which starts a related program faster.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    pub x: Vec<f64>,
    pub basis: Vec<usize>,
}

/// [`minimize`], starting from `start` (the basis of a related program's [`Solution`] with the
/// same `c`) when it is still a feasible basis of this program's dual, and from scratch
/// otherwise; the result is the same kind of optimum either way. Differential correction
/// solves a sequence of programs whose optimal bases differ by a few columns.
///
/// # Errors
/// [`LpError`] when there is no minimiser.
///
/// # Panics
/// When `g` is not `h.len() * c.len()` long.
pub fn minimize_from(
    c: &[f64],
    g: &[f64],
    h: &[f64],
    start: Option<&[usize]>,
) -> Result<Solution, LpError> {
    let n = c.len();
    let m = h.len();
    assert_eq!(
        g.len(),
        m * n,
        "G must have h.len() rows of c.len() entries"
    );
    // Dual rows i = 0..n: sum_j G[j][i] y_j = -c_i, scaled by sign[i] so the right side is >= 0.
    let sign: Vec<f64> = c
        .iter()
        .map(|&ci| if -ci < 0.0 { -1.0 } else { 1.0 })
        .collect();
    // The right side, perturbed by distinct small positive amounts so that no basis is
    // degenerate (Charnes' perturbation, as in Dantzig ch. 10): the all-but-one-zero right side of
    // a minimax problem's dual otherwise stalls the simplex method in degenerate pivots. The
    // perturbation moves the dual optimum by about its size, the primal solution read off the
    // basis not at all where the optimal basis is unique.
    let scale = c.iter().fold(0.0_f64, |a, &ci| a.max(ci.abs())).max(1e-300);
    let rhs: Vec<f64> = c
        .iter()
        .zip(&sign)
        .enumerate()
        .map(|(i, (&ci, &s))| {
            -ci * s + PERTURBATION * scale * (1.0 + (i as f64 * 0.618_033_988_749_895).fract())
        })
        .collect();
    let column = |j: usize, out: &mut [f64]| {
        if j < m {
            for i in 0..n {
                out[i] = g[j * n + i] * sign[i];
            }
        } else {
            out.fill(0.0);
            out[j - m] = 1.0;
        }
    };
    let mut norms = vec![1.0; m + n];
    let mut a = vec![0.0; n];
    for (j, norm) in norms.iter_mut().enumerate().take(m) {
        column(j, &mut a);
        *norm = a.iter().map(|x| x * x).sum::<f64>().sqrt().max(1.0);
    }
    let mut simplex = Simplex {
        n,
        basis: (m..m + n).collect(),
        inverse: identity(n),
        values: rhs.clone(),
        pivots: 0,
        norms,
    };
    let limit = 50 * (n + m).max(100);
    let warm = start.is_some_and(|basis| {
        let mut sorted = basis.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        if basis.len() != n || sorted.len() != n || sorted.last().is_some_and(|&j| j >= m + n) {
            return false;
        }
        simplex.basis = basis.to_vec();
        simplex
            .refactor(&column, &rhs)
            .is_some_and(|lowest| lowest > -1e-9)
            && simplex
                .values
                .iter()
                .zip(&simplex.basis)
                .all(|(&v, &j)| j < m || v <= 1e-9)
    });
    if !warm {
        simplex.basis = (m..m + n).collect();
        simplex.inverse = identity(n);
        simplex.values.clone_from(&rhs);
        // Phase 1: drive the artificial columns (indices m..m+n) out; cost -1 on each.
        let phase_one = |j: usize| if j < m { 0.0 } else { -1.0 };
        simplex.run(m + n, &phase_one, &column, &rhs, limit)?;
        if simplex
            .values
            .iter()
            .zip(&simplex.basis)
            .any(|(&v, &j)| j >= m && v > 1e-9)
        {
            // The dual has no feasible point: the primal is unbounded (or has no point either).
            return Err(LpError::Unbounded);
        }
        simplex.drive_out_artificials(m, &column);
    }
    // Phase 2: the dual objective -h . y; artificials may not re-enter.
    let phase_two = |j: usize| if j < m { -h[j] } else { 0.0 };
    simplex.run(m, &phase_two, &column, &rhs, limit)?;
    let multipliers = simplex.multipliers(&phase_two);
    Ok(Solution {
        x: multipliers
            .iter()
            .zip(&sign)
            .map(|(&p, &s)| -p * s)
            .collect(),
        basis: simplex.basis,
    })
}

fn identity(n: usize) -> Vec<f64> {
    let mut a = vec![0.0; n * n];
    for i in 0..n {
        a[i * n + i] = 1.0;
    }
    a
}

/// A basis of the dual (standard form `max cost . y`, `A y = rhs`, `y >= 0`) and its inverse.
struct Simplex {
    n: usize,
    basis: Vec<usize>,
    /// Row-major `B^-1`.
    inverse: Vec<f64>,
    /// The basic variables' values `B^-1 rhs`.
    values: Vec<f64>,
    pivots: usize,
    /// Each column's Euclidean norm (at least 1), which scales its reduced cost in pricing.
    norms: Vec<f64>,
}

impl Simplex {
    /// `pi = cost_B B^-1`.
    fn multipliers(&self, cost: &dyn Fn(usize) -> f64) -> Vec<f64> {
        let n = self.n;
        let mut pi = vec![0.0; n];
        for (r, &j) in self.basis.iter().enumerate() {
            let cj = cost(j);
            if cj != 0.0 {
                for (p, &b) in pi.iter_mut().zip(&self.inverse[r * n..(r + 1) * n]) {
                    *p += cj * b;
                }
            }
        }
        pi
    }

    fn direction(&self, a: &[f64]) -> Vec<f64> {
        let n = self.n;
        (0..n)
            .map(|r| {
                self.inverse[r * n..(r + 1) * n]
                    .iter()
                    .zip(a)
                    .map(|(b, x)| b * x)
                    .sum()
            })
            .collect()
    }

    /// Pivots until no column among `0..columns` improves `cost`.
    fn run(
        &mut self,
        columns: usize,
        cost: &(dyn Fn(usize) -> f64 + Sync),
        column: &(dyn Fn(usize, &mut [f64]) + Sync),
        rhs: &[f64],
        limit: usize,
    ) -> Result<(), LpError> {
        let n = self.n;
        let mut a = vec![0.0; n];
        let mut degenerate = 0;
        loop {
            if self.pivots >= limit {
                return Err(LpError::IterationLimit);
            }
            let pi = self.multipliers(cost);
            let bland = degenerate >= DEGENERATE_RUN;
            // Pricing, in parallel over blocks of columns: the largest scaled reduced cost
            // (Dantzig), or the first improving column (Bland); ties to the lowest index, so
            // the choice does not depend on the thread count.
            let price = |range: std::ops::Range<usize>| {
                let mut a = vec![0.0; n];
                let mut found: Option<(usize, f64)> = None;
                for j in range {
                    column(j, &mut a);
                    let reduced = (cost(j) - pi.iter().zip(&a).map(|(p, x)| p * x).sum::<f64>())
                        / self.norms[j];
                    if reduced > TOLERANCE
                        && found.is_none_or(|(_, best)| reduced > best)
                        && !self.basis.contains(&j)
                    {
                        found = Some((j, reduced));
                        if bland {
                            break;
                        }
                    }
                }
                found
            };
            let blocks: Vec<std::ops::Range<usize>> = (0..columns)
                .step_by(PRICING_BLOCK)
                .map(|lo| lo..(lo + PRICING_BLOCK).min(columns))
                .collect();
            let entering = blocks
                .into_par_iter()
                .map(price)
                .collect::<Vec<_>>()
                .into_iter()
                .flatten()
                .reduce(|a, b| if bland || a.1 >= b.1 { a } else { b })
                .map(|(j, _)| j);
            let Some(q) = entering else { return Ok(()) };
            column(q, &mut a);
            let w = self.direction(&a);
            // Harris: the largest step any row allows with slack TOLERANCE, then the row with
            // the largest pivot among those blocking within it.
            let mut step = f64::INFINITY;
            for (r, &wr) in w.iter().enumerate() {
                if wr > TOLERANCE {
                    step = step.min((self.values[r].max(0.0) + TOLERANCE) / wr);
                }
            }
            if step == f64::INFINITY {
                // The dual is unbounded: the primal has no feasible point. (Phase 1's objective
                // is at most 0, so only phase 2 gets here.)
                return Err(LpError::Infeasible);
            }
            let mut leaving = None;
            let mut pivot = 0.0;
            for (r, &wr) in w.iter().enumerate() {
                if wr > TOLERANCE && self.values[r].max(0.0) / wr <= step {
                    let better = if bland {
                        leaving.is_none_or(|l: usize| self.basis[r] < self.basis[l])
                    } else {
                        wr > pivot
                    };
                    if better {
                        leaving = Some(r);
                        pivot = wr;
                    }
                }
            }
            let r = leaving.expect("a row blocks the step");
            let theta = self.values[r].max(0.0) / w[r];
            degenerate = if theta > TOLERANCE { 0 } else { degenerate + 1 };
            self.pivot(r, q, &w);
            if self.pivots.is_multiple_of(REFACTOR_EVERY) {
                let _ = self.refactor(column, rhs);
            }
        }
    }

    fn pivot(&mut self, r: usize, q: usize, w: &[f64]) {
        let n = self.n;
        let wr = w[r];
        let row: Vec<f64> = self.inverse[r * n..(r + 1) * n]
            .iter()
            .map(|b| b / wr)
            .collect();
        let vr = self.values[r] / wr;
        for (i, &wi) in w.iter().enumerate() {
            if i != r && wi != 0.0 {
                for (b, &x) in self.inverse[i * n..(i + 1) * n].iter_mut().zip(&row) {
                    *b -= wi * x;
                }
                self.values[i] = (self.values[i] - wi * vr).max(0.0);
            }
        }
        self.inverse[r * n..(r + 1) * n].copy_from_slice(&row);
        self.values[r] = vr.max(0.0);
        self.basis[r] = q;
        self.pivots += 1;
    }

    /// Recomputes `B^-1` (Gauss-Jordan with partial pivoting) and the basic values (clamped at
    /// 0); returns the lowest value before clamping, `None` for a singular basis (the inverse
    /// then stays as it was).
    fn refactor(&mut self, column: &dyn Fn(usize, &mut [f64]), rhs: &[f64]) -> Option<f64> {
        let n = self.n;
        let mut b = vec![0.0; n * n];
        let mut a = vec![0.0; n];
        for (k, &j) in self.basis.iter().enumerate() {
            column(j, &mut a);
            for i in 0..n {
                b[i * n + k] = a[i];
            }
        }
        let mut inv = identity(n);
        for k in 0..n {
            let p = (k..n)
                .max_by(|&x, &y| b[x * n + k].abs().total_cmp(&b[y * n + k].abs()))
                .unwrap_or(k);
            if b[p * n + k].abs() < 1e-300 {
                return None;
            }
            for col in 0..n {
                b.swap(k * n + col, p * n + col);
                inv.swap(k * n + col, p * n + col);
            }
            let d = b[k * n + k];
            for col in 0..n {
                b[k * n + col] /= d;
                inv[k * n + col] /= d;
            }
            for i in 0..n {
                let f = b[i * n + k];
                if i != k && f != 0.0 {
                    for col in 0..n {
                        b[i * n + col] -= f * b[k * n + col];
                        inv[i * n + col] -= f * inv[k * n + col];
                    }
                }
            }
        }
        self.inverse = inv;
        let values = self.direction(rhs);
        let lowest = values.iter().copied().fold(f64::INFINITY, f64::min);
        self.values = values.into_iter().map(|v| v.max(0.0)).collect();
        Some(lowest)
    }

    /// Replaces basic artificial columns (at level 0 after phase 1) by real ones where a real
    /// column has a nonzero entry in their row; a row with none is redundant and keeps its
    /// artificial at 0.
    fn drive_out_artificials(&mut self, m: usize, column: &dyn Fn(usize, &mut [f64])) {
        let n = self.n;
        let mut a = vec![0.0; n];
        for r in 0..n {
            if self.basis[r] < m {
                continue;
            }
            let row = &self.inverse[r * n..(r + 1) * n];
            let mut best: Option<(usize, f64)> = None;
            for j in 0..m {
                column(j, &mut a);
                let wr: f64 = row.iter().zip(&a).map(|(b, x)| b * x).sum();
                if wr.abs() > 1e-9
                    && best.is_none_or(|b| wr.abs() > b.1)
                    && !self.basis.contains(&j)
                {
                    best = Some((j, wr.abs()));
                }
            }
            if let Some((j, _)) = best {
                column(j, &mut a);
                let w = self.direction(&a);
                self.pivot(r, j, &w);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `min -x - y` subject to `x + 2y <= 4`, `3x + y <= 6`, `x, y >= 0`: the vertex where the
    /// two lines cross, (8/5, 6/5), by hand.
    #[test]
    fn a_small_program_has_its_vertex() {
        let g = [1.0, 2.0, 3.0, 1.0, -1.0, 0.0, 0.0, -1.0];
        let h = [4.0, 6.0, 0.0, 0.0];
        let x = minimize(&[-1.0, -1.0], &g, &h).unwrap();
        assert!(
            (x[0] - 1.6).abs() < 1e-9 && (x[1] - 1.2).abs() < 1e-9,
            "{x:?}"
        );
    }

    /// The best straight line to `x^2` on [0, 1] in the maximum norm is `x - 1/8`, off by 1/8
    /// (Chebyshev's equioscillation at 0, 1/2 and 1): as a linear program in `(a, b, z)`,
    /// `min z` subject to `|a + b x_i - x_i^2| <= z` at 201 points, a degenerate program
    /// (402 constraints on 3 unknowns, most of them through the optimum's neighbourhood).
    #[test]
    fn the_best_line_to_a_parabola_is_chebyshevs() {
        let mut g = Vec::new();
        let mut h = Vec::new();
        for i in 0..=200 {
            let x = f64::from(i) / 200.0;
            for sign in [1.0, -1.0] {
                g.extend([sign, sign * x, -1.0]);
                h.push(sign * x * x);
            }
        }
        let x = minimize(&[0.0, 0.0, 1.0], &g, &h).unwrap();
        assert!((x[2] - 0.125).abs() < 1e-9, "{x:?}");
        assert!(
            (x[0] + 0.125).abs() < 1e-9 && (x[1] - 1.0).abs() < 1e-9,
            "{x:?}"
        );
    }

    /// No `x` has `x <= 1` and `x >= 2`; `min x` subject to `x <= 1` has no minimum.
    #[test]
    fn programs_without_a_solution_say_why() {
        assert_eq!(
            minimize(&[1.0], &[1.0, -1.0], &[1.0, -2.0]),
            Err(LpError::Infeasible)
        );
        assert_eq!(minimize(&[1.0], &[1.0], &[1.0]), Err(LpError::Unbounded));
    }
}

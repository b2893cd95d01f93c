//! Linear minimax (Chebyshev) approximation by Lawson's iteratively reweighted least squares
//! (C. L. Lawson, "Contributions to the theory of linear least maximum approximation", PhD
//! thesis, UCLA 1961; see Rice and Usow, Math. Comp. 22 (1968) 118-127): weighted least
//! squares, each point's weight then multiplied by its absolute error and renormalised, which
//! converges to the minimax weights. Each least-squares step solves the normal equations by
//! banded Cholesky: the rows are sparse, and the band is the widest span of a row's indices (a
//! dense problem is the band of full width). The best iterate, the smallest maximum over the
//! points, is kept. What the texel fit for a lookup ([`crate::table::lookup_fit`]) and the
//! polynomial fits ([`crate::fit::polynomial`]) solve.

/// How long to iterate and how to weigh.
#[derive(Clone, Copy, Debug)]
pub struct Lawson {
    /// Iterations (at least one least-squares solve).
    pub iterations: usize,
    /// The largest weight a point may take, as a multiple of the mean weight (infinite: the
    /// pure minimax).
    pub weight_cap: f64,
    /// Added to the normal equations' diagonal, relative to its mean, so that an unknown no
    /// point constrains stays 0.
    pub regularisation: f64,
}

/// `sum coefficient * x[index]` over a sparse row.
#[must_use]
pub fn dot(row: &[(usize, f64)], x: &[f64]) -> f64 {
    row.iter().map(|&(k, w)| w * x[k]).sum()
}

/// Lawson's algorithm for `min_x max_j |a_j . x - b_j|` with sparse rows `a_j` (terms
/// `(index, coefficient)`; see the module docs); returns the iterate with the smallest maximum.
#[must_use]
pub fn lawson<R: AsRef<[(usize, f64)]>>(
    rows: &[R],
    b: &[f64],
    unknowns: usize,
    settings: &Lawson,
) -> Vec<f64> {
    let bandwidth = rows
        .iter()
        .map(|w| {
            let (lo, hi) = w
                .as_ref()
                .iter()
                .fold((usize::MAX, 0), |(lo, hi), &(k, _)| (lo.min(k), hi.max(k)));
            hi - lo
        })
        .max()
        .unwrap_or(0);
    let mut weight = vec![1.0 / rows.len() as f64; rows.len()];
    let mut best = (f64::INFINITY, vec![0.0; unknowns]);
    for _ in 0..settings.iterations.max(1) {
        let mut matrix = Banded::new(unknowns, bandwidth);
        let mut rhs = vec![0.0; unknowns];
        for ((row, &w), &bj) in rows.iter().zip(&weight).zip(b) {
            for &(i, wi) in row.as_ref() {
                rhs[i] += w * wi * bj;
                for &(j, wj) in row.as_ref() {
                    if j <= i {
                        matrix.add(i, j, w * wi * wj);
                    }
                }
            }
        }
        matrix.regularise(settings.regularisation);
        let Some(x) = matrix.solve(&rhs) else { break };
        let errors: Vec<f64> = rows
            .iter()
            .zip(b)
            .map(|(row, &bj)| (dot(row.as_ref(), &x) - bj).abs())
            .collect();
        let max = errors.iter().fold(0.0_f64, |m, &e| m.max(e));
        if !max.is_finite() {
            break;
        }
        if max < best.0 {
            best = (max, x);
        }
        let total: f64 = weight.iter().zip(&errors).map(|(w, e)| w * e).sum();
        if total.is_nan() || total <= 0.0 {
            break;
        }
        let cap = settings.weight_cap / rows.len() as f64;
        for (w, e) in weight.iter_mut().zip(&errors) {
            *w = (*w * (e / total)).min(cap);
        }
    }
    best.1
}

/// A symmetric positive definite band matrix, lower triangle stored by rows: entry `(i, j)`,
/// `i - bandwidth <= j <= i`, at `i * (bandwidth + 1) + (j + bandwidth - i)`.
struct Banded {
    n: usize,
    bandwidth: usize,
    data: Vec<f64>,
}

impl Banded {
    fn new(n: usize, bandwidth: usize) -> Self {
        Self {
            n,
            bandwidth,
            data: vec![0.0; n * (bandwidth + 1)],
        }
    }

    fn at(&self, i: usize, j: usize) -> usize {
        i * (self.bandwidth + 1) + (j + self.bandwidth - i)
    }

    fn add(&mut self, i: usize, j: usize, v: f64) {
        let k = self.at(i, j);
        self.data[k] += v;
    }

    /// Adds `relative` times the mean diagonal to the diagonal (so that a texel no point
    /// constrains keeps its node value, correction 0).
    fn regularise(&mut self, relative: f64) {
        let mean = (0..self.n).map(|i| self.data[self.at(i, i)]).sum::<f64>() / self.n as f64;
        let shift = relative * mean.max(f64::MIN_POSITIVE);
        for i in 0..self.n {
            let k = self.at(i, i);
            self.data[k] += shift;
        }
    }

    /// Solves `A x = b` by banded Cholesky `A = L L^T`; `None` if `A` is not positive definite.
    fn solve(mut self, b: &[f64]) -> Option<Vec<f64>> {
        let (n, bw) = (self.n, self.bandwidth);
        for i in 0..n {
            let j0 = i.saturating_sub(bw);
            for j in j0..=i {
                let mut sum = self.data[self.at(i, j)];
                let k0 = j0.max(j.saturating_sub(bw));
                for k in k0..j {
                    sum -= self.data[self.at(i, k)] * self.data[self.at(j, k)];
                }
                if i == j {
                    if sum <= 0.0 || !sum.is_finite() {
                        return None;
                    }
                    let k = self.at(i, i);
                    self.data[k] = sum.sqrt();
                } else {
                    let k = self.at(i, j);
                    self.data[k] = sum / self.data[self.at(j, j)];
                }
            }
        }
        let mut y = b.to_vec();
        for i in 0..n {
            for k in i.saturating_sub(bw)..i {
                y[i] -= self.data[self.at(i, k)] * y[k];
            }
            y[i] /= self.data[self.at(i, i)];
        }
        for i in (0..n).rev() {
            for k in i + 1..(i + bw + 1).min(n) {
                y[i] -= self.data[self.at(k, i)] * y[k];
            }
            y[i] /= self.data[self.at(i, i)];
        }
        Some(y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The banded solver against a dense system solved by hand: a tridiagonal matrix.
    #[test]
    fn banded_cholesky_solves_a_tridiagonal_system() {
        // [[4, 1, 0], [1, 4, 1], [0, 1, 4]] x = [5, 6, 5] has x = [1, 1, 1].
        let mut a = Banded::new(3, 1);
        for i in 0..3 {
            a.add(i, i, 4.0);
        }
        a.add(1, 0, 1.0);
        a.add(2, 1, 1.0);
        let x = a.solve(&[5.0, 6.0, 5.0]).unwrap();
        for v in x {
            assert!((v - 1.0).abs() < 1e-14, "{v}");
        }
    }

    /// Lawson on the textbook case: the best constant for three points 0, 1, 3 is 1.5 (the
    /// midrange, max error 1.5), where least squares gives the mean 4/3.
    #[test]
    fn lawson_finds_the_midrange() {
        let one = [(0, 1.0)];
        let settings = Lawson {
            iterations: 200,
            weight_cap: f64::INFINITY,
            regularisation: 1e-12,
        };
        let x = lawson(&[one, one, one], &[0.0, 1.0, 3.0], 1, &settings);
        assert!((x[0] - 1.5).abs() < 1e-3, "{}", x[0]);
    }
}

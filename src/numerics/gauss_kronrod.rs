//! Adaptive Gauss-Kronrod quadrature (7-point Gauss, 15-point Kronrod), for vector integrands.
//!
//! Nodes and weights are QUADPACK's `qk15` (Piessens, de Doncker-Kapenga, Überhuber and Kahaner,
//! "QUADPACK: A Subroutine Package for Automatic Integration", Springer 1983). The adaptive driver
//! follows QUADPACK's `qag` strategy: keep a list of intervals, split the one with the largest
//! error estimate in two, until the summed estimate meets the tolerance or the interval budget
//! runs out. The error estimate of an interval is `|K15 - G7|`, the largest over the components:
//! pessimistic for smooth integrands (the K15 value is far better than that), which is the side
//! to err on.

/// Kronrod abscissae on [-1, 1], positive half, largest first; odd indices are the Gauss nodes.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];

/// Kronrod weights for [`XGK`].
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];

/// Gauss weights for `XGK[1], XGK[3], XGK[5], XGK[7]`.
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// Relative size of an error estimate below which it is f64 rounding, not truncation.
const ROUNDOFF: f64 = 50.0 * f64::EPSILON;

/// The result of an adaptive integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadrature<const N: usize> {
    /// The integral of each component.
    pub value: [f64; N],
    /// The summed error estimate (largest component per interval).
    pub error: f64,
    /// Integrand evaluations spent.
    pub evaluations: u64,
    /// Whether the tolerance was met within the interval budget.
    pub converged: bool,
}

/// The number of nodes of one Kronrod rule, the size of a batch of [`integrate_pieces_batch`].
pub const KRONROD_NODES: usize = 15;

/// The nodes of one 15-point Kronrod rule on `[a, b]`, in the order a batch integrand receives
/// them: the centre, then `centre - half XGK[j]` and `centre + half XGK[j]` for `j = 0..7`.
fn kronrod_nodes(a: f64, b: f64) -> [f64; KRONROD_NODES] {
    let centre = 0.5 * (a + b);
    let half = 0.5 * (b - a);
    let mut nodes = [centre; KRONROD_NODES];
    for j in 0..7 {
        let dx = half * XGK[j];
        nodes[1 + 2 * j] = centre - dx;
        nodes[2 + 2 * j] = centre + dx;
    }
    nodes
}

/// One 15-point Kronrod rule on `[a, b]`: the K15 value and the `|K15 - G7|` estimate, from the
/// integrand's values at [`kronrod_nodes`], evaluated in one call.
fn kronrod<const N: usize>(
    f: &mut impl FnMut(&[f64; KRONROD_NODES], &mut [[f64; N]; KRONROD_NODES]),
    a: f64,
    b: f64,
) -> ([f64; N], f64) {
    let half = 0.5 * (b - a);
    let mut values = [[0.0; N]; KRONROD_NODES];
    f(&kronrod_nodes(a, b), &mut values);
    let mut k = [0.0; N];
    let mut g = [0.0; N];
    let mid = values[0];
    for c in 0..N {
        k[c] = WGK[7] * mid[c];
        g[c] = WG[3] * mid[c];
    }
    for j in 0..7 {
        let (lo, hi) = (values[1 + 2 * j], values[2 + 2 * j]);
        for c in 0..N {
            let pair = lo[c] + hi[c];
            k[c] += WGK[j] * pair;
            if j % 2 == 1 {
                g[c] += WG[j / 2] * pair;
            }
        }
    }
    let mut error: f64 = 0.0;
    for c in 0..N {
        k[c] *= half;
        g[c] *= half;
        // `f64::max` would drop a NaN: a value that is not a number makes the estimate NaN,
        // so the interval is never counted as converged.
        let difference = (k[c] - g[c]).abs();
        error = if difference.is_nan() {
            f64::NAN
        } else {
            error.max(difference)
        };
    }
    (k, error)
}

/// Integrates `f` over `[a, b]` until the summed error estimate is at most `tolerance`, using at
/// most `max_intervals` intervals. If the budget runs out, the result carries `converged: false`
/// and the error estimate reached: the best available, never silently passed off as converged.
/// A tolerance below f64 rounding of the integral is met as far as rounding allows (the
/// estimate then reports that level).
pub fn integrate<const N: usize>(
    mut f: impl FnMut(f64) -> [f64; N],
    a: f64,
    b: f64,
    tolerance: f64,
    max_intervals: usize,
) -> Quadrature<N> {
    integrate_pieces(&mut f, &[a, b], tolerance, max_intervals)
}

/// As [`integrate`], over consecutive pieces `[breaks[0], breaks[1]], [breaks[1], breaks[2]], ...`
/// (split where the integrand has a kink or a steep layer, so every piece starts smooth). Empty
/// pieces are skipped.
pub fn integrate_pieces<const N: usize>(
    f: &mut impl FnMut(f64) -> [f64; N],
    breaks: &[f64],
    tolerance: f64,
    max_intervals: usize,
) -> Quadrature<N> {
    let mut batch = |nodes: &[f64; KRONROD_NODES], values: &mut [[f64; N]; KRONROD_NODES]| {
        for (node, value) in nodes.iter().zip(values.iter_mut()) {
            *value = f(*node);
        }
    };
    integrate_pieces_batch(&mut batch, breaks, tolerance, max_intervals)
}

/// As [`integrate_pieces`], for an integrand that evaluates a whole rule's nodes in one call
/// (`f(nodes, values)` fills `values[k]` with the integrand at `nodes[k]`), so that it can
/// evaluate them several at a time in SIMD. The result is the same, bit for bit, as
/// [`integrate_pieces`] with an integrand that gives the same values.
pub fn integrate_pieces_batch<const N: usize>(
    f: &mut impl FnMut(&[f64; KRONROD_NODES], &mut [[f64; N]; KRONROD_NODES]),
    breaks: &[f64],
    tolerance: f64,
    max_intervals: usize,
) -> Quadrature<N> {
    struct Interval<const N: usize> {
        a: f64,
        b: f64,
        value: [f64; N],
        error: f64,
    }
    // Inline up to a typical piece count plus a few splits: most calls never touch the heap.
    let mut intervals: smallvec::SmallVec<[Interval<N>; 24]> = smallvec::SmallVec::new();
    for pair in breaks.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if b > a {
            let (value, error) = kronrod(f, a, b);
            intervals.push(Interval { a, b, value, error });
        }
    }
    let mut evaluations = 15 * intervals.len() as u64;
    let total_error = |intervals: &[Interval<N>]| intervals.iter().map(|i| i.error).sum::<f64>();
    let mut converged = total_error(&intervals) <= tolerance;
    while !converged && intervals.len() < max_intervals {
        let (worst, worst_error) = intervals
            .iter()
            .enumerate()
            .max_by(|x, y| x.1.error.total_cmp(&y.1.error))
            .map(|(k, i)| (k, i.error))
            .expect("at least one interval");
        // Roundoff floor: when even the worst interval's estimate is at the level of f64
        // rounding of the values summed, splitting cannot lower the total any further.
        let scale: f64 = intervals
            .iter()
            .map(|i| i.value.iter().map(|v| v.abs()).fold(0.0, f64::max))
            .sum();
        if worst_error <= ROUNDOFF * scale {
            converged =
                total_error(&intervals) <= tolerance.max(ROUNDOFF * scale * intervals.len() as f64);
            break;
        }
        let Interval { a, b, .. } = intervals.swap_remove(worst);
        let mid = 0.5 * (a + b);
        if !(mid > a && mid < b) {
            break; // cannot split further in f64
        }
        for (lo, hi) in [(a, mid), (mid, b)] {
            let (value, error) = kronrod(f, lo, hi);
            intervals.push(Interval {
                a: lo,
                b: hi,
                value,
                error,
            });
        }
        evaluations += 30;
        converged = total_error(&intervals) <= tolerance;
    }
    // Sum in a fixed order (by position), whatever order the splitting left the list in.
    intervals.sort_by(|x, y| x.a.total_cmp(&y.a));
    let mut value = [0.0; N];
    for interval in &intervals {
        for (total, part) in value.iter_mut().zip(interval.value) {
            *total += part;
        }
    }
    Quadrature {
        value,
        error: total_error(&intervals),
        evaluations,
        converged,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// One rule's nodes on `[a, b]`, in the order a batch integrand receives them.
    pub(crate) fn nodes_of(a: f64, b: f64) -> [f64; KRONROD_NODES] {
        kronrod_nodes(a, b)
    }

    /// An integrand that is NaN somewhere gives a NaN value and error and `converged: false`,
    /// never a finite error beside a NaN value (`f64::max` drops NaN; an estimate built on it
    /// claimed convergence).
    #[test]
    fn a_nan_integrand_is_never_converged() {
        let q = integrate(
            |x: f64| [1.0, if x > 0.7 { f64::NAN } else { x }],
            0.0,
            1.0,
            1e-10,
            50,
        );
        assert!(
            q.value[1].is_nan() && q.error.is_nan() && !q.converged,
            "{q:?}"
        );
        let q = integrate(|x: f64| [x], 0.0, 1.0, 1e-10, 50);
        assert!(q.converged && (q.value[0] - 0.5).abs() < 1e-15);
    }

    #[test]
    fn rules_integrate_polynomials_exactly() {
        // K15 is exact to degree 22, G7 to degree 13: a single interval must reproduce ∫ x^k,
        // and miss it just beyond (the degree is no higher, so a wrong weight cannot hide).
        for k in 0..=24 {
            let exact = if k % 2 == 1 {
                0.0
            } else {
                2.0 / (k as f64 + 1.0)
            };
            let (value, error) = kronrod(
                &mut |xs: &[f64; KRONROD_NODES], out: &mut [[f64; 1]; KRONROD_NODES]| {
                    for (x, v) in xs.iter().zip(out.iter_mut()) {
                        *v = [x.powi(k)];
                    }
                },
                -1.0,
                1.0,
            );
            let off = (value[0] - exact).abs();
            if k <= 22 {
                assert!(off < 1e-14, "x^{k}: {} vs {exact}", value[0]);
            } else if k % 2 == 0 {
                assert!(off > 1e-12, "K15 exact beyond its degree at x^{k}");
            }
            if k <= 13 {
                assert!(error < 1e-14, "G7 should be exact for x^{k}: {error}");
            } else if k == 14 {
                assert!(error > 1e-6, "G7 exact beyond its degree: {error}");
            }
        }
        assert!((WGK.iter().sum::<f64>() * 2.0 - WGK[7] - 2.0).abs() < 1e-15);
        assert!((WG.iter().sum::<f64>() * 2.0 - WG[3] - 2.0).abs() < 1e-15);
    }

    #[test]
    fn adaptive_integration_meets_its_tolerance_on_hard_integrands() {
        // A kink, a narrow peak and an integrable endpoint singularity.
        let q = integrate(
            |x: f64| [x.abs(), (-1e4 * x * x).exp()],
            -1.0,
            2.0,
            1e-12,
            1000,
        );
        let peak = (std::f64::consts::PI / 1e4).sqrt();
        assert!(q.converged);
        assert!(
            (q.value[0] - 2.5).abs() < 1e-12 && (q.value[1] - peak).abs() < 1e-12,
            "{q:?}"
        );
        let q = integrate(|x: f64| [1.0 / x.sqrt()], 0.0, 1.0, 1e-10, 1000);
        assert!((q.value[0] - 2.0).abs() < 1e-9, "{q:?}");
        // A budget too small says so.
        let q = integrate(|x: f64| [(1.0 / (x + 1e-9)).sin()], 0.0, 1.0, 1e-14, 4);
        assert!(!q.converged && q.error > 1e-14);
    }
}

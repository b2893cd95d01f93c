//! Whether the dielectric reference's stated error holds at every node of kiln's glass layout:
//! each node of the GGX height-correlated `E_dielectric_inside` (or, with `outside`,
//! `E_dielectric`) table, 16 IOR nodes by SIZE x SIZE, computed at the tolerance TOL (as a bake at that max error
//! computes it) and against the same reference at 1e-11. Prints the mean integrand evaluations
//! per node and every node whose stated error is below its distance to the tighter value, the
//! largest first (none since numerics version 13; docs/bake.md). 16 x 32 x 32 at 1e-7: about a minute
//! on 2 cores.
//!
//! Usage: `cargo run --release --example glass_node_margin -- [SIZE] [TOL] [inside|outside]`
use kiln::bake::BakeOptions;
use kiln::integrate::quantity::Quantity;
use kiln::integrate::reference::ReferenceSettings;
use kiln::integrate::value::Point;
use rayon::prelude::*;

fn main() {
    let mut args = std::env::args().skip(1);
    let size: usize = args
        .next()
        .map_or(32, |s| s.parse().expect("SIZE: a number"));
    let tolerance: f64 = args
        .next()
        .map_or(1e-7, |s| s.parse().expect("TOL: a number"));
    let quantity = match args.next().as_deref() {
        Some("outside") => Quantity::EDielectric,
        None | Some("inside") => Quantity::EDielectricInside,
        Some(other) => panic!("inside or outside, not {other}"),
    };
    let spec = BakeOptions {
        size,
        quantities: vec![quantity],
        ..BakeOptions::default()
    }
    .specs()
    .remove(0);
    let integral = spec.integral();
    let at = |k: usize| {
        let (alpha, mu, eta) = spec.texel_point(k);
        Point { alpha, mu, eta }
    };
    // (node, distance to the tighter value, stated error, evaluations).
    let nodes: Vec<(usize, f64, f64, u64)> = (0..spec.len())
        .into_par_iter()
        .map(|k| {
            let settings = |tolerance| ReferenceSettings {
                tolerance,
                max_intervals: 400,
            };
            let coarse = integral.reference(at(k), &settings(tolerance));
            let fine = integral.reference(at(k), &settings(1e-11));
            (
                k,
                (coarse.value - fine.value).abs(),
                coarse.error,
                coarse.evaluations,
            )
        })
        .collect();
    let mut understated: Vec<_> = nodes.iter().filter(|n| n.1 > n.2).collect();
    understated.sort_by(|a, b| b.1.total_cmp(&a.1));
    let evaluations: u64 = nodes.iter().map(|n| n.3).sum();
    println!(
        "{quantity:?} {:?} at {tolerance:e}: {} nodes, {} evaluations a node, {} understated",
        spec.shape(),
        nodes.len(),
        evaluations / nodes.len() as u64,
        understated.len()
    );
    for &&(k, actual, stated, _) in &understated {
        let Point { alpha, mu, eta } = at(k);
        println!(
            "  node {k}: alpha {alpha:.4}, mu {mu:?}, eta {eta:?}: off by {actual:.2e}, stated {stated:.2e}"
        );
    }
}

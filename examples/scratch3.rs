use kiln::model::ndf::beckmann_visible_slope_x;
use kiln::model::special::*;
fn main() {
    for (b, u) in [(0.0, 0.001), (0.0, 0.5), (1.0, 0.3), (20.0, 0.3)] {
        let x = beckmann_visible_slope_x(b, u);
        let sqrt_pi = 1.0 / FRAC_1_SQRT_PI;
        let cdf = |x: f64| 0.5 * (b * sqrt_pi * erfc(-x) + (-x * x).exp());
        println!("b {b} u {u} x {x} err {:e}", cdf(x) / cdf(b) - u);
    }
}

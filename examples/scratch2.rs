use kiln::model::ndf::beckmann_visible_slope_x;
use kiln::model::special::erf_inv_uniform;
fn main() {
    let n = 1_000_000;
    let t = std::time::Instant::now();
    let mut acc = 0.0;
    for i in 0..n {
        acc += erf_inv_uniform((i as f64 + 0.5) / n as f64);
    }
    println!("erf_inv {:?} per call {}", t.elapsed() / n as u32, acc);
    for b in [0.1, 1.0, 3.0] {
        let t = std::time::Instant::now();
        for i in 0..n {
            acc += beckmann_visible_slope_x(b, (i as f64 + 0.5) / n as f64);
        }
        println!(
            "slope_x b={b} {:?} per call {}",
            t.elapsed() / n as u32,
            acc
        );
    }
    let t = std::time::Instant::now();
    for i in 0..n {
        acc += libm::erfc((i as f64 + 0.5) / n as f64 * 3.0);
    }
    println!("erfc {:?} per call {}", t.elapsed() / n as u32, acc);
}

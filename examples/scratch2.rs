use kiln::model::ndf::VisibleSlopeX;
fn main() {
    let n = 2_000_000;
    let mut acc = 0.0;
    for b in [0.1, 1.0, 3.0] {
        let s = VisibleSlopeX::new(b).with_guess_table(1025);
        let t = std::time::Instant::now();
        for i in 0..n {
            acc += s.sample((i as f64 + 0.5) / n as f64);
        }
        println!(
            "tab slope_x b={b} {:?} per call {}",
            t.elapsed() / n as u32,
            acc
        );
    }
}

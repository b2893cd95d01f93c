use kiln::verify::input::read_kiln;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let table = read_kiln(std::path::Path::new(&args[1])).unwrap().unwrap();
    let eta: f64 = args[2].parse().unwrap();
    let mu: f64 = args[3].parse().unwrap();
    let settings = kiln::integrate::reference::ReferenceSettings {
        tolerance: 1e-9,
        ..Default::default()
    };
    for k in 0..=12 {
        let r = k as f64 * 0.01;
        let alpha = r * r;
        let at = kiln::integrate::value::Point {
            alpha,
            mu: Some(mu),
            eta: Some(eta),
        };
        let truth = table.spec.integral().reference(at, &settings).value;
        let lookup = table.lookup_eta(mu, r, eta);
        println!(
            "r {r:.3} truth {truth:.6} lookup {lookup:.6} dev {:.2e}",
            truth / lookup - 1.0
        );
    }
}

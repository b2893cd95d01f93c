use kiln::Quantity;
use kiln::bake::BakeOptions;
use rayon::prelude::*;
fn main() {
    let q: Quantity = if std::env::args().nth(1).as_deref() == Some("in") {
        Quantity::EDielectricInside
    } else {
        Quantity::EDielectric
    };
    let tol: f64 = std::env::args().nth(2).map_or(1e-9, |s| s.parse().unwrap());
    let options = BakeOptions {
        quantities: vec![q],
        ..BakeOptions::default()
    };
    let spec = options.specs().remove(0);
    let mut settings = kiln::integrate::reference::ReferenceSettings::default();
    settings.tolerance = tol;
    let out: Vec<_> = (0..spec.len())
        .into_par_iter()
        .map(|k| {
            let (alpha, mu, eta) = spec.texel_point(k);
            let t = std::time::Instant::now();
            let r = spec
                .integral()
                .reference(kiln::integrate::value::Point { alpha, mu, eta }, &settings);
            let mut fine = settings.clone();
            fine.tolerance = 1e-10;
            let f = spec
                .integral()
                .reference(kiln::integrate::value::Point { alpha, mu, eta }, &fine);
            (
                k,
                alpha,
                mu,
                eta,
                r.value,
                (r.one_minus_value - f.one_minus_value).abs(),
                r.converged,
                t.elapsed().as_secs_f64(),
                r.error,
            )
        })
        .collect();
    let mut slow = 0.0;
    for o in &out {
        slow += o.7;
    }
    let mut sorted = out.clone();
    sorted.sort_by(|a, b| b.5.total_cmp(&a.5));
    for o in sorted.iter().take(8) {
        println!("{:?}", o);
    }
    let mut by_time = out.clone();
    by_time.sort_by(|a, b| b.7.total_cmp(&a.7));
    for o in by_time.iter().take(5) {
        println!("slow {:?}", o);
    }
    println!("total cpu {slow:.1} s");
}

use kiln::integrate::*;
use kiln::model::*;
fn main() {
    let hc = |ndf| Model {
        ndf,
        masking: Masking::HeightCorrelated,
    };
    let sep = |ndf| Model {
        ndf,
        masking: Masking::Separable,
    };
    let s = QmcSettings::default();
    let t = std::time::Instant::now();
    let e = albedo(hc(Ndf::Ggx), 0.5, 0.5, &s);
    println!(
        "GGX E(0.5,0.5) {:?} vs 0.69825070 dev {:.2} sigma  {:?}",
        e,
        (e.value - 0.69825070) / e.std_error,
        t.elapsed()
    );
    let e = average_albedo(hc(Ndf::Ggx), 1.0, &s);
    println!(
        "GGX Eavg(1) {:?} vs 0.40913709 dev {:.2}",
        e,
        (e.value - 0.40913709) / e.std_error
    );
    let e = average_albedo(hc(Ndf::Ggx), 0.5, &s);
    println!(
        "GGX Eavg(.5) {:?} vs 0.70024047 dev {:.2}",
        e,
        (e.value - 0.70024047) / e.std_error
    );
    let e = average_albedo(sep(Ndf::Ggx), 1.0, &s);
    println!(
        "GGX sep Eavg(1) {:?} vs 0.37663461 dev {:.2}",
        e,
        (e.value - 0.37663461) / e.std_error
    );
    let t = std::time::Instant::now();
    let e = albedo(hc(Ndf::Beckmann), 1.0, 0.5, &s);
    println!(
        "Beck E(.5,1) {:?} vs 0.76656777 dev {:.2} {:?}",
        e,
        (e.value - 0.76656777) / e.std_error,
        t.elapsed()
    );
    let e = average_albedo(hc(Ndf::Beckmann), 1.0, &s);
    println!(
        "Beck Eavg(1) {:?} vs 0.66367771 dev {:.2}",
        e,
        (e.value - 0.66367771) / e.std_error
    );
    for &(mu, a) in &[(0.1, 0.1), (0.9, 0.9), (0.05, 0.5), (0.5, 0.01)] {
        let e = albedo(hc(Ndf::Ggx), a, mu, &s);
        println!("GGX E({mu},{a}) {:.9} se {:.2e}", e.value, e.std_error);
    }
}

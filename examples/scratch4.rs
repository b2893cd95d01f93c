use kiln::integrate::albedo::generic_loss;
use kiln::integrate::sobol::OwenSobol;
use kiln::model::*;
fn se(f: &dyn Fn(f64, f64) -> f64) -> (f64, f64) {
    let n = 1u32 << 15;
    let means: Vec<f64> = (0..8)
        .map(|r| {
            let seq = OwenSobol::new(1000 + r);
            (0..n)
                .map(|i| f(seq.sample(i, 0), seq.sample(i, 1)))
                .sum::<f64>()
                / n as f64
        })
        .collect();
    let m = means.iter().sum::<f64>() / 8.0;
    let v = means.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / 56.0;
    (m, v.sqrt())
}
fn main() {
    for &(alpha, mu) in &[(1.0, 0.5), (0.5, 0.5), (0.2, 0.8)] {
        let o = Vec3::from_mu(mu);
        let g = Ggx { alpha };
        let b = Beckmann { alpha };
        let hc = Masking::HeightCorrelated;
        println!("alpha {alpha} mu {mu}");
        println!(
            "  ggx generic        {:?}",
            se(&|u0, u1| generic_loss(g, hc, o, g.lambda(o), [u0, u1]))
        );
        println!(
            "  ggx generic folded {:?}",
            se(&|u0, u1| generic_loss(g, hc, o, g.lambda(o), [u0 / 2.0, u1]))
        );
        println!(
            "  beck               {:?}",
            se(&|u0, u1| generic_loss(b, hc, o, b.lambda(o), [u0, u1]))
        );
        println!(
            "  beck folded y      {:?}",
            se(&|u0, u1| generic_loss(b, hc, o, b.lambda(o), [u0, 0.5 + u1 / 2.0]))
        );
        println!(
            "  beck swapped       {:?}",
            se(&|u0, u1| generic_loss(b, hc, o, b.lambda(o), [u1, u0]))
        );
    }
}

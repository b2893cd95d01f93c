//! Coats (issue 61, part 2): the reflection-only albedo `E_reflection(mu, r, eta)` of a rough
//! dielectric interface and its average, over the IOR and at one IOR, against an integrator
//! written here from scratch (over the incident directions, with the exact unpolarised Fresnel
//! factor and GGX's `D` and height-correlated `G2` typed anew), a mirror's closed forms (`F(mu)`
//! and `F_avg`), and the refusals.

use crate::command;
use crate::common;

use kiln::table::Table;
use kiln::verify::input::read_kiln;
use std::f64::consts::PI;
use std::path::Path;

/// The exact unpolarised Fresnel reflectance of a dielectric of relative index `eta > 1` at
/// `cos = c` (Walter et al. 2007, eq. 22).
fn fresnel(eta: f64, c: f64) -> f64 {
    let g = (eta * eta - 1.0 + c * c).sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// `E_reflection(mu)` of GGX (height-correlated) at slope-space `alpha` and relative index
/// `eta > 1`, by composite Gauss-Legendre over the incident direction `(mu_i, phi_i)`:
/// `∫ F(i.h) D(h) G2(o, i) / (4 mu) dmu_i dphi_i` (the view in the plane `phi = 0`, the
/// integrand even in `phi_i`).
fn independent_reflection(alpha: f64, eta: f64, mu: f64) -> f64 {
    let a2 = alpha * alpha;
    let lambda = |z: f64| {
        let t2 = (1.0 - z * z).max(0.0) / (z * z);
        ((1.0 + a2 * t2).sqrt() - 1.0) / 2.0
    };
    let d = |z: f64| {
        let q = z * z * (a2 - 1.0) + 1.0;
        a2 / (PI * q * q)
    };
    let o = [(1.0 - mu * mu).sqrt(), 0.0, mu];
    let lambda_o = lambda(mu);
    let rule = common::gauss_legendre(8);
    let panels = 160;
    let mut total = 0.0;
    for p in 0..panels {
        let (lo, hi) = (p as f64 / panels as f64, (p + 1) as f64 / panels as f64);
        for &(x, w) in &rule {
            let mu_i = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
            let w_mu = 0.5 * (hi - lo) * w;
            let si = (1.0 - mu_i * mu_i).sqrt();
            let g2 = 1.0 / (1.0 + lambda_o + lambda(mu_i));
            for q in 0..panels {
                let width = PI / panels as f64;
                for &(y, v) in &rule {
                    let phi = (q as f64 + 0.5 * (1.0 + y)) * width;
                    let i = [si * phi.cos(), si * phi.sin(), mu_i];
                    let h = [o[0] + i[0], o[1] + i[1], o[2] + i[2]];
                    let n = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
                    let c = (i[0] * h[0] + i[1] * h[1] + i[2] * h[2]) / n;
                    total += w_mu * 0.5 * width * v * 2.0 * fresnel(eta, c) * d(h[2] / n) * g2;
                }
            }
        }
    }
    total / (4.0 * mu)
}

fn read(dir: &Path, stem: &str) -> Table {
    read_kiln(&dir.join(format!("{stem}.json")))
        .unwrap()
        .unwrap()
}

fn bake(dir: &Path, args: &[&str]) {
    let mut all = vec![
        "bake",
        "--format",
        "json",
        "-q",
        "--out",
        dir.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    command::succeeded(&all);
}

/// The tables at one IOR (glTF's clearcoat: 1.5, `F0 = 0.04`) and over the IOR hold the
/// independent integral at their nodes (within 2e-6, where the independent rule resolves the
/// lobe: `alpha >= 0.06` at one IOR, `alpha` and `mu` from 0.1 over the IOR), the mirror row holds `F(mu)`, and the averages' mirror row
/// `F_avg(eta)` (closed form, 0.0917779593 at 1.5).
#[test]
fn the_reflection_is_the_independent_integral() {
    let dir = tempfile::tempdir().unwrap();
    bake(
        dir.path(),
        &[
            "--quantity",
            "e-reflection,e-avg-reflection",
            "--ior",
            "1.5",
            "--size",
            "6",
        ],
    );
    let one = read(dir.path(), "ggx-height-correlated-E_reflection-ior-1.5");
    let average = read(dir.path(), "ggx-height-correlated-E_avg_reflection-ior-1.5");
    assert_eq!(one.spec.shape(), [6, 6]);
    let mut checked = 0;
    for index in 0..one.value.len() {
        let (alpha, mu, _) = one.spec.texel_point(index);
        let mu = mu.unwrap();
        if alpha < 1e-6 {
            // The mirror row (computed at alpha = 1e-7): F(mu) itself wherever mu >> alpha
            // (masking there is 1 - O((alpha / mu)^2)).
            if mu >= 1e-3 {
                assert!(
                    (one.value[index] - fresnel(1.5, mu)).abs() < 1e-7,
                    "mirror texel {index} at mu {mu}: {} vs {}",
                    one.value[index],
                    fresnel(1.5, mu)
                );
                checked += 1;
            }
            continue;
        }
        if alpha < 0.06 || mu < 0.05 {
            continue;
        }
        let want = independent_reflection(alpha, 1.5, mu);
        assert!(
            (one.value[index] - want).abs() < 2e-6,
            "texel {index} (alpha {alpha}, mu {mu}): {} vs {want}",
            one.value[index]
        );
        checked += 1;
    }
    assert!(checked >= 15, "{checked}");
    // The average's mirror row: F_avg(1.5).
    assert!(
        (average.value[0] - 0.091_777_959_3).abs() < 1e-9,
        "{}",
        average.value[0]
    );
    // The average's rough rows, as point samples: 2 ∫ E mu dmu of the independent integral, by
    // Gauss-Legendre over mu in four panels (the grazing views weigh little).
    let nodes = tempfile::tempdir().unwrap();
    bake(
        nodes.path(),
        &[
            "--quantity",
            "e-avg-reflection",
            "--ior",
            "1.5",
            "--size",
            "4",
            "--texels",
            "nodes",
        ],
    );
    let average = read(
        nodes.path(),
        "ggx-height-correlated-E_avg_reflection-ior-1.5-nodes",
    );
    let rule = common::gauss_legendre(8);
    for index in 1..4 {
        let (alpha, _, _) = average.spec.texel_point(index);
        let mut want = 0.0;
        for p in 0..4 {
            let (lo, hi) = (f64::from(p) / 4.0, f64::from(p + 1) / 4.0);
            for &(x, w) in &rule {
                let mu = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
                want += 0.5 * (hi - lo) * w * 2.0 * mu * independent_reflection(alpha, 1.5, mu);
            }
        }
        assert!(
            (average.value[index] - want).abs() < 1e-5,
            "E_avg_reflection at alpha {alpha}: {} vs {want}",
            average.value[index]
        );
    }

    // Over the IOR: a node at another index.
    let over = tempfile::tempdir().unwrap();
    bake(
        over.path(),
        &[
            "--quantity",
            "e-reflection",
            "--size",
            "5",
            "--ior-size",
            "4",
            "--max-error",
            "1e-6",
        ],
    );
    let table = read(over.path(), "ggx-height-correlated-E_reflection");
    assert_eq!(table.spec.shape(), [4, 5, 5]);
    let mut checked = 0;
    for index in 0..table.value.len() {
        let (alpha, mu, eta) = table.spec.texel_point(index);
        let (mu, eta) = (mu.unwrap(), eta.unwrap());
        if alpha < 0.1 || mu < 0.1 || eta <= 1.0 {
            continue;
        }
        let want = independent_reflection(alpha, eta, mu);
        assert!(
            (table.value[index] - want).abs() < 2e-6,
            "texel {index} (alpha {alpha}, mu {mu}, eta {eta}): {} vs {want}",
            table.value[index]
        );
        checked += 1;
    }
    assert!(checked >= 12, "{checked}");
}

/// A transmission convention, an index of 1 and the coat's tables from inside have no meaning
/// for a coat's reflection: refused with the reason, nothing written.
#[test]
fn a_coat_refuses_what_it_is_not() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    command::refused(
        &[
            "bake",
            "--quantity",
            "e-reflection",
            "--transmission",
            "cycles",
            "--out",
            out,
        ],
        &["transmission"],
    );
    command::refused(
        &[
            "bake",
            "--quantity",
            "e-reflection",
            "--ior",
            "1",
            "--out",
            out,
        ],
        &["no interface"],
    );
    assert!(!dir.path().join("out").exists());
}

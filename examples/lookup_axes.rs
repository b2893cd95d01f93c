//! Which axes let a fitted 32 x 32 `E` table's bilinear lookup come closest to the truth: for a
//! candidate pair of axis warps, the texels are fitted in the maximum norm (Lawson, as
//! `--texels lookup-fit` does) against the reference at a dense set of points that does not
//! depend on the candidate, and the largest error is printed with where it is.
//!
//! The truth: GGX height-correlated `E` at 1e-9 on 545 roughness rows (`r = k / 512` and 32
//! rows from 1e-3 to 0.06), each at 259 uniform `mu` and 257 points of kiln's adaptive axis
//! (which resolve the grazing layer at every roughness), cached in `/tmp/kiln-lookup-truth.bin`
//! (about a minute on 2 cores to build).
//!
//! Candidates, as `key=value` (defaults: kiln's axes): `n=32` samples per axis (nodes grid);
//! the `mu` coordinate `t = (1 - b') A(mu; c alpha, p) + b' mu`, `b' = 4 b alpha (1 - alpha)`, `A(y; k, p) = (y (1 + k) / (y +
//! k))^p` (`c=4 p=0.4 b=0`); the roughness coordinate `t_r = (1 - h) r + h r^g - s sin(2 pi r) / (2 pi)` (`h=0 g=1 s=0`; with `d > 0`, `r^g` is `((r^2 + d^2)^(g/2) - d^g) / ((1 + d^2)^(g/2) - d^g)`, like `alpha` below `r ~ d`), then blended with a smoothstep, `(1 - m) t_r + m r^2 (3 - 2 r)` (`m=0`);
//! `e=0` a slope in `k = c alpha (1 + e alpha)`, `q=0` a slope of the power `p + q alpha`;
//! `z=0` an offset that makes `t` linear in `mu` at grazing, `t = ((u + z') ^ p - z'^p) / ((1 +
//! z')^p - z'^p)` with `u = A(mu; k, 1)` and `z' = (z / 32) (32 / n)^w exp(-y alpha)` (`y=1`, `w=1`);
//! `cap=30` the fit's weight cap (`inf` for the pure minimax).
//!
//! Usage: `cargo run --release --example lookup_axes -- [key=value ...]`
use kiln::integrate::reference::{ReferenceSettings, reference_albedo};
use kiln::model::{Masking, Model, Ndf};
use kiln::numerics::minimax::{Lawson, dot, lawson};
use rayon::prelude::*;
use std::io::{Read, Write};

const TRUTH: &str = "/tmp/kiln-lookup-truth.bin";

fn adaptive(mu: f64, k: f64, p: f64, offset: f64) -> f64 {
    if mu <= 0.0 {
        0.0
    } else if k <= 0.0 {
        1.0
    } else {
        let u = (mu * (1.0 + k) / (mu + k)).min(1.0);
        ((u + offset).powf(p) - offset.powf(p)) / ((1.0 + offset).powf(p) - offset.powf(p))
    }
}

fn truth() -> Vec<[f64; 3]> {
    if let Ok(mut file) = std::fs::File::open(TRUTH) {
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).unwrap();
        return bytes
            .chunks_exact(24)
            .map(|c| {
                let f = |i: usize| f64::from_le_bytes(c[8 * i..8 * i + 8].try_into().unwrap());
                [f(0), f(1), f(2)]
            })
            .collect();
    }
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let settings = ReferenceSettings {
        tolerance: 1e-9,
        ..ReferenceSettings::default()
    };
    let mut rows: Vec<f64> = (0..=512).map(|k| k as f64 / 512.0).collect();
    rows.extend((0..32).map(|k| 1e-3 * 60f64.powf(k as f64 / 31.0)));
    let mut points = Vec::new();
    for &r in &rows {
        let alpha = r * r;
        let mut mus: Vec<f64> = (0..=256).map(|k| k as f64 / 256.0).collect();
        mus.extend([1e-6, 1e-4]);
        mus.extend((0..=256).map(|k| {
            let t: f64 = k as f64 / 256.0;
            kiln::integrate::grazing::mu_of_t(t, alpha)
        }));
        for mu in mus {
            points.push((r, mu));
        }
    }
    let values: Vec<[f64; 3]> = points
        .par_iter()
        .map(|&(r, mu)| {
            let e = if r == 0.0 {
                1.0
            } else {
                reference_albedo(model, r * r, mu, &settings).value
            };
            [r, mu, e]
        })
        .collect();
    let mut file = std::fs::File::create(TRUTH).unwrap();
    for v in &values {
        for x in v {
            file.write_all(&x.to_le_bytes()).unwrap();
        }
    }
    values
}

fn main() {
    let mut p = std::collections::BTreeMap::from([
        ("n", 32.0),
        ("c", 4.0),
        ("p", 0.4),
        ("b", 0.0),
        ("h", 0.0),
        ("s", 0.0),
        ("m", 0.0),
        ("d", 0.0),
        ("g", 1.0),
        ("e", 0.0),
        ("q", 0.0),
        ("z", 0.0),
        ("y", 1.0),
        ("w", 1.0),
        ("cap", 30.0),
        ("iters", 60.0),
    ]);
    for arg in std::env::args().skip(1) {
        let (k, v) = arg.split_once('=').expect("key=value");
        let key = *p.keys().find(|&&key| key == k).expect("a known key");
        p.insert(key, v.parse().expect("a number"));
    }
    let truth = truth();
    let n = p["n"] as usize;
    let (c, pw, b, h, g, s) = (p["c"], p["p"], p["b"], p["h"], p["g"], p["s"]);
    let (m, d) = (p["m"], p["d"]);
    let (e, q, z, y, w) = (p["e"], p["q"], p["z"], p["y"], p["w"]);
    let weights = |r: f64, mu: f64| -> Vec<(usize, f64)> {
        let alpha = r * r;
        let blend = b * 4.0 * alpha * (1.0 - alpha).max(0.0);
        let t_mu = (1.0 - blend)
            * adaptive(
                mu,
                c * alpha * (1.0 + e * alpha),
                pw + q * alpha,
                z / 32.0 * (32.0 / n as f64).powf(w) * (-y * alpha).exp(),
            )
            + blend * mu;
        let power = if d > 0.0 {
            ((r * r + d * d).powf(g / 2.0) - d.powf(g)) / ((1.0 + d * d).powf(g / 2.0) - d.powf(g))
        } else {
            r.powf(g)
        };
        let t_r = (1.0 - h) * r + h * power
            - s * (std::f64::consts::TAU * r).sin() / std::f64::consts::TAU;
        let t_r = (1.0 - m) * t_r + m * r * r * (3.0 - 2.0 * r);
        let pos = |t: f64| {
            let x = (t * (n - 1) as f64).clamp(0.0, (n - 1) as f64);
            let i = (x.floor() as usize).min(n - 2);
            (i, x - i as f64)
        };
        let (i, fi) = pos(t_r);
        let (j, fj) = pos(t_mu);
        vec![
            (i * n + j, (1.0 - fi) * (1.0 - fj)),
            (i * n + j + 1, (1.0 - fi) * fj),
            ((i + 1) * n + j, fi * (1.0 - fj)),
            ((i + 1) * n + j + 1, fi * fj),
        ]
    };
    let rows: Vec<Vec<(usize, f64)>> = truth.iter().map(|v| weights(v[0], v[1])).collect();
    let b_values: Vec<f64> = truth.iter().map(|v| v[2]).collect();
    let texels = lawson(
        &rows,
        &b_values,
        n * n,
        &Lawson {
            iterations: p["iters"] as usize,
            weight_cap: p["cap"],
            regularisation: 1e-12,
        },
    );
    let errors: Vec<f64> = rows
        .iter()
        .zip(&b_values)
        .map(|(row, &e)| (dot(row, &texels) - e).abs())
        .collect();
    let (worst, max) =
        errors.iter().enumerate().fold(
            (0, 0.0),
            |(wi, wm), (i, &e)| if e > wm { (i, e) } else { (wi, wm) },
        );
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    let mut sorted = errors.clone();
    sorted.sort_by(f64::total_cmp);
    let p99 = sorted[sorted.len() * 99 / 100];
    if std::env::var_os("MAP").is_some() {
        // The largest error per roughness decile (rows) and mu band (columns).
        let bands = [0.0, 1e-3, 1e-2, 0.1, 0.5, 0.8, 1.0];
        let mut map = [[0.0f64; 6]; 10];
        for (v, &err) in truth.iter().zip(&errors) {
            let row = ((v[0] * 10.0) as usize).min(9);
            let col = bands[1..].iter().position(|&b| v[1] <= b).unwrap_or(5);
            map[row][col] = map[row][col].max(err);
        }
        println!("r \\ mu   <=1e-3   <=1e-2   <=0.1    <=0.5    <=0.8    <=1");
        for (row, m) in map.iter().enumerate() {
            let cells: Vec<String> = m.iter().map(|e| format!("{e:.2e}")).collect();
            println!(
                "{:.1}-{:.1}  {}",
                row as f64 / 10.0,
                (row + 1) as f64 / 10.0,
                cells.join(" ")
            );
        }
    }
    let args: Vec<String> = p.iter().map(|(k, v)| format!("{k}={v}")).collect();
    println!(
        "{}: max {max:.3e} at r {:.4} mu {:.4}, p99 {p99:.3e}, rms {rms:.3e} ({} points)",
        args.join(" "),
        truth[worst][0],
        truth[worst][1],
        truth.len()
    );
}

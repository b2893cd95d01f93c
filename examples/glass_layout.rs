//! Issue 38's measurement harness: the white-furnace error `max |E_true / E_lookup - 1|` of
//! candidate glass layouts, per eta band, for the 16^3 (or any N^3) `E_dielectric` table of
//! light from outside (`out`) or inside (`in`), GGX height-correlated, on nodes grids, IOR axis
//! up to 3, built from the reference at 1e-9 and audited at every IOR node and halfway between
//! (in the IOR coordinate of Cycles' axis), every roughness node and halfway, and `mu` at 0,
//! 1e-12, 1e-6 to 1 in 24 log steps and every 1/64 (the truth is cached in the temporary
//! directory, `kiln-glass-truth-{out,in}.bin`, so a second design costs only its table).
//!
//! A candidate's `mu` coordinate is `t = w A(mu; kappa, p_e) + (1 - w) A(mu; 4 alpha, 0.4)`,
//! `A(mu; k, p) = (mu (1 + k) / (mu + k))^p` (kiln's adaptive axis is `w = 0`), with the eta
//! layer's width `kappa = c_e (eta - 1) / (alpha + s sqrt(eta - 1))`; a negative `w` splits
//! instead at the critical angle `mu_c = sqrt(1 - 1 / eta^2)` of light from inside, at
//! `t_c = -w` (`A(mu / mu_c; c_e alpha / mu_c, p_e)` below, `((mu - mu_c) / (1 - mu_c))^s`
//! above). The IOR coordinate is `z = b A(x; c_z alpha^2, q) + (1 - b) x^q`, `x = ((eta - 1) /
//! (eta + 1)) / (1 / 2)`, (Cycles' axis is `q = 1/2`, `c_z = 0`). The `eta = 1` slice holds the
//! limit `eta -> 1+` at fixed coordinates (computed at `eta = 1 + 1e-7`).
//!
//! Usage: `cargo run --release --example glass_layout -- N out|in q w c_e p_e s [c_z [b]]`;
//! `... -- 16 out 0.5 0 0 1 0` is Cycles' product grid with kiln's adaptive `mu` axis (the
//! default layout today). `AUDIT_M=M` audits on `M` steps per axis instead of `2 (N - 1)`.
use kiln::integrate::dielectric::reference_dielectric_albedo;
use kiln::integrate::reference::ReferenceSettings;
use kiln::model::{Masking, Model, Ndf};
use rayon::prelude::*;
use std::collections::HashMap;
use std::io::Write;

const ETA_MAX: f64 = 3.0;
const EPS_LIMIT: f64 = 1e-7;

#[derive(Clone, Copy, Debug)]
struct Design {
    inside: bool,
    q: f64,  // IOR warp: z = (u / u_max)^q, u = (eta-1)/(eta+1)
    w: f64,  // share of t for the eta layer (0: current adaptive)
    ce: f64, // eta layer scale constant
    pe: f64, // eta layer power
    cz: f64,
    bz: f64,
    sq: f64, // weight of sqrt(eps) in kappa = ce * eps / (alpha + sq*sqrt(eps))
}

fn u(eta: f64) -> f64 {
    (eta - 1.0) / (eta + 1.0)
}
fn eta_of_z(d: &Design, z: f64, alpha: f64) -> f64 {
    let x = if d.cz > 0.0 {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..100 {
            let m = 0.5 * (lo + hi);
            if zx(d, m, alpha) < z { lo = m } else { hi = m }
        }
        0.5 * (lo + hi)
    } else {
        z.powf(1.0 / d.q)
    };
    let uu = x * u(ETA_MAX);
    (1.0 + uu) / (1.0 - uu)
}
fn zx(d: &Design, x: f64, alpha: f64) -> f64 {
    if d.cz > 0.0 {
        d.bz * a(x, d.cz * alpha * alpha, d.q) + (1.0 - d.bz) * x.powf(d.q)
    } else {
        x.powf(d.q)
    }
}
fn z_of_eta(d: &Design, eta: f64, alpha: f64) -> f64 {
    zx(d, u(eta) / u(ETA_MAX), alpha)
}

fn a(mu: f64, k: f64, p: f64) -> f64 {
    if mu <= 0.0 {
        return 0.0;
    }
    if k <= 0.0 {
        return 1.0;
    }
    (mu * (1.0 + k) / (mu + k)).min(1.0).powf(p)
}
fn kappa(d: &Design, alpha: f64, eta_up: f64) -> f64 {
    let e = eta_up - 1.0;
    d.ce * e / (alpha + d.sq * e.sqrt()).max(1e-300)
}
fn t_of_mu(d: &Design, mu: f64, alpha: f64, eta_up: f64) -> f64 {
    if d.w < 0.0 {
        // Critical-angle split: t_c = -w; lower piece adaptive in mu / mu_c, upper sqrt onset.
        let tc = -d.w;
        let muc = (1.0 - 1.0 / (eta_up * eta_up)).max(0.0).sqrt();
        if mu <= muc {
            return tc * a(mu / muc.max(1e-300), d.ce * alpha / muc.max(1e-300), d.pe);
        }
        let x = ((mu - muc) / (1.0 - muc)).min(1.0);
        return tc + (1.0 - tc) * x.powf(d.sq);
    }
    let base = a(mu, 4.0 * alpha, 0.4);
    if d.w == 0.0 {
        return base;
    }
    d.w * a(mu, kappa(d, alpha, eta_up), d.pe) + (1.0 - d.w) * base
}
fn mu_of_t(d: &Design, t: f64, alpha: f64, eta_up: f64) -> f64 {
    if t <= 0.0 {
        return 0.0;
    }
    if t >= 1.0 {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..200 {
        let mid = if hi / lo.max(1e-300) > 4.0 && lo > 0.0 {
            (lo * hi).sqrt()
        } else if lo == 0.0 {
            hi * 1e-3
        } else {
            0.5 * (lo + hi)
        };
        if t_of_mu(d, mid, alpha, eta_up) < t {
            lo = mid
        } else {
            hi = mid
        }
        if hi - lo < 1e-15 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

fn truth(alpha: f64, mu: f64, eta_rel: f64) -> f64 {
    let model = Model {
        ndf: Ndf::Ggx,
        masking: Masking::HeightCorrelated,
    };
    let s = ReferenceSettings {
        tolerance: 1e-9,
        ..Default::default()
    };
    reference_dielectric_albedo(model, alpha, mu, eta_rel, &s).value()
}
fn rel(d: &Design, eta_up: f64) -> f64 {
    if d.inside { 1.0 / eta_up } else { eta_up }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args[0].parse().unwrap();
    let f = |i: usize| args[i].parse::<f64>().unwrap();
    let d = Design {
        inside: args[1] == "in",
        q: f(2),
        w: f(3),
        ce: f(4),
        pe: f(5),
        sq: f(6),
        cz: args.get(7).map_or(0.0, |a| a.parse().unwrap()),
        bz: args.get(8).map_or(1.0, |a| a.parse().unwrap()),
    };
    // Table.
    let nodes: Vec<(usize, usize, usize)> = (0..n)
        .flat_map(|k| (0..n).flat_map(move |i| (0..n).map(move |j| (k, i, j))))
        .collect();
    let table: Vec<f64> = nodes
        .par_iter()
        .map(|&(k, i, j)| {
            let z = k as f64 / (n - 1) as f64;
            let r = i as f64 / (n - 1) as f64;
            let t = j as f64 / (n - 1) as f64;
            let alpha = if i == 0 { 1e-7 } else { r * r };
            let eta_up = if k == 0 {
                1.0 + EPS_LIMIT
            } else {
                eta_of_z(&d, z, alpha)
            };
            let mu = mu_of_t(&d, t, alpha, eta_up);
            truth(alpha, mu, rel(&d, eta_up))
        })
        .collect();
    let lookup = |mu: f64, r: f64, eta_up: f64| {
        let alpha = r * r;
        let pos = |x: f64| (x * (n - 1) as f64).clamp(0.0, (n - 1) as f64);
        let (pz, pr, pt) = (
            pos(z_of_eta(&d, eta_up, alpha)),
            pos(r),
            pos(t_of_mu(&d, mu, alpha, eta_up)),
        );
        let idx = |p: f64| {
            let k = (p as usize).min(n - 2);
            (k, p - k as f64)
        };
        let ((k, hz), (i, hr), (j, ht)) = (idx(pz), idx(pr), idx(pt));
        let mut v = 0.0;
        for (dk, wk) in [(0, 1.0 - hz), (1, hz)] {
            for (di, wi) in [(0, 1.0 - hr), (1, hr)] {
                for (dj, wj) in [(0, 1.0 - ht), (1, ht)] {
                    v += wk * wi * wj * table[((k + dk) * n + i + di) * n + j + dj];
                }
            }
        }
        v
    };
    // Audit points: eta at nodes and halfway in z; r at nodes and halfway; mu fixed set.
    let m = std::env::var("AUDIT_M").map_or(2 * (n - 1), |v| v.parse().unwrap());
    let d0 = Design {
        cz: 0.0,
        q: 0.5,
        ..d
    };
    let mut etas: Vec<f64> = (1..=m)
        .map(|k| eta_of_z(&d0, k as f64 / m as f64, 1.0))
        .collect();
    etas.insert(0, 1.0 + 1e-6);
    let rs: Vec<f64> = (0..=m).map(|i| i as f64 / m as f64).collect();
    let mut mus = vec![0.0, 1e-12];
    mus.extend((0..=24).map(|k| 10f64.powf(-6.0 + k as f64 / 4.0)));
    mus.extend((1..=64).map(|k| k as f64 / 64.0));
    // Cache of truth values.
    let path = std::env::temp_dir().join(format!(
        "kiln-glass-truth-{}.bin",
        if d.inside { "in" } else { "out" }
    ));
    let mut cache: HashMap<(u64, u64, u64), f64> = HashMap::new();
    if let Ok(bytes) = std::fs::read(&path) {
        for c in bytes.chunks_exact(32) {
            let g = |o: usize| u64::from_le_bytes(c[o..o + 8].try_into().unwrap());
            cache.insert((g(0), g(8), g(16)), f64::from_bits(g(24)));
        }
    }
    let mut pts: Vec<(f64, f64, f64)> = Vec::new();
    for &e in &etas {
        for &r in &rs {
            for &mu in &mus {
                pts.push((e, r, mu));
            }
        }
    }
    let missing: Vec<(f64, f64, f64)> = pts
        .iter()
        .copied()
        .filter(|&(e, r, mu)| !cache.contains_key(&(e.to_bits(), r.to_bits(), mu.to_bits())))
        .collect();
    eprintln!("{} points, {} to compute", pts.len(), missing.len());
    let computed: Vec<f64> = missing
        .par_iter()
        .map(|&(e, r, mu)| truth(r * r, mu, rel(&d, e)))
        .collect();
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .unwrap();
    for (&(e, r, mu), &v) in missing.iter().zip(&computed) {
        cache.insert((e.to_bits(), r.to_bits(), mu.to_bits()), v);
        for x in [e.to_bits(), r.to_bits(), mu.to_bits(), v.to_bits()] {
            file.write_all(&x.to_le_bytes()).unwrap();
        }
    }
    let bands = [1.0, 1.01, 1.05, 1.2, 1.5, 2.0, 3.0001];
    let mut worst = vec![(0.0f64, 0.0, 0.0, 0.0); bands.len() - 1];
    for &(e, r, mu) in &pts {
        let tv = cache[&(e.to_bits(), r.to_bits(), mu.to_bits())];
        let lv = lookup(mu, r, e);
        let dev = (tv / lv - 1.0).abs();
        let b = bands.iter().position(|&b| e < b).unwrap() - 1;
        if dev.is_nan() || dev > worst[b].0 {
            worst[b] = (dev, e, r, mu);
        }
    }
    for (b, w) in worst.iter().enumerate() {
        println!(
            "{:.2}-{:.2}: {:.2e} at eta {:.7} r {:.3} mu {:.2e}",
            bands[b],
            bands[b + 1],
            w.0,
            w.1,
            w.2,
            w.3
        );
    }
}

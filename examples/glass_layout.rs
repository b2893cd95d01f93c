//! Issue 38's measurement harness: the white-furnace error `max |E_true / E_lookup - 1|` of
//! candidate glass layouts ([`GlassLayout`], kiln's is `GlassLayout::KILN`), per eta band, for
//! the N^3 `E_dielectric` table of light from outside (`out`) or inside (`in`), GGX
//! height-correlated, on nodes grids, IOR axis up to 3. The table is built as `kiln bake` builds
//! one in the glass layout (`TableSpec::texel_point`: the row `alpha = 0` at `ROW_LIMIT_ALPHA`,
//! the slice `eta = 1` at `eta = 1` above the eta layer and at `limit_slice_eta` inside it), from
//! the reference at 1e-9, and audited at a fixed set of points for every
//! candidate: `eta` at `1 + 1e-6` and 30 steps of Cycles' `z` (IOR nodes of a 16-texel axis and
//! halfway between), `r` in 30 steps, and `mu` at 0, 1e-12, 1e-6 to 1 in 24 log steps and every
//! 1/64 (the truth is cached in the temporary directory, `kiln-glass-truth-{out,in}.bin`, so a
//! second design costs only its table).
//!
//! Usage: `cargo run --release --example glass_layout -- N out|in [key=value ...]` with the keys
//! of [`GlassLayout`]'s fields: `w` (layer_share), `d` (layer_share_decay), `ce` (layer_scale),
//! `s` (layer_sqrt_weight), `pe` (layer_power), `q` (ior_power), `cz` (ior_scale), `b`
//! (ior_share); unnamed fields keep kiln's values. `... -- 16 out` measures kiln's layout.
//! `AUDIT_M=M` audits on `M` steps per axis instead of 30; `LIMIT_OFFSET=X` computes the eta
//! layer's texels of the `eta = 1` slice at `eta - 1 = X alpha^2` instead of kiln's offset.
use kiln::integrate::dielectric::reference_dielectric_albedo;
use kiln::integrate::reference::ReferenceSettings;
use kiln::model::{Masking, Model, Ndf};
use kiln::table::glass_layout::{GlassLayout, ROW_LIMIT_ALPHA};
use rayon::prelude::*;
use std::collections::HashMap;
use std::io::Write;

const ETA_MAX: f64 = 3.0;

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

/// Cycles' `eta` at its `z` coordinate `t` (the fixed audit ladder).
fn cycles_eta(t: f64) -> f64 {
    let u = t.powf(2.0) * ((ETA_MAX - 1.0) / (ETA_MAX + 1.0));
    (1.0 + u) / (1.0 - u)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args[0].parse().unwrap();
    let inside = args[1] == "in";
    let mut layout = GlassLayout::KILN;
    for pair in &args[2..] {
        let (key, value) = pair.split_once('=').expect("key=value");
        let value: f64 = value.parse().unwrap();
        match key {
            "w" => layout.layer_share = value,
            "d" => layout.layer_share_decay = value,
            "ce" => layout.layer_scale = value,
            "s" => layout.layer_sqrt_weight = value,
            "pe" => layout.layer_power = value,
            "q" => layout.ior_power = value,
            "cz" => layout.ior_scale = value,
            "b" => layout.ior_share = value,
            _ => panic!("unknown key {key}"),
        }
    }
    // LIMIT_OFFSET=X computes the eta layer's texels of the eta = 1 slice at eta - 1 = X alpha^2.
    let limit_offset: Option<f64> = std::env::var("LIMIT_OFFSET")
        .ok()
        .map(|v| v.parse().unwrap());
    let rel = |eta_up: f64| if inside { 1.0 / eta_up } else { eta_up };
    // Table, as kiln bakes one in a glass layout.
    let nodes: Vec<(usize, usize, usize)> = (0..n)
        .flat_map(|k| (0..n).flat_map(move |i| (0..n).map(move |j| (k, i, j))))
        .collect();
    let table: Vec<f64> = nodes
        .par_iter()
        .map(|&(k, i, j)| {
            let z = k as f64 / (n - 1) as f64;
            let r = i as f64 / (n - 1) as f64;
            let t = j as f64 / (n - 1) as f64;
            let alpha = if i == 0 { ROW_LIMIT_ALPHA } else { r * r };
            let eta = layout.ior_at(z, ETA_MAX, alpha);
            // The eta = 1 slice where `TableSpec::texel_point` puts it (LIMIT_OFFSET moves the
            // eta layer's texels).
            let (alpha, eta_up) = if eta > 1.0 {
                (alpha, eta)
            } else {
                match layout.limit_slice_point(t, alpha) {
                    (alpha, eta_up) if eta_up > 1.0 => (
                        alpha,
                        limit_offset.map_or(eta_up, |o| 1.0 + o * alpha * alpha),
                    ),
                    point => point,
                }
            };
            if i == 0 && t >= 1.0 {
                return truth(0.0, 1.0, rel(eta_up));
            }
            let mu = layout.mu_at(t, alpha, eta_up);
            truth(alpha, mu, rel(eta_up))
        })
        .collect();
    let lookup = |mu: f64, r: f64, eta_up: f64| {
        let alpha = r * r;
        let pos = |x: f64| (x * (n - 1) as f64).clamp(0.0, (n - 1) as f64);
        let (pz, pr, pt) = (
            pos(layout.ior_coordinate(eta_up, ETA_MAX, alpha)),
            pos(r),
            pos(layout.mu_coordinate(mu, alpha, eta_up)),
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
    let m = std::env::var("AUDIT_M").map_or(30, |v| v.parse().unwrap());
    let mut etas: Vec<f64> = (1..=m).map(|k| cycles_eta(k as f64 / m as f64)).collect();
    etas.insert(0, 1.0 + 1e-6);
    let rs: Vec<f64> = (0..=m).map(|i| i as f64 / m as f64).collect();
    let mut mus = vec![0.0, 1e-12];
    mus.extend((0..=24).map(|k| 10f64.powf(-6.0 + k as f64 / 4.0)));
    mus.extend((1..=64).map(|k| k as f64 / 64.0));
    // Cache of truth values.
    let path = std::env::temp_dir().join(format!(
        "kiln-glass-truth-{}.bin",
        if inside { "in" } else { "out" }
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
        .map(|&(e, r, mu)| truth(r * r, mu, rel(e)))
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

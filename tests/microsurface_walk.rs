//! The microsurface random walk (`kiln::integrate::walk`) against what is known independently
//! of it: GGX at `alpha = 1`, where the walk is a one-dimensional chain in (cosine, depth)
//! written here from scratch (after a bounce the travel cosine is uniform on `(w_z, 1]`:
//! `docs/multiple-scattering.md`), with its closed-form first order; kiln's deterministic
//! reference `E` for the first order at other roughness; the visible-normal density below the
//! horizon by quadrature; and the walk's own promises (height distributions, thread counts).

#[cfg(feature = "cli")]
use crate::compensation_bake;
use crate::rng;
#[cfg(feature = "cli")]
use crate::rustc;

use kiln::integrate::dielectric::reference_dielectric_albedo;
use kiln::integrate::reference::{ReferenceSettings, reference_albedo};
use kiln::integrate::walk::dielectric::{REFLECTED, TRANSMITTED};
use kiln::integrate::walk::lobe::LobeGrid;
use kiln::integrate::walk::{
    DielectricEstimate, Heights, LobeEstimate, View, WalkEstimate, WalkSettings, walk_albedo,
    walk_dielectric, walk_lobe, walk_schlick_polynomial,
};
use kiln::model::{Beckmann, Ggx, Masking, MicrofacetDistribution, Model, Ndf, Vec3};
use kiln::{Fresnel, model::fresnel::Rgb};
use std::f64::consts::PI;

const GGX: Model = Model {
    ndf: Ndf::Ggx,
    masking: Masking::HeightCorrelated,
};

/// Beckmann's walk: the sampler below the horizon of `kiln::model::ndf::VisibleSlopeX`.
const BECKMANN: Model = Model {
    ndf: Ndf::Beckmann,
    masking: Masking::HeightCorrelated,
};

fn walk(alpha: f64, mu: f64, fresnel: Fresnel, orders: usize, walks: u64) -> WalkEstimate {
    let settings = WalkSettings {
        walks,
        ..WalkSettings::default()
    };
    walk_albedo(GGX, alpha, mu, &fresnel, orders, &settings, &|_| {}).unwrap()
}

fn schlick(f0: f64, f90: f64) -> Fresnel {
    Fresnel::Schlick {
        f0: [f0; 3],
        f90: [f90; 3],
    }
}

/// `E(mu) = 1 - mu ln(1 + 1 / mu)` at `alpha = 1` (`docs/physics.md`).
fn e_alpha_one(mu: f64) -> f64 {
    1.0 - mu * (1.0 + 1.0 / mu).ln()
}

/// One walk of the chain at `alpha = 1`, written without vectors, visible normals or
/// reflections: `D = 1 / pi`, so the visible normal of `v` and the reflection about it send
/// the ray to a direction uniform on the sphere's cap above the plane `z = w_z` (the half
/// vector of `v` and a point `p` of that cap reflects `v` onto `p`). `Lambda(c) = (1 / c - 1) /
/// 2`. State: the travel cosine and the optical depth `tau = -ln C1`. Schlick's `F` at the
/// facet's cosine `v.m = sqrt((1 + v.p) / 2)`, with `p`'s azimuth uniform about `z`. Adds
/// `e_k` to `orders` and the coloured albedo to `albedo`; and to `lobe[j]` the BRDF of the
/// second and later orders at the exit cosine `exits[j]` (any azimuth: the cap is uniform), by
/// next-event estimation: from each vertex the ray leaves towards a point of the cap with
/// density `1 / (2 pi (1 - w_z))` and escapes from its depth with `exp(-Lambda tau)`.
fn chain(
    mu: f64,
    f0: f64,
    rng: &mut rng::Rng,
    orders: &mut [f64],
    albedo: &mut f64,
    (exits, lobe): (&[f64], &mut [f64]),
) {
    let uniform = |rng: &mut rng::Rng| ((rng.next() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let lambda = |c: f64| (1.0 / c - 1.0) / 2.0;
    let mut c = -mu;
    let mut tau = -uniform(rng).ln() / (1.0 + lambda(mu));
    let (mut plain, mut coloured) = (1.0, 1.0);
    for k in 0..10_000 {
        if k >= 1 {
            for (sum, &exit) in lobe.iter_mut().zip(exits) {
                if exit > c {
                    // Schlick's F at the facet that sends v to the exit, at an azimuth drawn
                    // about v (the average over the exit's azimuth).
                    let psi = 2.0 * PI * uniform(rng);
                    let v_dot_o = -c * exit
                        + ((1.0 - c * c) * (1.0 - exit * exit)).max(0.0).sqrt() * psi.cos();
                    let cosine = ((1.0 + v_dot_o) / 2.0).max(0.0).sqrt();
                    let fresnel = f0 + (1.0 - f0) * (1.0 - cosine).powi(5);
                    *sum += coloured * fresnel * (-lambda(exit) * tau).exp()
                        / (2.0 * PI * (1.0 - c) * exit);
                }
            }
        }
        let z = c + (1.0 - c) * uniform(rng);
        let phi = 2.0 * PI * uniform(rng);
        // v = -w: v_z = -c; v.p = v_z z + |v_xy| |p_xy| cos(phi).
        let v_dot_p = -c * z + ((1.0 - c * c) * (1.0 - z * z)).max(0.0).sqrt() * phi.cos();
        let cosine = ((1.0 + v_dot_p) / 2.0).max(0.0).sqrt();
        coloured *= f0 + (1.0 - f0) * (1.0 - cosine).powi(5);
        if z > 0.0 {
            let l = lambda(z);
            let escape = (-l * tau).exp();
            if k < orders.len() {
                orders[k] += plain * escape;
            }
            *albedo += coloured * escape;
            plain *= 1.0 - escape;
            coloured *= 1.0 - escape;
            // The free path up, given that it stays below the top: truncated exponential.
            tau += (1.0 - uniform(rng) * (1.0 - escape)).ln() / l;
        } else {
            tau += -uniform(rng).ln() / (1.0 + lambda(-z));
        }
        c = z;
        if plain < 1e-14 {
            return;
        }
    }
}

/// The mean of batch means and its standard error (written here, not kiln's estimator).
fn batch_stats(means: &[f64]) -> (f64, f64) {
    let r = means.len() as f64;
    let mean = means.iter().sum::<f64>() / r;
    let var = means.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (r * (r - 1.0));
    (mean, var.sqrt())
}

/// The chain's orders and albedo over `n` walks, with standard errors from 16 batches.
fn chain_estimates(mu: f64, f0: f64, orders: usize, n: usize) -> (Vec<(f64, f64)>, (f64, f64)) {
    let batches = 16;
    let mut rng = rng::Rng(0x9e37_79b9_7f4a_7c15 ^ mu.to_bits());
    let mut order_means = vec![Vec::new(); orders];
    let mut albedo_means = Vec::new();
    for _ in 0..batches {
        let mut sums = vec![0.0; orders];
        let mut albedo = 0.0;
        for _ in 0..n / batches {
            chain(mu, f0, &mut rng, &mut sums, &mut albedo, (&[], &mut []));
        }
        for k in 0..orders {
            order_means[k].push(sums[k] / (n / batches) as f64);
        }
        albedo_means.push(albedo / (n / batches) as f64);
    }
    (
        order_means.iter().map(|m| batch_stats(m)).collect(),
        batch_stats(&albedo_means),
    )
}

/// The chain is right where it can be checked in closed form: its first order is `E` at
/// `alpha = 1`.
#[test]
fn the_chain_first_order_is_the_closed_form() {
    for mu in [0.1, 0.5, 1.0] {
        let (orders, _) = chain_estimates(mu, 1.0, 1, 1 << 18);
        let (value, se) = orders[0];
        let truth = e_alpha_one(mu);
        assert!(
            (value - truth).abs() < 4.0 * se,
            "mu {mu}: {value} +- {se} vs {truth}"
        );
    }
}

/// The walk at `alpha = 1` against the chain, order by order and with a coloured Fresnel (a
/// throughput applied twice, or a Fresnel at the wrong cosine, moves the coloured albedo while
/// the white furnace cannot see it), and its first order against the closed form with a
/// standard error of at most `1e-4`.
#[test]
fn the_walk_at_alpha_one_is_the_chain() {
    for mu in [0.05, 0.5, 1.0] {
        let walked = walk(1.0, mu, schlick(0.3, 1.0), 6, 1 << 20);
        let (orders, albedo) = chain_estimates(mu, 0.3, 6, 1 << 20);
        let truth = e_alpha_one(mu);
        let e1 = walked.orders[0];
        assert!(e1.std_error <= 1e-4, "mu {mu}: {e1:?}");
        assert!(
            (e1.value - truth).abs() <= 3.0 * e1.std_error + 1e-7,
            "mu {mu}: e_1 {e1:?} vs {truth}"
        );
        for (k, (walk_k, (chain_k, chain_se))) in walked.orders.iter().zip(&orders).enumerate() {
            let allowed = 4.0 * (walk_k.std_error.powi(2) + chain_se.powi(2)).sqrt();
            assert!(
                (walk_k.value - chain_k).abs() <= allowed,
                "mu {mu}, order {}: walk {walk_k:?}, chain {chain_k} +- {chain_se}",
                k + 1
            );
        }
        let a = walked.albedo[0];
        let allowed = 4.0 * (a.std_error.powi(2) + albedo.1.powi(2)).sqrt();
        assert!(
            (a.value - albedo.0).abs() <= allowed,
            "mu {mu}: albedo {a:?}, chain {albedo:?}"
        );
    }
}

/// The first order is the height-correlated Smith BRDF's albedo: kiln's deterministic
/// reference `E` (an adaptive quadrature that shares only `D` and `Lambda` with the walk), from
/// near a mirror to beyond `alpha = 1`, and at grazing.
#[test]
fn the_first_order_is_kilns_reference_e() {
    let settings = ReferenceSettings::default();
    for model in [GGX, BECKMANN] {
        for (alpha, mu) in [(0.05, 0.3), (0.3, 0.02), (0.5, 0.7), (2.0, 0.4)] {
            let walk_settings = WalkSettings {
                walks: 1 << 18,
                ..WalkSettings::default()
            };
            let walked =
                walk_albedo(model, alpha, mu, &Fresnel::None, 3, &walk_settings, &|_| {}).unwrap();
            let e1 = walked.orders[0];
            let truth = reference_albedo(model, alpha, mu, &settings).value;
            assert!(
                e1.std_error <= 1e-4,
                "{model} alpha {alpha}, mu {mu}: {e1:?}"
            );
            assert!(
                (e1.value - truth).abs() <= 3.5 * e1.std_error + 1e-7,
                "{model} alpha {alpha}, mu {mu}: e_1 {e1:?} vs reference {truth}"
            );
        }
    }
}

/// Visible normals from below the horizon (a ray travelling up meets a facet from below):
/// the sampler's histogram over `cos(theta_m)` matches the density `<v, m>+ D(m) / A(v)`
/// integrated by quadrature here, and that density's integral is `A(v) = |v_z| Lambda(-v)`.
#[test]
fn visible_normals_below_the_horizon_follow_their_density() {
    let alpha: f64 = 0.6;
    let ggx = Ggx { alpha };
    let ggx_d = |m: Vec3| {
        let t = (1.0 - m.z * m.z) + alpha * alpha * m.z * m.z;
        alpha * alpha / (PI * t * t)
    };
    below_the_horizon(&ggx, &ggx_d);
    let beckmann = Beckmann { alpha };
    // Walter 2007, eq. 25.
    let beckmann_d = |m: Vec3| {
        let c2 = m.z * m.z;
        (-(1.0 - c2) / (c2 * alpha * alpha)).exp() / (PI * alpha * alpha * c2 * c2)
    };
    below_the_horizon(&beckmann, &beckmann_d);
}

/// The test above for one distribution `ndf` with the density `d` written here.
fn below_the_horizon<N: MicrofacetDistribution>(ndf: &N, d: &dyn Fn(Vec3) -> f64) {
    for vz in [-0.3f64, -0.8] {
        let v = Vec3::new((1.0 - vz * vz).sqrt(), 0.0, vz);
        // Quadrature of <v, m>+ D(m) over bins of m.z, midpoint in cos and phi.
        let bins = 16;
        let (nc, nphi) = (400, 400);
        let mut expected = vec![0.0; bins];
        for i in 0..bins * nc {
            let z = (i as f64 + 0.5) / (bins * nc) as f64;
            let s = (1.0 - z * z).sqrt();
            for j in 0..nphi {
                let phi = 2.0 * PI * (j as f64 + 0.5) / nphi as f64;
                let m = Vec3::new(s * phi.cos(), s * phi.sin(), z);
                let w = v.dot(m).max(0.0) * d(m) / (bins * nc * nphi) as f64 * 2.0 * PI;
                expected[i / nc] += w;
            }
        }
        let area: f64 = expected.iter().sum();
        let lambda_up = ndf.lambda(Vec3::new(-v.x, -v.y, -v.z));
        assert!(
            (area - vz.abs() * lambda_up).abs() < 1e-4 * area,
            "vz {vz}: {area} vs {}",
            vz.abs() * lambda_up
        );
        let n = 1 << 20;
        let mut counts = vec![0u64; bins];
        let mut rng = rng::Rng(12345);
        for _ in 0..n {
            let u = [
                ((rng.next() >> 11) as f64 + 0.5) / (1u64 << 53) as f64,
                ((rng.next() >> 11) as f64 + 0.5) / (1u64 << 53) as f64,
            ];
            let m = ndf.sample_visible_normal(v, u);
            assert!(v.dot(m) >= -1e-12, "vz {vz}: {m:?} is not visible");
            counts[((m.z * bins as f64) as usize).min(bins - 1)] += 1;
        }
        for b in 0..bins {
            let p = expected[b] / area;
            let observed = counts[b] as f64 / n as f64;
            let sigma = (p * (1.0 - p) / n as f64).sqrt();
            assert!(
                (observed - p).abs() <= 5.0 * sigma + 1e-5,
                "vz {vz}, bin {b}: {observed} vs {p}"
            );
        }
    }
}

/// Nothing depends on the height distribution: the same numbers walked on exponential,
/// uniform and Gaussian heights give the same albedo (a slip in one distribution's `C1` or its
/// inverse moves every hit below the first).
#[test]
fn the_height_distribution_does_not_matter() {
    let run = |heights| {
        let settings = WalkSettings {
            walks: 1 << 14,
            heights,
            ..WalkSettings::default()
        };
        walk_albedo(GGX, 0.8, 0.3, &schlick(0.5, 1.0), 4, &settings, &|_| {}).unwrap()
    };
    let reference = run(Heights::Exponential);
    for heights in [Heights::Uniform, Heights::Gaussian] {
        let other = run(heights);
        for k in 0..4 {
            let (a, b) = (reference.orders[k].value, other.orders[k].value);
            assert!(
                (a - b).abs() < 1e-9,
                "{heights:?}, order {}: {a} vs {b}",
                k + 1
            );
        }
        let (a, b) = (reference.albedo[0].value, other.albedo[0].value);
        assert!((a - b).abs() < 1e-9, "{heights:?}: albedo {a} vs {b}");
    }
}

/// The same settings give the same bits on one thread and on several.
#[test]
fn a_fixed_seed_reproduces_across_thread_counts() {
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| walk(0.7, 0.4, schlick(0.2, 1.0), 8, 1 << 16))
    };
    let one = run(1);
    let three = run(3);
    let bits = |e: &WalkEstimate| -> Vec<u64> {
        let albedo: Rgb = std::array::from_fn(|j| e.albedo[j].value);
        e.orders
            .iter()
            .map(|m| m.value.to_bits())
            .chain(albedo.iter().map(|v| v.to_bits()))
            .chain([e.beyond.value.to_bits()])
            .collect()
    };
    assert_eq!(bits(&one), bits(&three));
}

/// One set of walks for every `F0` (Schlick's Fresnel carried as a polynomial in `F0`): at
/// `alpha = 1` its albedo at several `F0` is the chain's, written with `F` at each bounce
/// directly; at `F0 = 1` (`F = 1`) it is 1, every walk leaving in the end.
#[test]
fn the_f0_polynomial_is_the_albedo_at_every_f0() {
    let settings = WalkSettings {
        walks: 1 << 20,
        ..WalkSettings::default()
    };
    let mu = 0.4;
    let polynomial = walk_schlick_polynomial(GGX, 1.0, mu, 1.0, &settings, &|_| {}).unwrap();
    for f0 in [0.0, 0.3, 0.8] {
        let (_, (chain, chain_se)) = chain_estimates(mu, f0, 1, 1 << 20);
        let walked = polynomial.albedo(f0);
        let allowed = 4.0 * (walked.std_error.powi(2) + chain_se.powi(2)).sqrt();
        assert!(
            (walked.value - chain).abs() <= allowed,
            "F0 {f0}: polynomial {walked:?}, chain {chain} +- {chain_se}"
        );
    }
    // Russian roulette keeps it unbiased, not exact: within its standard error.
    let white = polynomial.albedo(1.0);
    assert!(
        (white.value - 1.0).abs() <= 4.0 * white.std_error + 1e-12,
        "{white:?}"
    );
}

/// `kiln ARGS`, run to its end.
#[cfg(feature = "cli")]
fn run(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(args)
        .output()
        .unwrap()
}

/// `kiln ARGS --json`, which must succeed, its output parsed.
#[cfg(feature = "cli")]
fn kiln_json(args: &[&str]) -> serde_json::Value {
    let output = run(&[args, &["--json"]].concat());
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

/// The interface the checks use: `e-order` with its standard error, and
/// `e-compensated` against the closed forms at `alpha = 1` with a constant `F = 1/2`
/// (`--f0 0.5 --f90 0.5`): Kulla-Conty's albedo `F E + F^2 E_avg / (1 - F (1 - E_avg)) (1 - E)`,
/// Turquin's `F E (1 + F (1 - E) / E)`, with `E(mu) = 1 - mu ln(1 + 1/mu)` and
/// `E_avg = 4/3 (1 - ln 2)`.
#[cfg(feature = "cli")]
#[test]
fn the_command_line_gives_the_walk_and_the_compensations() {
    let mu = 0.3;
    let e = e_alpha_one(mu);
    let json = kiln_json(&[
        "eval",
        "--quantity",
        "e-order",
        "--order",
        "1",
        "--roughness",
        "1",
        "--mu",
        "0.3",
        "--walks",
        "2^20",
    ]);
    let (value, se) = (
        json["value"].as_f64().unwrap(),
        json["std_error"].as_f64().unwrap(),
    );
    assert!(se <= 1e-4 && (value - e).abs() <= 3.0 * se + 1e-7, "{json}");
    let e_avg = 4.0 / 3.0 * (1.0 - std::f64::consts::LN_2);
    let f = 0.5;
    for (name, expected) in [
        (
            "kulla-conty",
            f * e + f * f * e_avg / (1.0 - f * (1.0 - e_avg)) * (1.0 - e),
        ),
        ("turquin", f * e * (1.0 + f * (1.0 - e) / e)),
    ] {
        let json = kiln_json(&[
            "eval",
            "--quantity",
            "e-compensated",
            "--compensation",
            name,
            "--f0",
            "0.5",
            "--f90",
            "0.5",
            "--alpha",
            "1",
            "--mu",
            "0.3",
        ]);
        let value = json["value"].as_f64().unwrap();
        assert!(
            (value - expected).abs() < 1e-9,
            "{name}: {value} vs {expected}"
        );
    }
}

/// Out of range: exit 2 with the range named, before any walk.
#[cfg(feature = "cli")]
#[test]
fn the_command_line_refuses_what_the_walk_cannot_do() {
    for (args, says) in [
        (
            &[
                "--quantity",
                "e-order",
                "--order",
                "65",
                "--alpha",
                "1",
                "--mu",
                "0.5",
            ][..],
            "1 to 64",
        ),
        (
            &[
                "--quantity",
                "e-order",
                "--order",
                "0",
                "--alpha",
                "1",
                "--mu",
                "0.5",
            ][..],
            "1 to 64",
        ),
        (
            &[
                "--quantity",
                "e-multiple",
                "--f0",
                "0.5",
                "--masking",
                "separable",
                "--alpha",
                "1",
                "--mu",
                "0.5",
            ][..],
            "height-correlated",
        ),
        (
            &[
                "--quantity",
                "e-multiple",
                "--ior",
                "1.5",
                "--alpha",
                "1",
                "--mu",
                "0.5",
            ][..],
            "dielectric",
        ),
        (
            &[
                "--quantity",
                "e-multiple",
                "--f0",
                "0.5",
                "--alpha",
                "1",
                "--mu",
                "0.5",
                "--walks",
                "3",
            ][..],
            "power of two",
        ),
        // A ray skimming a near-mirror: every bounce leaves it nearly tangent, and each walk
        // ran to the vertex cap (2^20: minutes of silence); now the first such walk refuses.
        (
            &[
                "--quantity",
                "e-multiple",
                "--f0",
                "0.5",
                "--alpha",
                "1e-300",
                "--mu",
                "0",
            ][..],
            "did not end within 65536 vertices",
        ),
    ] {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_kiln"))
            .arg("eval")
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
}

/// A mirror (`alpha = 0`) reflects once: the walk's albedo is Schlick's Fresnel at the view,
/// in closed form, and at `mu = 0` (a tangent view, which has no visible normal to sample and
/// whose reflection runs along the surface) its grazing value `F90`.
#[test]
fn a_mirror_walk_is_one_reflection() {
    for (mu, f0, expected) in [
        (0.3, 0.5, 0.5 + 0.5 * 0.7_f64.powi(5)),
        (1.0, 0.04, 0.04),
        (0.0, 0.5, 1.0),
    ] {
        let estimate = walk(0.0, mu, schlick(f0, 1.0), 1, 1 << 10);
        let value = estimate.albedo[0].value;
        assert!((value - expected).abs() < 1e-14, "mu {mu}: {value}");
        assert_eq!(estimate.mean_vertices, 1.0);
    }
}

/// kiln's compensation: the fit recovers coefficients it is given (a synthetic walk made of
/// its own basis, so that only the least squares and the pinned white furnace are tested),
/// and at a view its albedo is within 0.5 % of walks independent of those it was fitted to.
#[test]
fn kilns_compensation_fits_its_basis_and_matches_independent_walks() {
    use kiln::integrate::compensation::{KILN_FIT_SEED, KilnCompensation};
    let (e_scale, e_bias) = (0.4, 0.05);
    let given = [0.01, 0.08, 0.2, 0.3];
    let truth = KilnCompensation {
        coefficients: given,
    };
    let walk = |f: f64| f * e_scale + e_bias + truth.multiple(f);
    let fitted = KilnCompensation::fit(walk, e_scale, e_bias);
    for (a, b) in fitted.coefficients.iter().zip(given) {
        assert!(
            (a - b).abs() < 1e-9,
            "{:?} vs {given:?}",
            fitted.coefficients
        );
    }
    let settings = WalkSettings {
        walks: 1 << 16,
        seed: KILN_FIT_SEED,
        ..WalkSettings::default()
    };
    let reference = ReferenceSettings::default();
    let (alpha, mu) = (1.0, 0.35);
    let kiln = KilnCompensation::at(GGX, alpha, mu, &settings, &reference).unwrap();
    let audit = WalkSettings {
        walks: 1 << 16,
        ..WalkSettings::default()
    };
    let independent = walk_schlick_polynomial(GGX, alpha, mu, 1.0, &audit, &|_| {}).unwrap();
    for f0 in [0.04, 0.5, 0.9] {
        let fresnel = schlick(f0, 1.0);
        let e_f = kiln::integrate::reference::reference_weighted_albedo(
            GGX,
            alpha,
            mu,
            move |c| fresnel.reflectance(c)[0],
            &reference,
        )
        .value;
        let truth = independent.albedo(f0).value;
        let ours = e_f + kiln.multiple(f0);
        assert!(
            (ours / truth - 1.0).abs() < 5e-3,
            "F0 {f0}: kiln {ours}, walk {truth}"
        );
    }
}

/// kiln's compensation as a table: `kiln compensation --bake` writes one JSON document that
/// reads back checked, `--table` measures its lookup against independent walks, and a damaged
/// document is refused by name before anything is walked.
#[test]
fn the_compensation_table_bakes_reads_back_and_is_audited() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tables");
    let baked = run(&[
        "compensation",
        "--bake",
        out.to_str().unwrap(),
        "--size",
        "6",
        "--walks",
        "2^12",
        "-q",
    ]);
    assert!(
        baked.status.success(),
        "{}",
        String::from_utf8_lossy(&baked.stderr)
    );
    let file = out.join("ggx-height-correlated-kiln-compensation.json");
    let bytes = std::fs::read(&file).unwrap();
    let table = kiln::format::compensation::decode(&bytes, "baked").unwrap();
    assert_eq!(table.spec.shape(), vec![6, 6]);
    assert_eq!(table.walks, 1 << 12);
    // The textures beside it hold the same coefficients, R to A, x = mu (6 wide, 6 high).
    for (extension, decode) in [
        (
            "ktx2",
            kiln::format::ktx2::decode
                as fn(&[u8]) -> kiln::Result<kiln::format::texture::DecodedTexture>,
        ),
        ("dds", kiln::format::dds::decode),
    ] {
        let path = out.join(format!(
            "ggx-height-correlated-kiln-compensation.{extension}"
        ));
        let texture = decode(&std::fs::read(&path).unwrap()).unwrap();
        assert_eq!(texture.extent.0, 6, "{extension}");
        assert_eq!(texture.channels.len(), 4, "{extension}");
        for (j, channel) in texture.channels.iter().enumerate() {
            for (k, &v) in channel.iter().enumerate() {
                assert_eq!(
                    v,
                    f64::from(table.coefficients[j][k] as f32),
                    "{extension} c_{j}[{k}]"
                );
            }
        }
    }
    // The EXR: channels c0 to c3 (read by the exr crate), 6 x 6, the same coefficients.
    let exr = kiln::format::exr::decode(
        &std::fs::read(out.join("ggx-height-correlated-kiln-compensation.exr")).unwrap(),
    )
    .unwrap();
    assert_eq!((exr.width, exr.height), (6, 6));
    for j in 0..4 {
        let (_, values) = exr
            .channels
            .iter()
            .find(|(name, _)| *name == format!("c{j}"))
            .unwrap_or_else(|| panic!("no channel c{j}: {:?}", exr.channels));
        for (k, &v) in values.iter().enumerate() {
            assert_eq!(
                v,
                f64::from(table.coefficients[j][k] as f32),
                "exr c_{j}[{k}]"
            );
        }
    }
    assert!(exr.metadata.unwrap().contains("kiln-compensation"));
    let audit = run(&[
        "compensation",
        "--table",
        file.to_str().unwrap(),
        "--compensation",
        "kiln",
        "--roughness",
        "0.6",
        "--mu",
        "0.4",
        "--f0",
        "0.5",
        "--walks",
        "2^14",
        "-q",
    ]);
    let text = String::from_utf8_lossy(&audit.stdout);
    assert!(
        audit.status.success(),
        "{}",
        String::from_utf8_lossy(&audit.stderr)
    );
    assert!(text.contains("  kiln "), "{text}");
    // A coefficient of the wrong length: refused, naming it.
    let damaged = String::from_utf8(bytes).unwrap().replacen(
        "\"coefficients\": [\n      [",
        "\"coefficients\": [\n      [0.5, ",
        1,
    );
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, damaged).unwrap();
    let refused = run(&["compensation", "--table", bad.to_str().unwrap(), "-q"]);
    let message = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{message}");
    assert!(
        message.contains("coefficient 0 holds 37 numbers for 36 texels"),
        "{message}"
    );
}

/// The multiple-scattering lobe of the chain at `alpha = 1` with Schlick's `f0` (`F90` = 1) at
/// each exit cosine, averaged over the azimuth, with standard errors from 16 batches.
fn chain_lobe(mu: f64, f0: f64, exits: &[f64], n: usize) -> Vec<(f64, f64)> {
    let batches = 16;
    let mut rng = rng::Rng(0x5851_f42d_4c95_7f2d ^ mu.to_bits());
    let mut means = vec![Vec::new(); exits.len()];
    for _ in 0..batches {
        let mut sums = vec![0.0; exits.len()];
        for _ in 0..n / batches {
            chain(mu, f0, &mut rng, &mut [], &mut 0.0, (exits, &mut sums));
        }
        for (m, s) in means.iter_mut().zip(&sums) {
            m.push(s / (n / batches) as f64);
        }
    }
    means.iter().map(|m| batch_stats(m)).collect()
}

fn lobe(alpha: f64, mu: f64, grid: &LobeGrid, walks: u64) -> LobeEstimate {
    let settings = WalkSettings {
        walks,
        ..WalkSettings::default()
    };
    walk_lobe(GGX, alpha, mu, grid, &Fresnel::None, &settings, &|_| {}).unwrap()
}

/// A direction with `cos(theta) = mu` at azimuth `phi` from the view's plane.
fn direction(mu: f64, phi: f64) -> Vec3 {
    let s = (1.0 - mu * mu).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), mu)
}

/// The height-correlated Smith BRDF of GGX, `D(h) / (4 mu_i mu_o (1 + Lambda_i + Lambda_o))`,
/// written here from Walter 2007 (eq. 33) and Heitz 2014 (eq. 72, 99).
fn single_scattering(alpha: f64, i: Vec3, o: Vec3) -> f64 {
    let a2 = alpha * alpha;
    let h = (i + o).normalize();
    let t = 1.0 + (a2 - 1.0) * h.z * h.z;
    let d = a2 / (PI * t * t);
    let lambda = |v: Vec3| ((1.0 + a2 * (1.0 - v.z * v.z) / (v.z * v.z)).sqrt() - 1.0) / 2.0;
    d / (4.0 * i.z * o.z * (1.0 + lambda(i) + lambda(o)))
}

/// The walk's lobe by next-event estimation, where it is known independently: its first order
/// is the height-correlated Smith BRDF in closed form (at every azimuth, and averaged over it
/// against a quadrature of that form), and at `alpha = 1` its later orders are the chain's
/// (a wrong projected area below the horizon, escape or order bookkeeping moves them).
#[test]
fn the_lobe_is_the_smith_brdf_then_the_chain() {
    let exits = [0.05, 0.3, 0.7, 1.0];
    let grid = LobeGrid {
        mus: exits.to_vec(),
        azimuths: vec![0.0, 1.0, PI],
        strata: 4,
    };
    for (alpha, mu) in [(1.0, 0.5), (1.0, 0.1), (0.3, 0.6)] {
        let walked = lobe(alpha, mu, &grid, 1 << 18);
        let i = Vec3::from_mu(mu);
        for (j, &mu_o) in exits.iter().enumerate() {
            for (k, &phi) in grid.azimuths.iter().enumerate() {
                let got = walked.single[j * grid.azimuths.len() + k];
                let truth = single_scattering(alpha, i, direction(mu_o, phi));
                assert!(
                    (got.value - truth).abs() <= 4.0 * got.std_error + 1e-12 * truth,
                    "alpha {alpha}, mu {mu} -> ({mu_o}, {phi}): {got:?} vs {truth}"
                );
            }
            // The azimuthal average by the midpoint rule, spectrally accurate here.
            let n = 4096;
            let truth = (0..n)
                .map(|k| {
                    single_scattering(alpha, i, direction(mu_o, PI * (k as f64 + 0.5) / n as f64))
                })
                .sum::<f64>()
                / n as f64;
            let got = walked.single_averaged[j];
            assert!(
                (got.value - truth).abs() <= 4.0 * got.std_error + 1e-9 * truth,
                "alpha {alpha}, mu {mu} -> {mu_o}, averaged: {got:?} vs {truth}"
            );
        }
        if alpha == 1.0 {
            let chain = chain_lobe(mu, 1.0, &exits, 1 << 19);
            for (j, &(value, se)) in chain.iter().enumerate() {
                let averaged = walked.multiple_averaged[j];
                let mut seen = vec![averaged];
                seen.extend((0..3).map(|k| walked.multiple[j * 3 + k]));
                for got in seen {
                    let allowed = 4.0 * (got.std_error.powi(2) + se * se).sqrt();
                    assert!(
                        (got.value - value).abs() <= allowed,
                        "mu {mu} -> {}: walk {got:?}, chain {value} +- {se}",
                        exits[j]
                    );
                }
            }
        }
    }
}

/// The measured multiple-scattering lobe is reciprocal, `f(a, b) = f(b, a)`, from two
/// independent sets of walks (one from each direction), at every azimuth; the walk is not
/// symmetric in its two directions, so a wrong phase function or escape shows here.
#[test]
fn the_measured_lobe_is_reciprocal() {
    let (a, b) = (0.35, 0.8);
    for alpha in [0.6, 0.3] {
        let grid = |exit: f64| LobeGrid {
            mus: vec![exit],
            azimuths: vec![0.0, PI / 2.0, PI],
            strata: 1,
        };
        // Leaving near grazing from a smooth surface is the noisy side.
        let from_a = lobe(alpha, a, &grid(b), 1 << 18);
        let from_b = lobe(alpha, b, &grid(a), 1 << 20);
        for k in 0..3 {
            let (ab, ba) = (from_a.multiple[k], from_b.multiple[k]);
            let allowed = 4.0 * (ab.std_error.powi(2) + ba.std_error.powi(2)).sqrt();
            assert!(
                (ab.value - ba.value).abs() <= allowed && allowed <= 0.02 * ab.value,
                "alpha {alpha}, azimuth {k}: f({a} -> {b}) {ab:?}, f({b} -> {a}) {ba:?}"
            );
        }
    }
}

/// `kiln compensation --lobe`: at `alpha = 1` the compensations' lobes are closed forms
/// (Kulla-Conty's `(1 - E(mu_i)) (1 - E(mu_o)) / (pi (1 - E_avg))`, Turquin's `f_ss (1 - E) / E`
/// with `D = 1 / pi`), and the walk's lobe does not depend on the azimuth (`D` is constant, so
/// every reflection is uniform on its cap): the fixed azimuths' estimates and the stratified
/// average are different estimators of one number. The refusals name the range.
#[cfg(feature = "cli")]
#[test]
fn the_lobe_audit_reports_the_closed_forms_and_refuses_by_name() {
    let json = kiln_json(&[
        "compensation",
        "--lobe",
        "--roughness",
        "1",
        "--mu",
        "0.3,0.8",
        "--exit",
        "0.15,0.6",
        "--azimuth",
        "0,90,180",
        "--walks",
        "2^18",
        "--f0",
        "1,0.5",
        "--compensation",
        "kulla-conty,turquin",
        "-q",
    ]);
    let e_avg = 4.0 / 3.0 * (1.0 - std::f64::consts::LN_2);
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), 2 * 2 * 2 * 4);
    let mut averaged = std::collections::HashMap::new();
    for p in points {
        let (view, exit) = (p["view"].as_f64().unwrap(), p["exit"].as_f64().unwrap());
        let walk = p["walk"]["value"].as_f64().unwrap();
        let se = p["walk"]["std_error"].as_f64().unwrap();
        let added: Vec<f64> = p["added"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let f0 = p["f0"].as_f64().unwrap();
        let (e_i, e_o) = (e_alpha_one(view), e_alpha_one(exit));
        // Schlick's average 2 ∫ F mu dmu = F0 + (1 - F0) / 21, and Kulla-Conty's colour.
        let f_avg = f0 + (1.0 - f0) / 21.0;
        let colour = f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg));
        let kulla_conty = colour * (1.0 - e_i) * (1.0 - e_o) / (PI * (1.0 - e_avg));
        assert!((added[0] - kulla_conty).abs() < 1e-9 * kulla_conty, "{p}");
        assert!(se > 0.0 && se < 2e-3 * walk, "{p}");
        let key = (view.to_bits(), exit.to_bits(), f0.to_bits());
        match p["azimuth"].as_f64() {
            None => {
                averaged.insert(key, (walk, se));
            }
            Some(phi) => {
                // Turquin's: D = 1 / pi, Schlick at the half vector, times F0 (1 - E) / E.
                let (i, o) = (Vec3::from_mu(view), direction(exit, phi));
                let cosine = ((1.0 + i.dot(o)) / 2.0).sqrt();
                let fresnel = f0 + (1.0 - f0) * (1.0 - cosine).powi(5);
                let lambda = |c: f64| (1.0 / c - 1.0) / 2.0;
                let turquin =
                    fresnel / PI / (4.0 * view * exit * (1.0 + lambda(view) + lambda(exit)))
                        * f0
                        * (1.0 - e_i)
                        / e_i;
                assert!((added[1] - turquin).abs() < 1e-9 * turquin, "{p}");
                // At F = 1 nothing depends on the azimuth.
                if f0 == 1.0 {
                    let (mean, mean_se) = averaged[&key];
                    let allowed = 4.0 * (se * se + mean_se * mean_se).sqrt();
                    assert!((walk - mean).abs() <= allowed, "{p} vs averaged {mean}");
                }
            }
        }
    }
    for (args, says) in [
        (&["--exit", "0"][..], "(0, 1]"),
        (&["--azimuth", "200"][..], "[0, 180]"),
        (&["--roughness", "0"][..], "delta"),
        (&["--compensation", "kiln"][..], "--table"),
        (&["--f0", "1.5"][..], "[0, 1]"),
        (
            &["--mu", "0.1,0.2,0.3,0.4,0.5", "--plot", "lobe.png"][..],
            "at most 12",
        ),
    ] {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_kiln"))
            .args(["compensation", "--lobe", "--walks", "2^10", "-q"])
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
}

/// The benchmark's other estimators measure the same walk: the analog walk (escapes drawn) with
/// pseudorandom numbers agrees with kiln's (expected escapes, Sobol) order by order and on the
/// coloured albedo, within their combined errors, so that `examples/walk_estimators.rs`
/// compares costs of one quantity.
#[test]
fn the_analog_walk_measures_the_same_orders() {
    use kiln::integrate::walk::{Escape, Numbers};
    let run = |escape, numbers| {
        let settings = WalkSettings {
            walks: 1 << 18,
            escape,
            numbers,
            ..WalkSettings::default()
        };
        walk_albedo(GGX, 0.5, 0.4, &schlick(0.5, 1.0), 3, &settings, &|_| {}).unwrap()
    };
    let kilns = run(Escape::Expected, Numbers::Sobol);
    let analog = run(Escape::Sampled, Numbers::Pseudorandom);
    let pairs = kilns
        .orders
        .iter()
        .zip(&analog.orders)
        .chain([(&kilns.albedo[0], &analog.albedo[0])]);
    for (a, b) in pairs {
        let allowed = 4.0 * (a.std_error.powi(2) + b.std_error.powi(2)).sqrt();
        assert!(
            (a.value - b.value).abs() <= allowed && b.std_error > 3.0 * a.std_error,
            "kiln's {a:?}, analog {b:?}"
        );
    }
}

/// With Schlick's Fresnel at every vertex, the walk's lobe (averaged over the azimuth, where the
/// last facet's Fresnel depends on it) is the chain's at `alpha = 1`: the Fresnel of the
/// next-event reflection is taken at the right cosine and the throughput carries every earlier
/// one. With `F0 = 0.3` a factor at the wrong cosine moves it by far more than its error.
#[test]
fn the_lobe_with_fresnel_is_the_chain() {
    let exits = [0.1, 0.5, 0.9];
    let grid = LobeGrid {
        mus: exits.to_vec(),
        azimuths: vec![0.0],
        strata: 8,
    };
    let settings = WalkSettings {
        walks: 1 << 18,
        ..WalkSettings::default()
    };
    let fresnel = schlick(0.3, 1.0);
    for mu in [0.2, 0.7] {
        let walked = walk_lobe(GGX, 1.0, mu, &grid, &fresnel, &settings, &|_| {}).unwrap();
        let chain = chain_lobe(mu, 0.3, &exits, 1 << 19);
        for (j, &(value, se)) in chain.iter().enumerate() {
            let got = walked.multiple_averaged[j];
            let allowed = 4.0 * (got.std_error.powi(2) + se * se).sqrt();
            assert!(
                (got.value - value).abs() <= allowed && allowed < 0.03 * value,
                "mu {mu} -> {}: walk {got:?}, chain {value} +- {se}",
                exits[j]
            );
        }
    }
}

/// The compensation's generated Rust (`--format rs`), compiled with rustc and run in f32: its
/// coefficients, `M`, `M_avg` and lobe against the library's f64 lookups of the same table at
/// points inside cells, on texel rows and at the edges.
#[cfg(feature = "cli")]
#[test]
fn the_generated_rust_compensation_agrees_with_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tables");
    let table = compensation_bake::bake(&out, "8", "2^10", &["--format", "json,rs"]);
    let stem = compensation_bake::STEM;
    let points = [
        (0.0, 0.3, 0.02),
        (0.013, 0.27, 0.3),
        (0.2, 0.5, 0.955),
        (0.37, 0.81, 0.5),
        (0.5, 1.0, 0.04),
        (0.92, 0.64, 0.8),
        (1.0, 0.4, 0.3),
    ];
    let s = stem.replace('-', "_");
    let mut program = std::fs::read_to_string(out.join(format!("{stem}.rs"))).unwrap();
    program += "\nfn main() {\n";
    for (mu, r, f0) in points {
        program += &format!(
            "    let c = {s}_coefficients({mu:?}, {r:?});\n\
             let ci = {s}_coefficients(0.61, {r:?});\n\
             let m = {s}_albedo(c, [{f0:?}, 1.0, 0.5]);\n\
             let m_avg = {s}_albedo({s}_average({r:?}), [{f0:?}, 1.0, 0.5]);\n\
             let lobe = {s}_lobe(m, {s}_albedo(ci, [{f0:?}, 1.0, 0.5]), m_avg);\n\
             for v in c.iter().chain(&m).chain(&m_avg).chain(&lobe) {{ println!(\"{{v:e}}\"); }}\n"
        );
    }
    program += "}\n";
    let printed = rustc::compile_and_run(dir.path(), "compensation", &program);
    let mut values = printed.into_iter();
    for (mu, r, f0) in points {
        let c = table.lookup(mu, r);
        let ci = table.lookup(0.61, r);
        let average = table.lookup_average(r);
        let f0s = [f0, 1.0, 0.5];
        let mut expected: Vec<(f64, f64)> = c.coefficients.iter().map(|&v| (v, 2e-6)).collect();
        expected.extend(f0s.iter().map(|&f| (c.multiple(f), 2e-6)));
        expected.extend(f0s.iter().map(|&f| (average.multiple(f), 2e-6)));
        expected.extend(f0s.iter().map(|&f| {
            let lobe = c.multiple(f) * ci.multiple(f) / (PI * average.multiple(f).max(1e-30));
            (lobe, 1e-5)
        }));
        for (want, tolerance) in expected {
            let got = values.next().expect("as many numbers as asked for");
            assert!(
                (got - want).abs() <= tolerance * (1.0 + want.abs()),
                "at mu {mu}, r {r}, F0 {f0}: generated {got:e}, library {want:e}"
            );
        }
    }
    assert!(values.next().is_none());
}

// The dielectric walk (`kiln::integrate::walk::dielectric`).

fn glass_walk(alpha: f64, view: View, eta: f64, walks: u64) -> DielectricEstimate {
    glass_walk_of(GGX, alpha, view, eta, walks)
}

fn glass_walk_of(model: Model, alpha: f64, view: View, eta: f64, walks: u64) -> DielectricEstimate {
    let settings = WalkSettings {
        walks,
        ..WalkSettings::default()
    };
    walk_dielectric(model, alpha, view, eta, &settings, &|_| {}).unwrap()
}

/// `ln Gamma(x)`, `x > 0`: Stirling's series at `x + 8` and more, stepped down by
/// `Gamma(x + 1) = x Gamma(x)` (Abramowitz and Stegun 6.1.40), to about 1e-15.
fn ln_gamma(x: f64) -> f64 {
    let mut shift = 0.0;
    let mut z = x;
    while z < 8.0 {
        shift += z.ln();
        z += 1.0;
    }
    let series = 1.0 / (12.0 * z) - 1.0 / (360.0 * z.powi(3)) + 1.0 / (1260.0 * z.powi(5))
        - 1.0 / (1680.0 * z.powi(7));
    (z - 0.5) * z.ln() - z + 0.5 * (2.0 * PI).ln() + series - shift
}

/// The Beta function `B(a, b) = Gamma(a) Gamma(b) / Gamma(a + b)`.
fn beta(a: f64, b: f64) -> f64 {
    (ln_gamma(a) + ln_gamma(b) - ln_gamma(a + b)).exp()
}

/// Unpolarised Fresnel reflectance at a dielectric interface of relative index `eta` for the
/// cosine `c` (Born and Wolf, from Snell's law and the two polarisations' amplitudes).
fn fresnel_dielectric(eta: f64, c: f64) -> f64 {
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let t = (1.0 - sin2_t).sqrt();
    let r_s = (c - eta * t) / (c + eta * t);
    let r_p = (eta * c - t) / (eta * c + t);
    0.5 * (r_s * r_s + r_p * r_p)
}

/// GGX's `Lambda` for a direction of cosine `c` (either sign), `alpha`.
fn ggx_lambda(alpha: f64, c: f64) -> f64 {
    let tan2 = (1.0 - c * c) / (c * c);
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// The Smith microsurface's single scattering through a dielectric, `[R_1, T_1]`, by Monte
/// Carlo over visible normals (kiln's sampler; its density is checked above) of the closed
/// forms written here: a facet at `C1 = x` (density `(1 + Lambda(o)) x^Lambda(o)`) reflects with
/// `F` and the reflection leaves above with `x^Lambda(i)`: `(1 + Lambda(o)) / (1 + Lambda(o) +
/// Lambda(i))`; the refraction leaves through the part of the surface above it, `(1 -
/// x)^Lambda(i)`: `(1 + Lambda(o)) B(1 + Lambda(o), 1 + Lambda(i))` (Heitz 2014, section 6).
/// Returns the means and their standard errors.
fn smith_single_scattering(alpha: f64, mu: f64, eta: f64, n: usize) -> [(f64, f64); 2] {
    let ggx = Ggx { alpha };
    let o = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let lambda_o = ggx_lambda(alpha, mu);
    let mut rng = rng::Rng(0x6c61_7373);
    let mut sums = [[0.0; 2]; 2];
    for _ in 0..n {
        let u = [rng.next(), rng.next()].map(|b| ((b >> 11) as f64 + 0.5) / (1u64 << 53) as f64);
        let m = ggx.sample_visible_normal(o, u);
        let c = o.x * m.x + o.y * m.y + o.z * m.z;
        let f = fresnel_dielectric(eta, c);
        let mut values = [0.0; 2];
        // Reflection: i = 2 (o.m) m - o.
        let i_z = 2.0 * c * m.z - o.z;
        if i_z > 0.0 {
            values[0] = f * (1.0 + lambda_o) / (1.0 + lambda_o + ggx_lambda(alpha, i_z));
        }
        // Refraction (Snell in vector form): t = -o / eta + (c / eta - cos_t) m.
        let sin2_t = (1.0 - c * c) / (eta * eta);
        if sin2_t < 1.0 {
            let cos_t = (1.0 - sin2_t).sqrt();
            let t_z = -o.z / eta + (c / eta - cos_t) * m.z;
            if t_z < 0.0 {
                let lambda_t = ggx_lambda(alpha, t_z);
                values[1] = (1.0 - f) * (1.0 + lambda_o) * beta(1.0 + lambda_o, 1.0 + lambda_t);
            }
        }
        for side in 0..2 {
            sums[side][0] += values[side];
            sums[side][1] += values[side] * values[side];
        }
    }
    sums.map(|[s, s2]| {
        let mean = s / n as f64;
        let variance = (s2 / n as f64 - mean * mean).max(0.0);
        (mean, (variance / n as f64).sqrt())
    })
}

/// The dielectric walk's first order is the Smith microsurface's single scattering: at an
/// index-matched interface in closed form (`eta = 1`: every ray goes straight through, nothing
/// is reflected, and at `alpha = 1` the views with `Lambda = 1` and `2`, `mu = 1/3` and `1/5`,
/// transmit `2 B(2, 2) = 1/3` and `3 B(3, 3) = 1/10` at once); a smooth interface reflects
/// `F(mu)` and transmits the rest; elsewhere its reflection is kiln's reference (an independent
/// quadrature of the BSDF renderers evaluate) and its transmission the closed form above by
/// Monte Carlo, from outside and from inside (total internal reflection). A height not turned
/// over at a refraction fails it (tried by hand), and the renderers' `1 / (1 + Lambda(o) +
/// Lambda(i))` would give 2/3 at `mu = 1/3`.
#[test]
fn the_dielectric_walks_first_order_is_the_smith_microsurfaces() {
    for (mu, transmitted) in [(1.0 / 3.0, 1.0 / 3.0), (0.2, 0.1)] {
        let w = glass_walk(1.0, View::Mu(mu), 1.0, 1 << 18);
        let t1 = w.single[TRANSMITTED];
        assert!(
            (t1.value - transmitted).abs() <= 4.0 * t1.std_error + 1e-9,
            "mu {mu}: T_1 {t1:?}, closed form {transmitted}"
        );
        assert_eq!(w.single[REFLECTED].value, 0.0);
        assert_eq!(w.all[REFLECTED].value, 0.0);
        let t = w.all[TRANSMITTED];
        assert!((t.value - 1.0).abs() <= 4.0 * t.std_error + 1e-12, "{t:?}");
    }
    let smooth = glass_walk(0.0, View::Mu(0.6), 1.5, 1 << 14);
    // A smooth interface scatters each walk exactly once.
    assert_eq!(smooth.mean_vertices, 1.0);
    let f = fresnel_dielectric(1.5, 0.6);
    assert!(
        (smooth.single[REFLECTED].value - f).abs() < 1e-3 * f,
        "{smooth:?}"
    );
    assert!(
        (smooth.all[TRANSMITTED].value - (1.0 - f)).abs() < 1e-3,
        "{smooth:?}"
    );
    let settings = ReferenceSettings::default();
    for (alpha, mu, eta) in [(0.5, 0.5, 1.5), (1.0, 0.2, 1.33), (0.6, 0.4, 1.0 / 1.5)] {
        let w = glass_walk(alpha, View::Mu(mu), eta, 1 << 19);
        let bsdf = reference_dielectric_albedo(GGX, alpha, mu, eta, &settings);
        let r1 = w.single[REFLECTED];
        assert!(
            (r1.value - bsdf.reflection).abs() <= 4.0 * r1.std_error + 1e-9,
            "alpha {alpha}, mu {mu}, eta {eta}: R_1 {r1:?}, the BSDF's {}",
            bsdf.reflection
        );
        let [_, (t1, t1_error)] = smith_single_scattering(alpha, mu, eta, 1 << 20);
        let walked = w.single[TRANSMITTED];
        assert!(
            (walked.value - t1).abs() <= 4.0 * walked.std_error.hypot(t1_error),
            "alpha {alpha}, mu {mu}, eta {eta}: T_1 {walked:?}, Smith's {t1} +- {t1_error}"
        );
    }
}

/// Reciprocity of the whole interface, every order: with the energy albedo, the light
/// transmitted from outside averaged over the hemisphere is `eta^2` times that from inside
/// (`T_avg(eta) = eta^2 T_avg(1 / eta)`, Fresnel's reciprocity for a smooth interface: the
/// walk's BSDF is reciprocal, Heitz et al. 2016, section 6). Nothing in the walk makes this
/// hold by construction: a walk that keeps the relative index after a refraction fails it
/// (tried by hand; a height not turned over passes it, and fails the first-order test).
#[test]
fn the_dielectric_walk_is_reciprocal() {
    for (model, alpha) in [(GGX, 0.3), (GGX, 1.0), (BECKMANN, 0.7)] {
        let outside = glass_walk_of(model, alpha, View::CosineWeighted, 1.5, 1 << 20);
        let inside = glass_walk_of(model, alpha, View::CosineWeighted, 1.0 / 1.5, 1 << 20);
        for (what, a, b) in [
            ("all", outside.all[TRANSMITTED], inside.all[TRANSMITTED]),
            (
                "single",
                outside.single[TRANSMITTED],
                inside.single[TRANSMITTED],
            ),
        ] {
            let scaled = 2.25 * b.value;
            let error = a.std_error.hypot(2.25 * b.std_error);
            assert!(
                (a.value - scaled).abs() <= 4.0 * error,
                "{model} alpha {alpha}, {what}: T_avg(1.5) {a:?}, 2.25 T_avg(1/1.5) {scaled} +- \
                 {error}"
            );
        }
    }
}

/// `kiln compensation --ior`: every point's Turquin split is the renderer's single scattering
/// over its energy albedo (kiln's reference, recomputed here), the walk's two sides sum to 1,
/// and a relative index outside its range is refused with the range.
#[cfg(feature = "cli")]
#[test]
fn the_command_line_measures_glass() {
    let audit = kiln_json(&[
        "compensation",
        "--ior",
        "1.5,0.6667",
        "--roughness",
        "1",
        "--mu",
        "0.3,1",
        "--walks",
        "65536",
        "-q",
    ]);
    let points = audit["points"].as_array().unwrap();
    assert_eq!(points.len(), 4);
    let settings = ReferenceSettings::default();
    for p in points {
        let (eta, alpha, mu) = (
            p["eta"].as_f64().unwrap(),
            p["alpha"].as_f64().unwrap(),
            p["mu"].as_f64().unwrap(),
        );
        let bsdf = reference_dielectric_albedo(GGX, alpha, mu, eta, &settings);
        let energy = bsdf.reflection + bsdf.transmission;
        let turquin = p["turquin"].as_array().unwrap();
        assert!((turquin[0].as_f64().unwrap() - bsdf.reflection / energy).abs() < 1e-12);
        assert!((turquin[1].as_f64().unwrap() - bsdf.transmission / energy).abs() < 1e-12);
        let all = &p["walk"]["all"];
        let sum = all[0]["value"].as_f64().unwrap() + all[1]["value"].as_f64().unwrap();
        assert!((sum - 1.0).abs() < 1e-2, "{p}");
    }
    assert_eq!(audit["summaries"].as_array().unwrap().len(), 2);
    // --ndf beckmann walks Beckmann's microsurface: its first reflection is Beckmann's BSDF.
    let audit = kiln_json(&[
        "compensation",
        "--ndf",
        "beckmann",
        "--ior",
        "1.5",
        "--roughness",
        "0.8",
        "--mu",
        "0.4",
        "--walks",
        "2^18",
        "-q",
    ]);
    let single = &audit["points"][0]["walk"]["single"][0];
    let (r1, r1_error) = (
        single["value"].as_f64().unwrap(),
        single["std_error"].as_f64().unwrap(),
    );
    let beckmann = reference_dielectric_albedo(BECKMANN, 0.64, 0.4, 1.5, &settings).reflection;
    assert!(
        (r1 - beckmann).abs() <= 4.0 * r1_error,
        "Beckmann's R_1 {r1} +- {r1_error}, its BSDF's {beckmann}"
    );
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(["compensation", "--ior", "0", "-q"])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("[0.01, 100]"), "{stderr}");
}

/// kiln's glass compensation: `kiln compensation --bake DIR --ior 1.5` writes a JSON document
/// and an EXR of its four factors, and `--ior 1.5,0.6667 --table` measures its lookup against
/// walks of another seed: at a texel (`r = 1`, `mu = 1`, the layout's corner, where the lookup
/// is the texel) from inside, where Turquin's split sends 0.06 of the light back and the walk
/// 0.41, kiln's agrees with the walk within its confidence and the table's noise.
#[cfg(feature = "cli")]
#[test]
fn the_glass_compensation_bakes_and_matches_independent_walks() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("glass");
    let baked = run(&[
        "compensation",
        "--bake",
        out.to_str().unwrap(),
        "--ior",
        "1.5",
        "--size",
        "4",
        "--walks",
        "2^16",
        "-q",
    ]);
    assert!(
        baked.status.success(),
        "{}",
        String::from_utf8_lossy(&baked.stderr)
    );
    let stem = "ggx-height-correlated-kiln-glass-compensation-ior-1.5";
    let file = out.join(format!("{stem}.json"));
    let table =
        kiln::format::glass_compensation::decode(&std::fs::read(&file).unwrap(), "baked").unwrap();
    let exr = kiln::format::exr::decode(&std::fs::read(out.join(format!("{stem}.exr"))).unwrap())
        .unwrap();
    assert_eq!((exr.width, exr.height), (4, 4));
    let (_, k_r_inside) = exr
        .channels
        .iter()
        .find(|(name, _)| name == "kR_inside")
        .unwrap();
    for (k, &v) in k_r_inside.iter().enumerate() {
        assert_eq!(
            v,
            f64::from(table.reflection[1][k] as f32),
            "kR_inside[{k}]"
        );
    }
    let audit = kiln_json(&[
        "compensation",
        "--ior",
        "0.6667",
        "--table",
        file.to_str().unwrap(),
        "--roughness",
        "1",
        "--mu",
        "1",
        "--walks",
        "2^18",
        "-q",
    ]);
    let point = &audit["points"][0];
    let walk = point["walk"]["all"][0]["value"].as_f64().unwrap();
    let walk_error = point["walk"]["all"][0]["std_error"].as_f64().unwrap();
    let kiln = point["kiln"][0].as_f64().unwrap();
    let turquin = point["turquin"][0].as_f64().unwrap();
    assert!(walk > 0.3 && turquin < 0.1, "{point}");
    let table_error = table.max_std_error();
    assert!(
        (kiln - walk).abs() <= 4.0 * walk_error.hypot(table_error) + 1e-4,
        "kiln's R {kiln}, the walk's {walk} +- {walk_error} (table {table_error})"
    );
    // Another index than the table's is refused by name.
    let refused = run(&[
        "compensation",
        "--ior",
        "1.33",
        "--table",
        file.to_str().unwrap(),
        "-q",
    ]);
    let message = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{message}");
    assert!(message.contains("at eta 1.5"), "{message}");
    // A table walked on GGX is not measured against Beckmann's walk.
    let refused = run(&[
        "compensation",
        "--ndf",
        "beckmann",
        "--ior",
        "1.5",
        "--table",
        file.to_str().unwrap(),
        "-q",
    ]);
    let message = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{message}");
    assert!(message.contains("the walk is beckmann"), "{message}");
    // Glass has no shader code yet: asked for, refused by name.
    let refused = run(&[
        "compensation",
        "--bake",
        dir.path().join("other").to_str().unwrap(),
        "--ior",
        "1.5",
        "--format",
        "wgsl",
        "-q",
    ]);
    let message = String::from_utf8_lossy(&refused.stderr);
    assert!(
        message.contains("--format wgsl is not written for glass"),
        "{message}"
    );
}

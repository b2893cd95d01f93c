//! The yardstick kiln's speed is quoted against: a 32 x 32 GGX `E` table estimated the way Blender
//! Cycles bakes its own (`docs/engines.md`: Owen-scrambled Sobol points, visible-normal sampling, the
//! estimate of `E` itself rather than of `1 - E`, single-precision arithmetic), at a sample count
//! the caller chooses (Cycles ships 2^23 per texel; the benchmark uses 2^16).
//!
//! Each sample: a visible normal by Heitz's 2018 stretch-sample-unstretch method ("Sampling the
//! GGX Distribution of Visible Normals", JCGT 7(4)) with library `sin`/`cos` of `2 pi u`, the
//! reflected direction, and the weight `G2 / G1(o)` for height-correlated masking,
//! `(1 + Lambda(o)) / (1 + Lambda(o) + Lambda(i))`, all in `f32`. Texel sums are `f64`, so the
//! yardstick's error is the method's and its precision's, not a summation artefact.

use crate::integrate::sobol::{OwenSobol, mix_seed};
use crate::model::RoughnessConvention;
use crate::table::axis::{Axis, Grid, MuMapping};
use rayon::prelude::*;

/// GGX `Lambda` from `tan^2(theta)` (`docs/physics.md`), in `f32`.
fn lambda(alpha2: f32, tan2: f32) -> f32 {
    0.5 * ((1.0 + alpha2 * tan2).sqrt() - 1.0)
}

/// `E(mu)` of GGX with height-correlated masking at slope roughness `alpha`, from `samples`
/// points of one Owen-scrambled Sobol sequence seeded by `seed`, evaluated in `f32`.
#[must_use]
pub fn cycles_style_albedo(alpha: f32, mu: f32, samples: u32, seed: u64) -> f64 {
    let sobol = OwenSobol::new(seed);
    let so = (1.0 - mu * mu).max(0.0).sqrt();
    let (ox, oz) = (so, mu);
    let alpha2 = alpha * alpha;
    let lambda_o = if mu > 0.0 {
        lambda(alpha2, (so * so) / (mu * mu))
    } else {
        f32::INFINITY
    };
    // The stretched view.
    let (vx, vz) = {
        let (x, z) = (alpha * ox, oz);
        let length = (x * x + z * z).sqrt();
        (x / length, z / length)
    };
    // Heitz's basis around the stretched view `V = (vx, 0, vz)`: `T1 = normalize(-Vy, Vx, 0)`
    // (or `(1, 0, 0)` at normal incidence), `T2 = V x T1`.
    let (t1x, t1y) = if vx > 0.0 {
        (0.0f32, 1.0f32)
    } else {
        (1.0, 0.0)
    };
    let (t2x, t2y, t2z) = (-vz * t1y, vz * t1x, vx * t1y);
    let mut total = 0.0f64;
    for index in 0..samples {
        let u1 = sobol.sample(index, 0) as f32;
        let u2 = sobol.sample(index, 1) as f32;
        let r = u1.sqrt();
        let phi = 2.0 * std::f32::consts::PI * u2;
        let (sin_phi, cos_phi) = phi.sin_cos();
        let p1 = r * cos_phi;
        let mut p2 = r * sin_phi;
        let s = 0.5 * (1.0 + vz);
        p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
        let p3 = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        let nx = p1 * t1x + p2 * t2x + p3 * vx;
        let ny = p1 * t1y + p2 * t2y;
        let nz = p2 * t2z + p3 * vz;
        // Unstretch and normalise.
        let (mx, my, mz) = (alpha * nx, alpha * ny, nz.max(0.0));
        let length = (mx * mx + my * my + mz * mz).sqrt();
        let (mx, my, mz) = (mx / length, my / length, mz / length);
        let om = ox * mx + oz * mz;
        let (ix, iy, iz) = (2.0 * om * mx - ox, 2.0 * om * my, 2.0 * om * mz - oz);
        if iz <= 0.0 || !lambda_o.is_finite() {
            continue;
        }
        let lambda_i = lambda(alpha2, (ix * ix + iy * iy) / (iz * iz));
        let weight = (1.0 + lambda_o) / (1.0 + lambda_o + lambda_i);
        total += f64::from(weight);
    }
    total / f64::from(samples)
}

/// The yardstick table: `size x size` texels over Cycles' axes (perceptual roughness and `mu`,
/// both linear over nodes `i / (size - 1)`, clamped to 1e-4 as Cycles does), `samples` per
/// texel, texels in parallel. Row-major, roughness slowest.
#[must_use]
pub fn cycles_style_table(size: usize, samples: u32) -> Vec<f64> {
    let roughness = Axis::Roughness {
        size,
        convention: RoughnessConvention::Perceptual,
        grid: Grid::Nodes,
        spacing: crate::table::axis::RoughnessSpacing::Linear,
    };
    let mu_axis = Axis::Mu {
        size,
        mapping: MuMapping::Linear,
        grid: Grid::Nodes,
    };
    (0..size * size)
        .into_par_iter()
        .map(|k| {
            let (row, column) = (k / size, k % size);
            let alpha = roughness.alpha(row).max(1e-4) as f32;
            let mu = mu_axis.value_at(column, 0.0, 1.0).max(1e-4) as f32;
            cycles_style_albedo(alpha, mu, samples, mix_seed(&[0x6379_636c, k as u64]))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::reference::{ReferenceSettings, reference_albedo};
    use crate::model::{Masking, Model, Ndf};

    /// The yardstick is a correct estimator: near the reference at ordinary points (2^14 Sobol
    /// points give errors around 1e-5 there; f32 rounding of 2^14 weights adds ~1e-7), and its
    /// table has Cycles' shape.
    #[test]
    fn agrees_with_the_reference() {
        let model = Model {
            ndf: Ndf::Ggx,
            masking: Masking::HeightCorrelated,
        };
        for (alpha, mu) in [(1.0, 1.0), (0.25, 0.5), (0.5, 0.1), (0.04, 0.8)] {
            let truth = reference_albedo(model, alpha, mu, &ReferenceSettings::default()).value;
            let got = cycles_style_albedo(alpha as f32, mu as f32, 1 << 14, 7);
            assert!(
                (got - truth).abs() < 5e-5,
                "alpha {alpha} mu {mu}: {got} vs {truth}"
            );
        }
        let table = cycles_style_table(4, 1 << 8);
        assert_eq!(table.len(), 16);
        assert!(table.iter().all(|v| (0.0..=1.0).contains(v)));
    }
}

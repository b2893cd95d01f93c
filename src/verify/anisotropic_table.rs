//! The white furnace of an anisotropic lobe compensated with kiln's anisotropic table
//! ([`crate::table::anisotropic`]), at points between its samples.
//!
//! At each point `(r, a, mu, phi)` (drawn from a seeded sequence, uniform in `r`, `a`, `mu` and
//! the azimuth over `[0, pi/2]`), the truth is the anisotropic reference `E` and the table gives
//! `E_lookup`. Turquin's scaling of the lobe by `1 / E_lookup` reflects `E / E_lookup`: its
//! deviation is `E / E_lookup - 1`. Kulla-Conty's lobe `(1 - E_lookup(o)) (1 - E_lookup(i)) /
//! (pi (1 - E_avg))` adds `(1 - E_lookup(o)) (1 - A) / (1 - E_avg)`, with `A` the average of the
//! lookup itself over the hemisphere at `(r, a)` (by quadrature, [`lookup_average`]) and `E_avg` the table's
//! average read as a renderer reads it: its deviation is `E + that - 1`.

use crate::integrate::anisotropic::reference_anisotropic_albedo;
use crate::integrate::reference::ReferenceSettings;
use crate::integrate::sobol::{hash32, mix_seed};
use crate::model::AnisotropicGgx;
use crate::table::anisotropic::{AnisotropicTable, MeasuredFurnace, SMOOTH_R, hemisphere_average};
use rayon::prelude::*;
use serde::Serialize;

/// The truth's tolerance.
pub const TRUTH_TOLERANCE: f64 = 1e-8;

/// One point of the furnace.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FurnacePoint {
    pub roughness: f64,
    pub anisotropy: f64,
    pub mu: f64,
    pub phi: f64,
    /// The lobe's `E` (the reference).
    pub truth: f64,
    pub lookup: f64,
    /// `E / E_lookup - 1`.
    pub turquin: f64,
    /// `E + (1 - E_lookup) (1 - A) / (1 - E_avg) - 1`.
    pub kulla_conty: f64,
}

/// What [`anisotropic_furnace`] measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AnisotropicFurnace {
    pub points: usize,
    /// The smallest roughness drawn.
    pub min_roughness: f64,
    pub max_lookup_error: f64,
    pub worst_lookup: FurnacePoint,
    pub max_turquin: f64,
    pub worst_turquin: FurnacePoint,
    pub max_kulla_conty: f64,
    pub worst_kulla_conty: FurnacePoint,
    pub truth_tolerance: f64,
    /// Every point, in the order drawn.
    #[serde(skip)]
    pub compared: Vec<FurnacePoint>,
}

impl AnisotropicFurnace {
    /// What a table's file states of this furnace.
    #[must_use]
    pub fn measured(&self) -> MeasuredFurnace {
        MeasuredFurnace {
            points: self.points,
            max_lookup_error: self.max_lookup_error,
            max_turquin: self.max_turquin,
            max_kulla_conty: self.max_kulla_conty,
        }
    }
}

/// The average of `E_lookup` over the hemisphere at `(r, a)`
/// ([`crate::table::anisotropic::hemisphere_average`] of the lookup).
#[must_use]
pub fn lookup_average(table: &AnisotropicTable, r: f64, a: f64) -> f64 {
    let (alpha_x, alpha_y) = table.convention.alphas(r.max(SMOOTH_R).powi(2), a);
    hemisphere_average(
        |mu, phi| table.lookup(mu, phi, r, a),
        alpha_x,
        alpha_y,
        table.sizes.mu,
        table.sizes.azimuth,
    )
}

/// Checks the furnace's smallest roughness: in `[0, 1)`.
pub fn check_min_roughness(min_roughness: f64) -> crate::Result<()> {
    if (0.0..1.0).contains(&min_roughness) {
        Ok(())
    } else {
        Err(crate::Error::InvalidInput(format!(
            "min roughness {min_roughness} is outside [0, 1)"
        )))
    }
}

/// The furnace at `points` points with `r >= min_roughness` (module docs), drawn from `seed`.
///
/// # Errors
/// `points` 0, or `min_roughness` outside `[0, 1)`.
pub fn anisotropic_furnace(
    table: &AnisotropicTable,
    points: usize,
    min_roughness: f64,
    seed: u64,
) -> crate::Result<AnisotropicFurnace> {
    if points == 0 {
        return Err(crate::Error::InvalidInput(
            "the furnace needs at least one point".into(),
        ));
    }
    check_min_roughness(min_roughness)?;
    let settings = ReferenceSettings {
        tolerance: TRUTH_TOLERANCE,
        ..ReferenceSettings::default()
    };
    let compared: Vec<FurnacePoint> = (0..points)
        .into_par_iter()
        .map(|k| {
            let unit = |d: u64| {
                let word = hash32(mix_seed(&[seed, k as u64, d]) as u32);
                (f64::from(word) + 0.5) / 4_294_967_296.0
            };
            let r = min_roughness + (1.0 - min_roughness) * unit(0);
            let a = table.max_anisotropy * unit(1);
            let mu = unit(2);
            let phi = std::f64::consts::FRAC_PI_2 * unit(3);
            let (alpha_x, alpha_y) = table.convention.alphas(r * r, a);
            let ndf = AnisotropicGgx { alpha_x, alpha_y };
            let truth = reference_anisotropic_albedo(ndf, mu, phi, &settings).value;
            let lookup = table.lookup(mu, phi, r, a);
            let average = table.lookup_average(r, a);
            let lost = 1.0 - average;
            let added = if lost > 1e-12 {
                (1.0 - lookup) * (1.0 - lookup_average(table, r, a)) / lost
            } else {
                1.0 - lookup
            };
            FurnacePoint {
                roughness: r,
                anisotropy: a,
                mu,
                phi,
                truth,
                lookup,
                turquin: truth / lookup - 1.0,
                kulla_conty: truth + added - 1.0,
            }
        })
        .collect();
    let worst = |key: &dyn Fn(&FurnacePoint) -> f64| {
        let p = *compared
            .iter()
            .max_by(|x, y| key(x).abs().total_cmp(&key(y).abs()))
            .expect("at least one point");
        (key(&p).abs(), p)
    };
    let (max_lookup_error, worst_lookup) = worst(&|p| p.lookup - p.truth);
    let (max_turquin, worst_turquin) = worst(&|p| p.turquin);
    let (max_kulla_conty, worst_kulla_conty) = worst(&|p| p.kulla_conty);
    Ok(AnisotropicFurnace {
        points,
        min_roughness,
        max_lookup_error,
        worst_lookup,
        max_turquin,
        worst_turquin,
        max_kulla_conty,
        worst_kulla_conty,
        truth_tolerance: TRUTH_TOLERANCE,
        compared,
    })
}

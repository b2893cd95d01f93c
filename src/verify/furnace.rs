//! The white furnace test of a table pair: with a table's own `E` and `E_avg` lookups, the
//! Kulla-Conty multiple-scattering lobe must give back exactly the energy single scattering loses.
//!
//! Kulla and Conty 2017 ("Revisiting Physically Based Shading at Imageworks", SIGGRAPH course;
//! `docs/physics.md`, "Kulla-Conty quantities"):
//! `f_ms(o, i) = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))`, whose albedo is
//! `∫ f_ms mu_i dω_i = (1 - E(mu_o)) (1 - Ē) / (1 - E_avg)` with `1 - Ē = 2 ∫ (1 - E(mu)) mu dmu`.
//! So `E(mu_o) + ∫ f_ms mu_i dω_i - 1 = (1 - E(mu_o)) ((1 - Ē) / (1 - E_avg) - 1)`: the
//! deviation vanishes when the `E_avg` lookup is the average of the `E` lookup. Here `E` and
//! `E_avg` are the tables' bilinear lookups ([`Table::lookup_one_minus`], `1 - E` read directly),
//! and `1 - Ē` is integrated by adaptive Gauss-Kronrod over `mu`, split at the `E` table's nodes
//! (where its lookup has kinks), to a relative accuracy far below the deviations reported.
//!
//! What it shows: the deviation is `1 - E(mu_o)` times the relative mismatch of `1 - E_avg`. At
//! small roughness `1 - E_avg` is tiny (7.4e-6 at `alpha = 1e-3`, GGX) while `1 - E(mu_o)`
//! reaches 0.11 in the grazing layer, so a lookup error far below the table's `E` error becomes
//! a visible energy error there.

use crate::integrate::gauss_kronrod::integrate_pieces;
use crate::table::axis::Axis;
use crate::table::{Quantity, Table};
use crate::{Error, Result};
use serde::Serialize;

/// The furnace test at one roughness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FurnaceRow {
    /// Roughness in the `E` table's convention.
    pub roughness: f64,
    pub alpha: f64,
    /// `1 - E_avg` from the `E_avg` table's lookup.
    pub one_minus_e_avg: f64,
    /// `1 - Ē = 2 ∫ (1 - E(mu)) mu dmu` of the `E` table's lookup.
    pub one_minus_e_avg_of_e: f64,
    /// `(1 - Ē) / (1 - E_avg) - 1`.
    pub relative_mismatch: f64,
    /// The `mu_o` where the deviation is largest in magnitude, and the deviation there
    /// (`E + albedo(f_ms) - 1`: positive when the lobe adds energy).
    pub worst_mu: f64,
    pub deviation: f64,
}

/// The furnace test over a roughness ladder.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FurnaceReport {
    pub rows: Vec<FurnaceRow>,
    /// The largest `|deviation|` over every row.
    pub max_deviation: f64,
    pub worst: FurnaceRow,
}

/// Runs the furnace test of `e` (an `E` table) with `e_avg` (the `E_avg` table of the same
/// model) at roughness `t = j / (density N)`, `j = 0 ..= density N` of the `E` table's axis, and
/// at each roughness over `mu` at the same density plus grazing probes down to `mu = 0`.
///
/// # Errors
/// When the tables are not an `E` and an `E_avg` table of the same model.
pub fn furnace(e: &Table, e_avg: &Table, density: usize) -> Result<FurnaceReport> {
    if e.spec.quantity != Quantity::E || e_avg.spec.quantity != Quantity::EAvg {
        return Err(Error::InvalidInput(format!(
            "the furnace test needs an E table and an E_avg table (got {} and {})",
            e.spec.quantity.symbol(),
            e_avg.spec.quantity.symbol()
        )));
    }
    if e.spec.model != e_avg.spec.model {
        return Err(Error::InvalidInput(format!(
            "the E table is for {} {} but the E_avg table for {} {}",
            e.spec.model.ndf, e.spec.model.masking, e_avg.spec.model.ndf, e_avg.spec.model.masking
        )));
    }
    let Some(Axis::Mu {
        size: n_mu,
        mapping,
        grid,
    }) = e.spec.mu
    else {
        unreachable!("an E table has a mu axis")
    };
    let convention = e.spec.roughness_convention();
    let avg_convention = e_avg.spec.roughness_convention();
    let steps = |n: usize| density.max(1) * n;
    let rows: Vec<FurnaceRow> = (0..=steps(e.spec.roughness_axis().size()))
        .map(|j| {
            let roughness = j as f64 / steps(e.spec.roughness_axis().size()) as f64;
            let alpha = convention.to_alpha(roughness);
            let loss = |mu: f64| e.lookup_one_minus(mu, roughness);
            // The E lookup is smooth between the mu of its nodes (and of the clamp edges).
            let mut breaks: Vec<f64> = (0..n_mu)
                .map(|i| mapping.mu(grid.coordinate(i, n_mu), alpha))
                .chain([0.0, 1.0])
                .collect();
            breaks.sort_by(f64::total_cmp);
            breaks.dedup();
            let integral =
                integrate_pieces(&mut |mu: f64| [2.0 * mu * loss(mu)], &breaks, 1e-16, 20_000);
            let of_e = integral.value[0];
            let one_minus_e_avg = e_avg.lookup_one_minus(1.0, avg_convention.from_alpha(alpha));
            // The lobe's albedo is (1 - E(mu_o)) * ratio; where 1 - E_avg = 0 (a mirror) f_ms is
            // taken as 0 (`kulla_conty::multiple_scattering`), so the ratio is 0.
            let ratio = if one_minus_e_avg > 0.0 {
                of_e / one_minus_e_avg
            } else {
                0.0
            };
            let mut mus: Vec<f64> = (0..=steps(n_mu))
                .map(|k| mapping.mu(k as f64 / steps(n_mu) as f64, alpha))
                .collect();
            mus.extend(super::grazing_probes());
            let (worst_mu, deviation) = mus
                .into_iter()
                .map(|mu| {
                    let l = loss(mu);
                    (mu, if l == 0.0 { 0.0 } else { l * (ratio - 1.0) })
                })
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .expect("mu points");
            FurnaceRow {
                roughness,
                alpha,
                one_minus_e_avg,
                one_minus_e_avg_of_e: of_e,
                relative_mismatch: if of_e == 0.0 && one_minus_e_avg == 0.0 {
                    0.0
                } else {
                    ratio - 1.0
                },
                worst_mu,
                deviation,
            }
        })
        .collect();
    let worst = *rows
        .iter()
        .max_by(|a, b| a.deviation.abs().total_cmp(&b.deviation.abs()))
        .expect("rows");
    Ok(FurnaceReport {
        max_deviation: worst.deviation.abs(),
        worst,
        rows,
    })
}

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
//! a visible energy error there (0.128 for the default tables with the exact `E_avg`). Normalised
//! by kiln's `f_ms_norm` instead ([`crate::table::normalisation`]), the average of the lookup
//! itself, the lobe closes the furnace to 4.1e-6. [`turquin`] checks the other compensation
//! form, single scattering scaled by `1 / E`.

use crate::table::axis::Axis;
use crate::table::normalisation::{normalisation_lookup, one_minus_lookup_average};
use crate::table::{Quantity, Table, TableSpec};
use crate::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The furnace test at one roughness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FurnaceRow {
    /// Roughness in the `E` table's convention.
    pub roughness: f64,
    pub alpha: f64,
    /// The lobe's normalisation `1 - E_avg` as the renderer looks it up: from the `f_ms_norm`
    /// table, or from an `E_avg` table.
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

/// The roughness bands the report summarises (in the E table's roughness coordinate).
pub const BAND_EDGES: [f64; 7] = [0.0, 0.01, 0.05, 0.1, 0.25, 0.5, 1.0];

/// The worst deviation in one roughness band `[from, to)` (`[from, 1]` for the last).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FurnaceBand {
    pub from: f64,
    pub to: f64,
    pub max_deviation: f64,
    pub worst_roughness: f64,
    pub worst_mu: f64,
}

/// The furnace test over a roughness ladder.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FurnaceReport {
    /// What normalised the lobe: `f_ms_norm` (the average of the E table's lookup) or `E_avg`.
    pub normalisation: String,
    /// The worst deviation per roughness band ([`BAND_EDGES`]).
    pub bands: Vec<FurnaceBand>,
    pub rows: Vec<FurnaceRow>,
    /// The largest `|deviation|` over every row.
    pub max_deviation: f64,
    pub worst: FurnaceRow,
}

/// At `roughness` (in `e`'s convention): `1 - Ē` of `e`'s lookup, the lobe's `1 - E_avg` as a
/// renderer looks it up in `normalisation` (`f_ms_norm` or `E_avg`), and their ratio, which
/// scales the lobe's albedo `(1 - E(mu_o)) * ratio`. Where `1 - E_avg` is 0 (a mirror) `f_ms` is
/// taken as 0 (`kulla_conty::multiple_scattering`), so the ratio is 0.
fn lobe_ratio(e: &Table, normalisation: &Table, roughness: f64) -> (f64, f64, f64) {
    let (of_e, _) = one_minus_lookup_average(e, roughness);
    let alpha = e.spec.roughness_convention().to_alpha(roughness);
    let at = normalisation.spec.roughness_convention().from_alpha(alpha);
    let one_minus_e_avg = match normalisation.spec.quantity {
        Quantity::FMsNorm => normalisation_lookup(normalisation, at),
        _ => normalisation.lookup_one_minus(1.0, at),
    };
    let ratio = if one_minus_e_avg >= f64::MIN_POSITIVE {
        of_e / one_minus_e_avg
    } else {
        0.0
    };
    (of_e, one_minus_e_avg, ratio)
}

/// `E + albedo(f_ms) - 1 = (1 - E(mu_o)) (ratio - 1)`, 0 where nothing is lost.
fn lobe_deviation(loss: f64, ratio: f64) -> f64 {
    if loss == 0.0 {
        0.0
    } else {
        loss * (ratio - 1.0)
    }
}

/// Turquin's deviation `E_true / E_lookup - 1` at one point of an E or E_dielectric table
/// (`eta` the relative index for glass).
fn turquin_deviation(
    e: &Table,
    alpha: f64,
    mu: f64,
    eta: Option<f64>,
    reference: &crate::integrate::reference::ReferenceSettings,
) -> f64 {
    let roughness = e.spec.roughness_convention().from_alpha(alpha);
    let at = super::Coordinates {
        alpha,
        mu: Some(mu),
        eta,
    };
    let truth = e.spec.integral().reference(at, reference).value;
    let lookup = e.lookup_eta(mu, roughness, eta.unwrap_or(1.0));
    if lookup > 0.0 {
        truth / lookup - 1.0
    } else {
        0.0
    }
}

/// The roughness ladder of the furnace test of an E table with `rows` rows: steps of
/// `1 / (density (rows - 1))` (at least four per texel) over [0, 1], 400 more steps below 0.1,
/// where the loss of a mirror-like surface hides in the grazing layer, and the midpoints
/// between the nodes of the `f_ms_norm` table of a nodes-grid E table (with the refined start
/// of [`crate::table::normalisation::REFINED_START`] and without it).
#[must_use]
pub fn roughness_ladder(rows: usize, density: usize) -> Vec<f64> {
    let steps = density.max(4) * (rows.max(2) - 1);
    let mut ladder: Vec<f64> = (0..=steps).map(|j| j as f64 / steps as f64).collect();
    ladder.extend((1..400).map(|j| 0.1 * j as f64 / 400.0));
    // Halfway between the nodes of the f_ms_norm table, where its interpolation errs most
    // (with kiln's refined start, and without it as older files have it).
    use crate::table::normalisation::{REFINED_START, SUBDIVISIONS};
    let cells = rows.max(2) - 1;
    for per_cell in [SUBDIVISIONS, REFINED_START.subdivisions] {
        let fine = per_cell * cells;
        let refined = if per_cell == SUBDIVISIONS {
            fine
        } else {
            REFINED_START.cells.min(cells) * per_cell
        };
        ladder.extend((0..refined).map(|j| (j as f64 + 0.5) / fine as f64));
    }
    ladder.sort_by(f64::total_cmp);
    ladder.dedup();
    ladder
}

/// Runs the furnace test of `e` (an `E` table) with `normalisation`, the table that gives the
/// lobe's `1 - E_avg`: kiln's `f_ms_norm` (the average of `e`'s own lookup,
/// [`crate::table::normalisation`]) or an `E_avg` table of the same model (the exact average),
/// at every roughness of [`roughness_ladder`] and at each over `mu` at the same density plus
/// grazing probes down to `mu = 0`.
///
/// # Errors
/// When the tables are not an `E` table and an `E_avg` or `f_ms_norm` table of the same model.
pub fn furnace(e: &Table, normalisation: &Table, density: usize) -> Result<FurnaceReport> {
    let quantity = normalisation.spec.quantity;
    if e.spec.quantity != Quantity::E || !matches!(quantity, Quantity::EAvg | Quantity::FMsNorm) {
        return Err(Error::InvalidInput(format!(
            "the furnace test needs an E table and its E_avg or f_ms_norm table (got {} and {})",
            e.spec.quantity.symbol(),
            quantity.symbol()
        )));
    }
    if e.spec.model != normalisation.spec.model {
        return Err(Error::InvalidInput(format!(
            "the E table is for {} but the {} table for {}",
            e.spec.model,
            quantity.symbol(),
            normalisation.spec.model
        )));
    }
    let Some(Axis::Mu {
        size: n_mu,
        mapping,
        grid: _,
    }) = e.spec.mu
    else {
        unreachable!("an E table has a mu axis")
    };
    let convention = e.spec.roughness_convention();
    let mu_steps = density.max(4) * n_mu;
    let rows: Vec<FurnaceRow> = roughness_ladder(e.spec.roughness_axis().size(), density)
        .into_iter()
        .map(|roughness| {
            let alpha = convention.to_alpha(roughness);
            let loss = |mu: f64| e.lookup_one_minus(mu, roughness);
            let (of_e, one_minus_e_avg, ratio) = lobe_ratio(e, normalisation, roughness);
            let mut mus: Vec<f64> = (0..=mu_steps)
                .map(|k| mapping.mu(k as f64 / mu_steps as f64, alpha, n_mu))
                .collect();
            mus.extend(super::grazing_probes());
            let (worst_mu, deviation) = mus
                .into_iter()
                .map(|mu| (mu, lobe_deviation(loss(mu), ratio)))
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
    let bands = BAND_EDGES
        .windows(2)
        .filter_map(|edge| {
            let (from, to) = (edge[0], edge[1]);
            rows.iter()
                .filter(|row| row.roughness >= from && (row.roughness < to || to == 1.0))
                .max_by(|a, b| a.deviation.abs().total_cmp(&b.deviation.abs()))
                .map(|row| FurnaceBand {
                    from,
                    to,
                    max_deviation: row.deviation.abs(),
                    worst_roughness: row.roughness,
                    worst_mu: row.worst_mu,
                })
        })
        .collect();
    Ok(FurnaceReport {
        bands,
        normalisation: quantity.symbol().to_string(),
        max_deviation: worst.deviation.abs(),
        worst,
        rows,
    })
}

/// The audit of an `f_ms_norm` table against what it stands for: the average of its E table's
/// lookup, `1 - Ē`, recomputed at its nodes and halfway between them (relative errors of
/// [`normalisation_lookup`]; `x = 0`, where both are 0, is left out).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NormalisationAudit {
    pub quantity: String,
    pub nodes: usize,
    pub node_max_relative_error: f64,
    pub lookup_points: usize,
    pub lookup_max_relative_error: f64,
    /// Where the lookup's relative error is largest.
    pub worst_roughness: f64,
}

/// Audits `norm` (an `f_ms_norm` table) against the lookup of `e`, the E table it was derived
/// from ([`NormalisationAudit`]).
///
/// # Errors
/// When `norm` is not an `f_ms_norm` table derived from `e`.
pub fn audit_normalisation(e: &Table, norm: &Table) -> Result<NormalisationAudit> {
    if norm.spec.quantity != Quantity::FMsNorm || norm.spec.lookup_of.as_deref() != Some(&e.spec) {
        return Err(Error::InvalidInput(format!(
            "{} was not derived from the E table {} (another size, axis, model or accuracy)",
            norm.spec.id(),
            e.spec.id()
        )));
    }
    let n = norm.spec.len();
    let axis = norm.spec.roughness_axis();
    let line = crate::table::normalisation::NodeLine::of(&norm.spec);
    // Nodes and the points halfway between them, in texture coordinates, as roughness values.
    let at = |i: f64| axis.roughness_at_coordinate(line.coordinate(i));
    let relative = |x: f64| -> f64 {
        let (truth, _) = one_minus_lookup_average(e, x);
        let table = normalisation_lookup(norm, x);
        if truth == 0.0 {
            table.abs()
        } else {
            (table / truth - 1.0).abs()
        }
    };
    let nodes: Vec<f64> = (1..n).map(|i| at(i as f64)).collect();
    let between: Vec<f64> = (0..n - 1).map(|i| at(i as f64 + 0.5)).collect();
    let node_max_relative_error = crate::stats::max_or_nan(nodes.iter().map(|&x| relative(x)));
    let (worst_roughness, lookup_max_relative_error) = between
        .iter()
        .map(|&x| (x, relative(x)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0.0, 0.0));
    Ok(NormalisationAudit {
        quantity: Quantity::FMsNorm.symbol().to_string(),
        nodes: nodes.len(),
        node_max_relative_error,
        lookup_points: between.len(),
        lookup_max_relative_error,
        worst_roughness,
    })
}

/// The energy-compensation forms the furnace test checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Form {
    /// Kulla and Conty 2017: an added lobe `f_ms`, normalised by the `E_avg` or `f_ms_norm`
    /// table.
    KullaConty,
    /// Turquin 2019 (Filament, Unreal 5, Bevy, three.js, Cycles 4): single scattering scaled by
    /// `1 / E(mu_o)` (for `F = 1`; `1 + F0 (1 / E - 1)` in general), checked as
    /// `E_true(mu_o) / E_lookup(mu_o) - 1`.
    Turquin,
}

impl Form {
    /// The name in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Form::KullaConty => "kulla-conty",
            Form::Turquin => "turquin",
        }
    }
}

/// The forms a furnace test of a table of `spec` checks: `asked`, or by default both for an `E`
/// table and Turquin's for glass (`E_dielectric` from either side), whose Kulla-Conty lobe kiln
/// does not have.
///
/// # Errors
/// A table of another quantity (the furnace needs an `E` table with its normalisation), or
/// Kulla-Conty's form asked of glass.
pub fn forms_for(spec: &TableSpec, asked: Option<&[Form]>) -> Result<Vec<Form>> {
    let glass = matches!(
        spec.quantity,
        Quantity::EDielectric | Quantity::EDielectricInside
    );
    if !glass && spec.quantity != Quantity::E {
        return Err(Error::InvalidInput(format!(
            "it holds {}, and the white furnace tests an E table with its normalisation: give \
             the E file (NAME-E.EXT), whose f_ms_norm or E_avg is found beside it or given with \
             --average",
            spec.quantity.symbol()
        )));
    }
    if glass && asked.is_some_and(|f| f.contains(&Form::KullaConty)) {
        return Err(Error::InvalidInput(
            "it is a glass table: kiln checks Turquin's 1 / E compensation of it (--form \
             turquin); the Kulla-Conty lobe of glass is not in this version"
                .into(),
        ));
    }
    Ok(match asked {
        Some(forms) => forms.to_vec(),
        None if glass => vec![Form::Turquin],
        None => vec![Form::KullaConty, Form::Turquin],
    })
}

/// The file beside a kiln `E` table's file `path` (`NAME.EXT`, named as kiln names it) that
/// holds its Kulla-Conty normalisation: `f_ms_norm` if it is there, else `E_avg`.
///
/// # Errors
/// A file not named as kiln names the table, or neither file beside it.
pub fn normalisation_beside(path: &Path, spec: &TableSpec) -> Result<PathBuf> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if stem != spec.id() {
        return Err(Error::InvalidInput(format!(
            "{} is not named as kiln names its E table ({}.{extension}): give its f_ms_norm or \
             E_avg table with --average",
            path.display(),
            spec.id()
        )));
    }
    let norm = crate::table::normalisation::spec_for(spec).id();
    let average = TableSpec {
        quantity: Quantity::EAvg,
        mu: None,
        ..spec.clone()
    }
    .id();
    let candidates = [norm, average].map(|id| path.with_file_name(format!("{id}.{extension}")));
    candidates
        .iter()
        .find(|candidate| candidate.is_file())
        .cloned()
        .ok_or_else(|| {
            Error::InvalidInput(format!(
                "found neither {} nor {} beside {}: give the normalisation with --average",
                candidates[0].display(),
                candidates[1].display(),
                path.display()
            ))
        })
}

/// The estimated cost of [`turquin`] on a table of `spec` at `settings`' points, in seconds of
/// one core: each point is the reference at [`TURQUIN_TRUTH_TOLERANCE`], and a glass table's
/// points cost four times what the bake's figures say (measured at 1e-10: the 16 x 16 x 16
/// `E_dielectric`'s 65340 points took 137 s on 2 threads, 2026-12-03, 4.2 ms each).
#[must_use]
pub fn turquin_core_seconds(spec: &TableSpec, settings: &super::AuditSettings) -> f64 {
    let points = super::lookup_coordinate_count(spec, settings);
    let glass = if spec.ior.is_some() { 4.0 } else { 1.0 };
    let digits = (-TURQUIN_TRUTH_TOLERANCE.log10()).round() as u32;
    points as f64
        * glass
        * crate::integrate::cost::reference_seconds(spec.quantity, spec.model, digits)
}

/// The edges of the IOR bands a glass table's furnace report gives, on the index as the axis
/// lists it (`eta`, or `1 / eta` from inside): near 1 the grazing albedo changes fastest.
pub const ETA_BAND_EDGES: [f64; 7] = [1.0, 1.01, 1.05, 1.2, 1.5, 2.0, f64::INFINITY];

/// The worst deviation within one IOR band of a glass table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EtaBand {
    /// The band's edges on `eta` (or `1 / eta`), lower included.
    pub lower: f64,
    pub upper: f64,
    pub max_deviation: f64,
    pub worst_mu: f64,
    pub worst_roughness: f64,
    pub worst_eta: f64,
}

/// The worst deviation of one compensation form.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FormReport {
    pub form: Form,
    pub max_deviation: f64,
    pub worst_mu: f64,
    pub worst_roughness: f64,
    /// The relative index there, for a glass table.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_eta: Option<f64>,
    /// Where the worst deviation is: the compensated albedo's excess over 1 (negative: energy
    /// still lost).
    pub deviation: f64,
    /// For a glass table, the worst deviation per IOR band ([`ETA_BAND_EDGES`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub eta_bands: Vec<EtaBand>,
    /// For a glass table, its points binned for a picture ([`glass_map`]); not in reports.
    #[serde(skip)]
    pub map: Option<FurnaceMap>,
}

impl FormReport {
    /// The Kulla-Conty form's summary of a [`FurnaceReport`].
    #[must_use]
    pub fn of_kulla_conty(report: &FurnaceReport) -> Self {
        Self {
            form: Form::KullaConty,
            max_deviation: report.max_deviation,
            worst_mu: report.worst.worst_mu,
            worst_roughness: report.worst.roughness,
            worst_eta: None,
            map: None,
            deviation: report.worst.deviation,
            eta_bands: Vec::new(),
        }
    }
}

/// The reference settings for the truth of Turquin's deviation, at
/// [`TURQUIN_TRUTH_TOLERANCE`].
fn truth_settings() -> crate::integrate::reference::ReferenceSettings {
    crate::integrate::reference::ReferenceSettings {
        tolerance: TURQUIN_TRUTH_TOLERANCE,
        ..Default::default()
    }
}

/// The reference's tolerance for the truth of Turquin's deviation `E_true / E_lookup - 1`: the
/// deviations reported are 1e-5 and more, printed to three digits, so a truth to 1e-9 moves none
/// of them (the 16 x 16 x 16 glass tables' bands are the same at 1e-11), and at 1e-11 the glass
/// tables' truth near `eta = 1` costs seconds a point (their furnace took 139 s and 246 s at
/// 1e-11, 95 s and 106 s at 1e-9 with a build running beside them, one run each on 2 cores,
/// 2026-12-05).
pub const TURQUIN_TRUTH_TOLERANCE: f64 = 1e-9;

/// The furnace test of Turquin's compensation with an E table's lookup: single scattering
/// scaled by `1 / E_lookup(mu_o)` returns `E_true(mu_o) / E_lookup(mu_o)` of the incident
/// energy (`F = 1`), so the deviation is `E_true / E_lookup - 1`, the relative error of the
/// lookup. For glass (`E_dielectric`, from either side: the energy albedo `R + T`, the sample
/// weight Cycles divides by) the same at every IOR of the ladder, on the axis and between. Checked at the points of `kiln verify`'s lookup audit ([`super::lookup_coordinates`]:
/// a ladder of `1 / density` texel over both axes, ends included, and grazing probes down to
/// `mu = 0` on every roughness rung) against the reference quadrature; in parallel,
/// deterministic. `progress` is called once per point.
///
/// # Errors
/// When `e` is not an `E` table.
pub fn turquin(
    e: &Table,
    settings: &super::AuditSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<FormReport> {
    use rayon::prelude::*;
    if !matches!(
        e.spec.quantity,
        Quantity::E | Quantity::EDielectric | Quantity::EDielectricInside
    ) {
        return Err(Error::InvalidInput(format!(
            "Turquin's compensation divides by E: the furnace test needs an E or E_dielectric \
             table (got {})",
            e.spec.quantity.symbol()
        )));
    }
    let convention = e.spec.roughness_convention();
    let reference = truth_settings();
    let deviations: Vec<(f64, f64, Option<f64>, f64)> =
        super::lookup_coordinates(&e.spec, settings)
            .into_par_iter()
            .map(|at| {
                let mu = at.mu.unwrap_or(1.0);
                let deviation = turquin_deviation(e, at.alpha, mu, at.eta, &reference);
                progress();
                (mu, convention.from_alpha(at.alpha), at.eta, deviation)
            })
            .collect();
    let eta_bands = ETA_BAND_EDGES
        .windows(2)
        .filter_map(|edges| {
            let index = |eta: f64| if eta < 1.0 { 1.0 / eta } else { eta };
            deviations
                .iter()
                .filter_map(|d| d.2.map(|eta| (d, index(eta))))
                .filter(|(_, x)| (edges[0]..edges[1]).contains(x))
                .max_by(|a, b| a.0.3.abs().total_cmp(&b.0.3.abs()))
                .map(|(d, _)| EtaBand {
                    lower: edges[0],
                    upper: edges[1],
                    max_deviation: d.3.abs(),
                    worst_mu: d.0,
                    worst_roughness: d.1,
                    worst_eta: d.2.unwrap_or(1.0),
                })
        })
        .collect();
    let map = match e.spec.ior {
        Some(Axis::Ior { max, .. }) => Some(glass_map(&deviations, max.0, GLASS_MAP_CELLS)),
        _ => None,
    };
    let (worst_mu, worst_roughness, worst_eta, deviation) = deviations
        .into_iter()
        .max_by(|a, b| a.3.abs().total_cmp(&b.3.abs()))
        .unwrap_or((0.0, 0.0, None, 0.0));
    Ok(FormReport {
        form: Form::Turquin,
        max_deviation: deviation.abs(),
        worst_mu,
        worst_roughness,
        worst_eta,
        deviation,
        eta_bands,
        map,
    })
}

/// Rows (IOR) and columns (`mu`) of a glass table's furnace picture ([`glass_map`]): as many
/// as the 16 x 16 x 16 tables' audit points fill in every layout (48 rows left rows of the
/// glass layout's empty near `eta = 3`, whose IOR samples are sparser there).
pub const GLASS_MAP_CELLS: (usize, usize) = (24, 40);

/// Where a glass furnace point `(mu, eta)` falls on its picture ([`MapRows::Ior`]): across
/// `sqrt(mu)`, up `sqrt((eta - 1) / (eta_max - 1))`, `eta` as the IOR axis lists it (`1 / eta`
/// from inside). Physical coordinates, the same for every layout, so that two layouts' pictures
/// compare cell by cell; the square roots open the grazing layer and the band next to `eta = 1`.
#[must_use]
pub fn glass_map_position(mu: f64, eta: f64, eta_max: f64) -> (f64, f64) {
    let index = if eta < 1.0 { 1.0 / eta } else { eta };
    (
        mu.clamp(0.0, 1.0).sqrt(),
        ((index - 1.0) / (eta_max - 1.0)).clamp(0.0, 1.0).sqrt(),
    )
}

/// A glass table's furnace deviations `(mu, r, eta, deviation)` (the points of [`turquin`])
/// binned on a picture of `(rows, columns)` cells ([`glass_map_position`]): each cell the
/// deviation of largest magnitude among the points in it, over every roughness (NaN where none
/// falls).
#[must_use]
pub fn glass_map(
    deviations: &[(f64, f64, Option<f64>, f64)],
    eta_max: f64,
    (rows, columns): (usize, usize),
) -> FurnaceMap {
    let (rows, columns) = (rows.max(2), columns.max(2));
    let mut deviation = vec![vec![f64::NAN; columns]; rows];
    let bin = |x: f64, n: usize| ((x * n as f64) as usize).min(n - 1);
    for &(mu, _, eta, d) in deviations {
        let (x, y) = glass_map_position(mu, eta.unwrap_or(1.0), eta_max);
        let cell = &mut deviation[bin(y, rows)][bin(x, columns)];
        if cell.is_nan() || d.abs() > cell.abs() {
            *cell = d;
        }
    }
    FurnaceMap {
        form: Form::Turquin,
        rows,
        columns,
        rows_are: MapRows::Ior { eta_max },
        deviation,
    }
}

/// The deviation of each compensation form over a grid, for a picture: rows of roughness
/// `r_j = j / (rows - 1)`, columns of the E table's mu coordinate `t_k = k / (columns - 1)`
/// (so that the grazing layer, at fixed `t` on an adaptive axis, stays visible at every
/// roughness), `map[j][k]` the deviation there. Kulla-Conty with `normalisation` as
/// [`furnace`] computes it; Turquin as [`turquin`] (against the reference: `rows * columns`
/// reference evaluations, in parallel).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FurnaceMap {
    pub form: Form,
    pub rows: usize,
    pub columns: usize,
    /// What the rows and columns are.
    pub rows_are: MapRows,
    pub deviation: Vec<Vec<f64>>,
}

/// The coordinates of a [`FurnaceMap`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum MapRows {
    /// Rows of roughness `r_j = j / (rows - 1)`, columns of the E table's mu coordinate
    /// `t_k = k / (columns - 1)`, each cell the deviation there.
    Roughness,
    /// A glass table's cells ([`glass_map`]): rows `sqrt((eta - 1) / (eta_max - 1))`, columns
    /// `sqrt(mu)`, each `1 / cells` wide, the cell's worst deviation over every roughness.
    Ior { eta_max: f64 },
}

/// [`FurnaceMap`]s of the forms asked for (Kulla-Conty needs `normalisation`).
///
/// # Errors
/// As [`furnace`] and [`turquin`].
pub fn furnace_maps(
    e: &Table,
    normalisation: Option<&Table>,
    forms: &[Form],
    rows: usize,
    columns: usize,
) -> Result<Vec<FurnaceMap>> {
    use rayon::prelude::*;
    let Some(Axis::Mu {
        mapping,
        size: mu_size,
        ..
    }) = e.spec.mu
    else {
        return Err(Error::InvalidInput("a furnace map needs an E table".into()));
    };
    if forms.contains(&Form::KullaConty) && normalisation.is_none() {
        return Err(Error::InvalidInput(
            "the Kulla-Conty map needs the lobe's normalisation table".into(),
        ));
    }
    let convention = e.spec.roughness_convention();
    let coordinate = |n: usize, i: usize| i as f64 / (n.max(2) - 1) as f64;
    let reference = truth_settings();
    let mut maps = Vec::new();
    for &form in forms {
        let deviation: Vec<Vec<f64>> = (0..rows)
            .into_par_iter()
            .map(|j| {
                let roughness = coordinate(rows, j);
                let alpha = convention.to_alpha(roughness);
                let ratio = match (form, normalisation) {
                    (Form::KullaConty, Some(norm)) => lobe_ratio(e, norm, roughness).2,
                    _ => 1.0,
                };
                (0..columns)
                    .map(|k| {
                        let mu = mapping.mu(coordinate(columns, k), alpha, mu_size);
                        match form {
                            Form::KullaConty => {
                                lobe_deviation(e.lookup_one_minus(mu, roughness), ratio)
                            }
                            Form::Turquin => turquin_deviation(e, alpha, mu, None, &reference),
                        }
                    })
                    .collect()
            })
            .collect();
        maps.push(FurnaceMap {
            form,
            rows,
            columns,
            rows_are: MapRows::Roughness,
            deviation,
        });
    }
    Ok(maps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::TableSpec;
    use crate::table::axis::{Grid, MuMapping};
    use crate::table::normalisation::derive;
    use crate::table::test_e_spec;
    use crate::verify::tests::{e_avg_spec, glass_spec, table};

    /// A 5 x 4 E table (rows on nodes) whose loss `1 - E` is `loss(r)` on every column, and the
    /// E_avg table of the same model whose `1 - E_avg` is `avg(r)`.
    fn tables(loss: impl Fn(f64) -> f64, avg: impl Fn(f64) -> f64) -> (Table, Table) {
        let spec = test_e_spec(5, 4, Grid::Nodes, MuMapping::Linear);
        let e = table(
            spec,
            (0..20).map(|k| 1.0 - loss((k / 4) as f64 / 4.0)).collect(),
        );
        let e_avg = table(
            e_avg_spec(5),
            (0..5).map(|k| 1.0 - avg(k as f64 / 4.0)).collect(),
        );
        (e, e_avg)
    }

    #[test]
    fn the_lobe_adds_the_mismatch_of_its_normalisation() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        // The E lookup loses 0.1 r at every mu, so its average loss is 0.1 r; an E_avg table that
        // says half that doubles the lobe, which then adds 0.1 r too much at every mu.
        let (e, e_avg) = tables(|r| 0.1 * r, |r| 0.05 * r);
        let report = furnace(&e, &e_avg, 2).unwrap();
        assert_eq!(report.normalisation, "E_avg");
        assert_eq!(report.rows.len(), roughness_ladder(5, 2).len());
        for row in &report.rows {
            let r = row.roughness;
            assert!(close(row.alpha, r * r));
            assert!(close(row.one_minus_e_avg_of_e, 0.1 * r), "{row:?}");
            assert!(close(row.one_minus_e_avg, 0.05 * r), "{row:?}");
            if r == 0.0 {
                assert_eq!((row.relative_mismatch, row.deviation), (0.0, 0.0));
            } else {
                assert!(close(row.relative_mismatch, 1.0), "{row:?}");
                assert!(close(row.deviation, 0.1 * r), "{row:?}");
            }
        }
        assert!(close(report.max_deviation, 0.1));
        assert_eq!(report.worst.roughness, 1.0);
        // Six bands, each with its largest roughness: below 1/2 that is the midpoint of the
        // normalisation's last node interval there, 191.5 / 384 (all four cells refined).
        assert_eq!(report.bands.len(), 6);
        let band = report.bands[4];
        assert_eq!((band.from, band.to), (0.25, 0.5));
        assert_eq!(band.worst_roughness, 191.5 / 384.0);
        assert!(close(band.max_deviation, 0.1 * 191.5 / 384.0));
        let last = report.bands[5];
        assert_eq!((last.from, last.to, last.worst_roughness), (0.5, 1.0, 1.0));
        assert!(close(last.max_deviation, 0.1));
        assert!(report.bands[0].max_deviation < 1e-3);
        assert_eq!(FormReport::of_kulla_conty(&report).worst_roughness, 1.0);
        assert!(close(FormReport::of_kulla_conty(&report).deviation, 0.1));

        // The exact average closes the furnace.
        let (e, e_avg) = tables(|r| 0.1 * r, |r| 0.1 * r);
        assert!(furnace(&e, &e_avg, 2).unwrap().max_deviation < 1e-12);
    }

    /// Where the normalisation says nothing is lost (`1 - E_avg = 0`) the lobe is 0: the
    /// single-scattering loss stays lost, whatever the ratio would be.
    #[test]
    fn a_mirror_normalisation_gives_no_lobe() {
        let (e, e_avg) = tables(|_| 0.1, |r| 0.1 * r);
        let report = furnace(&e, &e_avg, 2).unwrap();
        let mirror = report.rows[0];
        assert_eq!(mirror.roughness, 0.0);
        assert!((mirror.deviation + 0.1).abs() < 1e-12, "{mirror:?}");
        assert!((mirror.relative_mismatch + 1.0).abs() < 1e-12);
        // The next rung, r = 1/4000: the lobe is 4000 times too strong.
        assert_eq!(report.worst.roughness, 0.1 / 400.0);
        assert!((report.max_deviation / 399.9 - 1.0).abs() < 1e-9);
    }

    #[test]
    fn the_lobes_deviation_is_the_loss_times_the_mismatch() {
        assert_eq!(lobe_deviation(0.0, 5.0), 0.0);
        assert_eq!(lobe_deviation(0.0, f64::INFINITY), 0.0);
        assert!((lobe_deviation(0.1, 1.5) - 0.05).abs() < 1e-15);
        assert!((lobe_deviation(0.2, 0.5) + 0.1).abs() < 1e-15);
    }

    /// A glass furnace picture: each cell keeps its points' deviation of largest magnitude
    /// (over roughness), with its sign; `1 / eta` from inside lands where `eta` does; cells no
    /// point falls in are NaN (drawn grey), not 0.
    #[test]
    fn the_glass_map_keeps_each_cells_worst_deviation() {
        assert_eq!(glass_map_position(0.25, 1.5, 3.0), (0.5, 0.5));
        let inside = glass_map_position(0.25, 1.0 / 1.5, 3.0);
        assert!((inside.0 - 0.5).abs() < 1e-15 && (inside.1 - 0.5).abs() < 1e-15);
        assert_eq!(glass_map_position(-1.0, 9.0, 3.0), (0.0, 1.0));
        let points = [
            (0.25, 0.1, Some(1.5), 1e-3),
            (0.26, 0.9, Some(1.5), -4e-3),
            (0.27, 0.5, Some(1.5), 2e-3),
            (0.0, 0.5, Some(1.0), 2e-2),
            (1.0, 0.5, Some(3.0), 5e-4),
        ];
        let map = glass_map(&points, 3.0, (4, 5));
        assert_eq!((map.rows, map.columns), (4, 5));
        assert_eq!(map.rows_are, MapRows::Ior { eta_max: 3.0 });
        // sqrt(0.25..0.27) = 0.5..0.52: column 2 of 5; sqrt(1/4) = 0.5: row 2 of 4.
        assert_eq!(map.deviation[2][2], -4e-3);
        assert_eq!(map.deviation[0][0], 2e-2);
        assert_eq!(map.deviation[3][4], 5e-4);
        let filled = map
            .deviation
            .iter()
            .flatten()
            .filter(|d| !d.is_nan())
            .count();
        assert_eq!(filled, 3);
    }

    #[test]
    fn the_ladder_holds_the_texels_the_grazing_decade_and_the_midpoints() {
        let ladder = roughness_ladder(5, 2);
        assert!(ladder.windows(2).all(|w| w[0] < w[1]));
        assert_eq!((ladder[0], *ladder.last().unwrap()), (0.0, 1.0));
        let has = |ladder: &[f64], x: f64| ladder.iter().any(|&y| (y - x).abs() < 1e-15);
        // Four steps a texel (density 2 is raised to 4) over 4 texels.
        assert!((0..=16).all(|j| has(&ladder, j as f64 / 16.0)));
        assert!((1..400).all(|j| has(&ladder, 0.1 * j as f64 / 400.0)));
        assert!((0..64).all(|j| has(&ladder, (j as f64 + 0.5) / 64.0)));
        // The midpoints of the refined start (all four cells here).
        assert!((0..384).all(|j| has(&ladder, (j as f64 + 0.5) / 384.0)));
        // 17 + 399 + 64 + 384, less 1/16, which the grazing decade holds too.
        assert_eq!(ladder.len(), 863);
        // On 32 rows, only the first four cells are refined.
        let long = roughness_ladder(33, 4);
        assert!(has(&long, 383.5 / 3072.0) && !has(&long, 384.5 / 3072.0));
        assert!(!has(&ladder, 17.0 / 32.0));
        assert!(has(&roughness_ladder(5, 8), 17.0 / 32.0));
        // One row is taken as two.
        assert!(has(&roughness_ladder(1, 4), 0.25));
    }

    #[test]
    fn the_furnace_needs_an_e_table_and_its_normalisation() {
        let (e, e_avg) = tables(|r| 0.1 * r, |r| 0.1 * r);
        let message = |r: Result<FurnaceReport>| r.unwrap_err().to_string();
        assert!(message(furnace(&e_avg, &e, 2)).contains("needs an E table and its E_avg"));
        assert!(message(furnace(&e, &e, 2)).contains("(got E and E)"));
        let beckmann = Table {
            spec: TableSpec {
                model: crate::model::Model {
                    ndf: crate::model::Ndf::Beckmann,
                    ..e_avg.spec.model
                },
                ..e_avg.spec.clone()
            },
            ..e_avg.clone()
        };
        assert!(message(furnace(&e, &beckmann, 2)).contains("the E table is for"));
    }

    #[test]
    fn a_normalisation_table_is_audited_against_its_e_tables_lookup() {
        let (e, _) = tables(|r| 0.1 * r, |r| r);
        let mut norm = derive(&e, String::new());
        let audit = audit_normalisation(&e, &norm).unwrap();
        let n = norm.spec.len();
        assert_eq!((audit.nodes, audit.lookup_points), (n - 1, n - 1));
        assert_eq!(audit.quantity, "f_ms_norm");
        assert!(audit.node_max_relative_error < 1e-12, "{audit:?}");
        assert!(audit.lookup_max_relative_error < 1e-12, "{audit:?}");
        // One node 1% high: 1% there, and halfway to its lower neighbour 1% of its share.
        assert_eq!(n, 65);
        norm.value[33] *= 1.01;
        let audit = audit_normalisation(&e, &norm).unwrap();
        assert!(
            (audit.node_max_relative_error - 0.01).abs() < 1e-12,
            "{audit:?}"
        );
        let share = 33.0 / 65.0;
        assert!((audit.lookup_max_relative_error - 0.01 * share).abs() < 1e-12);
        assert_eq!(audit.worst_roughness, 32.5 / 64.0);
        // The last node 1% high: its cell's midpoint is audited too.
        norm.value[33] /= 1.01;
        norm.value[64] *= 1.01;
        let audit = audit_normalisation(&e, &norm).unwrap();
        assert!((audit.lookup_max_relative_error - 0.01 * 64.0 / 127.0).abs() < 1e-12);
        assert_eq!(audit.worst_roughness, 63.5 / 64.0);
        // Another E table's normalisation is refused.
        let other = table(
            test_e_spec(5, 8, Grid::Nodes, MuMapping::Linear),
            vec![0.5; 40],
        );
        assert!(
            audit_normalisation(&other, &norm)
                .unwrap_err()
                .to_string()
                .contains("was not derived from the E table")
        );
    }

    #[test]
    fn forms_are_named_as_serde_names_them() {
        for form in [Form::KullaConty, Form::Turquin] {
            assert_eq!(
                serde_json::to_string(&form).unwrap(),
                format!("\"{}\"", form.name())
            );
        }
    }

    #[test]
    fn turquins_form_needs_e_and_leaves_a_zero_lookup_alone() {
        let (e, e_avg) = tables(|_| 1.0, |r| r);
        let message = turquin(&e_avg, &crate::verify::AuditSettings::default(), &|| {})
            .unwrap_err()
            .to_string();
        assert!(message.contains("needs an E or E_dielectric table (got E_avg)"));
        // E = 0 everywhere: nothing to divide by, no deviation (not infinity).
        let settings = crate::verify::AuditSettings {
            density: 1,
            ..crate::verify::AuditSettings::default()
        };
        let report = turquin(&e, &settings, &|| {}).unwrap();
        assert_eq!(report.max_deviation, 0.0);
        assert_eq!(report.form, Form::Turquin);
        assert!(report.eta_bands.is_empty());
    }

    #[test]
    fn furnace_maps_lay_the_deviation_over_roughness_and_mu() {
        let (e, e_avg) = tables(|r| 0.1 * r, |r| 0.05 * r);
        let maps = furnace_maps(&e, Some(&e_avg), &[Form::KullaConty], 3, 4).unwrap();
        assert_eq!(maps.len(), 1);
        assert_eq!((maps[0].rows, maps[0].columns), (3, 4));
        for (j, row) in maps[0].deviation.iter().enumerate() {
            assert_eq!(row.len(), 4);
            for &d in row {
                assert!((d - 0.05 * j as f64).abs() < 1e-12, "{j}: {d}");
            }
        }
        let message = |r: Result<Vec<FurnaceMap>>| r.unwrap_err().to_string();
        assert!(
            message(furnace_maps(&e, None, &[Form::KullaConty], 3, 4))
                .contains("needs the lobe's normalisation")
        );
        assert!(message(furnace_maps(&e_avg, None, &[Form::Turquin], 3, 4)).contains("E table"));
        // E = 0: Turquin's map is 0 (no division by zero).
        let (zero, _) = tables(|_| 1.0, |r| r);
        let maps = furnace_maps(&zero, None, &[Form::Turquin], 2, 2).unwrap();
        assert_eq!(maps[0].deviation, vec![vec![0.0; 2]; 2]);
    }

    /// Kulla-Conty's lobe normalised by kiln's `f_ms_norm` (the average of the E table's own
    /// lookup) closes the furnace of any E table; read as an E_avg table it would not.
    #[test]
    fn the_lobe_normalised_by_f_ms_norm_closes_the_furnace() {
        let (e, _) = tables(|r| 0.1 * r + 0.02, |r| r);
        let norm = derive(&e, String::new());
        let report = furnace(&e, &norm, 2).unwrap();
        assert_eq!(report.normalisation, "f_ms_norm");
        assert!(report.max_deviation < 1e-12, "{}", report.max_deviation);
    }

    /// Turquin's deviation is `E_true / E_lookup - 1`: against a table that looks up 0.8
    /// everywhere, `E_true / 0.8 - 1` at every point of the audit's ladder, by IOR band for glass
    /// (from inside, banded by `1 / eta`).
    #[test]
    fn turquins_deviation_is_the_truth_over_the_lookup() {
        let settings = crate::verify::AuditSettings {
            density: 1,
            ..crate::verify::AuditSettings::default()
        };
        // The truth at the reference's own 1e-11: the furnace's, at 1e-9, within 1e-8 of it.
        let reference = crate::integrate::reference::ReferenceSettings::default();
        let expected = |spec: &TableSpec| {
            crate::verify::lookup_coordinates(spec, &settings)
                .into_iter()
                .map(|at| {
                    let truth = spec.integral().reference(at, &reference).value;
                    (at, (truth / 0.8 - 1.0).abs())
                })
                .collect::<Vec<_>>()
        };
        let e = table(
            test_e_spec(2, 2, Grid::Nodes, MuMapping::Linear),
            vec![0.8; 4],
        );
        let report = turquin(&e, &settings, &|| {}).unwrap();
        let points = expected(&e.spec);
        let worst = points.iter().map(|p| p.1).fold(0.0, f64::max);
        assert!(
            (report.max_deviation - worst).abs() < 1e-8,
            "{report:?} {worst}"
        );
        assert!(report.max_deviation > 0.1);
        assert!((report.deviation.abs() - worst).abs() < 1e-8);
        // Glass seen from inside (the slowest reference: one side only), banded by `1 / eta`.
        let spec = glass_spec(Quantity::EDielectricInside, 2, 2, 2);
        let glass = table(spec.clone(), vec![0.8; 8]);
        let report = turquin(&glass, &settings, &|| {}).unwrap();
        // The ladder's indices are 1, 2 and 3: bands [1, 1.01), [2, inf).
        let bands: Vec<(f64, f64)> = report
            .eta_bands
            .iter()
            .map(|b| (b.lower, b.upper))
            .collect();
        assert_eq!(bands, [(1.0, 1.01), (2.0, f64::INFINITY)]);
        let points = expected(&spec);
        for band in &report.eta_bands {
            let in_band = |eta: f64| (band.lower..band.upper).contains(&(1.0 / eta));
            let worst = points
                .iter()
                .filter(|p| in_band(p.0.eta.unwrap()))
                .map(|p| p.1)
                .fold(0.0, f64::max);
            assert!(
                (band.max_deviation - worst).abs() < 1e-8,
                "{band:?} {worst}"
            );
            assert!(in_band(band.worst_eta));
        }
        assert!(report.worst_eta.is_some_and(|eta| eta <= 1.0));
    }

    /// The furnace's `mu` ladder: four steps a texel at least. A loss peaked at the column
    /// `mu = 2/3` of a 4-column table is worst, on that ladder of sixteenths, at `mu = 11/16`,
    /// where the lookup gives 15/16 of the peak.
    #[test]
    fn the_furnace_walks_mu_in_quarter_texels() {
        let spec = test_e_spec(5, 4, Grid::Nodes, MuMapping::Linear);
        let e = table(
            spec,
            (0..20)
                .map(|k| {
                    1.0 - if k % 4 == 2 {
                        0.1 * (k / 4) as f64 / 4.0
                    } else {
                        0.0
                    }
                })
                .collect(),
        );
        // The lookup's average loss is 2 x (area 0.1 r / 3) x (centroid 2/3) = 0.4 r / 9; an
        // E_avg of half that doubles the lobe.
        let e_avg = table(
            e_avg_spec(5),
            (0..5).map(|k| 1.0 - 0.2 * k as f64 / 36.0).collect(),
        );
        let report = furnace(&e, &e_avg, 2).unwrap();
        let last = report.rows.last().unwrap();
        assert_eq!(last.roughness, 1.0);
        assert!((last.relative_mismatch - 1.0).abs() < 1e-12, "{last:?}");
        assert_eq!(last.worst_mu, 11.0 / 16.0);
        assert!(
            (last.deviation - 0.1 * 15.0 / 16.0).abs() < 1e-12,
            "{last:?}"
        );
    }
}

//! `kiln eval --quantity e-order|e-multiple|e-compensated`: the microsurface walk's bounce
//! spectrum and albedo, and the albedo a compensation gives (`kiln::integrate::walk`,
//! `kiln::integrate::compensation`).

use super::{EvalArgs, scalar_or_rgb};
use kiln::integrate::compensation::compensated_albedo;
use kiln::integrate::reference::ReferenceSettings;
use kiln::integrate::walk::{WalkEstimate, WalkSettings, walk_albedo};
use kiln::{Fresnel, Model};
use std::time::Instant;

/// Walks run to time the machine before a long request is announced.
const PILOT_WALKS: u64 = 1 << 15;

/// Announced on stderr (with a progress bar on a terminal) when longer than this.
const ANNOUNCE_SECONDS: f64 = 2.0;

/// Where and for what a walk quantity is evaluated.
#[derive(Clone, Copy, Debug)]
pub struct View {
    pub model: Model,
    pub fresnel: Fresnel,
    pub alpha: f64,
    pub mu: f64,
}

/// `e-order` (`order` given, `fresnel` none) or `e-multiple`.
pub fn multiple_scattering(args: &EvalArgs, view: View, order: Option<u64>) -> kiln::Result<()> {
    let View {
        model,
        fresnel,
        alpha,
        mu,
    } = view;
    let settings = WalkSettings {
        walks: args.walks.unwrap_or(WalkSettings::DEFAULT_WALKS),
        scrambles: args.scrambles.unwrap_or(WalkSettings::DEFAULT_SCRAMBLES),
        seed: args.seed,
        ..WalkSettings::default()
    };
    settings.validate()?;
    let orders = match order {
        Some(k) if (1..=kiln::integrate::walk::MAX_ORDER as u64).contains(&k) => k as usize,
        Some(k) => return Err(kiln::integrate::walk::WalkError::Order(k).into()),
        None => 1,
    };
    kiln::integrate::walk::check_inputs(model, alpha, mu, orders)?;
    let start = Instant::now();
    let bar = announce(args, view, orders, &settings)?;
    let estimate = walk_albedo(model, alpha, mu, &fresnel, orders, &settings, &|done| {
        bar.set_position(done)
    })?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    print(args, view, order, &estimate, seconds);
    Ok(())
}

/// Times a pilot run and, when the whole request would take more than [`ANNOUNCE_SECONDS`],
/// says how long before it starts; returns the progress bar (hidden off a terminal).
fn announce(
    args: &EvalArgs,
    view: View,
    orders: usize,
    settings: &WalkSettings,
) -> kiln::Result<indicatif::ProgressBar> {
    let hidden = indicatif::ProgressBar::hidden;
    if settings.walks <= 4 * PILOT_WALKS {
        return Ok(hidden());
    }
    let pilot = WalkSettings {
        walks: PILOT_WALKS.max(u64::from(settings.scrambles)),
        ..*settings
    };
    let start = Instant::now();
    walk_albedo(
        view.model,
        view.alpha,
        view.mu,
        &view.fresnel,
        orders,
        &pilot,
        &|_| {},
    )?;
    let estimate = start.elapsed().as_secs_f64() * (settings.walks / pilot.walks) as f64;
    if estimate < ANNOUNCE_SECONDS || args.quiet {
        return Ok(hidden());
    }
    eprintln!(
        "kiln: {} walks, about {} on this machine (fewer with --walks)",
        settings.walks,
        crate::human_seconds(estimate)
    );
    Ok(crate::progress_bar(false, settings.walks, "walking"))
}

fn print(args: &EvalArgs, view: View, order: Option<u64>, estimate: &WalkEstimate, seconds: f64) {
    let View {
        model,
        fresnel,
        alpha,
        mu,
    } = view;
    let (symbol, value, error) = match order {
        Some(k) => {
            let e = estimate.orders[k as usize - 1];
            (format!("e_{k}"), [e.value; 3], e.std_error)
        }
        None => (
            "E_multiple".to_string(),
            estimate.albedo.map(|m| m.value),
            kiln::stats::max_or_nan(estimate.albedo.iter().map(|m| m.std_error)),
        ),
    };
    if args.json {
        let mut object = point_json(args, &symbol, view, value, seconds);
        object["std_error"] = error.into();
        object["method"] = "microsurface-walk".into();
        object["walks"] = estimate.walks.into();
        object["scrambles"] = args
            .scrambles
            .unwrap_or(WalkSettings::DEFAULT_SCRAMBLES)
            .into();
        object["seed"] = args.seed.into();
        object["mean_vertices"] = estimate.mean_vertices.into();
        object["dropped_bound"] = estimate.dropped.into();
        if let Some(k) = order {
            object["order"] = k.into();
            object["orders"] = serde_json::json!(estimate.orders);
            object["beyond"] = serde_json::json!(estimate.beyond);
        }
        println!("{object}");
    } else {
        let shown = shown_rgb(value, 8);
        println!(
            "{symbol}(mu = {}, alpha = {}) = {shown} ± {error:.1e} (microsurface walk, {model}, \
             {} Fresnel, {} walks, {:.2} vertices a walk, {seconds:.3} s)",
            kiln::error::brief(mu),
            kiln::error::brief(alpha),
            fresnel.name(),
            estimate.walks,
            estimate.mean_vertices
        );
        if let Some(k) = order {
            println!(
                "  orders after {k}: {:.8} ± {:.1e}",
                estimate.beyond.value, estimate.beyond.std_error
            );
        }
    }
}

/// `e-compensated`: the albedo of single scattering plus `compensation`.
pub fn compensated(args: &EvalArgs, view: View) -> kiln::Result<()> {
    let View {
        model,
        fresnel,
        alpha,
        mu,
    } = view;
    let Some(compensation) = args.compensation else {
        return Err(kiln::Error::InvalidInput(
            "--quantity e-compensated needs --compensation kulla-conty|turquin|kiln".into(),
        ));
    };
    let start = Instant::now();
    let value = compensated_albedo(
        model,
        alpha,
        mu,
        &fresnel,
        compensation,
        &ReferenceSettings::default(),
    )?;
    let seconds = start.elapsed().as_secs_f64();
    if args.json {
        let mut object = point_json(args, "E_compensated", view, value, seconds);
        object["compensation"] = compensation.name().into();
        object["method"] = "reference".into();
        println!("{object}");
    } else {
        let shown = shown_rgb(value, 10);
        println!(
            "E_compensated(mu = {}, alpha = {}; {}, {} Fresnel) = {shown} ({model}, from the \
             reference's E, E_avg, E_F and F_avg{}, {seconds:.3} s)",
            kiln::error::brief(mu),
            kiln::error::brief(alpha),
            compensation.name(),
            fresnel.name(),
            if compensation == kiln::integrate::compensation::Compensation::Kiln {
                ", kiln's coefficients fitted to 2^22 walks"
            } else {
                ""
            }
        );
    }
    Ok(())
}

/// The JSON fields every walk quantity prints: what, where, the value.
fn point_json(
    args: &EvalArgs,
    quantity: &str,
    view: View,
    value: [f64; 3],
    seconds: f64,
) -> serde_json::Value {
    serde_json::json!({
        "quantity": quantity,
        "ndf": view.model.ndf.name(),
        "masking": view.model.masking.name(),
        "fresnel": view.fresnel,
        "alpha": view.alpha,
        "roughness": args.roughness,
        "mu": view.mu,
        "value": scalar_or_rgb(value),
        "value_rgb": value,
        "seconds": seconds,
        "kiln_version": kiln::format::metadata::KILN_VERSION,
    })
}

/// One number when the channels agree, `[R, G, B]` otherwise, to `decimals` places.
fn shown_rgb(value: [f64; 3], decimals: usize) -> String {
    if value[0] == value[1] && value[1] == value[2] {
        format!("{:.decimals$}", value[0])
    } else {
        format!(
            "[{:.decimals$}, {:.decimals$}, {:.decimals$}]",
            value[0], value[1], value[2]
        )
    }
}

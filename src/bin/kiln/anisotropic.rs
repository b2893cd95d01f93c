//! `kiln anisotropic`: kiln's table of anisotropic GGX's albedo over (mu, azimuth, r, a) in an
//! engine's convention (`kiln::table::anisotropic`), and the white furnace of a lobe
//! compensated with it (`kiln::verify::anisotropic_table`).

use crate::args::SEE_CONVENTIONS;
use clap::Args;
use kiln::model::AnisotropyConvention;
use kiln::table::anisotropic::{AnisotropicSizes, AnisotropicTable};
use kiln::verify::anisotropic_table::anisotropic_furnace;
use std::path::PathBuf;

/// Bake or check kiln's anisotropic albedo table.
#[derive(Args, Debug)]
#[command(
    long_about = "Bake kiln's table of anisotropic GGX's directional albedo E(mu, phi; r, a) \
                  (height-correlated, F = 1) over the view's cosine, its azimuth from the \
                  tangent, the perceptual roughness and the anisotropy of an engine's \
                  convention, with E_avg(r, a) beside it, for Kulla-Conty's lobe and Turquin's \
                  scaling of an anisotropic lobe (--bake); or run the white furnace of a lobe \
                  compensated with such a table at points between its samples (--table). \
                  docs/anisotropy.md says how a renderer reads it.",
    after_help = SEE_CONVENTIONS
)]
pub struct AnisotropicArgs {
    /// Bake the table into this folder: ggx-anisotropic-CONVENTION-E.json (the checked
    /// document: axes, values, error estimates, the furnace measured), .bin (the values as
    /// little-endian f32, t fastest, then v, r, a) and -avg.bin (E_avg, r fastest).
    #[arg(long, value_name = "DIR", conflicts_with = "table")]
    bake: Option<PathBuf>,
    /// How the anisotropy makes alpha_x and alpha_y: kulla-conty (Filament, Unreal), disney
    /// (Cycles), gltf (KHR_materials_anisotropy), openpbr.
    #[arg(long, value_enum, default_value = "kulla-conty")]
    convention: AnisotropyConvention,
    /// The largest anisotropy of the table (its last sample), within the convention's range.
    #[arg(long, default_value_t = 0.95, allow_negative_numbers = true)]
    max_anisotropy: f64,
    /// Samples per axis: mu, azimuth, roughness, anisotropy (2 to 256 each).
    #[arg(long, value_delimiter = ',', default_values_t = [32, 16, 32, 16])]
    size: Vec<usize>,
    /// The reference quadrature's tolerance at each texel (its estimates are pessimistic: at
    /// 1e-3 the errors measured were below 2e-5).
    #[arg(long, default_value_t = 1e-3, value_parser = crate::args::parse_number)]
    tolerance: f64,
    /// Run the white furnace of this baked table's lookup (its JSON document).
    #[arg(long, value_name = "FILE")]
    table: Option<PathBuf>,
    /// Points of the furnace, between the table's samples (the bake measures its own).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    points: u32,
    /// The furnace's points have r at least this.
    #[arg(long, default_value_t = 0.0, value_parser = crate::args::parse_number)]
    min_roughness: f64,
    /// Seed of the furnace's points.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// With --table: fail (status 1) when the lookup's furnace deviation exceeds this.
    #[arg(long, requires = "table")]
    max_error: Option<f64>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Print nothing on stderr (no estimate, no progress).
    #[arg(long, short)]
    quiet: bool,
}

pub fn run(args: AnisotropicArgs) -> kiln::Result<bool> {
    let invalid = kiln::Error::InvalidInput;
    if args.size.len() != 4 {
        return Err(invalid(format!(
            "--size takes four sample counts, mu,azimuth,roughness,anisotropy (got {})",
            args.size.len()
        )));
    }
    let sizes = AnisotropicSizes {
        mu: args.size[0],
        azimuth: args.size[1],
        roughness: args.size[2],
        anisotropy: args.size[3],
    };
    let quiet = args.quiet || args.json;
    kiln::verify::anisotropic_table::check_min_roughness(args.min_roughness)?;
    if let Some(out) = &args.bake {
        sizes.check()?;
        kiln::table::anisotropic::check_tolerance(args.tolerance)?;
        args.convention.check_anisotropy(args.max_anisotropy)?;
        kiln::format::check_output_dir(out)?;
        crate::announce_cost(sizes.core_seconds(), quiet);
        let rows = (sizes.roughness * sizes.anisotropy) as u64;
        let bar = crate::progress_bar(quiet, rows, "integrating");
        let table = AnisotropicTable::bake(
            args.convention,
            args.max_anisotropy,
            sizes,
            args.tolerance,
            &|done| bar.set_position(done),
        )?;
        bar.finish_and_clear();
        let furnace =
            anisotropic_furnace(&table, args.points as usize, args.min_roughness, args.seed)?;
        let command = format!(
            "kiln anisotropic --bake {} --convention {} --max-anisotropy {} --size {},{},{},{} \
             --tolerance {:e} --points {} --seed {}",
            out.display(),
            args.convention,
            args.max_anisotropy,
            sizes.mu,
            sizes.azimuth,
            sizes.roughness,
            sizes.anisotropy,
            args.tolerance,
            args.points,
            args.seed
        );
        let stem = kiln::format::anisotropic::stem(&table);
        let files = vec![
            (
                format!("{stem}.json"),
                kiln::format::anisotropic::encode(&table, Some(&furnace.measured()), &command),
            ),
            (
                format!("{stem}.bin"),
                kiln::format::anisotropic::f32_bytes(&table.values),
            ),
            (
                format!("{stem}-avg.bin"),
                kiln::format::anisotropic::f32_bytes(&table.average),
            ),
        ];
        let written = kiln::format::write_files(out, &files)?;
        if args.json {
            let mut object = serde_json::to_value(&furnace).expect("a report serialises");
            object["files"] = written
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .into();
            object["max_node_error"] = table.max_node_error().into();
            println!("{object}");
        } else if !args.quiet {
            println!(
                "{} texels, largest error estimate {:.1e}; furnace at {} points between the \
                 samples: lookup {:.2e}, Turquin {:.2e}, Kulla-Conty {:.2e}: {}",
                sizes.len(),
                table.max_node_error(),
                furnace.points,
                furnace.max_lookup_error,
                furnace.max_turquin,
                furnace.max_kulla_conty,
                written
                    .iter()
                    .map(|p| kiln::error::escaped_path(p))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        return Ok(true);
    }
    let Some(path) = &args.table else {
        return Err(invalid(
            "give --bake DIR to bake a table, or --table FILE to run the furnace of one".into(),
        ));
    };
    let bytes = kiln::format::read_file(path)?;
    let table = kiln::format::anisotropic::decode(&bytes, &path.display().to_string())?;
    let furnace = anisotropic_furnace(&table, args.points as usize, args.min_roughness, args.seed)?;
    let worst = furnace.max_turquin.max(furnace.max_kulla_conty);
    let gate = crate::gate::Gate {
        json: args.json,
        quiet: args.quiet,
        bound: args.max_error,
        bound_field: "max_error",
    };
    let text = || {
        let at = |p: &kiln::verify::anisotropic_table::FurnacePoint| {
            format!(
                "r = {:.4}, a = {:.4}, mu = {:.4}, phi = {:.4} (E {:.5}, lookup {:.5})",
                p.roughness, p.anisotropy, p.mu, p.phi, p.truth, p.lookup
            )
        };
        format!(
            "{}: white furnace at {} points (r >= {}) against the reference to {:e}\n  lookup \
             max |E_lookup - E| {:.3e} at {}\n  turquin max |E / E_lookup - 1| {:.3e} at {}\n  \
             kulla-conty max |deviation| {:.3e} at {}\n",
            kiln::error::escaped_path(path),
            furnace.points,
            furnace.min_roughness,
            furnace.truth_tolerance,
            furnace.max_lookup_error,
            at(&furnace.worst_lookup),
            furnace.max_turquin,
            at(&furnace.worst_turquin),
            furnace.max_kulla_conty,
            at(&furnace.worst_kulla_conty)
        )
    };
    let subject = kiln::error::escaped_path(path);
    let passed = gate.print(&furnace, text, worst, "max deviation", &subject);
    Ok(passed)
}

//! `kiln merge`: the shards of one bake into its tables.

use clap::Args;
use kiln::format::replace::Replace;
use kiln::format::{self, Format};
use std::path::PathBuf;

/// Merge the shard files of one sharded bake into its tables
///
/// The shards of `kiln bake ... --shard I/N`: checks that they are all the shards of the same
/// bake, whole and each once, finishes the tables as the unsharded bake would (the check
/// against the reference to --max-error, the derived f_ms_norm) and writes them byte for byte
/// as it would have. Nothing is written if any check fails.
#[derive(Args, Debug)]
#[command(arg_required_else_help = true)]
pub struct MergeArgs {
    /// Shard files, or directories holding kiln-shard-*.json files.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Output directory [default: tables].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write only these of the bake's formats, comma-separated [default: the bake's].
    #[arg(long, value_enum, value_delimiter = ',')]
    format: Option<Vec<Format>>,
    /// Replace tables of the same name made to a different spec (as `kiln bake --force`).
    #[arg(long)]
    force: bool,
    /// Print one JSON object instead of the summary: each table (id, quantity, shape,
    /// max_std_error, node_errors, lookup_fit), the files written and the folder.
    #[arg(long, conflicts_with = "quiet")]
    json: bool,
    /// No summary.
    #[arg(long, short)]
    quiet: bool,
}

pub fn run(args: MergeArgs) -> kiln::Result<()> {
    let shards = kiln::shard::read_shards(&args.shards)?;
    let (bake, tables) = kiln::shard::merge(&shards)?;
    let formats = match args.format {
        Some(mut narrowed) => {
            narrowed.sort();
            narrowed.dedup();
            if let Some(f) = narrowed.iter().find(|f| !bake.formats.contains(f)) {
                return Err(kiln::Error::InvalidInput(format!(
                    "--format {}: the sharded bake wrote {}; --format may only narrow them",
                    f.name(),
                    bake.formats
                        .iter()
                        .map(|f| f.name())
                        .collect::<Vec<_>>()
                        .join(",")
                )));
            }
            narrowed
        }
        None => bake.formats.clone(),
    };
    let out = args.out.unwrap_or_else(|| PathBuf::from("tables"));
    let replace = if args.force {
        Replace::Force
    } else {
        Replace::Refuse
    };
    let written = format::write_tables(&out, &tables, &formats, bake.precision, replace)?;
    if args.json {
        let object = crate::report::tables_written_json(&tables, &written, &out, None);
        println!("{object}");
    } else if !args.quiet {
        println!(
            "merged {} into {}; wrote {} to {}",
            kiln::error::count(shards.len(), "shard"),
            kiln::error::count(tables.len(), "table"),
            kiln::error::count(written.len(), "file"),
            out.display()
        );
    }
    Ok(())
}

//! `kiln plan`.

use clap::Args;
use kiln::scene::Scene;
use std::path::PathBuf;

/// A scene file, for `--help` (docs/scenes.md has it all).
pub const SCENE_FORMAT: &str = "\
A scene file (TOML; unknown keys are errors):

  [output]                       # optional
  dir = \"tables\"                 # relative to the scene file
  formats = [\"exr\", \"rs\", \"json\"] # or preset = \"filament\" (an engine's own files)
  precision = \"f16\"              # f32 (default) or f16
  max_error = 1e-7               # the bake's bound (default 1e-7)

  [[material]]
  name = \"brushed_steel\"         # unique, no control characters
  ndf = \"ggx\"                    # ggx | beckmann
  masking = \"height-correlated\"  # optional (the default)
  roughness = [0.2, 0.6]         # perceptual r in [0, 1]: one value or [min, max]
  fresnel = { conductor = { eta = [2.9, 2.9, 2.4], k = [3.0, 2.9, 2.5] } }
                                 # or { dielectric = { ior = 1.5 } }, { schlick = { f0 = 0.04 } },
                                 # \"none\" (F = 1)
  multiple_scattering = true     # Kulla-Conty: E, E_avg, f_ms_norm (the default)
  image_based_lighting = false   # the split sum: E_scale, E_bias
  transmission = false           # glass: the dielectric tables (a dielectric fresnel)
  sheen = false                  # cloth albedo: only in filament's and godot's textures

Then `kiln bake --scene FILE` bakes exactly what `kiln plan FILE` lists. Example:
examples/scene.toml; the format in full: docs/scenes.md.";

/// Show the minimal set of tables a scene needs.
#[derive(Args, Debug)]
#[command(
    long_about = "Read a scene file (TOML: [output] and [[material]] entries with name, ndf, \
                  masking, roughness and fresnel, and the effects each asks for: \
                  multiple_scattering (on unless false), image_based_lighting, sheen, \
                  transmission; see docs/scenes.md) and print the minimal set of tables its \
                  materials need, each once with the materials and effects that need it: E, \
                  E_avg and f_ms_norm for multiple scattering, the split-sum scale and bias for \
                  image-based lighting, the dielectric tables for transmission, per NDF and \
                  masking combination. With [output] preset = NAME, the engine's own tables in \
                  its layout instead, and for each channel of its file what it holds, for which \
                  materials, and whether it is computed (Filament's cloth channel only for a \
                  sheen material). Per material, the scalars \
                  it needs: F_avg per channel for its Fresnel model (the Kulla-Conty colour \
                  term), which `kiln bake --scene` writes to materials.json. Each table with its \
                  estimated bake time on this machine's threads (a rough figure: seconds or \
                  minutes). output.dir is relative to the scene file. With --json, one object \
                  with a `tables` array (ndf, masking, quantity, materials, id, \
                  estimated_core_seconds) and a `materials` array (name, ndf, masking, \
                  roughness, fresnel, f_avg).",
    after_long_help = SCENE_FORMAT
)]
pub struct PlanArgs {
    /// The scene file (was --scene FILE, which still works in this release).
    scene: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Print nothing but errors: the exit status says whether the scene is one kiln bakes (0)
    /// or not (2). For a build step that checks a scene. Not with --json.
    #[arg(long, short, conflicts_with = "json")]
    quiet: bool,
}

pub fn run(args: PlanArgs) -> kiln::Result<()> {
    let scene = Scene::read(&args.scene)?;
    let plan = scene.plan();
    if args.quiet {
        return Ok(());
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&plan).expect("a plan serialises")
        );
        return Ok(());
    }
    if plan.materials.is_empty() {
        eprintln!(
            "kiln: warning: {} names no materials, so it needs no tables; add [[material]] \
             entries (name, ndf, roughness, fresnel; kiln plan --help shows the format)",
            kiln::error::escaped_path(&args.scene)
        );
    }
    let threads = rayon::current_num_threads();
    let total = plan
        .tables
        .iter()
        .fold(0.0, |sum, t| sum + t.estimated_core_seconds);
    println!(
        "{}: {} {} {} (estimated {} on {threads} threads, less what the cache in {} holds)",
        kiln::error::escaped_path(&args.scene),
        kiln::error::count(plan.materials.len(), "material"),
        if plan.materials.len() == 1 {
            "needs"
        } else {
            "need"
        },
        kiln::error::count(plan.tables.len(), "table"),
        crate::human_seconds(total / threads as f64),
        kiln::error::escaped_path(&scene.output_dir().join(".kiln-cache"))
    );
    let effects = |effects: &[kiln::scene::Effect]| -> String {
        let names: Vec<&str> = effects.iter().map(|e| e.name()).collect();
        names.join(", ")
    };
    // Names line up at 46 columns, or at the longest (the glass tables at one IOR).
    let width = plan.tables.iter().map(|t| t.id.len()).fold(46, usize::max);
    for t in &plan.tables {
        let why = if t.effects.is_empty() {
            " (the engine's file holds it)".to_string()
        } else {
            format!(" ({})", effects(&t.effects))
        };
        println!(
            "  {:<width$} ~{:>8}  for {}{why}",
            t.id,
            crate::human_seconds(t.estimated_core_seconds / threads as f64),
            t.materials.join(", ")
        );
    }
    if let Some(engine) = &plan.engine {
        println!("  {} layout, {}:", engine.preset, engine.file);
        for c in &engine.channels {
            let what = match (c.computed, c.effects.is_empty(), c.materials.is_empty()) {
                (false, false, _) => format!(
                    "not computed (written as 0): no material asks for {}",
                    effects(&c.effects)
                ),
                (false, true, _) => "a constant".to_string(),
                (true, _, true) => "for the engine's file".to_string(),
                (true, true, false) => format!("for {}", c.materials.join(", ")),
                (true, false, false) => {
                    format!("for {} ({})", c.materials.join(", "), effects(&c.effects))
                }
            };
            println!("    {:<4} {}: {what}", c.name, c.holds);
        }
    }
    for m in &plan.materials {
        let [r, g, b] = m.f_avg;
        println!(
            "  material {}: {} {}, roughness {}..{}, fresnel {}, asks for {}, F_avg [{r:.6}, \
             {g:.6}, {b:.6}]",
            m.name,
            m.ndf,
            m.masking,
            m.roughness[0],
            m.roughness[1],
            m.fresnel,
            if m.effects.is_empty() {
                "nothing".to_string()
            } else {
                effects(&m.effects)
            }
        );
    }
    Ok(())
}

//! `kiln plan`.

use clap::Args;
use kiln::scene::Scene;
use std::path::PathBuf;

/// Show the minimal set of tables a scene needs.
#[derive(Args, Debug)]
#[command(
    long_about = "Read a scene file (TOML: [output] and [[material]] entries with name, ndf, \
                  masking, roughness and fresnel; see the README) and print the minimal set of \
                  tables its materials need, each once with the materials that need it: E and \
                  E_avg for every NDF and masking combination in use. Per material, the scalars \
                  it needs: F_avg per channel for its Fresnel model (the Kulla-Conty colour \
                  term), which `kiln bake --scene` writes to materials.json. Each table with its \
                  estimated bake time on this machine's threads (a rough figure: seconds or \
                  minutes). output.dir is relative to the scene file. With --json, one object \
                  with a `tables` array (ndf, masking, quantity, materials, id, \
                  estimated_core_seconds) and a `materials` array (name, ndf, masking, \
                  roughness, fresnel, f_avg)."
)]
pub struct PlanArgs {
    /// The scene file.
    #[arg(long)]
    scene: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: PlanArgs) -> kiln::Result<()> {
    let scene = Scene::read(&args.scene)?;
    let plan = scene.plan();
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
             entries (name, ndf, roughness, fresnel; see kiln plan --help)",
            args.scene.display()
        );
    }
    let threads = rayon::current_num_threads();
    let total = plan
        .tables
        .iter()
        .fold(0.0, |sum, t| sum + t.estimated_core_seconds);
    println!(
        "{}: {} materials need {} tables (estimated {} on {threads} threads, less what the \
         cache in {} holds)",
        args.scene.display(),
        plan.materials.len(),
        plan.tables.len(),
        crate::human_seconds(total / threads as f64),
        scene.output_dir().join(".kiln-cache").display()
    );
    for t in &plan.tables {
        println!(
            "  {:<46} ~{:>8}  for {}",
            t.id,
            crate::human_seconds(t.estimated_core_seconds / threads as f64),
            t.materials.join(", ")
        );
    }
    for m in &plan.materials {
        let [r, g, b] = m.f_avg;
        println!(
            "  material {}: {} {}, roughness {}..{}, fresnel {}{}, F_avg [{r:.6}, {g:.6}, {b:.6}]",
            m.name,
            m.ndf,
            m.masking,
            m.roughness[0],
            m.roughness[1],
            m.fresnel,
            if m.transmission {
                " (transmission)"
            } else {
                ""
            }
        );
    }
    Ok(())
}

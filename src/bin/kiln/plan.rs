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
                  term). With --json, one object with a `tables` array (ndf, masking, quantity, \
                  materials) and a `materials` array (name, ndf, masking, roughness, fresnel, \
                  f_avg)."
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
    println!(
        "{}: {} materials need {} tables",
        args.scene.display(),
        plan.materials.len(),
        plan.tables.len()
    );
    for t in &plan.tables {
        let id = format!("{}-{}-{}", t.ndf, t.masking, t.quantity.symbol());
        println!("  {id:<46} for {}", t.materials.join(", "));
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

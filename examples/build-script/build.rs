//! Bakes the tables a scene needs into OUT_DIR at build time (reused from kiln's cache there when
//! nothing changed), for `src/main.rs` to `include!`.

use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let scene_path = PathBuf::from("scene.toml");
    println!("cargo::rerun-if-changed={}", scene_path.display());
    let scene = kiln::scene::Scene::read(&scene_path).expect("a valid scene");
    let start = std::time::Instant::now();
    // OUT_DIR is this build's own: a changed scene replaces what an earlier build wrote.
    let result = scene
        .bake(&out, &|_| {}, kiln::format::replace::Replace::Force)
        .expect("the bake succeeds");
    if !result.report.baked.is_empty() {
        println!(
            "cargo::warning=kiln baked {} in {:.2} s",
            result.report.baked.join(", "),
            start.elapsed().as_secs_f64()
        );
    }
}

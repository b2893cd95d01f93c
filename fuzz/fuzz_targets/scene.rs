//! Scene files: parsed, validated and planned as `kiln plan --scene` does.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(scene) = kiln::scene::Scene::parse(text, "fuzz.toml") {
        for table in scene.plan().tables {
            assert!(table.estimated_core_seconds.is_finite());
        }
    }
});

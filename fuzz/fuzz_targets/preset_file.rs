//! Engine files: the first byte picks the preset (in the order of `Preset::ALL`), the rest is
//! its engine file, read as `kiln verify --preset` reads it (the tables, then the extra
//! channel).
#![no_main]

use kiln::preset::Preset;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, file)) = data.split_first() else {
        return;
    };
    let preset = Preset::ALL[usize::from(pick) % Preset::ALL.len()];
    if let Ok(tables) = preset.read_tables(file, "fuzz") {
        for t in &tables {
            assert!(t.value.iter().all(|v| v.is_finite()));
        }
    }
    let _ = preset.decode_extra(file);
});

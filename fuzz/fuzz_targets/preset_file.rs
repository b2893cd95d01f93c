//! Engine files: the first byte picks the preset, the rest is its engine file, read as
//! `kiln verify --preset` reads it (the tables, then the extra channel).
#![no_main]

use kiln::preset::Preset;
use libfuzzer_sys::fuzz_target;

const PRESETS: [Preset; 8] = [
    Preset::Cycles,
    Preset::Bevy,
    Preset::Three,
    Preset::EnterprisePbr,
    Preset::Filament,
    Preset::Godot,
    Preset::UnityHdrp,
    Preset::Unreal,
];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, file)) = data.split_first() else {
        return;
    };
    let preset = PRESETS[usize::from(pick) % PRESETS.len()];
    if let Ok(tables) = preset.read_tables(file, "fuzz") {
        for t in &tables {
            assert!(t.value.iter().all(|v| v.is_finite()));
        }
    }
    let _ = preset.decode_extra(file);
});

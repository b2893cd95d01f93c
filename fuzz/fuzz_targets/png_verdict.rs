//! A games202 PNG LUT as `kiln verify --preset games202` reads it for its verdict: its tables
//! (every number finite) and the precision its data holds (`sBIT`, 8-bit levels widened to 16,
//! palettes, whose indices must lie within the palette).
#![no_main]

use kiln::preset::Preset;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(tables) = Preset::Games202.read_tables(data, "fuzz") {
        for t in &tables {
            assert!(t.value.iter().all(|v| v.is_finite()));
        }
    }
    let _ = Preset::Games202.storage_of(data);
    let _ = kiln::format::png::effective_bits(data);
});

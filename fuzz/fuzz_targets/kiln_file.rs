//! kiln's own files: the first byte picks the format (JSON sidecar, EXR, binary, KTX2, DDS, C
//! header, Rust source), the rest is the file, read by `read_kiln` beside a valid sidecar (the
//! binary and DDS readers take their model from it). An error is fine; a panic, a huge
//! allocation (libFuzzer's -malloc_limit_mb) or a non-finite number read is a finding.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

const EXTENSIONS: [&str; 7] = ["json", "exr", "bin", "ktx2", "dds", "h", "rs"];

/// A directory holding a valid sidecar for the files read beside it.
fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("kiln-fuzz-{}", std::process::id()));
        let tables = kiln::BakeOptions {
            quantities: vec![kiln::Quantity::E],
            size: 6,
            max_error: Some(1e-3),
            ..kiln::BakeOptions::default()
        }
        .bake(&|_| {})
        .unwrap();
        kiln::format::write_tables(
            &dir,
            &tables,
            &[kiln::format::Format::Json],
            kiln::format::Precision::F32,
            kiln::format::replace::Replace::Force,
        )
        .unwrap();
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let Some((&pick, file)) = data.split_first() else {
        return;
    };
    let extension = EXTENSIONS[usize::from(pick) % EXTENSIONS.len()];
    // JSON is the sidecar itself: read it under another name.
    let name = if extension == "json" {
        "other.json".to_string()
    } else {
        format!("ggx-height-correlated-E.{extension}")
    };
    let path = dir().join(name);
    std::fs::write(&path, file).unwrap();
    if let Ok(Some(table)) = kiln::verify::input::read_kiln(&path) {
        for v in table.value.iter().chain(&table.one_minus_value).chain(&table.std_error) {
            assert!(v.is_finite());
        }
    }
});

//! `tables/` holds exactly what the default bake produces, byte for byte.

use kiln::BakeOptions;
use kiln::format::{Format, Precision, encode_all};
use std::path::Path;

#[test]
fn committed_tables_are_reproduced_byte_for_byte_by_the_default_bake() {
    let tables = BakeOptions::default()
        .bake(&|_| {})
        .expect("default options are valid");
    let files = encode_all(&tables, &Format::ALL, Precision::F32).unwrap();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables");
    let mut committed: Vec<String> = std::fs::read_dir(&dir)
        .expect("tables/ exists: run scripts/regenerate-tables.sh")
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    committed.sort();
    let mut produced: Vec<String> = files.iter().map(|(name, _)| name.clone()).collect();
    produced.sort();
    assert_eq!(
        committed, produced,
        "tables/ lists different files: run scripts/regenerate-tables.sh"
    );
    for (name, bytes) in &files {
        let on_disk = std::fs::read(dir.join(name)).unwrap();
        assert!(
            on_disk == *bytes,
            "tables/{name} differs from a fresh default bake: run scripts/regenerate-tables.sh"
        );
    }
}

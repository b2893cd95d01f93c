//! Cache entries: whatever the file under a key's name holds, the lookup is a hit with a
//! whole, finite table of that key's spec, a miss or a damaged entry, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

struct Fixture {
    cache: kiln::cache::Cache,
    key: kiln::cache::CacheKey,
    entry: std::path::PathBuf,
}

fn fixture() -> &'static Fixture {
    static FIXTURE: OnceLock<Fixture> = OnceLock::new();
    FIXTURE.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("kiln-fuzz-cache-{}", std::process::id()));
        let table = kiln::BakeOptions {
            quantities: vec![kiln::Quantity::E],
            size: 4,
            max_error: Some(1e-3),
            ..kiln::BakeOptions::default()
        }
        .bake(&|_| {})
        .unwrap()
        .remove(0);
        let cache = kiln::cache::Cache::new(&dir);
        let key = kiln::cache::CacheKey::new(&table.spec, Some(1e-3), &table.command);
        cache.store(&key, &table).unwrap();
        let entry = dir.join(key.file_name());
        Fixture { cache, key, entry }
    })
}

fuzz_target!(|data: &[u8]| {
    let f = fixture();
    std::fs::write(&f.entry, data).unwrap();
    if let kiln::cache::Lookup::Hit(table) = f.cache.lookup(&f.key) {
        assert_eq!(table.spec, f.key.spec);
        assert!(table.value.iter().all(|v| v.is_finite()));
    }
});

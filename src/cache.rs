//! A content-addressed cache of baked tables, so that a scene baked again with nothing changed
//! does no integration, and a changed material rebakes only its tables.
//!
//! The key of a table is everything that changes its bytes: the spec (model, quantity, axes,
//! method, samples, seed, tolerance), the requested max error, the command recorded in its
//! metadata, and kiln's version. An entry is a JSON file named by a 64-bit FNV-1a hash of the
//! key's canonical JSON (Fowler, Noll and Vo; `offset 0xcbf29ce484222325`, prime
//! `0x100000001b3`), holding the key itself and the table with every value in f64 (serde_json
//! writes the shortest representation that reads back exactly). A hit requires the stored key to
//! equal the wanted one, so a hash collision is a miss, never a wrong table. Entries are written
//! to a temporary file and renamed into place.

use crate::error::{Error, Result};
use crate::format::metadata::KILN_VERSION;
use crate::table::{Table, TableSpec};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What identifies a table's bytes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CacheKey {
    pub spec: TableSpec,
    pub requested_max_error: Option<f64>,
    pub command: String,
    pub kiln_version: String,
}

impl CacheKey {
    #[must_use]
    pub fn new(spec: &TableSpec, requested_max_error: Option<f64>, command: &str) -> Self {
        Self {
            spec: spec.clone(),
            requested_max_error,
            command: command.to_string(),
            kiln_version: KILN_VERSION.to_string(),
        }
    }

    /// The entry's file name: the FNV-1a hash of the key's JSON, in hex.
    #[must_use]
    pub fn file_name(&self) -> String {
        let json = serde_json::to_string(self).expect("a key serialises");
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        for byte in json.bytes() {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
        format!("{hash:016x}.json")
    }
}

#[derive(Serialize, Deserialize)]
struct Entry {
    key: CacheKey,
    table: Table,
}

/// A cache directory.
#[derive(Clone, Debug)]
pub struct Cache {
    dir: PathBuf,
}

impl Cache {
    /// The cache in `dir` (created on first store).
    #[must_use]
    pub fn new(dir: &Path) -> Self {
        Self {
            dir: dir.to_path_buf(),
        }
    }

    /// The table stored under `key`, if any (an unreadable or foreign entry is a miss).
    #[must_use]
    pub fn load(&self, key: &CacheKey) -> Option<Table> {
        let bytes = std::fs::read(self.dir.join(key.file_name())).ok()?;
        let entry: Entry = serde_json::from_slice(&bytes).ok()?;
        (entry.key == *key).then_some(entry.table)
    }

    /// Stores `table` under `key`.
    pub fn store(&self, key: &CacheKey, table: &Table) -> Result<()> {
        let io = |action: &'static str, path: &Path| {
            let path = path.to_path_buf();
            move |source| Error::Io {
                path,
                action,
                source,
            }
        };
        std::fs::create_dir_all(&self.dir).map_err(io("create the cache directory", &self.dir))?;
        let entry = Entry {
            key: key.clone(),
            table: table.clone(),
        };
        let bytes = serde_json::to_vec(&entry).expect("an entry serialises");
        let mut file = tempfile::NamedTempFile::new_in(&self.dir)
            .map_err(io("create a temporary file in", &self.dir))?;
        std::io::Write::write_all(&mut file, &bytes).map_err(io("write", file.path()))?;
        let path = self.dir.join(key.file_name());
        file.persist(&path)
            .map_err(|e| io("rename into", &path)(e.error))?;
        Ok(())
    }
}

//! A content-addressed cache of baked tables, so that a scene baked again with nothing changed
//! does no integration, and a changed material rebakes only its tables.
//!
//! The key of a table is everything that changes its bytes: the spec (model, quantity, axes,
//! method, samples, seed, tolerance), the requested max error, the command recorded in its
//! metadata, kiln's version and [`NUMERICS_VERSION`], the version of the numbers themselves
//! (bumped whenever any integrator, model or derivation changes a stored value; a test of
//! golden digests, `tests/numerics_version.rs`, fails until it is). An entry is a JSON file
//! named by a 64-bit FNV-1a hash of the key's canonical JSON (Fowler, Noll and Vo; `offset
//! 0xcbf29ce484222325`, prime `0x100000001b3`), holding the key itself, the table with every
//! value in f64 (serde_json writes the shortest representation that reads back exactly), and a
//! digest (FNV-1a of the key's and the table's canonical JSON) that proves the entry whole. A
//! hit requires the stored key to equal the wanted one (so a hash collision is a miss, never a
//! wrong table), the digest to hold, and the table to be the key's spec with finite values
//! ([`Table::check_computed`](crate::table::Table::check_computed)); an entry that fails is reported as damaged, and the
//! bake integrates the table again and replaces it. Entries are written to a temporary file and
//! renamed into place.

use crate::error::{Error, Result};
use crate::format::metadata::KILN_VERSION;
use crate::table::{Table, TableSpec};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The version of kiln's numbers: bump it in any change that alters a stored value (an
/// integrator, a model, a derivation, a default tolerance), so that no cache, scene or build
/// script reuses a table the new code would not make. `tests/numerics_version.rs` holds golden
/// digests of small tables for this version and fails when they change and it did not.
pub const NUMERICS_VERSION: u32 = 15;

/// What identifies a table's bytes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CacheKey {
    pub spec: TableSpec,
    pub requested_max_error: Option<f64>,
    pub command: String,
    pub kiln_version: String,
    pub numerics_version: u32,
}

/// FNV-1a, 64 bits, of `bytes`.
#[must_use]
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &byte in bytes {
        hash ^= u64::from(byte);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// The digest of an entry: FNV-1a of the key's and the table's canonical JSON, in hex.
fn digest(key: &CacheKey, table: &Table) -> String {
    let mut json = serde_json::to_vec(key).expect("a key serialises");
    json.extend(serde_json::to_vec(table).expect("a table serialises"));
    format!("{:016x}", fnv1a(&json))
}

/// What the cache holds for a key.
#[derive(Clone, Debug)]
pub enum Lookup {
    /// A whole entry made for this key.
    Hit(Box<Table>),
    /// No entry (or one made for another key, after a hash collision).
    Miss,
    /// An entry that is not what it claims: why.
    Damaged(String),
}

impl CacheKey {
    #[must_use]
    pub fn new(spec: &TableSpec, requested_max_error: Option<f64>, command: &str) -> Self {
        Self {
            spec: spec.clone(),
            requested_max_error,
            command: command.to_string(),
            kiln_version: KILN_VERSION.to_string(),
            numerics_version: NUMERICS_VERSION,
        }
    }

    /// The entry's file name: the FNV-1a hash of the key's JSON, in hex.
    #[must_use]
    pub fn file_name(&self) -> String {
        let json = serde_json::to_string(self).expect("a key serialises");
        format!("{:016x}.json", fnv1a(json.as_bytes()))
    }
}

#[derive(Serialize, Deserialize)]
struct Entry {
    key: CacheKey,
    digest: String,
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

    /// The table stored under `key`, if any (a damaged or foreign entry is a miss).
    #[must_use]
    pub fn load(&self, key: &CacheKey) -> Option<Table> {
        match self.lookup(key) {
            Lookup::Hit(table) => Some(*table),
            Lookup::Miss | Lookup::Damaged(_) => None,
        }
    }

    /// What the cache holds for `key`: a whole entry made for it, nothing, or a damaged entry
    /// (unreadable, not JSON, a digest that does not hold, a table of another spec or with
    /// values that are not finite), with the reason.
    #[must_use]
    pub fn lookup(&self, key: &CacheKey) -> Lookup {
        let path = self.dir.join(key.file_name());
        if !path.exists() {
            return Lookup::Miss;
        }
        // Through the reader of every file kiln is given: a regular file within its size cap.
        let bytes = match crate::format::read_file(&path) {
            Ok(bytes) => bytes,
            Err(e) => return Lookup::Damaged(format!("unreadable: {e}")),
        };
        let entry: Entry = match serde_json::from_slice(&bytes) {
            Ok(entry) => entry,
            Err(e) => return Lookup::Damaged(format!("not a cache entry: {e}")),
        };
        if entry.key != *key {
            // Another key with the same file name: a hash collision (or an edited key).
            return if digest(&entry.key, &entry.table) == entry.digest {
                Lookup::Miss
            } else {
                Lookup::Damaged("its key was edited".into())
            };
        }
        if digest(&entry.key, &entry.table) != entry.digest {
            return Lookup::Damaged("its digest does not hold".into());
        }
        if entry.table.spec != key.spec {
            return Lookup::Damaged("its table is of another spec".into());
        }
        if let Err(e) = entry.table.check_computed() {
            return Lookup::Damaged(e.to_string());
        }
        Lookup::Hit(Box::new(entry.table))
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
            digest: digest(key, table),
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

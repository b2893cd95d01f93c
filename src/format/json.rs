//! The JSON sidecar: the metadata, the names of the files written beside it, and the values at
//! full f64 precision (the lossless copy of the table).

use super::metadata::Metadata;
use crate::table::Table;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The sidecar document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sidecar {
    /// Always `"kiln-table"`.
    pub kind: String,
    #[serde(flatten)]
    pub metadata: Metadata,
    /// Other files written for this table, by format (`exr`, `bin`, `rs`, `png`), relative to
    /// this file.
    pub files: BTreeMap<String, String>,
    /// Every channel, row-major (slowest axis first), in f64.
    pub data: BTreeMap<String, Vec<f64>>,
}

/// The `kind` of a kiln sidecar.
pub const KIND: &str = "kiln-table";

/// Builds the sidecar of a table.
#[must_use]
pub fn sidecar(table: &Table, precision: &str, files: BTreeMap<String, String>) -> Sidecar {
    let data = table
        .channel_names()
        .into_iter()
        .zip(table.channels())
        .map(|(name, values)| (name, values.to_vec()))
        .collect();
    Sidecar {
        kind: KIND.to_string(),
        metadata: Metadata::new(table, precision),
        files,
        data,
    }
}

/// Encodes the sidecar as pretty-printed JSON with a final newline.
pub fn encode(sidecar: &Sidecar) -> crate::Result<Vec<u8>> {
    let mut bytes =
        serde_json::to_vec_pretty(sidecar).map_err(|e| crate::Error::Encode(e.to_string()))?;
    bytes.push(b'\n');
    Ok(bytes)
}

//! kiln's anisotropic albedo table as files ([`crate::table::anisotropic`]): one JSON document
//! holding the axes, the values, their error estimates, the furnace measured at the bake, how a
//! renderer reads it and the command that reproduces it; and the values and averages as raw
//! little-endian f32 arrays for a renderer's 3-D texture array. Read back, everything a lookup
//! relies on is checked first.

use crate::error::{Error, Result};
use crate::table::anisotropic::{AnisotropicTable, MeasuredFurnace};
use serde::{Deserialize, Serialize};

/// The document's `kind`.
pub const KIND: &str = "kiln-anisotropic-albedo";

/// How a renderer reads the table, for the document.
pub const LOOKUP: &str = "E(mu, phi; r, a) for anisotropic GGX (height-correlated, F = 1) in the \
    convention's (alpha_x, alpha_y) = f(r^2, a): with alpha_phi = sqrt(alpha_x^2 cos^2 phi + \
    alpha_y^2 sin^2 phi) (phi: the view's azimuth from the tangent), the coordinates are t = \
    (mu (1 + 4 alpha_phi) / (mu + 4 alpha_phi))^0.4, v = ln(alpha_x / alpha_phi) / \
    ln(alpha_x / alpha_y) (sin^2 phi when alpha_x = alpha_y), r, and the anisotropy's coordinate w (kulla-conty atanh(a) / atanh(max), disney ln(1 - 0.9 a) / ln(1 - 0.9 max), openpbr ln(1 - a) / ln(1 - max), gltf (a / max)^2), each \
    in [0, 1] with samples on both ends; interpolate linearly in each. Values are stored t \
    fastest, then v, r, w; average (E_avg, the average of the lookup over the hemisphere) r fastest, then w: read 1 - E_avg = alpha^2 c with c = (1 - E_avg) / alpha^2 interpolated linearly in r and w (alpha = max(r, 1e-3)^2)";

/// The file: the table and what it is.
#[derive(Serialize, Deserialize)]
struct Document {
    kind: String,
    kiln_version: String,
    lookup: String,
    command: String,
    max_node_error: f64,
    furnace: Option<MeasuredFurnace>,
    table: AnisotropicTable,
}

impl super::document::Kinded for Document {
    fn kind(&self) -> &str {
        &self.kind
    }
}

/// The name stem of `table`'s files: `ggx-anisotropic-kulla-conty-E`.
#[must_use]
pub fn stem(table: &AnisotropicTable) -> String {
    format!("ggx-anisotropic-{}-E", table.convention.name())
}

/// `table` as its JSON document, with the furnace measured and the `command` that made it.
#[must_use]
pub fn encode(
    table: &AnisotropicTable,
    furnace: Option<&MeasuredFurnace>,
    command: &str,
) -> Vec<u8> {
    let document = Document {
        kind: KIND.to_string(),
        kiln_version: super::metadata::KILN_VERSION.to_string(),
        lookup: LOOKUP.to_string(),
        command: command.to_string(),
        max_node_error: table.max_node_error(),
        furnace: furnace.cloned(),
        table: table.clone(),
    };
    // Compact: a pretty document of the default table is 14 MB, most of it indentation.
    let mut bytes = serde_json::to_vec(&document).expect("a table serialises");
    bytes.push(b'\n');
    bytes
}

/// Little-endian f32 of `values`.
#[must_use]
pub fn f32_bytes(values: &[f64]) -> Vec<u8> {
    let mut out = Vec::with_capacity(4 * values.len());
    for &v in values {
        super::Precision::F32.push_le(&mut out, v);
    }
    out
}

/// Reads a document [`encode`] wrote, checking it; `name` names the file in errors.
///
/// # Errors
/// Not such a document, or a table a lookup cannot trust.
pub fn decode(bytes: &[u8], name: &str) -> Result<AnisotropicTable> {
    let bad = |message: String| Error::InvalidInput(format!("{name}: {message}"));
    let document: Document = super::document::decode_kind(
        bytes,
        name,
        KIND,
        "kiln anisotropic albedo file",
        "kiln anisotropic --bake DIR",
    )?;
    let table = document.table;
    table.check().map_err(|e| bad(e.to_string()))?;
    Ok(table)
}

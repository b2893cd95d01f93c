//! kiln's glass compensation as a file ([`crate::table::glass_compensation`]): one JSON
//! document holding the layout, the index, the four scale channels, their standard errors, how
//! a renderer applies them and the command that reproduces them; and the four channels as an
//! RGBA image (EXR). Read back, everything a lookup relies on is checked first.

use crate::error::{Error, Result};
use crate::table::glass_compensation::GlassCompensationTable;
use serde::{Deserialize, Serialize};

/// The document's `kind`.
pub const KIND: &str = "kiln-glass-compensation";

/// How a renderer applies the factors, for the document and the image's metadata.
pub const USE: &str = "multiply the single-scattering BSDF's reflection lobe by k_R(mu_o, r) \
                       and its transmission lobe by k_T(mu_o, r), read at the view's side \
                       (outside: relative index eta; inside: 1 / eta); the energy sent on is \
                       then the dielectric microsurface walk's, split as it splits it";

/// The file: the table and what it is.
#[derive(Serialize, Deserialize)]
struct Document {
    kind: String,
    kiln_version: String,
    /// How a renderer applies the factors.
    r#use: String,
    command: String,
    max_std_error: f64,
    table: GlassCompensationTable,
}

impl super::document::Kinded for Document {
    fn kind(&self) -> &str {
        &self.kind
    }
}

/// The name stem of `table`'s files: `ggx-height-correlated-kiln-glass-compensation-ior-1.5`.
#[must_use]
pub fn stem(table: &GlassCompensationTable) -> String {
    format!(
        "{}-{}-kiln-glass-compensation-ior-{}",
        table.spec.model.ndf.name(),
        table.spec.model.masking.name(),
        table.eta
    )
}

/// The channel names of the image, R to A.
pub const CHANNELS: [&str; 4] = ["kR_outside", "kT_outside", "kR_inside", "kT_inside"];

/// `table`'s factors as an RGBA texture over its `E` layout ([`CHANNELS`]).
#[must_use]
pub fn texture(table: &GlassCompensationTable) -> super::texture::Texture {
    let metadata = serde_json::json!({
        "kind": KIND,
        "channels": CHANNELS,
        "use": USE,
        "eta": table.eta,
        "spec": table.spec,
        "walks": table.walks,
        "max_std_error": table.max_std_error(),
    });
    let planes = [
        &table.reflection[0],
        &table.transmission[0],
        &table.reflection[1],
        &table.transmission[1],
    ];
    super::texture::Texture {
        shape: table.spec.shape(),
        channels: CHANNELS
            .iter()
            .zip(planes)
            .map(|(name, values)| ((*name).to_string(), values.clone()))
            .collect(),
        metadata: metadata.to_string(),
    }
}

/// `table` as its JSON document, with the `command` that made it.
#[must_use]
pub fn encode(table: &GlassCompensationTable, command: &str) -> Vec<u8> {
    let document = Document {
        kind: KIND.to_string(),
        kiln_version: super::metadata::KILN_VERSION.to_string(),
        r#use: USE.to_string(),
        command: command.to_string(),
        max_std_error: table.max_std_error(),
        table: table.clone(),
    };
    let mut bytes = serde_json::to_vec_pretty(&document).expect("a table serialises");
    bytes.push(b'\n');
    bytes
}

/// Reads a document [`encode`] wrote, checking it; `name` names the file in errors.
///
/// # Errors
/// Not such a document, or a table a lookup cannot trust.
pub fn decode(bytes: &[u8], name: &str) -> Result<GlassCompensationTable> {
    let bad = |message: String| Error::InvalidInput(format!("{name}: {message}"));
    let document: Document = super::document::decode_kind(
        bytes,
        name,
        KIND,
        "kiln glass compensation file",
        "kiln compensation --bake DIR --ior ETA",
    )?;
    let table = document.table;
    table.check().map_err(|e| bad(e.to_string()))?;
    Ok(table)
}

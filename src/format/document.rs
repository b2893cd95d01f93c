//! kiln's checked JSON documents (its compensation, its glass compensation, its anisotropic
//! albedo): each names what it is in its `kind`, which is read back before anything else.

use crate::error::{Error, Result};
use serde::de::DeserializeOwned;

/// A document with a `kind`.
pub trait Kinded {
    /// The document's `kind` as read.
    fn kind(&self) -> &str;
}

/// Parses `bytes` as a document whose `kind` must be `kind`. Errors name the file (`name`), say
/// what it is not (`what`: "kiln compensation file") and which command writes one (`writer`).
///
/// # Errors
/// Not JSON of the document's shape, or another kind.
pub fn decode_kind<D: DeserializeOwned + Kinded>(
    bytes: &[u8],
    name: &str,
    kind: &str,
    what: &str,
    writer: &str,
) -> Result<D> {
    let document: D = serde_json::from_slice(bytes).map_err(|e| {
        Error::InvalidInput(format!(
            "{name}: not a {what} ({}); `{writer}` writes them",
            crate::error::quoted(&e.to_string())
        ))
    })?;
    if document.kind() != kind {
        return Err(Error::InvalidInput(format!(
            "{name}: its kind is {}, not {kind}",
            crate::error::quoted(document.kind())
        )));
    }
    Ok(document)
}

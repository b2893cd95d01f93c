//! kiln's compensation tables as a file: one JSON document holding the layouts, the four
//! coefficients of every texel and of every average, their standard errors, the basis they are
//! coefficients of and the command that reproduces them ([`crate::table::compensation`]).
//! Read back, everything a lookup relies on is checked before the table is used: the layouts,
//! the lengths, finite numbers.

use crate::error::{Error, Result};
use crate::integrate::compensation::KILN_POLE;
use crate::table::compensation::CompensationTable;
use serde::{Deserialize, Serialize};

/// The document's `kind`.
pub const KIND: &str = "kiln-compensation";

/// The file: the table and what it is.
#[derive(Serialize, Deserialize)]
struct Document {
    kind: String,
    kiln_version: String,
    /// How a renderer evaluates the coefficients, in words.
    basis: String,
    /// The pole of the basis ([`KILN_POLE`]).
    pole: f64,
    command: String,
    max_std_error: f64,
    table: CompensationTable,
}

/// The file name of `table`'s document: `NDF-MASKING-kiln-compensation.json`.
#[must_use]
pub fn file_name(table: &CompensationTable) -> String {
    format!(
        "{}-{}-kiln-compensation.json",
        table.spec.model.ndf.name(),
        table.spec.model.masking.name()
    )
}

/// The name stem of `table`'s files and shader functions: `ggx_height_correlated_kiln_compensation`.
#[must_use]
pub fn stem(table: &CompensationTable) -> String {
    format!(
        "{}_{}_kiln_compensation",
        table.spec.model.ndf.name(),
        table.spec.model.masking.name()
    )
    .replace('-', "_")
}

/// `table`'s coefficients as an RGBA texture over its `E` layout (R = `c_0` .. A = `c_3`),
/// for [`super::ktx2`] and [`super::dds`].
#[must_use]
pub fn texture(table: &CompensationTable) -> super::texture::Texture {
    let metadata = serde_json::json!({
        "kind": KIND,
        "channels": ["c0", "c1", "c2", "c3"],
        "basis": basis_text(),
        "spec": table.spec,
        "walks": table.walks,
        "max_std_error": table.max_std_error(),
    });
    super::texture::Texture {
        shape: table.spec.shape(),
        channels: (0..4)
            .map(|j| (format!("c{j}"), table.coefficients[j].clone()))
            .collect(),
        metadata: metadata.to_string(),
    }
}

fn basis_text() -> String {
    format!(
        "M(mu, F0) = sum_j c_j(mu, r) B_j(F0) / (1 - {KILN_POLE} F0), B_j the cubic \
         Bernstein polynomials (1 - F0)^3, 3 F0 (1 - F0)^2, 3 F0^2 (1 - F0), F0^3; c_j by \
         the bilinear lookup of the coefficients at (mu, r) in the E layout of `spec`, \
         M_avg's by the lookup of `average` at r in `average_spec`; the lobe M(mu_o) M(mu_i) \
         / (pi M_avg) per channel"
    )
}

/// `table` as its JSON document, with the `command` that made it.
#[must_use]
pub fn encode(table: &CompensationTable, command: &str) -> Vec<u8> {
    let document = Document {
        kind: KIND.to_string(),
        kiln_version: super::metadata::KILN_VERSION.to_string(),
        basis: basis_text(),
        pole: KILN_POLE,
        command: command.to_string(),
        max_std_error: table.max_std_error(),
        table: table.clone(),
    };
    let mut bytes = serde_json::to_vec_pretty(&document).expect("a table serialises");
    bytes.push(b'\n');
    bytes
}

/// Reads a document [`encode`] wrote, checking it (see the module docs); `name` names the file
/// in errors.
///
/// # Errors
/// Not such a document, or a table a lookup cannot trust.
pub fn decode(bytes: &[u8], name: &str) -> Result<CompensationTable> {
    let bad = |message: String| Error::InvalidInput(format!("{name}: {message}"));
    let document: Document = serde_json::from_slice(bytes).map_err(|e| {
        bad(format!(
            "not a kiln compensation file ({}); `kiln compensation --bake DIR` writes them",
            crate::error::quoted(&e.to_string())
        ))
    })?;
    if document.kind != KIND {
        return Err(bad(format!(
            "its kind is {}, not {KIND}",
            crate::error::quoted(&document.kind)
        )));
    }
    if document.pole != KILN_POLE {
        return Err(bad(format!(
            "its basis has the pole {}, not this kiln's {KILN_POLE}: bake it again",
            crate::error::shown(document.pole)
        )));
    }
    let table = document.table;
    table.check().map_err(bad)?;
    Ok(table)
}

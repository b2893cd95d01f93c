//! The rule that keeps the files of a table consistent when a bake writes into a folder that
//! already holds tables.
//!
//! A table's files share one name ([`crate::table::TableSpec::id`]): the model, the quantity
//! and every axis convention a lookup reads differently, so tables of different layouts never
//! share a name. Two bakes can still make tables of the same name to different specs (another
//! size, method or accuracy). Before anything is written, every existing file of a table this
//! bake writes is read for the spec it was made to (its own metadata, or for files without any,
//! the sidecar beside it). The bake refuses (nothing written) when
//!
//! - a file it would replace was made to another spec, or
//! - a file it would not replace (another format) was made to another spec, or cannot be told
//!   apart from one, so that the folder would end with a mixed set,
//!
//! unless told to replace ([`Replace::Force`]): then it writes its files and removes the other
//! formats' files of that name it did not write, so the set left behind is its own. Files of the
//! same spec (the same bake run again) are replaced silently: baking is deterministic.

use super::Format;
use super::json::{KIND, Sidecar};
use super::metadata::Metadata;
use crate::error::{Error, Result};
use crate::table::TableSpec;
use std::path::{Path, PathBuf};

/// What a bake does with existing files of the tables it writes that were made to another spec.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Replace {
    /// Refuse, naming the files (the default).
    #[default]
    Refuse,
    /// Replace them, and remove the table's files in formats this bake does not write.
    Force,
}

/// Every extension kiln writes a table in.
const EXTENSIONS: [Format; 11] = [
    Format::Exr,
    Format::Bin,
    Format::Rs,
    Format::Json,
    Format::Png,
    Format::Ktx2,
    Format::Dds,
    Format::H,
    Format::Wgsl,
    Format::Glsl,
    Format::Hlsl,
];

/// The spec an existing kiln file was made to, from its own metadata; `None` for formats that
/// carry none (binary, PNG, DDS, shaders) and for files kiln cannot read as its own.
fn own_spec(path: &Path, format: Format) -> Option<TableSpec> {
    let bytes = super::read_file(path).ok()?;
    match format {
        Format::Json => serde_json::from_slice::<Sidecar>(&bytes)
            .ok()
            .filter(|sidecar| sidecar.kind == KIND)
            .map(|sidecar| sidecar.metadata.spec),
        Format::Exr => super::exr::decode(&bytes)
            .ok()?
            .metadata
            .and_then(|text| serde_json::from_str::<Metadata>(&text).ok())
            .map(|metadata| metadata.spec),
        #[cfg(feature = "containers")]
        Format::Ktx2 => {
            let text = super::ktx2::decode(&bytes).ok()?.metadata?;
            let tables = super::texture::texture_metadata(&text).ok()?;
            tables.into_iter().next().map(|metadata| metadata.spec)
        }
        Format::H | Format::Rs => {
            let text = std::str::from_utf8(&bytes).ok()?;
            super::metadata::find_embedded(text)?
                .ok()
                .map(|metadata| metadata.spec)
        }
        _ => None,
    }
}

/// A short description of a spec, to tell two apart in a message.
fn describe(spec: &TableSpec) -> String {
    let shape: Vec<String> = spec.shape().iter().map(ToString::to_string).collect();
    let method = match spec.method {
        crate::table::Method::Qmc => format!("QMC, {} samples", spec.qmc.samples),
        crate::table::Method::Reference => match spec.reference_digits {
            Some(digits) => format!("quadrature to 1e-{digits}"),
            None => "reference quadrature".to_string(),
        },
    };
    format!("{}, {method}", shape.join("x"))
}

/// The names of the files a bake of `specs` in `formats` writes (as [`super::encode_all`]
/// names them: PNG only for tables of two or three axes).
#[must_use]
pub fn planned_names(specs: &[TableSpec], formats: &[Format]) -> Vec<String> {
    let mut names = Vec::new();
    for spec in specs {
        for &format in formats {
            if format == Format::Png && spec.shape().len() < 2 {
                continue;
            }
            names.push(format!("{}.{}", spec.id(), format.name()));
        }
    }
    names
}

/// Checks, before any integration, that a bake of `specs` in `formats` into `dir` may write
/// there ([`check`]): so that a refusal comes at once, not after the bake.
pub fn precheck(
    dir: &Path,
    specs: &[TableSpec],
    formats: &[Format],
    replace: Replace,
) -> Result<()> {
    check(dir, specs, &planned_names(specs, formats), replace).map(drop)
}

/// The fields in which the spec `there` (an existing file's) differs from `here` (this
/// bake's), as `field (THERE in the file, HERE here)`, by the names files are written with;
/// nested fields joined by dots (`qmc.seed`).
#[must_use]
pub fn differences(there: &TableSpec, here: &TableSpec) -> Vec<String> {
    fn walk(path: &str, a: &serde_json::Value, b: &serde_json::Value, out: &mut Vec<String>) {
        use serde_json::Value;
        match (a, b) {
            (Value::Object(x), Value::Object(y)) => {
                let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
                keys.sort();
                keys.dedup();
                for key in keys {
                    let field = if path.is_empty() {
                        key.clone()
                    } else {
                        format!("{path}.{key}")
                    };
                    walk(
                        &field,
                        x.get(key).unwrap_or(&Value::Null),
                        y.get(key).unwrap_or(&Value::Null),
                        out,
                    );
                }
            }
            // serde_json writes any text escaped (no control characters); long values are cut.
            _ if a != b => out.push(format!(
                "{path} ({} in the file, {} here)",
                crate::error::quoted(&a.to_string()).trim_matches('\''),
                crate::error::quoted(&b.to_string()).trim_matches('\'')
            )),
            _ => {}
        }
    }
    let mut out = Vec::new();
    match (serde_json::to_value(there), serde_json::to_value(here)) {
        (Ok(a), Ok(b)) => walk("", &a, &b, &mut out),
        _ => out.push("a field that does not serialise".into()),
    }
    if out.is_empty() {
        out.push("nothing serialised (please report it)".into());
    }
    out
}

/// Checks the files of the tables of `specs` already in `dir` against the rule above, given the
/// names of the files this bake writes. Returns the files to remove once the new ones are in
/// place (only with [`Replace::Force`]); an error naming the files otherwise.
pub fn check(
    dir: &Path,
    specs: &[TableSpec],
    writing: &[String],
    replace: Replace,
) -> Result<Vec<PathBuf>> {
    let mut conflicts = Vec::new();
    let mut remove = Vec::new();
    for table_spec in specs {
        let id = table_spec.id();
        let sidecar_spec = own_spec(&dir.join(format!("{id}.json")), Format::Json);
        // (what the file was made to, its extensions), in the order found.
        let mut found: Vec<(String, Vec<&str>)> = Vec::new();
        for format in EXTENSIONS {
            let name = format!("{id}.{}", format.name());
            let path = dir.join(&name);
            if !path.is_file() {
                continue;
            }
            let replaced = writing.contains(&name);
            let spec = own_spec(&path, format).or_else(|| sidecar_spec.clone());
            let conflict = match &spec {
                Some(spec) => spec != table_spec,
                // A file of unknown spec is replaced by this bake's, or left as a stranger.
                None => !replaced,
            };
            if !conflict {
                continue;
            }
            let made = spec.map_or_else(
                || "of unknown spec".to_string(),
                |spec| {
                    format!(
                        "made to {} (differing in {})",
                        describe(&spec),
                        differences(&spec, table_spec).join(", ")
                    )
                },
            );
            match found.iter_mut().find(|(m, _)| *m == made) {
                Some((_, extensions)) => extensions.push(format.name()),
                None => found.push((made, vec![format.name()])),
            }
            if !replaced {
                remove.push(path);
            }
        }
        for (made, extensions) in found {
            conflicts.push(format!(
                "{}.{{{}}} {made}, where this bake makes {}",
                dir.join(&id).display(),
                extensions.join(","),
                describe(table_spec)
            ));
        }
    }
    if conflicts.is_empty() {
        return Ok(Vec::new());
    }
    match replace {
        Replace::Force => Ok(remove),
        Replace::Refuse => Err(Error::InvalidInput(format!(
            "{} already holds tables of these names from another bake: {}. Writing here would \
             leave a mixed set: bake into another folder (--out), or add --force to replace them \
             (and remove those tables' files in formats this bake does not write). Nothing was \
             written.",
            dir.display(),
            conflicts.join("; ")
        ))),
    }
}

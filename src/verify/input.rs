//! Reading tables to audit: kiln's own files (JSON sidecar, EXR, binary, KTX2, DDS, C header, Rust
//! source) with their metadata, and
//! external tables (text, raw f32/f16, one EXR channel) whose layout the caller describes.

use crate::error::{Error, Result};
use crate::format::json::{KIND, Sidecar};
use crate::format::metadata::Metadata;
use crate::format::{Precision, binary, exr};
use crate::integrate::QmcSettings;
use crate::model::{Model, RoughnessConvention};
use crate::table::axis::{Axis, Grid, MuMapping};
use crate::table::{Quantity, Table, TableSpec};
use std::path::Path;

/// The two kinds of axis a table can have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum AxisName {
    /// `mu = cos(theta)`.
    Mu,
    /// Roughness, in the layout's convention.
    R,
}

/// How an external table is laid out: everything a file of bare numbers does not say.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub model: Model,
    pub quantity: Quantity,
    /// The Fresnel model of an `E_F` table (`None` otherwise).
    pub fresnel: Option<crate::model::Fresnel>,
    /// Sizes, slowest-varying axis first (one size for `E_avg`).
    pub shape: Vec<usize>,
    /// The axes in the same order as `shape` (`[Mu, R]` when mu varies slowest).
    pub order: Vec<AxisName>,
    pub grid: Grid,
    pub roughness: RoughnessConvention,
    pub mu_mapping: MuMapping,
}

/// How to read the numbers of an external table.
#[derive(Clone, Debug, PartialEq)]
pub enum Encoding {
    /// Numbers separated by whitespace or commas; `#` starts a comment.
    Text,
    /// Little-endian floats and nothing else.
    Raw(Precision),
    /// One channel of an EXR image, rows top to bottom.
    ExrChannel(String),
}

fn invalid(path: &Path, message: impl std::fmt::Display) -> Error {
    Error::InvalidInput(format!("{}: {message}", path.display()))
}

fn read(path: &Path) -> Result<Vec<u8>> {
    crate::format::read_file(path)
}

/// Checks that no value is NaN or infinite, naming the first one that is.
fn check_finite(path: &Path, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(invalid(
            path,
            format!("value {k} is {}, not a finite number", values[k]),
        )),
        None => Ok(()),
    }
}

fn table_from_channel(spec: TableSpec, values: Vec<f64>, command: String) -> Table {
    Table {
        one_minus_value: values.iter().map(|v| 1.0 - v).collect(),
        std_error: vec![0.0; values.len()],
        value: values,
        spec,
        command,
        node_errors: None,
        requested_max_error: None,
    }
}

fn channel(path: &Path, channels: &[(String, Vec<f64>)], name: &str) -> Result<Vec<f64>> {
    channels
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| v.clone())
        .ok_or_else(|| {
            let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
            invalid(
                path,
                format!(
                    "no channel '{name}' (it has {}); an engine layout's file (R, G, B ...) \
                     reads with --preset NAME, another channel with --channel NAME",
                    names.join(", ")
                ),
            )
        })
}

/// Parses a kiln JSON sidecar; `Ok(None)` for JSON that is not one. A kiln sidecar this kiln
/// cannot read is an error, not an external table.
fn parse_sidecar(path: &Path, bytes: &[u8]) -> Result<Option<Sidecar>> {
    match serde_json::from_slice::<Sidecar>(bytes) {
        Ok(sidecar) if sidecar.kind == KIND => Ok(Some(sidecar)),
        Ok(_) => Ok(None),
        Err(e) => {
            let value: Option<serde_json::Value> = serde_json::from_slice(bytes).ok();
            if value
                .as_ref()
                .and_then(|v| v.get("kind"))
                .and_then(|k| k.as_str())
                == Some(KIND)
            {
                return Err(invalid(
                    path,
                    format!(
                        "unreadable kiln sidecar ({e}); was it written by another kiln version?"
                    ),
                ));
            }
            // Not JSON at all, but naming itself a kiln table: cut short or damaged.
            let marker = format!("\"kind\": \"{KIND}\"");
            if value.is_none() && bytes.windows(marker.len()).any(|w| w == marker.as_bytes()) {
                return Err(invalid(
                    path,
                    format!(
                        "a damaged kiln sidecar, not valid JSON ({e}): it was cut short or \
                         edited; bake it again (its command is in the other files' metadata)"
                    ),
                ));
            }
            Ok(None)
        }
    }
}

/// Reads one of kiln's own files, if it is one: a JSON sidecar, an EXR with kiln's metadata, or a
/// kiln binary (whose model comes from its sidecar beside it). `Ok(None)` for anything else.
pub fn read_kiln(path: &Path) -> Result<Option<Table>> {
    let bytes = read(path)?;
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let from_metadata = |metadata: Metadata, channels: &[(String, Vec<f64>)]| -> Result<Table> {
        metadata
            .spec
            .check()
            .map_err(|m| invalid(path, format!("its metadata: {m}")))?;
        if metadata.quantity != metadata.spec.quantity.symbol() {
            return Err(invalid(
                path,
                format!(
                    "its metadata names quantity {} but its spec {}",
                    metadata.quantity,
                    metadata.spec.quantity.symbol()
                ),
            ));
        }
        let values = channel(path, channels, &metadata.quantity)?;
        check_finite(path, &values)?;
        if values.len() != metadata.spec.len() {
            return Err(invalid(
                path,
                format!(
                    "{} values for shape {:?}",
                    values.len(),
                    metadata.spec.shape()
                ),
            ));
        }
        let mut table = table_from_channel(metadata.spec, values, metadata.command);
        if let Ok(one_minus) = channel(path, channels, &format!("one_minus_{}", metadata.quantity))
        {
            table.one_minus_value = one_minus;
        }
        if let Ok(std_error) = channel(path, channels, "std_error") {
            table.std_error = std_error;
        }
        table.check().map_err(|m| invalid(path, m))?;
        Ok(table)
    };
    match extension.as_str() {
        "json" => match parse_sidecar(path, &bytes)? {
            Some(sidecar) => {
                let channels: Vec<(String, Vec<f64>)> = sidecar.data.into_iter().collect();
                from_metadata(sidecar.metadata, &channels).map(Some)
            }
            None => Ok(None),
        },
        "exr" => {
            let image = exr::decode(&bytes).map_err(|e| invalid(path, e))?;
            let Some(text) = image.metadata else {
                return Ok(None);
            };
            let metadata: Metadata = serde_json::from_str(&text)
                .map_err(|e| invalid(path, format!("bad kiln metadata: {e}")))?;
            from_metadata(metadata, &image.channels).map(Some)
        }
        "ktx2" => read_kiln_texture(path, &bytes, Container::Ktx2, None, &from_metadata),
        "dds" => {
            let sidecar = sidecar_beside(path)?;
            let table = read_kiln_texture(
                path,
                &bytes,
                Container::Dds,
                sidecar.as_ref(),
                &from_metadata,
            )?;
            if let (Some(table), Some(sidecar)) = (&table, &sidecar) {
                agrees_with_sidecar(path, sidecar, table)?;
            }
            Ok(table)
        }
        "h" | "rs" => {
            let Ok(text) = std::str::from_utf8(&bytes) else {
                return Ok(None);
            };
            let metadata = match crate::format::metadata::find_embedded(text) {
                Some(parsed) => parsed.map_err(|e| invalid(path, e))?,
                None => match sidecar_beside(path)? {
                    Some(sidecar) => sidecar.metadata,
                    None => return Ok(None),
                },
            };
            let prefix = metadata.spec.id().to_uppercase().replace('-', "_");
            let c = extension == "h";
            let mut channels = Vec::new();
            for (suffix, name) in [
                ("", metadata.quantity.clone()),
                ("_ONE_MINUS", format!("one_minus_{}", metadata.quantity)),
                ("_STD_ERROR", "std_error".to_string()),
            ] {
                if let Some(values) = source_array(text, &format!("{prefix}{suffix}"), c) {
                    channels.push((name, values.map_err(|e| invalid(path, e))?));
                }
            }
            from_metadata(metadata, &channels).map(Some)
        }
        _ if bytes.starts_with(binary::MAGIC) => {
            let contents = binary::decode(&bytes).map_err(|e| invalid(path, e))?;
            let sidecar = sidecar_beside(path)?.ok_or_else(|| {
                invalid(
                    path,
                    format!(
                        "a kiln binary holds no model; its sidecar {} is missing or unreadable",
                        path.with_extension("json").display()
                    ),
                )
            })?;
            let metadata = sidecar.metadata.clone();
            metadata
                .spec
                .check()
                .map_err(|m| invalid(path, format!("its sidecar's spec: {m}")))?;
            if contents.shape != metadata.spec.shape() {
                return Err(invalid(path, "shape differs from its sidecar's"));
            }
            if contents.axes != binary::descriptors(&metadata.spec) {
                return Err(invalid(
                    path,
                    "its axis descriptors differ from its sidecar's axes (a file of another \
                     bake, or damaged)",
                ));
            }
            let table = from_metadata(metadata, &contents.channels)?;
            agrees_with_sidecar(path, &sidecar, &table)?;
            Ok(Some(table))
        }
        _ => Ok(None),
    }
}

/// Builds a table from kiln's metadata and named channels (the reader of [`read_kiln`]).
type FromMetadata<'a> = dyn Fn(Metadata, &[(String, Vec<f64>)]) -> Result<Table> + 'a;

/// The GPU containers kiln writes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Container {
    Ktx2,
    Dds,
}

/// The kiln sidecar beside `path` (`NAME.json`), if there is one, read once for both its
/// metadata and its values.
fn sidecar_beside(path: &Path) -> Result<Option<Sidecar>> {
    let sidecar_path = path.with_extension("json");
    if !sidecar_path.is_file() {
        return Ok(None);
    }
    let bytes = read(&sidecar_path)?;
    parse_sidecar(&sidecar_path, &bytes)
}

/// Checks that a file read through the sidecar beside it (binary, DDS) holds the values that
/// sidecar holds, as its precision stores them (relative 1e-3, the f16 rounding with room): a
/// kill between the renames of a bake with `--force` can leave a new file beside an old
/// sidecar of another table, which would otherwise be read under the wrong description.
fn agrees_with_sidecar(path: &Path, sidecar: &Sidecar, table: &Table) -> Result<()> {
    let Some(values) = sidecar.data.get(&sidecar.metadata.quantity) else {
        return Ok(());
    };
    let differs = values.len() != table.value.len()
        || values
            .iter()
            .zip(&table.value)
            .any(|(s, v)| (s - v).abs() > 1e-3 * s.abs() + 1e-7);
    if differs {
        return Err(invalid(
            path,
            format!(
                "it does not hold the values of its sidecar {}: the two are of different \
                 bakes (a bake interrupted while renaming its files?); bake the table again \
                 (with --force if its spec changed)",
                path.with_extension("json").display()
            ),
        ));
    }
    Ok(())
}

/// A kiln KTX2 (metadata inside) or DDS (metadata in the sidecar beside it, `beside`): R = the
/// value, G = one minus the value.
fn read_kiln_texture(
    path: &Path,
    bytes: &[u8],
    container: Container,
    beside: Option<&Sidecar>,
    from_metadata: &FromMetadata<'_>,
) -> Result<Option<Table>> {
    #[cfg(not(feature = "containers"))]
    {
        let _ = (bytes, container, beside, from_metadata);
        Err(invalid(
            path,
            "reading KTX2 and DDS files needs kiln's `containers` feature",
        ))
    }
    #[cfg(feature = "containers")]
    {
        let texture = match container {
            Container::Ktx2 => crate::format::ktx2::decode(bytes),
            Container::Dds => crate::format::dds::decode(bytes),
        }
        .map_err(|e| invalid(path, e))?;
        let metadata = match (&texture.metadata, container) {
            (Some(text), _) => {
                // A texture's metadata lists its tables; kiln's own texture holds one.
                let mut tables =
                    crate::format::texture::texture_metadata(text).map_err(|e| invalid(path, e))?;
                if tables.len() != 1 {
                    return Err(invalid(
                        path,
                        "a texture of several tables (an engine layout): read it with \
                         --preset NAME",
                    ));
                }
                tables.remove(0)
            }
            (None, Container::Ktx2) => return Ok(None),
            (None, Container::Dds) => match beside {
                Some(sidecar) => sidecar.metadata.clone(),
                None => {
                    return Err(invalid(
                        path,
                        format!(
                            "a DDS file holds no metadata: keep kiln's sidecar {} beside it, or \
                             give the layout with --preset NAME",
                            path.with_extension("json").display()
                        ),
                    ));
                }
            },
        };
        let names = [
            metadata.quantity.clone(),
            format!("one_minus_{}", metadata.quantity),
        ];
        let channels: Vec<(String, Vec<f64>)> = names.into_iter().zip(texture.channels).collect();
        from_metadata(metadata, &channels).map(Some)
    }
}

/// The numbers of the array `name` in a generated C header (`static const float NAME[N] = {
/// ... };`) or Rust source (`pub const NAME: [...] = [ ... ];`); `None` if there is no such
/// array.
fn source_array(text: &str, name: &str, c: bool) -> Option<std::result::Result<Vec<f64>, String>> {
    let declaration = if c {
        format!("static const float {name}[")
    } else {
        format!("pub const {name}: ")
    };
    let start = text.find(&declaration)? + declaration.len();
    let rest = &text[start..];
    let (open, close) = if c { ("= {", "};") } else { ("= ", "];") };
    let body = rest
        .find(open)
        .map(|k| &rest[k + open.len()..])
        .and_then(|body| body.find(close).map(|end| &body[..end]));
    let Some(body) = body else {
        return Some(Err(format!("the array {name} is not closed")));
    };
    let numbers = body
        .split(|ch: char| ch.is_whitespace() || matches!(ch, ',' | '[' | ']'))
        .filter(|token| !token.is_empty())
        .map(|token| {
            let digits = if c {
                token.trim_end_matches('f')
            } else {
                token
            };
            // The generators print the shortest literal that round-trips to the f32 they
            // store: parse it as that f32.
            digits.parse::<f32>().map(f64::from).map_err(|_| {
                format!(
                    "the array {name} holds {}, not a number",
                    crate::error::quoted(token)
                )
            })
        })
        .collect();
    Some(numbers)
}

/// Reads an external table of bare numbers laid out as `layout` says.
pub fn read_external(path: &Path, encoding: &Encoding, layout: &Layout) -> Result<Table> {
    let bytes = read(path)?;
    let values: Vec<f64> = match encoding {
        Encoding::Text => {
            let text = String::from_utf8(bytes)
                .map_err(|_| invalid(path, "not text (use --dtype for raw floats)"))?;
            let mut values = Vec::new();
            for (line_number, line) in text.lines().enumerate() {
                let line = line.split('#').next().unwrap_or("");
                for token in line
                    .split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|t| !t.is_empty())
                {
                    let value: f64 = token.parse().map_err(|_| {
                        invalid(
                            path,
                            format!(
                                "line {}: {} is not a number",
                                line_number + 1,
                                crate::error::quoted(token)
                            ),
                        )
                    })?;
                    values.push(value);
                }
            }
            values
        }
        Encoding::Raw(precision) => {
            let size = precision.bytes();
            if bytes.len() % size != 0 {
                return Err(invalid(
                    path,
                    format!(
                        "{} bytes is not a whole number of {}-byte floats",
                        bytes.len(),
                        size
                    ),
                ));
            }
            bytes
                .chunks_exact(size)
                .map(|b| match precision {
                    Precision::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Precision::F16 => f64::from(half::f16::from_le_bytes([b[0], b[1]]).to_f32()),
                })
                .collect()
        }
        Encoding::ExrChannel(name) => {
            let image = exr::decode(&bytes).map_err(|e| invalid(path, e))?;
            channel(path, &image.channels, name)?
        }
    };
    let expected: usize = layout.shape.iter().product();
    if values.len() != expected {
        return Err(invalid(
            path,
            format!(
                "holds {} values but the layout {:?} needs {expected}",
                values.len(),
                layout.shape
            ),
        ));
    }
    check_finite(path, &values)?;
    let (spec, values) = spec_and_values(layout, values).map_err(|m| invalid(path, m))?;
    let table = table_from_channel(spec, values, format!("external table {}", path.display()));
    table.check().map_err(|m| invalid(path, m))?;
    Ok(table)
}

/// Builds kiln's spec for a layout and reorders the values into kiln's order (roughness slowest).
fn spec_and_values(
    layout: &Layout,
    values: Vec<f64>,
) -> std::result::Result<(TableSpec, Vec<f64>), String> {
    let roughness_axis = |size| Axis::Roughness {
        size,
        convention: layout.roughness,
        grid: layout.grid,
    };
    let mu_axis = |size| Axis::Mu {
        size,
        mapping: layout.mu_mapping,
        grid: layout.grid,
    };
    let spec = |roughness, mu| TableSpec {
        reference_digits: None,
        lookup_of: None,
        transmission: crate::model::dielectric::TransmissionConvention::SingleScattering,
        model: layout.model,
        quantity: layout.quantity,
        fresnel: layout.fresnel,
        ior: None,
        roughness: Some(roughness),
        mu,
        method: crate::table::Method::Qmc,
        qmc: QmcSettings::default(),
    };
    if layout.shape.len() != layout.order.len() {
        return Err(format!(
            "--shape has {} sizes but --order names {} axes",
            layout.shape.len(),
            layout.order.len()
        ));
    }
    if layout.shape.iter().any(|&n| n < 2) {
        return Err(format!(
            "every axis needs at least 2 samples (shape {:?})",
            layout.shape
        ));
    }
    layout.model.validate()?;
    if layout.quantity.has_ior() {
        return Err(format!(
            "--quantity {}: only kiln's own dielectric and F_avg tables can be audited (their \
             sidecar or header describes the IOR axis); external layouts with an IOR axis are \
             not supported yet",
            layout.quantity.cli_name()
        ));
    }
    let two_d = layout.quantity.has_mu();
    match (two_d, &layout.order[..], &layout.shape[..]) {
        (false, [AxisName::R], &[n]) => Ok((spec(roughness_axis(n), None), values)),
        (true, [AxisName::R, AxisName::Mu], &[rows, columns]) => {
            Ok((spec(roughness_axis(rows), Some(mu_axis(columns))), values))
        }
        (true, [AxisName::Mu, AxisName::R], &[n_mu, n_r]) => {
            // Transpose into roughness-major order.
            let transposed = (0..n_r * n_mu)
                .map(|k| values[(k % n_mu) * n_r + k / n_mu])
                .collect();
            Ok((spec(roughness_axis(n_r), Some(mu_axis(n_mu))), transposed))
        }
        (true, _, _) => Err(format!(
            "an {} table needs two axes, e.g. --shape 32x32 --order mu,r",
            layout.quantity.symbol()
        )),
        (false, _, _) => {
            Err("an E_avg table has one roughness axis, e.g. --shape 32 --order r".into())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Masking, Ndf};

    #[test]
    fn mu_major_tables_are_transposed_into_roughness_major_order() {
        let layout = Layout {
            model: Model {
                ndf: Ndf::Ggx,
                masking: Masking::HeightCorrelated,
            },
            quantity: Quantity::E,
            fresnel: None,
            shape: vec![3, 2],
            order: vec![AxisName::Mu, AxisName::R],
            grid: Grid::Nodes,
            roughness: RoughnessConvention::Perceptual,
            mu_mapping: MuMapping::Linear,
        };
        // value = 10 * mu_index + r_index, stored mu-major.
        let values = vec![0.0, 1.0, 10.0, 11.0, 20.0, 21.0];
        let (spec, reordered) = spec_and_values(&layout, values).unwrap();
        assert_eq!(spec.shape(), [2, 3]);
        assert_eq!(reordered, [0.0, 10.0, 20.0, 1.0, 11.0, 21.0]);
    }
}

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
    /// The roughness rows' spacing (kiln's balanced rows, or linear as engines' are).
    pub roughness_spacing: crate::table::axis::RoughnessSpacing,
    /// Point samples, or texels fitted for the lookup (which verify judges by the lookup).
    pub texels: crate::table::Texels,
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

pub(super) fn table_from_channel(spec: TableSpec, values: Vec<f64>, command: String) -> Table {
    Table::of_values(spec, values, command)
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
fn source_array(text: &str, name: &str, c: bool) -> Option<crate::Result<Vec<f64>>> {
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
        return Some(Err(crate::Error::Malformed(format!(
            "the array {name} is not closed"
        ))));
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
                crate::Error::Malformed(format!(
                    "the array {name} holds {}, not a number",
                    crate::error::quoted(token)
                ))
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
            if bytes.starts_with(b"\x89PNG") {
                return Err(invalid(
                    path,
                    "a PNG image, not a table of numbers: an engine's 8-bit PNG table is read \
                     with --preset games202; --shape reads text (numbers) or, with --dtype, raw \
                     floats",
                ));
            }
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
fn spec_and_values(layout: &Layout, values: Vec<f64>) -> crate::Result<(TableSpec, Vec<f64>)> {
    let roughness_axis = |size| Axis::Roughness {
        size,
        convention: layout.roughness,
        grid: layout.grid,
        spacing: layout.roughness_spacing,
    };
    let mu_axis = |size| Axis::Mu {
        size,
        mapping: layout.mu_mapping,
        grid: layout.grid,
    };
    let spec = |roughness, mu| TableSpec {
        reference_digits: None,
        lookup_of: None,
        refined_start: None,
        texels: layout.texels,
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
        return Err(crate::Error::Malformed(format!(
            "--shape has {} sizes but --order names {} axes",
            layout.shape.len(),
            layout.order.len()
        )));
    }
    if layout.shape.iter().any(|&n| n < 2) {
        return Err(crate::Error::Malformed(format!(
            "every axis needs at least 2 samples (shape {:?})",
            layout.shape
        )));
    }
    layout.model.validate()?;
    if layout.quantity.has_ior() {
        return Err(crate::Error::Malformed(format!(
            "--quantity {}: only kiln's own dielectric and F_avg tables can be audited (their \
             sidecar or header describes the IOR axis); external layouts with an IOR axis are \
             not supported yet",
            layout.quantity.cli_name()
        )));
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
        (true, _, _) => Err(crate::Error::Malformed(format!(
            "an {} table needs two axes, e.g. --shape 32x32 --order mu,r",
            layout.quantity.symbol()
        ))),
        (false, _, _) => Err(crate::Error::Malformed(
            "an E_avg table has one roughness axis, e.g. --shape 32 --order r".into(),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::Format;
    use crate::model::{Masking, Ndf};
    use crate::table::test_e_spec;
    use std::path::PathBuf;

    /// A directory of its own for one test, removed when the test ends.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(name: &str) -> Self {
            let dir =
                std::env::temp_dir().join(format!("kiln-input-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }

        fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
            let path = self.0.join(name);
            std::fs::write(&path, bytes).unwrap();
            path
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// A 3 x 4 E table whose texel k holds `0.9 - 0.01 k` (and a std_error of `1e-6 k`).
    fn e_table(mapping: MuMapping, columns: usize) -> Table {
        let spec = test_e_spec(3, columns, Grid::Nodes, mapping);
        let n = spec.len();
        let mut table = table_from_channel(
            spec,
            (0..n).map(|k| 0.9 - 0.01 * k as f64).collect(),
            "kiln bake".into(),
        );
        table.std_error = (0..n).map(|k| 1e-6 * k as f64).collect();
        table
    }

    /// Every kiln file of `table` in `dir`, by extension.
    fn write_kiln_files(dir: &Scratch, table: &Table) -> Vec<PathBuf> {
        let formats = [
            Format::Exr,
            Format::Bin,
            Format::Rs,
            Format::H,
            Format::Ktx2,
            Format::Dds,
            Format::Json,
        ];
        crate::format::encode_all(std::slice::from_ref(table), &formats, Precision::F32)
            .unwrap()
            .into_iter()
            .map(|(name, bytes)| dir.write(&name, &bytes))
            .collect()
    }

    #[track_caller]
    fn error(result: Result<Option<Table>>) -> String {
        result.expect_err("an error").to_string()
    }

    /// A sidecar's JSON with `edit` applied.
    fn edited_sidecar(table: &Table, edit: impl Fn(&mut serde_json::Value)) -> Vec<u8> {
        let sidecar = crate::format::json::sidecar(table, "f32", Default::default());
        let mut value: serde_json::Value =
            serde_json::from_slice(&crate::format::json::encode(&sidecar).unwrap()).unwrap();
        edit(&mut value);
        serde_json::to_vec_pretty(&value).unwrap()
    }

    #[test]
    fn every_kiln_format_reads_back_as_written() {
        let dir = Scratch::new("formats");
        let table = e_table(MuMapping::Sqrt, 4);
        let paths = write_kiln_files(&dir, &table);
        assert_eq!(paths.len(), 7);
        for path in &paths {
            let read = read_kiln(path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .unwrap_or_else(|| panic!("{}: not read as kiln's", path.display()));
            assert_eq!(read.spec, table.spec, "{}", path.display());
            assert_eq!(read.command, table.command, "{}", path.display());
            // As the f32 the file stores (the sidecar: f64).
            let extension = path.extension().unwrap().to_str().unwrap();
            let stored = |v: f64| {
                if extension == "json" {
                    v
                } else {
                    f64::from(v as f32)
                }
            };
            for k in 0..12 {
                let stored_value = stored(table.value[k]);
                assert_eq!(read.value[k], stored_value, "{} value {k}", path.display());
                let one_minus = stored(table.one_minus_value[k]);
                assert_eq!(
                    read.one_minus_value[k],
                    one_minus,
                    "{} 1 - E {k}",
                    path.display()
                );
            }
            // Only the sidecar, the EXR, the binary and the sources carry std_error.
            if !matches!(extension, "ktx2" | "dds") {
                let e = stored(1e-6 * 11.0);
                assert_eq!(read.std_error[11], e, "{}", path.display());
            }
        }
    }

    #[test]
    fn other_files_are_not_kilns() {
        let dir = Scratch::new("others");
        let table = e_table(MuMapping::Linear, 4);
        for (name, bytes) in [
            ("numbers.txt", b"0.5 0.25".as_slice()),
            (
                "other.json",
                br#"{"kind": "something-else", "x": 1}"#.as_slice(),
            ),
            ("array.json", b"[1, 2, 3]".as_slice()),
            ("broken.json", b"{ not json".as_slice()),
            (
                "long.json",
                b"{ not json either, and longer than kiln's kind marker }".as_slice(),
            ),
            (
                "plain.h",
                b"static const float X[2] = { 1.0f, 2.0f };".as_slice(),
            ),
            ("binary.rs", [0xff, 0xfe, 0x00].as_slice()),
        ] {
            let path = dir.write(name, bytes);
            assert!(read_kiln(&path).unwrap().is_none(), "{name}");
        }
        // A sidecar's structure under another kind is not kiln's.
        let foreign = edited_sidecar(&table, |v| v["kind"] = "other-table".into());
        assert!(
            read_kiln(&dir.write("foreign.json", &foreign))
                .unwrap()
                .is_none()
        );
        // A sidecar whose kind is kiln's: read as kiln's even when the name says otherwise.
        let sidecar = edited_sidecar(&table, |_| {});
        let path = dir.write("renamed.json", &sidecar);
        assert!(read_kiln(&path).unwrap().is_some());
    }

    #[test]
    fn a_damaged_sidecar_says_what_is_wrong() {
        let dir = Scratch::new("sidecars");
        let table = e_table(MuMapping::Linear, 4);
        let read = |name: &str, bytes: &[u8]| error(read_kiln(&dir.write(name, bytes)));
        // Valid JSON, kiln's kind, another structure.
        let message = read("a.json", br#"{"kind": "kiln-table", "metadata": 3}"#);
        assert!(message.contains("unreadable kiln sidecar"), "{message}");
        // Cut short (as kiln writes it: its kind first).
        let sidecar = crate::format::json::sidecar(&table, "f32", Default::default());
        let whole = crate::format::json::encode(&sidecar).unwrap();
        let message = read("b.json", &whole[..whole.len() / 2]);
        assert!(
            message.contains("a damaged kiln sidecar, not valid JSON"),
            "{message}"
        );
        // The metadata's quantity and the spec's disagree.
        let message = read(
            "c.json",
            &edited_sidecar(&table, |v| v["quantity"] = "E_avg".into()),
        );
        assert!(
            message.contains("its metadata names quantity E_avg but its spec E"),
            "{message}"
        );
        // The quantity's channel is missing.
        let message = read(
            "d.json",
            &edited_sidecar(&table, |v| {
                v["data"].as_object_mut().unwrap().remove("E");
            }),
        );
        assert!(
            message.contains("no channel 'E' (it has one_minus_E, std_error)"),
            "{message}"
        );
        // One value short.
        let message = read(
            "e.json",
            &edited_sidecar(&table, |v| {
                v["data"]["E"].as_array_mut().unwrap().pop();
            }),
        );
        assert!(message.contains("11 values for shape [3, 4]"), "{message}");
        // A value out of range: the table's own check.
        let message = read(
            "f.json",
            &edited_sidecar(&table, |v| v["data"]["E"][2] = 1.5.into()),
        );
        assert!(
            message.contains("E at texel 2 is 1.5, outside [0, 1]"),
            "{message}"
        );
        // The spec's own check.
        let message = read(
            "g.json",
            &edited_sidecar(&table, |v| v["spec"]["mu"] = serde_json::Value::Null),
        );
        assert!(
            message.contains("its metadata: E needs a mu axis"),
            "{message}"
        );
        // The one-minus channel is optional: without it, it is 1 - E.
        let path = dir.write(
            "h.json",
            &edited_sidecar(&table, |v| {
                v["data"].as_object_mut().unwrap().remove("one_minus_E");
                v["data"].as_object_mut().unwrap().remove("std_error");
            }),
        );
        let read = read_kiln(&path).unwrap().unwrap();
        assert_eq!(read.one_minus_value[3], 1.0 - read.value[3]);
        assert_eq!(read.std_error, vec![0.0; 12]);
    }

    /// The 3 x 4 test table's files in `dir`: the table, its file of `extension` and its
    /// sidecar.
    fn written(dir: &Scratch, extension: &str) -> (Table, PathBuf, PathBuf) {
        let table = e_table(MuMapping::Linear, 4);
        let file = write_kiln_files(dir, &table)
            .into_iter()
            .find(|p| p.extension().unwrap() == extension)
            .unwrap();
        let sidecar = file.with_extension("json");
        (table, file, sidecar)
    }

    /// The sidecar of the same layout with one value changed.
    fn other_values_sidecar() -> Vec<u8> {
        let mut other = e_table(MuMapping::Linear, 4);
        other.value[5] = 0.5;
        other.one_minus_value[5] = 0.5;
        edited_sidecar(&other, |_| {})
    }

    #[test]
    fn a_binary_needs_its_own_sidecar() {
        let dir = Scratch::new("binary");
        let (table, bin, sidecar) = written(&dir, "bin");
        let bin = &bin;
        let bytes = std::fs::read(&sidecar).unwrap();
        // Without it.
        std::fs::remove_file(&sidecar).unwrap();
        assert!(error(read_kiln(bin)).contains("a kiln binary holds no model"));
        // Beside the sidecar of a table of other values.
        std::fs::write(&sidecar, other_values_sidecar()).unwrap();
        assert!(error(read_kiln(bin)).contains("does not hold the values of its sidecar"));
        // Beside the sidecar of another shape, or other axes.
        std::fs::write(
            &sidecar,
            edited_sidecar(&e_table(MuMapping::Linear, 5), |_| {}),
        )
        .unwrap();
        assert!(error(read_kiln(bin)).contains("shape differs from its sidecar's"));
        std::fs::write(
            &sidecar,
            edited_sidecar(&e_table(MuMapping::Sqrt, 4), |_| {}),
        )
        .unwrap();
        assert!(error(read_kiln(bin)).contains("axis descriptors differ"));
        // A sidecar whose spec is broken.
        std::fs::write(
            &sidecar,
            edited_sidecar(&table, |v| v["spec"]["mu"] = serde_json::Value::Null),
        )
        .unwrap();
        assert!(error(read_kiln(bin)).contains("its sidecar's spec: E needs a mu axis"));
        // Its own again.
        std::fs::write(&sidecar, bytes).unwrap();
        assert!(read_kiln(bin).unwrap().is_some());
    }

    #[test]
    fn a_dds_file_needs_its_own_sidecar() {
        let dir = Scratch::new("dds");
        let (_, dds, sidecar) = written(&dir, "dds");
        let dds = &dds;
        std::fs::write(&sidecar, other_values_sidecar()).unwrap();
        assert!(error(read_kiln(dds)).contains("does not hold the values of its sidecar"));
        std::fs::remove_file(&sidecar).unwrap();
        assert!(error(read_kiln(dds)).contains("a DDS file holds no metadata"));
    }

    #[test]
    fn values_agree_with_a_sidecar_to_the_precision_stored() {
        let path = Path::new("t.bin");
        let table = e_table(MuMapping::Linear, 4);
        let sidecar = |edit: &dyn Fn(&mut Vec<f64>)| {
            let mut s = crate::format::json::sidecar(&table, "f32", Default::default());
            edit(s.data.get_mut("E").unwrap());
            s
        };
        let agrees = |s: &Sidecar| agrees_with_sidecar(path, s, &table).is_ok();
        assert!(agrees(&sidecar(&|_| {})));
        // Within 1e-3 relative (plus 1e-7): the rounding of half floats.
        assert!(agrees(&sidecar(&|v| v[0] *= 1.0 + 0.9e-3)));
        assert!(!agrees(&sidecar(&|v| v[0] *= 1.0 + 1.1e-3)));
        assert!(!agrees(&sidecar(&|v| v[11] *= 1.0 - 1.1e-3)));
        // 1e-3 of the sidecar's value and half the 1e-7 more: within, thanks to the 1e-7.
        assert!(agrees(&sidecar(
            &|v| v[11] += (1e-3 * v[11] + 0.5e-7) / (1.0 - 1e-3)
        )));
        assert!(!agrees(&sidecar(
            &|v| v[11] += (1e-3 * v[11] + 1.5e-7) / (1.0 - 1e-3)
        )));
        assert!(!agrees(&sidecar(&|v| {
            v.pop();
        })));
        // A sidecar without the values cannot disagree.
        let mut s = sidecar(&|_| {});
        s.data.clear();
        assert!(agrees(&s));
    }

    #[test]
    fn arrays_are_read_from_generated_sources() {
        let c = "static const float T[3] = { 1.0f, 2.5f,\n -3e-2f };\nstatic const float T_ONE_MINUS[1] = { 0.5f };";
        assert_eq!(
            source_array(c, "T", true).unwrap().unwrap(),
            vec![1.0, 2.5, f64::from(-3e-2f32)]
        );
        assert_eq!(
            source_array(c, "T_ONE_MINUS", true).unwrap().unwrap(),
            vec![0.5]
        );
        assert!(source_array(c, "U", true).is_none());
        let rust = "pub const T: [f32; 3] = [1.0, 2.5, -3e-2];\npub const T_STD_ERROR: [[f32; 1]; 1] = [[0.25]];";
        assert_eq!(
            source_array(rust, "T", false).unwrap().unwrap(),
            vec![1.0, 2.5, f64::from(-3e-2f32)]
        );
        assert_eq!(
            source_array(rust, "T_STD_ERROR", false).unwrap().unwrap(),
            vec![0.25]
        );
        // The shortest f32 literal is read as that f32: 0.1 is 0.1f32 widened.
        let tenth = source_array("pub const A: [f32; 1] = [0.1];", "A", false);
        assert_eq!(tenth.unwrap().unwrap(), vec![f64::from(0.1f32)]);
        let open = source_array("static const float T[2] = { 1.0f, 2.0f", "T", true);
        assert!(
            open.unwrap()
                .unwrap_err()
                .to_string()
                .contains("the array T is not closed")
        );
        let bad = source_array("pub const T: [f32; 2] = [1.0, x2];", "T", false);
        assert!(
            bad.unwrap()
                .unwrap_err()
                .to_string()
                .contains("the array T holds 'x2', not a number")
        );
    }

    fn layout(quantity: Quantity, shape: Vec<usize>, order: Vec<AxisName>) -> Layout {
        Layout {
            model: Model {
                ndf: Ndf::Ggx,
                masking: Masking::HeightCorrelated,
            },
            quantity,
            fresnel: None,
            shape,
            order,
            grid: Grid::Nodes,
            roughness: RoughnessConvention::Perceptual,
            mu_mapping: MuMapping::Linear,
            roughness_spacing: crate::table::axis::RoughnessSpacing::Linear,
            texels: crate::table::Texels::Nodes,
        }
    }

    #[test]
    fn external_numbers_are_read_as_text_or_raw_floats() {
        let dir = Scratch::new("external");
        let e = layout(Quantity::E, vec![2, 3], vec![AxisName::R, AxisName::Mu]);
        let text = dir.write(
            "e.txt",
            b"# a comment\n0.5, 0.25 0.125 # more\n\n1,0.75,\t0.625\n",
        );
        let table = read_external(&text, &Encoding::Text, &e).unwrap();
        assert_eq!(table.value, vec![0.5, 0.25, 0.125, 1.0, 0.75, 0.625]);
        assert_eq!(table.one_minus_value[1], 0.75);
        assert_eq!(table.spec.shape(), vec![2, 3]);
        assert_eq!(table.command, format!("external table {}", text.display()));
        // Raw little-endian f32 and f16.
        let values = [0.5f32, 0.25, 0.125, 1.0, 0.75, 0.625];
        let f32s: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let raw = dir.write("e.f32", &f32s);
        let table = read_external(&raw, &Encoding::Raw(Precision::F32), &e).unwrap();
        assert_eq!(table.value, vec![0.5, 0.25, 0.125, 1.0, 0.75, 0.625]);
        let f16s: Vec<u8> = values
            .iter()
            .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
            .collect();
        let raw = dir.write("e.f16", &f16s);
        let table = read_external(&raw, &Encoding::Raw(Precision::F16), &e).unwrap();
        assert_eq!(table.value, vec![0.5, 0.25, 0.125, 1.0, 0.75, 0.625]);
        // 0.1 as a half float is 0.0999755859375.
        let raw = dir.write("tenth.f16", &[0x66, 0x2e].repeat(6));
        let table = read_external(&raw, &Encoding::Raw(Precision::F16), &e).unwrap();
        assert_eq!(table.value[0], 0.0999755859375);
    }

    #[test]
    fn external_numbers_that_do_not_fit_are_refused_with_the_reason() {
        let dir = Scratch::new("external-errors");
        let e = layout(Quantity::E, vec![2, 3], vec![AxisName::R, AxisName::Mu]);
        let read = |name: &str, bytes: &[u8], encoding: Encoding| {
            read_external(&dir.write(name, bytes), &encoding, &e)
                .unwrap_err()
                .to_string()
        };
        let message = read("a.txt", b"0.5 0.5\n0.5 abc", Encoding::Text);
        assert!(
            message.contains("line 2: 'abc' is not a number"),
            "{message}"
        );
        let message = read("b.txt", &[0xff, 0xfe, 0x30], Encoding::Text);
        assert!(
            message.contains("not text (use --dtype for raw floats)"),
            "{message}"
        );
        let message = read("c.txt", b"0.5 0.5 0.5 0.5 0.5", Encoding::Text);
        assert!(
            message.contains("holds 5 values but the layout [2, 3] needs 6"),
            "{message}"
        );
        let message = read("d.txt", b"0.5 0.5 0.5 NaN 0.5 inf", Encoding::Text);
        assert!(
            message.contains("value 3 is NaN, not a finite number"),
            "{message}"
        );
        let message = read("e.f32", &[0; 7], Encoding::Raw(Precision::F32));
        assert!(
            message.contains("7 bytes is not a whole number of 4-byte floats"),
            "{message}"
        );
        let message = read("f.f16", &[0; 13], Encoding::Raw(Precision::F16));
        assert!(message.contains("13 bytes is not a whole number of 2-byte floats"));
        let message = read("g.txt", b"0.5 0.5 0.5 0.5 0.5 1.5", Encoding::Text);
        assert!(
            message.contains("E at texel 5 is 1.5, outside [0, 1]"),
            "{message}"
        );
        // An EXR channel that is not there.
        let table = e_table(MuMapping::Linear, 4);
        let exr = crate::format::exr::encode(&table, Precision::F32).unwrap();
        let message = read("h.exr", &exr, Encoding::ExrChannel("G".into()));
        assert!(
            message.contains("no channel 'G' (it has E, one_minus_E"),
            "{message}"
        );
    }

    #[test]
    fn an_exr_channel_is_read_by_name() {
        let dir = Scratch::new("exr-channel");
        let table = e_table(MuMapping::Linear, 4);
        let path = dir.write(
            "t.exr",
            &crate::format::exr::encode(&table, Precision::F32).unwrap(),
        );
        let e = layout(Quantity::E, vec![3, 4], vec![AxisName::R, AxisName::Mu]);
        let read = read_external(&path, &Encoding::ExrChannel("one_minus_E".into()), &e).unwrap();
        assert_eq!(read.value[4], f64::from((1.0 - (0.9 - 0.04)) as f32));
    }

    #[test]
    fn layouts_are_checked_against_their_quantity() {
        let values = |n: usize| vec![0.5; n];
        let fails = |l: Layout, n: usize| spec_and_values(&l, values(n)).unwrap_err();
        let (r, mu) = (AxisName::R, AxisName::Mu);
        assert!(
            fails(layout(Quantity::E, vec![2, 3], vec![r]), 6)
                .to_string()
                .contains("--shape has 2 sizes but --order names 1 axes")
        );
        assert!(
            fails(layout(Quantity::E, vec![1, 3], vec![r, mu]), 3)
                .to_string()
                .contains("every axis needs at least 2 samples (shape [1, 3])")
        );
        assert!(
            fails(layout(Quantity::EDielectric, vec![2, 3], vec![r, mu]), 6)
                .to_string()
                .contains("--quantity e-dielectric: only kiln's own dielectric")
        );
        assert!(
            fails(layout(Quantity::E, vec![6], vec![r]), 6)
                .to_string()
                .contains("an E table needs two axes")
        );
        assert!(
            fails(layout(Quantity::E, vec![2, 3], vec![r, r]), 6)
                .to_string()
                .contains("an E table needs two axes")
        );
        assert!(
            fails(layout(Quantity::EAvg, vec![2, 3], vec![r, mu]), 6)
                .to_string()
                .contains("an E_avg table has one roughness axis")
        );
        let mut bad_model = layout(Quantity::E, vec![2, 3], vec![r, mu]);
        bad_model.model = Model {
            ndf: Ndf::Beckmann,
            masking: Masking::SchlickGgx,
        };
        assert!(
            fails(bad_model, 6)
                .to_string()
                .contains("goes with --ndf ggx only")
        );
        // The forms that work: E_avg over r, E over (r, mu) as stored.
        let (spec, v) =
            spec_and_values(&layout(Quantity::EAvg, vec![4], vec![r]), values(4)).unwrap();
        assert_eq!((spec.shape(), spec.mu, v.len()), (vec![4], None, 4));
        let stored: Vec<f64> = (0..6).map(f64::from).collect();
        let (spec, v) = spec_and_values(
            &layout(Quantity::E, vec![2, 3], vec![r, mu]),
            stored.clone(),
        )
        .unwrap();
        assert_eq!((spec.shape(), v), (vec![2, 3], stored));
    }

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
            roughness_spacing: crate::table::axis::RoughnessSpacing::Linear,
            texels: crate::table::Texels::Nodes,
        };
        // value = 10 * mu_index + r_index, stored mu-major.
        let values = vec![0.0, 1.0, 10.0, 11.0, 20.0, 21.0];
        let (spec, reordered) = spec_and_values(&layout, values).unwrap();
        assert_eq!(spec.shape(), [2, 3]);
        assert_eq!(reordered, [0.0, 10.0, 20.0, 1.0, 11.0, 21.0]);
    }
}

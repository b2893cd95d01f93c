//! Output formats, and writing them without ever leaving a partial file.
//!
//! Every file is encoded in memory first; then each is written to a temporary file in the output
//! directory and renamed into place only after all of them were written. A failure part-way
//! removes the temporaries; a reader never sees a half-written table.

pub mod anisotropic;
pub mod binary;
pub mod c_header;
pub mod comment;
pub mod compensation;
#[cfg(feature = "containers")]
pub mod dds;
pub mod document;
pub mod exr;
pub mod f16;
pub mod folder_lock;
pub mod glass_compensation;
pub mod json;
pub mod ktx2;
pub mod metadata;
pub mod png;
pub mod replace;
pub mod rust;
pub mod shader;
pub mod texture;

use crate::error::{Error, Result};
use crate::table::Table;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// An output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Format {
    /// OpenEXR, channels `E`, `one_minus_E`, `std_error`, metadata in the header.
    Exr,
    /// kiln's raw binary format (see the module `binary`).
    Bin,
    /// Rust source with `pub const` arrays.
    Rs,
    /// JSON sidecar with metadata and f64 values.
    Json,
    /// PNG heat map (2-D tables only).
    Png,
    /// KTX2 texture: R = value, G = 1 - value, `R16G16_SFLOAT` (`--precision f16`) or
    /// `R32G32_SFLOAT`, metadata as key/value data (not written by default).
    Ktx2,
    /// DDS texture with the DX10 header: `R16G16_FLOAT` or `R32G32_FLOAT` (not written by
    /// default).
    Dds,
    /// C/C++ header: float arrays and interleaved half-float bits (not written by default).
    H,
    /// WGSL lookup functions for the table's KTX2/DDS texture (not written by default).
    Wgsl,
    /// GLSL 4.50 lookup functions (not written by default).
    Glsl,
    /// HLSL lookup functions (not written by default).
    Hlsl,
}

impl Format {
    /// The formats written by default, in the order they are written.
    pub const ALL: [Format; 5] = [
        Format::Exr,
        Format::Bin,
        Format::Rs,
        Format::Json,
        Format::Png,
    ];

    /// The name on the command line, which is also the file extension.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Format::Exr => "exr",
            Format::Bin => "bin",
            Format::Rs => "rs",
            Format::Json => "json",
            Format::Png => "png",
            Format::Ktx2 => "ktx2",
            Format::Dds => "dds",
            Format::H => "h",
            Format::Wgsl => "wgsl",
            Format::Glsl => "glsl",
            Format::Hlsl => "hlsl",
        }
    }
}

/// How the value channels are stored in EXR and binary files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Precision {
    /// IEEE single precision, 4 bytes.
    F32,
    /// IEEE half precision, 2 bytes (spacing 2^-11 just below 1: near 1, the `1 - value`
    /// channel kiln stores beside the value keeps the precision the value loses).
    F16,
}

impl Precision {
    /// Appends `value` to `out` little-endian in this precision (f16 rounded once, from f64:
    /// [`f16::encode`]).
    pub fn push_le(self, out: &mut Vec<u8>, value: f64) {
        match self {
            Precision::F32 => out.extend_from_slice(&(value as f32).to_le_bytes()),
            Precision::F16 => out.extend_from_slice(&f16::encode(value).0.to_le_bytes()),
        }
    }

    /// `f32` or `f16`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F16 => "f16",
        }
    }

    /// The precision `table`'s value channels are stored in when this one is asked: as asked,
    /// but `f_ms_norm` always in f32. Its values, `(1 - Ē) / r`, fall to 3.4e-5 at low
    /// roughness, below f16's smallest normal number (6.1e-5), where half floats are 6e-8
    /// apart (2e-3 relative; 4e-4 relative at the top), far from the 1e-4 relative the table
    /// is made to; it is 817 values (3 KB in f32).
    #[must_use]
    pub fn stored_for(self, table: &Table) -> Precision {
        if table.spec.quantity == crate::table::Quantity::FMsNorm {
            Precision::F32
        } else {
            self
        }
    }

    /// Bytes per value.
    #[must_use]
    pub fn bytes(self) -> usize {
        match self {
            Precision::F32 => 4,
            Precision::F16 => 2,
        }
    }

    /// The binary format's dtype code.
    #[must_use]
    pub fn code(self) -> u32 {
        match self {
            Precision::F32 => 1,
            Precision::F16 => 2,
        }
    }

    /// The precision of a binary dtype code.
    #[must_use]
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            1 => Some(Precision::F32),
            2 => Some(Precision::F16),
            _ => None,
        }
    }
}

/// Encodes each table in each format: `(file name, bytes)` pairs, file names from
/// [`crate::table::TableSpec::id`] and the format's extension. PNG is skipped for 1-D tables.
pub fn encode_all(
    tables: &[Table],
    formats: &[Format],
    precision: Precision,
) -> Result<Vec<(String, Vec<u8>)>> {
    let mut files = Vec::new();
    let tables = as_stored(tables, precision);
    let asked = precision;
    for table in &tables {
        let precision = asked.stored_for(table);
        let id = table.spec.id();
        let fail = |format: Format, message: String| Error::Format {
            path: PathBuf::from(format!("{id}.{}", format.name())),
            message,
        };
        let mut written = BTreeMap::new();
        for &format in formats {
            let bytes = match format {
                Format::Exr => {
                    exr::encode(table, precision).map_err(|m| fail(format, m.to_string()))?
                }
                Format::Bin => binary::encode(table, precision),
                Format::Rs => rust::encode(table).into_bytes(),
                Format::Png => match png::encode(table) {
                    None => continue,
                    Some(result) => result.map_err(|m| fail(format, m.to_string()))?,
                },
                Format::Ktx2 => ktx2::encode(&texture::Texture::of_table(table), precision)
                    .map_err(|m| fail(format, m.to_string()))?,
                #[cfg(feature = "containers")]
                Format::Dds => dds::encode(&texture::Texture::of_table(table), precision)
                    .map_err(|m| fail(format, m.to_string()))?,
                #[cfg(not(feature = "containers"))]
                Format::Dds => {
                    return Err(fail(
                        format,
                        "DDS output needs kiln's `containers` feature".to_string(),
                    ));
                }
                Format::H => c_header::encode(table).into_bytes(),
                Format::Wgsl => shader::encode(table, shader::Language::Wgsl).into_bytes(),
                Format::Glsl => shader::encode(table, shader::Language::Glsl).into_bytes(),
                Format::Hlsl => shader::encode(table, shader::Language::Hlsl).into_bytes(),
                Format::Json => continue, // last, once the others are known
            };
            let name = format!("{id}.{}", format.name());
            written.insert(format.name().to_string(), name.clone());
            files.push((name, bytes));
        }
        if formats.contains(&Format::Json) {
            let sidecar = json::sidecar(table, precision.name(), written);
            let bytes = json::encode(&sidecar).map_err(|m| fail(Format::Json, m.to_string()))?;
            files.push((format!("{id}.json"), bytes));
        }
    }
    Ok(files)
}

/// The tables as files of `precision` hold them, where that changes what another table must
/// say: the lookup-consistent normalisation (`f_ms_norm`) of an E table stored in half floats
/// is derived from the E table's values as stored (rounded to f16, [`f16::encode`]), so that
/// it is the average of the lookup a renderer of those files really makes.
#[must_use]
pub fn as_stored(tables: &[Table], precision: Precision) -> Vec<Table> {
    tables
        .iter()
        .map(|table| {
            let source = table.spec.lookup_of.as_deref();
            let e = tables.iter().find(|t| Some(&t.spec) == source);
            match (precision, table.spec.quantity, e) {
                (Precision::F16, crate::table::Quantity::FMsNorm, Some(e)) => {
                    let stored = Table {
                        value: e.value.iter().map(|&v| f16::stored(v)).collect(),
                        one_minus_value: e
                            .one_minus_value
                            .iter()
                            .map(|&v| f16::stored(v))
                            .collect(),
                        ..e.clone()
                    };
                    crate::table::normalisation::derive(&stored, table.command.clone())
                }
                _ => table.clone(),
            }
        })
        .collect()
}

/// The most texels kiln reads from any file or accepts in any metadata
/// ([`crate::table::MAX_TEXELS`]).
pub use crate::table::MAX_TEXELS;

/// The largest file kiln reads: 2 GiB (a 4096 x 4096 table with its three channels in JSON is
/// about 1 GiB). Larger files, and anything that is not a regular file (`/dev/zero`, a pipe,
/// a directory), are refused before reading.
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// Reads a file kiln was given, within [`MAX_FILE_BYTES`]: a regular file only, refused at once
/// otherwise, and read through a limit so that a file growing meanwhile cannot exceed it.
///
/// # Errors
/// When the file cannot be read, is not a regular file or is too large.
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    let io = |action: &'static str| {
        move |source| Error::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    };
    let metadata = std::fs::metadata(path).map_err(io("read"))?;
    if !metadata.is_file() {
        return Err(Error::InvalidInput(format!(
            "{}: not a regular file (kiln reads tables and scenes from files, not devices, \
             pipes or directories)",
            path.display()
        )));
    }
    if metadata.len() > MAX_FILE_BYTES {
        return Err(Error::InvalidInput(format!(
            "{}: {} bytes, more than the {} bytes of any table kiln reads",
            path.display(),
            metadata.len(),
            MAX_FILE_BYTES
        )));
    }
    let file = std::fs::File::open(path).map_err(io("open"))?;
    let mut bytes = Vec::with_capacity(usize::try_from(metadata.len()).unwrap_or(0));
    std::io::Read::read_to_end(
        &mut std::io::Read::take(file, MAX_FILE_BYTES + 1),
        &mut bytes,
    )
    .map_err(io("read"))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(Error::InvalidInput(format!(
            "{}: grew beyond {} bytes while being read",
            path.display(),
            MAX_FILE_BYTES
        )));
    }
    Ok(bytes)
}

/// Checks that `dir` exists or can be created, and that kiln can create files in it: called
/// before long work so that a bad `--out` fails at once, not after the bake. A folder it had to
/// create for the check is removed again (the files' writer creates it when there is something
/// to write), so a refusal or an interrupt later leaves no empty folder behind.
pub fn check_output_dir(dir: &Path) -> Result<()> {
    // The folders that do not exist yet, deepest first.
    let missing: Vec<&Path> = dir
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .collect();
    // Another kiln's check may remove the folder it created between this one's creating it
    // and probing it (two bakes started into one new folder): then create it again.
    let mut attempts = 0;
    let probe = loop {
        attempts += 1;
        create_output_dir(dir)?;
        match tempfile::Builder::new()
            .prefix(".kiln-probe-")
            .tempfile_in(dir)
        {
            Ok(file) => {
                drop(file);
                break Ok(());
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound && attempts < 100 => {}
            Err(source) => {
                break Err(Error::Io {
                    path: dir.to_path_buf(),
                    action: "write to the output directory",
                    source,
                });
            }
        }
    };
    for created in missing {
        // Fails, harmlessly, if another process has put something there meanwhile; not while
        // another kiln holds the folder to write into it.
        folder_lock::remove_if_free(created);
    }
    probe
}

fn create_output_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        path: dir.to_path_buf(),
        action: "create the output directory",
        source,
    })
}

/// Writes `(file name, bytes)` pairs into `dir` all-or-nothing (as far as a file system allows):
/// each goes to a temporary file first; only when all were written are they renamed into place.
/// Under the folder's lock ([`folder_lock`]), so that two writers' sets are never interleaved.
pub fn write_files(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<Vec<PathBuf>> {
    let _lock = folder_lock::FolderLock::acquire(dir)?;
    write_files_locked(dir, files)
}

/// [`write_files`] for a caller that holds the folder's lock.
fn write_files_locked(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<Vec<PathBuf>> {
    remove_stale_temporaries(dir);
    let mut staged = Vec::with_capacity(files.len());
    for (name, bytes) in files {
        let path = dir.join(name);
        let io = |action, source| Error::Io {
            path: path.clone(),
            action,
            source,
        };
        let prefix = format!(".{name}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        // Temporary files are private (0600) by default; tables are ordinary files.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
        let mut temp = builder
            .tempfile_in(dir)
            .map_err(|e| io("create a temporary file for", e))?;
        temp.write_all(bytes).map_err(|e| io("write", e))?;
        temp.as_file().sync_all().map_err(|e| io("flush", e))?;
        staged.push((temp, path));
    }
    let mut paths = Vec::with_capacity(staged.len());
    for (temp, path) in staged {
        temp.persist(&path).map_err(|e| Error::Io {
            path: path.clone(),
            action: "rename into place",
            source: e.error,
        })?;
        paths.push(path);
    }
    Ok(paths)
}

/// How old a temporary file of kiln's must be to count as left behind by an interrupted run:
/// a bake holds its temporaries for the moments between writing and renaming its files.
const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(60);

/// Removes the temporary files an interrupted kiln left in `dir` (`.NAME.EXT.XXXXXX.tmp` of the
/// files kiln writes, and `.kiln-probe-*`), if older than `STALE_AFTER`, so that a
/// concurrent bake's own are left alone. Returns how many were removed; failures to remove are
/// ignored (the next run tries again).
pub fn remove_stale_temporaries(dir: &Path) -> usize {
    const EXTENSIONS: [&str; 14] = [
        ".json.", ".exr.", ".bin.", ".rs.", ".png.", ".ktx2.", ".dds.", ".h.", ".wgsl.", ".glsl.",
        ".hlsl.", ".tables.", ".js.", ".inc.",
    ];
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let ours = name.starts_with(".kiln-probe-")
            || (name.starts_with('.')
                && name.ends_with(".tmp")
                && EXTENSIONS.iter().any(|e| name.contains(e)));
        let old = entry
            .metadata()
            .ok()
            .filter(std::fs::Metadata::is_file)
            .and_then(|m| m.modified().ok())
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age > STALE_AFTER);
        if ours && old && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Encodes and writes tables: [`encode_all`], the replacement rule ([`replace::check`]), then
/// [`write_files`].
pub fn write_tables(
    dir: &Path,
    tables: &[Table],
    formats: &[Format],
    precision: Precision,
    replace: replace::Replace,
) -> Result<Vec<PathBuf>> {
    let files = encode_all(tables, formats, precision)?;
    write_table_files(dir, tables, &files, replace)
}

/// Writes files holding `tables` (and perhaps others, an engine's own file) after checking the
/// replacement rule ([`replace::check`]) for the tables' names: the check and the writes under
/// one hold of the folder's lock ([`folder_lock`]), so that of two bakes of different specs
/// into one folder the second to get there is refused, naming the first one's files.
pub fn write_table_files(
    dir: &Path,
    tables: &[Table],
    files: &[(String, Vec<u8>)],
    replace: replace::Replace,
) -> Result<Vec<PathBuf>> {
    let names: Vec<String> = files.iter().map(|(name, _)| name.clone()).collect();
    let specs: Vec<crate::table::TableSpec> = tables.iter().map(|t| t.spec.clone()).collect();
    let _lock = folder_lock::FolderLock::acquire(dir)?;
    let stale = replace::check(dir, &specs, &names, replace)?;
    let written = write_files_locked(dir, files)?;
    for path in stale {
        std::fs::remove_file(&path).map_err(|source| Error::Io {
            path: path.clone(),
            action: "remove the replaced table's file",
            source,
        })?;
    }
    Ok(written)
}

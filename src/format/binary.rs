//! kiln's raw binary table format: a small fixed header, then one little-endian plane per channel.
//! Easy to `include_bytes!` and to read from C. All integers are little-endian `u32`.
//!
//! ```text
//! offset  size  field
//!      0     8  magic "KILNTAB\0"
//!      8     4  format version (1)
//!     12     4  header size in bytes = offset of the first plane (a multiple of 16)
//!     16     4  rank: 1 (E_avg, F_avg), 2 (E, E_avg_dielectric) or 3 (E_dielectric)
//!     20     4  channel count C
//!     24     4  dims[0]: size of the slowest-varying axis (roughness, or eta)
//!     28     4  dims[1]: size of the next axis (mu, or roughness), 1 when rank is 1
//!     32    16  axis 0 descriptor  \  each: u32 quantity (1 = mu, 2 = r with alpha = r^2,
//!     48    16  axis 1 descriptor  /  3 = alpha, 4 = eta), u32 mapping (mu: 0 = linear,
//!                                     1 = sqrt: mu = t^2, 2 = adaptive:
//!                                     t = (mu (1 + 4a) / (mu + 4a))^0.4, 3 = glass: kiln's
//!                                     glass layout, `table::glass_layout`, 4 = balanced:
//!                                     kiln's balanced layout, `table::balanced_layout`,
//!                                     5 = split-sum: kiln's split-sum layout,
//!                                     `table::split_sum_layout`;
//!                                     r or alpha: 0 = linear, 1 = balanced; eta: 0 = linear,
//!                                     1 = cycles: linear in sqrt((eta - 1) / (eta + 1)),
//!                                     2 = blender, 3 = glass),
//!                                     u32 grid (0 = centers (i + 0.5)/N, 1 = nodes i/(N - 1)),
//!                                     u32: for eta the f32 bits of the axis' top eta_max,
//!                                     otherwise 0; all zero for an absent axis
//!     64  32*C  channel entries: 24 bytes name (ASCII, NUL-padded), u32 dtype (1 = f32,
//!               2 = f16), u32 byte offset of the channel's plane from the start of the file
//!      …        planes, each 16-byte aligned: dims[0] * dims[1] values, row-major
//!               (index = i0 * dims[1] + i1)
//! ```
//!
//! Version 2, written for tables with an IOR axis only (the others stay version 1), inserts 32
//! bytes after the version-1 fixed header: at 64 `dims[2]` (the fastest axis, mu, of a rank-3
//! table; 1 otherwise), 68..80 reserved (0), at 80 the axis 2 descriptor; the channel entries
//! then start at 96 and are 48 bytes each (a 40-byte name, then dtype and offset as above), and
//! the planes hold `dims[0] * dims[1] * dims[2]` values (index
//! `(i0 * dims[1] + i1) * dims[2] + i2`).
//!
//! Channels, in order: `E`, `one_minus_E`, `std_error` (or `E_avg`, `one_minus_E_avg`,
//! `std_error`). The value channels use the requested precision; `std_error` is always f32.

use super::Precision;
use crate::model::RoughnessConvention;
use crate::table::Table;
use crate::table::axis::{Axis, Grid, IorMapping, MuMapping};

/// The file's first 8 bytes.
pub const MAGIC: &[u8; 8] = b"KILNTAB\0";
/// The format version written for tables of rank 1 and 2.
pub const VERSION: u32 = 1;
/// The format version written for rank-3 tables.
pub const VERSION_IOR: u32 = 2;

const FIXED_HEADER: usize = 64;
const FIXED_HEADER_IOR: usize = 96;
const CHANNEL_ENTRY: usize = 32;
const NAME_BYTES: usize = 24;
const CHANNEL_ENTRY_IOR: usize = 48;
const NAME_BYTES_IOR: usize = 40;

fn align16(n: usize) -> usize {
    n.div_ceil(16) * 16
}

/// The axis descriptors the header of `spec`'s binary holds, in its order (what
/// [`BinaryContents::axes`] reads back).
#[must_use]
pub fn descriptors(spec: &crate::table::TableSpec) -> Vec<[u32; 4]> {
    spec.axes()
        .iter()
        .map(|a| axis_descriptor(Some(a)))
        .collect()
}

fn axis_descriptor(axis: Option<&Axis>) -> [u32; 4] {
    let grid = |g: Grid| match g {
        Grid::Centers => 0,
        Grid::Nodes => 1,
    };
    match axis {
        None => [0; 4],
        Some(&Axis::Mu {
            mapping, grid: g, ..
        }) => {
            let m = match mapping {
                MuMapping::Linear => 0,
                MuMapping::Sqrt => 1,
                MuMapping::Adaptive => 2,
                MuMapping::Glass => 3,
                MuMapping::Balanced => 4,
                MuMapping::SplitSum => 5,
                MuMapping::OneIor => 6,
            };
            [1, m, grid(g), 0]
        }
        Some(&Axis::Roughness {
            convention,
            grid: g,
            spacing,
            ..
        }) => {
            let q = match convention {
                RoughnessConvention::Perceptual => 2,
                RoughnessConvention::Alpha => 3,
            };
            let s = match spacing {
                crate::table::axis::RoughnessSpacing::Linear => 0,
                crate::table::axis::RoughnessSpacing::Balanced => 1,
            };
            [q, s, grid(g), 0]
        }
        Some(&Axis::Ior {
            mapping,
            max,
            grid: g,
            ..
        }) => {
            let m = match mapping {
                IorMapping::Linear => 0,
                IorMapping::Cycles => 1,
                IorMapping::Blender => 2,
                IorMapping::Glass => 3,
            };
            [4, m, grid(g), (max.0 as f32).to_bits()]
        }
    }
}

/// Encodes a table in kiln's binary format.
#[must_use]
pub fn encode(table: &Table, precision: Precision) -> Vec<u8> {
    let axes = table.spec.axes();
    let shape = table.spec.shape();
    let count = table.spec.len();
    let names = table.channel_names();
    let dtypes = [precision, precision, Precision::F32];
    // Version 2's longer names hold the glass channels' (`one_minus_E_dielectric_inside`),
    // also for a glass table at one IOR, which has two axes.
    let v2 = table.spec.ior.is_some() || names.iter().any(|name| name.len() > NAME_BYTES);
    let (fixed, entry_size, name_bytes) = if v2 {
        (FIXED_HEADER_IOR, CHANNEL_ENTRY_IOR, NAME_BYTES_IOR)
    } else {
        (FIXED_HEADER, CHANNEL_ENTRY, NAME_BYTES)
    };
    let header_size = align16(fixed + entry_size * names.len());
    let mut offsets = Vec::with_capacity(names.len());
    let mut offset = header_size;
    for dtype in dtypes {
        offsets.push(offset);
        offset = align16(offset + count * dtype.bytes());
    }

    let mut out = Vec::with_capacity(offset);
    let put = |out: &mut Vec<u8>, v: u32| out.extend_from_slice(&v.to_le_bytes());
    out.extend_from_slice(MAGIC);
    put(&mut out, if v2 { VERSION_IOR } else { VERSION });
    put(&mut out, header_size as u32);
    put(&mut out, axes.len() as u32);
    put(&mut out, names.len() as u32);
    put(&mut out, shape[0] as u32);
    put(&mut out, shape.get(1).copied().unwrap_or(1) as u32);
    for k in 0..2 {
        for word in axis_descriptor(axes.get(k)) {
            put(&mut out, word);
        }
    }
    if v2 {
        put(&mut out, shape.get(2).copied().unwrap_or(1) as u32);
        for _ in 0..3 {
            put(&mut out, 0);
        }
        for word in axis_descriptor(axes.get(2)) {
            put(&mut out, word);
        }
    }
    for ((name, dtype), &plane) in names.iter().zip(dtypes).zip(&offsets) {
        let mut field = vec![0u8; name_bytes];
        field[..name.len()].copy_from_slice(name.as_bytes());
        out.extend_from_slice(&field);
        put(&mut out, dtype.code());
        put(&mut out, plane as u32);
    }
    for (values, dtype) in table.channels().into_iter().zip(dtypes) {
        out.resize(align16(out.len()), 0);
        for &v in values {
            dtype.push_le(&mut out, v);
        }
    }
    out.resize(align16(out.len()), 0);
    out
}

/// A decoded binary table: its shape, axis descriptors and channels widened to f64.
#[derive(Debug, PartialEq)]
pub struct BinaryContents {
    pub shape: Vec<usize>,
    /// The raw axis descriptors (see the module docs), one per axis.
    pub axes: Vec<[u32; 4]>,
    pub channels: Vec<(String, Vec<f64>)>,
}

/// Decodes kiln's binary format, checking every size against the bytes present.
pub fn decode(bytes: &[u8]) -> crate::Result<BinaryContents> {
    let word = |offset: usize| -> crate::Result<u32> {
        bytes
            .get(offset..offset + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| {
                crate::Error::Malformed(format!("file ends inside the header (at byte {offset})"))
            })
    };
    if bytes.len() < FIXED_HEADER || &bytes[..8] != MAGIC {
        return Err(crate::Error::Malformed(
            "not a kiln binary table (bad magic)".into(),
        ));
    }
    let version = word(8)?;
    let max_rank = match version {
        VERSION => 2,
        VERSION_IOR => 3,
        _ => {
            return Err(crate::Error::Malformed(format!(
                "unsupported kiln binary version {version} (this kiln reads {VERSION} and \
                 {VERSION_IOR})"
            )));
        }
    };
    let rank = word(16)? as usize;
    let channel_count = word(20)? as usize;
    if !(1..=max_rank).contains(&rank) || channel_count == 0 || channel_count > 64 {
        return Err(crate::Error::Malformed(format!(
            "bad header: rank {rank}, {channel_count} channels (version {version})"
        )));
    }
    let (fixed, entry_size, name_bytes) = if version == VERSION_IOR {
        (FIXED_HEADER_IOR, CHANNEL_ENTRY_IOR, NAME_BYTES_IOR)
    } else {
        (FIXED_HEADER, CHANNEL_ENTRY, NAME_BYTES)
    };
    // dims[2] and the third descriptor sit after the version-1 header.
    let dim_offset = |k: usize| if k < 2 { 24 + 4 * k } else { 64 };
    let descriptor_offset = |k: usize| if k < 2 { 32 + 16 * k } else { 80 };
    let shape: Vec<usize> = (0..rank)
        .map(|k| word(dim_offset(k)).map(|v| v as usize))
        .collect::<std::result::Result<_, _>>()?;
    let count = shape
        .iter()
        .try_fold(1_usize, |n, &s| n.checked_mul(s))
        .filter(|&n| n > 0 && n <= super::MAX_TEXELS)
        .ok_or_else(|| {
            crate::Error::Malformed(format!(
                "bad header: shape {shape:?} (1 to {} texels)",
                super::MAX_TEXELS
            ))
        })?;
    let mut axes = Vec::with_capacity(rank);
    for k in 0..rank {
        let base = descriptor_offset(k);
        axes.push([
            word(base)?,
            word(base + 4)?,
            word(base + 8)?,
            word(base + 12)?,
        ]);
    }
    let mut channels = Vec::with_capacity(channel_count);
    for c in 0..channel_count {
        let entry = fixed + entry_size * c;
        let name_field = bytes
            .get(entry..entry + name_bytes)
            .ok_or_else(|| crate::Error::Malformed("file ends inside the channel list".into()))?;
        let name_len = name_field
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(name_bytes);
        let name = String::from_utf8_lossy(&name_field[..name_len]).into_owned();
        let dtype = Precision::from_code(word(entry + name_bytes)?)
            .ok_or_else(|| crate::Error::Malformed(format!("channel {name}: unknown dtype")))?;
        let plane = word(entry + name_bytes + 4)? as usize;
        let data = plane
            .checked_add(count * dtype.bytes())
            .and_then(|end| bytes.get(plane..end))
            .ok_or_else(|| {
                crate::Error::Malformed(format!(
                    "channel {name}: file too short for {count} values"
                ))
            })?;
        let values = match dtype {
            Precision::F32 => data
                .chunks_exact(4)
                .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
                .collect(),
            Precision::F16 => data
                .chunks_exact(2)
                .map(|b| f64::from(half::f16::from_le_bytes([b[0], b[1]]).to_f32()))
                .collect(),
        };
        channels.push((name, values));
    }
    Ok(BinaryContents {
        shape,
        axes,
        channels,
    })
}

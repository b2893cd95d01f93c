//! A GPU texture made of tables: one or more value planes of the same layout, interleaved per
//! texel, for the GPU containers ([`super::ktx2`], [`super::dds`]) and the C header.
//!
//! Layout, as in every kiln output: row-major, slowest axis first; the fastest axis is the
//! texture's x (width), the next its y (height, rows top to bottom), an IOR axis its z (depth).

use super::Precision;
use crate::table::Table;

/// Interleaved channels of one layout.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// The shape, slowest axis first (as [`crate::TableSpec::shape`]).
    pub shape: Vec<usize>,
    /// Channel names and values, in texel order (R, G, ...).
    pub channels: Vec<(String, Vec<f64>)>,
    /// What the texture holds: the tables' metadata as JSON.
    pub metadata: String,
}

impl Texture {
    /// A table's own texture: R = the value, G = one minus the value (estimated directly, the
    /// channel to use near 1 in half precision).
    #[must_use]
    pub fn of_table(table: &Table) -> Texture {
        let [value, one_minus, _] = table.channel_names();
        Texture {
            shape: table.spec.shape(),
            channels: vec![
                (value, table.value.clone()),
                (one_minus, table.one_minus_value.clone()),
            ],
            metadata: metadata_json(&[table]),
        }
    }

    /// The value planes of several tables of the same axes as channels R, G, ... (an engine's
    /// scale/bias texture, for instance).
    pub fn of_values(tables: &[&Table]) -> crate::Result<Texture> {
        let first = tables
            .first()
            .ok_or_else(|| crate::Error::Malformed("a texture needs at least one table".into()))?;
        if let Some(other) = tables.iter().find(|t| t.spec.axes() != first.spec.axes()) {
            return Err(crate::Error::Malformed(format!(
                "{} and {} have different axes and cannot share a texture",
                first.spec.id(),
                other.spec.id()
            )));
        }
        Ok(Texture {
            shape: first.spec.shape(),
            channels: tables
                .iter()
                .map(|t| (t.spec.quantity.symbol().to_string(), t.value.clone()))
                .collect(),
            metadata: metadata_json(tables),
        })
    }

    /// `(width, height, depth)` as KTX2 counts them: 0 for an absent dimension.
    #[must_use]
    pub fn extent(&self) -> (usize, usize, usize) {
        match self.shape[..] {
            [n] => (n, 0, 0),
            [rows, columns] => (columns, rows, 0),
            [slices, rows, columns] => (columns, rows, slices),
            _ => unreachable!("tables are 1-D, 2-D or 3-D"),
        }
    }

    /// The number of texels.
    #[must_use]
    pub fn len(&self) -> usize {
        self.shape.iter().product()
    }

    /// Whether the texture has no texels (never, for a table's).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The texels, channels interleaved, little-endian in `precision` (f16 through f32, as
    /// kiln's other writers: [`super::f16`]).
    #[must_use]
    pub fn interleaved(&self, precision: Precision) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.len() * self.channels.len() * precision.bytes());
        for k in 0..self.len() {
            for (_, values) in &self.channels {
                precision.push_le(&mut out, values[k]);
            }
        }
        out
    }
}

/// The metadata of the tables in a texture, as one JSON object: `channels` (names in texel
/// order) and `tables` (each table's [`super::metadata::Metadata`]).
fn metadata_json(tables: &[&Table]) -> String {
    let object = serde_json::json!({
        "tables": tables
            .iter()
            .map(|t| super::metadata::Metadata::new(t, "texture"))
            .collect::<Vec<_>>(),
    });
    object.to_string()
}

/// The tables' metadata of a texture's `kiln` JSON (as `metadata_json` writes it).
pub fn texture_metadata(text: &str) -> crate::Result<Vec<super::metadata::Metadata>> {
    #[derive(serde::Deserialize)]
    struct TextureMetadata {
        tables: Vec<super::metadata::Metadata>,
    }
    serde_json::from_str::<TextureMetadata>(text)
        .map(|t| t.tables)
        .map_err(|e| crate::Error::Malformed(format!("bad kiln metadata: {e}")))
}

/// A float texture read back from a GPU container ([`super::ktx2::decode`],
/// [`super::dds::decode`]): its extent, its channels de-interleaved, and kiln's metadata JSON
/// when the container carries it (KTX2 does, DDS cannot).
#[derive(Clone, Debug, PartialEq)]
pub struct DecodedTexture {
    /// `(width, height, depth)`, 1 for an absent dimension.
    pub extent: (usize, usize, usize),
    /// The storage precision of the texels.
    pub precision: Precision,
    /// Each channel's values in texel order (R, G, ...).
    pub channels: Vec<Vec<f64>>,
    /// kiln's metadata (the `kiln` key of a KTX2 file).
    pub metadata: Option<String>,
}

impl DecodedTexture {
    /// The number of texels of a container's `extent`, refused beyond
    /// [`super::MAX_TEXELS`]: what a header claims is checked before anything is allocated or
    /// decompressed.
    ///
    /// # Errors
    /// An extent of more than [`super::MAX_TEXELS`] texels.
    pub fn texels_within_limit(extent: (usize, usize, usize)) -> crate::Result<usize> {
        let texels = extent.0.saturating_mul(extent.1).saturating_mul(extent.2);
        if texels > super::MAX_TEXELS {
            return Err(crate::Error::Malformed(format!(
                "{} x {} x {} texels, more than the {} kiln reads",
                extent.0,
                extent.1,
                extent.2,
                super::MAX_TEXELS
            )));
        }
        Ok(texels)
    }

    /// De-interleaves `count` little-endian float channels of `precision` from `data`, which
    /// must hold exactly `width * height * depth` texels.
    pub fn from_interleaved(
        extent: (usize, usize, usize),
        count: usize,
        precision: Precision,
        data: &[u8],
        metadata: Option<String>,
    ) -> crate::Result<Self> {
        let texels = extent
            .0
            .checked_mul(extent.1)
            .and_then(|n| n.checked_mul(extent.2))
            .ok_or_else(|| crate::Error::Malformed("the texture's extent overflows".into()))?;
        let size = precision.bytes();
        let expected = texels.saturating_mul(count).saturating_mul(size);
        if data.len() != expected {
            return Err(crate::Error::Malformed(format!(
                "{} bytes of texels where {} x {} x {} texels of {count} channels of {} bytes \
                 need {expected}",
                data.len(),
                extent.0,
                extent.1,
                extent.2,
                size
            )));
        }
        let value = |k: usize| -> f64 {
            let b = &data[k * size..(k + 1) * size];
            match precision {
                Precision::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                Precision::F16 => f64::from(half::f16::from_le_bytes([b[0], b[1]]).to_f32()),
            }
        };
        let channels = (0..count)
            .map(|c| (0..texels).map(|t| value(t * count + c)).collect())
            .collect();
        Ok(Self {
            extent,
            precision,
            channels,
            metadata,
        })
    }
}

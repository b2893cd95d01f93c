//! OpenEXR output: one layer with channels `E`, `one_minus_E` (f32 or f16) and `std_error` (always
//! f32: half floats cannot hold errors of 1e-7), the metadata as a JSON text attribute `kiln`.
//!
//! Encoding is chosen for byte-reproducible files: ZIP-compressed scan lines in increasing order,
//! written without parallel compression (the `exr` crate's default tiled RLE with parallel
//! compression gives different bytes on each run), and a single custom attribute (the crate keeps
//! custom attributes in a `HashMap`, whose iteration order changes from run to run). f64 values
//! reach f16 through f32 (`half`'s direct f64 path differs between CPUs).

use super::Precision;
use super::metadata::{KILN_VERSION, Metadata};
use crate::table::Table;
use exr::prelude::*;
use std::io::Cursor;

/// The name of the header attribute holding the metadata JSON.
pub const METADATA_ATTRIBUTE: &str = "kiln";

/// Encodes a table as an EXR file in memory. A 2-D table is `mu` (or roughness) wide and
/// `roughness` (or `eta`) high; a 1-D table is one row; a 3-D table `(eta, roughness, mu)` is its
/// `eta` slices stacked top to bottom, `mu` wide and `eta x roughness` high (image row
/// `eta_index * R + r_index`).
pub fn encode(table: &Table, precision: Precision) -> crate::Result<Vec<u8>> {
    let shape = table.spec.shape();
    let (width, height) = match shape[..] {
        [slices, rows, columns] => (columns, slices * rows),
        [rows, columns] => (columns, rows),
        [n] => (n, 1),
        _ => {
            return Err(crate::Error::Encode(format!(
                "cannot store a table of shape {shape:?} as an image"
            )));
        }
    };
    let names = table.channel_names();
    let channels = table.channels();
    write(
        table,
        (width, height),
        vec![
            (names[0].as_str(), channels[0], precision),
            (names[1].as_str(), channels[1], precision),
            (names[2].as_str(), channels[2], Precision::F32),
        ],
    )
}

/// Encodes only the table's value channel, under the channel name `name` (an engine's layout,
/// e.g. Enterprise PBR's half-float `Y`), with the same header and metadata as [`encode`].
pub fn encode_value_as(table: &Table, name: &str, precision: Precision) -> crate::Result<Vec<u8>> {
    let shape = table.spec.shape();
    let (width, height) = match shape[..] {
        [rows, columns] => (columns, rows),
        [n] => (n, 1),
        _ => {
            return Err(crate::Error::Encode(format!(
                "cannot store a table of shape {shape:?} as an image"
            )));
        }
    };
    write(
        table,
        (width, height),
        vec![(name, &table.value, precision)],
    )
}

/// Encodes named planes of `table`'s 2-D shape (an engine's RGB layout, values already in that
/// engine's texel order) in `precision`, with `table`'s header and metadata.
pub fn encode_planes(
    table: &Table,
    planes: &[(&str, &[f64])],
    precision: Precision,
) -> crate::Result<Vec<u8>> {
    let [rows, columns] = table.spec.shape()[..] else {
        return Err(crate::Error::Encode("engine planes are 2-D".to_string()));
    };
    write(
        table,
        (columns, rows),
        planes
            .iter()
            .map(|&(name, values)| (name, values, precision))
            .collect(),
    )
}

/// Encodes a 2-D texture (kiln's compensation's RGBA coefficients,
/// [`super::compensation::texture`]) as an EXR image of its shape's width and height, channels
/// named as the texture names them, in `precision`, the texture's metadata JSON in the `kiln`
/// attribute and `layer` as the layer's name.
pub fn encode_texture(
    texture: &super::texture::Texture,
    layer: &str,
    precision: Precision,
) -> crate::Result<Vec<u8>> {
    let [rows, columns] = texture.shape[..] else {
        return Err(crate::Error::Encode(format!(
            "cannot store a texture of shape {:?} as an image",
            texture.shape
        )));
    };
    write_image(
        layer,
        &texture.metadata,
        (columns, rows),
        texture
            .channels
            .iter()
            .map(|(name, values)| (name.as_str(), values.as_slice(), precision))
            .collect(),
    )
}

/// Writes channels `(name, values, precision)` of a `width x height` image with kiln's header.
fn write(
    table: &Table,
    size: (usize, usize),
    channels: Vec<(&str, &[f64], Precision)>,
) -> crate::Result<Vec<u8>> {
    let metadata = serde_json::to_string(&Metadata::new(table, channels[0].2.name()))
        .map_err(|e| crate::Error::Encode(e.to_string()))?;
    write_image(table.spec.id().as_str(), &metadata, size, channels)
}

/// Writes channels `(name, values, precision)` of a `width x height` image, the layer named
/// `layer` and `metadata` (JSON, ASCII) in the `kiln` attribute.
fn write_image(
    layer: &str,
    metadata: &str,
    (width, height): (usize, usize),
    channels: Vec<(&str, &[f64], Precision)>,
) -> crate::Result<Vec<u8>> {
    let samples = |values: &[f64], precision: Precision| match precision {
        Precision::F32 => FlatSamples::F32(values.iter().map(|&v| v as f32).collect()),
        Precision::F16 => {
            FlatSamples::F16(values.iter().map(|&v| super::f16::encode(v).0).collect())
        }
    };
    let list = SmallVec::from_vec(
        channels
            .into_iter()
            .map(|(name, values, precision)| AnyChannel::new(name, samples(values, precision)))
            .collect(),
    );
    let mut attributes = LayerAttributes::named(layer);
    attributes.software_name = Some(Text::from(format!("kiln {KILN_VERSION}").as_str()));
    attributes.other.insert(
        Text::from(METADATA_ATTRIBUTE),
        AttributeValue::Text(
            Text::new_or_none(metadata)
                .ok_or_else(|| crate::Error::Encode("metadata is not ASCII".into()))?,
        ),
    );
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (width, height),
        attributes,
        encoding,
        AnyChannels::sort(list),
    );
    let mut bytes = Vec::new();
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_buffered(Cursor::new(&mut bytes))
        .map_err(|e| crate::Error::Encode(e.to_string()))?;
    Ok(bytes)
}

/// A table's channels as read back from an EXR file: name, values (widened to f64), width, height,
/// and the metadata JSON if present.
#[derive(Debug)]
pub struct ExrContents {
    pub width: usize,
    pub height: usize,
    pub channels: Vec<(String, Vec<f64>)>,
    pub metadata: Option<String>,
}

/// Reads the first layer of an EXR file from memory.
pub fn decode(bytes: &[u8]) -> crate::Result<ExrContents> {
    // The header first: a data window beyond what a table can be is refused before the image
    // is allocated (a 405-byte file can claim 2^40 pixels).
    let meta = ::exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| crate::Error::Malformed(e.to_string()))?;
    for header in &meta.headers {
        let (w, h) = (header.layer_size.0, header.layer_size.1);
        let samples = w
            .saturating_mul(h)
            .saturating_mul(header.channels.list.len().max(1));
        if w.saturating_mul(h) > super::MAX_TEXELS || samples > 4 * super::MAX_TEXELS {
            return Err(crate::Error::Malformed(format!(
                "a {w} x {h} image with {} channels, more than the {} texels kiln reads",
                header.channels.list.len(),
                super::MAX_TEXELS
            )));
        }
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| crate::Error::Malformed(e.to_string()))?;
    let layer = image.layer_data;
    let metadata = layer
        .attributes
        .other
        .get(&Text::from(METADATA_ATTRIBUTE))
        .and_then(|v| match v {
            AttributeValue::Text(text) => Some(text.to_string()),
            _ => None,
        });
    let channels = layer
        .channel_data
        .list
        .iter()
        .map(|c| {
            let values = c.sample_data.values_as_f32().map(f64::from).collect();
            (c.name.to_string(), values)
        })
        .collect();
    Ok(ExrContents {
        width: layer.size.0,
        height: layer.size.1,
        channels,
        metadata,
    })
}

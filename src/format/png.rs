//! PNG heat map of a 2-D table, for a person to look at: each texel drawn as a square of
//! [`SCALE`] pixels in the viridis colour map, stretched between the table's minimum and maximum.
//! Rows are roughness (top: smallest), columns `mu` (left: smallest), as in the EXR; a 3-D table's
//! `eta` slices are stacked top to bottom, as in the EXR.

use crate::table::Table;

/// Pixels per texel side.
pub const SCALE: usize = 8;

/// Viridis (van der Walt and Smith, matplotlib), sampled at 0, 1/8, ..., 1 and interpolated.
const VIRIDIS: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// Viridis at `t` in [0, 1] (clamped), as 8-bit RGB.
#[must_use]
pub fn viridis(t: f64) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * 8.0;
    let i = (x.floor() as usize).min(7);
    let f = x - i as f64;
    std::array::from_fn(|c| (VIRIDIS[i][c] * (1.0 - f) + VIRIDIS[i + 1][c] * f).round() as u8)
}

/// Encodes the table's value channel as a heat map; `None` for a 1-D table.
pub fn encode(table: &Table) -> Option<crate::Result<Vec<u8>>> {
    let (rows, columns) = match table.spec.shape()[..] {
        [slices, rows, columns] => (slices * rows, columns),
        [rows, columns] => (rows, columns),
        _ => return None,
    };
    let (lo, hi) = table
        .value
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let span = if hi > lo { hi - lo } else { 1.0 };
    let (width, height) = (columns * SCALE, rows * SCALE);
    let mut pixels = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            let v = table.value[(y / SCALE) * columns + x / SCALE];
            pixels.extend_from_slice(&viridis((v - lo) / span));
        }
    }
    let mut bytes = Vec::new();
    let result = (|| {
        let mut encoder = png::Encoder::new(&mut bytes, width as u32, height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.add_text_chunk(
            "Description".into(),
            format!(
                "{} heat map, {lo:.6} (dark) to {hi:.6} (bright)",
                table.spec.id()
            ),
        )?;
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&pixels)?;
        writer.finish()
    })();
    Some(
        result
            .map(|()| bytes)
            .map_err(|e| crate::Error::Encode(e.to_string())),
    )
}

/// An 8-bit RGB image whose three channels hold the same grey level, `round(255 v)` clamped to
/// [0, 255], of `values` (`width x height`, rows top to bottom): the lookup tables of the
/// GAMES202 homework. `comment` goes into a `tEXt` chunk.
pub fn encode_grey8(
    (width, height): (usize, usize),
    values: &[f64],
    comment: &str,
) -> crate::Result<Vec<u8>> {
    if values.len() != width * height {
        return Err(crate::Error::Encode(format!(
            "{} values for a {width} x {height} image",
            values.len()
        )));
    }
    let pixels: Vec<u8> = values.iter().flat_map(|&v| [unorm8(v); 3]).collect();
    let mut bytes = Vec::new();
    let result = (|| {
        let mut encoder = png::Encoder::new(&mut bytes, width as u32, height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.add_text_chunk("Comment".into(), comment.to_string())?;
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&pixels)?;
        writer.finish()
    })();
    result
        .map(|()| bytes)
        .map_err(|e| crate::Error::Encode(e.to_string()))
}

/// `v` as an 8-bit unsigned normalised number: `round(255 v)`, clamped to [0, 255] (NaN to 0).
#[must_use]
pub fn unorm8(v: f64) -> u8 {
    (v * 255.0).round().clamp(0.0, 255.0) as u8
}

/// A PNG image read as grey levels in [0, 1]: its first channel (grey or red), 8 or 16 bits
/// (fewer bits and palettes expanded to 8), rows top to bottom. Refused before anything is
/// decoded unless it is `expected` (width, height).
pub fn decode_grey(bytes: &[u8], expected: (usize, usize)) -> crate::Result<Vec<f64>> {
    let mut decoder = png::Decoder::new(bytes);
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder
        .read_info()
        .map_err(|e| crate::Error::Malformed(format!("not a PNG file ({e})")))?;
    let (width, height) = {
        let info = reader.info();
        (info.width as usize, info.height as usize)
    };
    if (width, height) != expected {
        return Err(crate::Error::Malformed(format!(
            "a {width} x {height} image (expected {} x {})",
            expected.0, expected.1
        )));
    }
    if reader.info().color_type == png::ColorType::Indexed {
        check_palette_indices(bytes)?;
    }
    let mut buffer = vec![0; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buffer)
        .map_err(|e| crate::Error::Malformed(format!("a damaged PNG file ({e})")))?;
    let samples = frame.color_type.samples();
    let sixteen = frame.bit_depth == png::BitDepth::Sixteen;
    let bytes_per_sample = if sixteen { 2 } else { 1 };
    let stride = samples * bytes_per_sample;
    let data = &buffer[..frame.buffer_size()];
    let mut values = Vec::with_capacity(width * height);
    for row in data.chunks_exact(frame.line_size).take(height) {
        for pixel in row.chunks_exact(stride).take(width) {
            values.push(if sixteen {
                f64::from(u16::from_be_bytes([pixel[0], pixel[1]])) / 65535.0
            } else {
                f64::from(pixel[0]) / 255.0
            });
        }
    }
    if values.len() != width * height {
        return Err(crate::Error::Malformed(format!(
            "{} pixels decoded of {width} x {height}",
            values.len()
        )));
    }
    Ok(values)
}

/// Refuses a palette image with a pixel whose index is past its palette (the PNG
/// specification calls that an error; expanded, such a pixel read as black, a silent 0).
fn check_palette_indices(bytes: &[u8]) -> crate::Result<()> {
    let mut reader = png::Decoder::new(bytes)
        .read_info()
        .map_err(|e| crate::Error::Malformed(format!("not a PNG file ({e})")))?;
    let (colours, width, height, bits) = {
        let info = reader.info();
        let colours = info.palette.as_ref().map_or(0, |p| p.len() / 3);
        (
            colours,
            info.width as usize,
            info.height as usize,
            info.bit_depth as usize,
        )
    };
    let mut buffer = vec![0; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buffer)
        .map_err(|e| crate::Error::Malformed(format!("a damaged PNG file ({e})")))?;
    let mask = (1_usize << bits) - 1;
    for (y, row) in buffer[..frame.buffer_size()]
        .chunks_exact(frame.line_size)
        .take(height)
        .enumerate()
    {
        for x in 0..width {
            let bit = x * bits;
            let index = (usize::from(row[bit / 8]) >> (8 - bits - bit % 8)) & mask;
            if index >= colours {
                return Err(crate::Error::Malformed(format!(
                    "pixel ({x}, {y}) holds palette index {index}, past its palette of \
                     {colours} colours (a damaged or hand-made file)"
                )));
            }
        }
    }
    Ok(())
}

/// How many bits a grey (or first-channel) PNG really holds: its bit depth, less where the
/// data says otherwise: an `sBIT` chunk's significant bits, or a 16-bit image whose every sample
/// is a multiple of 257 (8-bit levels widened, `v * 257`), which holds 8 bits. `None` for what
/// is not a PNG. (Read from the header alone, an 8-bit LUT saved as 16 bits was judged against
/// 16-bit storage and told it was noisy: issue 64, defect 6.)
#[must_use]
pub fn effective_bits(bytes: &[u8]) -> Option<u8> {
    let decoder = png::Decoder::new(bytes);
    let mut reader = decoder.read_info().ok()?;
    let info = reader.info();
    let depth = info.bit_depth as u8;
    let significant = info
        .sbit
        .as_ref()
        .and_then(|s| s.first().copied())
        .filter(|&b| b > 0 && b < depth);
    if let Some(bits) = significant {
        return Some(bits);
    }
    if depth != 16 {
        return Some(depth);
    }
    let samples = info.color_type.samples();
    let (width, height) = (info.width as usize, info.height as usize);
    // The header's size is the file's word: no image larger than a table may be (a forged
    // height of 4e9 asked for a terabyte; found by the png_verdict fuzz target).
    if width.saturating_mul(height) > crate::table::MAX_TEXELS {
        return None;
    }
    let mut buffer = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buffer).ok()?;
    let widened = buffer[..frame.buffer_size()]
        .chunks_exact(frame.line_size)
        .take(height)
        .flat_map(|row| row.chunks_exact(2 * samples).take(width))
        .all(|pixel| u16::from_be_bytes([pixel[0], pixel[1]]) % 257 == 0);
    Some(if widened { 8 } else { 16 })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 x 1 palette image of `colours` grey entries (entry k is grey `k * 85`) whose pixels
    /// hold `indices`, at `depth` bits an index.
    fn palette_png(colours: usize, indices: [u8; 4], depth: png::BitDepth) -> Vec<u8> {
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, 4, 1);
        encoder.set_color(png::ColorType::Indexed);
        encoder.set_depth(depth);
        encoder.set_palette(
            (0..colours)
                .flat_map(|k| [(k * 85) as u8; 3])
                .collect::<Vec<u8>>(),
        );
        let row = match depth {
            png::BitDepth::Eight => indices.to_vec(),
            // Four 2-bit indices in one byte, the first in the high bits.
            _ => vec![indices[0] << 6 | indices[1] << 4 | indices[2] << 2 | indices[3]],
        };
        let mut writer = encoder.write_header().expect("header");
        writer.write_image_data(&row).expect("data");
        writer.finish().expect("finished");
        bytes
    }

    /// The CRC-32 of PNG chunks (ISO 3309), bit by bit.
    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0_u32;
        for &b in bytes {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 == 1 {
                    (crc >> 1) ^ 0xedb8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }

    /// A 16-bit grey PNG whose header claims 128 x 4,294,965,120 pixels (with a valid CRC)
    /// over the data of a 128 x 1 image: `effective_bits` sized its buffer from the header and
    /// asked for a terabyte (the png_verdict fuzz target's find). Now it declines to judge.
    #[test]
    fn a_forged_image_size_is_not_allocated() {
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, 128, 1);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Sixteen);
        let mut writer = encoder.write_header().expect("header");
        writer.write_image_data(&[0x01; 256]).expect("data");
        writer.finish().expect("finished");
        // IHDR's data is bytes 16..29 (width at 16, height at 20), its CRC at 29.
        bytes[20..24].copy_from_slice(&0xffff_f780_u32.to_be_bytes());
        let crc = crc32(&bytes[12..29]);
        bytes[29..33].copy_from_slice(&crc.to_be_bytes());
        assert_eq!(effective_bits(&bytes), None);
    }

    /// Issue 64: a palette image whose indices run past its palette decoded those pixels as
    /// black (0) instead of being refused. In range, the palette's greys are what is read.
    #[test]
    fn palette_indices_past_the_palette_are_refused() {
        for depth in [png::BitDepth::Eight, png::BitDepth::Two] {
            let fine = palette_png(4, [0, 1, 2, 3], depth);
            let values = decode_grey(&fine, (4, 1)).expect("in range");
            assert_eq!(values, [0.0, 85.0 / 255.0, 170.0 / 255.0, 1.0]);
            let past = palette_png(2, [0, 1, 3, 0], depth);
            let message = decode_grey(&past, (4, 1)).unwrap_err();
            assert!(
                message
                    .to_string()
                    .contains("pixel (2, 0) holds palette index 3, past its palette of 2"),
                "{message}"
            );
        }
    }
}

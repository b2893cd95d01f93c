//! KTX2 (Khronos Texture 2.0) output: one texture, one mip level, no supercompression, with the
//! table's metadata as key/value data.
//!
//! Layout (KTX 2.0 specification, Khronos, sections 3-4; Khronos Data Format 1.3 for the
//! descriptor): the 12-byte identifier, the 68-byte header (`vkFormat`, `typeSize`, width,
//! height, depth, layer count 0, face count 1, level count 1, supercompression 0), the section
//! index, one level index entry, the data format descriptor (one basic block: RGBSDA colour
//! model, BT.709 primaries, linear transfer, one sample per channel, signed float,
//! `sampleLower = -1.0f`, `sampleUpper = 1.0f` as the specification's float formats have them),
//! the key/value data (`KTXorientation = rd`: rows top to bottom; `KTXwriter`; `kiln`: the
//! metadata JSON), sorted by key, then the texels, aligned to 16 bytes.
//!
//! Formats: `R16_SFLOAT` (76), `R16G16_SFLOAT` (83), `R32_SFLOAT` (100), `R32G32_SFLOAT` (103);
//! 1-D, 2-D and 3-D (an IOR table: depth = the `eta` axis).
//!
//! Supercompression ([`Supercompression::Zstd`], with the `containers` feature): the level's
//! bytes compressed as one Zstandard frame (scheme 2, `ruzstd` at its fastest level,
//! deterministic), `bytesPlane0` 0 as the specification requires of supercompressed data, the
//! level index holding the compressed and the uncompressed lengths.

use super::Precision;
use super::texture::Texture;

/// The KTX2 file identifier.
pub const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// The `VkFormat` of a texture with `channels` float channels of `precision`.
#[must_use]
pub fn vk_format(channels: usize, precision: Precision) -> Option<u32> {
    match (channels, precision) {
        (1, Precision::F16) => Some(76),
        (2, Precision::F16) => Some(83),
        (1, Precision::F32) => Some(100),
        (2, Precision::F32) => Some(103),
        (4, Precision::F16) => Some(97),
        (4, Precision::F32) => Some(109),
        _ => None,
    }
}

/// How the texels are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Supercompression {
    None,
    /// Zstandard (KTX2 scheme 2), as Bevy ships its DFG table.
    #[cfg(feature = "containers")]
    Zstd,
}

fn align(n: usize, to: usize) -> usize {
    n.div_ceil(to) * to
}

/// Encodes a texture of one, two or four channels, uncompressed.
pub fn encode(texture: &Texture, precision: Precision) -> crate::Result<Vec<u8>> {
    encode_with(texture, precision, Supercompression::None)
}

/// Encodes a texture of one, two or four channels with the given supercompression.
pub fn encode_with(
    texture: &Texture,
    precision: Precision,
    supercompression: Supercompression,
) -> crate::Result<Vec<u8>> {
    let channels = texture.channels.len();
    let format = vk_format(channels, precision).ok_or_else(|| {
        crate::Error::Encode(format!(
            "KTX2 output takes one, two or four channels (got {channels})"
        ))
    })?;
    let type_size = precision.bytes();
    let texel_bytes = type_size * channels;
    let raw = texture.interleaved(precision);
    let raw_len = raw.len();
    let (texels, scheme) = match supercompression {
        Supercompression::None => (raw, 0),
        #[cfg(feature = "containers")]
        Supercompression::Zstd => (
            ruzstd::encoding::compress_to_vec(
                raw.as_slice(),
                ruzstd::encoding::CompressionLevel::Fastest,
            ),
            2,
        ),
    };
    // Supercompressed data has no fixed bytes per plane (KTX 2.0, 3.10.2).
    let plane_bytes = if scheme == 0 { texel_bytes as u8 } else { 0 };

    // Data format descriptor: total size, then one basic block of 24 + 16 * channels bytes.
    let block_size = 24 + 16 * channels;
    let mut dfd = Vec::new();
    let put = |out: &mut Vec<u8>, v: u32| out.extend_from_slice(&v.to_le_bytes());
    put(&mut dfd, (4 + block_size) as u32);
    put(&mut dfd, 0); // vendor 0 (Khronos), descriptor type 0 (basic)
    put(&mut dfd, 2 | (block_size as u32) << 16); // version 2
    dfd.extend_from_slice(&[1, 1, 1, 0]); // RGBSDA, BT.709, linear, straight alpha
    dfd.extend_from_slice(&[0, 0, 0, 0]); // texel block 1 x 1 x 1 x 1
    dfd.extend_from_slice(&[plane_bytes, 0, 0, 0, 0, 0, 0, 0]); // bytes per plane
    let bits = 8 * type_size as u32;
    for c in 0..channels as u32 {
        // Float (0x80) and signed (0x40) qualifiers; channel id R = 0, G = 1, B = 2, A = 15
        // (KHR_DF_CHANNEL_RGBSDA_ALPHA).
        let id = if c == 3 { 15 } else { c };
        let channel_type = 0x80 | 0x40 | id;
        put(&mut dfd, (c * bits) | (bits - 1) << 16 | channel_type << 24);
        put(&mut dfd, 0); // sample position
        put(&mut dfd, (-1.0f32).to_bits());
        put(&mut dfd, 1.0f32.to_bits());
    }

    // Key/value data, sorted by key (byte order).
    let writer = format!("kiln {}", super::metadata::KILN_VERSION);
    let mut pairs: Vec<(&str, &[u8])> = vec![
        ("KTXorientation", b"rd"),
        ("KTXwriter", writer.as_bytes()),
        ("kiln", texture.metadata.as_bytes()),
    ];
    pairs.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
    let mut kvd = Vec::new();
    for (key, value) in pairs {
        let length = key.len() + 1 + value.len() + 1;
        put(&mut kvd, length as u32);
        kvd.extend_from_slice(key.as_bytes());
        kvd.push(0);
        kvd.extend_from_slice(value);
        kvd.push(0);
        kvd.resize(align(kvd.len(), 4), 0);
    }

    let header_end = IDENTIFIER.len() + 9 * 4 + 4 * 4 + 2 * 8 + 3 * 8;
    let dfd_offset = header_end;
    let kvd_offset = dfd_offset + dfd.len();
    let data_offset = align(kvd_offset + kvd.len(), 16);

    let mut out = Vec::with_capacity(data_offset + texels.len());
    out.extend_from_slice(&IDENTIFIER);
    let (width, height, depth) = texture.extent();
    for v in [
        format,
        type_size as u32,
        width as u32,
        height as u32,
        depth as u32,
        0, // layers: not an array
        1, // faces
        1, // levels
        scheme,
    ] {
        put(&mut out, v);
    }
    for v in [dfd_offset, dfd.len(), kvd_offset, kvd.len()] {
        put(&mut out, v as u32);
    }
    let put64 = |out: &mut Vec<u8>, v: u64| out.extend_from_slice(&v.to_le_bytes());
    put64(&mut out, 0); // no supercompression global data
    put64(&mut out, 0);
    put64(&mut out, data_offset as u64);
    put64(&mut out, texels.len() as u64);
    put64(&mut out, raw_len as u64);
    debug_assert_eq!(out.len(), header_end);
    out.extend_from_slice(&dfd);
    out.extend_from_slice(&kvd);
    out.resize(data_offset, 0);
    out.extend_from_slice(&texels);
    Ok(out)
}

/// Reads a KTX2 file of float texels (R, RG or RGBA, 16- or 32-bit; uncompressed or
/// Zstandard-supercompressed): its first level and kiln's metadata (the `kiln` key), if any.
/// kiln's own parser of the KTX 2.0 layout (header, level index, key/value data): every offset
/// and length is checked against the file before use, the extent against
/// [`super::MAX_TEXELS`] before anything is decompressed, and decompression stops at the
/// bytes the extent needs, so that no file can make it panic or allocate beyond that.
///
/// # Errors
/// A message naming what is wrong with the file.
#[cfg(feature = "containers")]
pub fn decode(bytes: &[u8]) -> crate::Result<super::texture::DecodedTexture> {
    let u32_at = |offset: usize| -> crate::Result<u32> {
        bytes
            .get(offset..offset + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| {
                crate::Error::Malformed(format!(
                    "the file ends at byte {} inside its header",
                    bytes.len()
                ))
            })
    };
    let u64_at = |offset: usize| -> crate::Result<u64> {
        Ok(u64::from(u32_at(offset)?) | u64::from(u32_at(offset + 4)?) << 32)
    };
    if bytes.len() < 80 || bytes[..12] != IDENTIFIER {
        return Err(crate::Error::Malformed(
            "not a KTX2 file (no KTX 2.0 identifier)".into(),
        ));
    }
    let format = u32_at(12)?;
    let (channels, precision) = match format {
        76 => (1, Precision::F16),
        83 => (2, Precision::F16),
        97 => (4, Precision::F16),
        100 => (1, Precision::F32),
        103 => (2, Precision::F32),
        109 => (4, Precision::F32),
        other => {
            return Err(crate::Error::Malformed(format!(
                "VkFormat {other}: kiln reads R, RG and RGBA textures of 16- or 32-bit floats"
            )));
        }
    };
    let extent = (
        u32_at(20)?.max(1) as usize,
        u32_at(24)?.max(1) as usize,
        u32_at(28)?.max(1) as usize,
    );
    let texels = super::texture::DecodedTexture::texels_within_limit(extent)?;
    let level_count = u32_at(40)?.max(1) as usize;
    let scheme = u32_at(44)?;
    let (kvd_offset, kvd_length) = (u32_at(56)? as usize, u32_at(60)? as usize);
    if level_count > 64 {
        return Err(crate::Error::Malformed(format!("{level_count} levels")));
    }
    // The first level's index entry: byte offset, byte length (then the uncompressed length).
    let (offset, length) = (u64_at(80)?, u64_at(88)?);
    let level = usize::try_from(offset)
        .ok()
        .zip(usize::try_from(length).ok())
        .and_then(|(o, l)| bytes.get(o..o.checked_add(l)?))
        .ok_or_else(|| {
            crate::Error::Malformed(format!(
                "level 0 claims bytes {offset} to {} of a {}-byte file",
                offset.saturating_add(length),
                bytes.len()
            ))
        })?;
    // What the texels must take: decompression stops there, whatever the file claims.
    let expected = texels * channels * precision.bytes();
    let data: Vec<u8> = match scheme {
        0 => level.to_vec(),
        2 => {
            let mut out = Vec::new();
            let decoder = ruzstd::decoding::StreamingDecoder::new(level)
                .map_err(|e| crate::Error::Malformed(format!("zstd: {e}")))?;
            std::io::Read::read_to_end(
                &mut std::io::Read::take(decoder, expected as u64 + 1),
                &mut out,
            )
            .map_err(|e| crate::Error::Malformed(format!("zstd: {e}")))?;
            out
        }
        other => {
            return Err(crate::Error::Malformed(format!(
                "supercompression scheme {other}: kiln reads none (0) or Zstandard (2)"
            )));
        }
    };
    // Key/value data: (u32 length, key NUL value, padding to 4) entries.
    let mut metadata = None;
    if kvd_length > 0 {
        let kvd = kvd_offset
            .checked_add(kvd_length)
            .and_then(|end| bytes.get(kvd_offset..end))
            .ok_or_else(|| {
                crate::Error::Malformed("the key/value data lies outside the file".into())
            })?;
        let mut at = 0;
        while at + 4 <= kvd.len() {
            let n = u32::from_le_bytes([kvd[at], kvd[at + 1], kvd[at + 2], kvd[at + 3]]) as usize;
            let entry = at
                .checked_add(4)
                .zip((at + 4).checked_add(n))
                .and_then(|(start, end)| kvd.get(start..end))
                .ok_or_else(|| {
                    crate::Error::Malformed("a key/value entry runs past the key/value data".into())
                })?;
            if let Some(split) = entry.iter().position(|&b| b == 0)
                && &entry[..split] == b"kiln"
            {
                let value = &entry[split + 1..];
                let value = value.strip_suffix(&[0]).unwrap_or(value);
                metadata = Some(String::from_utf8_lossy(value).into_owned());
            }
            at = align(at + 4 + n, 4);
        }
    }
    super::texture::DecodedTexture::from_interleaved(extent, channels, precision, &data, metadata)
}

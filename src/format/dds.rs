//! DDS (DirectDraw Surface) output with the DX10 header, through the `ddsfile` crate: DXGI
//! `R16_FLOAT`, `R16G16_FLOAT`, `R32_FLOAT` or `R32G32_FLOAT` (and four-channel
//! `R16G16B16A16_FLOAT` / `R32G32B32A32_FLOAT` for engine presets), a 1-D, 2-D or (IOR tables) 3-D
//! texture with one mip level, rows top to bottom. DDS has no room for metadata: the JSON sidecar
//! or the KTX2 file carries it.

use super::Precision;
use super::texture::Texture;
use ddsfile::{AlphaMode, Caps2, D3D10ResourceDimension, Dds, DxgiFormat, NewDxgiParams};

/// The DXGI format of a texture with `channels` float channels of `precision`.
#[must_use]
pub fn dxgi_format(channels: usize, precision: Precision) -> Option<DxgiFormat> {
    match (channels, precision) {
        (1, Precision::F16) => Some(DxgiFormat::R16_Float),
        (2, Precision::F16) => Some(DxgiFormat::R16G16_Float),
        (1, Precision::F32) => Some(DxgiFormat::R32_Float),
        (2, Precision::F32) => Some(DxgiFormat::R32G32_Float),
        (4, Precision::F16) => Some(DxgiFormat::R16G16B16A16_Float),
        (4, Precision::F32) => Some(DxgiFormat::R32G32B32A32_Float),
        _ => None,
    }
}

/// Encodes a texture of one, two or four channels.
pub fn encode(texture: &Texture, precision: Precision) -> crate::Result<Vec<u8>> {
    let channels = texture.channels.len();
    let format = dxgi_format(channels, precision).ok_or_else(|| {
        crate::Error::Encode(format!(
            "DDS output takes one, two or four channels (got {channels})"
        ))
    })?;
    let (width, height, depth) = texture.extent();
    let (dimension, depth, caps2) = match (height, depth) {
        (0, _) => (D3D10ResourceDimension::Texture1D, None, None),
        (_, 0) => (D3D10ResourceDimension::Texture2D, None, None),
        (_, d) => (
            D3D10ResourceDimension::Texture3D,
            Some(d as u32),
            Some(Caps2::VOLUME),
        ),
    };
    let mut dds = Dds::new_dxgi(NewDxgiParams {
        height: height.max(1) as u32,
        width: width as u32,
        depth,
        format,
        mipmap_levels: Some(1),
        array_layers: None,
        caps2,
        is_cubemap: false,
        resource_dimension: dimension,
        alpha_mode: AlphaMode::Unknown,
    })
    .map_err(|e| crate::Error::Encode(e.to_string()))?;
    dds.data = texture.interleaved(precision);
    let mut bytes = Vec::new();
    dds.write(&mut bytes)
        .map_err(|e| crate::Error::Encode(e.to_string()))?;
    Ok(bytes)
}

/// Reads a DDS file of one, two or four 16- or 32-bit float channels (DX10 header), one level.
pub fn decode(bytes: &[u8]) -> crate::Result<super::texture::DecodedTexture> {
    let dds =
        Dds::read(bytes).map_err(|e| crate::Error::Malformed(format!("not a DDS file ({e})")))?;
    let format = dds.get_dxgi_format();
    let (channels, precision) = match format {
        Some(DxgiFormat::R16_Float) => (1, Precision::F16),
        Some(DxgiFormat::R16G16_Float) => (2, Precision::F16),
        Some(DxgiFormat::R16G16B16A16_Float) => (4, Precision::F16),
        Some(DxgiFormat::R32_Float) => (1, Precision::F32),
        Some(DxgiFormat::R32G32_Float) => (2, Precision::F32),
        Some(DxgiFormat::R32G32B32A32_Float) => (4, Precision::F32),
        other => {
            return Err(crate::Error::Malformed(format!(
                "format {other:?}: kiln reads R, RG and RGBA DXGI float textures"
            )));
        }
    };
    let extent = (
        dds.get_width().max(1) as usize,
        dds.get_height().max(1) as usize,
        dds.get_depth().max(1) as usize,
    );
    super::texture::DecodedTexture::texels_within_limit(extent)?;
    super::texture::DecodedTexture::from_interleaved(extent, channels, precision, &dds.data, None)
}

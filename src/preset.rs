//! Engine presets: a table laid out exactly as an engine loads it (size, axis order, roughness
//! convention, grid, channels, container), so that kiln's file replaces the engine's own, and
//! the reader of that layout for `kiln verify --preset`.
//!
//! Conventions (`../shared/docs/peers.md`, and the engines' sources named there):
//!
//! - `cycles`: Blender Cycles' `table_ggx_E[1024]` and `table_ggx_Eavg[32]` (`shader.tables`):
//!   GGX, height-correlated, F = 1; 32 x 32, `index = mu_index * 32 + r_index` (roughness
//!   fastest), nodes `i / 31` on both axes, `mu` linear, perceptual `r`. Cycles computed its
//!   first row and column at 1e-4 instead of 0; kiln computes the true node values (its lookup
//!   lerps between nodes, so these are the values that lookup wants). C float arrays.
//! - `bevy`: Bevy's `dfg.ktx2`: 64 x 64, x = `NoV` (linear `mu`), y = perceptual roughness, texel
//!   centres, R = `E_scale` (`∫ (1 - Fc) w`), G = `E_bias` (`∫ Fc w`), `R16G16_SFLOAT`, GGX
//!   height-correlated, zstd-supercompressed as Bevy ships it (uncompressed without the
//!   `containers` feature).
//! - `three`: three.js' DFG LUT: 16 x 16, transposed (x = roughness, y = `NoV`), texel centres,
//!   R = `E_scale`, G = `E_bias` as half-float bits in a `Uint16Array`, interleaved RG.
//! - `enterprise-pbr`: Dassault Systèmes' Enterprise PBR `res/GGX_E.exr` (32 x 32, x = `cos`,
//!   y = perceptual roughness from the top, texel centres) and `res/GGX_E_avg.exr` (32 x 1), GGX
//!   height-correlated, F = 1, one half-float channel `Y`.

use crate::bake::BakeOptions;
use crate::error::{Error, Result};
use crate::format::{Precision, ktx2, texture::Texture};
use crate::model::{Masking, Ndf, RoughnessConvention};
use crate::table::axis::{Grid, MuMapping};
use crate::table::{Quantity, Table};
use std::fmt::Write as _;

/// An engine layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Preset {
    /// Blender Cycles: E and E_avg, 32 x 32 mu-major, nodes, C float arrays.
    Cycles,
    /// Bevy: scale/bias, 64 x 64, centres, RG16F KTX2.
    Bevy,
    /// three.js: scale/bias, 16 x 16 transposed (roughness, NoV), centres, half bits.
    Three,
    /// Enterprise PBR: GGX_E.exr 32 x 32 and GGX_E_avg.exr 32, centres, half channel Y.
    #[cfg_attr(feature = "cli", value(name = "enterprise-pbr"))]
    EnterprisePbr,
}

impl Preset {
    /// Every preset.
    pub const ALL: [Preset; 4] = [
        Preset::Cycles,
        Preset::Bevy,
        Preset::Three,
        Preset::EnterprisePbr,
    ];

    /// The name on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Preset::Cycles => "cycles",
            Preset::Bevy => "bevy",
            Preset::Three => "three",
            Preset::EnterprisePbr => "enterprise-pbr",
        }
    }

    /// The file the preset writes (the engine's own name; the first, for a preset of two).
    #[must_use]
    pub fn file_name(self) -> &'static str {
        match self {
            Preset::Cycles => "shader.tables",
            Preset::Bevy => "dfg.ktx2",
            Preset::Three => "DFGLUT.js",
            Preset::EnterprisePbr => "GGX_E.exr",
        }
    }

    /// Every file the preset writes, `(name, bytes)`.
    pub fn files(self, tables: &[Table]) -> Result<Vec<(String, Vec<u8>)>> {
        let mut files = vec![(self.file_name().to_string(), self.encode(tables)?)];
        if self == Preset::EnterprisePbr {
            let average = crate::format::exr::encode_value_as(&tables[1], "Y", Precision::F16)
                .map_err(Error::InvalidInput)?;
            files.push(("GGX_E_avg.exr".to_string(), average));
        }
        Ok(files)
    }

    /// The bake that gives the preset's tables (to the default max error).
    #[must_use]
    pub fn options(self) -> BakeOptions {
        let (size, grid, quantities) = match self {
            Preset::Cycles => (32, Grid::Nodes, vec![Quantity::E, Quantity::EAvg]),
            Preset::EnterprisePbr => (32, Grid::Centers, vec![Quantity::E, Quantity::EAvg]),
            Preset::Bevy => (64, Grid::Centers, vec![Quantity::EScale, Quantity::EBias]),
            Preset::Three => (16, Grid::Centers, vec![Quantity::EScale, Quantity::EBias]),
        };
        BakeOptions {
            ndfs: vec![Ndf::Ggx],
            maskings: vec![Masking::HeightCorrelated],
            quantities,
            size,
            grid,
            mu_mapping: MuMapping::Linear,
            roughness_convention: RoughnessConvention::Perceptual,
            ..BakeOptions::default()
        }
    }

    /// The engine's value of `tables[channel]` at roughness index `r` and `mu` index `m`:
    /// where in the engine's flat array it sits (in texels; channels interleave within one).
    #[must_use]
    pub fn texel(self, r: usize, m: usize) -> usize {
        let n = self.options().size;
        match self {
            // mu-major (Cycles), roughness rows (Bevy), NoV rows (three.js).
            Preset::Cycles | Preset::Three => m * n + r,
            Preset::Bevy | Preset::EnterprisePbr => r * n + m,
        }
    }

    /// Writes the tables ([`Preset::options`]'s bake, in its order) in the engine's layout: the
    /// file [`Preset::file_name`] (see [`Preset::files`] for all of them).
    pub fn encode(self, tables: &[Table]) -> Result<Vec<u8>> {
        let n = self.options().size;
        let engine_order = |table: &Table| -> Vec<f64> {
            let mut out = vec![0.0; n * n];
            for r in 0..n {
                for m in 0..n {
                    out[self.texel(r, m)] = table.value[r * n + m];
                }
            }
            out
        };
        match self {
            Preset::EnterprisePbr => {
                crate::format::exr::encode_value_as(&tables[0], "Y", Precision::F16)
                    .map_err(Error::InvalidInput)
            }
            Preset::Cycles => {
                let mut out = format!(
                    "/* kiln {}: Cycles' GGX energy-compensation tables (GGX, height-correlated, \
                     F = 1).\n * table_ggx_E: index = mu_index * 32 + r_index, mu = j / 31, \
                     r = i / 31 (alpha = r^2), exact nodes.\n * Regenerate: {}\n */\n",
                    crate::format::metadata::KILN_VERSION,
                    tables[0].command
                );
                for (name, values) in [
                    ("table_ggx_E", engine_order(&tables[0])),
                    ("table_ggx_Eavg", tables[1].value.clone()),
                ] {
                    crate::format::c_header::float_array(&mut out, name, &values);
                }
                Ok(out.into_bytes())
            }
            Preset::Bevy => {
                let texture =
                    Texture::of_values(&[&tables[0], &tables[1]]).map_err(Error::InvalidInput)?;
                #[cfg(feature = "containers")]
                let scheme = ktx2::Supercompression::Zstd;
                #[cfg(not(feature = "containers"))]
                let scheme = ktx2::Supercompression::None;
                ktx2::encode_with(&texture, Precision::F16, scheme).map_err(Error::InvalidInput)
            }
            Preset::Three => {
                let (scale, bias) = (engine_order(&tables[0]), engine_order(&tables[1]));
                let mut out = format!(
                    "// kiln {}: three.js DFG LUT, 16 x 16, x = roughness, y = dot(N, V), texel \
                     centres;\n// RG half floats: R = scale (integral of (1 - Fc) f mu_i), G = bias \
                     (integral of Fc f mu_i).\n// Regenerate: {}\n\nexport const DFGLUT_DATA = new \
                     Uint16Array( [",
                    crate::format::metadata::KILN_VERSION,
                    tables[0].command
                );
                for k in 0..n * n {
                    out.push_str(if k % 4 == 0 { "\n\t" } else { " " });
                    let half = |v: f64| crate::format::f16::encode(v).0.to_bits();
                    let _ = write!(out, "0x{:04x}, 0x{:04x},", half(scale[k]), half(bias[k]));
                }
                out.push_str("\n] );\n");
                Ok(out.into_bytes())
            }
        }
    }

    /// Reads an engine's own file in this layout: each table it holds, as its quantity and its
    /// values in kiln's order (roughness rows, `mu` columns; `E_avg` by roughness).
    pub fn decode(self, bytes: &[u8]) -> Result<Vec<(Quantity, Vec<f64>)>> {
        let n = self.options().size;
        let bad = |m: String| Error::InvalidInput(format!("not a {} table: {m}", self.name()));
        let kiln_order = |engine: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; n * n];
            for r in 0..n {
                for m in 0..n {
                    out[r * n + m] = engine[self.texel(r, m)];
                }
            }
            out
        };
        match self {
            Preset::EnterprisePbr => {
                let image = crate::format::exr::decode(bytes).map_err(bad)?;
                let (_, values) = image
                    .channels
                    .iter()
                    .find(|(name, _)| name == "Y")
                    .ok_or_else(|| bad("no channel Y".into()))?;
                match (image.width, image.height) {
                    (w, h) if (w, h) == (n, n) => Ok(vec![(Quantity::E, kiln_order(values))]),
                    (w, 1) if w == n => Ok(vec![(Quantity::EAvg, values.clone())]),
                    (w, h) => Err(bad(format!(
                        "{w} x {h} (expected GGX_E.exr, {n} x {n}, or GGX_E_avg.exr, {n} x 1)"
                    ))),
                }
            }
            Preset::Cycles => {
                let text = String::from_utf8_lossy(bytes);
                let e =
                    c_array(&text, "table_ggx_E").ok_or_else(|| bad("no table_ggx_E".into()))?;
                let avg = c_array(&text, "table_ggx_Eavg")
                    .ok_or_else(|| bad("no table_ggx_Eavg".into()))?;
                if e.len() != n * n || avg.len() != n {
                    return Err(bad(format!(
                        "table_ggx_E has {} values and table_ggx_Eavg {} (expected {} and {n})",
                        e.len(),
                        avg.len(),
                        n * n
                    )));
                }
                Ok(vec![(Quantity::E, kiln_order(&e)), (Quantity::EAvg, avg)])
            }
            #[cfg(not(feature = "containers"))]
            Preset::Bevy => Err(bad(
                "reading KTX2 needs kiln's `containers` feature".to_string()
            )),
            #[cfg(feature = "containers")]
            Preset::Bevy => {
                let reader = ::ktx2::Reader::new(bytes).map_err(|e| bad(format!("{e:?}")))?;
                let header = reader.header();
                let level = reader
                    .levels()
                    .next()
                    .ok_or_else(|| bad("no level".into()))?;
                let data: Vec<u8> = match header.supercompression_scheme {
                    None => level.data.to_vec(),
                    Some(::ktx2::SupercompressionScheme::Zstandard) => {
                        let mut out = Vec::new();
                        ruzstd::decoding::StreamingDecoder::new(level.data)
                            .map_err(|e| bad(format!("zstd: {e}")))
                            .and_then(|mut d| {
                                std::io::Read::read_to_end(&mut d, &mut out)
                                    .map_err(|e| bad(format!("zstd: {e}")))
                            })?;
                        out
                    }
                    Some(other) => {
                        return Err(bad(format!(
                            "supercompression {other:?}: kiln reads none or Zstandard"
                        )));
                    }
                };
                if header.format != Some(::ktx2::Format::R16G16_SFLOAT)
                    || (header.pixel_width, header.pixel_height) != (n as u32, n as u32)
                {
                    return Err(bad(format!(
                        "expected {n} x {n} R16G16_SFLOAT, found {} x {} {:?}",
                        header.pixel_width, header.pixel_height, header.format
                    )));
                }
                let half = |k: usize| {
                    f64::from(half::f16::from_le_bytes([data[2 * k], data[2 * k + 1]]).to_f32())
                };
                let channel = |c: usize| -> Vec<f64> {
                    kiln_order(&(0..n * n).map(|k| half(2 * k + c)).collect::<Vec<_>>())
                };
                Ok(vec![
                    (Quantity::EScale, channel(0)),
                    (Quantity::EBias, channel(1)),
                ])
            }
            Preset::Three => {
                let text = String::from_utf8_lossy(bytes);
                let start = text
                    .find("Uint16Array")
                    .ok_or_else(|| bad("no Uint16Array".into()))?;
                let body = &text[start..];
                let open = body.find('[').ok_or_else(|| bad("no [".into()))?;
                let close = body.find(']').ok_or_else(|| bad("no ]".into()))?;
                let bits: Vec<u16> = body[open + 1..close]
                    .split(',')
                    .map(str::trim)
                    .filter(|s| !s.is_empty())
                    .map(|s| {
                        let s = s.trim_start_matches("0x").trim_start_matches("0X");
                        u16::from_str_radix(s, 16).map_err(|e| bad(format!("'{s}': {e}")))
                    })
                    .collect::<Result<_>>()?;
                if bits.len() != 2 * n * n {
                    return Err(bad(format!(
                        "{} half floats (expected {})",
                        bits.len(),
                        2 * n * n
                    )));
                }
                let channel = |c: usize| -> Vec<f64> {
                    let engine: Vec<f64> = (0..n * n)
                        .map(|k| f64::from(half::f16::from_bits(bits[2 * k + c]).to_f32()))
                        .collect();
                    kiln_order(&engine)
                };
                Ok(vec![
                    (Quantity::EScale, channel(0)),
                    (Quantity::EBias, channel(1)),
                ])
            }
        }
    }
}

impl Preset {
    /// An engine's own file read as kiln tables of the preset's specs (values as stored; `1 -
    /// value` by subtraction; no standard errors), for auditing.
    pub fn read_tables(self, bytes: &[u8], origin: &str) -> Result<Vec<Table>> {
        let specs = self.options().resolved().specs();
        Ok(self
            .decode(bytes)?
            .into_iter()
            .filter_map(|(quantity, value)| {
                let spec = specs.iter().find(|s| s.quantity == quantity)?.clone();
                Some((spec, value))
            })
            .map(|(spec, value)| Table {
                one_minus_value: value.iter().map(|v| 1.0 - v).collect(),
                std_error: vec![0.0; value.len()],
                value,
                spec,
                command: format!("{origin}, read in the {} layout", self.name()),
                node_errors: None,
                requested_max_error: None,
            })
            .collect())
    }
}

/// The numbers of the C float array `name` (`name[...] = { ... }`), `f` suffixes allowed, read
/// as f32 (what the C compiler stores) and widened.
fn c_array(text: &str, name: &str) -> Option<Vec<f64>> {
    let mut rest = text;
    loop {
        let at = rest.find(name)?;
        let after = &rest[at + name.len()..];
        // The whole identifier: not table_ggx_E inside table_ggx_Eavg.
        if after.starts_with(|c: char| c.is_alphanumeric() || c == '_') {
            rest = after;
            continue;
        }
        let open = after.find('{')?;
        let close = after[open..].find('}')? + open;
        return after[open + 1..close]
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.trim_end_matches(['f', 'F'])
                    .parse::<f32>()
                    .ok()
                    .map(f64::from)
            })
            .collect();
    }
}

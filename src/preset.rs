//! Engine presets: a table laid out exactly as an engine loads it (size, axis order, roughness
//! convention, grid, channels, container), so that kiln's file replaces the engine's own, and
//! the reader of that layout for `kiln verify --preset`.
//!
//! Conventions (`docs/engines.md`, with the engines' source files and commits):
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
//! - `filament`: Filament's `dfg.inc` (`cmgen --ibl-dfg-multiscatter --ibl-dfg-cloth`, included
//!   into `DFG_LUT[]` and uploaded as `RGB16F`): 128 x 128 in GL order, x = `NoV`, y = perceptual
//!   roughness, both on texel centres (`PrefilteredDFG_LUT` samples `vec2(NoV, r)` unremapped);
//!   R = `E_bias` (`∫ Fc w`), G = `E` (`∫ w`), B = the Charlie/Ashikhmin cloth albedo
//!   ([`crate::integrate::sheen`]), half-float bits. GGX height-correlated. Filament's own file
//!   computes row `j` at `r = min(1, (j + 1.5) / 128)`, one texel rougher than its shader reads
//!   (`CubemapIBL::DFG` takes `(height - y + 0.5) / height` before cmgen flips the rows); kiln's
//!   row `j` is at `(j + 0.5) / 128`, where the shader reads it.
//! - `godot`: Godot 4's DFG texture (`integrate_dfg.glsl`, computed at start-up into an
//!   `rgba16f` image) written as `dfg_lut.dds`, `R16G16B16A16_FLOAT`: 128 x 128, x = `NoV`,
//!   rows from the top at roughness `1 - (j + 0.5) / 128` (the shader stores row `127 - y`),
//!   texel centres; R = `E_bias`, G = `E`, B = the cloth albedo, A = 1; GGX with separable
//!   Schlick-GGX masking, `k = alpha / 2`, as Godot integrates it.
//! - `unity-hdrp`: Unity HDRP's `_PreIntegratedFGD_GGXDisneyDiffuse` (drawn at start-up by
//!   `preIntegratedFGD_GGXDisneyDiffuse.shader` into a 64 x 64 `A2B10G10R10_UNormPack32` target)
//!   written as a half-float RGB EXR to import in its place: x = `sqrt(NoV)`, y = perceptual
//!   roughness, both on nodes `i / 63` (Unity remaps half a texel on write and read); R =
//!   `E_bias`, G = `E` (GGX height-correlated), B = the Disney diffuse albedo minus 0.5
//!   ([`crate::model::disney_diffuse`]); rows from the top at `r = 1 - j / 63`, since Unity puts
//!   an imported image's top row at `v = 1`.
//! - `unreal`: Unreal Engine 5's `ShadingEnergyGGXSpecTexture` (`ShadingEnergyConservation`: a
//!   precomputed RGBA16F texture uploaded as `G16R16` UNORM, or built at run time by
//!   `BuildEnergyTableCS`): 32 x 32, x = `NoV`, y = roughness (perceptual; rows from the top, as
//!   D3D and Unreal's importer count `v`), texel centres; R = `E`, G = `∫ Fc w` (the shader's
//!   `F0 E + (F90 - F0) E_Fc`), B = 0, A = 1, as a half-float EXR to import in its place.

use crate::bake::BakeOptions;
use crate::error::{Error, Result};
use crate::format::{Precision, ktx2, texture::Texture};
use crate::model::{Masking, Ndf, RoughnessConvention};
use crate::table::axis::{Grid, MuMapping};
use crate::table::{Quantity, Table, TableSpec};
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
    /// Filament: multiscatter DFG + cloth, 128 x 128, centres, RGB16F half bits (dfg.inc).
    Filament,
    /// Godot 4: Filament's layout flipped (1 - r), Schlick-GGX k = alpha/2, RGBA16F DDS.
    Godot,
    /// Unity HDRP: FGD + Disney diffuse, 64 x 64, sqrt(NoV) nodes, half RGB EXR.
    #[cfg_attr(feature = "cli", value(name = "unity-hdrp"))]
    UnityHdrp,
    /// Unreal Engine 5: E and E*Fc, 32 x 32, centres, half RGBA EXR.
    Unreal,
}

impl Preset {
    /// Every preset.
    pub const ALL: [Preset; 8] = [
        Preset::Cycles,
        Preset::Bevy,
        Preset::Three,
        Preset::EnterprisePbr,
        Preset::Filament,
        Preset::Godot,
        Preset::UnityHdrp,
        Preset::Unreal,
    ];

    /// The absolute tolerance of the cloth channel's quadrature (Filament, Godot): well below
    /// half-float spacing (`2^-11` relative).
    pub const SHEEN_TOLERANCE: f64 = 1e-7;

    /// The name on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Preset::Cycles => "cycles",
            Preset::Bevy => "bevy",
            Preset::Three => "three",
            Preset::EnterprisePbr => "enterprise-pbr",
            Preset::Filament => "filament",
            Preset::Godot => "godot",
            Preset::UnityHdrp => "unity-hdrp",
            Preset::Unreal => "unreal",
        }
    }

    /// The name of kiln's JSON sidecar of one of the preset's tables:
    /// `unreal-ggx-height-correlated-E.json` (the preset's name and the table's model and
    /// quantity: the layout is the preset's, so kiln's own tables never share the name).
    #[must_use]
    pub fn sidecar_name(self, table: &Table) -> String {
        format!("{}-{}.json", self.name(), table.spec.base_id())
    }

    /// The file the preset writes (the engine's own name; the first, for a preset of two).
    #[must_use]
    pub fn file_name(self) -> &'static str {
        match self {
            Preset::Cycles => "shader.tables",
            Preset::Bevy => "dfg.ktx2",
            Preset::Three => "DFGLUTData.js",
            Preset::EnterprisePbr => "GGX_E.exr",
            Preset::Filament => "dfg.inc",
            Preset::Godot => "dfg_lut.dds",
            Preset::UnityHdrp => "preIntegratedFGD_GGXDisneyDiffuse.exr",
            Preset::Unreal => "ShadingEnergyGGXSpec.exr",
        }
    }

    /// Every file the preset writes, `(name, bytes)`.
    pub fn files(self, tables: &[Table]) -> Result<Files> {
        Ok(self.files_and_extra(tables)?.0)
    }

    /// [`Preset::files`], with the [`Preset::extra_channel`] they hold (computed once), for a
    /// caller that reports it.
    pub fn files_and_extra(self, tables: &[Table]) -> Result<(Files, Option<ExtraChannel>)> {
        let extra = self.extra_channel();
        let mut files = vec![(
            self.file_name().to_string(),
            self.encode_with(tables, extra.as_ref())?,
        )];
        if self == Preset::EnterprisePbr {
            let average = crate::format::exr::encode_value_as(&tables[1], "Y", Precision::F16)
                .map_err(Error::InvalidInput)?;
            files.push(("GGX_E_avg.exr".to_string(), average));
        }
        if let Some((name, bytes)) = self.normalisation_file(tables)? {
            files.push((name.to_string(), bytes));
        }
        Ok((files, extra))
    }

    /// The smallest `mu` and roughness the engine computed the file `bytes` at, where its
    /// lookups clamp: Blender computes its Cycles tables' first row and column at 1e-4; kiln's
    /// own Cycles file (it starts with kiln's header) and every other engine's hold the node
    /// values themselves (0).
    #[must_use]
    pub fn computed_from(self, bytes: &[u8]) -> f64 {
        if self == Preset::Cycles && !bytes.starts_with(b"/* kiln") {
            1e-4
        } else {
            0.0
        }
    }

    /// The number of entries of the preset's `f_ms_norm` table (0 for a preset without one).
    #[must_use]
    pub fn normalisation_size(self) -> usize {
        self.options()
            .resolved()
            .specs()
            .iter()
            .find(|s| s.quantity == Quantity::FMsNorm)
            .map_or(0, TableSpec::len)
    }

    /// How the engine file stores `E`, for the presets that carry `f_ms_norm` beside it: Cycles'
    /// f32 arrays, Enterprise PBR's half floats. `None` for the other presets.
    fn stored_e(self) -> Option<fn(f64) -> f64> {
        match self {
            Preset::Cycles => Some(|v| f64::from(v as f32)),
            Preset::EnterprisePbr => Some(crate::format::f16::stored),
            _ => None,
        }
    }

    /// The tables as the preset's files hold them: `f_ms_norm` derived from the E table as the
    /// engine file stores it ([`Preset::stored_e`]; Enterprise PBR's shader computes `1 - E` from
    /// the f16 `E`), so that it is the average of the lookup the engine makes; the others as
    /// given. The engine's files and kiln's sidecars beside them are both written from these, so
    /// a sidecar describes the bytes beside it. Idempotent.
    pub fn engine_tables(self, tables: &[Table]) -> Result<Vec<Table>> {
        let Some(round) = self.stored_e() else {
            return Ok(tables.to_vec());
        };
        if !tables.iter().any(|t| t.spec.quantity == Quantity::FMsNorm) {
            return Ok(tables.to_vec());
        }
        let e = tables
            .iter()
            .find(|t| t.spec.quantity == Quantity::E)
            .ok_or_else(|| Error::InvalidInput("f_ms_norm needs the E table".into()))?;
        let value: Vec<f64> = e.value.iter().map(|&v| round(v)).collect();
        let stored = Table {
            one_minus_value: value.iter().map(|v| 1.0 - v).collect(),
            value,
            ..e.clone()
        };
        Ok(tables
            .iter()
            .map(|t| {
                if t.spec.quantity == Quantity::FMsNorm {
                    crate::table::normalisation::derive(&stored, t.command.clone())
                } else {
                    t.clone()
                }
            })
            .collect())
    }

    /// The file of the lookup-consistent Kulla-Conty normalisation (`f_ms_norm`,
    /// [`crate::table::normalisation`]) of a preset whose engine normalises by `E_avg`, beside
    /// the engine's own files (which stay exactly as the engine ships them), from
    /// [`Preset::engine_tables`]. `None` for the other presets, or when `tables` has no
    /// `f_ms_norm`.
    fn normalisation_file(self, tables: &[Table]) -> Result<Option<(&'static str, Vec<u8>)>> {
        let engine = self.engine_tables(tables)?;
        let Some(norm) = engine.iter().find(|t| t.spec.quantity == Quantity::FMsNorm) else {
            return Ok(None);
        };
        match self {
            Preset::Cycles => {
                let rows = norm.value.len();
                let mut out = format!(
                    "/* kiln {}: the lookup-consistent normalisation of the Kulla-Conty lobe for \
                     Cycles' table_ggx_E (shader.tables).\n * table_ggx_f_ms_norm[i] = 1 - \
                     Ebar(r) at r = i / {}, Ebar the cosine-weighted average of table_ggx_E's \
                     bilinear lookup (as\n * lookup_table_read_2D reads it), linear between \
                     entries; f_ms = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - Ebar(r))).\n * \
                     Regenerate: {}\n */\n",
                    crate::format::metadata::KILN_VERSION,
                    rows - 1,
                    norm.command
                );
                crate::format::c_header::float_array(&mut out, "table_ggx_f_ms_norm", &norm.value);
                Ok(Some((CYCLES_NORMALISATION_FILE, out.into_bytes())))
            }
            Preset::EnterprisePbr => {
                // Values from 1e-7 to 1: stored in f32, as f16 would lose the small ones.
                let bytes = crate::format::exr::encode_value_as(norm, "Y", Precision::F32)
                    .map_err(Error::InvalidInput)?;
                Ok(Some((ENTERPRISE_NORMALISATION_FILE, bytes)))
            }
            _ => Ok(None),
        }
    }

    /// The bake that gives the preset's tables (to the default max error).
    #[must_use]
    pub fn options(self) -> BakeOptions {
        let (size, grid, quantities) = match self {
            Preset::Cycles => (
                32,
                Grid::Nodes,
                vec![Quantity::E, Quantity::EAvg, Quantity::FMsNorm],
            ),
            Preset::EnterprisePbr => (
                32,
                Grid::Centers,
                vec![Quantity::E, Quantity::EAvg, Quantity::FMsNorm],
            ),
            Preset::Bevy => (64, Grid::Centers, vec![Quantity::EScale, Quantity::EBias]),
            Preset::Three => (16, Grid::Centers, vec![Quantity::EScale, Quantity::EBias]),
            Preset::Filament | Preset::Godot => {
                (128, Grid::Centers, vec![Quantity::EBias, Quantity::E])
            }
            Preset::UnityHdrp => (64, Grid::Nodes, vec![Quantity::EBias, Quantity::E]),
            Preset::Unreal => (32, Grid::Centers, vec![Quantity::E, Quantity::EBias]),
        };
        let mu_mapping = if self == Preset::UnityHdrp {
            MuMapping::Sqrt
        } else {
            MuMapping::Linear
        };
        let masking = if self == Preset::Godot {
            Masking::SchlickGgx
        } else {
            Masking::HeightCorrelated
        };
        BakeOptions {
            ndfs: vec![Ndf::Ggx],
            maskings: vec![masking],
            quantities,
            size,
            grid,
            mu_mapping,
            roughness_convention: RoughnessConvention::Perceptual,
            ..BakeOptions::default()
        }
    }

    /// The engine's value of `tables[channel]` at roughness index `r` and `mu` index `m`:
    /// where in the engine's flat array it sits (in texels; channels interleave within one).
    #[must_use]
    pub fn texel(self, r: usize, m: usize) -> usize {
        self.texel_of_size(r, m, self.options().size)
    }

    /// [`Preset::texel`] in an `n x n` table of the engine's layout (three.js shipped 32 x 32
    /// before 16 x 16).
    fn texel_of_size(self, r: usize, m: usize, n: usize) -> usize {
        match self {
            // mu-major (Cycles), roughness rows (Bevy), NoV rows (three.js).
            Preset::Cycles | Preset::Three => m * n + r,
            Preset::Bevy | Preset::EnterprisePbr | Preset::Filament | Preset::Unreal => r * n + m,
            // Rows from the top at 1 - r.
            Preset::Godot | Preset::UnityHdrp => (n - 1 - r) * n + m,
        }
    }

    /// The channel of the engine's texture that is not one of kiln's tables, at the preset's
    /// texels in kiln's order: Filament's and Godot's cloth albedo
    /// ([`crate::integrate::sheen`]), HDRP's Disney diffuse albedo minus 0.5
    /// ([`crate::model::disney_diffuse`]); `None` for the other presets.
    #[must_use]
    pub fn extra_channel(self) -> Option<ExtraChannel> {
        match self {
            Preset::Filament | Preset::Godot => {
                let plane = crate::integrate::sheen::sheen_plane(
                    self.options().size,
                    Self::SHEEN_TOLERANCE,
                );
                Some(ExtraChannel {
                    name: "cloth albedo (Charlie NDF, Ashikhmin visibility)",
                    value: plane.value,
                    max_error: plane.max_error,
                })
            }
            Preset::UnityHdrp => {
                let spec = self.options().resolved().specs().swap_remove(0);
                let value = (0..spec.len())
                    .map(|k| {
                        let (alpha, mu) = spec.texel_coordinates(k);
                        let mu = mu.expect("a 2-D table has a mu axis");
                        crate::model::disney_diffuse::disney_diffuse_albedo(alpha.sqrt(), mu) - 0.5
                    })
                    .collect();
                Some(ExtraChannel {
                    name: "Disney diffuse albedo - 0.5",
                    value,
                    max_error: 0.0,
                })
            }
            _ => None,
        }
    }

    /// Writes the tables ([`Preset::options`]'s bake, in its order) in the engine's layout: the
    /// file [`Preset::file_name`] (see [`Preset::files`] for all of them).
    pub fn encode(self, tables: &[Table]) -> Result<Vec<u8>> {
        self.encode_with(tables, self.extra_channel().as_ref())
    }

    /// [`Preset::encode`] with the preset's [`Preset::extra_channel`] already computed.
    fn encode_with(self, tables: &[Table], extra: Option<&ExtraChannel>) -> Result<Vec<u8>> {
        let n = self.options().size;
        let engine_order = |values: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; n * n];
            for r in 0..n {
                for m in 0..n {
                    out[self.texel(r, m)] = values[r * n + m];
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
                    ("table_ggx_E", engine_order(&tables[0].value)),
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
            Preset::Three => Ok(three_module(
                n,
                &engine_order(&tables[0].value),
                &engine_order(&tables[1].value),
                &tables[0].command,
            )
            .into_bytes()),
            Preset::Filament => {
                let sheen = extra.expect("filament has a cloth channel");
                let planes = [
                    engine_order(&tables[0].value),
                    engine_order(&tables[1].value),
                    engine_order(&sheen.value),
                ];
                let mut out = format!(
                    "// kiln {}: Filament's DFG LUT (dfg.inc), {n} x {n} RGB16F half-float bits in \
                     GL order,\n// x = NoV = (i + 0.5) / {n}, y = perceptual roughness = (j + 0.5) \
                     / {n} (alpha = r^2), texel centres.\n// R = integral of Fc f mu_i, G = integral \
                     of f mu_i (GGX, height-correlated, F = 1);\n// B = cloth albedo (Charlie NDF, \
                     Ashikhmin visibility), quadrature error estimate <= {:.0e}.\n// Regenerate: \
                     {}\n",
                    crate::format::metadata::KILN_VERSION,
                    sheen.max_error,
                    tables[0].command
                );
                let half = |v: f64| crate::format::f16::encode(v).0.to_bits();
                for k in 0..n * n {
                    for plane in &planes {
                        let _ = write!(out, "0x{:04x}, ", half(plane[k]));
                    }
                    if k % 4 == 3 {
                        out.truncate(out.trim_end().len());
                        out.push('\n');
                    }
                }
                Ok(out.into_bytes())
            }
            #[cfg(not(feature = "containers"))]
            Preset::Godot => Err(Error::InvalidInput(
                "writing DDS needs kiln's `containers` feature".to_string(),
            )),
            #[cfg(feature = "containers")]
            Preset::Godot => {
                let sheen = extra.expect("godot has a cloth channel");
                let mut texture =
                    Texture::of_values(&[&tables[0], &tables[1]]).map_err(Error::InvalidInput)?;
                texture.channels = vec![
                    ("E_bias".into(), engine_order(&tables[0].value)),
                    ("E".into(), engine_order(&tables[1].value)),
                    ("E_sheen".into(), engine_order(&sheen.value)),
                    ("A".into(), vec![1.0; n * n]),
                ];
                crate::format::dds::encode(&texture, Precision::F16).map_err(Error::InvalidInput)
            }
            Preset::UnityHdrp => {
                let diffuse = extra.expect("unity-hdrp has a diffuse channel");
                let planes = [
                    engine_order(&tables[0].value),
                    engine_order(&tables[1].value),
                    engine_order(&diffuse.value),
                ];
                crate::format::exr::encode_planes(
                    &tables[1],
                    &[("R", &planes[0]), ("G", &planes[1]), ("B", &planes[2])],
                    Precision::F16,
                )
                .map_err(Error::InvalidInput)
            }
            Preset::Unreal => {
                let (zeros, ones) = (vec![0.0; n * n], vec![1.0; n * n]);
                let planes = [
                    engine_order(&tables[0].value),
                    engine_order(&tables[1].value),
                ];
                crate::format::exr::encode_planes(
                    &tables[0],
                    &[
                        ("R", &planes[0]),
                        ("G", &planes[1]),
                        ("B", &zeros),
                        ("A", &ones),
                    ],
                    Precision::F16,
                )
                .map_err(Error::InvalidInput)
            }
        }
    }

    /// Reads an engine's own file in this layout: each table it holds, as its quantity and its
    /// values in kiln's order (roughness rows, `mu` columns; `E_avg` by roughness).
    pub fn decode(self, bytes: &[u8]) -> Result<Vec<(Quantity, Vec<f64>)>> {
        Ok(self.decode_all(bytes)?.0)
    }

    /// Reads the [`Preset::extra_channel`] of an engine's own file, in kiln's order: `None` if
    /// the preset has none or the file does not hold it (an RG16F Filament include, say).
    pub fn decode_extra(self, bytes: &[u8]) -> Result<Option<Vec<f64>>> {
        Ok(self.decode_all(bytes)?.1)
    }

    /// The error for bytes that are not this engine's file.
    fn not_its_file(self, message: String) -> Error {
        Error::InvalidInput(format!(
            "not a {} file ({} in that engine's layout): {message}",
            self.name(),
            self.file_name()
        ))
    }

    /// The size of the engine's table in `bytes`: the preset's, or for three.js whichever
    /// square its `DATA` holds (16 x 16 since three r182, 32 x 32 in r181 and before), which must
    /// agree with the size its `DataTexture` is built with.
    fn size_in(self, bytes: &[u8]) -> Result<usize> {
        if self != Preset::Three {
            return Ok(self.options().size);
        }
        let bad = |m: String| self.not_its_file(m);
        let halves = three_data(bytes).map_err(bad)?.len();
        let n = (1..=MAX_THREE_SIZE)
            .find(|&n| 2 * n * n == halves)
            .ok_or_else(|| {
                bad(format!(
                    "{halves} half floats in DATA: not the two of each texel of a square table \
                     (16 x 16 holds 512, 32 x 32 holds 2048)"
                ))
            })?;
        let text = String::from_utf8_lossy(bytes);
        if let Some(declared) = three_texture_size(&text)
            && declared != (n, n)
        {
            return Err(bad(format!(
                "DATA holds {n} x {n} texels but the DataTexture is built {} x {}",
                declared.0, declared.1
            )));
        }
        Ok(n)
    }

    /// [`Preset::decode`] and [`Preset::decode_extra`] in one reading.
    fn decode_all(self, bytes: &[u8]) -> Result<Decoded> {
        let n = self.size_in(bytes)?;
        let mut extra = None;
        let bad = |m: String| self.not_its_file(m);
        let kiln_order = |engine: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; n * n];
            for r in 0..n {
                for m in 0..n {
                    out[r * n + m] = engine[self.texel_of_size(r, m, n)];
                }
            }
            out
        };
        // Channel `c` of `stride` interleaved half floats per texel, in kiln's order.
        let half_channel = |bits: &[u16], stride: usize, c: usize| -> Vec<f64> {
            let engine: Vec<f64> = (0..n * n)
                .map(|k| f64::from(half::f16::from_bits(bits[stride * k + c]).to_f32()))
                .collect();
            kiln_order(&engine)
        };
        let tables = match self {
            Preset::EnterprisePbr => {
                let image = crate::format::exr::decode(bytes).map_err(bad)?;
                let (_, values) = image
                    .channels
                    .iter()
                    .find(|(name, _)| name == "Y")
                    .ok_or_else(|| bad("no channel Y".into()))?;
                let norm = self.normalisation_size();
                match (image.width, image.height) {
                    (w, h) if (w, h) == (n, n) => Ok(vec![(Quantity::E, kiln_order(values))]),
                    (w, 1) if w == n => Ok(vec![(Quantity::EAvg, values.clone())]),
                    (w, 1) if w == norm => Ok(vec![(Quantity::FMsNorm, values.clone())]),
                    (w, h) => Err(bad(format!(
                        "{w} x {h} (expected GGX_E.exr, {n} x {n}, GGX_E_avg.exr, {n} x 1, or \
                         {ENTERPRISE_NORMALISATION_FILE}, {norm} x 1)"
                    ))),
                }
            }
            Preset::Cycles => {
                let text = String::from_utf8_lossy(bytes);
                if let Some(norm) = c_array(&text, "table_ggx_f_ms_norm") {
                    let size = self.normalisation_size();
                    if norm.len() != size {
                        return Err(bad(format!(
                            "table_ggx_f_ms_norm has {} values (expected {size})",
                            norm.len()
                        )));
                    }
                    return Ok((vec![(Quantity::FMsNorm, norm)], None));
                }
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
                let texture = crate::format::ktx2::decode(bytes).map_err(bad)?;
                if texture.channels.len() != 2
                    || texture.precision != Precision::F16
                    || texture.extent != (n, n, 1)
                {
                    return Err(bad(format!(
                        "expected {n} x {n} R16G16_SFLOAT, found {} x {} x {} with {} {} channels",
                        texture.extent.0,
                        texture.extent.1,
                        texture.extent.2,
                        texture.channels.len(),
                        texture.precision.name()
                    )));
                }
                let mut channels = texture.channels.into_iter();
                let (scale, bias) = (
                    channels.next().unwrap_or_default(),
                    channels.next().unwrap_or_default(),
                );
                Ok(vec![(Quantity::EScale, scale), (Quantity::EBias, bias)])
            }
            Preset::Three => {
                let bits = three_data(bytes).map_err(bad)?;
                Ok(vec![
                    (Quantity::EScale, half_channel(&bits, 2, 0)),
                    (Quantity::EBias, half_channel(&bits, 2, 1)),
                ])
            }
            Preset::Filament => {
                // Every 0x number outside comments: RGB (or, from cmgen before the cloth
                // channel, RG) half-float bits per texel.
                let text = String::from_utf8_lossy(bytes);
                let bits: Vec<u16> = text
                    .lines()
                    .map(|line| line.split("//").next().unwrap_or(""))
                    .flat_map(|line| line.split(','))
                    .map(str::trim)
                    .filter(|s| !s.is_empty())
                    .filter_map(|s| s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")))
                    // The digits only: the last number may run into the closing `};`.
                    .map(|s| {
                        s.split(|c: char| !c.is_ascii_hexdigit())
                            .next()
                            .unwrap_or("")
                    })
                    .map(|s| u16::from_str_radix(s, 16).map_err(|e| bad(format!("'0x{s}': {e}"))))
                    .collect::<Result<_>>()?;
                let stride = match bits.len() / (n * n) {
                    s @ (2 | 3) if bits.len() == s * n * n => s,
                    _ => {
                        return Err(bad(format!(
                            "{} half floats (expected {} for RGB16F or {} for RG16F)",
                            bits.len(),
                            3 * n * n,
                            2 * n * n
                        )));
                    }
                };
                extra = (stride > 2).then(|| half_channel(&bits, stride, 2));
                Ok(vec![
                    (Quantity::EBias, half_channel(&bits, stride, 0)),
                    (Quantity::E, half_channel(&bits, stride, 1)),
                ])
            }
            #[cfg(not(feature = "containers"))]
            Preset::Godot => Err(bad(
                "reading DDS needs kiln's `containers` feature".to_string()
            )),
            #[cfg(feature = "containers")]
            Preset::Godot => {
                let dds =
                    ddsfile::Dds::read(bytes).map_err(|e| bad(format!("not a DDS file ({e})")))?;
                let format = dds.get_dxgi_format();
                let stride = match format {
                    Some(ddsfile::DxgiFormat::R16G16B16A16_Float) => 4,
                    Some(ddsfile::DxgiFormat::R16G16_Float) => 2,
                    _ => 0,
                };
                if stride == 0
                    || (dds.get_width(), dds.get_height()) != (n as u32, n as u32)
                    || dds.data.len() < 2 * stride * n * n
                {
                    return Err(bad(format!(
                        "expected {n} x {n} R16G16B16A16_FLOAT, found {} x {} {format:?}",
                        dds.get_width(),
                        dds.get_height()
                    )));
                }
                let bits = little_endian(&dds.data);
                extra = (stride > 2).then(|| half_channel(&bits, stride, 2));
                Ok(vec![
                    (Quantity::EBias, half_channel(&bits, stride, 0)),
                    (Quantity::E, half_channel(&bits, stride, 1)),
                ])
            }
            Preset::UnityHdrp | Preset::Unreal => {
                let image = crate::format::exr::decode(bytes)
                    .map_err(|e| bad(format!("not an EXR file ({e})")))?;
                if (image.width, image.height) != (n, n) {
                    return Err(bad(format!(
                        "{} x {} (expected {n} x {n})",
                        image.width, image.height
                    )));
                }
                let channel = |name: &str| -> Result<Vec<f64>> {
                    image
                        .channels
                        .iter()
                        .find(|(c, _)| c == name)
                        .map(|(_, values)| kiln_order(values))
                        .ok_or_else(|| bad(format!("no channel {name}")))
                };
                let (red, green) = if self == Preset::Unreal {
                    (Quantity::E, Quantity::EBias)
                } else {
                    extra = channel("B").ok();
                    (Quantity::EBias, Quantity::E)
                };
                Ok(vec![(red, channel("R")?), (green, channel("G")?)])
            }
        }?;
        Ok((tables, extra))
    }
}

impl Preset {
    /// Audits the [`Preset::extra_channel`] of an engine's own file at its texels against
    /// kiln's values there; `None` if the file holds no such channel.
    pub fn audit_extra(self, bytes: &[u8]) -> Result<Option<ExtraAudit>> {
        let Some(stored) = self.decode_extra(bytes)? else {
            return Ok(None);
        };
        let reference = self
            .extra_channel()
            .expect("a preset that decodes an extra channel computes it");
        if stored.len() != reference.value.len() {
            return Err(Error::InvalidInput(format!(
                "the {} channel has {} values (expected {})",
                reference.name,
                stored.len(),
                reference.value.len()
            )));
        }
        if let Some(k) = stored.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "the {} channel at texel {k} is {}, not a finite number",
                reference.name, stored[k]
            )));
        }
        let (mut max_error, mut sum2, mut worst) = (0.0f64, 0.0, 0);
        for (k, (s, r)) in stored.iter().zip(&reference.value).enumerate() {
            let error = (s - r).abs();
            sum2 += error * error;
            if error > max_error || error.is_nan() {
                (max_error, worst) = (error, k);
            }
        }
        let spec = self.options().resolved().specs().swap_remove(0);
        let (worst_alpha, worst_mu) = spec.texel_coordinates(worst);
        Ok(Some(ExtraAudit {
            name: reference.name,
            texels: stored.len(),
            max_error,
            rms_error: (sum2 / stored.len() as f64).sqrt(),
            worst_alpha,
            worst_mu: worst_mu.unwrap_or(0.0),
            worst_table: stored[worst],
            worst_reference: reference.value[worst],
            reference_error: reference.max_error,
        }))
    }
}

/// The result of [`Preset::audit_extra`].
#[derive(Clone, Debug, PartialEq)]
pub struct ExtraAudit {
    /// What the channel holds.
    pub name: &'static str,
    /// Texels compared.
    pub texels: usize,
    /// The largest absolute difference from kiln's values (NaN if the file holds a NaN).
    pub max_error: f64,
    /// The root-mean-square difference.
    pub rms_error: f64,
    /// Where the largest difference is: `alpha` and `mu` of that texel.
    pub worst_alpha: f64,
    /// See `worst_alpha`.
    pub worst_mu: f64,
    /// The file's value there.
    pub worst_table: f64,
    /// kiln's value there.
    pub worst_reference: f64,
    /// The error estimate of kiln's values.
    pub reference_error: f64,
}

/// See [`Preset::extra_channel`].
#[derive(Clone, Debug, PartialEq)]
pub struct ExtraChannel {
    /// What the channel holds.
    pub name: &'static str,
    /// Its values at the preset's texels, roughness rows and `mu` columns.
    pub value: Vec<f64>,
    /// The largest error estimate of those values (0: exact up to rounding).
    pub max_error: f64,
}

impl Preset {
    /// An engine's own file read as kiln tables of the preset's specs (values as stored; `1 -
    /// value` by subtraction; no standard errors), for auditing.
    pub fn read_tables(self, bytes: &[u8], origin: &str) -> Result<Vec<Table>> {
        let options = BakeOptions {
            size: self.size_in(bytes)?,
            ..self.options()
        };
        let specs = options.resolved().specs();
        let tables: Vec<Table> = self
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
            .collect();
        for table in &tables {
            table.check().map_err(|m| {
                Error::InvalidInput(format!(
                    "{origin}: {} in the {} layout: {m}",
                    table.spec.quantity.symbol(),
                    self.name()
                ))
            })?;
        }
        Ok(tables)
    }
}

/// The file of `f_ms_norm` beside Cycles' `shader.tables`.
pub const CYCLES_NORMALISATION_FILE: &str = "ggx_f_ms_norm.tables";

/// The file of `f_ms_norm` beside Enterprise PBR's `GGX_E.exr` and `GGX_E_avg.exr`.
pub const ENTERPRISE_NORMALISATION_FILE: &str = "GGX_f_ms_norm.exr";

/// Files a preset writes: `(name, bytes)`.
pub type Files = Vec<(String, Vec<u8>)>;

/// An engine file's tables (quantity, values in kiln's order) and its extra channel.
type Decoded = (Vec<(Quantity, Vec<f64>)>, Option<Vec<f64>>);

/// Little-endian 16-bit words (a container's half floats).
#[cfg(feature = "containers")]
fn little_endian(data: &[u8]) -> Vec<u16> {
    data.chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .collect()
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

/// The largest three.js table kiln reads (its releases shipped 16 and 32).
const MAX_THREE_SIZE: usize = 256;

/// three.js' `DFGLUTData.js` as three ships it (`src/renderers/shaders/DFGLUTData.js`): a header
/// comment, the imports of `DataTexture` and the constants, the private `DATA` (half-float
/// bits, RG interleaved, one row of `n` texels per line) and the exported `getDFGLUT()` that
/// builds the `DataTexture` once, so that kiln's file replaces three's as is. `scale` and
/// `bias` are in the engine's order ([`Preset::texel`]).
fn three_module(n: usize, scale: &[f64], bias: &[f64], command: &str) -> String {
    let half = |v: f64| crate::format::f16::encode(v).0.to_bits();
    let mut out = format!(
        "/**\n * Precomputed DFG LUT for physically based specular lighting, used by both\n * \
         image-based lighting and direct-light multi-scattering energy compensation\n * \
         Resolution: {n}x{n}\n * Written by kiln {}: GGX, height-correlated Smith masking, by \
         quadrature\n * (not sampled), each value the nearest half float\n * Format: RG16F (2 half floats per texel: scale, bias); u = \
         roughness, v = dotNV, texel centres\n * Regenerate: {}\n */\n\n\
         import {{ DataTexture }} from '../../textures/DataTexture.js';\n\
         import {{ RGFormat, HalfFloatType, LinearFilter, ClampToEdgeWrapping }} from \
         '../../constants.js';\n\nconst DATA = new Uint16Array( [",
        crate::format::metadata::KILN_VERSION,
        command.replace("*/", "* /")
    );
    for row in 0..n {
        out.push_str("\n\t");
        for column in 0..n {
            let k = row * n + column;
            let _ = write!(out, "0x{:04x}, 0x{:04x}", half(scale[k]), half(bias[k]));
            out.push_str(match (column + 1 == n, k + 1 == n * n) {
                (_, true) => "",
                (true, false) => ",",
                (false, false) => ", ",
            });
        }
    }
    let _ = write!(
        out,
        "\n] );\n\nlet lut = null;\n\nexport function getDFGLUT() {{\n\n\tif ( lut === null ) {{\n\n\
         \t\tlut = new DataTexture( DATA, {n}, {n}, RGFormat, HalfFloatType );\n\
         \t\tlut.name = 'DFG_LUT';\n\t\tlut.minFilter = LinearFilter;\n\
         \t\tlut.magFilter = LinearFilter;\n\t\tlut.wrapS = ClampToEdgeWrapping;\n\
         \t\tlut.wrapT = ClampToEdgeWrapping;\n\t\tlut.generateMipmaps = false;\n\
         \t\tlut.needsUpdate = true;\n\n\t}}\n\n\treturn lut;\n\n}}\n"
    );
    out
}

/// The half-float bits of the `Uint16Array` in a three.js `DFGLUTData.js`, in file order.
fn three_data(bytes: &[u8]) -> std::result::Result<Vec<u16>, String> {
    let text = String::from_utf8_lossy(bytes);
    let start = text.find("Uint16Array").ok_or("no Uint16Array")?;
    let body = &text[start..];
    let open = body.find('[').ok_or("no [ after Uint16Array")?;
    // The first ] after the [ (one before it is not this array's).
    let close = body[open..]
        .find(']')
        .map(|c| open + c)
        .ok_or("no ] after the [")?;
    body[open + 1..close]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            let digits = s.trim_start_matches("0x").trim_start_matches("0X");
            u16::from_str_radix(digits, 16).map_err(|e| format!("{}: {e}", crate::error::quoted(s)))
        })
        .collect()
}

/// The `(width, height)` a three.js `DFGLUTData.js` builds its `DataTexture` with, if it says.
fn three_texture_size(text: &str) -> Option<(usize, usize)> {
    let call = &text[text.find("new DataTexture(")? + "new DataTexture(".len()..];
    let arguments: Vec<&str> = call[..call.find(')')?].split(',').map(str::trim).collect();
    Some((
        arguments.get(1)?.parse().ok()?,
        arguments.get(2)?.parse().ok()?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A three.js module holding `pairs` RG pairs and building a `w x h` texture.
    fn three_file(pairs: usize, w: usize, h: usize) -> Vec<u8> {
        let data: Vec<&str> = vec!["0x3c00, 0x0000"; pairs];
        format!(
            "const DATA = new Uint16Array( [ {} ] );\nlut = new DataTexture( DATA, {w}, {h}, \
             RGFormat, HalfFloatType );\n",
            data.join(", ")
        )
        .into_bytes()
    }

    #[test]
    fn a_three_table_s_size_is_read_from_its_data_and_checked_against_its_texture() {
        assert_eq!(Preset::Three.size_in(&three_file(256, 16, 16)).unwrap(), 16);
        assert_eq!(
            Preset::Three.size_in(&three_file(1024, 32, 32)).unwrap(),
            32
        );
        assert_eq!(Preset::Three.size_in(&three_file(64, 8, 8)).unwrap(), 8);
        let wrong = Preset::Three
            .size_in(&three_file(256, 32, 32))
            .unwrap_err()
            .to_string();
        assert!(
            wrong.contains("16 x 16") && wrong.contains("32 x 32"),
            "{wrong}"
        );
        let not_square = Preset::Three
            .size_in(&three_file(200, 16, 16))
            .unwrap_err()
            .to_string();
        assert!(not_square.contains("400 half floats"), "{not_square}");
        assert_eq!(three_texture_size("no texture here"), None);
    }
}

//! Engine presets: a table laid out exactly as an engine loads it (size, axis order, roughness
//! convention, grid, channels, container), so that kiln's file replaces the engine's own, and
//! the reader of that layout for `kiln verify --preset`.
//!
//! Each engine is one declarative [`Layout`] ([`layout`]: size, grid, `mu` mapping, masking,
//! tables, texel order, channels, storage, container); the files are written and read per
//! container (`container.rs`), so adding an engine is one `Layout` value, one arm of
//! [`Preset::layout`] and a test.
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

mod container;
mod decode;
pub mod layout;

pub use container::Carried;

use crate::bake::BakeOptions;
use crate::error::{Error, Result};
use crate::model::{Ndf, RoughnessConvention};
use crate::table::{Quantity, Table, TableSpec};
pub use layout::{CYCLES_NORMALISATION_FILE, ENTERPRISE_NORMALISATION_FILE};
use layout::{Container, Extra, Layout};

/// An engine layout (named in scene files as on the command line).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Preset {
    /// Blender Cycles: E and E_avg, 32 x 32 mu-major, nodes, and the 16^3 glass arrays, C float
    /// arrays.
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
    /// The GAMES202 Kulla-Conty homework: GGX_E_LUT.png and GGX_Eavg_LUT.png, 128 x 128 8-bit
    /// grey, roughest row on top, Schlick-GGX k = alpha/2.
    #[cfg_attr(feature = "cli", value(name = "games202"))]
    #[serde(rename = "games202")]
    Games202,
}

impl Preset {
    /// Every preset.
    pub const ALL: [Preset; 9] = [
        Preset::Cycles,
        Preset::Bevy,
        Preset::Three,
        Preset::EnterprisePbr,
        Preset::Filament,
        Preset::Godot,
        Preset::UnityHdrp,
        Preset::Unreal,
        Preset::Games202,
    ];

    /// The absolute tolerance of the cloth channel's quadrature (Filament, Godot): well below
    /// half-float spacing (`2^-11` relative).
    pub const SHEEN_TOLERANCE: f64 = 1e-7;

    /// The engine's layout: everything else follows from it.
    #[must_use]
    pub fn layout(self) -> &'static Layout {
        match self {
            Preset::Cycles => &layout::CYCLES,
            Preset::Bevy => &layout::BEVY,
            Preset::Three => &layout::THREE,
            Preset::EnterprisePbr => &layout::ENTERPRISE_PBR,
            Preset::Filament => &layout::FILAMENT,
            Preset::Godot => &layout::GODOT,
            Preset::UnityHdrp => &layout::UNITY_HDRP,
            Preset::Unreal => &layout::UNREAL,
            Preset::Games202 => &layout::GAMES202,
        }
    }

    /// How the engine's file stores its numbers, for an audit to show what that alone costs
    /// (half floats, 8 bits); `None` for f32, whose cost is below anything an audit reports.
    #[must_use]
    pub fn storage(self) -> Option<crate::verify::Storage> {
        Self::storage_as(self.layout().stored)
    }

    fn storage_as(stored: layout::Stored) -> Option<crate::verify::Storage> {
        (stored != layout::Stored::F32).then(|| crate::verify::Storage {
            name: stored.name(),
            round: stored.rounding(),
            step: stored.step(),
        })
    }

    /// [`Preset::storage`] of the engine's file `bytes` as it is: a PNG given where the engine
    /// writes 8 bits is audited against the precision it really holds
    /// ([`crate::format::png::effective_bits`]): 16 bits (floor 7.6e-6, not 1.96e-3), 8 bits
    /// saved as 16 (levels times 257, or an `sBIT` of 8), 4 bits.
    #[must_use]
    pub fn storage_of(self, bytes: &[u8]) -> Option<crate::verify::Storage> {
        let stored = self.layout().stored;
        if stored != layout::Stored::Unorm8 || !bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            return Self::storage_as(stored);
        }
        Self::storage_as(match crate::format::png::effective_bits(bytes) {
            Some(16) => layout::Stored::Unorm16,
            Some(bits) if bits <= 4 => layout::Stored::Unorm4,
            _ => layout::Stored::Unorm8,
        })
    }

    /// The name on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        self.layout().name
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
        self.layout().file_name
    }

    /// Every file the preset writes, `(name, bytes)`.
    pub fn files(self, tables: &[Table]) -> Result<Files> {
        Ok(self.files_and_extra(tables)?.0)
    }

    /// [`Preset::files`], with the [`Preset::extra_channel`] they hold (computed once), for a
    /// caller that reports it.
    pub fn files_and_extra(self, tables: &[Table]) -> Result<(Files, Option<ExtraChannel>)> {
        let extra = self.extra_channel();
        Ok((self.files_with(tables, extra.as_ref())?, extra))
    }

    /// The preset's files with the given extra channel (`None`: not computed, written as 0).
    pub fn files_with(self, tables: &[Table], extra: Option<&ExtraChannel>) -> Result<Files> {
        self.files_carrying(tables, extra, None)
    }

    /// [`Preset::files_with`], with the engine's arrays kiln does not compute carried over from
    /// its own file ([`Carried::from_file`]; Cycles' `table_sheen_ltc`).
    pub fn files_carrying(
        self,
        tables: &[Table],
        extra: Option<&ExtraChannel>,
        carried: Option<&Carried>,
    ) -> Result<Files> {
        let mut files = container::encode(self.layout(), tables, extra, carried)?;
        if let Some(file) = self.normalisation_file(tables)? {
            files.push(file);
        }
        Ok(files)
    }

    /// What `kiln bake --preset` writes: the engine's files from [`Preset::engine_tables`]
    /// (with `extra`, see [`Preset::files_with`]) and kiln's JSON sidecar of each table beside
    /// them ([`Preset::sidecar_name`]), each naming the engine's files it describes.
    pub fn files_with_sidecars(
        self,
        tables: &[Table],
        extra: Option<&ExtraChannel>,
        carried: Option<&Carried>,
    ) -> Result<Files> {
        let tables = self.engine_tables(tables)?;
        let mut files = self.files_carrying(&tables, extra, carried)?;
        let engine_files: Vec<String> = files.iter().map(|(name, _)| name.clone()).collect();
        for table in &tables {
            let described = [(self.name().to_string(), engine_files.join(", "))]
                .into_iter()
                .collect();
            let sidecar = crate::format::json::sidecar(table, "f32", described);
            let bytes = crate::format::json::encode(&sidecar).map_err(|message| {
                Error::InvalidInput(format!("{}: {message}", self.sidecar_name(table)))
            })?;
            files.push((self.sidecar_name(table), bytes));
        }
        Ok(files)
    }

    /// The smallest `mu` and roughness the engine computed the file `bytes` at, where its
    /// lookups clamp: Blender computes its Cycles tables' first row and column at 1e-4; kiln's
    /// own files (they start with kiln's header) and every other engine's hold the node values
    /// themselves (0).
    #[must_use]
    pub fn computed_from(self, bytes: &[u8]) -> f64 {
        let kiln_s_own = bytes.starts_with(b"/* kiln") || bytes.starts_with(b"// kiln");
        if kiln_s_own {
            0.0
        } else {
            self.layout().engine_computed_from
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

    /// The tables as the preset's files hold them: `f_ms_norm` derived from the E table as the
    /// engine file stores it ([`Layout::stored`]; Enterprise PBR's shader computes `1 - E` from
    /// the f16 `E`), so that it is the average of the lookup the engine makes; the others as
    /// given. The engine's files and kiln's sidecars beside them are both written from these, so
    /// a sidecar describes the bytes beside it. Idempotent.
    pub fn engine_tables(self, tables: &[Table]) -> Result<Vec<Table>> {
        let layout = self.layout();
        if layout.normalisation.is_none()
            || !tables.iter().any(|t| t.spec.quantity == Quantity::FMsNorm)
        {
            return Ok(tables.to_vec());
        }
        let e = tables
            .iter()
            .find(|t| t.spec.quantity == Quantity::E)
            .ok_or_else(|| Error::InvalidInput("f_ms_norm needs the E table".into()))?;
        let value: Vec<f64> = e.value.iter().map(|&v| layout.stored.round(v)).collect();
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
    fn normalisation_file(self, tables: &[Table]) -> Result<Option<(String, Vec<u8>)>> {
        let Some(form) = self.layout().normalisation else {
            return Ok(None);
        };
        let engine = self.engine_tables(tables)?;
        let Some(norm) = engine.iter().find(|t| t.spec.quantity == Quantity::FMsNorm) else {
            return Ok(None);
        };
        let bytes = container::encode_normalisation(form, norm)?;
        Ok(Some((form.file().to_string(), bytes)))
    }

    /// The bake that gives the preset's tables (to the default max error).
    #[must_use]
    pub fn options(self) -> BakeOptions {
        let layout = self.layout();
        BakeOptions {
            ndfs: vec![Ndf::Ggx],
            maskings: vec![layout.masking],
            quantities: layout.tables.to_vec(),
            size: layout.size,
            grid: layout.grid,
            mu_mapping: Some(layout.mu_mapping),
            roughness_convention: RoughnessConvention::Perceptual,
            // The engines' files: linear rows, point samples (`--texels lookup-fit` asks).
            roughness_spacing: Some(crate::table::axis::RoughnessSpacing::Linear),
            texels: Some(crate::table::Texels::Nodes),
            ..BakeOptions::default()
        }
    }

    /// The bake of the preset's glass tables ([`layout::GlassLayout`]; `None` for an engine
    /// without): to `max_error`, or the layout's default for them.
    #[must_use]
    pub fn glass_options(self, max_error: Option<f64>) -> Option<BakeOptions> {
        let glass = self.layout().glass?;
        Some(BakeOptions {
            quantities: glass.tables.to_vec(),
            size: glass.size,
            ior_size: glass.size,
            ior_mapping: glass.ior_mapping,
            transmission: glass.transmission,
            max_error: Some(max_error.unwrap_or(glass.default_max_error)),
            ..self.options()
        })
    }

    /// Every bake the preset's files hold: [`Preset::options`] and [`Preset::glass_options`],
    /// to `max_error` (`None`: the defaults, 1e-7 and the glass tables' own).
    #[must_use]
    pub fn bakes(self, max_error: Option<f64>) -> Vec<BakeOptions> {
        let main = BakeOptions {
            max_error: Some(max_error.unwrap_or(BakeOptions::DEFAULT_MAX_ERROR)),
            ..self.options()
        };
        std::iter::once(main)
            .chain(self.glass_options(max_error))
            .collect()
    }

    /// The engine's arrays kiln does not compute, from the engine's file `bytes` (`origin` names
    /// it), for [`Preset::files_carrying`]; `None` for a preset without such arrays.
    ///
    /// # Errors
    /// If the file lacks one of them.
    pub fn carried_from(self, bytes: &[u8], origin: &str) -> Result<Option<Carried>> {
        let layout = self.layout();
        if layout.carried.is_empty() {
            return Ok(None);
        }
        Carried::from_file(layout, bytes, origin).map(Some)
    }

    /// The engine's value of `tables[channel]` at roughness index `r` and `mu` index `m`:
    /// where in the engine's flat array it sits (in texels; channels interleave within one).
    #[must_use]
    pub fn texel(self, r: usize, m: usize) -> usize {
        let layout = self.layout();
        layout.order.index(r, m, layout.size)
    }

    /// The channel of the engine's texture that is not one of kiln's tables, at the preset's
    /// texels in kiln's order: Filament's and Godot's cloth albedo
    /// ([`crate::integrate::sheen`]), HDRP's Disney diffuse albedo minus 0.5
    /// ([`crate::model::disney_diffuse`]); `None` for the other presets.
    #[must_use]
    pub fn extra_channel(self) -> Option<ExtraChannel> {
        let extra = self.layout().extra?;
        let (value, max_error) = match extra {
            Extra::ClothAlbedo => {
                let plane = crate::integrate::sheen::sheen_plane(
                    self.options().size,
                    Self::SHEEN_TOLERANCE,
                );
                (plane.value, plane.max_error)
            }
            Extra::DisneyDiffuseMinusHalf => {
                let spec = self.options().resolved().specs().swap_remove(0);
                let value = (0..spec.len())
                    .map(|k| {
                        let (alpha, mu) = spec.texel_coordinates(k);
                        let mu = mu.expect("a 2-D table has a mu axis");
                        crate::model::disney_diffuse::disney_diffuse_albedo(alpha.sqrt(), mu) - 0.5
                    })
                    .collect();
                (value, 0.0)
            }
        };
        Some(ExtraChannel {
            name: extra.description(),
            value,
            max_error,
        })
    }

    /// Writes the tables ([`Preset::options`]'s bake) in the engine's layout: the file
    /// [`Preset::file_name`] (see [`Preset::files`] for all of them).
    pub fn encode(self, tables: &[Table]) -> Result<Vec<u8>> {
        let extra = self.extra_channel();
        let mut files = container::encode(self.layout(), tables, extra.as_ref(), None)?;
        Ok(files.swap_remove(0).1)
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

    /// The size of the engine's table in `bytes`: the layout's, or for three.js whichever
    /// square its `DATA` holds (16 x 16 since three r182, 32 x 32 in r181 and before), which must
    /// agree with the size its `DataTexture` is built with.
    fn size_in(self, bytes: &[u8]) -> Result<usize> {
        let layout = self.layout();
        if layout.container != Container::ThreeModule {
            return Ok(layout.size);
        }
        let bad = |m: String| self.not_its_file(m);
        let halves = container::three_data(bytes)
            .map_err(|e| bad(e.to_string()))?
            .len();
        let stride = layout.channels.len();
        let n = (1..=container::MAX_THREE_SIZE)
            .find(|&n| stride * n * n == halves)
            .ok_or_else(|| {
                bad(format!(
                    "{halves} half floats in DATA (expected {} for 16 x 16 or {} for 32 x 32: \
                     {stride} per texel of a square table)",
                    stride * 256,
                    stride * 1024
                ))
            })?;
        let text = String::from_utf8_lossy(bytes);
        if let Some(declared) = container::three_texture_size(&text)
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
    fn decode_all(self, bytes: &[u8]) -> Result<container::Decoded> {
        let n = self.size_in(bytes)?;
        decode::decode(self.layout(), bytes, n, self.normalisation_size(), &|m| {
            self.not_its_file(m)
        })
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
        let specs: Vec<TableSpec> = std::iter::once(options)
            .chain(self.glass_options(None))
            .flat_map(|o| o.resolved().specs())
            .collect();
        let tables: Vec<Table> = self
            .decode(bytes)?
            .into_iter()
            .filter_map(|(quantity, value)| {
                let spec = specs.iter().find(|s| s.quantity == quantity)?.clone();
                Some((spec, value))
            })
            .map(|(spec, value)| {
                let command = format!("{origin}, read in the {} layout", self.name());
                Table::of_values(spec, value, command)
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

/// Files a preset writes: `(name, bytes)`.
pub type Files = Vec<(String, Vec<u8>)>;

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
        assert_eq!(container::three_texture_size("no texture here"), None);
    }
}

//! Engine layouts as data: for each engine, one [`Layout`] value says what kiln bakes for it
//! (size, grid, `mu` mapping, masking, tables), where each texel sits in the engine's array
//! ([`TexelOrder`]), what each channel of its texture holds ([`Channel`]), how the engine stores
//! the numbers ([`Stored`]) and in what file ([`Container`]). The code that reads and writes the
//! files is per container, not per engine (`container.rs`); only the text formats that no
//! other engine shares (Cycles' C arrays, three.js' module, Filament's include) have their own.
//! The sources of each layout (engines' files and commits) are in `docs/engines.md`.

use crate::model::Masking;
use crate::model::dielectric::TransmissionConvention;
use crate::table::Quantity;
use crate::table::axis::{Grid, IorMapping, MuMapping};

/// Where the engine's flat array puts the texel at roughness index `r` and `mu` index `m` of an
/// `n x n` table (in texels; channels interleave within one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelOrder {
    /// `m n + r`: rows of `mu`, roughness across (Cycles' `mu_index * 32 + r_index`; three.js'
    /// texture with `u` = roughness, `v` = `NoV`).
    MuRows,
    /// `r n + m`: rows of roughness from the smooth end, `mu` across.
    RoughnessRows,
    /// `(n - 1 - r) n + m`: rows of roughness from the rough end (the image's top row at
    /// `r = 1`), `mu` across.
    RoughnessRowsFromRough,
}

impl TexelOrder {
    /// The engine's index of kiln's texel `(r, m)`.
    #[must_use]
    pub fn index(self, r: usize, m: usize, n: usize) -> usize {
        match self {
            TexelOrder::MuRows => m * n + r,
            TexelOrder::RoughnessRows => r * n + m,
            TexelOrder::RoughnessRowsFromRough => (n - 1 - r) * n + m,
        }
    }
}

/// What a material asks of the tables: the effects a renderer computes with them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Effect {
    /// Kulla-Conty energy compensation of the specular lobe (`E`, `E_avg`, `f_ms_norm`; or an
    /// engine's `1 / E` scaling from its DFG table).
    MultipleScattering,
    /// Image-based lighting by the split sum (scale and bias, an engine's DFG texture).
    ImageBasedLighting,
    /// Cloth sheen (the Charlie/Ashikhmin albedo in Filament's and Godot's DFG texture).
    Sheen,
    /// Light refracted through a dielectric (the dielectric tables).
    Transmission,
    /// A clear coat over the material: its reflection-only albedo, by which the base beneath
    /// is attenuated (`E_reflection`, `E_avg_reflection` at the coat's IOR).
    Coat,
}

impl Effect {
    /// The name in scene files and plans.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Effect::MultipleScattering => "multiple-scattering",
            Effect::ImageBasedLighting => "image-based-lighting",
            Effect::Sheen => "sheen",
            Effect::Transmission => "transmission",
            Effect::Coat => "coat",
        }
    }
}

/// What one channel of an engine's texture holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Channel {
    /// One of the tables kiln bakes for the layout.
    Table(Quantity),
    /// The layout's [`Extra`] channel.
    Extra,
    /// The same number at every texel (an alpha of 1, an unused 0).
    Constant(f64),
}

/// A channel kiln computes beside its tables for an engine's texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extra {
    /// The cloth albedo of Filament's and Godot's DFG texture: Charlie NDF, Ashikhmin visibility
    /// ([`crate::integrate::sheen`]).
    ClothAlbedo,
    /// Unity HDRP's Disney diffuse albedo minus 0.5 ([`crate::model::disney_diffuse`]).
    DisneyDiffuseMinusHalf,
}

impl Extra {
    /// What the channel holds, for reports.
    #[must_use]
    pub fn description(self) -> &'static str {
        match self {
            Extra::ClothAlbedo => "cloth albedo (Charlie NDF, Ashikhmin visibility)",
            Extra::DisneyDiffuseMinusHalf => "Disney diffuse albedo - 0.5",
        }
    }

    /// The effect that needs the channel (`None`: always written, as HDRP's diffuse albedo,
    /// which its engine uses for every material).
    #[must_use]
    pub fn effect(self) -> Option<Effect> {
        match self {
            Extra::ClothAlbedo => Some(Effect::Sheen),
            Extra::DisneyDiffuseMinusHalf => None,
        }
    }

    /// The channel's name in a container that names its channels.
    #[must_use]
    pub fn channel_name(self) -> &'static str {
        match self {
            Extra::ClothAlbedo => "E_sheen",
            Extra::DisneyDiffuseMinusHalf => "B",
        }
    }
}

/// How the engine stores each number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stored {
    /// IEEE single precision (C `float`).
    F32,
    /// IEEE half precision, nearest ([`crate::format::f16`]).
    F16,
    /// 8-bit unsigned normalised, `round(255 v) / 255` ([`crate::format::png::unorm8`]).
    Unorm8,
    /// 16-bit unsigned normalised, `round(65535 v) / 65535` (a 16-bit PNG given where the
    /// engine's is 8-bit: [`crate::preset::Preset::storage_of`]).
    Unorm16,
    /// 4-bit unsigned normalised, `round(15 v) / 15` (a 4-bit PNG given where the engine's is
    /// 8-bit).
    Unorm4,
}

impl Stored {
    /// A value as the engine's file holds it, widened back.
    #[must_use]
    pub fn round(self, value: f64) -> f64 {
        self.rounding()(value)
    }

    /// [`Stored::round`] as a function.
    #[must_use]
    pub fn rounding(self) -> fn(f64) -> f64 {
        match self {
            Stored::F32 => |v| f64::from(v as f32),
            Stored::F16 => crate::format::f16::stored,
            Stored::Unorm8 => |v| f64::from(crate::format::png::unorm8(v)) / 255.0,
            Stored::Unorm16 => |v| (v.clamp(0.0, 1.0) * 65535.0).round() / 65535.0,
            Stored::Unorm4 => |v| (v.clamp(0.0, 1.0) * 15.0).round() / 15.0,
        }
    }

    /// The spacing of a fixed-point storage (`1 / 255` for 8 bits), 0 for a floating one.
    #[must_use]
    pub fn step(self) -> f64 {
        match self {
            Stored::F32 | Stored::F16 => 0.0,
            Stored::Unorm8 => 1.0 / 255.0,
            Stored::Unorm16 => 1.0 / 65535.0,
            Stored::Unorm4 => 1.0 / 15.0,
        }
    }

    /// What the storage is called in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Stored::F32 => "f32",
            Stored::F16 => "f16",
            Stored::Unorm8 => "8-bit",
            Stored::Unorm16 => "16-bit",
            Stored::Unorm4 => "4-bit",
        }
    }
}

/// The file format of an engine's table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    /// C `float` arrays, one per table under its name (2-D tables in the layout's
    /// [`TexelOrder`], 1-D ones by roughness): Cycles' `shader.tables`.
    CycleTables(&'static [(&'static str, Quantity)]),
    /// KTX2 with the layout's channels interleaved, half floats, one level; zstd
    /// supercompression with kiln's `containers` feature (as Bevy ships it).
    Ktx2,
    /// DDS with the layout's channels interleaved, half floats (`containers` feature).
    Dds,
    /// One EXR image with the layout's channels as planes R, G, B, A, half floats.
    ExrPlanes,
    /// One EXR image per table, `(file, quantity)`, its values in one half-float channel `Y`
    /// (2-D tables `n x n`, 1-D ones `n x 1`).
    ExrPerTable(&'static [(&'static str, Quantity)]),
    /// three.js' `DFGLUTData.js` module: the channels' half-float bits interleaved in a
    /// `Uint16Array` with the `getDFGLUT()` that builds the `DataTexture`.
    ThreeModule,
    /// Filament's `dfg.inc`: the channels' half-float bits interleaved as C hex literals, four
    /// texels per line, to be included inside an array.
    HalfBitsInclude,
    /// One 8-bit grey PNG image (R = G = B) per table, `(file, quantity)`, all `n x n`: a 2-D
    /// table in the layout's [`TexelOrder`], a 1-D table (by roughness) repeated along each of
    /// its rows (the GAMES202 homework's `GGX_E_LUT.png` and `GGX_Eavg_LUT.png`).
    Png8(&'static [(&'static str, Quantity)]),
}

/// How an engine that normalises its multiple-scattering lobe by `E_avg` gets kiln's
/// lookup-consistent `f_ms_norm` ([`crate::table::normalisation`]) beside its own files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normalisation {
    /// A C `float` array `table_ggx_f_ms_norm` in its own file.
    CycleTable(&'static str),
    /// A one-row EXR, channel `Y` in f32 (its values reach 1e-7, below half-float range).
    ExrF32(&'static str),
}

impl Normalisation {
    /// The file it is written to.
    #[must_use]
    pub fn file(self) -> &'static str {
        match self {
            Normalisation::CycleTable(file) | Normalisation::ExrF32(file) => file,
        }
    }
}

/// One engine's layout: everything kiln needs to write a file that replaces the engine's own,
/// and to read the engine's file for an audit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// The preset's name on the command line.
    pub name: &'static str,
    /// The engine's file (the first, for a container of several).
    pub file_name: &'static str,
    /// Texels per axis (both axes; 1-D tables have `size` entries).
    pub size: usize,
    /// Texel centres or nodes, on both axes.
    pub grid: Grid,
    /// The `mu` axis' mapping (the roughness axis is always perceptual `r`, `alpha = r^2`).
    pub mu_mapping: MuMapping,
    /// The Smith masking the engine's BRDF uses (always GGX).
    pub masking: Masking,
    /// The tables kiln bakes, in order.
    pub tables: &'static [Quantity],
    /// Where each texel sits in the engine's arrays.
    pub order: TexelOrder,
    /// The channels of the engine's texture, in texel order (for the containers of one
    /// texture).
    pub channels: &'static [Channel],
    /// How the numbers are stored.
    pub stored: Stored,
    /// The file format.
    pub container: Container,
    /// The channel kiln computes beside its tables, if any.
    pub extra: Option<Extra>,
    /// `f_ms_norm` beside the engine's files, if the engine normalises by `E_avg`.
    pub normalisation: Option<Normalisation>,
    /// The smallest `mu` and roughness the engine itself computed its file at (its first row
    /// and column stand for this value), for a file kiln did not write: Cycles' 1e-4.
    pub engine_computed_from: f64,
    /// The effects the engine computes with its tables (its [`Layout::extra`] channel serves
    /// [`Extra::effect`]).
    pub effects: &'static [Effect],
    /// The engine's dielectric (glass) tables, on axes of their own, if it has any.
    pub glass: Option<GlassLayout>,
    /// The engine's arrays kiln does not compute (Cycles' `table_sheen_ltc`, an LTC fit): a
    /// preset's file carries them over verbatim from the engine's own file when given one.
    pub carried: &'static [&'static str],
}

/// The dielectric tables of a layout: same grid, `mu` mapping and masking as its other tables,
/// `size` samples on each of the IOR, roughness and `mu` axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlassLayout {
    pub size: usize,
    pub ior_mapping: IorMapping,
    /// The tables, in order (`E` over (eta, roughness, mu), `E_avg` over (eta, roughness)).
    pub tables: &'static [Quantity],
    /// How the engine's tables count a refraction that ends on the incident side.
    pub transmission: TransmissionConvention,
    /// The max error they are baked to unless the user names one: they cost ten to a hundred
    /// times the other tables per digit.
    pub default_max_error: f64,
}

/// The file of `f_ms_norm` beside Cycles' `shader.tables`.
pub const CYCLES_NORMALISATION_FILE: &str = "ggx_f_ms_norm.tables";

/// The file of `f_ms_norm` beside Enterprise PBR's `GGX_E.exr` and `GGX_E_avg.exr`.
pub const ENTERPRISE_NORMALISATION_FILE: &str = "GGX_f_ms_norm.exr";

use Channel::{Constant, Table};
use Quantity::{
    E, EAvg, EAvgDielectric, EAvgDielectricInside, EBias, EDielectric, EDielectricInside, EScale,
    FMsNorm,
};

/// Blender Cycles' `table_ggx_E[1024]` and `table_ggx_Eavg[32]` (`shader.tables`).
pub const CYCLES: Layout = Layout {
    name: "cycles",
    file_name: "shader.tables",
    size: 32,
    grid: Grid::Nodes,
    mu_mapping: MuMapping::Linear,
    masking: Masking::HeightCorrelated,
    tables: &[E, EAvg, FMsNorm],
    order: TexelOrder::MuRows,
    channels: &[Table(E)],
    stored: Stored::F32,
    container: Container::CycleTables(&[
        ("table_ggx_E", E),
        ("table_ggx_Eavg", EAvg),
        ("table_ggx_glass_E", EDielectric),
        ("table_ggx_glass_Eavg", EAvgDielectric),
        ("table_ggx_glass_inv_E", EDielectricInside),
        ("table_ggx_glass_inv_Eavg", EAvgDielectricInside),
    ]),
    extra: None,
    normalisation: Some(Normalisation::CycleTable(CYCLES_NORMALISATION_FILE)),
    engine_computed_from: 1e-4,
    effects: &[Effect::MultipleScattering, Effect::Transmission],
    glass: Some(GlassLayout {
        size: 16,
        ior_mapping: IorMapping::Blender,
        tables: &[
            EDielectric,
            EDielectricInside,
            EAvgDielectric,
            EAvgDielectricInside,
        ],
        transmission: TransmissionConvention::Cycles,
        default_max_error: CYCLES_GLASS_MAX_ERROR,
    }),
    carried: &["table_sheen_ltc"],
};

/// The default max error of Cycles' glass tables: Blender's own are within 1.5e-5 of the truth
/// in Cycles' convention (`docs/engines.md`), and each digit below costs the inside average
/// about twice the time.
pub const CYCLES_GLASS_MAX_ERROR: f64 = 1e-5;

/// Bevy's `dfg.ktx2`.
pub const BEVY: Layout = Layout {
    name: "bevy",
    file_name: "dfg.ktx2",
    size: 64,
    grid: Grid::Centers,
    mu_mapping: MuMapping::Linear,
    masking: Masking::HeightCorrelated,
    tables: &[EScale, EBias],
    order: TexelOrder::RoughnessRows,
    channels: &[Table(EScale), Table(EBias)],
    stored: Stored::F16,
    container: Container::Ktx2,
    extra: None,
    normalisation: None,
    engine_computed_from: 0.0,
    effects: &[Effect::MultipleScattering, Effect::ImageBasedLighting],
    glass: None,
    carried: &[],
};

/// three.js' `DFGLUTData.js` (16 x 16 since r182; r181 and before shipped 32 x 32, which
/// reads alike).
pub const THREE: Layout = Layout {
    name: "three",
    file_name: "DFGLUTData.js",
    size: 16,
    grid: Grid::Centers,
    mu_mapping: MuMapping::Linear,
    masking: Masking::HeightCorrelated,
    tables: &[EScale, EBias],
    order: TexelOrder::MuRows,
    channels: &[Table(EScale), Table(EBias)],
    stored: Stored::F16,
    container: Container::ThreeModule,
    extra: None,
    normalisation: None,
    engine_computed_from: 0.0,
    effects: &[Effect::MultipleScattering, Effect::ImageBasedLighting],
    glass: None,
    carried: &[],
};

/// Enterprise PBR's `res/GGX_E.exr` and `res/GGX_E_avg.exr`.
pub const ENTERPRISE_PBR: Layout = Layout {
    name: "enterprise-pbr",
    file_name: "GGX_E.exr",
    size: 32,
    grid: Grid::Centers,
    mu_mapping: MuMapping::Linear,
    masking: Masking::HeightCorrelated,
    tables: &[E, EAvg, FMsNorm],
    order: TexelOrder::RoughnessRows,
    channels: &[Table(E)],
    stored: Stored::F16,
    container: Container::ExrPerTable(&[("GGX_E.exr", E), ("GGX_E_avg.exr", EAvg)]),
    extra: None,
    normalisation: Some(Normalisation::ExrF32(ENTERPRISE_NORMALISATION_FILE)),
    engine_computed_from: 0.0,
    effects: &[Effect::MultipleScattering],
    glass: None,
    carried: &[],
};

/// Filament's `dfg.inc` (`cmgen --ibl-dfg-multiscatter --ibl-dfg-cloth`).
pub const FILAMENT: Layout = Layout {
    name: "filament",
    file_name: "dfg.inc",
    size: 128,
    grid: Grid::Centers,
    mu_mapping: MuMapping::Linear,
    masking: Masking::HeightCorrelated,
    tables: &[EBias, E],
    order: TexelOrder::RoughnessRows,
    channels: &[Table(EBias), Table(E), Channel::Extra],
    stored: Stored::F16,
    container: Container::HalfBitsInclude,
    extra: Some(Extra::ClothAlbedo),
    normalisation: None,
    engine_computed_from: 0.0,
    effects: &[Effect::MultipleScattering, Effect::ImageBasedLighting],
    glass: None,
    carried: &[],
};

/// Godot 4's DFG texture (`integrate_dfg.glsl`), as a DDS to upload in its place.
pub const GODOT: Layout = Layout {
    name: "godot",
    file_name: "dfg_lut.dds",
    size: 128,
    grid: Grid::Centers,
    mu_mapping: MuMapping::Linear,
    masking: Masking::SchlickGgx,
    tables: &[EBias, E],
    order: TexelOrder::RoughnessRowsFromRough,
    channels: &[Table(EBias), Table(E), Channel::Extra, Constant(1.0)],
    stored: Stored::F16,
    container: Container::Dds,
    extra: Some(Extra::ClothAlbedo),
    normalisation: None,
    engine_computed_from: 0.0,
    effects: &[Effect::MultipleScattering, Effect::ImageBasedLighting],
    glass: None,
    carried: &[],
};

/// Unity HDRP's `_PreIntegratedFGD_GGXDisneyDiffuse`, as an EXR to import in its place.
pub const UNITY_HDRP: Layout = Layout {
    name: "unity-hdrp",
    file_name: "preIntegratedFGD_GGXDisneyDiffuse.exr",
    size: 64,
    grid: Grid::Nodes,
    mu_mapping: MuMapping::Sqrt,
    masking: Masking::HeightCorrelated,
    tables: &[EBias, E],
    order: TexelOrder::RoughnessRowsFromRough,
    channels: &[Table(EBias), Table(E), Channel::Extra],
    stored: Stored::F16,
    container: Container::ExrPlanes,
    extra: Some(Extra::DisneyDiffuseMinusHalf),
    normalisation: None,
    engine_computed_from: 0.0,
    effects: &[Effect::MultipleScattering, Effect::ImageBasedLighting],
    glass: None,
    carried: &[],
};

/// Unreal Engine 5's `ShadingEnergyGGXSpecTexture`, as an EXR to import in its place.
pub const UNREAL: Layout = Layout {
    name: "unreal",
    file_name: "ShadingEnergyGGXSpec.exr",
    size: 32,
    grid: Grid::Centers,
    mu_mapping: MuMapping::Linear,
    masking: Masking::HeightCorrelated,
    tables: &[E, EBias],
    order: TexelOrder::RoughnessRows,
    channels: &[Table(E), Table(EBias), Constant(0.0), Constant(1.0)],
    stored: Stored::F16,
    container: Container::ExrPlanes,
    extra: None,
    normalisation: None,
    engine_computed_from: 0.0,
    effects: &[Effect::MultipleScattering, Effect::ImageBasedLighting],
    glass: None,
    carried: &[],
};

/// The Kulla-Conty homework of the GAMES202 course (assignment 4): `GGX_E_LUT.png` and
/// `GGX_Eavg_LUT.png`, 128 x 128 8-bit grey, row `i` at roughness `(i + 0.5) / 128` and column
/// `j` at `NdotV = (j + 0.5) / 128`, written flipped so that the roughest row is on top; GGX with
/// separable Schlick-GGX masking, `k = alpha / 2`. The homework's renderer samples
/// `vec2(NdotV, roughness)`.
pub const GAMES202: Layout = Layout {
    name: "games202",
    file_name: "GGX_E_LUT.png",
    size: 128,
    grid: Grid::Centers,
    mu_mapping: MuMapping::Linear,
    masking: Masking::SchlickGgx,
    tables: &[E, EAvg],
    order: TexelOrder::RoughnessRowsFromRough,
    channels: &[Table(E)],
    stored: Stored::Unorm8,
    container: Container::Png8(&[("GGX_E_LUT.png", E), ("GGX_Eavg_LUT.png", EAvg)]),
    extra: None,
    normalisation: None,
    engine_computed_from: 0.0,
    effects: &[Effect::MultipleScattering],
    glass: None,
    carried: &[],
};

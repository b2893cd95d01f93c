//! Scene files: the materials a renderer uses, and the minimal set of tables they need (the plan).
//!
//! A scene is TOML (unknown keys rejected):
//!
//! ```toml
//! [output]                      # optional
//! dir = "tables"
//! formats = ["exr", "rs", "json"]
//! precision = "f16"
//!
//! [[material]]
//! name = "brushed_steel"
//! ndf = "ggx"                   # ggx | beckmann
//! masking = "height-correlated" # optional, default height-correlated
//! roughness = [0.2, 0.6]        # perceptual roughness: one value or a [min, max] range
//! fresnel = { conductor = { eta = [2.9, 2.9, 2.4], k = [3.0, 2.9, 2.5] } }
//!
//! [[material]]
//! name = "varnish"
//! ndf = "beckmann"
//! roughness = 0.3
//! fresnel = { dielectric = { ior = 1.5 } }  # or { schlick = { f0 = 0.04 } }, or "none" (F = 1)
//!
//! [[material]]
//! name = "window"
//! ndf = "ggx"
//! roughness = 0.1
//! fresnel = { dielectric = { ior = 1.5 } }
//! transmission = true           # glass: light refracts through (needs a dielectric fresnel)
//! ior_varies = false            # true: a textured IOR, read from the tables over the IOR
//! coat = { ior = 1.5 }          # a clear coat: its reflection-only albedo at its IOR
//! image_based_lighting = true   # the split-sum tables (default false)
//! multiple_scattering = true    # Kulla-Conty's tables (the default)
//! ```
//!
//! `[output] preset = "filament"` writes that engine's own files instead ([`Preset`]): its
//! tables in its layout, and a channel whose effect no material asks for (`sheen = true` for
//! Filament's and Godot's cloth albedo) not computed.
//!
//! The plan ([`Scene::plan`]) lists each table once, with the materials and effects that need
//! it: `E`, `E_avg` and `f_ms_norm` for every NDF and masking combination whose materials ask
//! for multiple scattering (the Kulla-Conty lobe needs them, whatever the Fresnel model), the
//! split-sum scale and bias for image-based lighting, for the combinations a transmissive
//! material uses the dielectric tables
//! `E_dielectric`, `E_dielectric_inside` and their averages over (eta, roughness[, mu]) (energy
//! compensation of glass, [`crate::model::dielectric`]), and per material the scalars it needs:
//! `F_avg` per channel ([`crate::Fresnel::average`]) for the lobe's colour term.
//!
//! A glass material of one IOR gets, for each distinct IOR, the four dielectric tables at exactly
//! that IOR: [`ONE_IOR_SIZE`] x [`ONE_IOR_SIZE`] over (roughness, `mu`) from both sides, fitted
//! for the bilinear lookup as `E` is ([`crate::table::TableSpec::fixed_ior`]). A glass material
//! whose IOR varies (`ior_varies = true`: textured, animated) gets them over the IOR instead,
//! [`DIELECTRIC_SIZE`] samples per axis (Cycles' 16 x 16 x 16), with an IOR axis from 1 to the
//! larger of 3 and the highest `max(ior, 1 / ior)` of those materials. Each is a bake of its own,
//! so adding a glass material never re-bakes the `E` tables.

use crate::error::{Error, Result};
use crate::format::{Format, Precision};
use crate::model::fresnel::Rgb;
use crate::model::{Fresnel, Masking, Model, Ndf};
use crate::preset::Preset;
pub use crate::preset::layout::Effect;
use crate::table::Quantity;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The file [`Scene::bake`] writes beside the tables: each material's `F_avg`, `E_avg` and
/// colour multiplier.
pub const MATERIALS_FILE: &str = "materials.json";

/// Samples per axis of a scene's dielectric tables over the IOR (IOR, roughness and `mu`), for
/// the glass materials whose IOR varies.
pub const DIELECTRIC_SIZE: usize = 16;

/// Samples per axis (roughness and `mu`) of a scene's dielectric tables at one IOR.
pub const ONE_IOR_SIZE: usize = 32;

/// The reflection tables a coat needs, at its IOR.
pub const COAT_QUANTITIES: [Quantity; 2] = [Quantity::EReflection, Quantity::EAvgReflection];

/// The dielectric tables a transmissive material's model needs.
pub const DIELECTRIC_QUANTITIES: [Quantity; 4] = [
    Quantity::EDielectric,
    Quantity::EDielectricInside,
    Quantity::EAvgDielectric,
    Quantity::EAvgDielectricInside,
];

/// A scene file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    #[serde(default)]
    pub output: Option<Output>,
    #[serde(default, rename = "material")]
    pub materials: Vec<Material>,
    /// The folder of the scene file ([`Scene::read`]): `output.dir` is relative to it.
    #[serde(skip)]
    pub base_dir: Option<std::path::PathBuf>,
}

/// Where and how to write the tables.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Output {
    pub dir: Option<String>,
    pub formats: Option<Vec<Format>>,
    pub precision: Option<Precision>,
    /// The max error to bake to (default [`crate::BakeOptions::DEFAULT_MAX_ERROR`]).
    pub max_error: Option<f64>,
    /// An engine whose own files to write instead of kiln's ([`crate::preset::Preset`]): the
    /// scene's tables are then the engine's, in its layout, and channels no material asks for
    /// are not computed.
    pub preset: Option<crate::preset::Preset>,
}

/// One material.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub name: String,
    pub ndf: Ndf,
    #[serde(default = "default_masking")]
    pub masking: Masking,
    pub roughness: Roughness,
    #[serde(default)]
    pub fresnel: FresnelSpec,
    /// Whether light refracts through the material (glass): its model then needs the
    /// dielectric tables. Needs a dielectric Fresnel.
    #[serde(default)]
    pub transmission: bool,
    /// Whether a glass material's IOR varies over the surface or in time (textured, animated):
    /// its dielectric tables are then those over the IOR, which a renderer reads at each
    /// shading point's IOR; otherwise the tables at its one IOR. Needs `transmission`.
    #[serde(default)]
    pub ior_varies: bool,
    /// A clear coat over the material (`coat = { ior = 1.5 }`, glTF's clearcoat: `F0 = 0.04`):
    /// the coat's reflection-only albedo `E_reflection` and its average at the coat's IOR,
    /// [`ONE_IOR_SIZE`] a side, by which a renderer attenuates the base beneath it.
    #[serde(default)]
    pub coat: Option<Coat>,
    /// Whether the renderer compensates the energy single scattering loses (Kulla-Conty: `E`,
    /// `E_avg`, `f_ms_norm`). On unless turned off.
    #[serde(default = "on")]
    pub multiple_scattering: bool,
    /// Whether the material is lit by environment maps through the split sum (scale and bias).
    #[serde(default, alias = "ibl")]
    pub image_based_lighting: bool,
    /// Whether the material has a cloth sheen (the Charlie/Ashikhmin albedo; an engine preset
    /// whose texture holds it: filament, godot).
    #[serde(default)]
    pub sheen: bool,
}

fn on() -> bool {
    true
}

impl Material {
    /// The NDF and masking the material is evaluated with.
    #[must_use]
    pub fn model(&self) -> Model {
        Model {
            ndf: self.ndf,
            masking: self.masking,
        }
    }

    /// The IOR of a glass material whose IOR does not vary: its dielectric tables are at that
    /// IOR alone. `None` for a material that does not refract or whose IOR varies.
    #[must_use]
    pub fn one_ior(&self) -> Option<f64> {
        match self.fresnel {
            FresnelSpec::Dielectric { ior } if self.transmission && !self.ior_varies => Some(ior),
            _ => None,
        }
    }

    /// The one IOR at which `effect`'s tables are baked for this material: its glass's
    /// ([`Material::one_ior`]) for transmission, its coat's for a coat; `None` otherwise.
    #[must_use]
    pub fn one_ior_for(&self, effect: Effect) -> Option<f64> {
        match effect {
            Effect::Transmission => self.one_ior(),
            Effect::Coat => self.coat.map(|coat| coat.ior),
            _ => None,
        }
    }

    /// The effects the material asks for, in a fixed order.
    #[must_use]
    pub fn effects(&self) -> Vec<Effect> {
        [
            Effect::MultipleScattering,
            Effect::ImageBasedLighting,
            Effect::Sheen,
            Effect::Transmission,
            Effect::Coat,
        ]
        .into_iter()
        .filter(|&effect| self.asks(effect))
        .collect()
    }

    /// Whether the material asks for `effect`.
    #[must_use]
    pub fn asks(&self, effect: Effect) -> bool {
        match effect {
            Effect::MultipleScattering => self.multiple_scattering,
            Effect::ImageBasedLighting => self.image_based_lighting,
            Effect::Sheen => self.sheen,
            Effect::Transmission => self.transmission,
            Effect::Coat => self.coat.is_some(),
        }
    }
}

/// A clear coat: a smooth-to-rough dielectric layer of its own IOR over the material.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Coat {
    /// The coat's index of refraction relative to the medium above (1.5: glTF's clearcoat,
    /// `F0 = 0.04`; OpenPBR's default 1.6).
    pub ior: f64,
}

fn default_masking() -> Masking {
    Masking::HeightCorrelated
}

/// Perceptual roughness used: one value or a `[min, max]` range.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Roughness {
    One(f64),
    Range([f64; 2]),
}

/// A number or a pair, and otherwise kiln's own message (serde's for an untagged enum says only
/// that no variant matched).
impl<'de> Deserialize<'de> for Roughness {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Either {
            One(f64),
            Range([f64; 2]),
        }
        match Either::deserialize(deserializer) {
            Ok(Either::One(r)) => Ok(Roughness::One(r)),
            Ok(Either::Range(range)) => Ok(Roughness::Range(range)),
            Err(_) => Err(serde::de::Error::custom(ROUGHNESS_FORM)),
        }
    }
}

/// What a scene's `roughness` is, as a refusal says.
const ROUGHNESS_FORM: &str =
    "roughness is one perceptual roughness in [0, 1] or a [min, max] range";

impl Roughness {
    /// `[min, max]`.
    #[must_use]
    pub fn range(self) -> [f64; 2] {
        match self {
            Roughness::One(r) => [r, r],
            Roughness::Range(range) => range,
        }
    }
}

/// One value for every channel or three.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Channels {
    One(f64),
    Rgb(Rgb),
}

impl Channels {
    fn rgb(self) -> Rgb {
        match self {
            Channels::One(v) => [v; 3],
            Channels::Rgb(v) => v,
        }
    }
}

/// A material's Fresnel model as the scene writes it.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum FresnelSpec {
    /// `F = 1`.
    #[default]
    None,
    Schlick {
        f0: Channels,
        f90: Option<Channels>,
    },
    Dielectric {
        ior: f64,
    },
    Conductor {
        eta: Channels,
        k: Channels,
    },
}

impl FresnelSpec {
    /// The library's model.
    #[must_use]
    pub fn model(self) -> Fresnel {
        match self {
            FresnelSpec::None => Fresnel::None,
            FresnelSpec::Schlick { f0, f90 } => Fresnel::Schlick {
                f0: f0.rgb(),
                f90: f90.map_or([1.0; 3], Channels::rgb),
            },
            FresnelSpec::Dielectric { ior } => Fresnel::Dielectric { eta: ior },
            FresnelSpec::Conductor { eta, k } => Fresnel::Conductor {
                eta: eta.rgb(),
                k: k.rgb(),
            },
        }
    }
}

/// A TOML error in the words of the scene format: the file and line, what is wrong, and for a
/// Fresnel model given without its parameters, the forms it takes.
fn toml_message(error: &toml::de::Error, text: &str, origin: &str) -> String {
    let line = error
        .span()
        .map(|span| text[..span.start.min(text.len())].matches('\n').count() + 1);
    let source_line = line
        .and_then(|n| text.lines().nth(n - 1))
        .map(str::trim)
        .unwrap_or("");
    let mut message = error.message().trim().to_string();
    if source_line.starts_with("fresnel") {
        message = format!(
            "{}: a Fresnel model is \"none\", {{ schlick = {{ f0 = 0.04 }} }} (f0 \
             and an optional f90, one value or [r, g, b]), {{ dielectric = {{ ior = 1.5 }} }} or \
             {{ conductor = {{ eta = [r, g, b], k = [r, g, b] }} }}",
            crate::error::quoted(source_line)
        );
    } else if !source_line.is_empty() {
        message = format!("{}: {message}", crate::error::quoted(source_line));
    }
    match line {
        Some(line) => format!("{origin}, line {line}: {message}"),
        None => format!("{origin}: {message}"),
    }
}

impl Scene {
    /// Parses and checks a scene. A syntax error or an unknown key names the line and column
    /// and what was expected; an impossible value names the material and the value.
    pub fn parse(text: &str, origin: &str) -> Result<Scene> {
        let scene: Scene = toml::from_str(text)
            .map_err(|e| Error::InvalidInput(toml_message(&e, text, origin)))?;
        scene.validate(origin)?;
        Ok(scene)
    }

    /// Reads and parses a scene file.
    pub fn read(path: &Path) -> Result<Scene> {
        let bytes = crate::format::read_file(path)?;
        let text = String::from_utf8(bytes).map_err(|e| {
            Error::InvalidInput(format!(
                "{}: not a text file (invalid UTF-8 at byte {}); a scene is TOML",
                path.display(),
                e.utf8_error().valid_up_to()
            ))
        })?;
        let mut scene = Scene::parse(&text, &path.display().to_string())?;
        scene.base_dir = Some(
            path.parent()
                .map_or_else(std::path::PathBuf::new, Path::to_path_buf),
        );
        Ok(scene)
    }

    fn validate(&self, origin: &str) -> Result<()> {
        let bad = |message: String| Error::InvalidInput(format!("{origin}: {message}"));
        let mut names: Vec<&str> = Vec::new();
        for m in &self.materials {
            if m.name.trim().is_empty() {
                return Err(bad("a material has an empty name".into()));
            }
            if m.name
                .chars()
                .any(|c| c.is_control() || crate::error::is_bidi_control(c))
            {
                return Err(bad(format!(
                    "material {}: a name may not hold control characters (NUL, newlines, \
                     escapes) or bidirectional overrides, which would hide what it says",
                    crate::error::quoted(&m.name)
                )));
            }
            if names.contains(&m.name.as_str()) {
                return Err(bad(format!(
                    "material '{}' is named twice; names must be unique",
                    m.name
                )));
            }
            names.push(&m.name);
            let [lo, hi] = m.roughness.range();
            for r in [lo, hi] {
                if !(0.0..=1.0).contains(&r) {
                    return Err(bad(format!(
                        "material '{}': roughness {r} is outside [0, 1] (perceptual roughness, \
                         alpha = r^2)",
                        m.name
                    )));
                }
            }
            if lo > hi {
                return Err(bad(format!(
                    "material '{}': roughness range [{lo}, {hi}] is reversed; write [min, max]",
                    m.name
                )));
            }
            m.fresnel
                .model()
                .validate()
                .map_err(|e| bad(format!("material '{}': {e}", m.name)))?;
            m.model()
                .validate()
                .map_err(|e| bad(format!("material '{}': {e}", m.name)))?;
            if m.transmission && !matches!(m.fresnel, FresnelSpec::Dielectric { .. }) {
                return Err(bad(format!(
                    "material '{}': transmission = true needs a dielectric fresnel, e.g. \
                     fresnel = {{ dielectric = {{ ior = 1.5 }} }} (light refracts only through \
                     a dielectric interface)",
                    m.name
                )));
            }
            if let Some(coat) = m.coat {
                crate::table::check::check_fixed_ior(coat.ior)
                    .map_err(|e| bad(format!("material '{}': coat: {e}", m.name)))?;
            }
            if m.ior_varies && !m.transmission {
                return Err(bad(format!(
                    "material '{}': ior_varies = true chooses the glass tables over the IOR, \
                     and needs transmission = true (a material that does not refract has no \
                     glass tables)",
                    m.name
                )));
            }
        }
        if let Some(preset) = self.preset() {
            self.validate_for(preset).map_err(|e| bad(e.to_string()))?;
        } else if let Some(m) = self.materials.iter().find(|m| m.sheen) {
            return Err(bad(format!(
                "material '{}': sheen = true needs an engine whose texture holds the cloth \
                 albedo: name it in [output] (preset = \"filament\" or \"godot\"); kiln's own \
                 layout has no sheen table",
                m.name
            )));
        }
        if self
            .output
            .as_ref()
            .and_then(|o| o.formats.as_ref())
            .is_some_and(Vec::is_empty)
        {
            // An empty list baked every table and wrote none of them (exit 0).
            return Err(bad(format!(
                "output.formats is empty, so nothing would be written: list at least one of {}, \
                 or remove the line for every format",
                Format::ALL
                    .iter()
                    .map(|f| format!("\"{}\"", f.name()))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        if let Some(x) = self.output.as_ref().and_then(|o| o.max_error)
            && !(crate::BakeOptions::MIN_MAX_ERROR..=0.5).contains(&x)
        {
            return Err(bad(format!(
                "output.max_error must be between {:e} and 0.5 (got {})",
                crate::BakeOptions::MIN_MAX_ERROR,
                crate::error::shown(x)
            )));
        }
        // What the plan lists, the bake bakes: each of its bakes passes every check `kiln bake`
        // applies, here, so that `kiln plan` refuses what `kiln bake --scene` would.
        for (options, effect, _) in self.needs() {
            options.validate().map_err(|e| {
                bad(format!(
                    "the tables for {} cannot be baked: {e}",
                    effect.map_or("the engine", Effect::name)
                ))
            })?;
        }
        Ok(())
    }

    /// The engine the scene writes for, if `[output]` names one.
    #[must_use]
    pub fn preset(&self) -> Option<Preset> {
        self.output.as_ref().and_then(|o| o.preset)
    }

    /// What a scene that names `preset` may ask: the engine's own format (no `formats` or
    /// `precision`), materials of the model the engine evaluates, and only effects its layout
    /// serves.
    fn validate_for(&self, preset: Preset) -> crate::Result<()> {
        let layout = preset.layout();
        if let Some(output) = &self.output
            && (output.formats.is_some() || output.precision.is_some())
        {
            return Err(crate::Error::InvalidInput(format!(
                "[output] names preset {}, which writes the engine's own files ({}): formats \
                 and precision do not apply; remove them",
                layout.name, layout.file_name
            )));
        }
        let engine_model = Model {
            ndf: Ndf::Ggx,
            masking: layout.masking,
        };
        let sheen_in_layout = layout.extra.and_then(|e| e.effect()) == Some(Effect::Sheen);
        for m in &self.materials {
            if m.model() != engine_model {
                return Err(crate::Error::InvalidInput(format!(
                    "material '{}' is {} {}, but {} evaluates {} {}: the engine's tables would \
                     not be this material's; change its ndf and masking or the preset",
                    m.name,
                    m.ndf.name(),
                    m.masking.name(),
                    layout.name,
                    engine_model.ndf.name(),
                    engine_model.masking.name()
                )));
            }
            if m.transmission && layout.glass.is_none() {
                return Err(crate::Error::InvalidInput(format!(
                    "material '{}': transmission = true, but {}'s layout has no glass tables \
                     (cycles has them); bake the dielectric tables in kiln's own layout (a \
                     scene without a preset)",
                    m.name, layout.name
                )));
            }
            if m.coat.is_some() {
                return Err(crate::Error::InvalidInput(format!(
                    "material '{}': a coat, but {}'s layout has no coat tables; bake them in \
                     kiln's own layout (a scene without a preset)",
                    m.name, layout.name
                )));
            }
            if m.sheen && !sheen_in_layout {
                return Err(crate::Error::InvalidInput(format!(
                    "material '{}': sheen = true, but {}'s layout has no cloth channel (filament \
                     and godot have one)",
                    m.name, layout.name
                )));
            }
        }
        Ok(())
    }

    /// The materials that ask for any of `effects`, by name.
    fn asking(&self, model: Option<Model>, effects: &[Effect]) -> Vec<String> {
        self.materials
            .iter()
            .filter(|m| model.is_none_or(|model| m.model() == model))
            .filter(|m| effects.iter().any(|&e| m.asks(e)))
            .map(|m| m.name.clone())
            .collect()
    }

    /// The NDF and masking combinations in use, in order of first appearance.
    #[must_use]
    pub fn models(&self) -> Vec<Model> {
        self.models_asking(None)
    }

    /// The combinations whose materials ask for `effect` (any effect for `None`), in order of
    /// first appearance.
    fn models_asking(&self, effect: Option<Effect>) -> Vec<Model> {
        let mut models: Vec<Model> = Vec::new();
        for m in &self.materials {
            if effect.is_some_and(|e| !m.asks(e)) || models.contains(&m.model()) {
                continue;
            }
            models.push(m.model());
        }
        models
    }

    /// The combinations a transmissive material uses, in order of first appearance.
    #[must_use]
    pub fn transmissive_models(&self) -> Vec<Model> {
        self.models_asking(Some(Effect::Transmission))
    }

    /// Each bake the scene needs with the effect it serves and its model (`None` for an
    /// engine's tables, which serve the layout's effects): in kiln's layout, per NDF and
    /// masking combination, `E`, `E_avg` and `f_ms_norm` for multiple scattering, the
    /// split-sum scale and bias for image-based lighting, the dielectric tables for
    /// transmission (each a bake of its own, so that one's options never change another's
    /// cache keys); with a preset, the engine's tables.
    fn needs(&self) -> Vec<(crate::BakeOptions, Option<Effect>, Model)> {
        let asked_max_error = self.output.as_ref().and_then(|o| o.max_error);
        let max_error = asked_max_error.unwrap_or(crate::BakeOptions::DEFAULT_MAX_ERROR);
        if let Some(preset) = self.preset() {
            if self.materials.is_empty() {
                return Vec::new();
            }
            let options = crate::BakeOptions {
                max_error: Some(max_error),
                ..preset.options()
            };
            let model = Model {
                ndf: Ndf::Ggx,
                masking: preset.layout().masking,
            };
            let mut needs = vec![(options, None, model)];
            // The engine's glass tables when a material refracts.
            if self.materials.iter().any(|m| m.transmission)
                && let Some(glass) = preset.glass_options(asked_max_error)
            {
                needs.push((glass, Some(Effect::Transmission), model));
            }
            return needs;
        }
        let ior_max = self.ior_max();
        let mut needs = Vec::new();
        for model in self.models() {
            let base = crate::BakeOptions {
                ndfs: vec![model.ndf],
                maskings: vec![model.masking],
                max_error: Some(max_error),
                ..crate::BakeOptions::default()
            };
            let asked = |effect| self.models_asking(Some(effect)).contains(&model);
            if asked(Effect::MultipleScattering) {
                needs.push((base.clone(), Some(Effect::MultipleScattering), model));
            }
            if asked(Effect::ImageBasedLighting) {
                // On kiln's split-sum mu axis, as `kiln bake --quantity e-scale,e-bias` (an
                // engine's scene gets the engine's layout).
                let split_sum = crate::BakeOptions {
                    quantities: vec![Quantity::EScale, Quantity::EBias],
                    ..base.clone()
                };
                needs.push((split_sum, Some(Effect::ImageBasedLighting), model));
            }
            // The glass tables at each distinct IOR and a coat's reflection at each distinct
            // coat IOR, in order of first appearance; then the glass tables over the IOR for
            // the materials whose IOR varies.
            for (effect, quantities) in [
                (Effect::Transmission, &DIELECTRIC_QUANTITIES[..]),
                (Effect::Coat, &COAT_QUANTITIES[..]),
            ] {
                let mut iors: Vec<f64> = Vec::new();
                for m in self.materials.iter().filter(|m| m.model() == model) {
                    if let Some(ior) = m.one_ior_for(effect)
                        && !iors.contains(&ior)
                    {
                        iors.push(ior);
                    }
                }
                for ior in iors {
                    let at_ior = crate::BakeOptions {
                        quantities: quantities.to_vec(),
                        size: ONE_IOR_SIZE,
                        fresnel: Some(Fresnel::Dielectric { eta: ior }),
                        ..base.clone()
                    };
                    needs.push((at_ior, Some(effect), model));
                }
            }
            if self
                .materials
                .iter()
                .any(|m| m.transmission && m.ior_varies && m.model() == model)
            {
                let glass = crate::BakeOptions {
                    quantities: DIELECTRIC_QUANTITIES.to_vec(),
                    size: DIELECTRIC_SIZE,
                    ior_size: DIELECTRIC_SIZE,
                    ior_max,
                    ..base.clone()
                };
                needs.push((glass, Some(Effect::Transmission), model));
            }
        }
        needs
    }

    /// Whether the engine's extra channel is computed: always for one no effect gates (HDRP's
    /// diffuse albedo), otherwise when a material asks for its effect (Filament's and Godot's
    /// cloth albedo for sheen).
    fn computes_extra(&self, preset: Preset) -> bool {
        match preset.layout().extra {
            Some(extra) => extra
                .effect()
                .is_none_or(|effect| self.materials.iter().any(|m| m.asks(effect))),
            None => false,
        }
    }

    /// The top of the dielectric tables' IOR axis: 3, or the highest `max(ior, 1 / ior)` of a
    /// transmissive material whose IOR varies if that is higher (the others have tables at
    /// their own IOR).
    #[must_use]
    pub fn ior_max(&self) -> f64 {
        self.materials
            .iter()
            .filter(|m| m.transmission && m.ior_varies)
            .filter_map(|m| match m.fresnel {
                FresnelSpec::Dielectric { ior } => Some(ior.max(1.0 / ior)),
                _ => None,
            })
            .fold(crate::BakeOptions::DEFAULT_IOR_MAX, f64::max)
    }

    /// The minimal set of tables the scene needs and the scalars of each material: each table
    /// once, with the materials and the effects that need it; with a preset, the engine's files
    /// and what each of their channels holds, for which materials, and whether it is computed.
    #[must_use]
    pub fn plan(&self) -> Plan {
        let mut tables = Vec::new();
        for (options, effect, model) in self.needs() {
            // An engine's main tables serve its effects but transmission, which its glass
            // tables (a need of their own) serve.
            let engine_effects: Vec<Effect> = self
                .preset()
                .map(|p| p.layout().effects.to_vec())
                .unwrap_or_default()
                .into_iter()
                .filter(|&e| e != Effect::Transmission)
                .collect();
            let effects: Vec<Effect> = match effect {
                Some(effect) => vec![effect],
                None => engine_effects
                    .iter()
                    .copied()
                    .filter(|&e| self.materials.iter().any(|m| m.asks(e)))
                    .collect(),
            };
            let materials = match effect {
                // A bake at one IOR serves the materials of that IOR (a glass's or a coat's); the
                // glass tables over the IOR those whose IOR varies.
                Some(effect @ (Effect::Transmission | Effect::Coat)) if self.preset().is_none() => {
                    self.materials
                        .iter()
                        .filter(|m| m.asks(effect) && m.model() == model)
                        .filter(|m| match options.fresnel {
                            Some(Fresnel::Dielectric { eta }) => m.one_ior_for(effect) == Some(eta),
                            _ => m.ior_varies,
                        })
                        .map(|m| m.name.clone())
                        .collect()
                }
                Some(effect) => self.asking(Some(model), &[effect]),
                None => self.asking(Some(model), &engine_effects),
            };
            for spec in options.resolved().specs() {
                tables.push(PlannedTable {
                    ndf: model.ndf,
                    masking: model.masking,
                    quantity: spec.quantity,
                    materials: materials.clone(),
                    effects: effects.clone(),
                    id: spec.id(),
                    estimated_core_seconds: crate::bake::estimated_core_seconds(&spec),
                });
            }
        }
        let engine = self
            .preset()
            .filter(|_| !self.materials.is_empty())
            .map(|preset| self.planned_engine(preset, &tables));
        let materials = self
            .materials
            .iter()
            .map(|m| {
                let fresnel = m.fresnel.model();
                PlannedMaterial {
                    name: m.name.clone(),
                    ndf: m.ndf,
                    masking: m.masking,
                    roughness: m.roughness.range(),
                    fresnel: fresnel.name().to_string(),
                    transmission: m.transmission,
                    effects: m.effects(),
                    f_avg: fresnel.average(),
                }
            })
            .collect();
        Plan {
            tables,
            materials,
            engine,
        }
    }

    /// The engine's files and channels for [`Scene::plan`].
    fn planned_engine(&self, preset: Preset, tables: &[PlannedTable]) -> PlannedEngine {
        use crate::preset::layout::{Channel, Container};
        let layout = preset.layout();
        let of_table = |name: String, q: Quantity| {
            let planned = tables.iter().find(|t| t.quantity == q);
            PlannedChannel {
                name,
                holds: q.symbol().to_string(),
                effects: planned.map(|t| t.effects.clone()).unwrap_or_default(),
                materials: planned.map(|t| t.materials.clone()).unwrap_or_default(),
                // Cycles' glass arrays when no material refracts: not baked, not written.
                computed: planned.is_some(),
            }
        };
        let mut channels: Vec<PlannedChannel> = match layout.container {
            Container::CycleTables(parts)
            | Container::ExrPerTable(parts)
            | Container::Png8(parts) => parts
                .iter()
                .map(|&(name, q)| of_table(name.to_string(), q))
                .collect(),
            _ => layout
                .channels
                .iter()
                .zip(["R", "G", "B", "A"])
                .map(|(channel, name)| match *channel {
                    Channel::Table(q) => of_table(name.to_string(), q),
                    Channel::Extra => {
                        let extra = layout.extra.expect("a layout with an extra channel");
                        let effects: Vec<Effect> = extra.effect().into_iter().collect();
                        PlannedChannel {
                            name: name.to_string(),
                            holds: extra.description().to_string(),
                            materials: match extra.effect() {
                                Some(e) => self.asking(None, &[e]),
                                None => self.asking(None, layout.effects),
                            },
                            effects,
                            computed: self.computes_extra(preset),
                        }
                    }
                    Channel::Constant(c) => PlannedChannel {
                        name: name.to_string(),
                        holds: format!("{c}"),
                        effects: Vec::new(),
                        materials: Vec::new(),
                        computed: false,
                    },
                })
                .collect(),
        };
        if let Some(form) = layout.normalisation {
            channels.push(of_table(form.file().to_string(), Quantity::FMsNorm));
        }
        PlannedEngine {
            preset: layout.name.to_string(),
            file: layout.file_name.to_string(),
            channels,
        }
    }
}

/// What [`Scene::bake`] did.
#[derive(Clone, Debug)]
pub struct SceneBake {
    /// The tables, baked or reused, with which were which.
    pub report: crate::bake::BakeReport,
    /// The files written.
    pub written: Vec<std::path::PathBuf>,
}

impl Scene {
    /// The directory the scene asks for: `output.dir` (default `tables`), relative to the
    /// scene file's folder when the scene was [read](Scene::read) from a file (an absolute
    /// path stays as it is), so a scene bakes to the same place from any working directory.
    #[must_use]
    pub fn output_dir(&self) -> std::path::PathBuf {
        let dir: std::path::PathBuf = self
            .output
            .as_ref()
            .and_then(|o| o.dir.clone())
            .unwrap_or_else(|| "tables".into())
            .into();
        match &self.base_dir {
            Some(base) if dir.is_relative() => base.join(dir),
            _ => dir,
        }
    }

    /// The bakes the plan needs, in plan order ([`Scene::plan`]).
    #[must_use]
    pub fn bake_options(&self) -> Vec<crate::BakeOptions> {
        self.needs()
            .into_iter()
            .map(|(options, ..)| options)
            .collect()
    }

    /// Bakes the plan into `dir` in the scene's formats and precision (default: every format,
    /// f32), through the content-addressed cache in `dir/.kiln-cache` ([`crate::cache`]): a
    /// table whose key is unchanged is reused without integration. For a build script: no
    /// command-line dependencies. Files of the same names made to other specs are refused or
    /// replaced as `replace` says ([`crate::format::replace`]); a build script that owns its
    /// output folder passes [`Replace::Force`](crate::format::replace::Replace::Force).
    pub fn bake(
        &self,
        dir: &Path,
        progress: &(dyn Fn(u64) + Sync),
        replace: crate::format::replace::Replace,
    ) -> Result<SceneBake> {
        crate::format::check_output_dir(dir)?;
        if let Some(preset) = self.preset() {
            return self.bake_for(preset, dir, progress);
        }
        let output = self.output.clone().unwrap_or_default();
        let formats = output.formats.unwrap_or_else(|| Format::ALL.to_vec());
        let precision = output.precision.unwrap_or(Precision::F32);
        // Refuse at once, not after the integration.
        let specs: Vec<crate::TableSpec> = self
            .bake_options()
            .iter()
            .flat_map(|options| options.resolved().specs())
            .collect();
        crate::format::replace::precheck(dir, &specs, &formats, replace)?;
        let report = self.bake_cached(dir, progress)?;
        let mut files = crate::format::encode_all(&report.tables, &formats, precision)?;
        if !self.materials.is_empty() {
            files.push((
                MATERIALS_FILE.to_string(),
                self.materials_document(&report.tables),
            ));
        }
        let written = crate::format::write_table_files(dir, &report.tables, &files, replace)?;
        Ok(SceneBake { report, written })
    }

    /// Every bake of the plan through the cache in `dir/.kiln-cache`, in plan order.
    fn bake_cached(
        &self,
        dir: &Path,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<crate::bake::BakeReport> {
        let cache = crate::cache::Cache::new(&dir.join(".kiln-cache"));
        let mut report = crate::bake::BakeReport::default();
        for options in self.bake_options() {
            let part = options.bake_cached(Some(&cache), progress)?;
            report.tables.extend(part.tables);
            report.baked.extend(part.baked);
            report.reused.extend(part.reused);
            report.repaired.extend(part.repaired);
        }
        Ok(report)
    }

    /// [`Scene::bake`] for a scene that names an engine: its tables through the cache, its own
    /// files (the extra channel computed only if a material asks for it), kiln's sidecars and
    /// the materials file.
    fn bake_for(
        &self,
        preset: Preset,
        dir: &Path,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<SceneBake> {
        let report = self.bake_cached(dir, progress)?;
        if report.tables.is_empty() {
            return Ok(SceneBake {
                report,
                written: Vec::new(),
            });
        }
        let extra = self
            .computes_extra(preset)
            .then(|| preset.extra_channel())
            .flatten();
        let mut files = preset.files_with_sidecars(&report.tables, extra.as_ref(), None)?;
        files.push((
            MATERIALS_FILE.to_string(),
            self.materials_document(&report.tables),
        ));
        let written = crate::format::write_files(dir, &files)?;
        Ok(SceneBake { report, written })
    }

    /// The per-material values a renderer needs beside the tables (written as
    /// [`MATERIALS_FILE`]): for each material its model, roughness, Fresnel model and `F_avg`
    /// per channel, the `E_avg` table it reads, and for a material of one roughness `E_avg`
    /// there (the table's own lookup) and the Kulla-Conty colour multiplier
    /// `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))` per channel
    /// ([`crate::model::kulla_conty::fresnel_colour`]); a roughness range takes it per pixel.
    fn materials_document(&self, tables: &[crate::Table]) -> Vec<u8> {
        let plan = self.plan();
        let materials: Vec<serde_json::Value> = plan
            .materials
            .iter()
            .zip(&self.materials)
            .map(|(m, material)| {
                let average = tables.iter().find(|t| {
                    t.spec.quantity == Quantity::EAvg
                        && t.spec.model.ndf == m.ndf
                        && t.spec.model.masking == m.masking
                });
                let mut object = serde_json::json!({
                    "name": m.name,
                    "ndf": m.ndf.name(),
                    "masking": m.masking.name(),
                    "roughness": m.roughness,
                    "fresnel": m.fresnel,
                    "transmission": m.transmission,
                    "f_avg": m.f_avg,
                    "e_avg_table": average.map(|t| t.spec.id()),
                });
                // The tables of `quantities` this material reads at `ior` (over the IOR: None),
                // by quantity.
                let read = |quantities: &[Quantity], ior: Option<f64>| {
                    tables
                        .iter()
                        .filter(|t| {
                            quantities.contains(&t.spec.quantity)
                                && t.spec.model == material.model()
                                && t.spec.fixed_ior() == ior
                        })
                        .map(|t| (t.spec.quantity.symbol().to_string(), t.spec.id().into()))
                        .collect::<serde_json::Map<String, serde_json::Value>>()
                };
                if material.transmission && self.preset().is_none() {
                    // At its IOR, or over the IOR.
                    object["glass_tables"] =
                        read(&DIELECTRIC_QUANTITIES, material.one_ior()).into();
                    object["ior_varies"] = material.ior_varies.into();
                }
                if let Some(coat) = material.coat {
                    object["coat_ior"] = coat.ior.into();
                    object["coat_tables"] = read(&COAT_QUANTITIES, Some(coat.ior)).into();
                }
                if let (Some(table), [lo, hi]) = (average, m.roughness)
                    && lo == hi
                {
                    let e_avg = table.lookup(0.0, lo);
                    object["e_avg"] = e_avg.into();
                    object["colour_multiplier"] = m
                        .f_avg
                        .map(|f| crate::model::kulla_conty::fresnel_colour(f, e_avg))
                        .to_vec()
                        .into();
                }
                object
            })
            .collect();
        let document = serde_json::json!({
            "kind": "kiln-materials",
            "kiln_version": crate::format::metadata::KILN_VERSION,
            "colour_multiplier": "per channel, F_avg^2 E_avg / (1 - F_avg (1 - E_avg)): the \
                                  factor of the Kulla-Conty lobe f_ms (E_avg looked up in \
                                  e_avg_table at the material's roughness)",
            "coat_tables": "per coated material, its coat's reflection-only albedo and average at \
                            the coat's IOR (coat_ior), by quantity: the base beneath receives \
                            1 - E_reflection(mu) of the light",
            "glass_tables": "per glass material, the dielectric tables it reads, by quantity: \
                             at its one IOR (2-D, over roughness and mu), or over the IOR for a \
                             material whose IOR varies (ior_varies)",
            "materials": materials,
        });
        let mut bytes = serde_json::to_vec_pretty(&document).unwrap_or_default();
        bytes.push(b'\n');
        bytes
    }
}

/// What a scene needs.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Plan {
    pub tables: Vec<PlannedTable>,
    pub materials: Vec<PlannedMaterial>,
    /// The engine's files and channels, for a scene that names a preset.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub engine: Option<PlannedEngine>,
}

/// The engine a scene writes for: its file and what each channel (or array, or file) holds.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PlannedEngine {
    pub preset: String,
    /// The engine's (first) file.
    pub file: String,
    pub channels: Vec<PlannedChannel>,
}

/// One channel of an engine's texture (R, G, B, A), or one array or file of it.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PlannedChannel {
    pub name: String,
    /// The quantity or value it holds.
    pub holds: String,
    /// The effects that need it.
    pub effects: Vec<Effect>,
    /// The materials that need it.
    pub materials: Vec<String>,
    /// Whether kiln computes it (a channel no material asks for is written as 0; a constant is
    /// written as itself).
    pub computed: bool,
}

/// One table of the plan and the materials that need it.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PlannedTable {
    pub ndf: Ndf,
    pub masking: Masking,
    pub quantity: Quantity,
    pub materials: Vec<String>,
    /// The effects the materials need it for.
    pub effects: Vec<Effect>,
    /// The file-name stem the bake writes it under ([`crate::TableSpec::id`]).
    pub id: String,
    /// The estimated cost of baking it, in seconds of one core
    /// ([`crate::bake::estimated_core_seconds`]; 0 when the cache holds it).
    pub estimated_core_seconds: f64,
}

impl PlannedTable {
    #[must_use]
    pub fn model(&self) -> Model {
        Model {
            ndf: self.ndf,
            masking: self.masking,
        }
    }
}

/// A material's needs beyond the tables.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PlannedMaterial {
    pub name: String,
    pub ndf: Ndf,
    pub masking: Masking,
    /// `[min, max]` perceptual roughness.
    pub roughness: [f64; 2],
    pub fresnel: String,
    /// Whether light refracts through it (it then uses the dielectric tables).
    pub transmission: bool,
    /// The effects it asks for.
    pub effects: Vec<Effect>,
    /// `F_avg` per channel, for the Kulla-Conty colour term
    /// ([`crate::model::kulla_conty::fresnel_colour`]).
    pub f_avg: Rgb,
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXAMPLE: &str = r#"
[output]
dir = "tables"
formats = ["exr", "rs", "json"]
precision = "f16"

[[material]]
name = "brushed_steel"
ndf = "ggx"
masking = "height-correlated"
roughness = [0.2, 0.6]
fresnel = { conductor = { eta = [2.9, 2.9, 2.4], k = [3.0, 2.9, 2.5] } }

[[material]]
name = "varnish"
ndf = "beckmann"
roughness = 0.3
fresnel = { dielectric = { ior = 1.5 } }

[[material]]
name = "plastic"
ndf = "ggx"
roughness = 0.5
fresnel = { schlick = { f0 = 0.04 } }
"#;

    #[test]
    fn the_issue_example_parses_and_plans() {
        let scene = Scene::parse(EXAMPLE, "example.toml").unwrap();
        assert_eq!(scene.materials.len(), 3);
        let output = scene.output.as_ref().unwrap();
        assert_eq!(output.precision, Some(Precision::F16));
        let plan = scene.plan();
        // GGX height-correlated (steel, plastic) and Beckmann height-correlated (varnish): E,
        // E_avg and f_ms_norm each, merged.
        assert_eq!(plan.tables.len(), 6);
        let ggx_e = &plan.tables[0];
        assert_eq!((ggx_e.ndf, ggx_e.quantity), (Ndf::Ggx, Quantity::E));
        assert_eq!(ggx_e.materials, ["brushed_steel", "plastic"]);
        assert_eq!(plan.tables[3].materials, ["varnish"]);
        let varnish = &plan.materials[1];
        assert!((varnish.f_avg[0] - 0.091_777_959_3).abs() < 1e-9);
        assert_eq!(plan.materials[2].f_avg, [(20.0 * 0.04 + 1.0) / 21.0; 3]);
        assert_eq!(plan.materials[0].roughness, [0.2, 0.6]);
    }

    /// A coat gets its reflection tables at its IOR, per model and coat IOR, for the materials of
    /// that coat; a coat's IOR out of range is refused by name.
    #[test]
    fn coats_add_their_reflection_at_their_ior() {
        let scene = Scene::parse(
            "[[material]]\nname = \"car\"\nndf = \"ggx\"\nroughness = 0.3\n\
             coat = { ior = 1.5 }\n\n\
             [[material]]\nname = \"pearl\"\nndf = \"ggx\"\nroughness = 0.2\n\
             coat = { ior = 1.6 }\nmultiple_scattering = false\n\n\
             [[material]]\nname = \"van\"\nndf = \"ggx\"\nroughness = 0.4\n\
             coat = { ior = 1.5 }\nmultiple_scattering = false\n",
            "coats.toml",
        )
        .unwrap();
        let plan = scene.plan();
        let ids: Vec<&str> = plan.tables.iter().map(|t| t.id.as_str()).collect();
        assert_eq!(
            ids[3..],
            [
                "ggx-height-correlated-E_reflection-ior-1.5",
                "ggx-height-correlated-E_avg_reflection-ior-1.5",
                "ggx-height-correlated-E_reflection-ior-1.6",
                "ggx-height-correlated-E_avg_reflection-ior-1.6",
            ]
        );
        assert_eq!(plan.tables[3].materials, ["car", "van"]);
        assert_eq!(plan.tables[5].materials, ["pearl"]);
        assert_eq!(plan.tables[3].effects, [Effect::Coat]);
        let error = Scene::parse(
            "[[material]]\nname = \"bad\"\nndf = \"ggx\"\nroughness = 0.3\n\
             coat = { ior = 1.0 }\n",
            "bad.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(error.contains("bad") && error.contains("coat"), "{error}");
    }

    /// A glass of one IOR gets the four tables at that IOR, 32 x 32; a glass whose IOR varies
    /// those over the IOR, up to its index; each for its own model, each bake of its own.
    #[test]
    fn glass_adds_the_dielectric_tables_for_its_model_only() {
        let scene = Scene::parse(
            "[[material]]\nname = \"steel\"\nndf = \"ggx\"\nroughness = 0.3\n\n\
             [[material]]\nname = \"window\"\nndf = \"ggx\"\nroughness = 0.1\n\
             fresnel = { dielectric = { ior = 1.5 } }\ntransmission = true\n\n\
             [[material]]\nname = \"gem\"\nndf = \"ggx\"\nroughness = 0.0\n\
             fresnel = { dielectric = { ior = 3.4 } }\ntransmission = true\nior_varies = true\n\n\
             [[material]]\nname = \"pane\"\nndf = \"ggx\"\nroughness = 0.2\n\
             fresnel = { dielectric = { ior = 1.5 } }\ntransmission = true\n\n\
             [[material]]\nname = \"tile\"\nndf = \"beckmann\"\nroughness = 0.3\n\
             fresnel = { dielectric = { ior = 1.5 } }\n",
            "glass.toml",
        )
        .unwrap();
        let plan = scene.plan();
        let quantities: Vec<(Ndf, Quantity)> =
            plan.tables.iter().map(|t| (t.ndf, t.quantity)).collect();
        assert_eq!(
            quantities,
            [
                (Ndf::Ggx, Quantity::E),
                (Ndf::Ggx, Quantity::EAvg),
                (Ndf::Ggx, Quantity::FMsNorm),
                (Ndf::Ggx, Quantity::EDielectric),
                (Ndf::Ggx, Quantity::EDielectricInside),
                (Ndf::Ggx, Quantity::EAvgDielectric),
                (Ndf::Ggx, Quantity::EAvgDielectricInside),
                (Ndf::Ggx, Quantity::EDielectric),
                (Ndf::Ggx, Quantity::EDielectricInside),
                (Ndf::Ggx, Quantity::EAvgDielectric),
                (Ndf::Ggx, Quantity::EAvgDielectricInside),
                (Ndf::Beckmann, Quantity::E),
                (Ndf::Beckmann, Quantity::EAvg),
                (Ndf::Beckmann, Quantity::FMsNorm),
            ]
        );
        assert_eq!(plan.tables[0].materials, ["steel", "window", "gem", "pane"]);
        // The window and the pane share the tables at 1.5; the gem reads those over the IOR.
        assert_eq!(
            plan.tables[3].id,
            "ggx-height-correlated-E_dielectric-ior-1.5"
        );
        assert_eq!(plan.tables[3].materials, ["window", "pane"]);
        assert_eq!(plan.tables[7].id, "ggx-height-correlated-E_dielectric");
        assert_eq!(plan.tables[7].materials, ["gem"]);
        assert!(plan.materials[1].transmission && !plan.materials[4].transmission);
        // The IOR axis reaches the gem's 3.4; the E tables' options are those of a scene
        // without glass (their cache keys do not change when glass is added).
        assert_eq!(scene.ior_max(), 3.4);
        let options = scene.bake_options();
        assert_eq!(options.len(), 4);
        assert_eq!(options[0], {
            let no_glass = Scene {
                materials: vec![scene.materials[0].clone()],
                output: None,
                base_dir: None,
            };
            no_glass.bake_options()[0].clone()
        });
        assert_eq!(options[1].quantities, DIELECTRIC_QUANTITIES);
        assert_eq!(options[1].fresnel, Some(Fresnel::Dielectric { eta: 1.5 }));
        assert_eq!(options[1].size, ONE_IOR_SIZE);
        assert_eq!(options[2].quantities, DIELECTRIC_QUANTITIES);
        assert_eq!(options[2].ior_max, 3.4);
        assert_eq!(options[2].size, DIELECTRIC_SIZE);
        assert_eq!(options[2].fresnel, None);
    }

    /// `ior_varies` describes a glass: on a material that does not refract it is refused by
    /// name.
    #[test]
    fn ior_varies_needs_transmission() {
        let error = Scene::parse(
            "[[material]]\nname = \"cup\"\nndf = \"ggx\"\nroughness = 0.1\n\
             fresnel = { dielectric = { ior = 1.5 } }\nior_varies = true\n",
            "cup.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(
            error.contains("cup") && error.contains("ior_varies") && error.contains("transmission"),
            "{error}"
        );
    }

    #[test]
    fn empty_and_duplicate_needs() {
        let empty = Scene::parse("", "empty.toml").unwrap();
        assert!(empty.plan().tables.is_empty() && empty.plan().materials.is_empty());
        let twins = Scene::parse(
            "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.1\n\n\
             [[material]]\nname = \"b\"\nndf = \"ggx\"\nroughness = [0.0, 1.0]\n",
            "twins.toml",
        )
        .unwrap();
        let plan = twins.plan();
        assert_eq!(plan.tables.len(), 3);
        assert_eq!(plan.tables[1].materials, ["a", "b"]);
        assert_eq!(plan.materials[0].f_avg, [1.0; 3]);
    }

    /// Each effect brings its tables and only those: multiple scattering E, E_avg and
    /// f_ms_norm; image-based lighting the split-sum pair; a material that turns multiple
    /// scattering off brings none of its tables.
    #[test]
    fn effects_decide_the_tables() {
        let scene = Scene::parse(
            "[[material]]\nname = \"env\"\nndf = \"ggx\"\nroughness = 0.3\n\
             image_based_lighting = true\nmultiple_scattering = false\n\n\
             [[material]]\nname = \"lobe\"\nndf = \"ggx\"\nroughness = 0.5\n\n\
             [[material]]\nname = \"flat\"\nndf = \"beckmann\"\nroughness = 0.5\n\
             multiple_scattering = false\n",
            "effects.toml",
        )
        .unwrap();
        let plan = scene.plan();
        let rows: Vec<(Quantity, Vec<String>, Vec<Effect>)> = plan
            .tables
            .iter()
            .map(|t| (t.quantity, t.materials.clone(), t.effects.clone()))
            .collect();
        let ms = vec![Effect::MultipleScattering];
        let ibl = vec![Effect::ImageBasedLighting];
        let lobe = vec!["lobe".to_string()];
        let env = vec!["env".to_string()];
        assert_eq!(
            rows,
            [
                (Quantity::E, lobe.clone(), ms.clone()),
                (Quantity::EAvg, lobe.clone(), ms.clone()),
                (Quantity::FMsNorm, lobe, ms),
                (Quantity::EScale, env.clone(), ibl.clone()),
                (Quantity::EBias, env, ibl),
            ]
        );
        assert!(plan.engine.is_none());
        assert_eq!(plan.materials[2].effects, []);
        // The bakes: one per effect, the split sum apart from E (its cache keys untouched).
        let bakes = scene.bake_options();
        assert_eq!(bakes.len(), 2);
        assert_eq!(bakes[1].quantities, [Quantity::EScale, Quantity::EBias]);
    }

    /// A scene that names Filament plans Filament's texture: R and G for image-based lighting
    /// and multiple scattering, B (the cloth albedo) computed only when a material asks for
    /// sheen.
    #[test]
    fn a_scene_that_names_its_engine_plans_its_channels() {
        let text = |sheen: bool| {
            format!(
                "[output]\npreset = \"filament\"\n\n[[material]]\nname = \"paint\"\n\
                 ndf = \"ggx\"\nroughness = 0.3\nibl = true\n\n[[material]]\n\
                 name = \"velvet\"\nndf = \"ggx\"\nroughness = 0.8\nsheen = {sheen}\n"
            )
        };
        let plain = Scene::parse(&text(false), "filament.toml").unwrap().plan();
        let quantities: Vec<Quantity> = plain.tables.iter().map(|t| t.quantity).collect();
        assert_eq!(quantities, [Quantity::EBias, Quantity::E]);
        assert_eq!(
            plain.tables[0].effects,
            [Effect::MultipleScattering, Effect::ImageBasedLighting]
        );
        let engine = plain.engine.expect("a preset scene plans its engine");
        assert_eq!(
            (engine.preset.as_str(), engine.file.as_str()),
            ("filament", "dfg.inc")
        );
        let names: Vec<&str> = engine.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["R", "G", "B"]);
        let blue = &engine.channels[2];
        assert!(!blue.computed && blue.materials.is_empty(), "{blue:?}");
        assert_eq!(blue.effects, [Effect::Sheen]);
        let sheen = Scene::parse(&text(true), "filament.toml").unwrap().plan();
        let blue = &sheen.engine.expect("engine").channels[2];
        assert!(blue.computed && blue.materials == ["velvet"], "{blue:?}");
    }

    /// A Cycles scene bakes Cycles' glass tables only when a material refracts, and the plan
    /// says which materials need them for transmission; the E tables serve the others.
    #[test]
    fn a_cycles_scene_plans_its_glass_tables_only_for_glass() {
        let text = |glass: bool| {
            let mut text = "[output]\npreset = \"cycles\"\n\n[[material]]\nname = \"paint\"\n\
                            ndf = \"ggx\"\nroughness = 0.4\n"
                .to_string();
            if glass {
                text.push_str(
                    "\n[[material]]\nname = \"bottle\"\nndf = \"ggx\"\nroughness = 0.1\n\
                     fresnel = { dielectric = { ior = 1.5 } }\ntransmission = true\n",
                );
            }
            Scene::parse(&text, "cycles.toml").unwrap().plan()
        };
        let plain = text(false);
        assert!(plain.tables.iter().all(|t| !t.quantity.has_ior()));
        let engine = plain.engine.expect("engine");
        let glass = engine
            .channels
            .iter()
            .find(|c| c.name == "table_ggx_glass_inv_E")
            .expect("the array is planned");
        assert!(!glass.computed && glass.materials.is_empty(), "{glass:?}");

        let plan = text(true);
        let glass: Vec<_> = plan
            .tables
            .iter()
            .filter(|t| t.quantity.has_ior())
            .collect();
        assert_eq!(glass.len(), 4);
        for t in &glass {
            assert_eq!(
                (t.materials.clone(), t.effects.clone()),
                (vec!["bottle".to_string()], vec![Effect::Transmission])
            );
            assert!(t.id.contains("transmission-cycles"), "{}", t.id);
        }
        let e = plan
            .tables
            .iter()
            .find(|t| t.quantity == Quantity::E)
            .unwrap();
        assert_eq!(e.effects, [Effect::MultipleScattering]);
        let channel = plan
            .engine
            .expect("engine")
            .channels
            .into_iter()
            .find(|c| c.name == "table_ggx_glass_inv_E")
            .unwrap();
        assert!(
            channel.computed && channel.materials == ["bottle"],
            "{channel:?}"
        );
    }

    /// What a scene cannot ask, each refused with the material, the reason and what to do.
    #[test]
    fn effects_an_engine_cannot_serve_are_refused() {
        let material = "[[material]]\nname = \"m\"\nroughness = 0.3\n";
        let cases = [
            (
                format!("{material}ndf = \"ggx\"\nsheen = true\n"),
                "preset = \"filament\"",
            ),
            (
                format!("[output]\npreset = \"bevy\"\n{material}ndf = \"beckmann\"\n"),
                "bevy evaluates ggx height-correlated",
            ),
            (
                format!("[output]\npreset = \"godot\"\n{material}ndf = \"ggx\"\n"),
                "godot evaluates ggx schlick-ggx",
            ),
            (
                format!("[output]\npreset = \"unreal\"\n{material}ndf = \"ggx\"\nsheen = true\n"),
                "no cloth channel",
            ),
            (
                format!(
                    "[output]\npreset = \"bevy\"\n{material}ndf = \"ggx\"\n\
                     fresnel = {{ dielectric = {{ ior = 1.5 }} }}\ntransmission = true\n"
                ),
                "no glass tables (cycles has them)",
            ),
            (
                format!(
                    "[output]\npreset = \"three\"\nformats = [\"exr\"]\n{material}ndf = \"ggx\"\n"
                ),
                "formats and precision do not apply",
            ),
            (
                format!("[output]\npreset = \"ogre\"\n{material}ndf = \"ggx\"\n"),
                "ogre",
            ),
        ];
        for (text, needle) in cases {
            let error = Scene::parse(&text, "bad.toml").unwrap_err().to_string();
            assert!(error.contains(needle), "{needle}: {error}");
        }
    }

    #[test]
    fn bad_scenes_say_where_and_what() {
        let cases: [(&str, &str); 10] = [
            (
                "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.1\ntransmission = true\n",
                "needs a dielectric fresnel",
            ),
            (
                "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.1\ncolour = 1\n",
                "colour",
            ),
            (
                "[[material]]\nname = \"a\"\nndf = \"phong\"\nroughness = 0.1\n",
                "phong",
            ),
            (
                "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 1.5\n",
                "roughness 1.5",
            ),
            (
                "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.1\nfresnel = { dielectric = { ior = 0 } }\n",
                "ior must be between 0.01 and 100 (got 0)",
            ),
            (
                "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = [0.5, 0.2]\n",
                "reversed",
            ),
            (
                "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.1\n[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.2\n",
                "named twice",
            ),
            ("[output]\ndir = \"x\"\nprecison = \"f16\"\n", "precison"),
            (
                "[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.1\nfresnel = { metal = {} }\n",
                "metal",
            ),
            // Issue 64: an empty list baked every table for 13 s and wrote none (exit 0).
            (
                "[output]\nformats = []\n[[material]]\nname = \"a\"\nndf = \"ggx\"\nroughness = 0.1\n",
                "output.formats is empty, so nothing would be written",
            ),
        ];
        for (text, needle) in cases {
            let error = Scene::parse(text, "bad.toml").unwrap_err().to_string();
            assert!(error.contains(needle), "{needle}: {error}");
            assert!(error.contains("bad.toml"), "{error}");
        }
        // Syntax errors carry the line and column.
        let error = Scene::parse("[[material]\nname = 1\n", "syntax.toml")
            .unwrap_err()
            .to_string();
        assert!(error.contains("line 1"), "{error}");
    }
}

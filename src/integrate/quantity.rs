//! What a table holds: the quantities kiln integrates ([`Quantity`]), with their names,
//! descriptions and the weights they put on the albedo integrand. Below the tables, so that the
//! integration layer's one dispatch ([`super::value`]) can name them.

use serde::{Deserialize, Serialize};

/// What a table holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Quantity {
    /// Directional albedo `E(mu, roughness)` for F = 1, a 2-D table.
    #[serde(rename = "E")]
    #[cfg_attr(feature = "cli", value(name = "e"))]
    E,
    /// Its cosine-weighted average `E_avg(roughness) = 2 ∫ E(mu) mu dmu`, a 1-D table.
    #[serde(rename = "E_avg")]
    #[cfg_attr(feature = "cli", value(name = "e-avg"))]
    EAvg,
    /// The split-sum scale `E_scale(mu, roughness) = ∫ (1 - Fc(o.h)) f mu_i dω_i` with
    /// `Fc = (1 - o.h)^5` and `F = 1` inside `f`, a 2-D table: Schlick's Fresnel-weighted albedo
    /// is `E_F = F0 E_scale + F90 E_bias` (Karis 2013, "Real Shading in Unreal Engine 4").
    #[serde(rename = "E_scale")]
    #[cfg_attr(feature = "cli", value(name = "e-scale"))]
    EScale,
    /// The split-sum bias `E_bias(mu, roughness) = ∫ Fc(o.h) f mu_i dω_i`, a 2-D table;
    /// `E_scale + E_bias = E`. With `E` it is the multiscatter layout (Filament, Godot:
    /// `∫ Fc w` and `∫ w`).
    #[serde(rename = "E_bias")]
    #[cfg_attr(feature = "cli", value(name = "e-bias"))]
    EBias,
    /// The energy albedo `R + T` of a rough dielectric interface (reflection plus transmission;
    /// the model is in `model::dielectric`) for light arriving from outside, at relative index
    /// `eta` from the IOR axis: a 3-D table over (eta, roughness, mu).
    #[serde(rename = "E_dielectric")]
    #[cfg_attr(feature = "cli", value(name = "e-dielectric"))]
    EDielectric,
    /// As e-dielectric, for light arriving from inside: relative index `1 / eta`.
    #[serde(rename = "E_dielectric_inside")]
    #[cfg_attr(feature = "cli", value(name = "e-dielectric-inside"))]
    EDielectricInside,
    /// `2 ∫ E_dielectric(mu) mu dmu`, a 2-D table over (eta, roughness).
    #[serde(rename = "E_avg_dielectric")]
    #[cfg_attr(feature = "cli", value(name = "e-avg-dielectric"))]
    EAvgDielectric,
    /// `2 ∫ E_dielectric_inside(mu) mu dmu`, a 2-D table over (eta, roughness).
    #[serde(rename = "E_avg_dielectric_inside")]
    #[cfg_attr(feature = "cli", value(name = "e-avg-dielectric-inside"))]
    EAvgDielectricInside,
    /// The reflection-only albedo `E_R(mu) = ∫ F(o.h) f mu_i dω_i` of a rough dielectric
    /// interface for light arriving from outside at relative index `eta` (exact Fresnel; what a
    /// coat reflects, whose `1 - E_R` attenuates the base beneath it: OpenPBR, glTF's clearcoat,
    /// Blender's Principled coat): a 3-D table over (eta, roughness, mu), or 2-D at one IOR.
    #[serde(rename = "E_reflection")]
    #[cfg_attr(feature = "cli", value(name = "e-reflection"))]
    EReflection,
    /// `2 ∫ E_reflection(mu) mu dmu`, a 2-D table over (eta, roughness), or 1-D at one IOR.
    #[serde(rename = "E_avg_reflection")]
    #[cfg_attr(feature = "cli", value(name = "e-avg-reflection"))]
    EAvgReflection,
    /// The exact dielectric Fresnel average `F_avg(eta) = 2 ∫ F(mu) mu dmu` for light arriving
    /// from outside, a 1-D table over the IOR axis; from inside it is
    /// `1 - (1 - F_avg(eta)) / eta^2` (Fresnel reciprocity). The same for every model.
    #[serde(rename = "F_avg")]
    #[cfg_attr(feature = "cli", value(name = "f-avg"))]
    FAvg,
    /// The Fresnel-weighted albedo `E_F(mu, roughness) = ∫ F(o.h) f mu_i dω_i` for the table's
    /// own Fresnel model (a grey one: one value per parameter), a 2-D table.
    #[serde(rename = "E_F")]
    #[cfg_attr(feature = "cli", value(name = "e-f"))]
    EF,
    /// The lookup-consistent normalisation of the Kulla-Conty lobe, `1 - Ē(r)`: `Ē` is the
    /// cosine-weighted average of the E table's own bilinear lookup at roughness `r`, so that
    /// `f_ms = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - Ē))` gives back exactly what that lookup
    /// loses. For an E table on the adaptive `mu` axis stored divided by `r` (its leading
    /// power), so that it interpolates linearly down to 0, and the lookup multiplies by `r`
    /// again (see `table::normalisation`). A 1-D table over a fine roughness axis, derived
    /// from the E table of the same bake (needs e).
    #[serde(rename = "f_ms_norm")]
    #[cfg_attr(feature = "cli", value(name = "f-ms-norm"))]
    FMsNorm,
}

impl Quantity {
    /// The symbol used in channel and file names: `E` or `E_avg`.
    #[must_use]
    pub fn symbol(self) -> &'static str {
        match self {
            Quantity::E => "E",
            Quantity::EAvg => "E_avg",
            Quantity::EScale => "E_scale",
            Quantity::EBias => "E_bias",
            Quantity::EDielectric => "E_dielectric",
            Quantity::EDielectricInside => "E_dielectric_inside",
            Quantity::EAvgDielectric => "E_avg_dielectric",
            Quantity::EAvgDielectricInside => "E_avg_dielectric_inside",
            Quantity::FAvg => "F_avg",
            Quantity::EReflection => "E_reflection",
            Quantity::EAvgReflection => "E_avg_reflection",
            Quantity::EF => "E_F",
            Quantity::FMsNorm => "f_ms_norm",
        }
    }

    /// The name used on the command line: `e` or `e-avg`.
    #[must_use]
    pub fn cli_name(self) -> &'static str {
        match self {
            Quantity::E => "e",
            Quantity::EAvg => "e-avg",
            Quantity::EScale => "e-scale",
            Quantity::EBias => "e-bias",
            Quantity::EDielectric => "e-dielectric",
            Quantity::EDielectricInside => "e-dielectric-inside",
            Quantity::EAvgDielectric => "e-avg-dielectric",
            Quantity::EAvgDielectricInside => "e-avg-dielectric-inside",
            Quantity::FAvg => "f-avg",
            Quantity::EReflection => "e-reflection",
            Quantity::EAvgReflection => "e-avg-reflection",
            Quantity::EF => "e-f",
            Quantity::FMsNorm => "f-ms-norm",
        }
    }

    /// A sentence for metadata and generated docs (ASCII: EXR text attributes are Latin-1).
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Quantity::E => {
                "directional albedo E(mu) = integral of f(o, i) mu_i over incoming directions i, F = 1"
            }
            Quantity::EAvg => {
                "average albedo E_avg = 2 * integral of E(mu) mu dmu over [0, 1], F = 1"
            }
            Quantity::EScale => {
                "split-sum scale E_scale(mu) = integral of (1 - Fc(o.h)) f(o, i) mu_i over \
                 incoming directions i, Fc = (1 - o.h)^5, F = 1 inside f; Schlick's \
                 Fresnel-weighted albedo is F0 * E_scale + F90 * E_bias; one_minus_E_scale is \
                 1 - E_scale"
            }
            Quantity::EBias => {
                "split-sum bias E_bias(mu) = integral of Fc(o.h) f(o, i) mu_i over incoming \
                 directions i, Fc = (1 - o.h)^5, F = 1 inside f; E_scale + E_bias = E; \
                 one_minus_E_bias is 1 - E_bias"
            }
            Quantity::EDielectric => {
                "energy albedo R + T of a rough dielectric interface (Walter et al. 2007 \
                 reflection and transmission, exact Fresnel), light arriving from outside at \
                 relative index eta (the eta axis): the fraction of the incident power a single \
                 scattering sends on, i.e. the path tracer's sample weight; the radiance albedo \
                 is R + T / eta^2; 1 = smooth; one_minus_E_dielectric is the energy lost"
            }
            Quantity::EDielectricInside => {
                "energy albedo R + T of a rough dielectric interface, light arriving from \
                 inside: relative index 1 / eta (eta from the eta axis); as E_dielectric \
                 otherwise (radiance albedo R + T eta^2)"
            }
            Quantity::EAvgDielectric => {
                "average energy albedo 2 * integral of E_dielectric(mu) mu dmu over [0, 1], light \
                 arriving from outside at relative index eta"
            }
            Quantity::EAvgDielectricInside => {
                "average energy albedo 2 * integral of E_dielectric_inside(mu) mu dmu over \
                 [0, 1], light arriving from inside at relative index 1 / eta"
            }
            Quantity::FAvg => {
                "average dielectric Fresnel reflectance F_avg(eta) = 2 * integral of F(mu) mu dmu \
                 over [0, 1], exact unpolarised Fresnel, light arriving from outside at relative \
                 index eta; from inside: 1 - (1 - F_avg(eta)) / eta^2; one_minus_F_avg is \
                 1 - F_avg"
            }
            Quantity::EReflection => {
                "reflection-only albedo E_reflection(mu) = integral of F(o.h) f(o, i) mu_i over \
                 incoming directions i, exact dielectric Fresnel at relative index eta, light \
                 arriving from outside (a coat: the base beneath it receives 1 - E_reflection \
                 of the light, less what the coat's single scattering loses); the reflected part \
                 R of E_dielectric; one_minus_E_reflection is 1 - E_reflection"
            }
            Quantity::EAvgReflection => {
                "average reflection-only albedo 2 * integral of E_reflection(mu) mu dmu over \
                 [0, 1], light arriving from outside at relative index eta"
            }
            Quantity::EF => {
                "Fresnel-weighted albedo E_F(mu) = integral of F(o.h) f(o, i) mu_i over incoming \
                 directions i, F the table's Fresnel model (see fresnel), F = 1 inside f; \
                 one_minus_E_F is 1 - E_F"
            }
            Quantity::FMsNorm => {
                "lookup-consistent Kulla-Conty normalisation, Ebar(r) = 2 * integral of \
                 E_lookup(mu, r) mu dmu the average of the E table's own bilinear lookup (the \
                 table in lookup_of), stored as (1 - Ebar(r)) / x when that E table has an \
                 adaptive or balanced mu axis on nodes (multiply the lookup by x, the rows' \
                 coordinate: r on linear rows) and as 1 - Ebar(r) otherwise; 1 - Ebar is the denominator of f_ms = (1 - E(mu_o)) \
                 (1 - E(mu_i)) / (pi (1 - Ebar)); not E_avg, which is the exact average; \
                 one_minus_f_ms_norm is 1 - the value"
            }
        }
    }

    /// Whether the table has a `mu` axis (every quantity but the averages).
    #[must_use]
    pub fn has_mu(self) -> bool {
        !matches!(
            self,
            Quantity::EAvg
                | Quantity::EAvgDielectric
                | Quantity::EAvgDielectricInside
                | Quantity::EAvgReflection
                | Quantity::FAvg
                | Quantity::FMsNorm
        )
    }

    /// Whether the table has a roughness axis (every quantity but `F_avg`).
    #[must_use]
    pub fn has_roughness(self) -> bool {
        self != Quantity::FAvg
    }

    /// Whether the table has an index-of-refraction axis (the dielectric tables and `F_avg`;
    /// a dielectric table at one IOR has none, [`crate::table::TableSpec::fixed_ior`]).
    #[must_use]
    pub fn has_ior(self) -> bool {
        self.is_dielectric() || self == Quantity::FAvg
    }

    /// Whether the quantity is the reflection alone of a rough dielectric interface, a coat's
    /// (`E_reflection`, `E_avg_reflection`).
    #[must_use]
    pub fn is_reflection_only(self) -> bool {
        matches!(self, Quantity::EReflection | Quantity::EAvgReflection)
    }

    /// Whether the quantity is an albedo of a rough dielectric interface, over the IOR or at one
    /// IOR ([`crate::table::TableSpec::fixed_ior`]): the glass albedos `R + T` and the
    /// reflection-only ones.
    #[must_use]
    pub fn is_dielectric(self) -> bool {
        self.is_glass_albedo() || self.is_reflection_only()
    }

    /// Whether the quantity is a rough dielectric's energy albedo (`E_dielectric`, from either
    /// side, and their averages): over the IOR axis, or at one IOR a table's Fresnel model names
    /// ([`crate::table::TableSpec::fixed_ior`]).
    #[must_use]
    pub fn is_glass_albedo(self) -> bool {
        matches!(
            self,
            Quantity::EDielectric
                | Quantity::EDielectricInside
                | Quantity::EAvgDielectric
                | Quantity::EAvgDielectricInside
        )
    }

    /// Whether the table still varies with `mu` on a mirror (`roughness = 0`), so that it needs a
    /// `mu` axis independent of the roughness (not the adaptive one): the split-sum channels,
    /// `E_F` and `E_reflection`, which equal `h(mu)` and `F(mu)` there.
    #[must_use]
    pub fn varies_on_a_mirror(self) -> bool {
        self.weight().is_some() || self == Quantity::EF || self == Quantity::EReflection
    }

    /// Whether the light arrives from inside (relative index `1 / eta`).
    #[must_use]
    pub fn from_inside(self) -> bool {
        matches!(
            self,
            Quantity::EDielectricInside | Quantity::EAvgDielectricInside
        )
    }

    /// The weight `h(o.h)` a split-sum quantity puts on the albedo integrand (`None`: `h = 1`).
    #[must_use]
    pub fn weight(self) -> Option<fn(f64) -> f64> {
        match self {
            Quantity::EScale => Some(|c| 1.0 - schlick_weight(c)),
            Quantity::EBias => Some(schlick_weight),
            _ => None,
        }
    }
}

/// Schlick's `Fc = (1 - c)^5`.
#[must_use]
pub fn schlick_weight(c: f64) -> f64 {
    let x = 1.0 - c;
    let x2 = x * x;
    x2 * x2 * x
}

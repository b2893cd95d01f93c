//! Fresnel reflectance models and their hemispherical averages `F_avg = 2 ∫_0^1 F(mu) mu dmu`.
//!
//! - Schlick's approximation with `F0` and `F90` per RGB channel: `F = F0 + (F90 - F0) (1 - c)^5`
//!   (Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering"), whose average has
//!   the closed form `(20 F0 + F90) / 21` (`docs/physics.md`).
//! - The exact unpolarised Fresnel reflectance of a dielectric interface with relative index
//!   `eta = n_transmitted / n_incident` (`eta < 1`: light leaving the denser medium, with total
//!   internal reflection beyond the critical angle): Walter, Marschner, Li and Torrance 2007,
//!   "Microfacet Models for Refraction through Rough Surfaces", eq. 22,
//!   `F = (g - c)^2 / (2 (g + c)^2) (1 + ((c (g + c) - 1) / (c (g - c) + 1))^2)` with
//!   `g^2 = eta^2 - 1 + c^2`, and `F = 1` where `g^2 < 0`.
//! - Conductors with a complex index `eta + i k` per RGB channel: the unpolarised average of the
//!   two Fresnel amplitude reflectances `r_s = (c - n cos_t) / (c + n cos_t)` and
//!   `r_p = (n c - cos_t) / (n c + cos_t)`, `n = eta + i k`, `cos_t = sqrt(1 - (1 - c^2) / n^2)`
//!   (complex Snell's law; Born and Wolf, "Principles of Optics", 1.5.2 and 14.2; pbrt-v4
//!   `FrComplex`).
//!
//! `c` is the cosine between the incident direction and the (micro)surface normal, in `[0, 1]`.

use crate::numerics::gauss_kronrod::integrate_pieces;
use serde::{Deserialize, Serialize};

/// RGB values, one per channel.
pub type Rgb = [f64; 3];

/// A Fresnel model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "model")]
pub enum Fresnel {
    /// `F = 1`: the tables of energy compensation proper.
    None,
    /// Schlick's approximation.
    Schlick { f0: Rgb, f90: Rgb },
    /// An exact dielectric interface with relative index of refraction `eta > 0`.
    Dielectric { eta: f64 },
    /// A conductor with complex index `eta + i k` per channel (`eta > 0`, `k >= 0`).
    Conductor { eta: Rgb, k: Rgb },
}

/// The largest index of refraction (dielectric `ior`, conductor `eta` and `k`) kiln accepts,
/// and `1 / MAX_INDEX` the smallest `ior` and `eta`: far beyond any material (diamond 2.42,
/// germanium 4; metals' `eta` 0.03 to 5, `k` below 12), well within f64 (an `ior` of 1e155
/// overflows `ior^2` and gave NaN tables).
pub const MAX_INDEX: f64 = 100.0;

/// Models compare equal only with identical parameters (no NaN passes [`Fresnel::validate`]), so
/// a model can be part of a table's identity ([`crate::TableSpec`]).
impl Eq for Fresnel {}

impl std::hash::Hash for Fresnel {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        let bits = |state: &mut H, values: &[f64]| {
            for v in values {
                v.to_bits().hash(state);
            }
        };
        std::mem::discriminant(self).hash(state);
        match *self {
            Fresnel::None => {}
            Fresnel::Schlick { f0, f90 } => {
                bits(state, &f0);
                bits(state, &f90);
            }
            Fresnel::Dielectric { eta } => bits(state, &[eta]),
            Fresnel::Conductor { eta, k } => {
                bits(state, &eta);
                bits(state, &k);
            }
        }
    }
}

impl Fresnel {
    /// A short file-name tag with the parameters of channel 0 (grey models; see
    /// [`Fresnel::is_grey`]): `none`, `schlick-0.04-1`, `dielectric-1.5`, `conductor-0.2-3.1`.
    #[must_use]
    pub fn tag(&self) -> String {
        match *self {
            Fresnel::None => "none".to_string(),
            Fresnel::Schlick { f0, f90 } => format!("schlick-{}-{}", f0[0], f90[0]),
            Fresnel::Dielectric { eta } => format!("dielectric-{eta}"),
            Fresnel::Conductor { eta, k } => format!("conductor-{}-{}", eta[0], k[0]),
        }
    }

    /// The flags that name this model on the command line (channel 0 of a grey model).
    #[must_use]
    pub fn flags(&self) -> String {
        match *self {
            Fresnel::None => "--fresnel none".to_string(),
            Fresnel::Schlick { f0, f90 } => format!("--f0 {} --f90 {}", f0[0], f90[0]),
            Fresnel::Dielectric { eta } => format!("--ior {eta}"),
            Fresnel::Conductor { eta, k } => format!("--eta {} --k {}", eta[0], k[0]),
        }
    }

    /// The model's name on the command line and in files.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Fresnel::None => "none",
            Fresnel::Schlick { .. } => "schlick",
            Fresnel::Dielectric { .. } => "dielectric",
            Fresnel::Conductor { .. } => "conductor",
        }
    }

    /// Checks the parameters, naming the bad one and the allowed range.
    pub fn validate(&self) -> crate::Result<()> {
        let finite = |what: &str, v: &[f64]| -> crate::Result<()> {
            match v.iter().find(|x| !x.is_finite()) {
                Some(x) => Err(crate::Error::InvalidInput(format!(
                    "{what} must be finite (got {x})"
                ))),
                None => Ok(()),
            }
        };
        match *self {
            Fresnel::None => Ok(()),
            Fresnel::Schlick { f0, f90 } => {
                finite("f0", &f0)?;
                finite("f90", &f90)?;
                for (what, v) in [("f0", f0), ("f90", f90)] {
                    if let Some(x) = v.iter().find(|x| !(0.0..=1.0).contains(*x)) {
                        return Err(crate::Error::InvalidInput(format!(
                            "{what} must be in [0, 1] (got {})",
                            crate::error::shown(*x)
                        )));
                    }
                }
                Ok(())
            }
            Fresnel::Dielectric { eta } => {
                finite("ior", &[eta])?;
                if !(1.0 / MAX_INDEX..=MAX_INDEX).contains(&eta) {
                    return Err(crate::Error::InvalidInput(format!(
                        "ior must be between 0.01 and 100 (got {}); it is n_inside / \
                         n_outside, e.g. 1.5 for glass in air, 1/1.5 for light leaving glass \
                         (real materials lie between 1/4 and 4)",
                        crate::error::shown(eta)
                    )));
                }
                Ok(())
            }
            Fresnel::Conductor { eta, k } => {
                finite("eta", &eta)?;
                finite("k", &k)?;
                if let Some(x) = eta
                    .iter()
                    .find(|x| !(1.0 / MAX_INDEX..=MAX_INDEX).contains(*x))
                {
                    return Err(crate::Error::InvalidInput(format!(
                        "eta must be between 0.01 and 100 (got {}); metals lie between 0.03 \
                         and 5",
                        crate::error::shown(*x)
                    )));
                }
                if let Some(x) = k.iter().find(|x| !(0.0..=MAX_INDEX).contains(*x)) {
                    return Err(crate::Error::InvalidInput(format!(
                        "k must be between 0 and 100 (got {}); metals lie below 12",
                        crate::error::shown(*x)
                    )));
                }
                Ok(())
            }
        }
    }

    /// Whether every channel has the same reflectance (a scalar model).
    #[must_use]
    pub fn is_grey(&self) -> bool {
        let same = |v: Rgb| v[0] == v[1] && v[1] == v[2];
        match *self {
            Fresnel::None | Fresnel::Dielectric { .. } => true,
            Fresnel::Schlick { f0, f90 } => same(f0) && same(f90),
            Fresnel::Conductor { eta, k } => same(eta) && same(k),
        }
    }

    /// The reflectance per channel at cosine `c` in `[0, 1]`.
    #[must_use]
    pub fn reflectance(&self, c: f64) -> Rgb {
        let c = c.clamp(0.0, 1.0);
        match *self {
            Fresnel::None => [1.0; 3],
            Fresnel::Schlick { f0, f90 } => {
                let w = (1.0 - c).powi(5);
                std::array::from_fn(|j| f0[j] + (f90[j] - f0[j]) * w)
            }
            Fresnel::Dielectric { eta } => [dielectric(eta, c); 3],
            Fresnel::Conductor { eta, k } => std::array::from_fn(|j| conductor(eta[j], k[j], c)),
        }
    }

    /// `F_avg = 2 ∫_0^1 F(mu) mu dmu` per channel: Schlick's closed form `(20 F0 + F90) / 21`,
    /// otherwise adaptive Gauss-Kronrod quadrature to 1e-14, split at the critical angle of a
    /// dielectric with `eta < 1` (where `F` has a kink).
    #[must_use]
    pub fn average(&self) -> Rgb {
        self.average_report().value
    }

    /// [`Fresnel::average`] with how it was computed and its error estimate.
    #[must_use]
    pub fn average_report(&self) -> FresnelAverage {
        match *self {
            Fresnel::None => FresnelAverage {
                value: [1.0; 3],
                error: 0.0,
                evaluations: 0,
                method: "closed-form",
            },
            Fresnel::Schlick { f0, f90 } => FresnelAverage {
                value: std::array::from_fn(|j| (20.0 * f0[j] + f90[j]) / 21.0),
                error: 0.0,
                evaluations: 0,
                method: "closed-form",
            },
            _ => self.average_by_quadrature(),
        }
    }

    /// `F_avg` by quadrature for any model (the closed form's check for Schlick).
    #[must_use]
    pub fn average_by_quadrature(&self) -> FresnelAverage {
        let mut breaks = vec![0.0, 1.0];
        if let Fresnel::Dielectric { eta } = *self
            && eta < 1.0
        {
            breaks.insert(1, ((1.0 - eta) * (1.0 + eta)).sqrt());
        }
        let q = integrate_pieces(
            &mut |mu: f64| self.reflectance(mu).map(|f| 2.0 * f * mu),
            &breaks,
            1e-14,
            1000,
        );
        FresnelAverage {
            value: q.value,
            error: q.error,
            evaluations: q.evaluations,
            method: "quadrature",
        }
    }
}

/// `F_avg` per channel with how it was computed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FresnelAverage {
    pub value: Rgb,
    /// The quadrature's error estimate (0 for a closed form).
    pub error: f64,
    /// Reflectance evaluations spent.
    pub evaluations: u64,
    /// `closed-form` or `quadrature`.
    pub method: &'static str,
}

/// Exact unpolarised dielectric reflectance (Walter et al. 2007, eq. 22), `eta` relative.
#[must_use]
pub fn dielectric(eta: f64, c: f64) -> f64 {
    let g2 = eta * eta - 1.0 + c * c;
    if g2 <= 0.0 {
        return 1.0; // total internal reflection
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// Exact unpolarised reflectance for the complex index `eta + i k` (see the module docs).
#[must_use]
pub fn conductor(eta: f64, k: f64, c: f64) -> f64 {
    let n = Complex { re: eta, im: k };
    let c = Complex { re: c, im: 0.0 };
    let sin2 = Complex {
        re: 1.0 - c.re * c.re,
        im: 0.0,
    };
    let cos_t = (Complex { re: 1.0, im: 0.0 } - sin2 / (n * n)).sqrt();
    let r_s = (c - n * cos_t) / (c + n * cos_t);
    let r_p = (n * c - cos_t) / (n * c + cos_t);
    0.5 * (r_s.norm2() + r_p.norm2())
}

/// Just enough complex arithmetic for [`conductor`].
#[derive(Clone, Copy, Debug)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }

    /// The principal square root (non-negative real part).
    fn sqrt(self) -> Self {
        let r = self.norm2().sqrt();
        let re = (0.5 * (r + self.re)).max(0.0).sqrt();
        let im = (0.5 * (r - self.re)).max(0.0).sqrt();
        Complex {
            re,
            im: if self.im < 0.0 { -im } else { im },
        }
    }
}

impl std::ops::Add for Complex {
    type Output = Complex;
    fn add(self, o: Complex) -> Complex {
        Complex {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
}

impl std::ops::Sub for Complex {
    type Output = Complex;
    fn sub(self, o: Complex) -> Complex {
        Complex {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
}

impl std::ops::Mul for Complex {
    type Output = Complex;
    fn mul(self, o: Complex) -> Complex {
        Complex {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
}

impl std::ops::Div for Complex {
    type Output = Complex;
    fn div(self, o: Complex) -> Complex {
        let d = o.norm2();
        Complex {
            re: (self.re * o.re + self.im * o.im) / d,
            im: (self.im * o.re - self.re * o.im) / d,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The check values of the Fresnel issue: `F_avg` of glass from both sides, to 1e-9.
    #[test]
    fn dielectric_averages_match_the_check_values() {
        let outside = Fresnel::Dielectric { eta: 1.5 }.average()[0];
        let inside = Fresnel::Dielectric { eta: 1.0 / 1.5 }.average()[0];
        assert!((outside - 0.091_777_959_3).abs() < 1e-9, "{outside}");
        assert!((inside - 0.596_345_759_7).abs() < 1e-9, "{inside}");
    }

    /// Reciprocity: `1 - F_avg(1/eta) = (1 - F_avg(eta)) / eta^2`, over a range of indices.
    #[test]
    fn averages_obey_reciprocity() {
        for eta in [1.01, 1.1, 1.33, 1.5, 2.0, 2.4, 4.0] {
            let f = Fresnel::Dielectric { eta }.average()[0];
            let g = Fresnel::Dielectric { eta: 1.0 / eta }.average()[0];
            assert!(
                ((1.0 - g) - (1.0 - f) / (eta * eta)).abs() < 1e-9,
                "eta {eta}: {f} {g}"
            );
        }
    }

    /// Schlick's closed form against the quadrature, to 1e-12.
    #[test]
    fn schlick_closed_form_matches_quadrature() {
        for (f0, f90) in [(0.04, 1.0), (0.5, 1.0), (0.9, 0.7), (0.0, 0.0)] {
            let model = Fresnel::Schlick {
                f0: [f0, 0.3, 1.0],
                f90: [f90, 1.0, 1.0],
            };
            let closed = model.average();
            let numeric = model.average_by_quadrature().value;
            for j in 0..3 {
                assert!((closed[j] - numeric[j]).abs() < 1e-12, "{f0} {f90} {j}");
            }
        }
    }

    /// Known values: normal incidence `((eta - 1) / (eta + 1))^2` for dielectrics,
    /// `((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2)` for conductors, 1 at grazing; a conductor with
    /// `k = 0` is the dielectric; TIR beyond the critical angle.
    #[test]
    fn reflectance_limits_and_consistency() {
        for eta in [0.5f64, 1.0 / 1.5, 1.5, 3.0] {
            let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((dielectric(eta, 1.0) - f0).abs() < 1e-15, "{eta}");
            assert!((dielectric(eta, 0.0) - 1.0).abs() < 1e-15, "{eta}");
            for c in [0.0, 0.1, 0.3, 0.5, 0.77, 0.95, 1.0] {
                let d = dielectric(eta, c);
                let k0 = conductor(eta, 0.0, c);
                assert!((d - k0).abs() < 1e-13, "eta {eta} c {c}: {d} vs {k0}");
                assert!((0.0..=1.0).contains(&d));
            }
        }
        // Critical angle of eta = 1/1.5: sin = 1/1.5, so c_crit = sqrt(1 - 1/2.25).
        let c_crit = (1.0f64 - 1.0 / 2.25).sqrt();
        assert_eq!(dielectric(1.0 / 1.5, c_crit * 0.999), 1.0);
        assert!(dielectric(1.0 / 1.5, c_crit * 1.001) < 1.0);
        // Gold-like conductor.
        let (n, k) = (0.18, 3.0);
        let f0 = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
        assert!((conductor(n, k, 1.0) - f0).abs() < 1e-14);
        assert!((conductor(n, k, 0.0) - 1.0).abs() < 1e-12);
        for c in [0.0, 0.2, 0.6, 1.0] {
            assert!((0.0..=1.0).contains(&conductor(n, k, c)));
        }
    }

    #[test]
    fn bad_parameters_are_named() {
        assert!(
            Fresnel::Dielectric { eta: 0.0 }
                .validate()
                .unwrap_err()
                .to_string()
                .contains("ior")
        );
        assert!(
            Fresnel::Conductor {
                eta: [1.0, -1.0, 1.0],
                k: [0.0; 3]
            }
            .validate()
            .unwrap_err()
            .to_string()
            .contains("eta")
        );
        assert!(
            Fresnel::Schlick {
                f0: [1.5; 3],
                f90: [1.0; 3]
            }
            .validate()
            .unwrap_err()
            .to_string()
            .contains("f0")
        );
        assert!(Fresnel::Dielectric { eta: 1.5 }.validate().is_ok());
    }

    /// Conductors at oblique incidence, against the same Fresnel equations evaluated in
    /// mpmath's complex arithmetic at 30 digits (rounded to 16) (`r_s = (c - n cos_t) / (c + n cos_t)`,
    /// `r_p = (n c - cos_t) / (n c + cos_t)`, `cos_t = sqrt(1 - (1 - c^2) / n^2)`, principal
    /// root): gold-like, aluminium-like, and indices either side of 1 with small `k`.
    #[test]
    fn conductors_at_oblique_incidence_match_mpmath() {
        for (eta, k, c, mpmath) in [
            (0.18, 3.0, 0.5, 0.926_132_736_478_432_3),
            (0.18, 3.0, 0.1, 0.963_043_616_893_336_2),
            (1.2, 7.0, 0.3, 0.868_975_211_294_149_7),
            (2.5, 0.5, 0.7, 0.208_727_737_149_524_5),
            (0.5, 0.3, 0.2, 0.809_009_508_207_126_4),
        ] {
            let got = conductor(eta, k, c);
            assert!((got - mpmath).abs() < 1e-14, "{eta} {k} {c}: {got}");
            // Channel by channel: the middle one is glass (k = 0).
            let model = Fresnel::Conductor {
                eta: [eta, 1.5, eta],
                k: [k, 0.0, k],
            };
            let [first, glass, last] = model.reflectance(c);
            assert_eq!([first, last], [got, got]);
            assert!((glass - dielectric(1.5, c)).abs() < 1e-13, "{glass}");
        }
    }

    /// Names, tags and flags as files and the command line spell them, greyness channel by
    /// channel, each range check with its message, and hashing by value.
    #[test]
    fn models_are_named_tagged_and_checked() {
        let schlick = Fresnel::Schlick {
            f0: [0.04; 3],
            f90: [1.0; 3],
        };
        let glass = Fresnel::Dielectric { eta: 1.5 };
        let metal = Fresnel::Conductor {
            eta: [0.2; 3],
            k: [3.1; 3],
        };
        let none = Fresnel::None;
        let names: Vec<_> = [none, schlick, glass, metal]
            .iter()
            .map(Fresnel::name)
            .collect();
        assert_eq!(names, ["none", "schlick", "dielectric", "conductor"]);
        let tags: Vec<_> = [none, schlick, glass, metal]
            .iter()
            .map(Fresnel::tag)
            .collect();
        assert_eq!(
            tags,
            [
                "none",
                "schlick-0.04-1",
                "dielectric-1.5",
                "conductor-0.2-3.1"
            ]
        );
        let flags: Vec<_> = [none, schlick, glass, metal]
            .iter()
            .map(Fresnel::flags)
            .collect();
        assert_eq!(
            flags,
            [
                "--fresnel none",
                "--f0 0.04 --f90 1",
                "--ior 1.5",
                "--eta 0.2 --k 3.1"
            ]
        );
        assert!([none, schlick, glass, metal].iter().all(Fresnel::is_grey));
        for j in 0..3 {
            let mut v = [0.5; 3];
            v[j] = 0.6;
            for tinted in [
                Fresnel::Schlick {
                    f0: v,
                    f90: [1.0; 3],
                },
                Fresnel::Schlick {
                    f0: [0.5; 3],
                    f90: v,
                },
                Fresnel::Conductor {
                    eta: v,
                    k: [1.0; 3],
                },
                Fresnel::Conductor {
                    eta: [1.0; 3],
                    k: v,
                },
            ] {
                assert!(!tinted.is_grey(), "{j}: {tinted:?}");
            }
        }
        let refused = |model: Fresnel, words: &str| {
            let message = model.validate().unwrap_err();
            assert!(
                message.to_string().contains(words),
                "{message}: wanted {words}"
            );
        };
        for good in [none, schlick, glass, metal] {
            assert!(good.validate().is_ok());
        }
        for eta in [0.01, 100.0] {
            assert!(Fresnel::Dielectric { eta }.validate().is_ok());
        }
        refused(Fresnel::Dielectric { eta: f64::NAN }, "ior must be finite");
        refused(
            Fresnel::Dielectric { eta: 0.009 },
            "ior must be between 0.01 and 100",
        );
        refused(
            Fresnel::Dielectric { eta: 101.0 },
            "ior must be between 0.01 and 100",
        );
        let schlick_with = |f0: f64, f90: f64| Fresnel::Schlick {
            f0: [0.5, f0, 0.5],
            f90: [1.0, 1.0, f90],
        };
        assert!(schlick_with(0.0, 1.0).validate().is_ok());
        refused(schlick_with(-0.1, 1.0), "f0 must be in [0, 1] (got -0.1)");
        refused(schlick_with(0.5, 1.1), "f90 must be in [0, 1] (got 1.1)");
        refused(
            schlick_with(f64::INFINITY, 1.0),
            "f0 must be finite (got inf)",
        );
        refused(schlick_with(0.5, f64::NAN), "f90 must be finite (got NaN)");
        let metal_with = |eta: f64, k: f64| Fresnel::Conductor {
            eta: [1.0, eta, 1.0],
            k: [1.0, 1.0, k],
        };
        assert!(metal_with(100.0, 0.0).validate().is_ok());
        assert!(metal_with(0.01, 100.0).validate().is_ok());
        refused(metal_with(0.001, 1.0), "eta must be between 0.01 and 100");
        refused(metal_with(1.0, -0.5), "k must be between 0 and 100");
        refused(metal_with(1.0, 101.0), "k must be between 0 and 100");
        refused(metal_with(f64::NAN, 1.0), "eta must be finite");
        refused(metal_with(1.0, f64::INFINITY), "k must be finite");
        // Hashing follows the parameters of every channel.
        let hash = |model: Fresnel| {
            use std::hash::{BuildHasher, BuildHasherDefault};
            BuildHasherDefault::<std::collections::hash_map::DefaultHasher>::default()
                .hash_one(model)
        };
        assert_ne!(hash(glass), hash(Fresnel::Dielectric { eta: 1.33 }));
        assert_ne!(hash(schlick), hash(schlick_with(0.0, 1.0)));
        assert_ne!(hash(schlick_with(0.5, 1.0)), hash(schlick_with(0.5, 0.9)));
        assert_ne!(hash(metal), hash(metal_with(0.2, 3.1)));
        assert_ne!(hash(metal_with(1.0, 1.0)), hash(metal_with(1.0, 2.0)));
        assert_ne!(hash(none), hash(glass));
        assert_eq!(hash(glass), hash(Fresnel::Dielectric { eta: 1.5 }));
    }

    /// How each average was made: closed forms spend nothing; Schlick's is `(20 F0 + F90) / 21`
    /// per channel; a dielectric from inside is split at its critical angle (`sqrt(1 - eta^2)`),
    /// which a kink-blind quadrature would miss.
    #[test]
    fn averages_report_their_method() {
        let none = Fresnel::None.average_report();
        assert_eq!(
            (none.value, none.error, none.evaluations),
            ([1.0; 3], 0.0, 0)
        );
        assert_eq!(none.method, "closed-form");
        let schlick = Fresnel::Schlick {
            f0: [0.0, 0.21, 1.0],
            f90: [0.0, 1.0, 0.0],
        }
        .average_report();
        assert_eq!(schlick.method, "closed-form");
        assert_eq!(schlick.evaluations, 0);
        assert_eq!(schlick.value[0], 0.0);
        assert!((schlick.value[1] - 5.2 / 21.0).abs() < 1e-15);
        assert!((schlick.value[2] - 20.0 / 21.0).abs() < 1e-15);
        let inside = Fresnel::Dielectric { eta: 0.5 }.average_report();
        assert_eq!(inside.method, "quadrature");
        assert!(inside.evaluations > 0 && inside.error < 1e-13);
        // F_avg(1/2) = 1 - (1 - F_avg(2)) / 4 (reciprocity) with F_avg(2) = 0.2227...:
        // checked against its own quadrature from outside, which has no kink.
        let outside = Fresnel::Dielectric { eta: 2.0 }.average()[0];
        assert!((inside.value[0] - (1.0 - (1.0 - outside) / 4.0)).abs() < 1e-13);
    }
}

//! Burley's diffuse lobe as Unity HDRP evaluates and pre-integrates it (the blue channel of
//! its `PreIntegratedFGD` table).
//!
//! Burley 2012 ("Physically-Based Shading at Disney", eq. 3 with `F_D90 = 0.5 + 2 r cos^2(theta_d)`):
//! `f_d = (1 / pi) (1 + (F_D90 - 1)(1 - mu_i)^5) (1 + (F_D90 - 1)(1 - mu_o)^5)`. Unity's
//! `DisneyDiffuseNoPI` writes `2 cos^2(theta_d) = 1 + i.o`, takes the perceptual roughness `r`,
//! and divides by 1.03571, "the worst case (roughness = albedo = 1) at theta_view = 0"; that
//! constant is `29 / 28` rounded ([`disney_diffuse_albedo`] at `r = 1`, `mu_o = 1`).

/// Unity's normalisation constant (`rcp(1.03571)` in `DisneyDiffuseNoPI`).
pub const UNITY_NORMALISATION: f64 = 1.03571;

/// Unity's `DisneyDiffuseNoPI`: `pi f_d` for perceptual roughness `r`, cosines `mu_o`, `mu_i`
/// and `i.o = cos_io`.
#[must_use]
pub fn disney_diffuse_no_pi(mu_o: f64, mu_i: f64, cos_io: f64, r: f64) -> f64 {
    let fd90 = 0.5 + r * (1.0 + cos_io);
    let schlick = |mu: f64| 1.0 + (fd90 - 1.0) * (1.0 - mu).powi(5);
    schlick(mu_i) * schlick(mu_o) / UNITY_NORMALISATION
}

/// The directional albedo `∫ f_d mu_i dω_i` of [`disney_diffuse_no_pi`] (over `pi`), exactly.
///
/// With `i.o = mu_o mu_i + s_o s_i cos(phi)`, `F_D90 - 1 = A + B cos(phi)`, `A = r (1 + mu_o
/// mu_i) - 1/2`, `B = r s_o s_i`; the product of the two Schlick factors is quadratic in
/// `cos(phi)`, whose average over `phi` is `1 + A (p_i + p_o) + (A^2 + B^2 / 2) p_i p_o` with
/// `p = (1 - mu)^5`. What is left, `2 ∫_0^1 mu_i (...) dmu_i`, is a polynomial of degree 8 in
/// `mu_i` (`B^2 = r^2 s_o^2 (1 - mu_i^2)`), which the 5-point Gauss-Legendre rule integrates
/// exactly.
#[must_use]
pub fn disney_diffuse_albedo(r: f64, mu_o: f64) -> f64 {
    let p_o = (1.0 - mu_o).powi(5);
    let s_o2 = 1.0 - mu_o * mu_o;
    let rule = crate::numerics::gauss_legendre::rule(5);
    let mut f = |mu_i: f64| -> [f64; 1] {
        let a = r * (1.0 + mu_o * mu_i) - 0.5;
        let b2 = r * r * s_o2 * (1.0 - mu_i * mu_i);
        let p_i = (1.0 - mu_i).powi(5);
        [2.0 * mu_i * (1.0 + a * (p_i + p_o) + (a * a + 0.5 * b2) * p_i * p_o)]
    };
    crate::numerics::gauss_legendre::integrate(&rule, &mut f, 0.0, 1.0)[0] / UNITY_NORMALISATION
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The albedo by brute force: a 64 x 64 Gauss-Legendre product rule over `(mu_i, phi)` of
    /// the BRDF itself, with the directions as vectors (no averaging over `phi` by hand).
    fn brute_force(r: f64, mu_o: f64) -> f64 {
        let rule = crate::numerics::gauss_legendre::rule(64);
        let o = crate::model::Vec3::from_mu(mu_o);
        let mut outer = |mu_i: f64| -> [f64; 1] {
            let s_i = (1.0 - mu_i * mu_i).sqrt();
            let mut inner = |phi: f64| -> [f64; 1] {
                let i = crate::model::Vec3::new(s_i * phi.cos(), s_i * phi.sin(), mu_i);
                [disney_diffuse_no_pi(mu_o, mu_i, o.dot(i), r) * mu_i / PI]
            };
            crate::numerics::gauss_legendre::integrate(&rule, &mut inner, 0.0, 2.0 * PI)
        };
        crate::numerics::gauss_legendre::integrate(&rule, &mut outer, 0.0, 1.0)[0]
    }

    #[test]
    fn albedo_matches_brute_force_and_unity_normalisation() {
        for r in [0.0, 0.3, 0.7, 1.0] {
            for mu_o in [0.01, 0.25, 0.6, 1.0] {
                let (exact, brute) = (disney_diffuse_albedo(r, mu_o), brute_force(r, mu_o));
                // The product rule is exact for the polynomial in mu_i and cos(phi) up to
                // rounding, so the two agree to f64 accumulation error.
                assert!(
                    (exact - brute).abs() < 1e-13,
                    "r {r}, mu {mu_o}: {exact} vs {brute}"
                );
            }
        }
        // 2 (1/2 + ∫ mu (1/2 + mu)(1 - mu)^5) = 1 + 1/28 at r = 1, mu_o = 1 (Beta integrals).
        let normal = disney_diffuse_albedo(1.0, 1.0);
        assert!((normal - (29.0 / 28.0) / UNITY_NORMALISATION).abs() < 1e-15);
        // Unity normalises this case to 1 with 29/28 = 1.0357143 cut to five decimals.
        assert!((normal - 1.0).abs() < 5e-6, "{normal}");
    }
}

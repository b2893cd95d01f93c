// E of ggx height-correlated (F = 1) as a polynomial of degree 3 in u = 2 t - 1 and 2 in v = 2 r - 1 (12 coefficients), t = (mu (1 + 4 alpha) / (mu + 4 alpha))^0.4, alpha = r^2 (kiln's adaptive axis); max error 2.78e-2 over mu in [0, 1], r in [0, 1] against kiln's reference (kiln verify-fit); made by `kiln fit --ndf ggx --masking height-correlated --degrees 3,2`
#[allow(clippy::all)]
pub fn ggx_height_correlated_e_fit_t3_r2(mu: f32, r: f32) -> f32 {
    let k = 4e0_f32 * r * r;
    let t = (mu * (1.0 + k) / (mu + k).max(1e-30)).min(1.0).powf(0.4);
    let u = 2e0_f32 * t - 1e0_f32;
    let v = 2e0_f32 * r - 1e0_f32;
    let mut e = 5.7297457e-2_f32 + v * (3.0646069e-2_f32 + v * (-2.9504651e-2_f32));
    e = e * u + 8.2470626e-2_f32 + v * (-8.679972e-2_f32 + v * (-6.741011e-2_f32));
    e = e * u + -1.2641686e-1_f32 + v * (-2.14134e-1_f32 + v * (-9.201921e-2_f32));
    e = e * u + 8.7489986e-1_f32 + v * (-9.669789e-2_f32 + v * (-5.3020112e-2_f32));
    return e;
}

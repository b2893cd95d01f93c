// E of ggx height-correlated (F = 1) as a polynomial of degree 3 in u = 2 t - 1 and 2 in v = 2 r - 1 (12 coefficients), t = (mu (1 + 4 alpha) / (mu + 4 alpha))^0.4, alpha = r^2 (kiln's adaptive axis); max error 2.78e-2 over mu in [0, 1], r in [0, 1] against kiln's reference (kiln verify-fit); made by `kiln fit --ndf ggx --masking height-correlated --degrees 3,2`
float ggx_height_correlated_e_fit_t3_r2(float mu, float r) {
    float k = 4e0 * r * r;
    float t = pow(min(mu * (1.0 + k) / max(mu + k, 1e-30), 1.0), 0.4);
    float u = 2e0 * t - 1e0;
    float v = 2e0 * r - 1e0;
    float e = 5.7297457e-2 + v * (3.0646069e-2 + v * (-2.9504651e-2));
    e = e * u + 8.2470626e-2 + v * (-8.679972e-2 + v * (-6.741011e-2));
    e = e * u + -1.2641686e-1 + v * (-2.14134e-1 + v * (-9.201921e-2));
    e = e * u + 8.7489986e-1 + v * (-9.669789e-2 + v * (-5.3020112e-2));
    return e;
}

// E of ggx height-correlated (F = 1) as the rational 1 - t^2 P(u, s) / Q(u, s), P = A(u) + B(s) (no cross terms) of degree 2 in u = 2 t - 1 and 1 in s = 2 r^3.2 - 1, Q of degrees 2 and 2 with constant term 1 (12 coefficients), t = (mu (1 + alpha) / (mu + alpha))^0.3, alpha = r^2; max error 9.18e-3 over mu in [0, 1], r in [0, 1] against kiln's reference (kiln verify-fit); made by `kiln fit --ndf ggx --masking height-correlated --degrees 2+1/2,2`
fn ggx_height_correlated_e_fit_p2_plus_1_q2_2(mu: f32, r: f32) -> f32 {
    let k = r * r;
    let t = pow(min(mu * (1.0 + k) / max(mu + k, 1e-30), 1.0), 0.3);
    let u = 2e0 * t - 1e0;
    let s = 2e0 * pow(r, 3.2) - 1e0;
    var n = 1.3032663e-1;
    n = n * u + -3.5413e-1;
    n = n * u + 3.5354453e-1 + s * (1.3241081e-1);
    var d = 6.6804785e-1 + s * (-9.254912e-1 + s * (6.659628e-1));
    d = d * u + -1.3790286e0 + s * (1.4781656e0 + s * (-9.2926794e-1));
    d = d * u + 1e0 + s * (-5.067203e-1 + s * (3.1160355e-1));
    return 1e0 - t * t * n / d;
}

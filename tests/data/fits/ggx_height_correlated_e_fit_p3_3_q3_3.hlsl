// E of ggx height-correlated (F = 1) as the rational 1 - t^2 P(u, s) / Q(u, s), P of degree 3 in u = 2 t - 1 and 3 in s = 2 r^3.2 - 1, Q of degrees 3 and 3 with constant term 1 (31 coefficients), t = (mu (1 + alpha) / (mu + alpha))^0.3, alpha = r^2; max error 8.38e-4 over mu in [0, 1], r in [0, 1] against kiln's reference (kiln verify-fit); made by `kiln fit --ndf ggx --masking height-correlated --degrees 3,3/3,3`
float ggx_height_correlated_e_fit_p3_3_q3_3(float mu, float r) {
    float k = r * r;
    float t = pow(min(mu * (1.0 + k) / max(mu + k, 1e-30), 1.0), 0.3);
    float u = 2e0 * t - 1e0;
    float s = 2e0 * pow(r, 3.2) - 1e0;
    float n = 1.3154459e-1 + s * (2.7678668e-1 + s * (2.4338047e-1 + s * (9.6211426e-2)));
    n = n * u + -2.9218176e-1 + s * (-7.5316423e-1 + s * (-7.6243466e-1 + s * (-2.9945427e-1)));
    n = n * u + -1.4587557e-1 + s * (-1.7949186e-1 + s * (7.4473806e-2 + s * (1.0977165e-1)));
    n = n * u + 3.704071e-1 + s * (8.3130413e-1 + s * (6.0367674e-1 + s * (1.4102612e-1)));
    float d = 1.24706276e-1 + s * (1.8986632e-1 + s * (1.4774863e-1 + s * (9.028298e-2)));
    d = d * u + -6.0364407e-2 + s * (-6.7777896e-1 + s * (-7.395663e-1 + s * (-1.5846649e-1)));
    d = d * u + -9.231992e-1 + s * (-6.99819e-1 + s * (2.126726e-1 + s * (3.5755735e-2)));
    d = d * u + 1e0 + s * (1.4631759e0 + s * (5.604139e-1 + s * (7.81027e-2)));
    return 1e0 - t * t * n / d;
}

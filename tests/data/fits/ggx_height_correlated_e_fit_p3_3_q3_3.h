// E of ggx height-correlated (F = 1) as the rational 1 - t^2 P(u, s) / Q(u, s), P of degree 3 in u = 2 t - 1 and 3 in s = 2 r^3.2 - 1, Q of degrees 3 and 3 with constant term 1 (31 coefficients), t = (mu (1 + alpha) / (mu + alpha))^0.3, alpha = r^2; max error 8.38e-4 over mu in [0, 1], r in [0, 1] against kiln's reference (kiln verify-fit); made by `kiln fit --ndf ggx --masking height-correlated --degrees 3,3/3,3`
#pragma once
#include <math.h>
static inline float ggx_height_correlated_e_fit_p3_3_q3_3(float mu, float r) {
    const float k = r * r;
    const float t = powf(fminf(mu * (1.0f + k) / fmaxf(mu + k, 1e-30f), 1.0f), 0.3f);
    const float u = 2e0f * t - 1e0f;
    const float s = 2e0f * powf(r, 3.2f) - 1e0f;
    float n = 1.3154459e-1f + s * (2.7678668e-1f + s * (2.4338047e-1f + s * (9.6211426e-2f)));
    n = n * u + -2.9218176e-1f + s * (-7.5316423e-1f + s * (-7.6243466e-1f + s * (-2.9945427e-1f)));
    n = n * u + -1.4587557e-1f + s * (-1.7949186e-1f + s * (7.4473806e-2f + s * (1.0977165e-1f)));
    n = n * u + 3.704071e-1f + s * (8.3130413e-1f + s * (6.0367674e-1f + s * (1.4102612e-1f)));
    float d = 1.24706276e-1f + s * (1.8986632e-1f + s * (1.4774863e-1f + s * (9.028298e-2f)));
    d = d * u + -6.0364407e-2f + s * (-6.7777896e-1f + s * (-7.395663e-1f + s * (-1.5846649e-1f)));
    d = d * u + -9.231992e-1f + s * (-6.99819e-1f + s * (2.126726e-1f + s * (3.5755735e-2f)));
    d = d * u + 1e0f + s * (1.4631759e0f + s * (5.604139e-1f + s * (7.81027e-2f)));
    return 1e0f - t * t * n / d;
}

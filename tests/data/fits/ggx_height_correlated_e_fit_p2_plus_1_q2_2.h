// E of ggx height-correlated (F = 1) as the rational 1 - t^2 P(u, s) / Q(u, s), P = A(u) + B(s) (no cross terms) of degree 2 in u = 2 t - 1 and 1 in s = 2 r^3.2 - 1, Q of degrees 2 and 2 with constant term 1 (12 coefficients), t = (mu (1 + alpha) / (mu + alpha))^0.3, alpha = r^2; max error 9.18e-3 over mu in [0, 1], r in [0, 1] against kiln's reference (kiln verify-fit); made by `kiln fit --ndf ggx --masking height-correlated --degrees 2+1/2,2`
#pragma once
#include <math.h>
static inline float ggx_height_correlated_e_fit_p2_plus_1_q2_2(float mu, float r) {
    const float k = r * r;
    const float t = powf(fminf(mu * (1.0f + k) / fmaxf(mu + k, 1e-30f), 1.0f), 0.3f);
    const float u = 2e0f * t - 1e0f;
    const float s = 2e0f * powf(r, 3.2f) - 1e0f;
    float n = 1.3032663e-1f;
    n = n * u + -3.5413e-1f;
    n = n * u + 3.5354453e-1f + s * (1.3241081e-1f);
    float d = 6.6804785e-1f + s * (-9.254912e-1f + s * (6.659628e-1f));
    d = d * u + -1.3790286e0f + s * (1.4781656e0f + s * (-9.2926794e-1f));
    d = d * u + 1e0f + s * (-5.067203e-1f + s * (3.1160355e-1f));
    return 1e0f - t * t * n / d;
}

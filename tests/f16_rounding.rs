//! kiln's f16 storage (`kiln::format::f16`) against a rounding written here from the IEEE 754
//! definition, not through the `half` crate kiln uses: round to nearest, ties to even, directly
//! from f64 (one rounding), with f16's 11 significant bits, its subnormal spacing `2^-24` and
//! kiln's clamps (above 65504 to 65504, what would round to zero to `2^-24`). Ties, values one
//! f64 step either side of a tie (where rounding through f32 first rounds twice and can land
//! on the tie), subnormals and the range's edges.

use crate::f16_oracle;

use f16_oracle::oracle;
use kiln::format::f16::{MIN_SUBNORMAL, stored};

fn check(v: f64) {
    let want = oracle(v);
    let got = stored(v);
    assert!(
        got == want,
        "{v:e} ({:#018x}): kiln stores {got:e}, round-to-nearest-even gives {want:e}",
        v.to_bits()
    );
}

#[test]
fn ties_go_to_even_and_one_step_off_a_tie_goes_to_the_nearer() {
    // Ties between consecutive f16 values at several binades, and one f64 step either side.
    for exponent in [-24i32, -20, -15, -14, -13, -1, 0, 3, 10, 15] {
        let spacing = 2f64.powi((exponent - 10).max(-24));
        let base = if exponent <= -15 {
            0.0
        } else {
            2f64.powi(exponent)
        };
        for k in 0..8 {
            let tie = base + (f64::from(k) + 0.5) * spacing;
            for v in [
                tie,
                f64::from_bits(tie.to_bits() + 1),
                f64::from_bits(tie.to_bits() - 1),
            ] {
                check(v);
                check(-v);
            }
        }
    }
}

#[test]
fn random_values_round_as_the_definition_says() {
    let mut state = 0x243f_6a88_85a3_08d3u64;
    for _ in 0..200_000 {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        // Log-uniform over f16's range and a little beyond each end.
        let u = (state >> 11) as f64 / (1u64 << 53) as f64;
        let v = 2f64.powf(-27.0 + 44.0 * u);
        check(v);
    }
}

#[test]
fn the_range_edges_are_clamped_not_lost() {
    for v in [
        65504.0,
        65519.99,
        65520.0,
        1e300,
        2.9e-8,
        3.0e-8,
        1e-300,
        MIN_SUBNORMAL,
    ] {
        check(v);
        check(-v);
    }
}

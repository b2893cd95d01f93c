//! Uses the tables baked by `build.rs`: the generated constants and lookup functions.

include!(concat!(env!("OUT_DIR"), "/ggx-height-correlated-E.rs"));
include!(concat!(env!("OUT_DIR"), "/ggx-height-correlated-E_avg.rs"));

fn main() {
    let e = ggx_height_correlated_e_lookup(&GGX_HEIGHT_CORRELATED_E, 0.5, 0.5);
    let one_minus = ggx_height_correlated_e_lookup(&GGX_HEIGHT_CORRELATED_E_ONE_MINUS, 0.5, 0.5);
    println!("E(mu 0.5, r 0.5) = {e}, 1 - E = {one_minus}");
    println!("E_avg entries: {}", GGX_HEIGHT_CORRELATED_E_AVG.len());
}

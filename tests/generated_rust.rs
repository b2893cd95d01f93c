//! The committed Rust tables compile when `include!`d, and hold the JSON sidecar's values.

mod ggx {
    include!("../tables/ggx-height-correlated-E.rs");
    include!("../tables/ggx-height-correlated-E_avg.rs");
}

use kiln::format::json::Sidecar;

fn sidecar(name: &str) -> Sidecar {
    let path = format!("{}/tables/{name}.json", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn included_constants_match_the_sidecar() {
    let e = sidecar("ggx-height-correlated-E");
    let n = e.metadata.shape[1];
    for (k, &v) in e.data["E"].iter().enumerate() {
        assert_eq!(
            ggx::GGX_HEIGHT_CORRELATED_E[k / n][k % n],
            v as f32,
            "E texel {k}"
        );
    }
    for (k, &v) in e.data["one_minus_E"].iter().enumerate() {
        assert_eq!(
            ggx::GGX_HEIGHT_CORRELATED_ONE_MINUS_E[k / n][k % n],
            v as f32
        );
    }
    for (k, &v) in e.data["std_error"].iter().enumerate() {
        assert_eq!(
            ggx::GGX_HEIGHT_CORRELATED_E_STD_ERROR[k / n][k % n],
            v as f32
        );
    }
    for (k, &v) in e.metadata.axes[0].values.iter().enumerate() {
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_E_R[k], v as f32);
    }
    for (k, &v) in e.metadata.axes[1].values.iter().enumerate() {
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_E_MU[k], v as f32);
    }
    let avg = sidecar("ggx-height-correlated-E_avg");
    for (k, &v) in avg.data["E_avg"].iter().enumerate() {
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_E_AVG[k], v as f32);
    }
    for (k, &v) in avg.data["one_minus_E_avg"].iter().enumerate() {
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_ONE_MINUS_E_AVG[k], v as f32);
    }
    for (k, &v) in avg.data["std_error"].iter().enumerate() {
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_E_AVG_STD_ERROR[k], v as f32);
    }
    for (k, &v) in avg.metadata.axes[0].values.iter().enumerate() {
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_E_AVG_R[k], v as f32);
    }
}

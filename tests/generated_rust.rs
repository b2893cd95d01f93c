//! The committed Rust tables compile when `include!`d, hold the JSON sidecar's values, and their
//! generated lookup is within the error the sidecar states of the tests' own quadrature.

use crate::common;

#[allow(dead_code)] // the f_ms_norm file's ONE_MINUS, STD_ERROR and axis constants are not read here
mod ggx {
    include!("../tables/ggx-height-correlated-E.rs");
    include!("../tables/ggx-height-correlated-E_avg.rs");
    include!("../tables/ggx-height-correlated-f_ms_norm.rs");
}

use kiln::format::json::Sidecar;
use kiln::verify::input::read_kiln;
use kiln::verify::{AuditSettings, lookup_coordinates};

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
            ggx::GGX_HEIGHT_CORRELATED_E_ONE_MINUS[k / n][k % n],
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
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_E_AVG_ONE_MINUS[k], v as f32);
    }
    for (k, &v) in avg.data["std_error"].iter().enumerate() {
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_E_AVG_STD_ERROR[k], v as f32);
    }
    for (k, &v) in avg.metadata.axes[0].values.iter().enumerate() {
        assert_eq!(ggx::GGX_HEIGHT_CORRELATED_E_AVG_R[k], v as f32);
    }
}

/// The generated lookup functions give what the library's `Table::lookup` gives (in f32), at
/// every point `verify` audits: the same axis mapping, grid and clamping.
#[test]
fn generated_lookups_match_the_library_lookup() {
    let read = |name: &str| {
        let path = format!("{}/tables/{name}.json", env!("CARGO_MANIFEST_DIR"));
        read_kiln(std::path::Path::new(&path)).unwrap().unwrap()
    };
    let e = read("ggx-height-correlated-E");
    // f32 positions err by ~31 * 6e-8 of a texel; texel steps are below 0.1.
    let close = |got: f32, want: f64| (f64::from(got) - want).abs() < 2e-6;
    let points = lookup_coordinates(&e.spec, &AuditSettings::default());
    assert!(points.len() > 4000);
    for kiln::verify::Coordinates { alpha, mu, .. } in points {
        let (r, mu) = (alpha.sqrt(), mu.unwrap());
        let got =
            ggx::ggx_height_correlated_e_lookup(&ggx::GGX_HEIGHT_CORRELATED_E, mu as f32, r as f32);
        assert!(close(got, e.lookup(mu, r)), "E at mu {mu}, r {r}: {got}");
        let got = ggx::ggx_height_correlated_e_lookup(
            &ggx::GGX_HEIGHT_CORRELATED_E_ONE_MINUS,
            mu as f32,
            r as f32,
        );
        assert!(
            close(got, e.lookup_one_minus(mu, r)),
            "1 - E at mu {mu}, r {r}"
        );
    }
    let avg = read("ggx-height-correlated-E_avg");
    for kiln::verify::Coordinates { alpha, .. } in
        lookup_coordinates(&avg.spec, &AuditSettings::default())
    {
        let r = alpha.sqrt();
        let got =
            ggx::ggx_height_correlated_e_avg_lookup(&ggx::GGX_HEIGHT_CORRELATED_E_AVG, r as f32);
        assert!(close(got, avg.lookup(1.0, r)), "E_avg at r {r}");
    }
}

/// The generated `f_ms_norm` lookup gives back `1 - Ē`, as the library's `normalisation_lookup`
/// does (in f32), at 2000 roughness values: the multiplication by `r` included. A lookup that
/// forgot it would be off by a factor `1 / r`.
#[test]
fn generated_normalisation_lookup_matches_the_library() {
    use kiln::table::normalisation::normalisation_lookup;
    let path = format!(
        "{}/tables/ggx-height-correlated-f_ms_norm.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let norm = read_kiln(std::path::Path::new(&path)).unwrap().unwrap();
    for k in 0..=2000 {
        // Denser near 0, where 1 - Ē spans orders of magnitude.
        let r = (f64::from(k) / 2000.0).powi(2);
        let got = f64::from(ggx::ggx_height_correlated_f_ms_norm_lookup(
            &ggx::GGX_HEIGHT_CORRELATED_F_MS_NORM,
            r as f32,
        ));
        let want = normalisation_lookup(&norm, r);
        assert!(
            (got - want).abs() <= 1e-5 * want + 1e-12,
            "r {r}: {got} vs {want}"
        );
    }
}

/// The committed `E` table's generated lookup against the tests' own quadrature of `E`
/// (tests/common, accurate to 1e-9 for mu >= 0.02 and alpha >= 0.05), at every twentieth point
/// `verify` audits there: never further than the lookup error the sidecar states
/// (`lookup_fit.lookup_max_error`), plus f32's few 1e-7. The statement "never smaller than the
/// truth", checked by an integrator kiln does not use (the comparison with the JSON above only
/// shows that two of kiln's encoders agree).
#[test]
fn the_generated_lookup_is_within_its_stated_error_of_an_independent_integral() {
    let e = sidecar("ggx-height-correlated-E");
    let stated = e
        .metadata
        .lookup_fit
        .as_ref()
        .expect("the default table is fitted")
        .lookup_max_error;
    let path = format!(
        "{}/tables/ggx-height-correlated-E.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let table = read_kiln(std::path::Path::new(&path)).unwrap().unwrap();
    let points = lookup_coordinates(&table.spec, &AuditSettings::default());
    let mut worst = 0.0f64;
    let mut checked = 0;
    for kiln::verify::Coordinates { alpha, mu, .. } in points.into_iter().step_by(20) {
        let mu = mu.unwrap();
        if mu < 0.02 || alpha < 0.05 {
            continue;
        }
        let r = alpha.sqrt();
        let got = f64::from(ggx::ggx_height_correlated_e_lookup(
            &ggx::GGX_HEIGHT_CORRELATED_E,
            mu as f32,
            r as f32,
        ));
        let truth = common::reference_e(table.spec.model, alpha, mu);
        worst = worst.max((got - truth).abs());
        checked += 1;
    }
    assert!(checked > 100, "{checked} points");
    eprintln!("generated lookup: {worst:.3e} from the independent integral (stated {stated:.3e})");
    assert!(
        worst <= stated + 1e-6,
        "{worst:e} beyond the stated {stated:e}"
    );
}

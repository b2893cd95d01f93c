//! Dielectric (reflection plus transmission over the IOR) and `F_avg(eta)` tables: baked in
//! every format, read back, audited against the reference, looked up through the generated Rust.

use kiln::format::replace::Replace;
use kiln::format::{Format, Precision, write_tables};
use kiln::verify::input::read_kiln;
use kiln::verify::{Against, AuditSettings, audit};
use kiln::{BakeOptions, Fresnel, Quantity, Table};
use std::sync::OnceLock;

const MAX_ERROR: f64 = 1e-5;

/// One small bake of every dielectric quantity, shared by the tests.
fn tables() -> &'static [Table] {
    static TABLES: OnceLock<Vec<Table>> = OnceLock::new();
    TABLES.get_or_init(|| {
        BakeOptions {
            quantities: vec![
                Quantity::EDielectric,
                Quantity::EDielectricInside,
                Quantity::EAvgDielectric,
                Quantity::EAvgDielectricInside,
                Quantity::FAvg,
            ],
            size: 4,
            ior_size: 3,
            max_error: Some(MAX_ERROR),
            ..BakeOptions::default()
        }
        .bake(&|_| {})
        .expect("bake")
    })
}

fn table(quantity: Quantity) -> &'static Table {
    tables()
        .iter()
        .find(|t| t.spec.quantity == quantity)
        .expect("baked")
}

#[test]
fn shapes_axes_and_measured_errors() {
    let shapes: Vec<(Quantity, Vec<usize>)> = tables()
        .iter()
        .map(|t| (t.spec.quantity, t.spec.shape()))
        .collect();
    assert_eq!(
        shapes,
        [
            (Quantity::EDielectric, vec![3, 4, 4]),
            (Quantity::EDielectricInside, vec![3, 4, 4]),
            (Quantity::EAvgDielectric, vec![3, 4]),
            (Quantity::EAvgDielectricInside, vec![3, 4]),
            (Quantity::FAvg, vec![3]),
        ]
    );
    for t in tables() {
        let measured = t.node_errors.expect("confirmed against the reference");
        assert!(measured.max <= MAX_ERROR, "{}: {measured:?}", t.spec.id());
        // The IOR axis runs from 1 to 3; inside tables are computed at 1 / eta.
        let axis = t.spec.ior.expect("an IOR axis");
        assert_eq!(axis.value_at(0, 1.0, 1.0), 1.0);
        assert!((axis.value_at(2, 1.0, 1.0) - 3.0).abs() < 1e-12);
        let last = t.spec.len() - 1;
        let eta = t.spec.texel_eta(last).unwrap();
        let expected = if t.spec.quantity.from_inside() {
            1.0 / 3.0
        } else {
            3.0
        };
        assert!((eta - expected).abs() < 1e-12, "{}", t.spec.id());
    }
}

/// The hemispherical average `2 ∫ F(mu) mu dmu` of the unpolarised Fresnel reflectance of a
/// dielectric seen from the less dense side, in closed form (relative index `n > 1`; e.g.
/// d'Eon and Irving 2011, "A quantized-diffusion model for rendering translucent materials",
/// after Egan and Hilgeman 1979), written here independently of kiln's quadrature; checked in
/// Python against a 400000-point midpoint rule to 4e-9 at n = 1.1 to 3 (2026-12-07). From the
/// dense side (`eta = 1 / n`) energy conservation and reciprocity give
/// `1 - F_avg(1 / n) = (1 - F_avg(n)) / n^2`.
fn f_avg_closed_form(eta: f64) -> f64 {
    let outside = |n: f64| {
        let (n2, n4) = (n * n, n.powi(4));
        0.5 + (n - 1.0) * (3.0 * n + 1.0) / (6.0 * (n + 1.0).powi(2))
            + n2 * (n2 - 1.0).powi(2) / (n2 + 1.0).powi(3) * ((n - 1.0) / (n + 1.0)).ln()
            - 2.0 * n.powi(3) * (n2 + 2.0 * n - 1.0) / ((n2 + 1.0) * (n4 - 1.0))
            + 8.0 * n4 * (n4 + 1.0) / ((n2 + 1.0) * (n4 - 1.0).powi(2)) * n.ln()
    };
    if eta >= 1.0 {
        outside(eta)
    } else {
        1.0 - (1.0 - outside(1.0 / eta)) * eta * eta
    }
}

/// `F_avg(eta)` at each axis value against the closed form (its terms cancel near `eta = 1`,
/// where it holds only to about 1e-7 at `eta = 1.01`), and the smooth row (`r = 0`) of the
/// average tables holds 1 (no energy lost by a smooth interface).
#[test]
fn f_avg_and_the_smooth_limit() {
    let f_avg = table(Quantity::FAvg);
    for k in 0..f_avg.spec.len() {
        let eta = f_avg.spec.texel_eta(k).unwrap();
        let n = eta.max(1.0 / eta);
        if n == 1.0 {
            assert_eq!(f_avg.value[k], 0.0, "eta 1: an interface that is not there");
            continue;
        }
        let expected = f_avg_closed_form(eta);
        let tolerance = if n >= 1.05 { 1e-12 } else { 1e-6 };
        assert!(
            (f_avg.value[k] - expected).abs() < tolerance,
            "eta {eta}: {} vs {expected}",
            f_avg.value[k]
        );
        assert!((f_avg.one_minus_value[k] - (1.0 - expected)).abs() < tolerance);
    }
    // Beyond the table's axis values, the function the bake calls, at both sides.
    for eta in [1.05, 1.2, 1.33, 1.5, 2.0, 2.5, 3.0] {
        for e in [eta, 1.0 / eta] {
            let got = Fresnel::Dielectric { eta: e }.average()[0];
            let want = f_avg_closed_form(e);
            assert!((got - want).abs() < 1e-12, "eta {e}: {got} vs {want}");
        }
    }
    for quantity in [Quantity::EAvgDielectric, Quantity::EAvgDielectricInside] {
        let t = table(quantity);
        for slice in 0..3 {
            assert_eq!(t.value[slice * 4], 1.0, "{quantity:?} slice {slice}");
        }
    }
}

/// Every format a dielectric table is written in reads back (through the same reader `verify`
/// uses) with the values, the spec and a description that says what the channels hold.
#[test]
fn every_format_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let formats = [
        Format::Exr,
        Format::Bin,
        Format::Json,
        Format::Rs,
        Format::Png,
    ];
    write_tables(
        dir.path(),
        tables(),
        &formats,
        Precision::F32,
        Replace::Refuse,
    )
    .unwrap();
    for t in tables() {
        let id = t.spec.id();
        for ext in ["exr", "bin", "json"] {
            let path = dir.path().join(format!("{id}.{ext}"));
            let back = read_kiln(&path)
                .unwrap_or_else(|e| panic!("{id}.{ext}: {e}"))
                .expect("a kiln table");
            assert_eq!(back.spec, t.spec, "{id}.{ext}");
            for (k, (&a, &b)) in back.value.iter().zip(&t.value).enumerate() {
                // f32 storage except the JSON's f64.
                let tolerance = if ext == "json" { 0.0 } else { 6e-8 };
                assert!(
                    (a - b).abs() <= tolerance,
                    "{id}.{ext} texel {k}: {a} vs {b}"
                );
            }
        }
        let sidecar = std::fs::read_to_string(dir.path().join(format!("{id}.json"))).unwrap();
        let meta: serde_json::Value = serde_json::from_str(&sidecar).unwrap();
        let description = meta["description"].as_str().unwrap();
        assert!(
            description.contains("relative index"),
            "{id}: {description}"
        );
        if t.spec.quantity.from_inside() {
            assert!(description.contains("1 / eta"), "{id}: {description}");
        }
        assert_eq!(meta["axes"][0]["name"], "eta");
        // 3-D tables' images are their eta slices stacked; 1-D tables have no heat map.
        assert_eq!(
            dir.path().join(format!("{id}.png")).exists(),
            t.spec.shape().len() > 1
        );
    }
}

/// The audit `kiln verify` runs: stored values within the bake's max error of the reference,
/// and the lookup at every node returns the node's value.
#[test]
fn audit_against_the_reference() {
    for quantity in [Quantity::EDielectricInside, Quantity::EAvgDielectric] {
        let t = table(quantity);
        let report = audit(
            t,
            &Against::Reference(kiln::integrate::reference::ReferenceSettings {
                tolerance: 1e-8,
                ..Default::default()
            }),
            &AuditSettings {
                density: 1,
                ..AuditSettings::default()
            },
            &|_| {},
        );
        assert!(report.reference_converged);
        assert!(report.node_max_error <= MAX_ERROR, "{report:?}");
        assert_eq!(report.nodes, t.spec.len());
        // Lookups are compared too, with the IOR on every point.
        assert!(report.worst_lookup.eta.is_some());
    }
    let t = table(Quantity::EDielectric);
    for k in 0..t.spec.len() {
        let (alpha, mu) = t.spec.texel_coordinates(k);
        let eta = t.spec.texel_eta(k).unwrap();
        let [i, r, _] = t.spec.texel_indices(k);
        if r == Some(0) || i == Some(0) {
            // The r = 0 row holds the limit alpha -> 0+, the eta = 1 slice the limit eta -> 1+
            // (kiln's glass layout): each computed a little off its coordinate.
            continue;
        }
        let roughness = alpha.sqrt();
        let got = t.lookup_eta(mu.unwrap(), roughness, eta);
        assert!(
            (got - t.value[k]).abs() < 1e-12,
            "texel {k}: {got} vs {}",
            t.value[k]
        );
    }
}

/// The generated Rust source compiles and its lookup (f32) agrees with `Table::lookup_eta`.
#[test]
fn generated_rust_lookup_matches_the_library() {
    let dir = tempfile::tempdir().unwrap();
    write_tables(
        dir.path(),
        tables(),
        &[Format::Rs],
        Precision::F32,
        Replace::Refuse,
    )
    .unwrap();
    let points = [
        (0.3, 0.5, 1.2),
        (0.05, 0.9, 2.7),
        (0.8, 0.1, 1.0 / 1.4),
        (1.0, 1.0, 3.0),
        // Near eta = 1, where the glass layout's coordinates bend: from both sides, at grazing.
        (0.001, 0.2, 1.001),
        (0.0, 0.6, 1.0 / 1.0005),
        (0.02, 0.05, 1.00002),
    ];
    let mut main = String::new();
    for t in tables() {
        main += &format!(
            "mod m{} {{ include!(\"{}.rs\"); }}\n",
            t.spec.quantity.cli_name().replace('-', "_"),
            t.spec.id()
        );
    }
    main += "fn main() {\n";
    for t in tables() {
        let module = format!("m{}", t.spec.quantity.cli_name().replace('-', "_"));
        let name = kiln::format::rust::lookup_name(t);
        let constant = kiln::format::rust::const_prefix(t);
        for (mu, r, eta) in points {
            let args = match (t.spec.mu.is_some(), t.spec.roughness.is_some()) {
                (true, _) => format!("{mu:?}, {r:?}, {eta:?}"),
                (false, true) => format!("{r:?}, {eta:?}"),
                (false, false) => format!("{eta:?}"),
            };
            main += &format!(
                "    println!(\"{{}}\", {module}::{name}(&{module}::{constant}, {args}));\n"
            );
        }
    }
    main += "}\n";
    std::fs::write(dir.path().join("main.rs"), main).unwrap();
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let exe = dir.path().join("lookup");
    let status = std::process::Command::new(rustc)
        .args(["--edition", "2024", "-O", "-A", "warnings", "-o"])
        .arg(&exe)
        .arg(dir.path().join("main.rs"))
        .status()
        .expect("rustc runs");
    assert!(status.success(), "the generated Rust does not compile");
    let output = std::process::Command::new(&exe).output().unwrap();
    let printed: Vec<f64> = String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    let mut k = 0;
    for t in tables() {
        for (mu, r, eta) in points {
            // The generated lookup takes f32: near eta = 1 its rounding moves eta - 1 by 1e-5
            // relative, and the glass layout's eta layer with it.
            let f32_of = |x: f64| f64::from(x as f32);
            let expected = t.lookup_eta(f32_of(mu), f32_of(r), f32_of(eta));
            // f32 arithmetic on f32-rounded values: a few ulps of 1.
            assert!(
                (printed[k] - expected).abs() < 1e-6,
                "{} at {mu} {r} {eta}: generated {} vs library {expected}",
                t.spec.id(),
                printed[k]
            );
            k += 1;
        }
    }
}

//! `kiln verify --preset` on the files engines really ship, vendored byte for byte under
//! `tests/data/engines/` (origin, commit, licence and layout in `tests/data/engines/SOURCES.md`).
//!
//! These are the independent check of the preset layouts: a table another project computed with
//! its own code lines up with kiln's reference at every node, to the level of that project's own
//! sampling or printing, only if kiln reads its axes, order, grid and channels as the engine does.
//! A flipped or transposed reading gives node errors of 0.45 to 1.

#![cfg(feature = "cli")]

use serde_json::Value;
use std::path::PathBuf;

use crate::command;
use crate::external;
use command::kiln;

fn engine_file(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/engines")
        .join(path)
}

/// Runs `kiln verify --json` and returns one report per audited channel (JSON lines).
fn audit(args: &[&str]) -> Vec<Value> {
    let mut all = vec!["verify", "--json"];
    all.extend_from_slice(args);
    let output = kiln(&all);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|line| serde_json::from_str(line).unwrap())
        .collect()
}

fn field(report: &Value, name: &str) -> f64 {
    report[name]
        .as_f64()
        .unwrap_or_else(|| panic!("no {name} in {report}"))
}

/// Blender's `shader.tables`: `table_ggx_E` (mu-major nodes) and `table_ggx_Eavg`. Printed with 6
/// decimals (rounding up to 5e-7) from 2^23 QMC samples per entry, so its nodes agree with the
/// reference to about 1e-6; its linear mu axis misses the grazing layer between the nodes.
/// Blender computed its first row and column at 1e-4: `verify --preset cycles` knows it (the
/// default clamp for a Cycles file kiln did not write), so no flag is needed for a clean audit.
#[test]
fn blender_cycles_shader_tables() {
    let file = engine_file("cycles/shader.tables");
    // The glass arrays' audit takes minutes: tests/cycles_glass.rs checks them at a spread of
    // entries.
    let reports = audit(&[
        "--preset",
        "cycles",
        file.to_str().unwrap(),
        "--only",
        "e,e-avg",
    ]);
    assert_eq!(
        reports[0]["clamp_min"].as_f64(),
        Some(1e-4),
        "{}",
        reports[0]
    );
    assert_eq!(reports.len(), 2, "{reports:?}");
    let (e, e_avg) = (&reports[0], &reports[1]);
    assert_eq!(
        (e["quantity"].as_str(), e_avg["quantity"].as_str()),
        (Some("E"), Some("E_avg"))
    );
    assert!(field(e, "node_max_error") < 2e-6, "{e}");
    assert!(field(e, "node_rms_error") < 5e-7, "{e}");
    assert!(field(e_avg, "node_max_error") < 1e-6, "{e_avg}");
    // Between the nodes a linear mu axis misses the boundary layer at mu ~ alpha.
    assert!(field(e, "lookup_max_error") > 1e-2, "{e}");
    let worst = &e["worst_lookup"];
    assert!(
        field(worst, "mu") < 1.0 / 31.0 && field(worst, "roughness") < 0.25,
        "{worst}"
    );
}

/// Where Blender's own `ggx_E` departs from its nodes: the first row (mu = 0) and column (r =
/// 0) were computed at 1e-4, not at 0. Read at the nodes themselves (`--clamp-min 0`) its worst
/// node is on that row, about 2e-2 off; everywhere else it is right to 2e-6 (above).
#[test]
fn blender_s_first_row_is_computed_at_1e_4() {
    let file = engine_file("cycles/shader.tables");
    let reports = audit(&[
        "--preset",
        "cycles",
        file.to_str().unwrap(),
        "--clamp-min",
        "0",
        "--density",
        "1",
        "--only",
        "e",
    ]);
    let e = &reports[0];
    assert_eq!(e["quantity"], "E");
    let max = field(e, "node_max_error");
    assert!(max > 1e-2 && max < 3e-2, "{e}");
    assert_eq!(field(&e["worst_node"], "mu"), 0.0, "{e}");
}

/// Bevy's `dfg.ktx2` (zstd-supercompressed RG16F, 64 x 64, scale and bias). Its own Monte Carlo
/// is about 6e-3 low in the NdotV = 1/128 column (scale); the bias is right to 5e-4.
#[test]
fn bevy_dfg_ktx2() {
    let file = engine_file("bevy/dfg.ktx2");
    let reports = audit(&["--preset", "bevy", file.to_str().unwrap()]);
    assert_eq!(reports.len(), 2, "{reports:?}");
    let (scale, bias) = (&reports[0], &reports[1]);
    assert_eq!(scale["quantity"], "E_scale");
    assert_eq!(bias["quantity"], "E_bias");
    assert!(field(scale, "node_max_error") < 1e-2, "{scale}");
    assert!(field(scale, "node_rms_error") < 1e-3, "{scale}");
    assert!(field(bias, "node_max_error") < 1e-3, "{bias}");
    assert!(field(bias, "node_rms_error") < 1e-4, "{bias}");
    assert!(field(&scale["worst_node"], "mu") < 0.01, "{scale}");
}

/// three.js' `DFGLUTData.js` (16 x 16 half bits, transposed: roughness across, NdotV down).
#[test]
fn three_dfg_lut_data() {
    let file = engine_file("three/DFGLUTData-16.js");
    let reports = audit(&["--preset", "three", file.to_str().unwrap()]);
    assert_eq!(reports.len(), 2, "{reports:?}");
    let (scale, bias) = (&reports[0], &reports[1]);
    assert_eq!(scale["shape"], serde_json::json!([16, 16]));
    assert!(field(scale, "node_max_error") < 2e-2, "{scale}");
    assert!(field(scale, "node_rms_error") < 3e-3, "{scale}");
    assert!(field(bias, "node_max_error") < 1e-3, "{bias}");
    assert!(field(bias, "node_rms_error") < 1e-4, "{bias}");
}

/// The 32 x 32 `DFGLUTData.js` of three r181 reads with the same preset, its size taken from
/// the file (and checked against the `DataTexture` it builds).
#[test]
fn three_dfg_lut_data_of_r181() {
    let file = engine_file("three/DFGLUTData-32.js");
    let reports = audit(&["--preset", "three", file.to_str().unwrap()]);
    assert_eq!(reports.len(), 2, "{reports:?}");
    let (scale, bias) = (&reports[0], &reports[1]);
    assert_eq!(scale["shape"], serde_json::json!([32, 32]));
    assert!(field(scale, "node_max_error") < 2.5e-2, "{scale}");
    assert!(field(scale, "node_rms_error") < 3.5e-3, "{scale}");
    assert!(field(bias, "node_max_error") < 1.1e-3, "{bias}");
    assert!(field(bias, "node_rms_error") < 1.2e-4, "{bias}");
}

/// Where three's tables are wrong: in their most grazing rows of NdotV (its 4096 samples per
/// texel meet the grazing layer there), not elsewhere, node by node against the reference.
/// Per-row maxima of the scale channel measured (reference at 1e-8): 16 x 16: 1.4e-2, 5.8e-3,
/// then at most 2.7e-3; 32 x 32: 1.9e-2, 1.1e-2, 7.3e-3, then falling to ~4e-4.
#[test]
fn three_s_errors_sit_in_its_grazing_rows() {
    use kiln::integrate::reference::ReferenceSettings;
    use kiln::preset::Preset;
    for (name, grazing_row, other_rows) in [
        ("three/DFGLUTData-16.js", (1e-2, 2e-2), 3.5e-3),
        ("three/DFGLUTData-32.js", (1.5e-2, 2.5e-2), 9e-3),
    ] {
        let bytes = std::fs::read(engine_file(name)).unwrap();
        let scale = Preset::Three.read_tables(&bytes, name).unwrap().remove(0);
        let n = scale.spec.shape()[1];
        let mut row_max = vec![0.0_f64; n];
        for k in 0..scale.spec.len() {
            let (alpha, mu) = scale.spec.texel_coordinates(k);
            let settings = ReferenceSettings {
                tolerance: 1e-8,
                ..ReferenceSettings::default()
            };
            let truth = scale.spec.integral().reference(
                kiln::integrate::value::Point {
                    alpha,
                    mu,
                    eta: None,
                },
                &settings,
            );
            row_max[k % n] = row_max[k % n].max((scale.value[k] - truth.value).abs());
        }
        assert!(
            row_max[0] > grazing_row.0 && row_max[0] < grazing_row.1,
            "{name}: {row_max:?}"
        );
        assert!(row_max[1] < row_max[0], "{name}: {row_max:?}");
        let rest = row_max[2..].iter().copied().fold(0.0, f64::max);
        assert!(
            rest < other_rows && rest < row_max[1],
            "{name}: {row_max:?}"
        );
    }
}

/// kiln's `DFGLUTData.js` replaces three's as is: line for line the same module (imports, the
/// private `DATA`, `getDFGLUT()` building the same `DataTexture`) but for the header comment
/// and the numbers, one row of texels per line. `node --check` parses it where node is
/// installed.
#[test]
fn kiln_s_three_module_has_the_shape_three_ships() {
    let dir = tempfile::tempdir().unwrap();
    let baked = kiln(&[
        "bake",
        "--preset",
        "three",
        "-q",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(baked.status.success());
    let ours = std::fs::read_to_string(dir.path().join("DFGLUTData.js")).unwrap();
    let theirs = std::fs::read_to_string(engine_file("three/DFGLUTData-16.js")).unwrap();
    // Past the header comment, the lines that hold no numbers.
    let code = |text: &str| -> Vec<String> {
        text[text.find("*/").unwrap()..]
            .lines()
            .filter(|l| !l.trim_start().starts_with("0x"))
            .map(str::to_string)
            .collect()
    };
    assert_eq!(code(&ours), code(&theirs));
    // As many number lines (rows) holding as many numbers.
    let rows = |text: &str| -> Vec<usize> {
        text.lines()
            .filter(|l| l.trim_start().starts_with("0x"))
            .map(|l| l.matches("0x").count())
            .collect()
    };
    assert_eq!(rows(&ours), rows(&theirs));
    assert!(ours.contains("export function getDFGLUT()") && !ours.contains("export const"));
    if let Some(node) = external::node_or_skip("node --check of kiln's DFGLUTData.js")
        && let Ok(output) = std::process::Command::new(node)
            .arg("--check")
            .arg(dir.path().join("DFGLUTData.js"))
            .output()
    {
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
}

/// The numbers of the C float array `name` in Blender's `shader.tables`.
fn c_array(text: &str, name: &str) -> Vec<f64> {
    let at = text
        .find(&format!("{name}["))
        .unwrap_or_else(|| panic!("no {name}"));
    let open = at + text[at..].find('{').unwrap();
    let close = open + text[open..].find('}').unwrap();
    text[open + 1..close]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('f').parse::<f64>().unwrap())
        .collect()
}

/// Blender's glass tables are kiln's dielectric albedo in Cycles' convention
/// ([`kiln::model::dielectric::TransmissionConvention::Cycles`]: a refraction that ends on the
/// incident side kept, an index within 1e-4 of 1 smooth), to within 2e-5 at every entry checked
/// (`glass_E` at `eta = ior`, `glass_inv_E` at `eta = 1 / ior`, Cycles' axes: `ior = (1 + z^2) /
/// (1 - z^2)` with `z = k / 15` clamped to [1e-4, 0.99], `mu` and `r` on nodes `k / 15` clamped to
/// at least 1e-4). In kiln's single-scattering convention `glass_inv_E` differs by more than 0.3
/// somewhere: the convention, not the numerics, is what separates them.
#[test]
fn blender_s_glass_tables_are_kiln_s_in_cycles_convention() {
    use kiln::integrate::dielectric::{
        reference_dielectric_albedo_with, reference_dielectric_average_albedo_with,
    };
    use kiln::integrate::reference::ReferenceSettings;
    use kiln::model::dielectric::TransmissionConvention;
    use rayon::prelude::*;
    let text = std::fs::read_to_string(engine_file("cycles/shader.tables")).unwrap();
    let model = kiln::Model {
        ndf: kiln::Ndf::Ggx,
        masking: kiln::Masking::HeightCorrelated,
    };
    let settings = ReferenceSettings {
        tolerance: 1e-6,
        ..ReferenceSettings::default()
    };
    let node = |k: usize| (k as f64 / 15.0).max(1e-4);
    let eta = |z_index: usize, inside: bool| {
        let z = (z_index as f64 / 15.0).clamp(1e-4, 0.99);
        let ior = (1.0 + z * z) / (1.0 - z * z);
        if inside { 1.0 / ior } else { ior }
    };
    let worst = |name: &str, inside: bool, convention: TransmissionConvention| -> f64 {
        let table = c_array(&text, name);
        let averages = table.len() == 256;
        let stride = if averages { 7 } else { 97 };
        (0..table.len())
            .into_par_iter()
            .step_by(stride)
            .map(|k| {
                let value = if averages {
                    let r = node(k % 16);
                    reference_dielectric_average_albedo_with(
                        model,
                        r * r,
                        eta(k / 16, inside),
                        convention,
                        &settings,
                    )
                    .value()
                } else {
                    let r = node(k % 16);
                    reference_dielectric_albedo_with(
                        model,
                        r * r,
                        node((k / 16) % 16),
                        eta(k / 256, inside),
                        convention,
                        &settings,
                    )
                    .value()
                };
                (value - table[k]).abs()
            })
            .reduce(|| 0.0, f64::max)
    };
    let cycles = TransmissionConvention::Cycles;
    for (name, inside) in [
        ("table_ggx_glass_E", false),
        ("table_ggx_glass_inv_E", true),
        ("table_ggx_glass_Eavg", false),
        ("table_ggx_glass_inv_Eavg", true),
    ] {
        let error = worst(name, inside, cycles);
        assert!(error < 2e-5, "{name}: {error:e}");
    }
    let single = worst(
        "table_ggx_glass_inv_E",
        true,
        TransmissionConvention::SingleScattering,
    );
    assert!(single > 0.3, "{single}");
}

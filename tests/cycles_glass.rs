//! Cycles' glass tables (issue 21, item 1): `kiln bake --preset cycles` writes all of Blender's
//! `shader.tables` arrays in Blender's own indexing (checked by this file's own indexing, not
//! kiln's), the file compiles as C++ the way Cycles includes it with the names and sizes
//! Blender declares, `--carry-over` copies `table_sheen_ltc` verbatim, `verify --preset cycles`
//! reads Blender's glass arrays on Blender's axes, and a table's transmission convention is
//! part of its spec: recorded in its files and used by its audit.

use kiln::integrate::reference::ReferenceSettings;
use kiln::integrate::value::Point;
use kiln::model::dielectric::TransmissionConvention;
use kiln::preset::Preset;
use kiln::{BakeOptions, Quantity, Table, TableSpec};
use std::path::PathBuf;

use crate::cxx;

fn engine_file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/engines")
        .join(name)
}

/// The numbers between the braces after `name[` (this file's own reader).
fn c_numbers(text: &str, name: &str) -> Vec<f64> {
    let start = text.find(&format!("{name}[")).expect(name);
    let open = start + text[start..].find('{').unwrap();
    let close = open + text[open..].find('}').unwrap();
    text[open + 1..close]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| f64::from(s.trim_end_matches('f').parse::<f32>().unwrap()))
        .collect()
}

/// Every `static const float NAME[N]` a file declares, in order.
fn declarations(text: &str) -> Vec<(String, usize)> {
    text.match_indices("static const float ")
        .map(|(at, prefix)| {
            let rest = &text[at + prefix.len()..];
            let open = rest.find('[').unwrap();
            let close = rest.find(']').unwrap();
            (
                rest[..open].to_string(),
                rest[open + 1..close].parse().unwrap(),
            )
        })
        .collect()
}

/// A table of `spec` whose texel `k` holds a value that names `k` (distinct, in [0, 1], exact
/// in f32), so that the file's index of each texel can be read back.
fn numbered(spec: TableSpec) -> Table {
    let n = spec.len();
    let value: Vec<f64> = (0..n).map(|k| k as f64 / 8192.0).collect();
    Table {
        one_minus_value: value.iter().map(|v| 1.0 - v).collect(),
        std_error: vec![0.0; n],
        value,
        spec,
        command: "test".into(),
        node_errors: None,
        requested_max_error: None,
        lookup_fit: None,
    }
}

/// Every table of the Cycles preset, numbered ([`numbered`]); `f_ms_norm` is left out (it is
/// written to a file of its own).
fn numbered_cycles_tables() -> Vec<Table> {
    Preset::Cycles
        .bakes(None)
        .iter()
        .flat_map(|o| o.resolved().specs())
        .filter(|s| s.quantity != Quantity::FMsNorm)
        .map(numbered)
        .collect()
}

/// Blender's glass axes (`precompute.cpp`): `z = clamp(k / 15, 1e-4, 0.99)`, `ior = (1 + z^2) /
/// (1 - z^2)`, `mu` and `r` on nodes `k / 15`; the `_inv_` tables at `1 / ior`.
fn blender_eta(z_index: usize, inside: bool) -> f64 {
    let z = (z_index as f64 / 15.0).clamp(1e-4, 0.99);
    let ior = (1.0 + z * z) / (1.0 - z * z);
    if inside { 1.0 / ior } else { ior }
}

const GLASS: [(&str, Quantity); 4] = [
    ("table_ggx_glass_E", Quantity::EDielectric),
    ("table_ggx_glass_Eavg", Quantity::EAvgDielectric),
    ("table_ggx_glass_inv_E", Quantity::EDielectricInside),
    ("table_ggx_glass_inv_Eavg", Quantity::EAvgDielectricInside),
];

#[test]
fn glass_arrays_sit_where_blender_indexes_them_on_blender_s_axes() {
    let tables = numbered_cycles_tables();
    let text = String::from_utf8(Preset::Cycles.encode(&tables).unwrap()).unwrap();
    for (name, quantity) in GLASS {
        let table = tables.iter().find(|t| t.spec.quantity == quantity).unwrap();
        let spec = &table.spec;
        assert_eq!(spec.transmission, TransmissionConvention::Cycles, "{name}");
        let flat = c_numbers(&text, name);
        let inside = quantity.from_inside();
        if quantity.has_mu() {
            assert_eq!(flat.len(), 4096, "{name}");
            for z in 0..16 {
                for r in 0..16 {
                    for m in 0..16 {
                        let k = (z * 16 + r) * 16 + m;
                        // Blender: index = z * 256 + mu * 16 + r.
                        assert_eq!(flat[z * 256 + m * 16 + r], table.value[k], "{name} {k}");
                        let (alpha, mu) = spec.texel_coordinates(k);
                        assert_eq!(mu, Some(m as f64 / 15.0));
                        assert!((alpha - (r as f64 / 15.0).powi(2)).abs() < 1e-15);
                        let eta = spec.texel_eta(k).unwrap();
                        assert!(
                            (eta / blender_eta(z, inside) - 1.0).abs() < 1e-14,
                            "{name} {k}"
                        );
                    }
                }
            }
        } else {
            assert_eq!(flat.len(), 256, "{name}");
            for z in 0..16 {
                for r in 0..16 {
                    // Blender: index = z * 16 + r.
                    let k = z * 16 + r;
                    assert_eq!(flat[k], table.value[k], "{name} {k}");
                    let eta = spec.texel_eta(k).unwrap();
                    assert!(
                        (eta / blender_eta(z, inside) - 1.0).abs() < 1e-14,
                        "{name} {k}"
                    );
                }
            }
        }
    }
    // Read back as `verify --preset cycles` reads it: the four glass tables on the same specs.
    let back = Preset::Cycles.read_tables(text.as_bytes(), "test").unwrap();
    for (name, quantity) in GLASS {
        let ours = tables.iter().find(|t| t.spec.quantity == quantity).unwrap();
        let read = back
            .iter()
            .find(|t| t.spec.quantity == quantity)
            .expect(name);
        assert_eq!(
            (&read.spec, &read.value),
            (&ours.spec, &ours.value),
            "{name}"
        );
    }
}

/// Cycles includes `shader.tables` outside its namespace (the file opens and closes it), so
/// kiln's must compile that way, declaring exactly Blender's arrays with Blender's sizes; with
/// `--carry-over` the LTC table holds Blender's numbers.
#[test]
fn kiln_s_shader_tables_compiles_as_cycles_includes_it() {
    let blender = std::fs::read_to_string(engine_file("cycles/shader.tables")).unwrap();
    let carried = Preset::Cycles
        .carried_from(blender.as_bytes(), "Blender's shader.tables")
        .unwrap()
        .expect("cycles carries table_sheen_ltc");
    let files = Preset::Cycles
        .files_carrying(&numbered_cycles_tables(), None, Some(&carried))
        .unwrap();
    let text = String::from_utf8(files[0].1.clone()).unwrap();
    assert_eq!(declarations(&text), declarations(&blender));
    // The LTC numbers are Blender's, bit for bit as the compiler stores them (negative zeros
    // included), re-emitted by kiln: nothing but the declaration and numbers between its braces.
    let ltc = |t: &str| -> Vec<u32> {
        let at = t
            .find("static const float table_sheen_ltc[3072] = {")
            .unwrap();
        let body = &t[at + 45..at + t[at..].find("};").unwrap()];
        body.split(',')
            .map(|s| s.trim().trim_end_matches('f'))
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.parse::<f32>()
                    .unwrap_or_else(|_| panic!("{s:?}"))
                    .to_bits()
            })
            .collect()
    };
    assert_eq!(ltc(&blender).len(), 3072);
    assert_eq!(ltc(&text), ltc(&blender));
    // A file whose array is not numbers of its declared size is refused, not copied.
    for bad in [
        "static const float table_sheen_ltc[3] = { 1.0f, 2.0f };",
        "static const float table_sheen_ltc[2] = { 1.0f, 2.0f\n#include <x>\n };",
    ] {
        let message = Preset::Cycles
            .carried_from(bad.as_bytes(), "bad")
            .unwrap_err()
            .to_string();
        assert!(message.contains("declared size"), "{message}");
    }
    // Without it, the file says what to keep.
    let plain =
        String::from_utf8(Preset::Cycles.encode(&numbered_cycles_tables()).unwrap()).unwrap();
    assert!(!plain.contains("table_sheen_ltc["));
    assert!(plain.contains("keep Blender's"), "{}", &plain[..600]);

    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("shader.tables"), &text).unwrap();
    let mut source = String::from(
        "#define CCL_NAMESPACE_BEGIN namespace ccl {\n#define CCL_NAMESPACE_END }\n\
         #include \"shader.tables\"\n",
    );
    for (name, size) in declarations(&blender) {
        source.push_str(&format!(
            "static_assert(sizeof(ccl::{name}) == {size} * sizeof(float), \"{name}\");\n"
        ));
    }
    source.push_str("int main() { return 0; }\n");
    std::fs::write(dir.path().join("check.cpp"), source).unwrap();
    let Some(compiler) = cxx::compiler_or_skip("compiling Blender's declarations") else {
        return;
    };
    let out = std::process::Command::new(compiler)
        .current_dir(dir.path())
        .args([
            "-std=c++11",
            "-fsyntax-only",
            "-Wall",
            "-Werror",
            "check.cpp",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `verify --preset cycles` reads Blender's four glass arrays on Blender's axes in Cycles'
/// convention: at a spread of entries each is kiln's reference there (with Cycles' clamp of
/// `mu` and `r` to 1e-4) within 2e-5. A wrong IOR axis, a transposed slice or the
/// single-scattering convention is off by 1e-2 to 0.9 somewhere.
#[test]
fn blender_s_glass_arrays_are_read_on_blender_s_axes_in_its_convention() {
    use rayon::prelude::*;
    let bytes = std::fs::read(engine_file("cycles/shader.tables")).unwrap();
    let tables = Preset::Cycles.read_tables(&bytes, "Blender").unwrap();
    assert_eq!(tables.len(), 6);
    let settings = ReferenceSettings {
        tolerance: 1e-6,
        ..ReferenceSettings::default()
    };
    let worst = |table: &Table, convention: TransmissionConvention, stride: usize| {
        let integral = kiln::integrate::value::Integral {
            transmission: convention,
            ..table.spec.integral()
        };
        (0..table.spec.len())
            .into_par_iter()
            .step_by(stride)
            .map(|k| {
                let (alpha, mu) = table.spec.texel_coordinates(k);
                let at = Point {
                    alpha: alpha.max(1e-8),
                    mu: mu.map(|m| m.max(1e-4)),
                    eta: table.spec.texel_eta(k),
                };
                (integral.reference(at, &settings).value - table.value[k]).abs()
            })
            .reduce(|| 0.0, f64::max)
    };
    for (name, quantity) in GLASS {
        let table = tables
            .iter()
            .find(|t| t.spec.quantity == quantity)
            .expect(name);
        let stride = if quantity.has_mu() { 67 } else { 9 };
        let error = worst(table, table.spec.transmission, stride);
        assert!(error < 2e-5, "{name}: {error:e}");
    }
    let inside = tables
        .iter()
        .find(|t| t.spec.quantity == Quantity::EDielectricInside)
        .unwrap();
    let single = worst(inside, TransmissionConvention::SingleScattering, 67);
    assert!(single > 0.1, "{single}");
}

/// The convention is part of a table's spec: named in its id, written to its JSON (spec and
/// metadata) and read back, and the audit's reference uses it. A Cycles-convention table of
/// light from inside passes its own audit and fails one in the single-scattering convention.
#[test]
fn a_table_s_transmission_convention_travels_with_it_and_drives_its_audit() {
    let options = BakeOptions {
        quantities: vec![Quantity::EDielectricInside],
        size: 3,
        ior_size: 3,
        transmission: TransmissionConvention::Cycles,
        max_error: Some(1e-4),
        ..BakeOptions::default()
    };
    let table = options.bake(&|_| {}).unwrap().remove(0);
    assert!(
        table.spec.id().contains("transmission-cycles"),
        "{}",
        table.spec.id()
    );
    let json = kiln::format::json::encode(&kiln::format::json::sidecar(
        &table,
        "f32",
        Default::default(),
    ))
    .unwrap();
    let text = String::from_utf8(json.clone()).unwrap();
    assert!(text.contains("\"transmission\": \"cycles\""), "spec field");
    assert!(text.contains("Cycles' sampler"), "metadata sentence");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("glass.json");
    std::fs::write(&path, &json).unwrap();
    let back = kiln::verify::input::read_kiln(&path).unwrap().unwrap();
    assert_eq!(back.spec.transmission, TransmissionConvention::Cycles);

    let audit = |table: &Table| {
        let settings = ReferenceSettings {
            tolerance: 1e-6,
            ..ReferenceSettings::default()
        };
        kiln::verify::node_errors(table, &settings).max
    };
    assert!(audit(&back) < 1e-4, "{}", audit(&back));
    let mut single = back.clone();
    single.spec.transmission = TransmissionConvention::SingleScattering;
    assert!(audit(&single) > 0.05, "{}", audit(&single));
}

#[test]
fn a_transmission_convention_belongs_to_the_dielectric_tables_only() {
    let options = BakeOptions {
        transmission: TransmissionConvention::Cycles,
        ..BakeOptions::default()
    };
    let message = options.validate().unwrap_err().to_string();
    assert!(message.contains("dielectric tables only"), "{message}");
    let mut spec = BakeOptions::default().resolved().specs().remove(0);
    assert!(spec.check().is_ok());
    spec.transmission = TransmissionConvention::Cycles;
    let message = spec.check().unwrap_err().to_string();
    assert!(message.contains("dielectric"), "{message}");
}

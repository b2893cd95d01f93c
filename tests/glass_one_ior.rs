//! Glass at a material's own IOR (issue 61, part 3): `kiln bake --quantity e-dielectric,... --ior
//! X` writes 2-D tables at exactly that index from both sides; a scene's glass material of one
//! IOR gets them; their lookups (the library's, the generated Rust and HLSL) read the one-IOR
//! layout; bad indices are refused.

use kiln::format::replace::Replace;
use kiln::format::{Format, Precision, write_tables};
use kiln::table::{Quantity, Table};
use kiln::verify::input::read_kiln;
use kiln::{BakeOptions, Fresnel};
use std::fmt::Write as _;
use std::path::Path;

use crate::command;
use crate::cxx;
use crate::rustc;

fn read(dir: &Path, stem: &str) -> Table {
    read_kiln(&dir.join(format!("{stem}.json")))
        .unwrap()
        .unwrap()
}

/// `kiln eval`'s value of the dielectric albedo at relative index `eta` (named explicitly: the
/// command line's own path to the integral, not the table's).
fn eval(eta: f64, alpha: f64, mu: f64) -> f64 {
    let (_, report) = command::json_of(
        "eval",
        &[
            "--quantity",
            "e-dielectric",
            "--ior",
            &format!("{eta:?}"),
            "--alpha",
            &format!("{alpha:?}"),
            "--mu",
            &format!("{mu:?}"),
            "--method",
            "reference",
        ],
    );
    command::number(&report, "value")
}

/// Each side's table holds its own relative index: the outside table `eta`, the inside one
/// `1 / eta` (a table computed at the wrong side would be off by up to 0.5 here), at texels
/// across the table, against `kiln eval` given that index; the names and the metadata say the
/// index.
#[test]
fn each_side_holds_its_own_index() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    command::succeeded(&[
        "bake",
        "--quantity",
        "e-dielectric,e-dielectric-inside",
        "--ior",
        "1.5",
        "--size",
        "6",
        "--texels",
        "nodes",
        "--format",
        "json",
        "-q",
        "--out",
        out,
    ]);
    let outside = read(
        dir.path(),
        "ggx-height-correlated-E_dielectric-ior-1.5-nodes",
    );
    let inside = read(
        dir.path(),
        "ggx-height-correlated-E_dielectric_inside-ior-1.5-nodes",
    );
    assert_eq!(outside.spec.shape(), [6, 6]);
    assert_eq!(outside.spec.fixed_ior(), Some(1.5));
    assert_eq!(inside.spec.fixed_ior(), Some(1.5));
    let mut largest_gap = 0.0f64;
    for index in [7, 9, 16, 22, 28, 35] {
        for (table, eta) in [(&outside, 1.5), (&inside, 1.0 / 1.5)] {
            let (alpha, mu, _) = table.spec.texel_point(index);
            let mu = mu.unwrap();
            let want = eval(eta, alpha, mu);
            assert!(
                (table.value[index] - want).abs() < 1e-6,
                "{} texel {index} (alpha {alpha}, mu {mu}): {} vs eval {want}",
                table.spec.id(),
                table.value[index]
            );
        }
        let (alpha, mu, _) = inside.spec.texel_point(index);
        largest_gap = largest_gap.max((eval(1.5, alpha, mu.unwrap()) - inside.value[index]).abs());
    }
    assert!(largest_gap > 1e-2, "{largest_gap}");
    let sidecar: serde_json::Value = serde_json::from_slice(
        &std::fs::read(
            dir.path()
                .join("ggx-height-correlated-E_dielectric_inside-ior-1.5-nodes.json"),
        )
        .unwrap(),
    )
    .unwrap();
    let fresnel = sidecar["fresnel"].as_str().unwrap();
    assert!(
        fresnel.contains("1.5") && fresnel.contains("1 / 1.5"),
        "{fresnel}"
    );
}

/// The generated Rust (compiled by rustc) and HLSL (compiled as C++ with a GPU-style bilinear
/// texture) lookups of both sides' fitted tables compute the one-IOR layout's coordinate as the
/// library does: within f32's reach of `Table::lookup`, at grazing, at and around the critical
/// angle `sqrt(5) / 3` and at normal incidence, on a mirror and at full roughness.
#[test]
fn generated_lookups_read_the_one_ior_layout() {
    let tables = BakeOptions {
        quantities: vec![Quantity::EDielectric, Quantity::EDielectricInside],
        size: 8,
        fresnel: Some(Fresnel::Dielectric { eta: 1.5 }),
        max_error: Some(1e-4),
        ..BakeOptions::default()
    }
    .bake(&|_| {})
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_tables(
        dir.path(),
        &tables,
        &[Format::Hlsl, Format::Rs],
        Precision::F32,
        Replace::Refuse,
    )
    .unwrap();
    let mut points = Vec::new();
    for r in [0.0, 0.05, 0.3, 0.71, 1.0] {
        for mu in [0.0, 1e-4, 0.02, 0.5, 0.70, 0.7454, 0.79, 0.97, 1.0] {
            points.push((mu, r));
        }
    }
    let have_cxx = cxx::compiler_or_skip("generated_lookups_read_the_one_ior_layout").is_some();
    for table in &tables {
        let id = table.spec.id();
        let library: Vec<f64> = points
            .iter()
            .map(|&(mu, r)| table.lookup(f64::from(mu as f32), f64::from(r as f32)))
            .collect();
        let from_rust = rustc::generated_lookups(dir.path(), table, &points);
        let mut generated = vec![("Rust", from_rust)];
        if have_cxx {
            let stem = kiln::format::shader::name(table);
            let hlsl = std::fs::read_to_string(dir.path().join(format!("{id}.hlsl"))).unwrap();
            let hlsl = &hlsl[..hlsl.find("float3 ").unwrap_or(hlsl.len())];
            let texels = cxx::texels_rg(table);
            let prelude = crate::balanced_layout::HLSL_2D_PRELUDE;
            let mut source = format!("{prelude}{hlsl}\nint main() {{\n");
            let _ = writeln!(source, "  Tex2 tex{{8, 8, {{{texels}}}}};");
            for &(mu, r) in &points {
                let _ = writeln!(
                    source,
                    "  std::printf(\"%.9g\\n\", {stem}_lookup(tex, SamplerState{{}}, {mu:?}f, \
                     {r:?}f).x);"
                );
            }
            source += "}\n";
            let name = id.replace('.', "_");
            generated.push(("HLSL", cxx::compile_and_run(dir.path(), &name, &source)));
        }
        for (language, values) in generated {
            assert_eq!(values.len(), points.len());
            for (k, &(mu, r)) in points.iter().enumerate() {
                assert!(
                    (values[k] - library[k]).abs() < 2e-5,
                    "{id}, {language}, mu {mu}, r {r}: {} vs library {}",
                    values[k],
                    library[k]
                );
            }
        }
    }
}

/// An index outside kiln's range, or 1 (no interface), is refused with the range before any
/// work, and nothing is written.
#[test]
fn bad_indices_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    for ior in ["1", "0", "-1.5", "1000", "nan"] {
        let message = command::refused(
            &[
                "bake",
                "--quantity",
                "e-dielectric",
                &format!("--ior={ior}"),
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        );
        assert!(
            message.to_lowercase().contains("ior")
                && (message.contains("100") || message.contains("finite")),
            "--ior {ior}: {message}"
        );
        assert!(!out.exists(), "--ior {ior} wrote {}", out.display());
    }
}

/// A scene's glass of one IOR gets the four tables at that IOR and `materials.json` names them
/// for it; with them, Turquin's furnace from both sides is within issue 61's 1e-3 at 1.5
/// (measured 9.0e-4 outside, 8.4e-4 inside, docs/bake.md "Glass at one IOR").
#[test]
#[ignore = "long (about 40 s): .ci/run runs it with --ignored"]
fn a_scene_bakes_its_glass_at_its_ior_and_the_furnace_holds() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        "[output]\nformats = [\"json\"]\n\n[[material]]\nname = \"window\"\nndf = \"ggx\"\n\
         roughness = 0.1\nfresnel = { dielectric = { ior = 1.5 } }\ntransmission = true\n\
         multiple_scattering = false\n",
    )
    .unwrap();
    command::succeeded(&["bake", "--scene", scene.to_str().unwrap(), "-q"]);
    let tables = dir.path().join("tables");
    let materials: serde_json::Value =
        serde_json::from_slice(&std::fs::read(tables.join("materials.json")).unwrap()).unwrap();
    let glass = &materials["materials"][0]["glass_tables"];
    for (quantity, bound) in [("E_dielectric", 1e-3), ("E_dielectric_inside", 1e-3)] {
        let stem = glass[quantity].as_str().unwrap();
        assert!(stem.ends_with("-ior-1.5"), "{stem}");
        let file = tables.join(format!("{stem}.json"));
        let (_, report) = command::json_of("furnace", &[file.to_str().unwrap()]);
        let deviation = command::number(&report["forms"][0], "max_deviation");
        assert!(deviation < bound, "{stem}: {deviation}");
    }
    for quantity in ["E_avg_dielectric", "E_avg_dielectric_inside"] {
        let stem = glass[quantity].as_str().unwrap();
        assert!(tables.join(format!("{stem}.json")).exists(), "{stem}");
    }
}

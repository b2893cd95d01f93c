//! The generated HLSL is executed, not only parsed: compiled as C++ with a small prelude that
//! gives HLSL's types and intrinsics their meaning (`float2`, `float3`, `min`, `max`, `clamp`,
//! `pow`, `floor`) and `Texture2D::SampleLevel` a GPU's semantics (bilinear filtering between
//! texel centres, clamp-to-edge), every literal in single precision
//! (`-fsingle-precision-constant`), so the arithmetic is f32 as on a GPU. Its lookups, the
//! Kulla-Conty lobe, its colour term and Turquin's factor are compared with the library at
//! thousands of points: a wrong `alpha = roughness`, a missing half-texel remap or a lobe that
//! forgot to multiply by `r` fails here.
//!
//! WGSL and GLSL are generated from the same description of each function
//! (`src/format/shader.rs`) and validated by naga in `tests/shaders.rs`.

#![cfg(feature = "cli")]

use kiln::model::kulla_conty::{fresnel_colour, multiple_scattering};
use kiln::table::normalisation::normalisation_lookup;
use kiln::verify::input::read_kiln;
use kiln::verify::{AuditSettings, lookup_coordinates};
use kiln::{Quantity, Table};
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

#[path = "common/command.rs"]
mod command;
use command::kiln;

/// HLSL's vocabulary in C++, with GPU texture sampling.
const PRELUDE: &str = r"
#include <cmath>
#include <cstdio>
#include <vector>
using std::floor;
using std::pow;
using std::sqrt;
struct float2 {
    float x, y;
    float2(float x, float y) : x(x), y(y) {}
};
struct float3 {
    float x, y, z;
    float3(float x, float y, float z) : x(x), y(y), z(z) {}
};
inline float3 operator+(float3 a, float3 b) { return float3(a.x + b.x, a.y + b.y, a.z + b.z); }
inline float3 operator-(float3 a, float3 b) { return float3(a.x - b.x, a.y - b.y, a.z - b.z); }
inline float3 operator*(float3 a, float3 b) { return float3(a.x * b.x, a.y * b.y, a.z * b.z); }
inline float3 operator/(float3 a, float3 b) { return float3(a.x / b.x, a.y / b.y, a.z / b.z); }
inline float3 operator*(float3 a, float s) { return float3(a.x * s, a.y * s, a.z * s); }
inline float3 operator*(float s, float3 a) { return a * s; }
inline float min(float a, float b) { return a < b ? a : b; }
inline int min(int a, int b) { return a < b ? a : b; }
inline float max(float a, float b) { return a > b ? a : b; }
inline float3 max(float3 a, float3 b) { return float3(max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)); }
inline float clamp(float x, float a, float b) { return min(max(x, a), b); }
struct SamplerState {};
struct Sample2 { float2 rg; };
// A 2-D texture of (R, G) texels, row 0 at v = 0: bilinear between texel centres
// ((i + 0.5) / W), clamp to edge, as a GPU's linear filter samples level 0.
template <typename T> struct Texture2D {
    int width, height;
    std::vector<float> texels; // R, G interleaved, row-major
    Sample2 SampleLevel(SamplerState, float2 uv, int) const {
        float x = uv.x * width - 0.5f, y = uv.y * height - 0.5f;
        float fx0 = floor(x), fy0 = floor(y);
        float fx = x - fx0, fy = y - fy0;
        auto at = [&](int i, int j, int c) {
            i = i < 0 ? 0 : (i >= width ? width - 1 : i);
            j = j < 0 ? 0 : (j >= height ? height - 1 : j);
            return texels[2 * (j * width + i) + c];
        };
        int i0 = (int)fx0, j0 = (int)fy0;
        float c[2];
        for (int k = 0; k < 2; ++k) {
            float top = at(i0, j0, k) * (1 - fx) + at(i0 + 1, j0, k) * fx;
            float bottom = at(i0, j0 + 1, k) * (1 - fx) + at(i0 + 1, j0 + 1, k) * fx;
            c[k] = top * (1 - fy) + bottom * fy;
        }
        return Sample2{float2(c[0], c[1])};
    }
};
";

fn read(dir: &Path, name: &str) -> Table {
    read_kiln(&dir.join(format!("{name}.json")))
        .unwrap()
        .unwrap()
}

/// A C++ float array initialiser.
fn floats(values: impl Iterator<Item = f64>) -> String {
    let items: Vec<String> = values.map(|v| format!("{:?}f", v as f32)).collect();
    format!("{{{}}}", items.join(", "))
}

/// Compiles `main` (with the prelude and the given HLSL files) and runs it: the numbers it
/// prints, one per line.
fn run(dir: &Path, hlsl: &[&str], main: &str) -> Vec<f64> {
    let mut source = PRELUDE.to_string();
    for name in hlsl {
        source += &std::fs::read_to_string(dir.join(format!("{name}.hlsl"))).unwrap();
    }
    source += main;
    let cpp = dir.join("program.cpp");
    std::fs::write(&cpp, source).unwrap();
    let program = dir.join("program");
    let compiler = std::env::var("CXX").unwrap_or_else(|_| "c++".into());
    let compiled = Command::new(compiler)
        .args(["-std=c++17", "-O0", "-fsingle-precision-constant", "-o"])
        .arg(&program)
        .arg(&cpp)
        .output()
        .expect("a C++ compiler (c++) runs");
    assert!(
        compiled.status.success(),
        "{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    let output = Command::new(&program).output().unwrap();
    assert!(output.status.success());
    String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|line| line.parse().unwrap())
        .collect()
}

fn assert_close(got: f64, want: f64, tolerance: f64, what: &str) {
    assert!(
        (got - want).abs() <= tolerance,
        "{what}: HLSL {got:e}, library {want:e}"
    );
}

#[test]
fn generated_hlsl_runs_and_agrees_with_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.to_str().unwrap();
    let baked = kiln(&["bake", "--format", "hlsl,json", "-q", "--out", out]);
    assert!(
        baked.status.success(),
        "{}",
        String::from_utf8_lossy(&baked.stderr)
    );
    // A second layout: texel centres and the sqrt mu axis, 8 x 8.
    let other = d.join("centres");
    let baked = kiln(&[
        "bake",
        "--format",
        "hlsl,json",
        "--mu-axis",
        "sqrt",
        "--grid",
        "centers",
        "--size",
        "8",
        "--quantity",
        "e",
        "-q",
        "--out",
        other.to_str().unwrap(),
    ]);
    assert!(
        baked.status.success(),
        "{}",
        String::from_utf8_lossy(&baked.stderr)
    );

    let e = read(d, "ggx-height-correlated-E");
    let avg = read(d, "ggx-height-correlated-E_avg");
    let norm = read(d, "ggx-height-correlated-f_ms_norm");
    let centres = read(&other, "ggx-height-correlated-E-mu-sqrt-centers");
    assert_eq!(centres.spec.quantity, Quantity::E);

    let texture = |name: &str, t: &Table| {
        let [rows, columns] = t.spec.shape()[..] else {
            unreachable!()
        };
        let texels = floats((0..t.spec.len()).flat_map(|k| [t.value[k], t.one_minus_value[k]]));
        format!("const Texture2D<float2> {name} = {{{columns}, {rows}, {texels}}};\n")
    };
    let mut main = texture("E", &e) + &texture("C", &centres);
    main += "int main() {\n    SamplerState s;\n";

    // The 2-D lookups at every point `verify` audits, on both layouts.
    let points = |t: &Table| -> Vec<(f64, f64)> {
        lookup_coordinates(&t.spec, &AuditSettings::default())
            .into_iter()
            .map(|c| (c.mu.unwrap(), c.alpha.sqrt()))
            .collect()
    };
    let (e_points, c_points) = (points(&e), points(&centres));
    assert!(e_points.len() > 1000 && c_points.len() > 100);
    for (texture, stem, points) in [
        ("E", "ggx_height_correlated_e", &e_points),
        ("C", "ggx_height_correlated_e_mu_sqrt_centers", &c_points),
    ] {
        for &(mu, r) in points.iter() {
            let _ = writeln!(
                main,
                "    {{ float2 v = {stem}_lookup({texture}, s, {mu:?}f, {r:?}f); \
                 printf(\"%.9g\\n%.9g\\n\", v.x, v.y); }}"
            );
        }
    }
    // The 1-D lookups, the lobe, its colour and Turquin's factor on dense ladders.
    let ladder: Vec<f64> = (0..=1500)
        .map(|k| (f64::from(k) / 1500.0).powi(2))
        .collect();
    for &r in &ladder {
        let _ = writeln!(
            main,
            "    printf(\"%.9g\\n%.9g\\n\", ggx_height_correlated_e_avg_lookup({r:?}f), \
             ggx_height_correlated_f_ms_norm_lookup({r:?}f));"
        );
    }
    let lobes: Vec<(f64, f64, f64)> = (0..1200)
        .map(|k| {
            let k = f64::from(k);
            let r = ((k * 0.618_034) % 1.0).powi(2);
            ((k * 0.754_877) % 1.0 * 0.6, (k * 0.569_840) % 1.0 * 0.6, r)
        })
        .collect();
    for &(o, i, r) in &lobes {
        let _ = writeln!(
            main,
            "    printf(\"%.9g\\n\", ggx_height_correlated_f_ms_norm_f_ms({o:?}f, {i:?}f, {r:?}f));"
        );
    }
    let fresnels: Vec<(f64, f64)> = (0..1200)
        .map(|k| {
            let k = f64::from(k);
            ((k * 0.618_034) % 1.0, 0.05 + 0.95 * ((k * 0.754_877) % 1.0))
        })
        .collect();
    for &(f, x) in &fresnels {
        let _ = writeln!(
            main,
            "    {{ float3 c = ggx_height_correlated_f_ms_norm_fresnel_colour(float3({f:?}f, \
             {f:?}f, {f:?}f), {x:?}f); float3 t = ggx_height_correlated_e_turquin({x:?}f, \
             float3({f:?}f, {f:?}f, {f:?}f)); printf(\"%.9g\\n%.9g\\n\", c.y, t.z); }}"
        );
    }
    main += "    return 0;\n}\n";

    let centres_dir = other.clone();
    std::fs::copy(
        centres_dir.join("ggx-height-correlated-E-mu-sqrt-centers.hlsl"),
        d.join("ggx-height-correlated-E-mu-sqrt-centers.hlsl"),
    )
    .unwrap();
    let printed = run(
        d,
        &[
            "ggx-height-correlated-E",
            "ggx-height-correlated-E-mu-sqrt-centers",
            "ggx-height-correlated-E_avg",
            "ggx-height-correlated-f_ms_norm",
        ],
        &main,
    );
    let mut values = printed.into_iter();
    let mut next = || values.next().expect("as many numbers as asked for");

    // f32 positions err by ~31 * 6e-8 of a texel (texel steps below 0.1): 2e-6 at most.
    for (table, points) in [(&e, &e_points), (&centres, &c_points)] {
        for &(mu, r) in points.iter() {
            let what = format!("{} at mu {mu}, r {r}", table.spec.id());
            assert_close(next(), table.lookup(mu, r), 2e-6, &what);
            assert_close(next(), table.lookup_one_minus(mu, r), 2e-6, &what);
        }
    }
    for &r in &ladder {
        assert_close(next(), avg.lookup(1.0, r), 1e-6, &format!("E_avg at r {r}"));
        let want = normalisation_lookup(&norm, r);
        assert_close(
            next(),
            want,
            1e-6 * want.max(1e-3),
            &format!("f_ms_norm at r {r}"),
        );
    }
    for &(o, i, r) in &lobes {
        let want = multiple_scattering(o, i, normalisation_lookup(&norm, r));
        assert_close(
            next(),
            want,
            1e-5 * want.max(1.0),
            &format!("f_ms({o}, {i}, {r})"),
        );
    }
    for &(f, x) in &fresnels {
        assert_close(
            next(),
            fresnel_colour(f, x),
            1e-6,
            &format!("colour({f}, {x})"),
        );
        let turquin = 1.0 + f * (1.0 / x - 1.0);
        assert_close(
            next(),
            turquin,
            1e-6 * turquin,
            &format!("turquin({x}, {f})"),
        );
    }
    assert!(values.next().is_none());
}

//! The generated HLSL, GLSL and WGSL are executed, not only parsed: compiled as C++ with a
//! small prelude that gives each language's types and intrinsics their meaning (`float2`/`vec2`,
//! `min`, `max`, `clamp`, `pow`, `floor`, WGSL's `select`) and its texture sampling
//! (`Texture2D::SampleLevel`, `textureLod`, `textureSampleLevel`) a GPU's semantics (bilinear
//! filtering between texel centres, clamp-to-edge), every literal in single precision
//! (`-fsingle-precision-constant`), so the arithmetic is f32 as on a GPU. Its lookups, the
//! Kulla-Conty lobe, its colour term and Turquin's factor are compared with the library at
//! thousands of points: a wrong `alpha = roughness`, a missing half-texel remap or a lobe that
//! forgot to multiply by `r` fails here, in each language.
//!
//! HLSL is C++ as it stands. GLSL needs one rewrite, of its array constructor (`float[N](...)`
//! to a brace list). WGSL is rewritten by [`wgsl_as_cpp`] token for token (`fn f(x: f32) -> T`
//! to `T f(float x)`, `let`/`var` to `auto`, `vec2<f32>` to `vec2`, a module's `array<f32, N>(...)`
//! to a `std::array`); nothing in an expression changes. naga parses and validates the WGSL and GLSL
//! in `tests/shaders.rs`.

#![cfg(feature = "cli")]

use kiln::Table;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

use crate::compensation_bake;
use crate::cxx;
use crate::shader_cases;
use shader_cases::{Cases, POINT_SETS, TABLE_FILES};

/// The vocabulary the three languages share, in C++, with GPU texture sampling.
const PRELUDE: &str = r"
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>
using std::floor;
using std::pow;
using std::sqrt;
struct V2 {
    float x, y;
    V2(float x, float y) : x(x), y(y) {}
};
struct V3 {
    float x, y, z;
    V3(float x, float y, float z) : x(x), y(y), z(z) {}
};
inline V3 operator+(V3 a, V3 b) { return V3(a.x + b.x, a.y + b.y, a.z + b.z); }
inline V3 operator-(V3 a, V3 b) { return V3(a.x - b.x, a.y - b.y, a.z - b.z); }
inline V3 operator*(V3 a, V3 b) { return V3(a.x * b.x, a.y * b.y, a.z * b.z); }
inline V3 operator/(V3 a, V3 b) { return V3(a.x / b.x, a.y / b.y, a.z / b.z); }
inline V3 operator*(V3 a, float s) { return V3(a.x * s, a.y * s, a.z * s); }
inline V3 operator*(float s, V3 a) { return a * s; }
inline float min(float a, float b) { return a < b ? a : b; }
inline int min(int a, int b) { return a < b ? a : b; }
inline float max(float a, float b) { return a > b ? a : b; }
inline V3 max(V3 a, V3 b) { return V3(max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)); }
inline float clamp(float x, float a, float b) { return min(max(x, a), b); }
struct V4 {
    float x, y, z, w;
    V4(float x, float y, float z, float w) : x(x), y(y), z(z), w(w) {}
};
inline V4 operator/(V4 a, float s) { return V4(a.x / s, a.y / s, a.z / s, a.w / s); }
inline float dot(V4 a, V4 b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
// A sample: .rg as the tables' lookups read it, or the whole RGBA (kiln's compensation).
struct Sample2 {
    V2 rg;
    V4 rgba;
    operator V4() const { return rgba; }
};
struct Sampler {};
// A 2-D texture of (R, G) or (R, G, B, A) texels, row 0 at v = 0: bilinear between texel
// centres ((i + 0.5) / W), clamp to edge, as a GPU's linear filter samples level 0.
struct Tex {
    int width, height;
    std::vector<float> texels; // channels interleaved, row-major
    int channels = 2;
    Sample2 SampleLevel(Sampler, V2 uv, int) const {
        float x = uv.x * width - 0.5f, y = uv.y * height - 0.5f;
        float fx0 = floor(x), fy0 = floor(y);
        float fx = x - fx0, fy = y - fy0;
        auto at = [&](int i, int j, int c) {
            i = i < 0 ? 0 : (i >= width ? width - 1 : i);
            j = j < 0 ? 0 : (j >= height ? height - 1 : j);
            return texels[channels * (j * width + i) + c];
        };
        int i0 = (int)fx0, j0 = (int)fy0;
        float c[4] = {0, 0, 0, 0};
        for (int k = 0; k < channels; ++k) {
            float top = at(i0, j0, k) * (1 - fx) + at(i0 + 1, j0, k) * fx;
            float bottom = at(i0, j0 + 1, k) * (1 - fx) + at(i0 + 1, j0 + 1, k) * fx;
            c[k] = top * (1 - fy) + bottom * fy;
        }
        return Sample2{V2(c[0], c[1]), V4(c[0], c[1], c[2], c[3])};
    }
};
";

/// A shading language's names for the prelude's types and texture sampling.
#[derive(Clone, Copy, Debug)]
enum Language {
    Hlsl,
    Glsl,
    Wgsl,
}

impl Language {
    fn extension(self) -> &'static str {
        match self {
            Language::Hlsl => "hlsl",
            Language::Glsl => "glsl",
            Language::Wgsl => "wgsl",
        }
    }

    fn prelude(self) -> &'static str {
        match self {
            Language::Hlsl => {
                r"
using float2 = V2;
using float3 = V3;
using float4 = V4;
using SamplerState = Sampler;
template <typename T> using Texture2D = Tex;
"
            }
            Language::Glsl => {
                r"
using vec2 = V2;
using vec3 = V3;
using vec4 = V4;
using sampler2D = Tex;
inline Sample2 textureLod(const Tex& t, V2 uv, float lod) { return t.SampleLevel(Sampler{}, uv, (int)lod); }
"
            }
            Language::Wgsl => {
                r"
using vec2 = V2;
using vec3 = V3;
using vec4 = V4;
using texture_2d = Tex;
using sampler = Sampler;
inline Sample2 textureSampleLevel(const Tex& t, Sampler s, V2 uv, float lod) { return t.SampleLevel(s, uv, (int)lod); }
template <typename T> T select(T f, T t, bool c) { return c ? t : f; }
"
            }
        }
    }

    /// The generated source as C++.
    fn as_cpp(self, source: &str) -> String {
        match self {
            Language::Hlsl => source.to_string(),
            Language::Glsl => glsl_as_cpp(source),
            Language::Wgsl => wgsl_as_cpp(source),
        }
    }

    /// The arguments of a 2-D lookup before `mu, roughness`: the texture (and sampler).
    fn texture_arguments(self, texture: &str) -> String {
        match self {
            Language::Glsl => texture.to_string(),
            Language::Hlsl | Language::Wgsl => format!("{texture}, Sampler{{}}"),
        }
    }
}

/// GLSL's array constructors `= float[N](a, b);` as brace lists.
fn glsl_as_cpp(source: &str) -> String {
    source
        .lines()
        .map(|line| match line.find("= float[") {
            Some(at) if line.trim_end().ends_with(");") => {
                let open = at + line[at..].find('(').unwrap();
                let body = &line[open + 1..line.trim_end().len() - 2];
                format!("{}= {{{body}}};", &line[..at])
            }
            _ => line.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// WGSL's declarations as C++: `fn f(x: f32, t: T) -> R {` as `R f(float x, T t) {`, `let` and
/// `var` as `auto`, `var<private> NAME: array<f32, N> = array<f32, N>(...);` (or `const NAME =
/// array<f32, N>(...);`) as a `std::array`, and the type names
/// (`f32`, `i32`, `vec2<f32>`, `vec3<f32>`, `texture_2d<f32>`) as the prelude's.
fn wgsl_as_cpp(source: &str) -> String {
    let types = |text: &str| {
        text.replace("vec2<f32>", "vec2")
            .replace("vec3<f32>", "vec3")
            .replace("vec4<f32>", "vec4")
            .replace("texture_2d<f32>", "texture_2d")
            .replace("f32", "float")
            .replace("i32", "int")
    };
    source
        .lines()
        .map(|line| {
            let trimmed = line.trim_start();
            let indent = &line[..line.len() - trimmed.len()];
            if let Some(rest) = trimmed.strip_prefix("fn ") {
                let open = rest.find('(').unwrap();
                let close = rest.rfind(')').unwrap();
                let name = &rest[..open];
                let params: Vec<String> = rest[open + 1..close]
                    .split(',')
                    .filter(|p| !p.trim().is_empty())
                    .map(|p| {
                        let (n, t) = p.split_once(':').unwrap();
                        format!("{} {}", types(t.trim()), n.trim())
                    })
                    .collect();
                let ret = rest[close + 1..]
                    .trim()
                    .trim_start_matches("->")
                    .trim_end_matches('{')
                    .trim();
                format!("{indent}{} {name}({}) {{", types(ret), params.join(", "))
            } else if let Some(rest) = trimmed
                .strip_prefix("var<private> ")
                .or_else(|| trimmed.strip_prefix("const "))
            {
                if let Some(at) = rest.find("= array<f32, ") {
                    let name = rest[..at].split(':').next().unwrap().trim();
                    let n_end = at + rest[at..].find('>').unwrap();
                    let n = &rest[at + "= array<f32, ".len()..n_end];
                    let body = &rest[n_end + 2..rest.trim_end().len() - 2];
                    format!("{indent}const std::array<float, {n}> {name} = {{{body}}};")
                } else {
                    line.to_string()
                }
            } else if let Some(rest) = trimmed.strip_prefix("let ") {
                format!("{indent}const auto {}", types(rest))
            } else if let Some(rest) = trimmed.strip_prefix("var ") {
                format!("{indent}auto {}", types(rest))
            } else if trimmed.starts_with("//") {
                line.to_string()
            } else {
                types(line)
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// A C++ float array initialiser.
fn floats(values: impl Iterator<Item = f64>) -> String {
    let items: Vec<String> = values.map(|v| format!("{:?}f", v as f32)).collect();
    format!("{{{}}}", items.join(", "))
}

/// Compiles `main` (with the prelude and the given generated files of `language`) and runs
/// it: the numbers it prints, one per line.
fn run(dir: &Path, language: Language, files: &[&str], main: &str) -> Vec<f64> {
    let mut source = PRELUDE.to_string() + language.prelude();
    for name in files {
        let path = dir.join(format!("{name}.{}", language.extension()));
        source += &language.as_cpp(&std::fs::read_to_string(path).unwrap());
        source += "\n";
    }
    source += main;
    let cpp = dir.join(format!("program-{}.cpp", language.extension()));
    std::fs::write(&cpp, source).unwrap();
    let program = dir.join(format!("program-{}", language.extension()));
    let compiler = std::env::var("CXX")
        .unwrap_or_else(|_| cxx::compiler().expect("checked by the test").into());
    let compiled = Command::new(compiler)
        .args(["-std=c++17", "-O0", "-fsingle-precision-constant", "-o"])
        .arg(&program)
        .arg(&cpp)
        .output()
        .expect("a C++ compiler (c++) runs");
    assert!(
        compiled.status.success(),
        "{language:?} as C++ ({}): {}",
        cpp.display(),
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

/// A C++ array of the points' coordinates, flattened.
fn point_array(name: &str, points: &[f64]) -> String {
    format!(
        "const std::vector<float> {name} = {};\n",
        floats(points.iter().copied())
    )
}

#[test]
fn generated_shaders_run_and_agree_with_the_library() {
    if std::env::var_os("CXX").is_none()
        && cxx::compiler_or_skip("generated_shaders_run_and_agree_with_the_library").is_none()
    {
        return;
    }
    let cases = Cases::bake(&["hlsl", "glsl", "wgsl"]);
    let d = &cases.dir();
    let texture = |name: &str, t: &Table| {
        let [rows, columns] = t.spec.shape()[..] else {
            unreachable!()
        };
        let texels = floats((0..t.spec.len()).flat_map(|k| [t.value[k], t.one_minus_value[k]]));
        format!("const Tex {name} = {{{columns}, {rows}, {texels}}};\n")
    };
    let data = texture("E", &cases.e)
        + &texture("C", &cases.centres)
        + &point_array("E_POINTS", &cases.e_points)
        + &point_array("C_POINTS", &cases.c_points)
        + &point_array("LADDER", &cases.ladder)
        + &point_array("LOBES", &cases.lobes)
        + &point_array("FRESNELS", &cases.fresnels);

    for language in [Language::Hlsl, Language::Glsl, Language::Wgsl] {
        let mut main = data.clone();
        main += "int main() {\n";
        for (texture, stem, array) in [
            ("E", "ggx_height_correlated_e", "E_POINTS"),
            ("C", "ggx_height_correlated_e_bias_centers", "C_POINTS"),
        ] {
            let _ = writeln!(
                main,
                "    for (size_t k = 0; k < {array}.size(); k += 2) {{ auto v = \
                 {stem}_lookup({}, {array}[k], {array}[k + 1]); \
                 printf(\"%.9g\\n%.9g\\n\", v.x, v.y); }}",
                language.texture_arguments(texture)
            );
        }
        main += "    for (float r : LADDER) printf(\"%.9g\\n%.9g\\n\", \
                 ggx_height_correlated_e_avg_lookup(r), \
                 ggx_height_correlated_f_ms_norm_lookup(r));\n";
        main += "    for (size_t k = 0; k < LOBES.size(); k += 3) printf(\"%.9g\\n\", \
                 ggx_height_correlated_f_ms_norm_f_ms(LOBES[k], LOBES[k + 1], LOBES[k + 2]));\n";
        main += "    for (size_t k = 0; k < FRESNELS.size(); k += 2) { float f = FRESNELS[k], \
                 x = FRESNELS[k + 1]; auto c = \
                 ggx_height_correlated_f_ms_norm_fresnel_colour(V3(f, f, f), x); auto t = \
                 ggx_height_correlated_e_turquin(x, V3(f, f, f)); printf(\"%.9g\\n%.9g\\n\", \
                 c.y, t.z); }\n";
        main += "    return 0;\n}\n";

        let printed = run(d, language, &TABLE_FILES, &main);
        let mut values = printed.into_iter();
        for ((set, inputs), points) in POINT_SETS.into_iter().zip(cases.point_sets()) {
            for point in points.chunks(inputs) {
                for (want, tolerance) in cases.expected(set, point) {
                    let got = values.next().expect("as many numbers as asked for");
                    assert!(
                        (got - want).abs() <= tolerance,
                        "{set} at {point:?}: {language:?} {got:e}, library {want:e}"
                    );
                }
            }
        }
        assert!(values.next().is_none());
    }
}

/// kiln's compensation (issue 60) as a renderer reads it: the generated lookup of the RGBA
/// coefficient texture, `M_avg`'s arrays, the basis in `F0`, the albedo and the lobe, run as
/// C++ in f32 against the library's f64 (`CompensationTable::lookup`, `lookup_average`,
/// `KilnCompensation::multiple`). A missing half-texel remap, channels in the wrong order, a
/// wrong pole or an average read at the wrong roughness fails here, in each language.
#[test]
fn generated_compensation_shaders_run_and_agree_with_the_library() {
    if std::env::var_os("CXX").is_none()
        && cxx::compiler_or_skip("generated_compensation_shaders_run_and_agree_with_the_library")
            .is_none()
    {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tables");
    let table = compensation_bake::bake(&out, "8", "2^10", &[]);
    let stem = compensation_bake::STEM;
    let [rows, columns] = table.spec.shape()[..] else {
        unreachable!()
    };
    let texels = floats((0..table.spec.len()).flat_map(|k| {
        let c = &table.coefficients;
        [c[0][k], c[1][k], c[2][k], c[3][k]]
    }));
    // (mu, r, F0, mu_i): inside cells, on texel rows, at the edges.
    let mut points = Vec::new();
    for &(mu, r) in &[
        (0.0, 0.3),
        (0.013, 0.27),
        (0.2, 0.5),
        (0.37, 0.81),
        (0.5, 1.0),
        (0.92, 0.64),
        (1.0, 0.4),
    ] {
        for &f0 in &[0.02, 0.3, 0.955] {
            points.extend([mu, r, f0, 0.61]);
        }
    }
    let mut main = format!("const Tex K = {{{columns}, {rows}, {texels}, 4}};\n");
    main += &point_array("POINTS", &points);
    main += "int main() {\n";
    let s = stem.replace('-', "_");
    for language in [Language::Hlsl, Language::Glsl, Language::Wgsl] {
        let mut program = main.clone();
        let _ = writeln!(
            program,
            "    for (size_t k = 0; k < POINTS.size(); k += 4) {{\n\
             float mu = POINTS[k], r = POINTS[k + 1], f = POINTS[k + 2], mu_i = POINTS[k + 3];\n\
             V4 c = {s}_coefficients({tex}, mu, r);\n\
             V4 ci = {s}_coefficients({tex}, mu_i, r);\n\
             V4 a = {s}_average(r);\n\
             V3 f0 = V3(f, 0.5 * f, 1.0);\n\
             V3 m = {s}_albedo(c, f0);\n\
             V3 m_avg = {s}_albedo(a, f0);\n\
             V3 lobe = {s}_lobe(m, {s}_albedo(ci, f0), m_avg);\n\
             printf(\"%.9g\\n%.9g\\n%.9g\\n%.9g\\n\", c.x, c.y, c.z, c.w);\n\
             printf(\"%.9g\\n%.9g\\n%.9g\\n\", m.x, m.y, m.z);\n\
             printf(\"%.9g\\n%.9g\\n%.9g\\n\", m_avg.x, lobe.x, lobe.z);\n\
             }}\n    return 0;\n}}",
            tex = language.texture_arguments("K")
        );
        let printed = run(&out, language, &[stem], &program);
        let mut values = printed.into_iter();
        let mut check = |want: f64, tolerance: f64, what: &str, point: &[f64]| {
            let got = values.next().expect("as many numbers as asked for");
            assert!(
                (got - want).abs() <= tolerance * (1.0 + want.abs()),
                "{what} at {point:?}: {language:?} {got:e}, library {want:e}"
            );
        };
        for point in points.chunks(4) {
            let (mu, r, f, mu_i) = (point[0], point[1], point[2], point[3]);
            let c = table.lookup(mu, r);
            for j in 0..4 {
                check(c.coefficients[j], 2e-6, &format!("c_{j}"), point);
            }
            for f0 in [f, 0.5 * f, 1.0] {
                check(c.multiple(f0), 2e-6, "M", point);
            }
            let average = table.lookup_average(r);
            let ci = table.lookup(mu_i, r);
            check(average.multiple(f), 2e-6, "M_avg", point);
            for f0 in [f, 1.0] {
                let lobe = c.multiple(f0) * ci.multiple(f0)
                    / (std::f64::consts::PI * average.multiple(f0));
                check(lobe, 1e-5, "lobe", point);
            }
        }
        assert!(values.next().is_none());
    }
}

/// kiln's compensation as a C/C++ header (`--format h`), compiled and run: the texels
/// interleaved as the RGBA texture (every coefficient of the document, in f32), `M_avg`'s, and
/// the basis, albedo and lobe functions against the library's `KilnCompensation::multiple` at
/// every texel.
#[test]
fn the_compensation_header_holds_the_table_and_its_functions() {
    if cxx::compiler_or_skip("the_compensation_header_holds_the_table_and_its_functions").is_none()
    {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tables");
    let table = compensation_bake::bake(&out, "6", "2^10", &["--format", "json,h"]);
    let stem = compensation_bake::STEM;
    let s = stem.replace('-', "_");
    let c = s.to_uppercase();
    let n = table.spec.len();
    let m = table.average_spec.len();
    let mut source = format!(
        "#include <cstdio>\n{}\nint main() {{\n",
        std::fs::read_to_string(out.join(format!("{stem}.h"))).unwrap()
    );
    let _ = writeln!(
        source,
        "    for (int k = 0; k < {}; ++k) printf(\"%.9g\\n\", {c}[k]);\n    \
         for (int k = 0; k < {}; ++k) printf(\"%.9g\\n\", {c}_AVERAGE[k]);\n    \
         for (int k = 0; k < {n}; ++k) {{ const float* t = &{c}[4 * k]; const float* a = \
         &{c}_AVERAGE[4 * (k / {})];\n        float mo = {s}_albedo(t, 0.3f), mi = {s}_albedo(&{c}[0], \
         0.3f), ma = {s}_albedo(a, 0.3f);\n        printf(\"%.9g\\n%.9g\\n\", {s}_albedo(t, 0.9f), \
         {s}_lobe(mo, mi, ma)); }}\n    return 0;\n}}",
        4 * n,
        4 * m,
        table.spec.shape()[1]
    );
    let printed = cxx::compile_and_run(dir.path(), "header", &source);
    let mut values = printed.into_iter();
    let mut next = || values.next().expect("as many numbers as asked for");
    for k in 0..n {
        for j in 0..4 {
            // %.9g round-trips an f32.
            assert_eq!(next() as f32, table.coefficients[j][k] as f32, "c_{j}[{k}]");
        }
    }
    for k in 0..m {
        for j in 0..4 {
            assert_eq!(
                next() as f32,
                table.average[j][k] as f32,
                "average c_{j}[{k}]"
            );
        }
    }
    let at =
        |coefficients: &[Vec<f64>; 4], k: usize| kiln::integrate::compensation::KilnCompensation {
            coefficients: std::array::from_fn(|j| coefficients[j][k]),
        };
    let columns = table.spec.shape()[1];
    for k in 0..n {
        let texel = at(&table.coefficients, k);
        let average = at(&table.average, k / columns);
        let want_albedo = texel.multiple(0.9);
        let want_lobe = texel.multiple(0.3) * at(&table.coefficients, 0).multiple(0.3)
            / (std::f64::consts::PI * average.multiple(0.3).max(1e-30));
        for (want, tolerance) in [(want_albedo, 2e-6), (want_lobe, 1e-5)] {
            let got = next();
            assert!(
                (got - want).abs() <= tolerance * (1.0 + want.abs()),
                "texel {k}: header {got:e}, library {want:e}"
            );
        }
    }
}

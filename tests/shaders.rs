//! The generated shader lookups: WGSL and GLSL parse and validate with naga (as a fragment
//! shader that calls every lookup; GLSL in naga's Vulkan dialect, so through the generated
//! texture coordinate and the test's own sampling); HLSL, for which no compiler is at hand, is
//! checked for its functions and balanced braces.

use kiln::format::shader::{Language, encode, name};
use kiln::{BakeOptions, Grid, MuMapping, Quantity, Table};

/// Tables of every shape and axis kind: E on the adaptive axis with nodes and on the sqrt axis
/// with centres, E_avg (1-D), E_dielectric (3-D, IOR axis) and F_avg (1-D over the IOR), and
/// kiln's balanced, split-sum, glass and one-IOR glass layouts, and a coat's reflection.
fn tables() -> Vec<Table> {
    let base = BakeOptions {
        size: 3,
        ior_size: 2,
        max_error: Some(1e-3),
        ..BakeOptions::default()
    };
    let mut tables = base.bake(&|_| {}).unwrap();
    tables.extend(
        BakeOptions {
            quantities: vec![Quantity::E, Quantity::EDielectric, Quantity::FAvg],
            mu_mapping: Some(MuMapping::Sqrt),
            grid: Grid::Centers,
            ior_mapping: kiln::IorMapping::Cycles,
            ..base.clone()
        }
        .bake(&|_| {})
        .unwrap(),
    );
    // kiln's balanced layout, whose lookups compute both coordinates.
    tables.extend(
        BakeOptions {
            mu_mapping: Some(MuMapping::Balanced),
            roughness_spacing: Some(kiln::RoughnessSpacing::Balanced),
            ..base.clone()
        }
        .bake(&|_| {})
        .unwrap(),
    );
    // kiln's split-sum layout (the default axis of the split-sum channels).
    tables.extend(
        BakeOptions {
            quantities: vec![Quantity::EScale, Quantity::EBias],
            mu_mapping: Some(MuMapping::SplitSum),
            ..base.clone()
        }
        .bake(&|_| {})
        .unwrap(),
    );
    // kiln's layout of glass at one IOR, from both sides (the inside one with its critical
    // angle's step).
    tables.extend(
        BakeOptions {
            quantities: vec![Quantity::EDielectric, Quantity::EDielectricInside],
            fresnel: Some(kiln::Fresnel::Dielectric { eta: 1.5 }),
            ..base.clone()
        }
        .bake(&|_| {})
        .unwrap(),
    );
    // A coat's reflection over the IOR (the split-sum mu axis on Cycles' IOR axis) and at one
    // IOR.
    for fresnel in [None, Some(kiln::Fresnel::Dielectric { eta: 1.5 })] {
        tables.extend(
            BakeOptions {
                quantities: vec![Quantity::EReflection, Quantity::EAvgReflection],
                fresnel,
                ..base.clone()
            }
            .bake(&|_| {})
            .unwrap(),
        );
    }
    // kiln's glass layout, whose lookups compute its coordinates.
    tables.extend(
        BakeOptions {
            quantities: vec![Quantity::EDielectric, Quantity::EDielectricInside],
            ..base
        }
        .bake(&|_| {})
        .unwrap(),
    );
    tables
}

/// Arguments for a lookup: `mu, roughness, eta` as the table has them.
fn arguments(table: &Table) -> String {
    let mut args = Vec::new();
    if table.spec.mu.is_some() {
        args.push("0.5");
    }
    if table.spec.roughness.is_some() {
        args.push("0.3");
    }
    if table.spec.ior.is_some() {
        args.push("1.45");
    }
    args.join(", ")
}

/// naga's validator, with every check and capability.
fn validate(module: &naga::Module, source: &str, what: &str) {
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(module)
    .unwrap_or_else(|e| panic!("{what}: {e:?}\n{source}"));
}

#[test]
fn wgsl_lookups_validate() {
    for (k, table) in tables().iter().enumerate() {
        let dims = table.spec.shape().len();
        let mut source = String::new();
        if dims > 1 {
            source += &format!(
                "@group(0) @binding(0) var lut: texture_{dims}d<f32>;\n\
                 @group(0) @binding(1) var linear_clamp: sampler;\n"
            );
        }
        source += &encode(table, Language::Wgsl);
        let call = if dims > 1 {
            format!(
                "{}_lookup(lut, linear_clamp, {})",
                name(table),
                arguments(table)
            )
        } else {
            format!(
                "vec2<f32>({}_lookup({}), 0.0)",
                name(table),
                arguments(table)
            )
        };
        source += &format!(
            "\n@fragment\nfn main() -> @location(0) vec4<f32> {{\n    let v = {call};\n    \
             return vec4<f32>(v, 0.0, 1.0);\n}}\n"
        );
        let module = naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| {
            panic!(
                "table {k} ({}):\n{}\n{source}",
                table.spec.id(),
                e.emit_to_string(&source)
            )
        });
        validate(
            &module,
            &source,
            &format!("table {k} ({})", table.spec.id()),
        );
    }
}

#[test]
fn glsl_lookups_validate() {
    for (k, table) in tables().iter().enumerate() {
        let dims = table.spec.shape().len();
        // naga reads Vulkan GLSL: separate texture and sampler, so the combined-sampler
        // convenience function is left out and the test samples at the generated coordinate.
        let mut source = String::from(
            "#version 450\n#define KILN_NO_COMBINED_SAMPLERS\nlayout(location = 0) out vec4 colour;\n",
        );
        if dims > 1 {
            source += &format!(
                "layout(set = 0, binding = 0) uniform texture{dims}D lut;\n\
                 layout(set = 0, binding = 1) uniform sampler linear_clamp;\n"
            );
        }
        source += &encode(table, Language::Glsl);
        let call = if dims > 1 {
            format!(
                "textureLod(sampler{dims}D(lut, linear_clamp), {}_uv({}), 0.0).rg",
                name(table),
                arguments(table)
            )
        } else {
            format!("vec2({}_lookup({}), 0.0)", name(table), arguments(table))
        };
        source += &format!(
            "\nvoid main() {{\n    vec2 v = {call};\n    colour = vec4(v, 0.0, 1.0);\n}}\n"
        );
        let mut frontend = naga::front::glsl::Frontend::default();
        let module = frontend
            .parse(
                &naga::front::glsl::Options::from(naga::ShaderStage::Fragment),
                &source,
            )
            .unwrap_or_else(|e| panic!("table {k} ({}): {e:?}\n{source}", table.spec.id()));
        validate(
            &module,
            &source,
            &format!("table {k} ({})", table.spec.id()),
        );
    }
}

#[test]
fn hlsl_lookups_are_complete() {
    for table in tables() {
        let source = encode(&table, Language::Hlsl);
        let stem = name(&table);
        assert!(source.contains(&format!("{stem}_lookup(")), "{source}");
        if table.spec.shape().len() > 1 {
            let dims = table.spec.shape().len();
            assert!(
                source.contains(&format!("float{dims} {stem}_uv(")),
                "{source}"
            );
            assert!(
                source.contains(&format!("Texture{dims}D<float2> table")),
                "{source}"
            );
            assert!(source.contains(".SampleLevel(linear_clamp"), "{source}");
        } else {
            assert!(source.contains("static const float"), "{source}");
        }
        let opened = source.matches('{').count();
        assert_eq!(opened, source.matches('}').count(), "{source}");
        assert_eq!(
            source.matches('(').count(),
            source.matches(')').count(),
            "{source}"
        );
    }
}

/// The convention the shaders encode, checked numerically: a GPU's bilinear filter with
/// clamp-to-edge (texel centres at `(i + 0.5) / N`), sampled at `u = t` for centres and at
/// `u = (t (N - 1) + 0.5) / N` for nodes, returns `Table::lookup` (kiln's, and verify's).
#[test]
fn gpu_filtering_at_the_generated_coordinates_equals_the_table_lookup() {
    fn gpu_sample(table: &Table, u: f64, v: f64) -> f64 {
        let [rows, columns] = table.spec.shape()[..] else {
            unreachable!()
        };
        let axis = |t: f64, n: usize| {
            let x = t * n as f64 - 0.5;
            let i = x.floor();
            let f = x - i;
            let clamp = |k: f64| k.clamp(0.0, (n - 1) as f64) as usize;
            (clamp(i), clamp(i + 1.0), f)
        };
        let (i0, i1, fx) = axis(u, columns);
        let (j0, j1, fy) = axis(v, rows);
        let at = |j: usize, i: usize| table.value[j * columns + i];
        let row0 = at(j0, i0) * (1.0 - fx) + at(j0, i1) * fx;
        let row1 = at(j1, i0) * (1.0 - fx) + at(j1, i1) * fx;
        row0 * (1.0 - fy) + row1 * fy
    }
    for table in tables()
        .iter()
        .filter(|t| t.spec.shape().len() == 2 && t.spec.mu.is_some())
    {
        let (mu_axis, r_axis) = (table.spec.mu.unwrap(), table.spec.roughness.unwrap());
        let kiln::Axis::Mu { mapping, size, .. } = mu_axis else {
            unreachable!()
        };
        let kiln::Axis::Roughness {
            convention,
            spacing,
            ..
        } = r_axis
        else {
            unreachable!()
        };
        let gpu = |t: f64, axis: kiln::Axis| match axis.grid() {
            Grid::Centers => t,
            Grid::Nodes => {
                let n = axis.size() as f64;
                (t.clamp(0.0, 1.0) * (n - 1.0) + 0.5) / n
            }
        };
        for a in 0..=20 {
            for b in 0..=20 {
                let (mu, r) = (a as f64 / 20.0, b as f64 / 20.0);
                // At the table's own index (a glass table at one IOR lays mu out by it).
                let t_mu = mapping.coordinate_at(mu, r * r, table.spec.mapping_eta(1.0), size);
                let t_r = spacing.coordinate(r, convention);
                let sampled = gpu_sample(table, gpu(t_mu, mu_axis), gpu(t_r, r_axis));
                let expected = table.lookup(mu, r);
                assert!(
                    (sampled - expected).abs() < 1e-12,
                    "{} at mu {mu}, r {r}: {sampled} vs {expected}",
                    table.spec.id()
                );
            }
        }
    }
}

/// kiln's compensation (issue 60) at 4 x 4 texels from a few walks: what the shader code is
/// generated from (its numbers do not matter here).
fn compensation_table() -> kiln::table::compensation::CompensationTable {
    let options = BakeOptions {
        quantities: vec![Quantity::E, Quantity::EAvg],
        size: 4,
        texels: Some(kiln::table::Texels::Nodes),
        ..BakeOptions::default()
    };
    let mut specs = options.resolved().specs().into_iter();
    let (spec, average) = (specs.next().unwrap(), specs.next().unwrap());
    let settings = kiln::integrate::walk::WalkSettings {
        walks: 1 << 6,
        scrambles: 2,
        ..Default::default()
    };
    kiln::table::compensation::CompensationTable::bake(
        spec.model,
        spec,
        average,
        &settings,
        &|_| {},
    )
    .unwrap()
}

/// The compensation's WGSL and GLSL parse and validate with naga, called as a renderer calls
/// them: the coefficients at both directions, `M_avg`, the albedo and the lobe.
#[test]
fn compensation_shaders_validate() {
    use kiln::format::shader::encode_compensation;
    let table = compensation_table();
    let s = kiln::format::compensation::stem(&table);
    let wgsl = format!(
        "@group(0) @binding(0) var lut: texture_2d<f32>;\n\
         @group(0) @binding(1) var linear_clamp: sampler;\n{}\n\
         @fragment\nfn main() -> @location(0) vec4<f32> {{\n\
         let f0 = vec3<f32>(0.9, 0.6, 0.5);\n\
         let m_o = {s}_albedo({s}_coefficients(lut, linear_clamp, 0.5, 0.3), f0);\n\
         let m_i = {s}_albedo({s}_coefficients(lut, linear_clamp, 0.8, 0.3), f0);\n\
         let m_avg = {s}_albedo({s}_average(0.3), f0);\n\
         return vec4<f32>({s}_lobe(m_o, m_i, m_avg), 1.0);\n}}\n",
        encode_compensation(&table, Language::Wgsl, "kiln compensation --bake tables")
    );
    let module = naga::front::wgsl::parse_str(&wgsl)
        .unwrap_or_else(|e| panic!("{}\n{wgsl}", e.emit_to_string(&wgsl)));
    validate(&module, &wgsl, "the compensation's WGSL");
    let glsl = format!(
        "#version 450\n#define KILN_NO_COMBINED_SAMPLERS\nlayout(location = 0) out vec4 colour;\n\
         layout(set = 0, binding = 0) uniform texture2D lut;\n\
         layout(set = 0, binding = 1) uniform sampler linear_clamp;\n{}\n\
         void main() {{\n\
         vec3 f0 = vec3(0.9, 0.6, 0.5);\n\
         vec3 m_o = {s}_albedo(textureLod(sampler2D(lut, linear_clamp), {s}_uv(0.5, 0.3), 0.0), f0);\n\
         vec3 m_i = {s}_albedo(textureLod(sampler2D(lut, linear_clamp), {s}_uv(0.8, 0.3), 0.0), f0);\n\
         vec3 m_avg = {s}_albedo({s}_average(0.3), f0);\n\
         colour = vec4({s}_lobe(m_o, m_i, m_avg), 1.0);\n}}\n",
        encode_compensation(&table, Language::Glsl, "kiln compensation --bake tables")
    );
    let mut frontend = naga::front::glsl::Frontend::default();
    let module = frontend
        .parse(
            &naga::front::glsl::Options::from(naga::ShaderStage::Fragment),
            &glsl,
        )
        .unwrap_or_else(|e| panic!("{e:?}\n{glsl}"));
    validate(&module, &glsl, "the compensation's GLSL");
    let hlsl = encode_compensation(&table, Language::Hlsl, "kiln compensation --bake tables");
    assert!(hlsl.contains("Texture2D<float4> table"), "{hlsl}");
    assert_eq!(
        hlsl.matches('{').count(),
        hlsl.matches('}').count(),
        "{hlsl}"
    );
}

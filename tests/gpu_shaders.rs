//! The generated WGSL and GLSL run on a real Vulkan implementation (issue 40): `wgpu` compiles
//! them (naga to SPIR-V) into compute shaders that call the generated lookups and lobe
//! functions, kiln's textures are uploaded as `Rg32Float` and sampled with the engines' sampler
//! state (linear filtering, clamp to edge, level 0), and what the device writes back is compared
//! with the library at the points `tests/shader_execution.rs` runs as C++.
//!
//! The adapter is whatever Vulkan driver the machine has; CI's is Mesa's software rasteriser,
//! lavapipe (Debian `mesa-vulkan-drivers`, which `.ci/run` installs). On a machine without a
//! Vulkan adapter the test says that it skipped and what to install, and fails under
//! `CI=true` (`tests/common/external.rs`); `KILN_SKIP_VULKAN=1` skips it (and fails
//! under `CI=true` too).
//!
//! GLSL goes through naga's GLSL front end, which reads Vulkan GLSL with separate textures and
//! samplers: the shader defines `KILN_NO_COMBINED_SAMPLERS` (the generated file's switch for
//! that) and samples `sampler2D(texture, sampler)` at the generated `_uv` coordinate, as
//! `tests/shaders.rs` validates it.

#![cfg(feature = "cli")]

use crate::external;
use crate::shader_cases;
use shader_cases::{Cases, POINT_SETS, TABLE_FILES};

use std::fmt::Write as _;
use wgpu::util::DeviceExt as _;

/// The two shading languages wgpu takes as source.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Language {
    Wgsl,
    Glsl,
}

impl Language {
    fn extension(self) -> &'static str {
        match self {
            Language::Wgsl => "wgsl",
            Language::Glsl => "glsl",
        }
    }
}

/// One dispatch, over one of [`POINT_SETS`]: how many results a point gives, and the body that
/// computes them from `points[k * inputs ..]` into `results[k * outputs ..]`.
struct Task {
    outputs: usize,
    wgsl: &'static str,
    glsl: &'static str,
}

const TASKS: [Task; 5] = [
    Task {
        outputs: 2,
        wgsl: "let v = ggx_height_correlated_e_lookup(e_table, kiln_sampler, points[2u * k], points[2u * k + 1u]);\n\
               results[2u * k] = v.x; results[2u * k + 1u] = v.y;",
        glsl: "vec2 v = textureLod(sampler2D(e_table, kiln_sampler), ggx_height_correlated_e_uv(points[2u * k], points[2u * k + 1u]), 0.0).rg;\n\
               results[2u * k] = v.x; results[2u * k + 1u] = v.y;",
    },
    Task {
        outputs: 2,
        wgsl: "let v = ggx_height_correlated_e_bias_centers_lookup(c_table, kiln_sampler, points[2u * k], points[2u * k + 1u]);\n\
               results[2u * k] = v.x; results[2u * k + 1u] = v.y;",
        glsl: "vec2 v = textureLod(sampler2D(c_table, kiln_sampler), ggx_height_correlated_e_bias_centers_uv(points[2u * k], points[2u * k + 1u]), 0.0).rg;\n\
               results[2u * k] = v.x; results[2u * k + 1u] = v.y;",
    },
    Task {
        outputs: 2,
        wgsl: "results[2u * k] = ggx_height_correlated_e_avg_lookup(points[k]);\n\
               results[2u * k + 1u] = ggx_height_correlated_f_ms_norm_lookup(points[k]);",
        glsl: "results[2u * k] = ggx_height_correlated_e_avg_lookup(points[k]);\n\
               results[2u * k + 1u] = ggx_height_correlated_f_ms_norm_lookup(points[k]);",
    },
    Task {
        outputs: 1,
        wgsl: "results[k] = ggx_height_correlated_f_ms_norm_f_ms(points[3u * k], points[3u * k + 1u], points[3u * k + 2u]);",
        glsl: "results[k] = ggx_height_correlated_f_ms_norm_f_ms(points[3u * k], points[3u * k + 1u], points[3u * k + 2u]);",
    },
    Task {
        outputs: 2,
        wgsl: "let f = points[2u * k]; let x = points[2u * k + 1u];\n\
               results[2u * k] = ggx_height_correlated_f_ms_norm_fresnel_colour(vec3<f32>(f, f, f), x).y;\n\
               results[2u * k + 1u] = ggx_height_correlated_e_turquin(x, vec3<f32>(f, f, f)).z;",
        glsl: "float f = points[2u * k]; float x = points[2u * k + 1u];\n\
               results[2u * k] = ggx_height_correlated_f_ms_norm_fresnel_colour(vec3(f, f, f), x).y;\n\
               results[2u * k + 1u] = ggx_height_correlated_e_turquin(x, vec3(f, f, f)).z;",
    },
];

const WORKGROUP: usize = 64;

/// The compute shader of `task` in `language`: the bindings, the generated files, a main.
fn shader_source(language: Language, sources: &[String], body: &str, count: usize) -> String {
    let mut source = String::new();
    match language {
        Language::Wgsl => {
            source += "@group(0) @binding(0) var e_table: texture_2d<f32>;\n\
                       @group(0) @binding(1) var c_table: texture_2d<f32>;\n\
                       @group(0) @binding(2) var kiln_sampler: sampler;\n\
                       @group(0) @binding(3) var<storage, read> points: array<f32>;\n\
                       @group(0) @binding(4) var<storage, read_write> results: array<f32>;\n";
            for file in sources {
                source += file;
                source += "\n";
            }
            let _ = write!(
                source,
                "@compute @workgroup_size({WORKGROUP})\n\
                 fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
                 let k = id.x;\n\
                 if (k >= {count}u) {{ return; }}\n{body}\n}}\n"
            );
        }
        Language::Glsl => {
            let _ = write!(
                source,
                "#version 450\n#define KILN_NO_COMBINED_SAMPLERS\n\
                 layout(local_size_x = {WORKGROUP}) in;\n\
                 layout(set = 0, binding = 0) uniform texture2D e_table;\n\
                 layout(set = 0, binding = 1) uniform texture2D c_table;\n\
                 layout(set = 0, binding = 2) uniform sampler kiln_sampler;\n\
                 layout(std430, set = 0, binding = 3) readonly buffer Points {{ float points[]; }};\n\
                 layout(std430, set = 0, binding = 4) buffer Results {{ float results[]; }};\n"
            );
            for file in sources {
                source += file;
                source += "\n";
            }
            let _ = write!(
                source,
                "void main() {{\n\
                 uint k = gl_GlobalInvocationID.x;\n\
                 if (k >= {count}u) {{ return; }}\n{body}\n}}\n"
            );
        }
    }
    source
}

/// A device on the first adapter wgpu finds, with filterable f32 textures; `None` without one.
fn device() -> Option<(wgpu::Adapter, wgpu::Device, wgpu::Queue)> {
    let instance = wgpu::Instance::new(&wgpu::InstanceDescriptor {
        backends: wgpu::Backends::VULKAN,
        ..wgpu::InstanceDescriptor::from_env_or_default()
    });
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::LowPower,
        force_fallback_adapter: false,
        compatible_surface: None,
    }))
    .ok()?;
    assert!(
        adapter
            .features()
            .contains(wgpu::Features::FLOAT32_FILTERABLE),
        "the adapter {:?} cannot filter f32 textures linearly",
        adapter.get_info()
    );
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("kiln shaders"),
        required_features: wgpu::Features::FLOAT32_FILTERABLE,
        required_limits: wgpu::Limits::downlevel_defaults(),
        ..Default::default()
    }))
    .expect("the adapter gives a device");
    Some((adapter, device, queue))
}

/// A table as an `Rg32Float` texture: R = value, G = 1 - value, row 0 at v = 0.
fn texture(device: &wgpu::Device, queue: &wgpu::Queue, table: &kiln::Table) -> wgpu::TextureView {
    let [rows, columns] = table.spec.shape()[..] else {
        panic!("a 2-D table")
    };
    let texels: Vec<f32> = (0..table.spec.len())
        .flat_map(|k| [table.value[k] as f32, table.one_minus_value[k] as f32])
        .collect();
    let bytes: Vec<u8> = texels.iter().flat_map(|v| v.to_le_bytes()).collect();
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some(&table.spec.id()),
            size: wgpu::Extent3d {
                width: columns as u32,
                height: rows as u32,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rg32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &bytes,
    );
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

/// A device, the tables as textures, the engines' sampler, and the bindings' layout.
struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    layout: wgpu::BindGroupLayout,
    views: [wgpu::TextureView; 2],
    sampler: wgpu::Sampler,
}

impl Gpu {
    /// Runs `source` over `points` (`count` of them) and reads back `outputs` results each.
    fn dispatch(
        &self,
        language: Language,
        source: String,
        name: &str,
        points: &[f64],
        count: usize,
        outputs: usize,
    ) -> Vec<f64> {
        let Gpu {
            device,
            queue,
            layout,
            views,
            sampler,
        } = self;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: match language {
                Language::Wgsl => wgpu::ShaderSource::Wgsl(source.into()),
                Language::Glsl => wgpu::ShaderSource::Glsl {
                    shader: source.into(),
                    stage: naga::ShaderStage::Compute,
                    defines: &[],
                },
            },
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[layout],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(name),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let inputs: Vec<u8> = points
            .iter()
            .flat_map(|&v| (v as f32).to_le_bytes())
            .collect();
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("points"),
            contents: &inputs,
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size = (count * outputs * 4) as u64;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("results"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&views[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&views[1]),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: input.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: output.as_entire_binding(),
                },
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(count.div_ceil(WORKGROUP) as u32, 1, 1);
        }
        encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
        queue.submit([encoder.finish()]);
        let slice = readback.slice(..);
        slice.map_async(wgpu::MapMode::Read, |result| {
            result.expect("the results map")
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("the device finishes");
        let bytes = slice.get_mapped_range();
        bytes
            .chunks_exact(4)
            .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
            .collect()
    }
}

fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let buffer = |binding, read_only| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("kiln tables and points"),
        entries: &[
            texture(0),
            texture(1),
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
            buffer(3, true),
            buffer(4, false),
        ],
    })
}

/// A device on the machine's Vulkan adapter with kiln's two 2-D tables uploaded.
fn gpu(cases: &Cases) -> Option<Gpu> {
    if std::env::var_os("KILN_SKIP_VULKAN").is_some_and(|v| v == "1") {
        external::skipped(
            "the generated WGSL and GLSL on a device",
            "a Vulkan adapter, and KILN_SKIP_VULKAN=1 says not to look for one",
            "unset KILN_SKIP_VULKAN",
        );
        return None;
    }
    let Some((adapter, device, queue)) = device() else {
        external::skipped(
            "the generated WGSL and GLSL on a device",
            "a Vulkan adapter",
            "Debian: apt-get install mesa-vulkan-drivers, Mesa's software lavapipe",
        );
        return None;
    };
    eprintln!("adapter: {:?}", adapter.get_info());
    let layout = bind_group_layout(&device);
    let views = [
        texture(&device, &queue, &cases.e),
        texture(&device, &queue, &cases.centres),
    ];
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Nearest,
        ..Default::default()
    });
    Some(Gpu {
        device,
        queue,
        layout,
        views,
        sampler,
    })
}

/// Every point set through `language`'s generated files on the device, against the library.
fn run_and_compare(language: Language) {
    let cases = Cases::bake(&[language.extension()]);
    let Some(gpu) = gpu(&cases) else { return };
    let sources: Vec<String> = TABLE_FILES
        .iter()
        .map(|name| cases.source(name, language.extension()))
        .collect();
    for (((set, inputs), points), task) in
        POINT_SETS.into_iter().zip(cases.point_sets()).zip(&TASKS)
    {
        let count = points.len() / inputs;
        assert!(
            count >= 1000 || set == "centres lookups",
            "{set}: {count} points"
        );
        let body = match language {
            Language::Wgsl => task.wgsl,
            Language::Glsl => task.glsl,
        };
        let source = shader_source(language, &sources, body, count);
        let results = gpu.dispatch(language, source, set, points, count, task.outputs);
        assert_eq!(results.len(), count * task.outputs);
        let mut worst = 0.0_f64;
        for (k, (point, got)) in points
            .chunks(inputs)
            .zip(results.chunks(task.outputs))
            .enumerate()
        {
            for (which, (g, (w, tolerance))) in
                got.iter().zip(cases.expected(set, point)).enumerate()
            {
                assert!(
                    (g - w).abs() <= tolerance,
                    "{language:?} {set} at point {k} {point:?} (result {which}): device {g:e}, \
                     library {w:e}, off by {:e} > {tolerance:e}",
                    (g - w).abs()
                );
                worst = worst.max((g - w).abs() / tolerance);
            }
        }
        eprintln!(
            "{language:?} {set}: {} values agree, the worst at {worst:.2} of its tolerance",
            results.len()
        );
    }
}

#[test]
fn generated_wgsl_runs_on_vulkan_and_agrees_with_the_library() {
    run_and_compare(Language::Wgsl);
}

#[test]
fn generated_glsl_runs_on_vulkan_and_agrees_with_the_library() {
    run_and_compare(Language::Glsl);
}

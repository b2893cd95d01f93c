//! Engine presets: each file, read back in the engine's own convention (by the test's own
//! indexing, not kiln's), holds kiln's table at the same coordinates; `Preset::read_tables`
//! (what `kiln verify --preset` audits) gives the tables back.

use kiln::preset::Preset;
use kiln::{BakeOptions, Table};

fn bake(preset: Preset) -> Vec<Table> {
    bake_to(preset, 1e-5)
}

/// A bake to `max_error` (the layout tests compare bits, so a coarser bake does as well).
fn bake_to(preset: Preset, max_error: f64) -> Vec<Table> {
    BakeOptions {
        max_error: Some(max_error),
        ..preset.options()
    }
    .bake(&|_| {})
    .unwrap()
}

fn f32_of(v: f64) -> f64 {
    f64::from(v as f32)
}

use crate::f16_oracle;

fn f16_of(v: f64) -> f64 {
    // Rounded to nearest even from f64 (the tests' own rounding, not the half crate's, which
    // rounds through f32 twice), with kiln's documented rule that a non-zero value is never
    // flushed to zero but kept as the smallest subnormal (docs/accuracy.md).
    f16_oracle::oracle(v)
}

/// The numbers between the braces after `name[`.
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

#[test]
fn cycles_layout_is_mu_major_nodes_with_e_avg_by_roughness() {
    let tables = bake(Preset::Cycles);
    let (e, avg) = (&tables[0], &tables[1]);
    assert_eq!(e.spec.shape(), [32, 32]);
    let text = String::from_utf8(Preset::Cycles.encode(&tables).unwrap()).unwrap();
    let flat = c_numbers(&text, "table_ggx_E");
    assert_eq!(flat.len(), 1024);
    for r in 0..32 {
        for m in 0..32 {
            // Cycles: index = mu_index * 32 + r_index, nodes i / 31 on both axes.
            let (alpha, mu) = e.spec.texel_coordinates(r * 32 + m);
            assert_eq!(mu.unwrap(), m as f64 / 31.0);
            assert!((alpha - (r as f64 / 31.0).powi(2)).abs() < 1e-15);
            assert_eq!(
                flat[m * 32 + r],
                f32_of(e.value[r * 32 + m]),
                "r {r}, mu {m}"
            );
        }
    }
    // Cycles' special case, r_index 0 is exactly 1 (a mirror), holds for kiln's nodes too.
    assert!((0..32).all(|m| flat[m * 32] == 1.0));
    let averages = c_numbers(&text, "table_ggx_Eavg");
    assert_eq!(
        averages,
        avg.value.iter().map(|&v| f32_of(v)).collect::<Vec<_>>()
    );
    let back = Preset::Cycles.read_tables(text.as_bytes(), "test").unwrap();
    assert_eq!(
        (
            back[0].spec.axes(),
            back[0].spec.quantity,
            back[0].spec.model
        ),
        (e.spec.axes(), e.spec.quantity, e.spec.model)
    );
    assert_eq!(
        back[0].value,
        e.value.iter().map(|&v| f32_of(v)).collect::<Vec<_>>()
    );
}

#[test]
fn bevy_layout_is_rg16f_ktx2_scale_bias_with_nov_across() {
    let tables = bake(Preset::Bevy);
    let (scale, bias) = (&tables[0], &tables[1]);
    let bytes = Preset::Bevy.encode(&tables).unwrap();
    let reader = ktx2::Reader::new(bytes.as_slice()).unwrap();
    let header = reader.header();
    assert_eq!(header.format, Some(ktx2::Format::R16G16_SFLOAT));
    assert_eq!(
        (header.pixel_width, header.pixel_height, header.pixel_depth),
        (64, 64, 0)
    );
    // zstd-supercompressed, as Bevy ships it.
    assert_eq!(
        header.supercompression_scheme,
        Some(ktx2::SupercompressionScheme::Zstandard)
    );
    let level = reader.levels().next().unwrap();
    assert_eq!(level.uncompressed_byte_length, 64 * 64 * 4);
    let mut data = Vec::new();
    std::io::Read::read_to_end(
        &mut ruzstd::decoding::StreamingDecoder::new(level.data).unwrap(),
        &mut data,
    )
    .unwrap();
    assert!(level.data.len() < data.len(), "compressed");
    let texel = |x: usize, y: usize, c: usize| {
        let i = 2 * (2 * (y * 64 + x) + c);
        f64::from(half::f16::from_le_bytes([data[i], data[i + 1]]).to_f32())
    };
    for y in 0..64 {
        for x in 0..64 {
            // x = NoV, y = perceptual roughness, texel centres (i + 0.5) / 64.
            let (alpha, mu) = scale.spec.texel_coordinates(y * 64 + x);
            assert!((mu.unwrap() - (x as f64 + 0.5) / 64.0).abs() < 1e-15);
            assert!((alpha - ((y as f64 + 0.5) / 64.0).powi(2)).abs() < 1e-15);
            assert_eq!(texel(x, y, 0), f16_of(scale.value[y * 64 + x]));
            assert_eq!(texel(x, y, 1), f16_of(bias.value[y * 64 + x]));
        }
    }
    let back = Preset::Bevy.read_tables(&bytes, "test").unwrap();
    assert_eq!(
        back[1].value,
        bias.value.iter().map(|&v| f16_of(v)).collect::<Vec<_>>()
    );
}

#[test]
fn three_layout_is_transposed_half_bits() {
    let tables = bake(Preset::Three);
    let (scale, bias) = (&tables[0], &tables[1]);
    let text = String::from_utf8(Preset::Three.encode(&tables).unwrap()).unwrap();
    let open = text.find("Uint16Array( [").unwrap() + "Uint16Array( [".len();
    let close = open + text[open..].find(']').unwrap();
    let bits: Vec<u16> = text[open..close]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| u16::from_str_radix(s.trim_start_matches("0x"), 16).unwrap())
        .collect();
    assert_eq!(bits.len(), 2 * 16 * 16);
    let half = |b: u16| f64::from(half::f16::from_bits(b).to_f32());
    for r in 0..16 {
        for m in 0..16 {
            // Transposed: x = roughness, y = NoV, so texel (x = r, y = mu) is at mu * 16 + r.
            let k = m * 16 + r;
            assert_eq!(
                half(bits[2 * k]),
                f16_of(scale.value[r * 16 + m]),
                "r {r}, mu {m}"
            );
            assert_eq!(half(bits[2 * k + 1]), f16_of(bias.value[r * 16 + m]));
        }
    }
    let back = Preset::Three.read_tables(text.as_bytes(), "test").unwrap();
    assert_eq!(
        back[0].value,
        scale.value.iter().map(|&v| f16_of(v)).collect::<Vec<_>>()
    );
}

#[test]
fn damaged_engine_files_are_refused_with_a_reason() {
    let error = Preset::Cycles
        .read_tables(b"static const float table_ggx_E[2] = { 1.0f, 0.5f };", "x")
        .unwrap_err()
        .to_string();
    assert!(error.contains("table_ggx_Eavg"), "{error}");
    let error = Preset::Three
        .read_tables(b"new Uint16Array( [ 0x3c00 ] )", "x")
        .unwrap_err()
        .to_string();
    assert!(error.contains("expected 512"), "{error}");
    let error = Preset::Bevy
        .read_tables(b"KTX", "x")
        .unwrap_err()
        .to_string();
    assert!(error.contains("not a bevy file"), "{error}");
}

#[test]
fn enterprise_pbr_layout_is_half_exr_channel_y_with_cos_across() {
    let tables = bake(Preset::EnterprisePbr);
    let (e, avg) = (&tables[0], &tables[1]);
    let files = Preset::EnterprisePbr.files(&tables).unwrap();
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["GGX_E.exr", "GGX_E_avg.exr", "GGX_f_ms_norm.exr"]);
    // Read through the exr crate (kiln's thin reader of any EXR): one half-float channel Y.
    for ((_, bytes), table) in files.iter().zip([e, avg]) {
        let decoded = kiln::format::exr::decode(bytes).unwrap();
        assert_eq!(decoded.channels.len(), 1);
        assert_eq!(decoded.channels[0].0, "Y");
        let (w, h) = match table.spec.shape()[..] {
            [rows, columns] => (columns, rows),
            [n] => (n, 1),
            _ => unreachable!(),
        };
        assert_eq!((decoded.width, decoded.height), (w, h));
        for (k, &v) in decoded.channels[0].1.iter().enumerate() {
            // Row y = roughness index from the top, column x = cos, texel centres.
            assert_eq!(v, f16_of(table.value[k]), "{} {k}", table.spec.id());
        }
        let back = Preset::EnterprisePbr.read_tables(bytes, "test").unwrap();
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].spec.quantity, table.spec.quantity);
    }
    let (alpha, mu) = e.spec.texel_coordinates(3 * 32 + 5);
    assert!((mu.unwrap() - 5.5 / 32.0).abs() < 1e-15);
    assert!((alpha - (3.5f64 / 32.0).powi(2)).abs() < 1e-15);
}

#[test]
fn filament_layout_is_rgb16f_half_bits_in_gl_order_with_cloth_in_blue() {
    let tables = bake_to(Preset::Filament, 1e-4);
    let (bias, e) = (&tables[0], &tables[1]);
    assert_eq!(
        (bias.spec.quantity, e.spec.quantity),
        (kiln::Quantity::EBias, kiln::Quantity::E)
    );
    let text = String::from_utf8(Preset::Filament.encode(&tables).unwrap()).unwrap();
    // An include pasted into `const uint16_t DFG_LUT[] = { ... };`: comments and hex only.
    let bits: Vec<u16> = text
        .lines()
        .filter(|l| !l.starts_with("//"))
        .flat_map(|l| l.split(','))
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| u16::from_str_radix(s.strip_prefix("0x").unwrap(), 16).unwrap())
        .collect();
    assert_eq!(bits.len(), 3 * 128 * 128);
    let half = |b: u16| f64::from(half::f16::from_bits(b).to_f32());
    for y in 0..128 {
        for x in 0..128 {
            // GL order: row y is t = (y + 0.5) / 128 = perceptual roughness, x = NoV.
            let k = y * 128 + x;
            let (alpha, mu) = e.spec.texel_coordinates(k);
            let (r, mu) = (alpha.sqrt(), mu.unwrap());
            assert!((r - (y as f64 + 0.5) / 128.0).abs() < 1e-15);
            assert!((mu - (x as f64 + 0.5) / 128.0).abs() < 1e-15);
            assert_eq!(half(bits[3 * k]), f16_of(bias.value[k]), "R at {x}, {y}");
            assert_eq!(half(bits[3 * k + 1]), f16_of(e.value[k]), "G at {x}, {y}");
            if k % 61 == 0 {
                let cloth = kiln::integrate::sheen::sheen_albedo(alpha, mu, 1e-9).value[0];
                // The preset's quadrature tolerance and half-float rounding (half a spacing,
                // 2^-11 relative, or 2^-25 among the subnormals).
                let rounding = (cloth.abs() * 2f64.powi(-11)).max(2f64.powi(-25));
                assert!(
                    (half(bits[3 * k + 2]) - cloth).abs()
                        <= Preset::SHEEN_TOLERANCE + 2.0 * rounding,
                    "B at {x}, {y}: {} vs {cloth}",
                    half(bits[3 * k + 2])
                );
            }
        }
    }
    // The blue channel reads back as kiln's cloth values; an RG16F include (cmgen before the
    // cloth channel: two halves per texel) reads as the same R and G with no blue channel.
    let cloth = Preset::Filament.extra_channel().unwrap();
    assert_eq!(
        Preset::Filament
            .decode_extra(text.as_bytes())
            .unwrap()
            .unwrap(),
        cloth.value.iter().map(|&v| f16_of(v)).collect::<Vec<_>>()
    );
    let rg: String = bits
        .chunks(3)
        .map(|t| format!("0x{:04x}, 0x{:04x},\n", t[0], t[1]))
        .collect();
    assert_eq!(Preset::Filament.decode_extra(rg.as_bytes()).unwrap(), None);
    // A whole C array around the include reads the same (the last number before `}`).
    let wrapped = format!(
        "const uint16_t DFG_LUT[] = {{\n{}}};",
        text.trim_end().trim_end_matches(',')
    );
    assert_eq!(
        Preset::Filament.decode(wrapped.as_bytes()).unwrap(),
        Preset::Filament.decode(text.as_bytes()).unwrap()
    );
    assert_eq!(
        Preset::Filament.decode(rg.as_bytes()).unwrap(),
        Preset::Filament.decode(text.as_bytes()).unwrap()
    );
    // The audit of the blue channel: half-float rounding only, and a damaged texel is found.
    let audit = Preset::Filament
        .audit_extra(text.as_bytes())
        .unwrap()
        .unwrap();
    let largest = cloth.value.iter().fold(0.0f64, |m, &v| m.max(v));
    assert!(audit.max_error <= largest * 2f64.powi(-11) + Preset::SHEEN_TOLERANCE);
    let k = 77 * 128 + 40;
    let damaged_bits: Vec<u16> = bits
        .iter()
        .enumerate()
        .map(|(i, &b)| if i == 3 * k + 2 { 0 } else { b })
        .collect();
    let damaged: String = damaged_bits
        .iter()
        .map(|b| format!("0x{b:04x},\n"))
        .collect();
    let audit = Preset::Filament
        .audit_extra(damaged.as_bytes())
        .unwrap()
        .unwrap();
    let (alpha, mu) = e.spec.texel_coordinates(k);
    assert_eq!((audit.worst_alpha, audit.worst_mu), (alpha, mu.unwrap()));
    assert_eq!(audit.max_error, cloth.value[k]);
    assert_eq!(Preset::Filament.audit_extra(rg.as_bytes()).unwrap(), None);
    let back = Preset::Filament
        .read_tables(text.as_bytes(), "test")
        .unwrap();
    assert_eq!(back.len(), 2);
    assert_eq!(
        back[1].value,
        e.value.iter().map(|&v| f16_of(v)).collect::<Vec<_>>()
    );
    assert_eq!(back[1].spec.model, e.spec.model);
}

#[test]
fn godot_layout_is_rgba16f_dds_with_roughness_rows_from_the_top() {
    let tables = bake_to(Preset::Godot, 1e-4);
    let (bias, e) = (&tables[0], &tables[1]);
    assert_eq!(e.spec.model.masking, kiln::Masking::SchlickGgx);
    let bytes = Preset::Godot.encode(&tables).unwrap();
    let dds = ddsfile::Dds::read(bytes.as_slice()).unwrap();
    assert_eq!(
        dds.get_dxgi_format(),
        Some(ddsfile::DxgiFormat::R16G16B16A16_Float)
    );
    assert_eq!((dds.get_width(), dds.get_height()), (128, 128));
    let texel = |x: usize, row: usize, c: usize| {
        let i = 2 * (4 * (row * 128 + x) + c);
        f64::from(half::f16::from_le_bytes([dds.data[i], dds.data[i + 1]]).to_f32())
    };
    for row in 0..128 {
        for x in 0..128 {
            // integrate_dfg.glsl stores roughness index y at row 127 - y.
            let k = (127 - row) * 128 + x;
            let (alpha, mu) = e.spec.texel_coordinates(k);
            assert!((alpha.sqrt() - (1.0 - (row as f64 + 0.5) / 128.0)).abs() < 1e-14);
            assert!((mu.unwrap() - (x as f64 + 0.5) / 128.0).abs() < 1e-15);
            assert_eq!(texel(x, row, 0), f16_of(bias.value[k]));
            assert_eq!(texel(x, row, 1), f16_of(e.value[k]));
            assert_eq!(texel(x, row, 3), 1.0);
        }
    }
    let back = Preset::Godot.read_tables(&bytes, "test").unwrap();
    assert_eq!(
        back[0].value,
        bias.value.iter().map(|&v| f16_of(v)).collect::<Vec<_>>()
    );
}

#[test]
fn unity_hdrp_layout_is_sqrt_nov_nodes_with_disney_diffuse_in_blue() {
    let tables = bake_to(Preset::UnityHdrp, 1e-4);
    let (bias, e) = (&tables[0], &tables[1]);
    let bytes = Preset::UnityHdrp.encode(&tables).unwrap();
    let image = kiln::format::exr::decode(&bytes).unwrap();
    assert_eq!((image.width, image.height), (64, 64));
    let channel = |name: &str| &image.channels.iter().find(|(c, _)| c == name).unwrap().1;
    let (red, green, blue) = (channel("R"), channel("G"), channel("B"));
    for row in 0..64 {
        for x in 0..64 {
            // Unity: u = sqrt(NoV), v = perceptual roughness, both nodes i / 63 after its
            // half-texel remap; an imported image's top row is v = 1.
            let (r, t) = ((63 - row) as f64 / 63.0, x as f64 / 63.0);
            let k = (63 - row) * 64 + x;
            let (alpha, mu) = e.spec.texel_coordinates(k);
            assert!((alpha - r * r).abs() < 1e-15 && (mu.unwrap() - t * t).abs() < 1e-15);
            let at = row * 64 + x;
            assert_eq!(red[at], f16_of(bias.value[k]), "R at {x}, {row}");
            assert_eq!(green[at], f16_of(e.value[k]), "G at {x}, {row}");
            let diffuse = kiln::model::disney_diffuse::disney_diffuse_albedo(r, t * t) - 0.5;
            assert_eq!(blue[at], f16_of(diffuse), "B at {x}, {row}");
        }
    }
    assert_eq!(
        Preset::UnityHdrp.decode_extra(&bytes).unwrap().unwrap(),
        Preset::UnityHdrp
            .extra_channel()
            .unwrap()
            .value
            .iter()
            .map(|&v| f16_of(v))
            .collect::<Vec<_>>()
    );
    let back = Preset::UnityHdrp.read_tables(&bytes, "test").unwrap();
    assert_eq!(
        back[1].value,
        e.value.iter().map(|&v| f16_of(v)).collect::<Vec<_>>()
    );
    assert_eq!(back[1].spec.axes(), e.spec.axes());
}

#[test]
fn unreal_layout_is_e_and_e_fc_in_red_and_green_with_roughness_rows() {
    let tables = bake_to(Preset::Unreal, 1e-4);
    let (e, bias) = (&tables[0], &tables[1]);
    assert_eq!(
        (e.spec.quantity, bias.spec.quantity),
        (kiln::Quantity::E, kiln::Quantity::EBias)
    );
    let bytes = Preset::Unreal.encode(&tables).unwrap();
    let image = kiln::format::exr::decode(&bytes).unwrap();
    assert_eq!((image.width, image.height), (32, 32));
    let channel = |name: &str| &image.channels.iter().find(|(c, _)| c == name).unwrap().1;
    for row in 0..32 {
        for x in 0..32 {
            // Unreal samples float2(NoV, Roughness), v from the top row, texel centres.
            let k = row * 32 + x;
            let (alpha, mu) = e.spec.texel_coordinates(k);
            assert!((alpha.sqrt() - (row as f64 + 0.5) / 32.0).abs() < 1e-15);
            assert!((mu.unwrap() - (x as f64 + 0.5) / 32.0).abs() < 1e-15);
            assert_eq!(channel("R")[k], f16_of(e.value[k]));
            assert_eq!(channel("G")[k], f16_of(bias.value[k]));
            assert_eq!((channel("B")[k], channel("A")[k]), (0.0, 1.0));
        }
    }
    // Unreal's texture has no third quantity (its B is 0).
    assert_eq!(Preset::Unreal.decode_extra(&bytes).unwrap(), None);
    let back = Preset::Unreal.read_tables(&bytes, "test").unwrap();
    assert_eq!(back[0].spec.quantity, kiln::Quantity::E);
    assert_eq!(
        back[1].value,
        bias.value.iter().map(|&v| f16_of(v)).collect::<Vec<_>>()
    );
}

/// `1 - Ē` at row `j` of an engine's E table (`rows[j]`, `n` values over `mu` in kiln's order)
/// in closed form: the engine's lookup is linear in `mu` between its columns at `mu_k` (nodes
/// `k / (n - 1)`, or centres `(k + 0.5) / n` held constant to the edges), so `2 ∫ (1 - E) mu
/// dmu` is a sum of exact integrals of `mu (a + b mu)`. Independent of kiln's lookup and of its
/// adaptive quadrature.
fn one_minus_average_closed_form(row: &[f64], centres: bool) -> f64 {
    let n = row.len();
    let mu_k = |k: usize| {
        if centres {
            (k as f64 + 0.5) / n as f64
        } else {
            k as f64 / (n - 1) as f64
        }
    };
    // Breakpoints with the lookup's value there (constant ends for centres).
    let mut points: Vec<(f64, f64)> = (0..n).map(|k| (mu_k(k), 1.0 - row[k])).collect();
    if centres {
        points.insert(0, (0.0, 1.0 - row[0]));
        points.push((1.0, 1.0 - row[n - 1]));
    }
    points
        .windows(2)
        .map(|w| {
            let ((x0, y0), (x1, y1)) = (w[0], w[1]);
            let b = (y1 - y0) / (x1 - x0);
            let a = y0 - b * x0;
            // 2 ∫ mu (a + b mu) dmu = a mu^2 + 2 b mu^3 / 3.
            let f = |x: f64| a * x * x + 2.0 * b * x * x * x / 3.0;
            f(x1) - f(x0)
        })
        .sum()
}

/// Cycles and Enterprise PBR normalise by `E_avg`: kiln writes beside their files the
/// lookup-consistent normalisation of the table the engine file holds (f32 for Cycles, the
/// half floats of Enterprise PBR), `1 - Ē` itself on a 16x finer roughness axis. At every row of
/// the engine's E table it equals the closed-form average of that table's lookup (as read back
/// from the engine file), and between rows the linear interpolation is exact.
#[test]
fn cycles_and_enterprise_pbr_get_the_normalisation_of_their_own_lookup() {
    for (preset, file, centres) in [
        (
            Preset::Cycles,
            kiln::preset::CYCLES_NORMALISATION_FILE,
            false,
        ),
        (
            Preset::EnterprisePbr,
            kiln::preset::ENTERPRISE_NORMALISATION_FILE,
            true,
        ),
    ] {
        let tables = bake_to(preset, 1e-6);
        let files = preset.files(&tables).unwrap();
        let read = |name: &str| {
            let bytes = &files.iter().find(|(n, _)| n == name).unwrap().1;
            preset.read_tables(bytes, name).unwrap()
        };
        let e = read(preset.file_name()).remove(0);
        let norm = read(file).remove(0);
        assert_eq!(norm.spec.quantity, kiln::Quantity::FMsNorm);
        let n = 32;
        let entries = norm.value.len();
        for j in 0..n {
            let row = &e.value[j * n..(j + 1) * n];
            let truth = one_minus_average_closed_form(row, centres);
            // Row j sits at node 16 j (nodes) or 16 j + 8 (centres) of the normalisation axis.
            let at = 16 * j + if centres { 8 } else { 0 };
            let stored = norm.value[at];
            assert!(
                (stored - truth).abs() <= 1e-6 * truth + 1e-12,
                "{}: row {j}: stored {stored:e}, closed form {truth:e}",
                preset.name()
            );
            // Halfway between two rows the lookup average is the mean of theirs.
            if j + 1 < n {
                let next =
                    one_minus_average_closed_form(&e.value[(j + 1) * n..(j + 2) * n], centres);
                let r = (at as f64 + 8.0) / (entries - 1) as f64;
                let looked_up = kiln::table::normalisation::normalisation_lookup(&norm, r);
                let mid = 0.5 * (truth + next);
                assert!(
                    (looked_up - mid).abs() <= 1e-6 * mid + 1e-12,
                    "{}: r {r}: lookup {looked_up:e}, closed form {mid:e}",
                    preset.name()
                );
            }
        }
        // Below Enterprise PBR's first row centre the clamped lookup is constant.
        if centres {
            let first = one_minus_average_closed_form(&e.value[..n], true);
            let looked_up = kiln::table::normalisation::normalisation_lookup(&norm, 0.004);
            assert!((looked_up - first).abs() <= 1e-6 * first + 1e-12);
        }
    }
}

/// An 8-bit grey PNG read independently (the `png` crate, red channel; R = G = B checked).
fn grey_png(bytes: &[u8]) -> (usize, usize, Vec<u8>) {
    let decoder = png::Decoder::new(bytes);
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buffer).unwrap();
    assert_eq!(
        (frame.color_type, frame.bit_depth),
        (png::ColorType::Rgb, png::BitDepth::Eight)
    );
    let pixels: Vec<u8> = buffer[..frame.buffer_size()]
        .chunks_exact(3)
        .map(|p| {
            assert!(p[0] == p[1] && p[1] == p[2], "{p:?}");
            p[0]
        })
        .collect();
    (frame.width as usize, frame.height as usize, pixels)
}

/// GAMES202's homework reads `GGX_E_LUT.png` (row `i` at roughness `(i + 0.5) / 128`, column `j`
/// at NdotV `(j + 0.5) / 128`, written flipped so the roughest row is on top) and
/// `GGX_Eavg_LUT.png` (each row that roughness' `E_avg`), for GGX with separable Schlick-GGX
/// masking, `k = alpha / 2`. Checked against the reference computed here at the homework's own
/// coordinates, rounded to 8 bits.
#[test]
fn games202_layout_is_flipped_8_bit_grey_with_schlick_ggx() {
    use kiln::integrate::reference::{
        ReferenceSettings, reference_albedo, reference_average_albedo,
    };
    let tables = bake_to(Preset::Games202, 1e-4);
    let files = Preset::Games202.files(&tables).unwrap();
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["GGX_E_LUT.png", "GGX_Eavg_LUT.png"]);
    let model = kiln::Model {
        ndf: kiln::Ndf::Ggx,
        masking: kiln::Masking::SchlickGgx,
    };
    let settings = ReferenceSettings {
        tolerance: 1e-7,
        ..ReferenceSettings::default()
    };
    let unorm8 = |v: f64| (v * 255.0).round() as u8;
    let (w, h, e) = grey_png(&files[0].1);
    assert_eq!((w, h), (128, 128));
    for (y, x) in [
        (0, 0),
        (0, 127),
        (127, 0),
        (127, 127),
        (64, 3),
        (100, 40),
        (5, 90),
    ] {
        // The image's row y holds the homework's row i = 127 - y.
        let r = (127.0 - y as f64 + 0.5) / 128.0;
        let mu = (x as f64 + 0.5) / 128.0;
        let truth = reference_albedo(model, r * r, mu, &settings).value;
        assert_eq!(e[y * 128 + x], unorm8(truth), "y {y}, x {x}: {truth}");
    }
    let (w, h, avg) = grey_png(&files[1].1);
    assert_eq!((w, h), (128, 128));
    for y in [0, 1, 63, 126, 127] {
        let r = (127.0 - y as f64 + 0.5) / 128.0;
        let truth = reference_average_albedo(model, r * r, &settings).value;
        let row = &avg[y * 128..(y + 1) * 128];
        assert!(row.iter().all(|&p| p == unorm8(truth)), "y {y}: {truth}");
    }
    // Read back: each file gives its own table.
    let e_back = Preset::Games202.read_tables(&files[0].1, "e").unwrap();
    let avg_back = Preset::Games202.read_tables(&files[1].1, "avg").unwrap();
    assert_eq!(e_back[0].spec.quantity, kiln::Quantity::E);
    assert_eq!(avg_back[0].spec.quantity, kiln::Quantity::EAvg);
    assert_eq!(e_back[0].value[0], f64::from(e[127 * 128]) / 255.0);
}

/// A student's table as the homework writes it (`uint8(x * 255)`, truncated) audits at twice
/// what 8-bit storage alone costs, and the audit says both: storage alone (the true values
/// rounded) is at most half a step at the nodes, truncation up to a whole step.
#[test]
fn games202_audit_shows_what_8_bits_alone_cost_beside_a_truncated_table() {
    use kiln::integrate::reference::ReferenceSettings;
    use kiln::verify::{Against, AuditSettings, audit};
    let average = BakeOptions {
        max_error: Some(1e-6),
        quantities: vec![kiln::Quantity::EAvg],
        ..Preset::Games202.options()
    }
    .bake(&|_| {})
    .unwrap()
    .remove(0);
    let student: Vec<f64> = average
        .value
        .iter()
        .map(|&v| f64::from((v * 255.0) as u8) / 255.0)
        .collect();
    let table = Table {
        one_minus_value: student.iter().map(|v| 1.0 - v).collect(),
        value: student,
        ..average.clone()
    };
    assert_eq!(table.spec.quantity, kiln::Quantity::EAvg);
    let report = audit(
        &table,
        &Against::Reference(ReferenceSettings::default()),
        &AuditSettings {
            storage: Preset::Games202.storage(),
            ..AuditSettings::default()
        },
        &|_| {},
    );
    let cost = report.storage_cost.clone().expect("8-bit storage");
    assert_eq!(cost.storage, "8-bit");
    let step = 1.0 / 255.0;
    assert!(cost.node_max_error <= 0.5 * step + 1e-9, "{cost:?}");
    assert!(cost.node_max_error > 0.4 * step, "{cost:?}");
    assert!(
        report.node_max_error > 0.9 * step && report.node_max_error <= step,
        "{report:?}"
    );
    assert!(
        report.node_rms_error > 1.5 * cost.node_rms_error,
        "{report:?}"
    );
}

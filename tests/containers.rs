//! GPU containers and the C header, read back by independent readers: the `ktx2` crate (which
//! validates the header, the section bounds, the data format descriptor and the level index),
//! `ddsfile`, and a C compiler.

use crate::f16_oracle;

use kiln::format::{Format, Precision, as_stored, encode_all};
use kiln::{BakeOptions, MuMapping, Quantity, Table};
use std::sync::OnceLock;

/// A 2-D table (E), a 1-D table (E_avg), a 3-D table (E_dielectric) and the 1-D F_avg.
fn tables() -> &'static [Table] {
    static TABLES: OnceLock<Vec<Table>> = OnceLock::new();
    TABLES.get_or_init(|| {
        let options = BakeOptions {
            size: 5,
            ior_size: 3,
            mu_mapping: Some(MuMapping::Linear),
            max_error: Some(1e-4),
            ..BakeOptions::default()
        };
        let mut tables = options.bake(&|_| {}).unwrap();
        tables.extend(
            BakeOptions {
                quantities: vec![Quantity::EDielectric, Quantity::FAvg],
                size: 3,
                // kiln's glass layout, whose mu coordinate is its own.
                mu_mapping: Some(MuMapping::Adaptive),
                ..options
            }
            .bake(&|_| {})
            .unwrap(),
        );
        tables
    })
}

fn file<'a>(files: &'a [(String, Vec<u8>)], name: &str) -> &'a [u8] {
    &files.iter().find(|(n, _)| n == name).expect(name).1
}

/// The values a container holds for texel `k`, channel `c` (R = value, G = 1 - value).
fn decode(data: &[u8], precision: Precision, k: usize, c: usize) -> f64 {
    let i = (2 * k + c) * precision.bytes();
    match precision {
        Precision::F32 => f64::from(f32::from_le_bytes(data[i..i + 4].try_into().unwrap())),
        Precision::F16 => f64::from(half::f16::from_le_bytes([data[i], data[i + 1]]).to_f32()),
    }
}

/// What the stored value must be: the table's, rounded as kiln rounds.
fn expected(v: f64, precision: Precision) -> f64 {
    match precision {
        Precision::F32 => f64::from(v as f32),
        // Rounded to nearest even (the tests' own rounding), never flushed to zero
        // (docs/accuracy.md).
        Precision::F16 => f16_oracle::oracle(v),
    }
}

fn extent(table: &Table) -> (u32, u32, u32) {
    match table.spec.shape()[..] {
        [n] => (n as u32, 0, 0),
        [rows, columns] => (columns as u32, rows as u32, 0),
        [slices, rows, columns] => (columns as u32, rows as u32, slices as u32),
        _ => unreachable!(),
    }
}

#[test]
fn ktx2_files_parse_with_the_right_format_size_values_and_metadata() {
    for precision in [Precision::F16, Precision::F32] {
        let files = encode_all(tables(), &[Format::Ktx2], precision).unwrap();
        // As stored: an f16 file's f_ms_norm is derived from its f16 E (`as_stored`).
        for table in &as_stored(tables(), precision) {
            let id = table.spec.id();
            // f_ms_norm stays f32 whatever is asked (its smallest values are f16 subnormals).
            let precision = if table.spec.quantity == Quantity::FMsNorm {
                Precision::F32
            } else {
                precision
            };
            let bytes = file(&files, &format!("{id}.ktx2"));
            let reader = ktx2::Reader::new(bytes).unwrap_or_else(|e| panic!("{id}: {e:?}"));
            let header = reader.header();
            let format = match precision {
                Precision::F16 => ktx2::Format::R16G16_SFLOAT,
                Precision::F32 => ktx2::Format::R32G32_SFLOAT,
            };
            assert_eq!(header.format, Some(format), "{id}");
            let (w, h, d) = extent(table);
            assert_eq!(
                (header.pixel_width, header.pixel_height, header.pixel_depth),
                (w, h, d),
                "{id}"
            );
            assert_eq!(header.level_count, 1);
            // KTXwriter is a NUL-terminated string (KTX 2.0, 5.8).
            let writer = reader.writer().expect("KTXwriter").trim_end_matches('\0');
            assert_eq!(writer, format!("kiln {}", env!("CARGO_PKG_VERSION")));
            let levels: Vec<_> = reader.levels().collect();
            assert_eq!(levels.len(), 1);
            let data = levels[0].data;
            assert_eq!(data.len(), table.spec.len() * 2 * precision.bytes(), "{id}");
            for k in 0..table.spec.len() {
                assert_eq!(
                    decode(data, precision, k, 0),
                    expected(table.value[k], precision)
                );
                assert_eq!(
                    decode(data, precision, k, 1),
                    expected(table.one_minus_value[k], precision)
                );
            }
            let metadata = reader
                .key_value_data()
                .find(|(key, _)| *key == "kiln")
                .expect("kiln metadata")
                .1;
            let text = std::str::from_utf8(metadata)
                .unwrap()
                .trim_end_matches('\0');
            let json: serde_json::Value = serde_json::from_str(text).unwrap();
            assert_eq!(json["tables"][0]["quantity"], table.spec.quantity.symbol());
            assert_eq!(
                json["tables"][0]["spec"]["quantity"],
                table.spec.quantity.symbol()
            );
        }
    }
}

#[test]
fn dds_files_parse_with_the_right_format_size_and_values() {
    use ddsfile::{Dds, DxgiFormat};
    for precision in [Precision::F16, Precision::F32] {
        let files = encode_all(tables(), &[Format::Dds], precision).unwrap();
        // As stored: an f16 file's f_ms_norm is derived from its f16 E (`as_stored`).
        for table in &as_stored(tables(), precision) {
            let id = table.spec.id();
            // f_ms_norm stays f32 whatever is asked (its smallest values are f16 subnormals).
            let precision = if table.spec.quantity == Quantity::FMsNorm {
                Precision::F32
            } else {
                precision
            };
            let dds = Dds::read(file(&files, &format!("{id}.dds"))).unwrap();
            let format = match precision {
                Precision::F16 => DxgiFormat::R16G16_Float,
                Precision::F32 => DxgiFormat::R32G32_Float,
            };
            assert_eq!(dds.get_dxgi_format(), Some(format), "{id}");
            let (w, h, d) = extent(table);
            assert_eq!(dds.get_width(), w, "{id}");
            assert_eq!(dds.get_height(), h.max(1), "{id}");
            assert_eq!(dds.get_depth(), d.max(1), "{id}");
            assert_eq!(dds.data.len(), table.spec.len() * 2 * precision.bytes());
            for k in 0..table.spec.len() {
                assert_eq!(
                    decode(&dds.data, precision, k, 0),
                    expected(table.value[k], precision)
                );
            }
        }
    }
}

/// The header compiles as C, and the arrays hold the table: the float array the f32 values,
/// the half array the f16 bits of value and 1 - value, interleaved.
#[test]
fn c_headers_compile_and_hold_the_values() {
    let dir = tempfile::tempdir().unwrap();
    let files = encode_all(tables(), &[Format::H], Precision::F32).unwrap();
    let mut program = String::from("#include <stdio.h>\n");
    for (name, bytes) in &files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
        program += &format!("#include \"{name}\"\n");
    }
    program += "int main(void) {\n";
    for table in tables() {
        let name = kiln::format::c_header::name(table);
        program += &format!(
            "  for (int k = 0; k < {name}_SIZE; k++) printf(\"%.9g %.9g %u %u\\n\", \
             (double){name}[k], (double){name}_ONE_MINUS[k], (unsigned){name}_HALF[2 * k], \
             (unsigned){name}_HALF[2 * k + 1]);\n"
        );
    }
    program += "  return 0;\n}\n";
    std::fs::write(dir.path().join("main.c"), program).unwrap();
    let exe = dir.path().join("main");
    let status = std::process::Command::new("cc")
        .args(["-std=c99", "-Wall", "-Werror", "-o"])
        .arg(&exe)
        .arg(dir.path().join("main.c"))
        .status()
        .expect("a C compiler (the Rust toolchain's linker) runs");
    assert!(status.success(), "the generated header does not compile");
    let output = std::process::Command::new(&exe).output().unwrap();
    let text = String::from_utf8(output.stdout).unwrap();
    let mut lines = text.lines();
    for table in tables() {
        for k in 0..table.spec.len() {
            let fields: Vec<&str> = lines.next().unwrap().split(' ').collect();
            let value: f64 = fields[0].parse().unwrap();
            let one_minus: f64 = fields[1].parse().unwrap();
            assert_eq!(
                value as f32,
                table.value[k] as f32,
                "{} {k}",
                table.spec.id()
            );
            assert_eq!(one_minus as f32, table.one_minus_value[k] as f32);
            // Never flushed to zero: the smallest subnormal (docs/accuracy.md).
            // The oracle's value is an f16, so half's conversion of it is exact.
            let half = |v: f64| u32::from(half::f16::from_f64(f16_oracle::oracle(v)).to_bits());
            assert_eq!(fields[2].parse::<u32>().unwrap(), half(table.value[k]));
            assert_eq!(
                fields[3].parse::<u32>().unwrap(),
                half(table.one_minus_value[k])
            );
        }
    }
}

/// One-channel textures (a table's value alone, as an engine may upload it): `R16_SFLOAT` and
/// `R32_SFLOAT`, 2-D and 3-D.
#[test]
fn one_channel_ktx2_textures() {
    use kiln::format::ktx2::encode;
    use kiln::format::texture::Texture;
    for table in tables().iter().filter(|t| t.spec.shape().len() > 1) {
        let texture = Texture::of_values(&[table]).unwrap();
        for (precision, format) in [
            (Precision::F16, ktx2::Format::R16_SFLOAT),
            (Precision::F32, ktx2::Format::R32_SFLOAT),
        ] {
            let bytes = encode(&texture, precision).unwrap();
            let reader = ktx2::Reader::new(bytes.as_slice()).unwrap();
            assert_eq!(reader.header().format, Some(format), "{}", table.spec.id());
            let data = reader.levels().next().unwrap().data;
            assert_eq!(data.len(), table.spec.len() * precision.bytes());
            let last = table.spec.len() - 1;
            let i = last * precision.bytes();
            let stored = match precision {
                Precision::F16 => {
                    f64::from(half::f16::from_le_bytes([data[i], data[i + 1]]).to_f32())
                }
                Precision::F32 => f64::from(f32::from_le_bytes(data[i..i + 4].try_into().unwrap())),
            };
            assert_eq!(stored, expected(table.value[last], precision));
        }
    }
}

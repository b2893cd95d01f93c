//! External tables: the first byte picks the encoding (text, raw f32, raw f16, an EXR
//! channel) and the layout's shape, the rest is the file, read as `kiln verify FILE --shape`
//! reads it.
#![no_main]

use kiln::format::Precision;
use kiln::verify::input::{AxisName, Encoding, Layout, read_external};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, file)) = data.split_first() else {
        return;
    };
    let encoding = match pick % 4 {
        0 => Encoding::Text,
        1 => Encoding::Raw(Precision::F32),
        2 => Encoding::Raw(Precision::F16),
        _ => Encoding::ExrChannel("Y".into()),
    };
    let (shape, order, quantity) = match (pick / 4) % 3 {
        0 => (vec![4, 4], vec![AxisName::R, AxisName::Mu], kiln::Quantity::E),
        1 => (vec![4, 4], vec![AxisName::Mu, AxisName::R], kiln::Quantity::E),
        _ => (vec![8], vec![AxisName::R], kiln::Quantity::EAvg),
    };
    let layout = Layout {
        model: kiln::Model {
            ndf: kiln::Ndf::Ggx,
            masking: kiln::Masking::HeightCorrelated,
        },
        quantity,
        fresnel: None,
        shape,
        order,
        grid: kiln::Grid::Nodes,
        roughness: kiln::RoughnessConvention::Perceptual,
        mu_mapping: kiln::MuMapping::Linear,
    };
    let path = std::env::temp_dir().join(format!("kiln-fuzz-external-{}", std::process::id()));
    std::fs::write(&path, file).unwrap();
    if let Ok(table) = read_external(&path, &encoding, &layout) {
        assert!(table.value.iter().all(|v| v.is_finite()));
    }
});

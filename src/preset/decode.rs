//! Reading an engine's file by its [`Container`], one codec each: Cycles' C arrays, KTX2, DDS,
//! EXR planes, one EXR per table, 8-bit PNGs, three.js' module and Filament's include, each
//! giving the layout's tables in kiln's order and its extra channel.

#[cfg(feature = "containers")]
use super::container::little_endian;
use super::container::{Decoded, Orders, c_array, include_half_bits, three_data};
use super::layout::{Channel, Container, Layout, Normalisation};
use crate::error::{Error, Result};
#[cfg(feature = "containers")]
use crate::format::Precision;
use crate::table::Quantity;

/// Reads an engine's file of an `n x n` layout: its tables in kiln's order and its extra
/// channel. `normalisation_size` is the length of the layout's `f_ms_norm` (0 without).
/// `bad` makes the error for bytes that are not the engine's file.
pub(super) fn decode(
    layout: &Layout,
    bytes: &[u8],
    n: usize,
    normalisation_size: usize,
    bad: &dyn Fn(String) -> Error,
) -> Result<Decoded> {
    let reader = Reader {
        layout,
        n,
        normalisation_size,
        bad,
    };
    match layout.container {
        Container::CycleTables(arrays) => reader.c_tables(bytes, arrays),
        #[cfg(not(feature = "containers"))]
        Container::Ktx2 => Err(bad(
            "reading KTX2 needs kiln's `containers` feature".to_string()
        )),
        #[cfg(feature = "containers")]
        Container::Ktx2 => reader.ktx2(bytes),
        #[cfg(not(feature = "containers"))]
        Container::Dds => Err(bad(
            "reading DDS needs kiln's `containers` feature".to_string()
        )),
        #[cfg(feature = "containers")]
        Container::Dds => reader.dds(bytes),
        Container::ExrPlanes => reader.exr_planes(bytes),
        Container::ExrPerTable(files) => reader.exr_per_table(bytes, files),
        Container::Png8(files) => reader.png8(bytes, files),
        Container::ThreeModule => {
            let bits = three_data(bytes).map_err(|e| bad(e.to_string()))?;
            reader.half_bits_decoded(&bits, &[layout.channels.len()])
        }
        Container::HalfBitsInclude => {
            let bits = include_half_bits(bytes).map_err(|e| bad(e.to_string()))?;
            reader.half_bits_decoded(&bits, &[layout.channels.len(), reader.table_channels()])
        }
    }
}

/// What reading an engine's file of an `n x n` layout needs: one codec per container below.
struct Reader<'a> {
    layout: &'a Layout,
    n: usize,
    /// The length of the layout's `f_ms_norm` (0 without).
    normalisation_size: usize,
    /// Makes the error for bytes that are not the engine's file.
    bad: &'a dyn Fn(String) -> Error,
}

impl Reader<'_> {
    fn orders(&self) -> Orders<'_> {
        Orders {
            layout: self.layout,
            n: self.n,
        }
    }

    fn table_channels(&self) -> usize {
        self.layout
            .channels
            .iter()
            .filter(|c| matches!(c, Channel::Table(_)))
            .count()
    }

    /// The layout's channels from planes in the engine's order: the tables (each required) and
    /// the extra channel (kept if present).
    fn planes_decoded(&self, planes: &[Option<&[f64]>]) -> Result<Decoded> {
        let orders = self.orders();
        let mut tables = Vec::new();
        let mut extra = None;
        for (k, channel) in self.layout.channels.iter().enumerate() {
            let plane = planes.get(k).copied().flatten();
            match channel {
                Channel::Table(q) => {
                    let plane = plane
                        .ok_or_else(|| (self.bad)(format!("no channel for {}", q.symbol())))?;
                    tables.push((*q, orders.kiln(plane)));
                }
                // All zeros: not computed when the file was written (no material asked).
                Channel::Extra => {
                    extra = plane
                        .filter(|p| p.iter().any(|&v| v != 0.0))
                        .map(|p| orders.kiln(p));
                }
                Channel::Constant(_) => {}
            }
        }
        Ok((tables, extra))
    }

    /// Interleaved half floats with every channel, or only the tables' (an RG16F Filament
    /// include from before the cloth channel, a Godot texture without it).
    fn half_bits_decoded(&self, bits: &[u16], strides: &[usize]) -> Result<Decoded> {
        let n = self.n;
        let stride = strides
            .iter()
            .copied()
            .find(|&s| bits.len() == s * n * n)
            .ok_or_else(|| {
                let expected: Vec<String> =
                    strides.iter().map(|s| (s * n * n).to_string()).collect();
                (self.bad)(format!(
                    "{} half floats (expected {} for {n} x {n} texels)",
                    bits.len(),
                    expected.join(" or ")
                ))
            })?;
        // Channel `c` of `stride` interleaved half floats per texel.
        let half_plane = |c: usize| -> Vec<f64> {
            (0..n * n)
                .map(|k| f64::from(half::f16::from_bits(bits[stride * k + c]).to_f32()))
                .collect()
        };
        let planes: Vec<Vec<f64>> = (0..stride).map(half_plane).collect();
        let planes: Vec<Option<&[f64]>> = planes.iter().map(|p| Some(p.as_slice())).collect();
        self.planes_decoded(&planes)
    }

    /// Cycles' `shader.tables`: C float arrays, the glass tables' among them if present.
    fn c_tables(&self, bytes: &[u8], arrays: &[(&str, Quantity)]) -> Result<Decoded> {
        let (layout, n, bad) = (self.layout, self.n, self.bad);
        let normalisation_size = self.normalisation_size;
        let text = String::from_utf8_lossy(bytes);
        if let Some(Normalisation::CycleTable(_)) = layout.normalisation
            && let Some(norm) = c_array(&text, "table_ggx_f_ms_norm")
        {
            if norm.len() != normalisation_size {
                return Err(bad(format!(
                    "table_ggx_f_ms_norm has {} values (expected {normalisation_size})",
                    norm.len()
                )));
            }
            return Ok((vec![(Quantity::FMsNorm, norm)], None));
        }
        // Each array read once; every required one must be there before any size is
        // checked (a file from before Cycles' glass tables, or without them, is read
        // without them).
        let found: Vec<(&str, Quantity, Option<Vec<f64>>)> = arrays
            .iter()
            .map(|&(name, quantity)| (name, quantity, c_array(&text, name)))
            .collect();
        if let Some((name, _, _)) = found
            .iter()
            .find(|(_, q, values)| !q.has_ior() && values.is_none())
        {
            return Err(bad(format!("no {name}")));
        }
        let mut tables = Vec::new();
        for (name, quantity, values) in found {
            let Some(values) = values else { continue };
            let glass = quantity.has_ior().then_some(layout.glass).flatten();
            let (side, slices) = match glass {
                Some(g) => (g.size, g.size),
                None => (n, 1),
            };
            let expected = slices * if quantity.has_mu() { side * side } else { side };
            if values.len() != expected {
                return Err(bad(format!(
                    "{name} has {} values (expected {expected})",
                    values.len()
                )));
            }
            let values = if quantity.has_mu() {
                let orders = Orders { layout, n: side };
                values
                    .chunks(side * side)
                    .flat_map(|slice| orders.kiln(slice))
                    .collect()
            } else {
                values
            };
            tables.push((quantity, values));
        }
        Ok((tables, None))
    }

    /// Bevy's KTX2 texture: f16 channels.
    #[cfg(feature = "containers")]
    fn ktx2(&self, bytes: &[u8]) -> Result<Decoded> {
        let (layout, n, bad) = (self.layout, self.n, self.bad);
        let texture = crate::format::ktx2::decode(bytes).map_err(|e| bad(e.to_string()))?;
        let channels = layout.channels.len();
        if texture.channels.len() != channels
            || texture.precision != Precision::F16
            || texture.extent != (n, n, 1)
        {
            return Err(bad(format!(
                "expected {n} x {n} with {channels} f16 channels, found {} x {} x {} with {} \
                 {} channels",
                texture.extent.0,
                texture.extent.1,
                texture.extent.2,
                texture.channels.len(),
                texture.precision.name()
            )));
        }
        let planes: Vec<Option<&[f64]>> = texture
            .channels
            .iter()
            .map(|v| Some(v.as_slice()))
            .collect();
        self.planes_decoded(&planes)
    }

    /// Godot's DDS texture: RGBA16F or RG16F.
    #[cfg(feature = "containers")]
    fn dds(&self, bytes: &[u8]) -> Result<Decoded> {
        let (layout, n, bad) = (self.layout, self.n, self.bad);
        let table_channels = self.table_channels();
        let dds = ddsfile::Dds::read(bytes).map_err(|e| bad(format!("not a DDS file ({e})")))?;
        let format = dds.get_dxgi_format();
        let stride = match format {
            Some(ddsfile::DxgiFormat::R16G16B16A16_Float) => 4,
            Some(ddsfile::DxgiFormat::R16G16_Float) => 2,
            _ => 0,
        };
        if !(stride == layout.channels.len() || stride == table_channels)
            || (dds.get_width(), dds.get_height()) != (n as u32, n as u32)
            || dds.data.len() < 2 * stride * n * n
        {
            return Err(bad(format!(
                "expected {n} x {n} with {} f16 channels, found {} x {} {format:?}",
                layout.channels.len(),
                dds.get_width(),
                dds.get_height()
            )));
        }
        let bits = little_endian(&dds.data[..2 * stride * n * n]);
        self.half_bits_decoded(&bits, &[stride])
    }

    /// An EXR with the layout's channels as R, G, B and A.
    fn exr_planes(&self, bytes: &[u8]) -> Result<Decoded> {
        let (layout, n, bad) = (self.layout, self.n, self.bad);
        let image =
            crate::format::exr::decode(bytes).map_err(|e| bad(format!("not an EXR file ({e})")))?;
        if (image.width, image.height) != (n, n) {
            return Err(bad(format!(
                "{} x {} (expected {n} x {n})",
                image.width, image.height
            )));
        }
        let plane = |name: &str| {
            image
                .channels
                .iter()
                .find(|(c, _)| c == name)
                .map(|(_, values)| values.as_slice())
        };
        let planes: Vec<Option<&[f64]>> = ["R", "G", "B", "A"]
            .iter()
            .take(layout.channels.len())
            .map(|name| plane(name))
            .collect();
        self.planes_decoded(&planes)
    }

    /// One EXR per table, its channel Y: which table it is by its size.
    fn exr_per_table(&self, bytes: &[u8], files: &[(&str, Quantity)]) -> Result<Decoded> {
        let (layout, n, bad) = (self.layout, self.n, self.bad);
        let normalisation_size = self.normalisation_size;
        let orders = self.orders();
        let image = crate::format::exr::decode(bytes).map_err(|e| bad(e.to_string()))?;
        let (_, values) = image
            .channels
            .iter()
            .find(|(name, _)| name == "Y")
            .ok_or_else(|| bad("no channel Y".into()))?;
        let size = (image.width, image.height);
        for &(_, quantity) in files {
            match (quantity.has_mu(), size) {
                (true, s) if s == (n, n) => {
                    return Ok((vec![(quantity, orders.kiln(values))], None));
                }
                (false, s) if s == (n, 1) => {
                    return Ok((vec![(quantity, values.clone())], None));
                }
                _ => {}
            }
        }
        if let Some(Normalisation::ExrF32(_)) = layout.normalisation
            && size == (normalisation_size, 1)
        {
            return Ok((vec![(Quantity::FMsNorm, values.clone())], None));
        }
        let mut expected: Vec<String> = files
            .iter()
            .map(|&(file, q)| {
                let (w, h) = if q.has_mu() { (n, n) } else { (n, 1) };
                format!("{file}, {w} x {h}")
            })
            .collect();
        if let Some(form) = layout.normalisation {
            expected.push(format!("{}, {normalisation_size} x 1", form.file()));
        }
        Err(bad(format!(
            "{} x {} (expected {})",
            size.0,
            size.1,
            expected.join(", or ")
        )))
    }

    /// One 8-bit grey PNG per table: the 1-D table's rows are each one value.
    fn png8(&self, bytes: &[u8], files: &[(&str, Quantity)]) -> Result<Decoded> {
        let (layout, n, bad) = (self.layout, self.n, self.bad);
        let orders = self.orders();
        let plane =
            crate::format::png::decode_grey(bytes, (n, n)).map_err(|e| bad(e.to_string()))?;
        // A file whose rows are each one value is the 1-D table's; otherwise the 2-D one's.
        let rows_are_constant = plane
            .chunks_exact(n)
            .all(|row| row.iter().all(|&v| v == row[0]));
        let one_d = files.iter().find(|(_, q)| !q.has_mu());
        let two_d = files.iter().find(|(_, q)| q.has_mu());
        match (rows_are_constant, one_d, two_d) {
            (true, Some(&(_, quantity)), _) => {
                let values = (0..n).map(|r| plane[layout.order.index(r, 0, n)]).collect();
                Ok((vec![(quantity, values)], None))
            }
            (_, _, Some(&(_, quantity))) => Ok((vec![(quantity, orders.kiln(&plane))], None)),
            _ => Err(bad("no table of this layout fits the image".to_string())),
        }
    }
}

//! Reading and writing an engine's file by its [`Container`]: the generic texture containers
//! (KTX2, DDS, EXR planes, one EXR per table) take any [`Layout`]; the engines' own text formats
//! (Cycles' C arrays, three.js' module, Filament's include) are written here once each.

use super::layout::{Channel, Container, Layout, Normalisation};
use super::{ExtraChannel, Files};
use crate::error::{Error, Result};
use crate::format::Precision;
use crate::format::comment::safe;
use crate::format::texture::Texture;
use crate::model::dielectric::TransmissionConvention;
use crate::table::{Quantity, Table};
use std::fmt::Write as _;

/// An engine file's tables (quantity, values in kiln's order) and its extra channel.
pub(super) type Decoded = (Vec<(Quantity, Vec<f64>)>, Option<Vec<f64>>);

/// The values of an `n x n` plane moved between kiln's order (roughness rows, `mu` columns)
/// and the engine's ([`super::layout::TexelOrder`]).
pub(super) struct Orders<'a> {
    pub(super) layout: &'a Layout,
    pub(super) n: usize,
}

impl Orders<'_> {
    fn engine(&self, values: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut out = vec![0.0; n * n];
        for r in 0..n {
            for m in 0..n {
                out[self.layout.order.index(r, m, n)] = values[r * n + m];
            }
        }
        out
    }

    pub(super) fn kiln(&self, engine: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut out = vec![0.0; n * n];
        for r in 0..n {
            for m in 0..n {
                out[r * n + m] = engine[self.layout.order.index(r, m, n)];
            }
        }
        out
    }
}

/// The table of `quantity` among `tables`.
fn table_of(tables: &[Table], quantity: Quantity) -> Result<&Table> {
    tables
        .iter()
        .find(|t| t.spec.quantity == quantity)
        .ok_or_else(|| {
            Error::InvalidInput(format!("the layout needs the {} table", quantity.symbol()))
        })
}

/// The layout's channels as planes in the engine's order, with their names in a container that
/// names them (the table's symbol, the extra channel's name, `A` for a constant).
fn planes(
    layout: &Layout,
    n: usize,
    tables: &[Table],
    extra: Option<&ExtraChannel>,
) -> Result<Vec<(String, Vec<f64>)>> {
    let orders = Orders { layout, n };
    layout
        .channels
        .iter()
        .map(|channel| {
            Ok(match *channel {
                Channel::Table(q) => (
                    q.symbol().to_string(),
                    orders.engine(&table_of(tables, q)?.value),
                ),
                // Not computed (no material asks for its effect): zeros.
                Channel::Extra => {
                    let name = layout.extra.map_or("extra", |e| e.channel_name());
                    let values =
                        extra.map_or_else(|| vec![0.0; n * n], |e| orders.engine(&e.value));
                    (name.to_string(), values)
                }
                Channel::Constant(c) => ("A".to_string(), vec![c; n * n]),
            })
        })
        .collect()
}

/// The tables a texture container's metadata describes: those of its channels, in order.
fn channel_tables<'a>(layout: &Layout, tables: &'a [Table]) -> Result<Vec<&'a Table>> {
    layout
        .channels
        .iter()
        .filter_map(|c| match c {
            Channel::Table(q) => Some(table_of(tables, *q)),
            _ => None,
        })
        .collect()
}

/// Every file of the engine's own (the normalisation beside them is the caller's): the main file
/// first.
pub(super) fn encode(
    layout: &Layout,
    tables: &[Table],
    extra: Option<&ExtraChannel>,
    carried: Option<&Carried>,
) -> Result<Files> {
    let n = layout.size;
    let invalid = Error::InvalidInput;
    let main = |bytes: Vec<u8>| -> Files { vec![(layout.file_name.to_string(), bytes)] };
    match layout.container {
        Container::CycleTables(arrays) => Ok(main(cycle_tables(layout, arrays, tables, carried)?)),
        Container::Ktx2 => {
            let mut texture = Texture::of_values(&channel_tables(layout, tables)?)
                .map_err(|e| invalid(e.to_string()))?;
            texture.channels = planes(layout, n, tables, extra)?;
            #[cfg(feature = "containers")]
            let scheme = crate::format::ktx2::Supercompression::Zstd;
            #[cfg(not(feature = "containers"))]
            let scheme = crate::format::ktx2::Supercompression::None;
            crate::format::ktx2::encode_with(&texture, Precision::F16, scheme)
                .map_err(|e| invalid(e.to_string()))
                .map(main)
        }
        #[cfg(not(feature = "containers"))]
        Container::Dds => Err(invalid(
            "writing DDS needs kiln's `containers` feature".to_string(),
        )),
        #[cfg(feature = "containers")]
        Container::Dds => {
            let mut texture = Texture::of_values(&channel_tables(layout, tables)?)
                .map_err(|e| invalid(e.to_string()))?;
            texture.channels = planes(layout, n, tables, extra)?;
            crate::format::dds::encode(&texture, Precision::F16)
                .map_err(|e| invalid(e.to_string()))
                .map(main)
        }
        Container::ExrPlanes => {
            let planes = planes(layout, n, tables, extra)?;
            let named: Vec<(&str, &[f64])> = ["R", "G", "B", "A"]
                .into_iter()
                .zip(&planes)
                .map(|(name, (_, values))| (name, values.as_slice()))
                .collect();
            // The metadata is the E table's (the one every such engine holds).
            let described = table_of(tables, Quantity::E)?;
            crate::format::exr::encode_planes(described, &named, Precision::F16)
                .map_err(|e| invalid(e.to_string()))
                .map(main)
        }
        Container::ExrPerTable(files) => files
            .iter()
            .map(|&(file, quantity)| {
                let table = table_of(tables, quantity)?;
                let bytes = crate::format::exr::encode_value_as(table, "Y", Precision::F16)
                    .map_err(|e| invalid(e.to_string()))?;
                Ok((file.to_string(), bytes))
            })
            .collect(),
        Container::Png8(files) => files
            .iter()
            .map(|&(file, quantity)| {
                let table = table_of(tables, quantity)?;
                let plane = if quantity.has_mu() {
                    Orders { layout, n }.engine(&table.value)
                } else {
                    // Each roughness' value along its row, the rows in the layout's order.
                    let mut plane = vec![0.0; n * n];
                    for (r, &v) in table.value.iter().enumerate() {
                        let row = layout.order.index(r, 0, n) / n;
                        plane[row * n..(row + 1) * n].fill(v);
                    }
                    plane
                };
                let comment = format!(
                    "kiln {}: {} of GGX with separable Schlick-GGX masking (k = alpha / 2), \
                     rounded to 8 bits; regenerate: {}",
                    crate::format::metadata::KILN_VERSION,
                    quantity.symbol(),
                    safe(&table.command)
                );
                let bytes = crate::format::png::encode_grey8((n, n), &plane, &comment)
                    .map_err(|e| invalid(e.to_string()))?;
                Ok((file.to_string(), bytes))
            })
            .collect(),
        Container::ThreeModule => {
            let planes = planes(layout, n, tables, extra)?;
            Ok(main(
                three_module(n, &planes, &tables[0].command).into_bytes(),
            ))
        }
        Container::HalfBitsInclude => {
            let planes = planes(layout, n, tables, extra)?;
            Ok(main(
                filament_include(n, &planes, extra.map(|e| e.max_error), &tables[0].command)
                    .into_bytes(),
            ))
        }
    }
}

/// The file of the lookup-consistent normalisation `norm` ([`Normalisation`]).
pub(super) fn encode_normalisation(form: Normalisation, norm: &Table) -> Result<Vec<u8>> {
    match form {
        Normalisation::CycleTable(_) => {
            let rows = norm.value.len();
            let mut out = format!(
                "/* kiln {}: the lookup-consistent normalisation of the Kulla-Conty lobe for \
                 Cycles' table_ggx_E (shader.tables).\n * table_ggx_f_ms_norm[i] = 1 - \
                 Ebar(r) at r = i / {}, Ebar the cosine-weighted average of table_ggx_E's \
                 bilinear lookup (as\n * lookup_table_read_2D reads it), linear between \
                 entries; f_ms = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - Ebar(r))).\n * \
                 Regenerate: {}\n */\n",
                crate::format::metadata::KILN_VERSION,
                rows - 1,
                safe(&norm.command)
            );
            crate::format::c_header::float_array(&mut out, "table_ggx_f_ms_norm", &norm.value);
            Ok(out.into_bytes())
        }
        // Values from 1e-7 to 1: stored in f32, as f16 would lose the small ones.
        Normalisation::ExrF32(_) => crate::format::exr::encode_value_as(norm, "Y", Precision::F32),
    }
}

/// The engine's arrays that kiln does not compute ([`Layout::carried`]), read from the engine's
/// own file as numbers and written back by kiln: nothing of the file's text but the numbers'
/// values reaches the output (no declaration, no comment, no token between the numbers).
#[derive(Clone, Debug, PartialEq)]
pub struct Carried {
    /// Where they come from, for the file's header (written through
    /// [`crate::format::comment::safe`]).
    pub origin: String,
    /// Each array: the layout's name for it and its numbers, as the C compiler stores them.
    pub arrays: Vec<(&'static str, Vec<f32>)>,
}

impl Carried {
    /// The layout's carried arrays from the engine's file `bytes` (named `origin`).
    ///
    /// # Errors
    /// If the file lacks one of them, or its braces hold anything but its declared number of
    /// finite numbers (C float literals, `f` suffixes allowed).
    pub fn from_file(layout: &Layout, bytes: &[u8], origin: &str) -> Result<Self> {
        let text = String::from_utf8_lossy(bytes);
        let shown = crate::error::quoted(origin);
        let arrays = layout
            .carried
            .iter()
            .map(|&name| {
                let (declared, body) = c_declaration(&text, name).ok_or_else(|| {
                    Error::InvalidInput(format!(
                        "{shown} has no array {name} to carry over (expected `static const \
                         float {name}[N] = {{ ... }};`, as in Blender's shader.tables)"
                    ))
                })?;
                let values = c_numbers(body);
                match (declared, values) {
                    (Some(n), Some(values)) if values.len() == n => Ok((name, values)),
                    (declared, values) => Err(Error::InvalidInput(format!(
                        "{shown}: {name} is not an array of numbers of its declared size \
                         ({} declared, {} numbers read): not carried over",
                        declared.map_or("no size".to_string(), |n| n.to_string()),
                        values.map_or("no".to_string(), |v| v.len().to_string())
                    ))),
                }
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            origin: origin.to_string(),
            arrays,
        })
    }
}

/// The declaration of the C array `name`: its declared size (`None` if not a whole number)
/// and the text between its braces, from the first `name[` on (the whole identifier: not
/// `table_ggx_E` inside `table_ggx_Eavg`, nor the name in a comment).
fn c_declaration<'a>(text: &'a str, name: &str) -> Option<(Option<usize>, &'a str)> {
    let mut from = 0;
    loop {
        let at = from + text[from..].find(name)?;
        let before = text[..at].chars().next_back();
        let after = text[at + name.len()..].trim_start();
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_') || !after.starts_with('[')
        {
            from = at + name.len();
            continue;
        }
        let (size, rest) = after[1..].split_once(']')?;
        let (_, rest) = rest.split_once('{')?;
        let (body, _) = rest.split_once('}')?;
        return Some((size.trim().parse::<usize>().ok(), body));
    }
}

/// The numbers of a C array's braces: comma-separated C float literals (digits, one point, an
/// exponent, an `f` suffix, a sign) and nothing else but white space; `None` if any item is
/// something else or not finite.
fn c_numbers(body: &str) -> Option<Vec<f32>> {
    let mut items: Vec<&str> = body.split(',').map(str::trim).collect();
    // A trailing comma leaves one empty item.
    if items.last() == Some(&"") {
        items.pop();
    }
    items
        .into_iter()
        .map(|item| {
            let number = item.strip_suffix(['f', 'F']).unwrap_or(item);
            let literal = !number.is_empty()
                && number
                    .chars()
                    .all(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-'));
            let value = number.parse::<f32>().ok().filter(|v| v.is_finite());
            value.filter(|_| literal)
        })
        .collect()
}

/// Appends a carried array as Blender writes its own: `static const float name[N] = {`, 32
/// numbers a line indented by two spaces, each with five decimals where that is the number
/// (else the shortest literal that is), `};`.
fn carried_array(out: &mut String, name: &str, values: &[f32]) {
    let literal = |v: f32| {
        let five = format!("{v:.5}");
        if five.parse::<f32>().map(f32::to_bits) == Ok(v.to_bits()) {
            format!("{five}f")
        } else {
            let shortest = format!("{v:?}");
            if shortest.contains(['.', 'e']) {
                format!("{shortest}f")
            } else {
                format!("{shortest}.0f")
            }
        }
    };
    let _ = write!(out, "static const float {name}[{}] = {{", values.len());
    for (k, &v) in values.iter().enumerate() {
        out.push_str(match (k % 32, k) {
            (_, 0) => "\n  ",
            (0, _) => ",\n  ",
            _ => ", ",
        });
        out.push_str(&literal(v));
    }
    out.push_str("\n};\n\n");
}

/// Cycles' `shader.tables`: each array of the layout under its name (2-D tables in the layout's
/// texel order, the glass tables one such slice per IOR node, averages by roughness), inside
/// Cycles' namespace as Blender's file is; the glass arrays only when baked (a scene without
/// transmission), the carried ones when given.
fn cycle_tables(
    layout: &Layout,
    arrays: &[(&str, Quantity)],
    tables: &[Table],
    carried: Option<&Carried>,
) -> Result<Vec<u8>> {
    let n = layout.size;
    let has = |q: Quantity| tables.iter().any(|t| t.spec.quantity == q);
    let mut header = format!(
        "/* kiln {}: Cycles' albedo tables (shader.tables), GGX, height-correlated.\n * \
         table_ggx_E, table_ggx_Eavg: F = 1; index = mu_index * {n} + r_index, mu = j / {}, r = \
         i / {} (alpha = r^2), exact nodes.\n",
        crate::format::metadata::KILN_VERSION,
        n - 1,
        n - 1,
    );
    if let Some(glass) = layout.glass {
        let g = glass.size;
        if glass.tables.iter().all(|&q| has(q)) {
            let _ = write!(
                header,
                " * table_ggx_glass_*: energy albedo R + T of a rough dielectric, {}\n *   \
                 index = z_index * {} + mu_index * {g} + r_index (E),\n *   \
                 z_index * {g} + r_index (Eavg); z = clamp(k / {}, 1e-4, 0.99), ior = (1 + z^2) \
                 / (1 - z^2), _inv_ at 1 / ior;\n *   mu, r = k / {} (alpha = r^2), exact nodes.\n",
                match glass.transmission {
                    TransmissionConvention::Cycles => {
                        "in Cycles' convention (a refraction ending on the incident side kept; \
                         |ior - 1| < 1e-4 smooth);"
                    }
                    TransmissionConvention::SingleScattering => "single scattering;",
                },
                g * g,
                g - 1,
                g - 1
            );
        } else {
            header.push_str(
                " * table_ggx_glass_*: not baked (no material asks for transmission): keep \
                 Blender's.\n",
            );
        }
    }
    for name in layout.carried {
        match carried {
            Some(c) => {
                let _ = writeln!(
                    header,
                    " * {name}: not made by kiln (an LTC fit), its numbers carried over from \
                     {}.",
                    safe(&c.origin)
                );
            }
            None => {
                let _ = writeln!(
                    header,
                    " * {name}: not made by kiln (an LTC fit) and not in this file: Cycles \
                     needs it, so keep Blender's\n *   (kiln bake --preset {} --carry-over \
                     path/to/blender/shader.tables writes it in).",
                    layout.name
                );
            }
        }
    }
    let mut out = header;
    let _ = write!(
        out,
        " * Regenerate: {}\n */\n\nCCL_NAMESPACE_BEGIN\n\n",
        safe(&tables[0].command)
    );
    for &(name, quantity) in arrays {
        let glass = quantity.has_ior().then_some(layout.glass).flatten();
        let values = match glass {
            Some(_) if !has(quantity) => continue,
            Some(g) if quantity.has_mu() => {
                let orders = Orders { layout, n: g.size };
                table_of(tables, quantity)?
                    .value
                    .chunks(g.size * g.size)
                    .flat_map(|slice| orders.engine(slice))
                    .collect()
            }
            None if quantity.has_mu() => {
                Orders { layout, n }.engine(&table_of(tables, quantity)?.value)
            }
            _ => table_of(tables, quantity)?.value.clone(),
        };
        crate::format::c_header::float_array(&mut out, name, &values);
        out.push('\n');
    }
    if let Some(c) = carried {
        for (name, values) in &c.arrays {
            carried_array(&mut out, name, values);
        }
    }
    out.push_str("CCL_NAMESPACE_END\n");
    Ok(out.into_bytes())
}

/// Little-endian 16-bit words (a container's half floats).
#[cfg(feature = "containers")]
pub(super) fn little_endian(data: &[u8]) -> Vec<u16> {
    data.chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .collect()
}

/// The numbers of the C float array `name` (`name[...] = { ... }`), `f` suffixes allowed, read
/// as f32 (what the C compiler stores) and widened.
pub(super) fn c_array(text: &str, name: &str) -> Option<Vec<f64>> {
    let (_, body) = c_declaration(text, name)?;
    body.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.trim_end_matches(['f', 'F'])
                .parse::<f32>()
                .ok()
                .map(f64::from)
        })
        .collect()
}

/// Half-float bits, one per channel per texel, as hex literals.
fn half_bits(value: f64) -> u16 {
    crate::format::f16::encode(value).0.to_bits()
}

/// Filament's `dfg.inc` (included inside `DFG_LUT[]`): the planes' half-float bits interleaved
/// per texel as C hex literals, four texels per line, after a comment saying what they hold
/// (`sheen_max_error`: the cloth channel's error estimate, `None` when it was not computed and
/// holds 0).
fn filament_include(
    n: usize,
    planes: &[(String, Vec<f64>)],
    sheen_max_error: Option<f64>,
    command: &str,
) -> String {
    let blue = match sheen_max_error {
        Some(e) => format!(
            "cloth albedo (Charlie NDF, Ashikhmin visibility), quadrature error estimate <= \
             {e:.0e}"
        ),
        None => "0 (no material asks for sheen: the cloth albedo was not computed)".to_string(),
    };
    let mut out = format!(
        "// kiln {}: Filament's DFG LUT (dfg.inc), {n} x {n} RGB16F half-float bits in GL \
         order,\n// x = NoV = (i + 0.5) / {n}, y = perceptual roughness = (j + 0.5) / {n} \
         (alpha = r^2), texel centres.\n// R = integral of Fc f mu_i, G = integral of f mu_i \
         (GGX, height-correlated, F = 1);\n// B = {blue}.\n// Regenerate: {}\n",
        crate::format::metadata::KILN_VERSION,
        safe(command)
    );
    for k in 0..n * n {
        for (_, plane) in planes {
            let _ = write!(out, "0x{:04x}, ", half_bits(plane[k]));
        }
        if k % 4 == 3 {
            out.truncate(out.trim_end().len());
            out.push('\n');
        }
    }
    out
}

/// Every `0x` number outside `//` comments of a Filament include: RGB (or, from cmgen before
/// the cloth channel, RG) half-float bits per texel.
pub(super) fn include_half_bits(bytes: &[u8]) -> crate::Result<Vec<u16>> {
    let text = String::from_utf8_lossy(bytes);
    text.lines()
        .map(|line| line.split("//").next().unwrap_or(""))
        .flat_map(|line| line.split(','))
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .filter_map(|s| s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")))
        // The digits only: the last number may run into the closing `};`.
        .map(|s| {
            s.split(|c: char| !c.is_ascii_hexdigit())
                .next()
                .unwrap_or("")
        })
        .map(|s| u16::from_str_radix(s, 16).map_err(|e| Error::Malformed(format!("'0x{s}': {e}"))))
        .collect()
}

/// The largest three.js table kiln reads (its releases shipped 16 and 32).
pub(super) const MAX_THREE_SIZE: usize = 256;

/// three.js' `DFGLUTData.js` as three ships it (`src/renderers/shaders/DFGLUTData.js`): a header
/// comment, the imports of `DataTexture` and the constants, the private `DATA` (the planes'
/// half-float bits interleaved, one row of `n` texels per line) and the exported `getDFGLUT()`
/// that builds the `DataTexture` once, so that kiln's file replaces three's as is.
fn three_module(n: usize, planes: &[(String, Vec<f64>)], command: &str) -> String {
    let mut out = format!(
        "/**\n * Precomputed DFG LUT for physically based specular lighting, used by both\n * \
         image-based lighting and direct-light multi-scattering energy compensation\n * \
         Resolution: {n}x{n}\n * Written by kiln {}: GGX, height-correlated Smith masking, by \
         quadrature\n * (not sampled), each value the nearest half float\n * Format: RG16F (2 \
         half floats per texel: scale, bias); u = roughness, v = dotNV, texel centres\n * \
         Regenerate: {}\n */\n\nimport {{ DataTexture }} from \
         '../../textures/DataTexture.js';\nimport {{ RGFormat, HalfFloatType, LinearFilter, \
         ClampToEdgeWrapping }} from '../../constants.js';\n\nconst DATA = new Uint16Array( [",
        crate::format::metadata::KILN_VERSION,
        safe(command)
    );
    for row in 0..n {
        out.push_str("\n\t");
        for column in 0..n {
            let k = row * n + column;
            let texel: Vec<String> = planes
                .iter()
                .map(|(_, plane)| format!("0x{:04x}", half_bits(plane[k])))
                .collect();
            out.push_str(&texel.join(", "));
            out.push_str(match (column + 1 == n, k + 1 == n * n) {
                (_, true) => "",
                (true, false) => ",",
                (false, false) => ", ",
            });
        }
    }
    let _ = write!(
        out,
        "\n] );\n\nlet lut = null;\n\nexport function getDFGLUT() {{\n\n\tif ( lut === null ) {{\n\n\
         \t\tlut = new DataTexture( DATA, {n}, {n}, RGFormat, HalfFloatType );\n\
         \t\tlut.name = 'DFG_LUT';\n\t\tlut.minFilter = LinearFilter;\n\
         \t\tlut.magFilter = LinearFilter;\n\t\tlut.wrapS = ClampToEdgeWrapping;\n\
         \t\tlut.wrapT = ClampToEdgeWrapping;\n\t\tlut.generateMipmaps = false;\n\
         \t\tlut.needsUpdate = true;\n\n\t}}\n\n\treturn lut;\n\n}}\n"
    );
    out
}

/// The half-float bits of the `Uint16Array` in a three.js `DFGLUTData.js`, in file order.
pub(super) fn three_data(bytes: &[u8]) -> crate::Result<Vec<u16>> {
    let text = String::from_utf8_lossy(bytes);
    let start = text
        .find("Uint16Array")
        .ok_or_else(|| crate::Error::Malformed("no Uint16Array".into()))?;
    let body = &text[start..];
    let open = body
        .find('[')
        .ok_or_else(|| crate::Error::Malformed("no [ after Uint16Array".into()))?;
    // The first ] after the [ (one before it is not this array's).
    let close = body[open..]
        .find(']')
        .map(|c| open + c)
        .ok_or_else(|| crate::Error::Malformed("no ] after the [".into()))?;
    body[open + 1..close]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            let digits = s.trim_start_matches("0x").trim_start_matches("0X");
            u16::from_str_radix(digits, 16)
                .map_err(|e| crate::Error::Malformed(format!("{}: {e}", crate::error::quoted(s))))
        })
        .collect()
}

/// The `(width, height)` a three.js `DFGLUTData.js` builds its `DataTexture` with, if it says.
pub(super) fn three_texture_size(text: &str) -> Option<(usize, usize)> {
    let call = &text[text.find("new DataTexture(")? + "new DataTexture(".len()..];
    let arguments: Vec<&str> = call[..call.find(')')?].split(',').map(str::trim).collect();
    Some((
        arguments.get(1)?.parse().ok()?,
        arguments.get(2)?.parse().ok()?,
    ))
}

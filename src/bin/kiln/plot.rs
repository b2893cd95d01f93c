//! The study's plots, as SVG and PNG, with plotters (no system libraries: the PNG's text uses an
//! embedded font, registered once).

use kiln::study::estimators::Estimator;
use kiln::study::{LookupRun, StudyReport};
use kiln::verify::furnace::MapRows;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::Once;

const SIZE: (u32, u32) = (1100, 700);

/// Distinct colours (Okabe-Ito), one per series.
const COLOURS: [RGBColor; 6] = [
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(213, 94, 0),
    RGBColor(0, 114, 178),
];

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is a compile-time constant known to parse.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

/// A series: name and points `(x, y)`, both positive.
struct Series {
    name: String,
    points: Vec<(f64, f64)>,
}

/// The range covering `values` on a log axis, padded by a factor of 2 each way.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return 1e-3..1.0;
    }
    lo / 2.0..hi * 2.0
}

/// Draws a log-log chart: each series as a line with dots, and an optional highlighted path.
fn chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    highlight: Option<(&str, &[(f64, f64)])>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let all = || series.iter().flat_map(|s| s.points.iter().copied());
    let x_range = log_range(all().map(|p| p.0));
    let y_range = log_range(all().map(|p| p.1));
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 26))
        .margin(18)
        .x_label_area_size(55)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .axis_desc_style(("sans-serif", 20))
        .label_style(("sans-serif", 16))
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .light_line_style(WHITE.mix(0.0))
        .draw()?;
    for (k, s) in series.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let points: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| p.0 > 0.0 && p.1 > 0.0)
            .collect();
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(s.name.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
            });
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
    }
    if let Some((name, path)) = highlight {
        let path: Vec<(f64, f64)> = path.to_vec();
        chart
            .draw_series(DashedLineSeries::new(
                path.clone(),
                6,
                4,
                BLACK.stroke_width(2),
            ))?
            .label(name)
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(2)));
        chart.draw_series(
            path.iter()
                .map(|&p| Circle::new(p, 8, BLACK.stroke_width(2))),
        )?;
    }
    chart
        .configure_series_labels()
        .label_font(("sans-serif", 17))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerLeft)
        .draw()?;
    root.present()?;
    Ok(())
}

/// RGB pixels of `SIZE` as PNG bytes.
fn png_of(pixels: &[u8]) -> Result<Vec<u8>, String> {
    let mut png_bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut png_bytes, SIZE.0, SIZE.1);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(pixels).map_err(|e| e.to_string())?;
    }
    Ok(png_bytes)
}

/// Renders a chart as SVG text and as PNG bytes.
fn render(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    highlight: Option<(&str, &[(f64, f64)])>,
) -> Result<(String, Vec<u8>), String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        chart(&root, title, x_label, y_label, series, highlight).map_err(|e| e.to_string())?;
    }
    let mut pixels = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
        chart(&root, title, x_label, y_label, series, highlight).map_err(|e| e.to_string())?;
    }
    Ok((svg, png_of(&pixels)?))
}

/// Error against time, one line per method, the Pareto front dashed.
pub fn cost_plot(report: &StudyReport) -> Result<(String, Vec<u8>), String> {
    let series: Vec<Series> = Estimator::ALL
        .iter()
        .map(|e| Series {
            name: e.describe().to_string(),
            points: report
                .runs
                .iter()
                .filter(|r| r.method == e.name())
                .map(|r| (r.seconds, r.max_error.max(1e-16)))
                .collect(),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let front: Vec<(f64, f64)> = report
        .pareto
        .iter()
        .map(|&k| (report.runs[k].seconds, report.runs[k].max_error.max(1e-16)))
        .collect();
    render(
        &format!(
            "What accuracy costs: {} {} E, {} x {} table",
            report.ndf, report.masking, report.size, report.size
        ),
        &format!(
            "wall time to fill the table, {} threads (s)",
            report.threads
        ),
        "max error at the nodes",
        &series,
        Some(("Pareto front", &front)),
    )
}

/// Bake time against texel count (log-log), one line per case, its fitted exponent in the
/// legend.
pub fn scaling_plot(
    report: &kiln::study::scaling::ScalingReport,
) -> Result<(String, Vec<u8>), String> {
    let series: Vec<Series> = report
        .fits
        .iter()
        .map(|fit| Series {
            name: format!("{} (time ~ texels^{:.2})", fit.case, fit.exponent),
            points: report
                .runs
                .iter()
                .filter(|r| r.case == fit.case)
                .map(|r| (r.texels as f64, r.seconds.max(1e-6)))
                .collect(),
        })
        .collect();
    render(
        &format!(
            "How bake time grows with table size: {} {}, to {:.0e}",
            report.ndf, report.masking, report.max_error
        ),
        "texels (all of the case's tables)",
        &format!("wall time of the bake, {} threads (s)", report.threads),
        &series,
        None,
    )
}

/// `kiln fit --sweep`: the audited maximum error of each fit against its coefficient count.
pub fn fit_sweep_plot(
    model: &str,
    polynomial: &[(usize, f64)],
    rational: &[(usize, f64)],
) -> Result<(String, Vec<u8>), String> {
    let series = [
        Series {
            name: "kiln fit: polynomial in (t, r), audited max error".to_string(),
            points: polynomial.iter().map(|&(k, e)| (k as f64, e)).collect(),
        },
        Series {
            name: "kiln fit: rational 1 - t^2 P / Q in (t, r^3.2), audited max error".to_string(),
            points: rational.iter().map(|&(k, e)| (k as f64, e)).collect(),
        },
    ];
    render(
        &format!("Texture-free fits of {model} E: size against accuracy"),
        "coefficients",
        "max error over mu, r in [0, 1] (kiln verify-fit)",
        &series,
        None,
    )
}

/// Lookup error against table size, one line per mu mapping.
pub fn lookup_plot(report: &StudyReport) -> Result<(String, Vec<u8>), String> {
    let mut mappings: Vec<&str> = Vec::new();
    for r in &report.lookup {
        if !mappings.contains(&r.mapping.as_str()) {
            mappings.push(&r.mapping);
        }
    }
    let series: Vec<Series> = mappings
        .iter()
        .map(|m| Series {
            name: format!("mu axis {m}, nodes grid"),
            points: report
                .lookup
                .iter()
                .filter(|r: &&LookupRun| r.mapping == *m)
                .map(|r| (r.size as f64, r.max_error.max(1e-16)))
                .collect(),
        })
        .collect();
    render(
        &format!(
            "Lookup error of reference-filled {} {} E tables",
            report.ndf, report.masking
        ),
        "table size N (N x N)",
        "max lookup error (kiln verify)",
        &series,
        None,
    )
}

/// The furnace deviation maps side by side, one per form: roughness up, the E table's mu
/// coordinate across, colour by signed deviation on a log scale (blue: energy still lost, red:
/// energy added; white below 1e-7), the worst point of each ringed.
pub fn furnace_plot(
    title: &str,
    maps: &[kiln::verify::furnace::FurnaceMap],
    worst: &[Option<FurnaceMark>],
) -> Result<(String, Vec<u8>), String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        heat_maps(&root, title, maps, worst).map_err(|e| e.to_string())?;
    }
    let mut pixels = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
        heat_maps(&root, title, maps, worst).map_err(|e| e.to_string())?;
    }
    Ok((svg, png_of(&pixels)?))
}

/// Where the furnace command measured its worst deviation, to ring on the map: the point in the
/// map's coordinates (`x` across, `y` up: the E table's mu coordinate and roughness, or a glass
/// map's, [`kiln::verify::furnace::MapRows`]), `mu`, roughness and `eta` themselves, and the
/// deviation there.
#[derive(Clone, Copy, Debug)]
pub struct FurnaceMark {
    pub x: f64,
    pub y: f64,
    pub mu: f64,
    pub roughness: f64,
    pub eta: Option<f64>,
    pub deviation: f64,
}

/// The width of a heat map's colour bar, label room included.
const BAR_WIDTH: u32 = 130;

/// A vertical colour bar in `area`: `colour(s)` for `s` from -1 (bottom) to 1 (top) if `signed`,
/// else 0 to 1, with `labels` at their `s`, and a caption.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    signed: bool,
    colour: &dyn Fn(f64) -> RGBColor,
    labels: &[(f64, String)],
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let lo = if signed { -1.0 } else { 0.0 };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 14))
        .margin_top(40)
        .margin_bottom(52)
        .margin_right(4)
        .margin_left(6)
        .build_cartesian_2d(0.0..1.0, lo..1.0)?;
    // The bar in the left third, its labels to the right.
    let (left, right) = (0.0, 0.3);
    let steps = 240;
    chart.draw_series((0..steps).map(|k| {
        let (a, b) = (
            lo + (1.0 - lo) * k as f64 / steps as f64,
            lo + (1.0 - lo) * (k + 1) as f64 / steps as f64,
        );
        Rectangle::new([(left, a), (right, b)], colour((a + b) / 2.0).filled())
    }))?;
    chart.draw_series(std::iter::once(Rectangle::new(
        [(left, lo), (right, 1.0)],
        BLACK.stroke_width(1),
    )))?;
    for (at, text) in labels {
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(right, *at), (right + 0.06, *at)],
            BLACK.stroke_width(1),
        )))?;
        chart.draw_series(std::iter::once(Text::new(
            text.clone(),
            (right + 0.1, *at),
            ("sans-serif", 13).into_font().color(&BLACK).pos(
                plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Left,
                    plotters::style::text_anchor::VPos::Center,
                ),
            ),
        )))?;
    }
    Ok(())
}

/// A diverging colour for a signed deviation: white at |d| <= 1e-7, full blue (negative) or red
/// (positive) at |d| >= 1e-1, log-scaled between.
fn deviation_colour(d: f64) -> RGBColor {
    let level = ((d.abs().max(1e-7)).log10() + 7.0) / 6.0;
    let s = level.clamp(0.0, 1.0);
    let fade = |full: u8| (255.0 - (255.0 - f64::from(full)) * s).round() as u8;
    if d < 0.0 {
        RGBColor(fade(33), fade(102), fade(172))
    } else {
        RGBColor(fade(178), fade(24), fade(43))
    }
}

fn heat_maps<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    maps: &[kiln::verify::furnace::FurnaceMap],
    marks: &[Option<FurnaceMark>],
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let (maps_area, bar) = root.split_horizontally(SIZE.0 - BAR_WIDTH);
    // The bar: s in [-1, 1], |s| = (log10 |d| + 7) / 6, as `deviation_colour` shades.
    let deviation_at = |s: f64| s.signum() * 10f64.powf(-7.0 + 6.0 * s.abs());
    let labels: Vec<(f64, String)> = (-6..=6)
        .step_by(2)
        .map(|k| {
            let s = f64::from(k) / 6.0;
            let text = match k {
                0 => "< 1e-7".to_string(),
                _ => format!("{:+.0e}", deviation_at(s)),
            };
            (s, text)
        })
        .collect();
    colour_bar(
        &bar,
        "deviation",
        true,
        &|s| deviation_colour(deviation_at(s)),
        &labels,
    )?;
    let panels = maps_area.split_evenly((1, maps.len().max(1)));
    for (k, (panel, map)) in panels.iter().zip(maps).enumerate() {
        let (rows, columns) = (map.rows.max(2), map.columns.max(2));
        // Cell centres: the grid's points on a roughness map, the cells' middles on a glass
        // one (whose cells are 1 / n wide).
        let (dy, dx, offset) = match map.rows_are {
            MapRows::Roughness => (1.0 / (rows - 1) as f64, 1.0 / (columns - 1) as f64, 0.0),
            MapRows::Ior { .. } => (1.0 / rows as f64, 1.0 / columns as f64, 0.5),
        };
        let sampled = map
            .deviation
            .iter()
            .enumerate()
            .flat_map(|(j, row)| row.iter().enumerate().map(move |(k, d)| (j, k, *d)))
            .filter(|s| !s.2.is_nan())
            .max_by(|a, b| a.2.abs().total_cmp(&b.2.abs()))
            .unwrap_or((0, 0, 0.0));
        // The ring and the caption give the command's own worst point where it is known (it
        // measures on its own, finer ladder; the map samples a 64 x 64 grid).
        let (x, y, caption) = match marks.get(k).copied().flatten() {
            Some(m) => (
                m.x,
                m.y,
                format!(
                    "{}: max |deviation| {:.2e} at mu {}{}, r {:.4} (ringed)",
                    map.form.name(),
                    m.deviation.abs(),
                    if m.mu >= 1e-3 {
                        format!("{:.4}", m.mu)
                    } else {
                        format!("{:.2e}", m.mu)
                    },
                    m.eta
                        .map(|eta| format!(", eta {eta:.5}"))
                        .unwrap_or_default(),
                    m.roughness
                ),
            ),
            None => (
                (sampled.1 as f64 + offset) * dx,
                (sampled.0 as f64 + offset) * dy,
                format!(
                    "{}: max |deviation| {:.1e} (ringed)",
                    map.form.name(),
                    sampled.2.abs()
                ),
            ),
        };
        let mut chart = ChartBuilder::on(panel)
            .caption(caption, ("sans-serif", 15))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..1.0, 0.0..1.0)?;
        let (x_desc, y_desc) = match map.rows_are {
            MapRows::Roughness => (
                "t, the mu axis' coordinate (0 = grazing)".to_string(),
                "roughness r".to_string(),
            ),
            MapRows::Ior { eta_max } => (
                "sqrt(mu) (0 = grazing; grey: no audit point)".to_string(),
                format!("sqrt((eta - 1) / {}), eta or 1 / eta", eta_max - 1.0),
            ),
        };
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .draw()?;
        chart.draw_series(map.deviation.iter().enumerate().flat_map(|(j, row)| {
            row.iter().enumerate().map(move |(k, &d)| {
                let (x, y) = ((k as f64 + offset) * dx, (j as f64 + offset) * dy);
                let colour = if d.is_nan() {
                    RGBColor(215, 215, 215)
                } else {
                    deviation_colour(d)
                };
                Rectangle::new(
                    [(x - dx / 2.0, y - dy / 2.0), (x + dx / 2.0, y + dy / 2.0)],
                    colour.filled(),
                )
            })
        }))?;
        chart.draw_series(std::iter::once(Circle::new(
            (x, y),
            9,
            BLACK.stroke_width(2),
        )))?;
    }
    root.present()?;
    Ok(())
}

/// The audit's error maps side by side (nodes, lookups): for a 2-D table a heat map over the
/// table's texture coordinates (`mu`'s across, roughness up), colour by log10 of the error from
/// dark (the panels' smallest, or a millionth of their largest) to bright (their largest), as the
/// colour bar beside them shows, empty cells white, NaN magenta, the worst point ringed; for a 1-D table the error against roughness on a
/// log axis.
pub fn error_map_plot(
    title: &str,
    maps: &[kiln::verify::ErrorMap],
) -> Result<(String, Vec<u8>), String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        error_panels(&root, title, maps).map_err(|e| e.to_string())?;
    }
    let mut pixels = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
        error_panels(&root, title, maps).map_err(|e| e.to_string())?;
    }
    Ok((svg, png_of(&pixels)?))
}

/// Viridis at `s` in [0, 1] ([`kiln::format::png::viridis`]).
fn viridis(s: f64) -> RGBColor {
    let [r, g, b] = kiln::format::png::viridis(s);
    RGBColor(r, g, b)
}

fn error_panels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    maps: &[kiln::verify::ErrorMap],
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let panels = root.split_evenly((1, maps.len().max(1)));
    for (panel, map) in panels.iter().zip(maps) {
        // Each heat map's own colour scale, shown by the bar beside it: log10 of the error
        // from the panel's smallest (or a millionth of its largest) to its largest.
        let finite = || {
            map.cells
                .iter()
                .flatten()
                .copied()
                .filter(|e| e.is_finite() && *e > 0.0)
        };
        let hi = finite().fold(0.0_f64, f64::max);
        let lo = finite().fold(f64::INFINITY, f64::min).max(hi * 1e-6);
        let span = (hi / lo).log10().max(1e-12);
        let panel = if map.rows > 1 && hi > 0.0 {
            let (width, _) = panel.dim_in_pixel();
            let (map_area, bar) = panel.split_horizontally(width.saturating_sub(BAR_WIDTH - 20));
            let labels: Vec<(f64, String)> = (lo.log10().ceil() as i32..=hi.log10().floor() as i32)
                .map(|d| ((f64::from(d) - lo.log10()) / span, format!("1e{d}")))
                .filter(|(s, _)| (0.06..=0.94).contains(s))
                .chain([(0.0, format!("{lo:.1e}")), (1.0, format!("{hi:.1e}"))])
                .collect();
            colour_bar(&bar, "error", false, &viridis, &labels)?;
            map_area
        } else {
            panel.clone()
        };
        let panel = &panel;
        let (x, y, worst) = map.worst;
        let slice = map
            .eta
            .map(|eta| format!(", slice eta = {eta:.4}"))
            .unwrap_or_default();
        if map.rows > 1 {
            let caption = format!("{}: max {worst:.2e}{slice} (ringed)", map.group);
            let mut chart = ChartBuilder::on(panel)
                .caption(caption, ("sans-serif", 15))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(50)
                .build_cartesian_2d(0.0..1.0, 0.0..1.0)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(map.x_axis.as_str())
                .y_desc(map.y_axis.as_str())
                .draw()?;
            let (dx, dy) = (1.0 / map.columns as f64, 1.0 / map.rows as f64);
            chart.draw_series(map.cells.iter().enumerate().filter_map(|(k, cell)| {
                let e = (*cell)?;
                let colour = if e.is_nan() {
                    RGBColor(255, 0, 255)
                } else if e <= 0.0 {
                    viridis(0.0)
                } else {
                    viridis((e / lo).log10() / span)
                };
                let (i, j) = ((k % map.columns) as f64, (k / map.columns) as f64);
                Some(Rectangle::new(
                    [(i * dx, j * dy), ((i + 1.0) * dx, (j + 1.0) * dy)],
                    colour.filled(),
                ))
            }))?;
            chart.draw_series(std::iter::once(Circle::new((x, y), 9, RED.stroke_width(2))))?;
        } else {
            let caption = format!("{}: max {worst:.2e}{slice}", map.group);
            let points: Vec<(f64, f64)> = map
                .cells
                .iter()
                .enumerate()
                .filter_map(|(k, cell)| {
                    let e = (*cell)?;
                    (e > 0.0 && e.is_finite()).then_some(((k as f64 + 0.5) / map.columns as f64, e))
                })
                .collect();
            let mut chart = ChartBuilder::on(panel)
                .caption(caption, ("sans-serif", 15))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..1.0, log_range(points.iter().map(|p| p.1)).log_scale())?;
            chart
                .configure_mesh()
                .x_desc(map.x_axis.as_str())
                .y_desc("error")
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .draw()?;
            chart.draw_series(LineSeries::new(points.clone(), COLOURS[5].stroke_width(2)))?;
            chart.draw_series(
                points
                    .iter()
                    .map(|&p| Circle::new(p, 3, COLOURS[5].filled())),
            )?;
            if worst > 0.0 && worst.is_finite() {
                chart.draw_series(std::iter::once(Circle::new(
                    (x, worst),
                    9,
                    RED.stroke_width(2),
                )))?;
            }
        }
    }
    root.present()?;
    Ok(())
}

/// `kiln compensation --lobe --plot`: the multiple-scattering lobe in the plane of incidence,
/// one panel per roughness and view: the walk's (dots, with 95 % bars) against each
/// compensation's added lobe (lines; a line past the panel's top is clipped there).
pub fn lobe_plot(
    title: &str,
    profiles: &[kiln::verify::compensation::LobeProfile],
    names: &[&str],
) -> Result<(String, Vec<u8>), String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        lobe_panels(&root, title, profiles, names).map_err(|e| e.to_string())?;
    }
    let mut pixels = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
        lobe_panels(&root, title, profiles, names).map_err(|e| e.to_string())?;
    }
    Ok((svg, png_of(&pixels)?))
}

fn lobe_panels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    profiles: &[kiln::verify::compensation::LobeProfile],
    names: &[&str],
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let columns = profiles.len().clamp(1, 3);
    let rows = profiles.len().div_ceil(columns).max(1);
    let panels = root.split_evenly((rows, columns));
    for (n, (panel, profile)) in panels.iter().zip(profiles).enumerate() {
        // The top: the walk's bars and the reciprocal lobes; Turquin's spike may be clipped.
        let top = profile
            .walk
            .iter()
            .map(|m| m.value + 1.96 * m.std_error)
            .chain(
                profile
                    .added
                    .iter()
                    .zip(names)
                    .filter(|(_, name)| **name != "turquin")
                    .flat_map(|(a, _)| a.iter().copied()),
            )
            .fold(0.0_f64, f64::max)
            * 1.25;
        let top = if top > 0.0 { top } else { 1.0 };
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!(
                    "r = {}, view {:.0} deg",
                    kiln::error::brief(
                        kiln::RoughnessConvention::Perceptual.from_alpha(profile.alpha)
                    ),
                    profile.view.acos().to_degrees()
                ),
                ("sans-serif", 15),
            )
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(52)
            .build_cartesian_2d(-90.0..90.0, 0.0..top)?;
        chart
            .configure_mesh()
            .light_line_style(WHITE.mix(0.0))
            .x_desc("exit angle (deg; < 0: view's side, > 0: mirror side)")
            .y_desc("BRDF, orders 2+, F = 1")
            .label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 12))
            .y_label_formatter(&|y| format!("{y:.2}"))
            .draw()?;
        for (k, (added, name)) in profile.added.iter().zip(names).enumerate() {
            let colour = COLOURS[(k + 1) % COLOURS.len()];
            let points: Vec<(f64, f64)> = profile
                .angles
                .iter()
                .zip(added)
                .map(|(&x, &y)| (x, y.min(top)))
                .collect();
            let drawn = chart.draw_series(LineSeries::new(points, colour.stroke_width(2)))?;
            if n == 0 {
                drawn.label(*name).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(3))
                });
            }
        }
        let black = BLACK;
        let bars = chart.draw_series(profile.angles.iter().zip(&profile.walk).map(|(&x, m)| {
            PathElement::new(
                vec![
                    (x, (m.value - 1.96 * m.std_error).max(0.0)),
                    (x, (m.value + 1.96 * m.std_error).min(top)),
                ],
                black.stroke_width(1),
            )
        }))?;
        if n == 0 {
            bars.label("walk (95 %)")
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, black.filled()));
        }
        chart.draw_series(
            profile
                .angles
                .iter()
                .zip(&profile.walk)
                .map(|(&x, m)| Circle::new((x, m.value), 3, black.filled())),
        )?;
        if n == 0 {
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 12))
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperLeft)
                .draw()?;
        }
    }
    root.present()?;
    Ok(())
}

//! The plotting kit every figure is drawn with: the embedded font, rendering into a PNG file,
//! axis ranges, tick labels, the palette, legends (in a chart or in a strip of their own), lines
//! and legend marks.

use std::error::Error;
use std::panic::AssertUnwindSafe;
use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontStyle, register_font};
use sepval_core::atomic_file::write_atomically;

use super::FigureError;

/// DejaVu Sans, embedded so that text renders without system fonts.
static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The font family every text of the figures uses (plotters' default family too).
const FONT: &str = "sans-serif";

/// Registers the embedded font with plotters, once; whether that worked.
fn font_ready() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY.get_or_init(|| register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok())
}

/// A drawing area of a figure in memory (the whole figure or a part of it).
pub(super) type Root<'b> = DrawingArea<BitMapBackend<'b>, Shift>;
/// What drawing gives: plotters' errors, boxed.
pub(super) type DrawResult = Result<(), Box<dyn Error>>;
/// A pixel position.
type Px = (i32, i32);
/// A chart with two axes drawn into a figure in memory.
pub(super) type Chart2d<'a, 'b, X, Y> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<X, Y>>;

/// Draws a figure of `(width, height)` pixels with `draw` and writes it to `path` as PNG,
/// atomically.
pub(super) fn render<F>(
    path: &Path,
    (width, height): (u32, u32),
    draw: F,
) -> Result<(), FigureError>
where
    F: FnOnce(&Root<'_>) -> DrawResult,
{
    if !font_ready() {
        return Err(FigureError::Font {
            path: path.to_path_buf(),
        });
    }
    let mut rgb = vec![255u8; width as usize * height as usize * 3];
    // plotters is not expected to panic on the finite, widened ranges given to it; should it
    // still, the figure fails rather than the run.
    let drawn = std::panic::catch_unwind(AssertUnwindSafe(|| -> Result<(), String> {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        let inner = || -> DrawResult {
            root.fill(&WHITE)?;
            draw(&root)?;
            root.present()?;
            Ok(())
        };
        inner().map_err(|e| e.to_string())
    }));
    let draw_error = |message| FigureError::Draw {
        path: path.to_path_buf(),
        message,
    };
    match drawn {
        Ok(Ok(())) => {}
        Ok(Err(message)) => return Err(draw_error(message)),
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| (*s).to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            return Err(draw_error(format!("the plotting library failed: {what}")));
        }
    }
    let png = encode_png(&rgb, width, height).map_err(|e| FigureError::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    write_atomically(path, &png).map_err(|e| FigureError::Write {
        path: e.path,
        source: e.source,
    })
}

/// Encodes 8-bit RGB pixels as PNG.
fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Balanced);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}

/// Largest magnitude drawn; anything beyond is skipped like a NaN.
const MAX_ABS: f64 = 1e100;

/// Whether a value can be drawn.
pub(super) fn plottable(v: f64) -> bool {
    v.is_finite() && v.abs() <= MAX_ABS
}

/// Whether a point can be drawn.
pub(super) fn plottable_point((x, y): (f64, f64)) -> bool {
    plottable(x) && plottable(y)
}

/// The span of the plottable `values`, padded by `pad` of the span on each side; a single value
/// (or a span negligible beside the values) is widened by 5 % of its magnitude (±0.5 around
/// zero); no value gives (0, 1).
pub(super) fn padded_range(values: impl IntoIterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| plottable(*v)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    let scale = lo.abs().max(hi.abs());
    let span = hi - lo;
    if span <= scale * 1e-9 || span < 1e-200 {
        let half = if scale > 1e-200 { 0.05 * scale } else { 0.5 };
        (lo - half, hi + half)
    } else {
        (lo - pad * span, hi + pad * span)
    }
}

/// Like [`padded_range`] but not below zero when no value is negative.
pub(super) fn padded_range_from_zero(
    values: impl IntoIterator<Item = f64> + Clone,
    pad: f64,
) -> (f64, f64) {
    let (lo, hi) = padded_range(values.clone(), pad);
    let any_negative = values.into_iter().any(|v| plottable(v) && v < 0.0);
    if !any_negative && lo < 0.0 {
        (0.0, hi)
    } else {
        (lo, hi)
    }
}

/// The range of a log axis for the positive plottable `values`: whole decades around them
/// (plotters labels only the decades and the steps between them); (0.1, 10) when there is none.
pub(super) fn log_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| plottable(*v) && *v >= 1e-100) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.1, 10.0);
    }
    let l = (lo.log10() - 0.01).floor();
    let h = (hi.log10() + 0.01).ceil().max(l + 1.0);
    (10f64.powf(l), 10f64.powf(h))
}

/// A tick label: at most four decimals with trailing zeros dropped, scientific notation for
/// very large or very small magnitudes.
pub(super) fn fmt_tick(v: f64) -> String {
    if !v.is_finite() {
        return String::new();
    }
    let a = v.abs();
    if a < 1e-12 {
        return "0".to_string();
    }
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.2e}");
        return match s.split_once('e') {
            Some((mantissa, exp)) => {
                let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{mantissa}e{exp}")
            }
            None => s,
        };
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// A tick label for an axis of counts: integers only (other ticks unlabelled).
pub(super) fn fmt_count_tick(v: f64) -> String {
    if v.is_finite() && (v - v.round()).abs() < 1e-9 {
        fmt_tick(v.round())
    } else {
        String::new()
    }
}

/// Tableau 10: the colours of labelled series, in label order.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The colour of the `i`-th labelled series.
pub(super) fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Grey of noise floors and reference lines.
pub(super) const FLOOR_GREY: RGBColor = RGBColor(90, 90, 90);

/// A text style of the figure font.
pub(super) fn text(size: f64) -> TextStyle<'static> {
    TextStyle::from((FONT, size).into_font()).color(&BLACK)
}

/// A band as one filled polygon: along its upper edge, back along its lower, from the points
/// `(x, lo, hi)` in order of x.
pub(super) fn band_polygon(edges: &[(f64, f64, f64)], style: ShapeStyle) -> Polygon<(f64, f64)> {
    let upper = edges.iter().map(|&(x, _, hi)| (x, hi));
    let lower = edges.iter().rev().map(|&(x, lo, _)| (x, lo));
    Polygon::new(upper.chain(lower).collect::<Vec<_>>(), style)
}

/// `c` mixed with white, `white` of it white (0: `c` itself, 1: white): the light tint of a
/// series colour that bands are filled with.
pub(super) fn tint(c: RGBColor, white: f64) -> RGBColor {
    let w = if white.is_finite() {
        white.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let mix = |v: u8| {
        (f64::from(v) * (1.0 - w) + 255.0 * w)
            .round()
            .clamp(0.0, 255.0) as u8
    };
    RGBColor(mix(c.0), mix(c.1), mix(c.2))
}

/// Splits a polyline where a point cannot be drawn.
pub(super) fn segments(points: impl IntoIterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current = Vec::new();
    for p in points {
        if plottable_point(p) {
            current.push(p);
        } else if !current.is_empty() {
            out.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// The corner of the plot where the fewest of `points` lie, for the legend; `x` and `y` are the
/// axis ranges (in the same scale as the points).
pub(super) fn legend_corner(
    points: impl IntoIterator<Item = (f64, f64)>,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> SeriesLabelPosition {
    // Upper right, upper left, lower right, lower left: ties go to the first.
    let mut counts = [0usize; 4];
    for (x, y) in points.into_iter().filter(|p| plottable_point(*p)) {
        let fx = (x - x0) / (x1 - x0);
        let fy = (y - y0) / (y1 - y0);
        let (right, left) = (fx > 0.55, fx < 0.45);
        let (upper, lower) = (fy > 0.6, fy < 0.4);
        counts[0] += usize::from(upper && right);
        counts[1] += usize::from(upper && left);
        counts[2] += usize::from(lower && right);
        counts[3] += usize::from(lower && left);
    }
    let best = (0..4).min_by_key(|&i| counts[i]).unwrap_or(0);
    match best {
        1 => SeriesLabelPosition::UpperLeft,
        2 => SeriesLabelPosition::LowerRight,
        3 => SeriesLabelPosition::LowerLeft,
        _ => SeriesLabelPosition::UpperRight,
    }
}

/// A chart on `area` with linear axes over `x` and `y`, a caption, and room for tick labels.
pub(super) fn linear_chart<'a, 'b>(
    area: &'a Root<'b>,
    caption: &str,
    caption_size: f64,
    x: (f64, f64),
    y: (f64, f64),
) -> Result<Chart2d<'a, 'b, RangedCoordf64, RangedCoordf64>, Box<dyn Error>> {
    Ok(ChartBuilder::on(area)
        .caption(caption, text(caption_size))
        .margin(18)
        .x_label_area_size(55)
        .y_label_area_size(85)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?)
}

/// Draws the grid, tick labels and axis descriptions.
pub(super) fn draw_mesh<X, Y>(
    chart: &mut Chart2d<'_, '_, X, Y>,
    x_desc: &str,
    y_desc: &str,
    x_fmt: fn(f64) -> String,
    y_fmt: fn(f64) -> String,
) -> DrawResult
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .axis_desc_style(text(19.0))
        .label_style(text(15.0))
        .x_label_formatter(&|v| x_fmt(*v))
        .y_label_formatter(&|v| y_fmt(*v))
        .bold_line_style(RGBColor(210, 210, 210))
        .light_line_style(RGBColor(238, 238, 238))
        .axis_style(RGBColor(60, 60, 60))
        .draw()?;
    Ok(())
}

/// Draws the series labels in a box at `position`.
pub(super) fn draw_legend<'a, 'b: 'a, X, Y>(
    chart: &mut Chart2d<'a, 'b, X, Y>,
    position: SeriesLabelPosition,
) -> DrawResult
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    chart
        .configure_series_labels()
        .position(position)
        .margin(12)
        .legend_area_size(28)
        .label_font(text(16.0))
        .background_style(WHITE.mix(0.88))
        .border_style(RGBColor(150, 150, 150))
        .draw()?;
    Ok(())
}

/// A legend mark in a legend strip.
pub(super) enum LegendMark {
    /// A line in the colour.
    Line(RGBColor),
    /// A filled box in the colour (a band).
    Band(RGBColor),
    /// A dashed line in the colour.
    Dashed(RGBColor),
    /// A ring in the colour (a marked point, for example a release flown, hollow so that what
    /// is under it stays readable).
    Ring(RGBColor),
}

/// The radius of a marked point ([`LegendMark::Ring`]), in pixels.
pub(super) const RING_RADIUS_PX: i32 = 13;

/// The style of a ring of colour `c`.
pub(super) fn ring_style(c: RGBColor) -> ShapeStyle {
    c.stroke_width(4)
}

/// Draws a one-row legend centred in `area`.
pub(super) fn draw_legend_strip(area: &Root<'_>, entries: &[(String, LegendMark)]) -> DrawResult {
    let style = text(17.0);
    let (w, h) = area.dim_in_pixel();
    let widths: Vec<i32> = entries
        .iter()
        .map(|(label, _)| area.estimate_text_size(label, &style).map(|s| s.0 as i32))
        .collect::<Result<_, _>>()?;
    let gap = 30;
    let mark = 30;
    let total: i32 =
        widths.iter().map(|w| w + mark + 8).sum::<i32>() + gap * (entries.len() as i32 - 1).max(0);
    let mut x = ((w as i32 - total) / 2).max(4);
    let y = h as i32 / 2;
    for ((label, m), width) in entries.iter().zip(widths) {
        match m {
            LegendMark::Line(c) => area.draw(&PathElement::new(
                vec![(x, y), (x + mark, y)],
                c.stroke_width(3),
            ))?,
            LegendMark::Band(c) => {
                area.draw(&Rectangle::new([(x, y - 8), (x + mark, y + 8)], c.filled()))?
            }
            LegendMark::Dashed(c) => area.draw(&DashedPathElement::new(
                vec![(x, y), (x + mark, y)],
                7,
                4,
                c.stroke_width(2),
            ))?,
            LegendMark::Ring(c) => {
                let centre = (x + mark / 2, y);
                area.draw(&Circle::new(centre, RING_RADIUS_PX, ring_style(*c)))?;
            }
        }
        let style = style.pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(label.as_str(), (x + mark + 8, y), style))?;
        x += mark + 8 + width + gap;
    }
    Ok(())
}

/// A figure's title and one-row legend at the top of `root`; the area below them, for the
/// chart.
pub(super) fn titled_with_legend<'b>(
    root: &Root<'b>,
    title: &str,
    entries: &[(String, LegendMark)],
) -> Result<Root<'b>, Box<dyn Error>> {
    let (_, body) = root.split_vertically(8);
    let body = body.titled(title, text(26.0))?;
    let (legend, main) = body.split_vertically(44);
    draw_legend_strip(&legend, entries)?;
    Ok(main)
}

/// The legend mark of a line.
pub(super) fn line_mark(style: ShapeStyle) -> impl Fn(Px) -> PathElement<Px> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], style)
}

/// The legend mark of a dashed line.
fn dashed_mark(style: ShapeStyle) -> impl Fn(Px) -> DashedPathElement<std::vec::IntoIter<Px>, i32> {
    move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 22, y)], 6, 4, style)
}

/// The legend mark of a filled box.
pub(super) fn box_mark(style: ShapeStyle) -> impl Fn(Px) -> Rectangle<Px> {
    move |(x, y)| Rectangle::new([(x + 2, y - 7), (x + 20, y + 7)], style)
}

/// Draws `points` as lines broken where a value cannot be drawn (isolated points as dots),
/// with a legend entry when `label` is given.
pub(super) fn draw_polyline<X, Y>(
    chart: &mut Chart2d<'_, '_, X, Y>,
    points: impl IntoIterator<Item = (f64, f64)>,
    style: ShapeStyle,
    label: Option<&str>,
) -> DrawResult
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let segs = segments(points);
    let singles: Vec<(f64, f64)> = segs.iter().filter(|s| s.len() == 1).map(|s| s[0]).collect();
    let anno = chart.draw_series(
        segs.into_iter()
            .filter(|s| s.len() > 1)
            .map(|s| PathElement::new(s, style)),
    )?;
    if let Some(label) = label {
        anno.label(label).legend(line_mark(style));
    }
    chart.draw_series(
        singles
            .into_iter()
            .map(|p| Circle::new(p, 2, style.color.filled())),
    )?;
    Ok(())
}

/// A dashed line through `points` (all assumed plottable and inside the chart).
pub(super) fn draw_dashed<X, Y>(
    chart: &mut Chart2d<'_, '_, X, Y>,
    points: Vec<(f64, f64)>,
    style: ShapeStyle,
    label: Option<&str>,
) -> DrawResult
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let anno = chart.draw_series(std::iter::once(DashedPathElement::new(points, 9, 6, style)))?;
    if let Some(label) = label {
        anno.label(label).legend(dashed_mark(style));
    }
    Ok(())
}

/// The width in pixels of `s` in the figure font at `size`, without a drawing area.
pub(super) fn estimate_width(s: &str, size: f64) -> u32 {
    if !font_ready() {
        return 0;
    }
    text(size)
        .font
        .box_size(s)
        .map(|(w, _)| w)
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_finite_and_widened() {
        assert_eq!(padded_range([], 0.1), (0.0, 1.0));
        assert_eq!(padded_range([f64::NAN, f64::INFINITY], 0.1), (0.0, 1.0));
        let (lo, hi) = padded_range([5.0, 5.0], 0.1);
        assert!(lo < 5.0 && hi > 5.0);
        let (lo, hi) = padded_range([0.0], 0.1);
        assert!(lo < 0.0 && hi > 0.0);
        let (lo, hi) = padded_range([-1e100, 1e100, 1e300], 0.1);
        assert!(lo.is_finite() && hi.is_finite() && lo < hi);
        let (lo, hi) = log_range([0.0, -1.0, f64::NAN]);
        assert!(lo > 0.0 && hi > lo);
        let (lo, hi) = log_range([2.0]);
        assert!(lo < 2.0 && hi > 2.0 && hi / lo >= 9.99);
        let (lo, hi) = log_range([2.4, 7.5, 0.0]);
        assert!((lo - 1.0).abs() < 1e-12 && (hi - 10.0).abs() < 1e-12);
        assert_eq!(fmt_tick(0.30000000000000004), "0.3");
        assert_eq!(fmt_tick(-1e-17), "0");
        assert_eq!(fmt_tick(250000.0), "2.5e5");
        assert_eq!(fmt_count_tick(2.5), "");
        assert_eq!(fmt_count_tick(3.0), "3");
        assert_eq!(segments([(0.0, 1.0), (1.0, f64::NAN), (2.0, 2.0)]).len(), 2);
    }
}

//! A correlation matrix as a heat map (for example of the fitted factors).

use std::path::Path;

use plotters::prelude::*;
use plotters::style::FontTransform;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::kit::{DrawResult, Root, estimate_width, fmt_tick, render, text};
use super::{FigureError, FigureInput};

/// The most rows and columns a correlation figure draws (2 px a cell).
const MAX_CORRELATION_NAMES: usize = 450;

/// The diverging colour of a correlation: dark blue at −1, near white at 0, dark red at +1
/// (ColorBrewer RdBu); grey when not finite.
fn diverging(rho: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (-1.0, [5.0, 48.0, 97.0]),
        (-0.5, [67.0, 147.0, 195.0]),
        (0.0, [247.0, 247.0, 247.0]),
        (0.5, [214.0, 96.0, 77.0]),
        (1.0, [103.0, 0.0, 31.0]),
    ];
    if !rho.is_finite() {
        return RGBColor(170, 170, 170);
    }
    let r = rho.clamp(-1.0, 1.0);
    let k = (((r + 1.0) * 2.0).floor() as usize).min(3);
    let (r0, c0) = STOPS[k];
    let (r1, c1) = STOPS[k + 1];
    let f = (r - r0) / (r1 - r0);
    let mix = |i: usize| (c0[i] + f * (c1[i] - c0[i])).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(0), mix(1), mix(2))
}

/// A correlation matrix heat map (values in [−1, 1], diverging colours: blue negative, red
/// positive; a value outside is drawn at the end colour, one that is not finite in grey), the
/// value printed in each cell when n ≤ 24, rows and columns labelled with `names` (every k-th
/// when the cells are too small for all), a colour bar on the right. At least 800 × 600 px:
/// cells of 2 to 90 px, the matrix 900 px at most; at most 450 names.
pub fn correlation_figure(
    path: &Path,
    names: &[&str],
    rho: &[Vec<f64>],
    title: &str,
) -> Result<(), FigureError> {
    check_shape(names.len(), rho).map_err(|reason| FigureError::Input {
        path: path.to_path_buf(),
        reason,
    })?;
    let layout = Layout::of(names);
    let (width, height) = (layout.width, layout.height);
    render(path, (width, height), |root| {
        let title_style = text(26.0).pos(Pos::new(HPos::Center, VPos::Center));
        root.draw(&Text::new(title, (width as i32 / 2, 36), title_style))?;
        if names.is_empty() {
            let style = text(18.0).pos(Pos::new(HPos::Center, VPos::Center));
            root.draw(&Text::new(
                "(no factors)",
                (width as i32 / 2, height as i32 / 2),
                style,
            ))?;
        }
        draw_cells(root, rho, &layout)?;
        draw_names(root, names, &layout)?;
        draw_colour_bar(root, &layout)
    })
}

/// Checks that `rho` is n × n and that n is not above [`MAX_CORRELATION_NAMES`].
fn check_shape(n: usize, rho: &[Vec<f64>]) -> Result<(), FigureInput> {
    if rho.len() != n || rho.iter().any(|row| row.len() != n) {
        return Err(FigureInput::CorrelationShape {
            n,
            rows: rho.len(),
            lengths: rho.iter().map(Vec::len).collect(),
        });
    }
    if n > MAX_CORRELATION_NAMES {
        return Err(FigureInput::CorrelationNames {
            n,
            max: MAX_CORRELATION_NAMES,
        });
    }
    Ok(())
}

/// The sizes of a correlation figure, in pixels.
struct Layout {
    n: usize,
    /// Side of one cell.
    cell: u32,
    /// Side of the matrix.
    grid: u32,
    /// Font size of the names and of the values in the cells.
    name_size: f64,
    value_size: f64,
    width: u32,
    height: u32,
    /// The matrix's upper left corner.
    x0: i32,
    y0: i32,
}

impl Layout {
    fn of(names: &[&str]) -> Self {
        let n = names.len();
        let cell = if n == 0 {
            40
        } else {
            (900 / n as u32).clamp(2, 90)
        };
        let grid = cell * n as u32;
        let name_size = (f64::from(cell) * 0.45).clamp(9.0, 16.0);
        let value_size = (f64::from(cell) * 0.3).clamp(8.0, 16.0);
        let widest = names
            .iter()
            .map(|s| estimate_width(s, name_size))
            .max()
            .unwrap_or(0)
            .min(300);
        let (left, top) = ((widest + 30).max(60), 80u32);
        let bottom = (widest + 30).max(60);
        let bar_area = 130u32;
        let content = left + grid + bar_area;
        let width = content.max(800);
        let height = (top + grid + bottom).max(600);
        Layout {
            n,
            cell,
            grid,
            name_size,
            value_size,
            width,
            height,
            x0: (left + (width - content) / 2) as i32,
            y0: top as i32,
        }
    }
}

/// The cells in their colours with their values (n ≤ 24), thin white lines between them when
/// they are large enough, and a frame.
fn draw_cells(root: &Root, rho: &[Vec<f64>], l: &Layout) -> DrawResult {
    let (x0, y0, c, n) = (l.x0, l.y0, l.cell as i32, l.n);
    for (i, row) in rho.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            let (cx, cy) = (x0 + j as i32 * c, y0 + i as i32 * c);
            root.draw(&Rectangle::new(
                [(cx, cy), (cx + c, cy + c)],
                diverging(v).filled(),
            ))?;
            if n <= 24 && v.is_finite() {
                let ink = if v.abs() > 0.55 { WHITE } else { BLACK };
                let style = text(l.value_size)
                    .color(&ink)
                    .pos(Pos::new(HPos::Center, VPos::Center));
                let s = format!("{:.2}", v.clamp(-99.0, 99.0));
                root.draw(&Text::new(s, (cx + c / 2, cy + c / 2), style))?;
            }
        }
    }
    if n > 0 && l.cell >= 16 {
        for k in 1..n as i32 {
            let style = WHITE.stroke_width(1);
            root.draw(&PathElement::new(
                vec![(x0 + k * c, y0), (x0 + k * c, y0 + n as i32 * c)],
                style,
            ))?;
            root.draw(&PathElement::new(
                vec![(x0, y0 + k * c), (x0 + n as i32 * c, y0 + k * c)],
                style,
            ))?;
        }
    }
    if n > 0 {
        let g = l.grid as i32;
        root.draw(&Rectangle::new(
            [(x0, y0), (x0 + g, y0 + g)],
            RGBColor(80, 80, 80).stroke_width(1),
        ))?;
    }
    Ok(())
}

/// The names left of the rows and under the columns: every name while they fit side by side,
/// else every `step`-th.
fn draw_names(root: &Root, names: &[&str], l: &Layout) -> DrawResult {
    let (x0, y0, c) = (l.x0, l.y0, l.cell as i32);
    let step = (9 / l.cell.max(1) + 1) as usize;
    for (k, name) in names.iter().enumerate().step_by(step) {
        let mid = k as i32 * c + c / 2;
        let row_style = text(l.name_size).pos(Pos::new(HPos::Right, VPos::Center));
        root.draw(&Text::new(*name, (x0 - 8, y0 + mid), row_style))?;
        let col_style = text(l.name_size)
            .transform(FontTransform::Rotate270)
            .pos(Pos::new(HPos::Right, VPos::Center));
        root.draw(&Text::new(
            *name,
            (x0 + mid, y0 + l.grid as i32 + 8),
            col_style,
        ))?;
    }
    Ok(())
}

/// The colour bar right of the matrix, from +1 (top) to −1, with its ticks and ρ above it.
fn draw_colour_bar(root: &Root, l: &Layout) -> DrawResult {
    let grid = l.grid as i32;
    let bar_h = grid.clamp(200, 500);
    let (bx, by) = (l.x0 + grid + 40, l.y0 + (grid - bar_h).max(0) / 2);
    for p in 0..bar_h {
        let v = 1.0 - 2.0 * f64::from(p) / f64::from(bar_h - 1);
        root.draw(&PathElement::new(
            vec![(bx, by + p), (bx + 24, by + p)],
            diverging(v).stroke_width(1),
        ))?;
    }
    root.draw(&Rectangle::new(
        [(bx, by), (bx + 24, by + bar_h)],
        RGBColor(80, 80, 80).stroke_width(1),
    ))?;
    for tick in [-1.0, -0.5, 0.0, 0.5, 1.0] {
        let ty = by + ((1.0 - tick) / 2.0 * f64::from(bar_h - 1)).round() as i32;
        root.draw(&PathElement::new(
            vec![(bx + 24, ty), (bx + 30, ty)],
            BLACK.stroke_width(1),
        ))?;
        let style = text(14.0).pos(Pos::new(HPos::Left, VPos::Center));
        root.draw(&Text::new(fmt_tick(tick), (bx + 34, ty), style))?;
    }
    let style = text(18.0).pos(Pos::new(HPos::Center, VPos::Bottom));
    root.draw(&Text::new("ρ", (bx + 12, by - 10), style))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::{check_png, dark_pixels, decode_size};

    #[test]
    fn correlation_figure_draws_a_heat_map() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("correlation.png");
        let names = [
            "C_m_alpha",
            "C_n_beta",
            "C_l_p",
            "ejector_force",
            "cg_x",
            "mass",
        ];
        let n = names.len();
        let rho: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        if i == j {
                            1.0
                        } else {
                            ((i * 7 + j * 3) % 11) as f64 / 5.0 - 1.0
                        }
                    })
                    .collect()
            })
            .collect();
        correlation_figure(&path, &names, &rho, "Factor correlations (GA)").unwrap();
        let (w, h) = decode_size(&path);
        assert!(w >= 700 && h >= 500);
        check_png(&path, (w, h));
        assert!(dark_pixels(&path, 10..60) > 100);
    }

    #[test]
    fn correlation_figure_survives_odd_and_large_matrices_and_refuses_bad_shapes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("correlation.png");
        let rho = vec![vec![1.0, f64::NAN], vec![f64::INFINITY, -3.0]];
        correlation_figure(&path, &["a", "b"], &rho, "odd").unwrap();
        check_png(&path, decode_size(&path));
        correlation_figure(&path, &[], &[], "empty").unwrap();
        check_png(&path, decode_size(&path));
        let names: Vec<String> = (0..40).map(|i| format!("f{i}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let rho: Vec<Vec<f64>> = (0..40)
            .map(|i| (0..40).map(|j| ((i as f64) - (j as f64)).cos()).collect())
            .collect();
        correlation_figure(&path, &names, &rho, "large").unwrap();
        check_png(&path, decode_size(&path));
        let names: Vec<String> = (0..300).map(|i| format!("f{i}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let rho = vec![vec![0.3; 300]; 300];
        correlation_figure(&path, &names, &rho, "very large").unwrap();
        let (w, h) = decode_size(&path);
        assert!(w < 1400 && h < 1400, "{w} x {h}");
        check_png(&path, (w, h));
        let names = vec!["f"; 451];
        let rho = vec![vec![0.0; 451]; 451];
        let err = correlation_figure(&path, &names, &rho, "too large").unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");

        let err =
            correlation_figure(&path, &["a", "b"], &[vec![1.0, 0.0], vec![0.0]], "x").unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        assert!(err.to_string().contains("correlation.png"), "{err}");
    }

    #[test]
    fn diverging_colours_run_from_blue_to_red() {
        assert_eq!(diverging(f64::NAN), RGBColor(170, 170, 170));
        assert_eq!(diverging(-1.0), RGBColor(5, 48, 97));
        assert_eq!(diverging(1.0), RGBColor(103, 0, 31));
        assert_eq!(diverging(7.0), RGBColor(103, 0, 31));
    }
}

//! A predicted release with its bands, six channels in one figure, and a flown release drawn
//! over them when there is one (`sepval predict`, its post-flight check).

use std::path::Path;

use plotters::prelude::*;

use super::kit::{
    LegendMark, band_polygon, colour, draw_legend_strip, draw_mesh, draw_polyline, fmt_tick,
    padded_range, plottable, render, text, tint,
};
use super::{FigureError, FigureInput};

/// The six channels: caption and unit, in the order of a sample's values.
const CHANNELS: [(&str, &str); 6] = [
    ("Downrange x", "m"),
    ("Crossrange y", "m"),
    ("Down z", "m"),
    ("Roll φ", "deg"),
    ("Pitch θ", "deg"),
    ("Yaw ψ", "deg"),
];

/// How much white there is in a band's fill (a light tint of the prediction's colour).
const BAND_WHITE: f64 = 0.7;

/// One channel's band: lower edge, middle and upper edge at each time.
#[derive(Debug, Clone, Copy)]
pub struct Band<'a> {
    /// Lower edge.
    pub lo: &'a [f64],
    /// Middle (the median).
    pub mid: &'a [f64],
    /// Upper edge.
    pub hi: &'a [f64],
}

/// The bands of six channels against time in a 2 × 3 grid (x, y, z \[m\]; roll, pitch, yaw
/// \[deg\]): the band filled in a light tint, its middle as a line, and the flown `data` (one
/// `[x, y, z, roll, pitch, yaw]` per time) as black points over them when given. `band_label`
/// names the band in the legend (for example "95 % band"). 1600 × 1000 px, `title` on top and
/// one legend below it. Points that are not finite are skipped; vectors whose length is not
/// that of `times_s` are refused.
pub fn band_figure(
    path: &Path,
    times_s: &[f64],
    bands: &[Band; 6],
    data: Option<(&str, &[[f64; 6]])>,
    band_label: &str,
    title: &str,
) -> Result<(), FigureError> {
    let n = times_s.len();
    for (k, b) in bands.iter().enumerate() {
        if b.lo.len() != n || b.mid.len() != n || b.hi.len() != n {
            return Err(FigureError::Input {
                path: path.to_path_buf(),
                reason: FigureInput::BandEdges {
                    channel: CHANNELS[k].0,
                    times: n,
                },
            });
        }
    }
    if let Some((label, d)) = data
        && d.len() != n
    {
        return Err(FigureError::Input {
            path: path.to_path_buf(),
            reason: FigureInput::Data {
                label: label.to_string(),
                samples: d.len(),
                times: n,
            },
        });
    }
    render(path, (1600, 1000), |root| {
        let (_, body) = root.split_vertically(8);
        let body = body.titled(title, text(28.0))?;
        let (legend, grid) = body.split_vertically(44);
        let mut entries = vec![
            (
                band_label.to_string(),
                LegendMark::Band(tint(colour(0), BAND_WHITE)),
            ),
            ("median".to_string(), LegendMark::Line(colour(0))),
        ];
        if let Some((label, _)) = data {
            entries.push((label.to_string(), LegendMark::Line(BLACK)));
        }
        draw_legend_strip(&legend, &entries)?;
        let x = padded_range(times_s.iter().copied(), 0.01);
        for (k, (panel, &(name, unit))) in
            grid.split_evenly((2, 3)).iter().zip(&CHANNELS).enumerate()
        {
            let b = &bands[k];
            let values = b.lo.iter().chain(b.hi).chain(b.mid).copied().chain(
                data.into_iter()
                    .flat_map(|(_, d)| d.iter().map(move |r| r[k])),
            );
            let y = padded_range(values, 0.08);
            let mut chart = ChartBuilder::on(panel)
                .caption(format!("{name} [{unit}]"), text(20.0))
                .margin(12)
                .x_label_area_size(48)
                .y_label_area_size(80)
                .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
            draw_mesh(
                &mut chart,
                "Time [s]",
                &format!("{name} [{unit}]"),
                fmt_tick,
                fmt_tick,
            )?;
            let edge: Vec<(f64, f64, f64)> = (0..n)
                .filter(|&i| plottable(times_s[i]) && plottable(b.lo[i]) && plottable(b.hi[i]))
                .map(|i| (times_s[i], b.lo[i], b.hi[i]))
                .collect();
            if edge.len() > 1 {
                chart.draw_series(std::iter::once(band_polygon(
                    &edge,
                    tint(colour(0), BAND_WHITE).filled(),
                )))?;
            }
            let mid = times_s.iter().copied().zip(b.mid.iter().copied());
            draw_polyline(&mut chart, mid, colour(0).stroke_width(2), None)?;
            if let Some((_, d)) = data {
                let points = times_s.iter().zip(d).map(|(&t, r)| (t, r[k]));
                draw_polyline(&mut chart, points, BLACK.stroke_width(1), None)?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::{check_png, dark_pixels};

    #[test]
    fn bands_of_six_channels_with_data_are_drawn_and_a_short_edge_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let t: Vec<f64> = (0..60).map(|i| i as f64 * 0.02).collect();
        let mid: Vec<Vec<f64>> = (0..6)
            .map(|k| t.iter().map(|&t| (k as f64 + 1.0) * t * t).collect())
            .collect();
        let lo: Vec<Vec<f64>> = mid
            .iter()
            .map(|m| m.iter().zip(&t).map(|(v, t)| v - 0.1 * t).collect())
            .collect();
        let hi: Vec<Vec<f64>> = mid
            .iter()
            .map(|m| m.iter().zip(&t).map(|(v, t)| v + 0.1 * t).collect())
            .collect();
        let bands: [Band; 6] = std::array::from_fn(|k| Band {
            lo: &lo[k],
            mid: &mid[k],
            hi: &hi[k],
        });
        let data: Vec<[f64; 6]> = (0..t.len())
            .map(|i| std::array::from_fn(|k| mid[k][i] + 0.02))
            .collect();
        let path = dir.path().join("prediction.png");
        band_figure(
            &path,
            &t,
            &bands,
            Some(("flown", &data)),
            "95 % band",
            "A prediction",
        )
        .unwrap();
        check_png(&path, (1600, 1000));
        assert!(dark_pixels(&path, 100..1000) > 1000);
        let short = Band {
            lo: &lo[0][..3],
            ..bands[0]
        };
        let mut bad = bands;
        bad[0] = short;
        let e = band_figure(&path, &t, &bad, None, "band", "x").unwrap_err();
        assert!(e.to_string().contains("Downrange x"), "{e}");
    }
}

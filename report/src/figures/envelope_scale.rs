//! The colour scale of an envelope map: which side of the criterion is safe, the colour of a
//! value by how far it is on the safe or the unsafe side, and the colour bar that says so.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::kit::{DrawResult, Root, fmt_tick, padded_range, plottable, text};

/// Which side of the criterion is safe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Safety {
    /// Values below the criterion are safe (for example the probability that the clearance falls
    /// below its criterion).
    LowIsSafe,
    /// Values above the criterion are safe (for example a low percentile of the clearance).
    HighIsSafe,
}

/// The colours of the scale, from the safest value (0) through the criterion (0.5) to the
/// least safe (1): light green to yellow on the safe side, orange through red to dark red on
/// the other, darkening all the way (after ColorBrewer's YlGn and YlOrRd, C. Brewer,
/// colorbrewer2.org).
const STOPS: [(f64, [f64; 3]); 5] = [
    (0.0, [204.0, 236.0, 186.0]),
    (0.5, [254.0, 217.0, 118.0]),
    (0.65, [253.0, 141.0, 60.0]),
    (0.82, [227.0, 26.0, 28.0]),
    (1.0, [128.0, 0.0, 38.0]),
];

/// Above this risk a cell is dark enough for white text.
const DARK_FROM: f64 = 0.7;

/// Red of the word "unsafe" at the bar, green of "safe".
const UNSAFE_RED: RGBColor = RGBColor(165, 0, 38);
const SAFE_GREEN: RGBColor = RGBColor(35, 120, 50);

/// A colour scale over the values of a map, anchored at the criterion.
#[derive(Debug, Clone, Copy)]
pub(super) struct Scale {
    /// The smallest value shown (the criterion included).
    pub lo: f64,
    /// The largest value shown (the criterion included).
    pub hi: f64,
    /// The criterion: the middle colour.
    pub criterion: f64,
    /// Which side of it is safe.
    pub safety: Safety,
}

impl Scale {
    /// The scale over the plottable `values` and the `criterion` (assumed plottable).
    pub fn new(values: impl IntoIterator<Item = f64>, criterion: f64, safety: Safety) -> Self {
        let (lo, hi) = padded_range(values.into_iter().chain([criterion]), 0.0);
        Self {
            lo,
            hi,
            criterion,
            safety,
        }
    }

    /// How unsafe `v` is on the scale: 0 at the safest end, 0.5 at the criterion, 1 at the
    /// other end, linear in the value on each side; NaN for a value that cannot be drawn.
    pub fn risk(&self, v: f64) -> f64 {
        if !plottable(v) {
            return f64::NAN;
        }
        // Mirror a scale where high is safe so that low is safe.
        let (v, lo, hi, c) = match self.safety {
            Safety::LowIsSafe => (v, self.lo, self.hi, self.criterion),
            Safety::HighIsSafe => (-v, -self.hi, -self.lo, -self.criterion),
        };
        let r = if v <= c {
            if c > lo {
                0.5 * (v - lo) / (c - lo)
            } else {
                0.5
            }
        } else if hi > c {
            0.5 + 0.5 * (v - c) / (hi - c)
        } else {
            1.0
        };
        r.clamp(0.0, 1.0)
    }

    /// The colour of `v` (grey when it cannot be drawn).
    pub fn colour(&self, v: f64) -> RGBColor {
        risk_colour(self.risk(v))
    }

    /// The colour of text written over a cell of value `v`.
    pub fn ink(&self, v: f64) -> RGBColor {
        if self.risk(v) > DARK_FROM {
            WHITE
        } else {
            BLACK
        }
    }
}

/// The colour at `risk` in \[0, 1\], linear between the stops; grey when not finite.
fn risk_colour(risk: f64) -> RGBColor {
    if !risk.is_finite() {
        return super::condition_map::NO_VALUE_GREY;
    }
    let r = risk.clamp(0.0, 1.0);
    let k = STOPS
        .windows(2)
        .position(|w| r <= w[1].0)
        .unwrap_or(STOPS.len() - 2);
    let ((a, ca), (b, cb)) = (STOPS[k], STOPS[k + 1]);
    let g = (r - a) / (b - a);
    let mix = |i: usize| (ca[i] + g * (cb[i] - ca[i])).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(0), mix(1), mix(2))
}

/// The styles the criterion's line is drawn with, in turn: a white halo, then a black line over
/// it, so that the line shows on every colour of the scale.
pub(super) fn criterion_styles() -> [ShapeStyle; 2] {
    [WHITE.stroke_width(7), BLACK.stroke_width(3)]
}

/// The colour bar of `scale` on `bar`, labelled `value_label`, the criterion marked by its line,
/// the safe end and the unsafe end named beside it.
pub(super) fn draw_scale_bar(bar: &Root<'_>, scale: &Scale, value_label: &str) -> DrawResult {
    let (lo, hi) = (scale.lo, scale.hi);
    let mut chart = ChartBuilder::on(bar)
        .margin_top(60)
        .margin_bottom(95)
        .margin_right(10)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .y_desc(value_label)
        .axis_desc_style(text(17.0))
        .label_style(text(14.0))
        .y_label_formatter(&|v| fmt_tick(*v))
        .draw()?;
    let steps = 128;
    let span = hi - lo;
    chart.draw_series((0..steps).map(|i| {
        let (a, b) = (i as f64 / steps as f64, (i + 1) as f64 / steps as f64);
        let mid = lo + 0.5 * (a + b) * span;
        Rectangle::new(
            [(0.0, lo + a * span), (1.0, lo + b * span)],
            scale.colour(mid).filled(),
        )
    }))?;
    for style in criterion_styles() {
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(0.0, scale.criterion), (1.0, scale.criterion)],
            style,
        )))?;
    }
    // The ends named: the unsafe one at the top when low is safe, at the bottom otherwise.
    let (top, bottom) = match scale.safety {
        Safety::LowIsSafe => (("unsafe", UNSAFE_RED), ("safe", SAFE_GREEN)),
        Safety::HighIsSafe => (("safe", SAFE_GREEN), ("unsafe", UNSAFE_RED)),
    };
    let (x0, y0) = chart.backend_coord(&(0.5, hi));
    let (_, y1) = chart.backend_coord(&(0.5, lo));
    let (bx, by) = bar.get_base_pixel();
    let word = |(s, c): (&str, RGBColor), y: i32, v: VPos| {
        let style = text(18.0).color(&c).pos(Pos::new(HPos::Center, v));
        bar.draw(&Text::new(s, (x0 - bx, y - by), style))
    };
    word(top, y0 - 8, VPos::Bottom)?;
    word(bottom, y1 + 8, VPos::Top)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_criterion_is_the_middle_and_the_safe_side_is_light() {
        let low = Scale::new([0.0, 0.2, 1.0], 0.05, Safety::LowIsSafe);
        assert!((low.risk(0.05) - 0.5).abs() < 1e-12);
        assert!(low.risk(0.0).abs() < 1e-12 && (low.risk(1.0) - 1.0).abs() < 1e-12);
        assert!(low.risk(0.01) < 0.5 && low.risk(0.1) > 0.5);
        let high = Scale::new([10.0, 40.0], 25.4, Safety::HighIsSafe);
        assert!((high.risk(25.4) - 0.5).abs() < 1e-12);
        assert!(high.risk(40.0).abs() < 1e-12 && (high.risk(10.0) - 1.0).abs() < 1e-12);
        assert!(high.risk(f64::NAN).is_nan());
        // Lighter (sum of channels) on the safe side, darkest at the unsafe end.
        let light = |c: RGBColor| u32::from(c.0) + u32::from(c.1) + u32::from(c.2);
        assert!(light(high.colour(40.0)) > light(high.colour(25.4)));
        assert!(light(high.colour(25.4)) > light(high.colour(10.0)));
        assert_eq!(high.ink(10.0), WHITE);
        assert_eq!(high.ink(40.0), BLACK);
        // The criterion beyond every value still sits on the scale.
        let beyond = Scale::new([0.001, 0.002], 0.05, Safety::LowIsSafe);
        assert!(beyond.lo <= 0.001 && beyond.hi >= 0.05);
        assert!(beyond.risk(0.002) < 0.5);
    }
}

//! What the figures' tests share: reading back the PNGs written, and a trajectory to draw.

use std::collections::HashSet;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use super::Track;

/// Decodes a PNG: (width, height, number of distinct colours).
pub(super) fn decode(path: &Path) -> (u32, u32, usize) {
    let file = File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(BufReader::new(file)).read_info().unwrap();
    let (w, h) = (reader.info().width, reader.info().height);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let frame = reader.next_frame(&mut buf).unwrap();
    assert_eq!(frame.color_type, png::ColorType::Rgb);
    let colours: HashSet<&[u8]> = buf[..frame.buffer_size()].chunks_exact(3).collect();
    (w, h, colours.len())
}

/// The (width, height) of a PNG.
pub(super) fn decode_size(path: &Path) -> (u32, u32) {
    let (w, h, _) = decode(path);
    (w, h)
}

/// Checks a written figure: a PNG of `size` with more than a few colours, and no temporary
/// file left beside it.
pub(super) fn check_png(path: &Path, size: (u32, u32)) {
    let (w, h, colours) = decode(path);
    assert_eq!((w, h), size, "{}", path.display());
    assert!(colours > 10, "{}: only {colours} colours", path.display());
    let dir = path.parent().unwrap();
    for entry in std::fs::read_dir(dir).unwrap() {
        let name = entry.unwrap().file_name();
        assert!(
            !name.to_string_lossy().starts_with(".sepval-tmp"),
            "temporary file {name:?} left"
        );
    }
}

/// Dark pixels in rows `rows` of a figure (text drawn there).
pub(super) fn dark_pixels(path: &Path, rows: std::ops::Range<usize>) -> usize {
    let file = File::open(path).unwrap();
    let mut reader = png::Decoder::new(BufReader::new(file)).read_info().unwrap();
    let w = reader.info().width as usize;
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut buf).unwrap();
    buf[rows.start * w * 3..rows.end * w * 3]
        .chunks_exact(3)
        .filter(|p| p.iter().all(|&c| c < 100))
        .count()
}

/// The pixels of a figure that are exactly `colour`.
pub(super) fn count_colour(path: &Path, colour: plotters::style::RGBColor) -> usize {
    let file = File::open(path).unwrap();
    let mut reader = png::Decoder::new(BufReader::new(file)).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let frame = reader.next_frame(&mut buf).unwrap();
    buf[..frame.buffer_size()]
        .chunks_exact(3)
        .filter(|p| p == &[colour.0, colour.1, colour.2])
        .count()
}

/// A trajectory's samples, owned (what a [`Track`] borrows).
#[derive(Debug, Clone, Default)]
pub(super) struct Samples {
    pub(super) times_s: Vec<f64>,
    pub(super) pos_m: Vec<[f64; 3]>,
    pub(super) att_deg: Vec<[f64; 3]>,
}

impl Samples {
    /// The samples as the figures draw them.
    pub(super) fn track(&self) -> Track<'_> {
        Track {
            times_s: &self.times_s,
            pos_m: &self.pos_m,
            att_deg: &self.att_deg,
        }
    }
}

/// A trajectory over 1.2 s at 50 Hz, shaped by `k`.
pub(super) fn trajectory(k: f64) -> Samples {
    let times_s: Vec<f64> = (0..60).map(|i| f64::from(i) * 0.02).collect();
    let pos_m = times_s
        .iter()
        .map(|&t| [k * 2.0 * t, 0.3 * k * t * t, 4.9 * t * t])
        .collect();
    let att_deg = times_s
        .iter()
        .map(|&t| [10.0 * (3.0 * t).sin(), -8.0 * k * t, 2.0 * t * t])
        .collect();
    Samples {
        times_s,
        pos_m,
        att_deg,
    }
}

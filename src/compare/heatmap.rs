//! A false-colour picture of a comparison, with a legend.
//!
//! Each pixel shows `log10` of its relative error on the viridis scale (van der Walt & Smith, matplotlib 2015:
//! perceptually uniform, lightness rising monotonically, readable with the common colour-vision deficiencies and
//! in grey) from 1e-10 (dark purple) to 1 (yellow); exact pixels are black, coverage mismatches white, pixels
//! covered in neither image dark grey. The legend
//! below the picture carries the scale, its labels and the three special colours. The text is drawn with a
//! built-in 3×5 pixel font, so no font file is needed.

use super::metrics::PixelDiff;

/// Range of the colour scale, as log10 of the relative error.
pub const LOG_MIN: f64 = -10.0;
pub const LOG_MAX: f64 = 0.0;

const EXACT: [u8; 3] = [0, 0, 0];
const MISMATCH: [u8; 3] = [255, 255, 255];
const EMPTY: [u8; 3] = [40, 40, 40];
const BACKGROUND: [u8; 3] = [255, 255, 255];
/// Around the picture, so that white coverage mismatches at its border stay visible.
const FRAME: [u8; 3] = [128, 128, 128];
const INK: [u8; 3] = [0, 0, 0];
const LEGEND_HEIGHT: u32 = 44;
const MIN_WIDTH: u32 = 360;

/// Colour of a value `t` in [0, 1] on the viridis scale, interpolated linearly between nine of its samples.
pub fn colour_scale(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    sampled_scale(&STOPS, t)
}

/// Colour of `t` in [0, 1] (NaN: 1) on a scale given by samples evenly spaced over it, interpolated linearly.
pub(super) fn sampled_scale(stops: &[[f64; 3]], t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 1.0 } else { t.clamp(0.0, 1.0) } * (stops.len() - 1) as f64;
    let i = (t.floor() as usize).min(stops.len() - 2);
    let f = t - i as f64;
    let c: [f64; 3] = std::array::from_fn(|k| stops[i][k] * (1.0 - f) + stops[i + 1][k] * f);
    c.map(|v| v.round() as u8)
}

fn pixel_colour(d: &PixelDiff) -> [u8; 3] {
    match *d {
        PixelDiff::Empty => EMPTY,
        PixelDiff::CoverageMismatch => MISMATCH,
        PixelDiff::Relative(0.0) => EXACT,
        PixelDiff::Relative(r) => colour_scale((r.log10() - LOG_MIN) / (LOG_MAX - LOG_MIN)),
    }
}

/// Renders the heatmap of a `width × height` comparison as RGB8, returning `(width, height, pixels)`.
pub fn heatmap(width: u32, height: u32, diffs: &[PixelDiff]) -> (u32, u32, Vec<u8>) {
    let out_w = width.max(MIN_WIDTH);
    let out_h = height + LEGEND_HEIGHT;
    let mut canvas = Canvas { w: out_w, h: out_h, px: vec![255; (out_w * out_h * 3) as usize] };
    canvas.fill(0, 0, out_w, height, BACKGROUND);
    canvas.fill(width, 0, out_w - width, height, FRAME);
    for y in 0..height {
        for x in 0..width {
            canvas.put(x, y, pixel_colour(&diffs[(y * width + x) as usize]));
        }
    }
    // Legend: the colour bar with decade ticks, then the special colours.
    let top = height + 4;
    let (bar_x, bar_w) = (8u32, out_w.saturating_sub(16).min(400));
    for i in 0..bar_w {
        let c = colour_scale(i as f64 / (bar_w - 1) as f64);
        canvas.fill(bar_x + i, top, 1, 10, c);
    }
    for decade in 0..=5 {
        let e = LOG_MIN + (LOG_MAX - LOG_MIN) * decade as f64 / 5.0;
        let x = bar_x + ((bar_w - 1) as f64 * decade as f64 / 5.0).round() as u32;
        canvas.fill(x, top + 10, 1, 3, INK);
        let label = if e == 0.0 { "1".to_string() } else { format!("1e{}", e as i32) };
        let lx = x.saturating_sub(text_width(&label) / 2).min(out_w.saturating_sub(text_width(&label)));
        canvas.text(lx, top + 14, &label);
    }
    let y2 = top + 24;
    let mut x = bar_x;
    for (colour, name) in [(EXACT, "exact"), (MISMATCH, "coverage"), (EMPTY, "uncovered")] {
        canvas.fill(x - 1, y2 - 1, 12, 12, INK);
        canvas.fill(x, y2, 10, 10, colour);
        canvas.text(x + 13, y2 + 2, name);
        x += 13 + text_width(name) + 12;
    }
    canvas.text(x, y2 + 2, "log10 rel err");
    (out_w, out_h, canvas.px)
}

struct Canvas {
    w: u32,
    h: u32,
    px: Vec<u8>,
}

impl Canvas {
    fn put(&mut self, x: u32, y: u32, c: [u8; 3]) {
        if x < self.w && y < self.h {
            let i = ((y * self.w + x) * 3) as usize;
            self.px[i..i + 3].copy_from_slice(&c);
        }
    }

    fn fill(&mut self, x: u32, y: u32, w: u32, h: u32, c: [u8; 3]) {
        for yy in y..y + h {
            for xx in x..x + w {
                self.put(xx, yy, c);
            }
        }
    }

    /// Draws text in the 3×5 font at scale 1 (4 px per character).
    fn text(&mut self, x: u32, y: u32, s: &str) {
        for (i, ch) in s.chars().enumerate() {
            let rows = glyph(ch);
            for (r, bits) in rows.iter().enumerate() {
                for c in 0..3 {
                    if bits & (0b100 >> c) != 0 {
                        self.put(x + 4 * i as u32 + c, y + r as u32, INK);
                    }
                }
            }
        }
    }
}

fn text_width(s: &str) -> u32 {
    4 * s.chars().count() as u32
}

/// A 3×5 glyph, one byte per row, the three low bits from left to right. Unknown characters are blank.
fn glyph(c: char) -> [u8; 5] {
    match c {
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '2' => [0b111, 0b001, 0b111, 0b100, 0b111],
        '3' => [0b111, 0b001, 0b111, 0b001, 0b111],
        '4' => [0b101, 0b101, 0b111, 0b001, 0b001],
        '5' => [0b111, 0b100, 0b111, 0b001, 0b111],
        '6' => [0b111, 0b100, 0b111, 0b101, 0b111],
        '7' => [0b111, 0b001, 0b010, 0b010, 0b010],
        '8' => [0b111, 0b101, 0b111, 0b101, 0b111],
        '9' => [0b111, 0b101, 0b111, 0b001, 0b111],
        '-' => [0b000, 0b000, 0b111, 0b000, 0b000],
        '.' => [0b000, 0b000, 0b000, 0b000, 0b010],
        'a' => [0b000, 0b111, 0b001, 0b111, 0b111],
        'c' => [0b000, 0b111, 0b100, 0b100, 0b111],
        'd' => [0b001, 0b111, 0b101, 0b101, 0b111],
        'e' => [0b000, 0b111, 0b111, 0b100, 0b111],
        'g' => [0b000, 0b111, 0b101, 0b111, 0b011],
        'l' => [0b100, 0b100, 0b100, 0b100, 0b110],
        'n' => [0b000, 0b110, 0b101, 0b101, 0b101],
        'o' => [0b000, 0b111, 0b101, 0b101, 0b111],
        'r' => [0b000, 0b111, 0b100, 0b100, 0b100],
        't' => [0b010, 0b111, 0b010, 0b010, 0b011],
        'u' => [0b000, 0b101, 0b101, 0b101, 0b111],
        'v' => [0b000, 0b101, 0b101, 0b101, 0b010],
        'x' => [0b000, 0b101, 0b010, 0b010, 0b101],
        _ => [0; 5],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_mark_special_pixels_and_scale_errors() {
        let diffs = vec![
            PixelDiff::Empty,
            PixelDiff::CoverageMismatch,
            PixelDiff::Relative(0.0),
            PixelDiff::Relative(1e-10),
            PixelDiff::Relative(1.0),
            PixelDiff::Relative(1e-5),
        ];
        let (w, h, px) = heatmap(3, 2, &diffs);
        assert_eq!((w, h), (MIN_WIDTH, 2 + LEGEND_HEIGHT));
        let at = |x: u32, y: u32| {
            let i = ((y * w + x) * 3) as usize;
            [px[i], px[i + 1], px[i + 2]]
        };
        assert_eq!(at(0, 0), EMPTY);
        assert_eq!(at(1, 0), MISMATCH);
        assert_eq!(at(2, 0), EXACT);
        assert_eq!(at(0, 1), colour_scale(0.0));
        assert_eq!(at(1, 1), colour_scale(1.0));
        assert_eq!(at(2, 1), colour_scale(0.5));
        assert_ne!(colour_scale(0.0), colour_scale(1.0));
        // The legend draws the colour bar under the picture.
        assert_eq!(at(8, 2 + 4), colour_scale(0.0));
    }

    #[test]
    fn the_scale_brightens_monotonically_so_it_reads_without_hue() {
        // Relative luminance (Rec. 709 weights on sRGB-decoded channels) must rise along the scale: then the
        // order of errors survives colour-vision deficiencies and greyscale printing.
        let decode = |c: u8| {
            let v = c as f64 / 255.0;
            if v <= 0.04045 {
                v / 12.92
            } else {
                ((v + 0.055) / 1.055).powf(2.4)
            }
        };
        let luminance = |[r, g, b]: [u8; 3]| 0.2126 * decode(r) + 0.7152 * decode(g) + 0.0722 * decode(b);
        let samples: Vec<f64> = (0..=64).map(|i| luminance(colour_scale(i as f64 / 64.0))).collect();
        assert!(samples.windows(2).all(|w| w[1] > w[0]), "{samples:?}");
        // The special colours stand apart from every colour of the scale.
        for special in [EXACT, MISMATCH, EMPTY] {
            assert!((0..=64).all(|i| colour_scale(i as f64 / 64.0) != special));
        }
    }

    #[test]
    fn every_legend_character_has_a_glyph() {
        for c in "0123456789-.exactcoverageuncoveredlog10 rel err".chars().filter(|c| *c != ' ') {
            assert_ne!(glyph(c), [0; 5], "no glyph for '{c}'");
        }
    }
}

//! A false-colour picture of an image's values with a legend in their unit, as Radiance's `falsecolor` draws one:
//! for reading irradiance (W/m²) or radiance (W/(m²·sr)) off a render at a glance.
//!
//! - **Value** per pixel: the Rec. 709 luminance weighting of the linear RGB channels,
//!   `0.2126 R + 0.7152 G + 0.0722 B`, in the channels' own unit (for grey light it is that value; sunshade's RGB
//!   has the Rec. 709 primaries of linear sRGB). It is a weighting, not a conversion to photometric units.
//! - **Scale**: viridis (`compare::colour_scale`: perceptually uniform, lightness rising monotonically, readable
//!   with the common colour-vision deficiencies and in grey), linear from 0 to a maximum.
//! - **Range**: the maximum is the 99th percentile of the covered pixels' values rounded up to 1, 2 or 5 × 10ⁿ
//!   (so that a few hot pixels, a specular glint, do not flatten the rest, and the labels are round numbers), or
//!   the value given (`--false-color-max`). Values above it show in the top colour; the legend's last label says
//!   "≥". Pixels covered by nothing are dark grey.

use super::{Canvas, Rgb};
use crate::compare::colour_scale;
use crate::film::Image;

const EMPTY: Rgb = [40, 40, 40];
const INK: Rgb = [0, 0, 0];
/// Height of the legend under the picture \[pixels\].
pub const LEGEND_HEIGHT: u32 = 48;
const MIN_WIDTH: u32 = 320;

/// The value a pixel is coloured by: the Rec. 709 weighting of its channels.
pub fn pixel_value(p: [f32; 4]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// `v` rounded up to 1, 2 or 5 × 10ⁿ (positive, finite); 1 for anything else.
pub fn nice_ceiling(v: f64) -> f64 {
    if !(v.is_finite() && v > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powf(v.log10().floor());
    // The rounding of log10 and powf can leave `decade` a hair off; the steps are compared with a margin so that an
    // exact 200 stays 200.
    [1.0, 2.0, 5.0, 10.0].iter().map(|k| k * decade).find(|&n| n >= v * (1.0 - 1e-12)).unwrap_or(10.0 * decade)
}

/// The default maximum of the scale: the 99th percentile of the covered pixels' values, rounded up
/// ([`nice_ceiling`]).
pub fn default_max(image: &Image) -> f64 {
    let mut values: Vec<f64> =
        image.pixels().iter().filter(|p| p[3] > 0.0).map(|&p| pixel_value(p)).filter(|v| v.is_finite()).collect();
    if values.is_empty() {
        return 1.0;
    }
    values.sort_by(f64::total_cmp);
    let k = ((values.len() - 1) as f64 * 0.99).round() as usize;
    nice_ceiling(values[k])
}

/// A label for a value of the scale: up to 4 significant digits, no trailing zeros.
fn label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if (1e-3..1e5).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.1e}")
    }
}

/// The false-colour picture of `image` on the scale `[0, max]` (`max` > 0), with a legend naming `unit`.
pub fn false_color(image: &Image, max: f64, unit: &str) -> Canvas {
    let (w, h) = (image.width(), image.height());
    let out_w = w.max(MIN_WIDTH);
    let mut canvas = Canvas::new(out_w, h + LEGEND_HEIGHT);
    for y in 0..h {
        for x in 0..w {
            let p = image.get(x, y);
            let c = if p[3] > 0.0 { colour_scale(pixel_value(p) / max) } else { EMPTY };
            canvas.set(x as i32, y as i32, c);
        }
    }
    // The colour bar, five labelled ticks (0 … max), and the unit.
    let (bar_x, bar_w, top) = (8i32, (out_w as i32 - 16).min(400), h as i32 + 4);
    for i in 0..bar_w {
        let c = colour_scale(i as f64 / (bar_w - 1) as f64);
        canvas.fill((bar_x + i, top), (bar_x + i, top + 11), c);
    }
    for tick in 0..=4 {
        let x = bar_x + ((bar_w - 1) as f64 * tick as f64 / 4.0).round() as i32;
        canvas.fill((x, top + 12), (x, top + 15), INK);
        let v = max * tick as f64 / 4.0;
        let text = if tick == 4 { format!(">={}", label(v)) } else { label(v) };
        let tw = Canvas::text_width(&text, 1);
        let lx = (x - tw / 2).clamp(0, out_w as i32 - tw);
        canvas.text((lx, top + 18), &text, INK, 1);
    }
    canvas.text((bar_x, top + 30), unit, INK, 1);
    canvas
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_maxima_and_labels() {
        assert_eq!(nice_ceiling(0.7), 1.0);
        assert_eq!(nice_ceiling(1.0), 1.0);
        assert_eq!(nice_ceiling(1.01), 2.0);
        assert_eq!(nice_ceiling(200.0), 200.0);
        assert_eq!(nice_ceiling(201.0), 500.0);
        assert_eq!(nice_ceiling(8000.0), 10000.0);
        assert_eq!(nice_ceiling(3e-4), 5e-4);
        assert_eq!(nice_ceiling(f64::NAN), 1.0);
        assert_eq!(label(250.0), "250");
        assert_eq!(label(0.125), "0.125");
        assert_eq!(label(1.5e6), "1.5e6");
    }

    #[test]
    fn a_ramp_is_coloured_in_order_and_the_legend_sits_below() {
        // A ramp 0 … 1000 W/m² over 100 pixels, one pixel uncovered, one far above the 99th percentile.
        let mut image = Image::new(100, 10);
        for y in 0..10 {
            for x in 0..100 {
                let v = 10.0 * x as f32;
                image.set(x, y, [v, v, v, 1.0]);
            }
        }
        image.set(0, 0, [0.0; 4]);
        image.set(99, 9, [1e9, 1e9, 1e9, 1.0]);
        let max = default_max(&image);
        assert_eq!(max, 1000.0, "the 99th percentile (990) rounded up");
        let c = false_color(&image, max, "W/m2");
        assert_eq!((c.width(), c.height()), (MIN_WIDTH, 10 + LEGEND_HEIGHT));
        assert_eq!(c.get(0, 0), EMPTY);
        assert_eq!(c.get(99, 9), colour_scale(1.0), "above the maximum: the top colour");
        // Viridis grows lighter along the ramp: green rises monotonically across it.
        let greens: Vec<u8> = (0..99).map(|x| c.get(x, 5)[1]).collect();
        assert!(greens.windows(2).all(|w| w[0] <= w[1]), "{greens:?}");
        assert_eq!(c.get(50, 5), colour_scale(500.0 / 1000.0));
        // The legend: the bar's ends in the scale's ends, ink under it.
        assert_eq!(c.get(8, 15), colour_scale(0.0));
        assert!((0..c.width()).any(|x| (10 + 22..10 + 30).any(|y| c.get(x, y) == INK)), "labels drawn");
    }
}

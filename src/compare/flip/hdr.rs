//! HDR-FLIP (Andersson et al. 2021, "Visualizing Errors in Rendered High Dynamic Range Images"): two images of
//! linear radiance compared as a viewer would see them through a tone mapper at every exposure that matters: each
//! exposure's LDR-FLIP, the largest per pixel.
//!
//! The tone mapper is ACES's filmic curve as Narkowicz fits it, its input pre-scaled by 0.6:
//! `t(x) = (a x² + b x) / (c x² + d x + e)` per channel. The exposures run from `c_start = log2(x_max / Y_max)`,
//! which maps the reference's brightest luminance to `x_max`, the input the tone mapper takes to 0.85, to
//! `c_stop = log2(x_max / Y_median)`, which does so for its median luminance, in `max(2, ⌈c_stop − c_start⌉)`
//! evenly spaced steps (about one a stop).
//!
//! **Black backgrounds.** Where more than half of the reference is black (a render's background), its median
//! luminance is 0 and `c_stop` infinite; the median is then taken over the pixels of non-zero luminance, the
//! content a viewer would expose for. An image black throughout is compared at exposure 0 alone.

use super::ldr::ldr_flip;

/// The tone mapper's coefficients: `(a x² + b x + c) / (d x² + e x + f)`, ACES (Narkowicz 2015) with the input
/// pre-scaled by 0.6.
const ACES: [f32; 6] = [0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14];
/// The tone-mapped value the exposure range aims the brightest and the median luminance at.
const TARGET: f32 = 0.85;

/// ACES's curve, per channel.
fn tone_map(x: f32) -> f32 {
    let t = ACES;
    (x * x * t[0] + x * t[1] + t[2]) / (x * x * t[3] + x * t[4] + t[5])
}

/// The input that the tone mapper takes to [`TARGET`]: the larger root of `(a − T d) x² + (b − T e) x + (c − T f)`.
fn tone_map_input_for_target() -> f32 {
    let t = ACES;
    let (a, b, c) = (t[0] - TARGET * t[3], t[1] - TARGET * t[4], t[2] - TARGET * t[5]);
    if a == 0.0 {
        return -c / b;
    }
    let half = -0.5 * (b / a);
    half + (half * half - c / a).sqrt()
}

/// Rec. 709 luminance of a linear sRGB colour.
fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// The exposures HDR-FLIP compares at \[stops\]: `(start, stop, count)` from the reference's luminances.
pub fn exposure_range(reference: &[[f32; 3]]) -> (f32, f32, usize) {
    let mut lum: Vec<f32> = reference.iter().map(|&c| luminance(c)).collect();
    let y_max = lum.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let upper_median = |v: &mut Vec<f32>| {
        let m = v.len() / 2;
        *v.select_nth_unstable_by(m, f32::total_cmp).1
    };
    let mut y_median = if lum.is_empty() { 0.0 } else { upper_median(&mut lum) };
    if y_median <= 0.0 {
        lum.retain(|&y| y > 0.0);
        y_median = if lum.is_empty() { 0.0 } else { upper_median(&mut lum) };
    }
    if !(y_max > 0.0 && y_median > 0.0) {
        return (0.0, 0.0, 1);
    }
    let x_max = tone_map_input_for_target();
    let (start, stop) = ((x_max / y_max).log2(), (x_max / y_median).log2());
    (start, stop, (stop - start).ceil().max(2.0) as usize)
}

/// The HDR-FLIP map of `test` against `reference` (linear radiance, any scale) at `ppd` pixels per degree, with
/// the exposures compared (`exposure_range`).
pub fn hdr_flip(
    width: usize,
    height: usize,
    reference: &[[f32; 3]],
    test: &[[f32; 3]],
    ppd: f32,
) -> (Vec<f32>, (f32, f32, usize)) {
    let (start, stop, count) = exposure_range(reference);
    let step = if count > 1 { (stop - start) / (count - 1) as f32 } else { 0.0 };
    let mut worst = vec![0.0f32; width * height];
    for i in 0..count {
        let scale = (start + i as f32 * step).exp2();
        let exposed = |img: &[[f32; 3]]| -> Vec<[f32; 3]> {
            img.iter().map(|c| c.map(|v| tone_map(v * scale).clamp(0.0, 1.0))).collect()
        };
        let map = ldr_flip(width, height, &exposed(reference), &exposed(test), ppd);
        for (w, v) in worst.iter_mut().zip(map) {
            *w = w.max(v);
        }
    }
    (worst, (start, stop, count))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_input_maps_to_the_target() {
        let x = tone_map_input_for_target();
        assert!((tone_map(x) - TARGET).abs() < 1e-5, "{x} -> {}", tone_map(x));
        assert_eq!(tone_map(0.0), 0.0);
        assert!(tone_map(1e6) < 1.04);
    }

    #[test]
    fn exposures_span_the_brightest_to_the_median_luminance() {
        // Luminances 1 (a quarter), 4 (half) and 64 (a quarter): max 64, upper median 4, so 4 stops.
        let img: Vec<[f32; 3]> = [1.0f32, 4.0, 4.0, 64.0].iter().map(|&y| [y; 3]).collect();
        let (start, stop, count) = exposure_range(&img);
        assert!((stop - start - 4.0).abs() < 1e-5, "{start} {stop}");
        assert_eq!(count, 4);
        let x = tone_map_input_for_target();
        assert!(((x / 64.0).log2() - start).abs() < 1e-5);
    }

    #[test]
    fn a_black_background_does_not_stop_the_exposures_at_infinity() {
        // Seven black pixels of ten; of the others 2, 2 and 8: the median over them is 2, two stops below 8.
        let mut img = vec![[0.0f32; 3]; 10];
        img[0] = [2.0; 3];
        img[1] = [2.0; 3];
        img[2] = [8.0; 3];
        let (start, stop, count) = exposure_range(&img);
        assert!(start.is_finite() && stop.is_finite() && (stop - start - 2.0).abs() < 1e-5, "{start} {stop}");
        assert_eq!(count, 2);
        assert_eq!(exposure_range(&[[0.0; 3]; 4]), (0.0, 0.0, 1));
    }
}

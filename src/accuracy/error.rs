//! An image's error against the truth (a converged reference), in the terms of `sunshade diff`: per pixel the
//! relative error `|a − t| / max(|a|, |t|, floor)`, largest over RGB, with the floor 1% of the larger image peak
//! (below it a relative error measures f32 rounding, not rendering); coverage mismatches are counted apart.

use crate::compare::{self, DiffOptions, PixelDiff};
use crate::film::Image;

/// The thresholds whose exceedances are counted: 1e-2, 1e-3, 1e-4.
pub const THRESHOLDS: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// How far an image is from the truth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    /// The largest relative error over the pixels covered in both.
    pub max_rel: f64,
    /// The 99th percentile of the relative errors (nearest rank).
    pub p99: f64,
    /// Root mean square of the absolute differences over RGB of the pixels covered in both [W/(m²·sr)].
    pub rmse: f64,
    /// Pixels over each of [`THRESHOLDS`].
    pub over: [usize; 3],
    /// Pixels covered in both (and not excluded).
    pub compared: usize,
    /// Pixels covered in one only.
    pub coverage_mismatches: usize,
}

/// The error of `image` against `truth` (the same size), over the pixels covered in both that `excluded` does not
/// flag (row-major, one flag a pixel: the pixels where the truth itself has not converged).
pub fn image_error(image: &Image, truth: &Image, excluded: Option<&[bool]>) -> Result<ImageError, String> {
    let (report, per_pixel) = compare::diff(image, truth, &DiffOptions::default())?;
    let skip = |i: usize| excluded.is_some_and(|m| m.get(i) == Some(&true));
    let (mut rel, mut sum_sq) = (Vec::new(), 0.0);
    for (i, p) in per_pixel.iter().enumerate() {
        if let (PixelDiff::Relative(r), false) = (p, skip(i)) {
            rel.push(*r);
            let (a, b) = (image.pixels()[i], truth.pixels()[i]);
            sum_sq += (0..3).map(|c| (a[c] as f64 - b[c] as f64).powi(2)).sum::<f64>();
        }
    }
    let compared = rel.len();
    rel.sort_by(f64::total_cmp);
    let p99 = match compared {
        0 => 0.0,
        n => rel[((0.99 * n as f64).ceil() as usize).clamp(1, n) - 1],
    };
    Ok(ImageError {
        max_rel: rel.last().copied().unwrap_or(0.0),
        p99,
        rmse: if compared > 0 { (sum_sq / (3 * compared) as f64).sqrt() } else { 0.0 },
        over: THRESHOLDS.map(|t| rel.iter().filter(|&&r| r > t).count()),
        compared,
        coverage_mismatches: report.coverage_mismatches.total,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(values: &[f32]) -> Image {
        Image::from_pixels(values.len() as u32, 1, values.iter().map(|&v| [v, v, v, 1.0]).collect()).unwrap()
    }

    #[test]
    fn counts_and_percentile_follow_the_relative_errors() {
        // 100 pixels of radiance 1; pixel k is off by k·1.7e-5 (k = 0..99): relative k·1.7e-5 / (1 + k·1.7e-5),
        // over 1e-4 from k = 6, over 1e-3 from k = 59 (each well clear of f32 rounding, 6e-8).
        let truth = image(&[1.0; 100]);
        let values: Vec<f32> = (0..100).map(|k| 1.0 + k as f32 * 1.7e-5).collect();
        let rel = |k: f64| k * 1.7e-5 / (1.0 + k * 1.7e-5);
        let e = image_error(&image(&values), &truth, None).unwrap();
        assert!((e.max_rel - rel(99.0)).abs() < 1e-6, "{}", e.max_rel);
        // Nearest rank: the 99th of 100 sorted errors is pixel 98's.
        assert!((e.p99 - rel(98.0)).abs() < 1e-6, "{}", e.p99);
        assert_eq!(e.over, [0, 41, 94]);
        assert_eq!((e.compared, e.coverage_mismatches), (100, 0));
        // Excluding the worst pixel: the next is the largest.
        let mut excluded = vec![false; 100];
        excluded[99] = true;
        let e = image_error(&image(&values), &truth, Some(&excluded)).unwrap();
        assert!((e.max_rel - rel(98.0)).abs() < 1e-6 && e.compared == 99, "{}", e.max_rel);
    }

    #[test]
    fn below_the_floor_errors_are_relative_to_the_floor() {
        // Peak 100: the floor is 1; a pixel of 0.01 against 0.02 is off by 0.01 of the floor, not 50%.
        let e = image_error(&image(&[100.0, 0.02]), &image(&[100.0, 0.01]), None).unwrap();
        assert!((e.max_rel - 0.01).abs() < 1e-6, "{}", e.max_rel);
    }
}

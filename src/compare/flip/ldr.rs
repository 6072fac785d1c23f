//! LDR-FLIP (Andersson et al. 2020): the per-pixel difference of two images in linear sRGB within [0, 1], as a
//! viewer at `ppd` pixels per degree sees them when they alternate.
//!
//! Colour: both images are low-passed by the contrast sensitivity filters in YCxCz (what the eye cannot resolve is
//! removed), taken to CIELAB with the Hunt adjustment, and their HyAB distance `ΔE` raised to `q_c = 0.7` is
//! mapped to [0, 1]: linearly to `p_t = 0.95` up to `p_c = 0.4` of the largest difference `c_max`, the rest
//! compressed into (0.95, 1]. Features: the luminance's edges and points (first and second Gaussian
//! derivatives) in each image; their largest magnitude difference, over √2 and raised to `q_f = ½`, is `ΔE_f`.
//! The pixel's FLIP is `ΔE_c^(1 − ΔE_f)`: a colour difference counts more where an edge or point appears or
//! disappears.

use super::colour::{
    hunt, hyab, linear_rgb_to_xyz, max_colour_difference, xyz_to_lab, xyz_to_linear_rgb, xyz_to_ycxcz, ycxcz_to_xyz,
};
use super::filters::{CsfKernels, FeatureKernels, Plane};
use rayon::prelude::*;

/// The exponent of the colour difference.
const Q_C: f32 = 0.7;
/// The share of `c_max` below which differences map linearly onto [0, P_T].
const P_C: f32 = 0.4;
const P_T: f32 = 0.95;
/// The exponent of the feature difference.
const Q_F: f32 = 0.5;

/// An image's three YCxCz planes.
struct Ycxcz([Plane; 3]);

impl Ycxcz {
    /// From linear sRGB pixels, each clamped to [0, 1] first.
    fn from_linear(width: usize, height: usize, rgb: &[[f32; 3]]) -> Self {
        let c: Vec<[f32; 3]> =
            rgb.par_iter().map(|p| xyz_to_ycxcz(linear_rgb_to_xyz(p.map(|v| v.clamp(0.0, 1.0))))).collect();
        Ycxcz(std::array::from_fn(|k| Plane::new(width, height, c.iter().map(|p| p[k]).collect())))
    }

    /// Low-passed by the contrast sensitivity kernels (the blue–yellow channel as its two terms' sum).
    fn filtered(&self, k: &CsfKernels) -> [Plane; 3] {
        let [y, cx, cz] = &self.0;
        let cz0 = cz.along_x(&k.cz[0]).along_y(&k.cz[0]);
        let cz1 = cz.along_x(&k.cz[1]).along_y(&k.cz[1]);
        let sum = cz0.values.iter().zip(&cz1.values).map(|(a, b)| a + b).collect();
        [y.along_x(&k.y).along_y(&k.y), cx.along_x(&k.cx).along_y(&k.cx), Plane::new(cz.width, cz.height, sum)]
    }

    /// The luminance normalised to [0, 1] (`(Y' + 16) / 116 = Y / Yn`), where features are detected.
    fn grey(&self) -> Plane {
        let y = &self.0[0];
        Plane::new(y.width, y.height, y.values.iter().map(|v| (v + 16.0) / 116.0).collect())
    }
}

/// Each pixel's Hunt-adjusted CIELAB after the contrast sensitivity filters, the filtered colour clamped to
/// sRGB's gamut in linear RGB.
fn perceived(image: &Ycxcz, k: &CsfKernels) -> Vec<[f32; 3]> {
    let [y, cx, cz] = image.filtered(k);
    (0..y.values.len())
        .into_par_iter()
        .map(|i| {
            let rgb = xyz_to_linear_rgb(ycxcz_to_xyz([y.values[i], cx.values[i], cz.values[i]]));
            hunt(xyz_to_lab(linear_rgb_to_xyz(rgb.map(|v| v.clamp(0.0, 1.0)))))
        })
        .collect()
}

/// The edge and point magnitudes of the luminance `grey`: the Gaussian's first and second derivatives along x
/// (smoothed along y) and along y (smoothed along x), each pair's Euclidean length.
fn features(grey: &Plane, k: &FeatureKernels) -> (Vec<f32>, Vec<f32>) {
    let smooth_x = grey.along_x(&k.g);
    let (dx, ddx) = (grey.along_x(&k.dg).along_y(&k.g), grey.along_x(&k.ddg).along_y(&k.g));
    let (dy, ddy) = (smooth_x.along_y(&k.dg), smooth_x.along_y(&k.ddg));
    let length = |a: &Plane, b: &Plane| a.values.iter().zip(&b.values).map(|(u, v)| (u * u + v * v).sqrt()).collect();
    (length(&dx, &dy), length(&ddx, &ddy))
}

/// The colour difference `ΔE_c` in [0, 1] of two perceived colours.
fn colour_difference(a: [f32; 3], b: [f32; 3], c_max: f32) -> f32 {
    let d = hyab(a, b).powf(Q_C);
    let knee = P_C * c_max;
    if d < knee {
        d * (P_T / knee)
    } else {
        P_T + (d - knee) / (c_max - knee) * (1.0 - P_T)
    }
}

/// The LDR-FLIP map of `test` against `reference` (`width × height` pixels, linear sRGB, clamped to [0, 1]) at
/// `ppd` pixels per degree: one value in [0, 1] a pixel, row-major.
pub fn ldr_flip(width: usize, height: usize, reference: &[[f32; 3]], test: &[[f32; 3]], ppd: f32) -> Vec<f32> {
    let (r, t) = (Ycxcz::from_linear(width, height, reference), Ycxcz::from_linear(width, height, test));
    let csf = CsfKernels::new(ppd);
    let (pr, pt) = (perceived(&r, &csf), perceived(&t, &csf));
    let c_max = max_colour_difference(Q_C);
    let fk = FeatureKernels::new(ppd);
    let ((er, qr), (et, qt)) = (features(&r.grey(), &fk), features(&t.grey(), &fk));
    (0..width * height)
        .into_par_iter()
        .map(|i| {
            let colour = colour_difference(pr[i], pt[i], c_max);
            let feature =
                (std::f32::consts::FRAC_1_SQRT_2 * (er[i] - et[i]).abs().max((qr[i] - qt[i]).abs())).powf(Q_F);
            colour.powf(1.0 - feature)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_differ_by_nothing() {
        let img: Vec<[f32; 3]> = (0..64).map(|i| [(i % 8) as f32 / 8.0, (i / 8) as f32 / 8.0, 0.5]).collect();
        assert!(ldr_flip(8, 8, &img, &img, 67.0).iter().all(|&v| v == 0.0));
    }

    #[test]
    fn uniform_images_differ_by_their_colour_difference_alone() {
        // No edges, no points: FLIP is ΔE_c of the two colours, the filters leaving a uniform image as it is.
        let (a, b) = ([0.2f32, 0.4, 0.6], [0.25f32, 0.4, 0.5]);
        let map = ldr_flip(16, 16, &[a; 256], &[b; 256], 67.0);
        let lab = |c: [f32; 3]| hunt(xyz_to_lab(linear_rgb_to_xyz(c)));
        let expected = colour_difference(lab(a), lab(b), max_colour_difference(Q_C));
        assert!(expected > 0.05 && expected < 0.95, "{expected}");
        for v in map {
            assert!((v - expected).abs() < 2e-3 * expected, "{v} {expected}");
        }
    }

    #[test]
    fn black_against_white_differs_by_lightness_alone() {
        let map = ldr_flip(8, 8, &[[0.0; 3]; 64], &[[1.0; 3]; 64], 67.0);
        // HyAB(black, white) = 100: all of it lightness, Hunt-adjusted chroma 0 in both.
        let expected = colour_difference([0.0; 3], [100.0, 0.0, 0.0], max_colour_difference(Q_C));
        assert!(map.iter().all(|v| (v - expected).abs() < 1e-4), "{} {expected}", map[0]);
    }
}

//! FLIP's two filter banks, both separable, and the clamp-to-edge convolution they share.
//!
//! **Contrast sensitivity** (Andersson et al. 2020, section 3.1, after Johnson & Fairchild): each YCxCz channel is
//! low-passed by a sum of Gaussians given in the frequency domain; in the spatial domain a term `a e^{−b ρ²}`
//! (ρ in cycles per degree) is `a √(π/b) e^{−π² x²/b}` per axis (x in degrees, one pixel `1/ppd`). Achromatic
//! `(a, b) = (1, 0.0047)`, red–green `(1, 0.0053)`, blue–yellow `(34.1, 0.04) + (13.5, 0.025)`. The 2-D
//! kernel of one term is the outer product of its 1-D kernel with itself, so the blue–yellow sum is filtered as two
//! separable terms added after both passes, each 1-D kernel the square root of its term's 2-D factor; the kernels
//! are normalised so that each channel's 2-D kernel sums to 1 (uniform areas keep their colour). The radius is
//! three standard deviations of the widest term, `3 √(b_max / (2π²))` degrees.
//!
//! **Features** (section 3.2): edges and points of the luminance, found with the first and second derivatives of a
//! Gaussian of `σ = ½ w` degrees (`w = 0.082`, the width of the eye's edge detectors), radius `⌈3σ⌉` pixels. The
//! Gaussian's weights sum to 1; each derivative's positive weights sum to 1 and its negative ones to −1, so a
//! step's response does not depend on `ppd`.

use rayon::prelude::*;

/// The contrast sensitivity Gaussians (a, b): achromatic, red–green, and blue–yellow's two.
const CSF_Y: (f32, f32) = (1.0, 0.0047);
const CSF_CX: (f32, f32) = (1.0, 0.0053);
const CSF_CZ: [(f32, f32); 2] = [(34.1, 0.04), (13.5, 0.025)];
/// The width of the feature detectors \[degrees\].
pub const FEATURE_WIDTH: f32 = 0.082;

/// The 1-D contrast-sensitivity kernels: `y`, `cx`, and the blue–yellow channel's two terms `cz` (added after
/// filtering), each `2 r + 1` weights.
pub struct CsfKernels {
    pub y: Vec<f32>,
    pub cx: Vec<f32>,
    pub cz: [Vec<f32>; 2],
}

impl CsfKernels {
    pub fn new(ppd: f32) -> Self {
        let pi = std::f32::consts::PI;
        let b_max = CSF_Y.1.max(CSF_CX.1).max(CSF_CZ[0].1).max(CSF_CZ[1].1);
        let radius = (3.0 * (b_max / (2.0 * pi * pi)).sqrt() * ppd).ceil() as i32;
        let offsets = || (-radius..=radius).map(|i| i as f32 / ppd);
        // a √(π/b) e^{−π² x²/b}: one axis of a term's 2-D kernel; its square root for a term of a sum.
        let term = |(a, b): (f32, f32), x: f32| a * (pi / b).sqrt() * (-pi * pi * x * x / b).exp();
        let root_term = |(a, b): (f32, f32), x: f32| (a * (pi / b).sqrt()).sqrt() * (-pi * pi * x * x / b).exp();
        let normalised = |k: Vec<f32>, by: f32| k.into_iter().map(|v| v / by).collect::<Vec<f32>>();
        let y: Vec<f32> = offsets().map(|x| term(CSF_Y, x)).collect();
        let cx: Vec<f32> = offsets().map(|x| term(CSF_CX, x)).collect();
        let cz: [Vec<f32>; 2] = CSF_CZ.map(|t| offsets().map(|x| root_term(t, x)).collect());
        // Each term's 2-D sum is its 1-D sum squared: dividing both terms by √(s1² + s2²) makes the pair sum to 1.
        let (s1, s2) = (cz[0].iter().sum::<f32>(), cz[1].iter().sum::<f32>());
        let cz_norm = (s1 * s1 + s2 * s2).sqrt();
        let (sy, scx) = (y.iter().sum::<f32>(), cx.iter().sum::<f32>());
        let [cz0, cz1] = cz;
        Self { y: normalised(y, sy), cx: normalised(cx, scx), cz: [normalised(cz0, cz_norm), normalised(cz1, cz_norm)] }
    }
}

/// The 1-D feature kernels: the Gaussian `g`, its first derivative `dg` and second `ddg`, `2 r + 1` weights each.
pub struct FeatureKernels {
    pub g: Vec<f32>,
    pub dg: Vec<f32>,
    pub ddg: Vec<f32>,
}

impl FeatureKernels {
    pub fn new(ppd: f32) -> Self {
        let sigma = 0.5 * FEATURE_WIDTH * ppd;
        let radius = (3.0 * sigma).ceil() as i32;
        let g: Vec<f32> = (-radius..=radius).map(|i| (-((i * i) as f32) / (2.0 * sigma * sigma)).exp()).collect();
        let offsets = || (-radius..=radius).map(|i| i as f32);
        let dg: Vec<f32> = offsets().zip(&g).map(|(x, g)| -x * g).collect();
        let ddg: Vec<f32> = offsets().zip(&g).map(|(x, g)| (x * x / (sigma * sigma) - 1.0) * g).collect();
        let sum = g.iter().sum::<f32>();
        Self { g: g.iter().map(|v| v / sum).collect(), dg: signed_unit_sums(&dg), ddg: signed_unit_sums(&ddg) }
    }
}

/// The weights scaled so that the positive ones sum to 1 and the negative ones to −1.
fn signed_unit_sums(k: &[f32]) -> Vec<f32> {
    let positive: f32 = k.iter().filter(|&&v| v > 0.0).sum();
    let negative: f32 = -k.iter().filter(|&&v| v <= 0.0).sum::<f32>();
    k.iter().map(|&v| if v > 0.0 { v / positive } else { v / negative }).collect()
}

/// A single-channel image, row-major.
#[derive(Clone, Debug)]
pub struct Plane {
    pub width: usize,
    pub height: usize,
    pub values: Vec<f32>,
}

impl Plane {
    pub fn new(width: usize, height: usize, values: Vec<f32>) -> Self {
        debug_assert_eq!(values.len(), width * height);
        Self { width, height, values }
    }

    /// Convolved along x with `kernel` (odd length, centred), the image's edge pixels repeated beyond it.
    pub fn along_x(&self, kernel: &[f32]) -> Plane {
        let (w, r) = (self.width, (kernel.len() / 2) as i64);
        let mut out = vec![0.0f32; self.values.len()];
        out.par_chunks_mut(w.max(1)).zip(self.values.par_chunks(w.max(1))).for_each(|(dst, src)| {
            for (x, d) in dst.iter_mut().enumerate() {
                let (lo, hi) = (x as i64 - r, x as i64 + r);
                *d = if lo >= 0 && hi < w as i64 {
                    // Away from the edges: a plain dot product, in the taps' order as at the edges.
                    kernel.iter().zip(&src[lo as usize..=hi as usize]).fold(0.0f32, |sum, (k, v)| sum + k * v)
                } else {
                    kernel.iter().enumerate().fold(0.0f32, |sum, (k, weight)| {
                        sum + weight * src[(lo + k as i64).clamp(0, w as i64 - 1) as usize]
                    })
                };
            }
        });
        Plane::new(self.width, self.height, out)
    }

    /// Convolved along y with `kernel`, the edge rows repeated beyond the image.
    pub fn along_y(&self, kernel: &[f32]) -> Plane {
        let (w, h, r) = (self.width, self.height as i64, (kernel.len() / 2) as i64);
        let mut out = vec![0.0f32; self.values.len()];
        out.par_chunks_mut(w.max(1)).enumerate().for_each(|(y, dst)| {
            // Whole rows at a time (the same sums, tap after tap, for every pixel of the row).
            for (k, weight) in kernel.iter().enumerate() {
                let yy = (y as i64 + k as i64 - r).clamp(0, h - 1) as usize;
                for (d, v) in dst.iter_mut().zip(&self.values[yy * w..(yy + 1) * w]) {
                    *d += weight * v;
                }
            }
        });
        Plane::new(self.width, self.height, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csf_kernels_keep_a_uniform_channel() {
        for ppd in [10.0, 67.020_65, 120.0] {
            let k = CsfKernels::new(ppd);
            assert!((k.y.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            assert!((k.cx.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            let (s1, s2) = (k.cz[0].iter().sum::<f32>(), k.cz[1].iter().sum::<f32>());
            assert!((s1 * s1 + s2 * s2 - 1.0).abs() < 1e-5, "{s1} {s2}");
            assert_eq!(k.y.len() % 2, 1);
        }
        // At 67 pixels a degree: radius ⌈3 √(0.04 / 2π²) 67⌉ = 10.
        assert_eq!(CsfKernels::new(67.020_65).y.len(), 21);
    }

    #[test]
    fn feature_kernels_have_unit_signed_sums_and_the_derivatives_shapes() {
        let k = FeatureKernels::new(67.020_65);
        // σ = 0.041 × 67 ≈ 2.75 pixels, radius ⌈3σ⌉ = 9.
        assert_eq!(k.g.len(), 19);
        assert!((k.g.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        for d in [&k.dg, &k.ddg] {
            let pos: f32 = d.iter().filter(|v| **v > 0.0).sum();
            let neg: f32 = d.iter().filter(|v| **v < 0.0).sum();
            assert!((pos - 1.0).abs() < 1e-6 && (neg + 1.0).abs() < 1e-6, "{pos} {neg}");
        }
        // The first derivative is odd (negative ahead of the centre: it responds to a rising step), the second
        // negative at the centre.
        assert_eq!(k.dg[9], 0.0);
        assert!(k.dg[10] < 0.0 && (k.dg[10] + k.dg[8]).abs() < 1e-7);
        assert!(k.ddg[9] < 0.0);
    }

    #[test]
    fn convolution_repeats_the_edge_pixels() {
        let p = Plane::new(3, 2, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let x = p.along_x(&[1.0, 0.0, 0.0]);
        assert_eq!(x.values, vec![1.0, 1.0, 2.0, 4.0, 4.0, 5.0]);
        let y = p.along_y(&[0.0, 0.0, 1.0]);
        assert_eq!(y.values, vec![4.0, 5.0, 6.0, 4.0, 5.0, 6.0]);
    }
}

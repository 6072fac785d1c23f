//! FLIP, NVIDIA's perceptual difference of two images shown alternately (Andersson, Nilsson, Akenine-Möller,
//! Oskarsson, Åström & Fairchild, "FLIP: A Difference Evaluator for Alternating Images", HPG 2020), and HDR-FLIP
//! for images of linear radiance (Andersson, Nilsson, Shirley & Akenine-Möller, Eurographics 2021), with the
//! reference implementation's defaults: 67 pixels per degree (a 0.7 m wide 4K monitor seen from 0.7 m), ACES tone
//! mapping and the exposures it chooses from the reference image. A display-space companion to sunshade's physical
//! metrics: 0 where the two look the same, towards 1 where a viewer flipping between them sees the most.
//!
//! [`colour`] holds the colour spaces, [`filters`] the contrast-sensitivity and feature kernels, `ldr` LDR-FLIP,
//! `hdr` the exposures of HDR-FLIP. Computed in f32 as the reference implementation is (tests/flip.rs checks the
//! means and maps against its values).

pub mod colour;
pub mod filters;
mod hdr;
mod ldr;

use crate::film::Image;

pub use hdr::exposure_range;

/// Pixels per degree of the reference implementation's default viewer: `0.7 m × (3840 px / 0.7 m) × π/180`.
pub const DEFAULT_PPD: f32 = 0.7 * (3840.0 / 0.7) * (std::f32::consts::PI / 180.0);

/// What the images hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlipInput {
    /// Display values: sRGB-encoded, in [0, 1] (a PNG's codes / 255). LDR-FLIP.
    Ldr,
    /// Linear radiance, any scale (EXR, PFM, a render). HDR-FLIP.
    Hdr,
}

/// A FLIP error map and how it was computed.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipMap {
    pub width: u32,
    pub height: u32,
    /// One value in [0, 1] a pixel, row-major.
    pub values: Vec<f32>,
    pub input: FlipInput,
    pub ppd: f32,
    /// HDR-FLIP's exposures \[stops\]: first, last, and how many.
    pub exposures: Option<(f32, f32, usize)>,
}

/// The FLIP map of `test` against `reference` (their RGB; alpha is not read), at `ppd` pixels per degree.
/// `Err` where the sizes differ.
pub fn flip(reference: &Image, test: &Image, input: FlipInput, ppd: f32) -> Result<FlipMap, String> {
    super::same_size(reference, test)?;
    let (w, h) = (reference.width() as usize, reference.height() as usize);
    let rgb = |img: &Image| -> Vec<[f32; 3]> {
        img.pixels()
            .iter()
            .map(|p| {
                let c = [p[0], p[1], p[2]].map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
                match input {
                    FlipInput::Ldr => c.map(colour::srgb_to_linear),
                    FlipInput::Hdr => c,
                }
            })
            .collect()
    };
    let (r, t) = (rgb(reference), rgb(test));
    let (values, exposures) = match input {
        FlipInput::Ldr => (ldr::ldr_flip(w, h, &r, &t, ppd), None),
        FlipInput::Hdr => {
            let (map, range) = hdr::hdr_flip(w, h, &r, &t, ppd);
            (map, Some(range))
        }
    };
    Ok(FlipMap { width: w as u32, height: h as u32, values, input, ppd, exposures })
}

/// A FLIP map's summary: its mean over every pixel (the number FLIP is quoted by), percentiles and maximum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipStats {
    pub mean: f64,
    pub median: f64,
    pub p95: f64,
    pub p99: f64,
    pub max: f64,
    pub input: FlipInput,
    pub ppd: f64,
    pub exposures: Option<(f64, f64, usize)>,
}

impl FlipMap {
    pub fn stats(&self) -> FlipStats {
        let n = self.values.len();
        let mean = if n == 0 { 0.0 } else { self.values.iter().map(|&v| v as f64).sum::<f64>() / n as f64 };
        let mut sorted = self.values.clone();
        sorted.sort_unstable_by(f32::total_cmp);
        // The value below which a share q of the pixels lie (nearest rank).
        let at = |q: f64| if n == 0 { 0.0 } else { sorted[((q * n as f64).ceil() as usize).clamp(1, n) - 1] as f64 };
        FlipStats {
            mean,
            median: at(0.5),
            p95: at(0.95),
            p99: at(0.99),
            max: sorted.last().map_or(0.0, |&v| v as f64),
            input: self.input,
            ppd: self.ppd as f64,
            exposures: self.exposures.map(|(a, b, n)| (a as f64, b as f64, n)),
        }
    }

    /// The map as RGB8 on the magma scale (the reference implementation's), black 0 to pale yellow 1.
    pub fn magma_rgb8(&self) -> Vec<u8> {
        self.values.iter().flat_map(|&v| magma(v)).collect()
    }
}

impl FlipStats {
    /// One line for `diff`'s report.
    pub fn text(&self) -> String {
        let how = match (self.input, self.exposures) {
            (FlipInput::Hdr, Some((a, b, n))) => format!("HDR-FLIP, exposures {a:+.2} to {b:+.2} stops in {n}"),
            _ => "LDR-FLIP".to_string(),
        };
        // Four decimals as FLIP is usually quoted; three digits where that would read 0.
        let v = |x: f64| if x == 0.0 || x >= 1e-3 { format!("{x:.4}") } else { format!("{x:.2e}") };
        format!(
            "FLIP ({how}, {:.0} pixels a degree): mean {}, median {}, 95th percentile {}, 99th {}, max {}",
            self.ppd,
            v(self.mean),
            v(self.median),
            v(self.p95),
            v(self.p99),
            v(self.max)
        )
    }

    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "mean": self.mean, "median": self.median, "p95": self.p95, "p99": self.p99, "max": self.max,
            "kind": match self.input { FlipInput::Ldr => "ldr", FlipInput::Hdr => "hdr" },
            "ppd": self.ppd,
            "exposures": self.exposures.map(|(a, b, n)| serde_json::json!({ "start": a, "stop": b, "count": n })),
        })
    }
}

/// matplotlib's magma (van der Walt & Smith), nine samples interpolated linearly.
fn magma(t: f32) -> [u8; 3] {
    const STOPS: [[f64; 3]; 9] = [
        [0.0, 0.0, 4.0],
        [29.0, 17.0, 71.0],
        [81.0, 18.0, 124.0],
        [131.0, 38.0, 129.0],
        [183.0, 55.0, 121.0],
        [231.0, 81.0, 99.0],
        [252.0, 137.0, 97.0],
        [254.0, 196.0, 136.0],
        [252.0, 253.0, 191.0],
    ];
    super::heatmap::sampled_scale(&STOPS, t as f64)
}

/// Writes `map` as a magma PNG, atomically.
pub fn write_flip_map(path: &std::path::Path, map: &FlipMap) -> std::io::Result<()> {
    let buf = ::image::RgbImage::from_raw(map.width, map.height, map.magma_rgb8()).expect("one pixel a value");
    crate::film::write_atomically(path, |out| {
        ::image::DynamicImage::ImageRgb8(buf).write_to(out, ::image::ImageFormat::Png).map_err(std::io::Error::other)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_viewer_sees_67_pixels_a_degree() {
        assert!((DEFAULT_PPD - 67.020_65).abs() < 1e-3, "{DEFAULT_PPD}");
    }

    #[test]
    fn stats_take_nearest_ranks() {
        let map = FlipMap {
            width: 10,
            height: 10,
            values: (0..100).map(|i| i as f32 / 100.0).collect(),
            input: FlipInput::Ldr,
            ppd: DEFAULT_PPD,
            exposures: None,
        };
        let s = map.stats();
        assert!((s.mean - 0.495).abs() < 1e-9);
        assert_eq!((s.median, s.p95, s.max), (0.49f32 as f64, 0.94f32 as f64, 0.99f32 as f64));
    }

    #[test]
    fn tiny_and_hostile_images_give_values_in_the_unit_interval() {
        for (w, h) in [(1, 1), (1, 7), (5, 1)] {
            let mut a = Image::new(w, h);
            let mut b = Image::new(w, h);
            for (i, (p, q)) in a.pixels_mut().iter_mut().zip(b.pixels_mut()).enumerate() {
                *p = [i as f32, f32::NAN, -1.0, 1.0];
                *q = [f32::INFINITY, 0.5, 1e30, 1.0];
            }
            for input in [FlipInput::Ldr, FlipInput::Hdr] {
                let m = flip(&a, &b, input, DEFAULT_PPD).unwrap();
                assert!(m.values.iter().all(|v| (0.0..=1.0).contains(v)), "{w}x{h} {input:?}: {:?}", m.values);
            }
        }
        assert!(flip(&Image::new(2, 2), &Image::new(2, 3), FlipInput::Hdr, DEFAULT_PPD).is_err());
    }

    #[test]
    fn magma_runs_from_black_to_pale_yellow() {
        assert_eq!(magma(0.0), [0, 0, 4]);
        assert_eq!(magma(1.0), [252, 253, 191]);
        assert_eq!(magma(0.5), [183, 55, 121]);
    }
}

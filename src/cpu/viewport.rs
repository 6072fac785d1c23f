//! Clip space → window coordinates, and snapping to the device's sub-pixel grid.
//!
//! The viewport covers the whole image: `scale = (w/2, h/2, 1)`, `translate = (w/2, h/2, 0)` (depth range [0, 1]).
//! Two formulations exist on the device and the reference reproduces both:
//!
//! - a vertex inside the view volume is mapped by the vertex pipeline's generated code, `(x · (1/w))` followed by
//!   a multiply-add with `scale` and `translate`, which the JIT fuses into one FMA where the CPU has FMA
//!   ([`Viewport::fused`]);
//! - a vertex made by clipping is mapped by C code, `((x · (1/w)) · scale) + translate`, each step rounded.
//!
//! A difference of one ulp in a window coordinate moves its snapped position only when it sits on a rounding
//! boundary of the 1/2^bits grid, so a wrong choice shows up as rare single-pixel coverage differences on edges;
//! the image-diff tests measure it.

use glam::{Vec3, Vec4};

/// The viewport transform of a `width × height` image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    pub scale: [f32; 3],
    pub translate: [f32; 3],
    /// Whether unclipped vertices use a fused multiply-add for `ndc · scale + translate`.
    pub fused: bool,
}

impl Viewport {
    pub fn new(width: u32, height: u32, fused: bool) -> Self {
        let (hw, hh) = (0.5 * width as f32, 0.5 * height as f32);
        Self { scale: [hw, hh, 1.0], translate: [hw, hh, 0.0], fused }
    }

    /// Window coordinates of a vertex inside the view volume.
    pub fn window_from_vertex(&self, clip: Vec4) -> Vec3 {
        let oow = 1.0 / clip.w;
        let map = |c: f32, k: usize| {
            let ndc = c * oow;
            if self.fused {
                ndc.mul_add(self.scale[k], self.translate[k])
            } else {
                ndc * self.scale[k] + self.translate[k]
            }
        };
        Vec3::new(map(clip.x, 0), map(clip.y, 1), map(clip.z, 2))
    }

    /// Window coordinates of a vertex made by clipping.
    pub fn window_from_clipped(&self, clip: Vec4) -> Vec3 {
        let oow = 1.0 / clip.w;
        Vec3::new(
            clip.x * oow * self.scale[0] + self.translate[0],
            clip.y * oow * self.scale[1] + self.translate[1],
            clip.z * oow * self.scale[2] + self.translate[2],
        )
    }
}

/// A window coordinate snapped to the sub-pixel grid, in units of 1/2^bits pixel, measured from the pixel centres
/// (so that pixel `i`'s centre is at `i · 2^bits`).
///
/// As on the device: the half-pixel offset is subtracted in f32 first (exact for coordinates ≥ 0.25 px), the
/// product with 2^bits is exact, and the rounding is to nearest, ties to even.
pub fn snap(window: f32, bits: u32) -> i64 {
    let scaled = (window - 0.5) * (1u64 << bits) as f32;
    scaled.round_ties_even() as i64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snapping_rounds_half_to_even_about_pixel_centres() {
        assert_eq!(snap(0.5, 8), 0);
        assert_eq!(snap(10.5, 8), 10 * 256);
        assert_eq!(snap(0.5 + 1.0 / 512.0, 8), 0, "half a step rounds to even (0)");
        assert_eq!(snap(0.5 + 3.0 / 512.0, 8), 2, "1.5 steps rounds to even (2)");
        assert_eq!(snap(0.0, 8), -128);
        assert_eq!(snap(0.5, 4), 0);
        assert_eq!(snap(1.0, 4), 8);
    }

    #[test]
    fn viewport_maps_ndc_corners_to_image_corners() {
        let vp = Viewport::new(640, 480, true);
        let tl = vp.window_from_vertex(Vec4::new(-2.0, -2.0, 0.0, 2.0));
        let br = vp.window_from_clipped(Vec4::new(2.0, 2.0, 2.0, 2.0));
        assert_eq!(tl, Vec3::new(0.0, 0.0, 0.0));
        assert_eq!(br, Vec3::new(640.0, 480.0, 1.0));
    }
}

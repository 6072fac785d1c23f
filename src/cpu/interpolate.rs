//! Interpolation across a triangle at a pixel centre, in f64.
//!
//! Depth `z/w` is linear in window space; every other attribute is interpolated perspective-correctly: with
//! screen-space barycentrics `λᵢ` and clip-space `wᵢ`, the weights are `μᵢ = (λᵢ/wᵢ) / Σⱼ(λⱼ/wⱼ)` (e.g. PBR 4th ed.
//! or the Vulkan spec's "Triangle interpolation"). The device evaluates the same quantities through f32 plane
//! equations built from the unsnapped window positions, which is why those positions (not the snapped ones)
//! are used here: at 1/256 pixel, snapping would shift a smoothly varying normal by up to 1e-5 relative.

use glam::Vec3;

/// Interpolation set-up for one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interpolator {
    x: [f64; 3],
    y: [f64; 3],
    z: [f64; 3],
    inv_w: [f64; 3],
    inv_area: f64,
}

impl Interpolator {
    /// From window positions (pixels, depth) and clip-space `w` of the three vertices. `None` for a zero area.
    pub fn new(window: [Vec3; 3], clip_w: [f32; 3]) -> Option<Self> {
        let x = window.map(|v| v.x as f64);
        let y = window.map(|v| v.y as f64);
        let area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
        if area == 0.0 || !area.is_finite() {
            return None;
        }
        Some(Self { x, y, z: window.map(|v| v.z as f64), inv_w: clip_w.map(|w| 1.0 / w as f64), inv_area: 1.0 / area })
    }

    /// Screen-space barycentrics of the centre of pixel `(px, py)`.
    pub fn barycentrics(&self, px: u32, py: u32) -> [f64; 3] {
        let (sx, sy) = (px as f64 + 0.5, py as f64 + 0.5);
        let (x, y) = (&self.x, &self.y);
        let l0 = ((x[1] - sx) * (y[2] - sy) - (x[2] - sx) * (y[1] - sy)) * self.inv_area;
        let l1 = ((x[2] - sx) * (y[0] - sy) - (x[0] - sx) * (y[2] - sy)) * self.inv_area;
        [l0, l1, 1.0 - l0 - l1]
    }

    /// Window depth at the barycentrics.
    pub fn depth(&self, l: &[f64; 3]) -> f64 {
        l[0] * self.z[0] + l[1] * self.z[1] + l[2] * self.z[2]
    }

    /// Perspective-correct weights at the barycentrics (they sum to 1).
    pub fn perspective_weights(&self, l: &[f64; 3]) -> [f64; 3] {
        let m = [l[0] * self.inv_w[0], l[1] * self.inv_w[1], l[2] * self.inv_w[2]];
        let s = m[0] + m[1] + m[2];
        [m[0] / s, m[1] / s, m[2] / s]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentrics_reproduce_vertices_and_centroid() {
        let it = Interpolator::new(
            [Vec3::new(0.5, 0.5, 0.25), Vec3::new(10.5, 0.5, 0.5), Vec3::new(0.5, 20.5, 0.75)],
            [1.0, 1.0, 1.0],
        )
        .unwrap();
        assert_eq!(it.barycentrics(0, 0), [1.0, 0.0, 0.0]);
        let l = it.barycentrics(10, 0);
        assert!((l[1] - 1.0).abs() < 1e-15 && l[0].abs() < 1e-15);
        let l = it.barycentrics(5, 10);
        // Centre (5.5, 10.5) is half way along both edges from vertex 0: λ = (0, ½, ½).
        assert!((it.depth(&l) - (0.5 * 0.5 + 0.5 * 0.75)).abs() < 1e-15);
    }

    #[test]
    fn perspective_weights_favour_near_vertices() {
        let it = Interpolator::new(
            [Vec3::new(0.0, 0.0, 0.0), Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 4.0, 0.0)],
            [1.0, 3.0, 1.0],
        )
        .unwrap();
        // Half way along the edge 0–1 on screen, the far vertex (w = 3) weighs 1/4, not 1/2.
        let l = [0.5, 0.5, 0.0];
        let m = it.perspective_weights(&l);
        assert!((m[0] - 0.75).abs() < 1e-15 && (m[1] - 0.25).abs() < 1e-15 && m[2] == 0.0);
    }
}

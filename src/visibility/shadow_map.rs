//! The sun's shadow map: an orthographic depth map along the sun's direction, fitted to the scene's bounds (every
//! triangle can cast and receive), with square texels. The GPU renders it (`gpu::shadow_map`) and looks it up in
//! `shaders/shadow_map.glsl`; this is the frame both use, in f64, rounded once to f32.
//!
//! Light space: `x = orthonormal_to(l)`, `y = l × x` (the same basis as the sun's sample grid in
//! `shading::visibility`, so that a sample's offset on the sun's disk is the same offset in the map), and depth
//! measured from the sun, `d = l_max − l·p` [m]. Map coordinates: `u = (x·p − cx)/h`, `v = (y·p − cy)/h` in
//! [−1, 1] (h the larger half-extent, padded by two texels), depth `z = d / depth_extent` in [0, 1].

use glam::{DMat4, DVec3, DVec4};

use crate::scene::Aabb;
use crate::shading::orthonormal_to;

/// An orthographic map along the sun.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunMapFrame {
    /// World → map clip space (x, y in [−1, 1], depth in [0, 1]).
    pub map_from_world: DMat4,
    /// The side of one texel [m].
    pub texel: f64,
    /// The depth range [m] that [0, 1] covers.
    pub depth_extent: f64,
}

/// The map for the sun towards `l` (unit) over `bounds`, `size` texels a side.
pub fn fit_sun_map(bounds: Aabb, l: DVec3, size: u32) -> SunMapFrame {
    let x = orthonormal_to(l);
    let y = l.cross(x);
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for i in 0..8 {
        let c = DVec3::new(
            if i & 1 == 0 { bounds.min.x } else { bounds.max.x },
            if i & 2 == 0 { bounds.min.y } else { bounds.max.y },
            if i & 4 == 0 { bounds.min.z } else { bounds.max.z },
        );
        let q = DVec3::new(x.dot(c), y.dot(c), l.dot(c));
        lo = lo.min(q);
        hi = hi.max(q);
    }
    let center = (lo + hi) * 0.5;
    let half = (hi - lo) * 0.5;
    // Two texels of margin on each side, so that lookups near the bounds stay inside; a flat scene still gets a
    // finite map.
    let n = size.max(1) as f64;
    let h0 = half.x.max(half.y).max(1e-30);
    let h = h0 * n / (n - 4.0).max(1.0);
    let depth_extent = (2.0 * half.z).max(h * 1e-6) * (1.0 + 1e-3);
    let l_max = hi.z + depth_extent * 5e-4;
    let map_from_world = DMat4::from_cols(
        DVec4::new(x.x / h, y.x / h, -l.x / depth_extent, 0.0),
        DVec4::new(x.y / h, y.y / h, -l.y / depth_extent, 0.0),
        DVec4::new(x.z / h, y.z / h, -l.z / depth_extent, 0.0),
        DVec4::new(-center.x / h, -center.y / h, l_max / depth_extent, 1.0),
    );
    SunMapFrame { map_from_world, texel: 2.0 * h / n, depth_extent }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bounds_fit_inside_the_map_and_depth_grows_away_from_the_sun() {
        let bounds = Aabb { min: DVec3::new(-1.0, 0.0, -2.0), max: DVec3::new(3.0, 1.5, 2.0) };
        let l = DVec3::new(0.3, 1.0, 0.5).normalize();
        let f = fit_sun_map(bounds, l, 1024);
        for i in 0..8 {
            let c = DVec3::new(
                if i & 1 == 0 { -1.0 } else { 3.0 },
                if i & 2 == 0 { 0.0 } else { 1.5 },
                if i & 4 == 0 { -2.0 } else { 2.0 },
            );
            let q = f.map_from_world.project_point3(c);
            assert!(q.x.abs() < 1.0 && q.y.abs() < 1.0 && (0.0..=1.0).contains(&q.z), "{c} -> {q}");
        }
        let near = f.map_from_world.project_point3(DVec3::new(1.0, 0.75, 0.0) + l);
        let far = f.map_from_world.project_point3(DVec3::new(1.0, 0.75, 0.0) - l);
        assert!(near.z < far.z);
        assert!((((far.z - near.z) * f.depth_extent) - 2.0).abs() < 1e-9);
        // One texel in world units: a step of `texel` along x moves u by 2/size.
        let a = f.map_from_world.project_point3(DVec3::ZERO);
        let b = f.map_from_world.project_point3(orthonormal_to(l) * f.texel);
        assert!(((b.x - a.x) - 2.0 / 1024.0).abs() < 1e-12);
    }
}

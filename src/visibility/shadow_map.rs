//! The sun's shadow map: an orthographic depth map along the sun's direction, fitted to the scene's bounds (every
//! triangle can cast and receive), with square texels. The GPU renders it (`gpu::shadow_map`) and looks it up in
//! `shaders/shadow_map.glsl`; this is the frame both use, in f64, rounded once to f32.
//!
//! Light space: `x = orthonormal_to(l)`, `y = l × x` (the same basis as the sun's sample grid in
//! `shading::visibility`, so that a sample's offset on the sun's disk is the same offset in the map), and depth
//! measured from the sun, `d = l_max − l·p` \[m\]. Map coordinates: `u = (x·p − cx)/h`, `v = (y·p − cy)/h` in
//! [−1, 1] (h the larger half-extent, padded by two texels), depth `z = d / depth_extent` in [0, 1].

use glam::{DMat4, DVec3, DVec4};

use crate::scene::Aabb;
use crate::shading::orthonormal_to;

/// An orthographic map along the sun.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunMapFrame {
    /// World → map clip space (x, y in [−1, 1], depth in [0, 1]).
    pub map_from_world: DMat4,
    /// The side of one texel \[m\].
    pub texel: f64,
    /// The depth range \[m\] that [0, 1] covers.
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

    #[test]
    fn a_disk_map_sees_what_lies_in_front_of_the_disk() {
        // A disk at 2.5 m facing down over a 4 m room: the floor's corners project inside the map, with depth
        // growing away from the disk; linear depth is recovered from the stored one.
        let bounds = Aabb { min: DVec3::new(-2.0, 0.0, -2.0), max: DVec3::new(2.0, 2.5, 2.0) };
        let (c, d) = (DVec3::new(0.0, 2.5, 0.0), -DVec3::Y);
        let f = fit_disk_map(bounds, c, d).unwrap();
        for p in [DVec3::new(-2.0, 0.0, -2.0), DVec3::new(2.0, 0.0, 1.0), DVec3::new(0.3, 1.0, -0.2)] {
            let q = f.map_from_world.project_point3(p);
            assert!(q.x.abs() <= 1.0 && q.y.abs() <= 1.0 && (0.0..=1.0).contains(&q.z), "{p} -> {q}");
            let z = f.far * f.near / (f.far - q.z * (f.far - f.near));
            assert!((z - (2.5 - p.y)).abs() < 1e-9, "{p}: linear depth {z}");
        }
        assert!(fit_disk_map(bounds, DVec3::new(0.0, -1.0, 0.0), -DVec3::Y).is_none());
    }
}

/// A disk light's perspective shadow map: from the disk's centre, looking along its emission direction `d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskMapFrame {
    /// World → map clip space (perspective; depth in [0, 1] between `near` and `far`).
    pub map_from_world: DMat4,
    /// Tangent of the half field of view (both axes).
    pub tan_half: f64,
    /// Near and far planes \[m\] along `d`.
    pub near: f64,
    pub far: f64,
}

/// The widest half field of view a disk's map takes: 80° (what lies farther from the axis is unoccluded).
pub const DISK_MAP_MAX_HALF_ANGLE_DEGREES: f64 = 80.0;

/// The map of a disk light centred at `center` emitting along the unit `d`, over `bounds`: view axes
/// `x = orthonormal_to(d)`, `y = d × x`, depth `z = d·(p − center)`; the field of view fitted to the bounds'
/// corners in front of the disk (capped at [`DISK_MAP_MAX_HALF_ANGLE_DEGREES`]), near `10⁻⁴` of the bounds'
/// diagonal, far past the farthest corner. `None` when nothing of the bounds lies in front of the disk.
pub fn fit_disk_map(bounds: Aabb, center: DVec3, d: DVec3) -> Option<DiskMapFrame> {
    let x = orthonormal_to(d);
    let y = d.cross(x);
    let diagonal = (bounds.max - bounds.min).length().max(1e-30);
    let near = 1e-4 * diagonal;
    let (mut far, mut tan_half) = (0.0f64, 0.0f64);
    for i in 0..8 {
        let c = DVec3::new(
            if i & 1 == 0 { bounds.min.x } else { bounds.max.x },
            if i & 2 == 0 { bounds.min.y } else { bounds.max.y },
            if i & 4 == 0 { bounds.min.z } else { bounds.max.z },
        ) - center;
        let z = d.dot(c);
        far = far.max(z);
        if z > near {
            tan_half = tan_half.max(x.dot(c).abs() / z).max(y.dot(c).abs() / z);
        }
    }
    if far <= near {
        return None;
    }
    let tan_half = (tan_half * 1.01).clamp(1e-3, DISK_MAP_MAX_HALF_ANGLE_DEGREES.to_radians().tan());
    let far = far * 1.01 + near;
    // Vulkan perspective: x, y over z tan_half; depth (f (z − n)) / (z (f − n)) in [0, 1].
    let (a, b) = (far / (far - near), -far * near / (far - near));
    // Rows of the matrix acting on (p, 1): clip = (x·(p − c)/tan, y·(p − c)/tan, a z + b, z), z = d·(p − c).
    let rows = [x / tan_half, y / tan_half, d * a, d];
    let offsets = [-rows[0].dot(center), -rows[1].dot(center), -rows[2].dot(center) + b, -rows[3].dot(center)];
    let column = |k: usize| DVec4::new(rows[0][k], rows[1][k], rows[2][k], rows[3][k]);
    let m = DMat4::from_cols(column(0), column(1), column(2), DVec4::from_array(offsets));
    Some(DiskMapFrame { map_from_world: m, tan_half, near, far })
}

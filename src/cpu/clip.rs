//! Clipping against the view volume, as Mesa's draw module (which lavapipe uses) does it, in f32.
//!
//! Vulkan's view volume is `−w ≤ x ≤ w`, `−w ≤ y ≤ w`, `0 ≤ z ≤ w`. The device clips in x and y as well as in z
//! (llvmpipe uses no guard band), so the reference must too: a vertex made by clipping has window coordinates
//! computed from interpolated clip coordinates, and snapping them reproduces the device's coverage only if the
//! arithmetic is the same. The rules, in order:
//!
//! 1. Each vertex gets a mask bit per plane it is strictly outside of. A triangle with no bits is not clipped; one
//!    whose three vertices share a bit is discarded whole.
//! 2. Otherwise the polygon is clipped (Sutherland–Hodgman) against the planes in its mask, in plane order:
//!    `x ≤ w`, `x ≥ −w`, `y ≤ w`, `y ≥ −w`, `z ≥ 0`, `z ≤ w`. The signed distance to a plane is the dot product
//!    of the clip position with the plane's coefficients, summed left to right in f32.
//! 3. A new vertex between an outside vertex `out` and an inside one `in` lies at `t = dp_out / (dp_out − dp_in)`;
//!    every clip coordinate and attribute is `out + t·(in − out)` in f32 (clip-space interpolation is the
//!    perspective-correct one). Its window position is `((clip · (1/w)) · scale) + translate`, unfused.
//! 4. The clipped polygon is emitted as a fan `(v0, v[i−1], v[i])`, skipping triangles of zero area.

use glam::{Vec3, Vec4};

use super::viewport::Viewport;

/// Number of f32 attributes carried per vertex: world position (3), normal (3), tangent (3) and handedness (1),
/// TEXCOORD_0 (2), TEXCOORD_1 (2), COLOR_0 (4) (the layout of `gpu::layout::Vertex`).
pub const ATTRIBUTES: usize = 18;

/// A vertex after the vertex shader.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex {
    /// Clip-space position.
    pub clip: Vec4,
    /// Window coordinates (x, y in pixels, z depth), set for vertices inside the volume or made by clipping.
    pub window: Vec3,
    pub attributes: [f32; ATTRIBUTES],
}

/// The planes, as coefficients on (x, y, z, w): inside where the dot product is ≥ 0.
const PLANES: [[f32; 4]; 6] = [
    [-1.0, 0.0, 0.0, 1.0],
    [1.0, 0.0, 0.0, 1.0],
    [0.0, -1.0, 0.0, 1.0],
    [0.0, 1.0, 0.0, 1.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, -1.0, 1.0],
];

/// Mask of the planes a clip position is strictly outside of, computed as the device does (comparisons on the
/// coordinates, with `x + w` and `y + w` rounded in f32).
pub fn clip_mask(c: Vec4) -> u32 {
    let mut mask = 0;
    if c.x > c.w {
        mask |= 1;
    }
    if 0.0 > c.x + c.w {
        mask |= 2;
    }
    if c.y > c.w {
        mask |= 4;
    }
    if 0.0 > c.y + c.w {
        mask |= 8;
    }
    if 0.0 > c.z {
        mask |= 16;
    }
    if c.z > c.w {
        mask |= 32;
    }
    mask
}

/// Signed distance of a clip position to plane `i`, summed left to right in f32.
fn plane_distance(c: Vec4, i: usize) -> f32 {
    let p = PLANES[i];
    c.x * p[0] + c.y * p[1] + c.z * p[2] + c.w * p[3]
}

/// `out + t·(in − out)` in f32, unfused.
fn lerp(t: f32, out: f32, inside: f32) -> f32 {
    out + t * (inside - out)
}

fn interpolate(t: f32, out: &ClipVertex, inside: &ClipVertex, viewport: &Viewport) -> ClipVertex {
    let clip = Vec4::new(
        lerp(t, out.clip.x, inside.clip.x),
        lerp(t, out.clip.y, inside.clip.y),
        lerp(t, out.clip.z, inside.clip.z),
        lerp(t, out.clip.w, inside.clip.w),
    );
    let mut attributes = [0.0; ATTRIBUTES];
    for (k, a) in attributes.iter_mut().enumerate() {
        *a = lerp(t, out.attributes[k], inside.attributes[k]);
    }
    ClipVertex { clip, window: viewport.window_from_clipped(clip), attributes }
}

/// Whether a triangle has zero area in window space (the device's null-triangle test, in f32).
fn is_null(v: [&ClipVertex; 3]) -> bool {
    let (a, b, c) = (v[0].window, v[1].window, v[2].window);
    let (x1, y1, z1) = (b.x - a.x, b.y - a.y, b.z - a.z);
    let (x2, y2, z2) = (c.x - a.x, c.y - a.y, c.z - a.z);
    let vx = y1 * z2 - z1 * y2;
    let vy = x1 * z2 - z1 * x2;
    let vz = x1 * y2 - y1 * x2;
    vx * vx + vy * vy + vz * vz == 0.0
}

/// Clips one triangle (vertices with `window` set where the mask is 0) and calls `emit` for every resulting
/// triangle, in the device's order.
pub fn clip_triangle(tri: [ClipVertex; 3], viewport: &Viewport, mut emit: impl FnMut([ClipVertex; 3])) {
    let masks = tri.map(|v| clip_mask(v.clip));
    let any = masks[0] | masks[1] | masks[2];
    if any == 0 {
        emit(tri);
        return;
    }
    if masks[0] & masks[1] & masks[2] != 0 {
        return;
    }
    let mut poly: Vec<ClipVertex> = tri.to_vec();
    let mut remaining = any;
    while remaining != 0 && poly.len() >= 3 {
        let plane = remaining.trailing_zeros() as usize;
        remaining &= !(1 << plane);
        let mut out = Vec::with_capacity(poly.len() + 1);
        let mut prev = poly[0];
        let mut dp_prev = plane_distance(prev.clip, plane);
        if !dp_prev.is_finite() {
            return;
        }
        // Walk the closed polygon: vertices 1..n, then vertex 0 again.
        for i in 1..=poly.len() {
            let vert = poly[i % poly.len()];
            let dp = plane_distance(vert.clip, plane);
            if !dp.is_finite() {
                return;
            }
            if dp_prev >= 0.0 {
                out.push(prev);
            }
            // The device's "different signs": the product is ≤ 0 and the two differ.
            if dp * dp_prev <= 0.0 && dp - dp_prev != 0.0 {
                if dp < 0.0 {
                    // Going out: `vert` is outside.
                    let t = dp / (dp - dp_prev);
                    out.push(interpolate(t, &vert, &prev, viewport));
                } else {
                    // Coming back in: `prev` is outside.
                    let t = dp_prev / (dp_prev - dp);
                    out.push(interpolate(t, &prev, &vert, viewport));
                }
            }
            prev = vert;
            dp_prev = dp;
        }
        poly = out;
    }
    if poly.len() < 3 {
        return;
    }
    // Fan from vertex 0; a run of zero-area triangles is skipped as the device skips it.
    let (mut last_was_null, mut any_not_null) = (false, false);
    for i in 2..poly.len() {
        let t = [poly[0], poly[i - 1], poly[i]];
        let null = is_null([&t[0], &t[1], &t[2]]);
        if null && (any_not_null || last_was_null) {
            last_was_null = null;
            continue;
        }
        last_was_null = null;
        if !null {
            any_not_null = true;
        }
        emit(t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(clip: Vec4, viewport: &Viewport) -> ClipVertex {
        let window = if clip_mask(clip) == 0 { viewport.window_from_vertex(clip) } else { Vec3::NAN };
        ClipVertex {
            clip,
            window,
            attributes: [
                clip.x, clip.y, clip.z, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0,
            ],
        }
    }

    fn collect(tri: [ClipVertex; 3], vp: &Viewport) -> Vec<[ClipVertex; 3]> {
        let mut out = Vec::new();
        clip_triangle(tri, vp, |t| out.push(t));
        out
    }

    #[test]
    fn inside_triangles_pass_unchanged_and_outside_ones_vanish() {
        let vp = Viewport::new(100, 100, false);
        let tri = [Vec4::new(-0.5, -0.5, 0.5, 1.0), Vec4::new(0.5, -0.5, 0.5, 1.0), Vec4::new(0.0, 0.5, 0.5, 1.0)];
        let t = tri.map(|c| vertex(c, &vp));
        assert_eq!(collect(t, &vp), vec![t]);
        let outside = tri.map(|c| vertex(c + Vec4::new(3.0, 0.0, 0.0, 0.0), &vp));
        assert!(collect(outside, &vp).is_empty());
    }

    #[test]
    fn near_plane_cut_makes_a_quad_with_vertices_on_the_plane() {
        let vp = Viewport::new(64, 64, false);
        // One vertex behind the near plane (z < 0).
        let tri = [Vec4::new(-0.5, -0.5, 0.5, 1.0), Vec4::new(0.5, -0.5, 0.5, 1.0), Vec4::new(0.0, 0.5, -0.5, 1.0)];
        let out = collect(tri.map(|c| vertex(c, &vp)), &vp);
        assert_eq!(out.len(), 2, "a triangle cut at one corner becomes a quad: two triangles");
        for t in &out {
            for v in t {
                assert!(v.clip.z >= 0.0, "{:?}", v.clip);
                assert!(v.window.is_finite());
            }
        }
        // The new vertices lie on z = 0 and carry interpolated attributes.
        let new: Vec<_> = out.iter().flatten().filter(|v| v.clip.z == 0.0).collect();
        assert!(new.len() >= 2);
        for v in new {
            assert_eq!(v.attributes[0], v.clip.x);
        }
    }

    #[test]
    fn masks_follow_plane_order() {
        assert_eq!(clip_mask(Vec4::new(2.0, 0.0, 0.5, 1.0)), 1);
        assert_eq!(clip_mask(Vec4::new(-2.0, 0.0, 0.5, 1.0)), 2);
        assert_eq!(clip_mask(Vec4::new(0.0, 2.0, 0.5, 1.0)), 4);
        assert_eq!(clip_mask(Vec4::new(0.0, -2.0, 0.5, 1.0)), 8);
        assert_eq!(clip_mask(Vec4::new(0.0, 0.0, -0.1, 1.0)), 16);
        assert_eq!(clip_mask(Vec4::new(0.0, 0.0, 1.1, 1.0)), 32);
        // On a plane is inside.
        assert_eq!(clip_mask(Vec4::new(1.0, -1.0, 0.0, 1.0)), 0);
    }
}

//! The reference's occluders: every triangle of the scene in a BVH, and for the triangles of alpha-masked
//! materials what it takes to test their alpha where a shadow ray meets them, so that light passes where the
//! mask cuts the surface away, as it does for the camera. Mirrored on the GPU by `occluded` in
//! shaders/visibility.glsl (with `masked_hit_blocks`).
//!
//! The alpha at a hit is the base colour's (factor × texture × vertex colour) at the hit's barycentrics, the
//! texture read from level 0 with its magnification filter: a shadow ray has no pixel footprint.

use glam::DVec3;

use crate::scene::{AlphaMode, Scene};
use crate::shading::surface::{masked_hit_blocks, SurfaceSample};
use crate::shading::visibility::SliceReach;
use crate::shading::{Occlusion, ShadowedLights, Shadowing};
use crate::visibility::{occluder_bvh, Bvh, WatertightRay};

use super::cone_occluders::{ConeOccluders, LISTED_AT_MOST};

/// A masked triangle's material, corners [m], texture coordinates per set, and vertex alphas (if the mesh has
/// colours).
struct MaskedTriangle {
    material: usize,
    corners: [DVec3; 3],
    uv: [[[f32; 2]; 3]; 2],
    alpha: Option<[f32; 3]>,
}

/// The scene's triangles as occluders.
pub struct Occluders<'a> {
    pub bvh: Bvh,
    /// Per BVH triangle (the scene's order), the masked ones' data.
    masked: Vec<Option<MaskedTriangle>>,
    scene: &'a Scene,
}

impl<'a> Occluders<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        let masked = if !scene.has_alpha_masks() {
            Vec::new()
        } else {
            scene
                .meshes
                .iter()
                .flat_map(|m| {
                    let masked = matches!(scene.materials[m.material].alpha, AlphaMode::Mask(_));
                    m.indices.chunks_exact(3).map(move |t| {
                        masked.then(|| {
                            let at = |set: usize, k: usize| {
                                m.tex_coords[set].get(t[k] as usize).copied().unwrap_or([0.0; 2])
                            };
                            MaskedTriangle {
                                material: m.material,
                                corners: [0, 1, 2].map(|k| m.positions[t[k] as usize].as_dvec3()),
                                uv: [0, 1].map(|set| [0, 1, 2].map(|k| at(set, k))),
                                alpha: (!m.colors.is_empty()).then(|| [0, 1, 2].map(|k| m.colors[t[k] as usize][3])),
                            }
                        })
                    })
                })
                .collect()
        };
        Self { bvh: occluder_bvh(scene), masked, scene }
    }

    /// Whether triangle `i`, met by the ray at `t`, blocks it, and how near its alpha is to the cutoff (infinity
    /// for an unmasked triangle).
    pub fn blocks(&self, i: usize, origin: DVec3, direction: DVec3, t: f64) -> (bool, f64) {
        self.blocks_at(i, origin + t * direction)
    }

    /// [`Occluders::blocks`], and whether the decision is fragile: an alpha-masked triangle whose decision differs
    /// at one of four points `eps` \[m\] off the hit along two orthogonal directions of its plane (so that a straight
    /// contour within `eps/√2` of the hit is always found), or
    /// whose alpha lies within [`super::FRAGILE_TEXTURE_RELATIVE`] of the cutoff. The GPU finds its hit with f32
    /// rays and barycentrics: where the mask's alpha is steep in the triangle's plane (a sharp mask over many
    /// texels), a hit moved by the rounding of its point changes the alpha by far more than its own rounding, and
    /// the grid's bisections place rays on the mask's contour, where that decides.
    pub fn blocks_near(&self, i: usize, origin: DVec3, direction: DVec3, t: f64, eps: f64) -> (bool, bool) {
        let p = origin + t * direction;
        let (blocks, margin) = self.blocks_at(i, p);
        let Some(Some(m)) = self.masked.get(i) else { return (blocks, false) };
        if margin < super::FRAGILE_TEXTURE_RELATIVE {
            return (blocks, true);
        }
        let [a, b, c] = m.corners;
        let (Some(e1), Some(n)) = ((b - a).try_normalize(), (b - a).cross(c - a).try_normalize()) else {
            return (blocks, false);
        };
        let e2 = n.cross(e1);
        let near = [e1, -e1, e2, -e2].iter().any(|&e| self.blocks_at(i, p + eps * e).0 != blocks);
        (blocks, near)
    }

    /// Whether triangle `i` blocks a ray that meets its plane at `p` \[m\] (an unmasked one always), and how near
    /// its alpha is to the cutoff there.
    fn blocks_at(&self, i: usize, p: DVec3) -> (bool, f64) {
        let Some(Some(m)) = self.masked.get(i) else { return (true, f64::INFINITY) };
        let material = &self.scene.materials[m.material];
        let [a, b, c] = m.corners;
        // Barycentrics of the hit by signed areas (f64), normalised by the triangle's.
        let n = (b - a).cross(c - a);
        let n2 = n.length_squared();
        if n2 == 0.0 || !n2.is_finite() {
            return (true, f64::INFINITY);
        }
        let wa = (b - p).cross(c - p).dot(n) / n2;
        let wb = (c - p).cross(a - p).dot(n) / n2;
        let w = [wa, wb, 1.0 - wa - wb];
        let interpolate = |v: [f32; 3]| w[0] * v[0] as f64 + w[1] * v[1] as f64 + w[2] * v[2] as f64;
        let uv = [0, 1].map(|set| [0, 1].map(|c| interpolate([0, 1, 2].map(|k| m.uv[set][k][c]))));
        let color = m.alpha.map(|a| [1.0, 1.0, 1.0, interpolate(a) as f32]);
        masked_hit_blocks(material, &self.scene.textures, &SurfaceSample { uv, uv_x: uv, uv_y: uv, color })
    }
}

impl Occlusion for Occluders<'_> {
    fn occluded(&self, origin: DVec3, direction: DVec3, t_max: f64) -> bool {
        let Some(ray) = WatertightRay::new(origin, direction) else { return false };
        if self.masked.is_empty() {
            return self.bvh.any_hit(&ray, 0.0, t_max);
        }
        self.bvh.any_hit_where(&ray, 0.0, t_max, |i, t| self.blocks(i, origin, direction, t).0)
    }

    /// The slices need opaque triangles: with an alpha-masked occluder the reference casts rays instead.
    fn slice_triangles(&self, reach: &SliceReach, visit: &mut dyn FnMut([DVec3; 3])) -> bool {
        self.masked.is_empty() && self.bvh.slice_triangles(reach, visit)
    }

    /// The triangles within reach (`cpu::cone_occluders`), where the occluders are opaque and they are few.
    fn narrowed(&self, reach: &SliceReach) -> Option<Box<dyn Occlusion + '_>> {
        if !self.masked.is_empty() {
            return None;
        }
        let found = self.bvh.within_reach_at_most(reach, LISTED_AT_MOST)?;
        let triangles = found.into_iter().map(|i| self.bvh.triangle(i)).collect();
        Some(Box::new(ConeOccluders { reach: *reach, triangles, whole: self }))
    }
}

/// The shadow rays `cast` sends from `origin` through `occluders` with the located grid of `samples_per_axis`
/// (every light shadowed, no slices): what the GPU's visibility costs (`sun_costs`, `disk_costs`).
pub(super) fn count_rays(
    occluders: &Occluders,
    origin: DVec3,
    samples_per_axis: u32,
    cast: impl FnOnce(&Shadowing),
) -> u64 {
    let counting = Counting { inner: occluders, rays: std::sync::atomic::AtomicU64::new(0) };
    cast(&Shadowing { origin, occluders: &counting, samples_per_axis, lights: ShadowedLights::ALL, slices: false });
    counting.rays.into_inner()
}

/// Occluders that count the rays they are asked about.
struct Counting<'a> {
    inner: &'a Occluders<'a>,
    rays: std::sync::atomic::AtomicU64,
}

impl Occlusion for Counting<'_> {
    fn occluded(&self, origin: DVec3, direction: DVec3, t_max: f64) -> bool {
        self.rays.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.inner.occluded(origin, direction, t_max)
    }
}

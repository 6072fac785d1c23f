//! A disk light's shadow rays proven clear before one is cast: a walk of the occluders' BVH with the cone from the
//! ray origin to the disk. Where every node and triangle it meets is shown apart from the rays, every ray of the
//! light's grid and lobe gets through, so the visible fraction is exactly 1 (the grid's sums would be the same
//! additions) and the pixel casts none. Only where the walk meets triangles it cannot show apart (a penumbra, an
//! umbra, or a triangle close to the rays) does the grid cast its rays, and where those are few
//! ([`DISK_CONE_LISTED`]) and the shader walks the BVH for its rays (no ray queries), the rays test them alone:
//! every other triangle misses every ray. The GPU runs the walk on every device with shadow rays
//! (shaders/disk_cone.glsl mirrors this file name for name); the reference casts its f64 rays regardless, an
//! independent computation of the same fractions.
//!
//! **Where the rays go.** A disk light of centre `c`, unit emission direction `d` and radius `R` is sampled at
//! points `y` of its disk; a ray runs from the origin `o` (in front of the disk: `h = d·(o − c) > 0`) towards
//! `y` and is tested for `0 < t < SEGMENT_T_MAX` of the way. Every such ray
//! 1. lies in the cone of half-angle σ about the axis `a = (c − o)/D`, `D = |c − o|`, with `sin σ = R/D`: the disk
//!    lies in the ball of radius `R` about `c`, which from `o` subtends that cone (only where `D > R`);
//! 2. stays in front of the disk's plane: `d·(p − c)` falls linearly from `h` at `o` to 0 at `y`, so every point
//!    the ray tests has `d·(p − c) > 0`;
//! 3. stays in the box of `o` and the disk: along a unit axis `e` the disk spans `c·e ± R √(1 − (d·e)²)`;
//! 4. and is cast only where its sample weighs something, which holds `n·(y − x) > 0` (the grid's samples and the
//!    lobe's are weighed from the shading point `x` with its normal `n`; the ray starts at `o`, moved off `x`):
//!    along the ray `n·(p − x)` runs linearly from `δ = n·(o − x)` at `t = 0` to `n·(y − x)` at `t = 1`, which is
//!    positive and at least `g = n·(c − x) − R |n − (n·d) d|` (the disk's lowest point above the tangent plane at
//!    `x`). A point within `r` of `o` is reached at `t ≤ τ = min(1, r/(D − R))` (`|y − o| ≥ D − R`), where the ray
//!    is at least `f(r) = δ` if `δ ≤ g⁺`, else `(1 − τ) δ + τ g⁺` (`g⁺ = max(g, 0)`): an object within `r` of the
//!    origin lying wholly at or below `f(r)` above the tangent plane at `x` is not met. Near the origin that is the
//!    tangent plane through the origin (the ray starts there); far from it, through the disk's lowest visible
//!    point. Its margin is `2⁻²¹ M`: the clearance it leaves is `(1 − τ) δ`, the origin's offset (`2⁻¹⁶` of its
//!    triangle's coordinates) scaled, far above the rounding of `n·(q − x)`.
//!
//! **Apart.** A box (a node's) is apart from the rays where it lies wholly on the far side of one of these: outside
//! the hull's box along a coordinate axis (3); wholly behind the disk's plane (2); wholly below the floor `f` (4);
//! outside the cone (1): outside a face of the square pyramid about the cone (the planes through `o` of normals
//! `cos σ e − sin σ a`, `e = ±u, ±v` across the axis), or, for the ball about the box's centre through its corners,
//! by the signed distance `s(v) = |v⊥| cos σ − (v·a) sin σ` of `v = p − o`: `s` is 1-Lipschitz (the map
//! `v → (|v⊥|, v·a)` is) and positive outside the cone, so `s(centre) > r` puts the whole ball outside. A triangle
//! is apart where its box is by (3), where all its corners are behind the disk's plane (2) or below the floor (4),
//! or where the classification of a cone against a triangle ([`cone_triangle_class`], the sun's: the triangle's own
//! plane, its edges' planes) finds that the cone (1), as rays of any length, misses it.
//!
//! **Margins.** The GPU computes in f32, its rays included; a few roundings of `2⁻²⁴` relative on coordinates up
//! to the larger of the cone's and the object's magnitudes `M`. Every comparison but the sun's classification
//! (which carries its own margin on the sines) keeps `2⁻¹⁹ M`, some dozens of times that; a ray that passes within
//! rounding of an object's side is a fragile ray (src/cpu/mod.rs), which f32 and f64 may answer differently in
//! any case.

use glam::DVec3;

use super::bvh::Bvh;
use super::ray_triangle::WatertightRay;
use super::sun_cells::{cone_triangle_class, SunCone};

/// The margin of the comparisons, relative to the largest coordinate involved: `2⁻¹⁹`.
pub const DISK_CONE_MARGIN: f64 = 1.0 / 524_288.0;

/// The most triangles a walk lists for the rays to test alone; past them the rays take the traversal.
pub const DISK_CONE_LISTED: usize = 16;

/// What the walk found (`DISK_CONE_*` in shaders/visibility.glsl).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DiskConeGather {
    /// No triangle can meet a ray: the whole disk is visible.
    Clear,
    /// Only these triangles (indices as given to the BVH) can.
    List(Vec<u32>),
    /// No cone, or more than [`DISK_CONE_LISTED`] triangles near the rays.
    Unknown,
}

/// The rays from an origin to a disk light, as the walk tests them (module text).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskCone {
    /// The ray origin \[m\], the shading point \[m\] and its unit normal (or 0: then no tangent plane helps).
    pub origin: DVec3,
    pub x: DVec3,
    pub n: DVec3,
    /// The floor under the rays (module text, 4): the origin's height `δ` above the tangent plane at `x` and the
    /// disk's lowest point's `g⁺` \[m\], and `1/(D − R)` \[1/m\].
    pub delta: f64,
    pub lowest: f64,
    pub inv_reach: f64,
    /// The unit axis towards the disk's centre and the sine and cosine of the cone's half-angle.
    pub axis: DVec3,
    /// Two unit vectors across the axis, for the faces of the square pyramid about the cone.
    pub u: DVec3,
    pub v: DVec3,
    pub sin_half: f64,
    pub cos_half: f64,
    /// The disk's centre \[m\] and unit emission direction.
    pub center: DVec3,
    pub d: DVec3,
    /// The box of the origin and the disk \[m\].
    pub lo: DVec3,
    pub hi: DVec3,
    /// The largest coordinate of the origin and the disk \[m\], for the margins.
    pub size: f64,
}

fn largest_coordinate(v: DVec3) -> f64 {
    v.abs().max_element()
}

/// The cone of the rays from `origin` (moved off the shading point `x` of normal `n`) to the disk light of `center`
/// \[m\], unit emission direction `d` and `radius` \[m\]; `None` where the origin is not in front of the disk or
/// lies within a radius (and 2⁻¹⁰ of it) of its centre, where no cone narrower than a half-space holds the disk.
pub fn disk_cone(origin: DVec3, x: DVec3, n: DVec3, center: DVec3, d: DVec3, radius: f64) -> Option<DiskCone> {
    let to = center - origin;
    let dist = to.length();
    let h = d.dot(origin - center);
    if !(h > 0.0 && radius >= 0.0 && dist * (1.0 - 1.0 / 1024.0) > radius) {
        return None;
    }
    let sin_half = radius / dist;
    // The disk's extent along each coordinate axis e: R √(1 − (d·e)²), written (1 − d_e)(1 + d_e) so that an axis
    // nearly along d keeps its small extent.
    let spread = |de: f64| radius * ((1.0 - de) * (1.0 + de)).max(0.0).sqrt();
    let reach = DVec3::new(spread(d.x), spread(d.y), spread(d.z));
    // The disk's lowest point above the tangent plane at x: g = n·(c − x) − R |n − (n·d) d|.
    let lowest = n.dot(center - x) - radius * (n - n.dot(d) * d).length();
    let axis = to / dist;
    let u = crate::shading::orthonormal_to(axis);
    Some(DiskCone {
        origin,
        n,
        x,
        delta: n.dot(origin - x),
        lowest: lowest.max(0.0),
        inv_reach: 1.0 / (dist - radius),
        axis,
        u,
        v: axis.cross(u),
        sin_half,
        cos_half: ((1.0 - sin_half) * (1.0 + sin_half)).sqrt(),
        center,
        d,
        lo: origin.min(center - reach),
        hi: origin.max(center + reach),
        size: largest_coordinate(origin).max(largest_coordinate(center) + radius),
    })
}

/// Whether the ball of `centre` \[m\] and radius `r` \[m\] lies outside the cone (its signed distance; module text).
pub fn disk_cone_apart_from_ball(c: &DiskCone, centre: DVec3, r: f64) -> bool {
    let v = centre - c.origin;
    let along = v.dot(c.axis);
    let across = (v - along * c.axis).length();
    across * c.cos_half - along * c.sin_half > r
}

/// The height above the tangent plane at `x` \[m\] under which the rays meet nothing within `r` \[m\] of the
/// origin (module text, 4).
pub fn disk_cone_floor(c: &DiskCone, r: f64) -> f64 {
    if c.delta <= c.lowest {
        return c.delta;
    }
    let tau = (r * c.inv_reach).min(1.0);
    (1.0 - tau) * c.delta + tau * c.lowest
}

/// Whether the box (`centre`, `half` sizes \[m\]) lies wholly outside one face of the square pyramid about the
/// cone, by `margin` \[m\]: the planes through the origin of normals `m = cos σ e − sin σ a`, `e = ±u, ±v`, each
/// holding the cone on its side `m·(p − o) ≤ 0` (inside the cone `m·w = cos σ |w⊥| (e·ŵ⊥) − sin σ (w·a) ≤ 0`).
/// Tighter than the ball for a long box (a wall, a floor).
pub fn disk_cone_apart_from_pyramid(c: &DiskCone, centre: DVec3, half: DVec3, margin: f64) -> bool {
    let w = centre - c.origin;
    [c.u, -c.u, c.v, -c.v].iter().any(|&e| {
        let m = c.cos_half * e - c.sin_half * c.axis;
        m.dot(w) - m.abs().dot(half) > margin
    })
}

/// Whether the box `[lo, hi]` \[m\] lies apart from the cone's rays (module text): outside the hull's box, behind
/// the disk's plane, below the tangent plane or outside the cone (a face of its pyramid, or its ball), by the margin.
pub fn disk_cone_apart_from_box(c: &DiskCone, lo: DVec3, hi: DVec3) -> bool {
    let m = DISK_CONE_MARGIN * c.size.max(largest_coordinate(lo)).max(largest_coordinate(hi));
    if hi.cmplt(c.lo - m).any() || lo.cmpgt(c.hi + m).any() {
        return true;
    }
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    if c.d.dot(centre - c.center) + c.d.abs().dot(half) <= -m {
        return true;
    }
    let reach = (centre - c.origin).length() + half.length();
    if c.n.dot(centre - c.x) + c.n.abs().dot(half) <= disk_cone_floor(c, reach) - m / 4.0 {
        return true;
    }
    disk_cone_apart_from_pyramid(c, centre, half, m) || disk_cone_apart_from_ball(c, centre, half.length() + m)
}

/// Whether no ray of the cone can meet the triangle (world corners \[m\]; module text).
pub fn disk_cone_misses_triangle(c: &DiskCone, corners: [DVec3; 3]) -> bool {
    let [c0, c1, c2] = corners;
    let lo = c0.min(c1).min(c2);
    let hi = c0.max(c1).max(c2);
    let m = DISK_CONE_MARGIN * c.size.max(largest_coordinate(lo)).max(largest_coordinate(hi));
    if hi.cmplt(c.lo - m).any() || lo.cmpgt(c.hi + m).any() {
        return true;
    }
    if corners.iter().all(|p| c.d.dot(*p - c.center) <= -m) {
        return true;
    }
    let reach = corners.iter().map(|p| (*p - c.origin).length()).fold(0.0, f64::max);
    let floor = disk_cone_floor(c, reach) - m / 4.0;
    if corners.iter().all(|p| c.n.dot(*p - c.x) <= floor) {
        return true;
    }
    cone_triangle_class(c.origin, c.axis, c.sin_half, corners) == SunCone::Misses
}

/// The triangles of `bvh` the shadow rays from `origin` (moved off `x`) to the disk light may meet: the tree walked
/// with the cone, each triangle it cannot show apart listed, up to [`DISK_CONE_LISTED`].
pub fn disk_cone_gather(
    bvh: &Bvh,
    origin: DVec3,
    x: DVec3,
    n: DVec3,
    center: DVec3,
    d: DVec3,
    radius: f64,
) -> DiskConeGather {
    let Some(c) = disk_cone(origin, x, n, center, d, radius) else {
        return DiskConeGather::Unknown;
    };
    if bvh.triangle_count() == 0 {
        return DiskConeGather::Clear;
    }
    let order = bvh.order();
    let mut listed = Vec::new();
    // A leaf's triangles near the rays are listed; false once there are too many.
    let mut list = |first: u32, count: u32| {
        for &t in &order[first as usize..(first + count) as usize] {
            if !disk_cone_misses_triangle(&c, bvh.triangle(t as usize)) {
                if listed.len() == DISK_CONE_LISTED {
                    return false;
                }
                listed.push(t);
            }
        }
        true
    };
    let (lo, hi, first, count) = bvh.node(0);
    if count > 0 {
        if !list(first, count) {
            return DiskConeGather::Unknown;
        }
    } else if !disk_cone_apart_from_box(&c, lo, hi) {
        let mut stack = vec![0usize];
        while let Some(node) = stack.pop() {
            let first = bvh.node(node).2 as usize;
            for child in [first, first + 1] {
                let (lo, hi, first, count) = bvh.node(child);
                if disk_cone_apart_from_box(&c, lo, hi) {
                    continue;
                }
                if count == 0 {
                    stack.push(child);
                } else if !list(first, count) {
                    return DiskConeGather::Unknown;
                }
            }
        }
    }
    if listed.is_empty() {
        DiskConeGather::Clear
    } else {
        DiskConeGather::List(listed)
    }
}

/// Whether every shadow ray from `origin` (moved off `x`) to the disk light misses every triangle of `bvh`.
pub fn disk_cone_clear(bvh: &Bvh, origin: DVec3, x: DVec3, n: DVec3, center: DVec3, d: DVec3, radius: f64) -> bool {
    disk_cone_gather(bvh, origin, x, n, center, d, radius) == DiskConeGather::Clear
}

/// Whether the ray meets, with `0 < t < t_max`, one of the `listed` triangles of `bvh`: where the walk listed them,
/// what testing every triangle would answer.
pub fn disk_cone_occluded(bvh: &Bvh, listed: &[u32], ray: &WatertightRay, t_max: f64) -> bool {
    listed.iter().any(|&t| ray.intersect(bvh.triangle(t as usize), 0.0, t_max).is_some())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::visibility::SEGMENT_T_MAX;

    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
        fn point(&mut self, lo: f64, hi: f64) -> DVec3 {
            DVec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
        }
    }

    /// Points of the disk: its rim densely, and a polar grid inside.
    fn disk_points(center: DVec3, d: DVec3, radius: f64) -> Vec<DVec3> {
        let a = crate::shading::orthonormal_to(d);
        let b = d.cross(a);
        let mut points = Vec::new();
        for i in 0..=8 {
            let r = radius * i as f64 / 8.0;
            for j in 0..64 {
                let phi = std::f64::consts::TAU * j as f64 / 64.0;
                points.push(center + r * (phi.cos() * a + phi.sin() * b));
            }
        }
        points
    }

    /// Whether a ray the grid or the lobe could cast from `origin` to a point of the disk is blocked by a triangle
    /// (every triangle tested; only the rays whose samples weigh something from `x`, the ones that are cast).
    fn some_ray_blocked(triangles: &[[DVec3; 3]], origin: DVec3, x: DVec3, n: DVec3, targets: &[DVec3]) -> bool {
        targets.iter().any(|&y| {
            let to = y - origin;
            n.dot(y - x) > 0.0
                && WatertightRay::new(origin, to)
                    .is_some_and(|r| triangles.iter().any(|&t| r.intersect(t, 0.0, SEGMENT_T_MAX).is_some()))
        })
    }

    /// A floor under a ceiling disk, with a few boxes of triangles standing on it.
    fn furnished_room(rng: &mut Lcg) -> Vec<[DVec3; 3]> {
        let mut triangles = vec![
            [DVec3::new(-5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, 5.0)],
            [DVec3::new(-5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, 5.0), DVec3::new(-5.0, 0.0, 5.0)],
        ];
        for _ in 0..40 {
            let base = DVec3::new(rng.range(-4.0, 4.0), rng.range(0.0, 1.5), rng.range(-4.0, 4.0));
            let size = rng.range(0.05, 0.6);
            triangles.push([base, base + rng.point(-size, size), base + rng.point(-size, size)]);
        }
        triangles
    }

    #[test]
    fn a_clear_cone_means_every_ray_gets_through() {
        let mut rng = Lcg(7);
        let (center, d, radius) = (DVec3::new(0.0, 2.5, 0.0), DVec3::NEG_Y, 0.6);
        let targets = disk_points(center, d, radius);
        let (mut clear, mut blocked) = (0, 0);
        for scene in 0..20 {
            let triangles = furnished_room(&mut rng);
            let bvh = Bvh::new(triangles.clone());
            for _ in 0..200 {
                // Points on the floor, their rays' origins pushed up as the renderers do, and in the air facing any
                // way, their origins moved off them a little either way.
                let (x, n, origin) = if scene % 2 == 0 {
                    let x = DVec3::new(rng.range(-5.0, 5.0), 0.0, rng.range(-5.0, 5.0));
                    (x, DVec3::Y, x + DVec3::new(0.0, 5.0 / 65536.0, 0.0))
                } else {
                    let x = DVec3::new(rng.range(-5.0, 5.0), rng.range(0.0, 2.0), rng.range(-5.0, 5.0));
                    (x, rng.point(-1.0, 1.0).normalize(), x + rng.point(-1e-3, 1e-3))
                };
                if disk_cone_clear(&bvh, origin, x, n, center, d, radius) {
                    clear += 1;
                    assert!(
                        !some_ray_blocked(&triangles, origin, x, n, &targets),
                        "scene {scene}: the walk called {origin} clear, but a ray to the disk is blocked"
                    );
                } else if some_ray_blocked(&triangles, origin, x, n, &targets) {
                    blocked += 1;
                }
            }
        }
        // The walk proves most of the floor clear, and the scenes do block rays (so that the assertion is tested).
        assert!(clear > 1000 && blocked > 300, "clear {clear}, blocked {blocked} of 4000");
    }

    #[test]
    fn the_listed_triangles_answer_every_ray_as_all_the_triangles_do() {
        let mut rng = Lcg(11);
        let (center, d, radius) = (DVec3::new(0.0, 2.5, 0.0), DVec3::NEG_Y, 0.6);
        let targets = disk_points(center, d, radius);
        let (mut lists, mut blocked) = (0, 0);
        for _ in 0..20 {
            let triangles = furnished_room(&mut rng);
            let bvh = Bvh::new(triangles.clone());
            for _ in 0..100 {
                let x = DVec3::new(rng.range(-5.0, 5.0), 0.0, rng.range(-5.0, 5.0));
                let origin = x + DVec3::new(0.0, 5.0 / 65536.0, 0.0);
                let DiskConeGather::List(listed) = disk_cone_gather(&bvh, origin, x, DVec3::Y, center, d, radius)
                else {
                    continue;
                };
                assert!(!listed.is_empty() && listed.len() <= DISK_CONE_LISTED);
                lists += 1;
                for &y in &targets {
                    let ray = WatertightRay::new(origin, y - origin).unwrap();
                    let all = triangles.iter().any(|&t| ray.intersect(t, 0.0, SEGMENT_T_MAX).is_some());
                    assert_eq!(disk_cone_occluded(&bvh, &listed, &ray, SEGMENT_T_MAX), all, "{origin} to {y}");
                    blocked += usize::from(all);
                }
            }
        }
        assert!(lists > 100 && blocked > 1000, "{lists} lists, {blocked} rays blocked");
    }

    #[test]
    fn a_floor_under_its_light_is_clear_and_an_occluder_above_it_is_not() {
        let floor = vec![
            [DVec3::new(-5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, 5.0)],
            [DVec3::new(-5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, 5.0), DVec3::new(-5.0, 0.0, 5.0)],
        ];
        let (center, d, radius) = (DVec3::new(0.0, 2.5, 0.0), DVec3::NEG_Y, 0.6);
        let origin = DVec3::new(1.0, 5.0 / 65536.0, 1.0);
        let bvh = Bvh::new(floor.clone());
        let x = DVec3::new(1.0, 0.0, 1.0);
        assert!(disk_cone_clear(&bvh, origin, x, DVec3::Y, center, d, radius));
        // A plate halfway up, off the axis but within the cone's reach of the disk's rim.
        let mut scene = floor.clone();
        let p = DVec3::new(0.6, 1.2, 0.6);
        scene.push([p, p + DVec3::new(0.05, 0.0, 0.0), p + DVec3::new(0.0, 0.0, 0.05)]);
        let bvh = Bvh::new(scene.clone());
        assert!(!disk_cone_clear(&bvh, origin, x, DVec3::Y, center, d, radius));
        // The same plate behind the disk's plane, or below the floor: apart.
        for y in [2.6, -1.0] {
            let mut scene = floor.clone();
            let p = DVec3::new(0.5, y, 0.5);
            scene.push([p, p + DVec3::new(0.3, 0.0, 0.0), p + DVec3::new(0.0, 0.0, 0.3)]);
            let bvh = Bvh::new(scene.clone());
            assert!(disk_cone_clear(&bvh, origin, x, DVec3::Y, center, d, radius), "plate at y = {y}");
        }
    }

    #[test]
    fn the_lower_tangent_plane_bounds_the_rays() {
        // The ray origin 1 cm above its point, a disk low on the horizon (its points from 1 mm to 11 mm high), a
        // plate 5 mm high between the two tangent planes: rays from the origin down to the disk's lower points
        // meet it, though it lies below the origin's tangent plane.
        let (x, n) = (DVec3::ZERO, DVec3::Y);
        let origin = DVec3::new(0.0, 0.01, 0.0);
        let (center, d, radius) = (DVec3::new(5.0, 0.006, 0.0), DVec3::NEG_X, 0.005);
        let scene = vec![[DVec3::new(3.0, 0.005, -1.0), DVec3::new(4.5, 0.005, 0.0), DVec3::new(3.0, 0.005, 1.0)]];
        assert!(some_ray_blocked(&scene, origin, x, n, &disk_points(center, d, radius)));
        let bvh = Bvh::new(scene.clone());
        assert!(!disk_cone_clear(&bvh, origin, x, n, center, d, radius));
        // Below both planes it is apart.
        let below = vec![scene[0].map(|p| p - DVec3::new(0.0, 0.006, 0.0))];
        let bvh = Bvh::new(below.clone());
        assert!(!some_ray_blocked(&below, origin, x, n, &disk_points(center, d, radius)));
        assert!(disk_cone_clear(&bvh, origin, x, n, center, d, radius));
    }

    #[test]
    fn no_cone_behind_the_disk_or_within_its_radius() {
        let (center, d) = (DVec3::new(0.0, 2.5, 0.0), DVec3::NEG_Y);
        let up = DVec3::Y;
        assert!(disk_cone(DVec3::new(0.0, 3.0, 0.0), DVec3::new(0.0, 3.0, 0.0), up, center, d, 0.6).is_none());
        assert!(disk_cone(DVec3::new(0.3, 2.4, 0.0), DVec3::new(0.3, 2.4, 0.0), up, center, d, 0.6).is_none());
        let c = disk_cone(DVec3::ZERO, DVec3::ZERO, up, center, d, 0.6).unwrap();
        assert!((c.sin_half - 0.24).abs() < 1e-15 && (c.sin_half.powi(2) + c.cos_half.powi(2) - 1.0).abs() < 1e-15);
        // The hull's box holds the disk: a horizontal disk spans its radius along x and z, nothing along y.
        assert_eq!((c.lo, c.hi), (DVec3::new(-0.6, 0.0, -0.6), DVec3::new(0.6, 2.5, 0.6)));
    }

    #[test]
    fn the_ball_test_is_a_signed_distance_to_the_cone() {
        let c = disk_cone(DVec3::ZERO, DVec3::ZERO, DVec3::Y, DVec3::new(0.0, 2.0, 0.0), DVec3::NEG_Y, 1.0).unwrap();
        // Half-angle 30°: a point at 45° from the axis, 1 m away, lies sin 15° ≈ 0.2588 m from the cone.
        let p = DVec3::new(std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2, 0.0);
        assert!(disk_cone_apart_from_ball(&c, p, 0.25));
        assert!(!disk_cone_apart_from_ball(&c, p, 0.26));
        // Behind the apex: its distance is at least the signed one.
        assert!(disk_cone_apart_from_ball(&c, DVec3::new(0.0, -1.0, 0.0), 0.4));
        assert!(!disk_cone_apart_from_ball(&c, DVec3::new(0.0, 1.0, 0.0), 0.0));
    }
}

//! A bounding volume hierarchy over triangles for the visibility rays (the reference's, and the GPU's on devices
//! without ray queries: shaders/bvh.glsl walks the same tree): built once per scene by binned splits of
//! least surface-area cost (MacDonald & Booth, "Heuristics for ray tracing using space subdivision", The Visual
//! Computer 6, 1990; binned as in Wald, "On fast construction of SAH-based bounding volume hierarchies", 2007),
//! each side kept at least a quarter of its parent's triangles, and traversed with an explicit stack.
//!
//! The quarter bounds the depth: `log_{4/3} 2³² < 78` levels for any `u32` count, so the walks' stacks of
//! [`STACK_SIZE`] (one pending sibling a level) cannot overflow. On a scene of a large flat floor under compact
//! objects (sunset.glb) the surface-area splits separate the floor from the objects early: a ray along the floor
//! at the setting sun took up to 624 steps (nodes and leaf triangles) with median splits, which matters on
//! lavapipe, where every node a shader's walk enters spends one of the 65535 loop iterations a fragment has
//! (`gpu::loop_budget`).
//!
//! Exactness does not depend on the tree: a box test only decides what is tested, and the boxes are widened by a
//! relative 1e-9 so that rounding in the slab test can never skip a triangle the ray touches. `any_hit` (shadow
//! rays) and `closest_hit` return what testing every triangle with [`WatertightRay`] would return (tests below
//! compare with brute force).

use glam::DVec3;

use super::ray_triangle::WatertightRay;
use crate::shading::visibility::SliceReach;

/// The walks' stack entries: more than the deepest tree's levels (module text). `BVH_STACK_SIZE` in
/// shaders/bvh.glsl.
pub const STACK_SIZE: usize = 96;
/// Bins per axis of the split search.
const BINS: usize = 16;

/// Triangles per leaf at most (`BVH_LEAF_SIZE` in shaders/bvh.glsl, whose walk tests a child leaf's triangle
/// in its parent's iteration). One: on lavapipe a SIMD group runs a leaf's tests whenever one of its lanes is at a
/// leaf, so leaves of four cost the shader's walk 1.6 to 2 times as much (`render --shadows ray`, 256²: teapot.glb
/// 7.6 s against 4.2–5.2 s, sunset.glb 11.3–12.5 s against 6.3–6.5 s; brdfs.glb at 96 × 72: 7.0–7.5 s against
/// 3.5–3.7 s; docs/accuracy.md), while the reference's time did not change. (Each leaf its own loop iteration was
/// faster still, 2.8 s and 4.3 s, but spent llvmpipe's loop budget on leaves: measured materials with a ray per
/// lobe sample at 6² ran out.)
pub const LEAF_SIZE: usize = 1;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: DVec3,
    max: DVec3,
    /// Leaf: `first..first + count` of `order`; inner: children at `first` and `first + 1`, `count == 0`.
    first: u32,
    count: u32,
}

/// A BVH over triangles given in world space \[m\].
#[derive(Clone, Debug)]
pub struct Bvh {
    triangles: Vec<[DVec3; 3]>,
    /// Triangle indices in leaf order.
    order: Vec<u32>,
    nodes: Vec<Node>,
}

fn bounds(t: &[DVec3; 3]) -> (DVec3, DVec3) {
    (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

impl Bvh {
    /// Builds the tree (iteratively: no recursion on the depth of the tree). Triangles with non-finite vertices
    /// are left out (the loader refuses them anyway).
    pub fn new(triangles: Vec<[DVec3; 3]>) -> Self {
        let mut order: Vec<u32> =
            (0..triangles.len() as u32).filter(|&i| triangles[i as usize].iter().all(|v| v.is_finite())).collect();
        let centroid = |i: u32| {
            let t = &triangles[i as usize];
            (t[0] + t[1] + t[2]) / 3.0
        };
        let mut nodes = vec![Node { min: DVec3::ZERO, max: DVec3::ZERO, first: 0, count: order.len() as u32 }];
        let mut todo = vec![0usize];
        while let Some(n) = todo.pop() {
            let (first, count) = (nodes[n].first as usize, nodes[n].count as usize);
            let items = &mut order[first..first + count];
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for &i in items.iter() {
                let (a, b) = bounds(&triangles[i as usize]);
                lo = lo.min(a);
                hi = hi.max(b);
            }
            // Widen by a relative 1e-9 (and an absolute 1e-300): the slab test's rounding cannot cut a touching ray.
            let pad = (hi - lo).abs().max(lo.abs()).max(hi.abs()) * 1e-9 + DVec3::splat(1e-300);
            nodes[n].min = lo - pad;
            nodes[n].max = hi + pad;
            if count <= LEAF_SIZE {
                continue;
            }
            let mid = sah_split(items, &triangles, &centroid);
            let left = nodes.len();
            nodes.push(Node { min: DVec3::ZERO, max: DVec3::ZERO, first: first as u32, count: mid as u32 });
            nodes.push(Node {
                min: DVec3::ZERO,
                max: DVec3::ZERO,
                first: (first + mid) as u32,
                count: (count - mid) as u32,
            });
            nodes[n].first = left as u32;
            nodes[n].count = 0;
            todo.push(left);
            todo.push(left + 1);
        }
        Self { triangles, order, nodes }
    }

    pub fn triangle_count(&self) -> usize {
        self.order.len()
    }

    /// The triangle indices (as given to [`Bvh::new`]) in leaf order: a leaf's `first..first + count` index this.
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The nodes, root first, each as `(min, max, first, count)` \[m\]: a leaf (`count > 0`) holds
    /// `order()[first..first + count]`, an inner node (`count == 0`) has its children at `first` and `first + 1`.
    /// The boxes are padded as the traversal here uses them. The GPU's traversal (shaders/bvh.glsl) walks
    /// the same tree.
    pub fn nodes(&self) -> impl Iterator<Item = (DVec3, DVec3, u32, u32)> + '_ {
        self.nodes.iter().map(|n| (n.min, n.max, n.first, n.count))
    }

    /// Node `i` as [`Bvh::nodes`] gives it.
    pub fn node(&self, i: usize) -> (DVec3, DVec3, u32, u32) {
        let n = &self.nodes[i];
        (n.min, n.max, n.first, n.count)
    }

    /// The corners \[m\] of triangle `i` (as given to [`Bvh::new`]).
    pub fn triangle(&self, i: usize) -> [DVec3; 3] {
        self.triangles[i]
    }

    /// Whether the ray hits any triangle with `t_min < t < t_max` (a shadow ray: the light is occluded).
    pub fn any_hit(&self, ray: &WatertightRay, t_min: f64, t_max: f64) -> bool {
        self.traverse(ray, t_min, t_max, true).is_some()
    }

    /// Whether the ray hits, with `t_min < t < t_max`, a triangle that `accept(index, t)` accepts (a hit on an
    /// alpha-masked triangle where its alpha is below the cutoff is passed through).
    pub fn any_hit_where(
        &self,
        ray: &WatertightRay,
        t_min: f64,
        t_max: f64,
        mut accept: impl FnMut(usize, f64) -> bool,
    ) -> bool {
        let mut hit = false;
        self.walk(ray, t_min, t_max, 0.0, |i, t_max| {
            hit = ray.intersect(self.triangles[i], t_min, *t_max).is_some_and(|t| accept(i, t));
            hit
        });
        hit
    }

    /// The nearest hit with `t_min < t < t_max`: its `t` and the triangle's index as given to [`Bvh::new`].
    pub fn closest_hit(&self, ray: &WatertightRay, t_min: f64, t_max: f64) -> Option<(f64, usize)> {
        self.traverse(ray, t_min, t_max, false)
    }

    fn traverse(&self, ray: &WatertightRay, t_min: f64, t_max: f64, any: bool) -> Option<(f64, usize)> {
        let mut best = None;
        self.walk(ray, t_min, t_max, 0.0, |i, t_max| {
            if let Some(t) = ray.intersect(self.triangles[i], t_min, *t_max) {
                best = Some((t, i));
                if any {
                    return true;
                }
                *t_max = t;
            }
            false
        });
        best
    }

    /// Visits the triangles of every leaf whose box, widened by `pad` [m], the ray meets within `(t_min, t_max)`,
    /// nearest boxes not necessarily first. `triangle(i, &mut t_max)` may shorten the ray (boxes beyond are then
    /// skipped) and returns whether to stop.
    fn walk(
        &self,
        ray: &WatertightRay,
        t_min: f64,
        t_max: f64,
        pad: f64,
        mut triangle: impl FnMut(usize, &mut f64) -> bool,
    ) {
        let inv = ray.direction.recip();
        // The ray is shortened by `triangle` as the boxes are tested against it: one value read by both.
        let t_max = std::cell::Cell::new(t_max);
        self.descend(
            |node| slab(node, pad, ray.origin, inv, t_min, t_max.get()),
            |i| {
                let mut t = t_max.get();
                let stop = triangle(i, &mut t);
                t_max.set(t);
                stop
            },
        );
    }

    /// The trees' one descent, depth first with an explicit stack: a node is entered where `enter` says so (its
    /// box meets what is sought), an inner node's children stacked, an entered leaf's triangles (the index as
    /// given to [`Bvh::new`]) handed to `leaf`, which returns whether to stop. The depth is below 78 (module text)
    /// and the stack holds at most one pending sibling per level.
    fn descend(&self, mut enter: impl FnMut(&Node) -> bool, mut leaf: impl FnMut(usize) -> bool) {
        if self.order.is_empty() {
            return;
        }
        let mut stack = [0u32; STACK_SIZE];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if !enter(node) {
                continue;
            }
            if node.count == 0 {
                stack[top] = node.first;
                stack[top + 1] = node.first + 1;
                top += 2;
                continue;
            }
            for &i in &self.order[node.first as usize..(node.first + node.count) as usize] {
                if leaf(i as usize) {
                    return;
                }
            }
        }
    }
}

/// Whether the sphere of centre `centre` (relative to the cone's apex) and radius `r` \[m\] may meet the cone of unit
/// `axis` whose half-angle has cosine `cos_a` and sine `sin_a`: the apex inside the sphere, or the centre's angle
/// from the axis within the cone's half-angle plus the sphere's angular radius `asin(r/|centre|)`, compared by
/// their sines below a right angle (`|centre × axis|` keeps the small angles of the sun's half-degree, which a
/// cosine near 1 would lose) and by their cosines above, with a relative slack of 1e-9 as the boxes' padding.
pub(crate) fn sphere_meets_cone(centre: DVec3, r: f64, axis: DVec3, cos_a: f64, sin_a: f64) -> bool {
    let dist = centre.length();
    if dist <= r {
        return true;
    }
    let sin_p = r / dist;
    let cos_p = (1.0 - sin_p * sin_p).sqrt();
    let (sin_t, cos_t) = (sin_a * cos_p + cos_a * sin_p, cos_a * cos_p - sin_a * sin_p);
    let (along, across) = (centre.dot(axis), centre.cross(axis).length());
    let slack = 1e-9 * dist;
    if cos_t > 0.0 {
        along > -slack && across <= sin_t * dist + slack
    } else {
        along >= cos_t * dist - slack
    }
}

/// Where to split `items` (more than [`LEAF_SIZE`] triangles): reordered in place so that the first `mid` go left.
/// Along each axis of the centroids' box, the centroids are binned ([`BINS`]) and every boundary between bins
/// costed by the surface-area heuristic, `area(left box) · left count + area(right box) · right count`; the
/// cheapest boundary that leaves at least a quarter of the triangles on each side wins, else (all centroids in
/// one bin, or no balanced boundary) the median along the longest axis.
fn sah_split(items: &mut [u32], triangles: &[[DVec3; 3]], centroid: &impl Fn(u32) -> DVec3) -> usize {
    let count = items.len();
    let (mut clo, mut chi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for &i in items.iter() {
        clo = clo.min(centroid(i));
        chi = chi.max(centroid(i));
    }
    let extent = chi - clo;
    let area = |lo: DVec3, hi: DVec3| {
        let e = (hi - lo).max(DVec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    };
    let bin_of = |c: f64, axis: usize| (((c - clo[axis]) / extent[axis] * BINS as f64) as usize).min(BINS - 1);
    let mut best: Option<(f64, usize, usize)> = None; // (cost, axis, first bin on the right)
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let mut bins = [(0usize, DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)); BINS];
        for &i in items.iter() {
            let b = &mut bins[bin_of(centroid(i)[axis], axis)];
            let (lo, hi) = bounds(&triangles[i as usize]);
            *b = (b.0 + 1, b.1.min(lo), b.2.max(hi));
        }
        // Right-hand sums from each boundary, then a left-hand sweep.
        let mut right = [(0usize, 0.0f64); BINS];
        let (mut n, mut lo, mut hi) = (0, DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for b in (1..BINS).rev() {
            n += bins[b].0;
            lo = lo.min(bins[b].1);
            hi = hi.max(bins[b].2);
            right[b] = (n, area(lo, hi));
        }
        let (mut n, mut lo, mut hi) = (0, DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for b in 1..BINS {
            n += bins[b - 1].0;
            lo = lo.min(bins[b - 1].1);
            hi = hi.max(bins[b - 1].2);
            let (rn, ra) = right[b];
            if 4 * n < count || 4 * rn < count {
                continue;
            }
            let cost = area(lo, hi) * n as f64 + ra * rn as f64;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    if let Some((_, axis, b)) = best {
        // Partition in place: centroids in bins below b first.
        let mut mid = 0;
        for k in 0..count {
            if bin_of(centroid(items[k])[axis], axis) < b {
                items.swap(k, mid);
                mid += 1;
            }
        }
        return mid;
    }
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = count / 2;
    items.select_nth_unstable_by(mid, |&a, &b| centroid(a)[axis].total_cmp(&centroid(b)[axis]));
    mid
}

impl crate::shading::Occlusion for Bvh {
    fn occluded(&self, origin: DVec3, direction: DVec3, t_max: f64) -> bool {
        WatertightRay::new(origin, direction).is_some_and(|ray| self.any_hit(&ray, 0.0, t_max))
    }

    fn slice_triangles(&self, reach: &SliceReach, visit: &mut dyn FnMut([DVec3; 3])) -> bool {
        self.within_reach(reach, |i| visit(self.triangles[i]));
        true
    }
}

impl Bvh {
    /// Visits (the index as given to [`Bvh::new`] of) every triangle in a leaf whose box reaches into the
    /// half-spaces `above` and `beyond` of a point's slices, whose bounding sphere may meet their cone, and which
    /// may hold a part of their one `row` ([`within_row`]) (the lights' slices: `shading::sky_slices`,
    /// `sun_slices`, `disk_slices`). A box reaches into a half-space where
    /// its centre's signed distance plus its half-extent projected on the normal is positive; the boxes' padding
    /// (a relative 1e-9) covers the rounding of those tests.
    pub fn within_reach(&self, reach: &SliceReach, mut visit: impl FnMut(usize)) {
        self.descend(
            |node| node_within_reach(node, reach),
            |i| {
                visit(i);
                false
            },
        );
    }

    /// The triangles [`Bvh::within_reach`] visits, where they are at most `limit`; `None` (the walk cut short)
    /// where they are more.
    pub fn within_reach_at_most(&self, reach: &SliceReach, limit: usize) -> Option<Vec<usize>> {
        let mut found = Vec::new();
        let mut over = false;
        self.descend(
            |node| node_within_reach(node, reach),
            |i| {
                over = found.len() == limit;
                if !over {
                    found.push(i);
                }
                over
            },
        );
        (!over).then_some(found)
    }
}

/// Whether a node's box may hold a part of what `reach` bounds ([`Bvh::within_reach`]).
fn node_within_reach(node: &Node, reach: &SliceReach) -> bool {
    let reaches = |centre: DVec3, half: DVec3, k: DVec3| centre.dot(k) + half.dot(k.abs()) > 0.0;
    let centre = 0.5 * (node.min + node.max) - reach.origin;
    let half = 0.5 * (node.max - node.min);
    // The culls as written (a NaN distance keeps the box: no comparison culls it).
    let culled = !reach.above.iter().all(|&k| reaches(centre, half, k))
        || reach.cone.is_some_and(|(axis, cos, sin)| !sphere_meets_cone(centre, half.length(), axis, cos, sin))
        || reach.beyond.is_some_and(|(k, b)| centre.dot(k) + half.dot(k.abs()) <= b)
        || reach.row.is_some_and(|(p, m)| !within_row(centre, half, p, m));
    !culled
}

/// Whether a box (centre relative to a point's rays' origin, half-extent) may hold a part of a row's half-plane
/// `{s c + t p : t ≥ 0}` of unit normal `m` through that origin: it straddles the plane and reaches `t > 0` (the
/// GPU's sky rows' walk, shaders/slices.glsl; there with f32's slack, here the boxes' padding).
pub fn within_row(centre: DVec3, half: DVec3, p: DVec3, m: DVec3) -> bool {
    centre.dot(m).abs() <= half.dot(m.abs()) && centre.dot(p) + half.dot(p.abs()) > 0.0
}

impl Bvh {
    /// Whether the ray is occluded for `t_min < t < t_max`, and whether that answer is *fragile*: no triangle is
    /// hit farther than `eps` \[m\] inside its boundary, but one is hit, or missed, within `eps` of it, so that a
    /// few ulps of f32 geometry (the GPU's) could flip it. Boxes are padded by `eps` for this traversal.
    pub fn occluded_with_margin(&self, ray: &WatertightRay, t_min: f64, t_max: f64, eps: f64) -> (bool, bool) {
        self.occluded_with_margin_where(ray, t_min, t_max, eps, |_, _| (true, false))
    }

    /// [`Bvh::occluded_with_margin`] counting only the hits `accept(index, t)` accepts; its second answer says
    /// whether that acceptance is itself fragile (an alpha at its cutoff), which makes the ray's answer fragile.
    pub fn occluded_with_margin_where(
        &self,
        ray: &WatertightRay,
        t_min: f64,
        t_max: f64,
        eps: f64,
        mut accept: impl FnMut(usize, f64) -> (bool, bool),
    ) -> (bool, bool) {
        let (mut robust_hit, mut fragile_hit, mut near_miss) = (false, false, false);
        self.walk(ray, t_min, t_max, eps, |i, _| {
            let Some(d) = ray.edge_margin(self.triangles[i], t_min, t_max).filter(|&d| d >= -eps) else {
                return false;
            };
            let t = ray.hit_t(self.triangles[i]).unwrap_or(t_min);
            // A hit the filter rejects is no hit; an acceptance that is itself fragile makes the answer fragile
            // without changing it.
            match accept(i, t) {
                (true, false) if d > eps => robust_hit = true,
                (true, _) if d >= 0.0 => fragile_hit = true,
                (true, _) | (false, true) => near_miss = true,
                (false, false) => {}
            }
            robust_hit
        });
        if robust_hit {
            (true, false)
        } else if fragile_hit {
            (true, true)
        } else {
            (false, near_miss)
        }
    }
}

/// The slab test of a padded box, widened by `pad` more (0: the box as built; `min − 0` is `min` exactly). An
/// axis with a zero direction component gives ±inf or NaN products: the comparisons are written so that a NaN
/// (origin on the slab's plane) keeps the box rather than dropping it.
fn slab(node: &Node, pad: f64, origin: DVec3, inv: DVec3, t_min: f64, t_max: f64) -> bool {
    let (mut lo, mut hi) = (t_min, t_max);
    for k in 0..3 {
        (lo, hi) = slab_axis(node.min[k] - pad, node.max[k] + pad, origin[k], inv[k], (lo, hi));
        if lo > hi {
            return false;
        }
    }
    true
}

/// One axis of [`slab`]: the interval `(lo, hi)` of t narrowed to the slab `[box_min, box_max]` along it (`inv`:
/// 1/direction along it, ±inf where that is 0). The shader calls it axis by axis, without a loop (llvmpipe's
/// loop budget, src/gpu/loop_budget.rs).
fn slab_axis(box_min: f64, box_max: f64, origin: f64, inv: f64, (lo, hi): (f64, f64)) -> (f64, f64) {
    let (a, b) = ((box_min - origin) * inv, (box_max - origin) * inv);
    let (near, far) = if a <= b { (a, b) } else { (b, a) };
    (if near > lo { near } else { lo }, if far < hi { far } else { hi })
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Rng(u64);
    impl Rng {
        fn f(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn v(&mut self, s: f64) -> DVec3 {
            DVec3::new(self.f() - 0.5, self.f() - 0.5, self.f() - 0.5) * s
        }
        /// `count` triangles of corners within `size` of centres within 2 m of the origin.
        fn soup(&mut self, count: usize, size: f64) -> Vec<[DVec3; 3]> {
            (0..count)
                .map(|_| {
                    let c = self.v(2.0);
                    [c + self.v(size), c + self.v(size), c + self.v(size)]
                })
                .collect()
        }
    }

    #[test]
    fn the_walk_within_reach_visits_every_triangle_the_slices_can_meet() {
        // Every triangle with a corner in each half-space `above` and in `beyond`, a corner inside the cone, and a
        // part of the row's half-plane, must be visited (the walk may visit more); and the walk must leave some out.
        let mut rng = Rng(11);
        let mut left_out = 0;
        for (count, size) in [(1usize, 0.5), (200, 0.2), (3000, 0.05)] {
            let tris = rng.soup(count, size);
            let bvh = Bvh::new(tris.clone());
            for _ in 0..500 {
                let origin = rng.v(3.0);
                let above = [rng.v(1.0).normalize(), rng.v(1.0).normalize()];
                let (axis, angle) = (rng.v(1.0).normalize(), 0.01 + 1.5 * rng.f());
                let cone = (rng.f() < 0.5).then_some((axis, angle.cos(), angle.sin()));
                let k = rng.v(1.0).normalize();
                let beyond = (rng.f() < 0.5).then_some((k, rng.f() - 0.5));
                // A row's half-plane {s c + t p : t ≥ 0}, m = c × p, for some walks (the GPU's sky rows).
                let m = rng.v(1.0).normalize();
                let p = m.cross(rng.v(1.0)).normalize();
                let row = (rng.f() < 0.5).then_some((p, m));
                let reach = SliceReach { origin, above, cone, beyond, row };
                let mut visited = vec![false; count];
                bvh.within_reach(&reach, |i| visited[i] = true);
                left_out += visited.iter().filter(|&&v| !v).count();
                for (i, t) in tris.iter().enumerate() {
                    let side = |k: DVec3| t.map(|p| (p - origin).dot(k));
                    let reaches = |k: DVec3| side(k).iter().any(|&x| x > 0.0);
                    // A corner inside the cone (by its angle from the axis), a corner beyond the half-space.
                    let in_cone =
                        cone.is_none_or(|(a, cos, _)| t.iter().any(|&p| (p - origin).normalize().dot(a) > cos));
                    let is_beyond = beyond.is_none_or(|(k, b)| side(k).iter().any(|&x| x > b));
                    // The segment in which the row's plane cuts it, reaching t > 0.
                    let in_row = row.is_none_or(|(p, m)| {
                        crate::shading::sky_slices::slice_segment(t.map(|x| x - origin), m.cross(p), p, m)
                            .is_some_and(|[a, b]| a.1 > 0.0 || b.1 > 0.0)
                    });
                    if in_cone && is_beyond && in_row && above.iter().all(|&k| reaches(k)) {
                        assert!(visited[i], "{count} triangles: triangle {i} missed");
                    }
                }
            }
        }
        assert!(left_out > 100_000, "{left_out}");
    }

    #[test]
    fn agrees_with_brute_force_on_random_soups() {
        let mut rng = Rng(7);
        for (count, size) in [(1usize, 0.5), (3, 0.5), (200, 0.2), (3000, 0.05)] {
            let tris = rng.soup(count, size);
            let bvh = Bvh::new(tris.clone());
            assert_eq!(bvh.triangle_count(), count);
            for _ in 0..2000 {
                let origin = rng.v(3.0);
                // Some rays along an axis, to exercise zero direction components in the slab test.
                let dir = match rng.f() {
                    x if x < 0.1 => DVec3::X,
                    x if x < 0.2 => -DVec3::Y,
                    _ => rng.v(1.0),
                };
                let Some(ray) = WatertightRay::new(origin, dir) else { continue };
                let t_max = if rng.f() < 0.5 { f64::INFINITY } else { rng.f() * 4.0 };
                let brute = tris
                    .iter()
                    .enumerate()
                    .filter_map(|(i, &t)| ray.intersect(t, 0.0, t_max).map(|t| (t, i)))
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                assert_eq!(bvh.any_hit(&ray, 0.0, t_max), brute.is_some(), "{count} triangles");
                assert_eq!(bvh.closest_hit(&ray, 0.0, t_max).map(|h| h.0), brute.map(|h| h.0), "{count} triangles");
            }
        }
        assert!(!Bvh::new(Vec::new()).any_hit(&WatertightRay::new(DVec3::ZERO, DVec3::X).unwrap(), 0.0, 1.0));
    }

    #[test]
    fn fragile_rays_are_those_near_an_edge() {
        // One triangle 5 m away: rays through its middle are robust hits, rays far outside robust misses; rays
        // within eps inside or outside an edge, and through a vertex, are fragile, and their answers are any_hit's.
        let tri = [DVec3::new(0.0, 0.0, 5.0), DVec3::new(1.0, 0.0, 5.0), DVec3::new(0.0, 1.0, 5.0)];
        let bvh = Bvh::new(vec![tri]);
        let eps = 1e-6;
        let at = |x: f64, y: f64| {
            let ray = WatertightRay::new(DVec3::ZERO, DVec3::new(x, y, 5.0)).unwrap();
            let answer = bvh.occluded_with_margin(&ray, 0.0, f64::INFINITY, eps);
            assert_eq!(answer.0, bvh.any_hit(&ray, 0.0, f64::INFINITY), "({x}, {y})");
            answer
        };
        assert_eq!(at(0.25, 0.25), (true, false));
        assert_eq!(at(2.0, 2.0), (false, false));
        assert_eq!(at(0.5, 0.5 - 1e-7), (true, true)); // just inside the hypotenuse
        assert_eq!(at(0.5, 0.5 + 1e-7), (false, true)); // just outside it
        assert_eq!(at(0.5, -1e-7), (false, true));
        assert_eq!(at(0.0, 0.0), (true, true)); // a vertex
        assert_eq!(at(0.5, 0.5 - 1e-4), (true, false)); // far enough inside
        assert_eq!(at(0.5, -1e-4), (false, false)); // far enough outside
    }

    #[test]
    fn a_closed_mesh_has_no_holes_for_rays_from_inside() {
        // A UV sphere of 64 × 32 quads (two triangles each): every ray from inside must hit, including rays aimed
        // exactly at its vertices and edge midpoints, where triangles meet.
        let (stacks, slices) = (32usize, 64usize);
        let p = |i: usize, j: usize| {
            let (th, ph) =
                (i as f64 / stacks as f64 * std::f64::consts::PI, j as f64 / slices as f64 * std::f64::consts::TAU);
            DVec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()) * 1.3 + DVec3::new(0.1, -0.2, 0.3)
        };
        let mut tris = Vec::new();
        for i in 0..stacks {
            for j in 0..slices {
                // (j + 1) % slices: the seam's vertices must be the same numbers on both sides (sin 2π ≠ sin 0 in
                // floating point would leave a real crack, which is what a watertight test then finds).
                let jn = (j + 1) % slices;
                let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, jn), p(i, jn));
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        let bvh = Bvh::new(tris.clone());
        let origin = DVec3::new(0.12, -0.17, 0.29);
        let (mut misses, mut brute_misses) = (0, 0);
        for i in 0..=stacks {
            for j in 0..slices {
                for aim in
                    [p(i, j), (p(i, j) + p(i.min(stacks - 1) + 1, j)) / 2.0, (p(i, j) + p(i, (j + 1) % slices)) / 2.0]
                {
                    let ray = WatertightRay::new(origin, aim - origin).unwrap();
                    misses += usize::from(!bvh.any_hit(&ray, 1e-9, f64::INFINITY));
                    brute_misses += usize::from(!tris.iter().any(|&t| ray.intersect(t, 1e-9, f64::INFINITY).is_some()));
                }
            }
        }
        assert_eq!((misses, brute_misses), (0, 0), "rays slipped through the closed sphere");
    }
}

//! The occluders one point's sun grid can meet. A located grid casts its (k + 1)² rays and more from one origin,
//! all within the sun's cone and above the surface's horizon; the triangles any of them can meet are those whose
//! BVH leaves reach into that cone and half-spaces (`Bvh::within_reach`, the walk the slices use). Gathered once
//! per point, they answer each such ray exactly as the whole tree would: the same watertight test on every
//! triangle the ray could meet, the others out of its reach. A ray outside the reach (a bisection that dips below
//! the horizon, any other caller's ray) goes to the whole tree. Where more than [`LISTED_AT_MOST`] triangles lie in
//! reach, testing them all a ray would cost more than walking the tree, and the point keeps it (CHANGELOG.md has
//! the limit's measurement). A disk light's reach (its bounding ball's cone, wide near the light) holds more, and
//! its grids keep the tree.

use glam::DVec3;

use crate::shading::visibility::SliceReach;
use crate::shading::Occlusion;
use crate::visibility::WatertightRay;

/// The most triangles a point's rays test one by one instead of walking the tree.
pub const LISTED_AT_MOST: usize = 64;

/// The triangles within `reach` of its origin, and the whole set of occluders for the rays outside it.
pub struct ConeOccluders<'a> {
    pub(super) reach: SliceReach,
    pub(super) triangles: Vec<[DVec3; 3]>,
    pub(super) whole: &'a dyn Occlusion,
}

impl ConeOccluders<'_> {
    /// Whether the ray from `origin` along `direction` stays within the reach the triangles were gathered for:
    /// from its origin, into every half-space `above` (its direction's side of each plane through the origin),
    /// and within its cone (a reach bounded otherwise, by `beyond` or a `row`, is not taken).
    fn within(&self, origin: DVec3, direction: DVec3) -> bool {
        let r = &self.reach;
        if origin != r.origin || r.beyond.is_some() || r.row.is_some() {
            return false;
        }
        let above = r.above.iter().all(|&k| direction.dot(k) > 0.0);
        let in_cone = r.cone.is_none_or(|(axis, cos, sin)| {
            // Within the half-angle: along the axis, and the sine of the angle at most the cone's (small angles
            // kept by the cross product, as sphere_meets_cone keeps them).
            let len = direction.length();
            cos > 0.0 && direction.dot(axis) > 0.0 && direction.cross(axis).length() <= sin * len
        });
        above && in_cone
    }
}

impl Occlusion for ConeOccluders<'_> {
    fn occluded(&self, origin: DVec3, direction: DVec3, t_max: f64) -> bool {
        if !self.within(origin, direction) {
            return self.whole.occluded(origin, direction, t_max);
        }
        let Some(ray) = WatertightRay::new(origin, direction) else { return false };
        self.triangles.iter().any(|&t| ray.intersect(t, 0.0, t_max).is_some())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::orthonormal_to;
    use crate::test_rng::uniform;
    use crate::visibility::Bvh;

    /// Uniform numbers in [lo, hi) from a seeded generator.
    struct Rng(Box<dyn FnMut() -> f64>);

    impl Rng {
        fn new(seed: u64) -> Self {
            Rng(Box::new(uniform(seed)))
        }

        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * 0.5 * ((self.0)() + 1.0)
        }
    }

    /// A soup of small triangles over a box, some crossing every cone, so that many rays graze an edge.
    fn soup(rng: &mut Rng, n: usize) -> Vec<[DVec3; 3]> {
        (0..n)
            .map(|_| {
                let c = DVec3::new(rng.range(-2.0, 2.0), rng.range(0.0, 3.0), rng.range(-2.0, 2.0));
                let mut corner =
                    || c + 0.3 * DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
                [corner(), corner(), corner()]
            })
            .collect()
    }

    #[test]
    fn listed_triangles_answer_every_ray_of_the_cone_as_the_tree_does() {
        let mut rng = Rng::new(7);
        let bvh = Bvh::new(soup(&mut rng, 400));
        let (mut rays, mut listed_points, mut blocked) = (0, 0, 0);
        for _ in 0..300 {
            let origin = DVec3::new(rng.range(-2.5, 2.5), rng.range(-0.5, 1.0), rng.range(-2.5, 2.5));
            let l = DVec3::new(rng.range(-1.0, 1.0), rng.range(0.05, 1.0), rng.range(-1.0, 1.0)).normalize();
            let n = DVec3::new(rng.range(-0.3, 0.3), 1.0, rng.range(-0.3, 0.3)).normalize();
            let sigma: f64 = if rng.range(0.0, 1.0) < 0.5 { 0.0046 } else { 0.09 };
            let reach = SliceReach {
                origin,
                above: [n, l],
                cone: Some((l, sigma.cos(), sigma.sin())),
                beyond: None,
                row: None,
            };
            let Some(found) = bvh.within_reach_at_most(&reach, usize::MAX) else { unreachable!() };
            listed_points += 1;
            let near =
                ConeOccluders { reach, triangles: found.iter().map(|&i| bvh.triangle(i)).collect(), whole: &bvh };
            let (t, b) = (orthonormal_to(l), l.cross(orthonormal_to(l)));
            for _ in 0..40 {
                // Over the whole disk, its rim included, as a grid's corners and bisections reach it.
                let (r, phi) = (rng.range(0.0, 1.0).sqrt().min(1.0), rng.range(0.0, std::f64::consts::TAU));
                let d = l + sigma.tan() * r * (phi.cos() * t + phi.sin() * b);
                rays += 1;
                let whole = bvh.occluded(origin, d, f64::INFINITY);
                blocked += usize::from(whole);
                assert_eq!(near.occluded(origin, d, f64::INFINITY), whole, "origin {origin}, direction {d}");
            }
        }
        // Not vacuous: rays blocked and rays through.
        assert!(blocked > rays / 20 && blocked < rays - rays / 20, "{blocked} of {rays} blocked");
        assert_eq!(listed_points, 300);
    }

    #[test]
    fn rays_outside_the_reach_go_to_the_whole_tree() {
        let tri = [DVec3::new(-1.0, 10.0, -1.0), DVec3::new(1.0, 10.0, -1.0), DVec3::new(0.0, 10.0, 1.0)];
        let bvh = Bvh::new(vec![tri]);
        // A cone about +x that misses the triangle overhead: nothing listed, yet a ray straight up is blocked.
        let (o, x) = (DVec3::ZERO, DVec3::X);
        let reach = SliceReach {
            origin: o,
            above: [DVec3::Y, x],
            cone: Some((x, 0.1f64.cos(), 0.1f64.sin())),
            beyond: None,
            row: None,
        };
        assert!(bvh.within_reach_at_most(&reach, 8).unwrap().is_empty());
        let near = ConeOccluders { reach, triangles: Vec::new(), whole: &bvh };
        assert!(near.occluded(o, DVec3::Y, f64::INFINITY));
        assert!(!near.occluded(o, DVec3::new(1.0, 0.05, 0.0), f64::INFINITY));
        // The walk cut short past its limit.
        assert!(bvh.within_reach_at_most(&SliceReach { cone: None, ..reach }, 0).is_none());
    }
}

//! Watertight ray/triangle intersection (Woop, Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1),
//! 2013), in f64.
//!
//! The ray is transformed so that it runs along +z from the origin (a shear, no rotation: the dominant axis of
//! the direction becomes z, the other two are sheared by `S = (dx/dz, dy/dz)`); the triangle's vertices are
//! transformed the same way, and the ray hits it where the 2-D edge functions `U`, `V`, `W` of the projected
//! vertices all have the same sign. The edge function of an edge depends only on that edge's two transformed
//! vertices, computed by the same operations in the same order for both triangles that share it, so a ray through
//! a shared edge sees the same sign from both sides: it cannot slip between them (the point of the paper). A ray
//! exactly on an edge or vertex (an edge function exactly 0) counts as a hit for every triangle that has it.
//!
//! Precision: the shear loses at most a few ulps per coordinate; what matters for watertightness is that the
//! rounding is the same on both sides of an edge, not its size. The paper recomputes edge functions that come out
//! exactly 0 in higher precision to break ties consistently; here a 0 is already a hit for both triangles, which
//! is what shadow rays need (an occluder's shared edge occludes).

use glam::DVec3;

/// A ray precomputed for the watertight test: the permutation of axes and the shear.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub origin: DVec3,
    pub direction: DVec3,
    /// Axis indices: kz is the direction's dominant axis; kx, ky the others, swapped when the direction along kz
    /// is negative so that the winding (the sign of the edge functions) is preserved.
    k: [usize; 3],
    /// Shear `(Sx, Sy, Sz)`.
    shear: [f64; 3],
}

impl WatertightRay {
    /// A ray from `origin` along `direction` (need not be unit; `t` is then in units of its length). `None` for a
    /// zero or non-finite direction.
    pub fn new(origin: DVec3, direction: DVec3) -> Option<Self> {
        if !(direction.is_finite() && origin.is_finite()) || direction == DVec3::ZERO {
            return None;
        }
        let a = direction.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = [direction[kx] / direction[kz], direction[ky] / direction[kz], 1.0 / direction[kz]];
        Some(Self { origin, direction, k: [kx, ky, kz], shear })
    }

    /// The triangle `(a, b, c)` in the ray's sheared frame: the projected corners, the edge functions `(u, v, w)`
    /// and the sheared depths.
    fn shear_triangle(&self, [a, b, c]: [DVec3; 3]) -> Sheared {
        let [kx, ky, kz] = self.k;
        let [sx, sy, sz] = self.shear;
        let (a, b, c) = (a - self.origin, b - self.origin, c - self.origin);
        // Sheared vertices, projected: each depends on its own vertex only.
        let project = |v: DVec3| (v[kx] - sx * v[kz], v[ky] - sy * v[kz]);
        let ((ax, ay), (bx, by), (cx, cy)) = (project(a), project(b), project(c));
        // Edge functions: each depends on one edge's two vertices only (the watertightness argument).
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        Sheared {
            corners: [(ax, ay), (bx, by), (cx, cy)],
            uvw: [u, v, w],
            depths: [sz * a[kz], sz * b[kz], sz * c[kz]],
        }
    }

    /// The ray parameter `t` of the hit with triangle `(a, b, c)` (either winding), if `t_min < t < t_max`.
    pub fn intersect(&self, triangle: [DVec3; 3], t_min: f64, t_max: f64) -> Option<f64> {
        let tri = self.shear_triangle(triangle);
        let [u, v, w] = tri.uvw;
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        // The ray lies in the triangle's plane (or the triangle is degenerate) where det is 0: no proper hit.
        let t = tri.plane_t()?;
        (t > t_min && t < t_max).then_some(t)
    }

    /// The ray parameter of the point where the ray meets the triangle's plane (`None` for a ray in the plane),
    /// whether or not it lies inside.
    pub fn hit_t(&self, triangle: [DVec3; 3]) -> Option<f64> {
        self.shear_triangle(triangle).plane_t()
    }

    /// How far the ray passes from the boundary of the triangle `(a, b, c)`, where it meets the triangle's plane
    /// with `t_min < t < t_max` (`None` otherwise, or for a ray in the plane): in the sheared plane of the test,
    /// each edge function over its edge's length is the distance from the ray to that edge's line \[m\]; positive
    /// inside (the smallest of the three, a hit exactly when [`WatertightRay::intersect`] hits), negative outside
    /// (the largest violation). Used to find rays whose visibility a few ulps of geometry could flip.
    pub fn edge_margin(&self, triangle: [DVec3; 3], t_min: f64, t_max: f64) -> Option<f64> {
        let tri = self.shear_triangle(triangle);
        let t = tri.plane_t()?;
        if !(t > t_min && t < t_max) {
            return None;
        }
        let [u, v, w] = tri.uvw;
        let [(ax, ay), (bx, by), (cx, cy)] = tri.corners;
        let len = |(x0, y0): (f64, f64), (x1, y1): (f64, f64)| ((x1 - x0).powi(2) + (y1 - y0).powi(2)).sqrt();
        let s = (u + v + w).signum();
        let d = [s * u / len((bx, by), (cx, cy)), s * v / len((cx, cy), (ax, ay)), s * w / len((ax, ay), (bx, by))];
        let inside = d.iter().all(|&x| x >= 0.0);
        Some(if inside {
            d.iter().copied().fold(f64::INFINITY, f64::min)
        } else {
            -d.iter().filter(|&&x| x < 0.0).map(|x| -x).fold(0.0, f64::max)
        })
    }
}

/// A triangle in a ray's sheared frame ([`WatertightRay`]).
struct Sheared {
    corners: [(f64, f64); 3],
    uvw: [f64; 3],
    depths: [f64; 3],
}

impl Sheared {
    /// The ray parameter where the ray meets the triangle's plane, from the barycentric combination of the sheared
    /// depths; `None` where `u + v + w` is 0 (the ray in the plane, or a degenerate triangle).
    fn plane_t(&self) -> Option<f64> {
        let [u, v, w] = self.uvw;
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let [az, bz, cz] = self.depths;
        Some((u * az + v * bz + w * cz) / det)
    }
}

/// The GPU's watertight test (shaders/ray_triangle.glsl's `watertight_ray` and `intersect`, without ray queries),
/// in f32 as the shader computes it, unfused: whether the ray from `origin` along `direction` meets the triangle
/// with `0 < t < t_max`, and the hit's barycentrics of its second and third corners.
pub fn intersect_f32(origin: [f32; 3], direction: [f32; 3], [a, b, c]: [[f32; 3]; 3], t_max: f32) -> Option<[f32; 2]> {
    let d = direction;
    let m = d.map(f32::abs);
    let kz = if m[0] >= m[1] && m[0] >= m[2] {
        0
    } else if m[1] >= m[2] {
        1
    } else {
        2
    };
    let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let (sx, sy, sz) = (d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
    let rel = |v: [f32; 3]| [v[0] - origin[0], v[1] - origin[1], v[2] - origin[2]];
    let (pa, pb, pc) = (rel(a), rel(b), rel(c));
    let project = |p: [f32; 3]| (p[kx] - sx * p[kz], p[ky] - sy * p[kz]);
    let ((ax, ay), (bx, by), (cx, cy)) = (project(pa), project(pb), project(pc));
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let t = (u * (sz * pa[kz]) + v * (sz * pb[kz]) + w * (sz * pc[kz])) / det;
    (t > 0.0 && t < t_max).then_some([v / det, w / det])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_misses_outside_either_winding_and_any_direction() {
        let tri = [DVec3::new(0.0, 0.0, 5.0), DVec3::new(1.0, 0.0, 5.0), DVec3::new(0.0, 1.0, 5.0)];
        let flipped = [tri[0], tri[2], tri[1]];
        for dir in [DVec3::Z, DVec3::new(0.02, 0.03, 1.0)] {
            let r = WatertightRay::new(DVec3::new(0.2, 0.2, 0.0), dir).unwrap();
            let t = r.intersect(tri, 0.0, f64::INFINITY).expect("hit");
            assert!(((r.origin + r.direction * t).z - 5.0).abs() < 1e-12, "the hit lies in the plane z = 5");
            assert_eq!(r.intersect(flipped, 0.0, f64::INFINITY), Some(t));
        }
        let miss = WatertightRay::new(DVec3::new(0.8, 0.8, 0.0), DVec3::Z).unwrap();
        assert_eq!(miss.intersect(tri, 0.0, f64::INFINITY), None);
        // Behind the origin, and past t_max.
        let back = WatertightRay::new(DVec3::new(0.2, 0.2, 0.0), -DVec3::Z).unwrap();
        assert_eq!(back.intersect(tri, 0.0, f64::INFINITY), None);
        let short = WatertightRay::new(DVec3::new(0.2, 0.2, 0.0), DVec3::Z).unwrap();
        assert_eq!(short.intersect(tri, 0.0, 4.999), None);
        assert_eq!(short.intersect(tri, 0.0, 5.001), Some(5.0));
        // Every dominant axis, both signs.
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            for s in [1.0, -1.0] {
                let d = axis * s;
                let far = d * 3.0;
                let (u, v) = (d.any_orthonormal_pair().0, d.any_orthonormal_pair().1);
                let t = [far - u - v, far + 2.0 * u - v, far - u + 2.0 * v];
                let r = WatertightRay::new(DVec3::ZERO, d).unwrap();
                assert!((r.intersect(t, 0.0, f64::INFINITY).unwrap() - 3.0).abs() < 1e-12, "axis {d}");
            }
        }
        assert!(WatertightRay::new(DVec3::ZERO, DVec3::ZERO).is_none());
        assert!(WatertightRay::new(DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 1.0)).is_none());
    }

    #[test]
    fn rays_through_shared_edges_and_vertices_never_slip_through() {
        // A fan of thin triangles around one vertex: rays aimed exactly at the shared centre and at points along
        // every shared (inner) edge must hit at least one triangle. (The ring's vertices lie on the fan's open
        // boundary, where a ray may rightly pass outside.)
        let n = 97;
        let centre = DVec3::new(0.3, -0.2, 10.0);
        let ring: Vec<DVec3> = (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                centre + DVec3::new(a.cos() * 3.7, a.sin() * 2.3, 0.4 * (3.0 * a).sin())
            })
            .collect();
        let tris: Vec<[DVec3; 3]> = (0..n).map(|i| [centre, ring[i], ring[(i + 1) % n]]).collect();
        let origin = DVec3::new(0.011, 0.017, -0.5);
        let mut aims = vec![centre];
        for &r in &ring {
            for k in 1..8 {
                let f = k as f64 / 8.0;
                aims.push(centre.lerp(r, f));
            }
        }
        for aim in aims {
            let r = WatertightRay::new(origin, aim - origin).unwrap();
            assert!(tris.iter().any(|&t| r.intersect(t, 0.0, 2.0).is_some()), "slipped through at {aim}");
        }
    }

    /// The GPU's f32 test (shaders/ray_triangle.glsl, mirrored by `intersect_f32`) is watertight too: the fan's shared
    /// edges and centre, in f32, never let a ray through.
    #[test]
    fn the_f32_test_is_watertight_on_the_fan() {
        let n = 97;
        let centre = [0.3f32, -0.2, 10.0];
        let ring: Vec<[f32; 3]> = (0..n)
            .map(|i| {
                let a = i as f32 / n as f32 * std::f32::consts::TAU;
                [centre[0] + a.cos() * 3.7, centre[1] + a.sin() * 2.3, centre[2] + 0.4 * (3.0 * a).sin()]
            })
            .collect();
        let tris: Vec<[[f32; 3]; 3]> = (0..n).map(|i| [centre, ring[i], ring[(i + 1) % n]]).collect();
        let origin = [0.011f32, 0.017, -0.5];
        let mut aims = vec![centre];
        for r in &ring {
            for k in 1..8 {
                let f = k as f32 / 8.0;
                aims.push([0, 1, 2].map(|c| centre[c] + f * (r[c] - centre[c])));
            }
        }
        for aim in aims {
            let d = [0, 1, 2].map(|c| aim[c] - origin[c]);
            assert!(tris.iter().any(|&t| intersect_f32(origin, d, t, 2.0).is_some()), "slipped through at {aim:?}");
        }
    }

    /// The f32 test answers as the f64 one for rays that pass farther than 2⁻¹⁸ of the triangle's size from its
    /// boundary (the reference's "fragile" margin), on random triangles and rays; its barycentrics are the hit's.
    #[test]
    fn the_f32_test_agrees_with_f64_away_from_edges() {
        let mut next = crate::test_rng::uniform(0x2545_f491_4f6c_dd1d);
        let (mut checked, mut hits) = (0, 0);
        for _ in 0..200_000 {
            let scale = 10f64.powf(3.0 * next());
            let v = |n: &mut dyn FnMut() -> f64| DVec3::new(n(), n(), n()) * scale;
            let tri32 = [v(&mut next), v(&mut next), v(&mut next)].map(|p| p.as_vec3().to_array());
            let tri = tri32.map(|p| DVec3::from_array(p.map(f64::from)));
            let origin32 = v(&mut next).as_vec3().to_array();
            let dir32 = DVec3::new(next(), next(), next()).as_vec3().to_array();
            let (origin, dir) = (DVec3::from_array(origin32.map(f64::from)), DVec3::from_array(dir32.map(f64::from)));
            let Some(ray) = WatertightRay::new(origin, dir) else { continue };
            let size = (tri[1] - tri[0]).length().max((tri[2] - tri[0]).length());
            let margin = ray.edge_margin(tri, 0.0, 1e30);
            // Rays within the margin of an edge, or meeting the plane near the origin, may go either way.
            let t = ray.hit_t(tri).unwrap_or(0.0);
            if margin.is_some_and(|m| m.abs() <= size / 262_144.0) || t.abs() < 1e-4 * scale {
                continue;
            }
            let f64_hit = ray.intersect(tri, 0.0, 1e30).is_some();
            let f32_hit = intersect_f32(origin32, dir32, tri32, 1e30);
            assert_eq!(f64_hit, f32_hit.is_some(), "{tri:?} from {origin} along {dir}");
            if let Some([b1, b2]) = f32_hit {
                let at = tri[0] + (tri[1] - tri[0]) * b1 as f64 + (tri[2] - tri[0]) * b2 as f64;
                let along = origin + dir * t;
                assert!((at - along).length() <= 1e-3 * size.max(along.length()), "barycentrics {b1} {b2}");
                hits += 1;
            }
            checked += 1;
        }
        assert!(checked > 150_000 && hits > 5_000, "{checked} checked, {hits} hits");
    }
}

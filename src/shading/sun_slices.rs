//! The sun's visible fraction by slices: the sky's rule (`sky_slices`) on the sun's disk, for the reference's
//! truth in the sun's penumbrae, where a grid of rays converges slowly. No GPU mirror.
//!
//! The sun is the cap of half-angle `σ = δ/2` about `l`. The slices are half great circles through an axis
//! `c ⊥ l` ([`sun_slice_axis`]): `ω(β, ψ) = cos β c + sin β p(ψ)`, `p(ψ) = cos ψ l + sin ψ q`, `q = c × l`, so that
//! `ω·l = sin β cos ψ`: only the slices with `|ψ| ≤ σ` meet the cap, each in the chord
//! `β ∈ [π/2 − χ, π/2 + χ]`, `cos χ = cos σ / cos ψ`. Each chord is cut by the surface's horizon ([`above`]) and
//! by the intervals the occluding triangles in its plane block ([`blocked_interval`]; the sun is infinitely far,
//! so a triangle anywhere in front blocks), and its visible share of `(n·ω) sin β dβ` is closed-form
//! ([`visible_weight`](super::sky_slices::visible_weight)). Along `ψ` the chords' lengths fall to zero at `±σ`
//! like a square root; with `ψ = −σ cos u` (`dψ = σ sin u du`) the integrand over `u ∈ [0, π]` is smooth where no
//! occluder's outline is, and midpoints in `u` converge at the second order in the rows, as the sky's do.
//!
//! Why an axis across the sun rather than through it: slices through `l` would make every occluder edge whose
//! line passes through the sun's centre (seen from the point) a jump of the rows' integrand, at the middle of
//! every penumbra; across it, an edge is a jump only where its great circle passes through `±c`, 90° from the sun.
//!
//! The weight is the grid's (`visibility::sun_sample`: `(n·ω)⁺` per solid angle), so both rules estimate the same
//! fraction.

use std::f64::consts::FRAC_PI_2;

use glam::DVec3;

use super::sky_slices::{
    above, blocked_interval, cosine_rows, row_visible_weight, sliced_fraction, weight_integral, CosineRow, SLICE_AXIS,
};
use super::slice_buckets::frame_about;
use super::visibility::{Shadowing, SliceReach};

/// The slices' axis for the sun in direction `l`: the sky's oblique axis ([`SLICE_AXIS`]) made perpendicular to
/// `l` (or `x̂`'s, where `l` is nearly that axis).
pub fn sun_slice_axis(l: DVec3) -> DVec3 {
    let a = DVec3::from_array(SLICE_AXIS);
    let c = a - a.dot(l) * l;
    if c.length_squared() > 1e-6 {
        c.normalize()
    } else {
        (DVec3::X - l.x * l).normalize()
    }
}

/// The half-width χ of the chord at `ψ` (`|ψ| < σ`): `cos χ = cos σ / cos ψ`, as
/// `sin²(χ/2) = sin((σ + ψ)/2) sin((σ − ψ)/2) / cos ψ`, which keeps its digits for the sun's half-degree where
/// `acos` of a ratio within 1e-5 of 1 would keep half of them.
pub fn chord_half_width(sigma: f64, psi: f64) -> f64 {
    let s2 = (0.5 * (sigma + psi)).sin() * (0.5 * (sigma - psi)).sin() / psi.cos();
    2.0 * s2.max(0.0).sqrt().asin()
}

/// The sun's cosine-weighted visible fraction from `s.origin` on a surface of unit normal `n`, the sun in unit
/// direction `l` with angular diameter `angular_diameter` \[rad\], by `rows` slices (module text); `None` where
/// the occluders cannot be sliced (alpha masks). 1 where no row meets an occluder, and where the sun gives
/// nothing (wholly below the surface's horizon).
pub fn sun_visible_fraction_sliced(s: &Shadowing, n: DVec3, l: DVec3, angular_diameter: f64, rows: u32) -> Option<f64> {
    let sigma = 0.5 * angular_diameter;
    let c = sun_slice_axis(l);
    let q = c.cross(l);
    // One walk over the sun's cone, each triangle filed under the rows its arc about the axis holds
    // (`slice_buckets`); the rows, ψ = −σ cos u ascending, made only where the walk keeps a triangle.
    let cone = Some((l, sigma.cos(), sigma.sin()));
    let reach = SliceReach { origin: s.origin, above: [n, l], cone, beyond: None };
    let rows = || cosine_rows(l, q, (0.0, sigma), rows.max(1));
    sliced_fraction(
        s,
        &reach,
        |_| true,
        (frame_about(l, q), rows, |r: &CosineRow| r.p),
        |i, row, buckets, blocked| {
            let &CosineRow { sin_u, psi, p, .. } = row;
            let jacobian = sigma * sin_u;
            let chi = chord_half_width(sigma, psi);
            let surface = above(n, c, p);
            let span = ((FRAC_PI_2 - chi).max(surface.0), (FRAC_PI_2 + chi).min(surface.1));
            let (n_c, n_p) = (n.dot(c), n.dot(p));
            let unscaled = weight_integral(n_c, n_p, span.0, span.1);
            let whole = jacobian * unscaled;
            if whole <= 0.0 {
                return None;
            }
            let m = c.cross(p);
            let row = buckets.row(i).filter_map(|&tri| blocked_interval(tri, c, p, m));
            Some((jacobian * row_visible_weight(row, (n_c, n_p), (span, unscaled), blocked), whole))
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::visibility::{sun_visible_fraction, test_shadowing};
    use crate::shading::{Occlusion, Unoccluded};
    use crate::visibility::Bvh;

    fn shadowing(occ: &dyn Occlusion, k: u32) -> Shadowing<'_> {
        test_shadowing(occ, DVec3::ZERO, k)
    }

    /// A wall's edge: the half-plane `{x = 1, y < h}` (two triangles reaching 1e4 m) seen from the origin, the
    /// sun low in the +x direction.
    fn wall(h: f64, tilt: f64) -> Bvh {
        // The edge runs along (0, sin tilt, cos tilt) through (1, h, 0); the wall lies below it.
        let along = DVec3::new(0.0, tilt.sin(), tilt.cos());
        let down = DVec3::new(0.0, -tilt.cos(), tilt.sin());
        let e = DVec3::new(1.0, h, 0.0);
        let r = 1e4;
        let (a, b) = (e - r * along, e + r * along);
        let (c, d) = (b + r * down, a + r * down);
        Bvh::new(vec![[a, b, c], [a, c, d]])
    }

    #[test]
    fn chord_half_width_keeps_its_digits() {
        let sigma = 0.5 * 0.53f64.to_radians();
        for psi in [0.0, 0.3 * sigma, -0.9 * sigma, 0.999 * sigma] {
            let textbook = (sigma.cos() / psi.cos()).acos();
            let want = (sigma * sigma - psi * psi).sqrt(); // the flat limit, within σ² relative
            let got = chord_half_width(sigma, psi);
            assert!((got / want - 1.0).abs() < 1e-5, "{psi}: {got} against {want}");
            assert!((got - textbook).abs() < 1e-9, "{psi}: {got} against acos's {textbook}");
        }
    }

    #[test]
    fn the_sun_half_hidden_by_a_straight_edge_through_its_centre_is_half_seen() {
        // An edge through the sun's centre splits its disk in two halves; on a surface facing the sun the cosine
        // weight is symmetric about the edge to first order, so the fraction is ½ to within the disk's σ.
        let delta = 0.53f64.to_radians();
        for tilt in [0.0, 0.7, 1.3] {
            let occ = wall(0.0, tilt);
            let v = sun_visible_fraction_sliced(&shadowing(&occ, 6), DVec3::X, DVec3::X, delta, 256).unwrap();
            assert!((v - 0.5).abs() < 1e-6, "tilt {tilt}: {v}");
        }
    }

    #[test]
    fn slices_agree_with_the_located_grid_across_a_penumbra() {
        // The wall's edge at heights across the sun's disk (a penumbra), edges at several angles, surfaces facing
        // the sun and grazing it: the located grid at 512² (second order) against 1024 slices.
        let delta = 0.53f64.to_radians();
        let sigma = 0.5 * delta;
        let sun = DVec3::X;
        for tilt in [0.2, 0.9] {
            for h in [-0.8 * sigma, -0.3 * sigma, 0.5 * sigma] {
                let occ = wall(h, tilt);
                for n in [DVec3::X, DVec3::new(0.01, 1.0, 0.3).normalize()] {
                    let grid = sun_visible_fraction(&shadowing(&occ, 512), n, sun, delta);
                    let sliced = sun_visible_fraction_sliced(&shadowing(&occ, 6), n, sun, delta, 1024).unwrap();
                    assert!((grid - sliced).abs() < 2e-5, "tilt {tilt} h {h} n {n}: grid {grid} slices {sliced}");
                    assert!(sliced > 0.0 && sliced < 1.0, "a penumbra: {sliced}");
                }
            }
        }
        // Nothing in front: exactly 1.
        assert_eq!(sun_visible_fraction_sliced(&shadowing(&Unoccluded, 6), DVec3::Y, sun, delta, 64), Some(1.0));
    }
}

//! The sun's visible fraction by slices: the sky's rule (`sky_slices`) on the sun's disk, for the reference's
//! truth in the sun's penumbrae, where a grid of rays converges slowly; the GPU's too, where its fragment shader
//! walks the occluders' BVH (below).
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
//!
//! **On the GPU** (shaders/slices.glsl, where the fragment shader walks the occluders' BVH): the same rows,
//! chords and intervals in f32, the chords measured from their middle (`slices_about_centre`), and each gathered
//! triangle cut only in the rows of its azimuth range ([`slice_row_range`], where this file files triangles under
//! rows by `slice_buckets`' diamond-angle arcs).

use std::f64::consts::FRAC_PI_2;

use glam::DVec3;

use super::sky_slices::{
    above, blocked_interval, cosine_rows, row_visible_weight, rows_fraction, sliced_rows_weights, weight_integral,
    CosineRow, SLICE_AXIS,
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

/// The real index `u rows / π − ½` of the row (of `rows` along `ψ = −σ cos u`, row `i` at `u = π (i + ½) / rows`)
/// through the direction ψ, clamped to the rows' range: `cos u = −ψ/σ`.
pub fn row_of_psi(psi: f64, sigma: f64, rows: u32) -> f64 {
    let x = (-psi / sigma).clamp(-1.0, 1.0);
    x.acos() * rows as f64 / std::f64::consts::PI - 0.5
}

/// The rows (of `rows` along `ψ = ψ_mid − ψ_half cos u` in the frame `(h, q)` across the slicing axis: the sun's
/// with `(0, σ)`, a disk light's with its `psi_range`) whose half-plane may cut the triangle `tri` (corners
/// relative to the rays' origin \[m\]), as `(first, last)`, or `None` where none can: its azimuth range about the
/// axis, `ψ = atan((x·q)/(x·h))` over its corners, where every corner lies in front (`x·h > 0`: the projection
/// along the axis then lies in the half-plane `x·h > 0`, where the azimuths seen from the origin form an
/// interval), every row otherwise; widened by a row each side (floor and ceiling) for rounding. The GPU's filing of
/// triangles under rows (shaders/slices.glsl).
pub fn slice_row_range(
    tri: &[DVec3; 3],
    h: DVec3,
    q: DVec3,
    (psi_mid, psi_half): (f64, f64),
    rows: u32,
) -> Option<(u32, u32)> {
    let last = rows.max(1) - 1;
    let along = tri.map(|x| x.dot(h));
    if along.iter().any(|&a| a <= 0.0) {
        return Some((0, last));
    }
    let tau = [0, 1, 2].map(|j| tri[j].dot(q) / along[j]);
    let psi_lo = tau.iter().copied().fold(f64::INFINITY, f64::min).atan() - psi_mid;
    let psi_hi = tau.iter().copied().fold(f64::NEG_INFINITY, f64::max).atan() - psi_mid;
    if psi_lo > psi_half || psi_hi < -psi_half {
        return None;
    }
    let index = |r: f64| r.clamp(0.0, last as f64) as u32;
    Some((index(row_of_psi(psi_lo, psi_half, rows).floor()), index(row_of_psi(psi_hi, psi_half, rows).ceil())))
}

/// The sun's cosine-weighted visible fraction from `s.origin` on a surface of unit normal `n`, the sun in unit
/// direction `l` with angular diameter `angular_diameter` \[rad\], by `rows` slices (module text); `None` where
/// the occluders cannot be sliced (alpha masks). 1 where no row meets an occluder, and where the sun gives
/// nothing (wholly below the surface's horizon).
pub fn sun_visible_fraction_sliced(s: &Shadowing, n: DVec3, l: DVec3, angular_diameter: f64, rows: u32) -> Option<f64> {
    let rows = rows.max(1);
    let (visible, total) = sun_rows_weights(s, n, l, angular_diameter, rows, 0, rows)?;
    Some(rows_fraction(visible, total))
}

/// What the sun's rays from `origin` (on a surface of normal `n`) within `sigma` \[rad\] of `l` can meet: the
/// half-spaces above the surface and towards the sun, and that cone.
pub fn sun_reach(origin: DVec3, n: DVec3, l: DVec3, sigma: f64) -> SliceReach {
    SliceReach { origin, above: [n, l], cone: Some((l, sigma.cos(), sigma.sin())), beyond: None, row: None }
}

/// The rows `first .. first + count` of [`sun_visible_fraction_sliced`]'s `rows`: their cosine-weighted visible and
/// unoccluded weights ([`sliced_rows_weights`]), the GPU's unit of work where one fragment cannot take every row
/// (`gpu::slice_passes`).
pub fn sun_rows_weights(
    s: &Shadowing,
    n: DVec3,
    l: DVec3,
    angular_diameter: f64,
    rows: u32,
    first: u32,
    count: u32,
) -> Option<(f64, f64)> {
    let sigma = 0.5 * angular_diameter;
    let c = sun_slice_axis(l);
    let q = c.cross(l);
    // One walk over the sun's cone, each triangle filed under the rows its arc about the axis holds
    // (`slice_buckets`); the rows, ψ = −σ cos u ascending, made only where the walk keeps a triangle.
    let reach = sun_reach(s.origin, n, l, sigma);
    let rows = || cosine_rows(l, q, (0.0, sigma), rows.max(1));
    sliced_rows_weights(
        s,
        &reach,
        |_| true,
        (frame_about(l, q), rows, |r: &CosineRow| r.p),
        first..first + count,
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
    use crate::shading::lights::sun::sun_visible_fraction;
    use crate::shading::visibility::test_shadowing;
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
    fn a_triangle_is_cut_only_by_the_rows_of_its_range() {
        // Random small and large triangles about the rows' middle (the sun's rows and a disk light's): every row
        // whose half-plane cuts one (the exact test, `slice_segment` with t ≥ 0) lies in its range, and the ranges
        // leave rows out.
        use crate::shading::sky_slices::{cosine_rows, slice_segment};
        let mut next = crate::test_rng::uniform(17);
        let l = DVec3::new(0.3, 0.4, -0.2).normalize();
        let c = sun_slice_axis(l);
        let q = c.cross(l);
        let sigma = 0.5 * 0.53f64.to_radians();
        let rows = 64;
        // The sun's rows, and a disk light's off-centre ones.
        for (mid, half) in [(0.0, sigma), (0.3, 0.1)] {
            let made = cosine_rows(l, q, (mid, half), rows);
            let (mut cut, mut left_out) = (0, 0);
            for _ in 0..3000 {
                let dist = 1.0 + 20.0 * next().abs();
                let size = if next() > 0.0 { 0.002 * dist * next().abs() } else { 2.0 * next().abs() };
                let p_mid = mid.cos() * l + mid.sin() * q;
                let centre = dist * p_mid + 2.0 * half * dist * (next() * q + next() * c);
                let tri = [0; 3].map(|_| centre + size * DVec3::new(next(), next(), next()));
                let range = slice_row_range(&tri, l, q, (mid, half), rows);
                for (i, r) in made.iter().enumerate() {
                    let m = c.cross(r.p);
                    let hit = slice_segment(tri, c, r.p, m).is_some_and(|[a, b]| a.1 > 0.0 || b.1 > 0.0);
                    let inside = range.is_some_and(|(lo, hi)| (lo as usize..=hi as usize).contains(&i));
                    assert!(!hit || inside, "row {i} cuts {tri:?} outside its range {range:?}");
                    cut += usize::from(hit);
                    left_out += usize::from(!inside);
                }
            }
            assert!(cut > 10_000 && left_out > 10_000, "({mid}, {half}): {cut} cuts, {left_out} rows left out");
        }
    }

    #[test]
    fn row_of_psi_inverts_the_rows() {
        let sigma = 0.0046;
        let rows = 100;
        for i in 0..rows {
            let u = std::f64::consts::PI * (i as f64 + 0.5) / rows as f64;
            assert!((row_of_psi(-sigma * u.cos(), sigma, rows) - i as f64).abs() < 1e-9, "{i}");
        }
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

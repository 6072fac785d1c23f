//! A disk light's visible fraction by slices: the sky's rule (`sky_slices`) on a disk at a finite distance, for the
//! reference's truth in its penumbrae. No GPU mirror.
//!
//! The disk (centre `C`, unit emission direction `d`, radius `R` \[m\]) is seen from the rays' origin `o` at
//! `D = C − o`. The slices are the planes through `o` that hold an axis `c ⊥ D` ([`super::sun_slices::sun_slice_axis`] of
//! `D̂`): in-plane directions `ω(β) = cos β c + sin β p(ψ)`, `p(ψ) = cos ψ D̂ + sin ψ q`, `q = c × D̂`, normal
//! `m(ψ) = cos ψ q − sin ψ D̂`. A plane meets the disk where `|m·D| ≤ R √(1 − (m·d)²)`, a quadratic form in
//! `(cos ψ, sin ψ)` that is negative on one interval `[ψ₀, ψ₁]` about 0 ([`psi_range`]); there it cuts the disk in
//! a chord ([`chord`]), which spans an interval of β. An occluding triangle blocks the part of that interval that
//! its segment in the plane subtends *before* the chord: the segment is clipped to the chord line's near side
//! first, the line drawn `1 − 2⁻¹²` of the way from `o`, as the grid's rays to the disk end short of it
//! (`visibility::SEGMENT_T_MAX`), so that a ceiling around a skylight does not block it. The weight is the grid's,
//! `(n·ω)⁺` per solid angle (`visibility::disk_sample`'s `(n·ω)⁺ (−d·ω)⁺ / |y − x|²` per area), closed-form along
//! the chord ([`visible_weight`](super::sky_slices::visible_weight)); the rows run along
//! `ψ = ψ_mid − ψ_half cos u` so that the chords' square-root ends leave a smooth integrand, midpoints in `u`.
//!
//! Weights are taken from `o`, the grid's from the shading point (which `o` is pushed off by `2⁻¹⁶` of the
//! coordinates): the two fractions differ by that much of the weight's variation across the disk, far below what
//! either rule resolves.

use glam::DVec3;

use super::sky_slices::{
    above, clip_segment, cosine_rows, row_visible_weight, rows_fraction, segment_interval, slice_segment,
    sliced_rows_weights, weight_integral, CosineRow,
};
use super::slice_buckets::frame_about;
use super::sun_slices::sun_slice_axis;
use super::visibility::{Shadowing, SliceReach};

/// The share of the way to the disk where the rays end (`visibility::SEGMENT_T_MAX`).
const SEGMENT_T_MAX: f64 = 1.0 - 1.0 / 4096.0;

/// The interval `[ψ₀, ψ₁]` of slices that meet the disk (module text): where
/// `A cos²ψ + 2B cos ψ sin ψ + C sin²ψ ≤ 0` with `A = R²((q·d)² − 1)`, `B = −R² (q·d)(D̂·d)`,
/// `C = |D|² − R² (1 − (D̂·d)²)`, by the roots of `A + 2B t + C t²` in `t = tan ψ` (the product of the roots
/// `A/C` gives the second without cancellation). `None` where `C ≤ 0` (the origin within the disk's own reach).
pub fn psi_range(dist: f64, radius: f64, q_d: f64, dhat_d: f64) -> Option<(f64, f64)> {
    let r2 = radius * radius;
    let a = r2 * (q_d * q_d - 1.0);
    let b = -r2 * q_d * dhat_d;
    let c = dist * dist - r2 * (1.0 - dhat_d * dhat_d);
    if c <= 0.0 {
        return None;
    }
    let disc = (b * b - a * c).max(0.0);
    let t1 = (-b - b.signum() * disc.sqrt()) / c;
    let t2 = if t1 != 0.0 { a / (c * t1) } else { -2.0 * b / c };
    let (t_lo, t_hi) = (t1.min(t2), t1.max(t2));
    Some((t_lo.atan(), t_hi.atan()))
}

/// The chord in which the plane through `o` (the origin of `D`) of unit normal `m` cuts the disk: its ends
/// relative to `o` \[m\], or `None` where it misses it (or the disk lies in the plane).
pub fn chord(d_vec: DVec3, d: DVec3, radius: f64, m: DVec3) -> Option<[DVec3; 2]> {
    let d_m = d.dot(m);
    let across = 1.0 - d_m * d_m;
    if across <= 0.0 {
        return None;
    }
    let dm = d_vec.dot(m);
    // The point of the line (plane ∩ disk's plane) nearest the centre, and the half chord.
    let alpha = -dm / across;
    let foot = d_vec + alpha * (m - d_m * d);
    let half2 = radius * radius - dm * dm / across;
    if half2 <= 0.0 {
        return None;
    }
    let along = m.cross(d).normalize();
    let half = half2.sqrt();
    Some([foot - half * along, foot + half * along])
}

/// The visible fraction of the disk light (centre \[m\], unit emission direction `d`, radius \[m\]) from `s.origin`
/// on a surface of unit normal `n`, weighted by projected solid angle, by `rows` slices (module text); `None` where
/// the occluders cannot be sliced (alpha masks) or the origin is too near the disk for the slices' range. 1 where
/// no row meets an occluder before the disk, and where the disk gives nothing (seen from behind, or below the
/// surface's horizon).
pub fn disk_visible_fraction_sliced(
    s: &Shadowing,
    n: DVec3,
    center: DVec3,
    d: DVec3,
    radius: f64,
    rows: u32,
) -> Option<f64> {
    let rows = rows.max(1);
    let (visible, total) = disk_rows_weights(s, n, (center, d, radius), rows, 0, rows)?;
    Some(rows_fraction(visible, total))
}

/// The rows `first .. first + count` of [`disk_visible_fraction_sliced`]'s `rows` for the disk `(centre, d,
/// radius)`: their visible and unoccluded weights ([`sliced_rows_weights`]; `(0, 0)` where the disk gives nothing),
/// the GPU's unit of work where one fragment cannot take every row (`gpu::slice_passes`).
pub fn disk_rows_weights(
    s: &Shadowing,
    n: DVec3,
    (center, d, radius): (DVec3, DVec3, f64),
    rows: u32,
    first: u32,
    count: u32,
) -> Option<(f64, f64)> {
    let d_vec = center - s.origin;
    let dist = d_vec.length();
    // Seen from behind its emitting side, the disk gives nothing (the grid's weights are all 0 there).
    // (A NaN from a non-finite disk reads as behind: nothing to weigh.)
    let in_front = d.dot(d_vec) < 0.0 && dist > 0.0;
    if !in_front {
        return Some((0.0, 0.0));
    }
    let dhat = d_vec / dist;
    let c = sun_slice_axis(dhat);
    let q = c.cross(dhat);
    let (psi0, psi1) = psi_range(dist, radius, q.dot(d), dhat.dot(d))?;
    let (mid, half) = (0.5 * (psi0 + psi1), 0.5 * (psi1 - psi0));
    // The cone about D̂ that holds the disk's bounding sphere, where the origin is outside it.
    let cone = (dist > radius).then(|| {
        let sin = radius / dist;
        (dhat, (1.0 - sin * sin).sqrt(), sin)
    });
    // Only a triangle with a corner before where the rays end can block: `d·(x − C) > 2⁻¹² d·(o − C)` (a ray's
    // points have `d·(x − C) = (1 − t) d·(o − C)`, `t < 1 − 2⁻¹²`); a ceiling in the disk's plane has none.
    // (Corners relative to `o`: `x − C = x_rel − D`.)
    let before = |tri: &[DVec3; 3]| tri.iter().any(|&x| d.dot(x - d_vec) > (1.0 - SEGMENT_T_MAX) * -d.dot(d_vec));
    let beyond = Some((d, SEGMENT_T_MAX * d.dot(d_vec)));
    // One walk over the cone, each triangle filed under the rows its arc about the axis holds (`slice_buckets`);
    // only triangles with a corner before the rays' ends kept; the rows, ψ = mid − half cos u ascending, made only
    // where the walk keeps one.
    let reach = SliceReach { origin: s.origin, above: [n, dhat], cone, beyond, row: None };
    let rows = || cosine_rows(dhat, q, (mid, half), rows.max(1));
    let frame = (frame_about(dhat, q), rows, |r: &CosineRow| r.p);
    sliced_rows_weights(s, &reach, before, frame, first..first + count, |i, row, buckets, blocked| {
        let &CosineRow { sin_u, sin_psi: sin_p, cos_psi: cos_p, p, .. } = row;
        let jacobian = half * sin_u;
        let m = cos_p * q - sin_p * dhat;
        let [y0, y1] = chord(d_vec, d, radius, m)?;
        let in_plane = |y: DVec3| (y.dot(c), y.dot(p));
        let (e0, e1) = (in_plane(y0), in_plane(y1));
        let angle = |(s, t): (f64, f64)| t.max(0.0).atan2(s);
        let (b0, b1) = (angle(e0), angle(e1));
        let surface = above(n, c, p);
        let span = (b0.min(b1).max(surface.0), b0.max(b1).min(surface.1));
        let (n_c, n_p) = (n.dot(c), n.dot(p));
        let unscaled = weight_integral(n_c, n_p, span.0, span.1);
        let whole = jacobian * unscaled;
        if whole <= 0.0 {
            return None;
        }
        // The chord's line `a·(s, t) = b` (a its normal, towards the far side), pulled in to where the rays end.
        let a = (e1.1 - e0.1, e0.0 - e1.0);
        let b_line = a.0 * e0.0 + a.1 * e0.1;
        let (a, b_line) = if b_line < 0.0 { ((-a.0, -a.1), -b_line) } else { (a, b_line) };
        let b_line = SEGMENT_T_MAX * b_line;
        let row = buckets.row(i).filter_map(|&tri| {
            slice_segment(tri, c, p, m).and_then(|g| clip_segment(g, a, b_line)).and_then(segment_interval)
        });
        Some((jacobian * row_visible_weight(row, (n_c, n_p), (span, unscaled), blocked), whole))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::lights::disk::disk_visible_fraction;
    use crate::shading::sun_slices::{sun_rows_weights, sun_visible_fraction_sliced};
    use crate::shading::visibility::test_shadowing;
    use crate::shading::{Occlusion, Unoccluded};
    use crate::visibility::Bvh;

    fn shadowing(occ: &dyn Occlusion, origin: DVec3, k: u32) -> Shadowing<'_> {
        test_shadowing(occ, origin, k)
    }

    /// A square plate of side `2h` at height `y`, centred at `(x, y, z)`.
    fn plate(x: f64, y: f64, z: f64, h: f64) -> Bvh {
        let c = |dx: f64, dz: f64| DVec3::new(x + dx, y, z + dz);
        Bvh::new(vec![[c(-h, -h), c(h, -h), c(h, h)], [c(-h, -h), c(h, h), c(-h, h)]])
    }

    #[test]
    fn the_slices_range_and_chords_cover_the_disk_exactly() {
        // Unoccluded, every slice rule gives exactly 1; and the rows' total weight is the disk's projected solid
        // angle, within the rule's error, for disks seen square on and obliquely.
        let o = DVec3::new(0.3, 0.0, -0.2);
        for (center, d) in [
            (DVec3::new(0.0, 2.0, 0.0), -DVec3::Y),
            (DVec3::new(1.0, 1.5, 0.5), DVec3::new(-0.3, -1.0, 0.2).normalize()),
        ] {
            let v = disk_visible_fraction_sliced(&shadowing(&Unoccluded, o, 6), DVec3::Y, center, d, 0.6, 64);
            assert_eq!(v, Some(1.0));
        }
        // Seen from behind: nothing to weigh.
        let v =
            disk_visible_fraction_sliced(&shadowing(&Unoccluded, o, 6), DVec3::Y, DVec3::Y * 2.0, DVec3::Y, 0.6, 64);
        assert_eq!(v, Some(1.0));
    }

    #[test]
    fn slices_agree_with_the_located_grid_under_a_plate() {
        // A skylight of radius 0.6 m at 2 m, a plate at 1 m partly under it, points around its shadow: the located
        // grid at 512² (second order) against 1024 slices.
        let center = DVec3::new(0.0, 2.0, 0.0);
        let mut partial = 0;
        for (d, px) in [(-DVec3::Y, 0.35), (DVec3::new(-0.3, -1.0, 0.2).normalize(), 0.1)] {
            let occ = plate(px, 1.0, 0.1, 0.5);
            for ox in [-0.4, 0.0, 0.3, 0.9] {
                let o = DVec3::new(ox, 0.0, 0.05);
                for n in [DVec3::Y, DVec3::new(0.4, 1.0, -0.2).normalize()] {
                    let grid = disk_visible_fraction(&shadowing(&occ, o, 512), o, n, center, d, 0.6);
                    let sliced = disk_visible_fraction_sliced(&shadowing(&occ, o, 6), n, center, d, 0.6, 1024).unwrap();
                    partial += usize::from(sliced > 0.01 && sliced < 0.99);
                    assert!((grid - sliced).abs() < 3e-5, "d {d} o {o} n {n}: grid {grid} slices {sliced}");
                }
            }
        }
        assert!(partial >= 8, "points in the penumbra: {partial}");
    }

    /// The GPU's passes of a disk light's rows (`gpu::slice_passes`), and of the sun's, sum to the fraction by all
    /// rows, however the rows are cut.
    #[test]
    fn passes_of_rows_sum_to_the_fraction_by_slices() {
        let center = DVec3::new(0.0, 2.0, 0.0);
        let occ = plate(0.35, 1.0, 0.1, 0.5);
        let rows = 144;
        let cuts = [vec![0, rows], vec![0, 1, 50, 51, 100, rows], vec![0, 7, 72, rows - 1, rows]];
        let sum = |pass: &dyn Fn(u32, u32) -> (f64, f64), cuts: &[u32]| {
            let (visible, total) =
                cuts.windows(2).map(|w| pass(w[0], w[1] - w[0])).fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
            rows_fraction(visible, total)
        };
        let (mut partial, mut sun_partial) = (0, 0);
        // x = 0.4: the sun's penumbra from the plate's edge at x = 0.85.
        for ox in [-0.4, 0.0, 0.3, 0.4, 0.9] {
            let o = DVec3::new(ox, 0.0, 0.05);
            let s = shadowing(&occ, o, 6);
            for n in [DVec3::Y, DVec3::new(0.4, 1.0, -0.2).normalize()] {
                let disk = (center, -DVec3::Y, 0.6);
                let whole = disk_visible_fraction_sliced(&s, n, center, -DVec3::Y, 0.6, rows).unwrap();
                partial += usize::from(whole > 0.01 && whole < 0.99);
                for c in &cuts {
                    let passes = sum(&|first, count| disk_rows_weights(&s, n, disk, rows, first, count).unwrap(), c);
                    assert!((passes - whole).abs() < 1e-13, "o {o} n {n} {c:?}: {passes} against {whole}");
                }
                // The sun low behind the plate's edge, from the same points.
                let l = DVec3::new(0.45, 1.0, 0.05).normalize();
                let sun = |first, count| sun_rows_weights(&s, n, l, 0.02, rows, first, count).unwrap();
                let whole = sun_visible_fraction_sliced(&s, n, l, 0.02, rows).unwrap();
                sun_partial += usize::from(whole > 0.01 && whole < 0.99);
                for c in &cuts {
                    assert!((sum(&sun, c) - whole).abs() < 1e-13, "sun o {o} n {n} {c:?}");
                }
            }
        }
        assert!(partial >= 2 && sun_partial >= 1, "points in the penumbrae: disk {partial}, sun {sun_partial}");
    }

    #[test]
    fn a_ceiling_around_the_disk_does_not_block_it() {
        // A ceiling in the disk's own plane with the disk's hole: the rays end short of the disk, so the ceiling's
        // rim does not block it (as the grid's rays). A plate just below the disk, wider than it, hides it all.
        let center = DVec3::new(0.0, 2.0, 0.0);
        let o = DVec3::new(0.2, 0.0, 0.1);
        let ceiling = {
            let c = |x: f64, z: f64| DVec3::new(x, 2.0, z);
            // Four slabs around the hole |x|, |z| < 0.6.
            let quad = |x0: f64, x1: f64, z0: f64, z1: f64| {
                [[c(x0, z0), c(x1, z0), c(x1, z1)], [c(x0, z0), c(x1, z1), c(x0, z1)]]
            };
            let mut t = Vec::new();
            t.extend(quad(-5.0, 5.0, 0.6, 5.0));
            t.extend(quad(-5.0, 5.0, -5.0, -0.6));
            t.extend(quad(0.6, 5.0, -0.6, 0.6));
            t.extend(quad(-5.0, -0.6, -0.6, 0.6));
            Bvh::new(t)
        };
        let v = disk_visible_fraction_sliced(&shadowing(&ceiling, o, 6), DVec3::Y, center, -DVec3::Y, 0.6, 64);
        assert_eq!(v, Some(1.0));
        let below = plate(0.0, 1.9, 0.0, 1.0);
        let v = disk_visible_fraction_sliced(&shadowing(&below, o, 6), DVec3::Y, center, -DVec3::Y, 0.6, 64).unwrap();
        assert!(v.abs() < 1e-12, "{v}");
    }
}

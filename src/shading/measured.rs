//! Evaluating a measured (MERL) BRDF: Rusinkiewicz's half/difference angles of a pair of directions, the table's
//! coordinates, and the lookup. Mirrored by `shaders/measured.glsl` name for name: the same formulas, f64 here
//! and f32 there, reading the same f32 table, so that GPU and reference differ by the rounding of the
//! coordinates (docs/measured.md measures it).
//!
//! Angles (Rusinkiewicz 1998, "A New Change of Variables for Efficient BRDF Representation"): h the unit half
//! vector of l and v; θ_h its angle from n; θ_d the angle between l and h; φ_d the azimuth of l about h, measured
//! from the direction in the n–h plane that points away from n (Rusinkiewicz's frame after rotating h onto the
//! normal; for an isotropic BRDF φ_h does not matter). Angles come from `atan2(|a × b|, a·b)`, accurate near 0
//! and π/2 where `acos` of a dot product loses half its digits (the mirror peak is at θ_h = 0).
//!
//! Coordinates on the table's bins (`scene::measured`): `u_h = 90 √(θ_h/(π/2))`, `u_d = 90 θ_d/(π/2)`,
//! `u_φ = 180 φ_d/π` with φ_d folded into [0, π) by reciprocity (φ_d and φ_d + π swap l and v). Sample `i` sits at
//! `u = i`, the lower edge of its bin, so that truncation (the database reader's nearest-bin rule) returns the
//! sample below.
//! - **Linear** (the default): trilinear in (u_h, u_d, u_φ), φ periodic, θ's held at their last sample beyond
//!   it. Continuous in the directions, so the GPU and the reference differ only by rounding.
//! - **Nearest**: the bin the coordinates fall in (truncation), as the database's reader does; it jumps between
//!   bins, so a pixel whose coordinates round across a bin edge differs between GPU and reference by the jump.
//!
//! The square-root scale in θ_h amplifies errors near the peak: `du_h/dθ_h = 45/√(θ_h π/2)`, so an f32 rounding
//! of 1e-7 rad in θ_h moves u_h by 0.02 bins at θ_h = 1e-7 (a surface point whose view mirrors the light
//! to a tenth of a microradian), by 1e-4 bins at θ_h = 0.01.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

pub use crate::scene::measured::MeasuredLookup;
use crate::scene::measured::THETA_H_BINS;
use crate::scene::measured::{merl_bin_angles, merl_index, MeasuredBrdf, MERL_SAMPLES, PHI_D_BINS, THETA_D_BINS};

/// The angle between unit vectors a and b, `atan2(|a × b|, a·b)`: accurate at 0 and near π/2.
pub fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Rusinkiewicz's `(θ_h, θ_d, φ_d)` \[rad\] of light from `l` seen from `v` about the normal `n` (unit vectors),
/// φ_d in (−π, π]; `None` where l + v = 0 (no half vector).
pub fn half_diff_angles(n: DVec3, l: DVec3, v: DVec3) -> Option<(f64, f64, f64)> {
    let sum = l + v;
    let len2 = sum.length_squared();
    if len2 == 0.0 || !len2.is_finite() {
        return None;
    }
    let h = sum / len2.sqrt();
    let theta_h = angle_between(n, h);
    let theta_d = angle_between(l, h);
    // x: in the n–h plane, orthogonal to h, away from n: ((n·h) h − n)/sin θ_h. Where h is along n the azimuth's
    // origin is arbitrary (an isotropic table does not depend on φ_d there): any unit vector orthogonal to h.
    let away = n.dot(h) * h - n;
    let len = away.length();
    let x = if len > 1e-12 { away / len } else { super::orthonormal_to(h) };
    let y = h.cross(x);
    Some((theta_h, theta_d, l.dot(y).atan2(l.dot(x))))
}

/// The table coordinates `(u_h, u_d, u_φ)` of angles (see the module text): u_h and u_d in [0, 90], u_φ in
/// [0, 180).
pub fn measured_coordinates(theta_h: f64, theta_d: f64, phi_d: f64) -> (f64, f64, f64) {
    let u_h = THETA_H_BINS as f64 * (theta_h.max(0.0) / FRAC_PI_2).sqrt();
    let u_d = THETA_D_BINS as f64 * (theta_d.max(0.0) / FRAC_PI_2);
    // Reciprocity: φ_d and φ_d + π are the same configuration with l and v swapped.
    let folded = if phi_d < 0.0 { phi_d + PI } else { phi_d };
    let u_phi = (PHI_D_BINS as f64 * (folded / PI)).min(PHI_D_BINS as f64);
    (u_h, u_d, if u_phi >= PHI_D_BINS as f64 { 0.0 } else { u_phi })
}

/// The sample below coordinate `u` on an axis of `bins` samples and the fraction past it: `(i, i + 1, t)`, the
/// θ axes held at their last sample (`periodic` false), φ wrapping to its first.
pub fn measured_axis(u: f64, bins: usize, periodic: bool) -> (usize, usize, f64) {
    let last = bins - 1;
    let i = (u.floor().max(0.0) as usize).min(last);
    let t = (u - i as f64).clamp(0.0, 1.0);
    let next = if i < last {
        i + 1
    } else if periodic {
        0
    } else {
        last
    };
    (i, next, t)
}

/// ρ [1/sr] per channel of the table for light from `l` seen from `v` about `n` (unit vectors; 0 where either is
/// below the horizon or they are opposite).
pub fn measured_brdf(table: &MeasuredBrdf, lookup: MeasuredLookup, n: DVec3, l: DVec3, v: DVec3) -> [f64; 3] {
    if !(n.dot(l) > 0.0 && n.dot(v) > 0.0) {
        return [0.0; 3];
    }
    let Some((theta_h, theta_d, phi_d)) = half_diff_angles(n, l, v) else { return [0.0; 3] };
    let (u_h, u_d, u_phi) = measured_coordinates(theta_h, theta_d, phi_d);
    let (h0, h1, th) = measured_axis(u_h, THETA_H_BINS, false);
    let (d0, d1, td) = measured_axis(u_d, THETA_D_BINS, false);
    let (p0, p1, tp) = measured_axis(u_phi, PHI_D_BINS, true);
    let at = |i, j, k| measured_sample(table, i, j, k);
    if lookup == MeasuredLookup::Nearest {
        return at(h0, d0, p0);
    }
    // Trilinear: along φ, then θ_d, then θ_h, the same order as the shader.
    let along_phi = |i, j| lerp(at(i, j, p0), at(i, j, p1), tp);
    let along_d = |i| lerp(along_phi(i, d0), along_phi(i, d1), td);
    lerp(along_d(h0), along_d(h1), th)
}

/// `a + t (b − a)` per channel.
pub fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    [0, 1, 2].map(|c| a[c] + t * (b[c] - a[c]))
}

/// The table's ρ at bins (i, j, k) per channel.
pub fn measured_sample(table: &MeasuredBrdf, i: usize, j: usize, k: usize) -> [f64; 3] {
    let s = &table.values[3 * merl_index(i, j, k)..][..3];
    [s[0] as f64, s[1] as f64, s[2] as f64]
}

/// The part of the table above its floor, `ρ − floor` per channel: what the sample grids integrate (the floor is
/// a Lambertian part, integrated exactly; `scene::measured::MeasuredBrdf::floor`). At least −1e-16 ρ (rounding of
/// the interpolation; never NaN).
pub fn measured_residual(table: &MeasuredBrdf, lookup: MeasuredLookup, n: DVec3, l: DVec3, v: DVec3) -> [f64; 3] {
    if !(n.dot(l) > 0.0 && n.dot(v) > 0.0) {
        return [0.0; 3];
    }
    let rho = measured_brdf(table, lookup, n, l, v);
    [0, 1, 2].map(|c| rho[c] - table.floor[c] as f64)
}

/// An estimate per channel of the largest error of the trilinear lookup in the cells about sample (i, j, k):
/// per axis `|Δ²f| / 8` (`h² max|f''| / 8` with unit spacing: de Boor, A Practical Guide to Splines, ch. 2, for
/// the linear interpolant), the second difference centred on the sample, or on its neighbour at the first
/// sample of a θ axis; at the last sample of a θ axis, where the lookup holds the value to the axis' end, the
/// first difference `|f(i) − f(i − 1)|` (the held value's error over one bin, to first order). φ_d is periodic.
pub fn second_difference_bound(table: &MeasuredBrdf, i: usize, j: usize, k: usize) -> [f64; 3] {
    let at = |i, j, k| measured_sample(table, i, j, k);
    let second = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| [0, 1, 2].map(|x| (a[x] - 2.0 * b[x] + c[x]).abs() / 8.0);
    let along_theta = |count: usize, index: usize, f: &dyn Fn(usize) -> [f64; 3]| -> [f64; 3] {
        if index + 1 == count {
            let (a, b) = (f(index), f(index - 1));
            [0, 1, 2].map(|x| (a[x] - b[x]).abs())
        } else {
            let centre = index.max(1);
            second(f(centre - 1), f(centre), f(centre + 1))
        }
    };
    let phi = second(at(i, j, (k + PHI_D_BINS - 1) % PHI_D_BINS), at(i, j, k), at(i, j, (k + 1) % PHI_D_BINS));
    let h = along_theta(THETA_H_BINS, i, &|x| at(x, j, k));
    let d = along_theta(THETA_D_BINS, j, &|x| at(i, x, k));
    [0, 1, 2].map(|c| phi[c] + h[c] + d[c])
}

/// An estimate of the linear lookup's relative error for light from `l` seen from `v` about `n`: the largest
/// [`second_difference_bound`] of the cell's eight corners over the smallest corner value, per channel the
/// largest. An estimate, not a proof: curvature concentrated between samples is invisible to it. 0 where the
/// lookup gives 0.
pub fn linear_lookup_error_at(table: &MeasuredBrdf, n: DVec3, l: DVec3, v: DVec3) -> f64 {
    if !(n.dot(l) > 0.0 && n.dot(v) > 0.0) {
        return 0.0;
    }
    let Some((theta_h, theta_d, phi_d)) = half_diff_angles(n, l, v) else { return 0.0 };
    let (u_h, u_d, u_phi) = measured_coordinates(theta_h, theta_d, phi_d);
    let (h0, h1, _) = measured_axis(u_h, THETA_H_BINS, false);
    let (d0, d1, _) = measured_axis(u_d, THETA_D_BINS, false);
    let (p0, p1, _) = measured_axis(u_phi, PHI_D_BINS, true);
    let (mut bound, mut least) = ([0.0f64; 3], [f64::INFINITY; 3]);
    for i in [h0, h1] {
        for j in [d0, d1] {
            for k in [p0, p1] {
                let (b, f) = (second_difference_bound(table, i, j, k), measured_sample(table, i, j, k));
                for c in 0..3 {
                    bound[c] = bound[c].max(b[c]);
                    least[c] = least[c].min(f[c]);
                }
            }
        }
    }
    (0..3).map(|c| if least[c] > 0.0 { bound[c] / least[c] } else { 0.0 }).fold(0.0, f64::max)
}

/// Directions `(l, v)` of angles `(θ_h, θ_d, φ_d)` about the normal +z (φ_h = 0): h in the x–z plane at θ_h from
/// z; l at θ_d from h, azimuth φ_d from the direction away from the normal; v its mirror about h.
pub fn half_diff_directions(theta_h: f64, theta_d: f64, phi_d: f64) -> (DVec3, DVec3) {
    let (sh, ch) = theta_h.sin_cos();
    let (sd, cd) = theta_d.sin_cos();
    let (sp, cp) = phi_d.sin_cos();
    let h = DVec3::new(sh, 0.0, ch);
    let x = DVec3::new(ch, 0.0, -sh);
    let l = sd * cp * x + sd * sp * DVec3::Y + cd * h;
    let v = 2.0 * h.dot(l) * h - l;
    (l, v)
}

/// A table's directional albedo per channel for a viewer at `theta` \[rad\] from the normal: `∫ ρ(l, v) cos θ_l dω_l`
/// over the hemisphere, by a `per_axis²` stratified midpoint grid drawn cosine-weighted (pdf `cos θ/π`, so each
/// sample weighs `π ρ / per_axis²`). Exact for a constant table; a peak narrower than the grid's cells (about
/// `π/per_axis` rad) is resolved only on average.
pub fn measured_albedo(table: &MeasuredBrdf, lookup: MeasuredLookup, theta: f64, per_axis: u32) -> [f64; 3] {
    let v = DVec3::new(theta.sin(), 0.0, theta.cos());
    let k = per_axis as f64;
    let mut sum = [0.0; 3];
    for i in 0..per_axis {
        // cos θ_l = √(1 − ξ1): the cosine-weighted inverse CDF.
        let xi1 = (i as f64 + 0.5) / k;
        let (sin_l, cos_l) = (xi1.sqrt(), (1.0 - xi1).sqrt());
        for j in 0..per_axis {
            let phi = 2.0 * PI * (j as f64 + 0.5) / k;
            let l = DVec3::new(sin_l * phi.cos(), sin_l * phi.sin(), cos_l);
            let rho = measured_brdf(table, lookup, DVec3::Z, l, v);
            for c in 0..3 {
                sum[c] += rho[c];
            }
        }
    }
    sum.map(|x| PI * x / (k * k))
}

/// An analytic BRDF's value `kd/π + ks lobe` [1/sr] per channel about the normal +z ([`super::lobe_about_z_rgb`]),
/// the frame [`half_diff_directions`] and [`tabulate`] use.
pub fn brdf_about_z(brdf: &crate::scene::Brdf, l: DVec3, v: DVec3) -> [f64; 3] {
    let (kd, ks, lobe) = (brdf.kd(), brdf.ks(), super::lobe_about_z_rgb(brdf, l, v));
    [0, 1, 2].map(|c| kd[c] as f64 / PI + ks[c] as f64 * lobe[c])
}

/// A table of `rho(l, v)` per channel [1/sr] at each sample's angles (normal +z), as [`MeasuredBrdf::from_planes`]
/// takes it: for synthetic files made from analytic BRDFs.
pub fn tabulate(mut rho: impl FnMut(DVec3, DVec3) -> [f64; 3]) -> [Vec<f64>; 3] {
    let mut planes: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; MERL_SAMPLES]);
    for i in 0..THETA_H_BINS {
        for j in 0..THETA_D_BINS {
            for k in 0..PHI_D_BINS {
                let (theta_h, theta_d, phi_d) = merl_bin_angles(i, j, k);
                let (l, v) = half_diff_directions(theta_h, theta_d, phi_d);
                let value = rho(l, v);
                for c in 0..3 {
                    planes[c][merl_index(i, j, k)] = value[c];
                }
            }
        }
    }
    planes
}

/// The α of the Ward half-vector distribution that draws a measured table's sky samples: its peak width
/// `w` (2θ_h at e^{-1/2} of the peak) is Ward's `√2 α`, so `α = w/√2`, kept in [10⁻³, 1] (a table without a peak
/// has w = π: the broadest distribution).
pub fn measured_sampling_alpha(lobe_width: f64) -> f64 {
    (lobe_width / std::f64::consts::SQRT_2).clamp(1e-3, 1.0)
}

/// One sample of the sky's inverse-CDF grid for a table, which has no inverse CDF of its own: its part above the
/// floor ([`measured_residual`]) is drawn through Ward's isotropic half-vector distribution about n,
/// `p_h = exp(−tan²δ/α²)/(π α² cos³δ)`, with the α of the table's peak width ([`measured_sampling_alpha`]);
/// `tan²δ = −α² ln ξ1` makes the exponential ξ1 itself, and `p_ω = p_h/(4 v·h)`, so the sample's weight is
/// `ρ (n·ω) 4 (v·h) π α² cos³δ / ξ1` (ξ1 ≥ 1/(2k) on the midpoint grid); 0 (and ω = n) where h faces away from
/// the viewer. `(t, b)`: a frame about n.
pub fn measured_lobe_sample(
    table: &MeasuredBrdf,
    lookup: MeasuredLookup,
    (n, v): (DVec3, DVec3),
    (t, b): (DVec3, DVec3),
    xi1: f64,
    phi: f64,
) -> ([f64; 3], DVec3) {
    let alpha = measured_sampling_alpha(table.lobe_width as f64);
    let tan2 = -alpha * alpha * xi1.ln();
    let cos_d = 1.0 / (1.0 + tan2).sqrt();
    let sin_d = tan2.sqrt() * cos_d;
    let h = sin_d * (phi.cos() * t + phi.sin() * b) + cos_d * n;
    let vh = v.dot(h);
    if vh <= 0.0 {
        return ([0.0; 3], n);
    }
    let omega = 2.0 * vh * h - v;
    let weight = n.dot(omega).max(0.0) * 4.0 * vh * PI * alpha * alpha * cos_d * cos_d * cos_d / xi1;
    (measured_residual(table, lookup, n, omega, v).map(|x| x * weight), omega)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_round_trip_through_directions() {
        for &(th, td, pd) in &[(0.3, 0.2, 0.7), (1e-4, 0.5, -2.0), (1.2, 0.01, 3.0), (0.5, 1.0, 0.0)] {
            let (l, v) = half_diff_directions(th, td, pd);
            let (a, b, c) = half_diff_angles(DVec3::Z, l, v).unwrap();
            assert!((a - th).abs() < 1e-12 && (b - td).abs() < 1e-12, "{th} {td}: {a} {b}");
            assert!((c - pd).abs() < 1e-12, "{pd}: {c}");
        }
        assert_eq!(half_diff_angles(DVec3::Z, DVec3::X, -DVec3::X), None);
    }

    #[test]
    fn coordinates_place_samples_at_bin_edges() {
        for (i, j, k) in [(0, 0, 0), (1, 2, 3), (45, 89, 179), (89, 10, 90)] {
            let (th, td, pd) = merl_bin_angles(i, j, k);
            let (uh, ud, up) = measured_coordinates(th, td, pd);
            assert!((uh - i as f64).abs() < 1e-9 && (ud - j as f64).abs() < 1e-9 && (up - k as f64).abs() < 1e-9);
        }
        // Reciprocity folds negative azimuths.
        let (_, _, up) = measured_coordinates(0.1, 0.1, -0.5 * PI);
        assert!((up - 90.0).abs() < 1e-12);
        assert_eq!(measured_axis(179.5, 180, true), (179, 0, 0.5));
        assert_eq!(measured_axis(89.5, 90, false), (89, 89, 0.5));
        assert_eq!(measured_axis(95.0, 90, false), (89, 89, 1.0));
    }

    #[test]
    fn a_constant_tables_albedo_is_pi_times_its_value() {
        let planes: [Vec<f64>; 3] = std::array::from_fn(|c| vec![0.05 * (c + 1) as f64; MERL_SAMPLES]);
        let t = MeasuredBrdf::from_planes("c", &planes).unwrap();
        for theta in [0.0, 1.0, 1.5] {
            let a = measured_albedo(&t, MeasuredLookup::Linear, theta, 64);
            for (c, a) in a.iter().enumerate() {
                let want = PI * (0.05 * (c + 1) as f64) as f32 as f64;
                assert!((a - want).abs() < 1e-12, "{theta}: {a} against {want}");
            }
        }
    }

    #[test]
    fn lookup_reproduces_samples_and_interpolates_linearly() {
        // A table linear in u_d: the trilinear lookup is exact between samples, nearest truncates.
        let planes: [Vec<f64>; 3] = std::array::from_fn(|c| {
            let mut p = vec![0.0; MERL_SAMPLES];
            for i in 0..THETA_H_BINS {
                for j in 0..THETA_D_BINS {
                    for k in 0..PHI_D_BINS {
                        p[merl_index(i, j, k)] = 0.01 * (c + 1) as f64 * j as f64;
                    }
                }
            }
            p
        });
        let t = MeasuredBrdf::from_planes("lin", &planes).unwrap();
        let (l, v) = half_diff_directions(0.2, 10.5 / 90.0 * FRAC_PI_2, 0.3);
        let lin = measured_brdf(&t, MeasuredLookup::Linear, DVec3::Z, l, v);
        let near = measured_brdf(&t, MeasuredLookup::Nearest, DVec3::Z, l, v);
        for c in 0..3 {
            let s = 0.01 * (c + 1) as f64;
            assert!((lin[c] - 10.5 * s).abs() < 1e-6, "{lin:?}");
            assert!((near[c] - 10.0 * s).abs() < 1e-6, "{near:?}");
        }
        // Below the horizon: 0.
        assert_eq!(measured_brdf(&t, MeasuredLookup::Linear, DVec3::Z, -l, v), [0.0; 3]);
    }
}

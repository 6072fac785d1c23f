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
//! `u_φ = 180 φ_d/π` with φ_d folded into [0, π) by reciprocity (φ_d and φ_d + π swap l and v); bin `i` is
//! `[i, i + 1)`. **Sample `i` stands at `u = i + ½`, the centre of its bin.** A table's value stands for its whole
//! bin: the database's reader looks up by truncation (any direction in the bin gets the bin's value), and its
//! tables were made from the measurements falling in each bin (Matusik et al. 2003). Whether a bin's value is the
//! mean or the median of a smooth ρ sampled evenly over the bin, it is ρ at the bin's centre, to second order for
//! the mean (the midpoint rule, `mean = ρ(centre) + h² ρ''/24`) and exactly for the median of a monotone ρ; read at
//! the lower edge it would be off by `h ρ'/2`, first order (docs/measured.md measures the difference).
//! - **Linear** (the default): trilinear in (u_h, u_d, u_φ) between the samples' centres, φ periodic, the θ's held
//!   at their first sample below its centre and their last above. **Missing samples** take no part: the eight
//!   corners are weighted by their validity and the weights renormalised (the interpolation of `(a ρ, a)`, a = 1
//!   for a valid sample and 0 for a missing one, divided by its last component), so that a band of missing samples
//!   beyond the horizon does not darken the valid cells next to it; a cell without a valid corner interpolates the
//!   values the missing samples hold, their nearest valid ones' (`scene::measured`). A table without missing
//!   samples interpolates `a = 1` exactly, so the division is by 1 and changes no bit. Continuous in the directions
//!   wherever a valid corner's weight is not 0, so the GPU and the reference differ only by rounding.
//! - **Nearest**: the bin the coordinates fall in (truncation), as the database's reader does, which is also the
//!   sample whose centre is nearest; it jumps between bins, so a pixel whose coordinates round across a bin edge
//!   differs between GPU and reference by the jump.
//!
//! The square-root scale in θ_h amplifies errors near the peak: `du_h/dθ_h = 45/√(θ_h π/2)`, so an f32 rounding
//! of 1e-7 rad in θ_h moves u_h by 0.02 bins at θ_h = 1e-7 (a surface point whose view mirrors the light
//! to a tenth of a microradian), by 1e-4 bins at θ_h = 0.01.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

pub use crate::scene::measured::MeasuredLookup;
use crate::scene::measured::THETA_H_BINS;
use crate::scene::measured::{
    bin_centre_above_horizon, merl_bin_angles, merl_index, MeasuredBrdf, MERL_SAMPLES, PHI_D_BINS, THETA_D_BINS,
};

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

/// The two samples about coordinate `u` on an axis of `bins` samples, sample `i` at `u = i + ½`, and the fraction
/// past the first: `(i, next, t)`. The θ axes (`periodic` false) hold their first sample below its centre and
/// their last above; φ wraps from its last sample to its first. `u − ½` is exact in f64 and within half an ulp of
/// u in f32 (1e-5 bins at the axis' end), the size of u's own rounding.
pub fn measured_axis(u: f64, bins: usize, periodic: bool) -> (usize, usize, f64) {
    let last = bins - 1;
    let mut s = u - 0.5;
    if periodic && s < 0.0 {
        s += bins as f64;
    }
    let i = (s.floor().max(0.0) as usize).min(last);
    let t = (s - i as f64).clamp(0.0, 1.0);
    let next = if i < last {
        i + 1
    } else if periodic {
        0
    } else {
        last
    };
    (i, next, t)
}

/// The bin coordinate `u` falls in on an axis of `bins` (truncation, the database reader's rule): also the
/// sample whose centre is nearest.
pub fn measured_bin(u: f64, bins: usize) -> usize {
    (u.floor().max(0.0) as usize).min(bins - 1)
}

/// ρ [1/sr] per channel of the table for light from `l` seen from `v` about `n` (unit vectors; 0 where either is
/// below the horizon or they are opposite).
pub fn measured_brdf(table: &MeasuredBrdf, lookup: MeasuredLookup, n: DVec3, l: DVec3, v: DVec3) -> [f64; 3] {
    if !(n.dot(l) > 0.0 && n.dot(v) > 0.0) {
        return [0.0; 3];
    }
    let Some((theta_h, theta_d, phi_d)) = half_diff_angles(n, l, v) else { return [0.0; 3] };
    measured_lookup_at(table, lookup, measured_coordinates(theta_h, theta_d, phi_d))
}

/// ρ [1/sr] per channel of the table at coordinates `(u_h, u_d, u_φ)` ([`measured_coordinates`]): the lookup
/// [`measured_brdf`] makes once it has them.
pub fn measured_lookup_at(
    table: &MeasuredBrdf,
    lookup: MeasuredLookup,
    (u_h, u_d, u_phi): (f64, f64, f64),
) -> [f64; 3] {
    if lookup == MeasuredLookup::Nearest {
        let (i, j, k) =
            (measured_bin(u_h, THETA_H_BINS), measured_bin(u_d, THETA_D_BINS), measured_bin(u_phi, PHI_D_BINS));
        return measured_sample(table, i, j, k);
    }
    let (h0, h1, th) = measured_axis(u_h, THETA_H_BINS, false);
    let (d0, d1, td) = measured_axis(u_d, THETA_D_BINS, false);
    let (p0, p1, tp) = measured_axis(u_phi, PHI_D_BINS, true);
    // Trilinear over the valid corners: along φ, then θ_d, then θ_h, the same order as the shader.
    let at = |i, j, k| measured_weighted_sample(table, i, j, k);
    let along_phi = |i, j| lerp4(at(i, j, p0), at(i, j, p1), tp);
    let along_d = |i| lerp4(along_phi(i, d0), along_phi(i, d1), td);
    let weighted = lerp4(along_d(h0), along_d(h1), th);
    if weighted[3] > 0.0 {
        // A weighted mean of valid samples: between their least and largest value whatever the weights' rounding.
        return [0, 1, 2].map(|c| weighted[c] / weighted[3]);
    }
    // No valid corner: the values the missing corners hold (their nearest valid samples').
    let at = |i, j, k| measured_sample(table, i, j, k);
    let along_phi = |i, j| lerp(at(i, j, p0), at(i, j, p1), tp);
    let along_d = |i| lerp(along_phi(i, d0), along_phi(i, d1), td);
    lerp(along_d(h0), along_d(h1), th)
}

/// `a + t (b − a)` per channel.
pub fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    [0, 1, 2].map(|c| a[c] + t * (b[c] - a[c]))
}

/// `a + t (b − a)` per component of four.
pub fn lerp4(a: [f64; 4], b: [f64; 4], t: f64) -> [f64; 4] {
    [0, 1, 2, 3].map(|c| a[c] + t * (b[c] - a[c]))
}

/// The table's ρ at bins (i, j, k) per channel (a missing sample's: its nearest valid sample's).
pub fn measured_sample(table: &MeasuredBrdf, i: usize, j: usize, k: usize) -> [f64; 3] {
    let s = &table.values[3 * merl_index(i, j, k)..][..3];
    [s[0] as f64, s[1] as f64, s[2] as f64]
}

/// `(a ρ, a)` at bins (i, j, k): a = 1 for a valid sample, 0 for a missing one (the linear lookup's weights).
pub fn measured_weighted_sample(table: &MeasuredBrdf, i: usize, j: usize, k: usize) -> [f64; 4] {
    let a = if table.is_missing(merl_index(i, j, k)) { 0.0 } else { 1.0 };
    let s = measured_sample(table, i, j, k);
    [s[0] * a, s[1] * a, s[2] * a, a]
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
/// sample of a θ axis; at the first and last samples of a θ axis, where the lookup holds the value over the half
/// bin to the axis' end, at least half the first difference `|f(i) − f(i ± 1)| / 2` (the held value's error there,
/// to first order). φ_d is periodic. Missing samples count with the values they hold (their nearest valid ones').
pub fn second_difference_bound(table: &MeasuredBrdf, i: usize, j: usize, k: usize) -> [f64; 3] {
    let at = |i, j, k| measured_sample(table, i, j, k);
    let second = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| [0, 1, 2].map(|x| (a[x] - 2.0 * b[x] + c[x]).abs() / 8.0);
    let half_first = |a: [f64; 3], b: [f64; 3]| [0, 1, 2].map(|x| (a[x] - b[x]).abs() / 2.0);
    let along_theta = |count: usize, index: usize, f: &dyn Fn(usize) -> [f64; 3]| -> [f64; 3] {
        if index + 1 == count {
            half_first(f(index), f(index - 1))
        } else if index == 0 {
            let (held, curved) = (half_first(f(0), f(1)), second(f(0), f(1), f(2)));
            [0, 1, 2].map(|x| held[x].max(curved[x]))
        } else {
            second(f(index - 1), f(index), f(index + 1))
        }
    };
    let phi = second(at(i, j, (k + PHI_D_BINS - 1) % PHI_D_BINS), at(i, j, k), at(i, j, (k + 1) % PHI_D_BINS));
    let h = along_theta(THETA_H_BINS, i, &|x| at(x, j, k));
    let d = along_theta(THETA_D_BINS, j, &|x| at(i, x, k));
    [0, 1, 2].map(|c| phi[c] + h[c] + d[c])
}

/// An estimate of the linear lookup's relative error for light from `l` seen from `v` about `n`: the largest
/// [`second_difference_bound`] of the cell's valid corners over their smallest value, per channel the largest;
/// where a corner is missing, plus the largest [`valid_slopes`] of the valid corners (the lookup then reads the
/// cell from part of its corners). An estimate, not a proof: curvature concentrated between samples is invisible
/// to it. 0 where the lookup gives 0.
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
    let (mut slope, mut some_missing) = ([0.0f64; 3], false);
    for i in [h0, h1] {
        for j in [d0, d1] {
            for k in [p0, p1] {
                if table.is_missing(merl_index(i, j, k)) {
                    some_missing = true;
                    continue;
                }
                let (b, f, s) = (
                    second_difference_bound(table, i, j, k),
                    measured_sample(table, i, j, k),
                    valid_slopes(table, i, j, k),
                );
                for c in 0..3 {
                    bound[c] = bound[c].max(b[c]);
                    least[c] = least[c].min(f[c]);
                    slope[c] = slope[c].max(s[c]);
                }
            }
        }
    }
    // A cell with missing corners is read from its valid ones alone, up to a bin away on each axis: first order.
    let bound: [f64; 3] = std::array::from_fn(|c| if some_missing { bound[c] + slope[c] } else { bound[c] });
    (0..3).map(|c| if least[c].is_finite() && least[c] > 0.0 { bound[c] / least[c] } else { 0.0 }).fold(0.0, f64::max)
}

/// Per channel, the sum over the three axes of the largest first difference between valid sample (i, j, k) and a
/// valid neighbour on that axis (φ_d wrapping): how much the table changes over one bin about a valid sample.
pub fn valid_slopes(table: &MeasuredBrdf, i: usize, j: usize, k: usize) -> [f64; 3] {
    let f = measured_sample(table, i, j, k);
    let neighbours = [
        [i.checked_sub(1).map(|i| (i, j, k)), (i + 1 < THETA_H_BINS).then_some((i + 1, j, k))],
        [j.checked_sub(1).map(|j| (i, j, k)), (j + 1 < THETA_D_BINS).then_some((i, j + 1, k))],
        [Some((i, j, (k + PHI_D_BINS - 1) % PHI_D_BINS)), Some((i, j, (k + 1) % PHI_D_BINS))],
    ];
    let mut sum = [0.0; 3];
    for axis in neighbours {
        let mut largest = [0.0f64; 3];
        for (a, b, c) in axis.into_iter().flatten() {
            if !table.is_missing(merl_index(a, b, c)) {
                let g = measured_sample(table, a, b, c);
                for x in 0..3 {
                    largest[x] = largest[x].max((g[x] - f[x]).abs());
                }
            }
        }
        for x in 0..3 {
            sum[x] += largest[x];
        }
    }
    sum
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

/// A table of `rho(l, v)` per channel [1/sr] at each sample's angles, its bin's centre (normal +z), as
/// [`MeasuredBrdf::from_planes`] takes it: for synthetic files made from analytic BRDFs. A sample whose light or
/// view is not above the horizon is written missing (−1), as the database marks the directions it could not
/// measure; `rho` is not called there.
pub fn tabulate(mut rho: impl FnMut(DVec3, DVec3) -> [f64; 3]) -> [Vec<f64>; 3] {
    let mut planes: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; MERL_SAMPLES]);
    for i in 0..THETA_H_BINS {
        for j in 0..THETA_D_BINS {
            for k in 0..PHI_D_BINS {
                let (theta_h, theta_d, phi_d) = merl_bin_angles(i, j, k);
                let (l, v) = half_diff_directions(theta_h, theta_d, phi_d);
                let value = if bin_centre_above_horizon(i, j, k) { rho(l, v) } else { [-1.0; 3] };
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
    fn coordinates_place_samples_at_bin_centres() {
        for (i, j, k) in [(0, 0, 0), (1, 2, 3), (45, 89, 179), (89, 10, 90)] {
            let (th, td, pd) = merl_bin_angles(i, j, k);
            let (uh, ud, up) = measured_coordinates(th, td, pd);
            let centre = |n: usize| n as f64 + 0.5;
            assert!((uh - centre(i)).abs() < 1e-9 && (ud - centre(j)).abs() < 1e-9 && (up - centre(k)).abs() < 1e-9);
            assert_eq!((measured_bin(uh, 90), measured_bin(ud, 90), measured_bin(up, 180)), (i, j, k));
            for (u, n, periodic) in [(uh, i, false), (ud, j, false), (up, k, true)] {
                let (a, _, t) = measured_axis(u, if periodic { 180 } else { 90 }, periodic);
                assert!(a == n && t < 1e-9, "{u}: {a} {t}");
            }
        }
        // Reciprocity folds negative azimuths.
        let (_, _, up) = measured_coordinates(0.1, 0.1, -0.5 * PI);
        assert!((up - 90.0).abs() < 1e-12);
        // φ wraps between its last centre and its first; the θ's hold their first and last samples.
        assert_eq!(measured_axis(180.0, 180, true), (179, 0, 0.5));
        assert_eq!(measured_axis(0.0, 180, true), (179, 0, 0.5));
        assert_eq!(measured_axis(0.25, 90, false), (0, 1, 0.0));
        assert_eq!(measured_axis(90.0, 90, false), (89, 89, 0.5));
        assert_eq!(measured_axis(95.0, 90, false), (89, 89, 1.0));
    }

    #[test]
    fn the_horizon_test_at_bin_centres_agrees_with_the_directions() {
        let mut below = 0;
        for i in (0..THETA_H_BINS).step_by(3) {
            for j in 0..THETA_D_BINS {
                for k in (0..PHI_D_BINS).step_by(5) {
                    let (th, td, pd) = merl_bin_angles(i, j, k);
                    let (l, v) = half_diff_directions(th, td, pd);
                    assert_eq!(bin_centre_above_horizon(i, j, k), l.z > 0.0 && v.z > 0.0, "{i} {j} {k}");
                    below += usize::from(!(l.z > 0.0 && v.z > 0.0));
                }
            }
        }
        assert!(below > 1000, "{below}");
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
        // u_d = 11.2: 0.7 of the way from the centre of bin 10 to that of bin 11, in bin 11.
        let (l, v) = half_diff_directions(0.2, 11.2 / 90.0 * FRAC_PI_2, 0.3);
        let lin = measured_brdf(&t, MeasuredLookup::Linear, DVec3::Z, l, v);
        let near = measured_brdf(&t, MeasuredLookup::Nearest, DVec3::Z, l, v);
        for c in 0..3 {
            let s = 0.01 * (c + 1) as f64;
            assert!((lin[c] - 10.7 * s).abs() < 1e-6, "{lin:?}");
            assert!((near[c] - 11.0 * s).abs() < 1e-6, "{near:?}");
        }
        // Below the horizon: 0.
        assert_eq!(measured_brdf(&t, MeasuredLookup::Linear, DVec3::Z, -l, v), [0.0; 3]);
    }
}

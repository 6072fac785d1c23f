//! Directional albedo of a BRDF lobe, `a(v) = ∫ lobe(ω, v) (n·ω)+ dω` over the hemisphere, by converged
//! quadrature: the energy-conservation check (`a ≤ 1`) and the albedo tables in docs/brdf.md.
//!
//! Every lobe here is simplest in the half vector h (the direction ω = 2(v·h)h − v mirrors v about h):
//! `a(v) = ∫ lobe(ω(h), v) (n·ω) 4(v·h) dh`, with h at angle δ from n and azimuth φ,
//! `dh = sin δ dδ dφ`. The horizon `n·ω > 0` reads `2(n·h)(v·h) > n·v`, i.e. for each δ a bound
//! `cos(φ − φv) > c(δ)` on φ, so the integrand is smooth inside the bounds. δ is cut into panels graded
//! geometrically from the lobe's width (down to 1/65536 of it) and at the δ where c(δ) = ±1 (found by
//! bisection), φ into panels no wider than the lobe seen at that δ; Gauss–Legendre on each. [`lobe_albedo`]
//! doubles the order until two estimates agree.

use std::f64::consts::PI;

use glam::DVec3;

use super::lobe::{specular_lobe, SurfacePoint};
use super::quadrature::gauss_legendre;
use crate::scene::Brdf;

/// A width [rad] on which the lobe varies in h, for grading the panels.
fn lobe_width(brdf: &Brdf) -> f64 {
    match *brdf {
        Brdf::Lambert { .. } => 1.0,
        Brdf::Phong { exponent, .. } => (0.5 / (exponent as f64 + 1.0).sqrt()).min(1.0),
        Brdf::BlinnPhong { exponent, .. } => (1.0 / (exponent as f64 + 1.0).sqrt()).min(1.0),
        Brdf::Ward { alpha_x, alpha_y, .. } => (alpha_x.min(alpha_y) as f64).min(1.0),
        Brdf::Measured { ref table, .. } => (0.5 * table.lobe_width as f64).min(1.0),
        Brdf::Gltf { alpha, .. } => (alpha as f64).min(1.0),
    }
}

/// The lobe's directional albedo for a viewer at angle `theta` from n = +Y, azimuth `azimuth` from the tangent
/// t = +X towards b = +Z, by Gauss–Legendre of `order` points per panel.
pub fn lobe_albedo_at_order(brdf: &Brdf, theta: f64, azimuth: f64, order: usize) -> f64 {
    let (n, t, b) = (DVec3::Y, DVec3::X, DVec3::Z);
    let (st, ct) = theta.sin_cos();
    let v = ct * n + st * (azimuth.cos() * t + azimuth.sin() * b);
    let p = SurfacePoint { position: DVec3::ZERO, normal: n, tangent: t, bitangent: b, to_viewer: v };
    // The φ bound: cos(φ − φv) > c(δ) = (n·v/(2 cos δ) − cos δ cos θv) / (sin δ sin θv).
    let c_of = |delta: f64| {
        let (sd, cd) = delta.sin_cos();
        let den = sd * st;
        if den <= 0.0 {
            // Only δ = 0 (or a normal view): h = n gives ω = mirror of v, above the horizon iff n·v > 0.
            return if 2.0 * cd * cd * ct > ct { -2.0 } else { 2.0 };
        }
        (ct / (2.0 * cd) - cd * ct) / den
    };
    let w = lobe_width(brdf);
    let mut cuts = vec![0.0, 0.5 * PI];
    let mut g = w / 65536.0;
    while g < 0.5 * PI {
        cuts.push(g);
        g *= 2.0;
    }
    // Where c(δ) crosses ±1 (the φ-range changes form): sign changes on a fine scan, refined by bisection.
    let scan = 4096;
    for target in [-1.0, 1.0] {
        let f = |d: f64| c_of(d) - target;
        for i in 0..scan {
            let (a0, a1) = (0.5 * PI * i as f64 / scan as f64, 0.5 * PI * (i + 1) as f64 / scan as f64);
            let (mut lo, mut hi) = (a0.max(1e-12), a1.min(0.5 * PI - 1e-12));
            if f(lo).signum() != f(hi).signum() {
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if f(mid).signum() == f(lo).signum() {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                cuts.push(0.5 * (lo + hi));
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let rule = gauss_legendre(order);
    let mut total = 0.0;
    for pair in cuts.windows(2) {
        let (d0, d1) = (pair[0], pair[1]);
        let (dm, dh) = (0.5 * (d0 + d1), 0.5 * (d1 - d0));
        for &(xd, wd) in &rule {
            let delta = dm + dh * xd;
            let (sd, cd) = delta.sin_cos();
            let c = c_of(delta);
            let half_range = if c <= -1.0 {
                PI
            } else if c >= 1.0 {
                continue;
            } else {
                c.acos()
            };
            // φ panels no wider than the lobe's angular width seen at this δ (at most 1024).
            let panels = ((2.0 * half_range * sd / w).ceil() as usize).clamp(1, 1024);
            let step = 2.0 * half_range / panels as f64;
            let mut inner = 0.0;
            for k in 0..panels {
                let pm = azimuth - half_range + (k as f64 + 0.5) * step;
                for &(xp, wp) in &rule {
                    let phi = pm + 0.5 * step * xp;
                    let h = cd * n + sd * (phi.cos() * t + phi.sin() * b);
                    let vh = v.dot(h);
                    let omega = 2.0 * vh * h - v;
                    let cos = n.dot(omega);
                    if vh > 0.0 && cos > 0.0 {
                        inner += wp * 0.5 * step * specular_lobe(brdf, &p, omega) * cos * 4.0 * vh;
                    }
                }
            }
            total += wd * dh * sd * inner;
        }
    }
    total
}

/// The lobe's directional albedo at a viewer at angle `theta` \[rad\] from the normal and `azimuth` \[rad\] from the
/// tangent, converged: the order doubles from 8 until two estimates agree to `tolerance` (relative), at most
/// 64. Returns `(albedo, last relative change)`.
pub fn lobe_albedo(brdf: &Brdf, theta: f64, azimuth: f64, tolerance: f64) -> (f64, f64) {
    let mut prev = lobe_albedo_at_order(brdf, theta, azimuth, 8);
    let mut change = f64::INFINITY;
    for order in [16, 32, 64] {
        let next = lobe_albedo_at_order(brdf, theta, azimuth, order);
        change = (next - prev).abs() / next.abs().max(1e-300);
        prev = next;
        if change < tolerance {
            break;
        }
    }
    (prev, change)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phong_lobe_has_unit_albedo_at_normal_incidence() {
        // (e + 2)/(2π) ∫ cosᵉα cos θ dω = 1 at normal incidence, exactly.
        for e in [0.0f32, 1.0, 100.0, 1e4, 1e6] {
            let (a, change) = lobe_albedo(&Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: e }, 0.0, 0.0, 1e-10);
            assert!((a - 1.0).abs() < 1e-8 && change < 1e-8, "e {e}: {a} ({change})");
        }
    }

    #[test]
    fn blinn_phong_lobe_has_unit_albedo_at_normal_incidence() {
        for e in [0.0f32, 1.0, 100.0, 1e4, 1e6] {
            let (a, _) = lobe_albedo(&Brdf::BlinnPhong { kd: [0.0; 3], ks: [1.0; 3], exponent: e }, 0.0, 0.0, 1e-10);
            assert!((a - 1.0).abs() < 1e-8, "e {e}: {a}");
        }
    }
}

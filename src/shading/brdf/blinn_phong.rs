//! The normalized Blinn-Phong lobe `N(e) (n·h)^e`: the lobe itself, its normalization, its width, and how a grid
//! draws it (the inverse CDF of the half vector about the normal). It is smooth for light and viewer above the
//! horizon (`n·h > 0`), so its error bounds need no kink. `shaders/brdf/blinn_phong.glsl` mirrors it name for name.

use std::f64::consts::PI;

use glam::DVec3;

use super::{cos_power, cos_power_direction, one_minus_dot};

/// Normalization of the Blinn-Phong lobe `(n·h)^e` that makes its directional albedo exactly 1 at normal incidence:
/// `∫ (n·h)^e cos θ dω = 8π (e + 2^{−e/2}) / ((e + 2)(e + 4))` with `n·h = cos(θ/2)` there (substitute
/// `u = cos(θ/2)`), so the factor is `(e + 2)(e + 4) / (8π (e + 2^{−e/2}))`; `1/π` at e = 0 (Lambertian). The often
/// used `(e + 8)/(8π)` approximates it (Akenine-Möller et al., Real-Time Rendering, §9.8).
pub fn blinn_phong_normalization(exponent: f64) -> f64 {
    (exponent + 2.0) * (exponent + 4.0) / (8.0 * PI * (exponent + (-0.5 * exponent).exp2()))
}

/// The specular lobe of the normalized Blinn-Phong BRDF: `N(e) (n·h)^e`, h the unit half vector of l and v
/// (0 where n·h ≤ 0 or l = −v). Symmetric in l and v, so reciprocal.
pub fn blinn_phong_lobe(n: DVec3, l: DVec3, v: DVec3, exponent: f64) -> f64 {
    let sum = l + v;
    let len2 = sum.length_squared();
    if len2 == 0.0 {
        return 0.0;
    }
    let h = sum / len2.sqrt();
    if n.dot(h) <= 0.0 {
        return 0.0;
    }
    blinn_phong_normalization(exponent) * cos_power(one_minus_dot(n, h), exponent)
}

/// The angular width \[rad\] about the lobe's peak over which the disk integral crowds its samples
/// (`shading::lobe::lobe_width`): `(n·h)^e` falls to about `e^{-1/2}` at `θh ≈ 1/√e`, and ω turns twice as fast as h.
pub fn blinn_phong_lobe_width(exponent: f64) -> f64 {
    2.0 / (exponent + 1.0).sqrt()
}

/// One sample of the sky's inverse-CDF grid: the half vector h with `cos θh = (1 − ξ1)^{1/(e+1)}` and azimuth φ
/// about `axis` (the normal; frame `t`, `b`), `pdf_h = (e+1)/(2π) (n·h)^e`, reflected to `ω = 2(v·h)h − v`
/// (`dω = 4 (v·h) dh`), and its weight `lobe (n·ω)+ / pdf_ω`; 0 (and ω = n) where h faces away from the viewer.
pub fn blinn_phong_lobe_sample(
    n: DVec3,
    v: DVec3,
    (axis, t, b): (DVec3, DVec3, DVec3),
    exponent: f64,
    xi1: f64,
    phi: f64,
) -> (f64, DVec3) {
    let h = cos_power_direction(axis, t, b, exponent, xi1, phi);
    let vh = v.dot(h);
    if vh <= 0.0 {
        return (0.0, n);
    }
    let omega = 2.0 * vh * h - v;
    let value = blinn_phong_normalization(exponent) * 4.0 * vh * n.dot(omega).max(0.0) * 2.0 * PI / (exponent + 1.0);
    (value, omega)
}

//! BRDFs ρ(l_in, l_out) [1/sr]: the ratio of reflected radiance to incident irradiance.
//!
//! Each model is a Lambertian part plus, for the specular models, a lobe scaled by `ks`; `kd + ks ≤ 1` per channel
//! (checked when a scene is loaded) keeps every model energy-conserving. Vectors are unit, in world space: `n` the
//! shading normal, `l` towards the light, `v` towards the viewer. Each specular model has its own file (its lobe,
//! width, sampling and kink: `phong`, `blinn_phong`, `ward`, `metallic_roughness` (glTF's); a measured table's in `shading::measured`); this one
//! keeps the Lambertian term and the arithmetic they share. `shaders/brdf.glsl` and `shaders/brdf/` mirror them
//! name for name.
//!
//! Precision: a lobe `cosᵉα` for large e is where f32 loses most. `cos α` itself is rounded to `u = 6e-8`, an
//! error `e·u` relative after the power (6e-4 at e = 1e4, lavapipe's `pow` adds as much again). Here `1 − cos α` is
//! computed without cancellation as `|a − b|²/2` (for unit a, b) and `cosᵉα = exp(e · log1p(−(1 − cos α)))`
//! ([`cos_power`]); no `acos`, and no division by a cosine that can reach 0.

use std::f64::consts::FRAC_1_PI;

use glam::DVec3;

pub mod blinn_phong;
pub mod metallic_roughness;
pub mod phong;
pub mod ward;

pub use blinn_phong::{blinn_phong_lobe, blinn_phong_normalization};
pub use phong::phong_lobe;
pub use ward::ward_lobe;

/// Lambertian BRDF `ρ = albedo/π` [1/sr] (Lambert 1760; e.g. PBR 4th ed. §9.2). Its directional albedo
/// `∫ ρ cosθ dω` over the hemisphere is exactly `albedo`.
pub fn lambert_brdf(albedo: f64) -> f64 {
    albedo * FRAC_1_PI
}

/// `1 − a·b` for unit vectors a, b, as `|a − b|²/2`: no cancellation when a ≈ b (the peak of a narrow lobe),
/// where the dot product would lose `1/(1 − a·b)` of its relative precision.
pub fn one_minus_dot(a: DVec3, b: DVec3) -> f64 {
    0.5 * (a - b).length_squared()
}

/// `(1 − x)^e` for `0 ≤ x`, as `exp(e · log1p(−x))`: 1 for e = 0, 0 for x ≥ 1 (a cosine ≤ 0) when e > 0.
/// Accurate where `x` is, unlike `pow(1 − x, e)` whose base is already rounded.
pub fn cos_power(one_minus_cos: f64, exponent: f64) -> f64 {
    if exponent == 0.0 {
        return 1.0;
    }
    if one_minus_cos >= 1.0 {
        return 0.0;
    }
    (exponent * (-one_minus_cos).ln_1p()).exp()
}

/// The mirror direction of `l` about `n`: `2(n·l)n − l`.
pub fn mirror(l: DVec3, n: DVec3) -> DVec3 {
    2.0 * n.dot(l) * n - l
}

/// `exp(x) − 1` without cancellation for small x (Kahan's trick: exact where `exp` and `ln` are accurate).
pub fn exp_minus_one(x: f64) -> f64 {
    let u = x.exp();
    if u == 1.0 {
        return x;
    }
    let um1 = u - 1.0;
    if um1 == -1.0 {
        return -1.0;
    }
    um1 * x / u.ln()
}

/// A direction at angle a from the unit `axis` with `cos a = (1 − ξ1)^{1/(e+1)}` and azimuth φ in the frame
/// (t, b) about it: the inverse CDF of the pdf `(e+1)/(2π) cosᵉa`. `1 − cos a` is formed as
/// `−expm1(ln(1 − ξ1)/(e+1))`: for large e the exponent is tiny and `1 − (1 − ξ1)^{1/(e+1)}` would cancel.
pub fn cos_power_direction(axis: DVec3, t: DVec3, b: DVec3, exponent: f64, xi1: f64, phi: f64) -> DVec3 {
    let one_minus_cos = -exp_minus_one((-xi1).ln_1p() / (exponent + 1.0));
    let cos_a = 1.0 - one_minus_cos;
    let sin_a = (one_minus_cos * (1.0 + cos_a)).sqrt();
    cos_a * axis + sin_a * (phi.cos() * t + phi.sin() * b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn exp_minus_one_is_accurate_near_zero() {
        for x in [1e-12f64, -3e-7, 1e-3, -0.5, 2.0] {
            let want = x.exp_m1();
            assert!(((exp_minus_one(x) - want) / want).abs() < 1e-15, "{x}");
        }
    }

    #[test]
    fn lambert_albedo_integrates_to_albedo() {
        // ∫ρ cosθ dω = 2π ∫₀^{π/2} ρ cosθ sinθ dθ, by composite Simpson in θ (error O(h⁴) ≈ 1e-13 here).
        let albedo = 0.73;
        let n = 2000;
        let h = std::f64::consts::FRAC_PI_2 / n as f64;
        let f = |t: f64| lambert_brdf(albedo) * t.cos() * t.sin();
        let mut sum = f(0.0) + f(std::f64::consts::FRAC_PI_2);
        for i in 1..n {
            sum += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        let integral = 2.0 * std::f64::consts::PI * sum * h / 3.0;
        assert!((integral - albedo).abs() < 1e-9, "{integral}");
    }

    #[test]
    fn cos_power_is_exact_at_the_ends_and_beats_pow_near_one() {
        assert_eq!(cos_power(0.3, 0.0), 1.0);
        assert_eq!(cos_power(1.0, 0.0), 1.0);
        assert_eq!(cos_power(1.0, 5.0), 0.0);
        assert_eq!(cos_power(0.0, 1e6), 1.0);
        assert!((cos_power(0.5, 2.0) - 0.25).abs() < 1e-16);
        // (1 − 1e-9)^1e6 = exp(1e6 · log1p(−1e-9)) ≈ exp(−1e-3 − 5e-13).
        let want = (-1e-3f64 - 5e-13).exp();
        assert!((cos_power(1e-9, 1e6) - want).abs() < 1e-15);
        // The rounded base loses what the exponent amplifies: pow(1 − 1e-9, 1e6) is off by ~1e-7 relative.
        assert!(((1.0 - 1e-9f64).powf(1e6) - want).abs() > 1e-12);
    }

    #[test]
    fn one_minus_dot_has_no_cancellation() {
        let a = DVec3::new(1.0, 0.0, 0.0);
        let b = DVec3::new((1e-6f64).cos(), (1e-6f64).sin(), 0.0);
        // 1 − cos(1e-6) = 5e-13 − …: the dot product gives it to 1e-4 relative at best, |a − b|²/2 to ~1e-16.
        let want = 2.0 * (0.5e-6f64).sin().powi(2);
        assert!((one_minus_dot(a, b) - want).abs() < 1e-27, "{}", one_minus_dot(a, b));
    }

    #[test]
    fn blinn_phong_normalization_limits() {
        assert!((blinn_phong_normalization(0.0) - FRAC_1_PI).abs() < 1e-16);
        // For large e, N → e/(8π) · (1 + 6/e).
        let e = 1e6;
        assert!(((blinn_phong_normalization(e) - (e + 6.0) / (8.0 * PI)) / blinn_phong_normalization(e)).abs() < 1e-11);
    }

    #[test]
    fn lobes_are_finite_and_zero_where_they_should_be() {
        let n = DVec3::Y;
        let t = DVec3::X;
        let b = DVec3::Z;
        let l = DVec3::new(0.6, 0.8, 0.0);
        let mirror = DVec3::new(-0.6, 0.8, 0.0);
        for e in [0.0, 1.0, 100.0, 1e4, 1e6] {
            assert!((phong_lobe(n, l, mirror, e) - (e + 2.0) / (2.0 * PI)).abs() <= 1e-9 * (e + 2.0));
            assert!(blinn_phong_lobe(n, l, mirror, e).is_finite());
            // Opposite directions on the horizon: no half vector, no NaN.
            assert_eq!(blinn_phong_lobe(n, DVec3::X, -DVec3::X, e), 0.0);
        }
        assert_eq!(ward_lobe(n, t, b, DVec3::X, -DVec3::X, 0.1, 0.1), 0.0);
        let peak = ward_lobe(n, t, b, n, n, 0.2, 0.1);
        assert!((peak - 1.0 / (4.0 * PI * 0.02)).abs() < 1e-12, "{peak}");
        // Grazing light and view in the mirror configuration: large but finite (1/(4π α² cos²) = 8e14 here).
        let graze = DVec3::new(1.0, 1e-7, 0.0).normalize();
        let graze_v = DVec3::new(-1.0, 1e-7, 0.0).normalize();
        let w = ward_lobe(n, t, b, graze, graze_v, 0.1, 0.1);
        assert!(w.is_finite() && (w * 4.0 * PI * 0.01 * 1e-14 - 1.0).abs() < 1e-6, "{w}");
        for below in [DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, -1e-30, 0.0)] {
            assert_eq!(ward_lobe(n, t, b, below, -below, 0.1, 0.1), 0.0);
        }
    }
}

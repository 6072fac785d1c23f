//! BRDFs ρ(l_in, l_out) [1/sr]: the ratio of reflected radiance to incident irradiance.
//!
//! `shaders/brdf.glsl` mirrors these functions name for name.

use std::f64::consts::FRAC_1_PI;

/// Lambertian BRDF `ρ = albedo/π` [1/sr] (Lambert 1760; e.g. PBR 4th ed. §9.2). Its directional albedo
/// `∫ ρ cosθ dω` over the hemisphere is exactly `albedo`.
pub fn lambert_brdf(albedo: f64) -> f64 {
    albedo * FRAC_1_PI
}

#[cfg(test)]
mod tests {
    use super::*;

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
}

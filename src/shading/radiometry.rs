//! Radiometry: angles, solid angles and the irradiance each light gives a surface.
//!
//! Units: angles in radians unless a name says degrees; solid angles in steradians [sr]; radiance `L` in
//! W/(m²·sr); irradiance `E` in W/m². `shaders/radiometry.glsl` mirrors these functions name for name.
//!
//! Definitions (e.g. Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed., §4.1):
//! - irradiance at `x` with normal `n`: `E = ∫ L(x, l) (n·l) dΩ` over the hemisphere;
//! - solid angle of a cone of half-angle `a`: `Ω = 2π(1 − cos a)`.

use std::f64::consts::PI;

/// The sun's mean angular diameter seen from the Earth [degrees].
pub const SUN_ANGULAR_DIAMETER_DEGREES: f64 = 0.53;

/// Default irradiance on a surface facing the sun, `E⊥` [W/m²].
pub const DEFAULT_SUN_IRRADIANCE: f64 = 1000.0;

pub fn degrees_to_radians(degrees: f64) -> f64 {
    degrees * (PI / 180.0)
}

pub fn radians_to_degrees(radians: f64) -> f64 {
    radians * (180.0 / PI)
}

/// Exact solid angle [sr] of a cone of half-angle `half_angle` [rad]: `2π(1 − cos a)`.
///
/// Precision: for small cones `1 − cos a` cancels catastrophically (for the sun, `cos a = 1 − 1.07·10⁻⁵`, losing
/// five digits). The identity `1 − cos a = 2 sin²(a/2)` gives the same value without any subtraction.
pub fn cone_solid_angle(half_angle: f64) -> f64 {
    let s = (0.5 * half_angle).sin();
    4.0 * PI * s * s
}

/// Small-cone estimate of a solid angle [sr]: `area of the base / height²` (base area [m²], height [m]).
///
/// For a sphere of radius `r` seen from distance `d` (the sun) the base is its cross-section `π r²` and the
/// estimate is `π sin²a`, low by ≈ `a²/4` relative (5.3·10⁻⁶ for the sun). For a flat disk of radius `r` at
/// height `d` it is `π tan²a`, high by ≈ `3a²/4`.
pub fn small_cone_solid_angle(base_area: f64, height: f64) -> f64 {
    base_area / (height * height)
}

/// The sun's solid angle `Ω_sun` [sr] from its angular diameter `δ` [rad]: `2π(1 − cos(δ/2))`.
pub fn sun_solid_angle(angular_diameter: f64) -> f64 {
    cone_solid_angle(0.5 * angular_diameter)
}

/// Projected solid angle [sr] of the sun's cone at normal incidence: `∫ cosθ dΩ = π sin²(δ/2)`.
///
/// This is the exact ratio `E⊥ / L_sun`; it equals `Ω_sun (1 + cos(δ/2))/2`, i.e. `Ω_sun` to within
/// `sin²(δ/4)` relative (5.3·10⁻⁶ at 0.53°).
pub fn sun_projected_solid_angle(angular_diameter: f64) -> f64 {
    let s = (0.5 * angular_diameter).sin();
    PI * s * s
}

/// `E⊥` [W/m²] from the sun's radiance `L_sun` [W/(m²·sr)]: `E⊥ = L_sun · π sin²(δ/2)` (≈ `L_sun · Ω_sun`).
pub fn sun_irradiance_from_radiance(radiance: f64, angular_diameter: f64) -> f64 {
    radiance * sun_projected_solid_angle(angular_diameter)
}

/// `L_sun` [W/(m²·sr)] from `E⊥` [W/m²]; the inverse of [`sun_irradiance_from_radiance`].
pub fn sun_radiance_from_irradiance(irradiance: f64, angular_diameter: f64) -> f64 {
    irradiance / sun_projected_solid_angle(angular_diameter)
}

/// Irradiance [W/m²] from the sun treated as a direction (a delta light): `E = E⊥ · max(0, n·l)`.
///
/// `n_dot_l` is the cosine between the unit surface normal and the unit direction towards the sun.
pub fn sun_irradiance_delta(irradiance_normal: f64, n_dot_l: f64) -> f64 {
    irradiance_normal * n_dot_l.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn degrees_round_trip() {
        assert_eq!(degrees_to_radians(180.0), PI);
        assert!((radians_to_degrees(degrees_to_radians(0.53)) - 0.53).abs() < 1e-15);
    }

    #[test]
    fn cone_solid_angle_matches_closed_forms() {
        // Hemisphere: 2π; full sphere: 4π; 60°: 2π(1 − 1/2) = π.
        assert!(rel(cone_solid_angle(PI / 2.0), 2.0 * PI) < 1e-15);
        assert!(rel(cone_solid_angle(PI), 4.0 * PI) < 1e-15);
        assert!(rel(cone_solid_angle(PI / 3.0), PI) < 1e-15);
        // Against the textbook form, whose own cancellation error is ulp(1)/(1 − cos a): 4e-14 at a = 0.1.
        for a in [0.5, 1.0, 2.0] {
            assert!(rel(cone_solid_angle(a), 2.0 * PI * (1.0 - f64::cos(a))) < 1e-14);
        }
        assert!(rel(cone_solid_angle(0.1), 2.0 * PI * (1.0 - f64::cos(0.1))) < 1e-13);
    }

    #[test]
    fn sun_solid_angle_and_radiance_give_1000_w_per_m2() {
        let delta = degrees_to_radians(0.53);
        let omega = sun_solid_angle(delta);
        // Hand value: a = 0.265° = 4.6251e-3 rad, Ω ≈ π a² (1 − a²/12) = 6.7204e-5 sr.
        assert!(rel(omega, 6.7204e-5) < 1e-4, "{omega}");
        // The brief's figure: L_sun ≈ 1.47e7 W/(m²·sr) gives ≈ 1000 W/m² (within its 2 significant digits).
        let e = sun_irradiance_from_radiance(1.47e7, delta);
        assert!((e - 1000.0).abs() < 20.0, "{e}");
        // E⊥ = L_sun Ω_sun to within sin²(δ/4) = 5.3e-6 relative.
        let l = 1.47e7;
        assert!((rel(l * omega, e) - 5.3e-6).abs() < 0.1e-6, "{}", rel(l * omega, e));
        assert!(rel(sun_radiance_from_irradiance(e, delta), l) < 1e-15);
    }

    #[test]
    fn small_cone_estimate_error_is_tiny_for_the_sun_and_large_at_60_degrees() {
        // Sphere seen at half-angle a (the sun): base = π r², height = d, r/d = sin a.
        let sphere = |a: f64| rel(small_cone_solid_angle(PI * a.sin().powi(2), 1.0), cone_solid_angle(a));
        let a_sun = degrees_to_radians(0.265);
        assert!((sphere(a_sun) - 5.35e-6).abs() < 0.05e-6, "{}", sphere(a_sun));
        // 60° half-angle: π sin²60° = 3π/4 against π: 25% low.
        assert!((sphere(PI / 3.0) - 0.25).abs() < 1e-12);
        // Flat disk of radius tan a at height 1: π tan² a; at 60°: 3π against π, 200% high.
        let disk = |a: f64| rel(small_cone_solid_angle(PI * a.tan().powi(2), 1.0), cone_solid_angle(a));
        assert!((disk(a_sun) - 0.75 * a_sun * a_sun).abs() < 1e-9);
        assert!((disk(PI / 3.0) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn delta_sun_irradiance() {
        assert_eq!(sun_irradiance_delta(1000.0, 0.5), 500.0);
        assert_eq!(sun_irradiance_delta(1000.0, -0.5), 0.0);
        assert_eq!(sun_irradiance_delta(1000.0, 0.0), 0.0);
    }
}

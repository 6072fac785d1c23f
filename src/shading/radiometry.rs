//! Radiometry: angles and solid angles, and the units every light's file uses (each light's irradiance is in
//! `shading::lights`).
//!
//! Units: angles in radians unless a name says degrees; solid angles in steradians \[sr\]; radiance `L` in
//! W/(m²·sr); irradiance `E` in W/m². The GPU needs none of these (it is given the lights in world units).
//!
//! Definitions (e.g. Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed., §4.1):
//! - irradiance at `x` with normal `n`: `E = ∫ L(x, l) (n·l) dΩ` over the hemisphere;
//! - solid angle of a cone of half-angle `a`: `Ω = 2π(1 − cos a)`.

use std::f64::consts::PI;

pub use crate::scene::light::SUN_ANGULAR_DIAMETER_DEGREES;

/// Default irradiance on a surface facing the sun, `E⊥` [W/m²].
pub const DEFAULT_SUN_IRRADIANCE: f64 = 1000.0;

pub fn degrees_to_radians(degrees: f64) -> f64 {
    degrees * (PI / 180.0)
}

pub fn radians_to_degrees(radians: f64) -> f64 {
    radians * (180.0 / PI)
}

/// Exact solid angle \[sr\] of a cone of half-angle `half_angle` \[rad\]: `2π(1 − cos a)`.
///
/// Precision: for small cones `1 − cos a` cancels catastrophically (for the sun, `cos a = 1 − 1.07·10⁻⁵`, losing
/// five digits). The identity `1 − cos a = 2 sin²(a/2)` gives the same value without any subtraction.
pub fn cone_solid_angle(half_angle: f64) -> f64 {
    let s = (0.5 * half_angle).sin();
    4.0 * PI * s * s
}

/// Small-cone estimate of a solid angle \[sr\]: `area of the base / height²` (base area \[m²\], height \[m\]).
///
/// For a sphere of radius `r` seen from distance `d` (the sun) the base is its cross-section `π r²` and the
/// estimate is `π sin²a`, low by ≈ `a²/4` relative (5.3·10⁻⁶ for the sun). For a flat disk of radius `r` at
/// height `d` it is `π tan²a`, high by ≈ `3a²/4`.
pub fn small_cone_solid_angle(base_area: f64, height: f64) -> f64 {
    base_area / (height * height)
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
}

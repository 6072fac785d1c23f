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
    #[allow(unused_imports)]
    use crate::shading::lights::{disk::*, sky::*, sun::*};
    use glam::DVec3;

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

    use crate::shading::quadrature::{integrate, integrate_composite as composite};

    fn down_disk(height: f64, radius: f64) -> DiskGeometry {
        DiskGeometry { center: DVec3::new(0.0, height, 0.0), direction: -DVec3::Y, radius }
    }

    #[test]
    fn disk_on_axis_and_off_axis_match_the_view_factor_formulas() {
        for (f, r) in [(2.0, 0.1), (2.0, 0.5), (2.0, 2.0), (2.0, 8.0), (1.0, 1e-3)] {
            let disk = down_disk(f, r);
            let on_axis = disk_projected_solid_angle(DVec3::ZERO, DVec3::Y, &disk);
            assert!(rel(on_axis, PI * r * r / (r * r + f * f)) < 1e-14, "{f} {r}: {on_axis}");
            for rho in [0.01, 0.3, 1.0, 1.999, 2.0, 2.001, 5.0, 40.0] {
                let x = DVec3::new(rho * 0.6, 0.0, rho * 0.8);
                let got = disk_projected_solid_angle(x, DVec3::Y, &disk);
                let (a, b) = (f * f + rho * rho + r * r, f * f + rho * rho - r * r);
                let s = (a * a - 4.0 * rho * rho * r * r).sqrt();
                let want = 0.5 * PI * (1.0 - b / s);
                // The textbook form itself cancels for small sources: compare to its own precision.
                let tol = 1e-13 * (a / (want * s)).max(1.0);
                assert!(rel(got, want) < tol.max(1e-12), "f {f} R {r} ρ {rho}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn receivers_behind_or_in_the_plane_of_the_disk_get_nothing() {
        let disk = down_disk(2.0, 1.0);
        assert_eq!(disk_projected_solid_angle(DVec3::new(0.0, 3.0, 0.0), -DVec3::Y, &disk), 0.0);
        assert_eq!(disk_projected_solid_angle(DVec3::new(3.0, 2.0, 0.0), DVec3::Y, &disk), 0.0);
        // Facing away from the disk: the whole disk is below the horizon.
        assert_eq!(disk_projected_solid_angle(DVec3::ZERO, -DVec3::Y, &disk), 0.0);
    }

    #[test]
    fn small_source_estimate_on_the_floor_is_l0_a_cos4_over_f2() {
        let disk = down_disk(2.0, 0.1);
        for x in [DVec3::ZERO, DVec3::new(1.0, 0.0, 0.5), DVec3::new(-3.0, 0.0, 2.0)] {
            let cos = 2.0 / (disk.center - x).length();
            let want = PI * 0.01 * cos.powi(4) / 4.0;
            assert!(rel(disk_projected_solid_angle_small_source(x, DVec3::Y, &disk), want) < 1e-14);
        }
        // The estimate converges to the exact value as the disk shrinks, and differs for a big one.
        let exact = |r: f64| disk_projected_solid_angle(DVec3::ZERO, DVec3::Y, &down_disk(2.0, r));
        let small = |r: f64| disk_projected_solid_angle_small_source(DVec3::ZERO, DVec3::Y, &down_disk(2.0, r));
        assert!(rel(small(0.01), exact(0.01)) < 3e-5);
        assert!(rel(small(2.0), exact(2.0)) > 0.5);
    }

    #[test]
    fn rim_integrals_match_quadrature_on_and_off_the_axis() {
        for (b0, b) in [(2.0, 0.0), (2.0, 1e-9), (2.0, 1e-3), (2.0, 1.0), (2.0, 1.99)] {
            for (pa, pb) in [(-0.3, 1.2), (2.0, 4.0), (-3.5, -2.9), (-1.0, 5.0), (0.0, 2.0 * PI)] {
                let (j0, jc, js) = rim_integrals(pa, pb, b0, b);
                let w0 = composite(pa, pb, 200, 32, |p| 1.0 / (b0 + b * p.cos()));
                let wc = composite(pa, pb, 200, 32, |p| p.cos() / (b0 + b * p.cos()));
                let ws = composite(pa, pb, 200, 32, |p| p.sin() / (b0 + b * p.cos()));
                for (g, w) in [(j0, w0), (jc, wc), (js, ws)] {
                    assert!((g - w).abs() < 1e-11 * w0.abs(), "B0 {b0} B {b} [{pa}, {pb}]: {g} vs {w}");
                }
            }
        }
    }

    /// The sun's projected solid angle by quadrature over the cap's directions: polar angle β from the sun's
    /// centre, azimuth ψ, visible where n·ω > 0 (a ψ-interval for each β).
    fn sun_numerical(cos_theta: f64, sigma: f64, order: usize) -> f64 {
        let sin_theta = (1.0 - cos_theta * cos_theta).sqrt();
        let inner = |beta: f64| {
            // n·ω = cos β cos θ + sin β sin θ cos ψ > 0.
            let (sb, cb) = beta.sin_cos();
            let f = |psi: f64| (cb * cos_theta + sb * sin_theta * psi.cos()).max(0.0) * sb;
            let bound = if sb * sin_theta == 0.0 { 2.0 } else { -cb * cos_theta / (sb * sin_theta) };
            if bound <= -1.0 {
                integrate(0.0, 2.0 * PI, order, f)
            } else if bound >= 1.0 {
                0.0
            } else {
                2.0 * integrate(0.0, bound.acos(), order, f)
            }
        };
        // The ψ-interval changes form where the bound crosses ±1.
        let mut cuts = vec![0.0, sigma];
        let b = (cos_theta / sin_theta).abs().atan();
        if b > 0.0 && b < sigma {
            cuts.insert(1, b);
        }
        cuts.windows(2).map(|w| integrate(w[0], w[1], order, inner)).sum()
    }

    #[test]
    fn partly_set_sun_matches_numerical_integration_over_the_cap() {
        for diameter_degrees in [0.53, 5.0, 30.0] {
            let delta = degrees_to_radians(diameter_degrees);
            let sigma = 0.5 * delta;
            for frac in [-0.999, -0.7, -0.3, 0.0, 0.2, 0.6, 0.95, 0.999] {
                let theta = 0.5 * PI - frac * sigma;
                let e = sun_irradiance_disk(1.0, theta.cos(), delta);
                let want = sun_numerical(theta.cos(), sigma, 200) / sun_projected_solid_angle(delta);
                assert!(
                    (e - want).abs() < 1e-10 * want.max(1e-12) + 1e-14,
                    "δ {diameter_degrees}° frac {frac}: {e} vs {want}"
                );
            }
        }
    }

    #[test]
    fn sun_irradiance_is_continuous_and_monotone_through_sunset() {
        let delta = degrees_to_radians(0.53);
        let sigma = 0.5 * delta;
        let steps = 20_000;
        let mut prev = f64::INFINITY;
        let mut max_jump = 0.0f64;
        for i in 0..=steps {
            // Elevation of the centre from +2σ down to −2σ.
            let elevation = sigma * (2.0 - 4.0 * i as f64 / steps as f64);
            let e = sun_irradiance_disk(1000.0, elevation.sin(), delta);
            assert!(e <= prev + 1e-12, "not monotone at elevation {elevation}");
            if prev.is_finite() {
                max_jump = max_jump.max(prev - e);
            }
            prev = e;
        }
        // A step of 4σ/20000 in elevation moves E by at most E⊥ · step (the slope of E⊥ sin(elevation) ≤ E⊥).
        let step = 4.0 * sigma / steps as f64;
        assert!(max_jump <= 1000.0 * step * 1.0001, "jump {max_jump} > {}", 1000.0 * step);
        assert_eq!(sun_irradiance_disk(1000.0, (-1.01 * sigma).sin(), delta), 0.0);
        let above = (1.01 * sigma).sin();
        assert_eq!(sun_irradiance_disk(1000.0, above, delta), 1000.0 * above);
        // Half set: E/E⊥ = 2σ/(3π) to leading order (the visible half-disk's mean elevation is 4σ/(3π)).
        let half = sun_irradiance_disk(1.0, 0.0, delta);
        assert!(rel(half, 2.0 * sigma / (3.0 * PI)) < 1e-4, "{half}");
    }

    #[test]
    fn sky_irradiance_of_an_overcast_day() {
        assert!(rel(sky_irradiance(100.0, 1.0), PI * 100.0) < 1e-15);
        assert!(rel(sky_irradiance(100.0, 0.0), PI * 50.0) < 1e-15);
        assert_eq!(sky_irradiance(100.0, -1.0), 0.0);
    }

    #[test]
    fn atan_minus_identity_is_accurate_near_zero() {
        for t in [1e-8, 1e-4, 0.01, 0.3, 0.49, 0.5, 2.0, -0.2] {
            // Reference from the series in higher effective precision: compare with atan(t) − t where that is
            // well conditioned, and with −t³/3 + t⁵/5 for tiny t.
            let got = atan_minus_identity(t);
            let want = if t.abs() < 1e-3 { -t.powi(3) / 3.0 + t.powi(5) / 5.0 } else { t.atan() - t };
            let tol = if t.abs() < 1e-3 { 1e-15 } else { 1e-15 / (want / t).abs() };
            assert!(rel(got, want) < tol.max(1e-15), "{t}: {got} vs {want}");
        }
    }

    #[test]
    fn delta_sun_irradiance() {
        assert_eq!(sun_irradiance_delta(1000.0, 0.5), 500.0);
        assert_eq!(sun_irradiance_delta(1000.0, -0.5), 0.0);
        assert_eq!(sun_irradiance_delta(1000.0, 0.0), 0.0);
    }
}

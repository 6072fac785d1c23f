//! The sun: a disk of radiance `L_sun` [W/(m²·sr)] and angular diameter `θ` (0.53° by default), seen from a
//! surface as a small cone of solid angle `Ω_sun = 2π(1 − cos(θ/2))` \[sr\]. Everything sunshade computes of it in
//! one place: its solid angles and the irradiance it gives (as a delta light and as a disk cut by the horizon), its
//! specular lobe integrated over the disk, and the visible fraction of the disk. `shaders/lights/sun.glsl` mirrors
//! it name for name.

use std::f64::consts::PI;

use glam::DVec3;

use crate::scene::{Brdf, Sun};
use crate::shading::lobe::{
    normalized_lobe_integral, segment_lobe_integral, segment_lobe_integral_visible, specular_lobe_rgb, SampleRays,
};
use crate::shading::options::{ShadingOptions, SunModel};
use crate::shading::radiometry::cone_solid_angle;
use crate::shading::visibility::{grid_fraction, GridLight, Shadowing};
use crate::shading::{orthonormal_to, SurfacePoint};

/// The sun's solid angle `Ω_sun` \[sr\] from its angular diameter `δ` \[rad\]: `2π(1 − cos(δ/2))`.
pub fn sun_solid_angle(angular_diameter: f64) -> f64 {
    cone_solid_angle(0.5 * angular_diameter)
}

/// Projected solid angle \[sr\] of the sun's cone at normal incidence: `∫ cosθ dΩ = π sin²(δ/2)`.
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

/// `atan(t) − t` without the cancellation of the direct difference for small `t` (≈ −t³/3): the Taylor series
/// for `|t| < 0.5` (error below 1e-17 with 28 terms), the difference itself beyond, where it loses at most a factor
/// 14 of relative precision.
pub fn atan_minus_identity(t: f64) -> f64 {
    if t.abs() >= 0.5 {
        return t.atan() - t;
    }
    let t2 = t * t;
    // Σ_{k≥1} (−1)^k t^{2k+1}/(2k+1), summed from the smallest term up.
    let mut sum = 0.0;
    for k in (1..=28).rev() {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        sum = sum * t2 + sign / (2 * k + 1) as f64;
    }
    sum * t2 * t
}

/// Irradiance [W/m²] from the sun as a disk (a cone of directions of half-angle δ/2 and uniform radiance) on a
/// surface whose normal makes angle θ with the sun's centre (`cos_theta = n·l`).
///
/// While the whole disk is above the horizon (`cos θ ≥ sin(δ/2)`) the result is exactly `E⊥ cos θ` (the cap's
/// projected solid angle is `π sin²(δ/2) cos θ`). Within δ/2 of the horizon only part of the disk is visible; by
/// the contour integral over its boundary (the cap's rim above the horizon and the horizon arc inside the cap;
/// the same result as Snyder's sphere-light formula, e.g. Lagarde & de Rousiers 2014, §4.7.2):
///
/// `E/L = s² cosθ (π − φ₀) − c s sinθ sin φ₀ + atan(t)`, with `s, c = sin, cos(δ/2)`,
/// `cos φ₀ = cot(δ/2) cot θ`, `t = s sinθ sinφ₀ / c`.
///
/// Precision: for the sun the last two terms are each about `1/σ ≈ 216` and cancel to ~1e-3. Since
/// `c s sinθ sinφ₀ = c² t`, the sum is rewritten `s² (cosθ (π − φ₀) + t) + (atan(t) − t)`, and `atan(t) − t` is
/// taken from its series: no term cancels. `acos` is avoided in favour of `atan2` (lavapipe's `acos` is off by up to
/// 4e-4). E goes to 0 continuously and monotonically as the sun sets.
pub fn sun_irradiance_disk(irradiance_normal: f64, cos_theta: f64, angular_diameter: f64) -> f64 {
    let (s, c) = (0.5 * angular_diameter).sin_cos();
    if cos_theta >= s {
        return irradiance_normal * cos_theta;
    }
    if cos_theta <= -s {
        return 0.0;
    }
    let sin_theta = ((1.0 - cos_theta) * (1.0 + cos_theta)).sqrt();
    let k = ((c * cos_theta) / (s * sin_theta)).clamp(-1.0, 1.0);
    let sin_phi0 = ((1.0 - k) * (1.0 + k)).sqrt();
    let pi_minus_phi0 = sin_phi0.atan2(-k);
    let t = s * sin_theta * sin_phi0 / c;
    let projected = s * s * (cos_theta * pi_minus_phi0 + t) + atan_minus_identity(t);
    irradiance_normal * projected / (PI * s * s)
}

/// `∫ lobe(ω) (n·ω)+ dω` over the sun's cap (half-angle `σ = δ/2`), per unit radiance. The directions of the cap
/// are exactly those through a disk of radius `tan σ` one unit away along `direction`, facing back, so the graded
/// grid of `segment_lobe_integral` integrates it, lobes narrower than the sun included (a Phong lobe of
/// e = 1e6 is 0.06° wide against the sun's 0.53°).
/// Per channel, the first (an analytic lobe's three are equal).
pub fn sun_lobe_integral(brdf: &Brdf, p: &SurfacePoint, direction: DVec3, angular_diameter: f64, per_axis: u32) -> f64 {
    let sums = segment_lobe_integral(brdf, p, direction, -direction, (0.5 * angular_diameter).tan(), per_axis);
    normalized_lobe_integral(sums, sun_projected_solid_angle_above(p.normal.dot(direction), angular_diameter))[0]
}

/// The projected solid angle \[sr\] of the sun's cap above a surface's horizon, `∫ (n·ω)+ dω`: the disk sun's
/// irradiance per unit radiance, `π sin²(δ/2) E/E⊥`.
pub fn sun_projected_solid_angle_above(n_dot_l: f64, angular_diameter: f64) -> f64 {
    let s = (0.5 * angular_diameter).sin();
    PI * s * s * sun_irradiance_disk(1.0, n_dot_l, angular_diameter)
}

/// The cosine-weighted visible fraction of the sun's disk (direction `l`, angular diameter δ \[rad\]) from a point
/// with unit normal `n`.
///
/// Where `s.slices` asks for it and the occluders are opaque triangles, the reference takes it by slices instead
/// (`sun_slices`; the GPU too, shaders/slices.glsl, where its shader walks the BVH).
pub fn sun_visible_fraction(s: &Shadowing, n: DVec3, l: DVec3, angular_diameter: f64) -> f64 {
    if let Some(v) =
        s.by_slices(|rows| crate::shading::sun_slices::sun_visible_fraction_sliced(s, n, l, angular_diameter, rows))
    {
        return v;
    }
    let radius = (0.5 * angular_diameter).tan();
    let t = orthonormal_to(l);
    let b = l.cross(t);
    let light = GridLight::Sun { n, l, t, b, radius };
    // The grid's rays leave within the sun's cone and above the surface: the occluders within that reach, where
    // the occluders can list them, answer each as the whole would. The cone a little wider than the disk
    // (2^-20 of its half-angle) for the rounding of the rays' directions.
    let reach =
        crate::shading::sun_slices::sun_reach(s.origin, n, l, 0.5 * angular_diameter * (1.0 + 1.0 / 1_048_576.0));
    match s.occluders.narrowed(&reach) {
        Some(near) => grid_fraction(&Shadowing { occluders: near.as_ref(), ..*s }, &light),
        None => grid_fraction(s, &light),
    }
}

/// The sun's irradiance [W/m²] per channel at `point` from its visible part, `E · v`, with `E` the delta or the
/// disk model's (`options.sun`) and `v` its visible fraction (`shadow`: the rays that shadow the sun, if any), and
/// `v`, which [`sun_specular_visible`] reuses (1 unshadowed, or where the disk is wholly below the horizon). The
/// GPU keeps `v` in a global as it finds it (`sun_ray_fraction`, as `sun_map_fraction` for maps).
pub fn sun_irradiance_visible(
    sun: &Sun,
    point: &SurfacePoint,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> ([f64; 3], f64) {
    let l = sun.direction.as_dvec3();
    let n_dot_l = point.normal.dot(l);
    let delta = sun.angular_diameter as f64;
    let unoccluded = sun.irradiance.map(|perp| match options.sun {
        SunModel::Disk => sun_irradiance_disk(perp as f64, n_dot_l, delta),
        SunModel::Delta => sun_irradiance_delta(perp as f64, n_dot_l),
    });
    let v = match shadow {
        Some(s) if unoccluded.iter().any(|&x| x > 0.0) => match options.sun {
            SunModel::Disk => sun_visible_fraction(s, point.normal, l, delta),
            SunModel::Delta => f64::from(u8::from(s.visible_along(l))),
        },
        _ => 1.0,
    };
    (unoccluded.map(|u| u * v), v)
}

/// The sun's specular term at `point`: `∫ lobe(ω) L_sun (n·ω)+ V(ω) dω` over its disk [W/(m²·sr)] per channel, to
/// be scaled by `ks`. The delta model takes the lobe at the centre, `lobe(l) E⊥ (n·l)+`; the disk model integrates
/// it over the cap (`segment_lobe_integral_visible`, radiance `L_sun = E⊥ / (π sin²(δ/2))`). `sun_fraction` is
/// [`sun_irradiance_visible`]'s `v`: the lobe's samples cast their rays only in the sun's penumbra, where it is
/// strictly between 0 and 1 (that grid locates the edges): where it sees all of the disk the lobe is
/// unoccluded, where it sees none the lobe is 0, as the diffuse part takes them (an occluder slipping between all
/// of that grid's rays is missed by both alike).
pub fn sun_specular_visible(
    sun: &Sun,
    brdf: &Brdf,
    point: &SurfacePoint,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
    sun_fraction: f64,
) -> [f64; 3] {
    let l = sun.direction.as_dvec3();
    match options.sun {
        SunModel::Delta => {
            let cos = point.normal.dot(l).max(0.0);
            let mut factor = specular_lobe_rgb(brdf, point, l).map(|lobe| lobe * cos);
            if factor.iter().any(|&x| x > 0.0) && shadow.is_some_and(|s| !s.visible_along(l)) {
                factor = [0.0; 3];
            }
            [0, 1, 2].map(|c| factor[c] * sun.irradiance[c] as f64)
        }
        SunModel::Disk => {
            let delta = sun.angular_diameter as f64;
            let radius = (0.5 * delta).tan();
            let penumbra = sun_fraction > 0.0 && sun_fraction < 1.0;
            let rays = shadow.filter(|_| penumbra).map(SampleRays::Along);
            let sums = segment_lobe_integral_visible(brdf, point, l, -l, radius, options.sun_samples_per_axis, rays);
            let mut integral =
                normalized_lobe_integral(sums, sun_projected_solid_angle_above(point.normal.dot(l), delta));
            if shadow.is_some() && sun_fraction == 0.0 {
                integral = [0.0; 3];
            }
            let s = (0.5 * delta).sin();
            [0, 1, 2].map(|c| integral[c] * sun.irradiance[c] as f64 / (PI * s * s))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::rel;
    use super::*;
    use crate::shading::quadrature::integrate;
    use crate::shading::radiometry::*;

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

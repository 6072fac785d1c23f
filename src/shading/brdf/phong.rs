//! The modified Phong lobe (Lafortune & Willems 1994): the lobe itself, its width, how a grid draws it (the inverse
//! CDF about the mirror direction), and what its error bounds need to know (its kink at α = 90°).
//! `shaders/brdf/phong.glsl` mirrors it name for name.

use std::f64::consts::PI;

use glam::DVec3;

use super::{cos_power, cos_power_direction, mirror, one_minus_dot};

/// The specular lobe of the modified Phong BRDF (Lafortune & Willems 1994, "Using the modified Phong reflectance
/// model for physically based rendering"): `(e + 2)/(2π) cosᵉα`, α between the mirror direction of `l` and `v`
/// (0 where cos α ≤ 0). The `(e + 2)/(2π)` normalization makes the lobe's directional albedo at most 1, exactly 1
/// at normal incidence. Symmetric in l and v (`r(l)·v = r(v)·l`), so reciprocal.
pub fn phong_lobe(n: DVec3, l: DVec3, v: DVec3, exponent: f64) -> f64 {
    (exponent + 2.0) / (2.0 * PI) * cos_power(one_minus_dot(mirror(l, n), v), exponent)
}

/// The angular width \[rad\] about the lobe's peak over which the disk integral crowds its samples
/// (`shading::lobe::lobe_width`): `cosᵉα` falls to about `e^{-1/2}` at `α ≈ 1/√e`.
pub fn phong_lobe_width(exponent: f64) -> f64 {
    1.0 / (exponent + 1.0).sqrt()
}

/// One sample of the sky's inverse-CDF grid (`lights::sky::sky_lobe_hemisphere_grid`): the direction ω with
/// `cos α = (1 − ξ1)^{1/(e+1)}` and azimuth φ about `axis` (the mirror direction of the viewer; frame `t`, `b`), pdf
/// `(e+1)/(2π) cosᵉα`, and its weight `lobe (n·ω)+ / pdf = (e+2)/(e+1) (n·ω)+`.
pub fn phong_lobe_sample(n: DVec3, axis: DVec3, t: DVec3, b: DVec3, exponent: f64, xi1: f64, phi: f64) -> (f64, DVec3) {
    let omega = cos_power_direction(axis, t, b, exponent, xi1, phi);
    ((exponent + 2.0) / (exponent + 1.0) * n.dot(omega).max(0.0), omega)
}

/// The slope jump `J` (relative to the lobe's peak) where the light crosses the lobe's zero, for the error bounds
/// (`accuracy::bounds`), and whether a bound can be claimed at all: `max(0, cos α)ᵉ` bends at α = 90° with a slope
/// jump of e for 1 ≤ e < 2 (a continuous slope but unbounded curvature above 1), and has an unbounded slope there
/// for 0 < e < 1 (`None`: no claim). Smooth otherwise (0).
pub fn phong_lobe_kink(exponent: f64) -> Option<f64> {
    if exponent > 0.0 && exponent < 1.0 {
        None
    } else if (1.0..2.0).contains(&exponent) {
        Some(exponent)
    } else {
        Some(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sample_weight_is_the_lobe_over_its_pdf() {
        let (n, v) = (DVec3::Z, DVec3::new(0.3, 0.0, 1.0).normalize());
        let axis = mirror(v, n);
        let t = crate::shading::orthonormal_to(axis);
        let b = axis.cross(t);
        for e in [1.0, 20.0, 500.0] {
            let (weight, omega) = phong_lobe_sample(n, axis, t, b, e, 0.37, 1.1);
            let cos_a = omega.dot(axis);
            let pdf = (e + 1.0) / (2.0 * PI) * cos_a.powf(e);
            let want = phong_lobe(n, omega, v, e) * n.dot(omega).max(0.0) / pdf;
            assert!((weight - want).abs() <= 1e-12 * want, "e = {e}: {weight} against {want}");
        }
    }
}

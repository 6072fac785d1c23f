//! The overcast sky: uniform radiance `L0` [W/(m²·sr)] over the directions above the horizontal. Everything
//! sunshade computes of it in one place: the irradiance it gives a tilted surface, its specular lobe integrated over
//! the sky (over the lune of directions above both horizons, `shading::sky_lune`), and its visible fraction.
//! `shaders/lights/sky.glsl` mirrors it name for name.

use std::f64::consts::PI;

use glam::DVec3;

use crate::scene::Brdf;
use crate::shading::lobe::{lobe_sample, sampling_axis, sky_grid_per_axis};
use crate::shading::sky_lune::{sky_lobe_in_lune, sky_lune_blend, Lune};
use crate::shading::visibility::{grid_fraction, sky_lune, GridLight, Shadowing};
use crate::shading::{orthonormal_to, SurfacePoint};

/// Irradiance [W/m²] from a uniform overcast sky of radiance `L0` [W/(m²·sr)] over the whole sphere, unoccluded,
/// on a surface tilted by `t` from up (`n_dot_up = cos t`): `E = π L0 (1 + cos t)/2`.
pub fn sky_irradiance(radiance: f64, n_dot_up: f64) -> f64 {
    PI * radiance * 0.5 * (1.0 + n_dot_up)
}

/// `∫ lobe(ω) (n·ω)+ dω` over the sky (the surface's hemisphere above the horizontal, per unit radiance):
/// `sky_lobe_integral_visible` unoccluded. Per channel, the first (an analytic lobe's three are equal).
pub fn sky_lobe_integral(brdf: &Brdf, p: &SurfacePoint, per_axis: u32) -> f64 {
    sky_lobe_integral_visible(brdf, p, per_axis, None)[0]
}

/// [`sky_lobe_integral`] per channel, with a shadow ray along each sample's direction (`None`: unoccluded).
///
/// The sky is the upper hemisphere (up = +Y). The inverse-CDF grid ([`sky_lobe_hemisphere_grid`]) runs over the
/// whole hemisphere about n, whose coordinates know no horizontal (an indicator `ω·up > 0` would jump inside its
/// cells: first-order convergence, and a sample within rounding of the horizontal counted by one renderer and not
/// the other). So the part below the horizontal, the lower lune, is integrated on a grid whose edge is the
/// horizontal (`sky_lune::sky_lobe_in_lune`) and subtracted, while the lobe's peak is above the horizontal; once
/// it is below, the upper lune's own grid is taken; a blend between (`sky_lune::sky_lune_blend`, continuous). A
/// difference below 0 (the truth is not) is taken as 0.
///
/// A measured table takes the upper lune's grid wherever the surface is tilted: through a table's piecewise-linear
/// lookup the lower lune's sum moves with the viewer's rounding, and subtracted it moved silhouette pixels by up
/// to 2.4e-4 between the GPU's f32 and the reference (the analytic lobes' blend: 2.2e-5; the upper lune alone:
/// 9.5e-6, within `render --check`'s 1e-5; a sphere of tabulated Ward α = 0.2 at 64², 16² and 32² samples).
pub fn sky_lobe_integral_visible(brdf: &Brdf, p: &SurfacePoint, per_axis: u32, shadow: Option<&Shadowing>) -> [f64; 3] {
    let s = sky_lune_blend(brdf, p);
    let direct = if s > 0.0 { sky_lobe_in_lune(brdf, p, per_axis, Lune::Above, shadow) } else { [0.0; 3] };
    let by_difference = if s < 1.0 {
        let whole = sky_lobe_hemisphere_grid(brdf, p, per_axis, shadow);
        let below = sky_lobe_in_lune(brdf, p, per_axis, Lune::Below, None);
        let floor = if brdf.lobe_can_be_negative() { f64::NEG_INFINITY } else { 0.0 };
        [0, 1, 2].map(|c| (whole[c] - below[c]).max(floor))
    } else {
        [0.0; 3]
    };
    [0, 1, 2].map(|c| (1.0 - s) * by_difference[c] + s * direct[c])
}

/// `∫ lobe(ω) (n·ω)+ dω` over the surface's whole hemisphere, per unit radiance, per channel, by a stratified grid
/// of `per_axis²` cells (`lobe::sky_grid_per_axis`) through the lobe's inverse CDF, each sample weighted by lobe/pdf; each sample above the
/// horizontal that contributes casts its shadow ray (`shadow`), those below count as unoccluded (the lower lune's
/// unoccluded integral takes them out again).
pub fn sky_lobe_hemisphere_grid(brdf: &Brdf, p: &SurfacePoint, per_axis: u32, shadow: Option<&Shadowing>) -> [f64; 3] {
    let visible = |omega: DVec3| shadow.is_none_or(|s| omega.y <= 0.0 || s.visible_along(omega));
    let axis = sampling_axis(brdf, p);
    let t = orthonormal_to(axis);
    let b = axis.cross(t);
    let per_axis = sky_grid_per_axis(brdf, per_axis);
    let k = per_axis as f64;
    let mut sum = [0.0; 3];
    for i in 0..per_axis {
        let xi1 = (i as f64 + 0.5) / k;
        for j in 0..per_axis {
            let xi2 = (j as f64 + 0.5) / k;
            let phi = 2.0 * PI * xi2;
            let (value, omega) = lobe_sample(brdf, p, (axis, t, b), xi1, phi);
            // A sample that contributes casts its shadow ray; adding the 0 of a blocked one is skipped.
            if !value.iter().any(|&x| x != 0.0) || visible(omega) {
                for (s, x) in sum.iter_mut().zip(value) {
                    *s += x;
                }
            }
        }
    }
    sum.map(|s| s / (k * k))
}

/// The visible fraction of the sky (the directions with `ω_y > 0`), cosine-weighted, from a point with unit
/// normal `n`: its view factor to the sky relative to the unoccluded one, by `grid_fraction`'s located edges over
/// the sky's lune ([`SkyLune`](crate::shading::visibility::SkyLune), [`sky_sample`](crate::shading::visibility::sky_sample)).
///
/// The grid covers the lune and nothing else, so neither horizon is an edge inside it: the ground's is the grid's
/// side `u = 0`, the surface's the side `u = 1` (weight 0, no rays). Located on the cosine-weighted disk of the
/// whole hemisphere instead (Malley's method, the count's grid before), the edges converged at first order on the
/// roofs of the tests (5.1e-2, 2.7e-2, 1.3e-2 at 8², 16², 32² over a floor): the rim's rays graze the surface (a
/// floor's rim is its horizon, and rounding decides what its rays meet), and for a tilted surface the ground's
/// horizon is a curve inside the grid, near its rim, whose crossings use up the grid's allowance.
/// The squares at the lune's ends and along the surface's horizon have corners of weight 0 and count their corners
/// (first order), but their weight is itself of the order of the spacing there (`sin²β`, `sin(width − ψ)`), so
/// their error is second order with the rest. The rays along the ground's horizon (`u = 0`) are horizontal: they
/// reach what stands at the point's own height, the limit of the sky's rays just above it.
///
/// Where `s.slices` asks for it and the occluders are opaque triangles, the reference takes the fraction by
/// slices instead (`sky_slices`: exact along one angle, second order in its rows; the GPU in passes of them).
pub fn sky_visible_fraction(s: &Shadowing, n: DVec3) -> f64 {
    if let Some(v) = s.by_slices(|rows| crate::shading::sky_slices::sky_visible_fraction_sliced(s, n, rows)) {
        return v;
    }
    grid_fraction(s, &GridLight::Sky(sky_lune(n)))
}

/// The sky's irradiance [W/m²] per channel at `point` from its visible part, `π L0 (1 + cos t)/2 · v`, with `v`
/// its visible fraction (`shadow`: the rays that shadow the sky, if any), and `v`.
pub fn sky_irradiance_visible(
    radiance: &[f32; 3],
    point: &SurfacePoint,
    shadow: Option<&Shadowing>,
) -> ([f64; 3], f64) {
    let v = match shadow {
        Some(s) if point.normal.y > -1.0 => sky_visible_fraction(s, point.normal),
        _ => 1.0,
    };
    (radiance.map(|l0| sky_irradiance(l0 as f64, point.normal.y) * v), v)
}

/// The sky's specular term at `point`: `∫ lobe(ω) L0 (n·ω)+ V(ω) dω` over the sky [W/(m²·sr)] per channel, to be
/// scaled by `ks` ([`sky_lobe_integral_visible`], each sample with its own shadow ray).
pub fn sky_specular_visible(
    radiance: &[f32; 3],
    brdf: &Brdf,
    point: &SurfacePoint,
    per_axis: u32,
    shadow: Option<&Shadowing>,
) -> [f64; 3] {
    let integral = sky_lobe_integral_visible(brdf, point, per_axis, shadow);
    [0, 1, 2].map(|c| integral[c] * radiance[c] as f64)
}

#[cfg(test)]
mod tests {
    use super::super::rel;
    use super::*;

    #[test]
    fn sky_irradiance_of_an_overcast_day() {
        assert!(rel(sky_irradiance(100.0, 1.0), PI * 100.0) < 1e-15);
        assert!(rel(sky_irradiance(100.0, 0.0), PI * 50.0) < 1e-15);
        assert_eq!(sky_irradiance(100.0, -1.0), 0.0);
    }
}

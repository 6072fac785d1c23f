//! The lights, one file each: a light's irradiance term, its specular lobe integrated over it, and its visible
//! fraction, side by side (`shaders/lights/` mirrors each file). The sample grids the visible fractions share are in
//! `shading::visibility`, the lobe integrals' quadrature in `shading::lobe`.
//!
//! Every light gives a shading point two terms, which `shading::shade` sums over [`Lights::iter`](crate::scene::Lights::iter):
//! [`light_irradiance_visible`] (the Lambertian part's irradiance, and the light's visible fraction) and
//! [`light_specular_visible`] (its radiance through the specular lobe). These two functions are the only places
//! that tell the kinds of light apart.

pub mod disk;
pub mod sky;
pub mod sun;

use crate::scene::{Brdf, Light};
use crate::shading::lobe::SurfacePoint;
use crate::shading::options::ShadingOptions;
use crate::shading::visibility::Shadowing;

/// A light's irradiance [W/m²] per channel at `point` from its visible part, and its visible fraction `v` (1
/// where it is not shadowed), which its specular term may reuse. `shadow`: the point's shadow rays, if any (each
/// light takes them only if the render shadows it, `Shadowing::for_light`).
pub fn light_irradiance_visible(
    light: Light,
    point: &SurfacePoint,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> ([f64; 3], f64) {
    let shadow = shadow.and_then(|s| s.for_light(light));
    match light {
        Light::Sun(sun) => sun::sun_irradiance_visible(sun, point, options, shadow),
        Light::Disk { disk, .. } => disk::disk_irradiance_visible(disk, point, options, shadow),
        Light::Sky(radiance) => sky::sky_irradiance_visible(radiance, point, shadow),
    }
}

/// A light's specular term at `point`, `∫ lobe(ω) L(ω) (n·ω)+ V(ω) dω` [W/(m²·sr)] per channel, to be scaled by
/// the BRDF's `ks`. `visible_fraction`: what [`light_irradiance_visible`] returned for this light and point.
pub fn light_specular_visible(
    light: Light,
    brdf: &Brdf,
    point: &SurfacePoint,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
    visible_fraction: f64,
) -> [f64; 3] {
    let shadow = shadow.and_then(|s| s.for_light(light));
    match light {
        Light::Sun(sun) => sun::sun_specular_visible(sun, brdf, point, options, shadow, visible_fraction),
        Light::Disk { disk, .. } => disk::disk_specular_visible(disk, brdf, point, options, shadow),
        Light::Sky(radiance) => sky::sky_specular_visible(radiance, brdf, point, options.samples_per_axis, shadow),
    }
}

/// `|a − b| / |b|`, the lights' tests' relative difference.
#[cfg(test)]
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

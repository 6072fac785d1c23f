//! Outgoing radiance at a surface point: `L(x, l_out) = Σ_lights ∫ ρ(l_in, l_out) L(l_in) (n·l_in) dl_in`.
//!
//! For a Lambertian surface under the sun this is `L = (albedo/π) · E⊥ · max(0, n·l)` per channel.
//! Mirrored by `radiance_out` in `shaders/shade.glsl`.

use glam::DVec3;

use super::brdf::lambert_brdf;
use super::radiometry::sun_irradiance_delta;
use crate::scene::{Brdf, Lights, Material};

/// A point on a surface, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Position [m].
    pub position: DVec3,
    /// Unit shading normal, on the side being seen; the zero vector where it is undefined (then nothing is
    /// reflected).
    pub normal: DVec3,
    /// Unit vector towards the viewer.
    pub to_viewer: DVec3,
}

/// `v/|v|`, or the zero vector when `|v|²` is zero (or underflows) or is not finite, so that a degenerate normal shades to 0 radiance
/// instead of NaN.
pub fn safe_normalize(v: DVec3) -> DVec3 {
    let len2 = v.length_squared();
    if len2 > 0.0 && len2.is_finite() {
        v / len2.sqrt()
    } else {
        DVec3::ZERO
    }
}

/// Outgoing radiance [W/(m²·sr)] per linear RGB channel at `point` towards the viewer.
pub fn radiance_out(material: &Material, point: &SurfacePoint, lights: &Lights) -> [f64; 3] {
    let mut radiance = [0.0; 3];
    let Brdf::Lambert { albedo } = material.brdf;
    if let Some(sun) = &lights.sun {
        let n_dot_l = point.normal.dot(sun.direction.as_dvec3());
        for c in 0..3 {
            radiance[c] += lambert_brdf(albedo[c] as f64) * sun_irradiance_delta(sun.irradiance[c] as f64, n_dot_l);
        }
    }
    radiance
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Sun;
    use std::f64::consts::PI;

    #[test]
    fn lambert_under_the_sun() {
        let material =
            Material { name: "m".into(), double_sided: false, brdf: Brdf::Lambert { albedo: [0.5, 0.25, 1.0] } };
        let l = DVec3::new(0.0, 1.0, 1.0).normalize();
        let lights = Lights {
            sun: Some(Sun { direction: l.as_vec3(), irradiance: [1000.0, 500.0, 0.0], angular_diameter: 0.00925 }),
            ..Default::default()
        };
        let point = SurfacePoint { position: DVec3::ZERO, normal: DVec3::Y, to_viewer: DVec3::Z };
        let cos = l.as_vec3().as_dvec3().y;
        let got = radiance_out(&material, &point, &lights);
        let want = [0.5 / PI * 1000.0 * cos, 0.25 / PI * 500.0 * cos, 0.0];
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() <= 1e-15 * want[c].abs(), "{got:?} {want:?}");
        }
        let below = SurfacePoint { normal: -DVec3::Y, ..point };
        assert_eq!(radiance_out(&material, &below, &lights), [0.0; 3]);
        let degenerate = SurfacePoint { normal: safe_normalize(DVec3::ZERO), ..point };
        assert_eq!(radiance_out(&material, &degenerate, &lights), [0.0; 3]);
    }

    #[test]
    fn safe_normalize_never_gives_nan() {
        assert_eq!(safe_normalize(DVec3::ZERO), DVec3::ZERO);
        assert_eq!(safe_normalize(DVec3::splat(f64::NAN)), DVec3::ZERO);
        assert_eq!(safe_normalize(DVec3::new(0.0, 3.0, 4.0)), DVec3::new(0.0, 0.6, 0.8));
        assert_eq!(safe_normalize(DVec3::new(1e-100, 0.0, 0.0)), DVec3::X);
        // A squared length that underflows counts as zero (as the GPU's flushed denormals do).
        assert_eq!(safe_normalize(DVec3::new(1e-300, 0.0, 0.0)), DVec3::ZERO);
    }
}

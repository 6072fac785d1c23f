//! Outgoing radiance at a surface point: `L(x, l_out) = Σ_lights ∫ ρ(l_in, l_out) L(l_in) (n·l_in) dl_in`.
//!
//! For a Lambertian surface ρ is constant, so `L = (albedo/π) · E` with E the total irradiance from the sun, every
//! disk light and the sky. Mirrored by `radiance_out` in `shaders/shade.glsl`.

use glam::DVec3;

use super::brdf::lambert_brdf;
use super::radiometry::{
    disk_projected_solid_angle, disk_projected_solid_angle_small_source, sky_irradiance, sun_irradiance_delta,
    sun_irradiance_disk, DiskGeometry,
};
use crate::scene::{Brdf, DiskLight, Lights, Material};

/// How the sun is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SunModel {
    /// A disk of angular diameter δ: `E⊥ cos θ` while fully visible, the exact partly-set disk near the horizon.
    #[default]
    Disk,
    /// A single direction: `E⊥ max(0, cos θ)`.
    Delta,
}

/// How disk lights are evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DiskModel {
    /// The exact irradiance, horizon clipping included.
    #[default]
    Exact,
    /// The small-source estimate `L0 A cosθ_r cosθ_d / d²`.
    SmallSource,
}

/// Model choices for a render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadingOptions {
    pub sun: SunModel,
    pub disk: DiskModel,
}

impl std::str::FromStr for SunModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "disk" => Ok(SunModel::Disk),
            "delta" => Ok(SunModel::Delta),
            _ => Err(format!("'{s}' is not a sun model (disk, delta)")),
        }
    }
}

impl std::str::FromStr for DiskModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "exact" => Ok(DiskModel::Exact),
            "small-source" => Ok(DiskModel::SmallSource),
            _ => Err(format!("'{s}' is not a disk model (exact, small-source)")),
        }
    }
}

/// A scene disk light's geometry in f64.
pub fn disk_geometry(d: &DiskLight) -> DiskGeometry {
    DiskGeometry { center: d.center.as_dvec3(), direction: d.direction.as_dvec3(), radius: d.radius as f64 }
}

/// Irradiance [W/m²] per channel at `point` from all the lights.
pub fn irradiance(point: &SurfacePoint, lights: &Lights, options: &ShadingOptions) -> [f64; 3] {
    let mut e = [0.0; 3];
    if let Some(sun) = &lights.sun {
        let n_dot_l = point.normal.dot(sun.direction.as_dvec3());
        for (ec, &perp) in e.iter_mut().zip(&sun.irradiance) {
            *ec += match options.sun {
                SunModel::Disk => sun_irradiance_disk(perp as f64, n_dot_l, sun.angular_diameter as f64),
                SunModel::Delta => sun_irradiance_delta(perp as f64, n_dot_l),
            };
        }
    }
    for disk in &lights.disks {
        let g = disk_geometry(disk);
        let omega = match options.disk {
            DiskModel::Exact => disk_projected_solid_angle(point.position, point.normal, &g),
            DiskModel::SmallSource => disk_projected_solid_angle_small_source(point.position, point.normal, &g),
        };
        for (ec, &l0) in e.iter_mut().zip(&disk.radiance) {
            *ec += l0 as f64 * omega;
        }
    }
    if let Some(sky) = &lights.sky {
        for (ec, &l0) in e.iter_mut().zip(sky) {
            *ec += sky_irradiance(l0 as f64, point.normal.y);
        }
    }
    e
}

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
pub fn radiance_out(material: &Material, point: &SurfacePoint, lights: &Lights, options: &ShadingOptions) -> [f64; 3] {
    // An undefined (zero) normal reflects nothing: n·l = 0 would otherwise read as a surface edge-on to every light.
    if point.normal == DVec3::ZERO {
        return [0.0; 3];
    }
    let Brdf::Lambert { albedo } = material.brdf;
    let e = irradiance(point, lights, options);
    [0, 1, 2].map(|c| lambert_brdf(albedo[c] as f64) * e[c])
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
        let opts = ShadingOptions::default();
        let got = radiance_out(&material, &point, &lights, &opts);
        let want = [0.5 / PI * 1000.0 * cos, 0.25 / PI * 500.0 * cos, 0.0];
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() <= 1e-15 * want[c].abs(), "{got:?} {want:?}");
        }
        let below = SurfacePoint { normal: -DVec3::Y, ..point };
        assert_eq!(radiance_out(&material, &below, &lights, &opts), [0.0; 3]);
        let degenerate = SurfacePoint { normal: safe_normalize(DVec3::ZERO), ..point };
        assert_eq!(radiance_out(&material, &degenerate, &lights, &opts), [0.0; 3]);
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

//! Outgoing radiance at a surface point: `L(x, l_out) = Σ_lights ∫ ρ(l_in, l_out) L(l_in) (n·l_in) dl_in`.
//!
//! Every BRDF is `kd/π + ks · lobe`. The Lambertian part needs only the irradiance, which every light gives
//! exactly ([`irradiance`]). The lobe is integrated per light (mirrored by `shaders/shade.glsl`, with the same
//! deterministic sample points, so that the GPU and the reference differ only by rounding):
//! - sun, delta model: `lobe(l_sun) · E⊥ · max(0, n·l_sun)`;
//! - sun, disk model: a stratified midpoint grid of `sun_samples²` directions over the sun's cap (polar angle β
//!   from its centre, weight `sin β dβ dφ`), radiance `L_sun = E⊥ / (π sin²(δ/2))`;
//! - disk light, exact model: a midpoint grid of `samples²` points over the part of the disk above the horizon
//!   (the segment coordinates of `lights::disk::segment_projected_solid_angle`), `dω = h dA / |y − x|³`; small-source
//!   model: the lobe towards the centre times the small-source projected solid angle;
//! - sky: `samples²` directions drawn by a stratified grid through each lobe's own inverse CDF (Phong: cos α about
//!   the mirror direction; Blinn-Phong and Ward: the half vector), so that lobe/pdf is constant or smooth and
//!   only the horizon is left to resolve; a measured table through Ward's, with the α of its peak. The sky is the
//!   upper hemisphere: the part of the surface's hemisphere below the horizontal is integrated on its own grid
//!   and taken out, or the part above is integrated directly (`sky_lune`).
//!
//! A measured table (`Brdf::Measured`) is split the same way: its floor is the Lambertian part, the rest its
//! "lobe", per channel ([`specular_lobe_rgb`]), through the same grids.
//!
//! Convergence in the sample counts is measured in docs/accuracy.md ("BRDFs").

use std::f64::consts::PI;

use glam::DVec3;

use super::brdf::lambert_brdf;
use super::lights::disk::{
    disk_geometry, disk_projected_solid_angle, disk_projected_solid_angle_small_source, disk_visible_fraction,
};
use super::lights::sky::{sky_irradiance, sky_lobe_integral_visible, sky_visible_fraction};
use super::lights::sun::{
    sun_irradiance_delta, sun_irradiance_disk, sun_projected_solid_angle_above, sun_visible_fraction,
};
use super::lobe::{
    normalized_lobe_integral, safe_normalize, segment_lobe_integral_visible, specular_lobe_rgb, SampleRays,
    SurfacePoint,
};
use super::visibility::{
    ShadowMapFilter, Shadowing, Shadows, DEFAULT_SHADOW_MAP_SIZE, DEFAULT_SHADOW_SAMPLES_PER_AXIS,
};
use crate::scene::{Brdf, Lights};

/// How the sun is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SunModel {
    /// A disk of angular diameter δ: exact irradiance (also while it sets); specular lobes integrated over it.
    #[default]
    Disk,
    /// A single direction: `E⊥ max(0, cos θ)`, lobes evaluated at the sun's centre.
    Delta,
}

/// How disk lights are evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DiskModel {
    /// The exact irradiance, horizon clipping included; lobes integrated over the disk.
    #[default]
    Exact,
    /// The small-source estimate `L0 A cosθ_r cosθ_d / d²`, lobes evaluated towards the centre.
    SmallSource,
}

/// The sun's model and grid for one material's surfaces (`RenderSettings::sun_per_material`): `--tolerance`
/// chooses the cheapest that meets its bound for each material's lobe, so that a wide lobe or a Lambertian surface
/// does not pay for the sharpest lobe's grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SunChoice {
    pub sun: SunModel,
    /// Grid side over the sun's disk (`SunModel::Disk`).
    pub sun_samples_per_axis: u32,
}

/// Default sample counts (per axis of the stratified grids).
pub const DEFAULT_SUN_SAMPLES_PER_AXIS: u32 = 8;
pub const DEFAULT_SAMPLES_PER_AXIS: u32 = 16;

/// Model choices for a render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadingOptions {
    pub sun: SunModel,
    pub disk: DiskModel,
    /// Grid side for integrating lobes over the sun's disk (`n²` directions).
    pub sun_samples_per_axis: u32,
    /// Grid side for integrating lobes over disk lights and the sky (`n²` samples each).
    pub samples_per_axis: u32,
    /// How shadows are computed.
    pub shadows: Shadows,
    /// Grid side of each light's visible-fraction grid (`n²` shadow rays per light and pixel).
    pub shadow_samples_per_axis: u32,
    /// Side of the sun's shadow map \[texels\] (`--shadows map`).
    pub shadow_map_size: u32,
    /// Its filter.
    pub shadow_map_filter: ShadowMapFilter,
    /// What the pixels hold: radiance, or the irradiance at the surface.
    pub quantity: super::Quantity,
    /// How the reference takes the lights' visible fractions (the GPU's grids, or slices).
    pub visibility_rule: super::visibility::VisibilityRule,
}

impl Default for ShadingOptions {
    fn default() -> Self {
        Self {
            sun: SunModel::Disk,
            disk: DiskModel::Exact,
            sun_samples_per_axis: DEFAULT_SUN_SAMPLES_PER_AXIS,
            samples_per_axis: DEFAULT_SAMPLES_PER_AXIS,
            shadows: Shadows::Auto,
            shadow_samples_per_axis: DEFAULT_SHADOW_SAMPLES_PER_AXIS,
            shadow_map_size: DEFAULT_SHADOW_MAP_SIZE,
            shadow_map_filter: ShadowMapFilter::Pcss,
            quantity: super::Quantity::Radiance,
            visibility_rule: super::visibility::VisibilityRule::Grid,
        }
    }
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

/// Irradiance [W/m²] per channel at `point` from all the lights, unoccluded.
pub fn irradiance(point: &SurfacePoint, lights: &Lights, options: &ShadingOptions) -> [f64; 3] {
    irradiance_visible(point, lights, options, None)
}

/// Irradiance [W/m²] per channel at `point` from the visible part of every light: each light's exact
/// unoccluded irradiance times its visible fraction (`visibility`; a single ray for a delta sun and a
/// small-source disk). `None`: unoccluded.
pub fn irradiance_visible(
    point: &SurfacePoint,
    lights: &Lights,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> [f64; 3] {
    irradiance_and_sun_fraction(point, lights, options, shadow).0
}

/// [`irradiance_visible`] and the sun's visible fraction it took (1 without a sun, without shadows, or where the
/// sun's disk is wholly below the surface's horizon), which the specular part reuses: the GPU keeps it in a
/// global as `irradiance_visible` finds it (`sun_ray_fraction`, as `sun_map_fraction` for maps).
pub fn irradiance_and_sun_fraction(
    point: &SurfacePoint,
    lights: &Lights,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> ([f64; 3], f64) {
    let mut e = [0.0; 3];
    let mut sun_fraction = 1.0;
    if let Some(sun) = &lights.sun {
        let l = sun.direction.as_dvec3();
        let n_dot_l = point.normal.dot(l);
        let delta = sun.angular_diameter as f64;
        let mut unoccluded = [0.0; 3];
        for (ec, &perp) in unoccluded.iter_mut().zip(&sun.irradiance) {
            *ec = match options.sun {
                SunModel::Disk => sun_irradiance_disk(perp as f64, n_dot_l, delta),
                SunModel::Delta => sun_irradiance_delta(perp as f64, n_dot_l),
            };
        }
        let v = match shadow.and_then(Shadowing::for_sun) {
            Some(s) if unoccluded.iter().any(|&x| x > 0.0) => match options.sun {
                SunModel::Disk => sun_visible_fraction(s, point.normal, l, delta),
                SunModel::Delta => f64::from(u8::from(s.visible_along(l))),
            },
            _ => 1.0,
        };
        sun_fraction = v;
        for (ec, u) in e.iter_mut().zip(unoccluded) {
            *ec += u * v;
        }
    }
    for (i, disk) in lights.disks.iter().enumerate() {
        let g = disk_geometry(disk);
        let omega = match options.disk {
            DiskModel::Exact => disk_projected_solid_angle(point.position, point.normal, &g),
            DiskModel::SmallSource => disk_projected_solid_angle_small_source(point.position, point.normal, &g),
        };
        let v = match shadow.and_then(|s| s.for_disk(i)) {
            Some(s) if omega > 0.0 => match options.disk {
                DiskModel::Exact => {
                    disk_visible_fraction(s, point.position, point.normal, g.center, g.direction, g.radius)
                }
                DiskModel::SmallSource => f64::from(u8::from(s.visible_to(g.center))),
            },
            _ => 1.0,
        };
        let omega = omega * v;
        for (ec, &l0) in e.iter_mut().zip(&disk.radiance) {
            *ec += l0 as f64 * omega;
        }
    }
    if let Some(sky) = &lights.sky {
        let v = match shadow.and_then(Shadowing::for_sky) {
            Some(s) if point.normal.y > -1.0 => sky_visible_fraction(s, point.normal),
            _ => 1.0,
        };
        for (ec, &l0) in e.iter_mut().zip(sky) {
            *ec += sky_irradiance(l0 as f64, point.normal.y) * v;
        }
    }
    (e, sun_fraction)
}

/// Outgoing radiance [W/(m²·sr)] per linear RGB channel at `point` towards the viewer, every light unoccluded.
pub fn radiance_out(brdf: &Brdf, point: &SurfacePoint, lights: &Lights, options: &ShadingOptions) -> [f64; 3] {
    radiance_out_visible(brdf, point, lights, options, None)
}

/// Outgoing radiance [W/(m²·sr)] per linear RGB channel at `point` towards the viewer from the visible part of
/// each light (`shadow`; `None`: unoccluded): the diffuse part by the lights' visible fractions, each specular
/// sample by its own shadow ray (`visibility`; the sun's only in its penumbra, see the sun's branch).
pub fn radiance_out_visible(
    brdf: &Brdf,
    point: &SurfacePoint,
    lights: &Lights,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> [f64; 3] {
    // An undefined (zero) normal reflects nothing: n·l = 0 would otherwise read as a surface edge-on to every light.
    if point.normal == DVec3::ZERO {
        return [0.0; 3];
    }
    let (e, sun_fraction) = irradiance_and_sun_fraction(point, lights, options, shadow);
    let (kd, ks) = (brdf.kd(), brdf.ks());
    let mut radiance = [0, 1, 2].map(|c| lambert_brdf(kd[c] as f64) * e[c]);
    if brdf.is_lambert() {
        return radiance;
    }
    // Specular part: per unit radiance (or irradiance), then per channel.
    let mut specular = [0.0; 3];
    if let Some(sun) = &lights.sun {
        let shadow = shadow.and_then(Shadowing::for_sun);
        let l = sun.direction.as_dvec3();
        match options.sun {
            SunModel::Delta => {
                let cos = point.normal.dot(l).max(0.0);
                let mut factor = specular_lobe_rgb(brdf, point, l).map(|lobe| lobe * cos);
                if factor.iter().any(|&x| x > 0.0) && shadow.is_some_and(|s| !s.visible_along(l)) {
                    factor = [0.0; 3];
                }
                for ((sc, &perp), factor) in specular.iter_mut().zip(&sun.irradiance).zip(factor) {
                    *sc += factor * perp as f64;
                }
            }
            SunModel::Disk => {
                let delta = sun.angular_diameter as f64;
                let radius = (0.5 * delta).tan();
                // The lobe's samples cast their rays only in the sun's penumbra, where its visible fraction (the
                // diffuse part's, whose grid locates the edges) is strictly between 0 and 1: where that grid sees
                // all of the disk the lobe is unoccluded, where it sees none the lobe is 0, as the diffuse part
                // takes them (an occluder slipping between all of that grid's rays is missed by both alike).
                let penumbra = sun_fraction > 0.0 && sun_fraction < 1.0;
                let rays = shadow.filter(|_| penumbra).map(SampleRays::Along);
                let sums =
                    segment_lobe_integral_visible(brdf, point, l, -l, radius, options.sun_samples_per_axis, rays);
                let mut integral =
                    normalized_lobe_integral(sums, sun_projected_solid_angle_above(point.normal.dot(l), delta));
                if shadow.is_some() && sun_fraction == 0.0 {
                    integral = [0.0; 3];
                }
                let s = (0.5 * delta).sin();
                for ((sc, &perp), integral) in specular.iter_mut().zip(&sun.irradiance).zip(integral) {
                    *sc += integral * perp as f64 / (PI * s * s);
                }
            }
        }
    }
    for (i, disk) in lights.disks.iter().enumerate() {
        let g = disk_geometry(disk);
        let shadow = shadow.and_then(|s| s.for_disk(i));
        let integral = match options.disk {
            DiskModel::Exact => {
                let rays = shadow.map(SampleRays::ToPoint);
                let q = g.center - point.position;
                // The grid's sum as it is (see `disk_lobe_integral`).
                segment_lobe_integral_visible(brdf, point, q, g.direction, g.radius, options.samples_per_axis, rays)
                    .lobe
            }
            DiskModel::SmallSource => {
                let to_center = safe_normalize(g.center - point.position);
                let omega = disk_projected_solid_angle_small_source(point.position, point.normal, &g);
                let integral = specular_lobe_rgb(brdf, point, to_center).map(|lobe| lobe * omega);
                if integral.iter().any(|&x| x > 0.0) && shadow.is_some_and(|s| !s.visible_to(g.center)) {
                    [0.0; 3]
                } else {
                    integral
                }
            }
        };
        for ((sc, &l0), integral) in specular.iter_mut().zip(&disk.radiance).zip(integral) {
            *sc += integral * l0 as f64;
        }
    }
    if let Some(sky) = &lights.sky {
        let integral =
            sky_lobe_integral_visible(brdf, point, options.samples_per_axis, shadow.and_then(Shadowing::for_sky));
        for ((sc, &l0), integral) in specular.iter_mut().zip(sky).zip(integral) {
            *sc += integral * l0 as f64;
        }
    }
    for c in 0..3 {
        radiance[c] += ks[c] as f64 * specular[c];
    }
    radiance
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Sun;
    use crate::shading::lights::sky::sky_lobe_integral;
    use crate::shading::lobe::*;

    fn point(normal: DVec3, to_viewer: DVec3) -> SurfacePoint {
        let tangent = crate::scene::tangent::default_tangent(normal);
        SurfacePoint { position: DVec3::ZERO, normal, tangent, bitangent: normal.cross(tangent), to_viewer }
    }

    #[test]
    fn lambert_under_the_sun() {
        let m = Brdf::Lambert { albedo: [0.5, 0.25, 1.0] };
        let l = DVec3::new(0.0, 1.0, 1.0).normalize();
        let lights = Lights {
            sun: Some(Sun { direction: l.as_vec3(), irradiance: [1000.0, 500.0, 0.0], angular_diameter: 0.00925 }),
            ..Default::default()
        };
        let p = point(DVec3::Y, DVec3::Z);
        let cos = l.as_vec3().as_dvec3().y;
        let opts = ShadingOptions::default();
        let got = radiance_out(&m, &p, &lights, &opts);
        let want = [0.5 / PI * 1000.0 * cos, 0.25 / PI * 500.0 * cos, 0.0];
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() <= 1e-15 * want[c].abs(), "{got:?} {want:?}");
        }
        assert_eq!(radiance_out(&m, &SurfacePoint { normal: -DVec3::Y, ..p }, &lights, &opts), [0.0; 3]);
        assert_eq!(
            radiance_out(&m, &SurfacePoint { normal: safe_normalize(DVec3::ZERO), ..p }, &lights, &opts),
            [0.0; 3]
        );
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

    #[test]
    fn orthonormal_to_is_orthonormal() {
        for v in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::Z, DVec3::new(0.3, -0.5, 0.8).normalize()] {
            let t = orthonormal_to(v);
            assert!((t.length() - 1.0).abs() < 1e-15 && t.dot(v).abs() < 1e-15, "{v}");
        }
    }

    #[test]
    fn sky_lobe_sampling_integrates_the_lobes_albedo() {
        // At normal view the Phong and Blinn-Phong lobes integrate to 1 and the whole lobe is above the horizon
        // for e ≥ 1 up to the grid's resolution; the sampled integral converges to it.
        let p = point(DVec3::Y, DVec3::Y);
        for (brdf, tol) in [
            (Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 100.0 }, 1e-3),
            (Brdf::BlinnPhong { kd: [0.0; 3], ks: [1.0; 3], exponent: 100.0 }, 1e-3),
        ] {
            let got = sky_lobe_integral(&brdf, &p, 64);
            assert!((got - 1.0).abs() < tol, "{brdf:?}: {got}");
        }
        // Ward at normal view: the sampled integral matches its directional albedo by brute force.
        let ward = Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.2, alpha_y: 0.1 };
        let brute = {
            let mut s = 0.0;
            let (nt, np) = (2000, 400);
            for i in 0..nt {
                let th = (i as f64 + 0.5) / nt as f64 * 0.5 * PI;
                for j in 0..np {
                    let ph = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
                    let w = DVec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
                    s += specular_lobe(&ward, &p, w) * th.cos() * th.sin();
                }
            }
            s * (0.5 * PI / nt as f64) * (2.0 * PI / np as f64)
        };
        let got = sky_lobe_integral(&ward, &p, 64);
        assert!((got - brute).abs() < 2e-3 * brute, "{got} vs {brute}");
    }

    #[test]
    fn sinh_warp_is_monotone_and_integrates() {
        // The points increase inside [a, b]; the midpoint sums of dx/du and of a narrow Gaussian at c converge to
        // b − a and to √(2π) s, for widths from far below to far above the interval.
        for (a, b, c) in [(0.0, PI, 1.0), (-1.0, 1.0, -1.0), (-1.0, 1.0, 0.3), (0.0, 0.2, 0.2)] {
            // A Gaussian of width s, a hundredth of the interval; grids graded at 1 to 1e8 times that.
            let s = (b - a) * 1e-2;
            for scale in [1.0f64, 3.0, 1e3, 1e8] {
                let w = scale * s;
                let k = 64;
                let mut last = a;
                let (mut length, mut gauss) = (0.0, 0.0);
                let ends = sinh_warp_ends(a, b, c, w);
                for i in 0..k {
                    let (x, dx) = sinh_warp(a, b, c, w, ends, (i as f64 + 0.5) / k as f64);
                    assert!(x >= last && x <= b && dx > 0.0, "{a} {b} {c} {w}: {x} after {last}");
                    last = x;
                    length += dx / k as f64;
                    gauss += (-0.5 * ((x - c) / s).powi(2)).exp() * dx / k as f64;
                }
                assert!((length - (b - a)).abs() < 1e-3 * (b - a), "{a} {b} {c} {w}: length {length}");
                // Only the part of the Gaussian inside [a, b]: half of it where c is an end.
                let inside = if c == a || c == b { 0.5 } else { 1.0 };
                let want = inside * (2.0 * PI).sqrt() * s;
                // Graded at the Gaussian's width it is resolved; a uniform grid (scale ≥ 1e3) has 0.64 points per s.
                if scale <= 3.0 {
                    assert!((gauss - want).abs() < 1e-3 * want, "{a} {b} {c} {w}: {gauss} against {want}");
                }
            }
        }
    }

    #[test]
    fn exp_minus_one_is_accurate_near_zero() {
        for x in [1e-12f64, -3e-7, 1e-3, -0.5, 2.0] {
            let want = x.exp_m1();
            assert!(((exp_minus_one(x) - want) / want).abs() < 1e-15, "{x}");
        }
    }
}

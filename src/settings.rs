//! What one render needs besides the scene: image size, camera and lights, resolved from the scene and the
//! command-line overrides. Both renderers take the same [`RenderSettings`], so `render` and `reference` accept the
//! same flags and see the same `f32` inputs.

use glam::{DVec3, Mat4, Vec4};

use crate::scene::camera::{near_far_around, AUTO_FOV_DEGREES};
use crate::scene::{BoundingSphere, Camera, DiskLight, Lights, Projection, Scene, Sun};
use crate::shading::lights::sun::sun_irradiance_from_radiance;
use crate::shading::radiometry::{degrees_to_radians, DEFAULT_SUN_IRRADIANCE, SUN_ANGULAR_DIAMETER_DEGREES};
use crate::shading::{ShadingOptions, SunChoice};

/// Default image size \[pixels\].
pub const DEFAULT_WIDTH: u32 = 512;
pub const DEFAULT_HEIGHT: u32 = 512;
/// Direction towards the sun when neither the scene nor the flags give one (normalised).
pub const DEFAULT_SUN_DIRECTION: [f64; 3] = [0.3, 1.0, 0.5];

/// Everything a renderer needs for one image besides the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    pub lights: Lights,
    /// How the sun and disk lights are evaluated.
    pub shading: ShadingOptions,
    /// Per material (by index): the sun's model and grid for that material's surfaces where `--tolerance` chose
    /// them material by material (`accuracy::predicted::choose_sun_within`); `None` or past the end: `shading`'s.
    pub sun_per_material: Vec<Option<SunChoice>>,
    /// Per material (by index): the side of its lobe grids under disk lights and the sky where `--tolerance`'s
    /// study kept them material by material (`accuracy::trial`); `None` or past the end: `shading`'s.
    pub lobes_per_material: Vec<Option<u32>>,
}

impl RenderSettings {
    /// Settings with the default light models.
    pub fn new(width: u32, height: u32, camera: Camera, lights: Lights) -> Self {
        Self {
            width,
            height,
            camera,
            lights,
            shading: ShadingOptions::default(),
            sun_per_material: Vec::new(),
            lobes_per_material: Vec::new(),
        }
    }

    /// Whether some material is rendered with sun model `sun` (the render's, or a material's own).
    pub fn uses_sun_model(&self, sun: crate::shading::SunModel) -> bool {
        self.shading.sun == sun || self.sun_per_material.iter().flatten().any(|c| c.sun == sun)
    }

    /// The shading options of material `material`'s surfaces: [`Self::shading`] with the material's own sun model
    /// and grid ([`Self::sun_per_material`]) and lobe grids ([`Self::lobes_per_material`]) where it has them.
    pub fn shading_for(&self, material: usize) -> ShadingOptions {
        let mut shading = self.shading;
        if let Some(Some(choice)) = self.sun_per_material.get(material) {
            shading.sun = choice.sun;
            shading.sun_samples_per_axis = choice.sun_samples_per_axis;
        }
        if let Some(Some(k)) = self.lobes_per_material.get(material) {
            shading.samples_per_axis = *k;
        }
        shading
    }

    /// Width / height.
    pub fn aspect(&self) -> f64 {
        self.width as f64 / self.height as f64
    }

    /// World → Vulkan clip space, computed in f64 and rounded once to f32: the matrix both renderers use.
    pub fn clip_from_world(&self) -> Mat4 {
        self.camera.clip_from_world(self.aspect()).as_mat4()
    }

    /// The viewer as the shaders see it: `(eye, 1)` for a perspective camera, `(−forward, 0)` (the direction
    /// towards the viewer) for an orthographic one, in f32.
    pub fn viewer(&self) -> Vec4 {
        if self.camera.is_orthographic() {
            (-self.camera.forward).as_vec3().extend(0.0)
        } else {
            self.camera.eye.as_vec3().extend(1.0)
        }
    }
}

/// Camera choices from the command line; `None` keeps the scene's (or the automatic camera's) value.
#[derive(Clone, Debug, Default)]
pub struct CameraOptions {
    /// glTF camera index to use.
    pub camera: Option<usize>,
    /// The automatic camera (framing the scene's bounding sphere) even where the file places cameras.
    pub automatic: bool,
    pub eye: Option<DVec3>,
    pub target: Option<DVec3>,
    pub up: Option<DVec3>,
    /// Vertical field of view \[degrees\] (perspective only).
    pub fov_degrees: Option<f64>,
}

/// Sun choices from the command line.
#[derive(Clone, Debug, Default)]
pub struct SunOptions {
    /// Direction towards the sun (need not be normalised).
    pub direction: Option<DVec3>,
    /// Elevation above the horizontal XZ plane \[degrees\].
    pub elevation_degrees: Option<f64>,
    /// Azimuth \[degrees\]: 0° towards +Z, 90° towards +X.
    pub azimuth_degrees: Option<f64>,
    /// `E⊥` [W/m²].
    pub irradiance: Option<f64>,
    /// `L_sun` [W/(m²·sr)] (alternative to `irradiance`).
    pub radiance: Option<f64>,
    /// Angular diameter \[degrees\].
    pub diameter_degrees: Option<f64>,
    /// Per-channel factors on `E⊥`.
    pub color: Option<[f64; 3]>,
}

impl SunOptions {
    fn any(&self) -> bool {
        self.direction.is_some()
            || self.elevation_degrees.is_some()
            || self.azimuth_degrees.is_some()
            || self.irradiance.is_some()
            || self.radiance.is_some()
            || self.diameter_degrees.is_some()
            || self.color.is_some()
    }
}

/// Lights and light models from the command line, besides the sun.
#[derive(Clone, Debug, Default)]
pub struct LightOptions {
    pub sun: SunOptions,
    /// Disk lights added to the scene's.
    pub disks: Vec<DiskLight>,
    /// Sky radiance replacing the scene's [W/(m²·sr)].
    pub sky: Option<[f64; 3]>,
    pub shading: ShadingOptions,
}

/// A combination of options that cannot be rendered; a usage error (exit code 2 at the CLI).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct SettingsError(pub String);

fn usage(msg: impl Into<String>) -> SettingsError {
    SettingsError(msg.into())
}

/// Unit direction towards the sun from elevation and azimuth \[degrees\]: `(cos e sin a, sin e, cos e cos a)`.
pub fn sun_direction_from_angles(elevation_degrees: f64, azimuth_degrees: f64) -> DVec3 {
    let (e, a) = (degrees_to_radians(elevation_degrees), degrees_to_radians(azimuth_degrees));
    DVec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos())
}

/// The inverse of [`sun_direction_from_angles`]: the elevation and azimuth \[degrees\] of the direction `d` (need
/// not be unit), the azimuth in [0, 360). The elevation is the atan2 of the vertical part against the horizontal
/// one, accurate at the zenith and at the horizon alike (an asin of `d.y` loses digits near the zenith).
pub fn sun_angles_from_direction(d: DVec3) -> (f64, f64) {
    (d.y.atan2(d.x.hypot(d.z)).to_degrees(), d.x.atan2(d.z).to_degrees().rem_euclid(360.0))
}

/// Resolves the camera and lights of a render, with the sun the only light option.
pub fn resolve(
    scene: &Scene,
    width: u32,
    height: u32,
    camera: &CameraOptions,
    sun: &SunOptions,
) -> Result<RenderSettings, SettingsError> {
    resolve_with(scene, width, height, camera, &LightOptions { sun: sun.clone(), ..Default::default() })
}

/// Resolves the camera and lights of a render. The scene's lights come first; `--disk-light` adds disks,
/// `--sky-radiance` replaces the sky, the sun flags override the scene's sun. A default sun (E⊥ 1000 W/m² from
/// [`DEFAULT_SUN_DIRECTION`]) shines only where neither the scene nor the flags give any light.
pub fn resolve_with(
    scene: &Scene,
    width: u32,
    height: u32,
    camera: &CameraOptions,
    light_options: &LightOptions,
) -> Result<RenderSettings, SettingsError> {
    if width == 0 || height == 0 {
        return Err(usage(format!("image size {width}x{height} is empty")));
    }
    let aspect = width as f64 / height as f64;
    let camera = resolve_camera(scene, aspect, camera)?;
    let mut lights = scene.lights.clone();
    lights.disks.extend(light_options.disks.iter().copied());
    if let Some(sky) = light_options.sky {
        if sky.iter().any(|v| !(v.is_finite() && *v >= 0.0 && *v <= f32::MAX as f64)) {
            return Err(usage("--sky-radiance must be finite, non-negative and within f32 range"));
        }
        lights.sky = Some(sky.map(|v| v as f32));
    }
    let unlit = lights.is_empty();
    lights.sun = resolve_sun(scene.lights.sun, unlit, &light_options.sun)?;
    Ok(RenderSettings {
        width,
        height,
        camera,
        lights,
        shading: light_options.shading,
        sun_per_material: Vec::new(),
        lobes_per_material: Vec::new(),
    })
}

fn resolve_camera(scene: &Scene, aspect: f64, opts: &CameraOptions) -> Result<Camera, SettingsError> {
    let sphere = scene.bounding_sphere().unwrap_or(BoundingSphere { center: DVec3::ZERO, radius: 1.0 });
    let sphere = BoundingSphere { radius: if sphere.radius > 0.0 { sphere.radius } else { 1.0 }, ..sphere };
    if let Some(fov) = opts.fov_degrees {
        if !(fov > 0.0 && fov < 180.0) {
            return Err(usage(format!("--fov {fov} must be between 0 and 180 degrees")));
        }
    }
    let scene_camera = match opts.camera {
        Some(n) => Some(scene.cameras.iter().find(|(i, _)| *i == n).map(|(_, c)| *c).ok_or_else(|| {
            let placed: Vec<usize> = scene.cameras.iter().map(|(i, _)| *i).collect();
            usage(format!("--camera {n}: no node of the scene places glTF camera {n} (placed: {placed:?})"))
        })?),
        None if opts.automatic => None,
        None => scene.cameras.first().map(|(_, c)| *c),
    };
    let yfov = degrees_to_radians(opts.fov_degrees.unwrap_or(AUTO_FOV_DEGREES));
    let Some(mut cam) = scene_camera else {
        // Automatic camera, possibly moved by --eye/--target/--up.
        let auto = Camera::frame_sphere(sphere, aspect, yfov);
        if opts.eye.is_none() && opts.target.is_none() && opts.up.is_none() {
            return Ok(auto);
        }
        let eye = opts.eye.unwrap_or(auto.eye);
        let target = opts.target.unwrap_or(sphere.center);
        let (znear, zfar) = near_far_around(eye, sphere);
        let projection = Projection::Perspective { yfov, znear, zfar: Some(zfar) };
        return Camera::look_at(eye, target, opts.up.unwrap_or(DVec3::Y), projection)
            .ok_or_else(|| usage("--eye equals the target, or --up is parallel to the view direction"));
    };
    if let Some(fov) = opts.fov_degrees {
        match &mut cam.projection {
            Projection::Perspective { yfov, .. } => *yfov = degrees_to_radians(fov),
            Projection::Orthographic { .. } => return Err(usage("--fov applies to perspective cameras only")),
        }
    }
    let eye = opts.eye.unwrap_or(cam.eye);
    let direction = match opts.target {
        Some(t) => t - eye,
        None => cam.forward,
    };
    Camera::looking(eye, direction, opts.up.unwrap_or(cam.up), cam.projection)
        .ok_or_else(|| usage("--eye equals the target, or --up is parallel to the view direction"))
}

fn resolve_sun(scene_sun: Option<Sun>, scene_unlit: bool, opts: &SunOptions) -> Result<Option<Sun>, SettingsError> {
    if scene_sun.is_none() && !scene_unlit && !opts.any() {
        // The scene has its own (non-sun) lights and the flags add no sun.
        return Ok(None);
    }
    let diameter_degrees = opts.diameter_degrees.unwrap_or(SUN_ANGULAR_DIAMETER_DEGREES);
    if !(diameter_degrees > 0.0 && diameter_degrees < 180.0) {
        return Err(usage(format!("--sun-diameter {diameter_degrees} must be between 0 and 180 degrees")));
    }
    let diameter = degrees_to_radians(diameter_degrees);
    let direction = if let Some(d) = opts.direction {
        if opts.elevation_degrees.is_some() || opts.azimuth_degrees.is_some() {
            return Err(usage("give either --sun-dir or --sun-elevation/--sun-azimuth, not both"));
        }
        d.try_normalize().ok_or_else(|| usage("--sun-dir must be a non-zero finite vector"))?
    } else if opts.elevation_degrees.is_some() || opts.azimuth_degrees.is_some() {
        let (e, a) = (opts.elevation_degrees.unwrap_or(45.0), opts.azimuth_degrees.unwrap_or(0.0));
        if !(-90.0..=90.0).contains(&e) || !a.is_finite() {
            return Err(usage(format!("--sun-elevation {e} must be within [-90, 90] degrees")));
        }
        sun_direction_from_angles(e, a)
    } else if let Some(s) = scene_sun {
        s.direction.as_dvec3()
    } else {
        DVec3::from_array(DEFAULT_SUN_DIRECTION).normalize()
    };
    let color = opts.color.unwrap_or([1.0; 3]);
    if color.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
        return Err(usage("--sun-color factors must be finite and non-negative"));
    }
    let irradiance: [f64; 3] = match (opts.irradiance, opts.radiance) {
        (Some(_), Some(_)) => return Err(usage("give either --sun-irradiance or --sun-radiance, not both")),
        (Some(e), None) => color.map(|c| c * e),
        (None, Some(l)) => color.map(|c| c * sun_irradiance_from_radiance(l, diameter)),
        (None, None) => match scene_sun {
            // The scene's light: its intensity × color, unless --sun-color replaces the color.
            Some(s) if opts.color.is_none() => s.irradiance.map(f64::from),
            Some(s) => {
                let e = s.irradiance.iter().copied().fold(0.0f32, f32::max) as f64;
                color.map(|c| c * e)
            }
            None => color.map(|c| c * DEFAULT_SUN_IRRADIANCE),
        },
    };
    if irradiance.iter().any(|e| !(e.is_finite() && *e >= 0.0 && *e <= f32::MAX as f64)) {
        return Err(usage("the sun's irradiance must be finite, non-negative and within f32 range"));
    }
    Ok(Some(Sun {
        direction: direction.as_vec3(),
        irradiance: irradiance.map(|e| e as f32),
        angular_diameter: diameter as f32,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sun_angles_invert_the_direction() {
        for (e, a) in [(15.0, 90.0), (-10.0, 0.0), (89.999, 250.0), (0.0, 359.5), (45.0, 180.0)] {
            let (e2, a2) = sun_angles_from_direction(sun_direction_from_angles(e, a) * 3.0);
            assert!((e2 - e).abs() < 1e-10 && (a2 - a).abs() < 1e-9, "{e} {a}: {e2} {a2}");
        }
    }

    #[test]
    fn elevation_azimuth_convention() {
        let up = sun_direction_from_angles(90.0, 0.0);
        assert!((up - DVec3::Y).length() < 1e-15);
        let front = sun_direction_from_angles(0.0, 0.0);
        assert!((front - DVec3::Z).length() < 1e-15);
        let right = sun_direction_from_angles(0.0, 90.0);
        assert!((right - DVec3::X).length() < 1e-15);
    }

    #[test]
    fn default_sun_and_overrides() {
        let scene = Scene::default();
        let s = resolve(&scene, 4, 2, &CameraOptions::default(), &SunOptions::default()).unwrap();
        let sun = s.lights.sun.unwrap();
        assert_eq!(sun.irradiance, [1000.0; 3]);
        assert!((sun.direction.as_dvec3() - DVec3::from_array(DEFAULT_SUN_DIRECTION).normalize()).length() < 1e-7);
        let opts = SunOptions { radiance: Some(1.0), irradiance: Some(1.0), ..Default::default() };
        assert!(resolve(&scene, 4, 2, &CameraOptions::default(), &opts).is_err());
        let opts = SunOptions { direction: Some(DVec3::ZERO), ..Default::default() };
        assert!(resolve(&scene, 4, 2, &CameraOptions::default(), &opts).is_err());
        let opts = SunOptions { irradiance: Some(10.0), color: Some([1.0, 0.5, 0.0]), ..Default::default() };
        let sun = resolve(&scene, 4, 2, &CameraOptions::default(), &opts).unwrap().lights.sun.unwrap();
        assert_eq!(sun.irradiance, [10.0, 5.0, 0.0]);
    }

    #[test]
    fn bad_camera_options_are_usage_errors() {
        let scene = Scene::default();
        let same = CameraOptions { eye: Some(DVec3::ONE), target: Some(DVec3::ONE), ..Default::default() };
        assert!(resolve(&scene, 4, 4, &same, &SunOptions::default()).is_err());
        let fov = CameraOptions { fov_degrees: Some(180.0), ..Default::default() };
        assert!(resolve(&scene, 4, 4, &fov, &SunOptions::default()).is_err());
        let missing = CameraOptions { camera: Some(3), ..Default::default() };
        assert!(resolve(&scene, 4, 4, &missing, &SunOptions::default()).unwrap_err().0.contains("camera 3"));
        assert!(resolve(&scene, 0, 4, &CameraOptions::default(), &SunOptions::default()).is_err());
    }
}

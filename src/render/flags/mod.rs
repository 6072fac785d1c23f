//! The flags that define an image, shared by `render`, `reference`, `bench`, jobs of `batch` and `test`, and the
//! `testing` API: the scene, image size, camera, lights, models and `--tolerance`.

// The fields' doc comments are clap's help texts, where "[m]", "[s]" and "[degrees]" are units, not links.
#![allow(rustdoc::broken_intra_doc_links)]

pub mod daylight;
pub mod quantity;

use std::path::PathBuf;

use clap::Args;
use glam::DVec3;

use self::daylight::{AccumulationArgs, DaylightArgs, DaylightAt};
use self::quantity::RequestedQuantity;
use super::RenderError;
use crate::scene::light::MAX_DISK_EXTENT_M;
use crate::scene::{BrdfKind, DiskLight, LoadOptions, UriScope};
use crate::settings::{CameraOptions, LightOptions, SunOptions, DEFAULT_HEIGHT, DEFAULT_WIDTH};
use crate::shading::{
    DiskModel, ShadingOptions, ShadowMapFilter, Shadows, SunModel, VisibilityRule, DEFAULT_SAMPLES_PER_AXIS,
    DEFAULT_SHADOW_MAP_SIZE, DEFAULT_SHADOW_SAMPLES_PER_AXIS, DEFAULT_SUN_SAMPLES_PER_AXIS,
};

/// `x,y,z` → a finite vector.
pub fn parse_vec3(s: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected three comma-separated numbers x,y,z, got '{s}'"));
    }
    let mut v = [0.0; 3];
    for (slot, p) in v.iter_mut().zip(&parts) {
        *slot = p.parse::<f64>().map_err(|_| format!("'{p}' is not a number"))?;
        if !slot.is_finite() {
            return Err(format!("'{p}' is not finite"));
        }
    }
    Ok(DVec3::from_array(v))
}

/// `r,g,b` → three finite non-negative factors.
pub fn parse_rgb(s: &str) -> Result<[f64; 3], String> {
    let v = parse_vec3(s)?;
    if v.min_element() < 0.0 {
        return Err(format!("'{s}': components must be non-negative"));
    }
    Ok(v.to_array())
}

/// A radiance: one non-negative number for all channels, or `r,g,b`; within f32's range (images are f32).
pub fn parse_radiance(s: &str) -> Result<[f64; 3], String> {
    let v = if s.contains(',') {
        parse_rgb(s)?
    } else {
        let v = parse_finite(s)?;
        if v < 0.0 {
            return Err(format!("'{s}' must be non-negative"));
        }
        [v; 3]
    };
    if v.iter().any(|c| *c > f32::MAX as f64) {
        return Err(format!("'{s}' is beyond f32's range ({:e})", f32::MAX));
    }
    Ok(v)
}

/// `x,y,z:nx,ny,nz:R:L0` → a disk light (centre [m], emission direction, radius [m], radiance, one value or r,g,b).
pub fn parse_disk_light(s: &str) -> Result<DiskLight, String> {
    let parts: Vec<&str> = s.split(':').collect();
    if parts.len() != 4 {
        return Err(format!("expected centre:direction:radius:radiance (x,y,z:nx,ny,nz:R:L0), got '{s}'"));
    }
    let center = parse_vec3(parts[0])?;
    let direction =
        parse_vec3(parts[1])?.try_normalize().ok_or_else(|| format!("disk direction '{}' is zero", parts[1]))?;
    let radius = parse_positive(parts[2])?;
    let radiance = parse_radiance(parts[3])?;
    let extent = center.abs().max_element().max(radius);
    if extent > MAX_DISK_EXTENT_M || (radius as f32) < f32::MIN_POSITIVE {
        return Err(format!(
            "'{s}': the centre and radius must be within {MAX_DISK_EXTENT_M:e} m and the radius a normal f32 (docs: disk lights)"
        ));
    }
    Ok(DiskLight {
        center: center.as_vec3(),
        direction: direction.as_vec3(),
        radius: radius as f32,
        radiance: radiance.map(|v| v as f32),
    })
}

/// A finite number.
pub fn parse_finite(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("'{s}' is not a finite number")),
    }
}

/// An image side: a whole number of pixels ≥ 1.
pub fn parse_pixels(s: &str) -> Result<u32, String> {
    match s.trim().parse::<i64>() {
        Ok(v) if (1..=u32::MAX as i64).contains(&v) => Ok(v as u32),
        Ok(v) => Err(format!("{v} pixels: the size must be at least 1")),
        Err(_) => Err(format!("'{s}' is not a whole number of pixels")),
    }
}

/// A finite number ≥ 0.
pub fn parse_non_negative(s: &str) -> Result<f64, String> {
    let v = parse_finite(s)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("'{s}' must not be negative"))
    }
}

/// A finite number > 0.
pub fn parse_positive(s: &str) -> Result<f64, String> {
    let v = parse_finite(s)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(format!("'{s}' must be greater than 0"))
    }
}

/// `K/N` with 0 ≤ K < N.
pub fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let (k, n) = s.split_once('/').ok_or_else(|| format!("'{s}' is not K/N"))?;
    let (k, n): (usize, usize) = (
        k.trim().parse().map_err(|_| format!("'{k}' is not a count"))?,
        n.trim().parse().map_err(|_| format!("'{n}' is not a count"))?,
    );
    if n == 0 || k >= n {
        return Err(format!("'{s}': needs 0 ≤ K < N"));
    }
    Ok((k, n))
}

/// `--camera`: a glTF camera of the file, or the automatic one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraChoice {
    Scene(usize),
    Automatic,
}

impl std::str::FromStr for CameraChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "auto" {
            return Ok(CameraChoice::Automatic);
        }
        s.parse().map(CameraChoice::Scene).map_err(|_| format!("'{s}' is neither a glTF camera index nor 'auto'"))
    }
}

/// Everything that defines the image: scene, size, camera, lights.
#[derive(Args, Clone, Debug)]
pub struct SceneArgs {
    /// glTF 2.0 scene (.gltf with its .bin files or data URIs, or .glb).
    #[arg(help_heading = "Scene")]
    pub scene: PathBuf,

    /// Image width [pixels].
    #[arg(help_heading = "Image", long, default_value_t = DEFAULT_WIDTH, value_parser = parse_pixels)]
    pub width: u32,

    /// Image height [pixels].
    #[arg(help_heading = "Image", long, default_value_t = DEFAULT_HEIGHT, value_parser = parse_pixels)]
    pub height: u32,

    /// Buffer and image files must lie inside DIR (symbolic links resolved); default: the scene file's folder.
    #[arg(help_heading = "Scene", long, value_name = "DIR", conflicts_with = "allow_outside_uris")]
    pub asset_root: Option<PathBuf>,

    /// Read buffer and image files wherever their URIs point, absolute paths and `..` included (only for files
    /// you trust).
    #[arg(help_heading = "Scene", long)]
    pub allow_outside_uris: bool,

    /// Which glTF scene of the file to render (default: the file's default scene).
    #[arg(help_heading = "Scene", long = "scene", value_name = "N")]
    pub scene_index: Option<usize>,

    /// Pose the scene by glTF animation N (its nodes' translation, rotation, scale and morph weights) at
    /// --animation-time (default: the file at rest).
    #[arg(help_heading = "Scene", long, value_name = "N")]
    pub animation: Option<usize>,

    /// Textures larger than N texels on a side are drawn from their first mip level that fits (less memory; the
    /// same in both renderers).
    #[arg(help_heading = "Scene", long, value_name = "N", value_parser = parse_pixels)]
    pub max_texture_size: Option<u32>,

    /// The time of --animation [s] (before its first keyframe the first holds, after the last the last).
    #[arg(help_heading = "Scene", long, value_name = "SECONDS", requires = "animation", allow_negative_numbers = true)]
    pub animation_time: Option<f64>,

    /// Use glTF camera N (as placed by the scene's nodes) instead of the first one, or `auto`: the automatic camera
    /// (the scene's bounding sphere framed from +Z, 45° vertical field of view) even where the file has cameras.
    #[arg(help_heading = "Camera", long, value_name = "N|auto")]
    pub camera: Option<CameraChoice>,

    /// Camera position x,y,z [m] (world, +Y up).
    #[arg(help_heading = "Camera", long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z")]
    pub eye: Option<DVec3>,

    /// Point the camera looks at x,y,z [m].
    #[arg(help_heading = "Camera", long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z")]
    pub target: Option<DVec3>,

    /// Camera up vector x,y,z.
    #[arg(help_heading = "Camera", long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z")]
    pub up: Option<DVec3>,

    /// Vertical field of view [degrees] (perspective cameras; the automatic camera uses 45).
    #[arg(help_heading = "Camera", long, value_parser = parse_positive, value_name = "DEGREES")]
    pub fov: Option<f64>,

    /// Direction towards the sun x,y,z (world, +Y up; need not be normalised).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z",
          conflicts_with_all = ["sun_elevation", "sun_azimuth"], help_heading = "Sun")]
    pub sun_dir: Option<DVec3>,

    /// Sun elevation above the horizontal XZ plane [degrees] (default 45 when only --sun-azimuth is given).
    #[arg(help_heading = "Sun", long, value_parser = parse_finite, allow_hyphen_values = true, value_name = "DEGREES")]
    pub sun_elevation: Option<f64>,

    /// Sun azimuth [degrees]: 0 = towards +Z, 90 = towards +X.
    #[arg(help_heading = "Sun", long, value_parser = parse_finite, allow_hyphen_values = true, value_name = "DEGREES")]
    pub sun_azimuth: Option<f64>,

    /// Sun irradiance on a surface facing it, E⊥ [W/m²] (default 1000, or the scene's directional light).
    #[arg(help_heading = "Sun", long, value_parser = parse_finite, value_name = "W/M2", conflicts_with = "sun_radiance")]
    pub sun_irradiance: Option<f64>,

    /// Sun radiance L_sun [W/(m²·sr)]; E⊥ = L_sun·π·sin²(δ/2) ≈ L_sun·Ω_sun.
    #[arg(help_heading = "Sun", long, value_parser = parse_finite, value_name = "W/(M2·SR)")]
    pub sun_radiance: Option<f64>,

    /// Sun angular diameter δ [degrees].
    #[arg(help_heading = "Sun", long, value_parser = parse_positive, value_name = "DEGREES")]
    pub sun_diameter: Option<f64>,

    /// Per-channel factors on E⊥, r,g,b.
    #[arg(help_heading = "Sun", long, value_parser = parse_rgb, value_name = "R,G,B")]
    pub sun_color: Option<[f64; 3]>,

    /// The sun as a disk (default: exact also while it sets) or as a single direction.
    #[arg(help_heading = "Sun", long, default_value = "disk", value_name = "disk|delta")]
    pub sun_model: SunModel,

    /// Add a disk skylight: centre x,y,z [m], emission direction, radius [m], radiance L0 [W/(m²·sr)] (one value
    /// or r,g,b). Repeatable.
    #[arg(help_heading = "Disk lights and sky", long = "disk-light", value_parser = parse_disk_light, allow_hyphen_values = true, value_name = "X,Y,Z:NX,NY,NZ:R:L0")]
    pub disk_lights: Vec<DiskLight>,

    /// Disk lights: the exact irradiance (default) or the small-source estimate L0·A·cosθr·cosθd/d².
    #[arg(help_heading = "Disk lights and sky", long, default_value = "exact", value_name = "exact|small-source")]
    pub disk_model: DiskModel,

    /// Overcast sky of uniform radiance L0 [W/(m²·sr)], one value or r,g,b (replaces the scene's sky).
    #[arg(help_heading = "Disk lights and sky", long, value_parser = parse_radiance, value_name = "L0|R,G,B")]
    pub sky_radiance: Option<[f64; 3]>,

    /// Map every material's glTF metallic-roughness onto this BRDF (docs/brdf.md); `gltf` is the glTF
    /// specification's own, `lambert` forces Lambert.
    #[arg(help_heading = "Materials", long, value_name = "lambert|phong|blinn-phong|ward|gltf")]
    pub brdf: Option<BrdfKind>,

    /// Give every material this measured BRDF: a MERL `.binary` file (docs/measured.md).
    #[arg(help_heading = "Materials", long, value_name = "FILE", conflicts_with = "brdf")]
    pub merl: Option<std::path::PathBuf>,

    /// How measured BRDFs are read between their samples: trilinear (continuous; the default) or the nearest bin
    /// below, as the database's own reader does (docs/measured.md compares them).
    #[arg(help_heading = "Materials", long, value_name = "linear|nearest")]
    pub merl_lookup: Option<crate::shading::measured::MeasuredLookup>,

    /// Emitted radiance [W/(m²·sr)] per unit of glTF's `emissiveFactor` (times KHR_materials_emissive_strength and
    /// the emissive texture); 1 by default, which the default sun (about 300 W/(m²·sr) off a white surface)
    /// outshines: `-v` says when the scene's emission is under 1% of the image's peak.
    #[arg(help_heading = "Materials", long, value_parser = parse_non_negative, value_name = "W/(m²·sr)")]
    pub emission_scale: Option<f64>,

    /// Samples for integrating specular lobes over disk lights and the sky (a stratified grid; rounded up to a
    /// square).
    #[arg(help_heading = "Quality", long, default_value_t = DEFAULT_SAMPLES_PER_AXIS * DEFAULT_SAMPLES_PER_AXIS, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub samples: u32,

    /// Samples for integrating specular lobes over the sun's disk (--sun-model disk; rounded up to a square)
    /// [default: 64].
    #[arg(help_heading = "Quality", long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub sun_samples: Option<u32>,

    /// The largest relative error the image may have against the truth; the cheapest models that keep it are chosen.
    ///
    /// REL is relative, with the diff's floor of 1% of the peak; `-v` prints the models and the predicted error
    /// (docs/accuracy.md, "Error bounds"). Pixels with a derived bound are rendered on the GPU: for each material
    /// the cheapest sun model whose bound for its lobe (with the GPU's f32 arithmetic) meets REL; disk lights and
    /// the sky on Lambertian surfaces in closed form; every light wholly visible or wholly hidden (the frame's first
    /// draw proves it). The other pixels (penumbrae, where a light is partly hidden; specular surfaces under disk
    /// lights or the sky; measured materials; every pixel under a sky through occluders) are refined one by one on
    /// the CPU reference until two doublings of every grid change each by less than REL/3: their cost follows
    /// their number, and `-v` says how many. With f32 barycentrics their bound (per pixel) is kept within REL
    /// beside the models'. Refused: the device's interpolation, and `--shadows map` where the scene shadows itself.
    /// `--tolerance-outside-penumbrae` holds REL outside the penumbrae of the sun and of disk lights only;
    /// `--tolerance-by-study` estimates what has no bound over a ladder of whole renders instead, as `reference
    /// --tolerance` always does.
    #[arg(help_heading = "Quality", long, value_name = "REL", value_parser = parse_positive, conflicts_with_all = ["sun_model", "sun_samples"])]
    pub tolerance: Option<f64>,

    /// With --tolerance: hold it in penumbrae too (the default; the flag is kept for the scripts that name it).
    /// The penumbrae's pixels are refined on the reference (--tolerance's text); with --tolerance-by-study the
    /// shadow rays' grids go on the study's ladder with the sun's and the lobes' grids instead.
    #[arg(help_heading = "Quality", long, requires = "tolerance")]
    pub tolerance_in_penumbrae: bool,

    /// With --tolerance: hold it outside the penumbrae of the sun and of disk lights only, where the scene shadows
    /// itself (`-v` names them as not bounded). Cheaper where the shadow rays' grids cost the most: room.gltf (a
    /// disk skylight over a sphere) at 512², T = 1e-2, 20 s against 218 s in its penumbrae on the system
    /// lavapipe. Light of the sky through occluders is still held everywhere (its penumbra is nearly the whole
    /// image).
    #[arg(help_heading = "Quality", long, requires = "tolerance", conflicts_with = "tolerance_in_penumbrae")]
    pub tolerance_outside_penumbrae: bool,

    /// With --tolerance: estimate what has no derived bound by a study over a ladder of whole renders instead of
    /// refining those pixels alone on the reference. Specular surfaces under disk lights or a sky are rendered on
    /// a ladder of lobe grids (4² up to 162², overriding --samples; a ladder per material) until the finest one's
    /// error, estimated by refinement (Roache's grid convergence index), fits what the sun's bound leaves;
    /// measured materials likewise, the sun's grid on the ladder too; in penumbrae the shadow rays' grids join
    /// the ladder (its order taken as at most 1), and where every light can be sliced the study runs on the
    /// reference and the GPU's one image is measured against the reference's. Every rung renders the whole
    /// image: costly, and refused where the ladder cannot reach REL.
    #[arg(help_heading = "Quality", long, requires = "tolerance")]
    pub tolerance_by_study: bool,

    /// Shadows: `auto` (shadow rays; none where nothing can occlude a light), `none`, `ray`, or `map`.
    ///
    /// Rays on every device: the sun's against its cells, the other lights' by ray queries or, without them, by the
    /// fragment shader's walk of the occluders' BVH. `map`: shadow maps for the sun and the first four disk lights,
    /// the sky unoccluded, with a warning. The reference casts rays for every technique but `none` (for `map`, for
    /// the lights the maps shadow).
    #[arg(help_heading = "Shadows", long, default_value = "auto", value_name = "auto|none|ray|map")]
    pub shadows: Shadows,

    /// What the pixels hold: radiance [W/(m²·sr)], irradiance [W/m²], irradiation [Wh/m²] or sun-hours [h].
    ///
    /// `radiance` towards the camera [W/(m²·sr)], or `irradiance` [W/m²], the light
    /// arriving at the surface point each pixel sees, per RGB channel, from every light's visible part (the
    /// lecture's E(x, y); the material does not enter); accumulated over --from/--to/--step: `irradiation`
    /// [Wh/m²], the sum of the irradiance of each step's midpoint times its length, or `sun-hours` [h], the
    /// hours whose direct sun on the surface reaches --sun-hours-threshold. Images record the quantity and its unit.
    #[arg(
        help_heading = "Image",
        long,
        default_value = "radiance",
        value_name = "radiance|irradiance|irradiation|sun-hours"
    )]
    pub quantity: RequestedQuantity,

    #[command(flatten)]
    pub daylight: DaylightArgs,

    #[command(flatten)]
    pub accumulation: AccumulationArgs,

    /// The visible fractions' grid over each light, k² = N rounded up to a square: the sun, disk lights and the
    /// sky cast rays at its (k + 1)² corners (the sky's over its lune above both horizons) and locate their
    /// shadows' edges by bisection (1: the light's centre alone, a hard shadow).
    #[arg(help_heading = "Shadows", long, default_value_t = DEFAULT_SHADOW_SAMPLES_PER_AXIS * DEFAULT_SHADOW_SAMPLES_PER_AXIS, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub shadow_samples: u32,

    /// Side of each shadow map [texels] (`--shadows map`).
    #[arg(help_heading = "Shadows", long, default_value_t = DEFAULT_SHADOW_MAP_SIZE, value_parser = clap::value_parser!(u32).range(16..=16384))]
    pub shadow_map_size: u32,

    /// The shadow map's filter: `pcss` (the sun's disk: blocker search and filter, a penumbra) or `nearest`
    /// (the texel under the point: hard shadows).
    #[arg(help_heading = "Shadows", long, default_value = "pcss", value_name = "pcss|nearest")]
    pub shadow_map_filter: ShadowMapFilter,
}

/// The side of the smallest square grid with at least `samples` cells.
pub fn per_axis(samples: u32) -> u32 {
    (samples as f64).sqrt().ceil() as u32
}

impl SceneArgs {
    /// What `--tolerance` promises, if asked: in the penumbrae too unless `--tolerance-outside-penumbrae`.
    pub fn tolerance(&self) -> Option<crate::accuracy::trial::Tolerance> {
        self.tolerance.map(|t| crate::accuracy::trial::Tolerance {
            max_relative: t,
            in_penumbrae: !self.tolerance_outside_penumbrae,
        })
    }

    /// Whether `--tolerance` is asked and is to hold in penumbrae under `lights`: its default, or a sky (held in
    /// its penumbra whatever is asked: it is nearly the whole image). `render` and `reference` take the lights by
    /// slices there unless `--visibility` says otherwise.
    pub fn tolerance_holds_in_penumbrae(&self, lights: &crate::scene::Lights) -> bool {
        self.tolerance().is_some_and(|t| t.in_penumbrae || lights.sky.is_some())
    }

    /// Refuses flags that mean nothing together.
    pub fn check(&self) -> Result<(), RenderError> {
        self.daylight.check().map_err(RenderError::Usage)?;
        self.accumulation.check().map_err(RenderError::Usage)?;
        let accumulating = self.accumulation.from.is_some();
        if self.quantity.is_accumulated() != accumulating {
            return Err(RenderError::Usage(if accumulating {
                "--from/--to/--step accumulate: give --quantity irradiation or sun-hours".into()
            } else {
                format!(
                    "--quantity {} accumulates over time: give --from, --to, --step and --location",
                    self.quantity.name()
                )
            }));
        }
        if self.tolerance.is_some() && self.quantity != RequestedQuantity::Radiance {
            return Err(RenderError::Usage(
                "--tolerance chooses models for radiance; with other quantities choose the sun model and \
                 samples yourself (the irradiance's own formulas are exact; docs/accuracy.md)"
                    .into(),
            ));
        }
        if self.sun_samples.is_some() && self.sun_model == SunModel::Delta {
            return Err(RenderError::Usage("--sun-samples applies to --sun-model disk only".into()));
        }
        Ok(())
    }

    pub fn load_options(&self) -> LoadOptions {
        let uris = match (&self.asset_root, self.allow_outside_uris) {
            (_, true) => UriScope::Anywhere,
            (Some(dir), false) => UriScope::Folder(dir.clone()),
            (None, false) => UriScope::SceneFolder,
        };
        let animation = self.animation.map(|n| (n, self.animation_time.unwrap_or(0.0)));
        LoadOptions { scene: self.scene_index, uris, animation, max_texture_size: self.max_texture_size }
    }

    pub fn camera_options(&self) -> CameraOptions {
        let (camera, automatic) = match self.camera {
            Some(CameraChoice::Scene(n)) => (Some(n), false),
            Some(CameraChoice::Automatic) => (None, true),
            None => (None, false),
        };
        CameraOptions { camera, automatic, eye: self.eye, target: self.target, up: self.up, fov_degrees: self.fov }
    }

    /// The light options with the sun and clear sky of `daylight` (the flags' own where they give them): the sun's
    /// direction from its position; its `E⊥` the clear sky's direct normal irradiance unless --sun-irradiance or
    /// --sun-radiance; the sky the clear sky's uniform equivalent unless --sky-radiance. A sun below the horizon
    /// sends no direct light whatever the flags say.
    pub fn light_options_at(&self, daylight: Option<&DaylightAt>) -> LightOptions {
        let mut sun = self.sun_options();
        let mut sky = self.sky_radiance;
        if let Some(d) = daylight {
            sun.direction = Some(d.direction);
            if !d.position.is_up() {
                sun.irradiance = Some(0.0);
                sun.radiance = None;
            } else if sun.irradiance.is_none() && sun.radiance.is_none() {
                sun.irradiance = Some(d.clear_sky.dni);
            }
            if sky.is_none() {
                sky = Some([d.clear_sky.sky_radiance(); 3]);
            }
        }
        LightOptions {
            sun,
            disks: self.disk_lights.clone(),
            sky,
            shading: ShadingOptions {
                sun: self.sun_model,
                disk: self.disk_model,
                sun_samples_per_axis: self.sun_samples.map_or(DEFAULT_SUN_SAMPLES_PER_AXIS, per_axis),
                samples_per_axis: per_axis(self.samples),
                shadows: self.shadows,
                shadow_samples_per_axis: per_axis(self.shadow_samples),
                shadow_map_size: self.shadow_map_size,
                shadow_map_filter: self.shadow_map_filter,
                quantity: self.quantity.frame(),
                visibility_rule: VisibilityRule::Grid,
            },
        }
    }

    pub fn sun_options(&self) -> SunOptions {
        SunOptions {
            direction: self.sun_dir,
            elevation_degrees: self.sun_elevation,
            azimuth_degrees: self.sun_azimuth,
            irradiance: self.sun_irradiance,
            radiance: self.sun_radiance,
            diameter_degrees: self.sun_diameter,
            color: self.sun_color,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_parse_strictly() {
        assert_eq!(parse_vec3("0.3,1,-0.5").unwrap(), DVec3::new(0.3, 1.0, -0.5));
        assert_eq!(parse_vec3(" 1 , 2 , 3 ").unwrap(), DVec3::new(1.0, 2.0, 3.0));
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,2,3,4").is_err());
        assert!(parse_vec3("1,x,3").is_err());
        assert!(parse_vec3("1,nan,3").is_err());
        assert!(parse_rgb("1,-1,0").is_err());
        assert!(parse_positive("0").is_err());
        assert!(parse_finite("inf").is_err());
        let d = parse_disk_light("0,3,0:0,-2,0:0.5:100,50,25").unwrap();
        assert_eq!((d.center.y, d.direction.y, d.radius, d.radiance), (3.0, -1.0, 0.5, [100.0, 50.0, 25.0]));
        assert_eq!(parse_disk_light("0,3,0:0,-1,0:0.5:7").unwrap().radiance, [7.0; 3]);
        assert!(parse_disk_light("0,3,0:0,0,0:0.5:7").is_err());
        assert!(parse_disk_light("0,3,0:0,-1,0:-0.5:7").is_err());
        assert!(parse_disk_light("0,3,0:0,-1,0:0.5").is_err());
        assert!(parse_radiance("-1").is_err());
        assert!(parse_radiance("1e300").is_err() && parse_radiance("1,1e39,1").is_err());
        assert!(parse_disk_light("0,3,0:0,-1,0:1e300:7").is_err());
        assert!(parse_disk_light("0,1e20,0:0,-1,0:1:7").is_err());
        assert!(parse_disk_light("0,3,0:0,-1,0:1e-50:7").is_err());
        assert!(parse_disk_light("0,3,0:0,-1,0:1:1e300").is_err());
    }
}

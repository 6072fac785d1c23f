//! A request for an image: the flags that define it ([`SceneArgs`]) and how it is to be rendered (device,
//! interpolation, visibility rule); the scene loaded and the settings resolved from them.

use std::time::{Duration, Instant};

use clap::Args;

use super::flags::SceneArgs;
use super::warnings::{warn, warn_once};
use super::RenderError;
use crate::gpu::Interpolation;
use crate::scene::{self, Scene};
use crate::settings::{self, RenderSettings};
use crate::shading::VisibilityRule;

/// What `sunshade render`, a `batch` job, a `test` case and `sunshade::testing::job` ask for.
#[derive(Args, Clone, Debug)]
pub struct RequestArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Vulkan device: an index from `sunshade info`, or part of its name.
    #[arg(help_heading = "Device", long, value_name = "INDEX|NAME")]
    pub device: Option<String>,
    /// How the fragment shader interpolates position and normal: its own barycentrics in f64 (default where the
    /// device has shaderFloat64) or f32, or the device's varyings (docs/accuracy.md compares them).
    #[arg(help_heading = "Device", long, value_name = "f64|f32|device")]
    pub interpolation: Option<Interpolation>,
    /// How the sun's and disk lights' visible fractions through occluders are taken with shadow rays: `grid` (the
    /// located grids of --shadow-samples rays) or `slices` (exact across the light along one angle, a midpoint rule of
    /// 4k² rows along the other, for k² = --shadow-samples: second order in the rows where every occluder is opaque, as
    /// `sunshade reference --visibility slices` takes them; refused where a pixel's light cone holds more than 1024
    /// triangles). On devices without ray queries, whose fragment shader walks the occluders' BVH; refused where the
    /// sky casts shadows (the reference slices it). Default: slices with --tolerance in penumbrae (its default) where
    /// those hold (their f32 geometry then measured against the reference's), else the grid.
    #[arg(long = "visibility", value_name = "grid|slices", help_heading = "Shadows")]
    pub visibility_rule: Option<VisibilityRule>,
}

/// A request's parser on its own, for argument lists that come from elsewhere (the `testing` API): the first
/// element is the scene.
#[derive(clap::Parser, Debug)]
#[command(name = "render", allow_negative_numbers = true, no_binary_name = true)]
struct RequestParser {
    #[command(flatten)]
    args: RequestArgs,
}

impl RequestArgs {
    /// Parses a request's argument list (scene first, no program name); the error is clap's first line.
    pub fn parse_list(argv: &[String]) -> Result<Self, String> {
        <RequestParser as clap::Parser>::try_parse_from(argv).map(|p| p.args).map_err(|e| clap_error_line(&e))
    }
}

/// Loads the scene (with `--brdf` and `--merl` applied) and prints the loader's warnings; returns the time spent.
pub fn load(a: &SceneArgs) -> Result<(Scene, Duration), RenderError> {
    let t = Instant::now();
    let mut scene = scene::load_with_options(&a.scene, &a.load_options())?;
    if let Some(kind) = a.brdf {
        scene.map_brdfs(kind);
    }
    if let Some(path) = &a.merl {
        let table = scene::measured::read_merl_file(path).map_err(|e| RenderError::Failure(anyhow::anyhow!(e)))?;
        scene.warnings.extend(table.missing_warning());
        scene.use_measured(&std::sync::Arc::new(table), a.merl_lookup.unwrap_or_default());
    }
    if let Some(lookup) = a.merl_lookup {
        scene.set_measured_lookup(lookup);
    }
    if let Some(scale) = a.emission_scale {
        scene.scale_emission(scale as f32);
    }
    let load_time = t.elapsed();
    for w in &scene.warnings {
        warn(&format!("{}: {w}", a.scene.display()));
    }
    Ok((scene, load_time))
}

/// The settings of a render of `scene` with these flags (usage errors for flags the scene cannot take). Warns
/// where the light is not what the flags may seem to say: a sun below the horizon (lighting the scene from below;
/// `--time` at night warns on its own and puts the sun out), and a sky or disk light given to a scene without light,
/// which leaves it without the default sun.
pub fn resolve_settings(scene: &Scene, a: &SceneArgs) -> Result<RenderSettings, RenderError> {
    let daylight = a.daylight.at_time();
    if let Some(w) = daylight.as_ref().and_then(|d| d.below_horizon_warning()) {
        warn_once(&w);
    }
    let settings =
        settings::resolve_with(scene, a.width, a.height, &a.camera_options(), &a.light_options_at(daylight.as_ref()))
            .map_err(|e| RenderError::Usage(e.to_string()))?;
    if let (Some(sun), None) = (&settings.lights.sun, &daylight) {
        let (elevation, _) = settings::sun_angles_from_direction(sun.direction.as_dvec3());
        if elevation < 0.0 {
            warn_once(&format!(
                "the sun is below the horizon (elevation {elevation:.2}°): it lights the scene from below"
            ));
        }
    }
    let scene_unlit = scene.lights.is_empty();
    let other_light = a.sky_radiance.is_some() || !a.disk_lights.is_empty();
    if scene_unlit && other_light && settings.lights.sun.is_none() {
        warn_once(
            "no sun: --sky-radiance or --disk-light light this scene alone (the default sun shines only where \
             neither the scene nor the flags give light; --sun-elevation, --sun-dir or --time adds one)",
        );
    }
    Ok(settings)
}

/// clap's usage error on one line: its text without the "Usage:" block and the "--help" hint.
pub fn clap_error_line(e: &clap::Error) -> String {
    let text = e.to_string();
    let mut parts = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("Usage:") || line.starts_with("For more information") {
            break;
        }
        if !line.is_empty() {
            parts.push(line.strip_prefix("error: ").unwrap_or(line));
        }
    }
    parts.join(" ")
}

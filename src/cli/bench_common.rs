//! What every `sunshade bench` table shares: the flags, the warm-frame timing and its medians, the renderer and
//! the line that says what measured, the scenes by default, and a whole `render` process with its `-v` phases.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use clap::Args;

use super::args::parse_positive;
use super::generated::{machine, today};
use super::CliError;
use crate::cpu::ReferenceOptions;
use crate::gpu::{ContextOptions, DeviceInfo, Interpolation, Renderer};

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scenes to measure (default: every .glb and .gltf in models/).
    pub scenes: Vec<PathBuf>,
    /// Image width [pixels] (default 1024).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height [pixels] (default 1024).
    #[arg(long)]
    pub height: Option<u32>,
    /// Timed runs per measurement (after one warm-up run); the median is reported.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
    /// Also time the whole `sunshade render SCENE -o t.png` process this many times.
    #[arg(long, default_value_t = 0)]
    pub process_runs: u32,
    /// The scene whose whole `render` process is timed (default: the first scene).
    #[arg(long, value_name = "SCENE")]
    pub process_scene: Option<PathBuf>,
    /// Replace the generated region of this Markdown file (between the bench markers) with the results
    /// (repeatable).
    #[arg(long, value_name = "MARKDOWN")]
    pub update: Vec<PathBuf>,
    /// Relative tolerance reported as "over tolerance" (as `diff --fail-rel`).
    #[arg(long, default_value_t = 1e-5, value_parser = parse_positive)]
    pub fail_rel: f64,
    /// Vulkan device: an index from `sunshade info`, or part of its name.
    #[arg(long, value_name = "INDEX|NAME")]
    pub device: Option<String>,
    /// Interpolation modes to measure, comma-separated (default: the renderer's default only).
    #[arg(long, value_delimiter = ',', value_name = "f64,f32,device")]
    pub interpolation: Vec<Interpolation>,
    /// Instead of scenes, measure the BRDF chart (a sphere per BRDF and parameter under the sun from three
    /// directions, 256 × 256 unless --width/--height are given): the GPU's error against the reference with the
    /// accurate shader formulas and with the textbook ones (`pow(cos α, e)`, the device's `log`), and the GPU
    /// frame time of each. Its --update region is "brdf-chart".
    #[arg(long, conflicts_with_all = ["scenes", "interpolation", "process_runs"])]
    pub brdf_chart: bool,
    /// Instead of scenes, measure the shadow techniques and sample counts on shadowed scenes (the teapot on a
    /// floor under the sun, the room under its skylight; 256 × 192 unless --width/--height are given): GPU frame
    /// time, CPU reference time, and the visible-fraction error against a converged reference. Run from the
    /// repository (it reads models/). Its --update region is "shadows".
    #[arg(long, conflicts_with_all = ["scenes", "interpolation", "process_runs", "brdf_chart"])]
    pub shadows: bool,
    /// Measure what textures cost: each textured scene (default: the textured samples in models/gltf-samples;
    /// 512 × 512 unless --width/--height are given) with and without its textures, GPU frame and CPU reference
    /// times, and the GPU's agreement with the reference. Its --update region is "textures".
    #[arg(long, conflicts_with_all = ["interpolation", "process_runs", "brdf_chart", "shadows"])]
    pub textures: bool,
    /// Speed against error as a trade-off: for each scene (default: every .glb and .gltf in models/; 256 × 256
    /// unless --width/--height are given), every quality knob over its range alone and in a ladder of
    /// combinations (sun model and samples, disk model, lobe samples, interpolation, shadow technique, samples and
    /// map size, where the scene has what they act on), each with its GPU frame time and its error against the
    /// converged reference (`reference --converged`); the Pareto front is marked. Then what `render --tolerance`
    /// keeps at 1e-2, 1e-3 and 1e-4, its cost and its error over every pixel and outside the penumbrae (on a
    /// device without ray queries, a scene that shadows itself at 64 pixels on the longer side, against its own
    /// converged reference). Its --update region is "pareto".
    #[arg(long, conflicts_with_all = ["interpolation", "process_runs", "brdf_chart", "shadows", "textures"])]
    pub pareto: bool,
    /// Measured BRDFs: analytic BRDFs tabulated into the MERL format against their formulas (linear and nearest
    /// lookups), and each table (the MERL files given as SCENES, else synthetic ones) against its best fit of
    /// every analytic model: GPU frame time and image error under the sun and the sky (256 × 256 unless
    /// --width/--height are given). Its --update regions are "measured-lookup" and "measured-fit".
    #[arg(long, conflicts_with_all = ["interpolation", "process_runs", "brdf_chart", "shadows", "textures", "pareto"])]
    pub measured: bool,
    /// What a whole `render` process costs: each scene (default: every model in models/ at 512 × 512 unless
    /// --width/--height are given, and models/square.gltf at 64 × 64) rendered by --repeat separate processes; the
    /// medians of the process and of its phases, and each pipeline's SPIR-V size (as handed over and with its calls
    /// inlined) and creation time. Its --update region is "startup".
    #[arg(long, conflicts_with_all = ["interpolation", "process_runs", "brdf_chart", "shadows", "textures", "pareto", "measured"])]
    pub startup: bool,
    /// What the default render's shadows cost: teapot, cube, sunset and room (512 × 512 unless --width/--height are
    /// given) and the teapot on a floor under a delta sun at twice that, each GPU frame with the default shadows
    /// against `--shadows none` and `--shadows map`, the CPU reference's render, and for the sun and the disk
    /// lights the share of pixels left to the rays and the rays a pixel (`cpu::sun_costs`, `cpu::disk_costs`). Its
    /// --update region is "shadow-cost".
    #[arg(long, conflicts_with_all = ["interpolation", "process_runs", "brdf_chart", "shadows", "textures", "pareto", "measured", "startup"])]
    pub shadow_cost: bool,
    /// With --startup: the same processes again with the whole shaders handed to the driver (diagnostics:
    /// `SUNSHADE_WHOLE_SHADERS=1`), to show what specializing them saves.
    #[arg(long, requires = "startup")]
    pub whole_shaders: bool,
    /// With --pareto: draw error against frame time (log-log, the front drawn, each point labelled by its row)
    /// into this PNG, one chart per scene.
    #[arg(long, value_name = "PNG", requires = "pareto")]
    pub plot: Option<PathBuf>,
    /// With --pareto: its `--tolerance` table holds each T in the penumbrae too, as `render --tolerance T` does by
    /// default (the penumbrae's pixels refined on the reference: seconds where they are many), instead of outside
    /// them, as `render --tolerance T --tolerance-outside-penumbrae` does (the sweep's default).
    #[arg(long, requires = "pareto")]
    pub tolerance_in_penumbrae: bool,
    /// With --pareto: the accuracy the converged reference claims (relative).
    #[arg(long, value_name = "REL", default_value_t = 1e-4, value_parser = parse_positive)]
    pub accuracy: f64,
    /// With --pareto: refinements of the converged reference at most.
    #[arg(long, value_name = "N", default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..=12))]
    pub max_refinements: u32,
    /// With --pareto: how the converged reference takes the lights' visible fractions through occluders: `grid`
    /// (the located grids of shadow rays; quick, but in penumbrae it leaves pixels unconverged, and they are left
    /// out of the error) or `slices` (`reference --visibility slices`: converges there, at a cost; docs/accuracy.md,
    /// "The converged reference").
    #[arg(long = "visibility", value_name = "grid|slices", default_value = "grid", requires = "pareto")]
    pub visibility_rule: crate::shading::VisibilityRule,
    /// Print the tables as JSON (rows by column title) instead of Markdown; --update still writes Markdown.
    #[arg(long)]
    pub json: bool,
}

/// A GPU measurement: one warm-up frame (the device compiles the variant's shaders at its first draw), whose image
/// is returned, then `repeat` timed frames' render phases.
pub(super) fn warm_frames(
    renderer: &mut Renderer,
    uploaded: &crate::gpu::GpuScene,
    s: &crate::settings::RenderSettings,
    repeat: u32,
) -> Result<(crate::Image, Vec<Duration>), crate::gpu::GpuError> {
    let (image, _) = renderer.render(uploaded, s)?;
    let mut times = Vec::with_capacity(repeat as usize);
    for _ in 0..repeat {
        times.push(renderer.render(uploaded, s)?.1.render);
    }
    Ok((image, times))
}

pub(super) fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

pub(super) fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The renderer of a bench table on `--device`, checked for the image size, its device, and the reference options
/// that mirror it.
pub(super) fn bench_renderer(
    a: &BenchArgs,
    (width, height): (u32, u32),
) -> Result<(Renderer, DeviceInfo, ReferenceOptions), CliError> {
    let options = ContextOptions { device: a.device.clone(), ..ContextOptions::from_env() };
    let renderer = Renderer::new(&options)?;
    renderer.check_size(width, height)?;
    let info = renderer.device_info().clone();
    let reference = ReferenceOptions { sub_pixel_bits: info.sub_pixel_precision_bits, ..Default::default() };
    Ok((renderer, info, reference))
}

/// The first line of a generated table: the command, the date, the machine, the device, the build, the image size,
/// the repetitions and what else the table's reader needs (`tail`).
pub(super) fn measured_by(
    command: &str,
    info: &DeviceInfo,
    (width, height): (u32, u32),
    repeat: u32,
    tail: &str,
) -> String {
    format!(
        "Measured by `{command}` on {}: {}; Vulkan device {}; {} build; {width}×{height} pixels; median of {repeat} warm \
         runs; {tail}.\n\n",
        today(),
        machine(),
        device_description(info),
        build(),
    )
}

pub(super) fn device_description(info: &DeviceInfo) -> String {
    format!("{} ({}, {} {})", info.name, info.type_name(), info.driver_name, info.driver_info)
}

pub(super) fn build() -> &'static str {
    if cfg!(debug_assertions) {
        "debug"
    } else {
        "release"
    }
}

/// Every .glb/.gltf in `models/` (next to the current directory), sorted.
pub(super) fn default_scenes() -> Result<Vec<PathBuf>, CliError> {
    let dir = Path::new("models");
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| {
            CliError::Usage(format!("{}: {e} (give scenes explicitly, or run from the repository)", dir.display()))
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("glb" | "gltf")))
        .collect();
    v.sort();
    Ok(v)
}

/// Times the whole `sunshade render` process and its `-v` phases.
/// One whole `sunshade render SCENE -o TMP --width W --height H -v` process, as users run it: its wall time and
/// what it printed on stderr. `whole_shaders`: with `SUNSHADE_WHOLE_SHADERS=1` (diagnostics), else without it.
pub(super) fn render_process(
    scene: &Path,
    (width, height): (u32, u32),
    whole_shaders: bool,
) -> Result<(Duration, String), CliError> {
    let out = std::env::temp_dir().join(format!("sunshade-bench-{}.png", std::process::id()));
    let mut command = Command::new(std::env::current_exe()?);
    command.arg("render").arg(scene).arg("-o").arg(&out);
    command.args(["--width", &width.to_string(), "--height", &height.to_string(), "-v"]);
    if whole_shaders {
        command.env("SUNSHADE_WHOLE_SHADERS", "1");
    } else {
        command.env_remove("SUNSHADE_WHOLE_SHADERS");
    }
    let t = Instant::now();
    let o = command.output()?;
    let wall = t.elapsed();
    let _ = std::fs::remove_file(&out);
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    if !o.status.success() {
        return Err(CliError::Failure(anyhow::anyhow!("{}: render failed: {}", scene.display(), stderr.trim())));
    }
    Ok((wall, stderr))
}

/// A phase line of `render -v` ("  pipelines   24.08 ms"): its name and milliseconds. `None` for other lines,
/// among them the `sunshade: ...` lines that end in milliseconds too (each pipeline's creation time).
pub(super) fn phase_line(line: &str) -> Option<(String, f64)> {
    if line.starts_with("sunshade:") {
        return None;
    }
    let (name, num) = line.trim().strip_suffix(" ms")?.rsplit_once(' ')?;
    Some((name.trim().to_string(), num.trim().parse().ok()?))
}

pub(super) fn median_f64(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

//! `sunshade bench`: speed against error. For each scene, the GPU frame time and the CPU reference time (both
//! warm, median of `--repeat` runs) beside the GPU-vs-reference comparison; optionally the whole-process time of
//! the `render` command. Writes a Markdown table, and can replace a marked region of a document with it so that
//! published figures always come from this command.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use clap::Args;

use super::args::parse_positive;
use super::CliError;
use crate::compare::{self, DiffOptions};
use crate::cpu::{self, ReferenceOptions};
use crate::gpu::{ContextOptions, Interpolation, Renderer};
use crate::scene::{self, LoadOptions};
use crate::settings::{self, CameraOptions, SunOptions};

/// Marks the region of a Markdown file that `--update` replaces.
pub const BEGIN_MARK: &str = "<!-- sunshade bench: begin (generated; do not edit by hand) -->";
pub const END_MARK: &str = "<!-- sunshade bench: end -->";

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scenes to measure (default: every .glb and .gltf in models/).
    pub scenes: Vec<PathBuf>,
    /// Image width [pixels].
    #[arg(long, default_value_t = 1024)]
    pub width: u32,
    /// Image height [pixels].
    #[arg(long, default_value_t = 1024)]
    pub height: u32,
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
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let scenes = if a.scenes.is_empty() { default_scenes()? } else { a.scenes.clone() };
    let modes: Vec<Option<Interpolation>> =
        if a.interpolation.is_empty() { vec![None] } else { a.interpolation.iter().copied().map(Some).collect() };
    let mut rows = Vec::new();
    let mut info = None;
    for mode in modes {
        let options = ContextOptions { device: a.device.clone(), interpolation: mode, ..ContextOptions::from_env() };
        let mut renderer = Renderer::new(&options)?;
        renderer.check_size(a.width, a.height)?;
        info = Some(renderer.device_info().clone());
        rows.extend(bench_scenes(&mut renderer, &scenes, a)?);
    }
    let info = info.expect("at least one mode");
    let mut out = String::new();
    out += &format!(
        "Measured by `sunshade bench` on {}: {} ({} threads); Vulkan device {} ({}, {} {}); {} build; {}×{} pixels; \
         median of {} warm runs; tolerance {:e} relative with a floor of 1% of the peak.\n\n",
        today(),
        cpu_model(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        info.name,
        info.type_name(),
        info.driver_name,
        info.driver_info,
        if cfg!(debug_assertions) { "debug" } else { "release" },
        a.width,
        a.height,
        a.repeat,
        a.fail_rel,
    );
    out += "| scene | interpolation | triangles | covered px | coverage mismatches | px over tolerance | max rel (interior) | max rel (all) | RMSE [W/(m²·sr)] | GPU frame [ms] | CPU reference [ms] | CPU / GPU |\n";
    out += "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for r in &rows {
        out += r;
        out += "\n";
    }
    if a.process_runs > 0 {
        out += "\n";
        out += &process_timing(a.process_scene.as_ref().unwrap_or(&scenes[0]), a.width, a.height, a.process_runs)?;
    }
    print!("{out}");
    for doc in &a.update {
        update_region(doc, &out)?;
        eprintln!("sunshade bench: updated {}", doc.display());
    }
    Ok(())
}

/// One table row per scene, for this renderer.
fn bench_scenes(renderer: &mut Renderer, scenes: &[PathBuf], a: &BenchArgs) -> Result<Vec<String>, CliError> {
    let options =
        ReferenceOptions { sub_pixel_bits: renderer.device_info().sub_pixel_precision_bits, ..Default::default() };
    let diff_options = DiffOptions { fail_rel: Some(a.fail_rel), ..Default::default() };
    let mut rows = Vec::new();
    for path in scenes {
        let scene = scene::load_with_options(path, &LoadOptions::default())?;
        let s = settings::resolve(&scene, a.width, a.height, &CameraOptions::default(), &SunOptions::default())
            .map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
        let gpu_scene = renderer.upload(&scene)?;
        let (gpu_image, _) = renderer.render(&gpu_scene, &s)?; // warm-up: the device compiles shaders at first draw
        let mut gpu_times = Vec::new();
        for _ in 0..a.repeat {
            gpu_times.push(renderer.render(&gpu_scene, &s)?.1.render);
        }
        let cpu_image = cpu::render(&scene, &s, &options);
        let mut cpu_times = Vec::new();
        for _ in 0..a.repeat {
            let t = Instant::now();
            let _ = cpu::render(&scene, &s, &options);
            cpu_times.push(t.elapsed());
        }
        let (report, _) =
            compare::diff(&gpu_image, &cpu_image, &diff_options).map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let (g, c) = (median(gpu_times), median(cpu_times));
        rows.push(format!(
            "| {name} | {} | {} | {} | {} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2} | {:.2} | {:.1} |",
            renderer.interpolation().name(),
            scene.triangle_count(),
            report.covered_b,
            report.coverage_mismatches.total,
            report.over_tolerance.total,
            report.max_rel_interior,
            report.max_rel,
            report.rmse,
            ms(g),
            ms(c),
            c.as_secs_f64() / g.as_secs_f64()
        ));
        eprintln!("sunshade bench: {name} ({}) done", renderer.interpolation().name());
    }
    Ok(rows)
}

/// Every .glb/.gltf in `models/` (next to the current directory), sorted.
fn default_scenes() -> Result<Vec<PathBuf>, CliError> {
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
fn process_timing(scene: &Path, width: u32, height: u32, runs: u32) -> Result<String, CliError> {
    let exe = std::env::current_exe()?;
    let out = std::env::temp_dir().join(format!("sunshade-bench-{}.png", std::process::id()));
    let (w, h) = (width.to_string(), height.to_string());
    let mut wall = Vec::new();
    let mut phases: Vec<Vec<(String, f64)>> = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        let o = Command::new(&exe)
            .args([
                "render",
                &scene.display().to_string(),
                "-o",
                &out.display().to_string(),
                "--width",
                &w,
                "--height",
                &h,
                "-v",
            ])
            .output()?;
        wall.push(t.elapsed());
        if !o.status.success() {
            return Err(CliError::Failure(anyhow::anyhow!("render failed: {}", String::from_utf8_lossy(&o.stderr))));
        }
        phases.push(
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .filter_map(|l| {
                    let l = l.trim();
                    let v = l.strip_suffix(" ms")?;
                    let (name, num) = v.rsplit_once(' ')?;
                    Some((name.trim().to_string(), num.trim().parse().ok()?))
                })
                .collect(),
        );
    }
    let _ = std::fs::remove_file(&out);
    let mut s = format!(
        "Whole process, `sunshade render {} -o t.png --width {width} --height {height}`: median **{:.0} ms** of {runs} runs. \
         Phases (median, from `-v`):",
        scene.display(),
        ms(median(wall))
    );
    if let Some(first) = phases.first() {
        for (name, _) in first {
            let mut v: Vec<f64> =
                phases.iter().filter_map(|p| p.iter().find(|(n, _)| n == name).map(|(_, t)| *t)).collect();
            v.sort_by(f64::total_cmp);
            s += &format!(" {name} {:.1} ms;", v[v.len() / 2]);
        }
    }
    s.pop();
    s += ".\n";
    Ok(s)
}

/// Replaces the text between [`BEGIN_MARK`] and [`END_MARK`] in `doc`.
fn update_region(doc: &Path, content: &str) -> Result<(), CliError> {
    let text = std::fs::read_to_string(doc).map_err(|e| CliError::Usage(format!("{}: {e}", doc.display())))?;
    let (Some(b), Some(e)) = (text.find(BEGIN_MARK), text.find(END_MARK)) else {
        return Err(CliError::Usage(format!("{}: no '{BEGIN_MARK}' ... '{END_MARK}' region", doc.display())));
    };
    if e < b {
        return Err(CliError::Usage(format!("{}: the bench markers are out of order", doc.display())));
    }
    let new = format!("{}{BEGIN_MARK}\n{content}{}", &text[..b], &text[e..]);
    crate::film::write_atomically(doc, |w| std::io::Write::write_all(w, new.as_bytes()))?;
    Ok(())
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// Today's date (UTC) as YYYY-MM-DD.
fn today() -> String {
    let days =
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs() / 86_400) as i64;
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + (m <= 2) as i64;
    format!("{y:04}-{m:02}-{d:02}")
}

//! The command line: `render`, `info` (and the subcommands of later stages). One file per subcommand.
//!
//! Exit codes: 0 success, 1 failure, 2 usage error. Every error is one line on stderr that names the file or the
//! flag at fault.

mod accumulate;
mod albedo;
mod args;
mod batch;
mod bench;
mod bench_common;
mod bench_measured;
mod bench_pareto;
mod bench_shadow_cost;
mod bench_shadows;
mod bench_startup;
mod bench_textures;
mod bench_tolerance;
mod diff;
mod fit_brdf;
mod generated;
mod info;
mod metadata;
mod reference;
mod reference_doc;
pub(crate) mod render;
mod session;
mod short_help;
mod suite;
mod sum;
mod sun;
mod sweep;
mod tabulate_brdf;

use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand};

use crate::scene::Scene;
use crate::settings::RenderSettings;

#[derive(Parser, Debug)]
#[command(
    name = "sunshade",
    version,
    about = "Offscreen glTF rendering in physical units (radiance in W/(m²·sr)), checked against a CPU reference"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a glTF scene on the GPU (Vulkan) to an image of radiance.
    #[command(allow_negative_numbers = true)]
    Render(Box<render::RenderArgs>),
    /// Render the same image on the CPU (f64 shading, no Vulkan needed): the reference to check against.
    #[command(allow_negative_numbers = true)]
    Reference(Box<reference::ReferenceCommand>),
    /// Compare two images (.exr, .pfm, .png): coverage, errors, worst pixel; exit 1 when outside tolerance.
    #[command(allow_negative_numbers = true)]
    Diff(Box<diff::DiffCommand>),
    /// Add float images pixel by pixel (f64 sums): e.g. the shards of an accumulation rendered apart.
    Sum(sum::SumCommand),
    /// Where the sun is at a time and place (NREL SPA): zenith, azimuth (clockwise from north), elevation, its
    /// direction in scene axes, whether it is up, and the clear sky's irradiances.
    #[command(allow_negative_numbers = true)]
    Sun(sun::SunCommand),
    /// List the Vulkan devices, the one chosen, and the limits that matter to sunshade.
    Info(info::InfoArgs),
    /// Render many jobs of a JSON manifest in one process, on one device: scenes loaded and uploaded once while
    /// they are reused, pipelines created once, images encoded in parallel.
    #[command(allow_negative_numbers = true)]
    Batch(batch::BatchArgs),
    /// Golden-image tests from a suite file: each case rendered and compared with its golden or the CPU
    /// reference; JUnit XML and an HTML report on request; exit 1 when any case fails.
    #[command(allow_negative_numbers = true)]
    Test(suite::TestArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell), e.g.
    /// `sunshade completions bash > /etc/bash_completion.d/sunshade`.
    Completions {
        #[arg(value_name = "SHELL")]
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff), e.g. `sunshade man > sunshade.1 && man ./sunshade.1`; with --dir, write a page
    /// for every subcommand too (sunshade-render.1, ...) into DIR.
    Man {
        #[arg(long, value_name = "DIR", conflicts_with = "markdown")]
        dir: Option<std::path::PathBuf>,
        /// Print the whole reference as Markdown instead (docs/cli.md).
        #[arg(long)]
        markdown: bool,
    },
    /// Speed against error: GPU frame time, CPU reference time and their difference, per scene.
    #[command(allow_negative_numbers = true)]
    Bench(Box<bench_common::BenchArgs>),
    /// Energy check of the BRDFs (directional albedo by converged quadrature) and the error of the sampled
    /// light integrals per sample count; with a scene, the albedo of its materials.
    Albedo(albedo::AlbedoArgs),
    /// Fit an analytic BRDF (lambert, phong, blinn-phong, ward, gltf) to a measured MERL table: its parameters, the
    /// fit's error, and a material extras snippet.
    FitBrdf(fit_brdf::FitBrdfArgs),
    /// Write an analytic BRDF as a MERL table (for tests and comparisons with measured materials).
    TabulateBrdf(tabulate_brdf::TabulateBrdfArgs),
}

pub(crate) use crate::render::one_line;
pub(crate) use crate::render::request::{clap_error_line, load as load_only, resolve_settings};
pub(crate) use crate::render::warnings::{quiet, set_quiet, warn};

/// A failure of a subcommand: a usage error (exit 2) or any other failure (exit 1).
#[derive(Debug)]
pub enum CliError {
    Usage(String),
    Failure(anyhow::Error),
    /// A failure already reported on stdout (a comparison outside tolerance): exit with this code, print nothing.
    Quiet(u8),
}

impl CliError {
    /// The failure as one line, for a command that reports it and goes on (batch jobs, suite cases).
    pub fn message(&self) -> String {
        match self {
            CliError::Usage(m) => m.clone(),
            CliError::Failure(e) => one_line(e),
            CliError::Quiet(code) => format!("failed with exit code {code} (report above)"),
        }
    }
}

impl From<crate::render::RenderError> for CliError {
    fn from(e: crate::render::RenderError) -> Self {
        match e {
            crate::render::RenderError::Usage(m) => CliError::Usage(m),
            crate::render::RenderError::Failure(e) => CliError::Failure(e),
        }
    }
}

impl<E: Into<anyhow::Error>> From<E> for CliError {
    fn from(e: E) -> Self {
        CliError::Failure(e.into())
    }
}

/// The whole parser, for the generated references (man pages, docs/cli.md, completions).
fn command() -> clap::Command {
    <Cli as clap::CommandFactory>::command()
        .mut_subcommand("render", short_help::common_flags_first)
        .mut_subcommand("reference", short_help::common_flags_first)
}

/// Runs the command line and returns the process exit code.
pub fn main() -> ExitCode {
    // Before any thread and any Vulkan instance: the loader then skips Mesa's GPU drivers where no GPU node exists.
    crate::gpu::drivers::skip_mesa_drivers_without_render_node();
    let parsed = command().try_get_matches().and_then(|m| <Cli as clap::FromArgMatches>::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("sunshade: error: {} (see --help)", clap_error_line(&e));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Render(a) => render::run(&a),
        Command::Batch(a) => batch::run(&a),
        Command::Test(a) => suite::run(&a),
        Command::Completions { shell } => {
            clap_complete::generate(shell, &mut command(), "sunshade", &mut std::io::stdout());
            Ok(())
        }
        Command::Man { markdown: true, .. } => {
            print!("{}", reference_doc::markdown(&command()));
            Ok(())
        }
        Command::Man { dir: None, .. } => {
            clap_mangen::Man::new(command()).render(&mut std::io::stdout()).map_err(|e| CliError::Failure(e.into()))
        }
        Command::Man { dir: Some(dir), .. } => clap_mangen::generate_to(command(), &dir)
            .map_err(|e| CliError::Failure(anyhow::anyhow!("{}: {e}", dir.display()))),
        Command::Reference(a) => reference::run(&a),
        Command::Diff(a) => diff::run(&a),
        Command::Sum(a) => sum::run(&a),
        Command::Sun(a) => sun::run_sun(&a),
        Command::Info(a) => info::run(&a),
        Command::Bench(a) => bench::run(&a),
        Command::Albedo(a) => albedo::run(&a),
        Command::FitBrdf(a) => fit_brdf::run(&a),
        Command::TabulateBrdf(a) => tabulate_brdf::run(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Usage(msg)) => {
            eprintln!("sunshade: error: {msg}");
            ExitCode::from(2)
        }
        Err(CliError::Quiet(code)) => ExitCode::from(code),
        Err(CliError::Failure(e)) => {
            eprintln!("sunshade: error: {}", one_line(&e));
            ExitCode::from(1)
        }
    }
}

/// Loads the scene and resolves the render settings; prints the loader's warnings.
fn load_scene(a: &args::SceneArgs) -> Result<(Scene, RenderSettings, Duration), CliError> {
    let (scene, load_time) = load_only(a)?;
    let settings = resolve_settings(&scene, a)?;
    Ok((scene, settings, load_time))
}

/// Refuses an output path whose extension names no supported format, or whose folder does not exist, before any
/// work is done.
fn check_output_path(path: &std::path::Path) -> Result<(), CliError> {
    if crate::film::ImageFormat::from_path(path).is_none() {
        return Err(CliError::Usage(format!(
            "{}: unsupported output extension (use .exr, .pfm or .png)",
            path.display()
        )));
    }
    check_folder_exists(path)
}

/// A heatmap is a PNG; its folder must exist.
fn check_heatmap_path(path: &std::path::Path) -> Result<(), CliError> {
    check_png_path(path, "the heatmap")
}

/// `what` is written as a PNG; its folder must exist.
fn check_png_path(path: &std::path::Path, what: &str) -> Result<(), CliError> {
    if crate::film::ImageFormat::from_path(path) != Some(crate::film::ImageFormat::Png) {
        return Err(CliError::Usage(format!("{}: {what} is a PNG (use .png)", path.display())));
    }
    check_folder_exists(path)
}

pub(crate) fn check_folder_exists(path: &std::path::Path) -> Result<(), CliError> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => std::path::Path::new("."),
    };
    if !folder.is_dir() {
        return Err(CliError::Usage(format!("{}: the folder '{}' does not exist", path.display(), folder.display())));
    }
    Ok(())
}

/// An image in which no pixel is covered is almost always a mistake (a camera looking away, geometry at ±3e38):
/// say so, naming the scene.
fn warn_if_nothing_covered(image: &crate::film::Image, scene: &std::path::Path) {
    if image.covered_count() == 0 {
        warn(&format!(
            "{}: no pixel is covered: the image is empty (is the camera looking at the scene?)",
            scene.display()
        ));
    }
}

/// `-v`: the exposure a PNG was written with.
fn print_exposure(ev: Option<f64>) {
    if let Some(ev) = ev {
        eprintln!("sunshade: PNG exposure EV {ev:+.3} (display value = radiance × 2^EV)");
    }
}

/// Prints each phase's time and `total`, the wall-clock time of the whole command (phases may overlap), as a
/// small table on stderr; then the process's peak resident memory where the system says it.
fn print_phases(phases: &[(&str, Duration)], total: Duration) {
    for (name, d) in phases.iter().chain(std::iter::once(&("total", total))) {
        eprintln!("  {name:<15} {:>9.2} ms", d.as_secs_f64() * 1e3);
    }
    if let Some(kib) = peak_resident_kib() {
        eprintln!("  {:<15} {:>9.1} MB", "peak memory", kib as f64 * 1024.0 / 1e6);
    }
}

/// The process's peak resident set [KiB] (Linux: `VmHWM` in /proc/self/status; `None` elsewhere).
fn peak_resident_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find_map(|l| l.strip_prefix("VmHWM:"))?;
    line.trim().strip_suffix("kB")?.trim().parse().ok()
}

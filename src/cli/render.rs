//! `sunshade render`: the GPU image.

use std::time::Instant;

use clap::Args;

use super::args::{OutputArgs, SceneArgs};
use super::diff::{compare_and_report, ToleranceArgs};
use super::{check_heatmap_path, load_scene, print_exposure, print_phases, warn_if_nothing_covered, CliError};
use crate::cpu::{self, ReferenceOptions};
use crate::film::write_image;
use crate::gpu::{ContextOptions, Interpolation, Renderer};

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub output: OutputArgs,
    /// Vulkan device: an index from `sunshade info`, or part of its name.
    #[arg(long, value_name = "INDEX|NAME")]
    pub device: Option<String>,
    /// How the fragment shader interpolates position and normal: its own barycentrics in f64 (default where the
    /// device has shaderFloat64) or f32, or the device's varyings (docs/accuracy.md compares them).
    #[arg(long, value_name = "f64|f32|device")]
    pub interpolation: Option<Interpolation>,
    /// Print the device and the time of each phase (instance, shader compile, upload, pipelines, render, readback,
    /// encode).
    #[arg(short, long)]
    pub verbose: bool,
    /// Also render the CPU reference (with the device's sub-pixel bits) and compare: exit 1 outside tolerance.
    #[arg(long)]
    pub check: bool,
    /// With --check: write the comparison heatmap here.
    #[arg(long, value_name = "PNG", requires = "check")]
    pub heatmap: Option<std::path::PathBuf>,
    /// With --check: the tolerances of the comparison (as `diff`'s).
    #[command(flatten)]
    pub tolerances: ToleranceArgs,
    /// With --check: whether the device fuses the viewport multiply-add for unclipped vertices (default: whether
    /// this CPU has FMA, which is what lavapipe does). The reference takes the device's sub-pixel bits.
    #[arg(long, action = clap::ArgAction::Set, value_name = "true|false", requires = "check")]
    pub fused_viewport: Option<bool>,
}

pub fn run(a: &RenderArgs) -> Result<(), CliError> {
    let started = Instant::now();
    a.output.check()?;
    a.scene.check()?;
    if !a.check {
        if let Some(flag) = a.tolerances.given().first() {
            return Err(CliError::Usage(format!("{flag} applies only with --check")));
        }
    }
    if let Some(h) = &a.heatmap {
        check_heatmap_path(h)?;
    }
    let (scene, settings, load_time) = load_scene(&a.scene)?;
    let options =
        ContextOptions { device: a.device.clone(), interpolation: a.interpolation, ..ContextOptions::from_env() };
    let mut renderer = Renderer::new(&options)?;
    renderer.check_size(settings.width, settings.height)?;
    let t_upload = Instant::now();
    let gpu_scene = renderer.upload(&scene)?;
    let upload_time = t_upload.elapsed();
    let (image, frame) = renderer.render(&gpu_scene, &settings)?;
    warn_if_nothing_covered(&image, &a.scene.scene);
    let t_encode = Instant::now();
    let ev = write_image(&image, &a.output.output, a.output.exposure())?;
    let encode_time = t_encode.elapsed();
    if a.verbose {
        let info = renderer.device_info();
        eprintln!(
            "sunshade: device {}: {} ({}, {} {}); interpolation {}",
            info.index,
            info.name,
            info.type_name(),
            info.driver_name,
            info.driver_info,
            renderer.interpolation().name()
        );
        eprintln!(
            "sunshade: {} triangles, {}x{} pixels, {} covered",
            scene.triangle_count(),
            settings.width,
            settings.height,
            image.covered_count()
        );
        print_exposure(ev);
        let setup = renderer.setup_timings();
        print_phases(
            &[
                ("load", load_time),
                ("instance", setup.instance),
                ("shader compile", setup.shader_compile), // on other threads, during "instance"
                ("upload", upload_time),
                ("pipelines", frame.pipelines),
                ("render", frame.render),
                ("readback", frame.readback),
                ("encode", encode_time),
            ],
            started.elapsed(),
        );
    }
    if a.check {
        let options = ReferenceOptions {
            sub_pixel_bits: renderer.device_info().sub_pixel_precision_bits,
            fused_viewport: a.fused_viewport.unwrap_or_else(cpu::host_has_fma),
        };
        let t = Instant::now();
        let reference = cpu::render(&scene, &settings, &options);
        if a.verbose {
            eprintln!("sunshade: CPU reference {:.2} ms", t.elapsed().as_secs_f64() * 1e3);
        }
        let report = compare_and_report(
            &image,
            &reference,
            ("gpu", "cpu reference"),
            &a.tolerances.options(),
            a.heatmap.as_deref(),
            false,
        )?;
        if !report.pass {
            return Err(CliError::Quiet(1));
        }
    }
    Ok(())
}

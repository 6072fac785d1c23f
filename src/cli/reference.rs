//! `sunshade reference`: the CPU reference image (no Vulkan needed).

use std::time::Instant;

use clap::Args;

use super::args::{OutputArgs, SceneArgs};
use super::{load_scene, print_exposure, print_phases, warn_if_nothing_covered, CliError};
use crate::cpu::{self, ReferenceOptions};
use crate::film::write_image_with;

/// Options of the reference rasterizer that mirror the device.
#[derive(Args, Clone, Debug)]
pub struct ReferenceArgs {
    /// Sub-pixel precision bits of the device to mirror (`subPixelPrecisionBits`; 8 on lavapipe).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub sub_pixel_bits: u32,
    /// Whether the device fuses the viewport multiply-add for unclipped vertices (default: whether this CPU has
    /// FMA, which is what lavapipe does).
    #[arg(long, action = clap::ArgAction::Set, value_name = "true|false")]
    pub fused_viewport: Option<bool>,
}

impl ReferenceArgs {
    pub fn options(&self) -> ReferenceOptions {
        ReferenceOptions {
            sub_pixel_bits: self.sub_pixel_bits,
            fused_viewport: self.fused_viewport.unwrap_or_else(cpu::host_has_fma),
            // The reference is the truth: `--shadows auto` casts rays wherever something can occlude.
            device_ray_queries: true,
        }
    }
}

#[derive(Args, Debug)]
pub struct ReferenceCommand {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub output: OutputArgs,
    #[command(flatten)]
    pub reference: ReferenceArgs,
    /// The largest image the reference renders [pixels] (default: 2^27, the most lavapipe's largest allocation
    /// holds in RGBA32F, so that the reference has the GPU's limits). Each side is at most 16384, as on the GPU.
    #[arg(long, value_name = "N", default_value_t = cpu::DEFAULT_MAX_PIXELS, value_parser = clap::value_parser!(u64).range(1..))]
    pub max_pixels: u64,
    /// Print the time of each phase.
    #[arg(short, long)]
    pub verbose: bool,
    /// Print no warnings (errors still print).
    #[arg(short, long, conflicts_with = "verbose")]
    pub quiet: bool,
}

pub fn run(a: &ReferenceCommand) -> Result<(), CliError> {
    let started = Instant::now();
    super::set_quiet(a.quiet);
    a.output.check()?;
    a.scene.check()?;
    cpu::check_size(a.scene.width, a.scene.height, a.max_pixels).map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
    let (scene, mut settings, load_time) = load_scene(&a.scene)?;
    let t = Instant::now();
    let options = a.reference.options();
    let choice = cpu::shadow_choice(&scene, &settings, &options);
    settings.shading.shadows = choice.technique;
    let image = cpu::render(&scene, &settings, &options);
    let render_time = t.elapsed();
    warn_if_nothing_covered(&image, &a.scene.scene);
    let t = Instant::now();
    let meta = super::metadata::of_render(&settings, "cpu reference");
    let ev = write_image_with(&image, &a.output.output, a.output.exposure(), &meta)?;
    if a.verbose {
        eprintln!(
            "sunshade: CPU reference, {} threads, {} triangles, {}x{} pixels, {} covered",
            rayon::current_num_threads(),
            scene.triangle_count(),
            settings.width,
            settings.height,
            image.covered_count()
        );
        eprintln!("sunshade: shadows: {} ({})", settings.shading.shadows.name(), choice.reason);
        print_exposure(ev);
        print_phases(&[("load", load_time), ("render", render_time), ("encode", t.elapsed())], started.elapsed());
    }
    Ok(())
}

//! `sunshade reference`: the CPU reference image (no Vulkan needed).

use std::time::Instant;

use clap::Args;

use super::args::{parse_positive, OutputArgs, SceneArgs};
use super::{load_scene, print_exposure, print_phases, warn_if_nothing_covered, CliError};
use crate::accuracy::converged::{self, ConvergenceOptions};
use crate::cpu::{self, ReferenceOptions};
use crate::film::write_image_with;
use crate::shading::VisibilityRule;

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
    /// Render the converged reference: exact light models (disk sun, exact disks), and the sample grids (sun,
    /// lobes, shadow rays) refined from the given counts, each refinement at least doubling every count, until two
    /// doublings in a row change each pixel by less than a tenth of --accuracy (relative, with the diff's floor
    /// of 1% of the peak). Pixels that have not converged after --max-refinements are reported, not hidden
    /// (docs/accuracy.md, "Speed against error").
    #[arg(long, help_heading = "Quality", conflicts_with = "tolerance")]
    pub converged: bool,
    /// The accuracy the converged reference claims (relative).
    #[arg(long, value_name = "REL", default_value_t = converged::DEFAULT_ACCURACY, value_parser = parse_positive, requires = "converged", help_heading = "Quality")]
    pub accuracy: f64,
    /// Refinements of the converged reference at most (each doubles the samples of the pixels still moving).
    #[arg(long, value_name = "N", default_value_t = converged::DEFAULT_MAX_REFINEMENTS, value_parser = clap::value_parser!(u32).range(1..=12), requires = "converged", help_heading = "Quality")]
    pub max_refinements: u32,
    /// How the lights' visible fractions through occluders are taken: `grid` (the located grids of shadow rays
    /// the GPU casts, --shadow-samples) or `slices` (exact along one angle of the light, a midpoint rule of 4k²
    /// rows along the other, for k² = --shadow-samples: second order in the rows, where every occluder is opaque;
    /// the grid otherwise). Default: slices with --converged, and
    /// with --tolerance where it holds in penumbrae (--tolerance's default, or a sky, whose penumbra is the
    /// image): overcast.glb at 64² converges where the grid leaves 1938 of 2461 pixels moving, and --tolerance
    /// keeps 1e-2 there at 9², where the grid refused it or took 56² in penumbrae. The grid otherwise (what the
    /// GPU casts, so that `render --check` compares like with like).
    #[arg(long = "visibility", value_name = "grid|slices", help_heading = "Shadows")]
    pub visibility_rule: Option<VisibilityRule>,
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
    if a.scene.quantity.is_accumulated() {
        return run_accumulation(a, started);
    }
    let (scene, settings, load_time) = load_scene(&a.scene)?;
    let t = Instant::now();
    let options = a.reference.options();
    // Tested once: the shadow choice and the error bound both need it.
    let scene_can_occlude = crate::visibility::can_occlude(&scene);
    // `--converged` has no bound to predict (it is the truth), and takes no `--tolerance`.
    let (image, settings, shadow_reason, prediction, convergence) = if a.converged {
        let plan =
            crate::render::plan::for_reference(&scene, scene_can_occlude, &a.scene, a.visibility_rule, true, settings);
        let mut settings = plan.settings;
        let (image, record) = converged_image(&scene, &mut settings, &options, a);
        (image, settings, plan.shadow_reason, None, Some(record))
    } else {
        let (image, prediction, plan) =
            crate::render::on_reference(&scene, scene_can_occlude, &a.scene, a.visibility_rule, settings, &options)?;
        (image, plan.settings, plan.shadow_reason, Some(prediction), None)
    };
    let render_time = t.elapsed();
    warn_if_nothing_covered(&image, &a.scene.scene);
    let t = Instant::now();
    let mut meta = match &prediction {
        Some(p) => super::metadata::of_render_predicted(&settings, "cpu reference", p),
        None => super::metadata::of_render(&settings, "cpu reference"),
    };
    meta.text.extend(convergence);
    meta.text.extend(super::metadata::measured_materials(&scene));
    meta.text.extend(super::metadata::daylight(&a.scene));
    let ev = write_image_with(&image, &a.output.output, a.output.exposure(), &meta)?;
    a.output.write_false_color(&image, a.scene.quantity)?;
    if a.verbose {
        eprintln!(
            "sunshade: CPU reference, {} threads, {} triangles, {}x{} pixels, {} covered",
            rayon::current_num_threads(),
            scene.triangle_count(),
            settings.width,
            settings.height,
            image.covered_count()
        );
        eprintln!("sunshade: {}", super::metadata::camera_line(&settings, &scene, &a.scene));
        if let Some(line) = super::metadata::sun_position_line(&settings, &scene, &a.scene) {
            eprintln!("sunshade: {line}");
        }
        eprintln!("sunshade: shadows: {} ({})", settings.shading.shadows.name(), shadow_reason);
        eprintln!("sunshade: {}", super::metadata::sun_model_line(&settings, &scene));
        if let Some(line) = super::metadata::lobe_model_line(&settings, &scene) {
            eprintln!("sunshade: {line}");
        }
        if let Some(p) = &prediction {
            eprintln!("sunshade: {}", p.line());
        }
        print_exposure(ev);
        print_phases(&[("load", load_time), ("render", render_time), ("encode", t.elapsed())], started.elapsed());
    }
    Ok(())
}

/// `--converged`: the converged reference of `scene` (a warning names the pixels that did not converge), with
/// `settings` updated to its final sample counts, and its `sunshadeConverged` record for the output's metadata.
fn converged_image(
    scene: &crate::scene::Scene,
    settings: &mut crate::settings::RenderSettings,
    options: &ReferenceOptions,
    a: &ReferenceCommand,
) -> (crate::film::Image, (String, String)) {
    let c = converged::render_converged(
        scene,
        settings,
        options,
        &ConvergenceOptions { accuracy: a.accuracy, max_refinements: a.max_refinements },
    );
    settings.shading = c.shading;
    if !c.converged() {
        super::warn(&c.summary());
    } else if a.verbose {
        eprintln!("sunshade: {}", c.summary());
    }
    let record = serde_json::json!({
        "accuracy": c.accuracy, "refinements": c.refinements, "unconverged_pixels": c.unconverged.len(),
        "last_change": c.last_change,
    });
    (c.image, ("sunshadeConverged".into(), record.to_string()))
}

/// `--quantity irradiation|sun-hours` on the CPU: each step a reference frame (its shadows as `render` resolves
/// them on this machine's reference), summed as `render` sums them.
fn run_accumulation(a: &ReferenceCommand, started: Instant) -> Result<(), CliError> {
    if a.converged || a.scene.tolerance.is_some() {
        return Err(CliError::Usage("an accumulation takes neither --converged nor --tolerance".into()));
    }
    let (scene, load_time) = super::load_only(&a.scene)?;
    let options = a.reference.options();
    let scene_can_occlude = crate::visibility::can_occlude(&scene);
    let done = super::accumulate::accumulate(&scene, &a.scene, |settings| {
        let plan = crate::render::plan::for_reference(
            &scene,
            scene_can_occlude,
            &a.scene,
            a.visibility_rule,
            false,
            settings.clone(),
        );
        Ok(cpu::render(&scene, &plan.settings, &options))
    })?;
    let phases = [("load", load_time)];
    done.finish(&a.scene, &a.output, "cpu reference", a.verbose.then_some((&phases[..], started)))
}

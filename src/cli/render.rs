//! `sunshade render`: the GPU image.

use std::time::{Duration, Instant};

use clap::Args;

use super::args::{OutputArgs, SceneArgs};
use super::diff::{compare_and_report, ReportFormat, ToleranceArgs};
use super::session::Session;
use super::{check_heatmap_path, print_exposure, print_phases, resolve_settings, warn_if_nothing_covered, CliError};
use crate::accuracy::predicted::{self, Prediction};
use crate::accuracy::trial::{render_within_tolerance, Tolerance, TrialError};
use crate::cpu::{self, ReferenceOptions};
use crate::film::{write_image_with, Image};
use crate::gpu::{pipeline_cache, FrameTimings, Interpolation};
use crate::settings::RenderSettings;
use crate::shading::Shadows;

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub output: OutputArgs,
    /// Vulkan device: an index from `sunshade info`, or part of its name.
    #[arg(help_heading = "Device", long, value_name = "INDEX|NAME")]
    pub device: Option<String>,
    /// How the fragment shader interpolates position and normal: its own barycentrics in f64 (default where the
    /// device has shaderFloat64) or f32, or the device's varyings (docs/accuracy.md compares them).
    #[arg(help_heading = "Device", long, value_name = "f64|f32|device")]
    pub interpolation: Option<Interpolation>,
    /// Do not read or write the pipeline cache on disk ($SUNSHADE_CACHE_DIR, else $XDG_CACHE_HOME/sunshade, else
    /// ~/.cache/sunshade).
    #[arg(help_heading = "Device", long)]
    pub no_cache: bool,
    /// How the sun's and disk lights' visible fractions through occluders are taken with shadow rays: `grid` (the
    /// located grids of --shadow-samples rays) or `slices` (exact across the light along one angle, a midpoint rule of
    /// 4k² rows along the other, for k² = --shadow-samples: second order in the rows where every occluder is opaque, as
    /// `sunshade reference --visibility slices` takes them; refused where a pixel's light cone holds more than 1024
    /// triangles). On devices without ray queries, whose fragment shader walks the occluders' BVH; refused where the
    /// sky casts shadows (the reference slices it). Default: slices with --tolerance in penumbrae (its default) where
    /// those hold (their f32 geometry then measured against the reference's), else the grid.
    #[arg(long = "visibility", value_name = "grid|slices", help_heading = "Shadows")]
    pub visibility_rule: Option<crate::shading::VisibilityRule>,
    /// Print the device and the time of each phase (instance, shader compile, upload, pipelines, render, readback,
    /// encode).
    #[arg(help_heading = "Output", short, long)]
    pub verbose: bool,
    /// Print no warnings, and with --check no report: the exit code says whether it passed (errors still print).
    #[arg(help_heading = "Output", short, long, conflicts_with = "verbose")]
    pub quiet: bool,
    /// Also render the CPU reference (with the device's sub-pixel bits) and compare: exit 1 outside tolerance.
    #[arg(help_heading = "Check", long)]
    pub check: bool,
    /// With --check: print the comparison as JSON instead of text.
    #[arg(help_heading = "Check", long, requires = "check")]
    pub json: bool,
    /// With --check: write the comparison heatmap here.
    #[arg(help_heading = "Check", long, value_name = "PNG", requires = "check")]
    pub heatmap: Option<std::path::PathBuf>,
    /// With --check: the tolerances of the comparison (as `diff`'s).
    #[command(flatten, next_help_heading = "Check tolerances")]
    pub tolerances: ToleranceArgs,
    /// With --check: whether the device fuses the viewport multiply-add for unclipped vertices (default: whether
    /// this CPU has FMA, which is what lavapipe does). The reference takes the device's sub-pixel bits.
    #[arg(help_heading = "Check", long, action = clap::ArgAction::Set, value_name = "true|false", requires = "check")]
    pub fused_viewport: Option<bool>,
}

/// `render`'s parser on its own, for argument lists that come from elsewhere (batch jobs, suite cases, the
/// `testing` API): the first element is the scene.
#[derive(clap::Parser, Debug)]
#[command(name = "render", allow_negative_numbers = true, no_binary_name = true)]
struct RenderParser {
    #[command(flatten)]
    args: RenderArgs,
}

impl RenderArgs {
    /// Parses `render`'s argument list (scene first, no program name); the error is clap's, on one line.
    pub fn parse_list(argv: &[String]) -> Result<Self, String> {
        <RenderParser as clap::Parser>::try_parse_from(argv).map(|p| p.args).map_err(|e| super::clap_error_line(&e))
    }

    /// Refuses, before any work, flags that cannot be honoured or mean nothing together.
    pub fn check(&self) -> Result<(), CliError> {
        self.output.check()?;
        self.scene.check()?;
        if !self.check {
            if let Some(flag) = self.tolerances.given().first() {
                return Err(CliError::Usage(format!("{flag} applies only with --check")));
            }
        }
        if let Some(h) = &self.heatmap {
            check_heatmap_path(h)?;
        }
        Ok(())
    }
}

/// A rendered job, not yet written.
pub struct Rendered {
    pub image: Image,
    /// The settings it was rendered with, `shadows` the technique actually used (never `auto`).
    pub settings: RenderSettings,
    /// Why that shadow technique.
    pub shadow_reason: String,
    /// The predicted error of the models used.
    pub prediction: Prediction,
    pub frame: FrameTimings,
    pub load: Duration,
    pub upload: Duration,
    /// The session's scene and renderer it used.
    pub scene: usize,
    pub renderer: usize,
    /// The reference's image at `settings`, mirroring the device, where `--tolerance` rendered it to measure the
    /// GPU's against it: `--check` compares with it rather than render it again ([`reference_of`]).
    pub reference: Option<Image>,
    /// The GPU's own image, where `--tolerance` took some of `image`'s pixels from `reference`
    /// (`accuracy::from_reference`): `--check` compares the device's pixels, not the reference's.
    pub device_image: Option<Image>,
}

/// Renders one job on the session's renderer for its device: the scene loaded (unless the session has it), the
/// settings resolved, then the device, the upload (once per scene and renderer) and the frame.
pub fn render_job(session: &mut Session, a: &RenderArgs) -> Result<Rendered, CliError> {
    a.check()?;
    if a.scene.quantity.is_accumulated() {
        return Err(CliError::Usage(format!(
            "--quantity {} accumulates many frames: render it alone with sunshade render",
            a.scene.quantity.name()
        )));
    }
    let (scene, load) = session.load(&a.scene)?;
    let settings = resolve_settings(session.scene_ref(scene), &a.scene)?;
    let renderer = session.renderer(a.device.clone(), a.interpolation)?;
    session.renderer_mut(renderer).check_size(settings.width, settings.height)?;
    let upload = session.upload(scene, renderer)?;
    let (scene_data, gpu_scene, r) = session.parts(scene, renderer);
    let mut choice = r.shadow_choice(gpu_scene, &settings)?;
    let rule =
        a.visibility_rule.unwrap_or_else(|| default_visibility(&a.scene, &settings, scene_data, choice.technique));
    let slices = rule == crate::shading::VisibilityRule::Slices;
    if slices {
        choice.reason += if settings.lights.sky.is_some() {
            "; the lights' visible fractions by slices (--visibility slices; the sky's in passes before the frame)"
        } else {
            "; the lights' visible fractions by slices (--visibility slices)"
        };
    }
    if choice.warning {
        super::warn_once(&format!("shadows: {}", choice.reason));
    }
    let mut settings = settings;
    settings.shading.shadows = choice.technique;
    // Refused at the render where the GPU cannot take it (`Renderer::shadow_choice`).
    settings.shading.visibility_rule = rule;
    let predicted_for = predicted::Renderer::Gpu { barycentrics: predicted_barycentrics(r.interpolation()) };
    // The reference mirroring the device, for the bound of f32 interpolation.
    let reference = device_reference_options(r.device_info(), a);
    let request = predicted::Request {
        scene: scene_data,
        renderer: predicted_for,
        asked: a.scene.shadows,
        scene_can_occlude: gpu_scene.can_occlude(),
    };
    let tolerance = a.scene.tolerance();
    // Where the GPU slices the lights in their penumbrae (the sky through occluders, whose penumbra is the image, or
    // every light where the tolerance holds in penumbrae, its default), the grids are studied on the reference, whose
    // promise then holds in penumbrae too (`studied_on_the_reference`).
    let can_occlude = gpu_scene.can_occlude();
    let study_on_the_reference = crate::accuracy::trial::sky_by_slices(scene_data, &settings, can_occlude)
        || (tolerance.is_some_and(|t| t.in_penumbrae)
            && crate::accuracy::trial::lights_by_slices(scene_data, &settings, can_occlude));
    // Every render `--tolerance` makes (a delta trial, a lobe study's rungs) is part of this render's cost.
    let mut spent = FrameTimings::default();
    let mut gpu_render = |s: &RenderSettings| {
        let (image, t) = r.render(gpu_scene, s)?;
        spent.shadow_setup += t.shadow_setup;
        spent.pipelines += t.pipelines;
        spent.render += t.render;
        spent.readback += t.readback;
        spent.lights_in_passes |= t.lights_in_passes;
        spent.probe = t.probe.or(spent.probe);
        Ok::<_, crate::gpu::GpuError>((image, t))
    };
    let beyond = |e: crate::gpu::GpuError, settings: &RenderSettings| match (e, tolerance) {
        // A render the device cannot run (`settings` holds its grids, the finest of any material's): the models
        // chosen, or a grid the study went on to; no setting it can render meets the tolerance.
        (crate::gpu::GpuError::LoopBudget(why), Some(t)) => CliError::Usage(format!(
            "--tolerance {:e}: {}; `sunshade reference` with the same scene flags has no such limit{}",
            t.max_relative,
            beyond_this_device(settings, &why),
            if t.in_penumbrae {
                ", and --tolerance-outside-penumbrae holds T outside the penumbrae of the sun and of disk lights \
                 only (their shadow rays' grids then stay off the study's ladder)"
            } else {
                ""
            }
        )),
        (e, _) => CliError::from(e),
    };
    let (image, prediction, reference_image, device_image) = match tolerance {
        Some(t) if study_on_the_reference => {
            let scene_flags = (a.scene.shadows, can_occlude);
            studied_on_the_reference(scene_data, &mut settings, &reference, scene_flags, t, |s| {
                gpu_render(s).map(|(image, _)| image).map_err(|e| beyond(e, s))
            })?
        }
        _ => {
            let done = render_within_tolerance(request, &mut settings, tolerance, &reference, gpu_render, |(i, _)| i)
                .map_err(|e| match e {
                TrialError::Tolerance(why) => CliError::Usage(why),
                TrialError::Render(e) => beyond(e, &settings),
            })?;
            let ((mut image, _), mut prediction) = (done.kept, done.prediction);
            let (mut reference_image, mut device_image) = (None, None);
            if let Some(t) = tolerance.filter(|t| t.in_penumbrae) {
                (reference_image, device_image) = slices_measured_against_the_reference(
                    &mut image,
                    scene_data,
                    &settings,
                    &reference,
                    t.max_relative,
                    &mut prediction,
                )?;
            }
            (image, prediction, reference_image, device_image)
        }
    };
    let frame = spent;
    warn_if_nothing_covered(&image, &a.scene.scene);
    Ok(Rendered {
        image,
        settings,
        shadow_reason: choice.reason,
        prediction,
        frame,
        load,
        upload,
        scene,
        renderer,
        reference: reference_image,
        device_image,
    })
}

/// `--tolerance` where the GPU slices the lights in their penumbrae (the sky through occluders, or every light with the
/// promise held in penumbrae, `--tolerance`'s default): the grids are studied on the reference, the same rule in f64
/// (`accuracy::trial::reference_within_tolerance`, `settings` updated to the models it keeps; the promise there holds
/// in penumbrae too), then the GPU renders once with them (`render`), and the distance of its image from the
/// reference's at those settings (the GPU's f32: shading, interpolation, the slices' geometry) is measured and added to
/// the prediction, the pixels it leaves too far taken from the reference's image (`measured_against_the_reference`):
/// the image is within the sum of the truth. A study's rungs cost the GPU far more than the reference: the sky's
/// passes some 40 ms a row at 64 × 48 on lavapipe (`gpu::slice_passes`; on overcast.glb at 64 × 48 and 1e-3 a study
/// on the GPU took 6 min and kept 27², its order capped at 1, the reference's takes 4 s and keeps 19²); a disk
/// light's rows in passes where the frame runs out of the loop budget (room.gltf at 64², 1e-4: 7 min on the GPU, kept
/// 39²). `(asked, can_occlude)`: the shadows asked for, and whether the scene can shadow itself. The image, its
/// prediction, the reference's image it was measured against, and the GPU's own image where some of its pixels were
/// taken from the reference's.
fn studied_on_the_reference(
    scene: &crate::scene::Scene,
    settings: &mut RenderSettings,
    reference: &ReferenceOptions,
    (asked, can_occlude): (Shadows, bool),
    tolerance: Tolerance,
    render: impl FnOnce(&RenderSettings) -> Result<Image, CliError>,
) -> Result<(Image, Prediction, Option<Image>, Option<Image>), CliError> {
    let (studied, mut prediction) = crate::accuracy::trial::reference_within_tolerance(
        scene,
        settings,
        reference,
        asked,
        can_occlude,
        Some(tolerance),
    )
    .map_err(CliError::Usage)?;
    let mut image = render(settings)?;
    let what = "the GPU against the reference at the kept settings (measured; studied on the reference)";
    let device_image =
        measured_against_the_reference(&mut image, &studied, what, tolerance.max_relative, &mut prediction, |sum| {
            format!(
                "the study's own terms come to {sum:.1e}, leaving nothing for the GPU's f32 shading, interpolation \
                 and slices; `sunshade reference` with the same scene flags has no f32"
            )
        })?;
    Ok((image, prediction, Some(studied), device_image))
}

/// The GPU's `image` against the reference's f64 image at the same settings (`f64_image`): their distance added to
/// the prediction as the term `what`, measured where no bound is derived. Where the sum would exceed `tolerance`,
/// the pixels further from `f64_image` than the rest of the prediction leaves are taken from it
/// (`accuracy::from_reference`; the term names how many), and the GPU's own image is returned; `tolerance` is
/// refused by name only where the rest alone reaches it (`refusal(rest)` says why).
fn measured_against_the_reference(
    image: &mut Image,
    f64_image: &Image,
    what: &str,
    tolerance: f64,
    prediction: &mut Prediction,
    refusal: impl FnOnce(f64) -> String,
) -> Result<Option<Image>, CliError> {
    use crate::accuracy::{from_reference::take_from_reference, refinement::max_difference};
    let rest = prediction.max_relative;
    let apart = max_difference(image, f64_image);
    if rest + apart <= tolerance {
        prediction.add_term(&format!("{what}:"), apart);
        return Ok(None);
    }
    if rest >= tolerance {
        return Err(CliError::Usage(format!("--tolerance {tolerance:e}: {}", refusal(rest))));
    }
    // The pixels' budget, 1% short of what the rest leaves, so that the sum's rounding cannot tip it past T.
    let budget = 0.99 * (tolerance - rest);
    let device_image = image.clone();
    let taken = take_from_reference(image, f64_image, budget);
    let term = format!("{what}, {taken} pixel(s) further than {budget:.1e} taken from the reference's f64 image:");
    prediction.add_term(&term, max_difference(image, f64_image));
    Ok(Some(device_image))
}

/// What f32 geometry costs the GPU's slices where `--tolerance` holds in penumbrae: a point millimetres to
/// centimetres from an occluder sees its edges' crossings through corners relative to it rounded by an f32 ulp of
/// the scene's coordinates (1e-7 m at 1 m), about 1e-4 of the sun's chord at a centimetre (cube.glb at 64²,
/// `--tolerance 1e-4`: 1.5e-4 against the converged reference). No bound is derived for it, so it is measured: the
/// kept image against the reference's f64 slices at the same settings (mirroring the device), added to the
/// prediction as a term, the pixels too far taken from the reference's image (`measured_against_the_reference`).
/// The reference's image, and the GPU's own where pixels were taken.
fn slices_measured_against_the_reference(
    image: &mut Image,
    scene: &crate::scene::Scene,
    settings: &RenderSettings,
    reference: &ReferenceOptions,
    tolerance: f64,
    prediction: &mut Prediction,
) -> Result<(Option<Image>, Option<Image>), CliError> {
    if settings.shading.visibility_rule != crate::shading::VisibilityRule::Slices
        || settings.shading.shadows != Shadows::Ray
    {
        return Ok((None, None));
    }
    let f64_slices = cpu::render(scene, settings, reference);
    let what = "GPU f32 slices (measured against the reference's)";
    let device_image = measured_against_the_reference(image, &f64_slices, what, tolerance, prediction, |sum| {
        format!(
            "the other terms come to {sum:.1e}, leaving nothing for the GPU's slices' f32 geometry; `sunshade \
             reference` with the same scene flags has no f32 geometry"
        )
    })?;
    Ok((Some(f64_slices), device_image))
}

/// `render`'s visibility rule without `--visibility`: slices where `--tolerance` holds in penumbrae (its default, not
/// `--tolerance-outside-penumbrae`; or a sky, whose penumbra is nearly the whole image) and the GPU can take them (no
/// alpha-masked occluders, and shadow rays: `auto` or `ray`, not where `auto` found nothing to shadow), as the
/// reference defaults to them there; the grid otherwise.
fn default_visibility(
    a: &SceneArgs,
    settings: &RenderSettings,
    scene: &crate::scene::Scene,
    technique: Shadows,
) -> crate::shading::VisibilityRule {
    let in_penumbrae = a.tolerance_holds_in_penumbrae(&settings.lights);
    let lights = &settings.lights;
    let lit = lights.sun.is_some() || !lights.disks.is_empty() || lights.sky.is_some();
    let rays = matches!(a.shadows, Shadows::Auto | Shadows::Ray) && technique != Shadows::None;
    if in_penumbrae && lit && rays && !scene.has_alpha_masks() {
        crate::shading::VisibilityRule::Slices
    } else {
        crate::shading::VisibilityRule::Grid
    }
}

/// Why `--tolerance` stopped at a render the device's loop limiter refused (`why`): `settings` holds that render's
/// grids, the finest of any material's (the models chosen, or the next rung where it studies its grids).
pub(super) fn beyond_this_device(settings: &RenderSettings, why: &str) -> String {
    format!(
        "a render it needs (at most {}² lobe grids, {}² sun samples, {}² shadow rays; the next rung where it studies \
         its grids) is beyond this device: {why}",
        settings.shading.samples_per_axis,
        settings.shading.sun_samples_per_axis,
        settings.shading.shadow_samples_per_axis
    )
}

/// How the prediction names the device's interpolation.
pub fn predicted_barycentrics(interpolation: Interpolation) -> predicted::Barycentrics {
    match interpolation {
        Interpolation::BarycentricF64 => predicted::Barycentrics::F64,
        Interpolation::BarycentricF32 => predicted::Barycentrics::F32,
        Interpolation::Device => predicted::Barycentrics::Device,
    }
}

/// The reference options that mirror the device that rendered `job`.
fn reference_options(session: &mut Session, a: &RenderArgs, job: &Rendered) -> ReferenceOptions {
    device_reference_options(session.renderer_mut(job.renderer).device_info(), a)
}

/// The reference options that mirror a device: its sub-pixel bits, and the viewport's FMA as `--fused-viewport`
/// says (else as the host has it).
fn device_reference_options(info: &crate::gpu::DeviceInfo, a: &RenderArgs) -> ReferenceOptions {
    ReferenceOptions {
        sub_pixel_bits: info.sub_pixel_precision_bits,
        fused_viewport: a.fused_viewport.unwrap_or_else(cpu::host_has_fma),
    }
}

/// The CPU reference of a rendered job, mirroring the device that rendered it (its sub-pixel bits, and the
/// viewport's fused multiply-add as `--fused-viewport` says, else as the host CPU has it, as lavapipe does), and
/// the class of pixels a comparison with it counts apart (`cpu::checked`). The reference `--tolerance` rendered is
/// reused where no class is needed ([`Rendered::reference`]).
pub fn checked_reference_of(
    session: &mut Session,
    a: &RenderArgs,
    job: &Rendered,
) -> (Image, Option<cpu::checked::ApartClass>) {
    let options = reference_options(session, a, job);
    let scene = session.scene_ref(job.scene);
    let plain = !cpu::checked::may_be_fragile(scene, &job.settings) && job.settings.shading.shadows != Shadows::Map;
    match &job.reference {
        Some(image) if plain => (image.clone(), None),
        _ => cpu::checked::checked_reference(scene, &job.settings, &options),
    }
}

/// `--check`: the CPU reference with the device's sub-pixel bits ([`checked_reference_of`]), compared;
/// `Err(Quiet(1))` outside tolerance. The class of pixels counted apart is `cpu::checked`'s: a shadow map's edges,
/// or the fragile pixels of shadow rays, textures and alpha masks, at most `cpu::FRAGILE_ALLOWED_FRACTION` of the
/// compared pixels over tolerance.
pub fn check_job(session: &mut Session, a: &RenderArgs, job: &Rendered, verbose: bool) -> Result<(), CliError> {
    let t = Instant::now();
    let (reference, apart) = checked_reference_of(session, a, job);
    if verbose {
        eprintln!("sunshade: CPU reference {:.2} ms", t.elapsed().as_secs_f64() * 1e3);
    }
    // The JSON also carries the render's predicted error against the truth (the comparison is against the
    // reference with the same models).
    let unit = job.settings.shading.quantity.unit();
    let format = ReportFormat::new(a.json, unit, vec![("predicted_error".to_string(), job.prediction.json())]);
    let report = compare_and_report(
        job.device_image.as_ref().unwrap_or(&job.image),
        &reference,
        ("gpu", "cpu reference"),
        &a.tolerances.options(),
        a.heatmap.as_deref(),
        format,
        apart.as_ref().map(|c| (c.mask.as_slice(), c.name, c.allowed_fraction)),
    )?;
    if report.pass {
        return Ok(());
    }
    Err(CliError::Quiet(1))
}

/// The pipeline-cache folder the command line uses: the default one unless `--no-cache`.
pub fn cache_dir(no_cache: bool) -> Option<std::path::PathBuf> {
    if no_cache {
        None
    } else {
        pipeline_cache::default_dir()
    }
}

pub fn run(a: &RenderArgs) -> Result<(), CliError> {
    let started = Instant::now();
    super::set_quiet(a.quiet);
    let mut session = Session::new(cache_dir(a.no_cache));
    if a.scene.quantity.is_accumulated() {
        return run_accumulation(&mut session, a, started);
    }
    let job = render_job(&mut session, a)?;
    let t_cache = Instant::now();
    for w in session.save_pipeline_caches() {
        super::warn(&format!("pipeline cache not saved: {w}"));
    }
    let cache_save = t_cache.elapsed();
    let t_encode = Instant::now();
    let mut meta = super::metadata::of_render_predicted(
        &job.settings,
        &session.renderer_description(job.renderer),
        &job.prediction,
    );
    meta.text.extend(super::metadata::measured_materials(session.scene_ref(job.scene)));
    meta.text.extend(super::metadata::daylight(&a.scene));
    let ev = write_image_with(&job.image, &a.output.output, a.output.exposure(), &meta)?;
    a.output.write_false_color(&job.image, a.scene.quantity)?;
    let encode_time = t_encode.elapsed();
    if a.verbose {
        let triangles = session.scene_ref(job.scene).triangle_count();
        let sun_line = super::metadata::sun_model_line(&job.settings, session.scene_ref(job.scene));
        let lobe_line = super::metadata::lobe_model_line(&job.settings, session.scene_ref(job.scene));
        let cache_dir = session.pipeline_cache_dir.clone();
        let renderer = session.renderer_mut(job.renderer);
        let created = renderer.take_created_pipelines();
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
            "sunshade: {triangles} triangles, {}x{} pixels, {} covered",
            job.settings.width,
            job.settings.height,
            job.image.covered_count()
        );
        eprintln!("sunshade: shadows: {} ({})", job.settings.shading.shadows.name(), job.shadow_reason);
        eprintln!("sunshade: {sun_line}");
        if let Some(line) = lobe_line {
            eprintln!("sunshade: {line}");
        }
        if let Some(lights) = crate::gpu::slice_passes::passed_lights(job.frame.lights_in_passes) {
            eprintln!("sunshade: slices in passes before the frame: {lights} (gpu::slice_passes)");
        }
        if let Some(probe) = job.frame.probe {
            eprintln!("sunshade: {}", probe.describe());
        }
        eprintln!("sunshade: {}", job.prediction.line());
        print_exposure(ev);
        for p in created {
            eprintln!(
                "sunshade: pipeline {}: {} SPIR-V instructions, created in {:.1} ms",
                p.what,
                p.instructions,
                p.time.as_secs_f64() * 1e3
            );
        }
        match (&cache_dir, renderer.pipeline_cache_loaded_bytes()) {
            (None, _) => eprintln!("sunshade: pipeline cache: off"),
            (Some(d), 0) => eprintln!("sunshade: pipeline cache: none yet in {}", d.display()),
            (Some(d), n) => eprintln!("sunshade: pipeline cache: {n} bytes from {}", d.display()),
        }
        let setup = renderer.setup_timings();
        print_phases(
            &[
                ("load", job.load),
                ("instance", setup.instance),
                ("shader compile", setup.shader_compile), // on other threads, during "instance"
                ("upload", job.upload),
                ("shadow setup", job.frame.shadow_setup),
                ("pipelines", job.frame.pipelines),
                ("cache save", cache_save),
                ("render", job.frame.render),
                ("readback", job.frame.readback),
                ("encode", encode_time),
            ],
            started.elapsed(),
        );
    }
    if a.check {
        check_job(&mut session, a, &job, a.verbose)?;
    }
    Ok(())
}

/// `--quantity irradiation|sun-hours`: every step of the interval rendered on one renderer (the scene loaded and
/// uploaded once, the pipelines created at the first step), summed, written once.
fn run_accumulation(session: &mut Session, a: &RenderArgs, started: Instant) -> Result<(), CliError> {
    a.check()?;
    if a.check {
        return Err(CliError::Usage(
            "--check compares one frame: check an instant (--time) of the accumulation instead".into(),
        ));
    }
    let (scene, load) = session.load(&a.scene)?;
    let renderer = session.renderer(a.device.clone(), a.interpolation)?;
    session.renderer_mut(renderer).check_size(a.scene.width, a.scene.height)?;
    let upload = session.upload(scene, renderer)?;
    let (scene_data, gpu_scene, r) = session.parts(scene, renderer);
    let mut pipelines = std::time::Duration::ZERO;
    let done = super::accumulate::accumulate(scene_data, &a.scene, |settings| {
        let choice = r.shadow_choice(gpu_scene, settings)?;
        if choice.warning {
            super::warn_once(&format!("shadows: {}", choice.reason));
        }
        let mut settings = settings.clone();
        settings.shading.shadows = choice.technique;
        let (image, timings) = r.render(gpu_scene, &settings)?;
        pipelines += timings.pipelines;
        Ok(image)
    })?;
    for w in session.save_pipeline_caches() {
        super::warn(&format!("pipeline cache not saved: {w}"));
    }
    let phases = [("load", load), ("upload", upload), ("pipelines", pipelines)];
    done.finish(
        &a.scene,
        &a.output,
        &session.renderer_description(renderer),
        a.verbose.then_some((&phases[..], started)),
    )
}

//! `sunshade render`: the GPU image.

use std::time::{Duration, Instant};

use clap::Args;

use super::args::OutputArgs;
use super::diff::{compare_and_report, ReportFormat, ToleranceArgs};
use super::session::Session;
use super::{check_heatmap_path, print_exposure, print_phases, resolve_settings, warn_if_nothing_covered, CliError};
use crate::cpu::{self, ReferenceOptions};
use crate::film::{write_image_with, Image};
use crate::gpu::pipeline_cache;
use crate::render::RequestArgs;
use crate::shading::Shadows;

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub request: RequestArgs,
    #[command(flatten)]
    pub output: OutputArgs,
    /// Do not read or write the pipeline cache on disk ($SUNSHADE_CACHE_DIR, else $XDG_CACHE_HOME/sunshade, else
    /// ~/.cache/sunshade).
    #[arg(help_heading = "Device", long)]
    pub no_cache: bool,
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
        self.request.scene.check()?;
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

/// A rendered job, not yet written: the render layer's image and where in the session it was made.
pub struct Rendered {
    /// The image, its final settings, prediction and timings, and what `--tolerance` measured against the
    /// reference (`render::Rendered`: `--check` compares with its `reference` rather than render it again,
    /// [`checked_reference_of`]).
    pub render: crate::render::Rendered,
    pub load: Duration,
    pub upload: Duration,
    /// The session's scene and renderer it used.
    pub scene: usize,
    pub renderer: usize,
}

/// Renders one job on the session's renderer for its device: the scene loaded (unless the session has it), the
/// settings resolved, the upload (once per scene and renderer), then the render layer (`render::on_gpu`).
pub fn render_job(session: &mut Session, a: &RenderArgs) -> Result<Rendered, CliError> {
    a.check()?;
    let q = &a.request;
    if q.scene.quantity.is_accumulated() {
        return Err(CliError::Usage(format!(
            "--quantity {} accumulates many frames: render it alone with sunshade render",
            q.scene.quantity.name()
        )));
    }
    let (scene, load) = session.load(&q.scene)?;
    let settings = resolve_settings(session.scene_ref(scene), &q.scene)?;
    let renderer = session.renderer(q.device.clone(), q.interpolation)?;
    session.renderer_mut(renderer).check_size(settings.width, settings.height)?;
    let upload = session.upload(scene, renderer)?;
    let (scene_data, gpu_scene, r) = session.parts(scene, renderer);
    let reference = device_reference_options(r.device_info(), a);
    let render = crate::render::on_gpu(r, (scene_data, gpu_scene), &q.scene, q.visibility_rule, settings, &reference)?;
    warn_if_nothing_covered(&render.image, &q.scene.scene);
    Ok(Rendered { render, load, upload, scene, renderer })
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
    let plain = !cpu::checked::may_be_fragile(scene, &job.render.settings)
        && job.render.settings.shading.shadows != Shadows::Map;
    let (reference, apart) = match &job.render.reference {
        Some(image) if plain => (image.clone(), None),
        _ => cpu::checked::checked_reference(scene, &job.render.settings, &options),
    };
    (job.render.with_refined_pixels(reference), apart)
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
    let unit = job.render.settings.shading.quantity.unit();
    // And what was drawn: the lights and the settings (camera, models, technique, renderer) the files record.
    let recorded = super::metadata::of_render(&job.render.settings, &session.renderer_description(job.renderer));
    let as_json = |key: &str| {
        let text = recorded.text.iter().find(|(k, _)| k == key).map_or("null", |(_, v)| v.as_str());
        serde_json::from_str(text).unwrap_or(serde_json::Value::Null)
    };
    let drew = serde_json::json!({ "lights": as_json("sunshadeLights"), "settings": as_json("sunshadeSettings") });
    let extra = vec![("predicted_error".to_string(), job.render.prediction.json()), ("render".to_string(), drew)];
    let format = ReportFormat::new(a.json, unit, extra);
    let report = compare_and_report(
        job.render.device_image.as_ref().unwrap_or(&job.render.image),
        &reference,
        ("gpu", "cpu reference"),
        &a.tolerances.options(),
        None,
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
    if a.request.scene.quantity.is_accumulated() {
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
        &job.render.settings,
        &session.renderer_description(job.renderer),
        &job.render.prediction,
    );
    meta.text.extend(super::metadata::measured_materials(session.scene_ref(job.scene)));
    meta.text.extend(super::metadata::daylight(&a.request.scene));
    let ev = write_image_with(&job.render.image, &a.output.output, a.output.exposure(), &meta)?;
    a.output.write_false_color(&job.render.image, a.request.scene.quantity)?;
    let encode_time = t_encode.elapsed();
    if a.verbose {
        let triangles = session.scene_ref(job.scene).triangle_count();
        let sun_line = super::metadata::sun_model_line(&job.render.settings, session.scene_ref(job.scene));
        let scene_flags = &a.request.scene;
        let sun_position =
            super::metadata::sun_position_line(&job.render.settings, session.scene_ref(job.scene), scene_flags);
        let camera_line = super::metadata::camera_line(&job.render.settings, session.scene_ref(job.scene), scene_flags);
        let lobe_line = super::metadata::lobe_model_line(&job.render.settings, session.scene_ref(job.scene));
        let emission = emission_line(session.scene_ref(job.scene).largest_emission(), &job.render.image);
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
            job.render.settings.width,
            job.render.settings.height,
            job.render.image.covered_count()
        );
        eprintln!("sunshade: {camera_line}");
        if let Some(line) = &emission {
            eprintln!("sunshade: {line}");
        }
        if let Some(line) = sun_position {
            eprintln!("sunshade: {line}");
        }
        eprintln!("sunshade: shadows: {} ({})", job.render.settings.shading.shadows.name(), job.render.shadow_reason);
        eprintln!("sunshade: {sun_line}");
        if let Some(line) = lobe_line {
            eprintln!("sunshade: {line}");
        }
        if let Some(lights) = crate::gpu::slice_passes::passed_lights(job.render.frame.lights_in_passes) {
            eprintln!("sunshade: slices in passes before the frame: {lights} (gpu::slice_passes)");
        }
        if let Some(probe) = job.render.frame.probe {
            eprintln!("sunshade: {}", probe.describe());
        }
        if let Some(pixels) = job.render.frame.tree_redrawn {
            eprintln!(
                "sunshade: {pixels} pixel(s) cast sun rays through the occluders' tree (more triangles above them \
                 than the sun's cells answer for): drawn once more, with it"
            );
        }
        eprintln!("sunshade: {}", job.render.prediction.line());
        print_exposure(ev);
        for p in created {
            eprintln!(
                "sunshade: pipeline {}: {} SPIR-V instructions ({} inlined), created in {:.1} ms",
                p.what,
                p.instructions,
                p.inlined,
                p.time.as_secs_f64() * 1e3
            );
            if !p.largest.is_empty() {
                let shares: Vec<String> =
                    p.largest.iter().map(|f| format!("{} {} × {}", f.short_name(), f.own, f.copies)).collect();
                eprintln!(
                    "sunshade:   its largest functions inlined (own instructions × copies): {}",
                    shares.join(", ")
                );
            }
        }
        match (&cache_dir, renderer.pipeline_cache_loaded_bytes()) {
            (None, _) => eprintln!("sunshade: pipeline cache: off"),
            (Some(d), 0) => eprintln!("sunshade: pipeline cache: none yet in {}", d.display()),
            (Some(d), n) => eprintln!("sunshade: pipeline cache: {n} bytes from {}", d.display()),
        }
        let setup = renderer.setup_timings();
        let mut phases = vec![
            ("load", job.load),
            ("instance", setup.instance),
            ("shader compile", setup.shader_compile), // on other threads, during "instance"
            ("upload", job.upload),
            ("shadow setup", job.render.frame.shadow_setup),
            ("pipelines", job.render.frame.pipelines),
            ("cache save", cache_save),
            ("render", job.render.frame.render),
            ("readback", job.render.frame.readback),
        ];
        if job.render.refined.is_some() {
            // `--tolerance`'s pixels without a bound, refined on the reference.
            phases.push(("reference pixels", job.render.reference_time));
        }
        phases.push(("encode", encode_time));
        print_phases(&phases, started.elapsed());
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
    let (scene, load) = session.load(&a.request.scene)?;
    let renderer = session.renderer(a.request.device.clone(), a.request.interpolation)?;
    session.renderer_mut(renderer).check_size(a.request.scene.width, a.request.scene.height)?;
    let upload = session.upload(scene, renderer)?;
    let (scene_data, gpu_scene, r) = session.parts(scene, renderer);
    let mut pipelines = std::time::Duration::ZERO;
    let done = super::accumulate::accumulate(scene_data, &a.request.scene, |settings| {
        let q = &a.request;
        let plan =
            crate::render::plan::for_gpu(r, gpu_scene, scene_data, &q.scene, q.visibility_rule, settings.clone())?;
        let (image, timings) = r.render(gpu_scene, &plan.settings)?;
        pipelines += timings.pipelines;
        Ok(image)
    })?;
    for w in session.save_pipeline_caches() {
        super::warn(&format!("pipeline cache not saved: {w}"));
    }
    let phases = [("load", load), ("upload", upload), ("pipelines", pipelines)];
    done.finish(
        &a.request.scene,
        &a.output,
        &session.renderer_description(renderer),
        a.verbose.then_some((&phases[..], started)),
    )
}

/// `-v`'s note where the scene emits but its brightest emission is under 1% of the image's peak (invisible beside
/// the reflected light): how to make it visible.
fn emission_line(largest_emission: f32, image: &crate::Image) -> Option<String> {
    let peak = image.pixels().iter().flat_map(|p| p[..3].iter().copied()).fold(0.0f32, f32::max);
    (largest_emission > 0.0 && largest_emission < 0.01 * peak).then(|| {
        format!(
            "emission: at most {largest_emission:.3e} W/(m²·sr), under 1% of the image's peak {peak:.3e}: \
             --emission-scale S gives S W/(m²·sr) per unit emissiveFactor"
        )
    })
}

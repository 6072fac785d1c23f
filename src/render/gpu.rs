//! A request rendered on the GPU: its plan, then the frame, or with `--tolerance` the models chosen by their bounds
//! and, where none is derived, the pixels refined on the reference (`refined_pixels`), or with
//! `--tolerance-by-study` a study or a measurement against the reference (`tolerance`).

use super::flags::SceneArgs;
use super::plan;
use super::refined_pixels;
use super::tolerance::{beyond_this_device, slices_measured_against_the_reference, studied_on_the_reference};
use super::RenderError;
use crate::accuracy::predicted::{self, Prediction};
use crate::accuracy::trial::{render_within_tolerance, TrialError};
use crate::cpu::ReferenceOptions;
use crate::film::Image;
use crate::gpu::{FrameTimings, GpuError, GpuScene, Interpolation, Renderer};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::VisibilityRule;

/// A rendered request.
pub struct Rendered {
    pub image: Image,
    /// The settings it was rendered with, `shadows` the technique actually used (never `auto`).
    pub settings: RenderSettings,
    /// Why that shadow technique.
    pub shadow_reason: String,
    /// The predicted error of the models used.
    pub prediction: Prediction,
    /// Every frame the render took (`--tolerance`'s trials and studies included).
    pub frame: FrameTimings,
    /// The reference's image at `settings`, mirroring the device, where `--tolerance` rendered it to measure the
    /// GPU's against it: a check compares with it rather than render it again.
    pub reference: Option<Image>,
    /// The GPU's own image, where `--tolerance` took some of `image`'s pixels from `reference`
    /// (`accuracy::from_reference`): a check compares the device's pixels, not the reference's.
    pub device_image: Option<Image>,
    /// The pixels `--tolerance` refined on the reference, no bound covering them (`refined_pixels`), one flag a
    /// pixel: a check takes them as they are (they are the reference's).
    pub refined: Option<Vec<bool>>,
    /// The reference's time on those pixels.
    pub reference_time: std::time::Duration,
}

impl Rendered {
    /// `reference` (the reference at [`Self::settings`], for a check) with the pixels `--tolerance` refined on the
    /// reference ([`Self::refined`]) taken from the image as they are: they are the reference's own, at finer grids
    /// than `settings` name.
    pub fn with_refined_pixels(&self, mut reference: Image) -> Image {
        if let Some(refined) = &self.refined {
            let pixels = reference.pixels_mut().iter_mut().zip(self.image.pixels()).zip(refined);
            for ((r, p), _) in pixels.filter(|(_, &f)| f) {
                *r = *p;
            }
        }
        reference
    }
}

/// Renders `scene` (uploaded to `renderer` as `gpu_scene`) with the flags `a`, the rule `visibility` (else the
/// plan's default) and the resolved `settings`; `reference` mirrors the device (for the bound of f32 interpolation
/// and what `--tolerance` measures against the reference).
pub fn on_gpu(
    renderer: &mut Renderer,
    (scene, gpu_scene): (&Scene, &GpuScene),
    a: &SceneArgs,
    visibility: Option<VisibilityRule>,
    settings: RenderSettings,
    reference: &ReferenceOptions,
) -> Result<Rendered, RenderError> {
    let r = renderer;
    let plan = plan::for_gpu(r, gpu_scene, scene, a, visibility, settings.clone())?;
    let predicted_for = predicted::Renderer::Gpu { barycentrics: predicted_barycentrics(r.interpolation()) };
    let request = predicted::Request {
        scene,
        renderer: predicted_for,
        asked: a.shadows,
        scene_can_occlude: gpu_scene.can_occlude(),
    };
    let tolerance = a.tolerance();
    // What has no derived bound refined pixel by pixel on the reference (`refined_pixels`), unless the study is asked.
    if let Some(t) = tolerance.filter(|&t| !a.tolerance_by_study && refined_pixels::wanted(request, &plan.settings, t))
    {
        // The GPU's frame casts the grid (its first draw settles the pixels it can; the slices have none).
        let plan = plan::for_gpu(r, gpu_scene, scene, a, Some(VisibilityRule::Grid), settings)?;
        let mut settings = plan.settings;
        let done = refined_pixels::render(r, (scene, gpu_scene), &mut settings, request, t, reference)?;
        return Ok(Rendered {
            image: done.image,
            settings,
            shadow_reason: plan.shadow_reason,
            prediction: done.prediction,
            frame: done.frame,
            reference: None,
            device_image: None,
            refined: Some(done.refined),
            reference_time: done.reference_time,
        });
    }
    let mut settings = plan.settings;
    // Where the GPU slices the lights in their penumbrae (the sky through occluders, whose penumbra is the image, or
    // every light where the tolerance holds in penumbrae, its default), the grids are studied on the reference, whose
    // promise then holds in penumbrae too (`studied_on_the_reference`).
    let can_occlude = gpu_scene.can_occlude();
    let study_on_the_reference = crate::accuracy::trial::sky_by_slices(scene, &settings, can_occlude)
        || (tolerance.is_some_and(|t| t.in_penumbrae)
            && crate::accuracy::trial::lights_by_slices(scene, &settings, can_occlude));
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
        spent.tree_redrawn = t.tree_redrawn.or(spent.tree_redrawn);
        Ok::<_, GpuError>((image, t))
    };
    let beyond = |e: GpuError, settings: &RenderSettings| match (e, tolerance) {
        // A render the device cannot run (`settings` holds its grids, the finest of any material's): the models
        // chosen, or a grid the study went on to; no setting it can render meets the tolerance.
        (GpuError::LoopBudget(why), Some(t)) => RenderError::Usage(format!(
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
        (e, _) => RenderError::from(e),
    };
    let (image, prediction, reference_image, device_image) = match tolerance {
        Some(t) if study_on_the_reference => {
            let scene_flags = (a.shadows, can_occlude);
            studied_on_the_reference(scene, &mut settings, reference, scene_flags, t, |s| {
                gpu_render(s).map(|(image, _)| image).map_err(|e| beyond(e, s))
            })?
        }
        _ => {
            let done = render_within_tolerance(request, &mut settings, tolerance, reference, gpu_render, |(i, _)| i)
                .map_err(|e| match e {
                    TrialError::Tolerance(why) => RenderError::Usage(why),
                    TrialError::Render(e) => beyond(e, &settings),
                })?;
            let ((mut image, _), mut prediction) = (done.kept, done.prediction);
            let (mut reference_image, mut device_image) = (None, None);
            if let Some(t) = tolerance.filter(|t| t.in_penumbrae) {
                (reference_image, device_image) = slices_measured_against_the_reference(
                    &mut image,
                    scene,
                    &settings,
                    reference,
                    t.max_relative,
                    &mut prediction,
                )?;
            }
            (image, prediction, reference_image, device_image)
        }
    };
    Ok(Rendered {
        image,
        settings,
        shadow_reason: plan.shadow_reason,
        prediction,
        frame: spent,
        reference: reference_image,
        device_image,
        refined: None,
        reference_time: std::time::Duration::ZERO,
    })
}

/// How the prediction names the device's interpolation.
pub fn predicted_barycentrics(interpolation: Interpolation) -> predicted::Barycentrics {
    match interpolation {
        Interpolation::BarycentricF64 => predicted::Barycentrics::F64,
        Interpolation::BarycentricF32 => predicted::Barycentrics::F32,
        Interpolation::Device => predicted::Barycentrics::Device,
    }
}

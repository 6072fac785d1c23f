//! `--tolerance` held in penumbrae without a study: the GPU shades the pixels whose error has a derived bound, the
//! reference refines the others one by one, and the image's prediction is known once, without rendering the scene
//! on a ladder of grids.
//!
//! **Which pixels have a bound.** A pixel whose every light is wholly visible or wholly hidden (its visible
//! fractions exactly 1 or 0: the sun's cone clear of its cell's triangles or within an opaque one, a disk light's
//! cone clear of the tree, `visibility::sun_cells` and `visibility::disk_cone`), on a material whose models have
//! derived bounds (the sun's grid on an analytic lobe, `accuracy::bounds`; disk lights and the sky on a
//! Lambertian surface, in closed form): the GPU's first of two draws shades exactly those pixels
//! (`gpu::second_draw`) and marks every other. The rest are
//! - the marked pixels: penumbrae, and wherever the cheap proofs do not settle a light;
//! - the pixels of a material without a bound under the scene's lights (`predicted::material_unbounded`: a
//!   measured table under any light, a specular lobe under disk lights or the sky), found by the reference's own
//!   rasterization (`cpu::material_map`, the device's rules);
//! - every covered pixel where the frame has no first draw (the sky through occluders, whose grid every pixel
//!   casts; a sun whose cells hold too many triangles): no pixel of it is settled, and the GPU draws nothing.
//!
//! **How the rest are refined.** The reference renders them alone (`cpu::Frame`, rasterized once) with exact light models,
//! the lights' visible fractions by slices where every occluder is opaque, then doubles every grid of the pixels
//! still moving until two doublings in a row change each by less than a third of the tolerance
//! (`accuracy::converged::refine` with `Criterion::TOLERANCE`: the converged reference's refinement, with Roache's
//! factor of safety for two grids in place of the truth's tenth and without its final check; an estimate, not a
//! bound, measured against the converged reference by `tests/tolerance_refined.rs` and on every model in
//! docs/accuracy.md). The grids start from
//! the render's (6² shadow samples, `4·6²` rows of slices: the truth's start too), the shadows' from a coarser one
//! where the tolerance allows it (`converged::slices_start`: 3² at 1e-2, whose second doubling takes 256 rows, so
//! that an occluder passing between two of them hides less than T of the light). The cost follows the pixels that
//! need it: a penumbra's band, a specular sphere.
//!
//! **The prediction.** The GPU's pixels have the bounds of their models (`accuracy::predicted`, the sun's chosen
//! for the whole tolerance less the f32 terms); the refined pixels the refinement's claim. The two sets are apart,
//! so the image's bound is the larger of the two.

use std::time::{Duration, Instant};

use super::RenderError;
use crate::accuracy::converged::{refine, slices_start, with_exact_models, ConvergenceOptions, Criterion};
use crate::accuracy::interpolation::f32_interpolation_bound;
use crate::accuracy::predicted::{
    choose_sun_for_bounded_pixels, material_unbounded, predict_refining, Barycentrics, Prediction,
    Renderer as Predicted, Request,
};
use crate::accuracy::trial::Tolerance;
use crate::compare::default_floor;
use crate::cpu::{self, ReferenceOptions};
use crate::film::Image;
use crate::gpu::second_draw::LEFT_TO_SECOND_DRAW;
use crate::gpu::{FrameTimings, GpuScene, Renderer};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::{Shadows, VisibilityRule};

/// Doublings of a refined pixel's grids at most: past the converged reference's six, since only the pixels still
/// moving pay for them (a specular lobe's samples through an occluder's edge under the sky converge at the first
/// order or slower, and six left some of the BRDF chart's pixels moving at T = 1e-3).
const MAX_PIXEL_REFINEMENTS: u32 = 10;

/// A render whose unbounded pixels were refined on the reference.
pub struct Refined {
    pub image: Image,
    pub prediction: Prediction,
    /// Which pixels came from the reference (row-major, one flag a pixel).
    pub refined: Vec<bool>,
    /// The GPU's frame (none where it drew nothing).
    pub frame: FrameTimings,
    /// The reference's time on the refined pixels.
    pub reference_time: Duration,
}

/// Whether `--tolerance` (`tolerance`) takes this path: it holds in penumbrae in a scene that shadows itself with
/// shadow rays, or some material's pixels have no bound under its lights, or some lobe is too narrow for every sun
/// grid ([`Choice::refined_lobes`](crate::accuracy::predicted::Choice)).
pub fn wanted(request: Request, settings: &RenderSettings, tolerance: Tolerance) -> bool {
    let penumbrae = tolerance.in_penumbrae
        && request.can_occlude()
        && settings.shading.shadows == Shadows::Ray
        && !settings.lights.is_empty();
    let scene = request.scene;
    penumbrae
        || any_mesh_of(scene, &unbounded_materials(scene, settings))
        || choose_sun_for_bounded_pixels(
            scene,
            settings,
            request.renderer,
            request.can_occlude(),
            tolerance.max_relative,
        )
        .is_ok_and(|c| c.refined_lobes.contains(&true))
}

/// For each material of `scene`, whether its pixels have no derived bound under `settings`' lights
/// (`predicted::material_unbounded`), each asked once: a mapped material's sharpest lobe reads its whole roughness
/// texture.
fn unbounded_materials(scene: &Scene, settings: &RenderSettings) -> Vec<bool> {
    (0..scene.materials.len()).map(|m| material_unbounded(scene, settings, m)).collect()
}

/// Whether some mesh of `scene` uses a material flagged in `flags`.
fn any_mesh_of(scene: &Scene, flags: &[bool]) -> bool {
    scene.meshes.iter().any(|m| flags.get(m.material) == Some(&true))
}

/// Renders `scene` within `tolerance` (see the module's text): `settings` updated to the GPU's models (the grid
/// rule, so that the first draw can settle pixels), `request` the GPU's as the prediction sees it.
pub fn render(
    renderer: &mut Renderer,
    (scene, gpu_scene): (&Scene, &GpuScene),
    settings: &mut RenderSettings,
    request: Request,
    tolerance: Tolerance,
    reference: &ReferenceOptions,
) -> Result<Refined, RenderError> {
    let t = tolerance.max_relative;
    let can_occlude = request.can_occlude();
    settings.shading.visibility_rule = VisibilityRule::Grid;
    // f32 barycentrics add their bound to the GPU's pixels (computed for the models chosen, which it hardly
    // moves; half again as margin), the device's own interpolation has none.
    let f32_bound = match request.renderer {
        Predicted::Gpu { barycentrics: Barycentrics::F32 } => {
            let bound = f32_interpolation_bound(scene, settings, reference);
            if 1.5 * bound >= t {
                return Err(RenderError::Usage(format!(
                    "--tolerance {t:e}: f32 interpolation's bound is {bound:.1e} on this view: --interpolation f64 \
                     where the device has it"
                )));
            }
            Some(bound)
        }
        _ => None,
    };
    let gpu_share = t - 1.5 * f32_bound.unwrap_or(0.0);
    let choice = choose_sun_for_bounded_pixels(scene, settings, request.renderer, can_occlude, gpu_share)
        .map_err(RenderError::Usage)?;
    let (refined_lobes, too_narrow) = (choice.refined_lobes.clone(), choice.refined_materials(scene));
    choice.apply(settings);
    let mut prediction = predict_refining(scene, settings, request.renderer, can_occlude, &refined_lobes);
    if let Some(bound) = f32_bound {
        prediction.add_f32_bound(bound);
    }
    // The GPU's frame: its first draw alone where penumbrae are left to the reference.
    let leave = can_occlude && settings.shading.shadows == Shadows::Ray;
    let drawn = if leave {
        renderer.render_leaving_penumbrae(gpu_scene, settings)?
    } else {
        Some(renderer.render(gpu_scene, settings)?)
    };
    let t_reference = Instant::now();
    let (mut image, frame, mut selected) = match drawn {
        Some((image, frame)) => {
            let marked = image.pixels().iter().map(|p| p[3] == LEFT_TO_SECOND_DRAW).collect();
            (image, frame, marked)
        }
        None => {
            let n = (settings.width * settings.height) as usize;
            (Image::new(settings.width, settings.height), FrameTimings::default(), vec![true; n])
        }
    };
    let mut unbounded = unbounded_materials(scene, settings);
    for (flag, narrow) in unbounded.iter_mut().zip(&too_narrow) {
        *flag |= narrow;
    }
    if any_mesh_of(scene, &unbounded) {
        let materials = cpu::material_map(scene, settings, reference);
        for (flag, m) in selected.iter_mut().zip(materials) {
            *flag |= m.is_some_and(|m| unbounded.get(m) == Some(&true));
        }
    }
    if selected.contains(&true) {
        let mut s = with_exact_models(settings);
        s.sun_per_material.clear();
        if !scene.has_alpha_masks() {
            s.shading.visibility_rule = VisibilityRule::Slices;
            let start = slices_start(t).min(s.shading.shadow_samples_per_axis);
            s.shading.shadow_samples_per_axis = start;
        }
        let frame = cpu::Frame::new(scene, &s, reference);
        let first = frame.render_selected(&s, Some(&selected));
        for ((pixel, from), flag) in image.pixels_mut().iter_mut().zip(first.pixels()).zip(selected.iter_mut()) {
            if *flag {
                *pixel = *from;
                // A pixel the reference does not cover (all of them where the GPU drew nothing) has nothing to refine.
                *flag = from[3] > 0.0;
            }
        }
        let count = selected.iter().filter(|&&f| f).count();
        let floor = default_floor(&image);
        let options = ConvergenceOptions { accuracy: t, max_refinements: MAX_PIXEL_REFINEMENTS };
        let converged = refine(&frame, s, (&options, Criterion::TOLERANCE), (image, selected.clone()), floor);
        let worst = converged.unconverged.first().map_or(0.0, |u| u.change);
        prediction.add_refined_pixels(count, t, (converged.unconverged.len(), worst));
        image = converged.image;
    } else {
        prediction.add_refined_pixels(0, 0.0, (0, 0.0));
    }
    Ok(Refined { image, prediction, refined: selected, frame, reference_time: t_reference.elapsed() })
}

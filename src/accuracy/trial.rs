//! `--tolerance` with the delta sun's trial, for any renderer: where only the delta sun's horizon term keeps it from
//! meeting the tolerance against the floor-based bound (`predicted::delta_worth_trying`), the delta sun is rendered
//! first, the horizon term taken against that image's peak (`bounds::peak_lower_bound`), and the image kept when the
//! delta sun then meets the tolerance; otherwise the choice falls back to the disk sun's grid and the trial's time is
//! the price of asking. Where grids have no derived bound (the lobe grids of specular surfaces under disk lights or the
//! sky; the sun's grid on measured materials), the image is rendered on a ladder of grids instead and the finest one's
//! error estimated by refinement ([`super::refinement`]; a ladder per material where several specular materials share
//! the image, [`super::material_study`]). The sun's models are chosen material by material
//! (`predicted::choose_sun_within`). The reference (`reference_within_tolerance`) and `sunshade render` (the GPU,
//! `cli::render`) both go through [`render_within_tolerance`]; every render it makes is the caller's `render`, so a
//! caller that sums their times has the cost of asking.

use std::convert::Infallible;

use super::interpolation::f32_interpolation_bound;
use super::material_study::{specular_materials, study_per_material};
use super::predicted::{
    choose_and_predict, choose_sun_within, delta_trial, lobes_need_study, only_lambertian, penumbrae_need_study,
    predict_with_peak, sun_needs_study, techniques_within, Barycentrics, Prediction, Renderer, Request,
};
pub use super::promise::{Tolerance, TrialError, WithinTolerance};
use super::refinement::{ladder, Ladder};
use crate::compare::image_peak;
use crate::cpu::{self, ReferenceOptions};
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::{Shadows, SunModel, VisibilityRule};

/// Renders the request's scene with `--tolerance`'s models (`settings.shading` updated to them) by `render` (whose
/// result holds an image, `image_of`), and predicts its error for the request's renderer. A delta render, asked
/// for or chosen, has its horizon term taken against its own image's peak. Specular surfaces under disk lights or
/// the sky, measured materials, and penumbrae where the tolerance is to hold there: `lobe_study`. On a GPU with
/// f32 barycentrics, the bound they add (`accuracy::interpolation`) is computed by the reference with `reference`
/// (mirroring the device) and kept within the tolerance beside the models'.
pub fn render_within_tolerance<T, E>(
    request: Request,
    settings: &mut RenderSettings,
    tolerance: Option<Tolerance>,
    reference: &ReferenceOptions,
    mut render: impl FnMut(&RenderSettings) -> Result<T, E>,
    image_of: impl Fn(&T) -> &Image,
) -> Result<WithinTolerance<T>, TrialError<E>> {
    let f32_barycentrics = request.renderer == Renderer::Gpu { barycentrics: Barycentrics::F32 };
    let Some(Tolerance { max_relative: tolerance, in_penumbrae }) = tolerance.filter(|_| f32_barycentrics) else {
        return models_within(request, settings, tolerance, reference, render, image_of);
    };
    // f32 barycentrics: the models chosen for what their bound leaves, which is known only for the models
    // chosen; first for all of the tolerance, then, where the bound does not fit beside them, once more for what
    // it leaves (with half again as margin: the bound moves a little with the models).
    let initial = settings.clone();
    let mut reserve = 0.0;
    let mut bound = 0.0;
    for _ in 0..2 {
        *settings = initial.clone();
        let within = Tolerance { max_relative: tolerance - reserve, in_penumbrae };
        let mut done = models_within(request, settings, Some(within), reference, &mut render, &image_of)?;
        bound = f32_interpolation_bound(request.scene, settings, reference);
        if done.prediction.max_relative + bound <= tolerance {
            done.prediction.add_f32_bound(bound);
            return Ok(done);
        }
        if bound >= 0.5 * tolerance {
            break;
        }
        reserve = 1.5 * bound;
    }
    Err(TrialError::Tolerance(format!(
        "--tolerance {tolerance:e}: f32 interpolation's bound is {bound:.1e} on this view (its barycentrics' rounding \
         on its triangles, and the radiance's change over it; or a textured, vertex-coloured, normal-mapped or \
         emissive surface, where no bound is claimed): --interpolation f64 where the device has it"
    )))
}

/// What [`render_within_tolerance`] does besides f32 interpolation's bound: the models by their bounds, the delta
/// trial, the grids' study.
fn models_within<T, E>(
    request: Request,
    settings: &mut RenderSettings,
    tolerance: Option<Tolerance>,
    reference: &ReferenceOptions,
    mut render: impl FnMut(&RenderSettings) -> Result<T, E>,
    image_of: impl Fn(&T) -> &Image,
) -> Result<WithinTolerance<T>, TrialError<E>> {
    let Request { scene, renderer, .. } = request;
    let can_occlude = request.can_occlude();
    let penumbrae = tolerance.is_some_and(|t| t.in_penumbrae) && penumbrae_need_study(settings, can_occlude);
    let study = lobes_need_study(scene, settings) || sun_needs_study(scene, settings) || penumbrae;
    if let Some(t) = tolerance.filter(|_| study) {
        return lobe_study(request, settings, (t.max_relative, penumbrae), reference, render, image_of);
    }
    let tolerance = tolerance.map(|t| t.max_relative);
    let trial = if delta_trial(request, settings, tolerance) {
        let mut delta = settings.clone();
        delta.shading.sun = SunModel::Delta;
        delta.sun_per_material.clear();
        Some(render(&delta).map_err(TrialError::Render)?)
    } else {
        None
    };
    let peak = trial.as_ref().map(|t| image_peak(image_of(t)));
    let mut prediction = choose_and_predict(request, settings, tolerance, peak).map_err(TrialError::Tolerance)?;
    let kept = match trial {
        Some(delta) if settings.shading.sun == SunModel::Delta => delta,
        trial => {
            drop(trial);
            render(settings).map_err(TrialError::Render)?
        }
    };
    if settings.shading.sun == SunModel::Delta && peak.is_none() {
        // A delta render asked for (or chosen without a trial): its horizon term against its own image's peak.
        prediction = predict_with_peak(scene, settings, renderer, can_occlude, Some(image_peak(image_of(&kept))), None);
    }
    Ok(WithinTolerance { kept, prediction })
}

/// The shares of the tolerance the sun's models are chosen for in a lobe study, the first that the sun's bound
/// meets: a sun sample costs one lobe evaluation a pixel, a lobe grid's `k²` per disk light and for the sky, so the
/// lobe grids get the larger share unless a lobe too sharp for the sun's grids needs it.
pub const SUN_SHARES: [f64; 3] = [0.25, 0.5, 0.75];

/// `--tolerance` where specular surfaces are lit by disk lights or the sky, a measured material by the sun, or the
/// scene shadows itself: the sun's models chosen by their bounds for a quarter of the tolerance (or a half, or three
/// quarters: [`SUN_SHARES`]; the delta sun's horizon term floor-based, no trial), then the image rendered on the lobe
/// grids' ladder until the refinement's estimate of the finest image's error ([`super::refinement`]) fits what the
/// sun's bound and the arithmetic leave; over several specular materials, a ladder per material, each staying on the
/// rung that fits its own pixels ([`super::material_study`]). With a measured material under the sun, the disk sun's
/// grid is refined on the same rungs instead, and the estimate gets all of the tolerance but the arithmetic; where the
/// scene shadows itself and the tolerance holds in penumbrae too (`shadow_grids`, [`Tolerance::in_penumbrae`]), the
/// shadow rays' grids are refined on the rungs too, with the disk sun's (its lobe samples cast rays: a specular
/// penumbra). Refused as [`techniques_within`] refuses (the sky through occluders without `shadow_grids`, the device's
/// interpolation, shadows other than rays), where the sun's bound cannot meet three quarters of the tolerance, or where
/// the ladder's finest grid does not meet it.
fn lobe_study<T, E>(
    request: Request,
    settings: &mut RenderSettings,
    (tolerance, shadow_grid): (f64, bool),
    reference: &ReferenceOptions,
    mut render: impl FnMut(&RenderSettings) -> Result<T, E>,
    image_of: impl Fn(&T) -> &Image,
) -> Result<WithinTolerance<T>, TrialError<E>> {
    let Request { scene, renderer, .. } = request;
    let can_occlude = request.can_occlude();
    let sun_grid = settings.lights.sun.is_some() && (sun_needs_study(scene, settings) || shadow_grid);
    let budget = if sun_grid || settings.lights.sun.is_none() {
        // No sun's bound to choose: the sun's grid is on the ladder too (the disk sun; the estimate covers it), or
        // there is no sun.
        settings.shading = techniques_within(settings, renderer, can_occlude, shadow_grid, tolerance)
            .map_err(TrialError::Tolerance)?;
        settings.sun_per_material.clear();
        if sun_grid {
            settings.shading.sun = SunModel::Disk;
        }
        tolerance - renderer.arithmetic()
    } else {
        let mut sun = Err(String::new());
        for share in SUN_SHARES {
            sun = choose_sun_within(scene, settings, renderer, can_occlude, share * tolerance, None);
            if sun.is_ok() {
                break;
            }
        }
        // The message names the share it was refused at: say whose share it is.
        let last = SUN_SHARES[SUN_SHARES.len() - 1];
        sun.map_err(|e| {
            TrialError::Tolerance(format!(
                "{e} (the sun's share, {:.0}% of --tolerance {tolerance:e}: the lobe grids' study needs the rest)",
                100.0 * last
            ))
        })?
        .apply(settings);
        // What the sun's terms and the arithmetic leave.
        tolerance - predict_with_peak(scene, settings, renderer, can_occlude, None, None).max_relative
    };
    // The lobe grids alone, over several specular materials: a study per material (`super::material_study`).
    if !sun_grid && !shadow_grid {
        let materials = specular_materials(scene, settings, reference);
        if materials.len() > 1 {
            return study_per_material(request, settings, (tolerance, budget), materials, render, image_of);
        }
    }
    let mut study = Ladder::new(renderer.arithmetic(), sun_grid, shadow_grid);
    if shadow_grid && penumbrae_by_slices_alone(request, settings) {
        study = study.with_sliced_penumbrae();
    }
    let mut previous: Option<T> = None;
    let mut last = None;
    for k in ladder() {
        settings.shading.samples_per_axis = k;
        if sun_grid {
            settings.shading.sun_samples_per_axis = k;
        }
        if shadow_grid {
            settings.shading.shadow_samples_per_axis = k;
        }
        let image = render(settings).map_err(TrialError::Render)?;
        study.push(k, previous.as_ref().map(&image_of), image_of(&image));
        previous = Some(image);
        last = study.estimate();
        if let Some(estimate) = last.filter(|e| e.gci <= budget) {
            let kept = previous.take().expect("rendered");
            let peak = (settings.shading.sun == SunModel::Delta).then(|| image_peak(image_of(&kept)));
            let prediction = predict_with_peak(scene, settings, renderer, can_occlude, peak, Some(&estimate));
            return Ok(WithinTolerance { kept, prediction });
        }
    }
    Err(TrialError::Tolerance(format!(
        "--tolerance {tolerance:e}: the grids estimated by refinement did not meet the {budget:.1e} that the sun's \
         bound and the arithmetic leave by {}² ({}; docs/accuracy.md, \"Error bounds\")",
        settings.shading.samples_per_axis,
        match last {
            Some(e) => format!("estimated {:.1e}", e.gci),
            None => "the last grids' differences do not shrink like a converging grid's".into(),
        }
    )))
}

/// The reference image of `scene` with `--tolerance`'s models (`settings.shading` updated to them) and its
/// predicted error ([`render_within_tolerance`] with `cpu::render`). `Err`: why no setting can promise the
/// tolerance.
///
/// Where the reference takes the sky through occluders by slices ([`sky_by_slices`]) the promise holds in
/// penumbrae too, asked or not: the sky's penumbra is nearly the whole image (the reason the grid is refused
/// with `--tolerance-outside-penumbrae`), and the slices converge there at the second order, so the study that
/// estimates it keeps 9², 19² and 39² on overcast.glb at 48 × 36 for 1e-2, 1e-3 and 1e-4 where the grid took
/// 56² for 1e-2 (docs/accuracy.md, "The converged reference").
pub fn reference_within_tolerance(
    scene: &Scene,
    settings: &mut RenderSettings,
    options: &ReferenceOptions,
    asked: Shadows,
    scene_can_occlude: bool,
    tolerance: Option<Tolerance>,
) -> Result<(Image, Prediction), String> {
    let render = |s: &RenderSettings| Ok::<_, Infallible>(cpu::render(scene, s, options));
    let request = Request { scene, renderer: Renderer::Reference, asked, scene_can_occlude };
    let sliced = sky_by_slices(scene, settings, scene_can_occlude);
    let tolerance = tolerance.map(|t| Tolerance { in_penumbrae: t.in_penumbrae || sliced, ..t });
    match render_within_tolerance(request, settings, tolerance, options, render, |i| i) {
        Ok(done) => Ok((done.kept, done.prediction)),
        Err(TrialError::Tolerance(why)) => Err(why),
        Err(TrialError::Render(never)) => match never {},
    }
}

/// Whether every visible fraction the study refines is the reference's slices and no lobe sample casts a ray
/// (`refinement`'s "Penumbrae by slices"): the reference by `--visibility slices` (the GPU's slices keep the cap of
/// 1: nothing bounds their f32 geometry per pixel, which `render` measures instead), no
/// alpha-masked material (whose occluders send the slices back to the grid), and every material the meshes use
/// Lambertian at every pixel ([`only_lambertian`]: a lobe's samples under the lights cast rays).
fn penumbrae_by_slices_alone(request: Request, settings: &RenderSettings) -> bool {
    matches!(request.renderer, Renderer::Reference)
        && settings.shading.visibility_rule == VisibilityRule::Slices
        && !request.scene.has_alpha_masks()
        && only_lambertian(request.scene)
}

/// Whether the reference's shadow rays see the sky through occluders by slices: the sky lit and
/// [`lights_by_slices`].
pub fn sky_by_slices(scene: &Scene, settings: &RenderSettings, scene_can_occlude: bool) -> bool {
    settings.lights.sky.is_some() && lights_by_slices(scene, settings, scene_can_occlude)
}

/// Whether every shadowed light's visible fraction is taken by slices: shadows by rays in a scene that can shadow
/// itself, `--visibility slices`, and no alpha-masked material (whose occluders send the slices back to the grid,
/// `shading::sky_slices`).
pub fn lights_by_slices(scene: &Scene, settings: &RenderSettings, scene_can_occlude: bool) -> bool {
    scene_can_occlude
        && settings.shading.shadows == Shadows::Ray
        && settings.shading.visibility_rule == VisibilityRule::Slices
        && !scene.has_alpha_masks()
}

//! `--tolerance` on the CPU reference with the delta sun's trial: where only the delta sun's horizon term keeps
//! it from meeting the tolerance against the floor-based bound (`predicted::delta_worth_trying`), the delta sun is
//! rendered first, the horizon term taken against that image's peak (`bounds::peak_lower_bound`), and the image
//! kept when the delta sun then meets the tolerance; otherwise the choice falls back to the disk sun's grid and the
//! trial's time is the price of asking. `sunshade render` does the same on the GPU (`cli::render`).

use super::predicted::{choose_and_predict, delta_trial, predict_with_peak, Prediction, Renderer};
use crate::compare::image_peak;
use crate::cpu::{self, ReferenceOptions};
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::{Shadows, SunModel};

/// The reference image of `scene` with `--tolerance`'s models (`settings.shading` updated to them) and its
/// predicted error; `asked` the shadows asked for, `scene_can_occlude` whether anything in the scene can occlude a
/// light. `Err`: why no setting can promise the tolerance.
pub fn reference_within_tolerance(
    scene: &Scene,
    settings: &mut RenderSettings,
    options: &ReferenceOptions,
    asked: Shadows,
    scene_can_occlude: bool,
    tolerance: Option<f64>,
) -> Result<(Image, Prediction), String> {
    let renderer = Renderer::Reference;
    let trial = delta_trial(scene, settings, renderer, asked, scene_can_occlude, tolerance).then(|| {
        let mut delta = settings.clone();
        delta.shading.sun = SunModel::Delta;
        cpu::render(scene, &delta, options)
    });
    let peak = trial.as_ref().map(image_peak);
    let mut prediction = choose_and_predict(scene, settings, renderer, asked, scene_can_occlude, tolerance, peak)?;
    let image = match trial {
        Some(delta) if settings.shading.sun == SunModel::Delta => delta,
        _ => cpu::render(scene, settings, options),
    };
    if settings.shading.sun == SunModel::Delta && peak.is_none() {
        // A delta render asked for (or chosen without a trial): its horizon term against its own image's peak.
        let can_occlude = asked != Shadows::None && scene_can_occlude;
        prediction = predict_with_peak(scene, settings, renderer, can_occlude, Some(image_peak(&image)));
    }
    Ok((image, prediction))
}

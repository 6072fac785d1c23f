//! `--tolerance` with the delta sun's trial, for any renderer: where only the delta sun's horizon term keeps it
//! from meeting the tolerance against the floor-based bound (`predicted::delta_worth_trying`), the delta sun is
//! rendered first, the horizon term taken against that image's peak (`bounds::peak_lower_bound`), and the image
//! kept when the delta sun then meets the tolerance; otherwise the choice falls back to the disk sun's grid and the
//! trial's time is the price of asking. The reference (`reference_within_tolerance`) and `sunshade render` (the
//! GPU, `cli::render`) both go through [`render_within_tolerance`].

use std::convert::Infallible;

use super::predicted::{choose_and_predict, delta_trial, predict_with_peak, Prediction, Renderer};
use crate::compare::image_peak;
use crate::cpu::{self, ReferenceOptions};
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::{Shadows, SunModel};

/// What [`render_within_tolerance`] rendered: the render kept, its predicted error, and the delta trial where one
/// was rendered and not kept (its cost is part of the render's).
pub struct WithinTolerance<T> {
    pub kept: T,
    pub prediction: Prediction,
    pub discarded_trial: Option<T>,
}

/// Why [`render_within_tolerance`] rendered nothing: no setting can promise the tolerance, or the renderer failed.
pub enum TrialError<E> {
    Tolerance(String),
    Render(E),
}

/// Renders `scene` with `--tolerance`'s models (`settings.shading` updated to them) by `render` (whose result holds
/// an image, `image_of`), and predicts its error; `renderer` whose error is predicted, `asked` the shadows asked
/// for, `scene_can_occlude` whether anything in the scene can occlude a light. A delta render, asked for or
/// chosen, has its horizon term taken against its own image's peak.
#[allow(clippy::too_many_arguments)]
pub fn render_within_tolerance<T, E>(
    scene: &Scene,
    settings: &mut RenderSettings,
    renderer: Renderer,
    asked: Shadows,
    scene_can_occlude: bool,
    tolerance: Option<f64>,
    mut render: impl FnMut(&RenderSettings) -> Result<T, E>,
    image_of: impl Fn(&T) -> &Image,
) -> Result<WithinTolerance<T>, TrialError<E>> {
    let trial = if delta_trial(scene, settings, renderer, asked, scene_can_occlude, tolerance) {
        let mut delta = settings.clone();
        delta.shading.sun = SunModel::Delta;
        Some(render(&delta).map_err(TrialError::Render)?)
    } else {
        None
    };
    let peak = trial.as_ref().map(|t| image_peak(image_of(t)));
    let mut prediction = choose_and_predict(scene, settings, renderer, asked, scene_can_occlude, tolerance, peak)
        .map_err(TrialError::Tolerance)?;
    let (kept, discarded_trial) = match trial {
        Some(delta) if settings.shading.sun == SunModel::Delta => (delta, None),
        trial => (render(settings).map_err(TrialError::Render)?, trial),
    };
    if settings.shading.sun == SunModel::Delta && peak.is_none() {
        // A delta render asked for (or chosen without a trial): its horizon term against its own image's peak.
        let can_occlude = asked != Shadows::None && scene_can_occlude;
        prediction = predict_with_peak(scene, settings, renderer, can_occlude, Some(image_peak(image_of(&kept))));
    }
    Ok(WithinTolerance { kept, prediction, discarded_trial })
}

/// The reference image of `scene` with `--tolerance`'s models (`settings.shading` updated to them) and its
/// predicted error ([`render_within_tolerance`] with `cpu::render`). `Err`: why no setting can promise the
/// tolerance.
pub fn reference_within_tolerance(
    scene: &Scene,
    settings: &mut RenderSettings,
    options: &ReferenceOptions,
    asked: Shadows,
    scene_can_occlude: bool,
    tolerance: Option<f64>,
) -> Result<(Image, Prediction), String> {
    let render = |s: &RenderSettings| Ok::<_, Infallible>(cpu::render(scene, s, options));
    let r = Renderer::Reference;
    match render_within_tolerance(scene, settings, r, asked, scene_can_occlude, tolerance, render, |i| i) {
        Ok(done) => Ok((done.kept, done.prediction)),
        Err(TrialError::Tolerance(why)) => Err(why),
        Err(TrialError::Render(never)) => match never {},
    }
}

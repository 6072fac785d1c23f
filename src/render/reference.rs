//! A request rendered by the CPU reference, as `sunshade reference` renders it: its plan, then the image, or with
//! `--tolerance` the models chosen by their bounds and studies (`accuracy::trial::reference_within_tolerance`).

use super::flags::SceneArgs;
use super::plan::{self, Plan};
use super::RenderError;
use crate::accuracy::predicted::Prediction;
use crate::cpu::ReferenceOptions;
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::VisibilityRule;

/// The reference's image of `scene` with the flags `a` and the rule `visibility` (else the plan's default), its
/// predicted error, and the plan with the settings it kept. `scene_can_occlude`: `visibility::can_occlude(scene)`,
/// tested once by the caller.
pub fn on_reference(
    scene: &Scene,
    scene_can_occlude: bool,
    a: &SceneArgs,
    visibility: Option<VisibilityRule>,
    settings: RenderSettings,
    options: &ReferenceOptions,
) -> Result<(Image, Prediction, Plan), RenderError> {
    let mut plan = plan::for_reference(scene, scene_can_occlude, a, visibility, false, settings);
    let (image, prediction) = crate::accuracy::trial::reference_within_tolerance(
        scene,
        &mut plan.settings,
        options,
        a.shadows,
        scene_can_occlude,
        a.tolerance(),
    )
    .map_err(RenderError::Usage)?;
    Ok((image, prediction, plan))
}

//! How a request is rendered: the shadow technique and the visibility rule, decided here for the GPU and for the
//! reference alike.

use super::flags::SceneArgs;
use super::warnings::warn_once;
use super::RenderError;
use crate::gpu::{GpuScene, Renderer};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::{Shadows, VisibilityRule};

/// Which renderer a plan is for, with what its default visibility rule depends on.
#[derive(Clone, Copy, Debug)]
pub enum PlannedFor {
    /// The GPU, with the technique its device chose: it slices only with shadow rays, opaque occluders and
    /// something lit.
    Gpu { technique: Shadows },
    /// The CPU reference; `converged`: `reference --converged`, which slices wherever it shadows.
    Reference { converged: bool },
}

/// The visibility rule without `--visibility`: slices where the image is to be near the truth in penumbrae
/// (`--tolerance` held in them, its default, or a sky, whose penumbra is nearly the whole image; the converged
/// reference) and the renderer can take them (the GPU: shadow rays, `auto` or `ray`, not where `auto` found nothing
/// to shadow, something lit, no alpha-masked occluders); the grid otherwise, what the GPU casts, so that
/// `render --check` compares like with like. Where the promise leaves the penumbrae out, the slices' walks would cost
/// more for nothing promised (sunset.glb at 256², `--tolerance 1e-2`: 1.5 s against 0.15 s on the reference).
pub fn default_visibility(a: &SceneArgs, settings: &RenderSettings, scene: &Scene, by: PlannedFor) -> VisibilityRule {
    let in_penumbrae = a.tolerance_holds_in_penumbrae(&settings.lights);
    let slices = match by {
        PlannedFor::Reference { converged } => converged || in_penumbrae,
        PlannedFor::Gpu { technique } => {
            let lights = &settings.lights;
            let lit = !lights.is_empty();
            let rays = matches!(a.shadows, Shadows::Auto | Shadows::Ray) && technique != Shadows::None;
            in_penumbrae && lit && rays && !scene.has_alpha_masks()
        }
    };
    if slices {
        VisibilityRule::Slices
    } else {
        VisibilityRule::Grid
    }
}

/// A render's plan: `settings` with its shadow technique (never `auto`) and visibility rule, and why that technique.
pub struct Plan {
    pub settings: RenderSettings,
    pub shadow_reason: String,
}

/// The GPU's plan: the technique its device takes for the scene (`Renderer::shadow_choice`, warned about where it
/// leaves light unoccluded), the rule `--visibility` names or [`default_visibility`]'s.
pub fn for_gpu(
    renderer: &Renderer,
    gpu_scene: &GpuScene,
    scene: &Scene,
    a: &SceneArgs,
    visibility: Option<VisibilityRule>,
    mut settings: RenderSettings,
) -> Result<Plan, RenderError> {
    let mut choice = renderer.shadow_choice(gpu_scene, &settings)?;
    let rule = visibility
        .unwrap_or_else(|| default_visibility(a, &settings, scene, PlannedFor::Gpu { technique: choice.technique }));
    if rule == VisibilityRule::Slices {
        choice.reason += if settings.lights.sky.is_some() {
            "; the lights' visible fractions by slices (--visibility slices; the sky's in passes before the frame)"
        } else {
            "; the lights' visible fractions by slices (--visibility slices)"
        };
    }
    if choice.warning {
        warn_once(&format!("shadows: {}", choice.reason));
    }
    settings.shading.shadows = choice.technique;
    // Refused at the render where the GPU cannot take it (`Renderer::shadow_choice`).
    settings.shading.visibility_rule = rule;
    Ok(Plan { settings, shadow_reason: choice.reason })
}

/// The reference's plan: its technique (`cpu::shadow_choice_where`; `scene_can_occlude` tested once by the caller)
/// and the rule `--visibility` names or [`default_visibility`]'s.
pub fn for_reference(
    scene: &Scene,
    scene_can_occlude: bool,
    a: &SceneArgs,
    visibility: Option<VisibilityRule>,
    converged: bool,
    mut settings: RenderSettings,
) -> Plan {
    let choice = crate::cpu::shadow_choice_where(scene_can_occlude, &settings);
    settings.shading.shadows = choice.technique;
    settings.shading.visibility_rule =
        visibility.unwrap_or_else(|| default_visibility(a, &settings, scene, PlannedFor::Reference { converged }));
    Plan { settings, shadow_reason: choice.reason }
}

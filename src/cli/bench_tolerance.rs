//! `bench --pareto`'s `--tolerance` table: for each scene and T = 1e-2, 1e-3, 1e-4, the models `render --tolerance
//! T` chose, what its renders cost on the GPU (the sum of each render's median warm frame: a delta trial, a grid
//! study's rungs, the image kept), and the kept image's error against the same converged reference as the sweep's;
//! or why it refused.

use std::time::Duration;

use super::bench::{median, ms, warm_frames};
use super::metadata::{lobe_model_line, sun_model_line};
use super::CliError;
use crate::accuracy::converged::Converged;
use crate::accuracy::error::image_error;
use crate::accuracy::predicted::Renderer as Predicted;
use crate::accuracy::predicted::Request;
use crate::accuracy::trial::{render_within_tolerance, Tolerance, TrialError};
use crate::cpu::ReferenceOptions;
use crate::gpu::{GpuScene, Renderer};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::Shadows;

/// The tolerances of the table.
pub(super) const TOLERANCES: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// What `--tolerance` did for one T.
pub(super) struct ToleranceRow {
    tolerance: f64,
    outcome: Result<Kept, String>,
}

/// The image `--tolerance` kept: its models in words, its renders' cost, its measured and predicted error.
struct Kept {
    models: String,
    gpu_ms: f64,
    renders: u32,
    max_rel: f64,
    predicted: f64,
}

/// The table's rows for one scene: `settings` as resolved (default models, shadows as the truth has them),
/// rendered on `renderer` (whose error is predicted as `predicted`), each render timed by `repeat` warm frames;
/// `truth` the converged reference, its unconverged pixels left out; `in_penumbrae`: each T is held in the sun's
/// penumbrae too (`--tolerance-in-penumbrae`), else outside them. A scene that can shadow itself on a device
/// without ray queries is refused without a render (only shadow rays have a known error).
#[allow(clippy::too_many_arguments)]
pub(super) fn tolerance_rows(
    scene: &Scene,
    settings: &RenderSettings,
    renderer: &mut Renderer,
    uploaded: &GpuScene,
    predicted: Predicted,
    reference: &ReferenceOptions,
    truth: &Converged,
    repeat: u32,
    in_penumbrae: bool,
) -> Result<Vec<ToleranceRow>, CliError> {
    let can_occlude = settings.shading.shadows != Shadows::None;
    let excluded = truth.unconverged_mask();
    let mut rows = Vec::new();
    for tolerance in TOLERANCES {
        if can_occlude && !renderer.device_info().ray_query {
            let why = "the scene can shadow itself and the device has no ray queries (its shadow rays would walk the \
                       BVH in the shader: seconds a frame on lavapipe, not swept)"
                .to_string();
            rows.push(ToleranceRow { tolerance, outcome: Err(why) });
            continue;
        }
        let mut s = settings.clone();
        let (mut spent, mut renders) = (Duration::ZERO, 0u32);
        let request =
            Request { scene, renderer: predicted, asked: settings.shading.shadows, scene_can_occlude: can_occlude };
        let done = render_within_tolerance(
            request,
            &mut s,
            Some(if in_penumbrae { Tolerance::everywhere(tolerance) } else { Tolerance::outside_penumbrae(tolerance) }),
            reference,
            |s| {
                let (image, times) = warm_frames(renderer, uploaded, s, repeat)?;
                spent += median(times);
                renders += 1;
                Ok::<_, CliError>(image)
            },
            |image| image,
        );
        let outcome = match done {
            Ok(done) => {
                let error = image_error(&done.kept, &truth.image, Some(&excluded))
                    .map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
                let models: Vec<String> =
                    [Some(sun_model_line(&s, scene)), lobe_model_line(&s, scene)].into_iter().flatten().collect();
                Ok(Kept {
                    models: models.join("; "),
                    gpu_ms: ms(spent),
                    renders,
                    max_rel: error.max_rel,
                    predicted: done.prediction.max_relative,
                })
            }
            Err(TrialError::Tolerance(why)) => Err(why),
            Err(TrialError::Render(e)) => return Err(e),
        };
        rows.push(ToleranceRow { tolerance, outcome });
    }
    Ok(rows)
}

/// The Markdown table of one scene's rows (`in_penumbrae`: rendered with `--tolerance-in-penumbrae`).
pub(super) fn tolerance_table(name: &str, rows: &[ToleranceRow], in_penumbrae: bool) -> String {
    let flags = if in_penumbrae { "render --tolerance T --tolerance-in-penumbrae" } else { "render --tolerance T" };
    let mut out = format!(
        "`{flags}` on {name} (the same truth; GPU time: the sum of the median warm frames of every render it made; \
         max rel over every pixel, penumbrae included):\n\n| T | models chosen | renders | GPU time [ms] | max rel | \
         predicted |\n|---:|---|---:|---:|---:|---:|\n"
    );
    for r in rows {
        out += &match &r.outcome {
            Ok(k) => format!(
                "| {:.0e} | {} | {} | {:.2} | {:.2e} | {:.1e} |\n",
                r.tolerance, k.models, k.renders, k.gpu_ms, k.max_rel, k.predicted
            ),
            Err(why) => format!("| {:.0e} | refused: {} | 0 | — | — | — |\n", r.tolerance, why.replace('|', "/")),
        };
    }
    out + "\n"
}

//! `bench --pareto`'s `--tolerance` table: for each scene and T = 1e-2, 1e-3, 1e-4, the models `render --tolerance T
//! --tolerance-outside-penumbrae` chose (with `bench --tolerance-in-penumbrae`: `render --tolerance T`, which holds T
//! in the penumbrae too, refining their pixels on the reference, `render::refined_pixels`), what its renders cost on
//! the GPU (the sum of each render's median warm frame: a delta trial, a grid study's rungs, the image kept; one
//! frame where pixels were refined) and on the reference (the refined pixels), and the kept image's error against a
//! converged reference, over every pixel and outside the penumbrae (what `--tolerance-outside-penumbrae` promises);
//! or why it refused.
//!
//! On a device without ray queries, a scene that shadows itself gets its table at a smaller size ([`table_size`])
//! against its own converged reference: its shadow rays walk the BVH in the fragment shader there, seconds a frame
//! at the sweep's 256², and the sweep itself reads shadow maps, which `--tolerance` refuses.

use std::time::Duration;

use super::bench_common::{median, ms, warm_frames};
use super::metadata::{lobe_model_line, sun_model_line};
use super::CliError;
use crate::accuracy::converged::Converged;
use crate::accuracy::error::image_error;
use crate::accuracy::penumbrae::outside_penumbrae_excluded;
use crate::accuracy::predicted::Renderer as Predicted;
use crate::accuracy::predicted::Request;
use crate::accuracy::trial::{render_within_tolerance, Tolerance, TrialError, WithinTolerance};
use crate::cpu::ReferenceOptions;
use crate::gpu::{GpuError, GpuScene, Renderer};
use crate::render::{beyond_this_device, refined_pixels, RenderError};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::Shadows;

/// The tolerances of the table.
pub(super) const TOLERANCES: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// A scene's table: its rows, and how many of the truth's covered pixels are in a penumbra (where it was
/// computed: once an image was kept) of how many.
pub(super) struct ToleranceTable {
    rows: Vec<ToleranceRow>,
    penumbra_pixels: Option<(usize, usize)>,
}

/// What `--tolerance` did for one T.
struct ToleranceRow {
    tolerance: f64,
    outcome: Result<Kept, String>,
}

/// The image `--tolerance` kept: its models in words, its renders' cost, its measured error (over every pixel and
/// outside the penumbrae) and its predicted error.
struct Kept {
    models: String,
    gpu_ms: f64,
    /// The reference's time on the pixels without a bound (`render::refined_pixels`), 0 where none were refined.
    reference_ms: f64,
    renders: u32,
    max_rel: f64,
    max_rel_outside_penumbrae: f64,
    /// The predicted bound, and whether part of the image has none (the penumbrae, without
    /// `--tolerance-in-penumbrae`).
    predicted: (f64, bool),
}

/// The longest side of the table on a device without ray queries, where a scene shadows itself [pixels].
pub(super) const WALK_TABLE_SIDE: u32 = 64;

/// The size of a scene's `--tolerance` table: the sweep's, but on a device without ray queries for a scene that
/// shadows itself, scaled down (aspect kept, sides rounded, at least 1) so that its longer side is at most
/// [`WALK_TABLE_SIDE`]. Measured on the system lavapipe (Mesa 22.3.6, 2 threads): the whole bench of the eight
/// models at 64² (their sweeps too) took 67 s, where one render of teapot.glb or sunset.glb walking the BVH at 256²
/// takes 4 to 8 s.
pub(super) fn table_size((width, height): (u32, u32), ray_queries: bool, can_occlude: bool) -> (u32, u32) {
    let longer = width.max(height);
    if ray_queries || !can_occlude || longer <= WALK_TABLE_SIDE {
        return (width, height);
    }
    let scale = |side: u32| ((side as u64 * WALK_TABLE_SIDE as u64 + longer as u64 / 2) / longer as u64).max(1) as u32;
    (scale(width), scale(height))
}

/// The table's rows for one scene: `settings` as resolved (default models, shadows as the truth has them, the
/// table's size), rendered on `renderer` (whose error is predicted as `predicted`), each render timed by `repeat`
/// warm frames; `truth` the converged reference at that size, its unconverged pixels left out; `in_penumbrae`:
/// each T is held in the penumbrae too (`--tolerance-in-penumbrae`), else outside them, which the rows measure
/// apart ([`outside_penumbrae_excluded`]). A render the device cannot run (its loop limiter) is a refusal, as
/// `render` makes it ([`beyond_this_device`]).
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
) -> Result<ToleranceTable, CliError> {
    let can_occlude = settings.shading.shadows != Shadows::None;
    let excluded = truth.unconverged_mask();
    // Unconverged pixels and those in a penumbra, computed at the first image kept, and the penumbrae's pixels.
    let mut outside_penumbrae: Option<Vec<bool>> = None;
    let mut penumbra_pixels = None;
    let mut rows = Vec::new();
    for tolerance in TOLERANCES {
        let mut s = settings.clone();
        // The GPU's grids, whatever rule the truth took (`render`'s slices are not in this table yet).
        s.shading.visibility_rule = crate::shading::VisibilityRule::Grid;
        let (mut spent, mut renders, mut reference_time) = (Duration::ZERO, 0u32, Duration::ZERO);
        let request =
            Request { scene, renderer: predicted, asked: settings.shading.shadows, scene_can_occlude: can_occlude };
        let promise =
            if in_penumbrae { Tolerance::everywhere(tolerance) } else { Tolerance::outside_penumbrae(tolerance) };
        let done = if refined_pixels::wanted(request, &s, promise) {
            // As `render --tolerance` does: one frame, the pixels without a bound refined on the reference.
            match refined_pixels::render(renderer, (scene, uploaded), &mut s, request, promise, reference) {
                Ok(r) => {
                    (spent, renders, reference_time) = (r.frame.render, 1, r.reference_time);
                    Ok(WithinTolerance { kept: r.image, prediction: r.prediction })
                }
                Err(RenderError::Usage(why)) => Err(TrialError::Tolerance(why)),
                Err(e) => return Err(e.into()),
            }
        } else {
            render_within_tolerance(
                request,
                &mut s,
                Some(promise),
                reference,
                |s| {
                    let (image, times) = warm_frames(renderer, uploaded, s, repeat)?;
                    spent += median(times);
                    renders += 1;
                    Ok::<_, GpuError>(image)
                },
                |image| image,
            )
        };
        let outcome = match done {
            Ok(done) => {
                let error = |excluded: &[bool]| {
                    image_error(&done.kept, &truth.image, Some(excluded))
                        .map(|e| e.max_rel)
                        .map_err(|e| CliError::Failure(anyhow::anyhow!(e)))
                };
                let outside = outside_penumbrae.get_or_insert_with(|| {
                    let (excluded, in_penumbrae) = outside_penumbrae_excluded(scene, settings, truth, reference);
                    penumbra_pixels = Some((in_penumbrae, truth.covered));
                    excluded
                });
                let models: Vec<String> =
                    [Some(sun_model_line(&s, scene)), lobe_model_line(&s, scene)].into_iter().flatten().collect();
                Ok(Kept {
                    models: models.join("; "),
                    gpu_ms: ms(spent),
                    reference_ms: ms(reference_time),
                    renders,
                    max_rel: error(&excluded)?,
                    max_rel_outside_penumbrae: error(outside)?,
                    predicted: (done.prediction.max_relative, !done.prediction.unbounded.is_empty()),
                })
            }
            Err(e) => Err(refusal(&s, e)?),
        };
        rows.push(ToleranceRow { tolerance, outcome });
    }
    Ok(ToleranceTable { rows, penumbra_pixels })
}

/// The row of a T that `--tolerance` did not keep an image for, `settings` its last render's: its refusal, or
/// the device's loop limiter refusing that render (as `render` words it, [`beyond_this_device`]); any other
/// failure of the GPU fails the bench.
fn refusal(settings: &RenderSettings, error: TrialError<GpuError>) -> Result<String, CliError> {
    match error {
        TrialError::Tolerance(why) => Ok(why),
        TrialError::Render(GpuError::LoopBudget(why)) => Ok(beyond_this_device(settings, &why)),
        TrialError::Render(e) => Err(e.into()),
    }
}

/// The Markdown table of one scene's rows (`in_penumbrae`: the promise held in penumbrae too, `render`'s default;
/// `smaller`: the table's size where it is not the sweep's, and how long its own truth took [s]).
pub(super) fn tolerance_table(
    name: &str,
    table: &ToleranceTable,
    in_penumbrae: bool,
    smaller: Option<((u32, u32), f64)>,
) -> String {
    let flags = if in_penumbrae {
        "render --tolerance T --tolerance-in-penumbrae"
    } else {
        "render --tolerance T --tolerance-outside-penumbrae"
    };
    let truth = match smaller {
        Some(((w, h), seconds)) => format!(
            "at {w}×{h}, against the converged reference at that size ({seconds:.1} s): the device has no ray \
             queries, so its shadow rays walk the BVH in the fragment shader"
        ),
        None => "the same truth".into(),
    };
    let penumbrae = match table.penumbra_pixels {
        Some((n, covered)) => format!(", {n} of its {covered} covered pixels"),
        None => String::new(),
    };
    let mut out = format!(
        "`{flags}` on {name} ({truth}; GPU time: the sum of the median warm frames of every render it made, or \
         its one frame where the pixels without a bound were refined on the reference, whose time is the next \
         column; max rel over every pixel the truth converged on, penumbrae included, and outside the penumbrae \
         (where a light is partly hidden{penumbrae}): what `--tolerance-outside-penumbrae` promises; † where the \
         prediction names part of the image as not bounded, the penumbrae):\n\n| T | models chosen | renders | GPU \
         time [ms] | reference [ms] | max rel | max rel outside penumbrae | predicted |\n\
         |---:|---|---:|---:|---:|---:|---:|---:|\n"
    );
    for r in &table.rows {
        out += &match &r.outcome {
            Ok(k) => format!(
                "| {:.0e} | {} | {} | {:.2} | {:.2} | {:.2e} | {:.2e} | {:.1e}{} |\n",
                r.tolerance,
                k.models,
                k.renders,
                k.gpu_ms,
                k.reference_ms,
                k.max_rel,
                k.max_rel_outside_penumbrae,
                k.predicted.0,
                if k.predicted.1 { "†" } else { "" }
            ),
            Err(why) => {
                format!("| {:.0e} | refused: {} | 0 | — | — | — | — | — |\n", r.tolerance, why.replace('|', "/"))
            }
        };
    }
    out + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::light::Lights;
    use crate::scene::{Camera, Projection};
    use glam::DVec3;

    /// The loop limiter's refusal becomes a row naming the render that met it; other failures of the GPU fail the
    /// bench instead of hiding in a row.
    #[test]
    fn a_render_the_loop_limiter_cut_short_is_a_refused_row() {
        let camera = Camera::looking(
            DVec3::ZERO,
            -DVec3::Z,
            DVec3::Y,
            Projection::Orthographic { ymag: 1.0, znear: 0.1, zfar: 10.0 },
        )
        .unwrap();
        let mut settings = RenderSettings::new(8, 8, camera, Lights::default());
        settings.shading.samples_per_axis = 27;
        settings.shading.shadow_samples_per_axis = 13;
        let why = "llvmpipe cut the loops of 41 pixel(s) short".to_string();
        let row = refusal(&settings, TrialError::Render(GpuError::LoopBudget(why))).unwrap();
        assert!(row.contains("27² lobe grids") && row.contains("13² shadow rays"), "{row}");
        assert!(row.contains("beyond this device: llvmpipe cut the loops of 41 pixel(s) short"), "{row}");
        assert_eq!(refusal(&settings, TrialError::Tolerance("no bound".into())).unwrap(), "no bound");
        let failed = refusal(&settings, TrialError::Render(GpuError::Validation(vec!["VUID".into()])));
        assert!(failed.is_err(), "a validation message fails the bench");

        let table = ToleranceTable {
            rows: vec![ToleranceRow { tolerance: 1e-3, outcome: Err(format!("a | b {row}")) }],
            penumbra_pixels: None,
        };
        let text = tolerance_table("overcast.glb", &table, true, None);
        let line = text.lines().find(|l| l.starts_with("| 1e-3 |")).expect("the refused row");
        assert!(
            line.contains("refused: a / b a render it needs") && line.ends_with("| 0 | — | — | — | — | — |"),
            "{line}"
        );
    }

    #[test]
    fn only_a_scene_that_shadows_itself_without_ray_queries_gets_a_smaller_table() {
        assert_eq!(table_size((256, 256), false, true), (64, 64));
        assert_eq!(table_size((256, 192), false, true), (64, 48));
        assert_eq!(table_size((1000, 3), false, true), (64, 1), "at least one pixel a side");
        assert_eq!(table_size((256, 256), true, true), (256, 256), "ray queries: the sweep's size");
        assert_eq!(table_size((256, 256), false, false), (256, 256), "nothing to shadow");
        assert_eq!(table_size((48, 36), false, true), (48, 36), "already small");
    }
}

//! `--tolerance-by-study` where no bound is derived for the GPU's part: the grids studied on the reference, the GPU's
//! distance from the reference's f64 image measured and added to the prediction, the pixels too far taken from it.
//! (Without the flag those pixels are refined on the reference one by one: `refined_pixels`.)

use super::RenderError;
use crate::accuracy::predicted::Prediction;
use crate::accuracy::trial::Tolerance;
use crate::cpu::{self, ReferenceOptions};
use crate::film::Image;
use crate::settings::RenderSettings;
use crate::shading::Shadows;

/// `--tolerance` where the GPU slices the lights in their penumbrae (the sky through occluders, or every light with the
/// promise held in penumbrae, `--tolerance`'s default): the grids are studied on the reference, the same rule in f64
/// (`accuracy::trial::reference_within_tolerance`, `settings` updated to the models it keeps; the promise there holds
/// in penumbrae too), then the GPU renders once with them (`render`), and the distance of its image from the
/// reference's at those settings (the GPU's f32: shading, interpolation, the slices' geometry) is measured and added to
/// the prediction, the pixels it leaves too far taken from the reference's image (`measured_against_the_reference`):
/// the image is within the sum of the truth. A study's rungs cost the GPU far more than the reference: the sky's
/// passes some 40 ms a row at 64 × 48 on lavapipe (`gpu::slice_passes`; on overcast.glb at 64 × 48 and 1e-3 a study
/// on the GPU took 6 min and kept 27², its order capped at 1, the reference's takes 4 s and keeps 19²); a disk
/// light's rows in passes where the frame runs out of the loop budget (room.gltf at 64², 1e-4: 7 min on the GPU, kept
/// 39²). `(asked, can_occlude)`: the shadows asked for, and whether the scene can shadow itself. The image, its
/// prediction, the reference's image it was measured against, and the GPU's own image where some of its pixels were
/// taken from the reference's.
pub(super) fn studied_on_the_reference(
    scene: &crate::scene::Scene,
    settings: &mut RenderSettings,
    reference: &ReferenceOptions,
    (asked, can_occlude): (Shadows, bool),
    tolerance: Tolerance,
    render: impl FnOnce(&RenderSettings) -> Result<Image, RenderError>,
) -> Result<(Image, Prediction, Option<Image>, Option<Image>), RenderError> {
    let (studied, mut prediction) = crate::accuracy::trial::reference_within_tolerance(
        scene,
        settings,
        reference,
        asked,
        can_occlude,
        Some(tolerance),
    )
    .map_err(RenderError::Usage)?;
    let mut image = render(settings)?;
    let what = "the GPU against the reference at the kept settings (measured; studied on the reference)";
    let device_image =
        measured_against_the_reference(&mut image, &studied, what, tolerance.max_relative, &mut prediction, |sum| {
            format!(
                "the study's own terms come to {sum:.1e}, leaving nothing for the GPU's f32 shading, interpolation \
                 and slices; `sunshade reference` with the same scene flags has no f32"
            )
        })?;
    Ok((image, prediction, Some(studied), device_image))
}

/// The GPU's `image` against the reference's f64 image at the same settings (`f64_image`): their distance added to
/// the prediction as the term `what`, measured where no bound is derived. Where the sum would exceed `tolerance`,
/// the pixels further from `f64_image` than the rest of the prediction leaves are taken from it
/// (`accuracy::from_reference`; the term names how many), and the GPU's own image is returned; `tolerance` is
/// refused by name only where the rest alone reaches it (`refusal(rest)` says why).
fn measured_against_the_reference(
    image: &mut Image,
    f64_image: &Image,
    what: &str,
    tolerance: f64,
    prediction: &mut Prediction,
    refusal: impl FnOnce(f64) -> String,
) -> Result<Option<Image>, RenderError> {
    use crate::accuracy::{from_reference::take_from_reference, refinement::max_difference};
    let rest = prediction.max_relative;
    let apart = max_difference(image, f64_image);
    if rest + apart <= tolerance {
        prediction.add_term(&format!("{what}:"), apart);
        return Ok(None);
    }
    if rest >= tolerance {
        return Err(RenderError::Usage(format!("--tolerance {tolerance:e}: {}", refusal(rest))));
    }
    // The pixels' budget, 1% short of what the rest leaves, so that the sum's rounding cannot tip it past T.
    let budget = 0.99 * (tolerance - rest);
    let device_image = image.clone();
    let taken = take_from_reference(image, f64_image, budget);
    let term = format!("{what}, {taken} pixel(s) further than {budget:.1e} taken from the reference's f64 image:");
    prediction.add_term(&term, max_difference(image, f64_image));
    Ok(Some(device_image))
}

/// What f32 geometry costs the GPU's slices where `--tolerance` holds in penumbrae: a point millimetres to
/// centimetres from an occluder sees its edges' crossings through corners relative to it rounded by an f32 ulp of
/// the scene's coordinates (1e-7 m at 1 m), about 1e-4 of the sun's chord at a centimetre (cube.glb at 64²,
/// `--tolerance 1e-4`: 1.5e-4 against the converged reference). No bound is derived for it, so it is measured: the
/// kept image against the reference's f64 slices at the same settings (mirroring the device), added to the
/// prediction as a term, the pixels too far taken from the reference's image (`measured_against_the_reference`).
/// The reference's image, and the GPU's own where pixels were taken.
pub(super) fn slices_measured_against_the_reference(
    image: &mut Image,
    scene: &crate::scene::Scene,
    settings: &RenderSettings,
    reference: &ReferenceOptions,
    tolerance: f64,
    prediction: &mut Prediction,
) -> Result<(Option<Image>, Option<Image>), RenderError> {
    if settings.shading.visibility_rule != crate::shading::VisibilityRule::Slices
        || settings.shading.shadows != Shadows::Ray
    {
        return Ok((None, None));
    }
    let f64_slices = cpu::render(scene, settings, reference);
    let what = "GPU f32 slices (measured against the reference's)";
    let device_image = measured_against_the_reference(image, &f64_slices, what, tolerance, prediction, |sum| {
        format!(
            "the other terms come to {sum:.1e}, leaving nothing for the GPU's slices' f32 geometry; `sunshade \
             reference` with the same scene flags has no f32 geometry"
        )
    })?;
    Ok((Some(f64_slices), device_image))
}

/// Why `--tolerance` stopped at a render the device's loop limiter refused (`why`): `settings` holds that render's
/// grids, the finest of any material's (the models chosen, or the next rung where it studies its grids).
pub fn beyond_this_device(settings: &RenderSettings, why: &str) -> String {
    format!(
        "a render it needs (at most {}² lobe grids, {}² sun samples, {}² shadow rays; the next rung where it studies \
         its grids) is beyond this device: {why}",
        settings.shading.samples_per_axis,
        settings.shading.sun_samples_per_axis,
        settings.shading.shadow_samples_per_axis
    )
}

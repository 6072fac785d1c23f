//! `--tolerance`'s study of the lobe grids material by material: where several specular materials share an image
//! under disk lights or the sky, each keeps the coarsest rung of the ladder whose estimate meets the tolerance on
//! its own pixels, instead of every material taking the rung the hardest one needs.
//!
//! A pixel's lobe integrals are those of the material it sees: its value moves with that material's grids only.
//! So each material's pixels are measured on their own ([`super::refinement::max_difference_where`], the diff's
//! floor still the whole image's), each with its own ladder ([`Ladder::push_where`]), and a material whose
//! estimate meets the budget stays on its rung while the others go on refining; the image kept is the last rung,
//! every material on its own grid (`RenderSettings::lobes_per_material`), and its estimate is the largest of the
//! materials' (each pixel is one material's). Pixels that see no specular material (Lambertian surfaces, which
//! the lobe grids do not touch) and any the reference's rasterization does not assign are measured with every
//! material, so that nothing moves unmeasured. The rungs after the first material settles are cheaper, and so is
//! the image kept.

use super::predicted::{predict_with_peak, Request};
use super::promise::{TrialError, WithinTolerance};
use super::refinement::{ladder, Ladder, LobeEstimate};
use crate::compare::image_peak;
use crate::cpu::{self, ReferenceOptions};
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::SunModel;

/// One specular material's pixels (with those no specular material owns), by the reference's rasterization.
pub struct MaterialPixels {
    pub material: usize,
    pub mask: Vec<bool>,
}

/// The specular materials the image shows and each one's pixels; fewer than two: one study for the image does the
/// same work.
pub fn specular_materials(
    scene: &Scene,
    settings: &RenderSettings,
    reference: &ReferenceOptions,
) -> Vec<MaterialPixels> {
    let map = cpu::material_map(scene, settings, reference);
    let specular = |m: &Option<usize>| m.filter(|&m| scene.materials.get(m).is_some_and(|m| !m.brdf.is_lambert()));
    let mut materials: Vec<usize> = map.iter().filter_map(specular).collect();
    materials.sort_unstable();
    materials.dedup();
    materials
        .into_iter()
        .map(|material| MaterialPixels {
            material,
            mask: map.iter().map(|m| specular(m).is_none_or(|s| s == material)).collect(),
        })
        .collect()
}

/// One material's study: its pixels, its ladder, and its estimate once it met the budget.
struct Study {
    pixels: MaterialPixels,
    ladder: Ladder,
    settled: Option<LobeEstimate>,
}

/// The lobe grids' study per material (module text) for `tolerance`, of which the sun's bound and the arithmetic
/// leave `budget`; `settings` ends with the grids of the image kept (`lobes_per_material`, the finest of
/// them as the render's `samples_per_axis`). `Err`: the materials the ladder's finest grid did not settle, with
/// their last estimates.
pub fn study_per_material<T, E>(
    request: Request,
    settings: &mut RenderSettings,
    (tolerance, budget): (f64, f64),
    materials: Vec<MaterialPixels>,
    mut render: impl FnMut(&RenderSettings) -> Result<T, E>,
    image_of: impl Fn(&T) -> &Image,
) -> Result<WithinTolerance<T>, TrialError<E>> {
    let Request { scene, renderer, .. } = request;
    let mut studies: Vec<Study> = materials
        .into_iter()
        .map(|pixels| Study { pixels, ladder: Ladder::new(renderer.arithmetic(), false, false), settled: None })
        .collect();
    settings.lobes_per_material = vec![None; scene.materials.len()];
    let mut previous: Option<T> = None;
    for k in ladder() {
        for s in studies.iter().filter(|s| s.settled.is_none()) {
            settings.lobes_per_material[s.pixels.material] = Some(k);
        }
        settings.shading.samples_per_axis = settings.lobes_per_material.iter().flatten().copied().max().unwrap_or(k);
        let image = render(settings).map_err(TrialError::Render)?;
        for s in studies.iter_mut().filter(|s| s.settled.is_none()) {
            s.ladder.push_where(k, previous.as_ref().map(&image_of), image_of(&image), Some(&s.pixels.mask));
            s.settled = s.ladder.estimate().filter(|e| e.gci <= budget);
        }
        previous = Some(image);
        if studies.iter().all(|s| s.settled.is_some()) {
            let kept = previous.take().expect("rendered");
            let estimates: Vec<(usize, LobeEstimate)> =
                studies.iter().filter_map(|s| s.settled.map(|e| (s.pixels.material, e))).collect();
            let worst = estimates.iter().map(|(_, e)| *e).max_by(|a, b| a.gci.total_cmp(&b.gci)).expect("a material");
            let peak = (settings.shading.sun == SunModel::Delta).then(|| image_peak(image_of(&kept)));
            let mut prediction =
                predict_with_peak(scene, settings, renderer, request.can_occlude(), peak, Some(&worst));
            // Each material's estimate where the worst one's term stood (the worst is what the total adds).
            let at = match prediction.terms.iter().position(|(t, _)| *t == worst.term()) {
                Some(at) => {
                    prediction.terms.remove(at);
                    at
                }
                None => prediction.terms.len(),
            };
            for (i, (m, e)) in estimates.iter().enumerate() {
                prediction.terms.insert(at + i, (e.term_for(&scene.materials[*m].name), e.gci));
            }
            return Ok(WithinTolerance { kept, prediction });
        }
    }
    let unsettled: Vec<String> = studies
        .iter()
        .filter(|s| s.settled.is_none())
        .map(|s| {
            let last = match s.ladder.estimate() {
                Some(e) => format!("estimated {:.1e}", e.gci),
                None => "differences that do not shrink like a converging grid's".into(),
            };
            format!("{}: {last}", scene.materials[s.pixels.material].name)
        })
        .collect();
    Err(TrialError::Tolerance(format!(
        "--tolerance {tolerance:e}: the lobe grids estimated by refinement did not meet the {budget:.1e} that the \
         sun's bound and the arithmetic leave by {}² ({}; docs/accuracy.md, \"Error bounds\")",
        settings.shading.samples_per_axis,
        unsettled.join("; ")
    )))
}

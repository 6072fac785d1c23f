//! The converged reference: the CPU reference with its sampled integrals refined until they stop moving.
//!
//! The reference evaluates every irradiance in closed form (sun disk, disk lights, sky) but integrates three
//! things by deterministic midpoint grids: specular lobes over the sun's disk (`sun_samples²` directions), lobes
//! over disk lights and the sky (`samples²`), and each light's visible fraction (`shadow_samples²` rays). The
//! converged image uses the exact light models (disk sun, exact disks) and refines all three grids together,
//! each refinement at least doubling every sample count (`n → ⌈n·√2⌉` per axis), until two doublings in a row
//! change a pixel by less than a tenth of the accuracy claimed:
//!
//! `|L_k+1 − L_k| / max(|L_k+1|, |L_k|, floor) < accuracy / 10` for every channel, at k and k + 1,
//!
//! with the floor of `sunshade diff` (1% of the image's peak), below which relative differences measure rounding,
//! not rendering. A midpoint grid converges as O(n⁻²) on a smooth integrand, so once a doubling moves a pixel by
//! less than a tenth of the claim, the remaining error of the finer image is below the claim by the same margin.
//! Two passes, not one: where the integrand has a jump (a shadow edge, or the horizon crossing a lobe or the sun's
//! disk) the grid's error is not monotone in n, and two grids can agree by chance (measured: a Blinn-Phong sphere
//! under a 5° sun, one pass accepted a pixel that the next doubling moved by 1.1e-3, over a 1e-3 claim;
//! `tests/accuracy.rs` checks the claim by one more doubling). Such pixels converge as O(n⁻¹) or slower; the
//! refinement stops after [`ConvergenceOptions::max_refinements`] and reports those still moving, with their last
//! change, instead of hiding them.
//!
//! **The final check.** Two doublings can also agree exactly: where every ray of both grids misses an occluder
//! that a finer grid meets (overcast.glb at 48 × 36, a 1e-3 claim: one pixel identical on every grid from 8² to
//! 51² shadow rays and lobe samples, 5.5% darker from 73² on). So a pixel that stopped before the last doubling
//! is rendered once more with the finest grids any pixel reached, and reported (with that change, keeping the
//! finer value) where that moves it by a tenth of the claim or more. It narrows the chance, it cannot close it: an
//! occluder that every grid misses stays unseen.
//!
//! Texture filtering is not refined: a pixel's radiance is defined at its centre, and the reference filters a
//! texture over the pixel's footprint by the same deterministic rule as the GPU (`shading::texture_filter`); that
//! rule defines the image rather than approximating an integral that a finer grid would resolve. Interpolation is
//! in f64 throughout the reference.

use crate::accuracy::refinement::next_grid;
use crate::compare::{default_floor, pixel_difference};
use crate::cpu::{Frame, ReferenceOptions};
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::visibility::slice_rows;
use crate::shading::{DiskModel, ShadingOptions, SunModel};

/// The accuracy claimed by default: 1e-4 relative (with the diff's floor).
pub const DEFAULT_ACCURACY: f64 = 1e-4;
/// Refinements at most by default: six doublings, 64× the starting rays.
pub const DEFAULT_MAX_REFINEMENTS: u32 = 6;

/// How far the refinement goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConvergenceOptions {
    /// The accuracy claimed (relative, with the diff's floor): a doubling must change every pixel by less than a
    /// tenth of it.
    pub accuracy: f64,
    /// Doublings at most.
    pub max_refinements: u32,
}

impl Default for ConvergenceOptions {
    fn default() -> Self {
        Self { accuracy: DEFAULT_ACCURACY, max_refinements: DEFAULT_MAX_REFINEMENTS }
    }
}

/// A pixel that has not converged, and how much its last doubling changed it (relative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unconverged {
    pub x: u32,
    pub y: u32,
    pub change: f64,
}

/// The converged image and how it got there.
#[derive(Clone, Debug)]
pub struct Converged {
    /// The finest image rendered.
    pub image: Image,
    /// Its shading options (exact light models, the final sample counts).
    pub shading: ShadingOptions,
    /// The accuracy claimed.
    pub accuracy: f64,
    /// Doublings done.
    pub refinements: u32,
    /// The largest relative change of the last doubling, over the pixels it refined.
    pub last_change: f64,
    /// The pixels that have not passed two doublings in a row, largest last change first: empty when converged.
    pub unconverged: Vec<Unconverged>,
    /// Covered pixels.
    pub covered: usize,
}

impl Converged {
    /// Whether every pixel met the refinement criterion.
    pub fn converged(&self) -> bool {
        self.unconverged.is_empty()
    }

    /// One flag a pixel (row-major): whether it has not converged, for leaving it out of an error measured against
    /// this image.
    pub fn unconverged_mask(&self) -> Vec<bool> {
        let mut mask = vec![false; self.image.pixels().len()];
        for u in &self.unconverged {
            mask[(u.y * self.image.width() + u.x) as usize] = true;
        }
        mask
    }

    /// The sample counts reached: "sun 12², lobes 23², shadow rays 12²".
    pub fn summary_counts(&self) -> String {
        let s = &self.shading;
        format!(
            "{} doublings to sun {}², lobes {}², shadow rays {}²",
            self.refinements, s.sun_samples_per_axis, s.samples_per_axis, s.shadow_samples_per_axis
        )
    }

    /// One line: the sample counts reached and the pixels that did not converge.
    pub fn summary(&self) -> String {
        let s = &self.shading;
        let counts = format!(
            "sun {}², lobes {}², shadow rays {}²",
            s.sun_samples_per_axis, s.samples_per_axis, s.shadow_samples_per_axis
        );
        if let Some(worst) = self.unconverged.first() {
            format!(
                "not converged to {:.0e} after {} doublings ({counts}): {} of {} covered pixels changed by {:.0e} or \
                 more on the last doubling or the final check (largest {:.2e} at {},{})",
                self.accuracy,
                self.refinements,
                self.unconverged.len(),
                self.covered,
                self.accuracy / 10.0,
                worst.change,
                worst.x,
                worst.y
            )
        } else {
            format!(
                "converged to {:.0e} after {} doublings ({counts}): the last changed no pixel by more than {:.2e}",
                self.accuracy, self.refinements, self.last_change
            )
        }
    }
}

/// The module text's final check: the pixels that stopped early (`early`, those that stopped before the last
/// doubling) rendered with the finest grids (`finest`), each kept at that value; those it moved by `threshold` or
/// more (a NaN or an infinity included), with their change.
fn final_check(
    frame: &Frame,
    finest: &RenderSettings,
    image: &mut Image,
    early: &[bool],
    floor: f64,
    threshold: f64,
) -> Vec<Unconverged> {
    if !early.contains(&true) {
        return Vec::new();
    }
    let finer = frame.render_selected(finest, Some(early));
    let width = image.width();
    let mut moved = Vec::new();
    for (i, _) in early.iter().enumerate().filter(|(_, &e)| e) {
        let (old, new) = (image.pixels()[i], finer.pixels()[i]);
        let change = pixel_difference(old, new, floor).rel;
        image.pixels_mut()[i] = new;
        if change >= threshold || !change.is_finite() {
            moved.push(Unconverged { x: i as u32 % width, y: i as u32 / width, change });
        }
    }
    moved
}

/// The coarsest shadow grid `k` (at least 2) from which a refinement by slices that stops after two doublings
/// (`Criterion::TOLERANCE`) has taken the lights' visible fractions with `R = 4k₂²` rows at its second doubling
/// `k₂`, `R ≥ 2/tolerance`: the start of `--tolerance`'s refined pixels where it is coarser than the render's.
///
/// Why `2/R`: the rows cut the light along one angle ψ and are exact along the other, so an occluder is missed by
/// every row only where it lies wholly between two neighbours. The sun's and disk lights' rows run at
/// `ψ = −σ cos u` for midpoints `u` spaced `π/R` (`sun_slices`), so two neighbours lie at most `σπ/R` apart, and
/// the band between them, at most `2σ` long, holds at most `2πσ²/R` of the disk's `πσ²`: `2/R` of its area
/// (the sky's rows, `2π/R` apart about their axis, bound a lune of `4π/R` sr, `2/R` of a hemisphere). Two doublings
/// that agree are the refinement's estimate (`refine`); this keeps what no row of the last grid can see below the
/// tolerance too, as a share of the light's area (a share of its weight where that varies little across it).
pub fn slices_start(tolerance: f64) -> u32 {
    let rows_wanted = 2.0 / tolerance;
    let mut k = 2;
    while (slice_rows(next_grid(next_grid(k))) as f64) < rows_wanted && k < 1024 {
        k += 1;
    }
    k
}

/// The sample counts of one refinement: every count at least doubled, `n → ⌈n·√2⌉` per axis.
pub fn doubled(shading: &ShadingOptions) -> ShadingOptions {
    let up = next_grid;
    ShadingOptions {
        sun_samples_per_axis: up(shading.sun_samples_per_axis),
        samples_per_axis: up(shading.samples_per_axis),
        shadow_samples_per_axis: up(shading.shadow_samples_per_axis),
        ..*shading
    }
}

/// Renders `scene` on the CPU with exact light models, refining the sample grids from those of `settings` until
/// converged or `options.max_refinements` doublings (see the module's text). The starting grids render the whole
/// image; then each pixel takes its doublings in turn until it has passed two (`cpu::Frame::refine_pixels`), so
/// that the cost follows the pixels that need it. Each pixel keeps the value of the finest render it got. Shadows are as
/// `settings` asks (the reference casts rays for every technique but `none`).
pub fn render_converged(
    scene: &Scene,
    settings: &RenderSettings,
    reference: &ReferenceOptions,
    options: &ConvergenceOptions,
) -> Converged {
    let s = with_exact_models(settings);
    let frame = Frame::new(scene, &s, reference);
    let image = frame.render_selected(&s, None);
    // The floor of `sunshade diff`, from the starting image's peak (refinement moves the peak by far less than
    // the 1% the floor is of it).
    let floor = default_floor(&image);
    let moving: Vec<bool> = image.pixels().iter().map(|p| p[3] > 0.0).collect();
    refine(&frame, s, (options, Criterion::TRUTH), (image, moving), floor)
}

/// When a pixel counts as converged: two doublings in a row each changed it by less than `change_fraction` of the
/// accuracy claimed, and, with `final_check`, the pixels that stopped before the last doubling rendered once more
/// with the finest grids any pixel reached (the module's text).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Criterion {
    pub change_fraction: f64,
    pub final_check: bool,
}

impl Criterion {
    /// The converged reference's, the truth images are measured against: a tenth, and the final check.
    pub const TRUTH: Self = Self { change_fraction: 0.1, final_check: true };
    /// `--tolerance`'s for the pixels no bound covers: a third, no final check. Roache's grid convergence index for
    /// two grids, with his factor of safety 3 for an order not confirmed, at the first order in the samples that
    /// the slowest of the grids shows through a penumbra (a doubling halves the error): the finer image errs by
    /// about the change, so a change under T/3 leaves T for the error three times over; the second doubling
    /// guards against two grids agreeing by chance. The final check (the finest grids of any pixel, far past what
    /// most pixels need) would cost more than the rest together.
    pub const TOLERANCE: Self = Self { change_fraction: 1.0 / 3.0, final_check: false };
}

/// `settings` with the exact light models the converged reference refines: the disk sun for every material, exact
/// disk lights.
pub fn with_exact_models(settings: &RenderSettings) -> RenderSettings {
    let mut s = settings.clone();
    s.shading.sun = SunModel::Disk;
    s.shading.disk = DiskModel::Exact;
    s
}

/// The refinement of [`render_converged`] for the pixels flagged in `moving` alone: `image` holds their values at
/// the grids of `s` (exact light models, [`with_exact_models`]) in `frame`'s view, the other pixels whatever the
/// caller put there (left as they are); `floor` is the diff's floor of the image they belong to \[W/(m²·sr)\].
/// `--tolerance` refines this way the pixels no bound covers.
pub fn refine(
    frame: &Frame,
    mut s: RenderSettings,
    (options, criterion): (&ConvergenceOptions, Criterion),
    (mut image, moving): (Image, Vec<bool>),
    floor: f64,
) -> Converged {
    let threshold = options.accuracy * criterion.change_fraction;
    let mut result = Converged {
        covered: image.covered_count(),
        image: Image::new(1, 1),
        shading: s.shading,
        accuracy: options.accuracy,
        refinements: 0,
        last_change: 0.0,
        unconverged: Vec::new(),
    };
    let width = image.width();
    // Each pixel's doublings in turn, on one thread (`cpu::Frame::refine_pixels`): it is done after two in a row
    // pass (see the module's text). The grids of doubling k are `levels[k - 1]`.
    let max = options.max_refinements.max(1);
    let levels: Vec<RenderSettings> = (0..max)
        .scan(s.shading, |shading, _| {
            *shading = doubled(shading);
            Some(RenderSettings { shading: *shading, ..s.clone() })
        })
        .collect();
    let pixels: Vec<usize> = (0..moving.len()).filter(|&i| moving[i]).collect();
    let start = &image;
    // Per pixel: its last value, the doubling it reached, that doubling's change, and whether it converged.
    let outcomes = frame.refine_pixels(&levels, &pixels, |i, shade| {
        let (mut value, mut passes) = (start.pixels()[i], 0u8);
        for k in 1..=max {
            let finer = shade(k as usize - 1);
            // The relative change as `sunshade diff` measures it (a NaN or an infinity never converges).
            let change = pixel_difference(value, finer, floor).rel;
            value = finer;
            passes = if change < threshold { passes + 1 } else { 0 };
            if passes >= 2 || k == max {
                return (value, k, change, passes >= 2);
            }
        }
        unreachable!("the last doubling returns")
    });
    result.refinements = outcomes.iter().map(|o| o.1).max().unwrap_or(1);
    s = levels[result.refinements as usize - 1].clone();
    // The doubling after which each covered pixel stopped (0 while it moves).
    let mut stopped_at = vec![0u32; moving.len()];
    for (&i, &(value, k, change, converged)) in pixels.iter().zip(&outcomes) {
        image.pixels_mut()[i] = value;
        if k == result.refinements {
            result.last_change = result.last_change.max(change);
        }
        if converged {
            stopped_at[i] = k;
        } else {
            result.unconverged.push(Unconverged { x: i as u32 % width, y: i as u32 / width, change });
        }
    }
    if criterion.final_check {
        let early: Vec<bool> = stopped_at.iter().map(|&k| k > 0 && k < result.refinements).collect();
        result.unconverged.extend(final_check(frame, &s, &mut image, &early, floor, threshold));
    }
    result.unconverged.sort_by(|a, b| b.change.total_cmp(&a.change));
    result.image = image;
    result.shading = s.shading;
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_start_is_the_coarsest_grid_whose_second_doubling_has_two_rows_per_tolerance() {
        for t in [0.5, 1e-1, 3e-2, 1e-2, 1e-3, 1e-4] {
            let k = slices_start(t);
            let rows_at = |k| slice_rows(next_grid(next_grid(k))) as f64;
            assert!(rows_at(k) * t >= 2.0, "{t}: k = {k}, {} rows", rows_at(k));
            assert!(k == 2 || rows_at(k - 1) * t < 2.0, "{t}: k = {k} is not the coarsest");
        }
        // 1e-2 starts at 3² (36, 100 and 256 rows); 1e-3 at 11² (the render's 6² is then the coarser).
        assert_eq!((slices_start(1e-2), slices_start(1e-3)), (3, 11));
    }
}

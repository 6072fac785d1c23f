//! Where an image's shadows are soft: the pixels in a penumbra, as the reference's shadow rays see it.
//!
//! `--tolerance` with `--tolerance-outside-penumbrae` promises its T outside the penumbrae (where a light is partly
//! hidden, its visible fraction is a grid's count and has no bound), so a measurement of that promise needs those
//! pixels named. A pixel is in a penumbra where some light is neither wholly visible nor wholly hidden from
//! it; there, and only there, the light's visible fraction from one ray to its centre (a hard shadow: 0 or 1)
//! differs from the fraction over the light (the sun's disk, a disk light's, the sky's lune). So the mask is the pixels where the reference with one shadow ray a
//! light and the reference with the given grid of them differ at all, every other sample grid the same: outside a
//! penumbra both renders run the same arithmetic on a fraction of exactly 0 or 1, and agree to the bit.
//!
//! What it cannot see is what the grid cannot: an occluder that every ray of the grid misses. The callers take
//! the finest shadow grid the converged reference reached, which the truth's own pixels were judged by.

use super::converged::Converged;
use crate::cpu::{self, ReferenceOptions};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::Shadows;

/// The pixels (row-major, as the image's) in a penumbra of any light under `settings`' shadow rays (module
/// text); all `false` where `settings` casts no shadow rays.
pub fn penumbra_mask(scene: &Scene, settings: &RenderSettings, reference: &ReferenceOptions) -> Vec<bool> {
    let pixels = (settings.width * settings.height) as usize;
    if settings.shading.shadows != Shadows::Ray {
        return vec![false; pixels];
    }
    let soft = cpu::render(scene, settings, reference);
    let mut hard_settings = settings.clone();
    hard_settings.shading.shadow_samples_per_axis = 1;
    let hard = cpu::render(scene, &hard_settings, reference);
    soft.pixels().iter().zip(hard.pixels()).map(|(s, h)| s[..3] != h[..3]).collect()
}

/// The pixels a measurement of `--tolerance`'s promise outside the penumbrae leaves out, against `truth`, the
/// converged reference of `settings`: those the truth did not converge on, and those in a penumbra under the
/// finest shadow rays the truth reached; with how many of the truth's covered pixels are in a penumbra.
pub fn outside_penumbrae_excluded(
    scene: &Scene,
    settings: &RenderSettings,
    truth: &Converged,
    reference: &ReferenceOptions,
) -> (Vec<bool>, usize) {
    let mut finest = settings.clone();
    finest.shading.shadow_samples_per_axis = truth.shading.shadow_samples_per_axis;
    let penumbrae = penumbra_mask(scene, &finest, reference);
    let covered_in_penumbrae =
        truth.image.pixels().iter().zip(&penumbrae).filter(|(pixel, &p)| p && pixel[3] > 0.0).count();
    let excluded = truth.unconverged_mask().into_iter().zip(penumbrae).map(|(u, p)| u || p).collect();
    (excluded, covered_in_penumbrae)
}

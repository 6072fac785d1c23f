//! The reference as a check compares with it (`render --check`, `sunshade::testing`): the image, and the class of
//! pixels the comparison counts apart, because there the two renderers may differ by what they compute rather
//! than by error: a shadow map's edges (`--shadows map`: the map's own error, not capped), or the fragile pixels of
//! shadow rays, textures and alpha masks (f32 geometry or texture coordinates may decide a grazing ray or a
//! lookup at a discontinuity the other way: a few, capped at [`super::FRAGILE_ALLOWED_FRACTION`] of the compared
//! pixels).

use super::{map_edges, render, render_with_fragile_pixels, render_with_map_edges, shadow_choice, ReferenceOptions};
use super::{FRAGILE_ALLOWED_FRACTION, FRAGILE_CLASS};
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::Shadows;

/// Pixels a comparison counts apart: a row-major mask, the class's name, and the most of them that may be over
/// tolerance as a fraction of the compared pixels (`None`: any number).
#[derive(Clone, Debug, PartialEq)]
pub struct ApartClass {
    pub mask: Vec<bool>,
    pub name: &'static str,
    pub allowed_fraction: Option<f64>,
}

/// Whether a render of `scene` with `settings` may have fragile pixels: shadow rays, textures or alpha masks.
pub fn may_be_fragile(scene: &Scene, settings: &RenderSettings) -> bool {
    shadow_choice(scene, settings).technique == Shadows::Ray || !scene.textures.is_empty() || scene.has_alpha_masks()
}

/// The reference of a render with `settings` and the class its comparison counts apart (see the module docs).
pub fn checked_reference(
    scene: &Scene,
    settings: &RenderSettings,
    options: &ReferenceOptions,
) -> (Image, Option<ApartClass>) {
    if shadow_choice(scene, settings).technique == Shadows::Map {
        let (image, mask) = render_with_map_edges(scene, settings, options);
        return (image, Some(ApartClass { mask, name: map_edges::CLASS, allowed_fraction: None }));
    }
    if may_be_fragile(scene, settings) {
        let (image, mask) = render_with_fragile_pixels(scene, settings, options);
        let class = ApartClass { mask, name: FRAGILE_CLASS, allowed_fraction: Some(FRAGILE_ALLOWED_FRACTION) };
        return (image, Some(class));
    }
    (render(scene, settings, options), None)
}

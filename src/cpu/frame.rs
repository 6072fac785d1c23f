//! One view that the reference shades many times: the converged reference's doublings and `--tolerance`'s refined
//! pixels render the same camera and size over and over with finer sample grids. Rasterization and visibility do
//! not depend on the grids, nor does the occluders' BVH (tens of milliseconds for a scene of tens of thousands of
//! triangles), so a [`Frame`] computes each once and every render of it only shades. Its images are
//! [`render`](super::render)'s and [`render_selected`](super::render_selected)'s, bit for bit.

use std::sync::OnceLock;

use rayon::prelude::*;

use super::{
    occluders_for, plain_shader, rasterize, shade_covered, shade_rasterized, stored, Occluders, Rasterized,
    ReferenceOptions,
};
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::slice_buckets::with_pixel_cache;

/// A view of `scene` rasterized once, its occluders built on the first render that casts shadow rays.
pub struct Frame<'a> {
    scene: &'a Scene,
    /// The view it was rasterized for: size and clip-from-world (what rasterization reads of the settings).
    view: (u32, u32, glam::Mat4),
    rasterized: Rasterized,
    occluders: OnceLock<Occluders<'a>>,
}

impl<'a> Frame<'a> {
    /// Rasterizes `scene` in the view of `settings` (its camera and size; the shading options do not matter here).
    pub fn new(scene: &'a Scene, settings: &RenderSettings, options: &ReferenceOptions) -> Self {
        Self {
            scene,
            view: (settings.width, settings.height, settings.clip_from_world()),
            rasterized: rasterize(scene, settings, options),
            occluders: OnceLock::new(),
        }
    }

    /// Whether `settings` has this frame's view (size and camera), which [`Frame::render_selected`] needs.
    pub fn has_view_of(&self, settings: &RenderSettings) -> bool {
        (settings.width, settings.height, settings.clip_from_world()) == self.view
    }

    /// [`render_selected`](super::render_selected) of this view with `settings`' shading (`selected`: one flag a
    /// pixel; `None`: every pixel). Panics where `settings` has another view than the frame's: a caller's error.
    pub fn render_selected(&self, settings: &RenderSettings, selected: Option<&[bool]>) -> Image {
        assert!(self.has_view_of(settings), "a frame renders the view it was rasterized for");
        if let Some(flags) = selected {
            assert_eq!(flags.len(), (settings.width as usize) * (settings.height as usize), "one flag a pixel");
        }
        let rays = occluders_for(self.scene, settings, &self.occluders);
        let shader = plain_shader(self.scene, settings, rays.as_ref());
        shade_rasterized(&self.rasterized, selected, &shader).0
    }

    /// `refine(k, shade)` for each of `pixels` (row-major indices), pixel by pixel across the
    /// threads, where `shade(level)` is pixel `k` as [`Frame::render_selected`] with `levels[level]` gives it: a
    /// pixel refined grid after grid on one thread, each light's walk and arcs kept from one grid to the next
    /// (`shading::slice_buckets::with_pixel_cache`; the values are the same). The results in the order of `pixels`.
    pub fn refine_pixels<T: Send>(
        &self,
        levels: &[RenderSettings],
        pixels: &[usize],
        refine: impl Fn(usize, &dyn Fn(usize) -> [f32; 4]) -> T + Sync,
    ) -> Vec<T> {
        for s in levels {
            assert!(self.has_view_of(s), "a frame renders the view it was rasterized for");
        }
        let rays: Vec<_> = levels.iter().map(|s| occluders_for(self.scene, s, &self.occluders)).collect();
        let shaders: Vec<_> = levels.iter().zip(&rays).map(|(s, r)| plain_shader(self.scene, s, r.as_ref())).collect();
        pixels
            .par_iter()
            .with_max_len(1)
            .map(|&k| {
                // A pixel no triangle covers stays empty, as `render_selected` leaves it.
                let covered = self.rasterized.nearest[k] != u32::MAX;
                let shade = |level: usize| {
                    if covered {
                        stored(shade_covered(&self.rasterized, k, &shaders[level]).0)
                    } else {
                        [0.0; 4]
                    }
                };
                with_pixel_cache(|| refine(k, &shade))
            })
            .collect()
    }
}

//! What the GPU's visibility of the sun costs, pixel by pixel (`sunshade bench --shadows`): the sun's cells
//! (`visibility::sun_cells`) classify each pixel's sun cone from the reference's ray origin and normal, as the
//! shader does (shaders/sun_cells.glsl), and a pixel they leave to the rays (a penumbra, or a point past its
//! cell's bound) casts the located grid's rays, counted by running the reference's grid through a counting
//! occluder. The reference's own rays and arithmetic, so the counts are the GPU's up to rays that graze an edge.

use super::fragment::ray_frame;
use super::occluders::count_rays;
use super::{render_inner, Occluders, Prepared, ReferenceOptions};
use crate::scene::{AlphaMode, Scene};
use crate::settings::RenderSettings;
use crate::shading::lights::sun::sun_visible_fraction;
use crate::shading::SunModel;
use crate::visibility::sun_cells::{
    sun_cell_range, sun_cone_class, SunCells, SunCone, MAX_SUN_CELL_ENTRIES, SUN_CONE_MARGIN,
};

/// The sun's visibility over an image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SunRayCosts {
    /// Covered pixels.
    pub covered: usize,
    /// Of them, those whose sun visibility is evaluated (the sun's disk at least partly above the surface's
    /// horizon).
    pub evaluated: usize,
    /// Of those, the ones the classification leaves to the rays: penumbrae, and points past their cell's bound.
    pub penumbra: usize,
    /// Shadow rays towards the sun in all.
    pub rays: u64,
    /// Triangles classified in all (those above each evaluated point in its cell).
    pub tested: u64,
}

/// The costs of the sun's visibility in a render with `settings` (any technique: what shadow rays would cast),
/// `None` without a sun. A delta sun has no penumbra: one ray a pixel, through the cells.
pub fn sun_ray_costs(scene: &Scene, settings: &RenderSettings, options: &ReferenceOptions) -> Option<SunRayCosts> {
    let sun = settings.lights.sun?;
    let l = sun.direction.as_dvec3().normalize();
    let diameter = sun.angular_diameter as f64;
    let sin_sigma = (0.5 * diameter).sin();
    let triangles = crate::visibility::occluder_triangles(scene);
    let cells = SunCells::build(&triangles, l, 0.5 * diameter, MAX_SUN_CELL_ENTRIES)?;
    let opaque: Vec<bool> = scene
        .meshes
        .iter()
        .flat_map(|m| {
            let opaque = !matches!(scene.materials[m.material].alpha, AlphaMode::Mask(_));
            std::iter::repeat_n(opaque, m.indices.len() / 3)
        })
        .collect();
    let occluders = Occluders::new(scene);
    let k = settings.shading.shadow_samples_per_axis;
    let delta = settings.shading.sun == SunModel::Delta;
    // Each pixel's (0 not evaluated, 1 classified, 2 left to the rays; its rays; the triangles it classifies), as
    // an image's channels.
    let (image, _) = render_inner(scene, settings, options, None, &|t: &Prepared, _, w: [f64; 3]| {
        let f = ray_frame(t, w);
        if f.normal.dot(l) <= -sin_sigma {
            return ([0.0; 3], false);
        }
        let tested = sun_cell_range(&cells, f.origin).len() as f64;
        if delta {
            return ([1.0, 1.0, tested], false);
        }
        match sun_cone_class(&cells, &triangles, |i| opaque[i], f.origin, f.normal, sin_sigma) {
            SunCone::Misses => ([1.0, 0.0, tested], false),
            SunCone::Covered if f.normal.dot(l) > sin_sigma + SUN_CONE_MARGIN => ([1.0, 0.0, tested], false),
            _ => {
                let rays = count_rays(&occluders, f.origin, k, |s| {
                    sun_visible_fraction(s, f.normal, l, diameter);
                });
                ([2.0, rays as f64, tested], false)
            }
        }
    });
    let mut costs = SunRayCosts::default();
    for p in image.pixels().iter().filter(|p| p[3] > 0.0) {
        costs.covered += 1;
        costs.evaluated += usize::from(p[0] > 0.0);
        costs.penumbra += usize::from(p[0] > 1.0);
        costs.rays += p[1] as u64;
        costs.tested += p[2] as u64;
    }
    Some(costs)
}

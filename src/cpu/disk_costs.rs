//! What the GPU's visibility of disk lights costs, pixel by pixel (`sunshade bench --shadow-cost`): the walk of
//! `visibility::disk_cone` proves a pixel's rays to a disk clear from the reference's ray origin, shading point and
//! normal, as the shader does (shaders/disk_cone.glsl), and a pixel it leaves to the rays (a penumbra, an umbra, or
//! an occluder close to the rays) casts the located grid's rays, counted by running the reference's grid through a
//! counting occluder. The reference's own rays and arithmetic, so the counts are the GPU's up to rays that graze
//! an edge.

use super::fragment::ray_frame;
use super::occluders::count_rays;
use super::{render_inner, Occluders, Prepared, ReferenceOptions};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::lights::disk::{disk_geometry, disk_projected_solid_angle, disk_visible_fraction};
use crate::shading::DiskModel;
use crate::visibility::disk_cone::disk_cone_clear;

/// The disk lights' visibility over an image, summed over the lights.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DiskRayCosts {
    /// Covered pixels.
    pub covered: usize,
    /// Pixels and lights whose visibility is evaluated (the disk at least partly above the surface's horizon), and
    /// of them those the walk leaves to the rays.
    pub evaluated: usize,
    pub left_to_rays: usize,
    /// Shadow rays to the disks in all.
    pub rays: u64,
}

/// The costs of the disk lights' visibility in a render with `settings` (what shadow rays would cast), `None`
/// without a disk light. A small-source disk is one ray a pixel, never proven clear.
pub fn disk_ray_costs(scene: &Scene, settings: &RenderSettings, options: &ReferenceOptions) -> Option<DiskRayCosts> {
    let disks: Vec<_> = settings.lights.disks.iter().map(disk_geometry).collect();
    if disks.is_empty() {
        return None;
    }
    let occluders = Occluders::new(scene);
    let bvh = &occluders.bvh;
    let k = settings.shading.shadow_samples_per_axis;
    let exact = settings.shading.disk == DiskModel::Exact;
    // Each pixel's (lights evaluated, lights left to the rays, rays), as an image's channels.
    let (image, _) = render_inner(scene, settings, options, None, &|t: &Prepared, _, w: [f64; 3]| {
        let f = ray_frame(t, w);
        let mut counts = [0.0; 3];
        for g in &disks {
            if disk_projected_solid_angle(f.position, f.normal, g) <= 0.0 {
                continue;
            }
            counts[0] += 1.0;
            if !exact {
                counts[1] += 1.0;
                counts[2] += 1.0;
                continue;
            }
            if disk_cone_clear(bvh, f.origin, f.position, f.normal, g.center, g.direction, g.radius) {
                continue;
            }
            let rays = count_rays(&occluders, f.origin, k, |s| {
                disk_visible_fraction(s, f.position, f.normal, g.center, g.direction, g.radius);
            });
            counts[1] += 1.0;
            counts[2] += rays as f64;
        }
        (counts, false)
    });
    let mut costs = DiskRayCosts::default();
    for p in image.pixels().iter().filter(|p| p[3] > 0.0) {
        costs.covered += 1;
        costs.evaluated += p[0] as usize;
        costs.left_to_rays += p[1] as usize;
        costs.rays += p[2] as u64;
    }
    Some(costs)
}

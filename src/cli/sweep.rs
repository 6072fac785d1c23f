//! The quality settings `bench --pareto` sweeps: every knob over its range alone (the others at their defaults),
//! and a ladder of combinations (all sample counts raised together, with the exact and with the fast light models),
//! limited to the knobs that change something in the scene (no sun samples without a sun and a specular lobe, no
//! shadow settings where nothing can occlude a light).

use crate::gpu::Interpolation;
use crate::scene::{BrdfKind, Lights, Scene};
use crate::shading::{DiskModel, ShadingOptions, ShadowMapFilter, Shadows, SunModel};

/// What in a scene the knobs act on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Relevance {
    pub sun: bool,
    pub disks: bool,
    pub sky: bool,
    /// Some material has a specular lobe (the lobe grids matter).
    pub lobes: bool,
    /// Something can occlude a light (the shadow settings matter).
    pub shadows: bool,
    /// The device has ray queries (`ray` is available).
    pub ray_queries: bool,
}

impl Relevance {
    pub fn of(scene: &Scene, lights: &Lights, can_occlude: bool, ray_queries: bool) -> Self {
        let lobes =
            scene.materials.iter().any(|m| !m.brdf.is_lambert() || m.mapping.is_some_and(|k| k != BrdfKind::Lambert));
        Self {
            sun: lights.sun.is_some(),
            disks: !lights.disks.is_empty(),
            sky: lights.sky.is_some(),
            lobes,
            shadows: can_occlude,
            ray_queries,
        }
    }
}

/// One setting of the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    pub interpolation: Interpolation,
    pub shading: ShadingOptions,
}

impl Setting {
    /// The knobs that matter for this scene, in words: "sun disk 8², lobes 16², shadows ray 8², f64".
    pub fn label(&self, r: &Relevance) -> String {
        let s = &self.shading;
        let mut parts = Vec::new();
        if r.sun {
            parts.push(match s.sun {
                SunModel::Delta => "sun delta".to_string(),
                SunModel::Disk if r.lobes => format!("sun disk {}²", s.sun_samples_per_axis),
                SunModel::Disk => "sun disk".to_string(),
            });
        }
        if r.disks {
            parts.push(match s.disk {
                DiskModel::Exact => "disks exact".to_string(),
                DiskModel::SmallSource => "disks small-source".to_string(),
            });
        }
        if (r.disks && s.disk == DiskModel::Exact || r.sky) && r.lobes {
            parts.push(format!("lobes {}²", s.samples_per_axis));
        }
        if r.shadows {
            parts.push(match (s.shadows, s.shadow_map_filter) {
                (Shadows::Ray, _) if r.ray_queries => format!("shadows ray {}²", s.shadow_samples_per_axis),
                (Shadows::Ray, _) => format!("shadows ray {}² (BVH walk)", s.shadow_samples_per_axis),
                (Shadows::Map, ShadowMapFilter::Pcss) => format!("shadows map {} pcss", s.shadow_map_size),
                (Shadows::Map, ShadowMapFilter::Nearest) => format!("shadows map {} nearest", s.shadow_map_size),
                (other, _) => format!("shadows {}", other.name()),
            });
        }
        parts.push(self.interpolation.name().to_string());
        parts.join(", ")
    }
}

/// Sample counts per axis of the ladder's rungs: (sun, lobes, shadow rays).
const LADDER: [(u32, u32, u32); 4] = [(1, 2, 1), (2, 4, 2), (4, 8, 4), (16, 32, 16)];
/// Shadow-map sizes swept.
const MAP_SIZES: [u32; 4] = [512, 1024, 2048, 4096];

/// The settings to sweep: the base first (the default render: `interpolation` the renderer's default, shadow rays
/// where the scene can shadow itself, by ray queries or the fragment shader's walk), then each knob alone, then the
/// ladder; without repeats. `modes`: the interpolation modes the device offers.
pub fn sweep(r: &Relevance, default_mode: Interpolation, modes: &[Interpolation]) -> Vec<Setting> {
    let base = ShadingOptions { shadows: if r.shadows { Shadows::Ray } else { Shadows::None }, ..Default::default() };
    let at = |shading: ShadingOptions| Setting { interpolation: default_mode, shading };
    let mut v = vec![at(base)];
    if r.sun {
        v.push(at(ShadingOptions { sun: SunModel::Delta, ..base }));
        if r.lobes {
            for n in [1, 2, 4, 16] {
                v.push(at(ShadingOptions { sun_samples_per_axis: n, ..base }));
            }
        }
    }
    if r.disks {
        v.push(at(ShadingOptions { disk: DiskModel::SmallSource, ..base }));
    }
    if (r.disks || r.sky) && r.lobes {
        for n in [2, 4, 8, 32] {
            v.push(at(ShadingOptions { samples_per_axis: n, ..base }));
        }
    }
    for &m in modes {
        v.push(Setting { interpolation: m, shading: base });
    }
    if r.shadows {
        v.push(at(ShadingOptions { shadows: Shadows::None, ..base }));
        for size in MAP_SIZES {
            v.push(at(ShadingOptions { shadows: Shadows::Map, shadow_map_size: size, ..base }));
        }
        v.push(at(ShadingOptions { shadows: Shadows::Map, shadow_map_filter: ShadowMapFilter::Nearest, ..base }));
        for n in [1, 2, 4, 16] {
            v.push(at(ShadingOptions { shadows: Shadows::Ray, shadow_samples_per_axis: n, ..base }));
        }
    }
    // The ladder: every count raised together, with the exact models at the default interpolation and with the
    // fast ones (delta sun, small-source disks) at f32.
    let fast_mode = modes.iter().copied().find(|&m| m == Interpolation::BarycentricF32).unwrap_or(default_mode);
    for &(sun, lobes, rays) in &LADDER {
        let shadows = |o: ShadingOptions| match r.shadows {
            false => o,
            true => ShadingOptions { shadows: Shadows::Ray, shadow_samples_per_axis: rays, ..o },
        };
        let exact = ShadingOptions { sun_samples_per_axis: sun, samples_per_axis: lobes, ..base };
        v.push(at(shadows(exact)));
        let fast = ShadingOptions { sun: SunModel::Delta, disk: DiskModel::SmallSource, ..exact };
        v.push(Setting { interpolation: fast_mode, shading: shadows(fast) });
    }
    // Knobs that do not matter leave settings equal in effect: keep the first of each label.
    let mut seen = std::collections::HashSet::new();
    v.retain(|s| seen.insert(s.label(r)));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: Relevance =
        Relevance { sun: true, disks: true, sky: true, lobes: true, shadows: true, ray_queries: true };
    const MODES: [Interpolation; 3] =
        [Interpolation::BarycentricF64, Interpolation::BarycentricF32, Interpolation::Device];

    #[test]
    fn the_default_comes_first_and_every_setting_once() {
        let v = sweep(&ALL, Interpolation::BarycentricF64, &MODES);
        assert_eq!(v[0].shading, ShadingOptions { shadows: Shadows::Ray, ..Default::default() });
        let labels: Vec<String> = v.iter().map(|s| s.label(&ALL)).collect();
        let unique: std::collections::HashSet<&String> = labels.iter().collect();
        assert_eq!(unique.len(), labels.len());
        for knob in
            ["sun delta", "sun disk 1²", "disks small-source", "lobes 2²", "shadows map 512 pcss", "f32", "device"]
        {
            assert!(labels.iter().any(|l| l.contains(knob)), "{knob} missing from {labels:?}");
        }
    }

    #[test]
    fn without_ray_queries_the_default_and_the_rays_are_the_walk() {
        // The default render's shadows are rays on every device: without ray queries the fragment shader walks
        // the BVH, and the sweep starts from that default and sweeps its grid as it does with ray queries.
        let sky = Relevance { sun: false, disks: false, sky: true, lobes: false, shadows: true, ray_queries: false };
        let labels: Vec<String> =
            sweep(&sky, Interpolation::BarycentricF64, &MODES).iter().map(|s| s.label(&sky)).collect();
        assert_eq!(labels[0], "shadows ray 6² (BVH walk), f64", "{labels:?}");
        for n in [1, 2, 4, 16] {
            let rays = format!("shadows ray {n}² (BVH walk), f64");
            assert!(labels.contains(&rays), "{rays} missing from {labels:?}");
        }
        assert!(labels.iter().any(|l| l.contains("shadows map 2048 pcss")), "{labels:?}");
    }

    #[test]
    fn knobs_that_change_nothing_are_not_swept() {
        // A Lambertian scene under the sun alone, nothing to occlude, one interpolation: only the sun model.
        let r = Relevance { sun: true, disks: false, sky: false, lobes: false, shadows: false, ray_queries: false };
        let v = sweep(&r, Interpolation::BarycentricF64, &[Interpolation::BarycentricF64]);
        let labels: Vec<String> = v.iter().map(|s| s.label(&r)).collect();
        assert_eq!(labels, ["sun disk, f64", "sun delta, f64"]);
    }
}

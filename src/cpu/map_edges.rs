//! Where a shadow map may answer otherwise than the rays: the pixels whose map lookups can reach an occluder's
//! edge. `render --check` and the image-diff tests compare a `--shadows map` image with the reference, which
//! casts exact f64 rays for the lights the maps stand for; the maps agree with them only where everything the
//! lookups read says the same (docs/accuracy.md, "Shadows"). This is the class of pixels where they may not,
//! counted apart as coverage edges and fragile rays are.
//!
//! The *reach* of a pixel's map lookups, for each light with a map (`gpu::renderer` fits the same frames,
//! `visibility::shadow_map`):
//! - **sun** (orthographic): every texel within `search + 1.5` texels of the point's map position, `search =
//!   d tan(δ/2) / texel` for the PCSS filter (`d` the point's depth from the sun \[m\]), 0 for the nearest texel or
//!   a delta sun; 1.5 texels cover the texel a lookup rounds to and the f32 map position. Each is a ray along
//!   the sun from the receiver's own plane under that texel (the plane the map compares with), starting past
//!   the map's depth tolerance.
//! - **disk light** (perspective, from its centre): the same around the point, `search = R / texel` with the
//!   texel at the point's distance; each is a segment from the disk's centre to the point's plane, ending at the
//!   map's depth allowance. Where the lookups find blockers, PCSS looks farther (the spread at the nearest
//!   blocker's depth), and the reach grows to it.
//!
//! A pixel is *stable* for a light when every ray of its reach gives one answer, and the reference's own
//! visible fraction agrees with it (1 where the reach is clear, 0 where it is all blocked): the map then returns
//! exactly that value. Otherwise it is a *map edge*. The reach is sampled on a grid of at most
//! [`REACH_GRID`]² rays, texel by texel where the reach is that small (the sun's at the default 2048² map
//! and 0.53°); wider reaches are sampled more sparsely, so an occluder thinner than the spacing can slip between
//! the rays (then the check reports the pixel as a difference, never hides it).

use glam::{DVec3, DVec4};

use super::Occluders;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::lights::{disk::disk_visible_fraction, sun::sun_visible_fraction};
use crate::shading::{orthonormal_to, Occlusion, ShadowMapFilter, ShadowedLights, Shadowing, SunModel};
use crate::shading::{DiskModel, MAPPED_DISKS};
use crate::visibility::shadow_map::{fit_disk_map, fit_sun_map, DiskMapFrame, SunMapFrame};
use crate::visibility::WatertightRay;

/// The class's name in comparison reports.
pub const CLASS: &str = "shadow-map edges (the map's lookups reach an occluder's edge; the map's own error there is \
                         what `sunshade bench --shadows` measures)";

/// The most rays per axis a reach is sampled with.
pub const REACH_GRID: usize = 33;

/// The lights with maps in a render, and their frames.
pub struct MapReach {
    sun: Option<SunReach>,
    disks: Vec<DiskReach>,
    /// Samples per axis of the reference's visible-fraction grids.
    samples_per_axis: u32,
}

struct SunReach {
    l: DVec3,
    angular_diameter: f64,
    delta: bool,
    frame: SunMapFrame,
    /// `tan(δ/2)` for PCSS, 0 for one texel.
    search_tan: f64,
}

struct DiskReach {
    center: DVec3,
    d: DVec3,
    radius: f64,
    small_source: bool,
    frame: DiskMapFrame,
    size: f64,
    pcss: bool,
}

impl MapReach {
    /// The maps a `--shadows map` render of `scene` with `settings` uses.
    pub fn new(scene: &Scene, settings: &RenderSettings) -> Self {
        let bounds = scene.bounds();
        let size = settings.shading.shadow_map_size;
        let pcss = settings.shading.shadow_map_filter == ShadowMapFilter::Pcss;
        let sun = match (&settings.lights.sun, bounds) {
            (Some(sun), Some(b)) => {
                let l = sun.direction.as_dvec3();
                let delta = settings.shading.sun == SunModel::Delta;
                let angular_diameter = sun.angular_diameter as f64;
                Some(SunReach {
                    l,
                    angular_diameter,
                    delta,
                    frame: fit_sun_map(b, l, size),
                    search_tan: if pcss && !delta { (0.5 * angular_diameter).tan() } else { 0.0 },
                })
            }
            _ => None,
        };
        let small_source = settings.shading.disk == DiskModel::SmallSource;
        let disks = match bounds {
            Some(b) => settings
                .lights
                .disks
                .iter()
                .take(MAPPED_DISKS)
                .filter_map(|disk| {
                    let (center, d) = (disk.center.as_dvec3(), disk.direction.as_dvec3());
                    fit_disk_map(b, center, d).map(|frame| DiskReach {
                        center,
                        d,
                        radius: disk.radius as f64,
                        small_source,
                        frame,
                        size: size as f64,
                        pcss: pcss && !small_source,
                    })
                })
                .collect(),
            None => Vec::new(),
        };
        Self { sun, disks, samples_per_axis: settings.shading.shadow_samples_per_axis }
    }

    /// Whether the pixel whose shadow rays leave from `origin` (face normal `face`, on the shaded side; point
    /// `x` with normal `n`) is a map edge for any light with a map.
    pub fn is_edge(&self, occluders: &Occluders, origin: DVec3, face: DVec3, x: DVec3, n: DVec3) -> bool {
        let rays = Shadowing {
            origin,
            occluders,
            samples_per_axis: self.samples_per_axis,
            lights: ShadowedLights::ALL,
            slices: false,
        };
        if let Some(sun) = &self.sun {
            let v = if sun.delta {
                f64::from(u8::from(rays.visible_along(sun.l)))
            } else {
                sun_visible_fraction(&rays, n, sun.l, sun.angular_diameter)
            };
            // A fraction strictly between 0 and 1 is a penumbra: an edge whatever the reach says.
            if !(v == 0.0 || v == 1.0) || !sun.stable(occluders, origin, face, v) {
                return true;
            }
        }
        for disk in &self.disks {
            let v = if disk.small_source {
                f64::from(u8::from(rays.visible_to(disk.center)))
            } else {
                disk_visible_fraction(&rays, x, n, disk.center, disk.d, disk.radius)
            };
            if !(v == 0.0 || v == 1.0) || !disk.stable(occluders, origin, face, v) {
                return true;
            }
        }
        false
    }
}

/// The points of a grid over the disk of radius `r` (in units of `step`, the spacing wanted): at most
/// [`REACH_GRID`] a side, the centre always among them.
fn reach_grid(r: f64, step: f64) -> Vec<(f64, f64)> {
    let half = ((r / step).ceil() as usize).min(REACH_GRID / 2);
    let spacing = if half == 0 { 0.0 } else { r / half as f64 };
    let mut points = Vec::with_capacity((2 * half + 1).pow(2));
    for i in 0..=2 * half {
        for j in 0..=2 * half {
            let (a, b) = ((i as f64 - half as f64) * spacing, (j as f64 - half as f64) * spacing);
            // Keep the grid points whose cell meets the disk.
            if a * a + b * b <= (r + spacing).powi(2) {
                points.push((a, b));
            }
        }
    }
    points
}

/// One answer for every ray (`Some(occluded)`), or `None` where they differ.
fn one_answer(mut rays: impl Iterator<Item = bool>) -> Option<bool> {
    let first = rays.next()?;
    rays.all(|r| r == first).then_some(first)
}

/// Whether the map's value `v` agrees with the reach's one answer (clear: 1; blocked: 0).
fn agrees(answer: Option<bool>, v: f64) -> bool {
    match answer {
        Some(false) => v == 1.0,
        Some(true) => v == 0.0,
        None => false,
    }
}

impl SunReach {
    /// Whether the map's answer at this receiver is the rays' (visible fraction `v`).
    fn stable(&self, occluders: &Occluders, origin: DVec3, face: DVec3, v: f64) -> bool {
        let f = &self.frame;
        let q = f.map_from_world.project_point3(origin);
        // The point's depth from the sun [m]; the search radius [m].
        let depth = (q.z * f.depth_extent).max(0.0);
        let reach = depth * self.search_tan + 1.5 * f.texel;
        // The receiver's plane as the map sees it (shaders/shadow_map.glsl, sun_map_gradient): its depth grows
        // by g·(a, b) for a sideways step (a, b) [m], g = (n·x, n·y)/(n·l), capped at 1e3 (n·l → 0 at grazing sun:
        // the cap keeps the plane finite where the map's own comparison is capped too).
        let (ax, ay) = (orthonormal_to(self.l), self.l.cross(orthonormal_to(self.l)));
        let nl = face.dot(self.l);
        let nl = if nl.abs() > 1e-3 { nl } else { 1e-3f64.copysign(nl) };
        let mut g = (face.dot(ax) / nl, face.dot(ay) / nl);
        let m = (g.0 * g.0 + g.1 * g.1).sqrt();
        if m > 1e3 {
            g = (g.0 * 1e3 / m, g.1 * 1e3 / m);
        }
        let tolerance = 0.25 * f.texel + f.depth_extent / 16384.0;
        let answer = one_answer(reach_grid(reach, f.texel).into_iter().map(|(a, b)| {
            let start = origin + a * ax + b * ay - (g.0 * a + g.1 * b - tolerance) * self.l;
            occluders.occluded(start, self.l, f64::INFINITY)
        }));
        agrees(answer, v)
    }
}

impl DiskReach {
    /// Whether the map's answer at this receiver is the rays' (visible fraction `v`).
    fn stable(&self, occluders: &Occluders, origin: DVec3, face: DVec3, v: f64) -> bool {
        let f = &self.frame;
        let q = f.map_from_world * DVec4::new(origin.x, origin.y, origin.z, 1.0);
        let z = q.w;
        // (`z > near` is false for a NaN depth too: such a point is outside.)
        let inside = z > f.near && q.x.abs() <= z && q.y.abs() <= z;
        if !inside {
            // Outside the map's field of view the map leaves the light unoccluded.
            return v == 1.0;
        }
        // The side of one texel at the receiver's distance [m], and the map's depth allowance
        // (shaders/shadow_map.glsl, disk_visible_fraction_map): a texel times (1 + tan θ), plus the tangent plane's
        // depth change out to each lookup.
        let texel_at = 2.0 * z * f.tan_half / self.size;
        let to_light = (self.center - origin).normalize_or(-self.d);
        let c = face.dot(to_light).abs();
        let tan = if c > 1e-3 { (1.0 - c * c).max(0.0).sqrt() / c } else { 1e3 };
        let bias = texel_at * (1.0 + tan);
        let search = if self.pcss { (self.radius / texel_at).min(0.5 * self.size) } else { 0.0 };
        let (ax, ay) = (orthonormal_to(self.d), self.d.cross(orthonormal_to(self.d)));
        // The segment from the disk's centre towards the point (a, b) [m] sideways of the receiver, ending at the
        // allowance; `Some(depth)` of the nearest blocker along it [m].
        let segment = |a: f64, b: f64| -> Option<f64> {
            let target = origin + a * ax + b * ay;
            let r = (a * a + b * b).sqrt();
            let end = z - bias - tan.min(1e3) * r;
            if end <= f.near {
                return None;
            }
            let dir = target - self.center;
            // Depth along the axis grows as t z (d·dir = z): the map holds what lies past its near plane.
            let (t0, t1) = (f.near / z, end / z);
            if !occluders.occluded(self.center + t0 * dir, (t1 - t0) * dir, 1.0) {
                return None;
            }
            // The nearest surface on it (alpha masks aside: nearer is the safe side for the spread below).
            let ray = WatertightRay::new(self.center, dir)?;
            Some(occluders.bvh.closest_hit(&ray, t0, t1).map_or(end, |(t, _)| t * z))
        };
        let grid = reach_grid((search + 1.5) * texel_at, texel_at);
        let hits: Vec<Option<f64>> = grid.iter().map(|&(a, b)| segment(a, b)).collect();
        let answer = one_answer(hits.iter().map(Option::is_some));
        if answer == Some(true) {
            // All blocked: PCSS then looks up the spread at the mean blocker depth, which the nearest bounds.
            let nearest = hits.iter().flatten().fold(f64::INFINITY, |m, &h| m.min(h));
            let spread = (self.radius * (z - nearest).max(0.0) / nearest.max(f.near) / texel_at).min(0.5 * self.size);
            if spread > search {
                let wider = reach_grid((spread + 1.5) * texel_at, texel_at);
                if !wider.iter().all(|&(a, b)| segment(a, b).is_some()) {
                    return false;
                }
            }
        }
        agrees(answer, v)
    }
}

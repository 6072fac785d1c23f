//! Visibility of the lights: `E = ∫ V(x, l) L(x, l) (n·l) dΩ`, where `V` is 0 for the directions an occluder
//! blocks. Mirrored by `shaders/visibility.glsl` name for name: the same sample grids, the same ray origins and
//! the same ray extents, so that the GPU's ray queries and the reference's rays differ only at rays that graze an
//! occluder's edge.
//!
//! **Diffuse part.** Each light's exact unoccluded irradiance (`radiometry`) is scaled by the light's *visible
//! fraction*: the cosine-weighted fraction of its directions that reach it,
//! `V = Σ wᵢ vᵢ / Σ wᵢ` over a deterministic stratified grid of `k²` samples (`--shadow-samples`). Where every
//! sample is visible the two sums are the same additions in the same order, so `V` is exactly 1 and the pixel is
//! bitwise its unshadowed value. As `k` grows `V` converges to the exact visible fraction of the light (the
//! midpoint rule on an equal-area map).
//! - sun: the cap of half-angle `σ = δ/2` about `l`, through the disk of radius `tan σ` one unit away along `l`;
//!   `wᵢ = (n·ωᵢ)⁺ cos³γᵢ` (`cos³γ`: solid angle per unit area of that disk, γ the angle from `l`);
//! - disk light: points of the disk, `wᵢ = (n·ωᵢ)⁺ (−d·ωᵢ)⁺ / |yᵢ − x|²` (projected solid angle per area);
//! - sky: directions cosine-distributed about n (the grid's density is `cos θ / π`), `wᵢ = 1` where the direction
//!   is in the sky (`ω_y > 0`), 0 below the horizon.
//!
//! The grid is the midpoint grid of `k × k` cells of the unit square mapped to the unit disk by Shirley & Chiu's
//! concentric map (equal-area, low distortion; "A Low Distortion Map Between Disk and Square", 1997). With k = 1
//! its one point is the centre: the light's centre alone, a hard shadow.
//!
//! **Specular part.** The lobe integrals already sample each light (`shade.rs`); each of their samples casts its
//! own shadow ray, so the lobe sees exactly the part of the light that is visible. A delta sun and a small-source
//! disk are single directions: one ray each, for both parts.
//!
//! **Ray origins.** A shadow ray leaves from the shading point moved in two steps, identically in both renderers:
//! 1. Hanika's terminator offset ("Hacking the Shadow Terminator", Ray Tracing Gems II, ch. 4, 2021): the point
//!    is projected onto the tangent plane of each vertex (its normal) where it lies below that plane, and the
//!    projections are interpolated with the barycentrics: `x' = x − Σ bᵢ min(0, (x − pᵢ)·nᵢ) nᵢ`. On a coarse
//!    smooth-shaded mesh this lifts the point onto the smooth surface the normals describe, so that rays towards
//!    a light just above the shading horizon do not hit the neighbouring facets (the faceted terminator).
//!    On a flat triangle (all nᵢ equal to the face normal) `x' = x`.
//! 2. A push along the face normal on the side of the shading normal by
//!    [`ray_offset`] `= 2⁻¹⁶ max |pᵢ|∞`, so that the ray cannot hit its own triangle: about 500 ulps of the
//!    triangle's largest coordinate in f32, far above the rounding of the f32 interpolation (a few ulps) and
//!    scale-invariant (1 mm and 10 km scenes alike), yet far below a contact shadow's size (15 µm at 1 m from
//!    the origin).
//!
//! Rays towards a disk light end just short of it (`t < 1 − 2⁻¹²` of the way), so that a surface in the light's
//! own plane (a ceiling around a skylight) does not block it.

use std::f64::consts::PI;

use glam::DVec3;

use super::shade::orthonormal_to;

/// Default samples per axis of the visibility grids (`k² = 64` shadow rays per light and pixel).
pub const DEFAULT_SHADOW_SAMPLES_PER_AXIS: u32 = 8;

/// How the sun's shadow map is filtered (`--shadow-map-filter`; GPU, `--shadows map`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ShadowMapFilter {
    /// The sun's disk: a blocker search and a filter on the visible-fraction grid (PCSS): a penumbra.
    #[default]
    Pcss,
    /// The texel under the point alone: hard shadows (as for a delta sun).
    Nearest,
}

impl std::str::FromStr for ShadowMapFilter {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "pcss" => Ok(ShadowMapFilter::Pcss),
            "nearest" => Ok(ShadowMapFilter::Nearest),
            _ => Err(format!("'{s}' is not a shadow-map filter (pcss, nearest)")),
        }
    }
}

/// Default side of the sun's shadow map [texels] (`--shadow-map-size`; GPU, `--shadows map`).
pub const DEFAULT_SHADOW_MAP_SIZE: u32 = 2048;

/// How far along a ray to a point on a disk light the ray is tested: `t < 1 − 2⁻¹²`.
pub const SEGMENT_T_MAX: f64 = 1.0 - 1.0 / 4096.0;

/// The relative size of the push along the face normal: `2⁻¹⁶`.
pub const RAY_OFFSET_RELATIVE: f64 = 1.0 / 65536.0;

/// How shadows are computed (`--shadows`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Shadows {
    /// Ray queries where the device has them, else shadow maps; nothing where no triangle can occlude a light
    /// from a visible surface (`visibility::can_occlude`).
    #[default]
    Auto,
    /// Every light unoccluded.
    None,
    /// Shadow rays (the reference always casts rays: it is the truth the other techniques are measured against).
    Ray,
    /// Shadow maps (GPU).
    Map,
}

impl Shadows {
    pub fn name(self) -> &'static str {
        match self {
            Shadows::Auto => "auto",
            Shadows::None => "none",
            Shadows::Ray => "ray",
            Shadows::Map => "map",
        }
    }
}

impl std::str::FromStr for Shadows {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "auto" => Ok(Shadows::Auto),
            "none" => Ok(Shadows::None),
            "ray" => Ok(Shadows::Ray),
            "map" => Ok(Shadows::Map),
            _ => Err(format!("'{s}' is not a shadow technique (auto, none, ray, map)")),
        }
    }
}

/// Whether something blocks a ray. Implemented by the reference's BVH (`visibility::Bvh`) and by [`Unoccluded`].
pub trait Occlusion: Sync {
    /// Whether any occluder meets `origin + t direction` for `0 < t < t_max` (`direction` need not be unit).
    fn occluded(&self, origin: DVec3, direction: DVec3, t_max: f64) -> bool;
}

/// Nothing occludes anything.
pub struct Unoccluded;

impl Occlusion for Unoccluded {
    fn occluded(&self, _: DVec3, _: DVec3, _: f64) -> bool {
        false
    }
}

/// Which lights a render shadows: every light where it casts rays; where it reads shadow maps, the sun and the
/// first [`MAPPED_DISKS`] disk lights (the lights with a map), the sky and further disks unoccluded. The reference
/// mirrors the GPU's choice with exact rays for the lights the maps stand for, so that `render --check` compares
/// the same model (docs/accuracy.md, "Shadows").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowedLights {
    pub sun: bool,
    /// The first this many disk lights are shadowed.
    pub disks: usize,
    pub sky: bool,
}

/// The disk lights a shadow-map render gives a map of their own (the first ones; `MAX_DISK_MAPS` in the shaders).
pub const MAPPED_DISKS: usize = 4;

impl ShadowedLights {
    /// Every light (rays).
    pub const ALL: Self = Self { sun: true, disks: usize::MAX, sky: true };
    /// The lights a shadow-map render shadows.
    pub const MAPPED: Self = Self { sun: true, disks: MAPPED_DISKS, sky: false };

    /// The lights a render with technique `shadows` shadows: the mapped ones for `map`, every light otherwise (a
    /// resolved technique: `auto` must be resolved first, since it may mean maps).
    pub fn of(shadows: Shadows) -> Self {
        if shadows == Shadows::Map {
            Self::MAPPED
        } else {
            Self::ALL
        }
    }
}

/// What a shading point needs to cast shadow rays.
#[derive(Clone, Copy)]
pub struct Shadowing<'a> {
    /// The rays' origin [m] ([`shadow_ray_origin`]).
    pub origin: DVec3,
    pub occluders: &'a dyn Occlusion,
    /// Samples per axis of the visible-fraction grids.
    pub samples_per_axis: u32,
    /// The lights these rays shadow; the others are unoccluded.
    pub lights: ShadowedLights,
}

impl<'a> Shadowing<'a> {
    /// These rays for the sun, if it is shadowed.
    pub fn for_sun(&self) -> Option<&Self> {
        self.lights.sun.then_some(self)
    }

    /// These rays for disk light `i`, if it is shadowed.
    pub fn for_disk(&self, i: usize) -> Option<&Self> {
        (i < self.lights.disks).then_some(self)
    }

    /// These rays for the sky, if it is shadowed.
    pub fn for_sky(&self) -> Option<&Self> {
        self.lights.sky.then_some(self)
    }

    /// Whether the direction `direction` (to a light at infinity: the sun, the sky) is unblocked.
    pub fn visible_along(&self, direction: DVec3) -> bool {
        !self.occluders.occluded(self.origin, direction, f64::INFINITY)
    }

    /// Whether the point `target` [m] (on a disk light) is unblocked.
    pub fn visible_to(&self, target: DVec3) -> bool {
        !self.occluders.occluded(self.origin, target - self.origin, SEGMENT_T_MAX)
    }
}

/// The point of the unit disk for the point `(u, v)` of the unit square (Shirley & Chiu's concentric map;
/// equal-area). The centre `(½, ½)` maps to the origin.
pub fn concentric_disk(u: f64, v: f64) -> (f64, f64) {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a * a > b * b { (a, 0.25 * PI * (b / a)) } else { (b, 0.5 * PI - 0.25 * PI * (a / b)) };
    (r * phi.cos(), r * phi.sin())
}

/// The grid point `(i, j)` of `k × k` on the unit disk: the concentric map of the cell's midpoint.
pub fn disk_grid_point(i: u32, j: u32, k: u32) -> (f64, f64) {
    let kf = k as f64;
    concentric_disk((i as f64 + 0.5) / kf, (j as f64 + 0.5) / kf)
}

/// `Σ w v / Σ w`, exactly 1 when every weighted sample is visible (the same sums), and 1 when no sample has
/// weight (the light gives nothing there anyway).
fn fraction(visible: f64, total: f64) -> f64 {
    if visible == total || total <= 0.0 {
        1.0
    } else {
        visible / total
    }
}

/// A grid sample's shadow ray: along a direction (a light at infinity) or to a point (on a disk light).
enum SampleRay {
    Along(DVec3),
    To(DVec3),
}

/// `Σ wᵢ vᵢ / Σ wᵢ` over the `k × k` grid ([`fraction`]): `sample` gives a grid point's weight and shadow ray,
/// and the ray is cast only where the weight is positive.
fn grid_fraction(s: &Shadowing, mut sample: impl FnMut((f64, f64)) -> (f64, SampleRay)) -> f64 {
    let (mut visible, mut total) = (0.0, 0.0);
    let k = s.samples_per_axis;
    for i in 0..k {
        for j in 0..k {
            let (w, ray) = sample(disk_grid_point(i, j, k));
            if w > 0.0 {
                total += w;
                let seen = match ray {
                    SampleRay::Along(omega) => s.visible_along(omega),
                    SampleRay::To(y) => s.visible_to(y),
                };
                if seen {
                    visible += w;
                }
            }
        }
    }
    fraction(visible, total)
}

/// The sun's sample through the point `(x, y)` of the unit disk, in the frame `(t, b)` about `l`: its direction
/// and weight `(n·ω)⁺ cos³γ = (n·ω)⁺ / |p|³` (0 below the horizon). Shared by the rays and the shadow map.
pub fn sun_sample(n: DVec3, l: DVec3, t: DVec3, b: DVec3, radius: f64, (x, y): (f64, f64)) -> (DVec3, f64) {
    let p = l + radius * (x * t + y * b);
    let len = p.length();
    let omega = p / len;
    let cos = n.dot(omega);
    (omega, if cos > 0.0 { cos / (len * len * len) } else { 0.0 })
}

/// A disk light's sample at the point `(u, v)` of the unit disk, in the frame `(a, b)` of its plane: the point
/// `y` [m] and its weight `(n·ω)⁺ (−d·ω)⁺ / |y − x|²` from `x` (0 where either cosine is not positive). Shared by
/// the rays and the shadow maps.
#[allow(clippy::too_many_arguments)]
pub fn disk_sample(
    x: DVec3,
    n: DVec3,
    center: DVec3,
    d: DVec3,
    a: DVec3,
    b: DVec3,
    radius: f64,
    (u, v): (f64, f64),
) -> (DVec3, f64) {
    let y = center + radius * (u * a + v * b);
    let to = y - x;
    let dist2 = to.length_squared();
    let omega = to / dist2.sqrt();
    let (cos_r, cos_d) = (n.dot(omega), -d.dot(omega));
    (y, if cos_r > 0.0 && cos_d > 0.0 { cos_r * cos_d / dist2 } else { 0.0 })
}

/// The cosine-weighted visible fraction of the sun's disk (direction `l`, angular diameter δ [rad]) from a point
/// with unit normal `n`.
pub fn sun_visible_fraction(s: &Shadowing, n: DVec3, l: DVec3, angular_diameter: f64) -> f64 {
    let radius = (0.5 * angular_diameter).tan();
    let t = orthonormal_to(l);
    let b = l.cross(t);
    grid_fraction(s, |xy| {
        let (omega, w) = sun_sample(n, l, t, b, radius, xy);
        (w, SampleRay::Along(omega))
    })
}

/// The visible fraction of a disk light (centre [m], unit emission direction `d`, radius [m]), weighted by
/// projected solid angle, from the point `x` with unit normal `n`.
pub fn disk_visible_fraction(s: &Shadowing, x: DVec3, n: DVec3, center: DVec3, d: DVec3, radius: f64) -> f64 {
    let a = orthonormal_to(d);
    let b = d.cross(a);
    grid_fraction(s, |uv| {
        let (y, w) = disk_sample(x, n, center, d, a, b, radius, uv);
        (w, SampleRay::To(y))
    })
}

/// The visible fraction of the sky (the directions with `ω_y > 0`), cosine-weighted, from a point with unit
/// normal `n`: its view factor to the sky relative to the unoccluded one.
pub fn sky_visible_fraction(s: &Shadowing, n: DVec3) -> f64 {
    let t = orthonormal_to(n);
    let b = n.cross(t);
    grid_fraction(s, |(x, y)| {
        // Malley's method: the disk lifted onto the hemisphere is cosine-distributed. 1 − x² − y² ≥ 0 up to
        // rounding, which max() removes (a grazing direction, weight 0 in the cosine anyway).
        let z = (1.0 - x * x - y * y).max(0.0).sqrt();
        let omega = x * t + y * b + z * n;
        (if omega.y > 0.0 { 1.0 } else { 0.0 }, SampleRay::Along(omega))
    })
}

/// The push along the face normal for a triangle with these corners [m]: `2⁻¹⁶ max |pᵢ|∞` (see the module docs).
pub fn ray_offset(corners: &[DVec3; 3]) -> f64 {
    let m = corners.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
    RAY_OFFSET_RELATIVE * m
}

/// The origin of the shadow rays from the point with barycentrics `b` of the triangle with corners `p` [m],
/// vertex normals `normals` (unit, on the side being shaded) and unit shading normal `n`: Hanika's terminator
/// offset, then the push along the face normal on the shading normal's side (module docs).
pub fn shadow_ray_origin(p: &[DVec3; 3], normals: &[DVec3; 3], b: [f64; 3], x: DVec3, n: DVec3) -> DVec3 {
    let mut lifted = x;
    for k in 0..3 {
        let below = (x - p[k]).dot(normals[k]).min(0.0);
        lifted -= b[k] * below * normals[k];
    }
    let face = (p[1] - p[0]).cross(p[2] - p[0]);
    let face = if face.dot(n) < 0.0 { -face } else { face };
    let len2 = face.length_squared();
    if len2 > 0.0 && len2.is_finite() {
        lifted + ray_offset(p) * (face / len2.sqrt())
    } else {
        lifted + ray_offset(p) * n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An infinite half-plane occluder `{y = height, x < edge}`: exact, for tests.
    struct HalfPlane {
        height: f64,
        edge: f64,
    }

    impl Occlusion for HalfPlane {
        fn occluded(&self, o: DVec3, d: DVec3, t_max: f64) -> bool {
            if d.y == 0.0 {
                return false;
            }
            let t = (self.height - o.y) / d.y;
            t > 0.0 && t < t_max && o.x + t * d.x < self.edge
        }
    }

    fn shadowing<'a>(occ: &'a dyn Occlusion, k: u32) -> Shadowing<'a> {
        Shadowing { origin: DVec3::ZERO, occluders: occ, samples_per_axis: k, lights: ShadowedLights::ALL }
    }

    #[test]
    fn concentric_map_is_equal_area_and_inside_the_disk() {
        // Points of a fine grid land inside the disk, and the fraction within radius r is r².
        let k = 200;
        let mut within_half = 0;
        for i in 0..k {
            for j in 0..k {
                let (x, y) = disk_grid_point(i, j, k);
                let r2 = x * x + y * y;
                assert!(r2 <= 1.0 + 1e-15);
                within_half += usize::from(r2 < 0.25);
            }
        }
        let share = within_half as f64 / (k * k) as f64;
        assert!((share - 0.25).abs() < 2e-3, "{share}");
        assert_eq!(disk_grid_point(0, 0, 1), (0.0, 0.0));
    }

    #[test]
    fn everything_visible_is_exactly_one() {
        let s = shadowing(&Unoccluded, 8);
        let n = DVec3::new(0.2, 0.9, 0.1).normalize();
        assert_eq!(sun_visible_fraction(&s, n, DVec3::new(0.3, 1.0, 0.5).normalize(), 0.0093), 1.0);
        assert_eq!(disk_visible_fraction(&s, DVec3::ZERO, n, DVec3::new(0.3, 2.0, 0.0), -DVec3::Y, 0.7), 1.0);
        assert_eq!(sky_visible_fraction(&s, n), 1.0);
    }

    #[test]
    fn sun_fraction_converges_to_the_circular_segment() {
        // A straight edge overhead at x = e blocks the part of the sun's disk with x' < e: for a sun at the
        // zenith and a horizontal receiver the blocked fraction is the circular segment's share of the disk, by
        // the projected offset h = e / height in units of the disk's radius tan σ (cos³ and n·ω are 1 to 1e-5).
        let delta = 10f64.to_radians();
        let radius = (0.5 * delta).tan();
        for offset in [-0.5f64, 0.0, 0.3, 0.8] {
            let occ = HalfPlane { height: 1.0, edge: offset * radius };
            let c = offset;
            // Visible: the part of the unit disk with x > c: (acos c − c √(1 − c²)) / π.
            let want = (c.acos() - c * (1.0 - c * c).sqrt()) / PI;
            let mut last_err = f64::INFINITY;
            for k in [8, 32, 128] {
                let got = sun_visible_fraction(&shadowing(&occ, k), DVec3::Y, DVec3::Y, delta);
                let err = (got - want).abs();
                assert!(err < last_err.max(1e-4), "offset {offset}, k {k}: {got} vs {want}");
                last_err = err;
            }
            assert!(last_err < 2e-3, "offset {offset}: error {last_err}");
        }
    }

    #[test]
    fn sky_fraction_of_a_half_plane_wall() {
        // A horizontal point under an infinite half-plane roof {y = 1, x < 0} sees exactly half the sky.
        let occ = HalfPlane { height: 1.0, edge: 0.0 };
        let got = sky_visible_fraction(&shadowing(&occ, 64), DVec3::Y);
        assert!((got - 0.5).abs() < 5e-3, "{got}");
    }

    #[test]
    fn terminator_offset_lifts_points_onto_the_smooth_surface() {
        // A flat triangle (all normals the face's) is only pushed by the offset; a triangle whose normals fan
        // out (a facet of a sphere) lifts its interior above the plane.
        let p = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 0.0, -1.0)];
        let flat = [DVec3::Y; 3];
        let x = DVec3::new(0.25, 0.0, -0.25);
        let b = [0.5, 0.25, 0.25];
        let o = shadow_ray_origin(&p, &flat, b, x, DVec3::Y);
        assert_eq!(o, x + DVec3::Y * ray_offset(&p));
        let fan = [
            DVec3::new(-0.3, 1.0, 0.3).normalize(),
            DVec3::new(0.3, 1.0, 0.3).normalize(),
            DVec3::new(-0.3, 1.0, -0.3).normalize(),
        ];
        let o = shadow_ray_origin(&p, &fan, b, x, DVec3::Y);
        assert!(o.y > 10.0 * ray_offset(&p), "{o}");
        // At a vertex nothing moves but the push.
        let o = shadow_ray_origin(&p, &fan, [1.0, 0.0, 0.0], p[0], fan[0]);
        assert!((o - p[0]).length() <= 1.01 * ray_offset(&p));
    }
}

//! Visibility of the lights: `E = ∫ V(x, l) L(x, l) (n·l) dΩ`, where `V` is 0 for the directions an occluder
//! blocks. Mirrored by `shaders/visibility.glsl` name for name: the same sample grids, the same ray origins and
//! the same ray extents, so that the GPU's ray queries and the reference's rays differ only at rays that graze an
//! occluder's edge.
//!
//! **Diffuse part.** Each light's exact unoccluded irradiance (`radiometry`) is scaled by the light's *visible
//! fraction*: the cosine-weighted fraction of its directions that reach it, `V = ∫ w v / ∫ w` over the light,
//! `w` the weight of a direction (below) and `v` whether its shadow ray gets through, on a grid set by
//! `--shadow-samples` (`k²`). Where every ray gets through the two sums are the same additions in the same order,
//! so `V` is exactly 1 and the pixel is bitwise its unshadowed value.
//! - sun: the cap of half-angle `σ = δ/2` about `l`, through the disk of radius `tan σ` one unit away along `l`;
//!   `w = (n·ω)⁺ cos³γ` (`cos³γ`: solid angle per unit area of that disk, γ the angle from `l`);
//! - disk light: points of the disk, `w = (n·ω)⁺ (−d·ω)⁺ / |y − x|²` (projected solid angle per area);
//! - sky: the lune of directions above both the ground's horizon (`ω_y > 0`) and the surface's ([`SkyLune`]), in
//!   its angles `(β, ψ)`; `w = (n·ω) sin β` (projected solid angle per `dβ dψ`).
//!
//! The grids live on the unit square, mapped to the light: the sun's and disk lights' to the unit disk by Shirley &
//! Chiu's concentric map (equal-area, low distortion; "A Low Distortion Map Between Disk and Square", 1997), turned
//! by a small angle in the light's frame ([`turned`]), the sky's linearly to its lune's angles. They cast rays at
//! the `(k + 1)²` corners of `k²` squares and *locate* the edges of the shadows between disagreeing corners by
//! bisection, each square adding its visible share (marching squares): second order in `1/k` through a penumbra
//! (`grid_fraction`). With k = 1 one ray, through the light's centre (2⁻¹⁰ of its radius off it, [`turned`]): a
//! hard shadow. The reference can take the fractions by slices instead (`sky_slices`, `sun_slices`,
//! `disk_slices`, `reference --visibility`), exact along one angle, for a truth that the grid converges on too
//! slowly in penumbrae.
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

use crate::scene::Light;

/// Default side of the visibility grids, `k = 6` (`--shadow-samples 36`): the sun and disk lights cast `(k + 1)² = 49`
/// rays a pixel (up to 85 in a penumbra, locating its edges), the sky 30 (25 on a floor: its lune's sides of zero
/// weight cast none; up to 66 with its edges). Chosen by measurement
/// (sunset.glb, 96 × 72, against 64²): located 6² errs 4.3e-3 (max relative), where a count of 8²
/// midpoints errs 2.6e-2 and 16² 5.9e-3; at 256² on the system
/// lavapipe's BVH walk located 6² renders teapot.glb and sunset.glb in 3.1–3.3 s and 5.4 s, the old 8² in 4.0–4.9 s
/// and 6.7–6.8 s. Shadow maps filter on the same grid (PCSS, `k²` taps).
pub const DEFAULT_SHADOW_SAMPLES_PER_AXIS: u32 = 6;

/// How the reference takes the lights' visible fractions where it casts rays (`reference --visibility`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum VisibilityRule {
    /// The located grid of shadow rays the GPU casts too (`grid_fraction`; second order, `--shadow-samples`).
    #[default]
    Grid,
    /// Slices exact along one angle of the light (`sky_slices`, `sun_slices`, `disk_slices`; second order with 4
    /// rows a grid ray, no rays): the converged reference's, where every occluder is opaque. No GPU mirror.
    Slices,
}

impl VisibilityRule {
    /// Its name on the command line and in images' metadata.
    pub fn name(self) -> &'static str {
        match self {
            VisibilityRule::Grid => "grid",
            VisibilityRule::Slices => "slices",
        }
    }
}

impl std::str::FromStr for VisibilityRule {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "grid" => Ok(VisibilityRule::Grid),
            "slices" => Ok(VisibilityRule::Slices),
            _ => Err(format!("'{s}' is not a visibility rule (grid, slices)")),
        }
    }
}

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

/// Default side of the sun's shadow map \[texels\] (`--shadow-map-size`; GPU, `--shadows map`).
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

    /// Calls `visit` with (at least) every occluding triangle (corners \[m\]) that a point's slices of a light can
    /// meet ([`SliceReach`]: within its half-spaces, cone and near side) and returns true; false, visiting nothing,
    /// where the occluders are not all opaque triangles (then the caller casts rays).
    fn slice_triangles(&self, reach: &SliceReach, visit: &mut dyn FnMut([DVec3; 3])) -> bool {
        let _ = (reach, visit);
        false
    }

    /// These occluders for the many rays of one point that all leave within `reach`'s cone and half-spaces (a
    /// light's grid): where they can, the few triangles those rays can meet, gathered once, which answer each such
    /// ray as the whole would (and pass any other ray to the whole); `None` keeps the whole.
    fn narrowed(&self, reach: &SliceReach) -> Option<Box<dyn Occlusion + '_>> {
        let _ = reach;
        None
    }
}

/// What the slices of a light (`sky_slices`, `sun_slices`, `disk_slices`) from the rays' origin `origin` \[m\] can
/// meet: the half-spaces `k·(x − origin) > 0` (`above`: the sky's and the surface's sides, or the light's), the
/// light's cone and its near side, outside which nothing can block a direction that counts. One walk a point
/// gathers what lies within (`slice_buckets`), which each row then cuts.
#[derive(Clone, Copy, Debug)]
pub struct SliceReach {
    pub origin: DVec3,
    pub above: [DVec3; 2],
    /// A cone of directions from `origin` outside which nothing counts (the sun's disk, a disk light's bounding
    /// sphere), if any: its unit axis and the cosine and sine of its half-angle.
    pub cone: Option<(DVec3, f64, f64)>,
    /// A half-space `k·(x − origin) > b` (`(k, b)`) that a triangle must reach into to count (the near side of
    /// a disk light, where its rays end), if any.
    pub beyond: Option<(DVec3, f64)>,
    /// One row's half-plane `{s c + t p : t ≥ 0}` through `origin` (`(p, m)`, `m` the plane's unit normal), if the
    /// walk is for one row only (the GPU's sky, a walk a row: `sky_slices::sky_rows_weights`).
    pub row: Option<(DVec3, DVec3)>,
}

/// Nothing occludes anything.
pub struct Unoccluded;

impl Occlusion for Unoccluded {
    fn occluded(&self, _: DVec3, _: DVec3, _: f64) -> bool {
        false
    }

    fn slice_triangles(&self, _: &SliceReach, _: &mut dyn FnMut([DVec3; 3])) -> bool {
        true
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

/// Rows of a light's slices (the sky's, the sun's, a disk's) for a shadow-ray grid of `k²`: `4 k²` (each row
/// cutting the triangles its bucket holds, `slice_buckets`, costing about what a ray does); refining `k → ⌈k√2⌉`
/// at least doubles them, as it does every grid's count.
pub fn slice_rows(k: u32) -> u32 {
    4 * k.max(1).saturating_mul(k.max(1))
}

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
    /// The rays' origin \[m\] ([`shadow_ray_origin`]).
    pub origin: DVec3,
    pub occluders: &'a dyn Occlusion,
    /// Samples per axis of the visible-fraction grids.
    pub samples_per_axis: u32,
    /// The lights these rays shadow; the others are unoccluded.
    pub lights: ShadowedLights,
    /// Whether the lights' visible fractions are taken by slices (`sky_slices`, `sun_slices`, `disk_slices`: the
    /// reference's exact-in-one-angle rule) where the occluders allow it, rather than by the located grids the
    /// GPU mirrors.
    pub slices: bool,
}

impl<'a> Shadowing<'a> {
    /// A light's visible fraction by slices (`sliced`, given the rows, `slice_rows` of the grid's
    /// count), where `slices` asks for it; `None` where it does not or the occluders cannot be sliced (then the
    /// caller takes the grid).
    pub fn by_slices(&self, sliced: impl FnOnce(u32) -> Option<f64>) -> Option<f64> {
        self.slices.then(|| sliced(slice_rows(self.samples_per_axis))).flatten()
    }

    /// These rays for `light`, if the render shadows it.
    pub fn for_light(&self, light: Light) -> Option<&Self> {
        match light {
            Light::Sun(_) => self.for_sun(),
            Light::Disk { index, .. } => self.for_disk(index),
            Light::Sky(_) => self.for_sky(),
        }
    }

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

    /// Whether the point `target` \[m\] (on a disk light) is unblocked.
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

/// `cos θ` and `sin θ` of the turn of the sun's and disk lights' grids in their disks ([`turned`]): `θ = 2⁻⁶` rad.
pub const GRID_TURN_COS: f64 = 0.9998779321710066;
pub const GRID_TURN_SIN: f64 = 0.015624364224883372;

/// A point of the unit disk turned by `θ` ([`GRID_TURN_COS`]): where the sun's and disk lights' grid samples lie.
///
/// Why turned: unturned, the concentric map puts a grid's middle row and column on the axes of the light's frame,
/// which for a light along a coordinate axis are coordinate axes too, and its other samples at rational
/// coordinates in that frame. In a scene built on a grid (boxes at whole or dyadic coordinates, an orthographic
/// camera whose pixel centres are dyadic) such rays meet occluders' edges exactly, along whole lines of pixels,
/// where f32 and f64 then decide the edge differently (the touching blocks of tests/shadows.rs under a low disk
/// light). Turned by an angle whose sine and cosine are no small fractions, a sample meets such an edge only by
/// chance: it moves by `θρ` off its aligned place (`ρ` its distance from the centre), some 2⁻⁸ of the light's
/// radius for the corners of 6² nearest the centre (`ρ = 1/3`), 2⁻¹¹ for the nearest bisections, far above f32's
/// reach of an edge. The angle is small so that the rows stay
/// nearly parallel to the edges of such a scene, along which the located grid is most accurate (an edge along a
/// row is located exactly; a large turn makes every such edge oblique to the rows:
/// `tolerance_estimates_a_penumbra_against_its_circular_segment`). The light's centre, the turn's fixed point and
/// a corner of every even grid (its single ray where k = 1), is moved off it by [`GRID_CENTRE_SHIFT`] of the
/// radius along the turned axis: the user's light centre and a gridded scene line up as readily as the axes do.
/// Moving one sample by that much changes the located grid's estimate only where an edge passes between the two
/// places, by a sliver of some `2⁻¹⁰/k` of the disk, far below the grid's own error.
pub fn turned((x, y): (f64, f64)) -> (f64, f64) {
    if x == 0.0 && y == 0.0 {
        return (GRID_CENTRE_SHIFT * GRID_TURN_COS, GRID_CENTRE_SHIFT * GRID_TURN_SIN);
    }
    (GRID_TURN_COS * x - GRID_TURN_SIN * y, GRID_TURN_SIN * x + GRID_TURN_COS * y)
}

/// How far off the light's centre [`turned`] puts the grid's sample there, in the disk's radii: `2⁻¹⁰`.
pub const GRID_CENTRE_SHIFT: f64 = 1.0 / 1024.0;

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
#[derive(Clone, Copy)]
enum SampleRay {
    Along(DVec3),
    To(DVec3),
}

/// Whether a grid sample's shadow ray reaches its light.
fn sample_visible(s: &Shadowing, ray: SampleRay) -> bool {
    match ray {
        SampleRay::Along(omega) => s.visible_along(omega),
        SampleRay::To(y) => s.visible_to(y),
    }
}

/// What a visible-fraction grid samples: the light and the receiving point's frame (mirrored by the shaders'
/// `VisibilityLight`).
pub(crate) enum GridLight {
    /// The sun's cap: receiver normal `n`, direction `l`, frame `(t, b)` about it, disk radius `tan σ`.
    Sun { n: DVec3, l: DVec3, t: DVec3, b: DVec3, radius: f64 },
    /// A disk light seen from `x` with normal `n`: centre [m], emission direction `d`, frame `(a, b)`, radius [m].
    Disk { x: DVec3, n: DVec3, center: DVec3, d: DVec3, a: DVec3, b: DVec3, radius: f64 },
    /// The sky seen from a surface: its lune ([`SkyLune`]).
    Sky(SkyLune),
}

impl GridLight {
    /// The weight and shadow ray of the point `(u, v)` of the unit square: the sun's and disk lights' through
    /// [`concentric_disk`], [`turned`], the sky's through its lune's map.
    fn light_sample(&self, (u, v): (f64, f64)) -> (f64, SampleRay) {
        match *self {
            GridLight::Sun { n, l, t, b, radius } => {
                let (omega, w) = sun_sample(n, l, t, b, radius, turned(concentric_disk(u, v)));
                (w, SampleRay::Along(omega))
            }
            GridLight::Disk { x: at, n, center, d, a, b, radius } => {
                let (target, w) = disk_sample(at, n, center, d, a, b, radius, turned(concentric_disk(u, v)));
                (w, SampleRay::To(target))
            }
            GridLight::Sky(lune) => {
                let (omega, w) = sky_sample(&lune, (u, v));
                (w, SampleRay::Along(omega))
            }
        }
    }
}

/// The largest `k` of the located grid on the GPU (`grid_fraction`; `MAX_LOCATED_GRID` in
/// shaders/visibility.glsl): the shader keeps two columns of `k + 1` corners in arrays of a fixed size. The
/// reference has no such limit.
pub const MAX_LOCATED_GRID: u32 = 256;

/// Bisection steps that place a visibility edge between two neighbouring corners of a grid (`grid_fraction`):
/// `⌈log₂ k⌉` (at least 1), so that the edge's position error, at most a side `1/k` over `2^(steps+1)`, stays
/// below `1/(2k²)`: of the second order in `1/k`, like the rest of the estimate. Measured on the straight edges of
/// `located_edges_converge_at_second_order`, worst over 16 edges at 16², 32², 64²: 1.2e-3, 1.6e-4, 9.0e-5 (one step
/// more: 1.0e-3, 1.4e-4, 8.6e-5; one fewer: 1.8e-3, 2.9e-4, 1.0e-4).
pub fn edge_bisections(k: u32) -> u32 {
    (32 - k.saturating_sub(1).leading_zeros()).max(1)
}

/// How many edge crossings one grid locates: `2k`, what one straight edge across the light can make (it crosses
/// at most `k` lines of each family). Past that (a light crossed by several edges, a soup of small occluders), a
/// crossing is drawn through the side's midpoint without rays, so that a pixel's rays stay within
/// `(k + 1)² + 2k ⌈log₂ k⌉`: a cost known in advance (and llvmpipe's loop budget, src/gpu/loop_budget.rs, kept).
pub fn max_located_crossings(k: u32) -> u32 {
    2 * k
}

/// A corner of a located grid: its weight, whether its ray got through, and the crossing along v to the corner
/// above it (its parameter from this corner; read only where the two disagree).
#[derive(Clone, Copy, Default)]
struct Corner {
    w: f64,
    seen: bool,
    up: f64,
}

/// Whether the side between two neighbouring corners needs its crossing: both have weight and they disagree.
/// (The shader passes the neighbour's weight signed by its state.)
fn disagrees(w: f64, seen: bool, neighbour_w: f64, neighbour_seen: bool) -> bool {
    w > 0.0 && neighbour_w > 0.0 && seen != neighbour_seen
}

/// Where a visibility edge crosses the segment from one grid sample to its neighbour, found by `steps` bisections:
/// its parameter in (0, 1) from the first sample. `visible_at(t)` casts the ray of the segment's point `t`;
/// `first_seen` is the first sample's state.
fn locate_edge(steps: u32, first_seen: bool, visible_at: &dyn Fn(f64) -> bool) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..steps {
        let mid = 0.5 * (lo + hi);
        if visible_at(mid) == first_seen {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The visible share of the square between four grid samples, the marching-squares polygon: its corners
/// `(0,0), (1,0), (1,1), (0,1)` (visible or not) and, on each side whose two corners disagree, the edge's crossing
/// (`bottom` and `top` at x = their value, `left` and `right` at y = theirs), joined by straight lines; the area
/// by the shoelace formula. Exact for a straight edge; for a curved one off by the square's sagitta, second order.
/// Where the two diagonals disagree (a saddle: two corners visible, across from each other) the walk keeps them
/// joined through the middle, one of the two readings, as a grid that cannot see inside the square must choose.
pub fn cell_visible_area(seen: [bool; 4], bottom: f64, right: f64, top: f64, left: f64) -> f64 {
    // seen: (0,0), (1,0), (1,1), (0,1), counter-clockwise.
    if seen.iter().all(|&x| x) {
        return 1.0;
    }
    if !seen.iter().any(|&x| x) {
        return 0.0;
    }
    let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let crossings = [(bottom, 0.0), (1.0, right), (top, 1.0), (0.0, left)];
    let mut points = [(0.0, 0.0); 8];
    let mut count = 0;
    for c in 0..4 {
        if seen[c] {
            points[count] = corners[c];
            count += 1;
        }
        if seen[c] != seen[(c + 1) % 4] {
            points[count] = crossings[c];
            count += 1;
        }
    }
    let mut twice = 0.0;
    for p in 0..count {
        let (a, b) = (points[p], points[(p + 1) % count]);
        twice += a.0 * b.1 - b.0 * a.1;
    }
    0.5 * twice
}

/// `∫ w V / ∫ w` over the unit square mapped to the light ([`GridLight::light_sample`]) ([`fraction`]):
/// `w` a direction's weight, `V` its ray's visibility. `k = 1`: the ray through the light's centre alone (2⁻¹⁰ of its
/// radius off it, [`turned`]), a hard shadow. Otherwise the `(k + 1)²` corners of a `k × k` grid of squares cast their rays (none where the weight is
/// not positive), and each square adds the mean of its corners' weights times its visible share.
///
/// **Edges located, areas by marching squares.** Counting each square as wholly visible or blocked by a sample
/// converges at first order: an occluder's edge moves the count a whole square's weight at a time. Here, where two
/// neighbouring corners of positive weight disagree, the edge between them is located by [`edge_bisections`] rays
/// ([`locate_edge`]), and the square's visible share is the polygon the edge cuts off, drawn straight between its
/// crossings ([`cell_visible_area`]). An edge's preimage under the map is smooth (inside each of the concentric
/// map's four sectors), so the share is second order in `1/k` (the idea of line sampling, Billen & Dutré, "Line Sampling for
/// Direct Illumination", CGF 35(4), 2016, with the crossings found by rays alone). The grid's corners lie on the
/// light's rim, so a sliver of light left at the rim (a penumbra's dark end) is seen as soon as it spans a side.
/// A square with a corner of zero weight (the light cut by the horizon: the weights' business) counts its corners,
/// a quarter each. An occluder thinner than the spacing can still pass between the rays unseen.
///
/// The sums run in a fixed order and add the same weights to `visible` and `total`, so a wholly visible light is
/// exactly 1 and a wholly blocked one exactly 0: only penumbrae see the grid.
pub(crate) fn grid_fraction(s: &Shadowing, light: &GridLight) -> f64 {
    let k = s.samples_per_axis as usize;
    if k <= 1 {
        let (w, ray) = light.light_sample((0.5, 0.5));
        return fraction(if w > 0.0 && sample_visible(s, ray) { w } else { 0.0 }, w);
    }
    let kf = k as f64;
    let steps = edge_bisections(s.samples_per_axis);
    let ray_at = |u: f64, v: f64| sample_visible(s, light.light_sample((u / kf, v / kf)).1);
    // Crossings left to locate; past them a crossing is the side's midpoint.
    let mut left = max_located_crossings(s.samples_per_axis);
    let mut locate = |first_seen: bool, at: &dyn Fn(f64) -> bool| {
        if left == 0 {
            return 0.5;
        }
        left -= 1;
        locate_edge(steps, first_seen, at)
    };
    let (mut visible, mut total) = (0.0, 0.0);
    // The previous column of corners and this one's.
    let (mut prev, mut cur) = (vec![Corner::default(); k + 1], vec![Corner::default(); k + 1]);
    for i in 0..=k {
        let u = i as f64;
        // The crossing along u from the previous column's corner j − 1 to this column's.
        let mut across_below = 0.0;
        for j in 0..=k {
            let v = j as f64;
            let (w, ray) = light.light_sample((u / kf, v / kf));
            let seen = w > 0.0 && sample_visible(s, ray);
            cur[j] = Corner { w, seen, up: 0.0 };
            if j > 0 && disagrees(w, seen, cur[j - 1].w, cur[j - 1].seen) {
                cur[j - 1].up = locate(cur[j - 1].seen, &|t| ray_at(u, v - 1.0 + t));
            }
            let mut across = 0.0;
            if i > 0 && disagrees(w, seen, prev[j].w, prev[j].seen) {
                across = locate(prev[j].seen, &|t| ray_at(u - 1.0 + t, v));
            }
            if i > 0 && j > 0 {
                // The square with corners (i − 1, j − 1), (i, j − 1), (i, j), (i − 1, j), counter-clockwise in (u, v).
                let corners = [prev[j - 1], cur[j - 1], cur[j], prev[j]];
                if corners.iter().all(|c| c.w > 0.0) {
                    let mean = 0.25 * (corners[0].w + corners[1].w + corners[2].w + corners[3].w);
                    total += mean;
                    let seen4 = corners.map(|c| c.seen);
                    visible += mean * cell_visible_area(seen4, across_below, cur[j - 1].up, across, prev[j - 1].up);
                } else {
                    for c in corners.iter().filter(|c| c.w > 0.0) {
                        total += 0.25 * c.w;
                        if c.seen {
                            visible += 0.25 * c.w;
                        }
                    }
                }
            }
            across_below = across;
        }
        std::mem::swap(&mut prev, &mut cur);
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
/// `y` \[m\] and its weight `(n·ω)⁺ (−d·ω)⁺ / |y − x|²` from `x` (0 where either cosine is not positive). Shared by
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

/// The sky above a surface, as a located grid samples it: the lune of directions above both the ground's horizon
/// (`ω_y > 0`) and the surface's (`n·ω > 0`). Both horizons are great circles through the horizontal axis `a ⊥ n`,
/// so the lune is `ω(β, ψ) = cos β a + sin β (cos ψ e + sin ψ ŷ)` for `β ∈ [0, π]` (the angle from `a`) and
/// `ψ ∈ [0, width]` (from the ground's horizon towards the surface's), `e` the horizontal unit vector towards
/// which `n` leans, `width = π − tilt` (the surface's tilt from up). Then `n = sin(tilt) e + cos(tilt) ŷ` and
/// `n·ω = sin β sin(ψ + tilt) = sin β sin(width − ψ)`.
#[derive(Clone, Copy, Debug)]
pub struct SkyLune {
    /// The lune's axis `a` (horizontal, perpendicular to `n`).
    pub a: DVec3,
    /// The horizontal unit vector `e` towards which `n` leans (any one perpendicular to `a` for a floor).
    pub e: DVec3,
    /// The surface's tilt from up \[rad\].
    pub tilt: f64,
}

impl SkyLune {
    /// The lune's width `π − tilt` \[rad\].
    pub fn width(&self) -> f64 {
        PI - self.tilt
    }
}

/// The sky's lune above a surface of unit normal `n` ([`SkyLune`]). The tilt is `atan2(|n − n_y ŷ|, n_y)`, which
/// keeps its digits for surfaces nearly facing up or down (an `acos(n_y)` would lose half of them there). A floor
/// (`n − n_y ŷ = 0`) takes `e = x̂`: its lune is the whole hemisphere, and any `a` bounds it.
pub fn sky_lune(n: DVec3) -> SkyLune {
    let across = DVec3::new(n.x, 0.0, n.z);
    let len = across.length();
    let e = if len > 0.0 { across / len } else { DVec3::X };
    let tilt = len.atan2(n.y);
    SkyLune { a: e.cross(DVec3::Y), e, tilt }
}

/// The sky's sample at the point `(u, v)` of the unit square: the direction `ω(β = πv, ψ = width·u)` of its lune and
/// the weight `(n·ω) sin β`, projected solid angle per `dβ dψ` (the area element of the sphere is `sin β dβ dψ`),
/// as `sin²β sin(ψ + tilt)` ([`SkyLune`]). `ψ + tilt` and `width (1 − u) = π − ψ − tilt` have the same sine, and the
/// smaller of the two is taken: a sine near π would keep π's rounding (1.2e-16 instead of 0 on the surface's
/// horizon, where a floor's rays would then graze it), near 0 it is exact. So the weight is exactly 0 on the
/// surface's horizon (`u = 1`; for a floor, `u = 0` too) and at the lune's ends (`β = 0, π`, no rays there), and
/// never negative.
pub fn sky_sample(lune: &SkyLune, (u, v): (f64, f64)) -> (DVec3, f64) {
    // sin β as sin(π min(v, 1 − v)), exactly 0 at both ends (sin(π) would be 1.2e-16).
    let sin_b = (PI * v.min(1.0 - v)).sin();
    let cos_b = (PI * v).cos();
    let width = lune.width();
    let psi = width * u;
    let (sin_p, cos_p) = psi.sin_cos();
    let omega = cos_b * lune.a + sin_b * (cos_p * lune.e + sin_p * DVec3::Y);
    (omega, sin_b * sin_b * (psi + lune.tilt).min(width * (1.0 - u)).sin())
}

/// The push along the face normal for a triangle with these corners \[m\]: `2⁻¹⁶ max |pᵢ|∞` (see the module docs).
pub fn ray_offset(corners: &[DVec3; 3]) -> f64 {
    let m = corners.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
    RAY_OFFSET_RELATIVE * m
}

/// The origin of the shadow rays from the point with barycentrics `b` of the triangle with corners `p` \[m\],
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

/// Shadow rays from `origin` against `occ` on `k²` grids for every light, by the grids (tests).
#[cfg(test)]
pub(crate) fn test_shadowing(occ: &dyn Occlusion, origin: DVec3, k: u32) -> Shadowing<'_> {
    Shadowing { origin, occluders: occ, samples_per_axis: k, lights: ShadowedLights::ALL, slices: false }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::lights::{disk::disk_visible_fraction, sky::sky_visible_fraction, sun::sun_visible_fraction};

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

    fn shadowing(occ: &dyn Occlusion, k: u32) -> Shadowing<'_> {
        test_shadowing(occ, DVec3::ZERO, k)
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
        // the projected offset h = e / height in units of the disk's radius tan σ, for the real sun (0.53°: its
        // weights cos³γ n·ω are 1 to 4e-5; a 10° sun's vary by 1%, which the segment's share does not hold).
        let delta = 0.53f64.to_radians();
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
    fn located_edges_converge_at_second_order() {
        // The circular segment of sun_fraction_converges_to_the_circular_segment under a sun small enough (0.1°)
        // that its weights are uniform to 1e-6, edges at several angles to the grid and offsets from the centre
        // (0.9: a sliver at the rim, a penumbra's dark end): the worst error stays under 0.5/k², second order
        // (measured 9.4e-4, 1.1e-4, 8.5e-5; the plain count of the k² midpoints, 6.8e-3, 1.9e-3, 1.5e-3).
        let delta = 0.1f64.to_radians();
        let radius = (0.5 * delta).tan();
        struct Rotated(f64, f64);
        impl Occlusion for Rotated {
            fn occluded(&self, o: DVec3, d: DVec3, _: f64) -> bool {
                let t = (1.0 - o.y) / d.y;
                let p = o + t * d;
                t > 0.0 && p.x * self.0.cos() + p.z * self.0.sin() < self.1
            }
        }
        let mut worst = [0.0f64; 3];
        for angle in [0.0f64, 0.3, 0.7, 1.1] {
            for offset in [-0.6f64, 0.1, 0.45, 0.9] {
                let occ = Rotated(angle, offset * radius);
                let c = offset;
                let want = (c.acos() - c * (1.0 - c * c).sqrt()) / PI;
                for (slot, k) in [16u32, 32, 64].into_iter().enumerate() {
                    let got = sun_visible_fraction(&shadowing(&occ, k), DVec3::Y, DVec3::Y, delta);
                    worst[slot] = worst[slot].max((got - want).abs());
                }
            }
        }
        for (err, k) in worst.iter().zip([16.0, 32.0, 64.0]) {
            assert!(*err < 0.5 / (k * k), "{k}²: worst {worst:?}");
        }
    }

    #[test]
    fn marching_squares_areas_are_exact_for_straight_edges() {
        // One corner visible: the triangle of its two crossings; two adjacent: the trapezoid; three: the square
        // less the blocked corner's triangle; the saddle keeps its two visible corners joined through the middle.
        let close = |a: f64, b: f64| (a - b).abs() < 1e-15;
        assert!(close(cell_visible_area([true, false, false, false], 0.4, 0.0, 0.0, 0.5), 0.5 * 0.4 * 0.5));
        assert!(close(cell_visible_area([true, true, false, false], 0.0, 0.3, 0.0, 0.7), 0.5 * (0.3 + 0.7)));
        assert!(close(cell_visible_area([false, true, true, true], 0.6, 0.0, 0.0, 0.2), 1.0 - 0.5 * 0.6 * 0.2));
        let saddle = cell_visible_area([true, false, true, false], 0.5, 0.5, 0.5, 0.5);
        assert!(close(saddle, 1.0 - 2.0 * 0.125), "{saddle}");
        assert_eq!(cell_visible_area([true; 4], 0.3, 0.3, 0.3, 0.3), 1.0);
        assert_eq!(cell_visible_area([false; 4], 0.3, 0.3, 0.3, 0.3), 0.0);
        // Any straight line through the square: the share on one side by the polygon against a fine count.
        for (a, b, c) in [(1.0, 0.3, 0.6), (-0.4, 1.0, 0.1), (0.7, -0.7, 0.05), (0.2, 0.9, 0.5)] {
            let inside = |x: f64, y: f64| a * x + b * y > c;
            let cross = |p: (f64, f64), q: (f64, f64)| {
                let (fp, fq) = (a * p.0 + b * p.1 - c, a * q.0 + b * q.1 - c);
                fp / (fp - fq)
            };
            let seen = [inside(0.0, 0.0), inside(1.0, 0.0), inside(1.0, 1.0), inside(0.0, 1.0)];
            let got = cell_visible_area(
                seen,
                cross((0.0, 0.0), (1.0, 0.0)),
                cross((1.0, 0.0), (1.0, 1.0)),
                cross((0.0, 1.0), (1.0, 1.0)),
                cross((0.0, 0.0), (0.0, 1.0)),
            );
            let n = 2000;
            let count = (0..n * n)
                .filter(|i| {
                    inside((i % n) as f64 / n as f64 + 0.5 / n as f64, (i / n) as f64 / n as f64 + 0.5 / n as f64)
                })
                .count();
            let want = count as f64 / (n * n) as f64;
            assert!((got - want).abs() < 1e-3, "{a} {b} {c}: {got} vs {want}");
        }
    }

    /// An infinite roof `{y = 1, x cos θ + z sin θ < e}` over the origin: exact, for tests.
    struct Roof {
        edge: f64,
        cos: f64,
        sin: f64,
    }

    impl Occlusion for Roof {
        fn occluded(&self, o: DVec3, d: DVec3, _: f64) -> bool {
            if d.y <= 0.0 {
                return false;
            }
            let t = (1.0 - o.y) / d.y;
            (o.x + t * d.x) * self.cos + (o.z + t * d.z) * self.sin < self.edge
        }
    }

    #[test]
    fn sky_located_edges_converge_at_second_order() {
        // Roofs whose edges cross the sky's lune at several offsets and angles, over a floor (truth in closed form:
        // the visible directions ω·(cos θ, −e, sin θ) ≥ 0 project onto the floor as the unit disk less a half
        // ellipse of semi-axes |e|/√(1 + e²) and 1, so the fraction is ½ (1 − e/√(1 + e²))) and over two tilted
        // surfaces (truth: the same grid at 1024², whose error is four thousand times smaller than at 16² if it is
        // of the second order, as the floors show). Measured: error × k² at most 2.5 at 16², 32², 64²
        // (the steep surface's thin lune the largest); the count of k² midpoints it replaced was first order.
        for edge in [0.3, -0.7] {
            for theta in [0.0f64, 0.4, 1.1] {
                let occ = Roof { edge, cos: theta.cos(), sin: theta.sin() };
                for n in [DVec3::Y, DVec3::new(0.3, 1.0, 0.2).normalize(), DVec3::new(-0.8, 0.3, 0.2).normalize()] {
                    let truth = if n == DVec3::Y {
                        0.5 * (1.0 - edge / (1.0 + edge * edge).sqrt())
                    } else {
                        sky_visible_fraction(&shadowing(&occ, 1024), n)
                    };
                    for k in [16, 32, 64] {
                        let err = (sky_visible_fraction(&shadowing(&occ, k), n) - truth).abs();
                        assert!(err < 3.0 / (k * k) as f64, "edge {edge} θ {theta} n {n}: {err:e} at {k}²");
                    }
                }
            }
        }
    }

    #[test]
    fn sky_lune_weights_vanish_where_its_rays_would_graze() {
        // The lune's ends and the surface's horizon weigh exactly 0 (no rays there), the ground's horizon only on
        // a floor; a wholly visible sky is exactly 1 for any tilt.
        for n in [DVec3::Y, DVec3::new(0.3, 1.0, 0.2).normalize(), DVec3::new(-0.8, -0.3, 0.2).normalize()] {
            let lune = sky_lune(n);
            for i in 0..=8 {
                let t = i as f64 / 8.0;
                assert_eq!(sky_sample(&lune, (t, 0.0)).1, 0.0);
                assert_eq!(sky_sample(&lune, (t, 1.0)).1, 0.0);
                assert_eq!(sky_sample(&lune, (1.0, t)).1, 0.0);
                let (omega, w) = sky_sample(&lune, (0.5 * t + 0.25, 0.5));
                assert!(w > 0.0 && omega.y > -1e-15 && n.dot(omega) > 0.0, "{n} {t}: {omega} {w}");
            }
            assert_eq!(sky_sample(&lune, (0.0, 0.5)).1 == 0.0, n == DVec3::Y);
            assert_eq!(sky_visible_fraction(&shadowing(&Unoccluded, 6), n), 1.0);
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

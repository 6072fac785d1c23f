//! Outgoing radiance at a surface point: `L(x, l_out) = Σ_lights ∫ ρ(l_in, l_out) L(l_in) (n·l_in) dl_in`.
//!
//! Every BRDF is `kd/π + ks · lobe`. The Lambertian part needs only the irradiance, which every light gives
//! exactly ([`irradiance`]). The lobe is integrated per light (mirrored by `shaders/shade.glsl`, with the same
//! deterministic sample points, so that the GPU and the reference differ only by rounding):
//! - sun, delta model: `lobe(l_sun) · E⊥ · max(0, n·l_sun)`;
//! - sun, disk model: a stratified midpoint grid of `sun_samples²` directions over the sun's cap (polar angle β
//!   from its centre, weight `sin β dβ dφ`), radiance `L_sun = E⊥ / (π sin²(δ/2))`;
//! - disk light, exact model: a midpoint grid of `samples²` points over the part of the disk above the horizon
//!   (the segment coordinates of `lights::disk::segment_projected_solid_angle`), `dω = h dA / |y − x|³`; small-source
//!   model: the lobe towards the centre times the small-source projected solid angle;
//! - sky: `samples²` directions drawn by a stratified grid through each lobe's own inverse CDF (Phong: cos α about
//!   the mirror direction; Blinn-Phong and Ward: the half vector), so that lobe/pdf is constant or smooth and
//!   only the horizon is left to resolve; a measured table through Ward's, with the α of its peak. The sky is the
//!   upper hemisphere: the part of the surface's hemisphere below the horizontal is integrated on its own grid
//!   and taken out, or the part above is integrated directly (`sky_lune`).
//!
//! A measured table (`Brdf::Measured`) is split the same way: its floor is the Lambertian part, the rest its
//! "lobe", per channel ([`specular_lobe_rgb`]), through the same grids.
//!
//! Convergence in the sample counts is measured in docs/accuracy.md ("BRDFs").

use std::f64::consts::PI;

use glam::DVec3;

use super::brdf::{blinn_phong_lobe, lambert_brdf, mirror, phong_lobe, ward_lobe};
use super::lights::disk::{
    disk_geometry, disk_projected_solid_angle, disk_projected_solid_angle_small_source, disk_visible_fraction,
};
use super::lights::sky::{sky_irradiance, sky_lobe_integral_visible, sky_visible_fraction};
use super::lights::sun::{
    sun_irradiance_delta, sun_irradiance_disk, sun_projected_solid_angle_above, sun_visible_fraction,
};
use super::measured::measured_residual;
use super::visibility::{
    ShadowMapFilter, Shadowing, Shadows, DEFAULT_SHADOW_MAP_SIZE, DEFAULT_SHADOW_SAMPLES_PER_AXIS,
};
use crate::scene::{Brdf, Lights};

/// How the sun is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SunModel {
    /// A disk of angular diameter δ: exact irradiance (also while it sets); specular lobes integrated over it.
    #[default]
    Disk,
    /// A single direction: `E⊥ max(0, cos θ)`, lobes evaluated at the sun's centre.
    Delta,
}

/// How disk lights are evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DiskModel {
    /// The exact irradiance, horizon clipping included; lobes integrated over the disk.
    #[default]
    Exact,
    /// The small-source estimate `L0 A cosθ_r cosθ_d / d²`, lobes evaluated towards the centre.
    SmallSource,
}

/// The sun's model and grid for one material's surfaces (`RenderSettings::sun_per_material`): `--tolerance`
/// chooses the cheapest that meets its bound for each material's lobe, so that a wide lobe or a Lambertian surface
/// does not pay for the sharpest lobe's grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SunChoice {
    pub sun: SunModel,
    /// Grid side over the sun's disk (`SunModel::Disk`).
    pub sun_samples_per_axis: u32,
}

/// Default sample counts (per axis of the stratified grids).
pub const DEFAULT_SUN_SAMPLES_PER_AXIS: u32 = 8;
pub const DEFAULT_SAMPLES_PER_AXIS: u32 = 16;

/// Model choices for a render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadingOptions {
    pub sun: SunModel,
    pub disk: DiskModel,
    /// Grid side for integrating lobes over the sun's disk (`n²` directions).
    pub sun_samples_per_axis: u32,
    /// Grid side for integrating lobes over disk lights and the sky (`n²` samples each).
    pub samples_per_axis: u32,
    /// How shadows are computed.
    pub shadows: Shadows,
    /// Grid side of each light's visible-fraction grid (`n²` shadow rays per light and pixel).
    pub shadow_samples_per_axis: u32,
    /// Side of the sun's shadow map \[texels\] (`--shadows map`).
    pub shadow_map_size: u32,
    /// Its filter.
    pub shadow_map_filter: ShadowMapFilter,
    /// What the pixels hold: radiance, or the irradiance at the surface.
    pub quantity: super::Quantity,
    /// How the reference takes the lights' visible fractions (the GPU's grids, or slices).
    pub visibility_rule: super::visibility::VisibilityRule,
}

impl Default for ShadingOptions {
    fn default() -> Self {
        Self {
            sun: SunModel::Disk,
            disk: DiskModel::Exact,
            sun_samples_per_axis: DEFAULT_SUN_SAMPLES_PER_AXIS,
            samples_per_axis: DEFAULT_SAMPLES_PER_AXIS,
            shadows: Shadows::Auto,
            shadow_samples_per_axis: DEFAULT_SHADOW_SAMPLES_PER_AXIS,
            shadow_map_size: DEFAULT_SHADOW_MAP_SIZE,
            shadow_map_filter: ShadowMapFilter::Pcss,
            quantity: super::Quantity::Radiance,
            visibility_rule: super::visibility::VisibilityRule::Grid,
        }
    }
}

impl std::str::FromStr for SunModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "disk" => Ok(SunModel::Disk),
            "delta" => Ok(SunModel::Delta),
            _ => Err(format!("'{s}' is not a sun model (disk, delta)")),
        }
    }
}

impl std::str::FromStr for DiskModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "exact" => Ok(DiskModel::Exact),
            "small-source" => Ok(DiskModel::SmallSource),
            _ => Err(format!("'{s}' is not a disk model (exact, small-source)")),
        }
    }
}

/// A point on a surface, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Position \[m\].
    pub position: DVec3,
    /// Unit shading normal, on the side being seen; the zero vector where it is undefined (then nothing is
    /// reflected).
    pub normal: DVec3,
    /// Unit tangent (the αx direction), orthogonal to the normal.
    pub tangent: DVec3,
    /// Unit bitangent (the αy direction): `w (n × t)`.
    pub bitangent: DVec3,
    /// Unit vector towards the viewer.
    pub to_viewer: DVec3,
}

/// `v/|v|`, or the zero vector when `|v|²` is zero (or underflows) or is not finite, so that a degenerate normal
/// shades to 0 radiance instead of NaN.
pub fn safe_normalize(v: DVec3) -> DVec3 {
    let len2 = v.length_squared();
    if len2 > 0.0 && len2.is_finite() {
        v / len2.sqrt()
    } else {
        DVec3::ZERO
    }
}

/// A unit vector orthogonal to the unit vector `v` (Duff et al. 2017, "Building an Orthonormal Basis,
/// Revisited"), written out so that the shaders' `orthonormal_to` gives the same vector.
pub fn orthonormal_to(v: DVec3) -> DVec3 {
    let s = if v.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + v.z);
    let b = v.x * v.y * a;
    DVec3::new(b, s + v.y * v.y * a, -v.y)
}

/// Irradiance [W/m²] per channel at `point` from all the lights, unoccluded.
pub fn irradiance(point: &SurfacePoint, lights: &Lights, options: &ShadingOptions) -> [f64; 3] {
    irradiance_visible(point, lights, options, None)
}

/// Irradiance [W/m²] per channel at `point` from the visible part of every light: each light's exact
/// unoccluded irradiance times its visible fraction (`visibility`; a single ray for a delta sun and a
/// small-source disk). `None`: unoccluded.
pub fn irradiance_visible(
    point: &SurfacePoint,
    lights: &Lights,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> [f64; 3] {
    irradiance_and_sun_fraction(point, lights, options, shadow).0
}

/// [`irradiance_visible`] and the sun's visible fraction it took (1 without a sun, without shadows, or where the
/// sun's disk is wholly below the surface's horizon), which the specular part reuses: the GPU keeps it in a
/// global as `irradiance_visible` finds it (`sun_ray_fraction`, as `sun_map_fraction` for maps).
pub fn irradiance_and_sun_fraction(
    point: &SurfacePoint,
    lights: &Lights,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> ([f64; 3], f64) {
    let mut e = [0.0; 3];
    let mut sun_fraction = 1.0;
    if let Some(sun) = &lights.sun {
        let l = sun.direction.as_dvec3();
        let n_dot_l = point.normal.dot(l);
        let delta = sun.angular_diameter as f64;
        let mut unoccluded = [0.0; 3];
        for (ec, &perp) in unoccluded.iter_mut().zip(&sun.irradiance) {
            *ec = match options.sun {
                SunModel::Disk => sun_irradiance_disk(perp as f64, n_dot_l, delta),
                SunModel::Delta => sun_irradiance_delta(perp as f64, n_dot_l),
            };
        }
        let v = match shadow.and_then(Shadowing::for_sun) {
            Some(s) if unoccluded.iter().any(|&x| x > 0.0) => match options.sun {
                SunModel::Disk => sun_visible_fraction(s, point.normal, l, delta),
                SunModel::Delta => f64::from(u8::from(s.visible_along(l))),
            },
            _ => 1.0,
        };
        sun_fraction = v;
        for (ec, u) in e.iter_mut().zip(unoccluded) {
            *ec += u * v;
        }
    }
    for (i, disk) in lights.disks.iter().enumerate() {
        let g = disk_geometry(disk);
        let omega = match options.disk {
            DiskModel::Exact => disk_projected_solid_angle(point.position, point.normal, &g),
            DiskModel::SmallSource => disk_projected_solid_angle_small_source(point.position, point.normal, &g),
        };
        let v = match shadow.and_then(|s| s.for_disk(i)) {
            Some(s) if omega > 0.0 => match options.disk {
                DiskModel::Exact => {
                    disk_visible_fraction(s, point.position, point.normal, g.center, g.direction, g.radius)
                }
                DiskModel::SmallSource => f64::from(u8::from(s.visible_to(g.center))),
            },
            _ => 1.0,
        };
        let omega = omega * v;
        for (ec, &l0) in e.iter_mut().zip(&disk.radiance) {
            *ec += l0 as f64 * omega;
        }
    }
    if let Some(sky) = &lights.sky {
        let v = match shadow.and_then(Shadowing::for_sky) {
            Some(s) if point.normal.y > -1.0 => sky_visible_fraction(s, point.normal),
            _ => 1.0,
        };
        for (ec, &l0) in e.iter_mut().zip(sky) {
            *ec += sky_irradiance(l0 as f64, point.normal.y) * v;
        }
    }
    (e, sun_fraction)
}

/// The specular lobe of a material (without ks) per channel for light from `l`: the analytic lobes' one value in
/// each channel; a measured table's part above its floor ([`measured_residual`]).
pub fn specular_lobe_rgb(brdf: &Brdf, p: &SurfacePoint, l: DVec3) -> [f64; 3] {
    match brdf {
        Brdf::Measured { table, lookup } => measured_residual(table, *lookup, p.normal, l, p.to_viewer),
        _ => [specular_lobe(brdf, p, l); 3],
    }
}

/// A material's specular lobe (without ks) for light from `l` seen from `v` about the normal +z, tangent +x,
/// bitangent +y: the frame of the bounds' scans and of tabulated tables.
pub fn lobe_about_z(brdf: &Brdf, l: DVec3, v: DVec3) -> f64 {
    let p =
        SurfacePoint { position: DVec3::ZERO, normal: DVec3::Z, tangent: DVec3::X, bitangent: DVec3::Y, to_viewer: v };
    specular_lobe(brdf, &p, l)
}

/// The specular lobe of a material (without ks) for light from `l`; a measured table's, the mean of its
/// channels'.
pub fn specular_lobe(brdf: &Brdf, p: &SurfacePoint, l: DVec3) -> f64 {
    let (n, v) = (p.normal, p.to_viewer);
    match *brdf {
        Brdf::Lambert { .. } => 0.0,
        Brdf::Phong { exponent, .. } => phong_lobe(n, l, v, exponent as f64),
        Brdf::BlinnPhong { exponent, .. } => blinn_phong_lobe(n, l, v, exponent as f64),
        Brdf::Ward { alpha_x, alpha_y, .. } => {
            ward_lobe(n, p.tangent, p.bitangent, l, v, alpha_x as f64, alpha_y as f64)
        }
        Brdf::Measured { .. } => specular_lobe_rgb(brdf, p, l).iter().sum::<f64>() / 3.0,
    }
}

/// The angular width \[rad\] about a specular lobe's peak (the mirror direction of the viewer) over which the disk
/// integral crowds its samples: where the lobe falls to about `e^{-1/2}`. Phong's `cosᵉα` at `α ≈ 1/√e`;
/// Blinn-Phong's in the half vector, and ω turns twice as fast: `2/√e`; Ward's `exp(−tan²δ/α²)` at `δ = α/√2`,
/// `√2 α` in ω, taken as `2√(αx αy)` (the geometric mean measured better than either α on anisotropic lobes).
pub fn lobe_width(brdf: &Brdf) -> f64 {
    match *brdf {
        Brdf::Lambert { .. } => PI,
        Brdf::Phong { exponent, .. } => 1.0 / (exponent as f64 + 1.0).sqrt(),
        Brdf::BlinnPhong { exponent, .. } => 2.0 / (exponent as f64 + 1.0).sqrt(),
        Brdf::Ward { alpha_x, alpha_y, .. } => 2.0 * (alpha_x as f64 * alpha_y as f64).sqrt(),
        Brdf::Measured { ref table, .. } => table.lobe_width as f64,
    }
}

/// The point for `u ∈ (0, 1)` of a grid on `[a, b]` graded about `c` with width `w`: `x = c + w sinh z`, z uniform
/// between `asinh((a − c)/w)` and `asinh((b − c)/w)`, so the spacing is about `w Δz` within w of c and grows in
/// proportion to the distance beyond; returns x and its density `dx/du = w (zb − za) cosh z`. For w ≥ 16 (b − a)
/// it is uniform to 0.2%. (A Cauchy quantile `c + w tan θ` grades as well, but in f32 its θ near ±π/2 is
/// rounded to ~30 ulp of tan, and the GPU lost 1.8e-5 against the reference; sinh is conditioned by |z| ≤ 70.)
/// The ends `(za, zb)` come from [`sinh_warp_ends`], once per grid.
pub fn sinh_warp(a: f64, b: f64, c: f64, w: f64, (za, zb): (f64, f64), u: f64) -> (f64, f64) {
    let z = za + u * (zb - za);
    ((c + w * z.sinh()).clamp(a, b), w * (zb - za) * z.cosh())
}

/// How far a graded grid of width `w` on an interval of length `span` is blended towards the uniform grid:
/// 0 while `w ≤ 8 span` (graded), rising linearly to 1 at `w = 16 span` (uniform) and beyond. A wide lobe's
/// warp is uniform only to 0.2%, and that is enough to spoil what the uniform midpoint grid integrates exactly in
/// segment coordinates (the `sin²β` of the area element, and by symmetry every linear function of the disk's
/// points). The blend is continuous in w, so no sample jumps between the GPU and the reference.
pub fn uniform_blend(w: f64, span: f64) -> f64 {
    ((w / span - 8.0) / 8.0).clamp(0.0, 1.0)
}

/// A graded point `(x, dx/du)` of [`sinh_warp`] on `[a, b]` moved by `lambda` ([`uniform_blend`]) towards the
/// uniform grid's `(a + u (b − a), b − a)`; a mixture of two grids' densities is itself one.
pub fn blended_point(a: f64, b: f64, (x, dx): (f64, f64), lambda: f64, u: f64) -> (f64, f64) {
    (x + lambda * ((a + u * (b - a)) - x), dx + lambda * ((b - a) - dx))
}

/// One axis of a graded grid: `[a, b]` graded about c with width w ([`sinh_warp`]), with its warp's ends and its
/// blend towards the uniform grid over the span, computed once per grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GradedAxis {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub w: f64,
    pub ends: (f64, f64),
    pub blend: f64,
}

/// The graded axis on `[a, b]` about c with width w: [`sinh_warp_ends`] and [`uniform_blend`] over `b − a`.
pub fn graded_axis(a: f64, b: f64, c: f64, w: f64) -> GradedAxis {
    GradedAxis { a, b, c, w, ends: sinh_warp_ends(a, b, c, w), blend: uniform_blend(w, b - a) }
}

/// The axis' point `(x, dx/du)` for `u ∈ (0, 1)`: the graded point moved towards the uniform one by the blend
/// ([`sinh_warp`], [`blended_point`]).
pub fn graded_point(g: &GradedAxis, u: f64) -> (f64, f64) {
    blended_point(g.a, g.b, sinh_warp(g.a, g.b, g.c, g.w, g.ends, u), g.blend, u)
}

/// The ends of [`sinh_warp`]'s z range for the grid on `[a, b]` graded about c with width w:
/// `(asinh((a − c)/w), asinh((b − c)/w))`.
pub fn sinh_warp_ends(a: f64, b: f64, c: f64, w: f64) -> (f64, f64) {
    (((a - c) / w).asinh(), ((b - c) / w).asinh())
}

/// Which shadow rays a lobe integral's samples cast: none, along each sample's direction (a light at infinity:
/// the sun's cap, the sky), or to each sample's point on a disk light.
#[derive(Clone, Copy)]
pub enum SampleRays<'a> {
    Along(&'a Shadowing<'a>),
    ToPoint(&'a Shadowing<'a>),
}

impl SampleRays<'_> {
    /// Whether the sample at `y` (relative to the shading point `x`; a direction for `Along`) is visible.
    fn visible(&self, x: DVec3, y: DVec3, omega: DVec3) -> bool {
        match self {
            SampleRays::Along(s) => s.visible_along(omega),
            SampleRays::ToPoint(s) => s.visible_to(x + y),
        }
    }
}

/// `∫ lobe(ω) (n·ω)+ dω` over the part of a disk above the horizon, per unit radiance, for the disk of radius R
/// centred at `q` from the surface point emitting along the unit vector `d`: a midpoint grid over the
/// segment `β ∈ [0, α]`, `s ∈ [−1, 1]`, `y = C + R cos β w + R sin β s v`, `dω = h R² sin²β dβ ds / |y − x|³`.
///
/// A lobe much narrower than the disk would fall between the points of a uniform grid (a Phong lobe of e = 1e4
/// under the lecture's disk: 71% error on 16 × 16), so the grid is graded ([`sinh_warp`]) about the point where
/// the lobe's peak (the mirror direction of the viewer) meets the disk's plane, with the width of the lobe's
/// footprint there; for wide lobes it blends continuously into the uniform grid ([`uniform_blend`]). The integrand
/// stays smooth in the warped coordinates, so the midpoint rule keeps its 1/k² convergence, and everything is a
/// continuous function of the inputs: no sample switches on or off between the GPU and the reference.
pub fn segment_lobe_integral(
    brdf: &Brdf,
    p: &SurfacePoint,
    q: DVec3,
    d: DVec3,
    radius: f64,
    per_axis: u32,
) -> SegmentSums {
    segment_lobe_integral_visible(brdf, p, q, d, radius, per_axis, None)
}

/// The grid's sums over a disk: `∫ lobe(ω) (n·ω)+ dω` over its visible samples, the disk's projected solid angle
/// `∫ (n·ω)+ dω` over all of them (visible or not), each per unit radiance, and how uniform the grid was (the
/// smaller of its two [`uniform_blend`]s: 1 for a wide lobe's uniform grid, 0 for a narrow lobe's graded one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentSums {
    /// Per channel.
    pub lobe: [f64; 3],
    pub projected: f64,
    pub uniformity: f64,
}

/// The lobe integral with the grid's weights normalised, as far as the grid is uniform, so that they integrate
/// the cosine exactly: `lobe × (1 + uniformity (exact/projected − 1))`, `exact` the closed-form projected solid
/// angle of the disk's part above the horizon (a ratio estimator). A uniform grid's cosine quadrature errs where
/// the horizon cuts the disk (a circular segment is not what its `sin²β` rule is exact for); the ratio removes
/// that error, common to every smooth lobe, so that a constant lobe is exact and the error left follows the
/// lobe's variation over the disk. A graded grid crowds its samples about a narrow lobe and integrates the
/// cosine over the rest of the disk poorly, so there the ratio would add error (measured: Phong e = 1e5 under
/// the sun, 5.2e-3 instead of 4e-3 on 8²) and is not applied. Where every sample is visible the result is the
/// same as unoccluded; partly hidden disks keep their visible share of the grid.
pub fn normalized_lobe_integral(sums: SegmentSums, exact: f64) -> [f64; 3] {
    if sums.projected > 0.0 {
        sums.lobe.map(|lobe| lobe * (1.0 + sums.uniformity * (exact / sums.projected - 1.0)))
    } else {
        sums.lobe
    }
}

/// [`segment_lobe_integral`]'s sums with each sample's shadow ray (`rays`; `None`: unoccluded).
pub fn segment_lobe_integral_visible(
    brdf: &Brdf,
    p: &SurfacePoint,
    q: DVec3,
    d: DVec3,
    radius: f64,
    per_axis: u32,
    rays: Option<SampleRays>,
) -> SegmentSums {
    let n = p.normal;
    let h = -d.dot(q);
    let none = SegmentSums { lobe: [0.0; 3], projected: 0.0, uniformity: 0.0 };
    if !(h > 0.0 && radius > 0.0) {
        return none;
    }
    // Visible rim arc half-angle α about the in-plane direction w in which points rise above the horizon.
    let n_perp = n - n.dot(d) * d;
    let m = n_perp.length();
    let nq = n.dot(q);
    let (w, alpha) = if nq - radius * m >= 0.0 {
        (if m > 0.0 { n_perp / m } else { orthonormal_to(d) }, PI)
    } else if nq + radius * m <= 0.0 {
        return none;
    } else {
        let kappa = (-nq / (radius * m)).clamp(-1.0, 1.0);
        (n_perp / m, ((1.0 - kappa) * (1.0 + kappa)).sqrt().atan2(kappa))
    };
    let v = d.cross(w);
    // The lobe's peak on the disk's plane in segment coordinates (β*, s*). A peak direction parallel to the plane
    // or turned away from it is treated as one at a grazing 1e-6 (a point far out on the plane), so that the
    // centre moves continuously; the widths are then capped and the grid is nearly uniform.
    let r = mirror(p.to_viewer, n);
    let toward = r.dot(d).min(-1e-6);
    let t = h / -toward;
    let mut rel = t * r - q;
    // Footprint [m] of the lobe on the plane. A peak outside the disk leaves only the lobe's tail on it, which
    // falls off from the nearest rim point over footprint²/distance: crowd the grid there, that narrow.
    let mut footprint = t * lobe_width(brdf) / -toward;
    let off = rel.length();
    if off > radius {
        let outside = off - radius;
        footprint = footprint * footprint / (footprint + outside);
        rel *= radius / off;
    }
    let a = rel.dot(w) / radius;
    let beta_c = (if a >= 1.0 {
        0.0
    } else if a <= -1.0 {
        PI
    } else {
        ((1.0 - a) * (1.0 + a)).sqrt().atan2(a)
    })
    .min(alpha);
    let (sbc, cbc) = beta_c.sin_cos();
    let s_c = if sbc > 0.0 { (rel.dot(v) / (radius * sbc)).clamp(-1.0, 1.0) } else { 0.0 };
    // The footprint in units of the coordinates' rates |dy/dβ| and |dy/ds|.
    let rate_beta = radius * (sbc * sbc + cbc * cbc * s_c * s_c).sqrt();
    let width_beta = (footprint / rate_beta.max(1e-30)).min(16.0 * alpha);
    let width_s = (footprint / (radius * sbc).max(1e-30)).min(32.0);
    let k = per_axis as f64;
    let (mut sum, mut projected) = ([0.0; 3], 0.0);
    let (beta_axis, s_axis) = (graded_axis(0.0, alpha, beta_c, width_beta), graded_axis(-1.0, 1.0, s_c, width_s));
    for i in 0..per_axis {
        let u = (i as f64 + 0.5) / k;
        let (beta, d_beta) = graded_point(&beta_axis, u);
        let (sb, cb) = beta.sin_cos();
        for j in 0..per_axis {
            let u = (j as f64 + 0.5) / k;
            let (s, d_s) = graded_point(&s_axis, u);
            let y = q + radius * cb * w + radius * sb * s * v;
            let dist2 = y.length_squared();
            let dist = dist2.sqrt();
            let omega = y / dist;
            let cos = n.dot(omega);
            if cos > 0.0 {
                let weight = cos * h / (dist2 * dist) * radius * radius * sb * sb * d_beta * d_s;
                projected += weight;
                if rays.is_none_or(|r| r.visible(p.position, y, omega)) {
                    let lobe = specular_lobe_rgb(brdf, p, omega);
                    for (s, l) in sum.iter_mut().zip(lobe) {
                        *s += l * weight;
                    }
                }
            }
        }
    }
    SegmentSums {
        lobe: sum.map(|s| s / (k * k)),
        projected: projected / (k * k),
        uniformity: beta_axis.blend.min(s_axis.blend),
    }
}

/// `exp(x) − 1` without cancellation for small x (Kahan's trick: exact where `exp` and `ln` are accurate).
pub fn exp_minus_one(x: f64) -> f64 {
    let u = x.exp();
    if u == 1.0 {
        return x;
    }
    let um1 = u - 1.0;
    if um1 == -1.0 {
        return -1.0;
    }
    um1 * x / u.ln()
}

/// A direction at angle a from the unit `axis` with `cos a = (1 − ξ1)^{1/(e+1)}` and azimuth φ in the frame
/// (t, b) about it: the inverse CDF of the pdf `(e+1)/(2π) cosᵉa`. `1 − cos a` is formed as
/// `−expm1(ln(1 − ξ1)/(e+1))`: for large e the exponent is tiny and `1 − (1 − ξ1)^{1/(e+1)}` would cancel.
pub fn cos_power_direction(axis: DVec3, t: DVec3, b: DVec3, exponent: f64, xi1: f64, phi: f64) -> DVec3 {
    let one_minus_cos = -exp_minus_one((-xi1).ln_1p() / (exponent + 1.0));
    let cos_a = 1.0 - one_minus_cos;
    let sin_a = (one_minus_cos * (1.0 + cos_a)).sqrt();
    cos_a * axis + sin_a * (phi.cos() * t + phi.sin() * b)
}

/// The α of the Ward half-vector distribution that draws a measured table's sky samples: its peak width
/// `w` (2θ_h at e^{-1/2} of the peak) is Ward's `√2 α`, so `α = w/√2`, kept in [10⁻³, 1] (a table without a peak
/// has w = π: the broadest distribution).
pub fn measured_sampling_alpha(lobe_width: f64) -> f64 {
    (lobe_width / std::f64::consts::SQRT_2).clamp(1e-3, 1.0)
}

/// Outgoing radiance [W/(m²·sr)] per linear RGB channel at `point` towards the viewer, every light unoccluded.
pub fn radiance_out(brdf: &Brdf, point: &SurfacePoint, lights: &Lights, options: &ShadingOptions) -> [f64; 3] {
    radiance_out_visible(brdf, point, lights, options, None)
}

/// Outgoing radiance [W/(m²·sr)] per linear RGB channel at `point` towards the viewer from the visible part of
/// each light (`shadow`; `None`: unoccluded): the diffuse part by the lights' visible fractions, each specular
/// sample by its own shadow ray (`visibility`; the sun's only in its penumbra, see the sun's branch).
pub fn radiance_out_visible(
    brdf: &Brdf,
    point: &SurfacePoint,
    lights: &Lights,
    options: &ShadingOptions,
    shadow: Option<&Shadowing>,
) -> [f64; 3] {
    // An undefined (zero) normal reflects nothing: n·l = 0 would otherwise read as a surface edge-on to every light.
    if point.normal == DVec3::ZERO {
        return [0.0; 3];
    }
    let (e, sun_fraction) = irradiance_and_sun_fraction(point, lights, options, shadow);
    let (kd, ks) = (brdf.kd(), brdf.ks());
    let mut radiance = [0, 1, 2].map(|c| lambert_brdf(kd[c] as f64) * e[c]);
    if brdf.is_lambert() {
        return radiance;
    }
    // Specular part: per unit radiance (or irradiance), then per channel.
    let mut specular = [0.0; 3];
    if let Some(sun) = &lights.sun {
        let shadow = shadow.and_then(Shadowing::for_sun);
        let l = sun.direction.as_dvec3();
        match options.sun {
            SunModel::Delta => {
                let cos = point.normal.dot(l).max(0.0);
                let mut factor = specular_lobe_rgb(brdf, point, l).map(|lobe| lobe * cos);
                if factor.iter().any(|&x| x > 0.0) && shadow.is_some_and(|s| !s.visible_along(l)) {
                    factor = [0.0; 3];
                }
                for ((sc, &perp), factor) in specular.iter_mut().zip(&sun.irradiance).zip(factor) {
                    *sc += factor * perp as f64;
                }
            }
            SunModel::Disk => {
                let delta = sun.angular_diameter as f64;
                let radius = (0.5 * delta).tan();
                // The lobe's samples cast their rays only in the sun's penumbra, where its visible fraction (the
                // diffuse part's, whose grid locates the edges) is strictly between 0 and 1: where that grid sees
                // all of the disk the lobe is unoccluded, where it sees none the lobe is 0, as the diffuse part
                // takes them (an occluder slipping between all of that grid's rays is missed by both alike).
                let penumbra = sun_fraction > 0.0 && sun_fraction < 1.0;
                let rays = shadow.filter(|_| penumbra).map(SampleRays::Along);
                let sums =
                    segment_lobe_integral_visible(brdf, point, l, -l, radius, options.sun_samples_per_axis, rays);
                let mut integral =
                    normalized_lobe_integral(sums, sun_projected_solid_angle_above(point.normal.dot(l), delta));
                if shadow.is_some() && sun_fraction == 0.0 {
                    integral = [0.0; 3];
                }
                let s = (0.5 * delta).sin();
                for ((sc, &perp), integral) in specular.iter_mut().zip(&sun.irradiance).zip(integral) {
                    *sc += integral * perp as f64 / (PI * s * s);
                }
            }
        }
    }
    for (i, disk) in lights.disks.iter().enumerate() {
        let g = disk_geometry(disk);
        let shadow = shadow.and_then(|s| s.for_disk(i));
        let integral = match options.disk {
            DiskModel::Exact => {
                let rays = shadow.map(SampleRays::ToPoint);
                let q = g.center - point.position;
                // The grid's sum as it is (see `disk_lobe_integral`).
                segment_lobe_integral_visible(brdf, point, q, g.direction, g.radius, options.samples_per_axis, rays)
                    .lobe
            }
            DiskModel::SmallSource => {
                let to_center = safe_normalize(g.center - point.position);
                let omega = disk_projected_solid_angle_small_source(point.position, point.normal, &g);
                let integral = specular_lobe_rgb(brdf, point, to_center).map(|lobe| lobe * omega);
                if integral.iter().any(|&x| x > 0.0) && shadow.is_some_and(|s| !s.visible_to(g.center)) {
                    [0.0; 3]
                } else {
                    integral
                }
            }
        };
        for ((sc, &l0), integral) in specular.iter_mut().zip(&disk.radiance).zip(integral) {
            *sc += integral * l0 as f64;
        }
    }
    if let Some(sky) = &lights.sky {
        let integral =
            sky_lobe_integral_visible(brdf, point, options.samples_per_axis, shadow.and_then(Shadowing::for_sky));
        for ((sc, &l0), integral) in specular.iter_mut().zip(sky).zip(integral) {
            *sc += integral * l0 as f64;
        }
    }
    for c in 0..3 {
        radiance[c] += ks[c] as f64 * specular[c];
    }
    radiance
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Sun;
    use crate::shading::lights::sky::sky_lobe_integral;

    fn point(normal: DVec3, to_viewer: DVec3) -> SurfacePoint {
        let tangent = crate::scene::tangent::default_tangent(normal);
        SurfacePoint { position: DVec3::ZERO, normal, tangent, bitangent: normal.cross(tangent), to_viewer }
    }

    #[test]
    fn lambert_under_the_sun() {
        let m = Brdf::Lambert { albedo: [0.5, 0.25, 1.0] };
        let l = DVec3::new(0.0, 1.0, 1.0).normalize();
        let lights = Lights {
            sun: Some(Sun { direction: l.as_vec3(), irradiance: [1000.0, 500.0, 0.0], angular_diameter: 0.00925 }),
            ..Default::default()
        };
        let p = point(DVec3::Y, DVec3::Z);
        let cos = l.as_vec3().as_dvec3().y;
        let opts = ShadingOptions::default();
        let got = radiance_out(&m, &p, &lights, &opts);
        let want = [0.5 / PI * 1000.0 * cos, 0.25 / PI * 500.0 * cos, 0.0];
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() <= 1e-15 * want[c].abs(), "{got:?} {want:?}");
        }
        assert_eq!(radiance_out(&m, &SurfacePoint { normal: -DVec3::Y, ..p }, &lights, &opts), [0.0; 3]);
        assert_eq!(
            radiance_out(&m, &SurfacePoint { normal: safe_normalize(DVec3::ZERO), ..p }, &lights, &opts),
            [0.0; 3]
        );
    }

    #[test]
    fn safe_normalize_never_gives_nan() {
        assert_eq!(safe_normalize(DVec3::ZERO), DVec3::ZERO);
        assert_eq!(safe_normalize(DVec3::splat(f64::NAN)), DVec3::ZERO);
        assert_eq!(safe_normalize(DVec3::new(0.0, 3.0, 4.0)), DVec3::new(0.0, 0.6, 0.8));
        assert_eq!(safe_normalize(DVec3::new(1e-100, 0.0, 0.0)), DVec3::X);
        // A squared length that underflows counts as zero (as the GPU's flushed denormals do).
        assert_eq!(safe_normalize(DVec3::new(1e-300, 0.0, 0.0)), DVec3::ZERO);
    }

    #[test]
    fn orthonormal_to_is_orthonormal() {
        for v in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::Z, DVec3::new(0.3, -0.5, 0.8).normalize()] {
            let t = orthonormal_to(v);
            assert!((t.length() - 1.0).abs() < 1e-15 && t.dot(v).abs() < 1e-15, "{v}");
        }
    }

    #[test]
    fn sky_lobe_sampling_integrates_the_lobes_albedo() {
        // At normal view the Phong and Blinn-Phong lobes integrate to 1 and the whole lobe is above the horizon
        // for e ≥ 1 up to the grid's resolution; the sampled integral converges to it.
        let p = point(DVec3::Y, DVec3::Y);
        for (brdf, tol) in [
            (Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 100.0 }, 1e-3),
            (Brdf::BlinnPhong { kd: [0.0; 3], ks: [1.0; 3], exponent: 100.0 }, 1e-3),
        ] {
            let got = sky_lobe_integral(&brdf, &p, 64);
            assert!((got - 1.0).abs() < tol, "{brdf:?}: {got}");
        }
        // Ward at normal view: the sampled integral matches its directional albedo by brute force.
        let ward = Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.2, alpha_y: 0.1 };
        let brute = {
            let mut s = 0.0;
            let (nt, np) = (2000, 400);
            for i in 0..nt {
                let th = (i as f64 + 0.5) / nt as f64 * 0.5 * PI;
                for j in 0..np {
                    let ph = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
                    let w = DVec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
                    s += specular_lobe(&ward, &p, w) * th.cos() * th.sin();
                }
            }
            s * (0.5 * PI / nt as f64) * (2.0 * PI / np as f64)
        };
        let got = sky_lobe_integral(&ward, &p, 64);
        assert!((got - brute).abs() < 2e-3 * brute, "{got} vs {brute}");
    }

    #[test]
    fn sinh_warp_is_monotone_and_integrates() {
        // The points increase inside [a, b]; the midpoint sums of dx/du and of a narrow Gaussian at c converge to
        // b − a and to √(2π) s, for widths from far below to far above the interval.
        for (a, b, c) in [(0.0, PI, 1.0), (-1.0, 1.0, -1.0), (-1.0, 1.0, 0.3), (0.0, 0.2, 0.2)] {
            // A Gaussian of width s, a hundredth of the interval; grids graded at 1 to 1e8 times that.
            let s = (b - a) * 1e-2;
            for scale in [1.0f64, 3.0, 1e3, 1e8] {
                let w = scale * s;
                let k = 64;
                let mut last = a;
                let (mut length, mut gauss) = (0.0, 0.0);
                let ends = sinh_warp_ends(a, b, c, w);
                for i in 0..k {
                    let (x, dx) = sinh_warp(a, b, c, w, ends, (i as f64 + 0.5) / k as f64);
                    assert!(x >= last && x <= b && dx > 0.0, "{a} {b} {c} {w}: {x} after {last}");
                    last = x;
                    length += dx / k as f64;
                    gauss += (-0.5 * ((x - c) / s).powi(2)).exp() * dx / k as f64;
                }
                assert!((length - (b - a)).abs() < 1e-3 * (b - a), "{a} {b} {c} {w}: length {length}");
                // Only the part of the Gaussian inside [a, b]: half of it where c is an end.
                let inside = if c == a || c == b { 0.5 } else { 1.0 };
                let want = inside * (2.0 * PI).sqrt() * s;
                // Graded at the Gaussian's width it is resolved; a uniform grid (scale ≥ 1e3) has 0.64 points per s.
                if scale <= 3.0 {
                    assert!((gauss - want).abs() < 1e-3 * want, "{a} {b} {c} {w}: {gauss} against {want}");
                }
            }
        }
    }

    #[test]
    fn exp_minus_one_is_accurate_near_zero() {
        for x in [1e-12f64, -3e-7, 1e-3, -0.5, 2.0] {
            let want = x.exp_m1();
            assert!(((exp_minus_one(x) - want) / want).abs() < 1e-15, "{x}");
        }
    }
}

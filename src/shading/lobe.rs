//! A BRDF's specular lobe and how it is sampled. The table of models: each question asked of a lobe is one
//! function here whose `match` names every model and calls its file (`shading::brdf::{phong, blinn_phong, ward}`,
//! `shading::measured`): the lobe of a material at a surface point ([`specular_lobe`], per channel for a measured
//! table), its width ([`lobe_width`]), one sample of its inverse CDF ([`lobe_sample`] about [`sampling_axis`]),
//! its kink for the error bounds ([`lobe_kink`]). Then what every model shares: the graded grids that integrate a
//! lobe over a light's disk or segment ([`segment_lobe_integral`], with visibility
//! [`segment_lobe_integral_visible`]). The lights (`shading::lights`) integrate it over themselves with these;
//! `shaders/lobe.glsl` mirrors it name for name.

use std::f64::consts::PI;

use glam::DVec3;

use super::brdf::blinn_phong::{blinn_phong_lobe, blinn_phong_lobe_sample, blinn_phong_lobe_width};
use super::brdf::metallic_roughness::{gltf_lobe_rgb, gltf_lobe_sample, gltf_lobe_width};
use super::brdf::mirror;
use super::brdf::phong::{phong_lobe, phong_lobe_kink, phong_lobe_sample, phong_lobe_width};
use super::brdf::ward::{ward_lobe, ward_lobe_sample, ward_lobe_width};
use super::measured::{measured_lobe_sample, measured_residual};
use super::visibility::Shadowing;
use crate::scene::Brdf;

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

/// The specular lobe of a material (without ks) per channel for light from `l`: the analytic lobes' one value in
/// each channel; a measured table's part above its floor ([`measured_residual`]); glTF's, whose metal's Fresnel
/// follows the base colour.
pub fn specular_lobe_rgb(brdf: &Brdf, p: &SurfacePoint, l: DVec3) -> [f64; 3] {
    match brdf {
        Brdf::Measured { table, lookup } => measured_residual(table, *lookup, p.normal, l, p.to_viewer),
        Brdf::Gltf { base_color, metallic, alpha, specular } => {
            let (base, d) = (base_color.map(f64::from), dielectric_of(specular));
            gltf_lobe_rgb(p.normal, l, p.to_viewer, base, *metallic as f64, *alpha as f64, d)
        }
        Brdf::Lambert { .. } | Brdf::Phong { .. } | Brdf::BlinnPhong { .. } | Brdf::Ward { .. } => {
            [specular_lobe(brdf, p, l); 3]
        }
    }
}

/// A material's specular lobe (without ks) for light from `l` seen from `v` about the normal +z, tangent +x,
/// bitangent +y: the frame of the bounds' scans and of tabulated tables.
pub fn lobe_about_z(brdf: &Brdf, l: DVec3, v: DVec3) -> f64 {
    specular_lobe(brdf, &point_about_z(v), l)
}

/// [`lobe_about_z`] per channel ([`specular_lobe_rgb`]).
pub fn lobe_about_z_rgb(brdf: &Brdf, l: DVec3, v: DVec3) -> [f64; 3] {
    specular_lobe_rgb(brdf, &point_about_z(v), l)
}

/// The surface point at the origin with normal +z, tangent +x, bitangent +y, seen from `v`.
fn point_about_z(v: DVec3) -> SurfacePoint {
    SurfacePoint { position: DVec3::ZERO, normal: DVec3::Z, tangent: DVec3::X, bitangent: DVec3::Y, to_viewer: v }
}

/// The specular lobe of a material (without ks) for light from `l`; a measured table's and glTF's, the mean of
/// their channels'.
pub fn specular_lobe(brdf: &Brdf, p: &SurfacePoint, l: DVec3) -> f64 {
    let (n, v) = (p.normal, p.to_viewer);
    match *brdf {
        Brdf::Lambert { .. } => 0.0,
        Brdf::Phong { exponent, .. } => phong_lobe(n, l, v, exponent as f64),
        Brdf::BlinnPhong { exponent, .. } => blinn_phong_lobe(n, l, v, exponent as f64),
        Brdf::Ward { alpha_x, alpha_y, .. } => {
            ward_lobe(n, p.tangent, p.bitangent, l, v, alpha_x as f64, alpha_y as f64)
        }
        Brdf::Measured { .. } | Brdf::Gltf { .. } => specular_lobe_rgb(brdf, p, l).iter().sum::<f64>() / 3.0,
    }
}

/// The angular width \[rad\] about a specular lobe's peak (the mirror direction of the viewer) over which the disk
/// integral crowds its samples: where the lobe falls to about `e^{-1/2}` (each model's file says where).
pub fn lobe_width(brdf: &Brdf) -> f64 {
    match *brdf {
        Brdf::Lambert { .. } => PI,
        Brdf::Phong { exponent, .. } => phong_lobe_width(exponent as f64),
        Brdf::BlinnPhong { exponent, .. } => blinn_phong_lobe_width(exponent as f64),
        Brdf::Ward { alpha_x, alpha_y, .. } => ward_lobe_width(alpha_x as f64, alpha_y as f64),
        Brdf::Measured { ref table, .. } => table.lobe_width as f64,
        Brdf::Gltf { alpha, .. } => gltf_lobe_width(alpha as f64),
    }
}

/// The axis a BRDF's inverse-CDF directions are drawn about (for [`lobe_sample`]): Phong's mirror direction of
/// the viewer, the others' normal (their half vectors are drawn about it).
pub fn sampling_axis(brdf: &Brdf, p: &SurfacePoint) -> DVec3 {
    if brdf.sampled_about_mirror() {
        mirror(p.to_viewer, p.normal)
    } else {
        p.normal
    }
}

/// One sample `(ξ1, φ = 2πξ2)` of a stratified grid through the lobe's own inverse CDF: the weight
/// `lobe(ω) (n·ω)+ / pdf(ω)` per channel and the direction ω. `(axis, t, b)`: [`sampling_axis`] and a frame about
/// it. A Lambertian BRDF has no lobe: weight 0.
pub fn lobe_sample(
    brdf: &Brdf,
    p: &SurfacePoint,
    (axis, t, b): (DVec3, DVec3, DVec3),
    xi1: f64,
    phi: f64,
) -> ([f64; 3], DVec3) {
    let (n, v) = (p.normal, p.to_viewer);
    match *brdf {
        Brdf::Lambert { .. } => ([0.0; 3], n),
        Brdf::Phong { exponent, .. } => {
            let (weight, omega) = phong_lobe_sample(n, axis, t, b, exponent as f64, xi1, phi);
            ([weight; 3], omega)
        }
        Brdf::BlinnPhong { exponent, .. } => {
            let (weight, omega) = blinn_phong_lobe_sample(n, v, (axis, t, b), exponent as f64, xi1, phi);
            ([weight; 3], omega)
        }
        Brdf::Ward { alpha_x, alpha_y, .. } => {
            let frame = (n, p.tangent, p.bitangent);
            let (weight, omega) = ward_lobe_sample(frame, v, (alpha_x as f64, alpha_y as f64), xi1, phi);
            ([weight; 3], omega)
        }
        Brdf::Measured { ref table, lookup } => measured_lobe_sample(table, lookup, (n, v), (t, b), xi1, phi),
        Brdf::Gltf { base_color, metallic, alpha, specular } => {
            let params = (base_color.map(f64::from), metallic as f64, alpha as f64, dielectric_of(&specular));
            gltf_lobe_sample((n, t, b), v, params, xi1, phi)
        }
    }
}

/// A glTF material's dielectric Fresnel `(f0, f90)` in f64.
pub fn dielectric_of(specular: &crate::scene::material::DielectricSpecular) -> ([f64; 3], f64) {
    (specular.f0.map(f64::from), specular.f90 as f64)
}

/// The count per axis of the sky's inverse-CDF grid for a lobe asked `per_axis`: glTF's draws half its azimuths
/// from each of two densities (`gltf_lobe_sample`), so its count is made even, each half then a whole grid.
pub fn sky_grid_per_axis(brdf: &Brdf, per_axis: u32) -> u32 {
    match brdf {
        Brdf::Gltf { .. } => per_axis + per_axis % 2,
        Brdf::Lambert { .. }
        | Brdf::Phong { .. }
        | Brdf::BlinnPhong { .. }
        | Brdf::Ward { .. }
        | Brdf::Measured { .. } => per_axis,
    }
}

/// The slope jump of the lobe where the light crosses its zero, relative to its peak, for the error bounds
/// (`accuracy::bounds`; `None`: unbounded, no claim). Sampled scans do not find a kink (it is a line, the scan's
/// points a lattice), so each model says its own: Phong's at α = 90° (`phong_lobe_kink`); Blinn-Phong's `n·h` stays
/// positive for light and viewer above the horizon, Ward's and glTF's lobes are smooth, a table is linear between
/// its bins.
pub fn lobe_kink(brdf: &Brdf) -> Option<f64> {
    match *brdf {
        Brdf::Phong { exponent, .. } => phong_lobe_kink(exponent as f64),
        Brdf::Lambert { .. }
        | Brdf::BlinnPhong { .. }
        | Brdf::Ward { .. }
        | Brdf::Measured { .. }
        | Brdf::Gltf { .. } => Some(0.0),
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

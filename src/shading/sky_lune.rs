//! The two lunes the horizontal cuts a surface's hemisphere into: the sky's part and the rest.
//!
//! The sky is uniform over the upper hemisphere (`ω·up > 0`, up = +Y), so a surface tilted by `t` from up sees
//! it through the **upper lune** `{n·ω > 0, ω·up > 0}` of dihedral angle `π − t`: its irradiance is
//! `π L (1 + cos t)/2` (`lights::sky::sky_irradiance`). The lobe integral is sampled through each lobe's own
//! inverse CDF over the whole hemisphere about n (`lights::sky::sky_lobe_hemisphere_grid`), which cannot clip at the
//! horizontal without an indicator that jumps inside the grid's cells (first-order convergence, and a sample
//! within rounding of the horizontal counted by one renderer and not the other moves a pixel by its whole
//! weight). So `lights::sky::sky_lobe_integral_visible` subtracts the **lower lune**'s integral, computed here on a grid
//! whose edges are the lune's own, while the lobe's peak is above the horizontal, and takes the upper lune's
//! integral from its own grid once the peak is below ([`sky_lune_blend`]).
//!
//! **Lune coordinates.** With `b` the unit component of up across n (`up = cos t n + sin t b`) and `e = n × b`,
//! `ω = cos λ (cos ψ n + sin ψ b) + sin λ e` maps the rectangle `ψ ∈ (−π/2, t − π/2)`, `λ ∈ (−π/2, π/2)` onto
//! the lower lune exactly (`n·ω = cos λ cos ψ > 0`, `ω·up = cos λ cos(ψ − t) < 0`), and `ψ ∈ (t − π/2, π/2)` onto
//! the upper one, with `dω = cos λ dψ dλ`. The integrand `lobe(ω) cos²λ cos ψ` is smooth on the closed rectangle
//! (it vanishes at the surface's horizon ψ = ±π/2 and at the poles λ = ±π/2), so the midpoint rule keeps its
//! 1/k² convergence once the grid resolves the lobe (measured: Phong e = 100 with its peak on the lune's edge,
//! 4.6e-5 at 16², 4e-10 at 32²). As for disk lights (`shade::segment_lobe_integral`) the grid is graded by
//! `sinh_warp` about the lobe's peak (the mirror direction of the viewer) with the lobe's width, and blends into
//! the uniform grid for wide lobes; everything is continuous in the inputs, so no sample switches on or off
//! between the renderers. Precision: the tilt is `atan2(|up − (n·up) n|, n·up)`, not `acos(n·up)`, which loses
//! half its digits for surfaces nearly facing up (whose thin lune it places).

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use super::brdf::mirror;
use super::lobe::{
    graded_axis, graded_point, lobe_width, orthonormal_to, specular_lobe, specular_lobe_rgb, SurfacePoint,
};
use super::visibility::Shadowing;
use crate::scene::Brdf;

/// Which of the two lunes a surface's hemisphere is split into by the horizontal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lune {
    /// `{n·ω > 0, ω·up < 0}`: not sky.
    Below,
    /// `{n·ω > 0, ω·up > 0}`: the sky's part of the hemisphere.
    Above,
}

/// Up's part across the normal n (`up − (n·up) n = sin t b`, b the unit uphill direction) and the surface's tilt t
/// from up \[rad\]. `sin t` is that part's length and t its `atan2` with `n·up`: `acos(n·up)` or `sqrt(1 − cos²t)`
/// would cancel for surfaces nearly facing up, whose thin lune t then places wrongly.
pub fn up_across(n: DVec3) -> (DVec3, f64) {
    let across = DVec3::Y - n.y * n;
    (across, across.length().atan2(n.y))
}

/// How much narrower than a Gaussian lobe's fall-off [`sky_lobe_in_lune`] grades its grid across a lune's edge
/// where the lobe's peak lies beyond it: `width²/(width + 8 × distance)` against the fall-off's `width²/(2 ×
/// distance)` (`lobe_width` the lobe's width, the distance the peak's from the edge, in radians). The sinh warp
/// spaces its points geometrically beyond its width, so a narrow width costs little where the tail reaches further.
///
/// Measured against `width²/(width + distance)`, used before on both axes (along the edge the width is now the
/// lobe's own: a tail cut at a distance keeps the lobe's cross-section there). `cargo run --release --example
/// sky_lobe_tails` (the sky's lobe integral over a sphere's normals against 512², the worst normal relative to the
/// larger of its value and 1% of the peak; 4², 8², 16², 24²): Phong e = 80 0.19, 2.4e-2, 1.9e-3, 6.6e-4 before, 0.14,
/// 9.4e-3, 6.2e-4, 3.7e-4 now; Blinn-Phong e = 300 0.47, 8.1e-2, 6.1e-3, 2.6e-3 before, 0.53, 1.6e-2, 2.4e-3, 1.1e-3
/// now; Ward α = 0.15 0.44, 8.8e-2, 2.3e-2, 1.0e-2 before, 0.38, 3.1e-2, 4.0e-3, 1.8e-3 now; Ward αx = 0.05 αy = 0.3
/// 2.4, 0.99, 0.18, 4.8e-2 before, 2.5, 0.66, 7.8e-2, 1.2e-2 now. `sunshade albedo`'s table of tilted surfaces
/// (docs/brdf.md) keeps its medians; its worst cases move both ways (Phong e = 1 at 8²: 5.3e-2 against 2.7e-2;
/// the anisotropic Ward αx = 0.02 at 8² 1.0 against 0.12, at 32² 0.16 against 0.30: one grid width where that lobe
/// has two). Tried and not kept: 16 in place of 8 with `sqrt(width (width + distance))` along the edge (better on
/// the sphere, the anisotropic Ward's 16² 3.8e-2, but 6.6 at 4² on the tilted table), widths projected from the Ward
/// lobe's two axes at its peak (its far tail is not shaped like its peak), the fall-off measured from the lobe at
/// the edge (worse for every lobe).
pub const SKY_TAIL_GRADING: f64 = 8.0;

/// The least n·v at which [`grazing_narrowing`] narrows a lobe in proportion (below it, by this much).
///
/// Measured with `cargo run --release --example lobe_grid_pixel_classes` (Ward α = 0.15's silhouette ring, the
/// largest difference from 13² to 19²): 1.2e-2 with 0.2, 8.0e-3 with 0.05 and with 0.02; the sphere's normals of
/// `sky_lobe_tails` alike for all three.
pub const GRAZING_FLOOR: f64 = 0.05;

/// How much narrower than its width an isotropic half-vector lobe is along the unit direction `u` (tangent to the
/// sphere of directions at the lobe's peak): 1 in the plane of incidence, n·v across it (at least
/// [`GRAZING_FLOOR`]): the extent of that ellipse along u, `sqrt(1 − (1 − across²) (c·u)²)` with
/// `c = n × v / |n × v|` (u is orthogonal to the peak r there; where the peak lies beyond the lune's edge the same
/// formula is taken at the edge's point nearest it, as the grid is graded about that point). Where the viewer
/// grazes the surface, the mirror direction r = 2(n·v)n − v and v sum to `2(n·v) n`: turning ω from r by δ across
/// the plane of incidence turns the half vector by δ/(2 n·v), and by δ/2 within it, so an isotropic lobe in the
/// half vector's angle to n is n·v times as wide across as along.
///
/// Only the isotropic Ward lobe takes it: Blinn-Phong's is the same in principle, but on `sky_lobe_tails`' sphere
/// (e = 300) 8² erred 3.4e-2 against 1.6e-2 (its grazing ring 5.1e-4 against 9.9e-3 at 16², which its images do
/// not need), and the anisotropic Ward's grid has one width where its lobe has two (its tilted surfaces in
/// docs/brdf.md at 16² 0.65 against 0.20). For Ward α = 0.15 (`sky_lobe_tails`, 4², 8², 16², 24²): the grazing
/// ring (n·v 0.001 to 0.05) 1.2, 0.50, 3.2e-2, 1.5e-3 before, 0.76, 4.9e-2, 1.1e-3, 4.9e-4 now; the sphere 0.38,
/// 3.1e-2, 4.0e-3, 1.8e-3 before, 0.43, 2.2e-2, 1.4e-3, 9.1e-4 now. docs/brdf.md's tilted surfaces (views to 85°
/// from the normal, n·v ≥ 0.087) move both ways for Ward α = 0.2: worst 0.96, 5.6e-2 at 2², 4² before, 0.65,
/// 9.7e-2 now, the same from 8².
///
/// The hemisphere's inverse-CDF grid is not changed: it is drawn from the half vector's own distribution, so its
/// samples narrow with the lobe.
///
/// Precision: `1 − (n·v)² = |n × v|²` for unit vectors, so where n·v ≥ the floor the factor is
/// `sqrt(1 − ((n × v)·u)²)` with no normalization: a viewer head-on (n × v → 0, its direction all rounding) gives
/// 1, continuously. Below the floor |n × v|² ≥ 1 − floor², so normalizing c is safe there.
pub fn grazing_narrowing(brdf: &Brdf, p: &SurfacePoint, u: DVec3) -> f64 {
    // Every model by name, so that a new one says whether its lobe narrows.
    let isotropic_ward = match *brdf {
        Brdf::Ward { alpha_x, alpha_y, .. } => alpha_x == alpha_y,
        Brdf::Lambert { .. }
        | Brdf::Phong { .. }
        | Brdf::BlinnPhong { .. }
        | Brdf::Measured { .. }
        | Brdf::Gltf { .. } => false,
    };
    if !isotropic_ward {
        return 1.0;
    }
    let nxv = p.normal.cross(p.to_viewer);
    let sin2 = nxv.length_squared();
    // (1 − across²)/|n × v|²: 1 above the floor, less below it; 1 where n × v is 0 (the product is then 0).
    let scale = ((1.0 - GRAZING_FLOOR * GRAZING_FLOOR) / sin2.max(1e-30)).min(1.0);
    (1.0 - scale * nxv.dot(u).powi(2)).max(0.0).sqrt()
}

/// How far the sky's lobe integral is taken directly over the upper lune rather than as the hemisphere's less
/// the lower lune's: 0 while the lobe's peak (the mirror direction of the viewer) is above the horizontal by more
/// than a quarter of the lobe's width w (at most 1 rad), 1 once it is below by more than that, linear between, so
/// the result is continuous in the inputs. Above, the lower lune holds only the lobe's tail and the difference
/// keeps the inverse-CDF grid's accuracy; below, the difference would be a small remainder of two nearly equal
/// sums, each sum's error amplified by their ratio, so the upper lune's own grid (which holds the tail) is taken.
/// Measured with a blend over a whole width instead of a quarter: on a grazing view of a measured table whose
/// peak was 0.9 of a width below (weight 0.03 on the difference), the sky moved by 1.6e-4 for a 2e-7 turn of the
/// viewer (f32's rounding), from 1e-6 in each sum. The blend reads only the geometry: one that read the sums' ratio
/// moved with their rounding (3e-5 between the renderers on brdfs.glb's undersides).
///
/// Where the sky lies beyond the lobe altogether ([`sky_beyond_lobe`], read from the lobe's values at two
/// directions, not from the sums), the upper lune's grid takes the weight whatever the peak's elevation.
///
/// It is scaled by the surface's tilt from up over that quarter width (at most 1): a surface tilted less has a
/// lower lune too thin to hold much of the lobe, and one facing straight up has none, so floors keep the
/// hemisphere's grid alone (their images are those of the grid before the lobes knew the horizontal).
pub fn sky_lune_blend(brdf: &Brdf, p: &SurfacePoint) -> f64 {
    let n = p.normal;
    let r = mirror(p.to_viewer, n);
    let quarter = 0.25 * lobe_width(brdf).min(1.0);
    let (_, tilt) = up_across(n);
    // A measured table takes the upper lune wherever the surface is tilted (see `sky_lobe_integral_visible`).
    let below = if brdf.is_measured() {
        1.0
    } else {
        (0.5 - r.y / (2.0 * quarter)).clamp(0.0, 1.0).max(sky_beyond_lobe(brdf, p, r))
    };
    below * (tilt / quarter).min(1.0)
}

/// The lobe's value at the sky's direction nearest its peak, relative to the peak, under which
/// [`sky_beyond_lobe`] gives the upper lune's grid all the weight.
pub const SKY_REACH: f64 = 1e-2;

/// How surely the sky lies beyond the lobe, from 0 to 1: `1 − q/SKY_REACH` (clamped), q the lobe at the sky's
/// direction nearest its peak r over the lobe at r; 0 while r is in the sky. The nearest sky direction to an r
/// below the horizontal is r's projection onto the horizontal where that is in front of the surface, else the
/// apex of the upper lune on r's side (the horizontal direction in the surface's plane).
///
/// Why: [`sky_lune_blend`] reads the peak's elevation only, so at a silhouette facing down (n·v near 0, r a
/// little below the horizontal) it gave the hemisphere's grid less the lower lune's much of the weight, where the
/// sky sees nothing of a half-vector lobe (every sky direction's half vector leans away from n) and that
/// difference is the two grids' error alone. Measured on the BRDF chart's sphere (Ward α = 0.2, sky alone, view
/// along +Z) at n ≈ (0.455, −0.890, 0.013): truth 0, weight 0.39 on a difference of 3.4e-2 of the unit lobe at 16².
/// It reads two values of the lobe, never the sums, so it is continuous and both renderers round it alike.
/// A surface facing straight down (no apex, no sky in its hemisphere) gives 1. Either path converges to the same
/// integral; this only chooses the one whose error is not a remainder. (Where r's projection onto the horizontal
/// is behind the surface, `n·r ≤ n_y r_y`, so r's projection onto the surface's horizon is below the horizontal
/// too: the apex is then the nearest sky direction.)
pub fn sky_beyond_lobe(brdf: &Brdf, p: &SurfacePoint, r: DVec3) -> f64 {
    if r.y >= 0.0 || r.y.is_nan() {
        return 0.0;
    }
    let n = p.normal;
    let flat = DVec3::new(r.x, 0.0, r.z);
    let nearest = if n.dot(flat) > 0.0 {
        flat.normalize()
    } else {
        let apex = DVec3::Y.cross(n);
        if apex.length_squared() == 0.0 {
            return 1.0;
        }
        let apex = apex.normalize();
        if apex.dot(r) < 0.0 {
            -apex
        } else {
            apex
        }
    };
    let peak = specular_lobe(brdf, p, r);
    let q = if peak > 0.0 { specular_lobe(brdf, p, nearest) / peak } else { 0.0 };
    (1.0 - q / SKY_REACH).clamp(0.0, 1.0)
}

/// `∫ lobe(ω) (n·ω)+ dω` over one lune of the surface's hemisphere (`Below` or `Above` the horizontal), per unit
/// radiance, per channel: a `per_axis²` midpoint grid in lune coordinates graded about the lobe's peak (see the
/// module's text), each sample of the upper lune casting its shadow ray along ω where `shadow` is given (the lower
/// lune is not sky and casts none). 0 for a Lambertian BRDF, and for the lower lune of a surface facing up.
pub fn sky_lobe_in_lune(
    brdf: &Brdf,
    p: &SurfacePoint,
    per_axis: u32,
    lune: Lune,
    shadow: Option<&Shadowing>,
) -> [f64; 3] {
    let n = p.normal;
    let (across, tilt) = up_across(n);
    let sin_t = across.length();
    let (psi_lo, psi_hi) = match lune {
        Lune::Below => (-FRAC_PI_2, tilt - FRAC_PI_2),
        Lune::Above => (tilt - FRAC_PI_2, FRAC_PI_2),
    };
    // (A NaN normal compares unordered: nothing.)
    if psi_hi.partial_cmp(&psi_lo) != Some(std::cmp::Ordering::Greater) || brdf.is_lambert() {
        return [0.0; 3];
    }
    let b = if sin_t > 0.0 { across / sin_t } else { orthonormal_to(n) };
    let e = n.cross(b);
    // The lobe's peak in lune coordinates, its width in each (|dω/dψ| = cos λ, |dω/dλ| = 1). A peak outside the
    // lune leaves only its tail there: crowd the grid at the edge nearest the peak.
    let r = mirror(p.to_viewer, n);
    let psi_r = r.dot(b).atan2(r.dot(n));
    let lambda_r = r.dot(e).atan2((r.dot(n).powi(2) + r.dot(b).powi(2)).sqrt());
    let cos_lambda_r = lambda_r.cos();
    let outside = (psi_r - psi_hi).max(psi_lo - psi_r).max(0.0) * cos_lambda_r;
    // Across the edge (ψ) the tail is graded narrower than the lobe, the further its peak the narrower
    // ([`SKY_TAIL_GRADING`]); along the edge (λ) with the lobe's own width. Continuous at distance 0.
    let width = lobe_width(brdf);
    let w_psi = if outside > 0.0 { width * width / (width + SKY_TAIL_GRADING * outside) } else { width };
    let psi_c = psi_r.clamp(psi_lo, psi_hi);
    // Each axis' direction on the sphere at the grid's centre, for a lobe narrower across the plane of incidence.
    let (sin_psi_c, cos_psi_c) = psi_c.sin_cos();
    let f_psi = grazing_narrowing(brdf, p, -sin_psi_c * n + cos_psi_c * b);
    let f_lambda = grazing_narrowing(brdf, p, -lambda_r.sin() * (cos_psi_c * n + sin_psi_c * b) + cos_lambda_r * e);
    let width_psi = (w_psi * f_psi / cos_lambda_r.max(1e-30)).min(16.0 * (psi_hi - psi_lo));
    let width_lambda = (width * f_lambda).min(16.0 * PI);
    let psi_axis = graded_axis(psi_lo, psi_hi, psi_c, width_psi);
    let lambda_axis = graded_axis(-FRAC_PI_2, FRAC_PI_2, lambda_r, width_lambda);
    let k = per_axis as f64;
    let mut sum = [0.0; 3];
    for i in 0..per_axis {
        let (psi, d_psi) = graded_point(&psi_axis, (i as f64 + 0.5) / k);
        let (sp, cp) = psi.sin_cos();
        for j in 0..per_axis {
            let (lambda, d_lambda) = graded_point(&lambda_axis, (j as f64 + 0.5) / k);
            let (sl, cl) = lambda.sin_cos();
            let omega = cl * (cp * n + sp * b) + sl * e;
            // (n·ω) dω = cos λ cos ψ · cos λ dψ dλ; cos ψ ≥ 0 on the hemisphere.
            let weight = cl * cl * cp.max(0.0) * d_psi * d_lambda;
            let lobe = specular_lobe_rgb(brdf, p, omega).map(|l| l * weight);
            // A sample of the sky that contributes casts its shadow ray.
            if lune == Lune::Below || !lobe.iter().any(|&x| x > 0.0) || shadow.is_none_or(|s| s.visible_along(omega)) {
                for (s, l) in sum.iter_mut().zip(lobe) {
                    *s += l;
                }
            }
        }
    }
    sum.map(|s| s / (k * k))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::lights::sky::sky_lobe_integral;

    fn point(normal: DVec3, to_viewer: DVec3) -> SurfacePoint {
        let tangent = crate::scene::tangent::default_tangent(normal);
        SurfacePoint { position: DVec3::ZERO, normal, tangent, bitangent: normal.cross(tangent), to_viewer }
    }

    /// A lune's integral by brute force: a fine uniform grid in (θ, φ) about n, the indicator of ω·up's sign.
    fn brute_force(brdf: &Brdf, p: &SurfacePoint, lune: Lune) -> f64 {
        let n = p.normal;
        let t = orthonormal_to(n);
        let b = n.cross(t);
        let (nt, np) = (1500, 3000);
        let mut s = 0.0;
        for i in 0..nt {
            let th = (i as f64 + 0.5) / nt as f64 * FRAC_PI_2;
            for j in 0..np {
                let ph = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
                let w = th.cos() * n + th.sin() * (ph.cos() * t + ph.sin() * b);
                if (w.y < 0.0) == (lune == Lune::Below) {
                    s += specular_lobe_rgb(brdf, p, w)[0] * th.cos() * th.sin();
                }
            }
        }
        s * (FRAC_PI_2 / nt as f64) * (2.0 * PI / np as f64)
    }

    /// The worst of `(got, want)` relative to the larger of `want` and 1% of `peak` (the diff's floor).
    fn worst_relative(cases: &[(f64, f64)], peak: f64) -> f64 {
        cases.iter().map(|(got, want)| (got - want).abs() / want.max(0.01 * peak)).fold(0.0, f64::max)
    }

    #[test]
    fn the_shader_grades_tails_alike() {
        let glsl = [include_str!("../../shaders/shade.glsl"), include_str!("../../shaders/sky_lune.glsl")].concat();
        assert!(glsl.contains(&format!("const float SKY_TAIL_GRADING = {SKY_TAIL_GRADING:.1};\n")));
        assert!(glsl.contains(&format!("const float GRAZING_FLOOR = {GRAZING_FLOOR:.2};\n")));
        assert!(glsl.contains(&format!("const float SKY_REACH = {SKY_REACH:e};\n")));
    }

    #[test]
    fn a_silhouette_facing_down_takes_no_sky_from_a_difference_of_grids() {
        // The lower part of a sphere's silhouette seen along +Z (the BRDF chart's view; n·v 0.005 to 0.05, n·up
        // under −0.7), where no sky direction's half vector comes near n: the truth is 0 to 1e-16. 16² against
        // 512², relative to the larger of the value and 1% of the largest on the silhouette's equator. Without
        // `sky_beyond_lobe` the blend would give the hemisphere's grid less the lower lune's up to 0.75 of the
        // weight here, and the remainder of their errors would err 2.4 (at n ≈ (±0.555, −0.831, 0.02)).
        let brdf = Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.2, alpha_y: 0.2 };
        let v = DVec3::Z;
        let rim = |nv: f64, ph: f64| nv * v + (1.0f64 - nv * nv).sqrt() * DVec3::new(ph.cos(), ph.sin(), 0.0);
        let mut cases = Vec::new();
        for nv in [0.005, 0.0128, 0.02, 0.03, 0.05] {
            for j in 6..18 {
                let p = point(rim(nv, -PI * (j as f64 + 0.5) / 24.0), v);
                assert!(p.normal.y < -0.7);
                cases.push((sky_lobe_integral(&brdf, &p, 16), sky_lobe_integral(&brdf, &p, 512)));
            }
        }
        let peak =
            [0.0, PI].iter().map(|&ph| sky_lobe_integral(&brdf, &point(rim(0.03, ph), v), 512)).fold(0.0, f64::max);
        let worst = worst_relative(&cases, peak);
        assert!(worst < 1e-2, "worst {worst}");
    }

    #[test]
    fn only_a_grazing_view_of_an_isotropic_ward_narrows_across_the_plane_of_incidence() {
        let ward = Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.15, alpha_y: 0.15 };
        let n = DVec3::Y;
        let across = DVec3::Z;
        // Head-on: n × v = 0, nothing to narrow, and no NaN from normalizing it.
        assert_eq!(grazing_narrowing(&ward, &point(n, n), across), 1.0);
        // n·v = 0.5: across the plane of incidence (x, y) by n·v, within it not at all.
        let v = DVec3::new(0.75f64.sqrt(), 0.5, 0.0);
        assert!((grazing_narrowing(&ward, &point(n, v), across) - 0.5).abs() < 1e-12);
        assert!((grazing_narrowing(&ward, &point(n, v), DVec3::X) - 1.0).abs() < 1e-12);
        // Grazing: by the floor.
        let v = DVec3::new(1.0, 1e-9, 0.0).normalize();
        assert!((grazing_narrowing(&ward, &point(n, v), across) - GRAZING_FLOOR).abs() < 1e-12);
        // Other lobes keep their width.
        for brdf in [
            Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.05, alpha_y: 0.3 },
            Brdf::BlinnPhong { kd: [0.0; 3], ks: [1.0; 3], exponent: 300.0 },
            Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 80.0 },
        ] {
            assert_eq!(grazing_narrowing(&brdf, &point(n, v), across), 1.0);
        }
    }

    #[test]
    fn grazing_views_of_an_isotropic_ward_converge() {
        // A ring of normals about the viewer at n·v 0.001 to 0.05 (a sphere's silhouette; `examples/sky_lobe_tails`,
        // fewer normals), 16² against 256², relative to the larger of the value and 1% of the peak over the ring.
        // Without the narrowing (GRAZING_FLOOR = 1) Ward α = 0.15 erred 4.5e-2 here (now 7.2e-4).
        let brdf = Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.15, alpha_y: 0.15 };
        let v = DVec3::new(0.0, 0.3, 1.0).normalize();
        let (t1, t2) = (DVec3::X, v.cross(DVec3::X).normalize());
        let mut cases = Vec::new();
        for nv in [0.001, 0.01, 0.05] {
            for j in 0..16 {
                let ph = (j as f64 + 0.5) / 16.0 * 2.0 * PI;
                let n = nv * v + (1.0f64 - nv * nv).sqrt() * (ph.cos() * t1 + ph.sin() * t2);
                let p = point(n, v);
                cases.push((sky_lobe_integral(&brdf, &p, 16), sky_lobe_integral(&brdf, &p, 256)));
            }
        }
        let peak = cases.iter().map(|c| c.1).fold(0.0, f64::max);
        let worst = worst_relative(&cases, peak);
        assert!(worst < 5e-3, "worst {worst}");
    }

    #[test]
    fn tails_beyond_the_horizontal_converge_on_a_sphere() {
        // The sky's lobe integral over a sphere's normals seen from one direction (`examples/sky_lobe_tails`, fewer
        // normals), 16² against 256², relative to the larger of the value and 1% of the peak over the normals.
        // Graded with the tail's width²/(width + distance) on both axes, Ward α = 0.15 erred 2.8e-2 here, 4.7e-3
        // with the narrower tails, 1.5e-3 since `grazing_narrowing`.
        let brdf = Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.15, alpha_y: 0.15 };
        let v = DVec3::new(0.0, 0.3, 1.0).normalize();
        let side = 16;
        let mut cases = Vec::new();
        for i in 0..side {
            for j in 0..side {
                let th = (i as f64 + 0.5) / side as f64 * PI;
                let ph = (j as f64 + 0.5) / side as f64 * PI;
                let n = DVec3::new(th.cos(), ph.cos() * th.sin(), ph.sin() * th.sin());
                if n.dot(v) > 0.02 {
                    let p = point(n, v);
                    cases.push((sky_lobe_integral(&brdf, &p, 16), sky_lobe_integral(&brdf, &p, 256)));
                }
            }
        }
        let peak = cases.iter().map(|c| c.1).fold(0.0, f64::max);
        let worst = worst_relative(&cases, peak);
        assert!(worst < 8e-3, "worst {worst}");
    }

    #[test]
    fn nothing_is_below_the_horizon_of_a_surface_facing_up() {
        let phong = Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 10.0 };
        let p = point(DVec3::Y, DVec3::new(0.6, 0.8, 0.0));
        assert_eq!(sky_lobe_in_lune(&phong, &p, 16, Lune::Below, None), [0.0; 3]);
    }

    #[test]
    fn a_vertical_wall_seen_head_on_loses_half_its_lobe() {
        // n horizontal, the viewer along n: the lobe and the cosine are symmetric about the horizontal plane, so
        // the lower lune holds exactly half of the hemisphere's integral (1 for these normalised lobes).
        let n = DVec3::X;
        let p = point(n, n);
        // A lobe of e = 1e6 (0.06° wide) with its peak on the lune's edge needs 32² (16²: 2.2e-2; 32²: 1.5e-4).
        for (brdf, k) in [
            (Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 100.0 }, 16),
            (Brdf::BlinnPhong { kd: [0.0; 3], ks: [1.0; 3], exponent: 100.0 }, 16),
            (Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 1e6 }, 32),
        ] {
            // The whole hemisphere's integral: the same configuration on a floor, where nothing is below.
            let whole = sky_lobe_integral(&brdf, &point(DVec3::Y, DVec3::Y), 256);
            let lower = sky_lobe_in_lune(&brdf, &p, k, Lune::Below, None)[0];
            assert!((lower - 0.5 * whole).abs() < 2e-3 * whole, "{brdf:?}: {lower} of {whole}");
            // And the sky's share is the other half.
            let sky = sky_lobe_integral(&brdf, &p, k.max(64));
            assert!((sky - 0.5 * whole).abs() < 2e-3 * whole, "{brdf:?}: the sky's {sky} of {whole}");
        }
    }

    #[test]
    fn the_lune_grid_converges_to_the_brute_force_integral() {
        // Tilted surfaces, viewers on either side of the horizontal mirror, wide and narrow lobes.
        let cases = [
            (DVec3::new(1.0, 0.3, 0.0), DVec3::new(0.5, -0.2, 0.4)),
            (DVec3::new(0.2, -1.0, 0.3), DVec3::new(0.4, -0.5, 0.1)),
            (DVec3::new(0.0, 0.5, 1.0), DVec3::new(0.3, 0.1, 1.0)),
        ];
        for brdf in [
            Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 1.0 },
            Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 30.0 },
            Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.3, alpha_y: 0.3 },
        ] {
            for (n, v) in cases {
                let p = point(n.normalize(), v.normalize());
                let want = brute_force(&brdf, &p, Lune::Below);
                let got = sky_lobe_in_lune(&brdf, &p, 64, Lune::Below, None)[0];
                assert!((got - want).abs() < 1e-3 * want.max(1e-3), "{brdf:?} {n} {v}: {got} vs {want}");
                let coarse = sky_lobe_in_lune(&brdf, &p, 16, Lune::Below, None)[0];
                assert!((coarse - want).abs() < 2e-2 * want.max(1e-3), "{brdf:?} {n} {v}: 16²: {coarse} vs {want}");
            }
        }
    }

    #[test]
    fn the_sky_integral_converges_to_the_upper_lune_whichever_way_the_surface_faces() {
        // Facing up, sideways and down; peaks above, on and below the horizontal (the blend's three regimes).
        let cases = [
            (DVec3::new(0.3, 1.0, 0.0), DVec3::new(-0.9, 0.5, 0.1)),
            (DVec3::new(1.0, 0.0, 0.2), DVec3::new(1.0, 0.05, 0.0)),
            (DVec3::new(1.0, -0.4, 0.0), DVec3::new(0.6, 0.3, 0.3)),
            (DVec3::new(0.1, -1.0, 0.2), DVec3::new(0.3, -0.6, 0.0)),
        ];
        for brdf in [
            Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 30.0 },
            Brdf::BlinnPhong { kd: [0.0; 3], ks: [1.0; 3], exponent: 30.0 },
            Brdf::Ward { kd: [0.0; 3], ks: [1.0; 3], alpha_x: 0.3, alpha_y: 0.3 },
        ] {
            for (n, v) in cases {
                let p = point(n.normalize(), v.normalize());
                assert!(p.normal.dot(p.to_viewer) > 0.0);
                let want = brute_force(&brdf, &p, Lune::Above);
                let got = sky_lobe_integral(&brdf, &p, 64);
                assert!((got - want).abs() < 2e-3 * want.max(1e-2), "{brdf:?} {n} {v}: {got} vs {want}");
            }
        }
    }
}

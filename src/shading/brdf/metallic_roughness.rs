//! The glTF 2.0 metallic-roughness BRDF, as the glTF 2.0 specification's Appendix B ("BRDF Implementation")
//! defines it: a mix by `metallic` of a metal and a dielectric over the same microfacet lobe,
//!
//! `ρ = (1 − m) [(1 − F_d) base/π + F_d D V] + m F_m D V`,
//!
//! with D the GGX (Trowbridge-Reitz) distribution of `α = roughness²`, V the separable Smith visibility (which
//! holds the microfacet model's `1/(4 |n·l| |n·v|)`), `F_d = f0 + (f90 − f0)(1 − v·h)⁵` Schlick's Fresnel of the
//! dielectric (`f0 = 0.04` and `f90 = 1` by default, ior 1.5: the specification's `fresnel_mix` layers the specular
//! lobe over the Lambertian base colour by it) and `F_m = base + (1 − base)(1 − v·h)⁵` the metal's
//! (`conductor_fresnel`, f0 the base colour). `shaders/brdf/metallic_roughness.glsl` mirrors it name for name.
//!
//! **KHR_materials_ior and KHR_materials_specular** change the dielectric alone: `f0 = min(((ior − 1)/(ior + 1))²
//! colour, 1) weight` per channel and `f90 = weight` (`scene::material::DielectricSpecular`), and the base keeps
//! `1 − max_c F_d` (KHR_materials_specular's `fresnel_mix` with a weight and a colour: the largest channel, so that
//! the colour's complement does not tint the base). Without them `f0 = 0.04`, `f90 = 1` and every formula below is
//! the core specification's.
//!
//! **How it is split for the lights.** sunshade integrates `kd/π` exactly (each light's closed-form irradiance) and
//! a lobe over the light's extent with `ks = 1` (as for a measured table). The dielectric's diffuse term
//! `(1 − max F_d) base/π` varies with `v·h`: `1 − max F_d = (1 − max f0) − (f90 − max f0)(1 − v·h)⁵` (F_d grows with
//! f0), so its constant part `(1 − max f0) base/π` is the diffuse term (`kd = (1 − m)(1 − max f0) base`,
//! [`gltf_kd`]) and the rest goes into the lobe ([`gltf_lobe_rgb`]):
//!
//! `lobe = D V ((1 − m) F_d + m F_m) − (1 − m) (f90 − max f0) (1 − v·h)⁵ base/π`.
//!
//! The lobe is therefore **negative** where the Fresnel darkening of the base colour outweighs the specular lobe
//! (far from the mirror direction at grazing view); `kd/π + lobe = ρ ≥ 0` everywhere. The lights' grids sum it as
//! they sum any lobe; the sky's difference of lunes and its rays take the sign into account
//! (`Brdf::lobe_can_be_negative`).
//!
//! **Precision.**
//! - GGX's peak for small α: `D = α² / (π ((n·h)²(α² − 1) + 1)²)` is written `α² / (π (|n × h|² + α² (n·h)²)²)`
//!   (h unit). In the first form `1 − (n·h)²` cancels at the peak: in f32 with α = 10⁻³ (`α² = 10⁻⁶`) the
//!   rounding of `(n·h)²` alone (6e-8) errs by 6% of the denominator; the cross product keeps every digit.
//! - `1 − v·h` near `l = v` (backscatter): `v·h = |l + v|/2` for unit l and v, and `1 − v·h` is formed as
//!   `|l − v|² / (2 (2 + |l + v|))` (from `4 − |l + v|² = |l − v|²`), without cancellation. The fifth power is
//!   four products, not `pow`.
//! - Grazing light or view: V stays finite (`1/(α (…))` at `n·l = 0`), and the cosine of the light integral takes
//!   the lobe to 0 there; no division by `n·l` or `n·v` is left.
//! - `α → 0`: the lobe tends to a delta that no grid resolves; the mapping keeps `α ≥ 10⁻³` (roughness ≥ 0.032),
//!   where the peak `1/(π α²) ≈ 3·10⁵ /sr` is still finite in f32 and the sun's disk (4.6e-3 rad) is wider than the
//!   lobe (the disk's graded grid resolves it).

use std::f64::consts::{FRAC_1_PI, PI};

use glam::DVec3;

/// Reflectance at normal incidence of the dielectric without KHR_materials_ior and KHR_materials_specular: ior 1.5,
/// `((1 − ior)/(1 + ior))² = 0.04` (and `f90 = 1`).
pub const GLTF_DIELECTRIC_F0: f64 = 0.04;

/// The dielectric's Fresnel `(f0 per channel, f90)` (`scene::material::DielectricSpecular`, in f64).
pub type Dielectric = ([f64; 3], f64);

/// The largest of the dielectric's f0 over the channels.
pub fn f0_max(f0: [f64; 3]) -> f64 {
    f0[0].max(f0[1]).max(f0[2])
}

/// The diffuse reflectance the lights integrate in closed form: `(1 − m)(1 − max f0) base` (the module's split).
pub fn gltf_kd(base: f64, metallic: f64, f0: [f64; 3]) -> f64 {
    base * (1.0 - metallic) * (1.0 - f0_max(f0))
}

/// `1 − v·h` for unit l and v, h their unit half vector: `v·h = |l + v|/2`, so
/// `1 − v·h = |l − v|² / (2 (2 + |l + v|))` without cancellation where l ≈ v.
pub fn one_minus_v_dot_h(l: DVec3, v: DVec3) -> f64 {
    (l - v).length_squared() / (2.0 * (2.0 + (l + v).length()))
}

/// Schlick's `(1 − v·h)⁵` from `1 − v·h`, as products.
pub fn schlick_weight(one_minus_vh: f64) -> f64 {
    let x2 = one_minus_vh * one_minus_vh;
    x2 * x2 * one_minus_vh
}

/// The GGX (Trowbridge-Reitz) normal distribution [1/sr] for the (not necessarily unit) half vector `h` about the
/// unit normal n: `α² / (π ((n·h)²(α² − 1) + 1)²)` for unit h (the specification's D), written with `|n × h|²` in
/// place of `1 − (n·h)²` and scaled by `|h|⁴` so that h needs no normalising; 0 where `n·h ≤ 0` (χ⁺).
pub fn ggx_distribution(n: DVec3, h: DVec3, alpha: f64) -> f64 {
    let nh = n.dot(h);
    // Written so that NaN also returns 0.
    let facing = nh > 0.0;
    if !facing {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let across = n.cross(h).length_squared();
    let h2 = h.length_squared();
    let denominator = across + a2 * nh * nh;
    a2 * FRAC_1_PI * (h2 / denominator) * (h2 / denominator)
}

/// The separable Smith visibility of GGX (the specification's V, which holds the `1/(4 |n·l| |n·v|)` of the
/// microfacet BRDF): `1 / ((|n·l| + √(α² + (1 − α²)(n·l)²)) (|n·v| + √(α² + (1 − α²)(n·v)²)))`.
pub fn smith_visibility(n_dot_l: f64, n_dot_v: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let one = |c: f64| c.abs() + (a2 + (1.0 - a2) * c * c).sqrt();
    1.0 / (one(n_dot_l) * one(n_dot_v))
}

/// The lobe of the glTF BRDF per channel (the module's split): `D V ((1 − m) F_d + m F_m) − (1 − m)(f90 − max f0)
/// (1 − v·h)⁵ base/π` for light from l seen from v, `base` the linear base colour, `metallic` m, α the GGX width,
/// `(f0, f90)` the dielectric's Fresnel. 0 where `l = −v` (no half vector; light and viewer are then not both
/// above the surface).
pub fn gltf_lobe_rgb(
    n: DVec3,
    l: DVec3,
    v: DVec3,
    base: [f64; 3],
    metallic: f64,
    alpha: f64,
    (f0, f90): Dielectric,
) -> [f64; 3] {
    let h = l + v;
    if h.length_squared() == 0.0 {
        return [0.0; 3];
    }
    let specular = ggx_distribution(n, h, alpha) * smith_visibility(n.dot(l), n.dot(v), alpha);
    let s = schlick_weight(one_minus_v_dot_h(l, v));
    let m = metallic;
    let darkening = (1.0 - m) * (f90 - f0_max(f0)) * s;
    [0, 1, 2].map(|c| {
        let b = base[c];
        let dielectric_f = f0[c] + (f90 - f0[c]) * s;
        let metal_f = b + (1.0 - b) * s;
        specular * ((1.0 - m) * dielectric_f + m * metal_f) - darkening * b * FRAC_1_PI
    })
}

/// The whole BRDF ρ [1/sr] per channel: [`gltf_kd`]`/π` plus [`gltf_lobe_rgb`] (the specification's formula).
pub fn gltf_brdf(
    n: DVec3,
    l: DVec3,
    v: DVec3,
    base: [f64; 3],
    metallic: f64,
    alpha: f64,
    dielectric: Dielectric,
) -> [f64; 3] {
    let lobe = gltf_lobe_rgb(n, l, v, base, metallic, alpha, dielectric);
    [0, 1, 2].map(|c| gltf_kd(base[c], metallic, dielectric.0) * FRAC_1_PI + lobe[c])
}

/// The angular width \[rad\] about the lobe's peak over which the lights' grids crowd their samples
/// (`shading::lobe::lobe_width`): D falls to `e^{−1/2}` of its peak at `tan²θh = (e^{1/4} − 1) α²`, `θh ≈ 0.53 α`,
/// about `1.1 α` in ω; taken as `2α`, as for Ward, since GGX's tails are far heavier than its core.
pub fn gltf_lobe_width(alpha: f64) -> f64 {
    2.0 * alpha
}

/// One sample of the sky's inverse-CDF grid, drawn from an even mixture: azimuths `φ < π` draw the GGX half vector
/// (`tan²θh = α² ξ1/(1 − ξ1)`, azimuth `2φ`, reflected to `ω = 2(v·h)h − v`, `pdf_ω = D (n·h)/(4 v·h)`), the others
/// a cosine-weighted direction (`sin²θ = ξ1`, azimuth `2φ − 2π`, `pdf_ω = (n·ω)/π`); the weight is
/// `lobe(ω) (n·ω)+ / pdf_mix(ω)` per channel with `pdf_mix` the mean of the two. The GGX half alone would weigh
/// the lobe's broad negative part by `1/D`, which is unbounded in the tails of a narrow lobe; the mixture bounds
/// every weight. Each half is a whole stratified grid when the grid's azimuth count is even
/// (`shading::lobe::sky_grid_per_axis`). `(n, t, b)`: the frame about the normal.
pub fn gltf_lobe_sample(
    (n, t, b): (DVec3, DVec3, DVec3),
    v: DVec3,
    (base, metallic, alpha, dielectric): ([f64; 3], f64, f64, Dielectric),
    xi1: f64,
    phi: f64,
) -> ([f64; 3], DVec3) {
    let omega = if phi < PI {
        let a2 = alpha * alpha;
        let tan2 = a2 * xi1 / (1.0 - xi1);
        let cos_h = 1.0 / (1.0 + tan2).sqrt();
        let sin_h = tan2.sqrt() * cos_h;
        let phi_h = 2.0 * phi;
        let h = sin_h * (phi_h.cos() * t + phi_h.sin() * b) + cos_h * n;
        let vh = v.dot(h);
        let towards_viewer = vh > 0.0;
        if !towards_viewer {
            return ([0.0; 3], n);
        }
        2.0 * vh * h - v
    } else {
        let phi_c = 2.0 * phi - 2.0 * PI;
        let (sin_t, cos_t) = (xi1.sqrt(), (1.0 - xi1).sqrt());
        sin_t * (phi_c.cos() * t + phi_c.sin() * b) + cos_t * n
    };
    let cos = n.dot(omega);
    let above = cos > 0.0;
    if !above {
        return ([0.0; 3], n);
    }
    let pdf = 0.5 * gltf_half_vector_pdf(n, omega, v, alpha) + 0.5 * cos * FRAC_1_PI;
    let lobe = gltf_lobe_rgb(n, omega, v, base, metallic, alpha, dielectric);
    (lobe.map(|x| x * cos / pdf), omega)
}

/// The density per solid angle of ω when the GGX half vector is drawn about n and v reflected about it:
/// `D(h) (n·h) / (4 v·h)` (h the unit half vector of ω and v; `dω = 4 (v·h) dh`).
pub fn gltf_half_vector_pdf(n: DVec3, omega: DVec3, v: DVec3, alpha: f64) -> f64 {
    let sum = omega + v;
    let len = sum.length();
    if len == 0.0 {
        return 0.0;
    }
    let h = sum / len;
    ggx_distribution(n, h, alpha) * n.dot(h).max(0.0) / (4.0 * v.dot(h).max(f64::MIN_POSITIVE))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(theta: f64, phi: f64) -> DVec3 {
        DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    /// The specification's formulas as written there (unit h, `(n·h)²(α² − 1) + 1`, `pow`), in f64, with
    /// KHR_materials_specular's dielectric Fresnel `mix(f0, f90, (1 − v·h)⁵)` and its `1 − max_value(F)` for the base.
    fn as_written(n: DVec3, l: DVec3, v: DVec3, base: [f64; 3], m: f64, alpha: f64, d: Dielectric) -> [f64; 3] {
        let h = (l + v).normalize();
        let (nh, nl, nv, vh) = (n.dot(h), n.dot(l), n.dot(v), v.dot(h));
        let a2 = alpha * alpha;
        let dist = a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2)) * if nh > 0.0 { 1.0 } else { 0.0 };
        let vis =
            1.0 / ((nl.abs() + (a2 + (1.0 - a2) * nl * nl).sqrt()) * (nv.abs() + (a2 + (1.0 - a2) * nv * nv).sqrt()));
        let fw = (1.0 - vh.abs()).powi(5);
        let fr = d.0.map(|f0| f0 * (1.0 - fw) + d.1 * fw);
        let fr_max = fr[0].max(fr[1]).max(fr[2]);
        [0, 1, 2].map(|c| {
            let b = base[c];
            let metal = (b + (1.0 - b) * fw) * vis * dist;
            let dielectric = (1.0 - fr_max) * b / PI + fr[c] * vis * dist;
            (1.0 - m) * dielectric + m * metal
        })
    }

    const DEFAULT: Dielectric = ([0.04; 3], 1.0);

    #[test]
    fn the_split_adds_up_to_the_specification() {
        let n = DVec3::Z;
        for &alpha in &[0.05, 0.3, 1.0] {
            for &m in &[0.0, 0.5, 1.0] {
                for &(tl, pl, tv, pv) in &[(0.3, 0.0, 0.5, 3.0), (1.2, 1.0, 1.4, 4.0), (0.0, 0.0, 0.0, 0.0)] {
                    // The core specification's dielectric, and KHR_materials_specular's tinted and weighted one.
                    for d in [DEFAULT, ([0.02, 0.01, 0.5], 0.5), ([1.0 / 9.0; 3], 1.0), ([0.0; 3], 0.0)] {
                        let (l, v) = (dir(tl, pl), dir(tv, pv));
                        let base = [0.9, 0.5, 0.1];
                        let got = gltf_brdf(n, l, v, base, m, alpha, d);
                        let want = as_written(n, l, v, base, m, alpha, d);
                        for c in 0..3 {
                            assert!((got[c] - want[c]).abs() <= 1e-13 * want[c].abs().max(1.0), "{got:?} {want:?}");
                            assert!(got[c] >= 0.0);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_lobe_goes_negative_only_where_fresnel_darkens_the_base() {
        // Grazing view, grazing light 0.8 rad in azimuth off the mirror direction (v·h ≈ 0.4), a smooth
        // dielectric: ρ < kd/π.
        let (n, l, v) = (DVec3::Z, dir(1.5, 0.3 + PI + 0.8), dir(1.5, 0.3));
        let lobe = gltf_lobe_rgb(n, l, v, [1.0; 3], 0.0, 0.05, DEFAULT);
        assert!(lobe[0] < 0.0 && gltf_kd(1.0, 0.0, DEFAULT.0) / PI + lobe[0] >= 0.0, "{lobe:?}");
    }

    #[test]
    fn the_sample_weights_integrate_the_lobe() {
        // The mixture's grid against a brute-force product grid in (θ, φ) of `lobe cos sinθ`.
        let (n, t, b) = (DVec3::Z, DVec3::X, DVec3::Y);
        for &(alpha, tv) in &[(0.4, 0.3), (0.15, 1.2), (1.0, 0.0)] {
            let v = dir(tv, 0.0);
            let p = ([0.8, 0.4, 0.2], 0.3, alpha, ([0.03, 0.06, 0.01], 0.7));
            let k = 400;
            let mut grid = [0.0; 3];
            for i in 0..k {
                for j in 0..k {
                    let (xi1, phi) = ((i as f64 + 0.5) / k as f64, 2.0 * PI * (j as f64 + 0.5) / k as f64);
                    let (w, _) = gltf_lobe_sample((n, t, b), v, p, xi1, phi);
                    for c in 0..3 {
                        grid[c] += w[c] / (k * k) as f64;
                    }
                }
            }
            let kb = 2000;
            let mut brute = [0.0; 3];
            for i in 0..kb {
                let th = (i as f64 + 0.5) / kb as f64 * PI / 2.0;
                for j in 0..kb {
                    let ph = (j as f64 + 0.5) / kb as f64 * 2.0 * PI;
                    let l = dir(th, ph);
                    let lobe = gltf_lobe_rgb(n, l, v, p.0, p.1, p.2, p.3);
                    let w = th.cos() * th.sin() * (PI / 2.0 / kb as f64) * (2.0 * PI / kb as f64);
                    for c in 0..3 {
                        brute[c] += lobe[c] * w;
                    }
                }
            }
            for c in 0..3 {
                assert!((grid[c] - brute[c]).abs() < 2e-3 * brute[c].abs().max(0.05), "α {alpha}: {grid:?} {brute:?}");
            }
        }
    }
}

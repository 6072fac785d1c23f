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

use glam::DVec3;

use super::brdf::lambert_brdf;
use super::lights::{light_irradiance_visible, light_specular_visible};
use super::lobe::SurfacePoint;
use super::visibility::Shadowing;
use crate::scene::{Brdf, Lights};

use super::options::ShadingOptions;

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
    let mut e = [0.0; 3];
    for light in lights.iter() {
        add(&mut e, light_irradiance_visible(light, point, options, shadow).0);
    }
    e
}

/// Outgoing radiance [W/(m²·sr)] per linear RGB channel at `point` towards the viewer, every light unoccluded.
pub fn radiance_out(brdf: &Brdf, point: &SurfacePoint, lights: &Lights, options: &ShadingOptions) -> [f64; 3] {
    radiance_out_visible(brdf, point, lights, options, None)
}

/// Outgoing radiance [W/(m²·sr)] per linear RGB channel at `point` towards the viewer from the visible part of
/// each light (`shadow`; `None`: unoccluded): `kd/π · E + ks · Σ specular`, the diffuse part by the lights'
/// visible fractions, each specular sample by its own shadow ray (`lights`; the sun's only in its penumbra).
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
    let lobed = !brdf.is_lambert();
    let (mut e, mut specular) = ([0.0; 3], [0.0; 3]);
    for light in lights.iter() {
        let (irradiance, fraction) = light_irradiance_visible(light, point, options, shadow);
        add(&mut e, irradiance);
        if lobed {
            add(&mut specular, light_specular_visible(light, brdf, point, options, shadow, fraction));
        }
    }
    let (kd, ks) = (brdf.kd(), brdf.ks());
    let mut radiance = [0, 1, 2].map(|c| lambert_brdf(kd[c] as f64) * e[c]);
    if lobed {
        for c in 0..3 {
            radiance[c] += ks[c] as f64 * specular[c];
        }
    }
    radiance
}

/// `sum += term`, per channel.
fn add(sum: &mut [f64; 3], term: [f64; 3]) {
    for (s, t) in sum.iter_mut().zip(term) {
        *s += t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Sun;
    use crate::shading::lights::sky::sky_lobe_integral;
    use crate::shading::lobe::*;
    use std::f64::consts::PI;

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
}

//! The BRDFs on the CPU, in f64: reciprocity, energy conservation (directional albedo ≤ 1 at 0°, 30°, 60°, 85°
//! and 89.9° incidence by converged quadrature), finite values at grazing angles and extreme exponents.

use glam::DVec3;
use sunshade::scene::material::DielectricSpecular;
use sunshade::scene::Brdf;
use sunshade::shading::albedo::lobe_albedo;
use sunshade::shading::{specular_lobe, SurfacePoint};

const INCIDENCES_DEGREES: [f64; 5] = [0.0, 30.0, 60.0, 85.0, 89.9];

fn specular_models() -> Vec<(String, Brdf)> {
    let (z, o) = ([0.0f32; 3], [1.0f32; 3]);
    let mut v = Vec::new();
    for e in [0.0f32, 1.0, 100.0, 1e4, 1e6] {
        v.push((format!("Phong e={e}"), Brdf::Phong { kd: z, ks: o, exponent: e }));
        v.push((format!("Blinn-Phong e={e}"), Brdf::BlinnPhong { kd: z, ks: o, exponent: e }));
    }
    for a in [0.01f32, 0.05, 0.2, 0.5, 1.0] {
        v.push((format!("Ward α={a}"), Brdf::Ward { kd: z, ks: o, alpha_x: a, alpha_y: a }));
    }
    v.push(("Ward αx=0.02 αy=0.3".into(), Brdf::Ward { kd: z, ks: o, alpha_x: 0.02, alpha_y: 0.3 }));
    // glTF's white metal: its lobe is the whole BRDF, GGX with Fresnel 1 (its dielectric's lobe can be negative:
    // shading::brdf::metallic_roughness's tests).
    for a in [0.001f32, 0.01, 0.1, 0.5, 1.0] {
        v.push((
            format!("glTF metal α={a}"),
            Brdf::Gltf { base_color: o, metallic: 1.0, alpha: a, specular: DielectricSpecular::DEFAULT },
        ));
    }
    v
}

fn point(to_viewer: DVec3) -> SurfacePoint {
    SurfacePoint { position: DVec3::ZERO, normal: DVec3::Y, tangent: DVec3::X, bitangent: DVec3::Z, to_viewer }
}

/// Deterministic directions in the upper hemisphere, some within 1e-7 of the horizon.
fn directions() -> Vec<DVec3> {
    let mut v = Vec::new();
    for i in 0..12 {
        for j in 0..8 {
            let elevation = if i == 0 { 1e-7 } else { (i as f64 / 12.0) * 0.5 * std::f64::consts::PI };
            let azimuth = j as f64 * 0.83;
            v.push(DVec3::new(elevation.cos() * azimuth.cos(), elevation.sin(), elevation.cos() * azimuth.sin()));
        }
    }
    v
}

#[test]
fn every_lobe_is_reciprocal() {
    for (name, brdf) in specular_models() {
        for a in directions() {
            for b in directions() {
                let ab = specular_lobe(&brdf, &point(b), a);
                let ba = specular_lobe(&brdf, &point(a), b);
                assert!(ab.is_finite() && ba.is_finite(), "{name}: not finite for {a} {b}");
                assert!(
                    (ab - ba).abs() <= 1e-12 * ab.abs().max(ba.abs()),
                    "{name}: ρ({a}, {b}) = {ab} but ρ({b}, {a}) = {ba}"
                );
            }
        }
    }
}

#[test]
fn directional_albedo_never_exceeds_one() {
    for (name, brdf) in specular_models() {
        for deg in INCIDENCES_DEGREES {
            for azimuth in [0.0, 0.8] {
                let (a, change) = lobe_albedo(&brdf, deg.to_radians(), azimuth, 1e-9);
                assert!(change < 1e-4, "{name} at {deg}°: quadrature not converged (last change {change:e})");
                assert!(a <= 1.0 + 1e-6, "{name} at {deg}°: albedo {a} > 1");
                assert!(a > 0.0, "{name} at {deg}°: albedo {a}");
            }
        }
    }
}

#[test]
fn known_albedos() {
    let ks = [1.0f32; 3];
    // Narrow modified-Phong lobes entirely above the horizon reflect cos θ; the Blinn-Phong normalization makes
    // normal incidence exactly 1; bounded Ward at normal incidence: 1 − α² for small α (1 − 1e-4 at α = 0.01).
    let (a, _) = lobe_albedo(&Brdf::Phong { kd: [0.0; 3], ks, exponent: 1e4 }, 60f64.to_radians(), 0.0, 1e-10);
    assert!((a - 0.5).abs() < 1e-8, "{a}");
    let (a, _) = lobe_albedo(&Brdf::BlinnPhong { kd: [0.0; 3], ks, exponent: 37.0 }, 0.0, 0.0, 1e-10);
    assert!((a - 1.0).abs() < 1e-8, "{a}");
    let (a, _) = lobe_albedo(&Brdf::Ward { kd: [0.0; 3], ks, alpha_x: 0.01, alpha_y: 0.01 }, 0.0, 0.0, 1e-10);
    assert!((a - (1.0 - 1e-4)).abs() < 1e-8, "{a}");
}

#[test]
fn lobes_are_finite_at_grazing_and_extreme_exponents() {
    let n = DVec3::Y;
    for (name, brdf) in specular_models() {
        for l_elevation in [0.0f64, 1e-7, 1e-3] {
            for v_elevation in [0.0f64, 1e-7, 1e-3] {
                for azimuth in [0.0f64, 1.0, std::f64::consts::PI] {
                    let l = DVec3::new(l_elevation.cos(), l_elevation.sin(), 0.0);
                    let v = DVec3::new(
                        -v_elevation.cos() * azimuth.cos(),
                        v_elevation.sin(),
                        v_elevation.cos() * azimuth.sin(),
                    );
                    let value = specular_lobe(&brdf, &point(v), l);
                    assert!(value.is_finite() && value >= 0.0, "{name}: {value} for l {l} v {v}");
                    // Light exactly on the horizon contributes nothing once weighted by n·l = 0.
                    if l_elevation == 0.0 {
                        assert_eq!(value * n.dot(l).max(0.0), 0.0);
                    }
                }
            }
        }
        // Light below the horizon: the lobe is finite and the radiance weight (n·l)+ is 0.
        let below = DVec3::new(0.6, -0.8, 0.0);
        assert!(specular_lobe(&brdf, &point(DVec3::new(-0.6, 0.8, 0.0)), below).is_finite());
    }
}

/// The sun's disk with the lobe's peak at its centre, at normal incidence (n = l = v): for the Phong lobe the
/// integral over the cap of half-angle σ is `∫ (e + 2)/(2π) cosᵉβ cos β dω = 1 − cos^{e+2} σ` exactly. The
/// graded grid reaches it at the default 8 × 8 and converges at second order.
#[test]
fn sun_lobe_integral_matches_the_closed_form() {
    let sigma = 0.5 * 0.53f64.to_radians();
    let p = point(DVec3::Y);
    for e in [1.0f64, 100.0, 1e4, 1e5, 1e6] {
        let brdf = Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: e as f32 };
        let exact = -((e + 2.0) * sigma.cos().ln()).exp_m1();
        let err = |k| (sunshade::shading::sun_lobe_integral(&brdf, &p, DVec3::Y, 2.0 * sigma, k) - exact).abs() / exact;
        let (e8, e16, e32) = (err(8), err(16), err(32));
        println!("e = {e}: relative error 8×8 {e8:.1e}, 16×16 {e16:.1e}, 32×32 {e32:.1e}");
        assert!(e8 < 5e-3, "e = {e}: {e8:e} at 8 × 8");
        assert!(e32 < 2e-4, "e = {e}: {e32:e} at 32 × 32");
    }
}

/// A disk light whose solid angle holds the whole lobe: the integral over the disk equals the lobe's directional
/// albedo (quadrature), whatever the lobe's width; and a constant lobe (Phong e = 0, ρ = 1/π) gives the disk's
/// exact projected solid angle over π.
#[test]
fn disk_lobe_integral_resolves_narrow_and_wide_lobes() {
    use sunshade::shading::disk_lobe_integral;
    use sunshade::shading::lights::disk::{disk_projected_solid_angle, DiskGeometry};
    let disk = DiskGeometry { center: DVec3::new(0.0, 2.5, 0.0), direction: -DVec3::Y, radius: 0.6 };
    for x in [0.0f64, 0.8, 2.0] {
        let position = DVec3::new(x, 0.0, 0.3);
        let l = (disk.center - position).normalize();
        let v = DVec3::new(-l.x, l.y, -l.z); // the mirror of the centre's direction about n = +Y
        let p = SurfacePoint { position, ..point(v) };
        let theta = v.y.acos();
        let azimuth = v.z.atan2(v.x);
        for (name, brdf) in specular_models().into_iter().filter(|(n, _)| {
            ["Phong e=10000", "Phong e=1000000", "Blinn-Phong e=10000", "Blinn-Phong e=1000000", "Ward α=0.01"]
                .contains(&n.as_str())
        }) {
            let (albedo, _) = lobe_albedo(&brdf, theta, azimuth, 1e-10);
            // The default 16 × 16 resolves lobes down to e = 1e4 (0.6° wide, against the disk's 27°); the 0.06°
            // of e = 1e6 take 64 × 64 (docs/accuracy.md, "BRDFs").
            let k = if name.ends_with("e=1000000") { 64 } else { 16 };
            let got = disk_lobe_integral(&brdf, &p, &disk, k);
            let rel = (got - albedo).abs() / albedo;
            println!("{name} at x = {x}: {k} × {k} gives {got:.6} against the albedo {albedo:.6} ({rel:.1e})");
            assert!(rel < 1e-3, "{name} at x = {x}: {got} against {albedo}");
        }
        let constant = Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent: 0.0 };
        let exact = disk_projected_solid_angle(position, DVec3::Y, &disk) / std::f64::consts::PI;
        let got = disk_lobe_integral(&constant, &p, &disk, 16);
        assert!((got - exact).abs() < 1e-4 * exact, "constant lobe at x = {x}: {got} against {exact}");
    }
}

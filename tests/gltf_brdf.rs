//! The glTF 2.0 specification's metallic-roughness BRDF (`--brdf gltf`), GPU (lavapipe, validation on) and CPU
//! reference, against the specification's formulas written out here in f64:
//!
//! - a square seen in perspective under a delta sun: every covered pixel against `ρ(l, v) E⊥ (n·l)`, with l the
//!   sun and v the ray to the pixel's point, for several base colours, metallic 0, 0.5 and 1, roughness 0.15 to 1,
//!   and suns from high to 2° above the plane; and with KHR_materials_ior and KHR_materials_specular, whose
//!   dielectric Fresnel is written out here from the extensions' text;
//! - the white furnace: metallic 1, base colour 1 (Fresnel 1), a floor under a uniform sky, every pixel against
//!   the GGX directional albedo `∫ D V (n·l) dω` computed here by quadrature (single scattering: below 1, the
//!   more so the rougher).

mod common;

use common::{CheckedRenderer, TempDir};
use glam::{DVec3, Vec3};
use serde_json::json;
use std::f64::consts::PI;
use sunshade::authoring::shapes::quad;
use sunshade::authoring::{GltfBuilder, Node};
use sunshade::cpu;
use sunshade::scene::{BrdfKind, Camera, Lights, Projection, Scene, Sun};
use sunshade::settings::RenderSettings;
use sunshade::shading::{ShadingOptions, Shadows, SunModel};
use sunshade::Image;

/// The sun's irradiance on a surface facing it [W/m²].
const E_PERP: f64 = 1000.0;

/// The dielectric of a material's extensions as KHR_materials_ior and KHR_materials_specular write it:
/// `dielectric_f0 = min(((ior − 1)/(ior + 1))² specularColor, 1) specular`, `dielectric_f90 = specular` (ior 1.5,
/// specular 1 and colour 1 by default; ior 0 stands for a reflectance of 1).
fn dielectric(extensions: &serde_json::Value) -> ([f64; 3], f64) {
    let ior = extensions["KHR_materials_ior"]["ior"].as_f64().unwrap_or(1.5);
    let s = &extensions["KHR_materials_specular"];
    let weight = s["specularFactor"].as_f64().unwrap_or(1.0);
    let colour: Vec<f64> =
        s["specularColorFactor"].as_array().map_or(vec![1.0; 3], |a| a.iter().map(|x| x.as_f64().unwrap()).collect());
    let reflectance = if ior == 0.0 { 1.0 } else { ((ior - 1.0) / (ior + 1.0)).powi(2) };
    ([0, 1, 2].map(|c| (reflectance * colour[c]).min(1.0) * weight), weight)
}

/// The specification's BRDF (glTF 2.0, Appendix B), as written there: unit half vector, GGX's
/// `α² / (π ((n·h)²(α² − 1) + 1)²)`, the separable Smith V, Schlick's Fresnel with `pow`, the dielectric's
/// `fresnel_mix` over the Lambertian base colour (KHR_materials_specular's: `F = mix(f0, f90, (1 − v·h)⁵)` per
/// channel, the base weighted by `1 − max_value(F)`) and the metal's `conductor_fresnel`, mixed by metallic.
fn specification(
    n: DVec3,
    l: DVec3,
    v: DVec3,
    base: [f64; 3],
    metallic: f64,
    roughness: f64,
    (f0, f90): ([f64; 3], f64),
) -> [f64; 3] {
    let alpha = roughness * roughness;
    let a2 = alpha * alpha;
    let h = (l + v).normalize();
    let (nh, nl, nv, vh) = (n.dot(h), n.dot(l), n.dot(v), v.dot(h));
    let d = if nh > 0.0 { a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2)) } else { 0.0 };
    let vis = 1.0 / ((nl.abs() + (a2 + (1.0 - a2) * nl * nl).sqrt()) * (nv.abs() + (a2 + (1.0 - a2) * nv * nv).sqrt()));
    let weight = (1.0 - vh.abs()).powf(5.0);
    let fr = f0.map(|f| f + (f90 - f) * weight);
    let fr_max = fr[0].max(fr[1]).max(fr[2]);
    [0, 1, 2].map(|i| {
        let c = base[i];
        let metal = (c + (1.0 - c) * weight) * vis * d;
        let dielectric = (1.0 - fr_max) * c / PI + fr[i] * vis * d;
        (1.0 - metallic) * dielectric + metallic * metal
    })
}

/// A material's base colour, metallic and roughness factors.
type Factors = ([f32; 3], f32, f32);

/// A 4 × 4 m square through the origin with normal `normal` (+Z or +Y), of a glTF metallic-roughness material
/// with `extensions` (an object).
fn square(
    dir: &TempDir,
    name: &str,
    normal: Vec3,
    (base, metallic, roughness): Factors,
    extensions: &serde_json::Value,
) -> Scene {
    let mut b = GltfBuilder::new();
    let m = b.add_material_json(json!({
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [base[0], base[1], base[2], 1.0],
            "metallicFactor": metallic,
            "roughnessFactor": roughness,
        },
        "extensions": extensions,
    }));
    let (u, v) = if normal == Vec3::Z { (Vec3::X, Vec3::Y) } else { (Vec3::X, -Vec3::Z) };
    let mesh = b.add_mesh("square", &[quad(Vec3::ZERO, 2.0 * u, 2.0 * v).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    let mut scene = common::load(&dir.write(&format!("{name}.glb"), &b));
    scene.map_brdfs(BrdfKind::Gltf);
    scene
}

/// The worst relative error over the covered pixels of `image` against `want(point, to_viewer)`, with the diff's
/// floor (1% of the expected peak) in the denominator; and how many pixels were covered.
fn worst_against(
    image: &Image,
    s: &RenderSettings,
    plane_normal: DVec3,
    want: impl Fn(DVec3, DVec3) -> [f64; 3],
) -> (f64, usize) {
    let inv = s.camera.clip_from_world(s.aspect()).inverse();
    let (w, h) = (s.width, s.height);
    let mut expected = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if !image.covered(x, y) {
                continue;
            }
            let (o, d) = common::pixel_ray(&inv, x as f64 + 0.5, y as f64 + 0.5, w, h);
            let t = -o.dot(plane_normal) / d.dot(plane_normal);
            expected.push(((x, y), want(o + t * d, -d)));
        }
    }
    let peak = expected.iter().flat_map(|(_, e)| e.iter().copied()).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for ((x, y), e) in &expected {
        let got = image.get(*x, *y);
        for c in 0..3 {
            let err = (got[c] as f64 - e[c]).abs() / e[c].abs().max(1e-2 * peak);
            worst = worst.max(err);
        }
    }
    (worst, expected.len())
}

#[test]
fn a_plane_under_a_delta_sun_is_the_specification() {
    let dir = TempDir::new("gltf-spec");
    let mut gpu = CheckedRenderer::new();
    let camera = Camera::look_at(
        DVec3::new(0.4, -2.2, 1.6),
        DVec3::new(0.0, 0.1, 0.0),
        DVec3::Z,
        Projection::Perspective { yfov: 50f64.to_radians(), znear: 0.1, zfar: Some(20.0) },
    )
    .unwrap();
    // (base colour, metallic, roughness), extensions.
    let none = json!({});
    let materials: [(Factors, serde_json::Value); 9] = [
        (([0.9, 0.5, 0.1], 0.0, 0.15), none.clone()),
        (([0.9, 0.5, 0.1], 1.0, 0.15), none.clone()),
        (([0.2, 0.6, 0.9], 0.5, 0.4), none.clone()),
        (([1.0, 1.0, 1.0], 1.0, 0.7), none.clone()),
        (([0.05, 0.05, 0.05], 0.0, 1.0), none.clone()),
        (([0.8, 0.8, 0.2], 0.5, 1.0), none),
        // A denser dielectric; a weaker, tinted specular whose blue is clamped at f0 = 1 before the weight; a
        // specular-glossiness conversion (ior 0: the colour is f0).
        (([0.9, 0.5, 0.1], 0.0, 0.3), json!({"KHR_materials_ior": {"ior": 2.0}})),
        (
            ([0.2, 0.6, 0.9], 0.5, 0.4),
            json!({"KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1.0, 0.5, 30.0]}}),
        ),
        (
            ([0.3, 0.3, 0.3], 0.0, 0.15),
            json!({"KHR_materials_ior": {"ior": 0.0},
                   "KHR_materials_specular": {"specularColorFactor": [0.2, 0.3, 0.4]}}),
        ),
    ];
    // Suns from near the camera's mirror direction (the highlight on the square) to 2° above the plane.
    let suns = [DVec3::new(-0.3, 1.9, 1.7), DVec3::new(1.0, 0.5, 0.6), DVec3::new(-0.6, 1.0, 0.0435)];
    let mut failures = Vec::new();
    for (i, (factors, extensions)) in materials.iter().enumerate() {
        let (base, metallic, roughness) = *factors;
        let scene = square(&dir, &format!("m{i}"), Vec3::Z, *factors, extensions);
        let d = dielectric(extensions);
        for sun in suns {
            let l32 = sun.normalize().as_vec3();
            let lights = Lights {
                sun: Some(Sun {
                    direction: l32,
                    irradiance: [E_PERP as f32; 3],
                    angular_diameter: 0.53f32.to_radians(),
                }),
                ..Default::default()
            };
            let mut s = RenderSettings::new(128, 96, camera, lights);
            s.shading = ShadingOptions { sun: SunModel::Delta, shadows: Shadows::None, ..Default::default() };
            let l = l32.as_dvec3();
            let eye = camera.eye;
            let want = |p: DVec3, _: DVec3| {
                let v = (eye - p).normalize();
                let rho = specification(DVec3::Z, l, v, base.map(f64::from), metallic as f64, roughness as f64, d);
                rho.map(|r| r * E_PERP * l.z.max(0.0))
            };
            for (who, image) in
                [("GPU", gpu.render(&scene, &s)), ("reference", cpu::render(&scene, &s, &gpu.reference_options()))]
            {
                let (worst, covered) = worst_against(&image, &s, DVec3::Z, want);
                assert!(covered > 5000, "only {covered} pixels covered");
                println!("{who:9} base {base:?} m {metallic} r {roughness} {extensions} sun {sun}: worst {worst:.2e}");
                if worst > 1e-4 {
                    failures.push(format!(
                        "{who} base {base:?} m {metallic} r {roughness} {extensions} sun {sun}: {worst:.3e}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "over 1e-4: {failures:#?}");
}

/// GGX's directional albedo with Fresnel 1, `∫ D V (n·l) dω` over the hemisphere about n = +Y for the viewer v, by
/// the midpoint rule in (θ, φ) of l, graded in θ about the mirror direction's θ (`θ = θm + w sinh z`) so that the
/// narrow peak is resolved.
fn ggx_albedo(v: DVec3, roughness: f64) -> f64 {
    let n = DVec3::Y;
    let (theta_count, phi_count) = (300, 300);
    let theta_m = v.dot(n).clamp(-1.0, 1.0).acos();
    let w = (roughness * roughness).max(1e-3);
    let (za, zb) = ((-theta_m / w).asinh(), ((PI / 2.0 - theta_m) / w).asinh());
    let phi_v = v.z.atan2(v.x);
    let mut sum = 0.0;
    for i in 0..theta_count {
        let z = za + (i as f64 + 0.5) / theta_count as f64 * (zb - za);
        let theta = theta_m + w * z.sinh();
        let d_theta = w * z.cosh() * (zb - za) / theta_count as f64;
        for j in 0..phi_count {
            // φ about the mirror azimuth (φv + π), where the peak is.
            let phi = phi_v + PI + (j as f64 + 0.5) / phi_count as f64 * 2.0 * PI;
            let l = DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            let rho = specification(n, l, v, [1.0; 3], 1.0, roughness, ([0.04; 3], 1.0))[0];
            sum += rho * theta.cos() * theta.sin() * d_theta * (2.0 * PI / phi_count as f64);
        }
    }
    sum
}

#[test]
fn white_furnace_is_the_ggx_directional_albedo() {
    let dir = TempDir::new("gltf-furnace");
    let mut gpu = CheckedRenderer::new();
    let camera = Camera::look_at(
        DVec3::new(0.3, 1.2, 2.0),
        DVec3::new(0.0, 0.0, -0.3),
        DVec3::Y,
        Projection::Perspective { yfov: 70f64.to_radians(), znear: 0.1, zfar: Some(20.0) },
    )
    .unwrap();
    const L0: f64 = 100.0;
    let mut albedos = Vec::new();
    for roughness in [0.5f32, 1.0] {
        let scene = square(&dir, &format!("furnace{roughness}"), Vec3::Y, ([1.0; 3], 1.0, roughness), &json!({}));
        let lights = Lights { sky: Some([L0 as f32; 3]), ..Default::default() };
        let mut s = RenderSettings::new(24, 18, camera, lights);
        // Fine lobe grids: the comparison is with the integral, not with the default grid's error.
        s.shading = ShadingOptions { samples_per_axis: 96, shadows: Shadows::None, ..Default::default() };
        let eye = camera.eye;
        let want = |p: DVec3, _: DVec3| [L0 * ggx_albedo((eye - p).normalize(), roughness as f64); 3];
        for (who, image) in
            [("GPU", gpu.render(&scene, &s)), ("reference", cpu::render(&scene, &s, &gpu.reference_options()))]
        {
            let (worst, covered) = worst_against(&image, &s, DVec3::Y, want);
            assert!(covered > 200, "only {covered} pixels covered");
            println!("{who:9} roughness {roughness}: worst {worst:.2e}");
            assert!(worst < 1e-3, "{who}, roughness {roughness}: {worst:.3e} from the directional albedo");
        }
        albedos.push(ggx_albedo(DVec3::Y, roughness as f64));
    }
    // Single scattering loses energy, the more the rougher. At α = 1, D = 1/π and V = 1/((n·l + 1)(n·v + 1)), so
    // at normal view `a = ∫₀¹ 2c/(2(1 + c)) dc = 1 − ln 2` exactly: the quadrature's own check (it errs by 2.8e-6
    // on its 300² grid, 7e-7 on 600²: second order).
    assert!(albedos[0] < 1.0 && albedos[1] < albedos[0], "{albedos:?}");
    assert!((albedos[1] - (1.0 - 2f64.ln())).abs() < 1e-5, "{albedos:?}");
}

/// The extensions load as drawn: no "ignored" warning for KHR_materials_ior and KHR_materials_specular's factors,
/// one naming the specular textures sunshade does not read, and a bad value refused in one line naming the material.
#[test]
fn ior_and_specular_extensions_load_with_what_they_leave_out_named() {
    let dir = TempDir::new("gltf-khr");
    let ext = json!({"KHR_materials_ior": {"ior": 3.0}, "KHR_materials_specular": {"specularFactor": 0.8}});
    let scene = square(&dir, "plain", Vec3::Z, ([0.5; 3], 0.0, 0.5), &ext);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let sunshade::scene::Brdf::Gltf { specular, .. } = scene.materials[0].brdf else { panic!() };
    // ((3 − 1)/(3 + 1))² = 1/4, times the weight.
    assert_eq!((specular.f0, specular.f90), ([0.2; 3], 0.8));
    let textured = json!({"KHR_materials_specular": {"specularColorTexture": {"index": 0}}});
    let scene = square(&dir, "textured", Vec3::Z, ([0.5; 3], 0.0, 0.5), &textured);
    assert!(scene.warnings.len() == 1 && scene.warnings[0].contains("specularColorTexture"), "{:?}", scene.warnings);
    let mut b = GltfBuilder::new();
    let m = b.add_material_json(json!({"name": "bad", "extensions": {"KHR_materials_ior": {"ior": 0.5}}}));
    let mesh = b.add_mesh("square", &[quad(Vec3::ZERO, Vec3::X, Vec3::Y).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    let e = sunshade::scene::load(&dir.write("bad.glb", &b)).unwrap_err().to_string();
    assert!(e.contains("bad.glb") && e.contains("'bad'") && e.contains("ior 0.5") && !e.contains('\n'), "{e}");
}

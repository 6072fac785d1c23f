//! The BRDFs on the GPU (lavapipe, validation on) against the CPU reference and analytic values.
//!
//! - The BRDF chart (`sunshade::authoring::chart`): spheres, one per model and parameter, each sweeping every incidence and view angle under the sun
//!   from three directions, compared pixel by pixel with the f64 reference.
//! - Radiance far above the f16 range (a lobe of exponent 1e6 under the sun, ~1e8 W/(m²·sr)) against its
//!   closed form.
//! - Light at and below the horizon, and at 1e-7 above it: finite, and exactly 0 where n·l ≤ 0.

mod common;

use common::{CheckedRenderer, TempDir};
use glam::{DVec3, Vec3};
use serde_json::json;
use sunshade::authoring::chart;
use sunshade::authoring::shapes::quad;
use sunshade::authoring::{GltfBuilder, Node};
use sunshade::compare::{self, DiffOptions};
use sunshade::cpu;
use sunshade::scene::{Camera, Lights, Projection, Scene, Sun};
use sunshade::settings::RenderSettings;
use sunshade::shading::{ShadingOptions, SunModel};

/// The relative error the f32 shader reaches on smooth, diffuse-dominated shading (the reference issue's
/// tolerance and this target).
const BASE_TOLERANCE: f64 = 1e-5;

/// The error [rad] of a unit direction the shader works with: the interpolated normal, measured against the
/// reference's to at most 1.6e-7 (docs/accuracy.md, "BRDFs"), and the half vector or mirror direction built
/// from it, a few roundings more.
const DIRECTION_ERROR: f64 = 2.5e-7;

/// How far a lobe's value may move when its directions move by [`DIRECTION_ERROR`], relative, where the lobe is
/// above the comparison floor (1% of the peak: `e·x ≤ ln 100` for `(1 − x)^e`). This is the lobe's condition
/// number, not a fit to the measurement (docs/accuracy.md derives it):
/// - Phong: `x = |r − v|²/2`, `δx = |r − v| δ(r − v)` and `δ(r − v) ≤ 2δn + δv`, so
///   `δf/f = e δx ≤ √(2 e ln 100) · 3δ`;
/// - Blinn-Phong: `x = |n − h|²/2`, `δ(n − h) ≤ 2δ`: `δf/f ≤ √(2 e ln 100) · 2δ`;
/// - Ward: `exp(−tan²θh/α²)` moves by `2 tanθh/α² δθh ≤ 2√(ln 100)/α · 2δ` with the smaller α;
/// - glTF (GGX): `α²/(π(θh² + α²)²)` moves by `4θh/(θh² + α²) δθh ≤ 2/α · 2δ`.
fn lobe_tolerance(extras: &serde_json::Value) -> f64 {
    let spread = (2.0 * 100f64.ln()).sqrt();
    let bound = match extras["brdf"].as_str().unwrap() {
        "phong" => spread * extras["exponent"].as_f64().unwrap().sqrt() * 3.0 * DIRECTION_ERROR,
        "blinn-phong" => spread * extras["exponent"].as_f64().unwrap().sqrt() * 2.0 * DIRECTION_ERROR,
        "ward" => {
            let a = extras.get("alpha").map(|a| a.as_f64().unwrap());
            let ax = extras.get("alpha_x").and_then(|a| a.as_f64()).or(a).unwrap();
            let ay = extras.get("alpha_y").and_then(|a| a.as_f64()).or(a).unwrap();
            2.0 * 100f64.ln().sqrt() / ax.min(ay) * 2.0 * DIRECTION_ERROR
        }
        // GGX's D = α²/(π (θ² + α²)²) near its peak moves by 4θ/(θ² + α²) δθh ≤ 2/α δθh, δθh ≤ 2δ.
        "gltf" => {
            let alpha = extras["roughness"].as_f64().unwrap().powi(2);
            2.0 / alpha * 2.0 * DIRECTION_ERROR
        }
        _ => 0.0,
    };
    BASE_TOLERANCE + bound
}

fn file_name(name: &str) -> String {
    format!("{}.glb", name.replace(|c: char| !c.is_ascii_alphanumeric(), "_"))
}

/// A 2 × 2 m square in the XY plane facing +Z with the given material.
fn square_scene(dir: &TempDir, name: &str, extras: &serde_json::Value) -> Scene {
    let mut b = GltfBuilder::new();
    let m = b.add_material(name, [0.5; 3], false, Some(json!({ "sunshade": extras })));
    let mesh = b.add_mesh("square", &[quad(Vec3::ZERO, Vec3::X, Vec3::Y).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    common::load(&dir.write(&file_name(name), &b))
}

/// Orthographic, from +Z (5 m away) towards the origin.
fn front_camera() -> Camera {
    let projection = Projection::Orthographic { ymag: 1.05, znear: 1.0, zfar: 10.0 };
    Camera::looking(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, DVec3::Y, projection).unwrap()
}

fn sun(direction: DVec3, irradiance: f32) -> Sun {
    Sun {
        direction: direction.normalize().as_vec3(),
        irradiance: [irradiance; 3],
        angular_diameter: 0.53f32.to_radians(),
    }
}

/// The BRDF chart's spheres, written into `dir` and loaded: each material's name, scene and GPU tolerance.
fn chart_spheres(dir: &TempDir) -> Vec<(String, Scene, f64)> {
    chart::brdf_chart()
        .into_iter()
        .map(|material| {
            let scene = common::load(&dir.write(&chart::file_name(&material), &chart::sphere_scene(&material)));
            (material.name.clone(), scene, lobe_tolerance(&material.extras))
        })
        .collect()
}

#[test]
fn brdf_chart_gpu_against_reference() {
    let dir = TempDir::new("chart");
    let mut gpu = CheckedRenderer::new();
    let mut failures = Vec::new();
    for (name, scene, tolerance) in chart_spheres(&dir) {
        let mut worst = 0.0f64;
        let mut peak = 0.0f64;
        for degrees in chart::SUN_FROM_VIEW_DEGREES {
            let lights = Lights {
                sun: Some(sun(DVec3::from_array(chart::sun_direction(degrees)), 1000.0)),
                ..Default::default()
            };
            let mut s = RenderSettings::new(256, 256, scene.cameras[0].1, lights);
            s.shading = ShadingOptions { sun: SunModel::Delta, ..Default::default() };
            let g = gpu.render(&scene, &s);
            let c = cpu::render(&scene, &s, &gpu.reference_options());
            assert!(
                g.pixels().iter().all(|p| p.iter().all(|v| v.is_finite() && *v >= 0.0)),
                "{name}: non-finite pixel"
            );
            let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
            assert_eq!(report.coverage_mismatches.total, 0, "{name}: coverage differs");
            assert!(report.covered_b > 40_000, "{name}: only {} pixels covered", report.covered_b);
            worst = worst.max(report.max_rel_interior);
            peak = peak.max(report.peak);
        }
        println!("{name:24} max rel {worst:.2e} (tolerance {tolerance:.1e}), peak {peak:.3e} W/(m²·sr)");
        if worst > tolerance {
            failures.push(format!("{name}: {worst:.3e} > {tolerance:.3e}"));
        }
    }
    assert!(failures.is_empty(), "over tolerance: {failures:?}");
}

/// The chart's spheres under an overcast sky alone: the sky's lobe grids over the hemisphere and over the lunes
/// the horizontal cuts it into (`shading::sky_lune`), every lobe from Phong e = 1 to 1e6 and the anisotropic
/// Ward, GPU against the reference to the chart's tolerances.
#[test]
fn brdf_chart_under_the_sky_gpu_against_reference() {
    let dir = TempDir::new("chart-sky");
    let mut gpu = CheckedRenderer::new();
    let mut failures = Vec::new();
    for (name, scene, tolerance) in chart_spheres(&dir) {
        let lights = Lights { sky: Some([100.0; 3]), ..Default::default() };
        let s = RenderSettings::new(128, 128, scene.cameras[0].1, lights);
        let g = gpu.render(&scene, &s);
        let c = cpu::render(&scene, &s, &gpu.reference_options());
        assert!(g.pixels().iter().all(|p| p.iter().all(|v| v.is_finite() && *v >= 0.0)), "{name}: non-finite pixel");
        let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
        assert!(report.covered_b > 8_000, "{name}: only {} pixels covered", report.covered_b);
        println!("{name:24} sky: max rel {:.2e} (tolerance {tolerance:.1e})", report.max_rel_interior);
        if report.max_rel_interior > tolerance {
            failures.push(format!("{name}: {:.3e} > {tolerance:.3e}", report.max_rel_interior));
        }
    }
    assert!(failures.is_empty(), "over tolerance: {failures:?}");
}

/// A square facing the viewer, the sun straight behind the viewer (l = v = n): every pixel reflects the lobe's
/// peak, `ks ρ_peak E⊥ + kd E⊥/π` with `ρ_peak = (e + 2)/(2π)` (Phong) or the Blinn-Phong normalization, about
/// 1.1e8 (Phong) and 2.8e7 (Blinn-Phong) W/(m²·sr) at e = 1e6: far above f16's 65504, and exact in the f32
/// framebuffer.
#[test]
fn radiance_far_above_f16_range_is_exact() {
    let dir = TempDir::new("f16");
    let mut gpu = CheckedRenderer::new();
    let e = 1e6f64;
    let (kd, ks, irradiance) = (0.2f64, 0.7f64, 1000.0f32);
    let blinn_peak = (e + 2.0) * (e + 4.0) / (8.0 * std::f64::consts::PI * (e + 2f64.powf(-e / 2.0)));
    for (brdf, peak) in [("phong", (e + 2.0) / (2.0 * std::f64::consts::PI)), ("blinn-phong", blinn_peak)] {
        let extras = json!({ "brdf": brdf, "kd": [kd, kd, kd], "ks": [ks, ks, ks], "exponent": e });
        let scene = square_scene(&dir, brdf, &extras);
        let lights = Lights { sun: Some(sun(DVec3::Z, irradiance)), ..Default::default() };
        let mut s = RenderSettings::new(64, 64, front_camera(), lights);
        s.shading = ShadingOptions { sun: SunModel::Delta, ..Default::default() };
        let g = gpu.render(&scene, &s);
        let expected = (ks * peak + kd / std::f64::consts::PI) * irradiance as f64;
        assert!(expected > 100.0 * 65504.0, "{expected}"); // f16 max: 65504
        let mut covered = 0;
        for p in g.pixels().iter().filter(|p| p[3] > 0.0) {
            covered += 1;
            for &v in &p[..3] {
                let rel = (v as f64 - expected).abs() / expected;
                assert!(rel < 1e-6, "{brdf}: {v} W/(m²·sr), expected {expected} (relative error {rel:.2e})");
            }
        }
        assert!(covered > 3000, "{brdf}: {covered} pixels covered");
    }
}

/// Light exactly on the horizon, below it, and 1e-7 rad above it, onto a square seen at 60° from its normal:
/// every pixel finite, exactly 0 where n·l ≤ 0, and equal to the reference where n·l = 1e-7 (a radiance of
/// order 1e-4 W/(m²·sr), from the lobe's value at grazing incidence times n·l).
#[test]
fn light_at_and_below_the_horizon() {
    let dir = TempDir::new("horizon");
    let mut gpu = CheckedRenderer::new();
    let models = [
        json!({ "brdf": "lambert", "albedo": [0.8, 0.8, 0.8] }),
        json!({ "brdf": "phong", "kd": [0.3, 0.3, 0.3], "ks": [0.7, 0.7, 0.7], "exponent": 1e4 }),
        json!({ "brdf": "phong", "kd": [0.0, 0.0, 0.0], "ks": [1.0, 1.0, 1.0], "exponent": 1.0 }),
        json!({ "brdf": "blinn-phong", "kd": [0.3, 0.3, 0.3], "ks": [0.7, 0.7, 0.7], "exponent": 1e4 }),
        json!({ "brdf": "ward", "kd": [0.3, 0.3, 0.3], "ks": [0.7, 0.7, 0.7], "alpha": 0.01 }),
        json!({ "brdf": "ward", "kd": [0.0, 0.0, 0.0], "ks": [1.0, 1.0, 1.0], "alpha": 0.5 }),
        json!({ "brdf": "ward", "kd": [0.3, 0.3, 0.3], "ks": [0.7, 0.7, 0.7], "alpha_x": 0.02, "alpha_y": 0.5 }),
    ];
    let view = DVec3::new(0.0, 60f64.to_radians().sin(), 60f64.to_radians().cos());
    let camera =
        Camera::looking(view * 5.0, -view, DVec3::Y, Projection::Orthographic { ymag: 1.5, znear: 1.0, zfar: 10.0 })
            .unwrap();
    for (i, extras) in models.iter().enumerate() {
        let scene = square_scene(&dir, &format!("model {i}"), extras);
        // The mirror of the view direction lies at elevation 30° on the −Y side; the grazing suns come from
        // there and from the side.
        for elevation in [0.0f64, -1e-3, 1e-7] {
            for azimuth in [0.0f64, 1.2] {
                let toward =
                    DVec3::new(azimuth.sin(), -azimuth.cos(), 0.0) * elevation.cos() + DVec3::Z * elevation.sin();
                for model in [SunModel::Delta, SunModel::Disk] {
                    let lights = Lights { sun: Some(sun(toward, 1000.0)), ..Default::default() };
                    let mut s = RenderSettings::new(48, 48, camera, lights);
                    s.shading = ShadingOptions { sun: model, ..Default::default() };
                    let g = gpu.render(&scene, &s);
                    let c = cpu::render(&scene, &s, &gpu.reference_options());
                    let what = format!("{extras} sun at elevation {elevation}, azimuth {azimuth}, {model:?}");
                    assert!(
                        g.pixels().iter().all(|p| p.iter().all(|v| v.is_finite() && *v >= 0.0)),
                        "{what}: not finite"
                    );
                    let delta_below = model == SunModel::Delta && elevation <= 0.0;
                    if delta_below {
                        assert!(
                            g.pixels().iter().all(|p| p[..3] == [0.0; 3]),
                            "{what}: light below the horizon reflected"
                        );
                    }
                    // The sun's disk at elevation ≤ 0 is partly above the horizon (its radius is 0.265°): compare.
                    let (report, _) =
                        compare::diff(&g, &c, &DiffOptions { floor_fraction: 0.0, floor: 1e-30, ..Default::default() })
                            .unwrap();
                    println!("{what}: peak {:.3e} max rel {:.2e}", report.peak, report.max_rel_interior);
                    assert!(report.covered_b > 500, "{what}: only {} pixels covered", report.covered_b);
                    assert!(
                        report.max_rel_interior <= lobe_tolerance(extras),
                        "{what}: relative error {:.3e} (worst {:?})",
                        report.max_rel_interior,
                        report.worst
                    );
                }
            }
        }
    }
}

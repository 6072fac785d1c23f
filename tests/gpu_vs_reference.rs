//! The GPU image (lavapipe, validation on) against the CPU reference, pixel by pixel.
//!
//! Asserted for every scene:
//! - coverage mismatches: at most 1 per 100,000 pixels, and each within two sub-pixel steps of a triangle edge;
//! - interior covered pixels: relative error ≤ 1e-5 (relative to max(|a|, |b|, 1% of the peak));
//! - enough pixels are covered that the comparison means something.

mod common;

use std::path::Path;

use common::{CheckedRenderer, TempDir};
use glam::{DVec3, Quat, Vec3};
use sunshade::authoring::shapes::{cube, grid, quad, triangle_soup, uv_sphere, MeshData};
use sunshade::authoring::{GltfBuilder, Node, Transform};
use sunshade::compare::{self, DiffOptions, PixelDiff};
use sunshade::cpu;
use sunshade::scene::{Camera, DiskLight, Lights, Projection, Scene, Sun};
use sunshade::settings::{self, CameraOptions, RenderSettings, SunOptions};
use sunshade::shading::{DiskModel, ShadingOptions, SunModel};

const INTERIOR_REL_TOLERANCE: f64 = 1e-5;

/// Renders on both, compares, asserts; returns (coverage mismatches, max interior relative error).
fn check(name: &str, scene: &Scene, s: &RenderSettings, gpu: &mut CheckedRenderer, min_covered: usize) -> (usize, f64) {
    let pixels = (s.width * s.height) as usize;
    check_with(name, scene, s, gpu, min_covered, pixels / 100_000)
}

/// [`check`] with an explicit bound on coverage mismatches.
fn check_with(
    name: &str,
    scene: &Scene,
    s: &RenderSettings,
    gpu: &mut CheckedRenderer,
    min_covered: usize,
    max_mismatches: usize,
) -> (usize, f64) {
    // Rasterization, interpolation and shading agreement, unshadowed on every device (tests/shadows.rs checks the
    // shadows: on a device with ray queries the sliver soup below differs at rays grazing the slivers' edges,
    // 5.9e-2 at its worst pixel at 512², which is not what these tests measure).
    let mut s = s.clone();
    s.shading.shadows = sunshade::shading::Shadows::None;
    let s = &s;
    let g = gpu.render(scene, s);
    let options = gpu.reference_options();
    let c = cpu::render(scene, s, &options);
    let (report, per_pixel) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
    println!(
        "{name} {}x{}: covered {}, coverage mismatches {}, max rel interior {:.2e}, max rel {:.2e}, RMSE {:.2e}",
        s.width,
        s.height,
        report.covered_b,
        report.coverage_mismatches.total,
        report.max_rel_interior,
        report.max_rel,
        report.rmse
    );
    assert!(report.covered_b >= min_covered, "{name}: only {} pixels covered", report.covered_b);
    let mismatched: Vec<(u32, u32)> = per_pixel
        .iter()
        .enumerate()
        .filter(|(_, d)| matches!(d, PixelDiff::CoverageMismatch))
        .map(|(i, _)| (i as u32 % s.width, i as u32 / s.width))
        .collect();
    assert!(
        mismatched.len() <= max_mismatches,
        "{name}: {} coverage mismatches (at most {max_mismatches} allowed): {:?}",
        mismatched.len(),
        &mismatched[..mismatched.len().min(10)]
    );
    let distances = cpu::nearest_edge_distances(scene, s, &options, &mismatched);
    for (p, d) in mismatched.iter().zip(&distances) {
        assert!(*d < 2.0 / 256.0, "{name}: coverage mismatch at {p:?} is {d} px from any edge");
    }
    assert!(
        report.max_rel_interior <= INTERIOR_REL_TOLERANCE,
        "{name}: interior relative error {:.3e} (worst {:?})",
        report.max_rel_interior,
        report.worst
    );
    (mismatched.len(), report.max_rel_interior)
}

fn models_dir() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/models"))
}

#[test]
fn every_model_at_several_sizes_and_aspects() {
    let mut gpu = CheckedRenderer::new();
    for model in ["teapot.glb", "cube.glb", "spheres.glb", "square.gltf"] {
        let scene = common::load(&models_dir().join(model));
        for (w, h) in [(512, 512), (640, 360), (300, 700), (1000, 1000)] {
            let s = settings::resolve(&scene, w, h, &CameraOptions::default(), &SunOptions::default()).unwrap();
            check(model, &scene, &s, &mut gpu, (w * h / 20) as usize);
        }
    }
}

fn sun_lights(direction: DVec3) -> Lights {
    Lights {
        sun: Some(Sun {
            direction: direction.normalize().as_vec3(),
            irradiance: [1000.0, 900.0, 800.0],
            angular_diameter: 0.00925,
        }),
        ..Default::default()
    }
}

fn perspective(eye: DVec3, target: DVec3, yfov_degrees: f64, znear: f64) -> Camera {
    let projection = Projection::Perspective { yfov: yfov_degrees.to_radians(), znear, zfar: Some(100.0) };
    Camera::look_at(eye, target, DVec3::Y, projection).unwrap()
}

/// Builds, writes and loads a scene of one node per (mesh, albedo, double-sided, transform).
fn scene_of(dir: &TempDir, name: &str, parts: &[(MeshData, [f32; 3], bool, Transform)]) -> Scene {
    let mut b = GltfBuilder::new();
    let mut roots = Vec::new();
    for (i, (mesh, albedo, double_sided, transform)) in parts.iter().enumerate() {
        let m = b.add_material(&format!("m{i}"), *albedo, *double_sided, None);
        let mesh = b.add_mesh(&format!("mesh{i}"), &[mesh.primitive(Some(m))]);
        roots.push(b.add_node(Node { mesh: Some(mesh), transform: transform.clone(), ..Default::default() }));
    }
    b.add_scene(&roots, None);
    common::load(&dir.write(name, &b))
}

#[test]
fn camera_inside_a_room_with_the_near_plane_cutting_walls_and_floor() {
    let dir = TempDir::new("room");
    // A 4 × 3 × 4 m room seen from inside: floor and walls are double-sided grids, objects inside.
    let floor = grid(Vec3::ZERO, 4.0, 40);
    let wall = |rot: Quat, t: [f32; 3]| Transform::Trs { translation: t, rotation: rot.to_array(), scale: [1.0; 3] };
    let ry = |deg: f32| Quat::from_axis_angle(Vec3::Y, deg.to_radians());
    let upright = Quat::from_axis_angle(Vec3::X, 90f32.to_radians());
    let parts = vec![
        (floor.clone(), [0.6, 0.6, 0.55], true, Transform::Identity),
        (grid(Vec3::ZERO, 4.0, 30), [0.8, 0.7, 0.6], true, wall(upright, [0.0, 2.0, -2.0])),
        (grid(Vec3::ZERO, 4.0, 30), [0.7, 0.8, 0.6], true, wall(ry(90.0) * upright, [-2.0, 2.0, 0.0])),
        (grid(Vec3::ZERO, 4.0, 30), [0.6, 0.7, 0.8], true, wall(ry(-90.0) * upright, [2.0, 2.0, 0.0])),
        (uv_sphere(Vec3::new(0.5, 0.6, -0.8), 0.6, 32, 48), [0.9, 0.3, 0.2], false, Transform::Identity),
        (cube(0.4), [0.2, 0.5, 0.9], false, wall(ry(30.0), [-0.8, 0.4, 0.2])),
    ];
    let scene = scene_of(&dir, "room.glb", &parts);
    let mut gpu = CheckedRenderer::new();
    // Eye 2 cm above the floor and 10 cm from a wall, looking across the room: the floor passes under and behind
    // the eye, so its triangles cross the near plane (and the x/y planes).
    let cams = [
        perspective(DVec3::new(0.0, 0.02, 1.9), DVec3::new(0.2, 0.5, -2.0), 70.0, 0.01),
        perspective(DVec3::new(1.9, 1.5, 1.9), DVec3::new(-1.0, 0.3, -1.0), 100.0, 0.05),
        perspective(DVec3::new(-1.5, 2.5, 0.0), DVec3::new(-1.5, 0.0, 0.01), 60.0, 0.5),
    ];
    for (i, camera) in cams.into_iter().enumerate() {
        let s = RenderSettings::new(480, 320, camera, sun_lights(DVec3::new(0.3, 1.0, 0.4)));
        check(&format!("room camera {i}"), &scene, &s, &mut gpu, 480 * 320 / 2);
    }
}

#[test]
fn triangles_crossing_the_near_plane_directly_ahead() {
    let dir = TempDir::new("near");
    // Quads that reach from behind the eye to far ahead, tilted, double-sided.
    let mut mesh = MeshData::default();
    for k in 0..8 {
        let angle = k as f32 * 0.4;
        let u = Vec3::new(angle.cos(), angle.sin(), 0.0) * 0.7;
        mesh.append(&quad(Vec3::new(0.1 * k as f32, 0.05, -2.0), u, Vec3::new(0.0, 0.1, 3.0)));
    }
    let scene = scene_of(&dir, "near.glb", &[(mesh, [0.7, 0.7, 0.7], true, Transform::Identity)]);
    let mut gpu = CheckedRenderer::new();
    for znear in [0.05, 0.3, 1.0] {
        let camera = perspective(DVec3::new(0.2, 0.0, 0.5), DVec3::new(0.2, 0.0, -3.0), 75.0, znear);
        let s = RenderSettings::new(400, 300, camera, sun_lights(DVec3::new(-0.2, 0.4, 1.0)));
        check(&format!("near plane {znear}"), &scene, &s, &mut gpu, 400 * 300 / 20);
    }
}

#[test]
fn slivers_and_tiny_triangles() {
    let dir = TempDir::new("slivers");
    let soup = triangle_soup(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.3), 4000, 0.4, 11);
    // Needles: 1.6 m long, 1e-4 to 1e-2 m wide, in a fan.
    let mut needles = MeshData::default();
    for k in 0..40 {
        let a = k as f32 * 0.157;
        let dir = Vec3::new(a.cos(), a.sin(), 0.0);
        let width = 10f32.powf(-4.0 + 2.0 * (k % 5) as f32 / 4.0);
        let side = Vec3::new(-dir.y, dir.x, 0.0) * width;
        let base = needles.positions.len() as u32;
        needles.positions.extend([
            (-dir * 0.8).to_array(),
            (dir * 0.8 + side).to_array(),
            (dir * 0.8 - side).to_array(),
        ]);
        needles.normals.extend([[0.0, 0.0, 1.0]; 3]);
        needles.indices.extend([base, base + 2, base + 1]);
    }
    let scene = scene_of(
        &dir,
        "slivers.glb",
        &[(soup, [0.8, 0.8, 0.8], true, Transform::Identity), (needles, [0.4, 0.9, 0.4], true, Transform::Identity)],
    );
    let mut gpu = CheckedRenderer::new();
    for (w, h) in [(512, 512), (777, 333)] {
        let camera = perspective(DVec3::new(0.2, 0.3, 3.0), DVec3::ZERO, 45.0, 0.5);
        let s = RenderSettings::new(w, h, camera, sun_lights(DVec3::new(0.3, 0.5, 1.0)));
        check("slivers and tiny triangles", &scene, &s, &mut gpu, (w * h / 10) as usize);
    }
}

#[test]
fn shared_edges_and_vertices_leave_no_gaps() {
    let dir = TempDir::new("shared");
    // A fan of 64 triangles around one vertex and a 60 × 60 grid: every edge and vertex shared.
    let mut fan = MeshData::default();
    fan.positions.push([0.0, 0.0, 0.0]);
    fan.normals.push([0.0, 0.0, 1.0]);
    for k in 0..64 {
        let a = k as f32 * std::f32::consts::TAU / 64.0;
        fan.positions.push([0.9 * a.cos(), 0.9 * a.sin(), 0.0]);
        fan.normals.push([0.0, 0.0, 1.0]);
        fan.indices.extend([0, 1 + k, 1 + (k + 1) % 64]);
    }
    let tilt = Quat::from_axis_angle(Vec3::X, 80f32.to_radians());
    let trs = |t: [f32; 3], r: Quat| Transform::Trs { translation: t, rotation: r.to_array(), scale: [1.0; 3] };
    let scene = scene_of(
        &dir,
        "shared.glb",
        &[
            (fan, [0.9, 0.6, 0.3], false, trs([-1.0, 0.0, 0.0], Quat::IDENTITY)),
            (grid(Vec3::ZERO, 1.8, 60), [0.3, 0.6, 0.9], false, trs([1.0, 0.0, 0.0], tilt)),
        ],
    );
    let camera = perspective(DVec3::new(0.0, 0.3, 3.5), DVec3::ZERO, 45.0, 0.5);
    let s = RenderSettings::new(600, 400, camera, sun_lights(DVec3::new(0.2, 0.6, 1.0)));
    let mut gpu = CheckedRenderer::new();
    check("fan and grid", &scene, &s, &mut gpu, 600 * 400 / 10);
    // No gaps: inside the fan's inscribed circle (projected), every pixel is covered on the GPU.
    let img = gpu.render(&scene, &s);
    let m = s.camera.clip_from_world(s.aspect());
    let project = |p: DVec3| {
        let c = m * p.extend(1.0);
        ((c.x / c.w * 0.5 + 0.5) * 600.0, (c.y / c.w * 0.5 + 0.5) * 400.0)
    };
    let (cx, cy) = project(DVec3::new(-1.0, 0.0, 0.0));
    let (rx, _) = project(DVec3::new(-1.0 + 0.85, 0.0, 0.0));
    let r = (rx - cx).abs() * 0.9;
    let mut inside = 0;
    for y in 0..400 {
        for x in 0..600 {
            let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
            if dx * dx + dy * dy < r * r * 0.8 {
                inside += 1;
                assert!(img.covered(x, y), "gap at ({x},{y}) inside the fan");
            }
        }
    }
    assert!(inside > 1000);
}

#[test]
fn meshes_with_thousands_of_triangles() {
    let dir = TempDir::new("thousands");
    let scene = scene_of(
        &dir,
        "dense.glb",
        &[
            (uv_sphere(Vec3::new(-0.6, 0.0, 0.0), 0.55, 96, 192), [0.8, 0.5, 0.4], false, Transform::Identity),
            (
                grid(Vec3::ZERO, 1.2, 100),
                [0.5, 0.8, 0.4],
                false,
                Transform::Trs {
                    translation: [0.7, 0.0, 0.0],
                    rotation: Quat::from_axis_angle(Vec3::new(1.0, 0.2, 0.0).normalize(), 1.2).to_array(),
                    scale: [1.0; 3],
                },
            ),
        ],
    );
    assert!(scene.triangle_count() > 50_000, "{}", scene.triangle_count());
    let camera = perspective(DVec3::new(0.0, 0.4, 3.0), DVec3::ZERO, 45.0, 0.5);
    let s = RenderSettings::new(800, 600, camera, sun_lights(DVec3::new(0.5, 0.8, 0.6)));
    let mut gpu = CheckedRenderer::new();
    check("dense", &scene, &s, &mut gpu, 800 * 600 / 10);
}

/// 24,000 separate needles, about 40 px long and under 2 px wide, none touching another: the snapped position of
/// every vertex shows in the coverage, along edges that pass close to many pixel centres.
fn needle_field(dir: &TempDir) -> Scene {
    let mut field = MeshData::default();
    let mut seed = 1u64;
    for row in 0..400 {
        for col in 0..60 {
            seed += 1;
            let jitter = triangle_soup(Vec3::ZERO, Vec3::splat(1.0), 1, 1.0, seed).positions[0];
            let y = -1.0 + (row as f32 + 0.5) / 200.0 + 0.001 * jitter[1];
            let x0 = -1.0 + col as f32 / 30.0 + 0.002 * jitter[0];
            let (a, b) = (Vec3::new(x0, y, 0.0), Vec3::new(x0 + 0.03, y + 0.0015 * jitter[2], 0.0));
            let c = Vec3::new(x0 + 0.015 + 0.004 * jitter[0], y + 0.003 + 0.0005 * jitter[1], 0.0);
            let base = field.positions.len() as u32;
            field.positions.extend([a.to_array(), b.to_array(), c.to_array()]);
            field.normals.extend([[0.0, 0.0, 1.0]; 3]);
            field.indices.extend([base, base + 1, base + 2]);
        }
    }
    scene_of(dir, "needles.glb", &[(field, [0.9, 0.9, 0.9], true, Transform::Identity)])
}

#[test]
fn isolated_needles_at_a_size_that_is_not_a_power_of_two() {
    // At 1000 px the viewport scale (500) is not a power of two, so a fused and an unfused viewport transform
    // round differently for about 0.4% of the vertex coordinates. Measured: the device's formulation (fused on
    // FMA hosts) gives 0 coverage mismatches here, the other one 5; hence 0 is asserted, not the general bound.
    let dir = TempDir::new("needles");
    let scene = needle_field(&dir);
    let camera = perspective(DVec3::new(0.013, 0.007, 2.45), DVec3::new(0.013, 0.007, 0.0), 45.0, 0.5);
    let s = RenderSettings::new(1000, 1000, camera, sun_lights(DVec3::new(0.1, 0.2, 1.0)));
    let mut gpu = CheckedRenderer::new();
    check_with("isolated needles", &scene, &s, &mut gpu, 100_000, 0);
}

#[test]
fn every_light_and_model_on_the_teapot_and_the_sphere_scenes() {
    let mut gpu = CheckedRenderer::new();
    for model in ["teapot.glb", "spheres.glb", "brdfs.glb"] {
        let scene = common::load(&models_dir().join(model));
        let bs = scene.bounding_sphere().unwrap();
        // Disk lights outside the model, placed and sized by its bounding sphere (centre c, radius r).
        let disk = |offset: [f64; 3], radius: f64, l: f32| {
            let at = DVec3::from_array(offset) * bs.radius;
            DiskLight {
                center: (bs.center + at).as_vec3(),
                direction: (-at).normalize().as_vec3(),
                radius: (radius * bs.radius) as f32,
                radiance: [l, 0.8 * l, 0.6 * l],
            }
        };
        let top = disk([0.0, 1.6, 0.7], 0.5, 300.0);
        let side = disk([1.4, 0.3, 1.2], 0.2, 800.0);
        let sun = |elevation_degrees: f64| Sun {
            direction: settings::sun_direction_from_angles(elevation_degrees, 40.0).as_vec3(),
            irradiance: [1000.0; 3],
            angular_diameter: 0.53f32.to_radians(),
        };
        let cases: Vec<(&str, Lights, ShadingOptions)> = vec![
            (
                "disk skylights, exact",
                Lights { disks: vec![top, side], ..Default::default() },
                ShadingOptions::default(),
            ),
            (
                "disk skylights, small source",
                Lights { disks: vec![top, side], ..Default::default() },
                ShadingOptions { disk: DiskModel::SmallSource, ..Default::default() },
            ),
            (
                "overcast sky",
                Lights { sky: Some([100.0, 90.0, 80.0]), ..Default::default() },
                ShadingOptions::default(),
            ),
            ("sun setting (disk)", Lights { sun: Some(sun(0.1)), ..Default::default() }, ShadingOptions::default()),
            (
                "sun setting (delta)",
                Lights { sun: Some(sun(0.1)), ..Default::default() },
                ShadingOptions { sun: SunModel::Delta, ..Default::default() },
            ),
            (
                "everything",
                Lights { sun: Some(sun(30.0)), disks: vec![top], sky: Some([20.0, 20.0, 25.0]) },
                ShadingOptions::default(),
            ),
        ];
        let base = settings::resolve(&scene, 480, 360, &CameraOptions::default(), &SunOptions::default()).unwrap();
        for (name, lights, shading) in &cases {
            let s = RenderSettings { lights: lights.clone(), shading: *shading, ..base.clone() };
            check(&format!("{model}, {name}"), &scene, &s, &mut gpu, 480 * 360 / 20);
        }
    }
}

/// Item of the robustness issue: `render --check` at its default tolerance must pass on ordinary meshes. UV spheres
/// of 4k and 64k triangles under a sun whose terminator crosses the view: f32 rounding of n·l gives absolute errors
/// of a few u (2⁻²⁴) of the peak, which near the terminator are over 1e-5 relative at the 1% floor. The default
/// tolerance allows [`compare::F32_SHADING_PEAK_FRACTION`] of the peak; the strict relative one alone fails here.
#[test]
fn spheres_near_the_terminator_pass_the_default_tolerance() {
    let mut gpu = CheckedRenderer::new();
    let u = 1.0 / (1u64 << 24) as f64;
    let mut strict_failures = 0;
    for (stacks, slices) in [(32, 64), (128, 256)] {
        let mut b = GltfBuilder::new();
        let m = b.add_material("grey", [0.8; 3], false, None);
        let mesh = b.add_mesh("sphere", &[uv_sphere(Vec3::ZERO, 1.0, stacks, slices).primitive(Some(m))]);
        let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
        b.add_scene(&[n], None);
        let dir = TempDir::new("terminator");
        let scene = common::load(&dir.write("sphere.glb", &b));
        for (azimuth, elevation) in [(160.0, 45.0), (200.0, 45.0), (200.0, 10.0)] {
            let sun =
                SunOptions { azimuth_degrees: Some(azimuth), elevation_degrees: Some(elevation), ..Default::default() };
            let s = settings::resolve(&scene, 1024, 1024, &CameraOptions::default(), &sun).unwrap();
            let g = gpu.render(&scene, &s);
            let options = gpu.reference_options();
            let c = cpu::render(&scene, &s, &options);
            let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
            // The radiance of a surface facing the sun, ρ E⊥ = 0.8/π × 1000 W/(m²·sr).
            let facing = 0.8 / std::f64::consts::PI * 1000.0;
            println!(
                "sphere {}: sun {azimuth}/{elevation}: max abs {:.2}u of ρE⊥, max rel {:.2e}, over {}",
                stacks * slices * 2,
                report.max_abs / (u * facing),
                report.max_rel,
                report.over_tolerance.total
            );
            assert!(report.pass, "sphere {stacks}x{slices}, sun {azimuth}/{elevation}: {}", report.text("gpu", "cpu"));
            assert!(report.max_abs <= compare::F32_SHADING_PEAK_FRACTION * report.peak);
            let strict = DiffOptions { fail_peak: None, ..Default::default() };
            strict_failures += usize::from(!compare::diff(&g, &c, &strict).unwrap().0.pass);
        }
    }
    assert!(strict_failures > 0, "no case reaches the f32 rounding limit: the test no longer tests it");
}

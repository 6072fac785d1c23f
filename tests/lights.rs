//! The lights against analytic values, on the GPU (lavapipe, validation on) and on the CPU reference:
//! the disk skylight of the lecture's room (exact and small-source), receivers tilted so that the disk is partly
//! below their horizon (against quadrature written here), the overcast sky, and the sun setting.

mod common;

use common::{load, rel, CheckedRenderer, TempDir};
use glam::{DVec3, DVec4, Quat, Vec3};
use serde_json::json;
use std::f64::consts::PI;
use sunshade::authoring::shapes::{grid, quad, uv_sphere, MeshData};
use sunshade::authoring::{GltfBuilder, Node, Primitive, Transform};
use sunshade::cpu;
use sunshade::scene::{Camera, Lights, Projection, Scene, Sun};
use sunshade::settings::RenderSettings;
use sunshade::shading::lights::disk::DiskGeometry;
use sunshade::shading::lights::sun::sun_irradiance_disk;
use sunshade::shading::quadrature::integrate_composite;
use sunshade::shading::{DiskModel, ShadingOptions, SunModel};
use sunshade::Image;

const ALBEDO: f32 = 0.5;

/// The GPU and the CPU image of the same settings, unshadowed: the expectations here are the lights' closed forms
/// for unoccluded surfaces (tests/shadows.rs checks shadows).
fn both(gpu: &mut CheckedRenderer, scene: &Scene, s: &RenderSettings) -> [(&'static str, Image); 2] {
    let mut s = s.clone();
    s.shading.shadows = sunshade::shading::Shadows::None;
    let s = &s;
    let g = gpu.render(scene, s);
    let c = cpu::render(scene, s, &gpu.reference_options());
    [("gpu", g), ("cpu", c)]
}

/// A node holding a disk light (in its local XY plane, emitting towards local −Z) pointing straight down.
fn disk_node(b: &mut GltfBuilder, center: [f32; 3], radius: f64, radiance: f64) -> usize {
    b.add_node(Node {
        name: Some("skylight".into()),
        transform: Transform::Trs {
            translation: center,
            rotation: Quat::from_axis_angle(Vec3::X, -90f32.to_radians()).to_array(),
            scale: [1.0; 3],
        },
        extras: Some(
            json!({ "sunshade": { "light": "disk", "radius": radius, "radiance": [radiance, radiance, radiance] } }),
        ),
        ..Default::default()
    })
}

fn mesh_node(b: &mut GltfBuilder, mesh: &MeshData, flat: bool, transform: Transform) -> usize {
    let m = b.add_material("grey", [ALBEDO; 3], false, None);
    let mut prim = mesh.primitive(Some(m));
    if flat {
        prim = Primitive { normals: None, ..prim };
    }
    let mesh = b.add_mesh("mesh", &[prim]);
    b.add_node(Node { mesh: Some(mesh), transform, ..Default::default() })
}

/// Orthographic camera looking straight down at the floor, image right = +X, image up = −Z.
/// A one-sided 2 m × 2 m floor at y = 0 facing +Y, alone in its scene.
fn unit_floor(dir: &TempDir) -> Scene {
    let mut b = GltfBuilder::new();
    let floor = mesh_node(
        &mut b,
        &quad(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -1.0)),
        false,
        Transform::Identity,
    );
    b.add_scene(&[floor], None);
    load(&dir.write("floor.glb", &b))
}

fn looking_down(ymag: f64) -> Camera {
    Camera::looking(
        DVec3::new(0.0, 10.0, 0.0),
        -DVec3::Y,
        -DVec3::Z,
        Projection::Orthographic { ymag, znear: 1.0, zfar: 20.0 },
    )
    .unwrap()
}

/// The world ray through the centre of pixel (x, y).
fn pixel_ray(s: &RenderSettings, x: u32, y: u32) -> (DVec3, DVec3) {
    let inv = s.camera.clip_from_world(s.aspect()).inverse();
    let ndc = |px: f64, n: u32| 2.0 * px / n as f64 - 1.0;
    let (nx, ny) = (ndc(x as f64 + 0.5, s.width), ndc(y as f64 + 0.5, s.height));
    let unproject = |z: f64| {
        let p = inv * DVec4::new(nx, ny, z, 1.0);
        p.truncate() / p.w
    };
    let (a, b) = (unproject(0.2), unproject(0.8));
    (a, (b - a).normalize())
}

#[test]
fn lecture_room_floor_under_a_disk_skylight() {
    let dir = TempDir::new("room");
    let (f, l0) = (2.0f64, 1000.0f64);
    let mut gpu = CheckedRenderer::new();
    for r_over_f in [0.05, 0.25, 1.0, 4.0] {
        let radius = r_over_f * f;
        let mut b = GltfBuilder::new();
        let floor = mesh_node(&mut b, &grid(Vec3::ZERO, 8.0, 40), false, Transform::Identity);
        let light = disk_node(&mut b, [0.0, f as f32, 0.0], radius, l0);
        b.add_scene(&[floor, light], None);
        let scene = load(&dir.write(&format!("room{r_over_f}.glb"), &b));
        assert_eq!(scene.lights.disks.len(), 1);
        assert!((scene.lights.disks[0].direction.as_dvec3() + DVec3::Y).length() < 1e-6);
        for model in [DiskModel::Exact, DiskModel::SmallSource] {
            let mut s = RenderSettings::new(96, 96, looking_down(3.0), scene.lights.clone());
            s.shading = ShadingOptions { disk: model, ..Default::default() };
            for (who, img) in both(&mut gpu, &scene, &s) {
                let mut worst = 0.0f64;
                for y in 0..s.height {
                    for x in 0..s.width {
                        let (o, _) = pixel_ray(&s, x, y);
                        let rho2 = o.x * o.x + o.z * o.z;
                        let (r2, f2) = (radius * radius, f * f);
                        let omega = match model {
                            // The parallel-plane view factor, textbook form (f64 is enough for its cancellation).
                            DiskModel::Exact => {
                                let s2 = ((f2 + rho2 + r2).powi(2) - 4.0 * rho2 * r2).sqrt();
                                0.5 * PI * (1.0 - (f2 + rho2 - r2) / s2)
                            }
                            DiskModel::SmallSource => PI * r2 * (f2 / (f2 + rho2)).powi(2) / f2,
                        };
                        let want = ALBEDO as f64 / PI * l0 * omega;
                        let got = img.get(x, y);
                        assert_eq!(got[3], 1.0, "{who} ({x},{y}) not covered");
                        worst = worst.max(rel(got[0] as f64, want));
                    }
                }
                println!("room R/f {r_over_f} {model:?} {who}: worst relative error {worst:.2e}");
                assert!(worst <= 1e-5, "R/f {r_over_f} {model:?} {who}: worst relative error {worst:.3e}");
            }
        }
    }
}

/// The projected solid angle of the visible part of a disk by Gauss–Legendre over the visible region: in the
/// disk plane, with w along the in-plane part of n and v across it, the region above the horizon is `a > a*`
/// within the disk; with `a = R sin θ`, `b = R cos θ · s` it is the rectangle `θ ∈ [asin(a*/R), π/2]`,
/// `s ∈ [−1, 1]`, `dA = R² cos²θ dθ ds`, on which `n·y · h / |y|⁴` is smooth. Independent of the contour formula.
fn disk_numerical(x: DVec3, n: DVec3, disk: &DiskGeometry, panels: usize) -> f64 {
    let (d, radius) = (disk.direction, disk.radius);
    let q = disk.center - x;
    let h = -d.dot(q);
    if h <= 0.0 {
        return 0.0;
    }
    let n_perp = n - n.dot(d) * d;
    let m = n_perp.length();
    let w = if m > 0.0 { n_perp / m } else { d.any_orthonormal_vector() };
    let v = d.cross(w);
    let theta_lo = if m > 0.0 {
        (-n.dot(q) / (m * radius)).clamp(-1.0, 1.0).asin()
    } else if n.dot(q) > 0.0 {
        -0.5 * PI
    } else {
        return 0.0;
    };
    let f = |theta: f64, s: f64| {
        let (st, ct) = theta.sin_cos();
        let y = q + radius * st * w + radius * ct * s * v;
        let d2 = y.length_squared();
        n.dot(y).max(0.0) * h / (d2 * d2) * radius * radius * ct * ct
    };
    integrate_composite(theta_lo, 0.5 * PI, panels, 24, |theta| {
        integrate_composite(-1.0, 1.0, panels, 24, |s| f(theta, s))
    })
}

/// The numerical value, checked converged by doubling the panels.
fn disk_converged(x: DVec3, n: DVec3, disk: &DiskGeometry) -> f64 {
    let (a, b) = (disk_numerical(x, n, disk, 4), disk_numerical(x, n, disk, 8));
    assert!((a - b).abs() <= 1e-11 * b.abs().max(1e-9), "quadrature not converged at {x} {n}: {a} {b}");
    b
}

#[test]
fn closed_form_disk_matches_quadrature_for_any_orientation() {
    // A small disk (receivers far: h > R) and a large one (near field: h < R) exercise both partial-visibility paths.
    for radius in [0.8, 3.0] {
        closed_form_matches_quadrature(DiskGeometry {
            center: DVec3::new(0.2, 2.0, -0.1),
            direction: DVec3::new(0.1, -1.0, 0.2).normalize(),
            radius,
        });
    }
}

fn closed_form_matches_quadrature(disk: DiskGeometry) {
    let (mut worst, mut partial) = (0.0f64, 0);
    for i in 0..60 {
        let a = i as f64 * 0.7;
        let x = DVec3::new(1.3 * a.sin(), 0.3 * (1.7 * a).cos(), 1.1 * (0.6 * a).cos());
        let n = DVec3::new((1.3 * a).cos(), (0.9 * a).sin() + 0.2, (2.1 * a).sin()).normalize();
        let got = sunshade::shading::lights::disk::disk_projected_solid_angle(x, n, &disk);
        let want = disk_converged(x, n, &disk);
        let n_perp = (n - n.dot(disk.direction) * disk.direction).length();
        partial += (n.dot(disk.center - x).abs() < disk.radius * n_perp) as usize;
        if want > 1e-9 {
            worst = worst.max(rel(got, want));
        } else {
            assert!(got.abs() < 1e-9, "{got} vs {want}");
        }
    }
    assert!(partial > 10, "only {partial} partly visible cases");
    assert!(worst < 1e-8, "R {}: worst relative error {worst}", disk.radius);
}

#[test]
fn thin_visible_slivers_of_a_disk_match_quadrature() {
    // Receivers tilted so that only a sliver of the disk (rim arc half-angle α) rises above their horizon.
    let disk = DiskGeometry { center: DVec3::new(0.0, 2.0, 0.0), direction: -DVec3::Y, radius: 1.5 };
    let mut count = 0;
    for x in [DVec3::new(0.3, 0.0, 0.2), DVec3::new(1.2, 1.5, 0.0), DVec3::new(-0.4, 1.0, 1.0)] {
        for azimuth in [0.0f64, 1.3, 2.9] {
            let u = DVec3::new(azimuth.cos(), 0.0, azimuth.sin());
            for alpha in [0.5f64, 0.31, 0.29, 0.1, 0.01, 1e-3] {
                let Some(n) = receiver_normal_for_alpha(&disk, x, u, alpha) else { continue };
                let got = sunshade::shading::lights::disk::disk_projected_solid_angle(x, n, &disk);
                let want = disk_converged(x, n, &disk);
                assert!(rel(got, want) < 1e-9, "x {x} α {alpha}: {got} vs {want}");
                count += 1;
            }
        }
    }
    assert!(count >= 30, "{count}");
}

#[test]
fn tilted_receivers_under_a_disk_partly_below_their_horizon() {
    let dir = TempDir::new("tilted");
    let (l0, disk) = (500.0, DiskGeometry { center: DVec3::new(0.0, 2.0, 0.0), direction: -DVec3::Y, radius: 1.5 });
    // Three 1 m quads, tilted 30°, 60° and 89° about z (normal (sin t, cos t, 0)), placed so that the disk
    // straddles each one's horizon.
    let receivers =
        [(30.0f64, DVec3::new(-1.6, 1.3, 0.0)), (60.0, DVec3::new(0.0, 0.5, 0.0)), (89.0, DVec3::new(1.6, 0.6, 0.0))];
    let mut b = GltfBuilder::new();
    let mut roots = Vec::new();
    for (tilt, center) in receivers {
        let rot = Quat::from_axis_angle(Vec3::NEG_Z, (tilt as f32).to_radians());
        let t = Transform::Trs { translation: center.as_vec3().to_array(), rotation: rot.to_array(), scale: [1.0; 3] };
        // The quad lies in the XZ plane facing +Y before the rotation.
        let q = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.0, -0.5));
        roots.push(mesh_node(&mut b, &q, false, t));
    }
    roots.push(disk_node(&mut b, [0.0, 2.0, 0.0], disk.radius, l0));
    b.add_scene(&roots, None);
    let scene = load(&dir.write("tilted.glb", &b));
    let camera = Camera::look_at(
        DVec3::new(6.0, 3.5, 4.0),
        DVec3::new(0.0, 0.8, 0.0),
        DVec3::Y,
        Projection::Perspective { yfov: 40f64.to_radians(), znear: 1.0, zfar: Some(30.0) },
    )
    .unwrap();
    let s = RenderSettings::new(160, 120, camera, scene.lights.clone());
    let mut gpu = CheckedRenderer::new();
    let images = both(&mut gpu, &scene, &s);
    let (mut checked, mut partial, mut worst) = ([0usize; 3], 0, 0.0f64);
    for y in (0..s.height).step_by(2) {
        for x in (0..s.width).step_by(2) {
            let (o, dvec) = pixel_ray(&s, x, y);
            // The nearest receiver hit well inside its quad.
            let mut hit = None;
            for (k, (tilt, center)) in receivers.iter().enumerate() {
                let t = tilt.to_radians();
                let n = DVec3::new(t.sin(), t.cos(), 0.0);
                let along = DVec3::new(t.cos(), -t.sin(), 0.0);
                let dist = (center - o).dot(n) / dvec.dot(n);
                let p = o + dist * dvec;
                let (u, v) = ((p - center).dot(along), (p - center).z);
                if dist > 0.0 && u.abs() < 0.48 && v.abs() < 0.48 && hit.is_none_or(|(_, d, _, _)| dist < d) {
                    hit = Some((k, dist, p, n));
                }
            }
            let Some((k, _, p, n)) = hit else { continue };
            let omega = disk_converged(p, n, &disk);
            let want = ALBEDO as f64 / PI * l0 * omega;
            let n_perp = (n - n.dot(disk.direction) * disk.direction).length();
            partial += (n.dot(disk.center - p).abs() < disk.radius * n_perp) as usize;
            for (who, img) in &images {
                let got = img.get(x, y);
                assert_eq!(got[3], 1.0, "{who} ({x},{y})");
                let e = rel(got[0] as f64, want);
                worst = worst.max(e);
                assert!(e <= 1e-5, "{who} tilt {} at {p}: {} vs {want} ({e:.2e})", receivers[k].0, got[0]);
            }
            checked[k] += 1;
        }
    }
    println!("tilted receivers: checked {checked:?} pixels, {partial} partly visible, worst {worst:.2e}");
    assert!(checked.iter().all(|&c| c >= 30), "{checked:?}");
    assert!(partial >= 60, "only {partial} checked points see the disk cut by their horizon");
}

/// The nearest triangle of `mesh` hit by a ray: distance, face normal, and how far inside the triangle the hit
/// is (the smallest barycentric).
fn ray_mesh(o: DVec3, d: DVec3, mesh: &sunshade::scene::Mesh) -> Option<(f64, DVec3, f64)> {
    let mut best: Option<(f64, DVec3, f64)> = None;
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize].as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-14 {
            continue;
        }
        // Single-sided: a triangle seen from behind is culled.
        if d.dot(e1.cross(e2)) >= 0.0 {
            continue;
        }
        let s = o - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let dist = e2.dot(q) / det;
        if u < 0.0 || v < 0.0 || u + v > 1.0 || dist <= 0.0 {
            continue;
        }
        let margin = u.min(v).min(1.0 - u - v);
        if best.is_none_or(|(bd, _, _)| dist < bd) {
            best = Some((dist, e1.cross(e2).normalize(), margin));
        }
    }
    best
}

#[test]
fn overcast_sky_on_tilted_planes_and_a_sphere() {
    let dir = TempDir::new("sky");
    let l0 = [100.0f32, 80.0, 60.0];
    let mut b = GltfBuilder::new();
    let mut roots = Vec::new();
    // Planes tilted 0°, 45°, 90° and 135° from up towards the camera (the last faces partly down), and a
    // flat-shaded sphere.
    for (i, tilt) in [0.0f32, 45.0, 90.0, 135.0].iter().enumerate() {
        let rot = Quat::from_axis_angle(Vec3::X, -tilt.to_radians());
        let t = Transform::Trs {
            translation: [-3.0 + 1.6 * i as f32, 0.0, 0.0],
            rotation: rot.to_array(),
            scale: [1.0; 3],
        };
        roots.push(mesh_node(&mut b, &quad(Vec3::ZERO, Vec3::new(0.6, 0.0, 0.0), Vec3::new(0.0, 0.0, -0.6)), false, t));
    }
    roots.push(mesh_node(&mut b, &uv_sphere(Vec3::new(0.0, 0.0, 2.2), 1.0, 12, 20), true, Transform::Identity));
    b.add_scene(&roots, Some(json!({ "sunshade": { "sky_radiance": l0 } })));
    let scene = load(&dir.write("sky.glb", &b));
    assert_eq!(scene.lights.sky, Some(l0));
    let camera = Camera::look_at(
        DVec3::new(0.5, 4.0, -5.0),
        DVec3::new(-0.5, 0.0, 0.8),
        DVec3::Y,
        Projection::Perspective { yfov: 50f64.to_radians(), znear: 1.0, zfar: Some(30.0) },
    )
    .unwrap();
    let s = RenderSettings::new(200, 150, camera, scene.lights.clone());
    assert!(s.lights.sun.is_none(), "a scene with a sky gets no default sun");
    let mut gpu = CheckedRenderer::new();
    let images = both(&mut gpu, &scene, &s);
    // Checked pixels per surface: the four planes (by tilt), then the sphere.
    let plane_normals: Vec<DVec3> = [0.0f64, 45.0, 90.0, 135.0]
        .iter()
        .map(|t| DVec3::new(0.0, t.to_radians().cos(), -t.to_radians().sin()))
        .collect();
    let mut checked = [0usize; 5];
    for y in 0..s.height {
        for x in 0..s.width {
            let (o, d) = pixel_ray(&s, x, y);
            let nearest = scene.meshes.iter().filter_map(|m| ray_mesh(o, d, m)).min_by(|a, b| a.0.total_cmp(&b.0));
            // Skip pixels whose nearest hit is close to a triangle edge (the rasterizer may pick the neighbour).
            let Some((_, n, _)) = nearest.filter(|h| h.2 > 0.02) else { continue };
            // The visible side: the renderer culls back faces, so n faces the camera here.
            for (who, img) in &images {
                let got = img.get(x, y);
                for c in 0..3 {
                    let want = ALBEDO as f64 / PI * (PI * l0[c] as f64 * 0.5 * (1.0 + n.y));
                    assert!(rel(got[c] as f64, want) <= 1e-6, "{who} ({x},{y}) n {n}: {} vs {want}", got[c]);
                }
            }
            let surface = plane_normals.iter().position(|p| (*p - n).length() < 1e-6).unwrap_or(4);
            checked[surface] += 1;
        }
    }
    assert!(checked[..4].iter().all(|&c| c >= 100) && checked[4] >= 500, "checked pixels per surface: {checked:?}");
}

/// The sky is the upper hemisphere for the specular lobes too: a glossy wall (Phong e = 100, a lobe that
/// integrates to 1 at normal view) seen head on by an orthographic camera has its mirror direction on the
/// horizontal, so half of its lobe sees the sky and half the ground: `L = kd/π · π L0/2 + ks L0 / 2`, on both
/// renderers. (Before the lobes knew the horizontal, the specular part was the whole `ks L0`.) The lobe's grid is
/// the default 16²; 1e-3 covers its error there (the analytic half is checked to 1e-3 at 64² in the unit tests).
#[test]
fn a_glossy_wall_sees_the_sky_with_half_of_its_lobe() {
    let dir = TempDir::new("sky-wall");
    let l0 = 100.0f32;
    let (kd, ks) = (0.3f64, 0.6f64);
    let mut b = GltfBuilder::new();
    let m = b.add_material(
        "glossy",
        [0.5; 3],
        false,
        Some(json!({ "sunshade": { "brdf": "phong", "kd": [kd, kd, kd], "ks": [ks, ks, ks], "exponent": 100.0 } })),
    );
    // A wall in the XY plane facing +Z.
    let wall = quad(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
    let mesh = b.add_mesh("wall", &[wall.primitive(Some(m))]);
    let node = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[node], Some(json!({ "sunshade": { "sky_radiance": l0 } })));
    let scene = load(&dir.write("wall.glb", &b));
    let camera = Camera::looking(
        DVec3::new(0.0, 0.0, 10.0),
        -DVec3::Z,
        DVec3::Y,
        Projection::Orthographic { ymag: 1.5, znear: 1.0, zfar: 20.0 },
    )
    .unwrap();
    let s = RenderSettings::new(48, 48, camera, scene.lights.clone());
    let mut gpu = CheckedRenderer::new();
    let want = kd / PI * (PI * l0 as f64 * 0.5) + ks * l0 as f64 * 0.5;
    let mut checked = 0;
    for (who, img) in both(&mut gpu, &scene, &s) {
        for y in 0..s.height {
            for x in 0..s.width {
                let got = img.get(x, y);
                if got[3] == 0.0 {
                    continue;
                }
                checked += 1;
                assert!(rel(got[0] as f64, want) <= 1e-3, "{who} ({x},{y}): {} vs {want}", got[0]);
            }
        }
    }
    assert!(checked > 1000, "{checked} pixels checked");
}

#[test]
fn the_setting_sun_dims_continuously_and_monotonically() {
    let dir = TempDir::new("sunset");
    let scene = unit_floor(&dir);
    let delta = 0.53f64.to_radians();
    let sigma = 0.5 * delta;
    let e_perp = 1000.0f32;
    let scale = ALBEDO as f64 / PI;
    let mut gpu = CheckedRenderer::new();
    let steps = 40;
    let mut previous: Option<[f64; 2]> = None;
    for k in 0..=steps {
        let elevation = sigma * (2.0 - 4.0 * k as f64 / steps as f64);
        let direction = DVec3::new(0.0, elevation.sin(), elevation.cos());
        let lights = Lights {
            sun: Some(Sun { direction: direction.as_vec3(), irradiance: [e_perp; 3], angular_diameter: delta as f32 }),
            ..Default::default()
        };
        let s = RenderSettings::new(8, 8, looking_down(0.5), lights);
        let want = scale * sun_irradiance_disk(e_perp as f64, s.lights.sun.unwrap().direction.y as f64, delta);
        let mut now = [0.0; 2];
        for (i, (who, img)) in both(&mut gpu, &scene, &s).into_iter().enumerate() {
            let v = img.get(4, 4)[0] as f64;
            assert!(img.pixels().iter().all(|p| p[0] as f64 == v), "{who}: not constant");
            // Relative to the value, or to the half-set sun's value where it vanishes (f32 formula: ~1e-7 E⊥σ).
            let half_set = scale * e_perp as f64 * 2.0 * sigma / (3.0 * PI);
            assert!((v - want).abs() <= 1e-5 * want.max(0.01 * half_set), "{who} at {elevation:e}: {v} vs {want}");
            if let Some(p) = previous {
                assert!(v <= p[i], "{who}: brighter as the sun sets ({v} after {})", p[i]);
                // Continuous: a step moves E by at most E⊥ times the step in elevation.
                let step = 4.0 * sigma / steps as f64;
                assert!(p[i] - v <= scale * e_perp as f64 * step * 1.001, "{who}: jump {}", p[i] - v);
            }
            now[i] = v;
        }
        previous = Some(now);
    }
    assert_eq!(previous.unwrap(), [0.0, 0.0], "set sun gives nothing");
}

#[test]
fn delta_sun_model_is_the_plain_cosine() {
    let dir = TempDir::new("delta");
    let scene = unit_floor(&dir);
    // Half set: the disk model gives about 2σ/(3π) E⊥, the delta model exactly 0 (n·l = 0).
    let lights = Lights {
        sun: Some(Sun { direction: Vec3::Z, irradiance: [1000.0; 3], angular_diameter: 0.53f32.to_radians() }),
        ..Default::default()
    };
    let mut s = RenderSettings::new(4, 4, looking_down(0.5), lights);
    let mut gpu = CheckedRenderer::new();
    for (who, img) in both(&mut gpu, &scene, &s) {
        assert!(img.get(1, 1)[0] > 0.1, "{who}: the half-set disk lights the floor");
    }
    s.shading = ShadingOptions { sun: SunModel::Delta, ..Default::default() };
    for (who, img) in both(&mut gpu, &scene, &s) {
        assert_eq!(img.get(1, 1)[0], 0.0, "{who}");
    }
}

/// A receiver near x whose horizon cuts the disk's rim arc at half-angle α (its normal tilted between the in-plane
/// direction `u` and +Y, found by bisection); `None` when no tilt gives that α.
fn receiver_normal_for_alpha(disk: &DiskGeometry, x: DVec3, u: DVec3, alpha: f64) -> Option<DVec3> {
    let q = disk.center - x;
    let normal = |t: f64| (t.cos() * u + t.sin() * DVec3::Y).normalize();
    let kappa = |t: f64| {
        let n = normal(t);
        let m = (n - n.dot(disk.direction) * disk.direction).length();
        -n.dot(q) / (disk.radius * m)
    };
    let (mut lo, mut hi) = (-1.5f64, 1.5f64);
    let side = (kappa(lo) - alpha.cos()).signum();
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (kappa(mid) - alpha.cos()).signum() == side {
            lo = mid
        } else {
            hi = mid
        }
    }
    let t = 0.5 * (lo + hi);
    ((kappa(t) - alpha.cos()).abs() < 1e-9).then(|| normal(t))
}

#[test]
fn segment_quadrature_accuracy() {
    use sunshade::shading::lights::disk::{segment_projected_solid_angle, SEGMENT_ORDER};
    let mut count = 0;
    // Receivers at least a radius from the disk: above it (h ≥ R) or nearly in its plane but beyond the rim.
    for h_over_r in [1.0f64, 1.5, 2.0, 5.0, 0.05] {
        let disk = DiskGeometry { center: DVec3::new(0.0, h_over_r, 0.0), direction: -DVec3::Y, radius: 1.0 };
        let receivers: &[DVec3] = if h_over_r >= 1.0 {
            &[DVec3::ZERO, DVec3::new(0.7, 0.0, 0.3), DVec3::new(2.0, 0.0, 0.0)]
        } else {
            &[DVec3::new(2.0, 0.0, 0.0), DVec3::new(1.6, 0.0, 1.6), DVec3::new(0.0, 0.0, 4.0)]
        };
        for alpha in [0.5f64, 1.5, 2.5] {
            for &x in receivers {
                let Some(n) = receiver_normal_for_alpha(&disk, x, DVec3::new(1.0, 0.0, 0.4).normalize(), alpha) else {
                    continue;
                };
                let q = disk.center - x;
                let got = segment_projected_solid_angle(
                    n,
                    disk.direction,
                    q,
                    -disk.direction.dot(q),
                    1.0,
                    alpha,
                    SEGMENT_ORDER,
                );
                let want = disk_converged(x, n, &disk);
                assert!(rel(got, want) < 1e-8, "h/R {h_over_r} α {alpha} x {x}: {got} vs {want}");
                count += 1;
            }
        }
    }
    assert!(count >= 30, "{count}");
}

//! GPU images (lavapipe, validation on) against analytic values: Lambertian surfaces under the sun,
//! `L = (albedo/π) · E⊥ · max(0, n·l)`, and coverage against projected geometry.

mod common;

use common::{bits, load, rel, CheckedRenderer, TempDir};
use glam::{DMat4, DQuat, DVec3, DVec4, Quat, Vec3};
use std::f64::consts::PI;
use sunshade::authoring::shapes::{cube, quad, uv_sphere, MeshData};
use sunshade::authoring::{GltfBuilder, Indices, Node, Primitive, Transform};
use sunshade::scene::{Camera, Lights, Projection, Sun};
use sunshade::settings::RenderSettings;
use sunshade::Image;

const E_PERP: f32 = 1000.0;

fn sun(direction: DVec3) -> Lights {
    Lights {
        sun: Some(Sun {
            direction: direction.normalize().as_vec3(),
            irradiance: [E_PERP; 3],
            angular_diameter: 0.53f32.to_radians(),
        }),
        ..Default::default()
    }
}

/// An orthographic camera 5 m out on the z axis, looking at the origin along −z (`front`) or +z (back).
fn ortho_along_z(ymag: f64, front: bool) -> Camera {
    let side = if front { 1.0 } else { -1.0 };
    Camera::looking(
        DVec3::new(0.0, 0.0, 5.0 * side),
        -side * DVec3::Z,
        DVec3::Y,
        Projection::Orthographic { ymag, znear: 1.0, zfar: 10.0 },
    )
    .unwrap()
}

fn ortho_front(ymag: f64) -> Camera {
    ortho_along_z(ymag, true)
}

fn ortho_back(ymag: f64) -> Camera {
    ortho_along_z(ymag, false)
}

fn settings(width: u32, height: u32, camera: Camera, lights: Lights) -> RenderSettings {
    RenderSettings::new(width, height, camera, lights)
}

/// The expected radiance `(albedo/π) E⊥ max(0, n·l)` with the sun direction exactly as the renderer receives it.
fn lambert(albedo: f64, normal: DVec3, s: &RenderSettings) -> f64 {
    let l = s.lights.sun.unwrap().direction.as_dvec3();
    albedo / PI * E_PERP as f64 * normal.dot(l).max(0.0)
}

fn single_mesh_scene(mesh: &MeshData, albedo: [f32; 3], double_sided: bool, transform: Transform) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let mat = b.add_material("m", albedo, double_sided, None);
    let m = b.add_mesh("mesh", &[mesh.primitive(Some(mat))]);
    let n = b.add_node(Node { mesh: Some(m), transform, ..Default::default() });
    b.add_scene(&[n], None);
    b
}

fn covered_set(img: &Image) -> Vec<(u32, u32)> {
    let mut v = Vec::new();
    for y in 0..img.height() {
        for x in 0..img.width() {
            if img.covered(x, y) {
                v.push((x, y));
            }
        }
    }
    v
}

#[test]
fn square_facing_the_camera_orthographic() {
    let dir = TempDir::new("square-ortho");
    let albedo = [0.8f32, 0.5, 0.2];
    let square = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
    let path = dir.write("square.glb", &single_mesh_scene(&square, albedo, false, Transform::Identity));
    let scene = load(&path);
    // 2 m tall view on 200 px: 100 px per metre; the 1 m square covers columns and rows 50..150 exactly.
    let s = settings(200, 200, ortho_front(1.0), sun(DVec3::new(0.4, 0.3, 0.8)));
    let mut gpu = CheckedRenderer::new();
    let img = gpu.render(&scene, &s);
    let expected: Vec<(u32, u32)> = (50..150).flat_map(|y| (50..150).map(move |x| (x, y))).collect();
    assert_eq!(covered_set(&img), expected);
    for (x, y) in expected {
        let p = img.get(x, y);
        assert_eq!(p[3], 1.0);
        for c in 0..3 {
            let want = lambert(albedo[c] as f64, DVec3::Z, &s);
            assert!(rel(p[c] as f64, want) <= 1e-6, "pixel ({x},{y}) channel {c}: {} vs {want}", p[c]);
        }
    }
    // Uncovered pixels hold radiance 0 and alpha 0.
    assert_eq!(img.get(0, 0), [0.0; 4]);
    assert_eq!(img.get(150, 100), [0.0; 4]);
}

/// Window coordinates (pixels) of a world point, in f64.
fn to_window(m: &DMat4, p: DVec3, w: u32, h: u32) -> (f64, f64) {
    let c = *m * DVec4::new(p.x, p.y, p.z, 1.0);
    ((c.x / c.w * 0.5 + 0.5) * w as f64, (c.y / c.w * 0.5 + 0.5) * h as f64)
}

/// Signed distance [px] from (x, y) to the inside of a convex polygon given counter-clockwise on screen (y down):
/// positive inside.
fn inside_distance(poly: &[(f64, f64)], x: f64, y: f64) -> f64 {
    let mut d = f64::INFINITY;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        // With y down, the inside of a visually counter-clockwise polygon is to the right of each edge.
        let cross = ex * (y - a.1) - ey * (x - a.0);
        d = d.min(-cross / (ex * ex + ey * ey).sqrt());
    }
    d
}

#[test]
fn square_in_perspective_covers_its_projected_area() {
    let dir = TempDir::new("square-persp");
    let albedo = [0.6f32, 0.6, 0.6];
    let square = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
    let path = dir.write("square.gltf", &single_mesh_scene(&square, albedo, false, Transform::Identity));
    let scene = load(&path);
    let camera = Camera::look_at(
        DVec3::new(0.7, 0.4, 2.5),
        DVec3::new(0.05, -0.02, 0.0),
        DVec3::Y,
        Projection::Perspective { yfov: 40f64.to_radians(), znear: 0.1, zfar: Some(20.0) },
    )
    .unwrap();
    let s = settings(320, 240, camera, sun(DVec3::new(-0.2, 0.5, 1.0)));
    let mut gpu = CheckedRenderer::new();
    let img = gpu.render(&scene, &s);
    let m = s.camera.clip_from_world(s.aspect());
    // Visually counter-clockwise corner order (the square's own order: CCW seen from its front).
    let poly: Vec<(f64, f64)> =
        square.positions.iter().map(|p| to_window(&m, Vec3::from_array(*p).as_dvec3(), 320, 240)).collect();
    // Shoelace area of the projected square, in pixels.
    let area: f64 =
        (0..4).map(|i| poly[i].0 * poly[(i + 1) % 4].1 - poly[(i + 1) % 4].0 * poly[i].1).sum::<f64>() * 0.5;
    let covered = img.covered_count();
    let mut disagreements = 0;
    for y in 0..240 {
        for x in 0..320 {
            let d = inside_distance(&poly, x as f64 + 0.5, y as f64 + 0.5);
            if (d > 0.0) != img.covered(x, y) {
                // Only pixel centres within snapping distance (1/256 px, doubled for safety) of an edge may differ.
                assert!(d.abs() < 2.0 / 256.0, "pixel ({x},{y}) at {d} px from the edge disagrees");
                disagreements += 1;
            }
        }
    }
    assert!(disagreements <= 2, "{disagreements} edge pixels disagree");
    // The pixel count matches the projected area to within the pixels its perimeter cuts.
    let perimeter: f64 = (0..4).map(|i| (poly[(i + 1) % 4].0 - poly[i].0).hypot(poly[(i + 1) % 4].1 - poly[i].1)).sum();
    assert!((covered as f64 - area.abs()).abs() < perimeter * 0.5, "{covered} px vs area {area}");
    let want = lambert(0.6, DVec3::Z, &s);
    for (x, y) in covered_set(&img) {
        let p = img.get(x, y);
        assert!(rel(p[0] as f64, want) <= 1e-6, "({x},{y}): {} vs {want}", p[0]);
    }
}

/// The face (axis, sign) of the cube [-0.5, 0.5]³ a local-space ray enters first, if it hits.
fn cube_face(origin: DVec3, dir: DVec3) -> Option<(usize, i32)> {
    let (mut t0, mut t1, mut face) = (f64::NEG_INFINITY, f64::INFINITY, None);
    for k in 0..3 {
        let (a, b) = ((-0.5 - origin[k]) / dir[k], (0.5 - origin[k]) / dir[k]);
        let (near, far, sign) = if a < b { (a, b, -1) } else { (b, a, 1) };
        if near > t0 {
            t0 = near;
            face = Some((k, sign));
        }
        t1 = t1.min(far);
    }
    (t0 <= t1 && t1 > 0.0).then_some(face).flatten()
}

#[test]
fn turned_cube_faces_are_constant_and_analytic() {
    let dir = TempDir::new("cube");
    let albedo = [0.9f32, 0.7, 0.3];
    let rotation = Quat::from_axis_angle(Vec3::new(0.3, 1.0, 0.2).normalize(), 0.7);
    let translation = Vec3::new(0.1, -0.05, 0.0);
    let t = Transform::Trs { translation: translation.to_array(), rotation: rotation.to_array(), scale: [1.0; 3] };
    let path = dir.write("cube.glb", &single_mesh_scene(&cube(0.5), albedo, false, t));
    let scene = load(&path);
    // The camera looks at the cube corner-on (it sees the local +X, +Y and +Z faces); the sun lights +Y and +Z
    // and is behind the +X face.
    let q = rotation.as_dquat();
    let camera = Camera::look_at(
        translation.as_dvec3() + q * DVec3::new(1.6, 1.3, 1.9),
        translation.as_dvec3(),
        DVec3::Y,
        Projection::Perspective { yfov: 45f64.to_radians(), znear: 0.5, zfar: Some(10.0) },
    )
    .unwrap();
    let s = settings(300, 300, camera, sun(q * DVec3::new(-0.4, 0.8, 0.45)));
    let mut gpu = CheckedRenderer::new();
    let img = gpu.render(&scene, &s);

    let model =
        DMat4::from_rotation_translation(DQuat::from_array(rotation.to_array().map(f64::from)), translation.as_dvec3());
    let (to_local, rot) = (model.inverse(), DQuat::from_array(rotation.to_array().map(f64::from)));
    let inv = s.camera.clip_from_world(s.aspect()).inverse();
    let face_at = |x: f64, y: f64| {
        let (o, d) = common::pixel_ray(&inv, x, y, 300, 300);
        cube_face(to_local.transform_point3(o), to_local.transform_vector3(d))
    };
    let mut per_face = std::collections::HashMap::new();
    for y in 0..300 {
        for x in 0..300 {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let probes: Vec<_> = [(0.0, 0.0), (-0.6, -0.6), (0.6, -0.6), (-0.6, 0.6), (0.6, 0.6)]
                .iter()
                .map(|(dx, dy)| face_at(cx + dx, cy + dy))
                .collect();
            if probes.iter().all(Option::is_none) {
                assert!(!img.covered(x, y), "({x},{y}) covered but off the cube");
                continue;
            }
            let Some(face) = probes[0] else { continue };
            if probes.iter().any(|p| *p != Some(face)) {
                continue; // on an edge between faces or at the silhouette
            }
            assert!(img.covered(x, y), "({x},{y}) inside face {face:?} but not covered");
            let mut n_local = DVec3::ZERO;
            n_local[face.0] = face.1 as f64;
            let n = rot * n_local;
            let p = img.get(x, y);
            for c in 0..3 {
                let want = lambert(albedo[c] as f64, n, &s);
                if want == 0.0 {
                    assert_eq!(p[c], 0.0, "({x},{y}) face {face:?} turned from the sun");
                } else {
                    assert!(rel(p[c] as f64, want) <= 1e-6, "({x},{y}) face {face:?}: {} vs {want}", p[c]);
                }
            }
            *per_face.entry(face).or_insert(0) += 1;
        }
    }
    assert_eq!(per_face.len(), 3, "expected three visible faces, got {per_face:?}");
    assert!(per_face.values().all(|&n| n > 1000), "{per_face:?}");
    let unlit = per_face.keys().filter(|f| {
        let mut n = DVec3::ZERO;
        n[f.0] = f.1 as f64;
        lambert(1.0, rot * n, &s) == 0.0
    });
    assert_eq!(unlit.count(), 1, "the test should see exactly one face turned from the sun");
}

fn test_scene() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let red = b.add_material("red", [0.9, 0.2, 0.1], false, None);
    let grey = b.add_material("grey", [0.5, 0.5, 0.5], true, None);
    let c = b.add_mesh("cube", &[cube(0.4).primitive(Some(red))]);
    let s = b.add_mesh("sphere", &[uv_sphere(Vec3::ZERO, 0.5, 12, 16).primitive(Some(grey))]);
    let n1 = b.add_node(Node {
        mesh: Some(c),
        transform: Transform::Trs {
            translation: [-0.6, 0.0, 0.0],
            rotation: [0.0, 0.38268343, 0.0, 0.9238795],
            scale: [1.0; 3],
        },
        ..Default::default()
    });
    let n2 = b.add_node(Node {
        mesh: Some(s),
        transform: Transform::Trs { translation: [0.6, 0.1, 0.0], rotation: [0.0, 0.0, 0.0, 1.0], scale: [1.0; 3] },
        ..Default::default()
    });
    b.add_scene(&[n1, n2], None);
    b
}

fn default_view(w: u32, h: u32) -> RenderSettings {
    let camera = Camera::look_at(
        DVec3::new(0.4, 1.0, 3.0),
        DVec3::ZERO,
        DVec3::Y,
        Projection::Perspective { yfov: 45f64.to_radians(), znear: 0.1, zfar: Some(20.0) },
    )
    .unwrap();
    settings(w, h, camera, sun(DVec3::new(0.3, 1.0, 0.5)))
}

#[test]
fn gltf_glb_and_data_uri_give_bitwise_the_same_image() {
    let dir = TempDir::new("formats");
    let b = test_scene();
    let gltf = dir.write("scene.gltf", &b);
    let glb = dir.write("scene.glb", &b);
    let embedded = dir.path("embedded.gltf");
    b.write_embedded(&embedded).unwrap();
    let s = default_view(256, 192);
    let mut gpu = CheckedRenderer::new();
    let images: Vec<Image> = [&gltf, &glb, &embedded].iter().map(|p| gpu.render(&load(p), &s)).collect();
    assert!(images[0].covered_count() > 5000);
    assert_eq!(bits(&images[0]), bits(&images[1]), ".gltf and .glb differ");
    assert_eq!(bits(&images[0]), bits(&images[2]), ".gltf and data-URI .gltf differ");
}

#[test]
fn node_hierarchy_equals_pretransformed_vertices() {
    let dir = TempDir::new("hierarchy");
    let sphere = uv_sphere(Vec3::new(0.1, 0.0, 0.0), 0.5, 16, 24);
    let t_root = Transform::Trs {
        translation: [0.2, -0.1, 0.3],
        rotation: Quat::from_axis_angle(Vec3::Y, 0.4).to_array(),
        scale: [1.0, 1.0, 1.0],
    };
    let m_child = DMat4::from_cols_array(&[
        0.9, 0.1, 0.0, 0.0, //
        -0.1, 0.9, 0.05, 0.0, //
        0.0, -0.05, 1.1, 0.0, //
        0.05, 0.2, -0.1, 1.0,
    ]);
    let t_grand = Transform::Trs {
        translation: [0.0, 0.1, 0.0],
        rotation: Quat::from_axis_angle(Vec3::new(1.0, 0.0, 1.0).normalize(), -0.3).to_array(),
        scale: [1.3, 0.7, 1.0],
    };
    let mut b = GltfBuilder::new();
    let mat = b.add_material("m", [0.7, 0.7, 0.7], false, None);
    let mesh = b.add_mesh("sphere", &[sphere.primitive(Some(mat))]);
    let grand = b.add_node(Node { mesh: Some(mesh), transform: t_grand.clone(), ..Default::default() });
    let child = b.add_node(Node {
        children: vec![grand],
        transform: Transform::Matrix(m_child.to_cols_array().map(|v| v as f32)),
        ..Default::default()
    });
    let root = b.add_node(Node { children: vec![child], transform: t_root.clone(), ..Default::default() });
    b.add_scene(&[root], None);
    let nested = load(&dir.write("nested.glb", &b));

    // The same vertices transformed here, in f64, then rounded once to f32.
    let trs = |t: &Transform| match t {
        Transform::Trs { translation, rotation, scale } => DMat4::from_scale_rotation_translation(
            DVec3::from_array(scale.map(f64::from)),
            DQuat::from_array(rotation.map(f64::from)).normalize(),
            DVec3::from_array(translation.map(f64::from)),
        ),
        _ => unreachable!(),
    };
    let m_child_f32 = DMat4::from_cols_array(&m_child.to_cols_array().map(|v| v as f32 as f64));
    let world = trs(&t_root) * m_child_f32 * trs(&t_grand);
    let normal_matrix = glam::DMat3::from_mat4(world).inverse().transpose();
    let flat = MeshData {
        positions: sphere
            .positions
            .iter()
            .map(|p| world.transform_point3(Vec3::from_array(*p).as_dvec3()).as_vec3().to_array())
            .collect(),
        normals: sphere
            .normals
            .iter()
            .map(|n| (normal_matrix * Vec3::from_array(*n).as_dvec3()).normalize().as_vec3().to_array())
            .collect(),
        indices: sphere.indices.clone(),
    };
    let pre = load(&dir.write("flat.glb", &single_mesh_scene(&flat, [0.7; 3], false, Transform::Identity)));

    let s = default_view(256, 256);
    let mut gpu = CheckedRenderer::new();
    let (a, bimg) = (gpu.render(&nested, &s), gpu.render(&pre, &s));
    assert!(a.covered_count() > 5000, "{}", a.covered_count());
    assert_eq!(covered_set(&a), covered_set(&bimg), "coverage differs");
    let mut worst = 0.0f64;
    for (p, q) in a.pixels().iter().zip(bimg.pixels()) {
        for c in 0..3 {
            let scale = (p[c].abs().max(q[c].abs())) as f64;
            if scale > 0.0 {
                worst = worst.max((p[c] - q[c]).abs() as f64 / scale);
            }
        }
    }
    assert!(worst <= 1e-6, "worst relative difference {worst}");
}

#[test]
fn indexed_and_unindexed_give_bitwise_the_same_image() {
    let dir = TempDir::new("indexed");
    let sphere = uv_sphere(Vec3::ZERO, 0.8, 10, 14);
    let a = load(&dir.write("indexed.glb", &single_mesh_scene(&sphere, [0.5; 3], false, Transform::Identity)));
    let mut b = GltfBuilder::new();
    let mat = b.add_material("m", [0.5; 3], false, None);
    let flat = sphere.unindexed();
    let prim = Primitive {
        positions: flat.positions,
        normals: Some(flat.normals),
        indices: None,
        material: Some(mat),
        mode: None,
        ..Default::default()
    };
    let m = b.add_mesh("sphere", &[prim]);
    let n = b.add_node(Node { mesh: Some(m), ..Default::default() });
    b.add_scene(&[n], None);
    let unindexed = load(&dir.write("unindexed.glb", &b));
    let s = default_view(200, 150);
    let mut gpu = CheckedRenderer::new();
    let (ia, ib) = (gpu.render(&a, &s), gpu.render(&unindexed, &s));
    assert!(ia.covered_count() > 5000);
    assert_eq!(bits(&ia), bits(&ib));
}

#[test]
fn u8_u16_u32_indices_give_bitwise_the_same_image() {
    let dir = TempDir::new("u8");
    let c = cube(0.5);
    let with = |idx: Indices| {
        let mut b = GltfBuilder::new();
        let mat = b.add_material("m", [0.8, 0.6, 0.4], false, None);
        let prim = Primitive { indices: Some(idx), material: Some(mat), ..c.primitive(None) };
        let m = b.add_mesh("cube", &[prim]);
        let rot = Quat::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.5).to_array();
        let n = b.add_node(Node {
            mesh: Some(m),
            transform: Transform::Trs { translation: [0.0; 3], rotation: rot, scale: [1.0; 3] },
            ..Default::default()
        });
        b.add_scene(&[n], None);
        b
    };
    let u8s = load(&dir.write("u8.glb", &with(Indices::U8(c.indices.iter().map(|&i| i as u8).collect()))));
    let u16s = load(&dir.write("u16.glb", &with(Indices::U16(c.indices.iter().map(|&i| i as u16).collect()))));
    let u32s = load(&dir.write("u32.glb", &with(Indices::U32(c.indices.clone()))));
    let s = default_view(160, 160);
    let mut gpu = CheckedRenderer::new();
    let img8 = gpu.render(&u8s, &s);
    assert!(img8.covered_count() > 2000);
    assert_eq!(bits(&img8), bits(&gpu.render(&u16s, &s)));
    assert_eq!(bits(&img8), bits(&gpu.render(&u32s, &s)));
}

#[test]
fn mirrored_node_keeps_its_front_face_and_normal() {
    let dir = TempDir::new("mirror");
    let albedo = [0.8f32; 3];
    let square = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
    let scaled = |scale: [f32; 3]| Transform::Trs { translation: [0.0; 3], rotation: [0.0, 0.0, 0.0, 1.0], scale };
    // Mirrored in x: still faces +Z, so the front camera must see it (it would be culled if the winding were not
    // corrected), lit with normal +Z.
    let mx = load(&dir.write("mx.glb", &single_mesh_scene(&square, albedo, false, scaled([-1.0, 1.0, 1.0]))));
    // Mirrored in z: now faces −Z: culled from the front, seen from behind with normal −Z.
    let mz = load(&dir.write("mz.glb", &single_mesh_scene(&square, albedo, false, scaled([1.0, 1.0, -1.0]))));
    let lights = sun(DVec3::new(0.2, 0.3, 1.0));
    let front = settings(200, 200, ortho_front(1.0), lights.clone());
    let back_cam = ortho_back(1.0);
    let back = settings(200, 200, back_cam, sun(DVec3::new(0.2, 0.3, -1.0)));
    let mut gpu = CheckedRenderer::new();
    let img = gpu.render(&mx, &front);
    assert_eq!(img.covered_count(), 100 * 100);
    let want = lambert(0.8, DVec3::Z, &front);
    assert!(rel(img.get(100, 100)[0] as f64, want) <= 1e-6);
    assert_eq!(gpu.render(&mz, &front).covered_count(), 0, "the z-mirrored square faces away and must be culled");
    let img = gpu.render(&mz, &back);
    assert_eq!(img.covered_count(), 100 * 100);
    let want = lambert(0.8, -DVec3::Z, &back);
    assert!(want > 0.0 && rel(img.get(100, 100)[0] as f64, want) <= 1e-6, "{:?} vs {want}", img.get(100, 100));
}

#[test]
fn missing_normals_become_flat_face_normals() {
    let dir = TempDir::new("flat");
    // A tilted quad without NORMAL, under a rotating node.
    let q = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.1), Vec3::new(0.0, 0.45, 0.2));
    let mut b = GltfBuilder::new();
    let mat = b.add_material("m", [0.6, 0.3, 0.9], false, None);
    let prim = Primitive { normals: None, ..q.primitive(Some(mat)) };
    let m = b.add_mesh("quad", &[prim]);
    let rot = Quat::from_axis_angle(Vec3::X, -0.3);
    let n = b.add_node(Node {
        mesh: Some(m),
        transform: Transform::Trs { translation: [0.0; 3], rotation: rot.to_array(), scale: [1.0; 3] },
        ..Default::default()
    });
    b.add_scene(&[n], None);
    let scene = load(&dir.write("flat.gltf", &b));
    let s = settings(200, 200, ortho_front(1.0), sun(DVec3::new(0.5, 0.5, 1.0)));
    let mut gpu = CheckedRenderer::new();
    let img = gpu.render(&scene, &s);
    assert!(img.covered_count() > 5000);
    let face =
        rot.as_dquat() * Vec3::new(0.5, 0.0, 0.1).as_dvec3().cross(Vec3::new(0.0, 0.45, 0.2).as_dvec3()).normalize();
    for (x, y) in covered_set(&img) {
        let p = img.get(x, y);
        for (c, a) in [0.6, 0.3, 0.9].iter().enumerate() {
            let want = lambert(*a as f32 as f64, face, &s);
            assert!(rel(p[c] as f64, want) <= 1e-6, "({x},{y}) {c}: {} vs {want}", p[c]);
        }
    }
}

#[test]
fn double_sided_materials_show_back_faces_with_reversed_normals() {
    let dir = TempDir::new("double");
    let square = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0)); // faces +Z
    let single = load(&dir.write("single.glb", &single_mesh_scene(&square, [0.5; 3], false, Transform::Identity)));
    let double = load(&dir.write("double.glb", &single_mesh_scene(&square, [0.5; 3], true, Transform::Identity)));
    let back_cam = ortho_back(1.0);
    let lit_back = settings(200, 200, back_cam, sun(DVec3::new(0.3, 0.2, -1.0)));
    let lit_front = settings(200, 200, back_cam, sun(DVec3::new(0.3, 0.2, 1.0)));
    let mut gpu = CheckedRenderer::new();
    assert_eq!(gpu.render(&single, &lit_back).covered_count(), 0, "single-sided back faces are culled");
    let img = gpu.render(&double, &lit_back);
    assert_eq!(img.covered_count(), 100 * 100);
    let want = lambert(0.5, -DVec3::Z, &lit_back);
    assert!(want > 0.0);
    for (x, y) in covered_set(&img) {
        assert!(rel(img.get(x, y)[0] as f64, want) <= 1e-6);
    }
    // Lit from the other side, the back face (normal reversed to −Z) receives nothing.
    let img = gpu.render(&double, &lit_front);
    assert_eq!(img.covered_count(), 100 * 100);
    assert!(covered_set(&img).iter().all(|&(x, y)| img.get(x, y)[..3] == [0.0; 3]));
}

#[test]
fn one_sided_surface_lit_from_behind_is_black_but_covered() {
    let dir = TempDir::new("behind");
    let square = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
    let scene = load(&dir.write("s.glb", &single_mesh_scene(&square, [1.0; 3], false, Transform::Identity)));
    let s = settings(100, 100, ortho_front(1.0), sun(DVec3::new(0.1, 0.2, -1.0)));
    let mut gpu = CheckedRenderer::new();
    let img = gpu.render(&scene, &s);
    assert_eq!(img.covered_count(), 50 * 50);
    assert!(img.pixels().iter().all(|p| p[..3] == [0.0; 3]));
}

#[test]
fn scene_directional_light_is_the_sun() {
    let dir = TempDir::new("khr");
    let square = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
    // The light shines along its node's −Z; rotated −40° about X it comes from above-front.
    let rot = Quat::from_axis_angle(Vec3::X, -40f32.to_radians());
    let mut b2 = GltfBuilder::new();
    let mat = b2.add_material("m", [0.5; 3], false, None);
    let m = b2.add_mesh("square", &[square.primitive(Some(mat))]);
    let mesh_node = b2.add_node(Node { mesh: Some(m), ..Default::default() });
    let light = b2.add_directional_light([1.0, 0.5, 0.25], 800.0);
    let ln = b2.add_node(Node {
        light: Some(light),
        transform: Transform::Trs { translation: [0.0, 2.0, 2.0], rotation: rot.to_array(), scale: [1.0; 3] },
        ..Default::default()
    });
    b2.add_scene(&[mesh_node, ln], None);
    let scene = load(&dir.write("lit.glb", &b2));
    let s = sunshade::settings::resolve(&scene, 100, 100, &Default::default(), &Default::default()).unwrap();
    let sun = s.lights.sun.unwrap();
    assert_eq!(sun.irradiance, [800.0, 400.0, 200.0]);
    let to_sun = rot.as_dquat() * DVec3::Z;
    assert!((sun.direction.as_dvec3() - to_sun).length() < 1e-6);
    let s = RenderSettings { camera: ortho_front(1.0), ..s };
    let mut gpu = CheckedRenderer::new();
    let img = gpu.render(&scene, &s);
    let cos = sun.direction.as_dvec3().z;
    for (c, e) in [800.0, 400.0, 200.0].iter().enumerate() {
        let want = 0.5 / PI * e * cos;
        assert!(rel(img.get(50, 50)[c] as f64, want) <= 1e-6);
    }
}

#[test]
fn every_interpolation_mode_renders_flat_faces_exactly() {
    use sunshade::gpu::{ContextOptions, Interpolation, Renderer};
    let dir = TempDir::new("modes");
    let square = quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
    let scene = load(&dir.write("s.glb", &single_mesh_scene(&square, [0.7; 3], false, Transform::Identity)));
    let s = settings(100, 100, ortho_front(1.0), sun(DVec3::new(0.3, 0.1, 1.0)));
    let want = lambert(0.7, DVec3::Z, &s);
    for mode in [Interpolation::Device, Interpolation::BarycentricF32, Interpolation::BarycentricF64] {
        let mut r =
            Renderer::new(&ContextOptions { validation: true, interpolation: Some(mode), ..Default::default() })
                .unwrap();
        assert_eq!(r.interpolation(), mode);
        let log = r.validation_log();
        let (img, _) = r.render_scene(&scene, &s).unwrap();
        drop(r);
        common::assert_no_validation_messages(&log);
        assert_eq!(img.covered_count(), 50 * 50, "{mode:?}");
        assert!(rel(img.get(50, 50)[0] as f64, want) <= 1e-6, "{mode:?}: {:?} vs {want}", img.get(50, 50));
    }
}

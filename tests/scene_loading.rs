//! glTF import without a GPU: what is read, what is skipped, and how bad files are refused.

mod common;

use common::TempDir;
use glam::{DVec3, Quat, Vec3};
use serde_json::json;
use sunshade::authoring::shapes::{cube, quad};
use sunshade::authoring::{GltfBuilder, Node, Primitive, Transform};
use sunshade::scene::{self, Brdf, LoadOptions, Projection};
use sunshade::settings::{self, CameraOptions, SunOptions};

fn square_scene() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = b.add_material("grey", [0.5, 0.4, 0.3], false, None);
    let mesh = b.add_mesh("square", &[quad(Vec3::ZERO, Vec3::X, Vec3::Y).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    b
}

fn load_err(path: &std::path::Path) -> String {
    match scene::load(path) {
        Ok(_) => panic!("{} loaded, expected an error", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn reads_materials_and_default_material() {
    let dir = TempDir::new("materials");
    let mut b = square_scene();
    let mesh = b.add_mesh("no-material", &[cube(0.5).primitive(None)]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    let mut doc = b.document(Some("m.bin"));
    doc["scenes"][0]["nodes"] = json!([0, n]);
    std::fs::write(dir.path("m.bin"), b.bin()).unwrap();
    std::fs::write(dir.path("m.gltf"), doc.to_string()).unwrap();
    let s = scene::load(&dir.path("m.gltf")).unwrap();
    assert_eq!(s.meshes.len(), 2);
    assert_eq!(s.materials[s.meshes[0].material].brdf, Brdf::Lambert { albedo: [0.5, 0.4, 0.3] });
    let default = &s.materials[s.meshes[1].material];
    assert_eq!(default.brdf, Brdf::Lambert { albedo: [1.0; 3] });
    assert!(!default.double_sided);
}

/// A 2 × 2 RGBA PNG.
fn tiny_png() -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, 2, 2);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header().unwrap().write_image_data(&[200; 16]).unwrap();
    out
}

#[test]
fn material_features_not_drawn_are_named_in_warnings() {
    let dir = TempDir::new("unmodelled");
    let b = square_scene();
    let mut doc = b.document(Some("u.bin"));
    std::fs::write(dir.path("u.bin"), b.bin()).unwrap();
    std::fs::write(dir.path("plain.gltf"), doc.to_string()).unwrap();
    let plain = scene::load(&dir.path("plain.gltf")).unwrap();
    assert!(plain.warnings.is_empty(), "{:?}", plain.warnings);

    // Textures, emission and its strength are drawn without a warning; BLEND (drawn opaque), the occlusion
    // texture and a material extension sunshade does not draw are named.
    std::fs::write(dir.path("t.png"), tiny_png()).unwrap();
    doc["images"] = json!([{ "uri": "t.png" }]);
    doc["textures"] = json!([{ "source": 0 }]);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": 0 });
    doc["materials"][0]["normalTexture"] = json!({ "index": 0 });
    doc["materials"][0]["occlusionTexture"] = json!({ "index": 0 });
    doc["materials"][0]["emissiveFactor"] = json!([1.0, 0.5, 0.0]);
    doc["materials"][0]["alphaMode"] = json!("BLEND");
    doc["extensionsUsed"] = json!(["KHR_materials_emissive_strength", "KHR_materials_clearcoat"]);
    doc["materials"][0]["extensions"] = json!({
        "KHR_materials_emissive_strength": { "emissiveStrength": 5.0 },
        "KHR_materials_clearcoat": { "clearcoatFactor": 1.0 }
    });
    std::fs::write(dir.path("u.gltf"), doc.to_string()).unwrap();
    let s = scene::load(&dir.path("u.gltf")).unwrap();
    assert_eq!(s.warnings.len(), 3, "{:?}", s.warnings);
    assert!(s.warnings[0].contains("KHR_materials_clearcoat"), "{:?}", s.warnings);
    assert!(s.warnings[2].contains("reads TEXCOORD_0, which the primitive lacks"), "{:?}", s.warnings);
    assert!(!s.warnings[0].contains("emissive_strength"), "{:?}", s.warnings);
    let w = &s.warnings[1];
    for named in ["material 'grey'", "occlusionTexture", "alphaMode BLEND", "KHR_materials_clearcoat"] {
        assert!(w.contains(named), "{named} missing from {w}");
    }
    for drawn in ["baseColorTexture", "normalTexture", "emissive"] {
        assert!(!w.contains(drawn), "{drawn} named as not drawn: {w}");
    }
    let m = &s.materials[0];
    assert_eq!(m.brdf, Brdf::Lambert { albedo: [0.5, 0.4, 0.3] });
    assert_eq!(m.emission, [5.0, 2.5, 0.0]);
    assert!(m.base_color_texture.is_some() && m.normal_texture.is_some());
    assert_eq!(s.textures.len(), 2, "one texture read as sRGB (base colour) and as linear (normals)");

    // A required extension that only changes appearance sunshade does not draw is drawn, and the warning says
    // the file requires it; one that changes geometry is refused, naming it.
    doc["extensionsRequired"] = json!(["KHR_materials_clearcoat"]);
    std::fs::write(dir.path("required.gltf"), doc.to_string()).unwrap();
    let s = scene::load(&dir.path("required.gltf")).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("requires KHR_materials_clearcoat") && w.contains("drawn without it")),
        "{:?}",
        s.warnings
    );
    doc["extensionsRequired"] = json!(["KHR_materials_clearcoat", "KHR_draco_mesh_compression"]);
    std::fs::write(dir.path("draco.gltf"), doc.to_string()).unwrap();
    let e = load_err(&dir.path("draco.gltf"));
    assert!(e.contains("draco.gltf") && e.contains("KHR_draco_mesh_compression"), "{e}");
    assert!(!e.contains("clearcoat"), "an appearance-only extension is named as unsupported: {e}");

    // An image that cannot be read or decoded is an error naming it; a texture with only a WebP source is
    // ignored with a warning naming the extension.
    doc["extensionsRequired"] = json!([]);
    doc["images"] = json!([{ "uri": "missing.png" }]);
    std::fs::write(dir.path("missing.gltf"), doc.to_string()).unwrap();
    let e = load_err(&dir.path("missing.gltf"));
    assert!(e.contains("missing.png") && e.contains("image 0"), "{e}");
    std::fs::write(dir.path("bad.png"), b"not a png").unwrap();
    doc["images"] = json!([{ "uri": "bad.png" }]);
    std::fs::write(dir.path("bad.gltf"), doc.to_string()).unwrap();
    assert!(load_err(&dir.path("bad.gltf")).contains("not a PNG or JPEG"));
    doc["textures"] = json!([{ "extensions": { "EXT_texture_webp": { "source": 0 } } }]);
    std::fs::write(dir.path("webp.gltf"), doc.to_string()).unwrap();
    let s = scene::load(&dir.path("webp.gltf")).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("EXT_texture_webp") && w.contains("texture ignored")),
        "{:?}",
        s.warnings
    );
    assert!(s.materials[0].base_color_texture.is_none());
    // Required, it is refused, named.
    doc["extensionsUsed"] = json!(["EXT_texture_webp"]);
    doc["extensionsRequired"] = json!(["EXT_texture_webp"]);
    std::fs::write(dir.path("webp-required.gltf"), doc.to_string()).unwrap();
    let e = load_err(&dir.path("webp-required.gltf"));
    assert!(e.contains("EXT_texture_webp") && e.contains("does not support"), "{e}");
}

#[test]
fn skips_non_triangle_modes_and_non_sun_lights_with_warnings() {
    let dir = TempDir::new("modes");
    let mut b = GltfBuilder::new();
    let q = quad(Vec3::ZERO, Vec3::X, Vec3::Y);
    let lines = Primitive { mode: Some(1), ..q.primitive(None) };
    let strip = Primitive { mode: Some(5), ..q.primitive(None) };
    let mesh = b.add_mesh("mixed", &[q.primitive(None), lines, strip]);
    let point = b.add_point_light(100.0);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    let l = b.add_node(Node { light: Some(point), ..Default::default() });
    b.add_scene(&[n, l], None);
    let s = scene::load(&dir.write("modes.glb", &b)).unwrap();
    assert_eq!(s.meshes.len(), 1, "only the TRIANGLES primitive is kept");
    assert_eq!(s.warnings.len(), 3, "{:?}", s.warnings);
    assert!(s.warnings[0].contains("LINES") && s.warnings[0].contains("skipped"), "{:?}", s.warnings);
    assert!(s.warnings[1].contains("TRIANGLE_STRIP"), "{:?}", s.warnings);
    assert!(s.warnings[2].contains("point light ignored"), "{:?}", s.warnings);
    assert!(s.lights.sun.is_none());
}

#[test]
fn cameras_are_placed_by_nodes_and_chosen_by_index() {
    let dir = TempDir::new("cameras");
    let mut b = square_scene();
    let persp = b.add_perspective_camera(0.8, 0.1, Some(50.0));
    let ortho = b.add_orthographic_camera(2.0, 1.5, 0.5, 20.0);
    let rot = Quat::from_axis_angle(Vec3::Y, 0.5);
    let c0 = b.add_node(Node {
        camera: Some(persp),
        transform: Transform::Trs { translation: [1.0, 2.0, 3.0], rotation: rot.to_array(), scale: [1.0; 3] },
        ..Default::default()
    });
    let c1 = b.add_node(Node {
        camera: Some(ortho),
        transform: Transform::Trs {
            translation: [0.0, 5.0, 0.0],
            rotation: Quat::from_axis_angle(Vec3::X, -1.0).to_array(),
            scale: [1.0; 3],
        },
        ..Default::default()
    });
    let mut doc = b.document(None);
    doc["scenes"][0]["nodes"] = json!([0, c0, c1]);
    let path = dir.path("cams.gltf");
    std::fs::write(dir.path("cams.bin"), b.bin()).unwrap();
    doc["buffers"][0]["uri"] = json!("cams.bin");
    std::fs::write(&path, doc.to_string()).unwrap();
    let s = scene::load(&path).unwrap();
    assert_eq!(s.cameras.len(), 2);
    let (idx, cam) = s.cameras[0];
    assert_eq!(idx, persp);
    assert!((cam.eye - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
    let fwd = rot.as_dquat() * -DVec3::Z;
    assert!((cam.forward - fwd).length() < 1e-6);
    assert_eq!(cam.projection, Projection::Perspective { yfov: 0.8f32 as f64, znear: 0.1f32 as f64, zfar: Some(50.0) });
    // Default: the first placed camera; --camera 1 picks the orthographic one.
    let default = settings::resolve(&s, 64, 32, &CameraOptions::default(), &SunOptions::default()).unwrap();
    assert_eq!(default.camera, cam);
    let pick = CameraOptions { camera: Some(ortho), ..Default::default() };
    let o = settings::resolve(&s, 64, 32, &pick, &SunOptions::default()).unwrap();
    assert!(matches!(o.camera.projection, Projection::Orthographic { ymag, .. } if ymag == 1.5));
    // Overrides: --eye/--target replace the placement, --fov the field of view.
    let moved = CameraOptions {
        eye: Some(DVec3::new(0.0, 0.0, 9.0)),
        target: Some(DVec3::ZERO),
        fov_degrees: Some(30.0),
        ..Default::default()
    };
    let m = settings::resolve(&s, 64, 32, &moved, &SunOptions::default()).unwrap();
    assert_eq!(m.camera.eye, DVec3::new(0.0, 0.0, 9.0));
    assert!((m.camera.forward + DVec3::Z).length() < 1e-12);
    assert!(
        matches!(m.camera.projection, Projection::Perspective { yfov, .. } if (yfov - 30f64.to_radians()).abs() < 1e-12)
    );
    let fov_on_ortho = CameraOptions { camera: Some(ortho), fov_degrees: Some(30.0), ..Default::default() };
    assert!(settings::resolve(&s, 64, 32, &fov_on_ortho, &SunOptions::default()).is_err());
}

#[test]
fn automatic_camera_frames_the_scene() {
    let dir = TempDir::new("auto");
    let s = scene::load(&dir.write("sq.glb", &square_scene())).unwrap();
    assert!(s.cameras.is_empty());
    let r = settings::resolve(&s, 300, 200, &CameraOptions::default(), &SunOptions::default()).unwrap();
    let m = r.camera.clip_from_world(r.aspect());
    for p in s.meshes[0].positions.iter() {
        let c = m * p.as_dvec3().extend(1.0);
        let ndc = c.truncate() / c.w;
        assert!(ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0 && ndc.z > 0.0 && ndc.z < 1.0, "{ndc}");
    }
}

#[test]
fn scene_index_selects_the_scene() {
    let dir = TempDir::new("scenes");
    let mut b = square_scene();
    let mesh = b.add_mesh("cube", &[cube(0.5).primitive(None)]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    let path = dir.write("two.glb", &b);
    let first = scene::load(&path).unwrap();
    assert_eq!(first.meshes[0].name, "mesh 'square' primitive 0");
    let second = scene::load_with_options(&path, &LoadOptions { scene: Some(1), ..Default::default() }).unwrap();
    assert_eq!(second.meshes[0].name, "mesh 'cube' primitive 0");
    let err =
        scene::load_with_options(&path, &LoadOptions { scene: Some(5), ..Default::default() }).unwrap_err().to_string();
    assert!(err.contains("scene 5 does not exist"), "{err}");
}

#[test]
fn flat_normals_follow_the_front_face_of_mirrored_nodes() {
    let dir = TempDir::new("flatmirror");
    let mut b = GltfBuilder::new();
    let q = quad(Vec3::ZERO, Vec3::X, Vec3::Y);
    let mesh = b.add_mesh("q", &[Primitive { normals: None, ..q.primitive(None) }]);
    let n = b.add_node(Node {
        mesh: Some(mesh),
        transform: Transform::Trs { translation: [0.0; 3], rotation: [0.0, 0.0, 0.0, 1.0], scale: [1.0, 1.0, -2.0] },
        ..Default::default()
    });
    b.add_scene(&[n], None);
    let s = scene::load(&dir.write("f.glb", &b)).unwrap();
    let m = &s.meshes[0];
    assert_eq!(m.positions.len(), 6, "flat shading gives each triangle its own vertices");
    for t in m.indices.chunks_exact(3) {
        let p: Vec<Vec3> = t.iter().map(|&i| m.positions[i as usize]).collect();
        let geometric = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        assert!((geometric - Vec3::NEG_Z).length() < 1e-6, "mirrored in z the quad faces −Z: {geometric}");
        assert!((m.normals[t[0] as usize] - Vec3::NEG_Z).length() < 1e-6);
    }
}

/// Writes a .gltf whose JSON is modified by `edit`, with its buffer in a .bin beside it.
fn edited(dir: &TempDir, name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> std::path::PathBuf {
    let b = square_scene();
    let bin = format!("{name}.bin");
    let mut doc = b.document(Some(&bin));
    std::fs::write(dir.path(&bin), b.bin()).unwrap();
    edit(&mut doc);
    let path = dir.path(&format!("{name}.gltf"));
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

#[test]
fn bad_files_are_refused_with_a_message_naming_file_and_problem() {
    let dir = TempDir::new("bad");
    let good = dir.write("good.glb", &square_scene());
    let bytes = std::fs::read(&good).unwrap();

    let truncated = dir.path("truncated.glb");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let e = load_err(&truncated);
    assert!(e.starts_with(&truncated.display().to_string()) && e.contains("GLB"), "{e}");

    let bad_json = dir.path("bad.gltf");
    std::fs::write(&bad_json, "{ \"asset\": { \"version\": \"2.0\" }, ").unwrap();
    let e = load_err(&bad_json);
    assert!(e.contains("bad.gltf") && e.contains("invalid glTF JSON"), "{e}");

    let missing_bin = edited(&dir, "missingbin", |d| d["buffers"][0]["uri"] = json!("nowhere.bin"));
    let e = load_err(&missing_bin);
    assert!(e.contains("missingbin.gltf") && e.contains("nowhere.bin"), "{e}");

    let index_past_end = edited(&dir, "index", |d| {
        let last = d["accessors"].as_array().unwrap().len() - 1;
        d["accessors"][last]["count"] = json!(6000);
    });
    let e = load_err(&index_past_end);
    assert!(e.contains("index.gltf") && e.contains("run past the end"), "{e}");

    let out_of_range = edited(&dir, "range", |d| {
        // Point the indices at the position data, whose float bits make huge indices.
        let last = d["accessors"].as_array().unwrap().len() - 1;
        d["accessors"][last]["bufferView"] = json!(0);
        d["accessors"][last]["componentType"] = json!(5125);
    });
    let e = load_err(&out_of_range);
    assert!(e.contains("range.gltf") && e.contains("out of range"), "{e}");

    let short_buffer = edited(&dir, "short", |d| d["buffers"][0]["byteLength"] = json!(100000));
    let e = load_err(&short_buffer);
    assert!(e.contains("short.gltf") && e.contains("byteLength"), "{e}");

    let dangling = edited(&dir, "dangling", |d| d["meshes"][0]["primitives"][0]["material"] = json!(7));
    let e = load_err(&dangling);
    assert!(e.contains("dangling.gltf") && e.contains("material 7 does not exist"), "{e}");

    let cycle = edited(&dir, "cycle", |d| d["nodes"][0]["children"] = json!([0]));
    let e = load_err(&cycle);
    assert!(e.contains("cycle.gltf") && (e.contains("cycle") || e.contains("invalid")), "{e}");

    let albedo = edited(&dir, "albedo", |d| {
        d["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = json!([1.5, 0, 0, 1])
    });
    let e = load_err(&albedo);
    assert!(e.contains("albedo.gltf") && e.contains("outside [0, 1]"), "{e}");

    let no_file = dir.path("absent.glb");
    assert!(load_err(&no_file).contains("absent.glb"));
}

#[test]
fn non_finite_positions_are_refused() {
    let dir = TempDir::new("nan");
    let mut b = GltfBuilder::new();
    let mut q = quad(Vec3::ZERO, Vec3::X, Vec3::Y).primitive(None);
    q.positions[2][1] = f32::NAN;
    let mesh = b.add_mesh("nan", &[q]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    // The writer's POSITION min/max skip the NaN (f32::min ignores it), so the JSON stays valid.
    let e = load_err(&dir.write("nan.gltf", &b));
    assert!(e.contains("nan.gltf") && e.contains("non-finite") && e.contains("vertex 2"), "{e}");
}

#[test]
fn animations_pose_the_scene_at_the_time_asked() {
    // A node translated from x = 0 to x = 2 between t = 0 and 1 s (LINEAR), and a STEP rotation at t = 0.5 s.
    let dir = TempDir::new("animation");
    let mut b = square_scene();
    let times = b.add_accessor_f32(&[0.0, 1.0], 1, "SCALAR");
    let moves = b.add_accessor_f32(&[0.0, 0.0, 0.0, 2.0, 0.0, 0.0], 3, "VEC3");
    let step_times = b.add_accessor_f32(&[0.0, 0.5], 1, "SCALAR");
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let turns = b.add_accessor_f32(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, half, half], 4, "VEC4");
    let mut doc = b.document(Some("a.bin"));
    doc["animations"] = json!([{
        "channels": [
            { "sampler": 0, "target": { "node": 0, "path": "translation" } },
            { "sampler": 1, "target": { "node": 0, "path": "rotation" } }
        ],
        "samplers": [
            { "input": times, "output": moves },
            { "input": step_times, "output": turns, "interpolation": "STEP" }
        ]
    }]);
    std::fs::write(dir.path("a.bin"), b.bin()).unwrap();
    std::fs::write(dir.path("a.gltf"), doc.to_string()).unwrap();
    let path = dir.path("a.gltf");
    let rest = scene::load(&path).unwrap();
    assert!(rest.warnings.iter().any(|w| w.contains("1 animation(s); drawn at rest")), "{:?}", rest.warnings);
    let at = |t: f64| scene::load_with_options(&path, &LoadOptions { animation: Some((0, t)), ..Default::default() });
    let posed = at(0.25).unwrap();
    for (p, q) in posed.meshes[0].positions.iter().zip(&rest.meshes[0].positions) {
        assert!((*p - *q - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6, "{p} {q}");
    }
    // After 0.5 s the STEP rotation (a quarter turn about z) holds; past the last key the last values hold.
    let turned = at(7.0).unwrap();
    for (p, q) in turned.meshes[0].positions.iter().zip(&rest.meshes[0].positions) {
        let want = Vec3::new(-q.y, q.x, q.z) + Vec3::new(2.0, 0.0, 0.0);
        assert!((*p - want).length() < 1e-5, "{p} against {want}");
    }
    assert!(at(0.0).is_ok());
    let e = scene::load_with_options(&path, &LoadOptions { animation: Some((3, 0.0)), ..Default::default() })
        .unwrap_err()
        .to_string();
    assert!(e.contains("animation 3 does not exist"), "{e}");
}

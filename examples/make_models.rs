//! Writes the generated scenes in `models/` (all but `teapot.glb`, which comes from Panda3D's Utah teapot):
//!
//!     cargo run --release --example make_models
//!
//! Every scene is small and built with `sunshade::authoring`, the same helper the tests use.

use std::path::Path;

use glam::{Quat, Vec3};
use serde_json::json;
use sunshade::authoring::shapes::{cube, grid, quad, uv_sphere, MeshData};
use sunshade::authoring::{GltfBuilder, Node, Transform};

fn trs(translation: [f32; 3], rotation: Quat, scale: f32) -> Transform {
    Transform::Trs { translation, rotation: rotation.to_array(), scale: [scale; 3] }
}

/// A 1 m square facing +Z, grey albedo 0.5, with a directional light (the sun) at 30° from its normal.
fn square() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = b.add_material("grey 0.5", [0.5, 0.5, 0.5], false, None);
    let mesh = b
        .add_mesh("square", &[quad(Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0)).primitive(Some(m))]);
    let n = b.add_node(Node { name: Some("square".into()), mesh: Some(mesh), ..Default::default() });
    let sun = b.add_directional_light([1.0, 1.0, 1.0], 1000.0);
    let s = b.add_node(Node {
        name: Some("sun".into()),
        light: Some(sun),
        transform: trs([0.0, 0.0, 2.0], Quat::from_axis_angle(Vec3::X, -30f32.to_radians()), 1.0),
        ..Default::default()
    });
    b.add_scene(&[n, s], None);
    b
}

/// A unit cube turned about an oblique axis, on a floor, with a perspective camera.
fn cube_scene() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let orange = b.add_material("orange", [0.9, 0.45, 0.1], false, None);
    let floor = b.add_material("floor", [0.6, 0.6, 0.6], false, None);
    let c = b.add_mesh("cube", &[cube(0.5).primitive(Some(orange))]);
    let f = b.add_mesh("floor", &[grid(Vec3::new(0.0, -0.9, 0.0), 4.0, 8).primitive(Some(floor))]);
    let cn = b.add_node(Node {
        name: Some("cube".into()),
        mesh: Some(c),
        transform: trs([0.0, 0.0, 0.0], Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.8), 1.0),
        ..Default::default()
    });
    let fnode = b.add_node(Node { name: Some("floor".into()), mesh: Some(f), ..Default::default() });
    let camn = camera_node(&mut b, Vec3::new(2.2, 1.6, 3.0), Vec3::ZERO, 50.0);
    b.add_scene(&[cn, fnode, camn], None);
    b
}

/// A perspective camera node at `eye` looking at `target` (glTF cameras look down their local −Z).
fn camera_node(b: &mut GltfBuilder, eye: Vec3, target: Vec3, yfov_degrees: f32) -> usize {
    let cam = b.add_perspective_camera(yfov_degrees.to_radians(), 0.05, Some(100.0));
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let look = Quat::from_mat3(&glam::Mat3::from_cols(right, right.cross(forward), -forward));
    b.add_node(Node {
        name: Some("camera".into()),
        camera: Some(cam),
        transform: trs(eye.to_array(), look, 1.0),
        ..Default::default()
    })
}

/// A node holding a disk skylight (local XY plane, emitting towards local −Z) of radius [m] and radiance
/// [W/(m²·sr)], facing straight down at `center`.
fn ceiling_disk(b: &mut GltfBuilder, center: Vec3, radius: f32, radiance: f32) -> usize {
    b.add_node(Node {
        name: Some("disk skylight".into()),
        transform: trs(center.to_array(), Quat::from_axis_angle(Vec3::X, -90f32.to_radians()), 1.0),
        extras: Some(
            json!({ "sunshade": { "light": "disk", "radius": radius, "radiance": [radiance, radiance, radiance] } }),
        ),
        ..Default::default()
    })
}

fn mesh_node(
    b: &mut GltfBuilder,
    name: &str,
    mesh: &MeshData,
    albedo: [f32; 3],
    double_sided: bool,
    transform: Transform,
) -> usize {
    let m = b.add_material(name, albedo, double_sided, None);
    let mesh = b.add_mesh(name, &[mesh.primitive(Some(m))]);
    b.add_node(Node { name: Some(name.into()), mesh: Some(mesh), transform, ..Default::default() })
}

/// The lecture's room: a 6 × 6 m floor and two walls, a disk skylight of radius 0.6 m at f = 2.5 m facing down
/// (radiance 3000 W/(m²·sr): about 510 W/m² on the floor beneath it), a sphere and a box on the floor.
fn room() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let upright = Quat::from_axis_angle(Vec3::X, 90f32.to_radians());
    let mut roots = vec![
        mesh_node(&mut b, "floor", &grid(Vec3::ZERO, 6.0, 30), [0.6, 0.58, 0.55], false, Transform::Identity),
        mesh_node(
            &mut b,
            "back wall",
            &grid(Vec3::ZERO, 6.0, 20),
            [0.75, 0.72, 0.68],
            true,
            trs([0.0, 3.0, -3.0], upright, 1.0),
        ),
        mesh_node(
            &mut b,
            "left wall",
            &grid(Vec3::ZERO, 6.0, 20),
            [0.55, 0.65, 0.75],
            true,
            trs([-3.0, 3.0, 0.0], Quat::from_axis_angle(Vec3::Y, 90f32.to_radians()) * upright, 1.0),
        ),
        mesh_node(
            &mut b,
            "sphere",
            &uv_sphere(Vec3::new(0.8, 0.5, -0.6), 0.5, 32, 64),
            [0.85, 0.3, 0.2],
            false,
            Transform::Identity,
        ),
        mesh_node(
            &mut b,
            "box",
            &cube(0.4),
            [0.3, 0.5, 0.85],
            false,
            trs([-1.0, 0.4, 0.4], Quat::from_axis_angle(Vec3::Y, 0.5), 1.0),
        ),
    ];
    roots.push(ceiling_disk(&mut b, Vec3::new(0.0, 2.5, 0.0), 0.6, 3000.0));
    roots.push(camera_node(&mut b, Vec3::new(2.6, 2.2, 2.9), Vec3::new(-0.4, 0.4, -0.8), 60.0));
    b.add_scene(&roots, None);
    b
}

/// The teapot on a ground plane under an overcast sky of 300 W/(m²·sr) (about 940 W/m² on the ground), no sun.
fn overcast(teapot: &sunshade::scene::Scene) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let mut roots =
        vec![mesh_node(&mut b, "ground", &grid(Vec3::ZERO, 12.0, 24), [0.4, 0.45, 0.35], false, Transform::Identity)];
    for (i, mesh) in teapot.meshes.iter().enumerate() {
        let data = MeshData {
            positions: mesh.positions.iter().map(|p| p.to_array()).collect(),
            normals: mesh.normals.iter().map(|n| n.to_array()).collect(),
            indices: mesh.indices.clone(),
        };
        roots.push(mesh_node(&mut b, &format!("teapot {i}"), &data, [0.8, 0.8, 0.78], false, Transform::Identity));
    }
    roots.push(camera_node(&mut b, Vec3::new(5.5, 4.5, 8.0), Vec3::new(0.2, 1.2, 0.0), 45.0));
    b.add_scene(&roots, Some(json!({ "sunshade": { "sky_radiance": [300.0, 300.0, 320.0] } })));
    b
}

/// Spheres and a box on the ground with the sun 0.1° above the horizon, coming from the left: its disk, 0.53° wide,
/// is partly set for the ground, which then receives a few W/m².
fn sunset() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let mut roots =
        vec![mesh_node(&mut b, "ground", &grid(Vec3::ZERO, 10.0, 20), [0.5, 0.5, 0.5], false, Transform::Identity)];
    for (i, x) in [-1.5f32, 0.0, 1.5].iter().enumerate() {
        let sphere = uv_sphere(Vec3::new(*x, 0.5, 0.0), 0.5, 32, 64);
        roots.push(mesh_node(&mut b, &format!("sphere {i}"), &sphere, [0.8, 0.75, 0.7], false, Transform::Identity));
    }
    roots.push(mesh_node(
        &mut b,
        "box",
        &cube(0.5),
        [0.7, 0.7, 0.8],
        false,
        trs([0.8, 0.5, -1.5], Quat::from_axis_angle(Vec3::Y, 0.6), 1.0),
    ));
    let sun = b.add_directional_light([1.0, 0.9, 0.75], 1000.0);
    // Towards the sun: elevation 0.1°, azimuth −80° (from −X, a little in front). The light shines along its node's
    // −Z, so the node's +Z points at the sun.
    let (el, az) = (0.1f32.to_radians(), (-80f32).to_radians());
    let to_sun = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    let rot = Quat::from_rotation_arc(Vec3::Z, to_sun);
    roots.push(b.add_node(Node {
        name: Some("sun".into()),
        light: Some(sun),
        transform: trs([0.0, 5.0, 0.0], rot, 1.0),
        ..Default::default()
    }));
    roots.push(camera_node(&mut b, Vec3::new(0.5, 2.2, 6.5), Vec3::new(0.0, 0.4, 0.0), 45.0));
    b.add_scene(&roots, None);
    b
}

/// Three spheres of different albedo and a large triangle count, for accuracy and timing tables.
fn spheres() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let mut roots = Vec::new();
    for (i, albedo) in [[0.8, 0.2, 0.2], [0.2, 0.8, 0.2], [0.2, 0.2, 0.8]].iter().enumerate() {
        let m = b.add_material(&format!("sphere {i}"), *albedo, false, None);
        let x = (i as f32 - 1.0) * 1.1;
        let mesh =
            b.add_mesh(&format!("sphere {i}"), &[uv_sphere(Vec3::new(x, 0.0, 0.0), 0.5, 48, 96).primitive(Some(m))]);
        roots.push(b.add_node(Node { mesh: Some(mesh), ..Default::default() }));
    }
    b.add_scene(&roots, None);
    b
}

/// One sphere per BRDF on a grey floor: Lambert, Phong, Blinn-Phong, isotropic and anisotropic Ward (material
/// extras, docs/brdf.md). No light: the README's pictures light it with the sun, a disk skylight and the sky.
fn brdfs() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let mut roots =
        vec![mesh_node(&mut b, "floor", &grid(Vec3::ZERO, 8.0, 16), [0.5, 0.5, 0.5], false, Transform::Identity)];
    let materials = [
        ("Lambert", json!({ "brdf": "lambert", "albedo": [0.75, 0.45, 0.3] })),
        ("Phong e=80", json!({ "brdf": "phong", "kd": [0.15, 0.3, 0.6], "ks": [0.35, 0.35, 0.35], "exponent": 80 })),
        (
            "Blinn-Phong e=300",
            json!({ "brdf": "blinn-phong", "kd": [0.15, 0.5, 0.2], "ks": [0.35, 0.35, 0.35], "exponent": 300 }),
        ),
        ("Ward α=0.15", json!({ "brdf": "ward", "kd": [0.5, 0.15, 0.15], "ks": [0.4, 0.4, 0.4], "alpha": 0.15 })),
        (
            "Ward αx=0.05 αy=0.3",
            json!({ "brdf": "ward", "kd": [0.4, 0.4, 0.45], "ks": [0.5, 0.5, 0.5], "alpha_x": 0.05, "alpha_y": 0.3 }),
        ),
    ];
    for (i, (name, extras)) in materials.into_iter().enumerate() {
        let m = b.add_material(name, [0.5; 3], false, Some(json!({ "sunshade": extras })));
        let x = (i as f32 - 2.0) * 1.2;
        let mesh = b.add_mesh(name, &[uv_sphere(Vec3::new(x, 0.5, 0.0), 0.5, 48, 96).primitive(Some(m))]);
        roots.push(b.add_node(Node { name: Some(name.into()), mesh: Some(mesh), ..Default::default() }));
    }
    roots.push(camera_node(&mut b, Vec3::new(0.0, 1.8, 6.0), Vec3::new(0.0, 0.4, 0.0), 36.0));
    b.add_scene(&roots, None);
    b
}

fn main() -> std::io::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    std::fs::create_dir_all(&dir)?;
    square().write(&dir.join("square.gltf"))?;
    cube_scene().write(&dir.join("cube.glb"))?;
    spheres().write(&dir.join("spheres.glb"))?;
    room().write(&dir.join("room.gltf"))?;
    let teapot = sunshade::scene::load(&dir.join("teapot.glb")).map_err(std::io::Error::other)?;
    overcast(&teapot).write(&dir.join("overcast.glb"))?;
    sunset().write(&dir.join("sunset.glb"))?;
    brdfs().write(&dir.join("brdfs.glb"))?;
    println!(
        "wrote square.gltf (+ .bin), cube.glb, spheres.glb, room.gltf (+ .bin), overcast.glb, sunset.glb, brdfs.glb in {}",
        dir.display()
    );
    Ok(())
}

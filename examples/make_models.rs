//! Writes the generated scenes in `models/` (all but `teapot.glb`, which comes from Panda3D's Utah teapot):
//!
//!     cargo run --release --example make_models
//!
//! Every scene is small and built with `sunshade::authoring`, the same helper the tests use.

use std::path::Path;

use glam::{Quat, Vec3};
use sunshade::authoring::shapes::{cube, grid, quad, uv_sphere};
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
    let cam = b.add_perspective_camera(50f32.to_radians(), 0.1, Some(100.0));
    let eye = Vec3::new(2.2, 1.6, 3.0);
    // Camera axes: right, up, back (glTF cameras look down their local −Z).
    let forward = (Vec3::ZERO - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let look = Quat::from_mat3(&glam::Mat3::from_cols(right, right.cross(forward), -forward));
    let camn = b.add_node(Node {
        name: Some("camera".into()),
        camera: Some(cam),
        transform: trs(eye.to_array(), look, 1.0),
        ..Default::default()
    });
    b.add_scene(&[cn, fnode, camn], None);
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

fn main() -> std::io::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    std::fs::create_dir_all(&dir)?;
    square().write(&dir.join("square.gltf"))?;
    cube_scene().write(&dir.join("cube.glb"))?;
    spheres().write(&dir.join("spheres.glb"))?;
    println!("wrote square.gltf (+ square.bin), cube.glb, spheres.glb in {}", dir.display());
    Ok(())
}

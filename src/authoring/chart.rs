//! The BRDF chart: one scene per material, a finely tessellated unit sphere seen by an orthographic camera from
//! +Z, so that one image sweeps every angle between the normal and the viewer, and, lit by the sun from a few
//! directions, every incidence. The GPU-against-reference test (`tests/brdf_gpu.rs`) and
//! `sunshade bench --brdf-chart` both use it.

use glam::Vec3;
use serde_json::{json, Value};

use super::shapes::uv_sphere;
use super::{GltfBuilder, Node, Transform};

/// A chart entry: a name for tables and the material's `extras.sunshade` object.
#[derive(Clone, Debug)]
pub struct ChartMaterial {
    pub name: String,
    pub extras: Value,
}

/// Angles \[degrees\] between the viewer (+Z) and the sun in the chart's renders.
pub const SUN_FROM_VIEW_DEGREES: [f64; 3] = [20.0, 60.0, 85.0];

/// Direction towards the sun at `degrees` from the viewer (+Z), leaning towards (0.8, 0.6, 0).
pub fn sun_direction(degrees: f64) -> [f64; 3] {
    let t = degrees.to_radians();
    [0.8 * t.sin(), 0.6 * t.sin(), t.cos()]
}

/// Lambert; Phong and Blinn-Phong at exponents 0, 1, 100, 1e4, 1e6; Ward at α = 0.01, 0.05, 0.2 and anisotropic;
/// glTF's dielectric at roughness 0.15 and metal at 0.5.
pub fn brdf_chart() -> Vec<ChartMaterial> {
    let (kd, ks) = ([0.3, 0.2, 0.1], [0.7, 0.7, 0.7]);
    let mut v =
        vec![ChartMaterial { name: "Lambert".into(), extras: json!({ "brdf": "lambert", "albedo": [0.8, 0.6, 0.4] }) }];
    for e in [0.0, 1.0, 100.0, 1e4, 1e6] {
        v.push(ChartMaterial {
            name: format!("Phong e={e}"),
            extras: json!({ "brdf": "phong", "kd": kd, "ks": ks, "exponent": e }),
        });
        v.push(ChartMaterial {
            name: format!("Blinn-Phong e={e}"),
            extras: json!({ "brdf": "blinn-phong", "kd": kd, "ks": ks, "exponent": e }),
        });
    }
    for a in [0.01, 0.05, 0.2] {
        v.push(ChartMaterial {
            name: format!("Ward α={a}"),
            extras: json!({ "brdf": "ward", "kd": kd, "ks": ks, "alpha": a }),
        });
    }
    v.push(ChartMaterial {
        name: "Ward αx=0.02 αy=0.3".into(),
        extras: json!({ "brdf": "ward", "kd": kd, "ks": ks, "alpha_x": 0.02, "alpha_y": 0.3 }),
    });
    for (metallic, roughness) in [(0.0, 0.15), (1.0, 0.5)] {
        v.push(ChartMaterial {
            name: format!("glTF metallic={metallic} roughness={roughness}"),
            extras: json!({ "brdf": "gltf", "base_color": [0.9, 0.6, 0.3], "metallic": metallic, "roughness": roughness }),
        });
    }
    v
}

/// The chart's scene for one material: a unit sphere (96 stacks × 192 slices) at the origin and an orthographic
/// camera 5 m away on +Z (half-height 1.05 m). No light: the caller chooses the sun.
pub fn sphere_scene(material: &ChartMaterial) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = b.add_material(&material.name, [0.5; 3], false, Some(json!({ "sunshade": material.extras })));
    let mesh = b.add_mesh("sphere", &[uv_sphere(Vec3::ZERO, 1.0, 96, 192).primitive(Some(m))]);
    let sphere = b.add_node(Node { name: Some("sphere".into()), mesh: Some(mesh), ..Default::default() });
    let camera = b.add_orthographic_camera(1.05, 1.05, 1.0, 10.0);
    let camera = b.add_node(Node {
        name: Some("camera".into()),
        camera: Some(camera),
        transform: Transform::Trs { translation: [0.0, 0.0, 5.0], rotation: [0.0, 0.0, 0.0, 1.0], scale: [1.0; 3] },
        ..Default::default()
    });
    b.add_scene(&[sphere, camera], None);
    b
}

/// A file name for the material's scene.
pub fn file_name(material: &ChartMaterial) -> String {
    format!("{}.glb", material.name.replace(|c: char| !c.is_ascii_alphanumeric(), "_"))
}

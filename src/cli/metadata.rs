//! What an output file records about its render: the camera as OpenEXR's standard `worldToCamera` and
//! `worldToNDC` matrices, and the lights and quality settings as JSON text (`sunshadeLights`,
//! `sunshadeSettings`: in EXR inside the one JSON attribute `sunshade`, in PNG as tEXt chunks), and the predicted
//! error bound of the models used (`sunshadePredictedError`, `accuracy::predicted`), and the measured BRDF tables
//! its materials use (`sunshadeMeasured`).

use serde_json::json;

use crate::accuracy::predicted::Prediction;
use crate::film::Metadata;
use crate::render::flags::SceneArgs;
use crate::scene::{Light, Scene};
use crate::settings::RenderSettings;
use crate::shading::{DiskModel, ShadowMapFilter, SunModel};

/// The metadata of a render by `renderer` ("gpu: llvmpipe ...; interpolation f64" or "cpu reference"), with its
/// predicted error.
pub fn of_render_predicted(settings: &RenderSettings, renderer: &str, prediction: &Prediction) -> Metadata {
    let mut meta = of_render(settings, renderer);
    meta.text.push(("sunshadePredictedError".into(), prediction.json().to_string()));
    meta
}

/// The metadata of a render by `renderer` ("gpu: llvmpipe ...; interpolation f64" or "cpu reference").
pub fn of_render(settings: &RenderSettings, renderer: &str) -> Metadata {
    let aspect = settings.width as f64 / settings.height as f64;
    let cam = &settings.camera;
    let m = |x: glam::DMat4| x.to_cols_array().map(|v| v as f32);
    let l = &settings.lights;
    let (mut sun, mut disks, mut sky) = (json!(null), Vec::new(), json!(null));
    for light in l.iter() {
        match light {
            Light::Sun(s) => {
                sun = json!({
                    "direction_towards_sun": s.direction.to_array(),
                    "irradiance": s.irradiance,
                    "angular_diameter_deg": (s.angular_diameter as f64).to_degrees(),
                })
            }
            Light::Disk { disk: d, .. } => disks.push(json!({
                "center": d.center.to_array(), "direction": d.direction.to_array(), "radius": d.radius, "radiance": d.radiance,
            })),
            Light::Sky(radiance) => sky = json!(radiance),
        }
    }
    let lights = json!({
        "units": { "sun_irradiance": "W/m2 on a surface facing the sun", "radiance": "W/(m2 sr)", "lengths": "m" },
        "sun": sun,
        "disks": disks,
        "sky_radiance": sky,
    });
    let sh = &settings.shading;
    let quality = json!({
        "renderer": renderer,
        "width": settings.width,
        "height": settings.height,
        "sun_model": match sh.sun { SunModel::Disk => "disk", SunModel::Delta => "delta" },
        "sun_samples": sh.sun_samples_per_axis * sh.sun_samples_per_axis,
        // Where `--tolerance` chose the sun per material: by material index (null: the render's).
        "sun_per_material": settings.sun_per_material.iter().map(|c| c.map(|c| json!({
            "sun_model": match c.sun { SunModel::Disk => "disk", SunModel::Delta => "delta" },
            "sun_samples": c.sun_samples_per_axis * c.sun_samples_per_axis,
        }))).collect::<Vec<_>>(),
        "disk_model": match sh.disk { DiskModel::Exact => "exact", DiskModel::SmallSource => "small-source" },
        "samples": sh.samples_per_axis * sh.samples_per_axis,
        // Where `--tolerance`'s study kept the lobe grids per material: by material index (null: the render's).
        "samples_per_material": settings.lobes_per_material.iter().map(|k| k.map(|k| k * k)).collect::<Vec<_>>(),
        "shadows": sh.shadows.name(),
        "shadow_samples": sh.shadow_samples_per_axis * sh.shadow_samples_per_axis,
        // The lights' visible fractions through occluders: the ray grids, or the reference's slices.
        "visibility_rule": sh.visibility_rule.name(),
        "shadow_map_size": sh.shadow_map_size,
        "shadow_map_filter": match sh.shadow_map_filter { ShadowMapFilter::Pcss => "pcss", ShadowMapFilter::Nearest => "nearest" },
        "quantity": sh.quantity.name(),
        "camera": { "eye": cam.eye.to_array(), "forward": cam.forward.to_array(), "up": cam.up.to_array(),
                    "orthographic": cam.is_orthographic() },
        "worldToNDC": "Vulkan clip space before the divide by w: x right, y down, depth in [0, 1]",
    });
    Metadata {
        text: vec![
            ("sunshadeLights".into(), lights.to_string()),
            ("sunshadeSettings".into(), quality.to_string()),
            // What the pixel values are, in which unit (the image writer's default, radiance, replaced).
            (
                "quantity".into(),
                format!("{} {} per linear RGB channel; A = coverage", sh.quantity.name(), sh.quantity.unit_ascii()),
            ),
            ("sunshadeVersion".into(), env!("CARGO_PKG_VERSION").into()),
        ],
        matrices: vec![
            ("worldToCamera".into(), m(cam.view_from_world())),
            ("worldToNDC".into(), m(cam.clip_from_world(aspect))),
        ],
    }
}

/// `sunshadeMeasured`: the measured BRDF tables the scene's materials render with (material, file, lookup), or
/// nothing where none is measured, so that an image says which measurement it shows.
pub fn measured_materials(scene: &crate::scene::Scene) -> Option<(String, String)> {
    let list: Vec<_> = scene
        .materials
        .iter()
        .filter_map(|m| match &m.brdf {
            crate::scene::Brdf::Measured { table, lookup } => Some(json!({
                "material": m.name,
                "file": table.name,
                "lookup": if *lookup == crate::shading::measured::MeasuredLookup::Nearest { "nearest" } else { "linear" },
            })),
            _ => None,
        })
        .collect();
    (!list.is_empty()).then(|| ("sunshadeMeasured".to_string(), serde_json::Value::Array(list).to_string()))
}

/// The sun model of a render in words, for `-v`: "sun: disk, 8² samples"; where `--tolerance` chose per material
/// (`RenderSettings::sun_per_material`), each material's (by its name, "material 'floor'" or "material 2"):
/// "sun: per material: material 'floor' delta (a single direction); material 'Ward' disk, 6² samples".
pub fn sun_model_line(settings: &RenderSettings, scene: &Scene) -> String {
    let model = |sun: SunModel, k: u32| match sun {
        SunModel::Delta => "delta (a single direction)".to_string(),
        SunModel::Disk => format!("disk, {k}² samples"),
    };
    if settings.lights.sun.is_none() {
        return "sun: none".into();
    }
    if settings.sun_per_material.is_empty() {
        return format!("sun: {}", model(settings.shading.sun, settings.shading.sun_samples_per_axis));
    }
    let each: Vec<String> = (0..scene.materials.len())
        .filter(|&i| scene.meshes.iter().any(|m| m.material == i))
        .map(|i| {
            let s = settings.shading_for(i);
            format!("{} {}", scene.materials[i].name, model(s.sun, s.sun_samples_per_axis))
        })
        .collect();
    format!("sun: per material: {}", each.join("; "))
}

/// The lobe grids of a render in words, for `-v`, where it has disk lights or a sky: "lobes under disk lights and
/// the sky: 16² samples"; where `--tolerance`'s study kept them per material (`RenderSettings::lobes_per_material`),
/// the finest and then each material's: "... 27² samples (per material: material 'Phong' 13²; material 'Ward' 27²)".
pub fn lobe_model_line(settings: &RenderSettings, scene: &Scene) -> Option<String> {
    if settings.lights.disks.is_empty() && settings.lights.sky.is_none() {
        return None;
    }
    let mut line = format!("lobes under disk lights and the sky: {}² samples", settings.shading.samples_per_axis);
    let each: Vec<String> = settings
        .lobes_per_material
        .iter()
        .enumerate()
        .filter_map(|(i, k)| Some(format!("{} {}²", scene.materials.get(i)?.name, (*k)?)))
        .collect();
    if !each.is_empty() {
        line += &format!(" (per material: {})", each.join("; "));
    }
    Some(line)
}

/// `sunshadeDaylight`: where the sun of `--time` stood and the clear sky it gave, when the render has one.
pub fn daylight(a: &super::args::SceneArgs) -> Option<(String, String)> {
    let d = a.daylight.at_time()?;
    Some(("sunshadeDaylight".into(), d.json(a.daylight.north, a.daylight.linke_turbidity).to_string()))
}

/// Where a render's sun is, for `-v`: its elevation above the horizontal XZ plane and azimuth from +Z towards +X
/// (`--sun-elevation`/`--sun-azimuth`'s convention), its direction, and where it came from (the flags, `--time`
/// with the azimuth clockwise from north, the scene's directional light, or the default).
pub fn sun_position_line(settings: &RenderSettings, scene: &Scene, a: &SceneArgs) -> Option<String> {
    let sun = settings.lights.sun.as_ref()?;
    let d = sun.direction.as_dvec3();
    let (elevation, azimuth) = crate::settings::sun_angles_from_direction(d);
    let from = if let Some(at) = a.daylight.at_time() {
        format!(
            "--time {} at {:.4}°, {:.4}° (azimuth {:.3}° clockwise from north)",
            at.instant, at.location.latitude_deg, at.location.longitude_deg, at.position.azimuth_deg
        )
    } else if a.sun_dir.is_some() || a.sun_elevation.is_some() || a.sun_azimuth.is_some() {
        "the flags".to_string()
    } else if scene.lights.sun.is_some() {
        "the scene's directional light".to_string()
    } else {
        "the default".to_string()
    };
    Some(format!(
        "sun position: elevation {elevation:.3}°, azimuth {azimuth:.3}° (0 = towards +Z, 90 = towards +X), direction \
         ({:.4}, {:.4}, {:.4}); from {from}",
        d.x, d.y, d.z
    ))
}

/// Which camera a render used, for `-v`: the file's camera N (the first the nodes place, unless `--camera` named
/// one) or the automatic one, moved by `--eye`/`--target`/`--up` where given; its eye, view direction and field of
/// view.
pub fn camera_line(settings: &RenderSettings, scene: &Scene, a: &SceneArgs) -> String {
    use crate::render::flags::CameraChoice;
    use crate::scene::camera::Projection;
    let which = match a.camera {
        Some(CameraChoice::Scene(n)) => format!("the file's camera {n} (--camera)"),
        Some(CameraChoice::Automatic) => "automatic (--camera auto)".to_string(),
        None => match scene.cameras.first() {
            Some((n, _)) => format!("the file's camera {n} (its first placed camera; --camera auto frames the scene)"),
            None => "automatic (the file places no camera)".to_string(),
        },
    };
    let moved = if a.eye.is_some() || a.target.is_some() || a.up.is_some() { ", moved by the flags" } else { "" };
    let c = &settings.camera;
    let view = match c.projection {
        Projection::Perspective { yfov, .. } => {
            format!("perspective, {:.3}° vertical field of view", yfov.to_degrees())
        }
        Projection::Orthographic { ymag, .. } => format!("orthographic, {ymag} m half-height"),
    };
    format!(
        "camera: {which}{moved}; eye ({:.4}, {:.4}, {:.4}) m looking along ({:.4}, {:.4}, {:.4}); {view}",
        c.eye.x, c.eye.y, c.eye.z, c.forward.x, c.forward.y, c.forward.z
    )
}

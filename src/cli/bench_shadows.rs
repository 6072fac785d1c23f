//! `sunshade bench --shadows`: speed against error of the shadow techniques, on shadowed scenes (the teapot on a
//! floor under the sun; the room under its skylight). Each row is a technique and sample count or map size: the
//! GPU frame time (median; the map's pass included), the CPU reference's time, and the error against a converged
//! reference, measured as the visible-fraction error `|L − L_conv| / L_unshadowed` (exact for a Lambertian
//! surface under one light) over the pixels the converged reference finds shadowed at all. The last column counts
//! the GPU's pixels over the `render --check` tolerance against the reference's rays with the same samples.

use std::time::Instant;

use glam::Vec3;

use super::bench_common::{bench_renderer, build, device_description, median, ms, warm_frames, BenchArgs};
use super::generated::{machine, publish, today};
use super::CliError;
use crate::compare::{self, DiffOptions};
use crate::cpu;
use crate::film::Image;
use crate::scene::{self, LoadOptions, Mesh, Scene};
use crate::settings::{self, CameraOptions, LightOptions, RenderSettings, SunOptions};
use crate::shading::{ShadowMapFilter, Shadows, DEFAULT_SHADOW_SAMPLES_PER_AXIS};

/// Samples per axis of the converged reference, and of its refinement check (about twice the rays).
const CONVERGED: u32 = 32;
const REFINED: u32 = 45;

/// The visible-fraction error of `image` against `converged`, relative to `unshadowed`: (max, mean) over the
/// pixels `converged` shadows, and how many of them are over 1e-2 and 1e-3; and that pixel count.
struct FractionError {
    max: f64,
    mean: f64,
    over_1e2: usize,
    over_1e3: usize,
    shadowed: usize,
}

fn fraction_error(image: &Image, converged: &Image, unshadowed: &Image) -> FractionError {
    let mut e = FractionError { max: 0.0, mean: 0.0, over_1e2: 0, over_1e3: 0, shadowed: 0 };
    for ((p, c), u) in image.pixels().iter().zip(converged.pixels()).zip(unshadowed.pixels()) {
        let mut worst = None::<f64>;
        for k in 0..3 {
            let (p, c, u) = (p[k] as f64, c[k] as f64, u[k] as f64);
            // Shadowed: the converged image is darker than the unshadowed one by more than rounding.
            if u > 0.0 && c < u * (1.0 - 1e-5) {
                worst = Some(worst.unwrap_or(0.0).max((p - c).abs() / u));
            }
        }
        if let Some(w) = worst {
            e.shadowed += 1;
            e.max = e.max.max(w);
            e.mean += w;
            e.over_1e2 += usize::from(w > 1e-2);
            e.over_1e3 += usize::from(w > 1e-3);
        }
    }
    if e.shadowed > 0 {
        e.mean /= e.shadowed as f64;
    }
    e
}

/// The teapot on a square floor under its lowest point, three times its radius across.
pub(super) fn teapot_on_floor() -> Result<Scene, CliError> {
    let mut scene = scene::load_with_options(std::path::Path::new("models/teapot.glb"), &LoadOptions::default())?;
    let (b, r) = (scene.bounds().expect("the teapot has triangles"), scene.bounding_sphere().expect("").radius);
    let (c, y, h) = (((b.min + b.max) * 0.5).as_vec3(), b.min.y as f32, 1.5 * r as f32);
    let corners = [[-h, -h], [h, -h], [h, h], [-h, h]].map(|[x, z]| Vec3::new(c.x + x, y, c.z + z));
    scene.meshes.push(Mesh {
        name: "floor".into(),
        positions: corners.to_vec(),
        normals: vec![Vec3::Y; 4],
        tangents: vec![glam::Vec4::new(1.0, 0.0, 0.0, 1.0); 4],
        tex_coords: Default::default(),
        colors: Vec::new(),
        // Counter-clockwise seen from above.
        indices: vec![0, 2, 1, 0, 3, 2],
        material: 0,
    });
    Ok(scene)
}

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let (width, height) = (a.width.unwrap_or(256), a.height.unwrap_or(192));
    let (mut renderer, info, reference) = bench_renderer(a, (width, height))?;
    let sun = SunOptions { elevation_degrees: Some(40.0), azimuth_degrees: Some(30.0), ..Default::default() };
    let room = scene::load_with_options(std::path::Path::new("models/room.gltf"), &LoadOptions::default())?;
    let teapot = teapot_on_floor()?;
    let sphere = teapot.bounding_sphere().expect("triangles");
    // Looking down at the teapot and its shadow from the front, above.
    let above = CameraOptions {
        eye: Some(sphere.center + glam::DVec3::new(0.0, 1.6, 2.2) * sphere.radius),
        target: Some(sphere.center),
        ..Default::default()
    };
    let wide = SunOptions { diameter_degrees: Some(5.0), ..sun.clone() };
    let cases = [
        ("teapot on a floor, sun at 40° (0.53°)", teapot.clone(), sun, above.clone()),
        ("teapot on a floor, sun at 40°, 5° wide", teapot, wide, above),
        ("room.gltf, disk skylight", room, SunOptions::default(), CameraOptions::default()),
    ];
    let mut out = format!(
        "Measured by `sunshade bench --shadows` on {}: {}; Vulkan device {}{}; {} build; {}×{} pixels; median of \
         {} warm runs. Error: the visible-fraction error |L − L_conv| / L_unshadowed over the pixels the converged \
         reference ({CONVERGED}² shadow rays per light) shadows; its own refinement ({REFINED}², about twice the \
         rays) is given per scene.\n\n",
        today(),
        machine(),
        device_description(&info),
        if info.ray_query {
            ""
        } else {
            " (without ray queries: the sun's rays through its cells, the disk light's by the BVH walk)"
        },
        build(),
        width,
        height,
        a.repeat,
    );
    for (title, scene, sun, camera) in cases {
        let lights = LightOptions { sun, ..Default::default() };
        let mut s = settings::resolve_with(&scene, width, height, &camera, &lights)
            .map_err(|e| CliError::Usage(format!("{title}: {e}")))?;
        let with = |s: &RenderSettings, shadows: Shadows, k: u32| {
            let mut s = s.clone();
            s.shading.shadows = shadows;
            s.shading.shadow_samples_per_axis = k;
            s
        };
        s.shading.shadows = Shadows::Ray;
        let unshadowed = cpu::render(&scene, &with(&s, Shadows::None, 1), &reference);
        let converged = cpu::render(&scene, &with(&s, Shadows::Ray, CONVERGED), &reference);
        let refined = cpu::render(&scene, &with(&s, Shadows::Ray, REFINED), &reference);
        let refinement = fraction_error(&refined, &converged, &unshadowed);
        out += &format!(
            "**{title}** ({} triangles; {} shadowed pixels; refinement {CONVERGED}² → {REFINED}² changes the visible \
             fraction by at most {:.1e}, mean {:.1e}):\n\n",
            scene.triangle_count(),
            refinement.shadowed,
            refinement.max,
            refinement.mean
        );
        out += "| technique | grid k² per light (rays at its (k + 1)² corners, more in penumbrae; a map: its filter's taps) | GPU frame [ms] | CPU reference [ms] | max error | mean error | px > 1e-2 | px > 1e-3 | GPU vs CPU rays, px over tolerance |\n";
        out += "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        let gpu_scene = renderer.upload(&scene)?;
        // (technique, samples per axis, map size, filter): none; ray grids of 1² to 16² per light; the sun's map at
        // 512² to 4096² with the default grid for its PCSS filter, and at 2048² with the nearest texel alone.
        let mut rows: Vec<(Shadows, u32, u32, ShadowMapFilter)> = vec![(Shadows::None, 1, 0, ShadowMapFilter::Pcss)];
        rows.extend([1u32, 2, 4, 8, 16].map(|k| (Shadows::Ray, k, 0, ShadowMapFilter::Pcss)));
        rows.extend(
            [512u32, 1024, 2048, 4096]
                .map(|n| (Shadows::Map, DEFAULT_SHADOW_SAMPLES_PER_AXIS, n, ShadowMapFilter::Pcss)),
        );
        rows.push((Shadows::Map, 1, 2048, ShadowMapFilter::Nearest));
        for (technique, k, map_size, filter) in rows {
            let mut sk = with(&s, technique, k);
            if technique == Shadows::Map {
                sk.shading.shadow_map_size = map_size;
                sk.shading.shadow_map_filter = filter;
            }
            // The reference of the row: itself, or for the map the rays with the same samples.
            let t = Instant::now();
            let cpu_image = cpu::render(
                &scene,
                &with(&s, if technique == Shadows::Map { Shadows::Ray } else { technique }, k),
                &reference,
            );
            let cpu_time = t.elapsed();
            let gpu = {
                let (g, times) = warm_frames(&mut renderer, &gpu_scene, &sk, a.repeat)?;
                let (report, _) = compare::diff(&g, &cpu_image, &DiffOptions::default())
                    .map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
                Some((g, median(times), report.over_tolerance.total))
            };
            // The map's error is its own image's; the rays' the reference's (the GPU's agrees with it).
            let err = match (&gpu, technique) {
                (Some((g, _, _)), Shadows::Map) => fraction_error(g, &converged, &unshadowed),
                _ => fraction_error(&cpu_image, &converged, &unshadowed),
            };
            let (gpu_time, agreement) = match &gpu {
                Some((_, t, n)) => (format!("{:.1}", ms(*t)), n.to_string()),
                None => ("–".into(), "–".into()),
            };
            let (label, cpu_time) = match technique {
                Shadows::Map if filter == ShadowMapFilter::Nearest => {
                    (format!("map {map_size}², nearest"), "–".to_string())
                }
                Shadows::Map => (format!("map {map_size}²"), "–".to_string()),
                t => (t.name().to_string(), format!("{:.1}", ms(cpu_time))),
            };
            out += &format!(
                "| {label} | {} | {gpu_time} | {cpu_time} | {:.2e} | {:.2e} | {} | {} | {agreement} |\n",
                if technique == Shadows::None { 0 } else { k * k },
                err.max,
                err.mean,
                err.over_1e2,
                err.over_1e3,
            );
            eprintln!("sunshade bench: {title}: {label} {k} done");
        }
        out += "\n";
    }
    publish(&out, a.json, &a.update, "shadows")
}

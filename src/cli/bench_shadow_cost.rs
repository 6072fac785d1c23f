//! `sunshade bench --shadow-cost`: what the default render's shadows cost on the models of models/ and on the
//! teapot standing on a floor: each GPU frame with the default shadows (`auto`: shadow rays, the sun's through its
//! cells, in two draws) against the same frame unshadowed, in one draw (`ContextOptions::one_draw`) and by shadow
//! maps, the CPU reference's render of the same image, and
//! where each light's rays go (`cpu::sun_costs`, `cpu::disk_costs`): the fraction of the evaluated pixels left to
//! the rays (penumbrae, umbrae, occluders near the rays), and the rays a covered pixel and a pixel left to them
//! cast.

use std::time::Instant;

use super::bench_common::{bench_renderer, measured_by, median, ms, BenchArgs};
use super::generated::publish;
use super::CliError;
use crate::cpu;
use crate::scene::{self, LoadOptions};
use crate::settings::{self, CameraOptions, LightOptions, SunOptions};
use crate::shading::{Shadows, SunModel};

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let (width, height) = (a.width.unwrap_or(512), a.height.unwrap_or(512));
    let (mut renderer, info, reference) = bench_renderer(a, (2 * width, 2 * height))?;
    let mut one_draw = crate::gpu::Renderer::new(&crate::gpu::ContextOptions {
        device: a.device.clone(),
        one_draw: true,
        ..crate::gpu::ContextOptions::from_env()
    })?;
    let mut out = measured_by(
        "sunshade bench --shadow-cost",
        &info,
        (width, height),
        a.repeat,
        "frames are the render phase, the four of a scene timed in turn each round; the CPU reference renders the default image (f64 rays) on every core",
    );
    out += "| scene | covered px | unshadowed frame [ms] | default frame [ms] | default / unshadowed | one draw [ms] | shadow maps frame [ms] | CPU reference [ms] | light | evaluated px | left to rays | cell triangles / px | rays / covered px | rays / px left to rays |\n";
    out += "|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|\n";
    let mut cases = Vec::new();
    for model in ["teapot.glb", "cube.glb", "sunset.glb", "room.gltf"] {
        let path = std::path::Path::new("models").join(model);
        let scene = scene::load_with_options(&path, &LoadOptions::default())?;
        let s = settings::resolve_with(&scene, width, height, &CameraOptions::default(), &LightOptions::default())
            .map_err(|e| CliError::Usage(format!("{model}: {e}")))?;
        cases.push((format!("models/{model}"), scene, s));
    }
    // The teapot standing on a floor, twice the size, under a delta sun (hard shadows).
    let teapot = super::bench_shadows::teapot_on_floor()?;
    let sun = SunOptions { elevation_degrees: Some(40.0), azimuth_degrees: Some(30.0), ..Default::default() };
    let lights = LightOptions { sun, ..Default::default() };
    let mut s = settings::resolve_with(&teapot, 2 * width, 2 * height, &CameraOptions::default(), &lights)
        .map_err(|e| CliError::Usage(format!("teapot on a floor: {e}")))?;
    s.shading.sun = SunModel::Delta;
    cases.push((format!("teapot on a floor, delta sun, {}×{}", 2 * width, 2 * height), teapot, s));
    for (name, scene, s) in cases {
        let uploaded = renderer.upload(&scene)?;
        let uploaded_once = one_draw.upload(&scene)?;
        let with = |shadows: Shadows| {
            let mut s = s.clone();
            s.shading.shadows = shadows;
            s
        };
        // Each frame once to warm up, then the four in turn, --repeat rounds: the machine's drift between rounds
        // touches each alike, so that their ratios hold where the absolute times wander.
        let image = renderer.render(&uploaded, &with(Shadows::None))?.0;
        let mut frames: [Vec<std::time::Duration>; 4] = Default::default();
        for round in 0..=a.repeat {
            let times = [
                renderer.render(&uploaded, &with(Shadows::None))?.1.render,
                renderer.render(&uploaded, &with(Shadows::Auto))?.1.render,
                renderer.render(&uploaded, &with(Shadows::Map))?.1.render,
                one_draw.render(&uploaded_once, &with(Shadows::Auto))?.1.render,
            ];
            if round > 0 {
                frames.iter_mut().zip(times).for_each(|(f, t)| f.push(t));
            }
        }
        let [none, auto, map, once] = frames.map(median);
        let t = Instant::now();
        cpu::render(&scene, &with(Shadows::Auto), &reference);
        let cpu_time = t.elapsed();
        // Each light's costs: (light, covered, evaluated, left to the rays, the cell triangles its points classify
        // (the sun's), rays).
        let mut costs = Vec::new();
        if let Some(c) = cpu::sun_costs::sun_ray_costs(&scene, &with(Shadows::Ray), &reference) {
            costs.push(("sun", c.covered, c.evaluated, c.penumbra, Some(c.tested), c.rays));
        }
        if let Some(c) = cpu::disk_costs::disk_ray_costs(&scene, &with(Shadows::Ray), &reference) {
            costs.push(("disk lights", c.covered, c.evaluated, c.left_to_rays, None, c.rays));
        }
        let frames = format!(
            "{} | {:.1} | {:.1} | {:.2} | {:.1} | {:.1} | {:.1}",
            image.covered_count(),
            ms(none),
            ms(auto),
            auto.as_secs_f64() / none.as_secs_f64(),
            ms(once),
            ms(map),
            ms(cpu_time),
        );
        if costs.is_empty() {
            out += &format!("| {name} | {frames} | – | – | – | – | – | – |\n");
        }
        for (i, (light, covered, evaluated, left, tested, rays)) in costs.into_iter().enumerate() {
            let left_share = 100.0 * left as f64 / evaluated.max(1) as f64;
            let per_left = if left > 0 { format!("{:.1}", rays as f64 / left as f64) } else { "–".into() };
            let tested = tested.map_or("–".into(), |t| format!("{:.1}", t as f64 / evaluated.max(1) as f64));
            out += &format!(
                "| {} | {} | {light} | {evaluated} | {left} ({left_share:.2}%) | {tested} | {:.2} | {per_left} |\n",
                if i == 0 { name.as_str() } else { "" },
                if i == 0 { frames.clone() } else { [""; 7].join(" | ") },
                rays as f64 / covered.max(1) as f64,
            );
        }
        eprintln!("sunshade bench: {name} done");
    }
    publish(&out, a.json, &a.update, "shadow-cost")
}

//! `sunshade bench`: speed against error. For each scene, the GPU frame time and the CPU reference time (both
//! warm, median of `--repeat` runs) beside the GPU-vs-reference comparison; optionally the whole-process time of
//! the `render` command. Writes a Markdown table, and can replace a marked region of a document with it so that
//! published figures always come from this command.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::bench_common::{
    build, default_scenes, device_description, measured_by, median, median_f64, ms, phase_line, render_process,
    warm_frames, BenchArgs,
};
use super::generated::{check_region, machine, publish, today};
use super::CliError;
use crate::authoring::chart;
use crate::compare::{self, DiffOptions};
use crate::cpu::{self, ReferenceOptions};
use crate::gpu::{ContextOptions, Interpolation, Renderer};
use crate::scene::{self, LoadOptions};
use crate::settings::{self, CameraOptions, SunOptions};
use crate::shading::{Shadows, SunModel};
use glam::DVec3;

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let region = if a.brdf_chart {
        "brdf-chart"
    } else if a.shadows {
        "shadows"
    } else if a.textures {
        "textures"
    } else if a.pareto {
        super::bench_pareto::pareto_region(a.visibility_rule)
    } else if a.measured {
        "measured-fit"
    } else if a.startup {
        "startup"
    } else if a.shadow_cost {
        "shadow-cost"
    } else {
        ""
    };
    for doc in &a.update {
        check_region(doc, region)?;
    }
    if a.brdf_chart {
        return brdf_chart(a);
    }
    if a.startup {
        return super::bench_startup::run(a);
    }
    if a.shadow_cost {
        return super::bench_shadow_cost::run(a);
    }
    if a.shadows {
        return super::bench_shadows::run(a);
    }
    if a.textures {
        return super::bench_textures::run(a);
    }
    if a.measured {
        if a.scenes.is_empty() {
            for doc in &a.update {
                check_region(doc, "measured-lookup")?;
            }
        }
        return super::bench_measured::run(a);
    }
    if a.pareto {
        return super::bench_pareto::run(a);
    }
    let (width, height) = (a.width.unwrap_or(1024), a.height.unwrap_or(1024));
    let scenes = if a.scenes.is_empty() { default_scenes()? } else { a.scenes.clone() };
    let modes: Vec<Option<Interpolation>> =
        if a.interpolation.is_empty() { vec![None] } else { a.interpolation.iter().copied().map(Some).collect() };
    let mut rows = Vec::new();
    let mut info = None;
    for mode in modes {
        let options = ContextOptions { device: a.device.clone(), interpolation: mode, ..ContextOptions::from_env() };
        let mut renderer = Renderer::new(&options)?;
        renderer.check_size(width, height)?;
        info = Some(renderer.device_info().clone());
        rows.extend(bench_scenes(&mut renderer, &scenes, a, (width, height))?);
    }
    let info = info.expect("at least one mode");
    let mut out = measured_by(
        "sunshade bench",
        &info,
        (width, height),
        a.repeat,
        &format!("tolerance {:e} relative with a floor of 1% of the peak", a.fail_rel),
    );
    out += "| scene | interpolation | triangles | covered px | coverage mismatches | px over tolerance | max rel (interior) | max rel (all) | RMSE [W/(m²·sr)] | GPU frame [ms] | CPU reference [ms] | CPU / GPU |\n";
    out += "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for r in &rows {
        out += r;
        out += "\n";
    }
    if a.process_runs > 0 {
        out += "\n";
        out += &process_timing(a.process_scene.as_ref().unwrap_or(&scenes[0]), width, height, a.process_runs)?;
    }
    publish(&out, a.json, &a.update, "")
}

/// `--brdf-chart`: per chart material, the largest relative error over the three suns (interior pixels, floor 1%
/// of the peak) and the median GPU frame time, with the accurate and with the textbook shader formulas.
fn brdf_chart(a: &BenchArgs) -> Result<(), CliError> {
    let (width, height) = (a.width.unwrap_or(256), a.height.unwrap_or(256));
    let dir = std::env::temp_dir().join(format!("sunshade-brdf-chart-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| CliError::Usage(format!("{}: {e}", dir.display())))?;
    let result = brdf_chart_in(a, &dir, width, height);
    let _ = std::fs::remove_dir_all(&dir);
    let out = result?;
    publish(&out, a.json, &a.update, "brdf-chart")
}

fn brdf_chart_in(a: &BenchArgs, dir: &Path, width: u32, height: u32) -> Result<String, CliError> {
    let mut renderers = Vec::new();
    for naive_math in [false, true] {
        let options = ContextOptions { device: a.device.clone(), naive_math, ..ContextOptions::from_env() };
        let r = Renderer::new(&options)?;
        r.check_size(width, height)?;
        renderers.push(r);
    }
    let info = renderers[0].device_info().clone();
    let reference = ReferenceOptions { sub_pixel_bits: info.sub_pixel_precision_bits, ..Default::default() };
    let mut out = format!(
        "Measured by `sunshade bench --brdf-chart` on {}: {}; Vulkan device {}, {} interpolation; {} build; \
         {}×{} pixels; delta sun at {:?}° from the view; error relative to max(|GPU|, |CPU|, 1% of the peak), \
         interior pixels; GPU frame: median of {} warm runs over the three suns.\n\n",
        today(),
        machine(),
        device_description(&info),
        renderers[0].interpolation().name(),
        build(),
        width,
        height,
        chart::SUN_FROM_VIEW_DEGREES,
        a.repeat,
    );
    out += "| material | peak [W/(m²·sr)] | max rel, accurate formulas | max rel, textbook formulas | textbook / accurate | GPU frame, accurate [ms] | GPU frame, textbook [ms] |\n";
    out += "|---|---:|---:|---:|---:|---:|---:|\n";
    for material in chart::brdf_chart() {
        let path = dir.join(chart::file_name(&material));
        chart::sphere_scene(&material).write(&path).map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
        let scene = scene::load_with_options(&path, &LoadOptions::default())?;
        let (mut errors, mut times, mut peak) = ([0.0f64; 2], [Vec::new(), Vec::new()], 0.0f64);
        for degrees in chart::SUN_FROM_VIEW_DEGREES {
            let sun =
                SunOptions { direction: Some(DVec3::from_array(chart::sun_direction(degrees))), ..Default::default() };
            let mut s = settings::resolve(&scene, width, height, &CameraOptions::default(), &sun)
                .map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
            s.shading.sun = SunModel::Delta;
            // The BRDF chart measures the lobes, unshadowed (shadows have their own table).
            s.shading.shadows = Shadows::None;
            let cpu_image = cpu::render(&scene, &s, &reference);
            let mut uploaded = Vec::new();
            for (k, renderer) in renderers.iter_mut().enumerate() {
                let gpu_scene = renderer.upload(&scene)?;
                let (gpu_image, _) = renderer.render(&gpu_scene, &s)?;
                let (report, _) = compare::diff(&gpu_image, &cpu_image, &DiffOptions::default())
                    .map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
                errors[k] = errors[k].max(report.max_rel_interior);
                peak = peak.max(report.peak);
                uploaded.push(gpu_scene);
            }
            // Interleaved, so that drift in the machine's speed falls on both alike.
            for _ in 0..a.repeat {
                for (k, renderer) in renderers.iter_mut().enumerate() {
                    times[k].push(renderer.render(&uploaded[k], &s)?.1.render);
                }
            }
        }
        let [t0, t1] = times.map(median);
        out += &format!(
            "| {} | {:.3e} | {:.2e} | {:.2e} | {:.0} | {:.2} | {:.2} |\n",
            material.name,
            peak,
            errors[0],
            errors[1],
            errors[1] / errors[0],
            ms(t0),
            ms(t1)
        );
        eprintln!("sunshade bench: {} done", material.name);
    }
    Ok(out)
}

/// One table row per scene, for this renderer.
fn bench_scenes(
    renderer: &mut Renderer,
    scenes: &[PathBuf],
    a: &BenchArgs,
    (width, height): (u32, u32),
) -> Result<Vec<String>, CliError> {
    let options =
        ReferenceOptions { sub_pixel_bits: renderer.device_info().sub_pixel_precision_bits, ..Default::default() };
    let diff_options = DiffOptions { fail_rel: Some(a.fail_rel), fail_peak: None, ..Default::default() };
    let mut rows = Vec::new();
    for path in scenes {
        let scene = scene::load_with_options(path, &LoadOptions::default())?;
        let mut s = settings::resolve(&scene, width, height, &CameraOptions::default(), &SunOptions::default())
            .map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
        // This table measures the renderers' agreement unshadowed (shadows have their own table).
        s.shading.shadows = Shadows::None;
        let gpu_scene = renderer.upload(&scene)?;
        let (gpu_image, gpu_times) = warm_frames(renderer, &gpu_scene, &s, a.repeat)?;
        let cpu_image = cpu::render(&scene, &s, &options);
        let mut cpu_times = Vec::new();
        for _ in 0..a.repeat {
            let t = Instant::now();
            let _ = cpu::render(&scene, &s, &options);
            cpu_times.push(t.elapsed());
        }
        let (report, _) =
            compare::diff(&gpu_image, &cpu_image, &diff_options).map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let (g, c) = (median(gpu_times), median(cpu_times));
        rows.push(format!(
            "| {name} | {} | {} | {} | {} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2} | {:.2} | {:.1} |",
            renderer.interpolation().name(),
            scene.triangle_count(),
            report.covered_b,
            report.coverage_mismatches.total,
            report.over_tolerance.total,
            report.max_rel_interior,
            report.max_rel,
            report.rmse,
            ms(g),
            ms(c),
            c.as_secs_f64() / g.as_secs_f64()
        ));
        eprintln!("sunshade bench: {name} ({}) done", renderer.interpolation().name());
    }
    Ok(rows)
}

fn process_timing(scene: &Path, width: u32, height: u32, runs: u32) -> Result<String, CliError> {
    let mut wall = Vec::new();
    let mut phases: Vec<Vec<(String, f64)>> = Vec::new();
    for _ in 0..runs {
        let (t, stderr) = render_process(scene, (width, height), false)?;
        wall.push(t);
        phases.push(stderr.lines().filter_map(phase_line).collect());
    }
    let mut s = format!(
        "Whole process, `sunshade render {} -o t.png --width {width} --height {height}`: median **{:.0} ms** of {runs} runs. \
         Phases (median, from `-v`):",
        scene.display(),
        ms(median(wall))
    );
    if let Some(first) = phases.first() {
        for (name, _) in first {
            let v = phases.iter().filter_map(|p| p.iter().find(|(n, _)| n == name).map(|(_, t)| *t)).collect();
            s += &format!(" {name} {:.1} ms;", median_f64(v));
        }
    }
    s.pop();
    s += ".\n";
    Ok(s)
}

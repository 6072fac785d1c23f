//! `sunshade bench --textures`: what textures cost. For each textured scene (by default the textured Khronos
//! samples in `models/gltf-samples/`), the GPU frame time and the CPU reference time with its textures and with
//! the same scene untextured (every material's textures dropped, vertex colours kept), and how far GPU and
//! reference are apart with textures. The difference between the two frame times is the whole cost of filtering
//! in shader code: an upper bound on what a hardware sampler could save.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use super::bench_common::{bench_renderer, measured_by, median, ms, warm_frames, BenchArgs};
use super::generated::publish;
use super::CliError;
use crate::compare::{self, DiffOptions};
use crate::cpu;
use crate::scene::{self, LoadOptions, Scene};
use crate::settings::{self, CameraOptions, SunOptions};
use crate::shading::Shadows;

/// The scene with every texture dropped from its materials (factors, vertex colours, alpha modes kept).
fn untextured(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    for m in &mut s.materials {
        m.base_color_texture = None;
        m.metallic_roughness_texture = None;
        m.normal_texture = None;
        m.emissive_texture = None;
    }
    s.textures.clear();
    s
}

/// The textured samples shipped in models/gltf-samples.
fn default_scenes() -> Result<Vec<PathBuf>, CliError> {
    let dir = std::path::Path::new("models/gltf-samples");
    let read = |d: &std::path::Path| {
        std::fs::read_dir(d).map_err(|e| {
            CliError::Usage(format!("{}: {e} (give scenes explicitly, or run from the repository)", d.display()))
        })
    };
    let mut v = Vec::new();
    for entry in read(dir)? {
        let folder = entry.map_err(|e| CliError::Usage(e.to_string()))?.path();
        for file in read(&folder)? {
            let p = file.map_err(|e| CliError::Usage(e.to_string()))?.path();
            if matches!(p.extension().and_then(|e| e.to_str()), Some("glb" | "gltf")) {
                v.push(p);
            }
        }
    }
    v.sort();
    Ok(v)
}

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let (width, height) = (a.width.unwrap_or(512), a.height.unwrap_or(512));
    let (mut renderer, info, reference) = bench_renderer(a, (width, height))?;
    let scenes = if a.scenes.is_empty() { default_scenes()? } else { a.scenes.clone() };
    let mut out = measured_by(
        "sunshade bench --textures",
        &info,
        (width, height),
        a.repeat,
        "unshadowed; GPU vs reference at the default tolerance of `render --check`",
    );
    out += "| scene | textures | texels (all levels) | GPU frame textured [ms] | untextured [ms] | textured / untextured | CPU reference textured [ms] | untextured [ms] | GPU vs reference: max rel | px over tolerance |\n";
    out += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for path in scenes {
        let scene = scene::load_with_options(&path, &LoadOptions::default())?;
        if scene.textures.is_empty() {
            continue;
        }
        let mut s = settings::resolve(&scene, width, height, &CameraOptions::default(), &SunOptions::default())
            .map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
        s.shading.shadows = Shadows::None;
        let plain = untextured(&scene);
        let mut time = |scene: &Scene| -> Result<(Duration, Duration, crate::Image, crate::Image), CliError> {
            let gpu_scene = renderer.upload(scene)?;
            let (g, gpu) = warm_frames(&mut renderer, &gpu_scene, &s, a.repeat)?;
            let c = cpu::render(scene, &s, &reference);
            let mut cpu_times = Vec::new();
            for _ in 0..a.repeat {
                let t = Instant::now();
                let _ = cpu::render(scene, &s, &reference);
                cpu_times.push(t.elapsed());
            }
            Ok((median(gpu), median(cpu_times), g, c))
        };
        let (g_tex, c_tex, gi, ci) = time(&scene)?;
        let (g_plain, c_plain, _, _) = time(&plain)?;
        let (report, _) =
            compare::diff(&gi, &ci, &DiffOptions::default()).map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
        let texels: usize = scene.textures.iter().flat_map(|t| &t.levels).map(|l| l.len()).sum();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        out += &format!(
            "| {name} | {} | {texels} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2e} | {} |\n",
            scene.textures.len(),
            ms(g_tex),
            ms(g_plain),
            g_tex.as_secs_f64() / g_plain.as_secs_f64(),
            ms(c_tex),
            ms(c_plain),
            report.max_rel,
            report.over_tolerance.total,
        );
        eprintln!("sunshade bench: {name} done");
    }
    publish(&out, a.json, &a.update, "textures")
}

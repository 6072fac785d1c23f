//! `sunshade bench --startup`: what a whole `sunshade render` process costs, and where the time goes. Each scene is
//! rendered by `--repeat` separate processes (as users run it, once per image); the table gives the medians of the
//! process's wall time and of its phases (from `-v`), the process against the phases that make the image (render,
//! readback, encode), the load and upload phases with the process's peak memory (large textured samples included),
//! and the pipelines the driver created: each variant's SPIR-V size and creation time. With
//! `--whole-shaders` the same processes run again handing the driver the whole shaders (`SUNSHADE_WHOLE_SHADERS=1`),
//! to show what specializing them saves. Its --update region is "startup".

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

use super::bench_common::{build, default_scenes, median, median_f64, ms, phase_line, render_process, BenchArgs};
use super::generated::{machine, publish, today};
use super::CliError;

/// One scene's run: the scene, its size, and the flags beyond `--width`/`--height`.
struct Case {
    scene: PathBuf,
    size: (u32, u32),
}

/// A variant's (SPIR-V instructions, inlined), creation times and whole-shader creation times [ms].
type VariantTimes = ((usize, usize), Vec<f64>, Vec<f64>);

/// What one process printed and took.
#[derive(Default)]
struct Run {
    wall: Duration,
    phases: BTreeMap<String, f64>,
    /// (what, (SPIR-V instructions, inlined), creation time [ms]).
    pipelines: Vec<(String, (usize, usize), f64)>,
    device: String,
    /// Peak resident memory [MB] (`-v`'s "peak memory"; 0 where not printed).
    peak_mb: f64,
}

/// Samples in models/gltf-samples with large textures (three and two 2048² images).
const LARGE_TEXTURED_SAMPLES: [&str; 2] = ["AlphaBlendModeTest", "NormalTangentMirrorTest"];

fn cases(a: &BenchArgs) -> Result<Vec<Case>, CliError> {
    let size = (a.width.unwrap_or(512), a.height.unwrap_or(512));
    if !a.scenes.is_empty() {
        return Ok(a.scenes.iter().map(|s| Case { scene: s.clone(), size }).collect());
    }
    let mut v: Vec<Case> = default_scenes()?.into_iter().map(|scene| Case { scene, size }).collect();
    // Two triangles, nothing to shadow: the process with the least to do.
    v.push(Case { scene: Path::new("models").join("square.gltf"), size: (64, 64) });
    // Real assets: several 2048² textures each, whose loading and upload are most of the process.
    for sample in LARGE_TEXTURED_SAMPLES {
        let scene = Path::new("models").join("gltf-samples").join(sample).join(format!("{sample}.glb"));
        if scene.exists() {
            v.push(Case { scene, size: (800, 600) });
        }
    }
    Ok(v)
}

fn run_once(case: &Case, whole: bool) -> Result<Run, CliError> {
    let (wall, stderr) = render_process(&case.scene, case.size, whole)?;
    let mut run = Run { wall, ..Default::default() };
    for line in stderr.lines() {
        if let Some(rest) = line.strip_prefix("sunshade: pipeline ") {
            // "WHAT: N SPIR-V instructions (M inlined), created in X ms"
            let parsed = rest.rsplit_once(": ").and_then(|(what, tail)| {
                let (n, tail) = tail.split_once(" SPIR-V instructions (")?;
                let (inlined, t) = tail.split_once(" inlined), created in ")?;
                let sizes = (n.parse().ok()?, inlined.parse().ok()?);
                Some((what.to_string(), sizes, t.strip_suffix(" ms")?.parse().ok()?))
            });
            run.pipelines.extend(parsed);
        } else if let Some(rest) = line.strip_prefix("sunshade: device ") {
            run.device = rest.split_once(": ").map_or(rest, |(_, d)| d).to_string();
        } else if let Some(mb) = line.trim().strip_prefix("peak memory").and_then(|t| t.strip_suffix(" MB")) {
            run.peak_mb = mb.trim().parse().unwrap_or(0.0);
        } else {
            run.phases.extend(phase_line(line));
        }
    }
    Ok(run)
}

/// The median of a phase over runs (0 where a run did not print it).
fn phase(runs: &[Run], name: &str) -> f64 {
    median_f64(runs.iter().map(|r| r.phases.get(name).copied().unwrap_or(0.0)).collect())
}

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let cases = cases(a)?;
    let mut rows = String::new();
    let mut variants: BTreeMap<String, VariantTimes> = BTreeMap::new();
    let mut device = String::new();
    for case in &cases {
        let mut runs = Vec::new();
        for _ in 0..a.repeat {
            runs.push(run_once(case, false)?);
        }
        let mut whole_runs = Vec::new();
        for _ in 0..if a.whole_shaders { a.repeat } else { 0 } {
            whole_runs.push(run_once(case, true)?);
        }
        device = runs[0].device.clone();
        for r in &runs {
            for (what, n, t) in &r.pipelines {
                let e = variants.entry(what.clone()).or_insert((*n, Vec::new(), Vec::new()));
                e.1.push(*t);
            }
        }
        for r in &whole_runs {
            for (what, _, t) in &r.pipelines {
                variants.entry(what.clone()).or_insert(((0, 0), Vec::new(), Vec::new())).2.push(*t);
            }
        }
        let process = ms(median(runs.iter().map(|r| r.wall).collect()));
        let image = phase(&runs, "render") + phase(&runs, "readback") + phase(&runs, "encode");
        let slowest = runs[0]
            .pipelines
            .iter()
            .map(|(what, _, _)| {
                let t = median_f64(
                    runs.iter().filter_map(|r| r.pipelines.iter().find(|p| &p.0 == what).map(|p| p.2)).collect(),
                );
                (t, what.clone())
            })
            .max_by(|x, y| x.0.total_cmp(&y.0));
        let whole = if a.whole_shaders { format!(" {:.0} |", phase(&whole_runs, "pipelines")) } else { String::new() };
        rows += &format!(
            "| {} | {}×{} | {process:.0} | {:.1} | {:.1} | {:.0} | {:.1} | {:.1} |{whole} {image:.1} | {:.2} | {} |\n",
            case.scene.display(),
            case.size.0,
            case.size.1,
            phase(&runs, "load"),
            phase(&runs, "upload"),
            median_f64(runs.iter().map(|r| r.peak_mb).collect()),
            phase(&runs, "instance"),
            phase(&runs, "pipelines"),
            if image > 0.0 { process / image } else { f64::NAN },
            slowest.map_or("none".into(), |(t, what)| format!("{t:.1} ({what})")),
        );
    }
    let mut out = format!(
        "Measured by `sunshade bench --startup` on {}: {}; Vulkan device {device}; {} build; median of {} processes \
         each.\n\n",
        today(),
        machine(),
        build(),
        a.repeat
    );
    let whole_title = if a.whole_shaders { " pipelines, whole shaders [ms] |" } else { "" };
    let whole_rule = if a.whole_shaders { "---:|" } else { "" };
    out += &format!(
        "| scene | pixels | process [ms] | load [ms] | upload [ms] | peak memory [MB] | instance [ms] | pipelines [ms] \
         |{whole_title} render + readback + encode [ms] | process ÷ image phases | slowest pipeline [ms] \
         |\n|---|---|---:|---:|---:|---:|---:|---:|{whole_rule}---:|---:|---|\n"
    );
    out += &rows;
    out += &format!(
        "\n| pipeline | SPIR-V instructions | inlined | created in [ms] |{}\n|---|---:|---:|---:|{}\n",
        if a.whole_shaders { " whole shader [ms] |" } else { "" },
        if a.whole_shaders { "---:|" } else { "" }
    );
    for (what, ((n, inlined), times, whole)) in variants {
        let w = if a.whole_shaders { format!(" {:.1} |", median_f64(whole)) } else { String::new() };
        out += &format!("| {what} | {n} | {inlined} | {:.1} |{w}\n", median_f64(times));
    }
    publish(&out, a.json, &a.update, "startup")
}

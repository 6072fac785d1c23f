//! `sunshade bench --pareto`: speed against error as a trade-off. For each scene, every quality knob over its
//! range (`sweep`), each setting's GPU frame time (median and spread of `--repeat` warm runs) and its error
//! against the converged reference (`accuracy::converged`; the pixels where the truth itself did not converge are
//! left out and counted), the Pareto fronts of frame time against the max and the 99th-percentile relative
//! error, a Markdown table (or JSON) and optionally a log-log plot of each; and what `--tolerance` chose and cost
//! at 1e-2, 1e-3, 1e-4 (`bench_tolerance`).

use std::path::Path;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::bench_common::{build, default_scenes, device_description, median, ms, warm_frames, BenchArgs};
use super::bench_tolerance::{table_size, tolerance_rows, tolerance_table};
use super::generated::{machine, publish, today};
use super::sweep::{sweep, Relevance};
use super::CliError;
use crate::accuracy::converged::{render_converged, ConvergenceOptions};
use crate::accuracy::error::{image_error, ImageError};
use crate::accuracy::pareto::pareto_front;
use crate::accuracy::predicted;
use crate::cpu::ReferenceOptions;
use crate::gpu::{ContextOptions, GpuScene, Interpolation, Renderer};
use crate::plot::{Canvas, LogLogChart, Point};
use crate::scene::{self, LoadOptions};
use crate::settings::{self, CameraOptions, SunOptions};
use crate::shading::Shadows;

/// The documentation region `bench --pareto --update` writes: `pareto` for the grid's truth, `pareto-slices` for
/// the slices' (a separate table: the two truths leave different pixels out).
pub fn pareto_region(rule: crate::shading::VisibilityRule) -> &'static str {
    match rule {
        crate::shading::VisibilityRule::Grid => "pareto",
        crate::shading::VisibilityRule::Slices => "pareto-slices",
    }
}

/// Max relative errors below this are drawn at it (a log axis has no zero); the table gives them as measured.
const PLOT_ERROR_FLOOR: f64 = 1e-7;

/// One measured setting.
struct Row {
    label: String,
    frame_ms: f64,
    spread_ms: f64,
    error: ImageError,
    /// The predicted bound (`accuracy::predicted`), and whether part of the image has none.
    predicted: (f64, bool),
}

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let (width, height) = (a.width.unwrap_or(256), a.height.unwrap_or(256));
    let scenes = if a.scenes.is_empty() { default_scenes()? } else { a.scenes.clone() };
    // One renderer per interpolation mode the device offers; the first is its default.
    let first = Renderer::new(&ContextOptions { device: a.device.clone(), ..ContextOptions::from_env() })?;
    first.check_size(width, height)?;
    let info = first.device_info().clone();
    let default_mode = first.interpolation();
    let mut renderers = vec![first];
    let mut modes = vec![default_mode];
    for mode in [Interpolation::BarycentricF64, Interpolation::BarycentricF32, Interpolation::Device] {
        if mode == default_mode || (mode == Interpolation::BarycentricF64 && !info.shader_float64) {
            continue;
        }
        let options =
            ContextOptions { device: a.device.clone(), interpolation: Some(mode), ..ContextOptions::from_env() };
        renderers.push(Renderer::new(&options)?);
        modes.push(mode);
    }
    let reference = ReferenceOptions { sub_pixel_bits: info.sub_pixel_precision_bits, ..Default::default() };
    let convergence = ConvergenceOptions { accuracy: a.accuracy, max_refinements: a.max_refinements };
    let ray_queries = info.ray_query;
    let mut out = format!(
        "Measured by `sunshade bench --pareto` on {}: {}; Vulkan device {}{}; {} build; {width}×{height} pixels; \
         GPU frame: median of {} warm runs, spread = slowest − fastest. Error against the converged reference \
         (claimed accuracy {:.0e}, at most {} doublings, visible fractions by {}): per pixel |L − L_conv| / max(|L|, |L_conv|, 1% of the \
         peak), largest over RGB; the pixels where the reference itself did not converge are left out (counted per \
         scene). Predicted: the bound `-v` prints for the setting (`accuracy::predicted`); † where part of the image \
         has no bound (disk lights, the sky, penumbrae, shadow maps, f32 or device interpolation), the number \
         covering the rest. ★: on the Pareto front of frame time against the max (or the p99) relative error.\n\n",
        today(),
        machine(),
        device_description(&info),
        if ray_queries { "" } else { " (without ray queries: shadow rays by the fragment shader's walk)" },
        build(),
        a.repeat,
        a.accuracy,
        a.max_refinements,
        a.visibility_rule.name(),
    );
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {pos} settings measured: {msg}").expect("template"),
    );
    let mut charts = Vec::new();
    let mut costs = Vec::new();
    for path in &scenes {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let scene = scene::load_with_options(path, &LoadOptions::default())?;
        let mut s = settings::resolve(&scene, width, height, &CameraOptions::default(), &SunOptions::default())
            .map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
        let can_occlude = crate::visibility::can_occlude(&scene);
        let relevance = Relevance::of(&scene, &s.lights, can_occlude, ray_queries);

        bar.set_message(format!("{name}: the converged reference"));
        let t = Instant::now();
        let mut truth_settings = s.clone();
        truth_settings.shading.shadows = if can_occlude { Shadows::Ray } else { Shadows::None };
        truth_settings.shading.visibility_rule = a.visibility_rule;
        let truth = render_converged(&scene, &truth_settings, &reference, &convergence);
        let truth_time = t.elapsed();
        let excluded = truth.unconverged_mask();

        let uploaded: Vec<GpuScene> = renderers.iter().map(|r| r.upload(&scene)).collect::<Result<_, _>>()?;
        bar.set_message(format!("{name}: --tolerance"));
        let predicted_default =
            predicted::Renderer::Gpu { barycentrics: crate::render::predicted_barycentrics(default_mode) };
        // Without ray queries a scene that shadows itself gets the table at a smaller size, with its own truth.
        let size = table_size((width, height), ray_queries, can_occlude);
        let smaller = if size != (width, height) {
            bar.set_message(format!("{name}: the converged reference at {}×{} for --tolerance", size.0, size.1));
            let t = Instant::now();
            let mut small =
                settings::resolve(&scene, size.0, size.1, &CameraOptions::default(), &SunOptions::default())
                    .map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
            small.shading.shadows = truth_settings.shading.shadows;
            small.shading.visibility_rule = a.visibility_rule;
            let truth = render_converged(&scene, &small, &reference, &convergence);
            Some((small, truth, t.elapsed().as_secs_f64()))
        } else {
            None
        };
        let (table_settings, table_truth) = match &smaller {
            Some((small, truth, _)) => (small, truth),
            None => (&truth_settings, &truth),
        };
        let tolerance_rows = tolerance_rows(
            &scene,
            table_settings,
            &mut renderers[0],
            &uploaded[0],
            predicted_default,
            &reference,
            table_truth,
            a.repeat,
            a.tolerance_in_penumbrae,
        )?;
        let smaller = smaller.map(|(_, _, seconds)| (size, seconds));
        let mut rows = Vec::new();
        for setting in sweep(&relevance, default_mode, &modes) {
            let label = setting.label(&relevance);
            bar.set_message(format!("{name}: {label}"));
            let k = modes.iter().position(|&m| m == setting.interpolation).expect("a renderer per mode");
            s.shading = setting.shading;
            let (image, times) = match warm_frames(&mut renderers[k], &uploaded[k], &s, a.repeat) {
                Ok(measured) => measured,
                // A setting llvmpipe's loop limiter cuts short (the BVH walk's rays on a large scene) is not a
                // measurement: said, and the sweep goes on.
                Err(crate::gpu::GpuError::LoopBudget(why)) => {
                    bar.suspend(|| eprintln!("sunshade bench: {name}: {label}: not measured: {why}"));
                    continue;
                }
                Err(e) => return Err(e.into()),
            };
            let spread =
                times.iter().max().copied().unwrap_or_default() - times.iter().min().copied().unwrap_or_default();
            let error = image_error(&image, &truth.image, Some(&excluded))
                .map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
            let renderer =
                predicted::Renderer::Gpu { barycentrics: crate::render::predicted_barycentrics(setting.interpolation) };
            // A delta sun's horizon term is taken against its own image's peak.
            let peak = (s.shading.sun == crate::shading::SunModel::Delta).then(|| crate::compare::image_peak(&image));
            let p = predicted::predict_with_peak(&scene, &s, renderer, can_occlude, peak, None);
            let predicted = (p.max_relative, !p.unbounded.is_empty());
            rows.push(Row { label, frame_ms: ms(median(times)), spread_ms: ms(spread), error, predicted });
            bar.inc(1);
        }
        let front = pareto_front(&rows.iter().map(|r| (r.frame_ms, r.error.max_rel)).collect::<Vec<_>>());
        let front_p99 = pareto_front(&rows.iter().map(|r| (r.frame_ms, r.error.p99)).collect::<Vec<_>>());
        out += &format!(
            "**{name}** ({} triangles; truth, visible fractions by {}: {}; {} of {} covered pixels left out as \
             unconverged; the reference took {:.1} s):\n\n",
            scene.triangle_count(),
            truth_settings.shading.visibility_rule.name(),
            truth.summary_counts(),
            truth.unconverged.len(),
            truth.covered,
            truth_time.as_secs_f64(),
        );
        out += "| # | setting | GPU frame [ms] | spread [ms] | max rel | predicted | p99 rel | RMSE [W/(m²·sr)] | px > 1e-2 | px > 1e-3 | px > 1e-4 | front (max) | front (p99) |\n";
        out += "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|:---:|\n";
        for (i, ((r, &f), &f99)) in rows.iter().zip(&front).zip(&front_p99).enumerate() {
            out += &format!(
                "| {} | {} | {:.2} | {:.2} | {:.2e} | {:.1e}{} | {:.2e} | {:.2e} | {} | {} | {} | {} | {} |\n",
                i + 1,
                r.label,
                r.frame_ms,
                r.spread_ms,
                r.error.max_rel,
                r.predicted.0,
                if r.predicted.1 { "†" } else { "" },
                r.error.p99,
                r.error.rmse,
                r.error.over[0],
                r.error.over[1],
                r.error.over[2],
                if f { "★" } else { "" },
                if f99 { "★" } else { "" }
            );
        }
        out += "\n";
        out += &tolerance_table(&name, &tolerance_rows, a.tolerance_in_penumbrae, smaller);
        costs.push((name.clone(), exactness_cost(&rows)));
        for (metric, fronts, value) in [
            ("max relative error", &front, (|e: &ImageError| e.max_rel) as fn(&ImageError) -> f64),
            ("p99 relative error", &front_p99, |e: &ImageError| e.p99),
        ] {
            charts.push(LogLogChart {
                title: format!("{name}, {width}x{height}: {metric} (labels: table rows)"),
                x_title: "GPU frame [ms]".into(),
                y_title: metric.into(),
                points: rows
                    .iter()
                    .zip(fronts)
                    .enumerate()
                    .map(|(i, (r, &f))| Point {
                        x: r.frame_ms,
                        y: value(&r.error).max(PLOT_ERROR_FLOOR),
                        label: (i + 1).to_string(),
                        front: f,
                    })
                    .collect(),
            });
        }
        bar.suspend(|| eprintln!("sunshade bench: {name} done ({} settings)", rows.len()));
    }
    bar.finish_and_clear();
    out += &exactness_table(&costs);
    if let Some(plot) = &a.plot {
        write_plot(plot, &charts)?;
    }
    publish(&out, a.json, &a.update, pareto_region(a.visibility_rule))
}

/// The tolerances of "what exactness costs".
const COST_TOLERANCES: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// For one scene: the default setting's frame time and max error (row 1 of the sweep), and for each of
/// [`COST_TOLERANCES`] the fastest measured setting whose max relative error meets it (its row number and frame
/// time), or `None` where no setting does.
struct ExactnessCost {
    default_ms: f64,
    default_max_rel: f64,
    fastest: [Option<(usize, f64)>; 3],
}

fn exactness_cost(rows: &[Row]) -> ExactnessCost {
    let fastest = COST_TOLERANCES.map(|t| {
        rows.iter()
            .enumerate()
            .filter(|(_, r)| r.error.max_rel <= t)
            .min_by(|a, b| a.1.frame_ms.total_cmp(&b.1.frame_ms))
            .map(|(i, r)| (i + 1, r.frame_ms))
    });
    ExactnessCost { default_ms: rows[0].frame_ms, default_max_rel: rows[0].error.max_rel, fastest }
}

/// "What exactness costs", every scene: the default settings' frame against the fastest setting that still meets
/// each tolerance (measured against the converged reference, from the tables above).
fn exactness_table(costs: &[(String, ExactnessCost)]) -> String {
    let mut out = String::from(
        "**What exactness costs** (from the tables above): the default settings (row 1) against the fastest \
         setting whose max relative error meets each tolerance; `default / fastest` is how much the default's \
         accuracy costs over what that tolerance needs (1.00×: the default is itself the fastest meeting it; \
         below 1: the default does not meet it and the fastest setting that does is slower; — where no \
         setting meets it).\n\n\
         | scene | default [ms] | default max rel | fastest ≤ 1e-2: row, [ms], default / fastest | fastest ≤ 1e-3 | fastest ≤ 1e-4 |\n\
         |---|---:|---:|---|---|---|\n",
    );
    for (name, c) in costs {
        let cells: Vec<String> = c
            .fastest
            .iter()
            .map(|f| match f {
                Some((row, ms)) => format!("#{row}, {ms:.2}, {:.2}×", c.default_ms / ms),
                None => "—".into(),
            })
            .collect();
        out += &format!(
            "| {name} | {:.2} | {:.2e} | {} | {} | {} |\n",
            c.default_ms, c.default_max_rel, cells[0], cells[1], cells[2]
        );
    }
    out + "\n"
}

/// The charts in one PNG, two a row (each scene's max and p99 side by side).
fn write_plot(path: &Path, charts: &[LogLogChart]) -> Result<(), CliError> {
    let (w, h) = (640, 400);
    let mut canvas = Canvas::new(2 * w as u32, (h * charts.len().div_ceil(2).max(1)) as u32);
    for (i, chart) in charts.iter().enumerate() {
        chart.draw(&mut canvas, (((i % 2) * w) as i32, ((i / 2) * h) as i32), (w as i32, h as i32));
    }
    canvas.write_png(path).map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
    eprintln!("sunshade bench: wrote {}", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(frame_ms: f64, max_rel: f64) -> Row {
        let error = ImageError { max_rel, p99: max_rel, rmse: 0.0, over: [0; 3], compared: 1, coverage_mismatches: 0 };
        Row { label: String::new(), frame_ms, spread_ms: 0.0, error, predicted: (0.0, false) }
    }

    #[test]
    fn exactness_cost_takes_the_fastest_setting_meeting_each_tolerance() {
        // Row 1 the default (40 ms, 2e-4); a fast rough one, a middle one, a slow exact one.
        let rows = [row(40.0, 2e-4), row(5.0, 5e-3), row(10.0, 8e-4), row(80.0, 1e-6)];
        let c = exactness_cost(&rows);
        assert_eq!((c.default_ms, c.default_max_rel), (40.0, 2e-4));
        assert_eq!(c.fastest, [Some((2, 5.0)), Some((3, 10.0)), Some((4, 80.0))]);
        let table = exactness_table(&[("x.glb".into(), c)]);
        assert!(
            table.contains("| x.glb | 40.00 | 2.00e-4 | #2, 5.00, 8.00× | #3, 10.00, 4.00× | #4, 80.00, 0.50× |"),
            "{table}"
        );
        // Nothing meets 1e-4: a dash, not a number.
        let c = exactness_cost(&[row(40.0, 2e-3)]);
        assert_eq!(c.fastest, [Some((1, 40.0)), None, None]);
        assert!(exactness_table(&[("y.glb".into(), c)]).contains("| — | — |"));
    }
}

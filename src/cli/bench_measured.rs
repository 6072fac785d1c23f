//! `sunshade bench --measured [FILE.binary ...]`: what a measured BRDF costs and what it buys, on the BRDF chart's
//! sphere (256 × 256 unless --width/--height are given) under the sun (a disk, at 31° from the view) and under the
//! overcast sky, each alone and unshadowed.
//!
//! - **Lookups** (region "measured-lookup"): analytic BRDFs tabulated into the MERL format, rendered from the table
//!   with the linear and the nearest lookup and from the formula: GPU frame time, and each table image's error
//!   against the formula's image (both CPU references with the same sample grids, so the difference is the
//!   table's).
//! - **Fits** (region "measured-fit"): each table (the files given, else a synthetic two-lobe table and the
//!   tabulated Ward) against its best fit of every analytic model (`fit-brdf`): the fit's objective, GPU frame
//!   time, and the image error of the fit against the measured material (CPU references).

use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

use glam::DVec3;

use super::bench_common::{bench_renderer, measured_by, median, ms, warm_frames, BenchArgs};
use super::generated::{print_output, update_region};
use super::CliError;
use crate::authoring::chart::{self, ChartMaterial};
use crate::compare::{self, DiffOptions};
use crate::cpu::{self, ReferenceOptions};
use crate::gpu::Renderer;
use crate::scene::measured::{read_merl_file, MeasuredBrdf};
use crate::scene::{self, Brdf, BrdfKind, LoadOptions, Scene};
use crate::settings::{self, CameraOptions, RenderSettings, SunOptions};
use crate::shading::brdf_fit::fit_brdf;
use crate::shading::measured::{brdf_about_z, tabulate, MeasuredLookup};
use crate::shading::Shadows;
use crate::Image;

/// The sum of analytic BRDFs per channel about +z.
fn analytic_rho(brdfs: &[Brdf], l: DVec3, v: DVec3) -> [f64; 3] {
    brdfs.iter().map(|b| brdf_about_z(b, l, v)).fold([0.0; 3], |a, r| [a[0] + r[0], a[1] + r[1], a[2] + r[2]])
}

fn table_of(name: &str, brdfs: &[Brdf]) -> Result<MeasuredBrdf, CliError> {
    MeasuredBrdf::from_planes(name, &tabulate(|l, v| analytic_rho(brdfs, l, v)))
        .map_err(|e| CliError::Failure(anyhow::anyhow!(e)))
}

/// The analytic BRDFs the lookup table tabulates: a smooth Ward and a sharper Blinn-Phong.
fn lookup_cases() -> Vec<(&'static str, Brdf)> {
    vec![
        ("Ward α=0.2", Brdf::Ward { kd: [0.3, 0.25, 0.2], ks: [0.2; 3], alpha_x: 0.2, alpha_y: 0.2 }),
        ("Blinn-Phong e=2000", Brdf::BlinnPhong { kd: [0.3, 0.25, 0.2], ks: [0.3; 3], exponent: 2000.0 }),
    ]
}

/// A table no analytic model of sunshade represents: a diffuse part, a narrow coloured Ward lobe and a wide
/// Blinn-Phong lobe (a two-layer material's look).
fn two_lobe_table() -> Result<MeasuredBrdf, CliError> {
    let kd = [0.25, 0.18, 0.1];
    table_of(
        "two lobes (synthetic)",
        &[
            Brdf::Ward { kd, ks: [0.12, 0.1, 0.08], alpha_x: 0.06, alpha_y: 0.06 },
            Brdf::BlinnPhong { kd: [0.0; 3], ks: [0.08, 0.08, 0.1], exponent: 8.0 },
        ],
    )
}

/// The chart sphere with one material, its BRDF set directly.
fn with_brdf(sphere: &Scene, brdf: Brdf) -> Scene {
    let mut s = sphere.clone();
    for m in &mut s.materials {
        m.brdf = brdf.clone();
        m.mapping = None;
    }
    s
}

/// The two light cases: (name, settings).
fn light_cases(sphere: &Scene, size: (u32, u32)) -> Result<Vec<(&'static str, RenderSettings)>, CliError> {
    let mut out = Vec::new();
    for (name, sky) in [("sun", false), ("sky", true)] {
        let sun = SunOptions { direction: Some(DVec3::from_array(chart::sun_direction(31.0))), ..Default::default() };
        let mut s = settings::resolve(sphere, size.0, size.1, &CameraOptions::default(), &sun)
            .map_err(|e| CliError::Usage(e.to_string()))?;
        if sky {
            s.lights.sun = None;
            s.lights.sky = Some([100.0; 3]);
        }
        s.shading.shadows = Shadows::None;
        out.push((name, s));
    }
    Ok(out)
}

/// The GPU's median frame time, after a warm-up frame.
fn gpu_frame(renderer: &mut Renderer, scene: &Scene, s: &RenderSettings, repeat: u32) -> Result<Duration, CliError> {
    let uploaded = renderer.upload(scene)?;
    Ok(median(warm_frames(renderer, &uploaded, s, repeat)?.1))
}

/// `max rel` (with the diff's floor), relative RMSE (RMSE over the peak) and pixels over 1e-3 of `a` against
/// `truth`.
fn error(a: &Image, truth: &Image) -> Result<(f64, f64, usize), CliError> {
    let options = DiffOptions { fail_rel: Some(1e-3), ..Default::default() };
    let (r, _) = compare::diff(a, truth, &options).map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
    Ok((r.max_rel, r.rmse / r.peak.max(f64::MIN_POSITIVE), r.over_tolerance.total))
}

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let size = (a.width.unwrap_or(256), a.height.unwrap_or(256));
    let (mut renderer, info, reference) = bench_renderer(a, size)?;
    let dir = std::env::temp_dir().join(format!("sunshade-bench-measured-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| CliError::Usage(format!("{}: {e}", dir.display())))?;
    let result = tables(a, &dir, size, &mut renderer, &info, &reference);
    let _ = std::fs::remove_dir_all(&dir);
    let (lookups, fits) = result?;
    print_output(&format!("{lookups}\n{fits}"), a.json);
    for doc in &a.update {
        if a.scenes.is_empty() {
            update_region(doc, "measured-lookup", &lookups)?;
        }
        update_region(doc, "measured-fit", &fits)?;
        eprintln!("sunshade bench: updated {}", doc.display());
    }
    Ok(())
}

fn tables(
    a: &BenchArgs,
    dir: &Path,
    size: (u32, u32),
    renderer: &mut Renderer,
    info: &crate::gpu::DeviceInfo,
    reference: &ReferenceOptions,
) -> Result<(String, String), CliError> {
    let material = ChartMaterial { name: "measured".into(), extras: serde_json::json!({ "brdf": "lambert" }) };
    let path = dir.join("sphere.glb");
    chart::sphere_scene(&material).write(&path).map_err(|e| CliError::Usage(format!("{}: {e}", path.display())))?;
    let sphere = scene::load_with_options(&path, &LoadOptions::default())?;
    let lights = light_cases(&sphere, size)?;

    let mut lookups = measured_by(
        "sunshade bench --measured",
        info,
        size,
        a.repeat,
        "the chart's sphere under the sun (disk, 31° from the view) or the overcast sky, unshadowed; error of the \
         table's image against the formula's, both CPU references (max rel with the diff's floor of 1% of the peak; \
         RMSE over the peak)",
    );
    lookups += "| tabulated BRDF | light | lookup | GPU frame [ms] | max rel | RMSE / peak | px over 1e-3 |\n";
    lookups += "|---|---|---|---:|---:|---:|---:|\n";
    let mut tabulated = Vec::new();
    if a.scenes.is_empty() {
        for (name, brdf) in lookup_cases() {
            let table = Arc::new(table_of(&format!("{name} (tabulated)"), std::slice::from_ref(&brdf))?);
            for (light, s) in &lights {
                let formula = with_brdf(&sphere, brdf.clone());
                let truth = cpu::render(&formula, s, reference);
                let t = gpu_frame(renderer, &formula, s, a.repeat)?;
                lookups += &format!("| {name} | {light} | formula | {:.2} | | | |\n", ms(t));
                for lookup in [MeasuredLookup::Linear, MeasuredLookup::Nearest] {
                    let measured = with_brdf(&sphere, Brdf::Measured { table: table.clone(), lookup });
                    let t = gpu_frame(renderer, &measured, s, a.repeat)?;
                    let (max, rmse, over) = error(&cpu::render(&measured, s, reference), &truth)?;
                    let which = if lookup == MeasuredLookup::Linear { "linear" } else { "nearest" };
                    lookups +=
                        &format!("| {name} | {light} | {which} | {:.2} | {max:.2e} | {rmse:.2e} | {over} |\n", ms(t));
                }
            }
            eprintln!("sunshade bench: {name} tabulated");
            if name.starts_with("Ward") {
                tabulated.push(table);
            }
        }
    }

    let mut fits = measured_by(
        "sunshade bench --measured",
        info,
        size,
        a.repeat,
        "each table's best fit of every model (`sunshade fit-brdf`; objective: cosine-weighted relative RMS over \
         the measured direction pairs) against the table (linear lookup) on the chart's sphere under the sun or the \
         sky; image error of the fit against the table's image, both CPU references",
    );
    fits += "| table | model | fit objective (r) | light | GPU frame [ms] | max rel | RMSE / peak | px over 1e-3 |\n";
    fits += "|---|---|---:|---|---:|---:|---:|---:|\n";
    let mut tables: Vec<Arc<MeasuredBrdf>> = Vec::new();
    if a.scenes.is_empty() {
        tables.push(Arc::new(two_lobe_table()?));
        tables.extend(tabulated);
    } else {
        for file in &a.scenes {
            tables.push(Arc::new(read_merl_file(file).map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?));
        }
    }
    for table in tables {
        let measured = with_brdf(&sphere, Brdf::Measured { table: table.clone(), lookup: MeasuredLookup::Linear });
        let truths: Vec<Image> = lights.iter().map(|(_, s)| cpu::render(&measured, s, reference)).collect();
        for ((light, s), _) in lights.iter().zip(&truths) {
            let t = gpu_frame(renderer, &measured, s, a.repeat)?;
            fits += &format!("| {} | measured | | {light} | {:.2} | | | |\n", table.name, ms(t));
        }
        for kind in [BrdfKind::Lambert, BrdfKind::Phong, BrdfKind::BlinnPhong, BrdfKind::Ward] {
            let fit = fit_brdf(&table, kind);
            let fitted = with_brdf(&sphere, fit.brdf.clone());
            for ((light, s), truth) in lights.iter().zip(&truths) {
                let t = gpu_frame(renderer, &fitted, s, a.repeat)?;
                let (max, rmse, over) = error(&cpu::render(&fitted, s, reference), truth)?;
                fits += &format!(
                    "| {} | {} | {:.3e} | {light} | {:.2} | {max:.2e} | {rmse:.2e} | {over} |\n",
                    table.name,
                    super::fit_brdf::extras_snippet(&fit.brdf)["sunshade"],
                    fit.relative_rms[0],
                    ms(t)
                );
            }
        }
        eprintln!("sunshade bench: {} fitted", table.name);
    }
    Ok((lookups, fits))
}

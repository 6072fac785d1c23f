//! `sunshade fit-brdf FILE --model M [--json]`: an analytic BRDF fitted to a measured (MERL) table, its error,
//! and a material `extras` snippet to paste (`shading::brdf_fit` has the objective and the method).

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde_json::{json, Value};

use super::CliError;
use crate::scene::measured::read_merl_file;
use crate::scene::{Brdf, BrdfKind};
use crate::shading::brdf_fit::fit_brdf;

#[derive(Args, Debug)]
pub struct FitBrdfArgs {
    /// A MERL BRDF file (`.binary`: 90 × 90 × 180 samples per channel).
    pub file: PathBuf,
    /// The model to fit.
    #[arg(long, value_name = "lambert|phong|blinn-phong|ward|gltf")]
    pub model: BrdfKind,
    /// Print the result as JSON (parameters, errors, the extras snippet).
    #[arg(long)]
    pub json: bool,
}

/// The material `extras` of a fitted BRDF (rounded to 6 significant digits, what f32 keeps).
pub fn extras_snippet(brdf: &Brdf) -> Value {
    let r = |v: f32| (v as f64 * 1e6).round() / 1e6;
    let rgb = |c: [f32; 3]| json!([r(c[0]), r(c[1]), r(c[2])]);
    let sig = |v: f32| format!("{v:.6e}").parse::<f64>().unwrap_or(v as f64);
    let inner = match *brdf {
        Brdf::Lambert { albedo } => json!({ "brdf": "lambert", "albedo": rgb(albedo) }),
        Brdf::Phong { kd, ks, exponent } => {
            json!({ "brdf": "phong", "kd": rgb(kd), "ks": rgb(ks), "exponent": sig(exponent) })
        }
        Brdf::BlinnPhong { kd, ks, exponent } => {
            json!({ "brdf": "blinn-phong", "kd": rgb(kd), "ks": rgb(ks), "exponent": sig(exponent) })
        }
        Brdf::Ward { kd, ks, alpha_x, .. } => {
            json!({ "brdf": "ward", "kd": rgb(kd), "ks": rgb(ks), "alpha": sig(alpha_x) })
        }
        Brdf::Gltf { base_color, metallic, alpha, .. } => json!({
            "brdf": "gltf", "base_color": rgb(base_color), "metallic": r(metallic), "roughness": sig(alpha.sqrt())
        }),
        Brdf::Measured { .. } => unreachable!("fits are analytic"),
    };
    json!({ "sunshade": inner })
}

pub fn run(a: &FitBrdfArgs) -> Result<(), CliError> {
    let t = Instant::now();
    let table = read_merl_file(&a.file).map_err(|e| CliError::Failure(anyhow::anyhow!(e)))?;
    let read = t.elapsed();
    let fit = fit_brdf(&table, a.model);
    let seconds = t.elapsed().as_secs_f64();
    let snippet = extras_snippet(&fit.brdf);
    let valid = fit.brdf.validate();
    if a.json {
        let out = json!({
            "file": a.file.display().to_string(),
            "model": snippet["sunshade"]["brdf"],
            "parameters": snippet["sunshade"],
            "relative_rms": fit.relative_rms,
            "objective": "cosine-weighted relative RMS over the measured direction pairs (docs/measured.md)",
            "samples": fit.samples,
            "missing_values": table.missing,
            "seconds": seconds,
            "extras": snippet,
            "energy_conserving": valid.is_ok(),
        });
        println!("{}", serde_json::to_string_pretty(&out).expect("JSON"));
    } else {
        println!(
            "{}: {} samples fitted ({} values missing), read in {:.2} s, fitted in {:.2} s",
            a.file.display(),
            fit.samples,
            table.missing,
            read.as_secs_f64(),
            seconds - read.as_secs_f64()
        );
        println!("{}: {}", snippet["sunshade"]["brdf"].as_str().unwrap_or("?"), parameters_line(&snippet["sunshade"]));
        let e = fit.relative_rms;
        println!("fit error (cosine-weighted relative RMS): r {:.3e}, g {:.3e}, b {:.3e}", e[0], e[1], e[2]);
        println!("extras: {snippet}");
    }
    if let Err(e) = valid {
        super::warn(&format!(
            "the fitted parameters are not energy-conserving ({e}); sunshade refuses them as they are"
        ));
    }
    Ok(())
}

fn parameters_line(p: &Value) -> String {
    p.as_object()
        .map(|o| o.iter().filter(|(k, _)| *k != "brdf").map(|(k, v)| format!("{k} {v}")).collect::<Vec<_>>().join(", "))
        .unwrap_or_default()
}

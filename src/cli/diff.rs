//! `sunshade diff A B`: how far apart two images are. Exit 0 within tolerance, 1 outside, 2 on unusable input.

use std::path::PathBuf;

use clap::Args;

use super::args::parse_finite;
use super::CliError;
use crate::compare::{self, DiffOptions, DiffReport, PixelDiff};
use crate::film::{read_image, Image};

/// Tolerances and floor of a comparison (shared with `render --check`).
#[derive(Args, Clone, Debug)]
pub struct ToleranceArgs {
    /// Relative tolerance per pixel: |a−b| / max(|a|, |b|, floor), largest over RGB (default 1e-5 when neither
    /// --fail-rel nor --fail-abs is given).
    #[arg(long, value_parser = parse_finite)]
    pub fail_rel: Option<f64>,
    /// Absolute tolerance per pixel [W/(m²·sr)]. With --fail-rel, a pixel fails only when over both.
    #[arg(long, value_parser = parse_finite)]
    pub fail_abs: Option<f64>,
    /// Pixels allowed over tolerance.
    #[arg(long, default_value_t = 0)]
    pub fail_count: usize,
    /// Pixels allowed to differ in coverage (alpha).
    #[arg(long, default_value_t = 0)]
    pub fail_coverage: usize,
    /// Absolute floor of the relative error's denominator [W/(m²·sr)].
    #[arg(long, default_value_t = 0.0, value_parser = parse_finite)]
    pub floor: f64,
    /// Floor as a fraction of the larger image peak (the effective floor is the larger of the two). The default
    /// 1e-2: f32 rendering carries an absolute error of a few 1e-8 of the peak, so below 1% of the peak a relative
    /// tolerance of 1e-5 would measure rounding, not rendering (docs/accuracy.md).
    #[arg(long, default_value_t = 1e-2, value_parser = parse_finite)]
    pub floor_fraction: f64,
}

impl ToleranceArgs {
    pub fn options(&self) -> DiffOptions {
        let fail_rel = match (self.fail_rel, self.fail_abs) {
            (None, None) => Some(1e-5),
            (r, _) => r,
        };
        DiffOptions {
            floor: self.floor,
            floor_fraction: self.floor_fraction,
            fail_rel,
            fail_abs: self.fail_abs,
            fail_count: self.fail_count,
            fail_coverage: self.fail_coverage,
        }
    }
}

#[derive(Args, Debug)]
pub struct DiffCommand {
    /// First image (.exr, .pfm or .png).
    pub a: PathBuf,
    /// Second image, the same size.
    pub b: PathBuf,
    #[command(flatten)]
    pub tolerances: ToleranceArgs,
    /// Write a false-colour PNG of log10 relative error (coverage mismatches in magenta), with a legend.
    #[arg(long, value_name = "PNG")]
    pub heatmap: Option<PathBuf>,
    /// Print the metrics as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Compares, writes the heatmap if asked, prints the report; `Ok(pass)`.
pub fn compare_and_report(
    a: &Image,
    b: &Image,
    names: (&str, &str),
    options: &DiffOptions,
    heatmap: Option<&std::path::Path>,
    json: bool,
) -> Result<DiffReport, CliError> {
    let (report, per_pixel): (DiffReport, Vec<PixelDiff>) =
        compare::diff(a, b, options).map_err(|e| CliError::Usage(format!("{} vs {}: {e}", names.0, names.1)))?;
    if let Some(path) = heatmap {
        compare::write_heatmap(path, a.width(), a.height(), &per_pixel)
            .map_err(|e| CliError::Failure(anyhow::anyhow!("{}: {e}", path.display())))?;
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&report.json(names.0, names.1)).expect("serialisable"));
    } else {
        print!("{}", report.text(names.0, names.1));
    }
    Ok(report)
}

pub fn run(a: &DiffCommand) -> Result<(), CliError> {
    let read = |p: &PathBuf| read_image(p).map_err(|e| CliError::Usage(e.to_string()));
    let (ia, ib) = (read(&a.a)?, read(&a.b)?);
    let names = (a.a.display().to_string(), a.b.display().to_string());
    let report =
        compare_and_report(&ia, &ib, (&names.0, &names.1), &a.tolerances.options(), a.heatmap.as_deref(), a.json)?;
    if report.pass {
        Ok(())
    } else {
        Err(CliError::Quiet(1))
    }
}

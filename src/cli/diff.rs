//! `sunshade diff A B`: how far apart two images are. Exit 0 within tolerance, 1 outside, 2 on unusable input.

use std::path::PathBuf;

use clap::Args;

use super::args::parse_non_negative;
use super::CliError;
use crate::compare::flip::{FlipInput, FlipStats};
use crate::compare::{self, DiffOptions, DiffReport, PixelDiff};
use crate::film::{read_image, Image, ImageFormat};

/// Tolerances and floor of a comparison (shared with `render --check`). Every field is optional so that a command
/// can tell which were given (`render` refuses them without `--check`).
#[derive(Args, Clone, Debug, Default)]
pub struct ToleranceArgs {
    /// Relative tolerance per pixel: |a−b| / max(|a|, |b|, floor), largest over RGB. Default, when none of
    /// --fail-rel, --fail-abs, --fail-peak is given: 1e-5 relative or 4.8e-7 of the peak absolute (the f32
    /// rounding of n·l, docs/accuracy.md), whichever is larger.
    #[arg(long, value_parser = parse_non_negative, value_name = "REL")]
    pub fail_rel: Option<f64>,
    /// Absolute tolerance per pixel [W/(m²·sr)]. With other tolerances, a pixel fails only when over all of them.
    #[arg(long, value_parser = parse_non_negative, value_name = "ABS")]
    pub fail_abs: Option<f64>,
    /// Absolute tolerance per pixel as a fraction of the larger image peak.
    #[arg(long, value_parser = parse_non_negative, value_name = "FRACTION")]
    pub fail_peak: Option<f64>,
    /// Pixels allowed over tolerance [default: 0].
    #[arg(long, value_name = "N")]
    pub fail_count: Option<usize>,
    /// Pixels allowed over tolerance as a percentage of the compared pixels (the larger of this and
    /// --fail-count wins).
    #[arg(long, value_parser = parse_non_negative, value_name = "PERCENT")]
    pub fail_percent: Option<f64>,
    /// Fail when any one pixel's relative error exceeds this, whatever --fail-count and --fail-percent allow.
    #[arg(long, value_parser = parse_non_negative, value_name = "REL")]
    pub hard_fail: Option<f64>,
    /// Warn level: count the pixels over this relative error (and --warn-abs, if given); a comparison that passes
    /// with such pixels reports WARN (exit 0).
    #[arg(long, value_parser = parse_non_negative, value_name = "REL")]
    pub warn_rel: Option<f64>,
    /// Warn level, absolute [W/(m²·sr)].
    #[arg(long, value_parser = parse_non_negative, value_name = "ABS")]
    pub warn_abs: Option<f64>,
    /// Pixels allowed to differ in coverage (alpha) [default: 0].
    #[arg(long, value_name = "N")]
    pub fail_coverage: Option<usize>,
    /// Fail when the mean FLIP (NVIDIA's perceptual difference, in [0, 1]; HDR-FLIP for radiance, LDR-FLIP for
    /// PNGs) exceeds this.
    #[arg(long, value_parser = parse_non_negative, value_name = "MEAN")]
    pub fail_flip: Option<f64>,
    /// Absolute floor of the relative error's denominator [W/(m²·sr)] [default: 0].
    #[arg(long, value_parser = parse_non_negative, value_name = "W/(M2·SR)")]
    pub floor: Option<f64>,
    /// Floor as a fraction of the larger image peak (the effective floor is the larger of the two) [default: 1e-2]:
    /// below 1% of the peak a relative tolerance of 1e-5 would measure f32 rounding, not rendering.
    #[arg(long, value_parser = parse_non_negative, value_name = "FRACTION")]
    pub floor_fraction: Option<f64>,
}

impl ToleranceArgs {
    pub fn options(&self) -> DiffOptions {
        let defaults = DiffOptions::default();
        let none_given = self.fail_rel.is_none() && self.fail_abs.is_none() && self.fail_peak.is_none();
        let (fail_rel, fail_peak) =
            if none_given { (defaults.fail_rel, defaults.fail_peak) } else { (self.fail_rel, self.fail_peak) };
        DiffOptions {
            floor: self.floor.unwrap_or(defaults.floor),
            floor_fraction: self.floor_fraction.unwrap_or(defaults.floor_fraction),
            fail_rel,
            fail_abs: self.fail_abs,
            fail_peak,
            fail_count: self.fail_count.unwrap_or(defaults.fail_count),
            fail_percent: self.fail_percent,
            fail_coverage: self.fail_coverage.unwrap_or(defaults.fail_coverage),
            hard_fail: self.hard_fail,
            warn_rel: self.warn_rel,
            warn_abs: self.warn_abs,
            fail_flip: self.fail_flip,
        }
    }

    /// The long names of the flags given, for refusing them where they mean nothing.
    pub fn given(&self) -> Vec<&'static str> {
        [
            ("--fail-rel", self.fail_rel.is_some()),
            ("--fail-abs", self.fail_abs.is_some()),
            ("--fail-peak", self.fail_peak.is_some()),
            ("--fail-count", self.fail_count.is_some()),
            ("--fail-percent", self.fail_percent.is_some()),
            ("--hard-fail", self.hard_fail.is_some()),
            ("--warn-rel", self.warn_rel.is_some()),
            ("--warn-abs", self.warn_abs.is_some()),
            ("--fail-coverage", self.fail_coverage.is_some()),
            ("--fail-flip", self.fail_flip.is_some()),
            ("--floor", self.floor.is_some()),
            ("--floor-fraction", self.floor_fraction.is_some()),
        ]
        .into_iter()
        .filter_map(|(name, given)| given.then_some(name))
        .collect()
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
    /// Write a false-colour PNG of log10 relative error (viridis; coverage mismatches white), with a legend.
    #[arg(long, value_name = "PNG")]
    pub heatmap: Option<PathBuf>,
    /// Write FLIP's error map: each pixel's FLIP on the magma scale (black 0 to pale yellow 1), the images' size.
    #[arg(long, value_name = "PNG")]
    pub flip_map: Option<PathBuf>,
    /// Do not compute FLIP (about a third of a second per megapixel and exposure on two cores).
    #[arg(long, conflicts_with_all = ["flip_map", "fail_flip"])]
    pub no_flip: bool,
    /// Write the difference image: |A − B| per channel, alpha included (so coverage mismatches show as alpha 1),
    /// the same size, as .exr or .pfm.
    #[arg(short, long, value_name = "EXR|PFM")]
    pub output: Option<PathBuf>,
    /// Print the metrics as JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Print nothing: the exit code says whether the images agree (errors still print).
    #[arg(short, long, conflicts_with = "json")]
    pub quiet: bool,
}

/// Compares, writes the heatmap if asked, prints the report; `Ok(pass)`.
/// How a comparison is reported: text, or JSON with these extra members (`render --check --json` adds the
/// render's predicted error).
pub enum ReportFormat {
    /// Text, absolute errors in this unit.
    Text(String),
    Json(serde_json::Map<String, serde_json::Value>),
}

impl ReportFormat {
    /// Text or (`json`) JSON with `extra` members, absolute errors in `unit` (JSON member `unit`).
    pub fn new(json: bool, unit: &str, extra: Vec<(String, serde_json::Value)>) -> Self {
        if json {
            let mut map: serde_json::Map<String, serde_json::Value> = extra.into_iter().collect();
            map.insert("unit".into(), serde_json::json!(unit));
            ReportFormat::Json(map)
        } else {
            ReportFormat::Text(unit.to_string())
        }
    }
}

#[allow(clippy::too_many_arguments)]
pub fn compare_and_report(
    a: &Image,
    b: &Image,
    names: (&str, &str),
    options: &DiffOptions,
    flip: Option<(FlipStats, Option<f64>)>,
    heatmap: Option<&std::path::Path>,
    format: ReportFormat,
    excused: Option<(&[bool], &str, Option<f64>)>,
) -> Result<DiffReport, CliError> {
    let (mut report, per_pixel): (DiffReport, Vec<PixelDiff>) = compare::diff_apart(a, b, options, excused)
        .map_err(|e| CliError::Usage(format!("{} vs {}: {e}", names.0, names.1)))?;
    if let Some((stats, fail_flip)) = flip {
        report.add_flip(stats, fail_flip);
    }
    if let Some(path) = heatmap {
        compare::write_heatmap(path, a.width(), a.height(), &per_pixel)
            .map_err(|e| CliError::Failure(anyhow::anyhow!("{}: {e}", path.display())))?;
    }
    match format {
        // -q: the exit code says it.
        _ if super::quiet() => {}
        ReportFormat::Json(extra) => {
            let mut json = report.json(names.0, names.1);
            if let Some(object) = json.as_object_mut() {
                object.extend(extra);
            }
            println!("{}", serde_json::to_string_pretty(&json).expect("serialisable"));
        }
        ReportFormat::Text(unit) => print!("{}", report.text_in(names.0, names.1, &unit)),
    }
    Ok(report)
}

pub fn run(a: &DiffCommand) -> Result<(), CliError> {
    super::set_quiet(a.quiet);
    let format = |p: &PathBuf| {
        ImageFormat::from_path(p).ok_or_else(|| {
            CliError::Usage(format!("{}: unsupported image extension (use .exr, .pfm or .png)", p.display()))
        })
    };
    let (fa, fb) = (format(&a.a)?, format(&a.b)?);
    if (fa == ImageFormat::Png) != (fb == ImageFormat::Png) {
        return Err(CliError::Usage(format!(
            "{} and {}: a PNG holds 8-bit display codes, an EXR or PFM radiance; compare two of a kind",
            a.a.display(),
            a.b.display()
        )));
    }
    if let Some(h) = &a.heatmap {
        super::check_heatmap_path(h)?;
    }
    if let Some(m) = &a.flip_map {
        super::check_png_path(m, "FLIP's error map")?;
    }
    if let Some(o) = &a.output {
        super::check_output_path(o)?;
        if ImageFormat::from_path(o) == Some(ImageFormat::Png) {
            return Err(CliError::Usage(format!("{}: the difference image is float (use .exr or .pfm)", o.display())));
        }
    }
    // The quantities the files record: two different ones are not compared; the report's unit is theirs.
    let (qa, qb) = (crate::film::read_quantity(&a.a), crate::film::read_quantity(&a.b));
    if let (Some((na, _)), Some((nb, _))) = (&qa, &qb) {
        if na != nb {
            return Err(CliError::Usage(format!(
                "{} holds {na} and {} holds {nb}: compare images of one quantity",
                a.a.display(),
                a.b.display()
            )));
        }
    }
    let unit = match qa.or(qb) {
        _ if fa == ImageFormat::Png => "(8-bit sRGB codes)".to_string(),
        Some((_, unit)) => crate::render::flags::quantity::pretty_unit(&unit),
        None => "W/(m²·sr)".to_string(), // a PFM records nothing: radiance, sunshade's default quantity
    };
    let read = |p: &PathBuf| read_image(p).map_err(|e| CliError::Usage(e.to_string()));
    let (mut ia, mut ib) = (read(&a.a)?, read(&a.b)?);
    if fa == ImageFormat::Pfm || fb == ImageFormat::Pfm {
        // A PFM has no alpha: comparing its all-covered pixels with the other image's coverage would report every
        // background pixel as a coverage mismatch. Compare every pixel instead, and say so.
        for img in [&mut ia, &mut ib] {
            img.pixels_mut().iter_mut().for_each(|p| p[3] = 1.0);
        }
        if !super::quiet() {
            eprintln!("sunshade diff: note: a PFM has no alpha; every pixel is compared, without coverage");
        }
    }
    if let Some(o) = &a.output {
        let d = compare::difference_image(&ia, &ib)
            .map_err(|e| CliError::Usage(format!("{} vs {}: {e}", a.a.display(), a.b.display())))?;
        crate::film::write_image(&d, o, crate::film::Exposure::Ev(0.0))?;
    }
    let names = (a.a.display().to_string(), a.b.display().to_string());
    let format = ReportFormat::new(a.json, &unit, Vec::new());
    // FLIP once, for the report and the map: display values for PNGs, radiance otherwise; B is its reference, as
    // in the comparisons of `render --check`, suites and the testing API (the expected image second).
    let input = if fa == ImageFormat::Png { FlipInput::Ldr } else { FlipInput::Hdr };
    let flip = if a.no_flip {
        None
    } else {
        let map = compare::flip::flip(&ib, &ia, input, compare::flip::DEFAULT_PPD)
            .map_err(|e| CliError::Usage(format!("{} vs {}: {e}", names.0, names.1)))?;
        if let Some(path) = &a.flip_map {
            compare::flip::write_flip_map(path, &map)
                .map_err(|e| CliError::Failure(anyhow::anyhow!("{}: {e}", path.display())))?;
        }
        Some((map.stats(), a.tolerances.fail_flip))
    };
    let options = DiffOptions { fail_flip: None, ..a.tolerances.options() };
    let report =
        compare_and_report(&ia, &ib, (&names.0, &names.1), &options, flip, a.heatmap.as_deref(), format, None)?;
    if report.pass {
        Ok(())
    } else {
        Err(CliError::Quiet(1))
    }
}

//! Image comparison metrics, in the spirit of OpenImageIO's `idiff`.
//!
//! Over pixels covered in both images (alpha > 0), per RGB channel:
//! - absolute error `|a − b|` [W/(m²·sr)];
//! - relative error `|a − b| / max(|a|, |b|, floor)`: the floor keeps values near zero (a surface turning away
//!   from the light) from dominating; it is `max(--floor, --floor-fraction × peak)`, `peak` the largest channel
//!   value of either image;
//! - RMSE over all compared channels, and PSNR `20 log10(peak / RMSE)`.
//!
//! Coverage mismatches (alpha differs) are counted apart. A mismatching pixel is an *edge* pixel when its 3×3
//! neighbourhood holds a coverage boundary in either image, else *interior*.
//!
//! A pixel is over tolerance when it exceeds every tolerance given (`--fail-rel`, `--fail-abs`, `--fail-peak`):
//! each grants leeway, as `numpy.isclose` does.
//!
//! The default tolerance (neither of those flags given) is relative 1e-5, or an absolute error of
//! [`F32_SHADING_PEAK_FRACTION`] of the peak, whichever is larger: a renderer that shades in f32 cannot do better
//! than that absolute error, however exact its formulas, because `n·l` is formed in f32 (see the constant). The comparison fails when more than `--fail-count` pixels are over tolerance
//! or more than `--fail-coverage` pixels differ in coverage.

use serde_json::json;

use super::flip::{FlipInput, FlipStats};
use crate::film::Image;

/// The absolute error a renderer shading in f32 can carry, as a fraction of the peak radiance: 8u, u = 2⁻²⁴
/// (f32's unit roundoff), about 4.8e-7.
///
/// Derivation. Both renderers take the same f32 vertex normals; the GPU interpolates and normalizes the normal
/// and forms `n·l` in f32, the reference in f64. Normalizing costs at most 3 roundings per component (the dot
/// product for the length, the square root, the division), the dot product `n·l` of two unit vectors at most 3
/// (two additions and a product, each ≤ u of a value ≤ 1), and the interpolation at most 2 more. These errors are
/// *absolute* in `n·l` (≤ 8u, whatever `n·l` is), so the radiance `ρ E⊥ (n·l)` carries an absolute error of up to
/// 8u × `ρ E⊥`, the radiance of a surface facing the light: about the image's peak. Near a terminator, where
/// `n·l` → 0, that absolute error is a large relative one (a pixel at 1% of the peak can be 5e-5 off). The
/// products after `n·l` round relatively and are covered by the relative part. Measured on lavapipe (UV spheres
/// of 4k and 64k triangles under the sun, tests/gpu_vs_reference.rs): at most 3.0u of the peak.
pub const F32_SHADING_PEAK_FRACTION: f64 = 8.0 / (1u64 << 24) as f64;

/// Thresholds of a comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffOptions {
    /// Absolute floor of the relative error's denominator [W/(m²·sr)].
    pub floor: f64,
    /// Floor as a fraction of the images' peak value.
    pub floor_fraction: f64,
    /// Relative tolerance per pixel.
    pub fail_rel: Option<f64>,
    /// Absolute tolerance per pixel [W/(m²·sr)].
    pub fail_abs: Option<f64>,
    /// Absolute tolerance per pixel as a fraction of the images' peak (dimensionless).
    pub fail_peak: Option<f64>,
    /// Pixels allowed over tolerance.
    pub fail_count: usize,
    /// Pixels allowed over tolerance as a percentage of the compared pixels (the larger allowance wins).
    pub fail_percent: Option<f64>,
    /// Pixels allowed to differ in coverage.
    pub fail_coverage: usize,
    /// Any pixel over this relative error fails the comparison, whatever the counts allow.
    pub hard_fail: Option<f64>,
    /// Warn level: pixels over this relative error (and `warn_abs`, if given) are counted and reported; a
    /// comparison that passes with such pixels is a WARN (still a pass).
    pub warn_rel: Option<f64>,
    pub warn_abs: Option<f64>,
    /// The comparison fails where the mean HDR-FLIP ([`super::flip`], in [0, 1]) exceeds this; given, FLIP is
    /// computed and reported.
    pub fail_flip: Option<f64>,
}

impl Default for DiffOptions {
    fn default() -> Self {
        Self {
            floor: 0.0,
            floor_fraction: 1e-2,
            fail_rel: Some(1e-5),
            fail_abs: None,
            fail_peak: Some(F32_SHADING_PEAK_FRACTION),
            fail_count: 0,
            fail_percent: None,
            fail_coverage: 0,
            hard_fail: None,
            warn_rel: None,
            warn_abs: None,
            fail_flip: None,
        }
    }
}

/// The pixel with the largest relative error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorstPixel {
    pub x: u32,
    pub y: u32,
    pub a: [f32; 4],
    pub b: [f32; 4],
    pub rel: f64,
    pub abs: f64,
}

/// Counts split by where the pixels lie.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Split {
    pub total: usize,
    pub edge: usize,
    pub interior: usize,
}

impl Split {
    fn add(&mut self, edge: bool) {
        self.total += 1;
        if edge {
            self.edge += 1;
        } else {
            self.interior += 1;
        }
    }
}

/// The result of comparing image A with image B.
#[derive(Clone, Debug, PartialEq)]
pub struct DiffReport {
    pub width: u32,
    pub height: u32,
    pub covered_a: usize,
    pub covered_b: usize,
    pub coverage_mismatches: Split,
    /// Pixels covered in both.
    pub compared: usize,
    pub max_abs: f64,
    pub max_rel: f64,
    /// Largest relative error among interior pixels (not next to a coverage boundary).
    pub max_rel_interior: f64,
    pub rmse: f64,
    pub psnr_db: f64,
    pub peak: f64,
    /// The floor used in the relative error [W/(m²·sr)].
    pub floor: f64,
    pub over_tolerance: Split,
    /// Where the pixels over tolerance are, `(x, y)` in scan order (to classify them further, e.g. against the
    /// reference's fragile shadow rays).
    pub over_tolerance_pixels: Vec<(u32, u32)>,
    /// Pixels over the warn level.
    pub over_warn: Split,
    /// Pixels over `hard_fail`.
    pub hard_failures: usize,
    /// Pixels allowed over tolerance: `fail_count`, or `fail_percent` of the compared pixels if that is more.
    pub allowed_over: usize,
    pub worst: Option<WorstPixel>,
    pub options: DiffOptions,
    pub pass: bool,
    /// Passed with pixels over the warn level.
    pub warn: bool,
    /// The class of pixels counted apart, if the comparison was given one ([`diff_excusing`]).
    pub excused: Option<Excused>,
    /// FLIP over every pixel's RGB, where the options ask for it.
    pub flip: Option<FlipStats>,
}

/// Pixels counted apart from the tolerances: a class where the two images are known to differ by the models
/// compared (a shadow map's edges against exact rays), reported but not failed.
#[derive(Clone, Debug, PartialEq)]
pub struct Excused {
    /// What the class is, for the report.
    pub class: String,
    /// Pixels of the class covered in both images.
    pub compared: usize,
    /// Of them, over tolerance (not counted in [`DiffReport::over_tolerance`]).
    pub over_tolerance: usize,
    /// The largest relative error among them.
    pub max_rel: f64,
    /// How many of them may be over tolerance for the comparison to pass (`None`: any; [`DiffReport::cap_excused`]).
    pub allowed: Option<usize>,
}

/// Per-pixel results, for the heatmap.
#[derive(Clone, Debug, PartialEq)]
pub enum PixelDiff {
    /// Covered in neither image.
    Empty,
    /// Covered in one image only.
    CoverageMismatch,
    /// Covered in both, with this relative error.
    Relative(f64),
}

impl DiffOptions {
    /// The relative error's floor for images whose peak is `peak`: `floor`, or `floor_fraction` of the peak where
    /// that is more.
    pub fn floor_for(&self, peak: f64) -> f64 {
        self.floor.max(self.floor_fraction * peak)
    }
}

/// The floor `sunshade diff` takes by default against `image`: 1% of its peak ([`DiffOptions::floor_for`]), as the
/// accuracy studies measure an image against a finer or reference one.
pub fn default_floor(image: &Image) -> f64 {
    DiffOptions::default().floor_for(image_peak(image))
}

/// The largest absolute radiance over RGB of an image's covered pixels, ignoring non-finite values: the peak the
/// floor is a fraction of.
pub fn image_peak(image: &Image) -> f64 {
    image
        .pixels()
        .iter()
        .filter(|p| p[3] > 0.0)
        .flat_map(|p| p[..3].iter().map(|v| v.abs() as f64))
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max)
}

/// Two pixels' difference: per RGB channel `|a − b|` (NaN in either is an infinite difference, never silently
/// zero), the largest of them, and the largest relative one `|a − b| / max(|a|, |b|, floor)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelDifference {
    pub channels: [f64; 3],
    pub abs: f64,
    pub rel: f64,
}

/// The difference of pixels `a` and `b` with this floor of the relative error's denominator.
pub fn pixel_difference(a: [f32; 4], b: [f32; 4], floor: f64) -> PixelDifference {
    let (mut abs, mut rel) = (0.0f64, 0.0f64);
    let mut channels = [0.0; 3];
    for c in 0..3 {
        let (va, vb) = (a[c] as f64, b[c] as f64);
        let d = (va - vb).abs();
        let d = if d.is_nan() { f64::INFINITY } else { d };
        channels[c] = d;
        abs = abs.max(d);
        let denom = va.abs().max(vb.abs()).max(floor);
        let r = if d == 0.0 {
            0.0
        } else if denom > 0.0 {
            d / denom
        } else {
            f64::INFINITY
        };
        rel = rel.max(r);
    }
    PixelDifference { channels, abs, rel }
}

/// Compares two images of the same size. `Err` names the size mismatch.
pub fn diff(a: &Image, b: &Image, options: &DiffOptions) -> Result<(DiffReport, Vec<PixelDiff>), String> {
    diff_excusing(a, b, options, None)
}

/// [`diff_excusing`], the class's pixels over tolerance capped at `allowed_fraction` of the compared pixels
/// where it is given ([`DiffReport::cap_excused`]).
pub fn diff_apart(
    a: &Image,
    b: &Image,
    options: &DiffOptions,
    apart: Option<(&[bool], &str, Option<f64>)>,
) -> Result<(DiffReport, Vec<PixelDiff>), String> {
    let (mut report, per_pixel) = diff_excusing(a, b, options, apart.map(|(mask, class, _)| (mask, class)))?;
    if let Some((_, _, Some(fraction))) = apart {
        report.cap_excused(fraction);
    }
    Ok((report, per_pixel))
}

/// [`diff`], with the pixels flagged in `excused` (row-major mask, and the class's name) counted apart: their
/// differences enter the metrics (max, RMSE, worst pixel) but not the tolerance counts, the hard failures or the
/// warn level; [`DiffReport::excused`] reports them.
pub fn diff_excusing(
    a: &Image,
    b: &Image,
    options: &DiffOptions,
    excused: Option<(&[bool], &str)>,
) -> Result<(DiffReport, Vec<PixelDiff>), String> {
    super::same_size(a, b)?;
    let (w, h) = (a.width(), a.height());
    let covered = |img: &Image, x: i64, y: i64| {
        x >= 0 && y >= 0 && x < w as i64 && y < h as i64 && img.get(x as u32, y as u32)[3] > 0.0
    };
    let boundary = |x: u32, y: u32| {
        let (x, y) = (x as i64, y as i64);
        [a, b].iter().any(|img| {
            let c = covered(img, x, y);
            (-1..=1).any(|dy| (-1..=1).any(|dx| covered(img, x + dx, y + dy) != c))
        })
    };
    let peak = image_peak(a).max(image_peak(b));
    let floor = options.floor_for(peak);

    let mut report = DiffReport {
        width: w,
        height: h,
        covered_a: a.covered_count(),
        covered_b: b.covered_count(),
        coverage_mismatches: Split::default(),
        compared: 0,
        max_abs: 0.0,
        max_rel: 0.0,
        max_rel_interior: 0.0,
        rmse: 0.0,
        psnr_db: f64::INFINITY,
        peak,
        floor,
        over_tolerance: Split::default(),
        over_tolerance_pixels: Vec::new(),
        over_warn: Split::default(),
        hard_failures: 0,
        allowed_over: options.fail_count,
        worst: None,
        options: *options,
        pass: true,
        warn: false,
        excused: excused.map(|(_, class)| Excused {
            class: class.to_string(),
            compared: 0,
            over_tolerance: 0,
            max_rel: 0.0,
            allowed: None,
        }),
        flip: None,
    };
    let mut per_pixel = Vec::with_capacity((w * h) as usize);
    let mut sum_sq = 0.0;
    for y in 0..h {
        for x in 0..w {
            let (pa, pb) = (a.get(x, y), b.get(x, y));
            let (ca, cb) = (pa[3] > 0.0, pb[3] > 0.0);
            if !ca && !cb {
                per_pixel.push(PixelDiff::Empty);
                continue;
            }
            if ca != cb {
                report.coverage_mismatches.add(boundary(x, y));
                per_pixel.push(PixelDiff::CoverageMismatch);
                continue;
            }
            report.compared += 1;
            let PixelDifference { channels, abs, rel } = pixel_difference(pa, pb, floor);
            for d in channels {
                sum_sq += d * d;
            }
            let edge = boundary(x, y);
            report.max_abs = report.max_abs.max(abs);
            if !edge {
                report.max_rel_interior = report.max_rel_interior.max(rel);
            }
            report.max_rel = report.max_rel.max(rel);
            if report.worst.is_none_or(|wp| rel > wp.rel) {
                report.worst = Some(WorstPixel { x, y, a: pa, b: pb, rel, abs });
            }
            let checks = [
                options.fail_rel.map(|t| rel > t),
                options.fail_abs.map(|t| abs > t),
                options.fail_peak.map(|t| abs > t * peak),
            ];
            let mut given = checks.iter().flatten().peekable();
            let over = given.peek().is_some() && given.all(|&over| over);
            if let (Some(class), Some((mask, _))) = (report.excused.as_mut(), excused) {
                if mask.get((y * w + x) as usize) == Some(&true) {
                    class.compared += 1;
                    class.over_tolerance += usize::from(over);
                    class.max_rel = class.max_rel.max(rel);
                    per_pixel.push(PixelDiff::Relative(rel));
                    continue;
                }
            }
            if over {
                report.over_tolerance.add(edge);
                report.over_tolerance_pixels.push((x, y));
            }
            let warn_checks = [options.warn_rel.map(|t| rel > t), options.warn_abs.map(|t| abs > t)];
            let mut warn_given = warn_checks.iter().flatten().peekable();
            if warn_given.peek().is_some() && warn_given.all(|&over| over) {
                report.over_warn.add(edge);
            }
            if options.hard_fail.is_some_and(|h| rel > h) {
                report.hard_failures += 1;
            }
            per_pixel.push(PixelDiff::Relative(rel));
        }
    }
    if report.compared > 0 {
        report.rmse = (sum_sq / (3 * report.compared) as f64).sqrt();
        report.psnr_db = if report.rmse > 0.0 { 20.0 * (peak / report.rmse).log10() } else { f64::INFINITY };
    }
    if let Some(p) = options.fail_percent {
        // Rounded down: 0.1% of 999 pixels allows none.
        report.allowed_over = report.allowed_over.max((p / 100.0 * report.compared as f64).floor() as usize);
    }
    report.pass = report.over_tolerance.total <= report.allowed_over
        && report.coverage_mismatches.total <= options.fail_coverage
        && report.hard_failures == 0;
    report.warn = report.pass && report.over_warn.total > 0;
    // FLIP's reference is B, the expected image (HDR-FLIP chooses its exposures from it).
    if options.fail_flip.is_some() {
        report.add_flip(super::flip::flip(b, a, FlipInput::Hdr, super::flip::DEFAULT_PPD)?.stats(), options.fail_flip);
    }
    Ok((report, per_pixel))
}

impl DiffReport {
    /// Adds FLIP's summary; the comparison fails where its mean exceeds `fail_flip`.
    pub fn add_flip(&mut self, stats: FlipStats, fail_flip: Option<f64>) {
        self.options.fail_flip = fail_flip;
        if fail_flip.is_some_and(|t| stats.mean > t) {
            self.pass = false;
            self.warn = false;
        }
        self.flip = Some(stats);
    }

    /// Fails the comparison where more of the pixels counted apart are over tolerance than `fraction` of the
    /// compared pixels (rounded down): a class that excuses a few rays grazing an edge, not a region.
    pub fn cap_excused(&mut self, fraction: f64) {
        if let Some(e) = self.excused.as_mut() {
            let allowed = (fraction * self.compared as f64).floor() as usize;
            e.allowed = Some(allowed);
            if e.over_tolerance > allowed {
                self.pass = false;
                self.warn = false;
            }
        }
    }

    /// How many of the pixels over tolerance are flagged in `mask` (row-major, `width` pixels a row): the class
    /// of differences at places where the reference's result is *fragile*, a shadow ray grazing an occluder's
    /// edge or a texture lookup at a discontinuity (`cpu::render_with_fragile_pixels`), counted apart as coverage
    /// mismatches at triangle edges are.
    pub fn over_tolerance_at(&self, mask: &[bool], width: u32) -> usize {
        self.over_tolerance_pixels.iter().filter(|&&(x, y)| mask.get((y * width + x) as usize) == Some(&true)).count()
    }

    /// A short human-readable report, errors in W/(m²·sr) (radiance, the default quantity).
    pub fn text(&self, name_a: &str, name_b: &str) -> String {
        self.text_in(name_a, name_b, "W/(m²·sr)")
    }

    /// A short human-readable report, absolute errors in `unit` (the images' quantity's).
    pub fn text_in(&self, name_a: &str, name_b: &str, unit: &str) -> String {
        let mut s = String::new();
        let o = &self.options;
        let parts: Vec<String> = [
            o.fail_rel.map(|r| format!("rel > {r:e}")),
            o.fail_abs.map(|a| format!("abs > {a:e}")),
            o.fail_peak.map(|p| format!("abs > {p:.3e} × peak")),
        ]
        .into_iter()
        .flatten()
        .collect();
        let tol = if parts.is_empty() { "no tolerance".to_string() } else { parts.join(" and ") };
        s += &format!("A: {name_a} ({}x{}, {} covered)\n", self.width, self.height, self.covered_a);
        s += &format!("B: {name_b} ({}x{}, {} covered)\n", self.width, self.height, self.covered_b);
        s += &format!(
            "coverage mismatches: {} (edge {}, interior {}; allowed {})\n",
            self.coverage_mismatches.total,
            self.coverage_mismatches.edge,
            self.coverage_mismatches.interior,
            self.options.fail_coverage
        );
        s += &format!("compared (covered in both): {}\n", self.compared);
        s += &format!("max abs error: {:.3e} {unit}\n", self.max_abs);
        s += &format!(
            "max rel error: {:.3e} (interior {:.3e}; floor {:.3e} {unit})\n",
            self.max_rel, self.max_rel_interior, self.floor
        );
        s += &format!("RMSE: {:.3e} {unit}, PSNR: {:.1} dB (peak {:.4e})\n", self.rmse, self.psnr_db, self.peak);
        s += &format!(
            "over tolerance ({tol}): {} (edge {}, interior {}; allowed {})\n",
            self.over_tolerance.total, self.over_tolerance.edge, self.over_tolerance.interior, self.allowed_over
        );
        if o.warn_rel.is_some() || o.warn_abs.is_some() {
            let level: Vec<String> =
                [o.warn_rel.map(|r| format!("rel > {r:e}")), o.warn_abs.map(|a| format!("abs > {a:e}"))]
                    .into_iter()
                    .flatten()
                    .collect();
            s += &format!("over warn level ({}): {}\n", level.join(" and "), self.over_warn.total);
        }
        if let Some(h) = o.hard_fail {
            s += &format!("over hard fail (rel > {h:e}): {}\n", self.hard_failures);
        }
        if let Some(e) = &self.excused {
            let allowed = e.allowed.map_or(String::new(), |n| format!(" (allowed {n})"));
            let failed = if e.allowed.is_some() { "" } else { ", not failed" };
            s += &format!(
                "counted apart{failed}: {} pixels at {}; {} of them over tolerance{allowed}, max rel error {:.3e}\n",
                e.compared, e.class, e.over_tolerance, e.max_rel
            );
        }
        if let Some(f) = &self.flip {
            let limit = o.fail_flip.map_or(String::new(), |t| format!(" (allowed mean {t})"));
            s += &format!("{}{limit}\n", f.text());
        }
        if let Some(wp) = &self.worst {
            s += &format!(
                "worst pixel: ({}, {}) rel {:.3e} abs {:.3e}\n  A = [{:e}, {:e}, {:e}, {}]\n  B = [{:e}, {:e}, {:e}, {}]\n",
                wp.x, wp.y, wp.rel, wp.abs, wp.a[0], wp.a[1], wp.a[2], wp.a[3], wp.b[0], wp.b[1], wp.b[2], wp.b[3]
            );
        }
        s += match (self.pass, self.warn) {
            (true, false) => "result: PASS\n",
            (true, true) => "result: WARN\n",
            (false, _) => "result: FAIL\n",
        };
        s
    }

    /// The metrics as JSON, for scripts.
    pub fn json(&self, name_a: &str, name_b: &str) -> serde_json::Value {
        let finite = |v: f64| if v.is_finite() { json!(v) } else { json!(null) };
        json!({
            "a": name_a, "b": name_b,
            "width": self.width, "height": self.height,
            "covered_a": self.covered_a, "covered_b": self.covered_b,
            "coverage_mismatches": { "total": self.coverage_mismatches.total, "edge": self.coverage_mismatches.edge, "interior": self.coverage_mismatches.interior },
            "compared": self.compared,
            "max_abs": finite(self.max_abs), "max_rel": finite(self.max_rel), "max_rel_interior": finite(self.max_rel_interior),
            "rmse": finite(self.rmse), "psnr_db": finite(self.psnr_db), "peak": finite(self.peak), "floor": finite(self.floor),
            "over_tolerance": { "total": self.over_tolerance.total, "edge": self.over_tolerance.edge, "interior": self.over_tolerance.interior },
            "worst": self.worst.map(|w| json!({ "x": w.x, "y": w.y, "a": w.a, "b": w.b, "rel": finite(w.rel), "abs": finite(w.abs) })),
            "over_warn": { "total": self.over_warn.total, "edge": self.over_warn.edge, "interior": self.over_warn.interior },
            "hard_failures": self.hard_failures,
            "allowed_over": self.allowed_over,
            "tolerances": {
                "fail_rel": self.options.fail_rel, "fail_abs": self.options.fail_abs, "fail_peak": self.options.fail_peak,
                "fail_count": self.options.fail_count, "fail_percent": self.options.fail_percent,
                "fail_coverage": self.options.fail_coverage, "hard_fail": self.options.hard_fail,
                "warn_rel": self.options.warn_rel, "warn_abs": self.options.warn_abs,
                "fail_flip": self.options.fail_flip
            },
            "flip": self.flip.as_ref().map(|f| f.json()),
            "pass": self.pass,
            "warn": self.warn,
            "excused": self.excused.as_ref().map(|e| json!({ "class": e.class, "compared": e.compared, "over_tolerance": e.over_tolerance, "allowed": e.allowed, "max_rel": finite(e.max_rel) })),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 4]) -> Image {
        let mut i = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                i.set(x, y, f(x, y));
            }
        }
        i
    }

    #[test]
    fn identical_images_pass_with_zero_error() {
        let a = img(8, 8, |x, y| if x > 1 && y > 1 { [x as f32, y as f32, 1.0, 1.0] } else { [0.0; 4] });
        let (r, _) = diff(&a, &a, &DiffOptions::default()).unwrap();
        assert!(r.pass);
        assert_eq!((r.max_abs, r.max_rel, r.rmse, r.coverage_mismatches.total), (0.0, 0.0, 0.0, 0));
        assert_eq!(r.psnr_db, f64::INFINITY);
        assert_eq!(r.compared, 36);
    }

    #[test]
    fn relative_error_uses_the_floor_and_finds_the_worst_pixel() {
        let a = img(4, 4, |_, _| [100.0, 100.0, 100.0, 1.0]);
        let mut b = a.clone();
        b.set(2, 1, [100.0, 100.5, 100.0, 1.0]);
        b.set(0, 3, [100.0, 100.0, 100.2, 1.0]);
        let (r, per) = diff(&a, &b, &DiffOptions { fail_rel: Some(3e-3), ..Default::default() }).unwrap();
        let wp = r.worst.unwrap();
        assert_eq!((wp.x, wp.y), (2, 1));
        assert!((r.max_rel - 0.5 / 100.5).abs() < 1e-12);
        assert!((r.max_abs - 0.5).abs() < 1e-12);
        assert_eq!(r.over_tolerance.total, 1);
        assert!(!r.pass);
        assert!(matches!(per[4 + 2], PixelDiff::Relative(v) if v > 0.004));
        // Near zero the floor bounds the relative error.
        let z = img(2, 1, |_, _| [0.0, 0.0, 0.0, 1.0]);
        let mut zb = z.clone();
        zb.set(0, 0, [1e-6, 0.0, 0.0, 1.0]);
        let (r, _) = diff(&z, &zb, &DiffOptions { floor: 1e-3, floor_fraction: 0.0, ..Default::default() }).unwrap();
        assert!((r.max_rel - 1e-3).abs() < 1e-9, "{}", r.max_rel); // 1e-6 rounded to f32
    }

    #[test]
    fn tolerances_combine_like_isclose() {
        let a = img(1, 1, |_, _| [1.0, 1.0, 1.0, 1.0]);
        let b = img(1, 1, |_, _| [1.01, 1.0, 1.0, 1.0]);
        let run = |rel, abs| {
            diff(&a, &b, &DiffOptions { fail_rel: rel, fail_abs: abs, ..Default::default() }).unwrap().0.pass
        };
        assert!(!run(Some(1e-3), None));
        assert!(!run(None, Some(1e-3)));
        assert!(run(Some(1e-3), Some(0.1)), "within the absolute tolerance");
        assert!(run(Some(0.1), Some(1e-3)), "within the relative tolerance");
    }

    #[test]
    fn warn_level_percentages_and_hard_fail() {
        // 100 pixels at 1, ten of them 1% off, one 50% off.
        let a = img(10, 10, |_, _| [1.0, 1.0, 1.0, 1.0]);
        let b = img(10, 10, |x, y| match (x, y) {
            (0, 0) => [1.5, 1.0, 1.0, 1.0],
            (_, 1) => [1.01, 1.0, 1.0, 1.0],
            _ => [1.0, 1.0, 1.0, 1.0],
        });
        let run = |o: DiffOptions| diff(&a, &b, &o).unwrap().0;
        let base = DiffOptions { fail_rel: Some(1e-3), fail_peak: None, ..Default::default() };
        assert!(!run(base).pass);
        let r = run(DiffOptions { fail_percent: Some(11.0), ..base });
        assert!(r.pass && r.allowed_over == 11, "{r:?}");
        assert!(!run(DiffOptions { fail_percent: Some(10.9), ..base }).pass);
        let r = run(DiffOptions { fail_percent: Some(11.0), hard_fail: Some(0.3), ..base });
        assert!(!r.pass && r.hard_failures == 1, "{r:?}");
        let r = run(DiffOptions { fail_rel: Some(0.4), warn_rel: Some(1e-3), ..base });
        assert!(r.pass && r.warn && r.over_warn.total == 11 && r.text("a", "b").contains("result: WARN"), "{r:?}");
        let r = run(DiffOptions { fail_rel: Some(0.4), warn_rel: Some(0.4), ..base });
        assert!(r.pass && !r.warn);
    }

    #[test]
    fn an_excused_class_is_reported_apart_and_only_it() {
        // Row 1 is 1% off (the class), pixel (0, 0) 50% off outside it.
        let a = img(10, 10, |_, _| [1.0, 1.0, 1.0, 1.0]);
        let b = img(10, 10, |x, y| match (x, y) {
            (0, 0) => [1.5, 1.0, 1.0, 1.0],
            (_, 1) => [1.01, 1.0, 1.0, 1.0],
            _ => [1.0, 1.0, 1.0, 1.0],
        });
        let o = DiffOptions { fail_rel: Some(1e-3), fail_peak: None, hard_fail: Some(5e-3), ..Default::default() };
        let row: Vec<bool> = (0..100).map(|k| k / 10 == 1).collect();
        let (r, _) = diff_excusing(&a, &b, &o, Some((&row, "row 1"))).unwrap();
        let e = r.excused.as_ref().unwrap();
        assert_eq!((e.compared, e.over_tolerance), (10, 10), "{r:?}");
        assert!((e.max_rel - 0.01 / 1.01).abs() < 1e-6, "{r:?}");
        // The 50% pixel still fails; the class's pixels are in the metrics but not in the counts.
        assert!(!r.pass && r.over_tolerance.total == 1 && r.hard_failures == 1, "{r:?}");
        assert!(r.max_rel > 0.3 && r.text("a", "b").contains("10 pixels at row 1; 10 of them over tolerance"));
        // With the 50% pixel in the class too, the comparison passes.
        let both: Vec<bool> = (0..100).map(|k| k == 0 || k / 10 == 1).collect();
        let (r, _) = diff_excusing(&a, &b, &o, Some((&both, "both"))).unwrap();
        assert!(r.pass && r.json("a", "b")["excused"]["over_tolerance"] == 11, "{r:?}");
        // Capped at 11% of the 100 compared pixels it passes, at 10% it fails, and the report says so.
        let mut capped = r.clone();
        capped.cap_excused(0.11);
        assert!(capped.pass && capped.text("a", "b").contains("11 of them over tolerance (allowed 11)"));
        let mut capped = r.clone();
        capped.cap_excused(0.10);
        assert!(!capped.pass && capped.json("a", "b")["excused"]["allowed"] == 10, "{capped:?}");
        // Without a class the report has none.
        assert!(diff(&a, &b, &o).unwrap().0.excused.is_none());
    }

    #[test]
    fn default_tolerance_allows_f32_rounding_of_the_peak_and_no_more() {
        // A pixel at 2% of the peak, 5u of the peak off: 1.5e-5 relative, within 8u of the peak.
        let u = 1.0 / (1u64 << 24) as f64;
        let a = img(2, 1, |x, _| if x == 0 { [100.0, 100.0, 100.0, 1.0] } else { [2.0, 2.0, 2.0, 1.0] });
        let off = |k: f64| {
            let mut b = a.clone();
            b.set(1, 0, [(2.0 + k * u * 100.0) as f32, 2.0, 2.0, 1.0]);
            diff(&a, &b, &DiffOptions::default()).unwrap().0
        };
        let r = off(5.0);
        assert!(r.max_rel > 1.4e-5 && r.pass, "{r:?}");
        let r = off(12.0);
        assert!(!r.pass && r.over_tolerance.total == 1, "{r:?}");
        // Without the peak part the relative tolerance alone decides.
        let strict = DiffOptions { fail_peak: None, ..Default::default() };
        let mut b = a.clone();
        b.set(1, 0, [(2.0 + 5.0 * u * 100.0) as f32, 2.0, 2.0, 1.0]);
        assert!(!diff(&a, &b, &strict).unwrap().0.pass);
    }

    #[test]
    fn coverage_mismatches_are_split_into_edge_and_interior() {
        // A: 6×6 block covered; B: same block minus one boundary pixel and minus one pixel in the middle.
        let a = img(10, 10, |x, y| if (2..8).contains(&x) && (2..8).contains(&y) { [1.0; 4] } else { [0.0; 4] });
        let mut b = a.clone();
        b.set(2, 4, [0.0; 4]); // on the boundary of A's block
        b.set(5, 5, [0.0; 4]); // a hole: next to B's own boundary, so also an edge
        let (r, _) = diff(&a, &b, &DiffOptions::default()).unwrap();
        assert_eq!(r.coverage_mismatches.total, 2);
        assert_eq!(r.coverage_mismatches.edge, 2);
        assert!(!r.pass);
        let (r, _) = diff(&a, &b, &DiffOptions { fail_coverage: 2, ..Default::default() }).unwrap();
        assert!(r.pass);
        // An interior value error stays interior.
        let mut c = a.clone();
        c.set(5, 5, [1.5, 1.0, 1.0, 1.0]);
        let (r, _) = diff(&a, &c, &DiffOptions::default()).unwrap();
        assert_eq!((r.over_tolerance.interior, r.over_tolerance.edge), (1, 0));
        assert!(r.max_rel_interior > 0.3);
    }

    #[test]
    fn nan_is_an_infinite_error_and_size_mismatch_is_refused() {
        let a = img(2, 2, |_, _| [1.0; 4]);
        let mut b = a.clone();
        b.set(1, 1, [f32::NAN, 1.0, 1.0, 1.0]);
        let (r, _) = diff(&a, &b, &DiffOptions::default()).unwrap();
        assert_eq!(r.max_rel, f64::INFINITY);
        assert!(!r.pass);
        assert!(diff(&a, &Image::new(3, 2), &DiffOptions::default()).unwrap_err().contains("2x2"));
    }
}

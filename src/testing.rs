//! Image tests for your own `cargo test`: render a scene as the command line would, compare it with the CPU
//! reference or with a golden image, and fail with the comparison's report.
//!
//! - [`job`]: a scene and `sunshade render`'s flags that define the image, rendered by the same render layer
//!   (`sunshade::render`) as the command line, `--tolerance` and `--visibility` included, so that the image is the
//!   one the command line gives.
//! - [`CheckedRenderer`]: the GPU renderer with Vulkan validation on; any validation message fails (the renderer
//!   sunshade's own tests use).
//! - [`reference`](fn@reference): the CPU reference of a job, with a device's [`ReferenceOptions`].
//! - [`assert_images_close!`](crate::assert_images_close) and
//!   [`assert_matches_golden!`](crate::assert_matches_golden): the comparison of `sunshade diff` (default: the
//!   tolerance of `render --check`). A golden is an EXR file. With `UPDATE_GOLDENS=1` the golden is (re)written;
//!   a missing golden fails when the environment variable `CI` is set, and is written with a warning otherwise;
//!   on a mismatch the actual image (`NAME.actual.exr`) and a heatmap (`NAME.heatmap.png`) are written next to
//!   the golden.
//!
//! ```
//! use sunshade::testing::{self, CheckedRenderer};
//!
//! let teapot = concat!(env!("CARGO_MANIFEST_DIR"), "/models/teapot.glb");
//! let job = testing::job(teapot, &["--width", "64", "--height", "48", "--sun-elevation", "30"]).unwrap();
//! let mut gpu = CheckedRenderer::new();
//! let image = gpu.render_job(&job).unwrap();
//! let reference = testing::reference(&job, &gpu.reference_options()).unwrap();
//! sunshade::assert_images_close!(image, reference);
//! assert!(image.covered_count() > 500);
//! ```

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::compare::{self, DiffOptions, DiffReport};
use crate::cpu::{self, ReferenceOptions};
use crate::film::{read_image, write_image, Exposure, Image, ImageIoError};
use crate::gpu::{ContextOptions, FrameTimings, GpuError, Renderer, ValidationLog};
use crate::render::{RenderError, Rendered, RequestArgs};
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// What can go wrong in a test before any comparison.
#[derive(Debug, thiserror::Error)]
pub enum TestingError {
    /// Flags `sunshade render` refuses.
    #[error("flags: {0}")]
    Flags(String),
    /// The scene could not be loaded or rendered as asked.
    #[error("{0}")]
    Scene(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Image(#[from] ImageIoError),
    /// The images differ beyond the tolerances (the comparison's report), or cannot be compared.
    #[error("{0}")]
    Compare(String),
}

impl From<RenderError> for TestingError {
    fn from(e: RenderError) -> Self {
        match e {
            RenderError::Usage(m) => TestingError::Flags(m),
            other => TestingError::Scene(other.message()),
        }
    }
}

/// A scene and the flags of `sunshade render` that define the image (not its output: no `--output`, `--check`).
#[derive(Debug)]
pub struct Job {
    request: RequestArgs,
}

/// A job from a scene and `render`'s flags, e.g. `job("teapot.glb", &["--width", "64", "--brdf", "ward"])`.
pub fn job(scene: impl AsRef<Path>, flags: &[&str]) -> Result<Job, TestingError> {
    let mut argv: Vec<String> = vec![scene.as_ref().display().to_string()];
    argv.extend(flags.iter().map(|f| f.to_string()));
    let request = RequestArgs::parse_list(&argv).map_err(TestingError::Flags)?;
    request.scene.check()?;
    Ok(Job { request })
}

impl Job {
    /// The loaded scene and the settings of the render (the loader's warnings go to stderr).
    pub fn prepare(&self) -> Result<(Scene, RenderSettings), TestingError> {
        let (scene, _) = crate::render::request::load(&self.request.scene)?;
        let settings = crate::render::request::resolve_settings(&scene, &self.request.scene)?;
        Ok((scene, settings))
    }
}

/// The CPU reference image of a job, as `sunshade reference` renders it with the same flags (its shadow technique,
/// visibility rule and `--tolerance`), mirroring the device `options` describe.
pub fn reference(job: &Job, options: &ReferenceOptions) -> Result<Image, TestingError> {
    let (scene, settings) = job.prepare()?;
    let can_occlude = crate::visibility::can_occlude(&scene);
    let q = &job.request;
    let (image, _, _) =
        crate::render::on_reference(&scene, can_occlude, &q.scene, q.visibility_rule, settings, options)?;
    Ok(image)
}

/// Renders the job's CPU reference and compares `image`, the job's GPU render, with it as `render --check` does,
/// the pixels of `cpu::checked`'s class counted apart ([`DiffReport::excused`]): a shadow map's edges, or the
/// fragile pixels of shadow rays, textures and alpha masks (at most `cpu::FRAGILE_ALLOWED_FRACTION` of the
/// compared pixels over tolerance). `Err` holds the report of a failed comparison.
pub fn check_against_reference(
    job: &Job,
    image: &Image,
    options: &ReferenceOptions,
    diff: &DiffOptions,
) -> Result<DiffReport, TestingError> {
    let (scene, settings) = job.prepare()?;
    let (reference, apart) = cpu::checked::checked_reference(&scene, &settings, options);
    compare_with_reference(image, &reference, apart.as_ref(), diff)
}

/// `image` against `reference`, the pixels of `apart` counted apart; `Err` holds the report of a failed comparison.
fn compare_with_reference(
    image: &Image,
    reference: &Image,
    apart: Option<&cpu::checked::ApartClass>,
    diff: &DiffOptions,
) -> Result<DiffReport, TestingError> {
    let apart = apart.map(|c| (c.mask.as_slice(), c.name, c.allowed_fraction));
    let (report, _) = compare::diff_apart(image, reference, diff, apart).map_err(TestingError::Compare)?;
    if report.pass {
        Ok(report)
    } else {
        Err(TestingError::Compare(report.text("gpu", "cpu reference")))
    }
}

/// [`check_against_reference`] for what the render layer rendered ([`CheckedRenderer::rendered_job`]): the
/// reference at the settings the image was rendered with (`--tolerance`'s choice), and the pixels `--tolerance`
/// refined on the reference ([`Rendered::refined`]) taken as they are, as `render --check` does.
pub fn check_rendered_against_reference(
    job: &Job,
    rendered: &Rendered,
    options: &ReferenceOptions,
    diff: &DiffOptions,
) -> Result<DiffReport, TestingError> {
    let (scene, _) = job.prepare()?;
    let (reference, apart) = cpu::checked::checked_reference(&scene, &rendered.settings, options);
    compare_with_reference(&rendered.image, &rendered.with_refined_pixels(reference), apart.as_ref(), diff)
}

/// A GPU renderer with the validation layer on. Any validation message fails: after each render, and when the
/// renderer is dropped (messages about objects left alive arrive then).
pub struct CheckedRenderer {
    renderer: Option<Renderer>,
    log: Arc<ValidationLog>,
}

impl CheckedRenderer {
    /// The default device with validation on. Panics with the reason when there is none (a test cannot go on).
    pub fn new() -> Self {
        Self::try_new().unwrap_or_else(|e| panic!("GPU tests need Vulkan with validation layers (make setup): {e}"))
    }

    pub fn try_new() -> Result<Self, TestingError> {
        Self::try_with(ContextOptions::default())
    }

    /// A renderer with these options, validation on whatever they say.
    pub fn try_with(options: ContextOptions) -> Result<Self, TestingError> {
        let renderer = Renderer::new(&ContextOptions { validation: true, ..options })?;
        let log = renderer.validation_log();
        Ok(Self { renderer: Some(renderer), log })
    }

    pub fn renderer(&mut self) -> &mut Renderer {
        self.renderer.as_mut().expect("alive")
    }

    /// Renders a loaded scene; panics on a validation message.
    pub fn render(&mut self, scene: &Scene, settings: &RenderSettings) -> Image {
        self.render_timed(scene, settings).0
    }

    /// Renders a loaded scene, with the frame's timings (and what it took in passes); panics on a validation
    /// message.
    pub fn render_timed(&mut self, scene: &Scene, settings: &RenderSettings) -> (Image, FrameTimings) {
        let rendered = self.renderer().render_scene(scene, settings).unwrap_or_else(|e| panic!("render failed: {e}"));
        assert_no_validation_messages(&self.log);
        rendered
    }

    /// Renders a job as `sunshade render` does (the same render layer: its shadow technique, visibility rule and
    /// `--tolerance`); panics on a validation message.
    pub fn render_job(&mut self, job: &Job) -> Result<Image, TestingError> {
        Ok(self.rendered_job(job)?.image)
    }

    /// [`render_job`](Self::render_job) with what the render layer says of the image: the settings it was
    /// rendered with (`--tolerance`'s choice), the shadow technique and why, the predicted error.
    pub fn rendered_job(&mut self, job: &Job) -> Result<Rendered, TestingError> {
        let (scene, settings) = job.prepare()?;
        if job.request.device.is_some() || job.request.interpolation.is_some() {
            return Err(TestingError::Flags(
                "--device and --interpolation choose a renderer: create it with CheckedRenderer::try_with".into(),
            ));
        }
        let reference = self.reference_options();
        let renderer = self.renderer();
        renderer.check_size(settings.width, settings.height)?;
        let gpu_scene = renderer.upload(&scene)?;
        let q = &job.request;
        let rendered =
            crate::render::on_gpu(renderer, (&scene, &gpu_scene), &q.scene, q.visibility_rule, settings, &reference);
        drop(gpu_scene);
        assert_no_validation_messages(&self.log);
        Ok(rendered?)
    }

    pub fn sub_pixel_bits(&self) -> u32 {
        self.renderer.as_ref().expect("alive").device_info().sub_pixel_precision_bits
    }

    /// The reference options that mirror this device (its sub-pixel bits; FMA as the host has it).
    pub fn reference_options(&self) -> ReferenceOptions {
        ReferenceOptions { sub_pixel_bits: self.sub_pixel_bits(), ..Default::default() }
    }
}

impl Default for CheckedRenderer {
    fn default() -> Self {
        Self::new()
    }
}

impl Drop for CheckedRenderer {
    fn drop(&mut self) {
        drop(self.renderer.take());
        if !std::thread::panicking() {
            assert_no_validation_messages(&self.log);
        }
    }
}

/// Panics listing the validation layer's messages, if there are any.
pub fn assert_no_validation_messages(log: &ValidationLog) {
    let messages = log.messages();
    assert!(messages.is_empty(), "{} validation message(s):\n{}", messages.len(), messages.join("\n"));
}

/// Compares two images; `Err` holds the report of a failed comparison (or why they cannot be compared).
pub fn check_close(a: &Image, b: &Image, options: &DiffOptions) -> Result<DiffReport, String> {
    let (report, _) = compare::diff(a, b, options)?;
    if report.pass {
        Ok(report)
    } else {
        Err(report.text("actual", "expected"))
    }
}

/// What [`check_golden`] did.
#[derive(Debug)]
pub enum GoldenOutcome {
    /// The image matched the golden.
    Matched(Box<DiffReport>),
    /// The golden was written: `UPDATE_GOLDENS=1`, or it was missing outside CI.
    Written(PathBuf),
}

/// Compares `image` with the golden EXR at `golden` (see the module documentation for `UPDATE_GOLDENS` and
/// `CI`). `Err` is the message to fail with; on a mismatch it names the actual image and heatmap written next to
/// the golden.
pub fn check_golden(image: &Image, golden: &Path, options: &DiffOptions) -> Result<GoldenOutcome, String> {
    let update = std::env::var("UPDATE_GOLDENS").is_ok_and(|v| v == "1");
    check_golden_with(image, golden, options, update, std::env::var_os("CI").is_some())
}

/// [`check_golden`] with `UPDATE_GOLDENS=1` and `CI` given rather than read from the environment.
pub fn check_golden_with(
    image: &Image,
    golden: &Path,
    options: &DiffOptions,
    update: bool,
    ci: bool,
) -> Result<GoldenOutcome, String> {
    let write = |why: &str| {
        // A golden's folder is made where it does not exist yet (a test's first run).
        if let Some(folder) = golden.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
        }
        write_image(image, golden, Exposure::Auto).map_err(|e| e.to_string())?;
        eprintln!("sunshade testing: {why}: wrote {}", golden.display());
        Ok(GoldenOutcome::Written(golden.to_path_buf()))
    };
    if update {
        return write("UPDATE_GOLDENS=1");
    }
    if !golden.exists() {
        if ci {
            return Err(format!(
                "golden {} is missing (CI is set, so it is not written; run with UPDATE_GOLDENS=1 to write it)",
                golden.display()
            ));
        }
        return write("missing golden");
    }
    let expected = read_image(golden).map_err(|e| e.to_string())?;
    let (report, per_pixel) = compare::diff(image, &expected, options)?;
    if report.pass {
        return Ok(GoldenOutcome::Matched(Box::new(report)));
    }
    let stem = golden.with_extension("");
    let actual = PathBuf::from(format!("{}.actual.exr", stem.display()));
    let heatmap = PathBuf::from(format!("{}.heatmap.png", stem.display()));
    let written = write_image(image, &actual, Exposure::Auto).map_err(|e| e.to_string()).and_then(|_| {
        compare::write_heatmap(&heatmap, image.width(), image.height(), &per_pixel).map_err(|e| e.to_string())
    });
    let note = match written {
        Ok(()) => format!("actual image {} and heatmap {}", actual.display(), heatmap.display()),
        Err(e) => format!("the actual image could not be written: {e}"),
    };
    Err(format!("image differs from golden {}; {note}\n{}", golden.display(), report.text("actual", "golden")))
}

/// Asserts that two images agree within the tolerance of `render --check` (or the [`DiffOptions`] given); the
/// panic message is the comparison's report.
#[macro_export]
macro_rules! assert_images_close {
    ($actual:expr, $expected:expr $(,)?) => {
        $crate::assert_images_close!($actual, $expected, $crate::compare::DiffOptions::default())
    };
    ($actual:expr, $expected:expr, $options:expr $(,)?) => {
        if let Err(report) = $crate::testing::check_close(&$actual, &$expected, &$options) {
            panic!("images differ:\n{report}");
        }
    };
}

/// Asserts that an image matches its golden EXR (see [`testing`](crate::testing) for `UPDATE_GOLDENS` and `CI`).
#[macro_export]
macro_rules! assert_matches_golden {
    ($image:expr, $golden:expr $(,)?) => {
        $crate::assert_matches_golden!($image, $golden, $crate::compare::DiffOptions::default())
    };
    ($image:expr, $golden:expr, $options:expr $(,)?) => {
        if let Err(message) = $crate::testing::check_golden(&$image, ::std::path::Path::new(&$golden), &$options) {
            panic!("{message}");
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(v: f32) -> Image {
        let mut i = Image::new(4, 3);
        i.pixels_mut().iter_mut().for_each(|p| *p = [v, v, v, 1.0]);
        i
    }

    #[test]
    fn goldens_are_written_compared_and_never_pass_silently_in_ci() {
        let dir = std::env::temp_dir().join(format!("sunshade-golden-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let golden = dir.join("goldens").join("g.exr");
        let opts = DiffOptions::default();
        // Missing in CI: fails, writes nothing.
        let e = check_golden_with(&image(1.0), &golden, &opts, false, true).unwrap_err();
        assert!(e.contains("missing") && !golden.exists(), "{e}");
        // Missing outside CI: written, its folder made.
        assert!(matches!(check_golden_with(&image(1.0), &golden, &opts, false, false), Ok(GoldenOutcome::Written(_))));
        assert!(matches!(check_golden_with(&image(1.0), &golden, &opts, false, true), Ok(GoldenOutcome::Matched(_))));
        // A mismatch fails and leaves the actual image and the heatmap next to the golden.
        let e = check_golden_with(&image(1.1), &golden, &opts, false, true).unwrap_err();
        assert!(
            e.contains("differs")
                && dir.join("goldens/g.actual.exr").exists()
                && dir.join("goldens/g.heatmap.png").exists(),
            "{e}"
        );
        // UPDATE_GOLDENS=1 rewrites it.
        check_golden_with(&image(1.1), &golden, &opts, true, true).unwrap();
        assert!(matches!(check_golden_with(&image(1.1), &golden, &opts, false, true), Ok(GoldenOutcome::Matched(_))));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn jobs_take_render_flags_and_refuse_bad_ones() {
        assert!(job("a.glb", &["--width", "8"]).is_ok());
        // The command line's one-line error, naming the flag (no clap usage block).
        let Err(TestingError::Flags(m)) = job("a.glb", &["--width", "-8"]) else { panic!("--width -8 accepted") };
        assert!(m.contains("--width") && !m.contains('\n') && !m.contains("Usage"), "{m}");
        assert!(matches!(job("a.glb", &["--sun-model", "delta", "--sun-samples", "4"]), Err(TestingError::Flags(_))));
        let missing = job("/no/such/scene.glb", &[]).unwrap();
        assert!(matches!(missing.prepare(), Err(TestingError::Scene(m)) if m.contains("scene.glb")));
    }

    #[test]
    fn a_comparison_can_hold_the_mean_flip() {
        let (a, mut b) = (image(1.0), image(1.0));
        b.set(1, 1, [3.0, 3.0, 3.0, 1.0]);
        let loose = DiffOptions { fail_rel: Some(10.0), fail_peak: None, ..Default::default() };
        let report = check_close(&a, &b, &loose).unwrap();
        assert!(report.flip.is_none(), "FLIP only where asked");
        let mean = check_close(&a, &b, &DiffOptions { fail_flip: Some(1.0), ..loose }).unwrap().flip.unwrap().mean;
        assert!(mean > 0.0);
        let e = check_close(&a, &b, &DiffOptions { fail_flip: Some(mean / 2.0), ..loose }).unwrap_err();
        assert!(e.contains("FLIP (HDR-FLIP") && e.contains("allowed mean") && e.contains("FAIL"), "{e}");
    }

    #[test]
    #[should_panic(expected = "images differ")]
    fn assert_images_close_panics_with_the_report() {
        crate::assert_images_close!(image(1.0), image(2.0));
    }
}

//! Accumulation over time: `--quantity irradiation` (`H = Σ E(tᵢ) Δtᵢ` [Wh/m²]) and `--quantity sun-hours` (the
//! hours whose direct sun on the surface reaches a threshold [h]) over `--from`, `--to`, `--step`.
//!
//! The interval is cut into steps of `--step` (the last one shorter where the interval does not divide); each
//! step is represented by the sun and clear sky of its midpoint, weighted by its length (the midpoint rule:
//! exact for an irradiance linear in time over the step, error `O(Δt²)` per step otherwise). Only steps with the
//! sun up are rendered: with it down the clear sky sends nothing either (an explicit --sky-radiance, too, is not
//! counted at night). The sums are f64 per pixel and channel, rounded once to f32 at the end. All steps render in
//! one process on one device: the scene is loaded and uploaded once, the pipelines created once (the batch
//! machinery's session); `--shard K/N` takes steps K, K+N, … so that shards' images add up (`sunshade sum`) to
//! the whole.

use std::time::{Duration, Instant as Clock};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::args::SceneArgs;
use super::CliError;
use crate::daylight::Instant;
use crate::film::Image;
use crate::render::flags::quantity::RequestedQuantity;
use crate::scene::Scene;
use crate::settings::{self, RenderSettings};

/// One step of an accumulation: its midpoint and its length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    pub midpoint: Instant,
    /// Length [h].
    pub hours: f64,
}

/// The steps of `[from, to)` of `step_s` seconds each, the last one shorter if the interval does not divide.
pub fn steps(from: Instant, to: Instant, step_s: f64) -> Vec<Step> {
    let total = to.seconds_since(from);
    let count = (total / step_s).ceil().max(0.0) as usize;
    (0..count)
        .map(|k| {
            let start = k as f64 * step_s;
            let length = step_s.min(total - start);
            Step { midpoint: from.plus_seconds(start + 0.5 * length), hours: length / 3600.0 }
        })
        .filter(|s| s.hours > 0.0)
        .collect()
}

/// Indices `k, k+n, k+2n, …` of `count` items (shard `k` of `n`; all when `None`).
fn shard_of(count: usize, shard: Option<(usize, usize)>) -> Vec<usize> {
    let (k, n) = shard.unwrap_or((0, 1));
    (k..count).step_by(n).collect()
}

/// What an accumulation did.
pub struct Accumulated {
    /// Wh/m² (irradiation) or h (sun-hours) per channel; alpha the coverage.
    pub image: Image,
    /// The settings of the first rendered step (for the file's record).
    pub first_settings: RenderSettings,
    /// Steps in the interval, in this shard, and rendered (the sun up).
    pub steps_total: usize,
    pub steps_in_shard: usize,
    pub steps_rendered: usize,
    /// Hours of the shard's steps, and of those with the sun up.
    pub hours_in_shard: f64,
    pub hours_rendered: f64,
    /// Time spent in frames (each `frame` call) and in accumulating.
    pub frames: Duration,
    pub accumulating: Duration,
}

/// Accumulates `a.quantity` for `scene`, rendering each step's frame with `frame` (the GPU or the reference).
pub fn accumulate(
    scene: &Scene,
    a: &SceneArgs,
    mut frame: impl FnMut(&RenderSettings) -> Result<Image, CliError>,
) -> Result<Accumulated, CliError> {
    let (d, acc) = (&a.daylight, &a.accumulation);
    let (Some(from), Some(to), Some(step_s)) = (acc.from, acc.to, acc.step) else {
        return Err(CliError::Usage("an accumulation needs --from, --to and --step".into()));
    };
    let all = steps(from, to, step_s);
    let mine = shard_of(all.len(), acc.shard);
    let sun_hours = a.quantity == RequestedQuantity::SunHours;
    let (width, height) = (a.width, a.height);
    let pixels = width as usize * height as usize;
    let mut sum = vec![[0.0f64; 3]; pixels];
    let mut coverage: Option<Vec<f32>> = None;
    let mut first_settings = None;
    let (mut rendered, mut hours_in_shard, mut hours_rendered) = (0, 0.0, 0.0);
    let (mut frames, mut accumulating) = (Duration::ZERO, Duration::ZERO);
    let bar = if super::quiet() {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(mine.len() as u64), ProgressDrawTarget::stderr())
    };
    bar.set_style(
        ProgressStyle::with_template("sunshade: {msg} step {pos}/{len} [{elapsed}, {eta} left]").expect("template"),
    );
    bar.set_message(a.quantity.name());
    // Warnings (the shadow technique's, a sun below the horizon) print above the bar, not into its line.
    let printer = bar.clone();
    let _warnings = crate::render::warnings::print_through(move |line| printer.suspend(|| eprintln!("{line}")));
    for &k in &mine {
        let step = all[k];
        hours_in_shard += step.hours;
        let Some(at) = d.at(step.midpoint) else { return Err(no_location()) };
        bar.inc(1);
        if !at.position.is_up() {
            continue;
        }
        let lights = a.light_options_at(Some(&at));
        let mut settings = settings::resolve_with(scene, width, height, &a.camera_options(), &lights)
            .map_err(|e| CliError::Usage(e.to_string()))?;
        if sun_hours {
            // Direct sun only, at its own E⊥: the threshold is on the direct irradiance of the surface (the
            // scene's own disks and sky, which resolving adds, removed too).
            settings.lights.disks.clear();
            settings.lights.sky = None;
        }
        let t = Clock::now();
        let image = frame(&settings)?;
        frames += t.elapsed();
        let t = Clock::now();
        add_step(&mut sum, &image, step.hours, sun_hours.then_some(acc.sun_hours_threshold));
        if coverage.is_none() {
            coverage = Some(image.pixels().iter().map(|p| p[3]).collect());
        }
        accumulating += t.elapsed();
        first_settings.get_or_insert(settings);
        rendered += 1;
        hours_rendered += step.hours;
    }
    bar.finish_and_clear();
    // With no step rendered (the sun down throughout), one dark frame gives the coverage and the record.
    let first_settings = match first_settings {
        Some(s) => s,
        None => {
            let Some(at) = d.at(from) else { return Err(no_location()) };
            let mut lights = a.light_options_at(Some(&at));
            lights.sun.irradiance = Some(0.0);
            lights.sky = Some([0.0; 3]);
            lights.disks.clear();
            let settings = settings::resolve_with(scene, width, height, &a.camera_options(), &lights)
                .map_err(|e| CliError::Usage(e.to_string()))?;
            let image = frame(&settings)?;
            coverage = Some(image.pixels().iter().map(|p| p[3]).collect());
            settings
        }
    };
    let coverage = coverage.expect("a frame was rendered");
    let pixels = sum.iter().zip(&coverage).map(|(s, &alpha)| [s[0] as f32, s[1] as f32, s[2] as f32, alpha]).collect();
    let image = Image::from_pixels(width, height, pixels).expect("size");
    Ok(Accumulated {
        image,
        first_settings,
        steps_total: all.len(),
        steps_in_shard: mine.len(),
        steps_rendered: rendered,
        hours_in_shard,
        hours_rendered,
        frames,
        accumulating,
    })
}

fn no_location() -> CliError {
    CliError::Usage("an accumulation needs --location".into())
}

/// Adds one step: `E·Δt` per channel (irradiation), or `Δt` on every channel where the direct irradiance
/// (Rec. 709 weighting of the channels, the false colour's) reaches `threshold` (sun-hours).
fn add_step(sum: &mut [[f64; 3]], image: &Image, hours: f64, threshold: Option<f64>) {
    for (acc, p) in sum.iter_mut().zip(image.pixels()) {
        match threshold {
            None => {
                for c in 0..3 {
                    acc[c] += f64::from(p[c]) * hours;
                }
            }
            Some(t) => {
                let e = crate::plot::false_color::pixel_value(*p);
                if p[3] > 0.0 && e >= t && e > 0.0 {
                    for v in acc.iter_mut() {
                        *v += hours;
                    }
                }
            }
        }
    }
}

impl Accumulated {
    /// The record of the accumulation for the file's metadata (`sunshadeAccumulation`).
    pub fn json(&self, a: &SceneArgs) -> serde_json::Value {
        let (d, acc) = (&a.daylight, &a.accumulation);
        serde_json::json!({
            "quantity": a.quantity.name(),
            "unit": a.quantity.unit_ascii(),
            "from": acc.from.map(|t| t.to_string()),
            "to": acc.to.map(|t| t.to_string()),
            "step_s": acc.step,
            "rule": "midpoint of each step, weighted by its length; steps with the sun down add nothing",
            "shard": acc.shard.map(|(k, n)| format!("{k}/{n}")),
            "steps_total": self.steps_total,
            "steps_in_shard": self.steps_in_shard,
            "steps_rendered": self.steps_rendered,
            "hours_in_shard": self.hours_in_shard,
            "hours_rendered": self.hours_rendered,
            "location": d.location.map(|l| [l.latitude_deg, l.longitude_deg, l.elevation_m]),
            "north_deg": d.north,
            "refraction": !d.no_refraction,
            "linke_turbidity": d.linke_turbidity,
            "sun_hours_threshold_w_m2": (a.quantity == RequestedQuantity::SunHours).then_some(acc.sun_hours_threshold),
        })
    }

    /// The metadata of the accumulated image: the first step's render record with the quantity replaced.
    pub fn metadata(&self, a: &SceneArgs, renderer: &str) -> crate::film::Metadata {
        let mut meta = super::metadata::of_render(&self.first_settings, renderer);
        for (key, value) in meta.text.iter_mut() {
            if key == "quantity" {
                *value =
                    format!("{} {} per linear RGB channel; A = coverage", a.quantity.name(), a.quantity.unit_ascii());
            }
        }
        meta.text.push(("sunshadeAccumulation".into(), self.json(a).to_string()));
        meta
    }

    /// Writes the image (with its record) and the false colour if asked; with `verbose`, prints what was rendered,
    /// the exposure and `phases`.
    pub fn finish(
        &self,
        a: &SceneArgs,
        output: &super::args::OutputArgs,
        renderer: &str,
        verbose: Option<(&[(&str, Duration)], Clock)>,
    ) -> Result<(), CliError> {
        let meta = self.metadata(a, renderer);
        let ev = crate::film::write_image_with(&self.image, &output.output, output.exposure(), &meta)?;
        output.write_false_color(&self.image, a.quantity)?;
        super::warn_if_nothing_covered(&self.image, &a.scene);
        if let Some((phases, started)) = verbose {
            self.print();
            super::print_exposure(ev);
            let frames = [("frames", self.frames)];
            super::print_phases(&[phases, &frames[..]].concat(), started.elapsed());
        }
        Ok(())
    }

    /// `-v`: what was rendered and what it cost.
    pub fn print(&self) {
        if self.steps_in_shard == self.steps_total {
            eprintln!(
                "sunshade: {} of {} steps rendered (the sun up), {:.3} of {:.3} h",
                self.steps_rendered, self.steps_total, self.hours_rendered, self.hours_in_shard
            );
        } else {
            eprintln!(
                "sunshade: {} of {} steps in this shard rendered (the sun up), {:.3} of {:.3} h; {} steps in all",
                self.steps_rendered, self.steps_in_shard, self.hours_rendered, self.hours_in_shard, self.steps_total
            );
        }
        let per = |d: Duration| {
            if self.steps_rendered == 0 {
                0.0
            } else {
                d.as_secs_f64() * 1e3 / self.steps_rendered as f64
            }
        };
        eprintln!(
            "sunshade: frames {:.2} ms per step (incl. readback), accumulating {:.2} ms per step",
            per(self.frames),
            per(self.accumulating)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_cover_the_interval_once_with_midpoints() {
        let from = Instant::parse("2026-06-21T00:00:00Z").unwrap();
        let to = Instant::parse("2026-06-21T10:30:00Z").unwrap();
        let s = steps(from, to, 3600.0);
        assert_eq!(s.len(), 11);
        assert_eq!(s[0].midpoint.to_string(), "2026-06-21T00:30:00Z");
        assert_eq!(s[10].midpoint.to_string(), "2026-06-21T10:15:00Z");
        assert_eq!(s[10].hours, 0.5);
        assert_eq!(s.iter().map(|s| s.hours).sum::<f64>(), 10.5);
        // Shards partition the steps.
        let mut all: Vec<usize> = (0..3).flat_map(|k| shard_of(s.len(), Some((k, 3)))).collect();
        all.sort();
        assert_eq!(all, (0..11).collect::<Vec<_>>());
    }
}

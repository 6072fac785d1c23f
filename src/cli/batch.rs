//! `sunshade batch MANIFEST`: many renders in one process, on one device.
//!
//! The manifest is a JSON array of jobs. Each job is an object whose keys are `scene`, `output` and the long names
//! of `render`'s flags (`{"scene": "a.glb", "output": "a.png", "width": 256, "sun-elevation": 30}`); a job
//! becomes exactly the argument list of a `render` call (numbers and strings as `--key=value`, `true` as `--key`,
//! `false` and `null` left out, an array as the flag repeated) and is parsed by `render`'s own parser, so that its
//! image is bitwise the image `sunshade render` gives for the same flags. What the jobs share is made once: the
//! device and its pipelines, and each scene's load and upload while jobs reuse it ([`super::session`]). Images are
//! encoded on `--jobs` threads while the next job renders. A failed job is reported and the batch goes on; the
//! exit code is 1 when any job failed. `--shard K/N` renders jobs K, K+N, K+2N, … (counting from 0), so that N
//! machines or processes can split one manifest.

use std::path::{Path, PathBuf};
use std::sync::mpsc;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde_json::Value;

use super::render::{cache_dir, check_job, render_job, RenderArgs};
use super::session::Session;
use super::CliError;
use crate::film::{write_image_with, Exposure, Image, Metadata};
use crate::render::flags::parse_shard;

#[derive(Args, Debug)]
pub struct BatchArgs {
    /// The manifest: a JSON array of jobs, each `{"scene": ..., "output": ..., "<render flag>": value, ...}`.
    pub manifest: PathBuf,
    /// Threads that encode and write images while the next job renders.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub jobs: u32,
    #[command(flatten)]
    pub run: RunArgs,
    /// No progress bar and no summary line.
    #[arg(short, long)]
    pub quiet: bool,
}

/// What `batch` and `test` share: which of the jobs (or cases) this process runs, and the pipeline cache.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Run only every N-th job or case from K (0 ≤ K < N), to split one file over N machines or processes.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<(usize, usize)>,
    /// Do not read or write the pipeline cache on disk.
    #[arg(long)]
    pub no_cache: bool,
    /// Run only the cases whose name (`test`), or the jobs whose output path (`batch`), matches PATTERN: a
    /// substring, or a glob where it holds `*` (any run of characters) or `?` (one character). With --shard, the
    /// matching ones are split.
    #[arg(long, value_name = "PATTERN")]
    pub filter: Option<String>,
}

impl RunArgs {
    /// The indices of the items (named `names`) this process runs: those `--filter` matches, then this shard's.
    pub fn mine(&self, names: &[String]) -> Vec<usize> {
        let (k, n) = self.shard.unwrap_or((0, 1));
        let matching =
            (0..names.len()).filter(|&i| self.filter.as_deref().is_none_or(|p| matches_pattern(p, &names[i])));
        matching.enumerate().filter(|(j, _)| j % n == k).map(|(_, i)| i).collect()
    }
}

/// `--filter`'s rule: a glob where `pattern` holds `*` or `?` (the whole text must match), else a substring.
pub fn matches_pattern(pattern: &str, text: &str) -> bool {
    if !pattern.contains(['*', '?']) {
        return text.contains(pattern);
    }
    // Glob by dynamic programming over (pattern, text) prefixes: linear space, no backtracking blow-up.
    let (p, t): (Vec<char>, Vec<char>) = (pattern.chars().collect(), text.chars().collect());
    let mut row = vec![false; t.len() + 1];
    row[0] = true;
    for &c in &p {
        let mut next = vec![false; t.len() + 1];
        if c == '*' {
            let mut any = false;
            for j in 0..=t.len() {
                any = any || row[j];
                next[j] = any;
            }
        } else {
            for j in 1..=t.len() {
                next[j] = row[j - 1] && (c == '?' || c == t[j - 1]);
            }
        }
        row = next;
    }
    row[t.len()]
}

/// A job object → `render`'s argument list. Errors name the key.
pub fn job_arguments(job: &Value) -> Result<Vec<String>, String> {
    let object = job.as_object().ok_or("a job must be a JSON object")?;
    let text = |key: &str| -> Result<String, String> {
        match object.get(key) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(_) => Err(format!("\"{key}\" must be a string")),
            None => Err(format!("needs \"{key}\"")),
        }
    };
    let mut argv = vec![text("scene")?, "--output".to_string(), text("output")?];
    for (key, value) in object {
        if key == "scene" || key == "output" {
            continue;
        }
        let flag = format!("--{key}");
        let scalar = |v: &Value| match v {
            Value::String(s) => Ok(Some(format!("{flag}={s}"))),
            Value::Number(n) => Ok(Some(format!("{flag}={n}"))),
            Value::Bool(true) => Ok(Some(flag.clone())),
            Value::Bool(false) | Value::Null => Ok(None),
            _ => Err(format!("\"{key}\": a value must be a string, number or boolean")),
        };
        match value {
            Value::Array(items) => {
                for item in items {
                    argv.extend(scalar(item)?);
                }
            }
            v => argv.extend(scalar(v)?),
        }
    }
    Ok(argv)
}

/// The jobs of a manifest, each parsed or the reason it cannot be.
/// The manifest's jobs, each parsed or why it cannot be, and their names for `--filter` (their output paths).
type Manifest = (Vec<Result<RenderArgs, String>>, Vec<String>);

fn read_manifest(path: &Path) -> Result<Manifest, CliError> {
    let fail = |m: String| CliError::Failure(anyhow::anyhow!("{}: {m}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let value: Value = serde_json::from_str(&text).map_err(|e| fail(format!("invalid JSON: {e}")))?;
    let jobs = value.as_array().ok_or_else(|| fail("the manifest must be a JSON array of jobs".into()))?;
    let text_of = |job: &Value, key: &str| job.get(key).and_then(Value::as_str).unwrap_or("").to_string();
    let names = jobs.iter().map(|job| text_of(job, "output")).collect();
    let parsed = jobs
        .iter()
        .map(|job| {
            let args = RenderArgs::parse_list(&job_arguments(job)?)?;
            if args.request.scene.quantity.is_accumulated() {
                return Err(format!(
                    "quantity {}: not accumulated by batch jobs (render it with sunshade render, which runs its \
                     instants in one process)",
                    args.request.scene.quantity.name()
                ));
            }
            if args.output.false_color.is_some() {
                return Err("false-color: not written by batch jobs (render each with sunshade render)".to_string());
            }
            Ok(args)
        })
        .collect();
    Ok((parsed, names))
}

/// An image to write, and which job it is.
struct Encode {
    job: usize,
    image: Image,
    metadata: Metadata,
    output: PathBuf,
    exposure: Exposure,
}

pub fn run(a: &BatchArgs) -> Result<(), CliError> {
    let (jobs, names) = read_manifest(&a.manifest)?;
    let mine = a.run.mine(&names);
    let bar = if a.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(mine.len() as u64), ProgressDrawTarget::stderr())
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} jobs, {elapsed} ({eta} left) {msg}")
            .expect("a valid template"),
    );
    let mut failed = 0usize;
    // A job is done when it failed to render or its image is written (or failed to be): count and report it.
    // Warnings print above the bar, not into its line.
    let printer = bar.clone();
    let _warnings = crate::render::warnings::print_through(move |line| printer.suspend(|| eprintln!("{line}")));
    let mut finish = |job: usize, result: Result<(), String>| {
        if let Err(e) = result {
            failed += 1;
            let output =
                jobs[job].as_ref().map_or_else(|_| String::new(), |j| format!(" ({})", j.output.output.display()));
            bar.suspend(|| eprintln!("sunshade batch: job {job}{output}: {e}"));
        }
        bar.inc(1);
    };
    let mut session = Session::new(cache_dir(a.run.no_cache));
    let (to_encoders, queue) = mpsc::sync_channel::<Encode>(a.jobs as usize);
    let queue = std::sync::Mutex::new(queue);
    std::thread::scope(|scope| {
        let (done_tx, done) = mpsc::channel::<(usize, Result<(), String>)>();
        for _ in 0..a.jobs {
            let (queue, done_tx) = (&queue, done_tx.clone());
            scope.spawn(move || loop {
                let Ok(item) = queue.lock().expect("encoder queue").recv() else { break };
                let result = write_image_with(&item.image, &item.output, item.exposure, &item.metadata)
                    .map(|_| ())
                    .map_err(|e| e.to_string());
                let _ = done_tx.send((item.job, result));
            });
        }
        drop(done_tx);
        for &i in &mine {
            let result = match &jobs[i] {
                Err(e) => Err(e.clone()),
                Ok(args) => render_job(&mut session, args)
                    .and_then(|job| {
                        if args.check {
                            check_job(&mut session, args, &job, false)?;
                        }
                        Ok(job)
                    })
                    .map_err(|e| e.message()),
            };
            match result {
                Ok(job) => {
                    let args = jobs[i].as_ref().expect("rendered");
                    let mut metadata = super::metadata::of_render_predicted(
                        &job.render.settings,
                        &session.renderer_description(job.renderer),
                        &job.render.prediction,
                    );
                    metadata.text.extend(super::metadata::measured_materials(session.scene_ref(job.scene)));
                    let item = Encode {
                        job: i,
                        image: job.render.image,
                        metadata,
                        output: args.output.output.clone(),
                        exposure: args.output.exposure(),
                    };
                    to_encoders.send(item).expect("encoder threads alive");
                }
                Err(e) => finish(i, Err(e)),
            }
            while let Ok((job, r)) = done.try_recv() {
                finish(job, r);
            }
        }
        drop(to_encoders);
        for (job, r) in done.iter() {
            finish(job, r);
        }
    });
    for w in session.save_pipeline_caches() {
        bar.suspend(|| eprintln!("sunshade batch: warning: pipeline cache not saved: {w}"));
    }
    bar.finish_and_clear();
    if !a.quiet {
        eprintln!(
            "sunshade batch: {} of {} jobs rendered, {failed} failed{}",
            mine.len() - failed,
            mine.len(),
            match a.run.shard {
                Some((k, n)) => format!(" (shard {k}/{n} of {} jobs)", jobs.len()),
                None => String::new(),
            }
        );
    }
    if failed > 0 {
        return Err(CliError::Failure(anyhow::anyhow!("{failed} of {} jobs failed", mine.len())));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn jobs_become_render_arguments() {
        let argv = job_arguments(&json!({
            "scene": "a.glb", "output": "a.png", "width": 256, "sun-elevation": -3.5,
            "check": true, "no-cache": false, "disk-light": ["0,1,0:0,-1,0:1:5", "0,2,0:0,-1,0:1:5"]
        }))
        .unwrap();
        assert_eq!(&argv[..3], ["a.glb", "--output", "a.png"]);
        for a in [
            "--width=256",
            "--sun-elevation=-3.5",
            "--check",
            "--disk-light=0,1,0:0,-1,0:1:5",
            "--disk-light=0,2,0:0,-1,0:1:5",
        ] {
            assert!(argv.contains(&a.to_string()), "{a} missing from {argv:?}");
        }
        assert!(!argv.iter().any(|a| a.contains("no-cache")));
        let parsed = RenderArgs::parse_list(&argv).unwrap();
        assert_eq!(
            (parsed.request.scene.width, parsed.request.scene.sun_elevation, parsed.check),
            (256, Some(-3.5), true)
        );
        assert!(job_arguments(&json!({ "output": "a.png" })).unwrap_err().contains("scene"));
        assert!(job_arguments(&json!({ "scene": "a", "output": "b.png", "width": { "x": 1 } })).is_err());
        assert!(RenderArgs::parse_list(
            &job_arguments(&json!({ "scene": "a", "output": "b.png", "nope": 1 })).unwrap()
        )
        .is_err());
    }

    #[test]
    fn shards() {
        assert_eq!(parse_shard("0/3"), Ok((0, 3)));
        assert_eq!(parse_shard("2/3"), Ok((2, 3)));
        assert!(parse_shard("3/3").is_err() && parse_shard("1/0").is_err() && parse_shard("x").is_err());
        for (pattern, text, want) in [
            ("pot", "teapot-sunset", true),
            ("tea*set", "teapot-sunset", true),
            ("tea*", "a-teapot", false),
            ("*pot?sun*", "teapot-sunset", true),
            ("?", "", false),
            ("*", "", true),
            ("x", "teapot", false),
        ] {
            assert_eq!(matches_pattern(pattern, text), want, "{pattern} {text}");
        }
        let run = |filter: Option<&str>, shard| RunArgs { shard, no_cache: false, filter: filter.map(String::from) };
        let names: Vec<String> = ["a1", "b1", "a2", "a3"].map(String::from).to_vec();
        assert_eq!(run(Some("a"), None).mine(&names), [0, 2, 3]);
        assert_eq!(run(Some("a"), Some((1, 2))).mine(&names), [2]);
        assert_eq!(run(None, Some((0, 2))).mine(&names), [0, 2]);
    }
}

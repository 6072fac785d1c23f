//! `sunshade test SUITE`: golden-image tests from a suite file.
//!
//! The suite is a JSON object `{"tolerances": {...}, "cases": [...]}` (or just the array of cases). A case is a
//! batch job without `output` ([`super::batch`]: `scene` and `render`'s flags by their long names) plus `name`,
//! `golden` (an EXR path, or `"reference"` to compare with the CPU reference rendered with the device's sub-pixel
//! bits) and optional `tolerances` (the flags of `diff`, e.g. `{"fail-rel": 1e-4, "fail-count": 3}`, over the
//! suite's). Paths are relative to the suite file. A missing golden fails; `--update` writes the missing and failing
//! goldens, `--update-all` every one; `--filter` runs the cases whose name matches. A failed
//! case leaves its actual image (`NAME.actual.exr`) and heatmap (`NAME.heatmap.png`) in the results folder
//! (`--report DIR`, else `SUITE-results/` next to the suite). `--junit FILE` writes JUnit XML; `--report DIR`
//! an HTML page with each case's golden, actual and heatmap side by side. Exit 0 when every case passes.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, Parser};
use serde_json::{Map, Value};

use super::batch::{job_arguments, RunArgs};
use super::diff::ToleranceArgs;
use super::render::{cache_dir, checked_reference_of, render_job, RenderArgs};
use super::session::Session;
use super::{clap_error_line, CliError};
use crate::compare::{self, DiffReport};
use crate::film::{
    auto_exposure_ev, read_image, read_recorded, write_atomically, write_image, write_image_with, Exposure, Image,
    Metadata,
};

#[derive(Args, Debug)]
pub struct TestArgs {
    /// The suite file (JSON).
    pub suite: PathBuf,
    /// Write the goldens that are missing or fail, from the rendered images (a passing golden is kept; cases
    /// against "reference" have none).
    #[arg(long)]
    pub update: bool,
    /// Write every case's golden from its rendered image, the passing ones too.
    #[arg(long)]
    pub update_all: bool,
    /// Write the results as JUnit XML to FILE.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// Write an HTML report (index.html with each case's golden, actual and heatmap) and the failures' images to
    /// DIR.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub run: RunArgs,
    /// Print only failures and the summary.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Parser, Debug)]
#[command(name = "tolerances", allow_negative_numbers = true, no_binary_name = true)]
struct Tolerances {
    #[command(flatten)]
    t: ToleranceArgs,
}

/// Where a case's expected image comes from.
enum Expected {
    Golden(PathBuf),
    Reference,
}

struct Case {
    name: String,
    expected: Expected,
    tolerances: ToleranceArgs,
    args: RenderArgs,
}

enum Status {
    Passed,
    Updated,
    Failed(String),
    Error(String),
}

impl Status {
    /// A failed comparison or a case that could not run: either makes the suite fail.
    fn is_failure(&self) -> bool {
        matches!(self, Status::Failed(_) | Status::Error(_))
    }
}

struct Outcome {
    name: String,
    status: Status,
    seconds: f64,
    report: Option<DiffReport>,
    /// Preview PNGs for the HTML report, file names in the results folder.
    previews: Option<[String; 3]>,
}

fn parse_tolerances(suite: Option<&Value>, case: Option<&Value>) -> Result<ToleranceArgs, String> {
    let mut merged = Map::new();
    for t in [suite, case].into_iter().flatten() {
        let o = t.as_object().ok_or("\"tolerances\" must be an object of diff's flags")?;
        merged.extend(o.clone());
    }
    let mut argv = job_arguments(&Value::Object({
        let mut m = merged;
        m.insert("scene".into(), Value::String(String::new()));
        m.insert("output".into(), Value::String(String::new()));
        m
    }))?;
    argv.drain(..3); // scene, --output, output
    Tolerances::try_parse_from(&argv).map(|t| t.t).map_err(|e| format!("tolerances: {}", clap_error_line(&e)))
}

/// The cases of a suite, each parsed or the reason it cannot be (named by its index when it has no name).
/// A case that could not be read: its name (or "case N") and why.
type BadCase = (String, String);

fn read_suite(path: &Path, results: &Path) -> Result<Vec<Result<Case, BadCase>>, CliError> {
    let fail = |m: String| CliError::Failure(anyhow::anyhow!("{}: {m}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let value: Value = serde_json::from_str(&text).map_err(|e| fail(format!("invalid JSON: {e}")))?;
    let (suite_tolerances, cases) = match &value {
        Value::Array(cases) => (None, cases),
        Value::Object(o) => (
            o.get("tolerances"),
            o.get("cases").and_then(Value::as_array).ok_or_else(|| fail("needs \"cases\": an array".into()))?,
        ),
        _ => return Err(fail("a suite is an object with \"cases\", or an array of cases".into())),
    };
    let base = path.parent().unwrap_or(Path::new("."));
    let resolve = |p: &str| if Path::new(p).is_absolute() { PathBuf::from(p) } else { base.join(p) };
    let mut names = std::collections::HashSet::new();
    Ok(cases
        .iter()
        .enumerate()
        .map(|(i, case)| {
            let obj = case.as_object().ok_or_else(|| (format!("case {i}"), "a case must be an object".to_string()))?;
            let name =
                obj.get("name").and_then(Value::as_str).map(str::to_string).unwrap_or_else(|| format!("case {i}"));
            let bad = |m: String| (name.clone(), m);
            if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)) {
                return Err(bad("\"name\" must be letters, digits, '-', '_' or '.' (it names result files)".into()));
            }
            if !names.insert(name.clone()) {
                return Err(bad("another case has this name".into()));
            }
            let expected = match obj.get("golden").and_then(Value::as_str) {
                Some("reference") => Expected::Reference,
                Some(g) => Expected::Golden(resolve(g)),
                None => return Err(bad("needs \"golden\": an image path or \"reference\"".into())),
            };
            let tolerances = parse_tolerances(suite_tolerances, obj.get("tolerances")).map_err(bad)?;
            let mut job = obj.clone();
            for k in ["name", "golden", "tolerances"] {
                job.remove(k);
            }
            if job.contains_key("output") {
                return Err(bad("a case has no \"output\" (failures are written to the results folder)".into()));
            }
            let scene = job.get("scene").and_then(Value::as_str).ok_or_else(|| bad("needs \"scene\"".into()))?;
            job.insert("scene".into(), Value::String(resolve(scene).display().to_string()));
            job.insert(
                "output".into(),
                Value::String(results.join(format!("{name}.actual.exr")).display().to_string()),
            );
            let argv = job_arguments(&Value::Object(job)).map_err(bad)?;
            let args = RenderArgs::parse_list(&argv).map_err(bad)?;
            Ok(Case { name, expected, tolerances, args })
        })
        .collect())
}

pub fn run(a: &TestArgs) -> Result<(), CliError> {
    let stem = a.suite.file_stem().map_or("suite".into(), |s| s.to_string_lossy().into_owned());
    let results = a.report.clone().unwrap_or_else(|| a.suite.with_file_name(format!("{stem}-results")));
    if let Some(j) = &a.junit {
        super::check_folder_exists(j)?;
    }
    let cases = read_suite(&a.suite, &results)?;
    // Made before any case runs: each case's --output lies in it, and render checks an output's folder first.
    std::fs::create_dir_all(&results).map_err(|e| CliError::Usage(format!("{}: {e}", results.display())))?;
    let mut session = Session::new(cache_dir(a.run.no_cache));
    let started = Instant::now();
    let mut outcomes = Vec::new();
    let names: Vec<String> =
        cases.iter().map(|c| c.as_ref().map_or_else(|(name, _)| name.clone(), |c| c.name.clone())).collect();
    for case in a.run.mine(&names).into_iter().map(|i| &cases[i]) {
        let t = Instant::now();
        let mut outcome = match case {
            Err((name, e)) => Outcome {
                name: name.clone(),
                status: Status::Error(e.clone()),
                seconds: 0.0,
                report: None,
                previews: None,
            },
            Ok(case) => run_case(&mut session, case, a, &results),
        };
        outcome.seconds = t.elapsed().as_secs_f64();
        let line = match &outcome.status {
            Status::Passed => format!("PASS {}", outcome.name),
            Status::Updated => format!("UPDATED {}", outcome.name),
            Status::Failed(m) => format!("FAIL {}: {m}", outcome.name),
            Status::Error(m) => format!("ERROR {}: {m}", outcome.name),
        };
        if !a.quiet || outcome.status.is_failure() {
            println!("{line}");
        }
        outcomes.push(outcome);
    }
    let failed = outcomes.iter().filter(|o| o.status.is_failure()).count();
    let passed = outcomes.len() - failed;
    if let Some(path) = &a.junit {
        let xml = junit(&stem, &outcomes, started.elapsed().as_secs_f64());
        write_atomically(path, |w| std::io::Write::write_all(w, xml.as_bytes()))
            .map_err(|e| CliError::Failure(anyhow::anyhow!("{}: {e}", path.display())))?;
    }
    if a.report.is_some() {
        let page = html(&stem, &outcomes);
        let index = results.join("index.html");
        write_atomically(&index, |w| std::io::Write::write_all(w, page.as_bytes()))
            .map_err(|e| CliError::Failure(anyhow::anyhow!("{}: {e}", index.display())))?;
    }
    println!("{passed} passed, {failed} failed");
    if failed > 0 {
        Err(CliError::Quiet(1))
    } else {
        Ok(())
    }
}

fn run_case(session: &mut Session, case: &Case, a: &TestArgs, results: &Path) -> Outcome {
    // read_suite made the case's --output the results folder's NAME.actual.exr. A previous run's actual image and
    // heatmap of this case go first, so that what the folder holds is this run's.
    let actual = &case.args.output.output;
    let heatmap = results.join(format!("{}.heatmap.png", case.name));
    for stale in [actual, &heatmap] {
        let _ = std::fs::remove_file(stale);
    }
    let mut outcome =
        Outcome { name: case.name.clone(), status: Status::Passed, seconds: 0.0, report: None, previews: None };
    let job = match render_job(session, &case.args) {
        Ok(job) => job,
        Err(e) => {
            outcome.status = Status::Error(e.message());
            return outcome;
        }
    };
    // What a golden records of its render (lights, settings, renderer), written with it and compared on failure.
    let recorded = super::metadata::of_render(&job.render.settings, &session.renderer_description(job.renderer));
    let write_golden = |path: &Path| write_image_with(&job.render.image, path, Exposure::Auto, &recorded).map(|_| ());
    let mut apart = None;
    let expected = match &case.expected {
        Expected::Reference => {
            let (image, class) = checked_reference_of(session, &case.args, &job);
            apart = class;
            image
        }
        Expected::Golden(path) if a.update_all || (a.update && !path.exists()) => {
            // The golden's folder is made where it does not exist yet (a suite's first --update).
            let folder = path.parent().filter(|p| !p.as_os_str().is_empty());
            let made = folder.map_or(Ok(()), |f| {
                std::fs::create_dir_all(f).map_err(|e| format!("{}: cannot create the folder: {e}", f.display()))
            });
            outcome.status = match made.and_then(|_| write_golden(path).map_err(|e| e.to_string())) {
                Ok(_) => Status::Updated,
                Err(e) => Status::Error(e),
            };
            return outcome;
        }
        Expected::Golden(path) if !path.exists() => {
            outcome.status = Status::Failed(format!("golden {} is missing (--update writes it)", path.display()));
            // A result file that cannot be written does not change the outcome, which is already a failure.
            let _ = write_image(&job.render.image, actual, Exposure::Auto);
            return outcome;
        }
        Expected::Golden(path) => match read_image(path) {
            Ok(img) => img,
            Err(e) => {
                outcome.status = Status::Error(e.to_string());
                return outcome;
            }
        },
    };
    let apart = apart.as_ref().map(|c| (c.mask.as_slice(), c.name, c.allowed_fraction));
    let compared = compare::diff_apart(&job.render.image, &expected, &case.tolerances.options(), apart);
    // --update: a golden that fails (or cannot be compared: another size) is rewritten from this image.
    if let (Expected::Golden(path), true) = (&case.expected, a.update || a.update_all) {
        if !compared.as_ref().is_ok_and(|(report, _)| report.pass) {
            outcome.status = match write_golden(path) {
                Ok(()) => Status::Updated,
                Err(e) => Status::Error(e.to_string()),
            };
            return outcome;
        }
    }
    let (report, per_pixel) = match compared {
        Ok(r) => r,
        Err(e) => {
            outcome.status = Status::Failed(e);
            return outcome;
        }
    };
    if !report.pass {
        let changed = match &case.expected {
            Expected::Golden(path) => format!("; {}", recorded_changes(path, &recorded)),
            Expected::Reference => String::new(),
        };
        let flip = match (&report.flip, report.options.fail_flip) {
            (Some(f), Some(t)) => format!(", FLIP mean {:.4} (allowed {t})", f.mean),
            _ => String::new(),
        };
        outcome.status = Status::Failed(format!(
            "{} px over tolerance, {} coverage mismatches, max rel {:.3e}{flip} (actual: {}, heatmap: {}){changed}",
            report.over_tolerance.total,
            report.coverage_mismatches.total,
            report.max_rel,
            actual.display(),
            heatmap.display()
        ));
        let _ = write_image(&job.render.image, actual, Exposure::Auto);
    }
    if a.report.is_some() || !report.pass {
        let _ = compare::write_heatmap(&heatmap, job.render.image.width(), job.render.image.height(), &per_pixel);
    }
    if a.report.is_some() {
        outcome.previews = previews(&case.name, &expected, &job.render.image, results);
    }
    outcome.report = Some(report);
    outcome
}

/// What the golden at `golden` records of its render against this render's `now` (the lights, the settings with the
/// camera, the renderer with its device and driver, sunshade's version): "settings as recorded: PATH: GOLDEN →
/// NOW; ..." for those that differ (at most 8 named), or why there is nothing to compare.
fn recorded_changes(golden: &Path, now: &Metadata) -> String {
    const COMPARED: [&str; 3] = ["sunshadeLights", "sunshadeSettings", "sunshadeVersion"];
    let Some(then) = read_recorded(golden) else {
        return "the golden records no settings (--update rewrites it with them)".into();
    };
    let (mut was, mut is) = (Vec::new(), Vec::new());
    for key in COMPARED {
        flatten(key, then.get(key).unwrap_or(&Value::Null), &mut was);
        let current = now.text.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str()).unwrap_or("null");
        let current = serde_json::from_str(current).unwrap_or_else(|_| Value::String(current.to_string()));
        flatten(key, &current, &mut is);
    }
    let mut keys: Vec<&String> = was.iter().chain(&is).map(|(k, _)| k).collect();
    keys.sort();
    keys.dedup();
    let value = |list: &[(String, String)], k: &str| {
        list.iter().find(|(key, _)| key == k).map_or("(none)".to_string(), |(_, v)| v.clone())
    };
    let differ: Vec<String> = keys
        .into_iter()
        .filter_map(|k| {
            let (a, b) = (value(&was, k), value(&is, k));
            (a != b).then(|| format!("{}: {a} → {b}", k.trim_start_matches("sunshade")))
        })
        .collect();
    match differ.len() {
        0 => "settings as recorded: the same as the golden's".into(),
        n if n > 8 => format!("settings as recorded (golden → now): {}; and {} more", differ[..8].join("; "), n - 8),
        _ => format!("settings as recorded (golden → now): {}", differ.join("; ")),
    }
}

/// `value` as (dotted path, compact JSON) leaves; arrays of numbers stay one leaf, as written.
fn flatten(path: &str, value: &Value, out: &mut Vec<(String, String)>) {
    match value {
        Value::Object(o) => o.iter().for_each(|(k, v)| flatten(&format!("{path}.{k}"), v, out)),
        Value::Array(a) if a.iter().any(|v| v.is_object()) => {
            a.iter().enumerate().for_each(|(i, v)| flatten(&format!("{path}[{i}]"), v, out))
        }
        v => out.push((path.to_string(), v.to_string())),
    }
}

/// PNGs of the expected and actual images at one exposure (the expected image's auto exposure), and the heatmap.
fn previews(name: &str, expected: &Image, actual: &Image, results: &Path) -> Option<[String; 3]> {
    let ev = Exposure::Ev(auto_exposure_ev(expected));
    let files = [format!("{name}.expected.png"), format!("{name}.actual.png"), format!("{name}.heatmap.png")];
    write_image(expected, &results.join(&files[0]), ev).ok()?;
    write_image(actual, &results.join(&files[1]), ev).ok()?;
    Some(files)
}

/// A row comparing the golden (left of the slider) and the actual image (right of it) in place, at full size and
/// zoomed by whole factors without smoothing; open for a failure, folded for a pass.
fn compare_row(expected: &str, actual: &str, open: bool) -> String {
    let (e, a) = (escape(expected), escape(actual));
    format!(
        "<tr><td colspan=\"5\"><details{}><summary>golden and actual at full size, in place</summary>\
         <div class=\"compare\"><p>golden ◀ <input type=\"range\" min=\"0\" max=\"100\" value=\"50\" \
         oninput=\"slide(this)\" aria-label=\"golden and actual\"> ▶ actual &nbsp; zoom <select onchange=\"zoom(this)\" \
         aria-label=\"zoom\"><option value=\"1\">1×</option><option value=\"2\">2×</option><option value=\"4\">4×</option>\
         <option value=\"8\">8×</option></select></p><div class=\"cmp\"><img src=\"{e}\" alt=\"golden {e}\">\
         <img class=\"top\" src=\"{a}\" alt=\"actual {a}\"></div></div></details></td></tr>\n",
        if open { " open" } else { "" }
    )
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;").replace('\'', "&apos;")
}

fn junit(suite: &str, outcomes: &[Outcome], seconds: f64) -> String {
    let failures = outcomes.iter().filter(|o| matches!(o.status, Status::Failed(_))).count();
    let errors = outcomes.iter().filter(|o| matches!(o.status, Status::Error(_))).count();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<testsuites><testsuite name=\"{}\" tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\" time=\"{seconds:.3}\">",
        escape(suite),
        outcomes.len()
    );
    for o in outcomes {
        let _ = write!(
            x,
            "  <testcase classname=\"sunshade.{}\" name=\"{}\" time=\"{:.3}\"",
            escape(suite),
            escape(&o.name),
            o.seconds
        );
        match &o.status {
            Status::Passed | Status::Updated => x += "/>\n",
            Status::Failed(m) => {
                let _ = writeln!(
                    x,
                    "><failure message=\"{}\">{}</failure></testcase>",
                    escape(m),
                    escape(&o.report.as_ref().map(|r| r.text("actual", "expected")).unwrap_or_default())
                );
            }
            Status::Error(m) => {
                let _ = writeln!(x, "><error message=\"{}\"/></testcase>", escape(m));
            }
        }
    }
    x += "</testsuite></testsuites>\n";
    x
}

fn html(suite: &str, outcomes: &[Outcome]) -> String {
    let failed = outcomes.iter().filter(|o| o.status.is_failure()).count();
    let mut h = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>sunshade test: {s}</title><style>\
         body{{font-family:sans-serif;margin:2em;background:#fafafa}} table{{border-collapse:collapse}} \
         td,th{{border:1px solid #ccc;padding:6px;vertical-align:top;text-align:left}} \
         .pass{{color:#1a7f37;font-weight:bold}} .fail{{color:#b42318;font-weight:bold}} \
         img{{image-rendering:pixelated;width:192px;background:repeating-conic-gradient(#ddd 0 25%,#fff 0 50%) 0 0/16px 16px}} \
         img.heatmap{{width:auto;max-width:480px;background:none}} \
         .cmp{{position:relative;display:inline-block;line-height:0}} .cmp img{{width:auto;display:block}} \
         .cmp img.top{{position:absolute;left:0;top:0;clip-path:inset(0 0 0 50%)}} \
         code{{font-size:85%}}</style><script>\
         function slide(e){{const c=e.closest('.compare');c.querySelector('img.top').style.clipPath='inset(0 0 0 '+e.value+'%)';}}\
         function zoom(e){{const c=e.closest('.compare');c.querySelectorAll('.cmp img').forEach(i=>{{i.style.width=(i.naturalWidth*e.value)+'px';}});}}\
         </script></head><body>\n<h1>sunshade test: {s}</h1>\n<p>{} passed, {failed} failed</p>\n\
         <table><tr><th>case</th><th>result</th><th>golden / reference</th><th>actual</th><th>heatmap (log<sub>10</sub> relative error)</th></tr>\n",
        outcomes.len() - failed,
        s = escape(suite)
    );
    // Failures first: what needs a look is at the top.
    let failures_first =
        outcomes.iter().filter(|o| o.status.is_failure()).chain(outcomes.iter().filter(|o| !o.status.is_failure()));
    for o in failures_first {
        let (class, text) = match &o.status {
            Status::Passed => ("pass", "PASS".to_string()),
            Status::Updated => ("pass", "UPDATED".to_string()),
            Status::Failed(m) => ("fail", format!("FAIL: {m}")),
            Status::Error(m) => ("fail", format!("ERROR: {m}")),
        };
        let metrics = o.report.as_ref().map_or(String::new(), |r| {
            let flip = r.flip.map_or(String::new(), |f| format!(", FLIP mean {:.4}", f.mean));
            format!(
                "<br><code>max rel {:.2e}, RMSE {:.2e}, {} px over, {} coverage{flip}</code>",
                r.max_rel, r.rmse, r.over_tolerance.total, r.coverage_mismatches.total
            )
        });
        let _ = write!(h, "<tr><td>{}</td><td class=\"{class}\">{}{metrics}</td>", escape(&o.name), escape(&text));
        match &o.previews {
            Some(files) => {
                for (i, f) in files.iter().enumerate() {
                    let class = if i == 2 { " class=\"heatmap\"" } else { "" };
                    let _ = write!(h, "<td><img{class} src=\"{}\" alt=\"{}\"></td>", escape(f), escape(f));
                }
            }
            None => h += "<td colspan=\"3\">no images</td>",
        }
        h += "</tr>\n";
        if let Some(files) = &o.previews {
            h += &compare_row(&files[0], &files[1], o.status.is_failure());
        }
    }
    h += "</table>\n</body></html>\n";
    h
}

//! The command line as a user runs it: exit codes, one-line errors naming the file, no half-written output.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{bits, CheckedRenderer, TempDir};
use glam::Vec3;
use serde_json::json;
use sunshade::authoring::shapes::{cube, quad};
use sunshade::authoring::{GltfBuilder, Node};

fn sunshade(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunshade"))
        .args(args)
        .env("SUNSHADE_VALIDATION", "1")
        .output()
        .expect("run sunshade")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn scene() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = b.add_material("m", [0.5; 3], false, None);
    let mesh =
        b.add_mesh("cube", &[cube(0.5).primitive(Some(m)), quad(Vec3::ZERO, Vec3::X, Vec3::Z).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    b
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn renders_every_output_format_atomically() {
    let dir = TempDir::new("cli-ok");
    let input = dir.write("scene.glb", &scene());
    for out in ["out.exr", "out.pfm", "out.png"] {
        let o = sunshade(&["render", s(&input), "-o", s(&dir.path(out)), "--width", "64", "--height", "48", "-v"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        for phase in ["instance", "shader compile", "upload", "render", "readback", "encode"] {
            assert!(err.contains(phase), "-v does not print {phase}: {err}");
        }
        let img = sunshade::film::read_image(&dir.path(out)).unwrap();
        assert_eq!((img.width(), img.height()), (64, 48));
    }
    // Nothing but the scene, its outputs: no temporary files left behind.
    assert_eq!(dir.files(), ["out.exr", "out.pfm", "out.png", "scene.glb"]);
}

/// Runs a render that must fail: exit code, one line naming `names`, and no output file.
fn assert_refused(dir: &TempDir, input: &Path, extra: &[&str], code: i32, names: &str) {
    let out = dir.path("refused.exr");
    let mut args = vec!["render", s(input), "-o", s(&out)];
    args.extend_from_slice(extra);
    let o = sunshade(&args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(code), "{err}");
    assert!(err.contains(names), "message does not name '{names}': {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "output written despite the error");
    assert!(dir.files().iter().all(|f| !f.contains("sunshade-tmp")), "temporary file left behind");
}

#[test]
fn broken_inputs_exit_non_zero_with_a_message_and_no_output() {
    let dir = TempDir::new("cli-broken");
    let good = scene();
    let glb = good.to_glb();
    let truncated = dir.path("truncated.glb");
    std::fs::write(&truncated, &glb[..glb.len() - 40]).unwrap();
    assert_refused(&dir, &truncated, &[], 1, "truncated.glb");

    let bad_json = dir.path("bad.gltf");
    std::fs::write(&bad_json, "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [").unwrap();
    assert_refused(&dir, &bad_json, &[], 1, "bad.gltf");

    let mut doc = good.document(Some("index.bin"));
    std::fs::write(dir.path("index.bin"), good.bin()).unwrap();
    let last = doc["accessors"].as_array().unwrap().len() - 1;
    doc["accessors"][last]["count"] = json!(100000);
    let index = dir.path("index.gltf");
    std::fs::write(&index, doc.to_string()).unwrap();
    assert_refused(&dir, &index, &[], 1, "index.gltf");

    let doc = good.document(Some("gone.bin"));
    let missing = dir.path("missing.gltf");
    std::fs::write(&missing, doc.to_string()).unwrap();
    assert_refused(&dir, &missing, &[], 1, "gone.bin");

    assert_refused(&dir, &dir.path("nothing.glb"), &[], 1, "nothing.glb");
}

#[test]
fn bad_usage_exits_2() {
    let dir = TempDir::new("cli-usage");
    let input = dir.write("scene.glb", &scene());
    assert_refused(&dir, &input, &["--sun-dir", "0,0,0"], 2, "--sun-dir");
    assert_refused(&dir, &input, &["--sun-dir", "1,2"], 2, "--sun-dir");
    assert_refused(&dir, &input, &["--width", "0"], 2, "--width");
    assert_refused(&dir, &input, &["--camera", "4"], 2, "--camera 4");
    assert_refused(&dir, &input, &["--eye", "1,1,1", "--target", "1,1,1"], 2, "--eye");
    let o = sunshade(&["render", s(&input), "-o", s(&dir.path("x.tiff"))]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("x.tiff"));
}

#[test]
fn impossible_sizes_are_refused_clearly() {
    let dir = TempDir::new("cli-size");
    let input = dir.write("scene.glb", &scene());
    assert_refused(&dir, &input, &["--width", "100000", "--height", "8"], 1, "100000x8");
    // 16384² RGBA32F is 4 GiB: over lavapipe's 2 GiB allocation limit.
    assert_refused(&dir, &input, &["--width", "16384", "--height", "16384"], 1, "16384x16384");
}

#[test]
fn info_lists_the_chosen_device() {
    let o = sunshade(&["info"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("subPixelPrecisionBits"), "{out}");
    assert!(out.contains("chosen: device"), "{out}");
    let o = sunshade(&["info", "--device", "no-such-device"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("no-such-device"));
}

/// Runs sunshade with the Vulkan loader pointed at a driver list that does not exist: no device at all.
fn sunshade_without_vulkan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunshade"))
        .args(args)
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env_remove("SUNSHADE_VALIDATION")
        .output()
        .expect("run sunshade")
}

#[test]
fn reference_needs_no_vulkan_and_render_says_what_to_install() {
    let dir = TempDir::new("cli-novulkan");
    let input = dir.write("scene.glb", &scene());
    let out = dir.path("cpu.exr");
    let o = sunshade_without_vulkan(&["reference", s(&input), "-o", s(&out), "--width", "80", "--height", "60"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(sunshade::film::read_image(&out).unwrap().covered_count() > 100);
    let gpu_out = dir.path("gpu.exr");
    let o = sunshade_without_vulkan(&["render", s(&input), "-o", s(&gpu_out)]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("mesa-vulkan-drivers"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!gpu_out.exists());
}

#[test]
fn render_check_and_diff_agree_and_report() {
    let dir = TempDir::new("cli-check");
    let input = dir.write("scene.glb", &scene());
    let (gpu, cpu, heat) = (dir.path("gpu.exr"), dir.path("cpu.exr"), dir.path("heat.png"));
    // Unshadowed, so that the two commands agree on every device (without ray queries `render` casts no shadows;
    // tests/shadows.rs compares shadows where it does).
    let o = sunshade(&[
        "render",
        s(&input),
        "-o",
        s(&gpu),
        "--width",
        "160",
        "--height",
        "120",
        "--check",
        "--shadows",
        "none",
    ]);
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("result: PASS"));
    let o =
        sunshade(&["reference", s(&input), "-o", s(&cpu), "--width", "160", "--height", "120", "--shadows", "none"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = sunshade(&["diff", s(&gpu), s(&cpu), "--heatmap", s(&heat), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("diff --json prints JSON");
    assert_eq!(report["coverage_mismatches"]["total"], 0);
    assert!(report["max_rel"].as_f64().unwrap() <= 1e-5);
    assert!(heat.exists());
    // A changed image fails the diff with exit 1; a size mismatch or unreadable file is exit 2.
    let other = dir.path("other.exr");
    let o = sunshade(&[
        "reference",
        s(&input),
        "-o",
        s(&other),
        "--width",
        "160",
        "--height",
        "120",
        "--sun-irradiance",
        "1001",
    ]);
    assert!(o.status.success());
    assert_eq!(sunshade(&["diff", s(&gpu), s(&other)]).status.code(), Some(1));
    let small = dir.path("small.exr");
    assert!(sunshade(&["reference", s(&input), "-o", s(&small), "--width", "16", "--height", "12"]).status.success());
    let o = sunshade(&["diff", s(&gpu), s(&small)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("sizes differ"));
    let o = sunshade(&["diff", s(&gpu), s(&dir.path("absent.exr"))]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("absent.exr"));
}

#[test]
fn bench_reports_and_updates_a_marked_region() {
    let dir = TempDir::new("cli-bench");
    let input = dir.write("scene.glb", &scene());
    let doc = dir.path("doc.md");
    std::fs::write(
        &doc,
        "before\n<!-- sunshade bench: begin (generated; do not edit by hand) -->\nstale\n<!-- sunshade bench: end -->\nafter\n",
    )
    .unwrap();
    let o = sunshade(&[
        "bench",
        s(&input),
        "--width",
        "64",
        "--height",
        "48",
        "--repeat",
        "1",
        "--interpolation",
        "f64,device",
        "--update",
        s(&doc),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("| scene.glb | f64 |") && table.contains("| scene.glb | device |"), "{table}");
    let text = std::fs::read_to_string(&doc).unwrap();
    assert!(text.starts_with("before\n") && text.ends_with("<!-- sunshade bench: end -->\nafter\n"), "{text}");
    assert!(!text.contains("stale") && text.contains("| scene.glb | f64 |"), "{text}");
    // A document without the markers is refused and left alone.
    let plain = dir.path("plain.md");
    std::fs::write(&plain, "no markers\n").unwrap();
    let o = sunshade(&["bench", s(&input), "--width", "16", "--height", "16", "--repeat", "1", "--update", s(&plain)]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read_to_string(&plain).unwrap(), "no markers\n");
}

#[test]
fn bench_times_whole_processes_and_names_their_pipelines() {
    let dir = TempDir::new("cli-bench-process");
    let input = dir.write("scene.glb", &scene());
    let size = ["--width", "16", "--height", "16", "--repeat", "1"];
    let mut args = vec!["bench", s(&input), "--process-runs", "1"];
    args.extend_from_slice(&size);
    let o = sunshade(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    // The phases only: each pipeline's own line of `-v` is not one.
    assert!(out.contains("Phases (median, from `-v`):") && out.contains(" pipelines "), "{out}");
    assert!(!out.contains("sunshade:") && !out.contains("SPIR-V"), "{out}");
    let mut args = vec!["bench", "--startup", s(&input)];
    args.extend_from_slice(&size);
    let o = sunshade(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        out.contains("| pipeline | SPIR-V instructions | inlined | created in [ms] |") && out.contains("| Lambert · "),
        "{out}"
    );
}

#[test]
fn disk_light_and_sky_flags_light_a_floor_as_the_formulas_say() {
    let dir = TempDir::new("cli-lights");
    let mut b = GltfBuilder::new();
    let m = b.add_material("floor", [0.5; 3], false, None);
    let mesh = b
        .add_mesh("floor", &[quad(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -1.0)).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    let input = dir.write("floor.glb", &b);
    let out = dir.path("lit.exr");
    // Camera straight down at the floor's centre; a disk of R = 1 at height 2 above it; a sky of 10.
    let common = ["--eye", "0,5,0", "--target", "0,0,0", "--up", "0,0,-1", "--width", "33", "--height", "33"];
    let mut args =
        vec!["reference", s(&input), "-o", s(&out), "--disk-light", "0,2,0:0,-1,0:1:100", "--sky-radiance", "10"];
    args.extend_from_slice(&common);
    let o = sunshade(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = sunshade::film::read_image(&out).unwrap();
    // Centre pixel: (0.5/π)(π·100·1/(1 + 4) + π·10) = 0.5·(20 + 10) = 15.
    let centre = img.get(16, 16)[0] as f64;
    assert!((centre - 15.0).abs() < 1e-5 * 15.0, "{centre}");
    // With a disk light on the command line, no default sun is added; the same with the GPU and validation.
    let gpu_out = dir.path("gpu.exr");
    let mut args =
        vec!["render", s(&input), "-o", s(&gpu_out), "--disk-light", "0,2,0:0,-1,0:1:100", "--sky-radiance", "10"];
    args.extend_from_slice(&common);
    let o = sunshade(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let g = sunshade::film::read_image(&gpu_out).unwrap().get(16, 16)[0] as f64;
    assert!((g - 15.0).abs() < 1e-5 * 15.0, "{g}");
    assert_refused(&dir, &input, &["--disk-light", "0,2,0:0,0,0:1:100"], 2, "--disk-light");
    assert_refused(&dir, &input, &["--disk-model", "huge"], 2, "--disk-model");
}

#[test]
fn shaders_compile_at_run_time_from_sunshade_shader_dir_and_errors_name_the_line() {
    let dir = TempDir::new("shader-dir");
    let input = dir.write("scene.glb", &scene());
    let shaders = dir.path("shaders");
    std::fs::create_dir(&shaders).unwrap();
    // The whole tree (shaders/lights/ included), as a user's copy would be.
    let mut folders = vec![(Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders"), shaders.clone())];
    while let Some((from, to)) = folders.pop() {
        for e in std::fs::read_dir(&from).unwrap() {
            let e = e.unwrap();
            if e.path().is_dir() {
                std::fs::create_dir(to.join(e.file_name())).unwrap();
                folders.push((e.path(), to.join(e.file_name())));
            } else {
                std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
            }
        }
    }
    let out = dir.path("out.exr");
    let run = || {
        Command::new(env!("CARGO_BIN_EXE_sunshade"))
            .args(["render", s(&input), "-o", s(&out), "--width", "32", "--height", "24"])
            .env("SUNSHADE_VALIDATION", "1")
            .env("SUNSHADE_SHADER_DIR", &shaders)
            .output()
            .unwrap()
    };
    let ok = run();
    assert!(ok.status.success(), "{}", stderr(&ok));
    // The run-time compilation gives the image of the modules built ahead of time.
    let built_ahead = dir.path("ahead.exr");
    let o = sunshade(&["render", s(&input), "-o", s(&built_ahead), "--width", "32", "--height", "24"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&built_ahead).unwrap());
    std::fs::remove_file(&out).unwrap();
    let math = shaders.join("math.glsl");
    let text = std::fs::read_to_string(&math).unwrap();
    std::fs::write(&math, format!("{text}\nfloat broken = undefined_name;\n")).unwrap();
    let line = text.lines().count() + 2;
    let bad = run();
    let err = stderr(&bad);
    assert_eq!(bad.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("math.glsl:{line}")), "{err}");
    assert!(!out.exists());
    // A file in a subfolder is named by its path under the folder.
    std::fs::write(&math, text).unwrap();
    let sun = shaders.join("lights").join("sun.glsl");
    let text = std::fs::read_to_string(&sun).unwrap();
    std::fs::write(&sun, format!("{text}\nfloat broken = undefined_name;\n")).unwrap();
    let err = stderr(&run());
    assert!(err.contains(&format!("lights/sun.glsl:{}", text.lines().count() + 2)), "{err}");
}

#[test]
fn batch_renders_like_render_goes_on_after_a_failure_and_shards() {
    let dir = TempDir::new("batch");
    let input = dir.write("scene.glb", &scene());
    let out = |name: &str| dir.path(name).display().to_string();
    let jobs = json!([
        { "scene": s(&input), "output": out("a.exr"), "width": 40, "height": 30, "sun-elevation": -10, "sun-azimuth": 30 },
        { "scene": s(&dir.path("missing.glb")), "output": out("b.exr") },
        { "scene": s(&input), "output": out("c.png"), "width": 40, "height": 30, "brdf": "ward", "exposure": -3 },
        { "scene": s(&input), "output": out("d.exr"), "width": 40, "height": 30, "no-such-flag": 1 },
        { "scene": s(&input), "output": out("e.pfm"), "width": 24, "height": 24, "disk-light": ["0,2,0:0,-1,0:0.5:100"] },
    ]);
    let manifest = dir.path("jobs.json");
    std::fs::write(&manifest, jobs.to_string()).unwrap();
    let o = sunshade(&["batch", s(&manifest), "--jobs", "3"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("job 1") && err.contains("missing.glb"), "{err}");
    assert!(err.contains("job 3") && err.contains("no-such-flag"), "{err}");
    assert!(err.contains("2 of 5 jobs failed"), "{err}");
    // Bitwise the images of single render calls with the same flags.
    let single = |name: &str, extra: &[&str]| {
        let path = dir.path(name);
        let mut args = vec!["render", s(&input), "-o", s(&path)];
        args.extend_from_slice(extra);
        let o = sunshade(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(path).unwrap()
    };
    let a = single("ra.exr", &["--width", "40", "--height", "30", "--sun-elevation", "-10", "--sun-azimuth", "30"]);
    assert_eq!(std::fs::read(dir.path("a.exr")).unwrap(), a);
    let c = single("rc.png", &["--width", "40", "--height", "30", "--brdf", "ward", "--exposure", "-3"]);
    assert_eq!(std::fs::read(dir.path("c.png")).unwrap(), c);
    let e = single("re.pfm", &["--width", "24", "--height", "24", "--disk-light", "0,2,0:0,-1,0:0.5:100"]);
    assert_eq!(std::fs::read(dir.path("e.pfm")).unwrap(), e);
    assert!(!dir.path("b.exr").exists() && !dir.path("d.exr").exists());

    // Shards: 1/2 renders jobs 1 and 3 (both fail), 0/2 jobs 0, 2 and 4.
    for f in ["a.exr", "c.png", "e.pfm"] {
        std::fs::remove_file(dir.path(f)).unwrap();
    }
    let o = sunshade(&["batch", s(&manifest), "--shard", "1/2", "-q"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(!dir.path("a.exr").exists());
    let o = sunshade(&["batch", s(&manifest), "--shard", "0/2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("3 of 3 jobs rendered"), "{}", stderr(&o));
    assert_eq!(std::fs::read(dir.path("a.exr")).unwrap(), a);
    // --filter: the jobs whose output path matches (a glob here), numbered as in the manifest.
    std::fs::remove_file(dir.path("c.png")).unwrap();
    let o = sunshade(&["batch", s(&manifest), "--filter", "*.png"]);
    assert!(o.status.success() && stderr(&o).contains("1 of 1 jobs rendered"), "{}", stderr(&o));
    assert_eq!(std::fs::read(dir.path("c.png")).unwrap(), c);
    let o = sunshade(&["batch", s(&manifest), "--shard", "2/2"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    std::fs::write(&manifest, "{\"not\": \"an array\"}").unwrap();
    let o = sunshade(&["batch", s(&manifest)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("jobs.json") && stderr(&o).contains("array"), "{}", stderr(&o));
}

/// `sunshade` on Debian's own lavapipe (`system`: the Vulkan loader's variables and the library path that
/// `scripts/lavapipe-rt.sh` sets removed) or on Mesa 25's from `.lavapipe-rt/`.
fn sunshade_on(system: bool, args: &[&str]) -> Output {
    sunshade_command_on(system, args).output().expect("run sunshade")
}

/// Whether Mesa 25's lavapipe is installed in `.lavapipe-rt/` (`scripts/lavapipe-rt.sh` installs it if it can);
/// where it cannot, says so on the real stderr (not the test's captured output), so that the skip is never silent.
fn second_lavapipe_installed() -> bool {
    let install =
        Command::new("sh").arg("-c").arg("scripts/lavapipe-rt.sh").current_dir(env!("CARGO_MANIFEST_DIR")).output();
    let install = install.unwrap();
    if !install.status.success() {
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED: the lavapipe with ray queries cannot be installed here: {}",
            stderr(&install).trim()
        );
    }
    install.status.success()
}

/// The command of [`sunshade_on`], with validation on.
fn sunshade_command_on(system: bool, args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_sunshade"));
    c.args(args).env("SUNSHADE_VALIDATION", "1");
    let rt = Path::new(env!("CARGO_MANIFEST_DIR")).join(".lavapipe-rt");
    if system {
        c.env_remove("VK_ICD_FILENAMES").env_remove("VK_DRIVER_FILES").env_remove("LD_LIBRARY_PATH");
    } else {
        let icd = rt.join("lvp_icd.json");
        c.env("VK_ICD_FILENAMES", &icd).env("VK_DRIVER_FILES", &icd);
        c.env("LD_LIBRARY_PATH", rt.join("usr/lib/x86_64-linux-gnu"));
    }
    c
}

/// A golden rendered on one lavapipe passes on the other, both ways, the default flags (shadow rays: the sun's
/// through its cells on both, the disk light's by the BVH walk, on Mesa 25 by its ray queries where
/// `SUNSHADE_RAY_QUERIES=1` asks for them, as `make test`'s second stage does), and
/// each image passes `render --check` against the reference. Runs where `scripts/lavapipe-rt.sh` has installed
/// Mesa 25 (`make test`'s second stage, which names `gpu_`), else says why it cannot.
#[test]
fn gpu_goldens_move_between_lavapipes() {
    let rt = Path::new(env!("CARGO_MANIFEST_DIR")).join(".lavapipe-rt/lvp_icd.json");
    if !rt.exists() {
        eprintln!("gpu_goldens_move_between_lavapipes: no Mesa 25 lavapipe in .lavapipe-rt/ (scripts/lavapipe-rt.sh)");
        return;
    }
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let dir = TempDir::new("goldens-between-lavapipes");
    // Two different drivers: the system's (Debian 12's Mesa 22.3, or whatever the machine has) and Mesa 25's.
    let info = |system: bool| String::from_utf8_lossy(&sunshade_on(system, &["info"]).stdout).into_owned();
    let (system_info, rt_info) = (info(true), info(false));
    assert!(rt_info.contains("Mesa 25") && system_info != rt_info, "{system_info}\n{rt_info}");
    for (system, name) in [(true, "mesa22"), (false, "mesa25")] {
        let cases: Vec<_> = ["teapot.glb", "room.gltf"]
            .iter()
            .map(|m| json!({ "name": m, "scene": s(&models.join(m)), "width": 64, "height": 48, "golden": format!("{name}/{m}.exr") }))
            .collect();
        std::fs::write(dir.path(&format!("{name}.json")), json!({ "cases": cases }).to_string()).unwrap();
        let o = sunshade_on(system, &["test", s(&dir.path(&format!("{name}.json"))), "--update"]);
        assert!(o.status.success(), "{name} --update: {}{}", stderr(&o), String::from_utf8_lossy(&o.stdout));
        for m in ["teapot.glb", "room.gltf"] {
            let (scene, out) = (models.join(m), dir.path(&format!("{name}-{m}.exr")));
            let args = ["render", s(&scene), "-o", s(&out), "--width", "64", "--height", "48", "--check"];
            let o = sunshade_on(system, &args);
            assert!(o.status.success(), "{name} {m} --check: {}{}", stderr(&o), String::from_utf8_lossy(&o.stdout));
        }
    }
    // Each lavapipe's goldens, tested on the other.
    for (system, other) in [(true, "mesa25"), (false, "mesa22")] {
        let o = sunshade_on(system, &["test", s(&dir.path(&format!("{other}.json")))]);
        assert!(o.status.success(), "{other}'s goldens: {}{}", stderr(&o), String::from_utf8_lossy(&o.stdout));
    }
}

#[test]
fn test_suites_update_creates_the_goldens_folders() {
    let dir = TempDir::new("suite-folders");
    dir.write("scene.glb", &scene());
    let suite = dir.path("suite.json");
    let cases = json!({ "cases": [
        { "name": "a", "scene": "scene.glb", "width": 16, "height": 12, "golden": "goldens/new/a.exr" },
        { "name": "b", "scene": "scene.glb", "width": 16, "height": 12, "golden": "b.exr" }
    ]});
    std::fs::write(&suite, cases.to_string()).unwrap();
    let o = sunshade(&["test", s(&suite), "--update"]);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(out.contains("UPDATED a") && out.contains("UPDATED b"), "{out}{}", stderr(&o));
    assert!(dir.path("goldens/new/a.exr").exists() && dir.path("b.exr").exists());
    let o = sunshade(&["test", s(&suite)]);
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
}

#[test]
fn test_suites_fail_on_missing_goldens_update_them_and_report() {
    let dir = TempDir::new("suite");
    dir.write("scene.glb", &scene());
    let suite = dir.path("suite.json");
    let cases = json!({
        "tolerances": { "fail-count": 0 },
        "cases": [
            { "name": "golden", "scene": "scene.glb", "width": 32, "height": 24, "golden": "goldens/a.exr" },
            { "name": "ref", "scene": "scene.glb", "width": 32, "height": 24, "sun-elevation": 20, "golden": "reference" },
            { "name": "strict", "scene": "scene.glb", "width": 32, "height": 24, "golden": "goldens/b.exr",
              "tolerances": { "fail-rel": 1e-6 } }
        ]
    });
    std::fs::write(&suite, cases.to_string()).unwrap();
    std::fs::create_dir(dir.path("goldens")).unwrap();
    // Missing goldens fail (never a silent pass).
    let o = sunshade(&["test", s(&suite)]);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert_eq!(o.status.code(), Some(1), "{out}{}", stderr(&o));
    assert!(out.contains("FAIL golden") && out.contains("missing") && out.contains("PASS ref"), "{out}");
    assert!(out.contains("1 passed, 2 failed"), "{out}");
    let o = sunshade(&["test", s(&suite), "--update"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("UPDATED golden"));
    let o = sunshade(&["test", s(&suite), "--junit", s(&dir.path("j.xml")), "--report", s(&dir.path("report"))]);
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("3 passed, 0 failed"));
    let xml = std::fs::read_to_string(dir.path("j.xml")).unwrap();
    assert!(xml.contains("tests=\"3\" failures=\"0\" errors=\"0\"") && xml.contains("name=\"strict\""), "{xml}");
    let html = std::fs::read_to_string(dir.path("report/index.html")).unwrap();
    for f in ["golden.expected.png", "golden.actual.png", "golden.heatmap.png", "ref.expected.png"] {
        assert!(html.contains(f) && dir.path("report").join(f).exists(), "{f}");
    }
    // A changed image fails, and leaves the actual image and heatmap in the report folder.
    let other = dir.path("goldens/a.exr");
    let golden_of_a_sun_at_60 = || {
        let (scene, out) = (dir.path("scene.glb"), s(&other));
        let o = sunshade(&["render", s(&scene), "-o", out, "--width", "32", "--height", "24", "--sun-elevation", "60"]);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    golden_of_a_sun_at_60();
    let o = sunshade(&["test", s(&suite), "--report", s(&dir.path("report")), "--junit", s(&dir.path("j.xml"))]);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(out.contains("FAIL golden") && out.contains("px over tolerance"), "{out}");
    // The failure says what changed: the golden records its render's lights and settings (here its sun, 60° up).
    assert!(out.contains("settings as recorded (golden → now): Lights.sun.direction_towards_sun: ["), "{out}");
    assert!(!out.contains("Settings.width"), "only what differs is named: {out}");
    assert!(dir.path("report/golden.actual.exr").exists() && dir.path("report/golden.heatmap.png").exists());
    // The report compares the failing case's golden and actual in place at full size (a slider, a zoom), open;
    // the passing cases' comparisons are folded.
    let html = std::fs::read_to_string(dir.path("report/index.html")).unwrap();
    let failing = html.find("<details open>").expect("the failure's comparison is open");
    let block = &html[failing..html[failing..].find("</details>").unwrap() + failing];
    assert!(block.contains("type=\"range\"") && block.contains("onchange=\"zoom(this)\""), "{block}");
    assert!(block.contains("src=\"golden.expected.png\"") && block.contains("class=\"top\" src=\"golden.actual.png\""));
    assert_eq!(html.matches("<details>").count(), 2, "the passing cases fold theirs");
    let xml = std::fs::read_to_string(dir.path("j.xml")).unwrap();
    assert!(xml.contains("failures=\"1\"") && xml.contains("Lights.sun.direction_towards_sun"), "{xml}");
    // Shards: 1/3 runs only "ref".
    let o = sunshade(&["test", s(&suite), "--shard", "1/3"]);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(o.status.success() && out.contains("PASS ref") && !out.contains("golden"), "{out}");
    // --update rewrites the failing golden only; the passing one is kept as it was.
    let strict = dir.path("goldens/b.exr");
    let kept = std::fs::read(&strict).unwrap();
    let stamp = std::fs::metadata(&strict).unwrap().modified().unwrap();
    let o = sunshade(&["test", s(&suite), "--update", "--report", s(&dir.path("report"))]);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(o.status.success() && out.contains("UPDATED golden") && out.contains("PASS strict"), "{out}");
    assert_eq!(std::fs::metadata(&strict).unwrap().modified().unwrap(), stamp);
    // The run removed the previous run's actual image and heatmap of the case that failed then.
    assert!(!dir.path("report/golden.actual.exr").exists(), "a stale actual image is left");
    // --update-all rewrites every golden; --filter runs the matching cases (a substring or a glob).
    let o = sunshade(&["test", s(&suite), "--update-all", "--filter", "str*"]);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(o.status.success() && out.contains("UPDATED strict") && !out.contains("golden"), "{out}");
    assert!(out.contains("1 passed, 0 failed"), "{out}");
    assert_eq!(std::fs::read(&strict).unwrap(), kept, "the same image rewritten");
    let o = sunshade(&["test", s(&suite), "--filter", "re"]);
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(out.contains("PASS ref") && !out.contains("strict") && out.contains("1 passed"), "{out}");
    // FLIP in a suite: a golden of the sun at 60° against a render at the default 30°, within any relative
    // tolerance, fails on its mean FLIP where that is held low, and the failure says so.
    golden_of_a_sun_at_60();
    let flip_suite = |limit: f64| {
        let path = dir.path("flip.json");
        let case = json!([{ "name": "sun", "scene": "scene.glb", "width": 32, "height": 24, "golden": "goldens/a.exr",
                            "tolerances": { "fail-rel": 100, "fail-flip": limit } }]);
        std::fs::write(&path, case.to_string()).unwrap();
        let o = sunshade(&["test", s(&path)]);
        (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned())
    };
    let (code, out) = flip_suite(1e-3);
    assert!(code == Some(1) && out.contains("0 px over tolerance") && out.contains("FLIP mean"), "{out}");
    let (code, out) = flip_suite(0.99);
    assert!(code == Some(0) && out.contains("PASS sun"), "{out}");
}

#[test]
fn diff_reports_flip_fails_on_its_mean_and_writes_its_map() {
    let dir = TempDir::new("diff-flip");
    // A gradient, and the same with a bright square: FLIP sees the square, not the rest.
    let mut a = sunshade::Image::new(64, 48);
    for y in 0..48 {
        for x in 0..64 {
            let v = 1.0 + x as f32 / 8.0;
            a.set(x, y, [v, v, 0.5 * v, 1.0]);
        }
    }
    let mut b = a.clone();
    for y in 10..20 {
        for x in 10..20 {
            b.set(x, y, [40.0, 40.0, 40.0, 1.0]);
        }
    }
    let (pa, pb) = (dir.path("a.exr"), dir.path("b.exr"));
    sunshade::film::write_image(&a, &pa, sunshade::film::Exposure::Auto).unwrap();
    sunshade::film::write_image(&b, &pb, sunshade::film::Exposure::Auto).unwrap();
    let json = |extra: &[&str]| {
        let mut args = vec!["diff", s(&pa), s(&pb), "--fail-rel", "100", "--json"];
        args.extend_from_slice(extra);
        let o = sunshade(&args);
        (o.status.code(), serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap())
    };
    let (code, report) = json(&[]);
    let flip = &report["flip"];
    let mean = flip["mean"].as_f64().unwrap();
    assert_eq!((code, flip["kind"].as_str()), (Some(0), Some("hdr")), "{report}");
    // About 100 of 3072 pixels differ, strongly, and their neighbours a little.
    assert!(mean > 0.02 && mean < 0.2, "{report}");
    assert!(flip["max"].as_f64().unwrap() > 0.5 && flip["median"].as_f64().unwrap() < 1e-3, "{report}");
    assert!(flip["exposures"]["count"].as_u64().unwrap() >= 2, "{report}");
    let (code, report) = json(&["--fail-flip", &format!("{}", mean * 0.9)]);
    assert_eq!((code, report["pass"].as_bool()), (Some(1), Some(false)), "{report}");
    let (code, _) = json(&["--fail-flip", &format!("{}", mean * 1.1)]);
    assert_eq!(code, Some(0));
    // --no-flip skips it, and refuses to be asked for it.
    let (code, report) = json(&["--no-flip"]);
    assert!(code == Some(0) && report["flip"].is_null(), "{report}");
    assert_eq!(sunshade(&["diff", s(&pa), s(&pb), "--no-flip", "--fail-flip", "0.1"]).status.code(), Some(2));
    // The same pair against itself: FLIP 0.
    let o = sunshade(&["diff", s(&pa), s(&pa)]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("mean 0.0000"), "{}", String::from_utf8_lossy(&o.stdout));
    // The map: the images' size, dark where they agree, bright on the square.
    let map = dir.path("flip.png");
    assert_eq!(sunshade(&["diff", s(&pa), s(&pb), "--fail-rel", "100", "--flip-map", s(&map)]).status.code(), Some(0));
    let png = image::open(&map).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (64, 48));
    assert!(png.get_pixel(15, 15).0[0] > 200 && png.get_pixel(50, 40).0[0] < 10, "{:?}", png.get_pixel(15, 15));
    let o = sunshade(&["diff", s(&pa), s(&pb), "--flip-map", s(&dir.path("flip.exr"))]);
    assert!(o.status.code() == Some(2) && stderr(&o).contains("FLIP's error map is a PNG"), "{}", stderr(&o));
}

#[test]
fn diff_warns_allows_percentages_hard_fails_and_writes_the_difference_image() {
    let dir = TempDir::new("diff-levels");
    let mut a = sunshade::Image::new(10, 10);
    a.pixels_mut().iter_mut().for_each(|p| *p = [1.0, 1.0, 1.0, 1.0]);
    let mut b = a.clone();
    for x in 0..10 {
        b.set(x, 1, [1.01, 1.0, 1.0, 1.0]);
    }
    b.set(0, 0, [1.5, 1.0, 1.0, 1.0]);
    b.set(9, 9, [0.0, 0.0, 0.0, 0.0]);
    let (pa, pb) = (dir.path("a.exr"), dir.path("b.exr"));
    sunshade::film::write_image(&a, &pa, sunshade::film::Exposure::Auto).unwrap();
    sunshade::film::write_image(&b, &pb, sunshade::film::Exposure::Auto).unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["diff", s(&pa), s(&pb), "--fail-coverage", "1"];
        args.extend_from_slice(extra);
        let o = sunshade(&args);
        (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned())
    };
    assert_eq!(run(&["--fail-rel", "1e-3"]).0, Some(1));
    let (code, out) = run(&["--fail-rel", "1e-3", "--fail-percent", "12"]);
    assert!(code == Some(0) && out.contains("allowed 11"), "{out}");
    let (code, out) = run(&["--fail-rel", "1e-3", "--fail-percent", "12", "--hard-fail", "0.2"]);
    assert!(code == Some(1) && out.contains("over hard fail (rel > 2e-1): 1"), "{out}");
    let (code, out) = run(&["--fail-rel", "0.5", "--warn-rel", "1e-3"]);
    assert!(
        code == Some(0) && out.contains("result: WARN") && out.contains("over warn level (rel > 1e-3): 11"),
        "{out}"
    );
    let d = dir.path("d.exr");
    let (code, _) = run(&["--fail-rel", "0.5", "-o", s(&d)]);
    assert_eq!(code, Some(0));
    let diff = sunshade::film::read_image(&d).unwrap();
    assert_eq!(diff.get(0, 0), [0.5, 0.0, 0.0, 0.0]);
    assert_eq!(diff.get(9, 9), [1.0, 1.0, 1.0, 1.0], "a coverage mismatch shows in alpha");
    assert_eq!(run(&["-o", s(&dir.path("d.png"))]).0, Some(2));
}

#[test]
fn outputs_record_camera_lights_and_settings() {
    let dir = TempDir::new("metadata");
    let input = dir.write("scene.glb", &scene());
    let exr = dir.path("m.exr");
    let o = sunshade(&["render", s(&input), "-o", s(&exr), "--width", "64", "--height", "48", "--sky-radiance", "300"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let meta = exr::meta::MetaData::read_from_file(&exr, false).unwrap();
    let layer = &meta.headers[0].own_attributes;
    let all: serde_json::Value = match layer.other.get(&exr::prelude::Text::from("sunshade")) {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => serde_json::from_str(&t.to_string()).unwrap(),
        other => panic!("sunshade attribute: {other:?}"),
    };
    assert_eq!(layer.other.len(), 1, "one custom attribute, so that the header's bytes do not vary");
    let settings = &all["sunshadeSettings"];
    assert_eq!((settings["width"].as_u64(), settings["height"].as_u64()), (Some(64), Some(48)));
    assert!(settings["renderer"].as_str().unwrap().starts_with("gpu: "), "{settings}");
    assert_eq!(all["sunshadeLights"]["sky_radiance"], json!([300.0, 300.0, 300.0]));
    assert!(all["quantity"].as_str().unwrap().contains("W/(m2 sr)"));
    // worldToNDC (Imath: row vectors) takes a point straight ahead of the eye to the centre of the image.
    let m = layer.world_to_normalized_device.expect("worldToNDC");
    let eye: Vec<f64> = settings["camera"]["eye"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let fwd: Vec<f64> = settings["camera"]["forward"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let p: Vec<f64> = (0..3).map(|i| eye[i] + 2.0 * fwd[i]).chain([1.0]).collect();
    let clip: Vec<f64> = (0..4).map(|c| (0..4).map(|r| p[r] * m[r * 4 + c] as f64).sum()).collect();
    assert!((clip[0] / clip[3]).abs() < 1e-5 && (clip[1] / clip[3]).abs() < 1e-5, "{clip:?}");
    assert!(layer.world_to_camera.is_some());
    // The PNG carries the same settings as text.
    let png = dir.path("m.png");
    let o = sunshade(&["reference", s(&input), "-o", s(&png), "--width", "64", "--height", "48"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let reader = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap())).read_info().unwrap();
    let chunk = reader.info().uncompressed_latin1_text.iter().find(|t| t.keyword == "sunshadeSettings").unwrap();
    assert!(chunk.text.contains("\"renderer\":\"cpu reference\""), "{}", chunk.text);
    // `--quantity irradiance`: the unit W/m2, the layer and the settings say so, on the GPU and the reference.
    for command in ["render", "reference"] {
        let o = sunshade(&[
            command,
            s(&input),
            "-o",
            s(&exr),
            "--width",
            "32",
            "--height",
            "24",
            "--quantity",
            "irradiance",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let meta = exr::meta::MetaData::read_from_file(&exr, false).unwrap();
        let layer = &meta.headers[0].own_attributes;
        assert_eq!(layer.layer_name.as_ref().map(|n| n.to_string()), Some("irradiance".to_string()));
        let all: serde_json::Value = match layer.other.get(&exr::prelude::Text::from("sunshade")) {
            Some(exr::meta::attribute::AttributeValue::Text(t)) => serde_json::from_str(&t.to_string()).unwrap(),
            other => panic!("sunshade attribute: {other:?}"),
        };
        assert!(all["quantity"].as_str().unwrap().starts_with("irradiance W/m2"), "{all}");
        assert_eq!(all["sunshadeSettings"]["quantity"], "irradiance", "{all}");
        assert!(sunshade::film::read_image(&exr).is_ok(), "an irradiance EXR reads back");
    }
    // --false-color: a PNG of the picture and its legend below; only a .png, refused before any work.
    let fc = dir.path("e.png");
    let o = sunshade(&[
        "render",
        s(&input),
        "-o",
        s(&exr),
        "--width",
        "64",
        "--height",
        "48",
        "--quantity",
        "irradiance",
        "--false-color",
        s(&fc),
        "--false-color-max",
        "500",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let picture = image::open(&fc).unwrap().to_rgb8();
    assert_eq!(picture.dimensions(), (320, 48 + sunshade::plot::false_color::LEGEND_HEIGHT));
    let bad = dir.path("e.jpg");
    let o = sunshade(&["render", s(&input), "-o", s(&exr), "--false-color", s(&bad)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--false-color") && !bad.exists(), "{}", stderr(&o));
    // sum: two irradiance images add pixel by pixel (x + x = 2x exactly in f32), coverage kept; float images of
    // one size only, refused in one line naming the file.
    let (one, total) = (dir.path("one.exr"), dir.path("total.exr"));
    std::fs::copy(&exr, &one).unwrap();
    let o = sunshade(&["sum", s(&exr), s(&one), "-o", s(&total)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (x, t) = (sunshade::film::read_image(&exr).unwrap(), sunshade::film::read_image(&total).unwrap());
    assert!(x.pixels().iter().any(|p| p[3] > 0.0 && p[0] > 0.0));
    for (p, q) in x.pixels().iter().zip(t.pixels()) {
        assert_eq!([2.0 * p[0], 2.0 * p[1], 2.0 * p[2], p[3]], *q);
    }
    let small = dir.path("small.exr");
    let o = sunshade(&["render", s(&input), "-o", s(&small), "--width", "16", "--height", "16", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(&total).unwrap();
    let o = sunshade(&["sum", s(&exr), s(&small), "-o", s(&total)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("small.exr") && stderr(&o).lines().count() == 1 && !total.exists(), "{}", stderr(&o));
    let o = sunshade(&["sum", s(&exr), s(&fc), "-o", s(&total)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // --tolerance bounds radiance: refused with irradiance, in one line, nothing written.
    std::fs::remove_file(&exr).unwrap();
    let o = sunshade(&["render", s(&input), "-o", s(&exr), "--quantity", "irradiance", "--tolerance", "1e-3"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--tolerance") && stderr(&o).lines().count() == 1, "{}", stderr(&o));
    assert!(!exr.exists());
    // --tolerance holds in penumbrae unless --tolerance-outside-penumbrae: the two promises together, or either
    // without --tolerance, are usage errors, nothing written.
    for flags in [
        &["--tolerance", "1e-3", "--tolerance-outside-penumbrae", "--tolerance-in-penumbrae"][..],
        &["--tolerance-outside-penumbrae"][..],
        &["--tolerance-in-penumbrae"][..],
    ] {
        let o = sunshade(&[&["render", s(&input), "-o", s(&exr)][..], flags].concat());
        assert_eq!(o.status.code(), Some(2), "{flags:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("--tolerance"), "{flags:?}: {}", stderr(&o));
        assert!(!exr.exists());
    }
}

#[test]
fn the_converged_reference_says_how_far_it_got() {
    let dir = TempDir::new("converged-cli");
    let input = dir.write("scene.glb", &scene());
    let exr = dir.path("c.exr");
    let args = ["reference", s(&input), "-o", s(&exr), "--width", "32", "--height", "24", "--converged"];
    // A claim of 1e-9 after one doubling cannot be met: a warning names the pixels, the image is still written.
    let o = sunshade(&[&args[..], &["--accuracy", "1e-9", "--max-refinements", "1", "--sky-radiance", "300"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("warning: not converged to 1e-9 after 1 doublings"), "{}", stderr(&o));
    let meta = exr::meta::MetaData::read_from_file(&exr, false).unwrap();
    let all: serde_json::Value = match meta.headers[0].own_attributes.other.get(&exr::prelude::Text::from("sunshade")) {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => serde_json::from_str(&t.to_string()).unwrap(),
        other => panic!("sunshade attribute: {other:?}"),
    };
    assert_eq!(all["sunshadeConverged"]["accuracy"], json!(1e-9));
    assert!(all["sunshadeConverged"]["unconverged_pixels"].as_u64().unwrap() > 0);
    // The accuracy needs --converged.
    assert_eq!(sunshade(&["reference", s(&input), "-o", s(&exr), "--accuracy", "1e-3"]).status.code(), Some(2));
}

#[test]
fn bench_pareto_measures_each_setting_against_the_converged_reference() {
    let dir = TempDir::new("pareto");
    let material =
        sunshade::authoring::chart::brdf_chart().into_iter().find(|m| m.name == "Blinn-Phong e=100").unwrap();
    let input = dir.write("sphere.glb", &sunshade::authoring::chart::sphere_scene(&material));
    let plot = dir.path("front.png");
    let o = sunshade(&[
        "bench",
        "--pareto",
        s(&input),
        "--width",
        "24",
        "--height",
        "24",
        "--repeat",
        "1",
        "--accuracy",
        "1e-3",
        "--max-refinements",
        "4",
        "--json",
        "--plot",
        s(&plot),
        "--tolerance-in-penumbrae",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = json["tables"][0]["rows"].as_array().unwrap();
    let row = |prefix: &str| rows.iter().find(|r| r["setting"].as_str().unwrap().starts_with(prefix)).unwrap();
    // The sun as a disk (8² directions) is closer to the truth than the sun as a direction, for a lobe of e = 100.
    let (disk, delta) =
        (row("sun disk 8²")["max rel"].as_f64().unwrap(), row("sun delta")["max rel"].as_f64().unwrap());
    assert!(disk < delta, "disk {disk:e}, delta {delta:e}");
    assert!(rows.iter().any(|r| r["front (max)"] == "★"));
    assert!(rows.iter().all(|r| r["GPU frame [ms]"].as_f64().unwrap() > 0.0));
    // What `--tolerance` chose at 1e-2, 1e-3, 1e-4 (a sphere cannot shadow itself, so in penumbrae or not is the
    // same promise): each kept image meets its T against the same truth, and so does its prediction.
    let tolerance = json["tables"][1]["rows"].as_array().unwrap();
    assert_eq!(tolerance.len(), 3, "{}", json["tables"][1]);
    // Asked to hold T in penumbrae too (`--tolerance-in-penumbrae`), the table says so.
    let caption = json["tables"][1]["caption"].as_str().unwrap();
    assert!(caption.contains("--tolerance T --tolerance-in-penumbrae"), "{caption}");
    for r in tolerance {
        let t = r["T"].as_f64().unwrap();
        assert!(r["max rel"].as_f64().unwrap() <= t, "{r}");
        assert!(r["predicted"].as_f64().unwrap() <= t, "{r}");
        assert!(r["renders"].as_f64().unwrap() >= 1.0, "{r}");
    }
    let png = image::open(&plot).unwrap();
    assert_eq!((png.width(), png.height()), (1280, 400), "two charts: max and p99");
}

/// `bench --pareto`'s `--tolerance` table on a scene that shadows itself: every T is kept (shadow rays; on a device
/// without ray queries the shader's walk, the table at 64 pixels on the longer side against its own converged
/// reference), and each image meets T outside the penumbrae (what `--tolerance` promises without
/// `--tolerance-in-penumbrae`), its prediction too.
#[test]
fn bench_pareto_keeps_the_tolerance_of_a_scene_that_shadows_itself() {
    let o = sunshade(&[
        "bench",
        "--pareto",
        "models/teapot.glb",
        "--width",
        "80",
        "--height",
        "60",
        "--repeat",
        "1",
        "--max-refinements",
        "4",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let info = String::from_utf8_lossy(&sunshade(&["info"]).stdout).into_owned();
    let walk = info.lines().any(|l| l.contains("ray queries") && l.contains(": no"));
    let table = &json["tables"][1];
    let caption = table["caption"].as_str().unwrap();
    assert_eq!(caption.contains("at 64×48"), walk, "{info}\n{caption}");
    let rows = table["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3, "{table}");
    for r in rows {
        let t = r["T"].as_f64().unwrap();
        assert!(r["max rel outside penumbrae"].as_f64().is_some_and(|e| e <= t), "{r}");
        assert!(r["max rel"].as_f64().is_some(), "{r}");
        // † where the prediction names the penumbrae as not bounded.
        let predicted = r["predicted"].as_f64().or_else(|| r["predicted"].as_str()?.trim_end_matches('†').parse().ok());
        assert!(predicted.unwrap() <= t, "{r}");
    }
}

/// `bench --pareto --visibility slices`: the truth takes the lights' visible fractions by slices and converges in
/// the sun's penumbrae, where the grid's truth leaves pixels out of every error.
#[test]
fn bench_pareto_by_slices_leaves_no_penumbra_out() {
    let left_out = |rule: &str| {
        let o = sunshade(&[
            "bench",
            "--pareto",
            "models/sunset.glb",
            "--width",
            "48",
            "--height",
            "36",
            "--repeat",
            "1",
            "--max-refinements",
            "4",
            "--json",
            "--visibility",
            rule,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let caption = json["tables"][0]["caption"].as_str().unwrap().to_owned();
        assert!(caption.contains(&format!("visible fractions by {rule}")), "{caption}");
        let count = caption.split(" of ").next().unwrap().rsplit(' ').next().unwrap().parse::<u32>();
        count.unwrap_or_else(|e| panic!("{caption}: {e}"))
    };
    let (grid, slices) = (left_out("grid"), left_out("slices"));
    assert!(grid > 0, "the grid's truth converged everywhere: the test no longer compares anything");
    assert_eq!(slices, 0);
    // The rule needs --pareto.
    let o = sunshade(&["bench", "--visibility", "slices"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn renders_say_their_predicted_error_and_tolerance_chooses_the_sun() {
    let dir = TempDir::new("tolerance-cli");
    let material = sunshade::authoring::chart::brdf_chart().into_iter().find(|m| m.name == "Phong e=100").unwrap();
    let input = dir.write("sphere.glb", &sunshade::authoring::chart::sphere_scene(&material));
    let exr = dir.path("t.exr");
    // `--shadows none`: the bound is then against the unshadowed truth (a device without ray queries has no other).
    let base = ["render", s(&input), "-o", s(&exr), "--width", "32", "--height", "32", "-v", "--shadows", "none"];
    let predicted = |o: &Output| -> f64 {
        let line =
            stderr(o).lines().find(|l| l.starts_with("sunshade: predicted max relative error: ")).unwrap().to_string();
        line["sunshade: predicted max relative error: ".len()..].split(' ').next().unwrap().parse().unwrap()
    };
    let o = sunshade(&base);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("sunshade: sun: disk, 8² samples"), "{}", stderr(&o));
    let default_bound = predicted(&o);
    // The header records the bound, the same number.
    let meta = exr::meta::MetaData::read_from_file(&exr, false).unwrap();
    let all: serde_json::Value = match meta.headers[0].own_attributes.other.get(&exr::prelude::Text::from("sunshade")) {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => serde_json::from_str(&t.to_string()).unwrap(),
        other => panic!("sunshade attribute: {other:?}"),
    };
    let recorded = all["sunshadePredictedError"]["max_relative_error"].as_f64().unwrap();
    assert!((recorded - default_bound).abs() <= 0.01 * recorded, "{recorded} against {default_bound}");
    // `--check --json` carries it beside the comparison.
    let o = sunshade(&[&base[..8], &["--shadows", "none", "--check", "--json"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let check: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(check["predicted_error"]["max_relative_error"].as_f64(), Some(recorded));
    // And what it drew: the lights and the settings, the camera among them, as the files record them.
    assert_eq!(check["render"]["lights"], all["sunshadeLights"], "{check}");
    assert!(check["render"]["settings"]["camera"]["eye"].is_array(), "{check}");
    assert_eq!(check["render"]["settings"]["shadows"], "none", "{check}");
    // Looser tolerance, fewer samples; each bound within its tolerance.
    let mut samples = Vec::new();
    for t in ["1e-2", "1e-4"] {
        let o = sunshade(&[&base[..], &["--tolerance", t]].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(predicted(&o) <= t.parse::<f64>().unwrap(), "{}", stderr(&o));
        let line = stderr(&o).lines().find(|l| l.starts_with("sunshade: sun: ")).unwrap().to_string();
        samples.push(line);
    }
    assert_ne!(samples[0], samples[1], "{samples:?}");
    // Under a sky the lobe grid has no derived bound: its pixels are refined on the reference, within the
    // tolerance; or, with --tolerance-by-study, its error estimated by refinement over whole renders.
    let sky = dir.path("sky.exr");
    let o = sunshade(&[&base[..], &["--sky-radiance", "100", "--tolerance", "1e-3"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("pixel(s) no bound covers"), "{}", stderr(&o));
    assert!(predicted(&o) <= 1e-3, "{}", stderr(&o));
    let o = sunshade(&[&base[..], &["--sky-radiance", "100", "--tolerance", "1e-3", "--tolerance-by-study"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("estimated by refinement"), "{}", stderr(&o));
    assert!(predicted(&o) <= 1e-3, "{}", stderr(&o));
    // Without a bound, refused by name before any output: the device's interpolation.
    let o = sunshade(&["render", s(&input), "-o", s(&sky), "--interpolation", "device", "--tolerance", "1e-3"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("device interpolation has no error bound"), "{}", stderr(&o));
    assert!(!sky.exists());
}

#[test]
fn scripts_get_json_silence_completions_and_a_man_page() {
    let dir = TempDir::new("scripts");
    let input = dir.write("scene.glb", &scene());
    let json_of = |args: &[&str]| -> serde_json::Value {
        let o = sunshade(args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{args:?}: not JSON: {e}"))
    };
    let info = json_of(&["info", "--json"]);
    assert!(info["devices"].as_array().unwrap().iter().any(|d| d["sub_pixel_precision_bits"].is_u64()), "{info}");
    let out = dir.path("o.exr");
    let check = json_of(&["render", s(&input), "-o", s(&out), "--width", "32", "--height", "24", "--check", "--json"]);
    assert_eq!(check["pass"], true, "{check}");
    let bench = json_of(&["bench", s(&input), "--width", "32", "--height", "32", "--repeat", "1", "--json"]);
    assert_eq!(bench["tables"][0]["rows"][0]["scene"], "scene.glb", "{bench}");
    let albedo = json_of(&["albedo", s(&input), "--json"]);
    assert!(!albedo["tables"][0]["rows"].as_array().unwrap().is_empty(), "{albedo}");
    // -q: nothing on either stream, the exit code says it.
    let mut b = scene();
    b.add_material("unused", [0.5; 3], false, None);
    let unused = dir.write("unused.glb", &b);
    let o = sunshade(&["render", s(&unused), "-o", s(&out), "--width", "32", "--height", "24", "--check", "-q"]);
    assert!(o.status.success() && o.stdout.is_empty() && o.stderr.is_empty(), "{}", stderr(&o));
    let o = sunshade(&["diff", s(&out), s(&out), "-q"]);
    assert!(o.status.success() && o.stdout.is_empty());
    // Help grouped by topic; completions; man pages.
    let help = String::from_utf8_lossy(&sunshade(&["render", "--help"]).stdout).into_owned();
    for heading in ["Camera:", "Sun:", "Disk lights and sky:", "Quality:", "Output:", "Check tolerances:"] {
        assert!(help.contains(heading), "{heading} missing from render --help");
    }
    let bash = sunshade(&["completions", "bash"]);
    assert!(bash.status.success() && String::from_utf8_lossy(&bash.stdout).contains("_sunshade"));
    let man = sunshade(&["man"]);
    assert!(String::from_utf8_lossy(&man.stdout).contains(".TH sunshade 1"));
    let pages = dir.path("man");
    std::fs::create_dir(&pages).unwrap();
    assert!(sunshade(&["man", "--dir", s(&pages)]).status.success());
    let render_page = std::fs::read_to_string(pages.join("sunshade-render.1")).unwrap();
    assert!(render_page.contains("sun\\-elevation"));
}

#[test]
fn info_says_whether_the_device_has_ray_queries_on_both_lavapipes() {
    let info = |prefix: &str| -> serde_json::Value {
        let script = format!("{prefix}exec '{}' info --json", env!("CARGO_BIN_EXE_sunshade"));
        let o = Command::new("sh").arg("-c").arg(&script).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap();
        assert!(o.status.success(), "{script}: {}", stderr(&o));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let system = info("unset SUNSHADE_RAY_QUERIES; ");
    for d in system["devices"].as_array().unwrap() {
        assert!(d["ray_query"].is_boolean(), "{d}");
        if d["driver_info"].as_str().unwrap_or("").contains("Mesa 22.") {
            assert_eq!(d["ray_query"], false, "Debian 12's lavapipe has no ray queries: {d}");
        }
    }
    if !second_lavapipe_installed() {
        return;
    }
    let rt = info("unset SUNSHADE_RAY_QUERIES; eval \"$(scripts/lavapipe-rt.sh)\" && ");
    let lavapipe = &rt["devices"][rt["chosen"].as_u64().unwrap() as usize];
    assert_eq!(lavapipe["ray_query"], true, "{lavapipe}");
    assert!(lavapipe["driver_info"].as_str().unwrap().contains("Mesa 25"), "{lavapipe}");
    // A CPU device walks the BVH for its shadow rays unless SUNSHADE_RAY_QUERIES=1 asks for its ray queries.
    assert_eq!(lavapipe["shadow_rays"], "shader walk", "{lavapipe}");
    let asked = info("eval \"$(scripts/lavapipe-rt.sh)\" && SUNSHADE_RAY_QUERIES=1 ");
    assert_eq!(asked["devices"][asked["chosen"].as_u64().unwrap() as usize]["shadow_rays"], "ray queries");
}

/// A golden rendered on one lavapipe passes on the other: Debian 12's (Mesa 22.3, no ray queries) and Mesa 25's
/// (`scripts/lavapipe-rt.sh`) render every model, and a disk light with the sky, to the same bits, both walking the
/// occluders' BVH in the fragment shader. Skipped, loudly, where Mesa 25's lavapipe cannot be installed.
#[test]
fn a_render_on_one_lavapipe_is_the_same_image_on_the_other() {
    if !second_lavapipe_installed() {
        return;
    }
    let dir = TempDir::new("cli-two-lavapipes");
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    // Each lavapipe by default, whatever `make test`'s second stage asks of the ray queries.
    let on = |system: bool, name: &str, args: &[&str]| -> Vec<u8> {
        let out = dir.path(name);
        let mut c = sunshade_command_on(system, &["render", "-o", s(&out), "--width", "96", "--height", "72"]);
        let o = c.args(args).env_remove("SUNSHADE_RAY_QUERIES").output().unwrap();
        assert!(o.status.success(), "{args:?} (system lavapipe: {system}): {}", stderr(&o));
        std::fs::read(&out).unwrap()
    };
    let mut cases: Vec<Vec<String>> = Vec::new();
    for entry in std::fs::read_dir(&models).unwrap() {
        let path = entry.unwrap().path();
        if matches!(path.extension().and_then(|e| e.to_str()), Some("glb" | "gltf")) {
            cases.push(vec![path.display().to_string()]);
        }
    }
    cases.sort();
    assert!(cases.len() >= 8, "{cases:?}");
    for m in ["teapot.glb", "room.gltf"] {
        let model = models.join(m).display().to_string();
        let light = ["--disk-light", "1,1.2,1:-0.5,-0.7,-0.5:0.3:2000", "--sky-radiance", "50"];
        cases.push([model].into_iter().chain(light.map(String::from)).collect());
    }
    for (k, case) in cases.iter().enumerate() {
        let args: Vec<&str> = case.iter().map(String::as_str).collect();
        let a = on(true, &format!("{k}-22.pfm"), &args);
        let b = on(false, &format!("{k}-25.pfm"), &args);
        assert!(a == b, "{case:?}: the two lavapipes' images differ");
    }
}

#[test]
fn shadow_flags_warnings_and_refusals() {
    let dir = TempDir::new("cli-shadows");
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let room = models.join("room.gltf");
    let out = dir.path("room.exr");
    // A technique that does not exist is a usage error naming the choices.
    let o = sunshade(&["render", s(&room), "-o", s(&out), "--shadows", "soft"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("auto") && stderr(&o).contains("map"), "{}", stderr(&o));
    // The maps shadow the sun and disk lights, not the sky: the overcast scene's sky stays unoccluded and a
    // warning says so, the room's disk light is mapped without one; the image's metadata records the technique.
    let overcast = models.join("overcast.glb");
    let o = sunshade(&["render", s(&overcast), "-o", s(&out), "--width", "32", "--height", "24", "--shadows", "map"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("the sky has no shadow map"), "{}", stderr(&o));
    // ... and says which technique would shadow it.
    assert!(stderr(&o).contains("--shadows ray shadows it"), "{}", stderr(&o));
    let o = sunshade(&["render", s(&room), "-o", s(&out), "--width", "32", "--height", "24", "--shadows", "map"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let exr = std::fs::read(&out).unwrap();
    let needle = b"\"shadows\":\"map\"";
    assert!(exr.windows(needle.len()).any(|w| w == needle), "the EXR names the technique");
    // The reference says what it did and why.
    let o = sunshade(&["reference", s(&room), "-o", s(&out), "--width", "32", "--height", "24", "-v"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("shadows: ray (auto: the scene can shadow itself"), "{}", stderr(&o));
    // Rays on the GPU: by ray queries, or on a device without them by the shader's walk of the BVH (said so by
    // -v), checked against the reference either way.
    let info: serde_json::Value = serde_json::from_slice(&sunshade(&["info", "--json"]).stdout).unwrap();
    let chosen = info["chosen"].as_u64().map(|i| i as usize);
    let rq = chosen.is_some_and(|i| info["devices"][i]["shadow_rays"] == "ray queries");
    let o = sunshade(&[
        "render",
        s(&room),
        "-o",
        s(&out),
        "--width",
        "32",
        "--height",
        "24",
        "--shadows",
        "ray",
        "--check",
        "-v",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o).contains("walk of the occluders' BVH"), !rq, "{}", stderr(&o));
    // `auto`: shadow rays on every device, the sun's against its cells; `render --check` passes, its report
    // counting the fragile pixels apart (JSON `excused`, with the few it allows), and nothing else over tolerance.
    let teapot = models.join("teapot.glb");
    let base = ["render", s(&teapot), "-o", s(&out), "--width", "256", "--height", "192", "--check"];
    let o = sunshade(&[&base[..], &["-v"]].concat());
    assert!(o.status.success(), "{}{}", stderr(&o), String::from_utf8_lossy(&o.stdout));
    assert!(stderr(&o).contains("shadows: ray (auto: shadow rays (the sun's against its cells))"), "{}", stderr(&o));
    let o = sunshade(&[&base[..], &["--json"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["pass"], true, "{report}");
    assert_eq!(report["over_tolerance"]["total"], 0, "{report}");
    let class = &report["excused"];
    assert!(class["class"].as_str().unwrap().starts_with("fragile pixels"), "{report}");
    let allowed = class["allowed"].as_u64().unwrap();
    assert!(allowed * 2000 <= report["compared"].as_u64().unwrap(), "at most 0.05% allowed: {report}");
    assert!(class["over_tolerance"].as_u64().unwrap() <= allowed, "{report}");
    // `--shadows map` counts the maps' edges apart, where every difference over tolerance lies.
    let o = sunshade(&[&base[..], &["--json", "--shadows", "map"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["pass"], true, "{report}");
    let class = &report["excused"];
    let (n, over) = (class["compared"].as_u64().unwrap(), class["over_tolerance"].as_u64().unwrap());
    assert!(n > 0 && n * 10 < report["compared"].as_u64().unwrap(), "{report}");
    assert!(over > 0, "the maps differ from the rays somewhere, else this tests nothing: {report}");
    assert_eq!(report["over_tolerance"]["total"], 0, "{report}");
}

/// llvmpipe's loop limiter (docs/platform.md): the sky's three lobe grids at 162² per axis (79 218 loop iterations a
/// fragment) are cut short by Mesa 22.3's, silently; sunshade's probe finds the pixels and refuses the image with
/// the way out, while 140² (59 220) renders. Off llvmpipe both render.
#[test]
fn lavapipe_loop_budget_is_detected_not_trusted() {
    let dir = common::TempDir::new("loop-budget");
    let brdfs = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/brdfs.glb");
    let render = |samples: u32| {
        let n = samples.to_string();
        let out = dir.path(&format!("sky-{samples}.exr"));
        sunshade(&[
            "render",
            s(&brdfs),
            "-o",
            s(&out),
            "--width",
            "16",
            "--height",
            "16",
            "--shadows",
            "none",
            "--sun-irradiance",
            "0",
            "--sky-radiance",
            "100",
            "--samples",
            &n,
        ])
    };
    let info: serde_json::Value = serde_json::from_slice(&sunshade(&["info", "--json"]).stdout).unwrap();
    let chosen = info["chosen"].as_u64().unwrap() as usize;
    let llvmpipe = info["devices"][chosen]["name"].as_str().unwrap().contains("llvmpipe");
    let o = render(140 * 140);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = render(162 * 162);
    // Mesa 22.3's llvmpipe cuts them; Mesa 25.0.7's did not (docs/platform.md): either way the probe decides.
    let mesa22 = llvmpipe && info["devices"][chosen]["driver_info"].as_str().is_some_and(|d| d.contains("Mesa 22."));
    if mesa22 {
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains("cut the loops of") && stderr(&o).contains("--samples"), "{}", stderr(&o));
        assert!(!dir.path(&format!("sky-{}.exr", 162 * 162)).exists(), "no image is written");
    } else if !llvmpipe {
        assert!(o.status.success(), "{}", stderr(&o));
    }
}

/// `render --visibility slices` where a pixel's light cone holds more triangles than the GPU's slices gather (the
/// teapot under a disk light 3 m wide just above it): refused by name, exit non-zero, no image. On a device with
/// ray queries the slices are refused before that, by their own name.
#[test]
fn gpu_slices_refuse_a_light_cone_holding_too_many_triangles() {
    let dir = TempDir::new("cli-slices-overflow");
    let out = dir.path("teapot.exr");
    let flags = "render models/teapot.glb --width 32 --height 24 --shadows ray --visibility slices --sun-irradiance 0 \
                 --disk-light 0,3,0:0,-1,0:3:100 -o";
    let mut args: Vec<&str> = flags.split_whitespace().collect();
    args.push(out.to_str().unwrap());
    let o = sunshade(&args);
    let e = stderr(&o);
    assert!(!o.status.success() && !out.exists(), "{e}");
    assert!(e.contains("--visibility slices") && e.contains("more than 1024 triangles"), "{e}");
}

/// One render layer: the same flags through `sunshade render` and through the `testing` API give the same image, bit
/// for bit, also where `--tolerance` chooses the models (by bounds, refining the pixels without one on the reference,
/// by a study on the reference, by slices measured against it) and where `--visibility` names the rule.
#[test]
fn gpu_the_library_and_the_command_line_render_the_same_flags_to_the_same_image() {
    let dir = TempDir::new("same-flags");
    let teapot = concat!(env!("CARGO_MANIFEST_DIR"), "/models/teapot.glb");
    let cube = concat!(env!("CARGO_MANIFEST_DIR"), "/models/cube.glb");
    let size = ["--width", "48", "--height", "36"];
    let cases: [(&str, &[&str]); 5] = [
        // Each of the first four differs from the image without `--tolerance` (checked below).
        (teapot, &["--brdf", "ward", "--tolerance", "1e-3"]),
        (cube, &["--brdf", "ward", "--tolerance", "1e-3", "--tolerance-outside-penumbrae"]),
        (cube, &["--brdf", "ward", "--tolerance", "1e-3", "--visibility", "grid", "--tolerance-by-study"]),
        (teapot, &["--brdf", "ward", "--tolerance", "1e-3", "--tolerance-by-study"]),
        (teapot, &["--shadows", "map", "--brdf", "ward"]),
    ];
    let mut gpu = CheckedRenderer::new();
    for (i, (model, flags)) in cases.iter().enumerate() {
        let flags: Vec<&str> = size.iter().chain(flags.iter()).copied().collect();
        let out = dir.path(&format!("cli{i}.exr"));
        let mut argv = vec!["render", model, "-o", s(&out), "-q"];
        argv.extend(&flags);
        let o = sunshade(&argv);
        assert!(o.status.success(), "{flags:?}: {}", stderr(&o));
        let from_cli = sunshade::film::read_image(&out).unwrap();
        let job = sunshade::testing::job(model, &flags).unwrap();
        let from_library = gpu.render_job(&job).unwrap();
        assert!(from_cli.covered_count() > 100, "{flags:?}");
        assert_eq!(bits(&from_cli), bits(&from_library), "{flags:?}: the CLI's and the library's images differ");
        if i < 4 {
            let untoleranced: Vec<&str> = size.iter().chain(&["--brdf", "ward"]).copied().collect();
            let plain = gpu.render_job(&sunshade::testing::job(model, &untoleranced).unwrap()).unwrap();
            assert_ne!(bits(&plain), bits(&from_library), "{flags:?}: --tolerance chose the default models");
        }
    }
}

/// `-v` names the camera (the file's, or the automatic one, which `--camera auto` asks for even where the file has
/// cameras) and the sun (elevation, azimuth, where it came from); light the flags may not mean is warned about: a sun
/// below the horizon, a sky given to a scene without light (no default sun then); an empty file says so.
#[test]
fn renders_say_what_they_drew_and_warn_about_light_the_flags_may_not_mean() {
    let dir = TempDir::new("say-what");
    let mut b = GltfBuilder::new();
    let m = b.add_material("m", [0.5; 3], false, None);
    let mesh = b.add_mesh("cube", &[cube(0.5).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    let camera = b.add_perspective_camera(0.8, 0.1, Some(50.0));
    let placed = sunshade::authoring::Transform::Trs {
        translation: [0.0, 0.0, 4.0],
        rotation: [0.0, 0.0, 0.0, 1.0],
        scale: [1.0; 3],
    };
    let c = b.add_node(Node { camera: Some(camera), transform: placed, ..Default::default() });
    b.add_scene(&[n, c], None);
    let input = dir.write("cam.glb", &b);
    let out = dir.path("o.png");
    let v = |extra: &[&str]| {
        let mut argv = vec!["render", s(&input), "-o", s(&out), "--width", "32", "--height", "24", "-v"];
        argv.extend(extra);
        let o = sunshade(&argv);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    let text = v(&["--sun-elevation", "15", "--sun-azimuth", "90"]);
    assert!(text.contains(&format!("camera: the file's camera {camera}")), "{text}");
    assert!(
        text.contains("sun position: elevation 15.000°, azimuth 90.000°") && text.contains("from the flags"),
        "{text}"
    );
    let text = v(&["--camera", "auto"]);
    assert!(text.contains("camera: automatic (--camera auto)") && text.contains("from the default"), "{text}");
    assert!(!text.contains("warning"), "{text}");
    assert!(v(&["--sun-elevation", "-10"]).contains("warning: the sun is below the horizon (elevation -10.00°)"));
    let text = v(&["--sky-radiance", "50"]);
    assert!(text.contains("warning: no sun: --sky-radiance") && text.contains("sun: none"), "{text}");
    assert!(!v(&["--sky-radiance", "50", "--sun-elevation", "30"]).contains("warning"));
    let o = sunshade(&["render", s(&input), "-o", s(&out), "--camera", "front"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("'front' is neither a glTF camera index nor 'auto'"), "{}", stderr(&o));
    let empty = dir.path("empty.glb");
    std::fs::write(&empty, b"").unwrap();
    let o = sunshade(&["render", s(&empty), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("empty.glb: empty file (0 bytes)"), "{}", stderr(&o));
}

/// `--emission-scale S` gives S W/(m²·sr) per unit emissiveFactor: a Lambertian square emitting [1, 0.5, 0]
/// renders brighter by exactly (S − 1) × that; `-v` says when the emission is under 1% of the image's peak.
#[test]
fn emission_scale_makes_emission_visible_and_v_says_when_it_is_not() {
    let dir = TempDir::new("emission-scale");
    let mut b = GltfBuilder::new();
    let m = b.add_material_json(json!({
        "name": "glow",
        "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0 },
        "emissiveFactor": [1.0, 0.5, 0.0],
        "extras": { "sunshade": { "brdf": "lambert" } },
    }));
    let mesh = b.add_mesh("square", &[quad(Vec3::ZERO, Vec3::X, Vec3::Y).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    let scene = dir.write("glow.glb", &b);
    let scene = scene.to_str().unwrap();
    let view = [
        "--eye",
        "0,0,3",
        "--target",
        "0,0,0",
        "--width",
        "16",
        "--height",
        "16",
        "--shadows",
        "none",
        "--sun-dir",
        "0.2,0.3,1",
    ];
    let (plain, scaled) = (dir.path("plain.exr"), dir.path("scaled.exr"));
    let o = sunshade(&[&["render", scene, "-v", "-o", plain.to_str().unwrap()][..], &view].concat());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && e.contains("emission: at most 1.000e0") && e.contains("--emission-scale"), "{e}");
    let o = sunshade(
        &[&["render", scene, "-v", "--emission-scale", "500", "-o", scaled.to_str().unwrap()][..], &view].concat(),
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !e.contains("emission: at most"), "{e}");
    let (a, b) = (sunshade::film::read_image(&plain).unwrap(), sunshade::film::read_image(&scaled).unwrap());
    let (pa, pb) = (a.get(8, 8), b.get(8, 8));
    for (c, e) in [1.0f64, 0.5, 0.0].iter().enumerate() {
        let added = pb[c] as f64 - pa[c] as f64;
        assert!((added - 499.0 * e).abs() <= 1e-5 * pb[c] as f64, "channel {c}: {pa:?} → {pb:?}");
    }
    let o = sunshade(&["render", scene, "--emission-scale", "-1", "-o", scaled.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
}

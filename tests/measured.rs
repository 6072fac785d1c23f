//! Measured (MERL) BRDFs: synthetic tables made from analytic BRDFs (the database's files are large and not
//! redistributable), rendered by the reference and the GPU (lavapipe, validation on) under every light.
//!
//! - A constant table renders as Lambert (its floor is the Lambertian part; nothing is left to sample).
//! - A Ward BRDF tabulated into the format renders close to the analytic Ward, within a bound computed from the
//!   table's own second differences (the trilinear lookup's error).
//! - The GPU agrees with the reference on measured materials under the sun (disk and delta), a disk light and the
//!   sky.
//! - A constant table with the database's missing samples beyond the horizon still renders as Lambert; files with
//!   missing samples above the horizon load with a warning; a wrong header and a truncated file are refused in
//!   one line naming the file.

mod common;

use std::sync::OnceLock;

use common::{CheckedRenderer, TempDir};
use glam::{DVec3, Vec3};
use serde_json::json;
use sunshade::authoring::chart::{sphere_scene, ChartMaterial};
use sunshade::compare::{self, DiffOptions};
use sunshade::cpu;
use sunshade::scene::measured::{merl_bytes, MERL_SAMPLES};
use sunshade::scene::{Brdf, DiskLight, Lights, Scene, Sun};
use sunshade::settings::RenderSettings;
use sunshade::shading::measured::tabulate;
use sunshade::shading::{DiskModel, ShadingOptions, SunModel};

/// The analytic Ward of the synthetic table: kd 0.3/0.25/0.2, ks 0.2, α 0.2.
fn ward() -> Brdf {
    Brdf::Ward { kd: [0.3, 0.25, 0.2], ks: [0.2; 3], alpha_x: 0.2, alpha_y: 0.2 }
}

/// `kd/π + ks lobe` of an analytic BRDF at (l, v) about +z, per channel.
fn analytic(brdf: &Brdf, l: DVec3, v: DVec3) -> [f64; 3] {
    sunshade::shading::measured::brdf_about_z(brdf, l, v)
}

/// The Ward table's bytes, made once per test process.
fn ward_table_bytes() -> &'static [u8] {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| merl_bytes(&tabulate(|l, v| analytic(&ward(), l, v))))
}

/// A sphere scene whose material is `extras`, written with the files it names.
fn sphere(dir: &TempDir, name: &str, extras: serde_json::Value) -> Scene {
    let m = ChartMaterial { name: name.into(), extras };
    common::load(&dir.write(&format!("{name}.glb"), &sphere_scene(&m)))
}

fn sun(model_degrees: f64) -> Sun {
    let t = model_degrees.to_radians();
    Sun {
        direction: Vec3::new(0.8 * t.sin() as f32, 0.6 * t.sin() as f32, t.cos() as f32),
        irradiance: [1000.0; 3],
        angular_diameter: 0.53f32.to_radians(),
    }
}

/// Each light alone, with its model: the sun as a disk and as a direction, a disk light, the sky. The sun's
/// angles from the (orthographic) viewer, 31° and 61°, put θ_d = 15.5° and 30.5° mid-bin for every pixel: at 30° or
/// 60° θ_d would sit on a bin edge of the whole image, where a nearest lookup jumps with the last bit of the
/// coordinates (measured: 26% of the pixels 1.7% apart between GPU and reference with the delta sun at 60°).
fn light_cases() -> Vec<(&'static str, Lights, ShadingOptions)> {
    let disk = DiskLight {
        center: Vec3::new(1.0, 1.5, 2.5),
        direction: Vec3::new(-1.0, -1.5, -2.5).normalize(),
        radius: 0.6,
        radiance: [200.0, 150.0, 100.0],
    };
    let with = |sun: SunModel, disk: DiskModel| ShadingOptions { sun, disk, ..Default::default() };
    let (disk_sun, exact) = (SunModel::Disk, DiskModel::Exact);
    vec![
        ("sun (disk)", Lights { sun: Some(sun(31.0)), ..Default::default() }, with(disk_sun, exact)),
        ("sun (delta)", Lights { sun: Some(sun(61.0)), ..Default::default() }, with(SunModel::Delta, exact)),
        ("disk light", Lights { disks: vec![disk], ..Default::default() }, with(disk_sun, exact)),
        (
            "disk light (small-source)",
            Lights { disks: vec![disk], ..Default::default() },
            with(disk_sun, DiskModel::SmallSource),
        ),
        ("sky", Lights { sky: Some([100.0, 90.0, 80.0]), ..Default::default() }, with(disk_sun, exact)),
    ]
}

fn settings(scene: &Scene, lights: Lights, shading: ShadingOptions, size: u32) -> RenderSettings {
    let mut s = RenderSettings::new(size, size, scene.cameras[0].1, lights);
    s.shading = shading;
    s
}

fn write(dir: &TempDir, name: &str, bytes: &[u8]) {
    std::fs::write(dir.path(name), bytes).unwrap();
}

/// Marks missing (−1) every sample whose light or view, at its bin's centre, is not above the horizon: the
/// database's pattern for directions it could not measure.
fn with_horizon_pattern(mut planes: [Vec<f64>; 3]) -> [Vec<f64>; 3] {
    use sunshade::scene::measured::{bin_centre_above_horizon, merl_index, PHI_D_BINS, THETA_D_BINS, THETA_H_BINS};
    for i in 0..THETA_H_BINS {
        for j in 0..THETA_D_BINS {
            for k in 0..PHI_D_BINS {
                if !bin_centre_above_horizon(i, j, k) {
                    planes.iter_mut().for_each(|p| p[merl_index(i, j, k)] = -1.0);
                }
            }
        }
    }
    planes
}

/// A constant table renders as Lambert, also with the database's missing samples beyond the horizon, up to the
/// silhouette (the lookup interpolates over the valid samples only; taken as 0 they darkened a band there).
#[test]
fn constant_table_renders_as_lambert() {
    let dir = TempDir::new("merl-constant");
    let rho = [0.1f64, 0.15, 0.2];
    let planes: [Vec<f64>; 3] = std::array::from_fn(|c| vec![rho[c]; MERL_SAMPLES]);
    write(&dir, "constant.binary", &merl_bytes(&planes));
    write(&dir, "horizon.binary", &merl_bytes(&with_horizon_pattern(planes)));
    // The albedo whose ρ is the table's (f32) value.
    let albedo: Vec<f64> = rho.iter().map(|&r| r as f32 as f64 * std::f64::consts::PI).collect();
    let lambert = sphere(&dir, "lambert", json!({ "brdf": "lambert", "albedo": albedo }));
    let mut gpu = CheckedRenderer::new();
    for ((what, lights, model), file) in
        light_cases().into_iter().flat_map(|c| [(c.clone(), "constant.binary"), (c, "horizon.binary")])
    {
        let measured = sphere(&dir, file, json!({ "brdf": "merl", "file": file }));
        let what = format!("{what}, {file}");
        let s = settings(&measured, lights, model, 64);
        let options = gpu.reference_options();
        for (renderer, a, b) in [
            ("reference", cpu::render(&measured, &s, &options), cpu::render(&lambert, &s, &options)),
            ("GPU", gpu.render(&measured, &s), gpu.render(&lambert, &s)),
        ] {
            let (report, _) =
                compare::diff(&a, &b, &DiffOptions { floor_fraction: 0.0, floor: 1e-30, ..Default::default() })
                    .unwrap();
            println!("{what}, {renderer}: measured constant against Lambert: max rel {:.2e}", report.max_rel_interior);
            assert!(report.covered_b > 2000);
            // The albedo's f32 rounding (π ρ to 6e-8) and kd = π floor rounded again: a few ulp.
            assert!(report.max_rel_interior < 5e-7, "{what}, {renderer}: {:.3e}", report.max_rel_interior);
        }
    }
}

#[test]
fn gpu_matches_reference_on_measured_materials() {
    let dir = TempDir::new("merl-gpu");
    write(&dir, "ward.binary", ward_table_bytes());
    let mut gpu = CheckedRenderer::new();
    for lookup in ["linear", "nearest"] {
        let scene = sphere(&dir, lookup, json!({ "brdf": "merl", "file": "ward.binary", "lookup": lookup }));
        for (what, lights, model) in light_cases() {
            let s = settings(&scene, lights, model, 96);
            let g = gpu.render(&scene, &s);
            let c = cpu::render(&scene, &s, &gpu.reference_options());
            assert!(g.pixels().iter().all(|p| p.iter().all(|v| v.is_finite() && *v >= 0.0)), "{what}: not finite");
            let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
            println!(
                "{lookup} {what}: GPU against reference max rel {:.2e}, {} of {} over tolerance",
                report.max_rel_interior, report.over_tolerance.total, report.covered_b
            );
            assert_eq!(report.coverage_mismatches.total, 0);
            if lookup == "linear" {
                // Continuous in the directions: rounding only (measured 1.2e-6 to 4.3e-6).
                assert!(
                    report.max_rel_interior < 1e-4,
                    "{what}: {:.3e} at {:?}",
                    report.max_rel_interior,
                    report.worst
                );
            } else {
                // Nearest: a sample whose coordinates round across a bin edge jumps by the table's step between
                // bins (a few % here) times its weight in the grid (1/256 for a disk light's 16²); measured: 15
                // pixels of 6568 over 1e-5 with the disk light, at most 6.1e-4.
                let over = report.over_tolerance.total as f64 / report.covered_b as f64;
                assert!(
                    over < 0.01 && report.max_rel_interior < 0.05,
                    "{what}: {over:.3} over, max {:.3e}",
                    report.max_rel_interior
                );
            }
        }
    }
}

#[test]
fn bad_tables_are_refused_in_one_line_and_missing_samples_warned() {
    let dir = TempDir::new("merl-bad");
    let good = ward_table_bytes();
    let mut header = good.to_vec();
    header[8..12].copy_from_slice(&360i32.to_le_bytes());
    write(&dir, "header.binary", &header);
    write(&dir, "truncated.binary", &good[..good.len() / 2]);
    let mut long = good.to_vec();
    long.extend_from_slice(&[0; 8]);
    write(&dir, "long.binary", &long);
    for (file, what) in [
        ("header.binary", "90 × 90 × 360"),
        ("truncated.binary", "truncated"),
        ("long.binary", "MERL BRDF 'long.binary': the file holds 34992020 bytes, more than the 34992012 expected"),
    ] {
        let m = ChartMaterial { name: file.into(), extras: json!({ "brdf": "merl", "file": file }) };
        let path = dir.write("bad.glb", &sphere_scene(&m));
        let e = sunshade::scene::load(&path).unwrap_err().to_string();
        assert!(e.contains("bad.glb") && e.contains(file) && e.contains(what) && !e.contains('\n'), "{e}");
    }
    // Outside the scene's folder: refused like a buffer URI.
    let m = ChartMaterial { name: "outside".into(), extras: json!({ "brdf": "merl", "file": "../ward.binary" }) };
    let e = sunshade::scene::load(&dir.write("outside.glb", &sphere_scene(&m))).unwrap_err().to_string();
    assert!(e.contains("outside the asset folder") || e.contains("cannot read"), "{e}");
    // Not regular files: a FIFO (opening it for reading would block), a folder, a link out to /dev/zero; and a
    // --merl path that is a device. Each refused in one line, nothing read.
    #[cfg(unix)]
    {
        assert!(std::process::Command::new("mkfifo").arg(dir.path("pipe.binary")).status().unwrap().success());
        std::fs::create_dir(dir.path("folder.binary")).unwrap();
        std::os::unix::fs::symlink("/dev/zero", dir.path("zero.binary")).unwrap();
        for (file, what) in [("pipe.binary", "FIFO"), ("folder.binary", "director"), ("zero.binary", "outside")] {
            let m = ChartMaterial { name: file.into(), extras: json!({ "brdf": "merl", "file": file }) };
            let e = sunshade::scene::load(&dir.write("odd.glb", &sphere_scene(&m))).unwrap_err().to_string();
            assert!(e.contains(file) && e.contains(what) && !e.contains('\n'), "{file}: {e}");
        }
        let e = sunshade::scene::measured::read_merl_file(std::path::Path::new("/dev/zero")).unwrap_err();
        assert!(e.contains("/dev/zero") && !e.contains('\n'), "{e}");
    }
    // Missing samples above the horizon: loaded, warned, each holding its nearest valid sample's value; the
    // tabulated Ward's own missing samples (beyond the horizon) are not worth a warning.
    write(&dir, "ward.binary", good);
    assert!(sphere(&dir, "good", json!({ "brdf": "merl", "file": "ward.binary" })).warnings.is_empty());
    let mut missing = good.to_vec();
    for i in 0..1000 {
        missing[12 + 8 * i..][..8].copy_from_slice(&(-1.0f64).to_le_bytes());
    }
    write(&dir, "missing.binary", &missing);
    let scene = sphere(&dir, "missing", json!({ "brdf": "merl", "file": "missing.binary" }));
    assert!(
        scene.warnings.iter().any(|w| w.contains("1000 samples above the horizon are missing")),
        "{:?}",
        scene.warnings
    );
    let Brdf::Measured { table, .. } = &scene.materials[0].brdf else { panic!("not measured") };
    let good = sunshade::scene::measured::parse_merl("good", good).unwrap();
    // Samples 0–999 are θ_h bin 0's first θ_d bins: the nearest valid sample to sample 0 is θ_h bin 1's first.
    let above = sunshade::scene::measured::merl_index(1, 0, 0);
    assert_eq!(
        (table.missing - good.missing, table.value(0, 0), table.floor),
        (1000, good.value(above, 0), good.floor)
    );
}

/// The linear lookup of a tabulated Ward against the analytic Ward at 200 000 random pairs of directions above the
/// horizon: within the error estimate from the table's second differences (`linear_lookup_error_at`) plus the
/// f32 rounding of the table's values, everywhere.
#[test]
fn tabulated_ward_lookup_is_within_its_error_estimate() {
    use sunshade::shading::measured::{linear_lookup_error_at, measured_brdf, MeasuredLookup};
    let table = sunshade::scene::measured::parse_merl("ward", ward_table_bytes()).unwrap();
    // A fixed linear congruential sequence: the same directions on every run.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let direction = |u: f64, w: f64| {
        // Uniform on the upper hemisphere.
        let z = u.max(1e-9);
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * (2.0 * std::f64::consts::PI * w).cos(), r * (2.0 * std::f64::consts::PI * w).sin(), z)
    };
    let (mut worst, mut worst_ratio, mut mean) = (0.0f64, 0.0f64, 0.0);
    let count = 200_000;
    for _ in 0..count {
        let (a, b, c, d) = (uniform(), uniform(), uniform(), uniform());
        let (l, v) = (direction(a, b), direction(c, d));
        let want = analytic(&ward(), l, v);
        let got = measured_brdf(&table, MeasuredLookup::Linear, DVec3::Z, l, v);
        let estimate = linear_lookup_error_at(&table, DVec3::Z, l, v);
        for ch in 0..3 {
            let rel = (got[ch] - want[ch]).abs() / want[ch];
            worst = worst.max(rel);
            mean += rel / (3 * count) as f64;
            worst_ratio = worst_ratio.max(rel / (estimate + 1e-6));
            assert!(rel <= estimate + 1e-6, "l {l} v {v}: relative error {rel:.3e} over the estimate {estimate:.3e}");
        }
    }
    println!("linear lookup of tabulated Ward: max rel {worst:.2e}, mean {mean:.2e}, largest error/estimate {worst_ratio:.2}");
}

/// The reference with a tabulated Ward (linear lookup) against the analytic Ward, each with 64² samples per light
/// so that what is left is mostly the table's interpolation: a pixel integrates the BRDF against positive
/// weights, so its relative error is at most the lookup's largest over the directions it integrates, which the
/// table's global estimate bounds (measured 9.1e-4 to 2.5e-3 against an estimate of 0.27, reached only where
/// light and view both graze).
#[test]
fn tabulated_ward_renders_close_to_the_analytic_ward() {
    let dir = TempDir::new("merl-ward");
    write(&dir, "ward.binary", ward_table_bytes());
    let measured = sphere(&dir, "measured", json!({ "brdf": "merl", "file": "ward.binary" }));
    let analytic = sphere(
        &dir,
        "analytic",
        json!({ "brdf": "ward", "kd": [0.3, 0.25, 0.2], "ks": [0.2, 0.2, 0.2], "alpha": 0.2 }),
    );
    for (what, lights, model) in light_cases() {
        let mut s = settings(&measured, lights, model, 48);
        s.shading.samples_per_axis = 64;
        s.shading.sun_samples_per_axis = 16;
        let options = cpu::ReferenceOptions::default();
        let (a, b) = (cpu::render(&measured, &s, &options), cpu::render(&analytic, &s, &options));
        let (report, _) = compare::diff(&a, &b, &DiffOptions::default()).unwrap();
        println!(
            "{what}: tabulated against analytic max rel {:.2e} over {} pixels",
            report.max_rel_interior, report.compared
        );
        assert!(report.max_rel_interior < 1e-2, "{what}: {:.3e} at {:?}", report.max_rel_interior, report.worst);
    }
}

/// `fit_brdf` recovers the parameters of a tabulated Ward and a tabulated Blinn-Phong (to 5%; measured far
/// closer), and a Lambert fit of a constant table its albedo.
#[test]
fn fit_recovers_the_parameters_of_tabulated_brdfs() {
    use sunshade::scene::measured::MeasuredBrdf;
    use sunshade::scene::BrdfKind;
    use sunshade::shading::brdf_fit::fit_brdf;
    let blinn = Brdf::BlinnPhong { kd: [0.5, 0.4, 0.3], ks: [0.1, 0.15, 0.2], exponent: 200.0 };
    let cases = [
        (ward(), BrdfKind::Ward, "ward"),
        (blinn.clone(), BrdfKind::BlinnPhong, "blinn-phong"),
        (Brdf::Lambert { albedo: [0.7, 0.5, 0.2] }, BrdfKind::Lambert, "lambert"),
    ];
    for (truth, kind, name) in cases {
        let table = if name == "ward" {
            sunshade::scene::measured::parse_merl(name, ward_table_bytes()).unwrap()
        } else {
            MeasuredBrdf::from_planes(name, &tabulate(|l, v| analytic(&truth, l, v))).unwrap()
        };
        let t = std::time::Instant::now();
        let fit = fit_brdf(&table, kind);
        println!(
            "{name}: {:?}, relative RMS {:.2e} ({:.2} s)",
            fit.brdf,
            fit.relative_rms[0],
            t.elapsed().as_secs_f64()
        );
        let close = |got: f32, want: f32| want == 0.0 && got.abs() < 1e-3 || ((got - want) / want).abs() < 0.05;
        let (kd, ks, gkd, gks) = (truth.kd(), truth.ks(), fit.brdf.kd(), fit.brdf.ks());
        for c in 0..3 {
            assert!(close(gkd[c], kd[c]) && close(gks[c], ks[c]), "{name}: {:?} against {truth:?}", fit.brdf);
        }
        match (&truth, &fit.brdf) {
            (Brdf::Ward { alpha_x: a, .. }, Brdf::Ward { alpha_x: b, alpha_y: c, .. }) => {
                assert!(close(*b, *a) && b == c)
            }
            (Brdf::BlinnPhong { exponent: a, .. }, Brdf::BlinnPhong { exponent: b, .. }) => assert!(close(*b, *a)),
            (Brdf::Lambert { .. }, Brdf::Lambert { .. }) => {}
            _ => panic!("{name}: fitted {:?}", fit.brdf),
        }
        assert!(fit.relative_rms.iter().all(|&e| e < 1e-4), "{name}: {:?}", fit.relative_rms);
    }
}

/// `fit_brdf --model gltf` recovers the base colour, metallic and roughness of a tabulated glTF BRDF: a measured
/// material turned into a glTF one.
#[test]
fn fit_recovers_a_tabulated_gltf_material() {
    use sunshade::scene::measured::MeasuredBrdf;
    use sunshade::scene::BrdfKind;
    use sunshade::shading::brdf_fit::fit_brdf;
    let specular = sunshade::scene::material::DielectricSpecular::DEFAULT;
    let truth = Brdf::Gltf { base_color: [0.7, 0.4, 0.2], metallic: 0.3, alpha: 0.09, specular };
    let table = MeasuredBrdf::from_planes("gltf", &tabulate(|l, v| analytic(&truth, l, v))).unwrap();
    let t = std::time::Instant::now();
    let fit = fit_brdf(&table, BrdfKind::Gltf);
    println!("{:?}, relative RMS {:.2e} ({:.2} s)", fit.brdf, fit.relative_rms[0], t.elapsed().as_secs_f64());
    let Brdf::Gltf { base_color, metallic, alpha, .. } = fit.brdf else { panic!("fitted {:?}", fit.brdf) };
    for c in 0..3 {
        assert!((base_color[c] - [0.7, 0.4, 0.2][c]).abs() < 0.02, "{:?}", fit.brdf);
    }
    assert!((metallic - 0.3).abs() < 0.02 && ((alpha - 0.09) / 0.09).abs() < 0.02, "{:?}", fit.brdf);
    assert!(fit.relative_rms.iter().all(|&e| e < 1e-3), "{:?}", fit.relative_rms);
}

fn sunshade(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_sunshade"))
        .args(args)
        .env("SUNSHADE_VALIDATION", "1")
        .output()
        .expect("run sunshade")
}

/// The command line: `tabulate-brdf` writes a table, `fit-brdf --json` fits it and its snippet loads as a
/// material, `render --merl` puts it on every material and passes `--check` against the reference, and a bad
/// `--merl` file fails in one line naming it, with no output written.
#[test]
fn command_line_tabulates_fits_and_renders_measured_materials() {
    let dir = TempDir::new("merl-cli");
    let table = dir.path("ward.binary");
    let t = table.to_str().unwrap();
    let o = sunshade(&[
        "tabulate-brdf",
        "--model",
        "ward",
        "--kd",
        "0.3,0.25,0.2",
        "--ks",
        "0.2",
        "--alpha",
        "0.2",
        "-o",
        t,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(&table).unwrap(), ward_table_bytes());
    // Written where the lookup reads it: at a bin's centre the lookup returns the formula there (to f32).
    let parsed = sunshade::scene::measured::parse_merl(t, ward_table_bytes()).unwrap();
    for (i, j, k) in [(0, 0, 0), (3, 20, 40), (30, 45, 170), (60, 10, 90)] {
        let (th, td, pd) = sunshade::scene::measured::merl_bin_angles(i, j, k);
        let (l, v) = sunshade::shading::measured::half_diff_directions(th, td, pd);
        let got = sunshade::shading::measured::measured_brdf(&parsed, Default::default(), DVec3::Z, l, v);
        let want = analytic(&ward(), l, v);
        assert!((0..3).all(|c| (got[c] - want[c]).abs() <= 1e-6 * want[c]), "{i} {j} {k}: {got:?} {want:?}");
    }
    let o = sunshade(&["fit-brdf", t, "--model", "ward", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let fit: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!((fit["parameters"]["alpha"].as_f64().unwrap() - 0.2).abs() < 1e-4, "{fit}");
    assert!(fit["relative_rms"][0].as_f64().unwrap() < 1e-4 && fit["energy_conserving"] == true);
    // The snippet is a material.
    let snippet = sphere(&dir, "snippet", fit["extras"]["sunshade"].clone());
    assert_eq!(snippet.materials[0].brdf, ward());

    let scene =
        dir.write("scene.glb", &sphere_scene(&ChartMaterial { name: "m".into(), extras: json!({"brdf": "lambert"}) }));
    let out = dir.path("merl.exr");
    let o = sunshade(&[
        "render",
        scene.to_str().unwrap(),
        "--merl",
        t,
        "--sky-radiance",
        "50",
        "--width",
        "64",
        "--height",
        "64",
        "--check",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("result: PASS"));
    // The image says which measurement it shows.
    let meta = exr::meta::MetaData::read_from_file(&out, false).unwrap();
    let all: serde_json::Value = match meta.headers[0].own_attributes.other.get(&exr::prelude::Text::from("sunshade")) {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => serde_json::from_str(&t.to_string()).unwrap(),
        other => panic!("sunshade attribute: {other:?}"),
    };
    assert_eq!(all["sunshadeMeasured"][0]["file"], json!(t), "{all}");
    assert_eq!(all["sunshadeMeasured"][0]["lookup"], json!("linear"));
    // No error bound is derived for tables: --tolerance refines their pixels on the reference, and says so.
    let o = sunshade(&[
        "render",
        scene.to_str().unwrap(),
        "--merl",
        t,
        "--tolerance",
        "1e-2",
        "--shadows",
        "none",
        "--width",
        "32",
        "--height",
        "32",
        "-v",
        "-o",
        dir.path("t.exr").to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    if !e.contains("interpolation has no error bound") || e.contains("interpolation's bound") {
        assert!(o.status.success() && e.contains("pixel(s) no bound covers"), "{e}");
        assert!(!e.contains("not bounded"), "{e}");
    }
    let bad = dir.path("bad.binary");
    std::fs::write(&bad, &ward_table_bytes()[..1000]).unwrap();
    let none = dir.path("none.exr");
    let o =
        sunshade(&["render", scene.to_str().unwrap(), "--merl", bad.to_str().unwrap(), "-o", none.to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("bad.binary") && e.contains("truncated") && e.trim().lines().count() == 1, "{e}");
    assert!(!none.exists());
}

/// A measured sphere over a measured floor (one file, one table), under the sun and the sky with shadow rays: the
/// GPU's ray queries against the reference's rays, differences only at pixels with a fragile ray (as for the
/// analytic materials, tests/shadows.rs). Without ray queries, the shader's walk of the BVH, with coarser lobe
/// grids.
#[test]
fn gpu_shadow_rays_on_measured_materials_agree_with_the_reference() {
    use sunshade::authoring::shapes::{quad, uv_sphere};
    use sunshade::authoring::{GltfBuilder, Node};
    use sunshade::scene::{Camera, Projection};
    use sunshade::shading::Shadows;
    let mut gpu = common::shadow_ray_renderer();
    let dir = TempDir::new("merl-shadow");
    write(&dir, "ward.binary", ward_table_bytes());
    let mut b = GltfBuilder::new();
    let m =
        b.add_material("m", [0.5; 3], false, Some(json!({ "sunshade": { "brdf": "merl", "file": "ward.binary" } })));
    let floor = quad(Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.0, 0.0, 3.0), Vec3::new(3.0, 0.0, 0.0));
    let mesh = b.add_mesh("s", &[uv_sphere(Vec3::ZERO, 1.0, 48, 96).primitive(Some(m)), floor.primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    let scene = common::load(&dir.write("shadow.glb", &b));
    let Brdf::Measured { table, .. } = &scene.materials[0].brdf else { panic!("not measured") };
    assert_eq!(scene.materials.len(), 1, "{}", table.name);
    let eye = DVec3::new(0.0, 4.0, 4.0);
    let camera = Camera::looking(
        eye,
        -eye.normalize(),
        DVec3::Y,
        Projection::Orthographic { ymag: 2.5, znear: 1.0, zfar: 12.0 },
    )
    .unwrap();
    let mut lights = Lights { sun: Some(sun(31.0)), sky: Some([50.0; 3]), ..Default::default() };
    lights.sun.as_mut().unwrap().direction = Vec3::new(0.4, 1.0, 0.2).normalize();
    let mut s = RenderSettings::new(96, 96, camera, lights);
    s.shading = ShadingOptions { shadows: Shadows::Ray, shadow_samples_per_axis: 4, ..Default::default() };
    if !gpu.renderer().device_info().ray_query {
        // The shader's own BVH walk: every sky sample of the lobe grids casts a ray, and 16² samples (two grids)
        // would spend llvmpipe's loop budget (the render is refused: gpu::loop_budget); 5² keeps within it (6² did
        // until the sky's visible fraction located its edges: 8 pixels past it).
        s.shading.samples_per_axis = 5;
    }
    let g = gpu.render(&scene, &s);
    let (c, fragile) = cpu::render_with_fragile_pixels(&scene, &s, &gpu.reference_options());
    let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
    let unexplained: Vec<_> =
        report.over_tolerance_pixels.iter().filter(|&&(x, y)| !fragile[(y * c.width() + x) as usize]).collect();
    println!(
        "measured with shadows: max rel {:.2e}, {} over tolerance",
        report.max_rel_interior, report.over_tolerance.total
    );
    assert!(unexplained.is_empty(), "GPU/reference differences away from fragile rays: {unexplained:?}");
}

/// `sunshade albedo SCENE` gives a measured material's directional albedo (by quadrature over the table): the
/// tabulated Ward's is within 1% of the analytic Ward's at every incidence up to 85° (measured 2.0e-4 to 3.3e-3).
#[test]
fn albedo_of_a_measured_material_matches_its_analytic_source() {
    let dir = TempDir::new("merl-albedo");
    write(&dir, "ward.binary", ward_table_bytes());
    let measured = dir.write(
        "m.glb",
        &sphere_scene(&ChartMaterial { name: "m".into(), extras: json!({ "brdf": "merl", "file": "ward.binary" }) }),
    );
    let analytic = dir.write(
        "a.glb",
        &sphere_scene(&ChartMaterial {
            name: "a".into(),
            extras: json!({ "brdf": "ward", "kd": [0.3, 0.25, 0.2], "ks": [0.2, 0.2, 0.2], "alpha": 0.2 }),
        }),
    );
    let table = |path: &std::path::Path| -> Vec<Vec<f64>> {
        let o = sunshade(&["albedo", path.to_str().unwrap()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8_lossy(&o.stdout).into_owned();
        let row = text.lines().find(|l| l.starts_with("| material '")).unwrap_or_else(|| panic!("{text}")).to_string();
        row.split('|')
            .skip(2)
            .filter(|c| !c.trim().is_empty())
            .map(|c| c.split(',').map(|x| x.trim().parse::<f64>().unwrap()).collect())
            .collect()
    };
    let (m, a) = (table(&measured), table(&analytic));
    assert_eq!(m.len(), 5);
    // 0°, 30°, 60°, 85° (89.9° grazes where the table holds its last θ_d bin).
    for i in 0..4 {
        for c in 0..3 {
            let rel = (m[i][c] - a[i][c]).abs() / a[i][c];
            println!("incidence {i}, channel {c}: measured {:.4}, analytic {:.4} ({rel:.1e})", m[i][c], a[i][c]);
            assert!(rel < 1e-2, "incidence {i}, channel {c}: {} against {}", m[i][c], a[i][c]);
        }
    }
}

/// `--tolerance` on measured materials (`accuracy::refinement`): the tabulated Ward sphere (linear lookup) under
/// the sun, under sun and sky, and under a disk light, on the reference: the sun's grid (which has no derived bound
/// for a table) and the lobe grids are refined on one ladder until the estimate fits; every image kept meets T
/// against the converged reference (its unconverged pixels left out) and its prediction, which names nothing
/// unbounded, for T = 1e-2, 1e-3 and 1e-4, and a looser T never takes a finer grid.
#[test]
fn tolerance_estimates_measured_materials_by_refinement() {
    use sunshade::accuracy::trial::{reference_within_tolerance, Tolerance};
    use sunshade::shading::Shadows;
    let dir = TempDir::new("merl-tolerance");
    write(&dir, "ward.binary", ward_table_bytes());
    let scene = sphere(&dir, "measured", json!({ "brdf": "merl", "file": "ward.binary" }));
    let disk = DiskLight {
        center: Vec3::new(1.0, 1.5, 2.5),
        direction: Vec3::new(-1.0, -1.5, -2.5).normalize(),
        radius: 0.6,
        radiance: [200.0, 150.0, 100.0],
    };
    let cases = [
        ("sun", Lights { sun: Some(sun(31.0)), ..Default::default() }),
        ("sun and sky", Lights { sun: Some(sun(31.0)), sky: Some([100.0; 3]), ..Default::default() }),
        ("disk light", Lights { disks: vec![disk], ..Default::default() }),
    ];
    let reference = cpu::ReferenceOptions::default();
    let mut report = String::new();
    for (what, lights) in cases {
        let mut s = settings(&scene, lights, ShadingOptions::default(), 32);
        s.shading.shadows = Shadows::None;
        let mut grids = Vec::new();
        for tolerance in [1e-2, 1e-3, 1e-4] {
            let mut t = s.clone();
            let (image, prediction) = reference_within_tolerance(
                &scene,
                &mut t,
                &reference,
                Shadows::None,
                false,
                Some(Tolerance::outside_penumbrae(tolerance)),
            )
            .unwrap_or_else(|e| panic!("{what}, T = {tolerance:e}: {e}\n{report}"));
            let (measured, left_out) =
                common::error_against_converged(&scene, &s, &image, tolerance / 10.0, &reference);
            report += &format!(
                "{what}, T = {tolerance:e}: sun {}², lobes {}², measured {measured:.2e}, {}, {} pixels left out\n",
                t.shading.sun_samples_per_axis,
                t.shading.samples_per_axis,
                prediction.line(),
                left_out
            );
            assert!(prediction.unbounded.is_empty(), "{what}: {}", prediction.line());
            assert!(measured <= tolerance, "{what}: over T = {tolerance:e}:\n{report}");
            assert!(measured <= prediction.max_relative, "{what}: under-predicted:\n{report}");
            assert!(prediction.max_relative <= tolerance, "{what}: predicted over T:\n{report}");
            grids.push(t.shading.samples_per_axis.max(t.shading.sun_samples_per_axis));
        }
        assert!(grids.windows(2).all(|w| w[0] <= w[1]), "{what}: looser T must cost no more: {grids:?}");
    }
    eprintln!("{report}");
}

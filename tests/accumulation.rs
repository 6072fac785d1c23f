//! Daylight on the command line: the sun of a date, time and place lighting a scene, and irradiation and
//! sun-hours accumulated over time, on the GPU (validation layer on) and the reference, against sums computed
//! here from the solar position: a roof over a day (`Σ E⊥ max(0, cos θ_z) Δt`, and the clear sky's global
//! horizontal irradiance), a north wall at mid-latitude in summer (sun in the morning and evening only), shards
//! that add up to the whole, and a sun below the horizon.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::TempDir;
use glam::Vec3;
use sunshade::authoring::shapes::quad;
use sunshade::authoring::{GltfBuilder, Node};
use sunshade::daylight::clear_sky::{ineichen_perez, ClearSkyInputs};
use sunshade::daylight::{solar_position, Atmosphere, Instant, Location, SpaOptions};
use sunshade::Image;

fn sunshade(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunshade")).args(args).env("SUNSHADE_VALIDATION", "1").output().expect("run")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A 2 m square facing `u × v`.
fn plane(u: Vec3, v: Vec3, center: Vec3) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = b.add_material("m", [0.5; 3], false, None);
    let mesh = b.add_mesh("plane", &[quad(center, u, v).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    b
}

const ZURICH: Location = Location { latitude_deg: 47.37, longitude_deg: 8.54, elevation_m: 408.0 };
const PLACE: &str = "47.37,8.54,408";

/// The sun as the CLI computes it by default (refraction in the standard atmosphere at the site).
fn sun_at(t: Instant) -> sunshade::daylight::SolarPosition {
    let options =
        SpaOptions { delta_t_s: None, delta_ut1_s: 0.0, refraction: Some(Atmosphere::standard(ZURICH.elevation_m)) };
    solar_position(t, &ZURICH, &options)
}

/// The clear sky's global horizontal irradiance [W/m²] at Zurich at `t`, as the CLI's defaults give it.
fn clear_sky_ghi(t: Instant) -> f64 {
    let p = sun_at(t);
    let inputs = ClearSkyInputs {
        linke_turbidity: 3.0,
        elevation_m: ZURICH.elevation_m,
        pressure_mbar: Atmosphere::standard(ZURICH.elevation_m).pressure_mbar,
        distance_au: p.distance_au,
    };
    ineichen_perez(p.zenith_deg, &inputs).ghi
}

/// The `sunshade` JSON attribute of an EXR sunshade wrote.
fn exr_record(path: &Path) -> serde_json::Value {
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    match meta.headers[0].own_attributes.other.get(&exr::prelude::Text::from("sunshade")) {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => serde_json::from_str(&t.to_string()).unwrap(),
        other => panic!("sunshade attribute: {other:?}"),
    }
}

/// Midpoints and lengths [h] of `[from, to)` in steps of `step_h` hours; asserts that no midpoint's sun sits
/// within 0.3° of the horizon, where the disk sun is partly below a horizontal roof and `E⊥ cos θ` is not exact.
fn midpoints(from: &str, to: &str, step_h: f64) -> Vec<(Instant, f64)> {
    let (from, to) = (Instant::parse(from).unwrap(), Instant::parse(to).unwrap());
    let total_h = to.seconds_since(from) / 3600.0;
    let mut out = Vec::new();
    let mut start = 0.0;
    while start < total_h {
        let length = step_h.min(total_h - start);
        let mid = from.plus_seconds((start + 0.5 * length) * 3600.0);
        assert!(sun_at(mid).elevation_deg().abs() > 0.3, "{mid}: the sun is at the horizon; choose other steps");
        out.push((mid, length));
        start += step_h;
    }
    out
}

/// The covered pixels' values (channel 0; all three are equal under a white sun), at least `min` of them.
fn covered(image: &Image, min: usize) -> Vec<f64> {
    let v: Vec<f64> = image.pixels().iter().filter(|p| p[3] > 0.0).map(|p| p[0] as f64).collect();
    assert!(v.len() >= min, "{} covered pixels", v.len());
    for p in image.pixels().iter().filter(|p| p[3] > 0.0) {
        assert!(p[0] == p[1] && p[1] == p[2], "{p:?}");
    }
    v
}

fn worst_relative(values: &[f64], truth: f64) -> f64 {
    values.iter().fold(0.0f64, |w, v| w.max((v - truth).abs() / truth))
}

const VIEW_DOWN: [&str; 8] = ["--eye", "0,2.2,0.001", "--target", "0,0,0", "--width", "32", "--height", "24"];

#[test]
fn a_roof_over_a_day_is_the_sum_of_the_suns_normal_irradiance_times_the_cosine() {
    let dir = TempDir::new("roof-day");
    let roof = dir.write("roof.glb", &plane(Vec3::Z, Vec3::X, Vec3::ZERO));
    let (from, to) = ("2026-06-21T00:20:00+02:00", "2026-06-22T00:20:00+02:00");
    // A delta sun of E⊥ 1000 W/m², no sky: H = Σ 1000 max(0, cos θ_z) Δt over the steps with the sun up.
    let truth: f64 = midpoints(from, to, 1.0)
        .iter()
        .map(|&(t, hours)| {
            let p = sun_at(t);
            if p.is_up() {
                1000.0 * p.zenith_deg.to_radians().cos() * hours
            } else {
                0.0
            }
        })
        .sum();
    assert!(truth > 5000.0, "{truth}");
    for command in ["render", "reference"] {
        let out = dir.path(&format!("{command}.exr"));
        let o = sunshade(
            &[
                &[command, s(&roof), "-o", s(&out), "--quantity", "irradiation", "--location", PLACE],
                &["--from", from, "--to", to, "--step", "1h", "--sun-irradiance", "1000", "--sky-radiance", "0"][..],
                &["--sun-model", "delta", "-v"],
                &VIEW_DOWN,
            ]
            .concat(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
        // Without --shard no shard is spoken of.
        let err = stderr(&o);
        assert!(err.contains("of 24 steps rendered (the sun up)") && !err.contains("shard"), "{err}");
        let image = sunshade::film::read_image(&out).unwrap();
        let worst = worst_relative(&covered(&image, 500), truth);
        eprintln!("roof, delta sun, {command}: {truth:.3} Wh/m², max relative error {worst:.2e}");
        assert!(worst <= 1e-5, "{command}: {worst:e}");
        // The file says what it holds.
        let meta = exr::meta::MetaData::read_from_file(&out, false).unwrap();
        let layer = &meta.headers[0].own_attributes;
        assert_eq!(layer.layer_name.as_ref().map(|n| n.to_string()), Some("irradiation".to_string()));
        let all = exr_record(&out);
        assert!(all["quantity"].as_str().unwrap().starts_with("irradiation Wh/m2"), "{all}");
        assert_eq!(all["sunshadeAccumulation"]["steps_total"], 24, "{all}");
    }
}

#[test]
fn a_roof_under_the_clear_sky_gathers_its_global_horizontal_irradiation() {
    // The default disk sun and the clear sky: the roof sees the sun's DNI cos θ_z and the uniform sky's π L =
    // DHI, so H = Σ GHI Δt, with GHI from the Ineichen–Perez model here (2-hour steps, 15 June).
    let dir = TempDir::new("roof-clear");
    let roof = dir.write("roof.glb", &plane(Vec3::Z, Vec3::X, Vec3::ZERO));
    let (from, to) = ("2026-06-15T00:10:00+02:00", "2026-06-16T00:10:00+02:00");
    let truth: f64 = midpoints(from, to, 2.0).iter().map(|&(t, hours)| clear_sky_ghi(t) * hours).sum();
    let out = dir.path("clear.exr");
    let o = sunshade(
        &[
            &["render", s(&roof), "-o", s(&out), "--quantity", "irradiation", "--location", PLACE][..],
            &["--from", from, "--to", to, "--step", "2h"],
            &VIEW_DOWN,
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let worst = worst_relative(&covered(&sunshade::film::read_image(&out).unwrap(), 500), truth);
    eprintln!("roof, clear sky: {truth:.1} Wh/m² (GHI summed), max relative error {worst:.2e}");
    assert!((7000.0..9000.0).contains(&truth) && worst <= 1e-5, "{truth}: {worst:e}");
}

#[test]
fn a_north_wall_in_summer_gets_sun_only_in_the_morning_and_evening() {
    // A wall facing north (−Z, the default --north) at 47° N on 21 June: the sun rises in the north-east and
    // sets in the north-west, and stands in the south at midday.
    let dir = TempDir::new("north-wall");
    let wall = dir.write("wall.glb", &plane(Vec3::Y, Vec3::X, Vec3::new(0.0, 1.0, 0.0)));
    let view = ["--eye", "0,1,-2.2", "--target", "0,1,0", "--width", "32", "--height", "24"];
    let windows = [
        ("morning", "2026-06-21T04:10:00+02:00", "2026-06-21T09:10:00+02:00", true),
        ("midday", "2026-06-21T11:10:00+02:00", "2026-06-21T15:10:00+02:00", false),
        ("evening", "2026-06-21T17:10:00+02:00", "2026-06-21T21:10:00+02:00", true),
    ];
    for (name, from, to, sunny) in windows {
        let steps = midpoints(from, to, 0.5);
        // The wall's normal is north: n·s = sin θ_z cos A (A the compass azimuth).
        let direct = |t: Instant| {
            let p = sun_at(t);
            let cos = p.zenith_deg.to_radians().sin() * p.azimuth_deg.to_radians().cos();
            if p.is_up() {
                1000.0 * cos.max(0.0)
            } else {
                0.0
            }
        };
        let truth: f64 = steps.iter().map(|&(t, h)| direct(t) * h).sum();
        let hours: f64 = steps.iter().filter(|&&(t, _)| direct(t) >= 120.0).map(|&(_, h)| h).sum();
        assert_eq!(truth > 0.0, sunny, "{name}: {truth}");
        for (quantity, expected) in [("irradiation", truth), ("sun-hours", hours)] {
            let out = dir.path(&format!("{name}-{quantity}.exr"));
            let o = sunshade(
                &[
                    &["render", s(&wall), "-o", s(&out), "--quantity", quantity, "--location", PLACE][..],
                    &["--from", from, "--to", to, "--step", "30min", "--sun-irradiance", "1000", "--sky-radiance", "0"],
                    &["--sun-model", "delta"],
                    &view,
                ]
                .concat(),
            );
            assert!(o.status.success(), "{}", stderr(&o));
            let values = covered(&sunshade::film::read_image(&out).unwrap(), 200);
            eprintln!(
                "north wall, {name}, {quantity}: expected {expected:.4}, got {:.4}..{:.4}",
                values[0],
                values[values.len() - 1]
            );
            if expected == 0.0 {
                assert!(values.iter().all(|&v| v == 0.0), "{name} {quantity}: the wall is lit at midday");
            } else {
                assert!(worst_relative(&values, expected) <= 1e-5, "{name} {quantity}: {values:?} against {expected}");
            }
        }
    }
}

#[test]
fn shards_add_up_to_the_whole() {
    let dir = TempDir::new("shards");
    let roof = dir.write("roof.glb", &plane(Vec3::Z, Vec3::X, Vec3::ZERO));
    let base = [
        &["render", s(&roof), "--quantity", "irradiation", "--location", PLACE, "-q"][..],
        &["--from", "2026-03-01T00:00Z", "--to", "2026-03-03T00:00Z", "--step", "3h"],
        &VIEW_DOWN,
    ]
    .concat();
    let whole = dir.path("whole.exr");
    assert!(sunshade(&[&base[..], &["-o", s(&whole)]].concat()).status.success());
    let mut parts = Vec::new();
    for k in 0..3 {
        let part = dir.path(&format!("part{k}.exr"));
        let shard = format!("{k}/3");
        let o = sunshade(&[&base[..], &["-o", s(&part), "--shard", &shard]].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        parts.push(part);
    }
    let total = dir.path("total.exr");
    let args: Vec<&str> = ["sum"].into_iter().chain(parts.iter().map(|p| s(p))).chain(["-o", s(&total)]).collect();
    assert!(sunshade(&args).status.success());
    let (w, t) = (sunshade::film::read_image(&whole).unwrap(), sunshade::film::read_image(&total).unwrap());
    let values = covered(&w, 500);
    assert!(values[0] > 1000.0);
    for (p, q) in w.pixels().iter().zip(t.pixels()) {
        assert_eq!(p[3], q[3]);
        // Each shard is rounded to f32 once, and their sum once more: a few ulps apart at most.
        assert!((p[0] - q[0]).abs() <= 4.0 * f32::EPSILON * p[0], "{p:?} {q:?}");
    }
    // diff reads the quantity the files record: its errors in Wh/m²; a radiance image is not compared with it.
    let o = sunshade(&["diff", s(&whole), s(&total)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = String::from_utf8_lossy(&o.stdout);
    assert!(report.contains("max abs error") && report.contains("Wh/m²") && !report.contains("sr)"), "{report}");
    let radiance = dir.path("radiance.exr");
    let o = sunshade(&[&["render", s(&roof), "-o", s(&radiance), "-q"][..], &VIEW_DOWN].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    for command in ["diff", "sum"] {
        let mixed = dir.path("mixed.exr");
        let o = sunshade(&[command, s(&whole), s(&radiance), "-o", s(&mixed)]);
        assert_eq!(o.status.code(), Some(2), "{command}: {}", stderr(&o));
        assert!(stderr(&o).contains("holds irradiation") && stderr(&o).contains("holds radiance"), "{}", stderr(&o));
        assert!(!mixed.exists());
    }
}

#[test]
fn time_and_place_set_the_sun_and_a_night_is_dark_with_a_warning() {
    let dir = TempDir::new("night");
    let roof = dir.write("roof.glb", &plane(Vec3::Z, Vec3::X, Vec3::ZERO));
    let out = dir.path("night.exr");
    let o = sunshade(
        &[
            &["render", s(&roof), "-o", s(&out), "--time", "2026-06-21T01:00:00+02:00", "--location", PLACE][..],
            &VIEW_DOWN,
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("below the horizon"), "{}", stderr(&o));
    let image = sunshade::film::read_image(&out).unwrap();
    assert!(image.pixels().iter().filter(|p| p[3] > 0.0).count() > 500);
    assert!(image.pixels().iter().all(|p| p[0] == 0.0 && p[1] == 0.0 && p[2] == 0.0));
    // At noon the roof is lit by the sun and sky of the clear-sky model: irradiance = GHI.
    let noon = Instant::parse("2026-06-21T13:30:00+02:00").unwrap();
    let (p, ghi) = (sun_at(noon), clear_sky_ghi(noon));
    let o = sunshade(
        &[
            &["render", s(&roof), "-o", s(&out), "--time", "2026-06-21T13:30:00+02:00", "--location", PLACE][..],
            &["--quantity", "irradiance"],
            &VIEW_DOWN,
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let worst = worst_relative(&covered(&sunshade::film::read_image(&out).unwrap(), 500), ghi);
    assert!(worst <= 1e-5, "noon: {worst:e} against GHI {ghi}");
    // The image records where the sun stood and what the clear sky gave.
    let all = exr_record(&out);
    let recorded = &all["sunshadeDaylight"];
    assert_eq!(recorded["time"], "2026-06-21T11:30:00Z", "{all}");
    assert!((recorded["zenith_deg"].as_f64().unwrap() - p.zenith_deg).abs() < 1e-12, "{all}");
    assert!((recorded["clear_sky"]["ghi_w_m2"].as_f64().unwrap() - ghi).abs() < 1e-9 * ghi, "{all}");
    // `sunshade sun --json`: the fields the issue names, and the direction in scene axes (north −Z).
    let o = sunshade(&["sun", "--time", "2026-06-21T13:30:00+02:00", "--location", PLACE, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!((j["zenith_deg"].as_f64().unwrap() - p.zenith_deg).abs() < 1e-12);
    assert!((j["azimuth_deg"].as_f64().unwrap() - p.azimuth_deg).abs() < 1e-12);
    assert_eq!((j["refraction"].as_bool(), j["up"].as_bool()), (Some(true), Some(true)));
    let d: Vec<f64> = j["direction"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let (z, a) = (p.zenith_deg.to_radians(), p.azimuth_deg.to_radians());
    let expected = [z.sin() * a.sin(), z.cos(), -z.sin() * a.cos()]; // east +X, up +Y, north −Z
    for (got, want) in d.iter().zip(expected) {
        assert!((got - want).abs() < 1e-12, "{d:?} against {expected:?}");
    }
}

#[test]
fn daylight_flags_that_mean_nothing_are_refused_in_one_line() {
    let dir = TempDir::new("daylight-refusals");
    let roof = dir.write("roof.glb", &plane(Vec3::Z, Vec3::X, Vec3::ZERO));
    let out = dir.path("x.exr");
    let base = ["render", s(&roof), "-o", s(&out)];
    for (extra, names) in [
        (&["--time", "2026-06-21T12:00:00+02:00"][..], "--location"),
        (&["--time", "2026-06-21T12:00:00", "--location", PLACE][..], "no UTC offset"),
        (&["--time", "2026-06-21T12:00Z", "--location", PLACE, "--sun-dir", "0,1,0"][..], "--sun-dir"),
        (&["--location", "95,0", "--time", "2026-06-21T12:00Z"][..], "latitude"),
        (&["--quantity", "irradiation"][..], "--from"),
        (&["--time", "2026-06-21T12:00Z", "--location", PLACE, "--linke-turbidity", "20"][..], "--linke-turbidity"),
        (&["--time", "2026-06-21T12:00Z", "--location", PLACE, "--pressure", "5"][..], "--pressure"),
        (
            &["--location", PLACE, "--from", "2026-06-21T00:00Z", "--to", "2026-06-22T00:00Z", "--step", "1h"][..],
            "irradiation or sun-hours",
        ),
        (
            &[
                "--location",
                PLACE,
                "--from",
                "2026-06-22T00:00Z",
                "--to",
                "2026-06-21T00:00Z",
                "--step",
                "1h",
                "--quantity",
                "irradiation",
            ][..],
            "not after",
        ),
        (
            &[
                "--location",
                PLACE,
                "--from",
                "2026-06-21T00:00Z",
                "--to",
                "2026-06-22T00:00Z",
                "--step",
                "1y",
                "--quantity",
                "irradiation",
            ][..],
            "duration",
        ),
        (
            &[
                "--location",
                PLACE,
                "--from",
                "2000-01-01T00:00Z",
                "--to",
                "2900-01-01T00:00Z",
                "--step",
                "1s",
                "--quantity",
                "irradiation",
            ][..],
            "at most",
        ),
    ] {
        let o = sunshade(&[&base[..], extra].concat());
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(names) && e.trim().lines().count() == 1, "{extra:?}: {e}");
        assert!(!out.exists());
    }
}

//! `--tolerance` without a study (`render::refined_pixels`): the GPU shades the pixels whose error has a derived
//! bound, its first draw alone marking every pixel whose lights it does not settle; the reference refines the
//! marked pixels and those of materials without a bound, one by one. Validation is on in every GPU render.

mod common;

use sunshade::accuracy::converged::{render_converged, ConvergenceOptions};
use sunshade::accuracy::error::image_error;
use sunshade::gpu::second_draw::LEFT_TO_SECOND_DRAW;
use sunshade::gpu::Interpolation;
use sunshade::settings::RenderSettings;
use sunshade::shading::{Shadows, VisibilityRule};
use sunshade::testing::{job, CheckedRenderer};

/// The first draw alone shades every pixel it settles exactly as the two draws do (bit for bit), and marks every
/// pixel in a penumbra (`accuracy::penumbrae`, the reference's own soft-against-hard test at the render's grid): the
/// pixels it leaves unmarked need nothing the second draw computes. Under the sun (teapot.glb, sunset.glb) and a
/// disk light (room.gltf); where a draw has no first draw (the sky through occluders, overcast.glb) it draws
/// nothing.
#[test]
fn gpu_the_first_draw_alone_settles_what_two_draws_do_and_marks_every_penumbra() {
    let mut gpu = common::shadow_ray_renderer();
    let reference = gpu.reference_options();
    for name in ["teapot.glb", "sunset.glb", "room.gltf"] {
        let (scene, mut s) = common::sliced(name, (64, 48), 6);
        s.shading.visibility_rule = VisibilityRule::Grid;
        let both = gpu.render(&scene, &s);
        let r = gpu.renderer();
        let gpu_scene = r.upload(&scene).unwrap();
        let (first, _) = r.render_leaving_penumbrae(&gpu_scene, &s).unwrap().expect("a first draw");
        drop(gpu_scene);
        let penumbrae = sunshade::accuracy::penumbrae::penumbra_mask(&scene, &s, &reference);
        let (mut marked, mut in_penumbrae) = (0, 0);
        for (i, (f, b)) in first.pixels().iter().zip(both.pixels()).enumerate() {
            if f[3] == LEFT_TO_SECOND_DRAW {
                marked += 1;
                continue;
            }
            let bits = |p: &[f32; 4]| p.map(f32::to_bits);
            assert_eq!(bits(f), bits(b), "{name}: pixel {i} settled by the first draw differs from two draws'");
            assert!(!penumbrae[i] || b[3] <= 0.0, "{name}: pixel {i} in a penumbra left unmarked");
            in_penumbrae += usize::from(penumbrae[i]);
        }
        let soft = penumbrae.iter().zip(both.pixels()).filter(|(&p, b)| p && b[3] > 0.0).count();
        eprintln!("{name}: {marked} marked, {soft} covered pixels in a penumbra");
        assert!(soft > 0 && marked >= soft && in_penumbrae == 0, "{name}: {marked} marked, {soft} in a penumbra");
    }
    let (scene, mut s) = common::sliced("overcast.glb", (64, 48), 6);
    s.shading.visibility_rule = VisibilityRule::Grid;
    let r = gpu.renderer();
    let gpu_scene = r.upload(&scene).unwrap();
    assert!(r.render_leaving_penumbrae(&gpu_scene, &s).unwrap().is_none(), "the sky's grid settles no pixel");
}

/// A case of [`render_tolerance_refines_the_pixels_no_bound_covers`]: model, light flags, width and height,
/// tolerances.
type Case<'a> = (&'a str, &'a [&'a str], [&'a str; 2], &'a [f64]);

/// `render --tolerance T` (held in penumbrae, its default) meets T over every pixel against the converged
/// reference claimed at T/10, and `-v` says which pixels came from the reference and that nothing is left
/// unbounded: the sun's penumbrae (sunset.glb, 1e-2 and 1e-4), a disk skylight's (room.gltf), the sky through an
/// occluder (overcast.glb, every covered pixel refined), the BRDF chart's specular spheres under a disk light
/// and the sky (lobe grids without a bound; brdfs.glb).
#[test]
fn render_tolerance_refines_the_pixels_no_bound_covers() {
    let mut gpu = common::shadow_ray_renderer();
    if gpu.renderer().interpolation() != Interpolation::BarycentricF64 {
        return; // f32 barycentrics keep their bound beside the models' (tests/accuracy.rs); device has none
    }
    let chart_lights = ["--disk-light", "0,3,2:0,-1,0:0.8:2000", "--sky-radiance", "300", "--sun-elevation", "35"];
    // (model, lights, sizes, tolerances): the chart smaller, its specular lobes' truth under the sky being the
    // slowest (89 s at 40 × 30).
    let cases: [Case; 4] = [
        ("sunset.glb", &[], ["40", "30"], &[1e-2, 1e-4]),
        ("room.gltf", &[], ["40", "30"], &[1e-2]),
        ("overcast.glb", &[], ["40", "30"], &[1e-2]),
        ("brdfs.glb", &chart_lights, ["24", "18"], &[1e-2]),
    ];
    for (name, lights, [w, h], tolerances) in cases {
        for &t in tolerances {
            let path = format!("{}/models/{name}", env!("CARGO_MANIFEST_DIR"));
            let t_flag = format!("{t:e}");
            let flags = [&["--width", w, "--height", h, "--tolerance", &t_flag][..], lights].concat();
            refines_within(&mut gpu, &path, &flags, t, 6);
        }
    }
}

/// Renders `path` with `flags` (holding `--tolerance t`) and checks it against the converged reference claimed at
/// t/10 (at most `doublings` doublings): the prediction is at most t with nothing unbounded, it names the refined
/// pixels, and the image meets t over every pixel the truth converged (which must be nearly all). Returns the
/// prediction's line.
fn refines_within(gpu: &mut CheckedRenderer, path: &str, flags: &[&str], t: f64, doublings: u32) -> String {
    let reference = gpu.reference_options();
    let name = std::path::Path::new(path).file_name().unwrap().to_string_lossy().to_string();
    let j = job(path, flags).unwrap();
    let started = std::time::Instant::now();
    let rendered = gpu.rendered_job(&j).unwrap();
    let render_time = started.elapsed();
    let line = rendered.prediction.line();
    assert!(rendered.prediction.unbounded.is_empty(), "{name} at {t:e}: {line}");
    assert!(rendered.prediction.max_relative <= t, "{name} at {t:e}: {line}");
    let refined = rendered.refined.as_ref().expect("refined on the reference");
    let count = refined.iter().filter(|&&f| f).count();
    assert!(count > 0 && line.contains(&format!("the {count} pixel(s) no bound covers")), "{line}");
    let (scene, mut s): (_, RenderSettings) = j.prepare().unwrap();
    s.shading.shadows = Shadows::Ray;
    s.shading.visibility_rule = VisibilityRule::Slices;
    let truth = render_converged(
        &scene,
        &s,
        &reference,
        &ConvergenceOptions { accuracy: (t / 10.0).max(1e-5), max_refinements: doublings },
    );
    // The truth's pixels still moving are left out of the measurement, unless every one moved by less than t/10.
    let settled = truth.unconverged.iter().all(|u| u.change < t / 10.0);
    let left_out = truth.unconverged_mask();
    let e = image_error(&rendered.image, &truth.image, (!settled).then_some(&left_out)).unwrap();
    eprintln!(
        "{name}, T = {t:e}: {count} pixels refined, measured {:.2e} ({} unconverged in the truth); render {:.1} s, \
         truth {:.1} s",
        e.max_rel,
        truth.unconverged.len(),
        render_time.as_secs_f64(),
        (started.elapsed() - render_time).as_secs_f64()
    );
    assert!(e.max_rel <= t, "{name} at {t:e}: measured {:.3e}; {line}", e.max_rel);
    assert_eq!(e.coverage_mismatches, 0, "{name}");
    // Where the measurement leaves out the truth's unconverged pixels, they must stay few for it to mean something.
    assert!(settled || truth.unconverged.len() * 20 <= rendered.image.covered_count(), "{}", truth.summary());
    line
}

/// A glTF mirror (metallic 1, roughness 0: GGX's α = 10⁻³, a lobe narrower than the sun's disk, which no sun grid up
/// to 64² bounds to 1e-3) under the sun: `--tolerance 1e-3` refines its pixels on the reference instead of refusing,
/// and meets T.
#[test]
fn render_tolerance_refines_a_lobe_too_narrow_for_the_suns_grid() {
    use sunshade::authoring::shapes::uv_sphere;
    use sunshade::authoring::{GltfBuilder, Node};
    let mut gpu = common::shadow_ray_renderer();
    if gpu.renderer().interpolation() != Interpolation::BarycentricF64 {
        return;
    }
    let dir = common::TempDir::new("tolerance-mirror");
    let mut b = GltfBuilder::new();
    let m = b.add_material_json(serde_json::json!({
        "name": "mirror",
        "pbrMetallicRoughness": { "baseColorFactor": [0.9, 0.7, 0.4, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.0 },
    }));
    let mesh = b.add_mesh("sphere", &[uv_sphere(glam::Vec3::ZERO, 1.0, 48, 96).primitive(Some(m))]);
    let n = b.add_node(Node { mesh: Some(mesh), ..Default::default() });
    b.add_scene(&[n], None);
    let path = dir.write("mirror.glb", &b);
    let flags = ["--width", "24", "--height", "24", "--eye", "0,0,4", "--target", "0,0,0", "--sun-dir", "0.3,0.4,1"];
    let flags = [&flags[..], &["--tolerance", "1e-3"]].concat();
    // The truth needs more doublings than the others' six for a lobe this narrow.
    let line = refines_within(&mut gpu, path.to_str().unwrap(), &flags, 1e-3, 10);
    assert!(line.contains("α=0.001: no sun grid reaches the tolerance, its pixels refined"), "{line}");
}

/// `render --tolerance T --check` compares the GPU's pixels with the reference at the render's settings and the
/// refined pixels as they are (they are the reference's): it passes on sunset.glb, whose penumbrae the render's grid
/// would leave far from the refined values.
#[test]
fn render_tolerance_check_takes_the_refined_pixels_as_they_are() {
    let dir = common::TempDir::new("tolerance-refined-check");
    let out = dir.path("sunset.exr");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_sunshade"))
        .args(["render", "models/sunset.glb", "--width", "48", "--height", "36", "--tolerance", "1e-3", "--check"])
        .arg("-o")
        .arg(&out)
        .env("SUNSHADE_VALIDATION", "1")
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && out.exists(), "{e}{}", String::from_utf8_lossy(&o.stdout));
}

/// The library's check of a `--tolerance` render (`testing::check_rendered_against_reference`) takes the refined
/// pixels as they are, as the command line's does: it passes on sunset.glb at 1e-3 with the diff's default
/// tolerance, where the reference at the render's grid is far from the refined penumbrae.
#[test]
fn the_library_checks_a_tolerance_render_as_the_command_line_does() {
    use sunshade::compare::DiffOptions;
    let mut gpu = CheckedRenderer::new();
    let reference = gpu.reference_options();
    let path = format!("{}/models/sunset.glb", env!("CARGO_MANIFEST_DIR"));
    let j = job(&path, &["--width", "48", "--height", "36", "--tolerance", "1e-3"]).unwrap();
    let rendered = gpu.rendered_job(&j).unwrap();
    assert!(rendered.refined.as_ref().is_some_and(|r| r.contains(&true)), "{}", rendered.prediction.line());
    let report =
        sunshade::testing::check_rendered_against_reference(&j, &rendered, &reference, &DiffOptions::default());
    assert!(report.is_ok(), "{}", report.err().map(|e| e.to_string()).unwrap_or_default());
}

/// `--tolerance-by-study` keeps the study over a ladder of whole renders: `-v` names its estimate, not refined
/// pixels, and no pixel is taken from a per-pixel refinement.
#[test]
fn tolerance_by_study_keeps_the_ladder() {
    let mut gpu = CheckedRenderer::new();
    let path = format!("{}/models/sunset.glb", env!("CARGO_MANIFEST_DIR"));
    let flags = ["--width", "32", "--height", "24", "--tolerance", "1e-2", "--tolerance-by-study"];
    let rendered = gpu.rendered_job(&job(&path, &flags).unwrap());
    let Ok(rendered) = rendered else { return }; // a device without f64 interpolation may refuse by name
    let line = rendered.prediction.line();
    assert!(rendered.refined.is_none() && line.contains("estimated by refinement"), "{line}");
}

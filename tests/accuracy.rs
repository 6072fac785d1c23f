//! Speed against error: the converged reference (its claim checked by one more doubling, its unconverged pixels
//! reported), on the CPU only.

mod common;

use glam::DVec3;
use sunshade::accuracy::converged::{doubled, render_converged, ConvergenceOptions};
use sunshade::authoring::chart;
use sunshade::cpu::{self, ReferenceOptions};
use sunshade::settings::{self, CameraOptions, LightOptions, SunOptions};
use sunshade::shading::{ShadingOptions, Shadows};

fn chart_scene(name: &str, dir: &common::TempDir) -> sunshade::scene::Scene {
    let material = chart::brdf_chart().into_iter().find(|m| m.name == name).expect("a chart material");
    common::load(&dir.write(&chart::file_name(&material), &chart::sphere_scene(&material)))
}

#[test]
fn the_converged_reference_meets_its_claim_by_one_more_doubling() {
    let dir = common::TempDir::new("converged");
    // A glossy lobe (Blinn-Phong e = 100) under a 5° sun and an overcast sky: the sun and lobe grids matter.
    let scene = chart_scene("Blinn-Phong e=100", &dir);
    let lights = LightOptions {
        sun: SunOptions {
            direction: Some(DVec3::from_array(chart::sun_direction(20.0))),
            diameter_degrees: Some(5.0),
            ..Default::default()
        },
        sky: Some([20.0; 3]),
        shading: ShadingOptions { sun_samples_per_axis: 2, samples_per_axis: 4, ..Default::default() },
        ..Default::default()
    };
    let s = settings::resolve_with(&scene, 48, 48, &CameraOptions::default(), &lights).unwrap();
    let reference = ReferenceOptions::default();
    let accuracy = 1e-3;
    let c = render_converged(&scene, &s, &reference, &ConvergenceOptions { accuracy, max_refinements: 8 });
    assert!(c.refinements >= 2, "the coarse start must need refining: {}", c.summary());
    // One more doubling of the final counts, for every pixel: the converged pixels move by less than the claim.
    let mut finer = s.clone();
    finer.shading = doubled(&c.shading);
    let check = cpu::render(&scene, &finer, &reference);
    let unconverged: Vec<(u32, u32)> = c.unconverged.iter().map(|u| (u.x, u.y)).collect();
    let peak = c.image.pixels().iter().flat_map(|p| p[..3].iter().map(|&v| v as f64)).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for y in 0..48 {
        for x in 0..48 {
            if unconverged.contains(&(x, y)) {
                continue;
            }
            let (a, b) = (c.image.get(x, y), check.get(x, y));
            for k in 0..3 {
                let (a, b) = (a[k] as f64, b[k] as f64);
                worst = worst.max((a - b).abs() / a.abs().max(b.abs()).max(0.01 * peak));
            }
        }
    }
    assert!(worst < accuracy, "a converged pixel moved by {worst:.2e} on one more doubling: {}", c.summary());
    // Most of the sphere converges; whatever did not is listed, largest change first.
    assert!(c.unconverged.len() < c.covered / 20, "{}", c.summary());
    assert!(c.unconverged.windows(2).all(|w| w[0].change >= w[1].change));
    assert!(c.unconverged.iter().all(|u| u.change >= accuracy / 10.0));
}

#[test]
fn pixels_that_do_not_converge_are_reported() {
    let dir = common::TempDir::new("unconverged");
    // The sphere's own shadow edge and the sky's horizon: one doubling cannot move them by less than 1e-7.
    let scene = chart_scene("Phong e=100", &dir);
    let lights = LightOptions {
        sun: SunOptions { direction: Some(DVec3::from_array(chart::sun_direction(85.0))), ..Default::default() },
        sky: Some([20.0; 3]),
        shading: ShadingOptions { shadows: Shadows::Ray, ..Default::default() },
        ..Default::default()
    };
    let s = settings::resolve_with(&scene, 32, 32, &CameraOptions::default(), &lights).unwrap();
    let c = render_converged(
        &scene,
        &s,
        &ReferenceOptions::default(),
        &ConvergenceOptions { accuracy: 1e-6, max_refinements: 1 },
    );
    assert!(!c.converged() && !c.unconverged.is_empty());
    assert_eq!(c.refinements, 1);
    assert!(c.summary().starts_with("not converged to 1e-6 after 1 doublings"), "{}", c.summary());
}

#[test]
fn a_scene_without_sampled_integrals_converges_at_once_and_exactly() {
    let dir = common::TempDir::new("lambert");
    // Lambert under the sun disk and the sky, unshadowed: every irradiance is closed-form, no grid matters (two
    // doublings, the least that converges).
    let scene = chart_scene("Lambert", &dir);
    let lights = LightOptions { sky: Some([20.0; 3]), ..Default::default() };
    let s = settings::resolve_with(&scene, 32, 32, &CameraOptions::default(), &lights).unwrap();
    let reference = ReferenceOptions::default();
    let c = render_converged(&scene, &s, &reference, &ConvergenceOptions::default());
    assert!(c.converged() && c.refinements == 2 && c.last_change == 0.0, "{}", c.summary());
    assert_eq!(common::bits(&c.image), common::bits(&cpu::render(&scene, &s, &reference)));
}

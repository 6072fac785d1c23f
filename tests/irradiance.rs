//! `--quantity irradiance`: the irradiance E [W/m²] at the surface point each pixel sees, against closed forms
//! computed here, on the GPU (validation layer on) and on the reference: the lecture's floor under a disk
//! skylight (the view factor of a parallel disk, every pixel, not only on the axis) and the sun on tilted planes
//! (`E⊥ cos θ`).

mod common;

use common::CheckedRenderer;
use glam::{DVec3, Vec3};
use sunshade::accuracy::predicted;
use sunshade::authoring::shapes::{quad, MeshData};
use sunshade::cpu;
use sunshade::scene::{Brdf, Camera, DiskLight, Lights, Material, Projection, Scene, Sun};
use sunshade::settings::RenderSettings;
use sunshade::shading::{Quantity, ShadingOptions, Shadows};
use sunshade::Image;

fn scene(parts: &[MeshData], albedo: f32) -> Scene {
    // The albedo must not matter: irradiance is what arrives, whatever the surface reflects.
    common::scene_of(parts, Material::with_brdf("grey", Brdf::Lambert { albedo: [albedo; 3] }))
}

fn irradiance_settings(w: u32, h: u32, camera: Camera, lights: Lights) -> RenderSettings {
    let mut s = RenderSettings::new(w, h, camera, lights);
    s.shading = ShadingOptions { quantity: Quantity::Irradiance, shadows: Shadows::None, ..Default::default() };
    s
}

/// An orthographic camera looking straight down at the floor `y = 0` from 10 m.
fn camera_down(ymag: f64) -> Camera {
    Camera::looking(DVec3::Y * 10.0, -DVec3::Y, DVec3::Z, Projection::Orthographic { ymag, znear: 5.0, zfar: 20.0 })
        .unwrap()
}

/// The floor point (y = 0) seen at the centre of pixel (x, y).
fn floor_point(s: &RenderSettings, x: u32, y: u32) -> DVec3 {
    let inv = s.clip_from_world().as_dmat4().inverse();
    let ndc = |v: u32, n: u32| 2.0 * (v as f64 + 0.5) / n as f64 - 1.0;
    let a = inv.project_point3(DVec3::new(ndc(x, s.width), ndc(y, s.height), 0.2));
    let b = inv.project_point3(DVec3::new(ndc(x, s.width), ndc(y, s.height), 0.8));
    a + (b - a) * (-a.y / (b.y - a.y))
}

/// The view factor from a floor element at distance `r` from the axis of a parallel disk of radius `a` at
/// height `h` facing it (Siegel & Howell's configuration factor, differential planar element to a parallel
/// coaxial-or-offset disk): `F = ½ (1 − (r² + h² − a²) / √((r² + h² + a²)² − 4a²r²))`; on the axis
/// `a²/(a² + h²)`. A Lambertian disk of radiance L0 gives `E = π L0 F`. Far from the axis `1 − s/√D` cancels
/// (both terms near 1); since `D − s² = 4a²h²` (s = r² + h² − a²), `1 − s/√D = 4a²h² / (√D (√D + s))`, which
/// keeps every digit.
fn disk_view_factor(r: f64, h: f64, a: f64) -> f64 {
    let s = r * r + h * h - a * a;
    let d = ((r * r + h * h + a * a).powi(2) - 4.0 * a * a * r * r).sqrt();
    // 1 − s/d = (d − s)/d = (d² − s²)/(d (d + s)) = 4a²h² / (d (d + s)); s > −d always (d ≥ |s|).
    0.5 * 4.0 * a * a * h * h / (d * (d + s))
}

fn worst_relative(image: &Image, s: &RenderSettings, exact: impl Fn(DVec3) -> f64) -> (f64, usize) {
    let (mut worst, mut n) = (0.0f64, 0);
    for y in 0..s.height {
        for x in 0..s.width {
            let p = image.get(x, y);
            if p[3] == 0.0 {
                continue;
            }
            let e = exact(floor_point(s, x, y));
            for v in &p[..3] {
                worst = worst.max((*v as f64 - e).abs() / e);
            }
            n += 1;
        }
    }
    (worst, n)
}

#[test]
fn the_floor_under_a_disk_skylight_is_the_view_factor_everywhere() {
    // The lecture's skylight: a disk of radiance L0, radius R, at height f over the floor. Every pixel against
    // π L0 F(r) (the on-axis value π L0 R²/(R² + f²) included), to 1e-5.
    let (l0, radius, f) = (3000.0f32, 0.5f64, 2.0f64);
    let floor = quad(Vec3::ZERO, Vec3::new(0.0, 0.0, 3.0), Vec3::new(3.0, 0.0, 0.0));
    let lights = Lights {
        disks: vec![DiskLight {
            center: Vec3::new(0.0, f as f32, 0.0),
            direction: -Vec3::Y,
            radius: radius as f32,
            radiance: [l0; 3],
        }],
        ..Default::default()
    };
    let s = irradiance_settings(96, 96, camera_down(3.0), lights);
    let exact = |p: DVec3| std::f64::consts::PI * l0 as f64 * disk_view_factor(p.x.hypot(p.z), f, radius);
    let on_axis = std::f64::consts::PI * l0 as f64 * radius * radius / (radius * radius + f * f);
    assert!((exact(DVec3::ZERO) - on_axis).abs() <= 1e-12 * on_axis);
    let mut gpu = CheckedRenderer::new();
    for albedo in [0.2, 0.9] {
        let sc = scene(std::slice::from_ref(&floor), albedo);
        for (name, image) in
            [("gpu", gpu.render(&sc, &s)), ("reference", cpu::render(&sc, &s, &gpu.reference_options()))]
        {
            let (worst, n) = worst_relative(&image, &s, exact);
            eprintln!("disk skylight, albedo {albedo}, {name}: {n} pixels, max relative error {worst:.2e}");
            assert!(n == 96 * 96 && worst <= 1e-5, "{name}: max relative error {worst:e} over {n} pixels");
            // The predicted bound covers the measurement, with nothing left unbounded.
            let renderer = match name {
                "gpu" => predicted::Renderer::Gpu { barycentrics: predicted::Barycentrics::F64 },
                _ => predicted::Renderer::Reference,
            };
            let p = predicted::predict(&sc, &s, renderer, false);
            assert!(p.unbounded.is_empty() && worst <= p.max_relative.max(1e-6), "{name}: {}", p.line());
        }
    }
    // Irradiance has no lobes: a specular material changes neither the image nor the prediction.
    let shiny = common::scene_of(
        std::slice::from_ref(&floor),
        Material::with_brdf("shiny", Brdf::Phong { kd: [0.2; 3], ks: [0.5; 3], exponent: 5000.0 }),
    );
    let p =
        predicted::predict(&shiny, &s, predicted::Renderer::Gpu { barycentrics: predicted::Barycentrics::F64 }, false);
    assert!(p.unbounded.is_empty() && p.max_relative <= 1e-5, "{}", p.line());
}

#[test]
fn the_sun_on_tilted_planes_is_its_normal_irradiance_times_the_cosine() {
    // A floor tilted about z by θ, under the sun at the zenith: E = E⊥ cos θ wherever the whole disk of the
    // sun is above the plane (θ < 90° − 0.265°), for the disk sun and the delta sun alike.
    let e_perp = 1000.0f32;
    let mut gpu = CheckedRenderer::new();
    for degrees in [0.0f64, 30.0, 60.0, 85.0] {
        let t = degrees.to_radians();
        // The plane through the origin spanned by z and (cos θ, sin θ, 0): normal (−sin θ, cos θ, 0).
        let u = Vec3::new(t.cos() as f32, t.sin() as f32, 0.0) * 3.0;
        let plane = quad(Vec3::ZERO, Vec3::new(0.0, 0.0, 3.0), u);
        let sc = scene(&[plane], 0.5);
        for delta in [false, true] {
            let lights = Lights {
                sun: Some(Sun { direction: Vec3::Y, irradiance: [e_perp; 3], angular_diameter: 0.53f32.to_radians() }),
                ..Default::default()
            };
            let mut s = irradiance_settings(64, 64, camera_down(3.0), lights);
            if delta {
                s.shading.sun = sunshade::shading::SunModel::Delta;
            }
            let exact = e_perp as f64 * t.cos();
            for (name, image) in
                [("gpu", gpu.render(&sc, &s)), ("reference", cpu::render(&sc, &s, &gpu.reference_options()))]
            {
                let covered: Vec<&[f32; 4]> = image.pixels().iter().filter(|p| p[3] > 0.0).collect();
                assert!(covered.len() > 300, "{degrees}°: {} pixels", covered.len());
                let worst = covered
                    .iter()
                    .flat_map(|p| p[..3].iter())
                    .fold(0.0f64, |w, &v| w.max((v as f64 - exact).abs() / exact));
                eprintln!("sun, plane at {degrees}°, delta {delta}, {name}: max relative error {worst:.2e}");
                assert!(worst <= 1e-5, "{name}, plane at {degrees}°, delta {delta}: {worst:e}");
            }
        }
    }
}

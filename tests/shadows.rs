//! Shadows: the reference's visible fractions against closed forms and the hard cases of the shadows issue
//! (terminator, acne at grazing sun, contact shadows, thin occluders, the sun at the horizon, scales from 1 mm to
//! 10 km); and the GPU's ray queries against the reference, where the device has them (the test command runs
//! these on the lavapipe of `scripts/lavapipe-rt.sh` with `SUNSHADE_REQUIRE_RAY_QUERIES=1`, so that a device
//! without them fails there instead of skipping).

mod common;

use std::f64::consts::PI;

use common::CheckedRenderer;
use glam::{DVec3, Vec3};
use sunshade::authoring::shapes::{cube, icosphere, quad, uv_sphere, MeshData};
use sunshade::compare::{self, DiffOptions};
use sunshade::cpu::{self, ReferenceOptions};
use sunshade::scene::{Brdf, Camera, Lights, Material, MetallicRoughness, Projection, Scene, Sun};
use sunshade::settings::RenderSettings;
use sunshade::shading::quadrature::integrate_composite;
use sunshade::shading::visibility::shadow_ray_origin;
use sunshade::shading::{
    irradiance_visible, Occlusion, ShadingOptions, ShadowedLights, Shadowing, Shadows, SurfacePoint, VisibilityRule,
    DEFAULT_SHADOW_SAMPLES_PER_AXIS,
};
use sunshade::visibility::Bvh;
use sunshade::Image;

const E_PERP: f32 = 1000.0;

fn material(double_sided: bool) -> Material {
    Material {
        double_sided,
        pbr: MetallicRoughness {
            base_color: [1.0; 3],
            metallic: 0.0,
            roughness: 1.0,
            specular: sunshade::scene::material::DielectricSpecular::DEFAULT,
        },
        ..Material::with_brdf("white", Brdf::Lambert { albedo: [1.0; 3] })
    }
}

/// `mesh` scaled by `scale` about the origin and moved by `offset` [m].
fn placed(mesh: &MeshData, scale: f32, offset: Vec3) -> MeshData {
    MeshData {
        positions: mesh.positions.iter().map(|p| (Vec3::from_array(*p) * scale + offset).to_array()).collect(),
        ..mesh.clone()
    }
}

fn scene(parts: &[MeshData]) -> Scene {
    common::scene_of(parts, material(false))
}

fn sun_lights(direction: DVec3, diameter_degrees: f64) -> Lights {
    Lights {
        sun: Some(Sun {
            direction: direction.normalize().as_vec3(),
            irradiance: [E_PERP; 3],
            angular_diameter: (diameter_degrees.to_radians()) as f32,
        }),
        ..Default::default()
    }
}

fn settings(width: u32, height: u32, camera: Camera, lights: Lights, shadows: Shadows, k: u32) -> RenderSettings {
    let mut s = RenderSettings::new(width, height, camera, lights);
    s.shading = ShadingOptions { shadows, shadow_samples_per_axis: k, ..Default::default() };
    s
}

/// A floor `y = 0` of half-size `half` [m], facing up.
fn floor(half: f32) -> MeshData {
    quad(Vec3::ZERO, Vec3::new(0.0, 0.0, half), Vec3::new(half, 0.0, 0.0))
}

/// An orthographic camera looking straight down at the floor from `height`, image right along world −x... as
/// the camera's conventions make it; tests find each pixel's floor point by unprojecting ([`floor_point`]).
fn camera_down(center: DVec3, ymag: f64, height: f64) -> Camera {
    Camera::looking(
        center + DVec3::Y * height,
        -DVec3::Y,
        DVec3::Z,
        Projection::Orthographic { ymag, znear: 0.5 * height, zfar: 2.0 * height },
    )
    .expect("a valid camera")
}

/// The floor point (y = 0) seen at the centre of pixel (x, y), by unprojecting through the settings' matrix.
fn floor_point(s: &RenderSettings, x: u32, y: u32) -> DVec3 {
    let inv = s.clip_from_world().as_dmat4().inverse();
    let ndc_x = 2.0 * (x as f64 + 0.5) / s.width as f64 - 1.0;
    let ndc_y = 2.0 * (y as f64 + 0.5) / s.height as f64 - 1.0;
    let a = inv.project_point3(DVec3::new(ndc_x, ndc_y, 0.2));
    let b = inv.project_point3(DVec3::new(ndc_x, ndc_y, 0.8));
    a + (b - a) * (-a.y / (b.y - a.y))
}

/// The exact visible fraction of a sun at the zenith (half-angle σ) from a floor point at x under the half-plane
/// roof `{y = h, x < 0}`, weighted as the renderer weights it: over the disk of directions through the tangent
/// plane one unit up, `P = (X, 1, Z)`, |P − Y| < T = tan σ, weight `cos³γ` (solid angle per area) × `cos γ` (n·ω)
/// = `(1 + X² + Z²)⁻²`; the roof blocks `X < −x/h`. The Z integral in closed form,
/// `∫ (a + Z²)⁻² dZ` over `|Z| ≤ s` = `s/(a(a + s²)) + atan(s/√a)/a^{3/2}` (a = 1 + X²), the X integral by
/// Gauss–Legendre in X = T sin θ (smooth in θ).
fn zenith_sun_fraction_under_edge(x: f64, h: f64, half_angle: f64) -> f64 {
    let t = half_angle.tan();
    let strip = |theta: f64| {
        let (xx, s) = (t * theta.sin(), t * theta.cos());
        let a = 1.0 + xx * xx;
        (s / (a * (a + s * s)) + (s / a.sqrt()).atan() / (a * a.sqrt())) * t * theta.cos()
    };
    let total = integrate_composite(-0.5 * PI, 0.5 * PI, 64, 8, strip);
    let c = (-x / h / t).clamp(-1.0, 1.0);
    integrate_composite(c.asin(), 0.5 * PI, 64, 8, strip) / total
}

/// The floor under a roof that ends at x = 0, at height 1, sun at the zenith of diameter `diameter` degrees.
fn edge_scene() -> Scene {
    // The roof faces down: seen from the camera above it is a culled back face, so the camera sees the floor
    // through it, while shadow rays meet both faces.
    let roof = quad(Vec3::new(-5.0, 1.0, 0.0), Vec3::new(5.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 5.0));
    scene(&[floor(1.0), roof])
}

/// Largest and mean |V − V_exact| along the penumbra of [`edge_scene`] for `k²` shadow rays.
fn penumbra_errors(image: &Image, s: &RenderSettings, half_angle: f64) -> (f64, f64) {
    let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0);
    for y in 0..s.height {
        for x in 0..s.width {
            let p = floor_point(s, x, y);
            let got = image.get(x, y)[0] as f64 / (E_PERP as f64 / PI);
            let want = zenith_sun_fraction_under_edge(p.x, 1.0, half_angle);
            let err = (got - want).abs();
            max = max.max(err);
            sum += err;
            n += 1;
        }
    }
    (max, sum / n as f64)
}

#[test]
fn penumbra_of_a_straight_edge_converges_to_the_circular_segment() {
    // --sun-diameter 10: a penumbra ±tan(5°) = ±87 mm wide under an edge 1 m up; the image spans ±0.15 m.
    let scene = edge_scene();
    let camera = camera_down(DVec3::ZERO, 0.15 / 12.0, 5.0);
    let half_angle = (10f64.to_radians() as f32 as f64) / 2.0;
    let mut errors = Vec::new();
    for k in [4u32, 16, 64] {
        let s = settings(96, 8, camera, sun_lights(DVec3::Y, 10.0), Shadows::Ray, k);
        let image = cpu::render(&scene, &s, &ReferenceOptions::default());
        let (max, mean) = penumbra_errors(&image, &s, half_angle);
        eprintln!("penumbra, {k}x{k} shadow rays: max |V - V_exact| {max:.2e}, mean {mean:.2e}");
        errors.push((k, max, mean));
    }
    // The midpoint rule on the equal-area grid: the edge cuts about k of the k² cells, each worth 1/k², so the
    // error is O(1/k) at worst and falls as k grows; umbra and full light are exact (0 and 1).
    for w in errors.windows(2) {
        assert!(w[1].2 < w[0].2, "the mean error must fall with the samples: {errors:?}");
    }
    for &(k, max, _) in &errors {
        assert!(max <= 1.0 / k as f64, "{k}x{k}: max error {max} above 1/k");
    }
}

/// `accuracy::penumbrae::penumbra_mask` names the pixels in a penumbra: under a straight edge 1 m up and a 10° sun
/// at the zenith, the band `|x| < tan σ` (outside it the sun is wholly visible or wholly hidden), to within 1% of
/// the band's half-width at its borders, where a sliver of the disk falls between the grid's rays; and no pixel
/// where nothing shadows the floor, or where no shadow rays are cast.
#[test]
fn the_penumbra_mask_is_the_band_a_straight_edge_casts() {
    use sunshade::accuracy::penumbrae::penumbra_mask;
    let camera = camera_down(DVec3::ZERO, 0.15 / 12.0, 5.0);
    let half_angle = (10f64.to_radians() as f32 as f64) / 2.0;
    let s = settings(96, 8, camera, sun_lights(DVec3::Y, 10.0), Shadows::Ray, 16);
    let mask = penumbra_mask(&edge_scene(), &s, &ReferenceOptions::default());
    let band = half_angle.tan();
    let (mut inside, mut outside) = (0, 0);
    for y in 0..s.height {
        for x in 0..s.width {
            let distance = floor_point(&s, x, y).x.abs();
            let masked = mask[(y * s.width + x) as usize];
            if distance < 0.99 * band {
                assert!(masked, "({x}, {y}) at {distance:.4} m, inside the penumbra ±{band:.4} m, not masked");
                inside += 1;
            } else if distance > 1.01 * band {
                assert!(!masked, "({x}, {y}) at {distance:.4} m, outside the penumbra ±{band:.4} m, masked");
                outside += 1;
            }
        }
    }
    assert!(inside > 300 && outside > 200, "both sides measured: {inside} inside, {outside} outside");
    let lone = scene(&[floor(1.0)]);
    assert!(!penumbra_mask(&lone, &s, &ReferenceOptions::default()).contains(&true), "nothing shadows the floor");
    let unshadowed = settings(96, 8, camera, sun_lights(DVec3::Y, 10.0), Shadows::None, 16);
    assert!(!penumbra_mask(&edge_scene(), &unshadowed, &ReferenceOptions::default()).contains(&true));
}

#[test]
fn gpu_ray_queries_agree_with_the_reference_on_the_penumbra() {
    let mut gpu = common::shadow_ray_renderer();
    let scene = edge_scene();
    let camera = camera_down(DVec3::ZERO, 0.15 / 12.0, 5.0);
    let s = settings(96, 8, camera, sun_lights(DVec3::Y, 10.0), Shadows::Ray, 16);
    let g = gpu.render(&scene, &s);
    let c = cpu::render(&scene, &s, &gpu.reference_options());
    let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
    assert!(report.pass, "{}", report.text("gpu", "reference"));
    // And against the closed form directly, with the reference's bound at 16² rays.
    let half_angle = (10f64.to_radians() as f32 as f64) / 2.0;
    let (max, _) = penumbra_errors(&g, &s, half_angle);
    assert!(max <= 1.0 / 16.0, "GPU penumbra: max error {max}");
}

/// Sample points on every triangle of an 80-triangle icosphere lit by a sun from `l`: (lit points, those with
/// a visible fraction below 1) with Hanika's terminator origin, and with the naive origin (the point pushed
/// along the face normal only).
fn terminator_counts(l: DVec3) -> ((usize, usize), (usize, usize)) {
    let ico = icosphere(Vec3::ZERO, 1.0, 1);
    let corners =
        |t: &[u32]| t.iter().map(|&i| Vec3::from_array(ico.positions[i as usize]).as_dvec3()).collect::<Vec<_>>();
    let tris: Vec<[DVec3; 3]> = ico.indices.chunks_exact(3).map(|t| corners(t).try_into().unwrap()).collect();
    let bvh = Bvh::new(tris.clone());
    let lights = sun_lights(l, 0.53);
    let options = ShadingOptions { shadow_samples_per_axis: 4, ..Default::default() };
    let (mut hanika, mut naive) = ((0, 0), (0, 0));
    for (t, idx) in tris.iter().zip(ico.indices.chunks_exact(3)) {
        let normals: [DVec3; 3] =
            std::array::from_fn(|k| Vec3::from_array(ico.normals[idx[k] as usize]).as_dvec3().normalize());
        let m = 12;
        for i in 0..=m {
            for j in 0..=(m - i) {
                let b = [i as f64 / m as f64, j as f64 / m as f64, (m - i - j) as f64 / m as f64];
                let x = b[0] * t[0] + b[1] * t[1] + b[2] * t[2];
                let n = (b[0] * normals[0] + b[1] * normals[1] + b[2] * normals[2]).normalize();
                if n.dot(lights.sun.unwrap().direction.as_dvec3()) <= 0.0 {
                    continue;
                }
                let point =
                    SurfacePoint { position: x, normal: n, tangent: DVec3::X, bitangent: DVec3::Z, to_viewer: n };
                let face = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                let offset = sunshade::shading::visibility::ray_offset(t);
                for (origin, count) in
                    [(shadow_ray_origin(t, &normals, b, x, n), &mut hanika), (x + offset * face, &mut naive)]
                {
                    let sh = Shadowing {
                        origin,
                        occluders: &bvh as &dyn Occlusion,
                        samples_per_axis: 4,
                        lights: ShadowedLights::ALL,
                        slices: false,
                    };
                    let e = irradiance_visible(&point, &lights, &options, Some(&sh))[0];
                    let e0 = irradiance_visible(&point, &lights, &options, None)[0];
                    count.0 += 1;
                    count.1 += usize::from(e < e0);
                }
            }
        }
    }
    (hanika, naive)
}

#[test]
fn the_faceted_terminator_does_not_shadow_a_smooth_icosphere() {
    // A convex body cannot shadow itself: every lit point must see the whole sun. With the naive origin the
    // facets below the smooth normals' horizon occlude; Hanika's origin lifts the point onto the smooth surface.
    let mut totals = ((0, 0), (0, 0));
    for l in [DVec3::new(0.3, 1.0, 0.5), DVec3::new(1.0, 0.05, 0.0), DVec3::new(-0.2, 0.3, 1.0)] {
        let (h, n) = terminator_counts(l);
        eprintln!("sun {l}: darkened lit points: Hanika {} of {}, naive {} of {}", h.1, h.0, n.1, n.0);
        totals.0 .0 += h.0;
        totals.0 .1 += h.1;
        totals.1 .0 += n.0;
        totals.1 .1 += n.1;
    }
    let ((lit, hanika), (_, naive)) = totals;
    assert!(naive > 20 * hanika.max(1), "the naive origin should show the terminator: {naive} vs {hanika}");
    assert!(hanika * 1000 <= lit, "Hanika's origin darkened {hanika} of {lit} lit points");
}

#[test]
fn auto_skips_a_convex_body_and_forced_rays_leave_it_unchanged_where_lit() {
    // `auto` on the convex icosphere renders bitwise like `none`; `ray` forced shadows at most a few terminator
    // pixels, which are counted.
    let ico = icosphere(Vec3::ZERO, 1.0, 1);
    let scene = scene(&[ico]);
    let camera = Camera::looking(
        DVec3::new(0.0, 0.0, 4.0),
        -DVec3::Z,
        DVec3::Y,
        Projection::Perspective { yfov: 0.6, znear: 1.0, zfar: Some(10.0) },
    )
    .unwrap();
    let lights = sun_lights(DVec3::new(1.0, 0.4, 0.6), 0.53);
    let none = cpu::render(&scene, &settings(96, 96, camera, lights.clone(), Shadows::None, 8), &Default::default());
    let auto = cpu::render(&scene, &settings(96, 96, camera, lights.clone(), Shadows::Auto, 8), &Default::default());
    let ray = cpu::render(&scene, &settings(96, 96, camera, lights, Shadows::Ray, 8), &Default::default());
    assert_eq!(common::bits(&none), common::bits(&auto), "auto must skip the shadow pass on a convex body");
    let (mut lit, mut darkened) = (0, 0);
    for (a, b) in none.pixels().iter().zip(ray.pixels()) {
        if a[0] > 0.0 {
            lit += 1;
            darkened += usize::from(b[0] < a[0]);
        }
    }
    eprintln!("icosphere, forced rays: {darkened} of {lit} lit pixels darkened");
    assert!(darkened * 200 <= lit, "{darkened} of {lit} lit pixels darkened");
}

#[test]
fn no_acne_on_a_plane_at_grazing_sun() {
    // A plane alone lit at 1° and 0.1°: every shadow ray leaves it; the image is bitwise the unshadowed one.
    let scene = scene(&[floor(10.0)]);
    let camera = camera_down(DVec3::ZERO, 8.0, 20.0);
    for elevation in [1.0f64, 0.1] {
        let e = elevation.to_radians();
        let l = DVec3::new(e.cos(), e.sin(), 0.0);
        let none =
            cpu::render(&scene, &settings(64, 64, camera, sun_lights(l, 0.05), Shadows::None, 4), &Default::default());
        let ray =
            cpu::render(&scene, &settings(64, 64, camera, sun_lights(l, 0.05), Shadows::Ray, 4), &Default::default());
        assert!(none.pixels().iter().any(|p| p[0] > 0.0), "{elevation}°: nothing lit");
        assert_eq!(common::bits(&none), common::bits(&ray), "acne at {elevation}°");
    }
}

/// The visible fraction of a delta sun from `(x, 0, z)` on the floor of `scene`, by a shadow ray from the floor
/// triangle's origin rule (as the reference casts it).
fn floor_sun_visible(scene: &Scene, floor_half: f64, p: DVec3, l: DVec3) -> f64 {
    let bvh = cpu::occluder_bvh(scene);
    let corners = [
        DVec3::new(-floor_half, 0.0, -floor_half),
        DVec3::new(floor_half, 0.0, -floor_half),
        DVec3::new(0.0, 0.0, floor_half),
    ];
    let origin = shadow_ray_origin(&corners, &[DVec3::Y; 3], [1.0 / 3.0; 3], p, DVec3::Y);
    let sh = Shadowing {
        origin,
        occluders: &bvh as &dyn Occlusion,
        samples_per_axis: 1,
        lights: ShadowedLights::ALL,
        slices: false,
    };
    f64::from(u8::from(sh.visible_along(l.normalize())))
}

/// A 1 m box standing on a floor of half-size `floor_half` [m] and a 1 mm plate at 0.3 m centred at x = 3,
/// everything multiplied by `scale`.
fn blocks_scene(scale: f32, floor_half: f32) -> Scene {
    let b = placed(&cube(0.5), scale, Vec3::new(0.0, 0.5, 0.0) * scale);
    let plate = placed(&cube(0.5), scale, Vec3::ZERO);
    let plate = MeshData {
        positions: plate.positions.iter().map(|p| [p[0] + 3.0 * scale, p[1] * 0.001 + 0.3 * scale, p[2]]).collect(),
        ..plate
    };
    scene(&[placed(&floor(floor_half), scale, Vec3::ZERO), b, plate])
}

#[test]
fn contact_shadows_and_thin_plates_at_every_scale() {
    // The scene at 1 mm, 1 m and 10 km (a 10 m floor, everything multiplied by 1e-3, 1 and 1e3): a box standing
    // on the floor casts a shadow that starts at its base (no peter-panning: the push along the normal is
    // 2^-16 of the coordinates, 76 µm at scale 1); a plate 1 mm thick × scale shadows the floor under it.
    for scale in [1e-3f32, 1.0, 1e3] {
        let s = scale as f64;
        let floor_half = 5.0;
        let scene = blocks_scene(scale, floor_half);
        let half = floor_half as f64 * s;
        // Towards the sun: up and to −x, so the box's shadow falls on +x from its base (x = 0.5) to x = 1.5.
        let l = DVec3::new(-1.0, 1.0, 0.0);
        let near = (0.5 + 1e-3) * s;
        assert_eq!(floor_sun_visible(&scene, half, DVec3::new(near, 0.0, 0.0), l), 0.0, "scale {scale}: contact");
        assert_eq!(floor_sun_visible(&scene, half, DVec3::new(-near, 0.0, 0.0), l), 1.0, "scale {scale}: lit side");
        assert_eq!(floor_sun_visible(&scene, half, DVec3::new(1.45 * s, 0.0, 0.0), l), 0.0, "scale {scale}");
        assert_eq!(floor_sun_visible(&scene, half, DVec3::new(1.55 * s, 0.0, 0.0), l), 1.0, "scale {scale}");
        let up = DVec3::Y;
        assert_eq!(floor_sun_visible(&scene, half, DVec3::new(3.0 * s, 0.0, 0.0), up), 0.0, "scale {scale}: plate");
        assert_eq!(floor_sun_visible(&scene, half, DVec3::new(3.6 * s, 0.0, 0.0), up), 1.0, "scale {scale}: plate");
    }
}

#[test]
fn the_sun_at_the_horizon_throws_long_shadows() {
    // The sun 0.5° above the horizon from +x over a 800 m floor: the 1 m box shadows it out to
    // 1 / tan(0.5°) = 114.6 m on −x.
    let scene = blocks_scene(1.0, 400.0);
    let low = DVec3::new(0.5f64.to_radians().cos(), 0.5f64.to_radians().sin(), 0.0);
    for (x, want) in [(-0.6, 0.0), (-50.0, 0.0), (-110.0, 0.0), (-120.0, 1.0), (-300.0, 1.0), (0.6, 1.0)] {
        assert_eq!(floor_sun_visible(&scene, 400.0, DVec3::new(x, 0.0, 0.0), low), want, "x = {x}");
    }
}

#[test]
fn gpu_ray_queries_agree_with_the_reference_on_every_model() {
    // Every scene of models/ with its own lights, shadows by ray queries against the f64 reference, to the
    // tolerance of `render --check`, differences allowed only at fragile rays (the located grids bisect towards
    // the shadows' edges, so a pixel of a penumbra may cast a ray that f32 and f64 answer otherwise), and those a
    // handful.
    let mut gpu = common::shadow_ray_renderer();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut checked = 0;
    for name in ["room.gltf", "teapot.glb", "spheres.glb", "cube.glb", "brdfs.glb", "overcast.glb", "sunset.glb"] {
        let scene = common::load(&dir.join(name));
        let mut s = sunshade::settings::resolve(
            &scene,
            96,
            72,
            &Default::default(),
            &sunshade::settings::SunOptions::default(),
        )
        .unwrap();
        s.shading.shadows = Shadows::Ray;
        let g = gpu.render(&scene, &s);
        let (c, fragile) = cpu::render_with_fragile_pixels(&scene, &s, &gpu.reference_options());
        let (over, flagged) = over_tolerance_and_fragile(&g, &c, &fragile);
        let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
        assert_eq!(over, flagged, "{name}: {}", report.text("gpu", "reference"));
        assert!(over <= 8, "{name}: {over} fragile pixels over the tolerance");
        checked += 1;
    }
    assert_eq!(checked, 7);
}

#[test]
fn gpu_ray_queries_agree_with_the_reference_on_glossy_spheres_under_the_sky() {
    // brdfs.glb's glossy spheres on their floor under an overcast sky alone, every sky sample casting its ray
    // (the lobe grids over the hemisphere and over the lunes the horizontal cuts it into, shading::sky_lune):
    // against the f64 reference, to the tolerance of `render --check`.
    let mut gpu = common::shadow_ray_renderer();
    let scene = common::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/brdfs.glb"));
    let lights = sunshade::scene::Lights { sky: Some([300.0; 3]), ..Default::default() };
    let mut s =
        sunshade::settings::resolve(&scene, 96, 72, &Default::default(), &sunshade::settings::SunOptions::default())
            .unwrap();
    s.lights = lights;
    s.shading.shadows = Shadows::Ray;
    s.shading.samples_per_axis = 8;
    let g = gpu.render(&scene, &s);
    let c = cpu::render(&scene, &s, &gpu.reference_options());
    let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
    assert!(report.pass, "{}", report.text("gpu", "reference"));
    assert!(report.compared > 2000, "{} pixels compared", report.compared);
}

/// Settings for the shadow map with a map of `size` texels.
fn map_settings(s: &RenderSettings, size: u32) -> RenderSettings {
    let mut s = s.clone();
    s.shading.shadows = Shadows::Map;
    s.shading.shadow_map_size = size;
    s
}

#[test]
fn shadow_map_agrees_with_rays_away_from_penumbrae() {
    // The sun's shadow map against the reference's rays on models with sun shadows: only pixels at the edges of
    // shadows (where the map's texels and its PCSS estimate differ from the rays) may differ; measured on
    // lavapipe 22.3 at 256x192: 13 of 20693 covered pixels (cube), 11 of 8583 (teapot).
    let mut gpu = CheckedRenderer::new();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    for name in ["cube.glb", "teapot.glb"] {
        let scene = common::load(&dir.join(name));
        let s = sunshade::settings::resolve(&scene, 256, 192, &Default::default(), &Default::default()).unwrap();
        let s = map_settings(&s, 2048);
        let g = gpu.render(&scene, &s);
        let mut r = s.clone();
        r.shading.shadows = Shadows::Ray;
        let c = cpu::render(&scene, &r, &gpu.reference_options());
        let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
        eprintln!("{name}: map vs rays: {} of {} pixels over tolerance", report.over_tolerance.total, report.covered_b);
        assert_eq!(report.coverage_mismatches.total, 0);
        assert!(report.over_tolerance.total * 200 <= report.covered_b, "{name}: {}", report.text("map", "rays"));
        // The nearest texel alone against the one ray to the sun's centre: hard shadows both.
        let mut hard = s.clone();
        hard.shading.shadow_map_filter = sunshade::shading::ShadowMapFilter::Nearest;
        hard.shading.shadow_samples_per_axis = 1;
        let g = gpu.render(&scene, &hard);
        let mut r = hard.clone();
        r.shading.shadows = Shadows::Ray;
        let c = cpu::render(&scene, &r, &gpu.reference_options());
        let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
        eprintln!("{name}: nearest map vs one ray: {} pixels over tolerance", report.over_tolerance.total);
        assert!(report.over_tolerance.total * 200 <= report.covered_b, "{name}: {}", report.text("map", "rays"));
    }
}

#[test]
fn shadow_map_has_no_acne_at_grazing_sun_and_keeps_contact_shadows() {
    let mut gpu = CheckedRenderer::new();
    // A plane alone lit at 1° and 0.1°: the map leaves it bitwise unshadowed (the receiver-plane comparison).
    let plane = scene(&[floor(10.0)]);
    let camera = camera_down(DVec3::ZERO, 8.0, 20.0);
    for elevation in [1.0f64, 0.1] {
        let e = elevation.to_radians();
        let s = settings(64, 64, camera, sun_lights(DVec3::new(e.cos(), e.sin(), 0.0), 0.53), Shadows::None, 8);
        let none = gpu.render(&plane, &s);
        let map = gpu.render(&plane, &map_settings(&s, 1024));
        assert!(none.pixels().iter().any(|p| p[0] > 0.0));
        assert_eq!(common::bits(&none), common::bits(&map), "map acne at {elevation}°");
    }
    // A 1 m box standing on a 10 m floor, sun at 45° from −x, seen from above: the map's shadow starts at the
    // box's base (x = 0.5) like the rays' does, within two texels (2 × 10 m / 1024 ≈ 2 cm).
    let blocks = blocks_scene(1.0, 5.0);
    let camera = camera_down(DVec3::new(1.0, 0.0, 0.0), 1.0, 10.0);
    let s = settings(256, 256, camera, sun_lights(DVec3::new(-1.0, 1.0, 0.0), 0.53), Shadows::Ray, 1);
    let rays = cpu::render(&blocks, &s, &gpu.reference_options());
    let map = gpu.render(&blocks, &map_settings(&s, 1024));
    let texel = 10.0 * 1.01 / 1024.0;
    let (mut compared, mut far) = (0, 0);
    for y in 0..s.height {
        for x in 0..s.width {
            let p = floor_point(&s, x, y);
            // Floor pixels beside the box on its shadow side, away from the shadow's far end and sides.
            if p.x > 0.5 && p.x < 1.4 && p.z.abs() < 0.4 {
                compared += 1;
                let (a, b) = (rays.get(x, y)[0], map.get(x, y)[0]);
                if (a - b).abs() > 1e-3 * a.max(b).max(1e-30) && (p.x - 0.5) > 2.0 * texel {
                    far += 1;
                }
            }
        }
    }
    assert!(compared > 1000, "{compared}");
    assert_eq!(far, 0, "the map's shadow differs from the rays' more than two texels from the base");
}

#[test]
fn shadow_map_misses_an_occluder_smaller_than_a_texel_but_never_invents_shadow() {
    // A pole 5 mm thick standing 1 m high in a 10 m scene: at 64 texels (16 cm each) it is far thinner than a
    // texel and the map may lose it, but it must never darken what the rays light; at 4096 texels (2.5 mm) it
    // casts its shadow.
    let mut gpu = CheckedRenderer::new();
    let pole = MeshData {
        positions: cube(0.5).positions.iter().map(|p| [p[0] * 0.005 + 1.0, (p[1] + 0.5) * 1.0, p[2] * 0.005]).collect(),
        ..cube(0.5)
    };
    let sc = scene(&[floor(5.0), pole]);
    let camera = camera_down(DVec3::new(1.0, 0.0, 0.0), 0.6, 10.0);
    let s = settings(128, 128, camera, sun_lights(DVec3::new(-1.0, 1.0, 0.3), 0.53), Shadows::Ray, 1);
    let rays = cpu::render(&sc, &s, &gpu.reference_options());
    let dark = |img: &Image| img.pixels().iter().filter(|p| p[3] > 0.0 && p[0] == 0.0).count();
    assert!(dark(&rays) > 20, "the rays see the pole's shadow");
    for size in [64u32, 4096] {
        let map = gpu.render(&sc, &map_settings(&s, size));
        let invented = rays.pixels().iter().zip(map.pixels()).filter(|(r, m)| m[0] < r[0] * (1.0 - 1e-3)).count();
        eprintln!(
            "pole, map {size}: {} dark pixels (rays {}), {invented} darker than the rays",
            dark(&map),
            dark(&rays)
        );
        if size == 64 {
            assert!(invented <= dark(&rays), "a coarse map may blur the shadow, not add a new one");
        } else {
            assert!(dark(&map) * 2 >= dark(&rays), "a fine map finds the pole's shadow");
        }
    }
}

/// Pixels over the `render --check` tolerance, and how many of them the reference flags as having a fragile
/// shadow ray.
fn over_tolerance_and_fragile(g: &Image, c: &Image, fragile: &[bool]) -> (usize, usize) {
    let (report, _) = compare::diff(g, c, &DiffOptions::default()).unwrap();
    let flagged = report.over_tolerance_pixels.iter().filter(|&&(x, y)| fragile[(y * c.width() + x) as usize]).count();
    (report.over_tolerance_pixels.len(), flagged)
}

#[test]
fn gpu_ray_query_differences_lie_at_fragile_rays() {
    // A soup of 3000 triangles over three decades of size (slivers and sub-pixel ones) above a floor, under the
    // sun and the sky: the GPU's ray queries and the reference's f64 rays may answer differently only for rays
    // that pass within 2^-18 of the scene's size from an occluder's boundary, and the reference flags those
    // pixels; every pixel over the tolerance must be one of them.
    let mut gpu = common::shadow_ray_renderer();
    let soup =
        sunshade::authoring::shapes::triangle_soup(Vec3::new(0.0, 0.6, 0.0), Vec3::new(0.8, 0.4, 0.8), 3000, 0.2, 7);
    let sc = scene(&[floor(1.5), soup]);
    let camera = camera_down(DVec3::ZERO, 1.2, 6.0);
    let mut lights = sun_lights(DVec3::new(0.4, 1.0, 0.2), 2.0);
    lights.sky = Some([100.0; 3]);
    // 4² shadow rays: the sun's located grid casts up to (4 + 1)² + 2·4·2 = 41 rays a pixel through the soup's
    // edges, and at 6² (85 a pixel) and 5² (66) thousands of pixels ran past llvmpipe's loop budget on the
    // shader's BVH walk (Mesa 22.3; the plain count of 6², 36 rays, had fitted).
    let s = settings(160, 160, camera, lights, Shadows::Ray, 4);
    let g = gpu.render(&sc, &s);
    let (c, fragile) = cpu::render_with_fragile_pixels(&sc, &s, &gpu.reference_options());
    let (over, flagged) = over_tolerance_and_fragile(&g, &c, &fragile);
    let marked = fragile.iter().filter(|&&f| f).count();
    eprintln!(
        "soup: {over} pixels over tolerance, {flagged} of them with a fragile ray; {marked} pixels flagged of {}",
        fragile.len()
    );
    assert_eq!(over, flagged, "a GPU/reference difference away from any fragile shadow ray");
    // The fragile class stays a small part of the image: it is an edge class, not a blanket excuse.
    assert!(marked * 10 < fragile.len(), "{marked} fragile pixels");
}

#[test]
fn gpu_ray_queries_agree_with_the_reference_at_every_scale_and_at_grazing_sun() {
    // The blocks (a box standing on the floor, a 1 mm plate) at 1 mm, 1 m and 10 km, under a 45° sun and a sun
    // 0.5° above the horizon, seen from above: the GPU's shadow rays against the reference's, to the check
    // tolerance, differences allowed only at fragile rays.
    let mut gpu = common::shadow_ray_renderer();
    for scale in [1e-3f32, 1.0, 1e3] {
        let sc = blocks_scene(scale, 5.0);
        let camera = camera_down(DVec3::new(1.5, 0.0, 0.0) * scale as f64, 3.0 * scale as f64, 10.0 * scale as f64);
        for l in [DVec3::new(-1.0, 1.0, 0.2), DVec3::new(0.5f64.to_radians().cos(), 0.5f64.to_radians().sin(), 0.1)] {
            let s = settings(96, 96, camera, sun_lights(l, 0.53), Shadows::Ray, 4);
            let g = gpu.render(&sc, &s);
            let (c, fragile) = cpu::render_with_fragile_pixels(&sc, &s, &gpu.reference_options());
            let (over, flagged) = over_tolerance_and_fragile(&g, &c, &fragile);
            assert!(c.pixels().iter().any(|p| p[3] > 0.0 && p[0] == 0.0), "scale {scale}, sun {l}: no shadow seen");
            assert_eq!(over, flagged, "scale {scale}, sun {l}: {over} pixels over tolerance, {flagged} fragile");
        }
    }
}

/// A coarse smooth-shaded head on a floor: an 8 × 6 UV sphere with a nose, two ears and a brow of smaller coarse
/// spheres sunk into it (creases where smooth normals meet faceted occluders), `scale` metres tall.
fn low_poly_head(scale: f32) -> Scene {
    let at = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * scale;
    let parts = [
        placed(&floor(2.0), scale, Vec3::ZERO),
        uv_sphere(at(0.0, 0.5, 0.0), 0.35 * scale, 6, 8),
        uv_sphere(at(0.0, 0.5, 0.33), 0.08 * scale, 4, 6),
        uv_sphere(at(0.34, 0.5, 0.0), 0.1 * scale, 4, 6),
        uv_sphere(at(-0.34, 0.5, 0.0), 0.1 * scale, 4, 6),
        uv_sphere(at(0.0, 0.68, 0.22), 0.15 * scale, 4, 6),
    ];
    scene(&parts)
}

#[test]
fn gpu_default_shadows_agree_with_the_reference_on_hard_meshes() {
    // The default render (`auto`: shadow rays on every device, the sun's through its cells) against the default
    // reference, as `render --check` compares them: no coverage mismatch, and over tolerance only fragile pixels,
    // at most 0.05% of the compared ones. An 80-triangle icosphere and a coarse head on a floor (smooth normals
    // over few facets), a box and a 1 mm plate touching the floor, at 1 mm, 1 m and 10 km, under a sun 45°, 1° and
    // 0.1° above the horizon.
    let mut gpu = common::shadow_ray_renderer();
    let diff = DiffOptions::default();
    let (azimuth, suns) = (20f64.to_radians(), [45.0f64, 1.0, 0.1].map(f64::to_radians));
    let suns = suns.map(|e| DVec3::new(e.cos() * azimuth.cos(), e.sin(), e.cos() * azimuth.sin()));
    let mut shadowed_cases = 0;
    for (name, scale) in [("icosphere", 1.0f32), ("head", 1e-3), ("head", 1.0), ("blocks", 1e-3), ("blocks", 1e4)] {
        let sc = match name {
            "icosphere" => scene(&[floor(3.0), icosphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 1)]),
            "head" => low_poly_head(scale),
            _ => blocks_scene(scale, 5.0),
        };
        let centre = if name == "blocks" { DVec3::new(1.5, 0.0, 0.0) } else { DVec3::ZERO } * scale as f64;
        let camera = camera_down(centre, 3.0 * scale as f64, 10.0 * scale as f64);
        for l in suns {
            let s = settings(96, 96, camera, sun_lights(l, 0.53), Shadows::Auto, DEFAULT_SHADOW_SAMPLES_PER_AXIS);
            let what = format!("{name} at {scale} m, sun {:.1}° up", l.y.atan2(l.x.hypot(l.z)).to_degrees());
            let g = gpu.render(&sc, &s);
            let (c, apart) = cpu::checked::checked_reference(&sc, &s, &gpu.reference_options());
            let apart = apart.as_ref().map(|a| (a.mask.as_slice(), a.name, a.allowed_fraction));
            assert!(apart.is_some_and(|a| a.2.is_some()), "{what}: the fragile class, capped");
            let (report, _) = compare::diff_apart(&g, &c, &diff, apart).unwrap();
            assert!(report.pass && report.coverage_mismatches.total == 0, "{what}:\n{}", report.text("gpu", "cpu"));
            let e = report.excused.as_ref().expect("the fragile class");
            eprintln!(
                "{what}: {} compared, {} over tolerance, {} fragile ({} over)",
                report.compared, report.over_tolerance.total, e.compared, e.over_tolerance
            );
            let none = cpu::render(
                &sc,
                &settings(96, 96, camera, sun_lights(l, 0.53), Shadows::None, 1),
                &gpu.reference_options(),
            );
            shadowed_cases += usize::from(c.pixels().iter().zip(none.pixels()).any(|(a, b)| a[0] < b[0]));
        }
    }
    // Every case but none shows a shadow (the test would pass vacuously otherwise).
    assert!(shadowed_cases >= 14, "{shadowed_cases} of 15 cases show a shadow");
}

#[test]
fn sun_rays_are_spent_only_in_penumbrae() {
    // What the GPU's sun visibility casts (cpu::sun_costs, the shader's classification mirrored): a lit floor no
    // ray at all (its cells prove every cone clear); with the box and the plate on it, only the penumbrae cast
    // the 6² grid's rays, (6 + 1)² corners and at most 2·6 crossings located by 3 bisections each, and they are a
    // small part of the floor.
    let camera = camera_down(DVec3::new(1.5, 0.0, 0.0), 3.0, 10.0);
    let s = settings(96, 96, camera, sun_lights(DVec3::new(-1.0, 1.0, 0.2), 0.53), Shadows::Auto, 6);
    let options = ReferenceOptions::default();
    let lone = cpu::sun_costs::sun_ray_costs(&scene(&[floor(5.0)]), &s, &options).unwrap();
    assert!(lone.covered > 9000 && lone.evaluated == lone.covered, "{lone:?}");
    assert_eq!((lone.penumbra, lone.rays), (0, 0), "{lone:?}");
    let blocks = cpu::sun_costs::sun_ray_costs(&blocks_scene(1.0, 5.0), &s, &options).unwrap();
    assert!(blocks.penumbra > 0 && blocks.penumbra * 20 < blocks.evaluated, "{blocks:?}");
    let per_penumbra = blocks.rays as f64 / blocks.penumbra as f64;
    eprintln!("lone floor {lone:?}; with the blocks {blocks:?}");
    assert!((49.0..=85.0).contains(&per_penumbra), "{per_penumbra} rays a penumbra pixel: {blocks:?}");
}

/// A disk light of radius `radius` [m] at `center`, facing down.
fn disk_lights(center: DVec3, radius: f32) -> Lights {
    Lights {
        disks: vec![sunshade::scene::DiskLight {
            center: center.as_vec3(),
            direction: Vec3::NEG_Y,
            radius,
            radiance: [1000.0; 3],
        }],
        ..Default::default()
    }
}

#[test]
fn disk_rays_are_spent_only_where_the_walk_cannot_prove_them_clear() {
    // What the GPU's disk-light visibility casts (cpu::disk_costs, the shader's walk mirrored): a lit floor no ray
    // at all (the walk proves every pixel's rays clear); with the box and the plate on it, only the pixels whose
    // cone meets them cast the 6² grid's rays, and they are a small part of the floor.
    let camera = camera_down(DVec3::new(1.5, 0.0, 0.0), 3.0, 10.0);
    let s = settings(96, 96, camera, disk_lights(DVec3::new(0.0, 4.0, 0.0), 0.5), Shadows::Auto, 6);
    let options = ReferenceOptions::default();
    let lone = cpu::disk_costs::disk_ray_costs(&scene(&[floor(5.0)]), &s, &options).unwrap();
    assert!(lone.covered > 9000 && lone.evaluated == lone.covered, "{lone:?}");
    assert_eq!((lone.left_to_rays, lone.rays), (0, 0), "{lone:?}");
    let blocks = cpu::disk_costs::disk_ray_costs(&blocks_scene(1.0, 5.0), &s, &options).unwrap();
    eprintln!("lone floor {lone:?}; with the blocks {blocks:?}");
    assert!(blocks.left_to_rays > 0 && blocks.left_to_rays * 5 < blocks.evaluated, "{blocks:?}");
    let per_pixel = blocks.rays as f64 / blocks.left_to_rays as f64;
    assert!((1.0..=85.0).contains(&per_pixel), "{per_pixel} rays a pixel left to them: {blocks:?}");
}

/// The default render's disk-light shadows (the walk's proof, then the grid's rays) against the default reference,
/// as `render --check` compares them, at 96², each scene under a disk overhead and one low to the side: for each
/// case, what it is, whether it passes (no coverage mismatch, over tolerance only fragile pixels, at most 0.05% of
/// the compared ones) with the report, and whether the reference shows a shadow.
fn disk_light_agreement(cases: &[(&str, f32)]) -> Vec<(String, bool, String, bool)> {
    let mut gpu = common::shadow_ray_renderer();
    let diff = DiffOptions::default();
    let mut results = Vec::new();
    for &(name, scale) in cases {
        let sc = match name {
            "icosphere" => scene(&[floor(3.0), icosphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 1)]),
            "head" => low_poly_head(scale),
            _ => blocks_scene(scale, 5.0),
        };
        let m = scale as f64;
        let centre = if name == "blocks" { DVec3::new(1.5, 0.0, 0.0) } else { DVec3::ZERO } * m;
        let camera = camera_down(centre, 3.0 * m, 10.0 * m);
        for (at, radius) in [(DVec3::new(0.3, 4.0, 0.2), 0.8), (DVec3::new(-3.0, 1.5, 1.0), 0.4)] {
            let lights = disk_lights(at * m, radius * scale);
            let s = settings(96, 96, camera, lights.clone(), Shadows::Auto, DEFAULT_SHADOW_SAMPLES_PER_AXIS);
            let g = gpu.render(&sc, &s);
            let (c, apart) = cpu::checked::checked_reference(&sc, &s, &gpu.reference_options());
            let apart = apart.as_ref().map(|a| (a.mask.as_slice(), a.name, a.allowed_fraction));
            let (report, _) = compare::diff_apart(&g, &c, &diff, apart).unwrap();
            let none = cpu::render(&sc, &settings(96, 96, camera, lights, Shadows::None, 1), &gpu.reference_options());
            let shadowed = c.pixels().iter().zip(none.pixels()).any(|(a, b)| a[0] < b[0]);
            results.push((
                format!("{name} at {scale} m, disk at {at}"),
                report.pass && report.coverage_mismatches.total == 0,
                report.text("gpu", "cpu"),
                shadowed,
            ));
        }
    }
    results
}

#[test]
fn gpu_disk_light_shadows_agree_with_the_reference_on_hard_meshes() {
    // An 80-triangle icosphere and a coarse head on a floor (smooth normals over few facets), at 1 m and 1 mm.
    let results = disk_light_agreement(&[("icosphere", 1.0), ("head", 1e-3), ("head", 1.0)]);
    for (what, pass, report, _) in &results {
        assert!(pass, "{what}:\n{report}");
    }
    // Every case shows a shadow (the test would pass vacuously otherwise).
    assert!(results.iter().all(|r| r.3), "a case without a shadow");
}

#[test]
fn gpu_disk_light_shadows_agree_with_the_reference_on_touching_blocks() {
    // The 1 m box standing on the floor and the 1 mm plate, at 1 mm, 1 m and 10 km. Everything here is dyadic (the
    // boxes, the lights' centres, the orthographic camera's pixel centres): unturned, the grids' samples met the
    // boxes' edges exactly along whole lines of pixels (`visibility::turned`).
    let results = disk_light_agreement(&[("blocks", 1e-3), ("blocks", 1.0), ("blocks", 1e4)]);
    let failed: Vec<_> = results.iter().filter(|r| !r.1).map(|r| format!("{}:\n{}", r.0, r.2)).collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
    assert!(results.iter().all(|r| r.3), "a case without a shadow");
}

#[test]
fn disk_light_maps_leave_a_lone_floor_bitwise_and_cut_the_room_s_shadow_error() {
    let mut gpu = CheckedRenderer::new();
    // A floor alone under a disk light, with its map: nothing occludes, and the image is bitwise unshadowed.
    let plane = scene(&[floor(3.0)]);
    let lights = Lights {
        disks: vec![sunshade::scene::DiskLight {
            center: Vec3::new(0.5, 2.0, 0.0),
            direction: -Vec3::Y,
            radius: 0.5,
            radiance: [3000.0; 3],
        }],
        ..Default::default()
    };
    let s = settings(64, 64, camera_down(DVec3::ZERO, 3.0, 10.0), lights, Shadows::None, 8);
    let none = gpu.render(&plane, &s);
    let map = gpu.render(&plane, &map_settings(&s, 1024));
    assert!(none.pixels().iter().any(|p| p[0] > 0.0));
    assert_eq!(common::bits(&none), common::bits(&map), "a disk's map shadows a lone floor");
    // The room's disk skylight: against the reference's rays, the map removes most of the error of ignoring the
    // shadows (measured on lavapipe 22.3 at 256x192: RMSE 1.6 against 7.2 W/(m²·sr)).
    let room = common::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/room.gltf"));
    let s = sunshade::settings::resolve(&room, 128, 96, &Default::default(), &Default::default()).unwrap();
    let mut rays = s.clone();
    rays.shading.shadows = Shadows::Ray;
    let truth = cpu::render(&room, &rays, &gpu.reference_options());
    let mut unshadowed = s.clone();
    unshadowed.shading.shadows = Shadows::None;
    let rmse = |img: &Image| compare::diff(img, &truth, &DiffOptions::default()).unwrap().0.rmse;
    let (e_none, e_map) = (rmse(&gpu.render(&room, &unshadowed)), rmse(&gpu.render(&room, &map_settings(&s, 2048))));
    eprintln!("room: RMSE against rays, unshadowed {e_none:.3}, disk map {e_map:.3} W/(m²·sr)");
    assert!(e_map < 0.4 * e_none, "the disk's map: RMSE {e_map} against {e_none} unshadowed");
}

#[test]
fn shadow_map_differences_lie_at_map_edges_and_the_rest_is_checked() {
    // What `render --check` asserts of a shadow-map render (the default without ray queries): against the
    // reference's f64 rays for the mapped lights, every pixel over the tolerance lies where the map's lookups
    // reach an occluder's edge (`cpu::render_with_map_edges`), a class kept to a part of the image; and the
    // check is not vacuous: pixels the maps shadow lie outside the class, where the map must match the rays.
    // Measured on lavapipe 22.3 at 256x192: the class is 0.6% (cube) to 19% (sunset) of the covered pixels,
    // and holds every one of the 13 to 1756 pixels over tolerance; at 128x96 (here) 0.6% to 20%, 0 to 437.
    let mut gpu = CheckedRenderer::new();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut differing = 0;
    for name in ["cube.glb", "teapot.glb", "sunset.glb", "room.gltf"] {
        let scene = common::load(&dir.join(name));
        let s = sunshade::settings::resolve(&scene, 128, 96, &Default::default(), &Default::default()).unwrap();
        let s = map_settings(&s, 2048);
        let g = gpu.render(&scene, &s);
        let (c, edges) = cpu::render_with_map_edges(&scene, &s, &gpu.reference_options());
        let (plain, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
        let (report, _) = compare::diff_excusing(&g, &c, &DiffOptions::default(), Some((&edges, "map edges"))).unwrap();
        let class = report.excused.as_ref().unwrap();
        let mut unshadowed = s.clone();
        unshadowed.shading.shadows = Shadows::None;
        let u = gpu.render(&scene, &unshadowed);
        let shadowed_outside = (0..g.pixels().len())
            .filter(|&k| !edges[k] && g.pixels()[k][3] > 0.0 && g.pixels()[k][0] < 0.99 * u.pixels()[k][0])
            .count();
        eprintln!(
            "{name}: {} over tolerance without the class; class {} of {} pixels, {} of them over; {} shadowed \
             pixels outside it",
            plain.over_tolerance.total, class.compared, report.compared, class.over_tolerance, shadowed_outside
        );
        assert!(report.pass, "{name}: a difference outside the map edges: {}", report.text("map", "rays"));
        assert_eq!(class.over_tolerance, plain.over_tolerance.total, "{name}");
        differing += plain.over_tolerance.total;
        assert!(class.compared * 4 < report.compared, "{name}: the class covers {} pixels", class.compared);
        // Under the real sun the umbrae lie outside the class; the room's disk light (0.5 m across) leaves only
        // penumbrae, all of them in it.
        assert!(shadowed_outside > 0 || name == "room.gltf", "{name}: every shadowed pixel is in the class");
    }
    assert!(differing > 0, "the maps differ from the rays nowhere: the test tests nothing");
}

#[test]
fn the_testing_api_checks_auto_against_the_model_the_device_used() {
    // `auto` is shadow maps on a device without ray queries: the reference resolves it the same way, and its
    // rays then leave the sky unoccluded as the maps do, so the overcast scene (a sky its geometry occludes)
    // passes `testing::check_against_reference` unchanged; with ray queries both cast rays everywhere.
    let mut gpu = CheckedRenderer::new();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    for name in ["overcast.glb", "room.gltf"] {
        let job = sunshade::testing::job(dir.join(name), &["--width", "64", "--height", "48"]).unwrap();
        let image = gpu.render_job(&job).unwrap();
        let options = gpu.reference_options();
        sunshade::testing::check_against_reference(&job, &image, &options, &DiffOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// A floor (z = 0, 4 m square) and, 1 m above its left part, an alpha-masked square whose 2 × 2 texture
/// (NEAREST) is opaque in two opposite quarters and cut away in the others; a delta sun from (−1, 0, 1), so the
/// mask's shadow falls 1 m to the right of it, on the floor the orthographic camera looks down at.
fn masked_cutout_scene() -> (Scene, RenderSettings) {
    use serde_json::json;
    use sunshade::authoring::{png_rgba8, GltfBuilder, Indices, Node, Primitive};
    let dir = common::TempDir::new("masked-shadow");
    let mut b = GltfBuilder::new();
    let image = b.add_png_image(&png_rgba8(
        2,
        2,
        &[[255, 255, 255, 255], [255, 255, 255, 0], [255, 255, 255, 0], [255, 255, 255, 255]],
    ));
    let tex = b.add_texture(image, Some(9728), Some(9728), [33071, 33071]);
    let mask = b.add_material_json(json!({
        "alphaMode": "MASK", "doubleSided": true,
        "pbrMetallicRoughness": { "baseColorTexture": { "index": tex }, "metallicFactor": 0.0 }
    }));
    let floor = b.add_material("floor", [0.5; 3], false, None);
    let square = |x0: f32, x1: f32, y0: f32, y1: f32, z: f32, material: usize| Primitive {
        positions: vec![[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]],
        normals: Some(vec![[0.0, 0.0, 1.0]; 4]),
        tex_coords: Some(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]),
        colors: None,
        indices: Some(Indices::U8(vec![0, 1, 2, 0, 2, 3])),
        material: Some(material),
        mode: None,
    };
    let m =
        b.add_mesh("parts", &[square(-2.0, 2.0, -2.0, 2.0, 0.0, floor), square(-2.0, -0.5, -0.75, 0.75, 1.0, mask)]);
    let n = b.add_node(Node { mesh: Some(m), ..Default::default() });
    b.add_scene(&[n], None);
    let scene = common::load(&dir.write("m.glb", &b));
    let camera = Camera::looking(
        DVec3::new(0.0, 0.0, 5.0),
        -DVec3::Z,
        DVec3::Y,
        Projection::Orthographic { ymag: 2.0, znear: 1.0, zfar: 10.0 },
    )
    .unwrap();
    let lights = Lights {
        sun: Some(Sun {
            direction: Vec3::new(-1.0, 0.0, 1.0).normalize(),
            irradiance: [E_PERP; 3],
            angular_diameter: 0.0,
        }),
        ..Default::default()
    };
    let mut s = RenderSettings::new(64, 64, camera, lights);
    s.shading.sun = sunshade::shading::SunModel::Delta;
    s.shading.shadows = Shadows::Ray;
    (scene, s)
}

/// Asserts the floor under the mask's shadow of [`masked_cutout_scene`]: lit (to `tol`) under the cut-away
/// quarters, dark under the opaque ones, away from texel and mask edges by `margin` (in UV).
fn assert_cutout_shadow(image: &sunshade::Image, s: &RenderSettings, tol: f64, margin: f64) {
    let l = s.lights.sun.unwrap().direction.as_dvec3();
    let lit = 0.5f32 as f64 / PI * E_PERP as f64 * l.z;
    let (mut dark, mut through) = (0, 0);
    for y in 0..64u32 {
        for x in 0..64u32 {
            // Pixel centre on the floor; the ray towards the sun meets z = 1 at x − 1.
            let (wx, wy) = (-2.0 + (x as f64 + 0.5) / 16.0, 2.0 - (y as f64 + 0.5) / 16.0);
            let (hx, hy) = (wx + l.x / l.z, wy);
            let (u, v) = ((hx + 2.0) / 1.5, (0.75 - hy) / 1.5);
            let on_mask_pixel = wx <= -0.5 && wy.abs() <= 0.75; // the camera sees the mask there
            if on_mask_pixel || !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
                continue;
            }
            let near = |c: f64| (c - 0.5).abs() < margin || c < margin || c > 1.0 - margin;
            if near(u) || near(v) {
                continue; // at a texel or mask edge
            }
            let opaque = (u < 0.5) == (v < 0.5);
            let got = image.get(x, y)[0] as f64;
            if opaque {
                assert_eq!(got, 0.0, "pixel ({x}, {y}) under an opaque quarter");
                dark += 1;
            } else {
                assert!(common::rel(got, lit) < tol, "pixel ({x}, {y}) under a cut-away quarter: {got} against {lit}");
                through += 1;
            }
        }
    }
    assert!(dark > 40 && through > 40, "{dark} dark, {through} lit through the mask");
}

#[test]
fn shadow_rays_pass_through_alpha_masked_cutouts() {
    // The reference: a floor point in the mask's shadow is lit exactly where the ray towards the sun meets the
    // mask's cut-away quarters (its texel's alpha 0), dark where it meets an opaque one.
    let (scene, s) = masked_cutout_scene();
    assert_cutout_shadow(&cpu::render(&scene, &s, &ReferenceOptions::default()), &s, 1e-6, 0.02);
}

#[test]
fn a_shadow_ray_meeting_a_mask_near_its_contour_is_fragile() {
    // masked_cutout_scene's mask (NEAREST: its alpha jumps from 1 to 0 at u = 0.5, x = −1.25): a ray towards the
    // sun meeting it within eps of that contour is fragile, since the GPU's f32 hit may land on the other side,
    // whatever the alpha's distance from its cutoff (0.5 on both sides here); one meeting it a texel away from any
    // contour is not, nor one meeting the opaque floor. The mask's two triangles share its affine UV map, so
    // either decides a point of its plane alike.
    let (scene, _) = masked_cutout_scene();
    let occluders = cpu::Occluders::new(&scene);
    let eps = 1e-5;
    let direction = DVec3::new(-1.0, 0.0, 1.0);
    // From (x, y, 0) the ray meets the mask's plane z = 1 at (x − 1, y, 1), t = 1.
    let at = |hit_x: f64, i: usize| occluders.blocks_near(i, DVec3::new(hit_x + 1.0, -0.3, 0.0), direction, 1.0, eps);
    for i in [2, 3] {
        for (hit_x, fragile) in [(-1.25 + 0.3 * eps, true), (-1.25 - 0.3 * eps, true), (-1.6, false), (-0.9, false)] {
            assert_eq!(at(hit_x, i).1, fragile, "triangle {i}, hit at x = {hit_x}");
        }
        // Both sides of the contour decide differently (the test is not vacuous).
        assert_ne!(at(-1.25 + 2.0 * eps, i).0, at(-1.25 - 2.0 * eps, i).0);
    }
    assert_eq!(at(-1.25, 0), (true, false), "the opaque floor");
}

#[test]
fn gpu_shadow_maps_pass_light_through_alpha_masked_cutouts() {
    // Any device: the masked draw's depth pass discards below the cutoff, so the map lets the light through the
    // same quarters (away from the edges by two map texels' worth).
    let (scene, mut s) = masked_cutout_scene();
    s.shading.shadows = Shadows::Map;
    let mut gpu = CheckedRenderer::new();
    assert_cutout_shadow(&gpu.render(&scene, &s), &s, 1e-5, 0.05);
}

#[test]
fn gpu_ray_queries_pass_light_through_alpha_masked_cutouts() {
    let mut gpu = common::shadow_ray_renderer();
    let (scene, s) = masked_cutout_scene();
    let g = gpu.render(&scene, &s);
    let (c, fragile) = cpu::render_with_fragile_pixels(&scene, &s, &gpu.reference_options());
    let (report, _) = compare::diff(&g, &c, &DiffOptions::default()).unwrap();
    let at_fragile = report.over_tolerance_at(&fragile, g.width());
    assert!(
        report.over_tolerance.total == at_fragile,
        "{} of {} pixels over tolerance are not fragile:\n{}",
        report.over_tolerance.total - at_fragile,
        report.over_tolerance.total,
        report.text("gpu", "reference")
    );
}

/// `--tolerance T` on the reference where the scene shadows itself: the grids, shadow rays' included, are
/// estimated by refinement, and an image kept meets T against the circular segment's exact penumbra of a
/// straight edge (relative with the diff's floor: 1% of the image's peak, so that in the penumbra's dark end the
/// visible fraction must be right to `T/100`), or the study refuses. The real sun (0.53°), its penumbra spread over
/// 56 pixels, 2, or half a pixel; edges along the grid's axis and at 30° to it (the concentric map's cells meet an
/// axis-aligned edge row by row). A refusal may be
/// conservative (the estimate's order is cut to a jump's 1): the finest grid's measured error is reported.
#[test]
fn tolerance_estimates_a_penumbra_against_its_circular_segment() {
    use sunshade::accuracy::error::image_error;
    use sunshade::accuracy::trial::{reference_within_tolerance, Tolerance};
    let everywhere = Tolerance::everywhere;
    let mut report = String::new();
    let mut kept = 0;
    // (Scale-invariant: a 10° sun's penumbra at the same share of the image gives the same errors.)
    for (diameter, span) in [(0.53f64, 1.7), (0.53, 40.0), (0.53, 200.0)] {
        let half_angle = (diameter.to_radians() as f32 as f64) / 2.0;
        for degrees in [0.0f64, 30.0] {
            // The roof's edge turned by `degrees` about the vertical: a floor point's signed distance past the
            // edge is its coordinate `across` it.
            let (c, s) = (degrees.to_radians().cos(), degrees.to_radians().sin());
            let (across, along) = (DVec3::new(c, 0.0, -s), DVec3::new(s, 0.0, c));
            let roof = quad((DVec3::Y - 5.0 * across).as_vec3(), (5.0 * across).as_vec3(), (5.0 * along).as_vec3());
            let scene = scene(&[floor(1.0), roof]);
            // The image spans `span` penumbrae (±tan σ under an edge 1 m up): 56 pixels each, 2, or half a pixel.
            let camera = camera_down(DVec3::ZERO, span * half_angle.tan() / 12.0, 5.0);
            let base = settings(96, 8, camera, sun_lights(DVec3::Y, diameter), Shadows::Ray, 8);
            let mut exact = Image::new(base.width, base.height);
            for y in 0..base.height {
                for x in 0..base.width {
                    let v = zenith_sun_fraction_under_edge(floor_point(&base, x, y).dot(across), 1.0, half_angle);
                    let l = (E_PERP as f64 / PI * v) as f32;
                    exact.set(x, y, [l, l, l, 1.0]);
                }
            }
            let case = format!("{diameter}° sun, edge at {degrees}°, {span} penumbrae wide");
            let mut costs = Vec::new();
            for tolerance in [1e-2, 1e-3, 1e-4] {
                let mut s = base.clone();
                let reference = ReferenceOptions::default();
                match reference_within_tolerance(
                    &scene,
                    &mut s,
                    &reference,
                    Shadows::Ray,
                    true,
                    Some(everywhere(tolerance)),
                ) {
                    Ok((image, prediction)) => {
                        let e = image_error(&image, &exact, None).unwrap().max_rel;
                        report += &format!(
                            "{case}, T = {tolerance:e}: {}² shadow rays, measured {e:.2e}, predicted {:.2e}\n",
                            s.shading.shadow_samples_per_axis, prediction.max_relative
                        );
                        assert!(prediction.line().contains("penumbrae included"), "{}", prediction.line());
                        assert!(e <= tolerance, "over T:\n{report}");
                        costs.push(s.shading.shadow_samples_per_axis);
                        kept += 1;
                    }
                    Err(why) => {
                        assert!(why.contains("did not meet"), "{case}, T = {tolerance:e}: {why}");
                        let mut finest = base.clone();
                        finest.shading.sun_samples_per_axis = 162;
                        finest.shading.shadow_samples_per_axis = 162;
                        let e = image_error(&cpu::render(&scene, &finest, &reference), &exact, None).unwrap().max_rel;
                        report += &format!("{case}, T = {tolerance:e}: refused; 162² errs {e:.2e}\n");
                        break;
                    }
                }
            }
            assert!(costs.windows(2).all(|w| w[0] <= w[1]), "{case}: looser T must cost no more: {costs:?}");
        }
    }
    eprintln!("{report}");
    // The sun's located edges (second order) keep 13 of the 18 cases (measured); the count of points
    // before them kept 5, refusing the widest penumbra even at 1e-2.
    assert!(kept >= 10, "{kept} kept:\n{report}");
}

/// The sky through occluders under `render --tolerance 1e-2 --tolerance-in-penumbrae --tolerance-by-study`
/// (overcast.glb, the sky alone through the teapot): with ray queries the study keeps a grid and the image meets T against the reference with
/// its shadow grid at 128² (measured on Mesa 25's lavapipe: 56², 3.1e-3, predicted 8.1e-3). On a device
/// whose fragment shader walks the BVH the study's finer rungs pass llvmpipe's loop budget (overcast.glb fits 32²
/// at 96 × 72 since the slab test lost its loop; 10² before), and the render must then refuse by name, not return a
/// cut-short image.
#[test]
fn gpu_ray_queries_keep_the_sky_through_occluders_under_tolerance() {
    let ray_query = common::shadow_ray_renderer().renderer().device_info().ray_query;
    // The walk's study renders rung after rung until one passes the budget: smaller, to stay quick.
    let (w, h) = if ray_query { (48, 36) } else { (24, 18) };
    let dir = common::TempDir::new("sky-penumbrae");
    let out = dir.path("overcast.exr");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_sunshade"))
        .args(["render", "models/overcast.glb", "--width", &w.to_string(), "--height", &h.to_string()])
        .args(["--tolerance", "1e-2"])
        .args(["--tolerance-in-penumbrae", "--tolerance-by-study", "-v", "-o"])
        .arg(&out)
        .env("SUNSHADE_VALIDATION", "1")
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    if !ray_query {
        assert!(o.status.success() || e.contains("loop iterations"), "{e}");
        assert!(o.status.success() || e.contains("`sunshade reference` with the same scene flags has no such"), "{e}");
        if !o.status.success() {
            assert!(!out.exists(), "a refused render left {}", out.display());
            return;
        }
    }
    assert!(o.status.success() && e.contains("penumbrae included") && !e.contains("not bounded"), "{e}");
    let scene = common::load(std::path::Path::new("models/overcast.glb"));
    let mut s = sunshade::settings::resolve(
        &scene,
        w,
        h,
        &sunshade::settings::CameraOptions::default(),
        &sunshade::settings::SunOptions::default(),
    )
    .unwrap();
    s.shading.shadows = Shadows::Ray;
    s.shading.shadow_samples_per_axis = 128;
    let (measured, line) = common::error_against_fine(&out, &scene, &s, &e);
    eprintln!("overcast.glb on the GPU, T = 1e-2 in penumbrae: measured {measured:.2e} against 128²; {line}");
    assert!(measured <= 1e-2, "{measured:.3e} over 1e-2\n{e}");
}

/// The specular radiance [W/(m²·sr)] of a Phong floor (ks = 1, exponent `e`, kd = 0) at x under the roof of
/// [`edge_scene`] (height 1), seen straight down, under a zenith sun of half-angle σ and perpendicular irradiance
/// E: `L_sun ∫ lobe(ω) (n·ω) V(ω) dω` over the sun's cap, the roof hiding `X < −x` in the tangent-plane
/// coordinates `P = (X, 1, Z)` of [`zenith_sun_fraction_under_edge`]. The mirror direction is the zenith, so
/// `lobe (n·ω) dω = (e + 2)/(2π) |P|^−(e + 4) dX dZ`; Z in closed form would need a hypergeometric function, so
/// both by Gauss–Legendre (X = T sin θ, Z across the cap's chord).
fn zenith_phong_specular_under_edge(x: f64, e: f64, half_angle: f64, e_perp: f64) -> f64 {
    let t = half_angle.tan();
    let l_sun = e_perp / (PI * half_angle.sin().powi(2));
    let strip = |theta: f64| {
        let (xx, s) = (t * theta.sin(), t * theta.cos());
        let across = integrate_composite(-s, s, 16, 8, |z| (1.0 + xx * xx + z * z).powf(-(e + 4.0) / 2.0));
        across * t * theta.cos()
    };
    let c = (-x / t).clamp(-1.0, 1.0);
    l_sun * (e + 2.0) / (2.0 * PI) * integrate_composite(c.asin(), 0.5 * PI, 64, 8, strip)
}

#[test]
fn specular_lobes_in_the_suns_penumbra_meet_their_quadrature() {
    // A Phong floor (e = 100, a lobe about 6° wide) under the roof's edge and a 10° sun at the zenith, seen
    // straight down: the mirror direction is the sun's centre, so the lobe varies across the disk and its
    // visible part is not the diffuse part's fraction. The lobe's samples cast rays only where the shadow rays'
    // located grid finds the sun partly hidden; elsewhere the lobe is whole (lit) or 0 (umbra).
    let exponent = 100.0;
    let phong = Material {
        double_sided: false,
        ..Material::with_brdf("phong", Brdf::Phong { kd: [0.0; 3], ks: [1.0; 3], exponent })
    };
    let roof = quad(Vec3::new(-5.0, 1.0, 0.0), Vec3::new(5.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 5.0));
    let scene = common::scene_of(&[floor(1.0), roof], phong);
    let camera = camera_down(DVec3::ZERO, 0.15 / 12.0, 5.0);
    let half_angle = (10f64.to_radians() as f32 as f64) / 2.0;
    let mut s = settings(96, 8, camera, sun_lights(DVec3::Y, 10.0), Shadows::Ray, 16);
    s.shading.sun_samples_per_axis = 32;
    let image = cpu::render(&scene, &s, &ReferenceOptions::default());
    let unoccluded = zenith_phong_specular_under_edge(1.0, exponent as f64, half_angle, E_PERP as f64);
    let (mut lit, mut umbra, mut penumbra) = (0, 0, 0);
    let mut worst = 0.0f64;
    for x in 0..s.width {
        let p = floor_point(&s, x, 4);
        let got = image.get(x, 4)[0] as f64;
        let want = zenith_phong_specular_under_edge(p.x, exponent as f64, half_angle, E_PERP as f64);
        let t = half_angle.tan();
        if p.x > t * 1.02 {
            // Wholly lit: the lobe's grid alone (no ray can change it).
            assert!((got - want).abs() <= 2e-3 * unoccluded, "lit at x = {}: {got} against {want}", p.x);
            lit += 1;
        } else if p.x < -t * 1.02 {
            assert_eq!(got, 0.0, "umbra at x = {}", p.x);
            umbra += 1;
        } else {
            // A point count of the lobe's 32² samples: first order, each sample worth up to a few /32² of the
            // peak where the edge crosses the lobe's middle.
            worst = worst.max((got - want).abs() / unoccluded);
            penumbra += 1;
        }
    }
    eprintln!("lit {lit}, umbra {umbra}, penumbra {penumbra}: worst {worst:.2e} of the unoccluded {unoccluded:.4e}");
    assert!(lit > 10 && umbra > 10 && penumbra > 20, "{lit} {umbra} {penumbra}");
    assert!(worst < 2e-2, "penumbra: {worst:.2e} of the unoccluded lobe");
    // The GPU takes the same classes (validation on; shadow rays by ray queries or the BVH walk).
    let mut gpu = CheckedRenderer::new();
    let g = gpu.render(&scene, &s);
    let (report, _) = compare::diff(&g, &image, &DiffOptions::default()).unwrap();
    assert!(report.pass, "{}", report.text("gpu", "reference"));
}

/// The GPU's slices at `s` (k² shadow rays, slices) against the reference's at the same settings, and the GPU's
/// slices and grid against the reference's slices at k = 16 (the shadows' truth: everything else is the same):
/// `(apart, slices' error, grid's error)`, max relative.
fn slices_against_the_reference_and_the_grid(
    gpu: &mut CheckedRenderer,
    scene: &Scene,
    s: &RenderSettings,
) -> (f64, f64, f64) {
    let sliced = gpu.render(scene, s);
    let reference = cpu::render(scene, s, &gpu.reference_options());
    let mut grid = s.clone();
    grid.shading.visibility_rule = VisibilityRule::Grid;
    let gridded = gpu.render(scene, &grid);
    let mut fine = s.clone();
    fine.shading.shadow_samples_per_axis = 16;
    let truth = cpu::render(scene, &fine, &ReferenceOptions::default());
    let max_rel = |a: &Image, b: &Image| compare::diff(a, b, &DiffOptions::default()).unwrap().0.max_rel;
    (max_rel(&sliced, &reference), max_rel(&sliced, &truth), max_rel(&gridded, &truth))
}

#[test]
fn gpu_sun_slices_agree_with_the_reference_and_beat_the_grid() {
    // sunset.glb's low sun behind the spheres' limbs (a penumbra's pixel gathers 100 to 200 triangles): the GPU's
    // slices of the sun's disk against the reference's slices at the same 4k² rows, and both rules at k = 4 against the reference's slices at k = 16
    // (their shadows' truth: everything else is the same). Measured at 64 × 48 on Mesa 22.3.6: 8.6e-7 apart; the
    // slices err 5.7e-5, the grid 1.6e-2; on Mesa 25 with ray queries (the slices walk the BVH there too), 8.3e-7
    // apart. (shaders/slices.glsl.)
    let mut gpu = CheckedRenderer::new();
    let (scene, s) = common::sliced("sunset.glb", (64, 48), 4);
    let (apart, sliced_error, grid_error) = slices_against_the_reference_and_the_grid(&mut gpu, &scene, &s);
    eprintln!("GPU slices vs reference {apart:.1e}; against k = 16: slices {sliced_error:.1e}, grid {grid_error:.1e}");
    assert!(apart <= 1e-5, "the GPU's slices {apart:e} from the reference's");
    assert!(
        sliced_error <= 1e-3 && grid_error >= 10.0 * sliced_error,
        "{sliced_error:e} against the grid's {grid_error:e}"
    );
}

#[test]
fn gpu_sky_slices_in_passes_agree_with_the_reference_and_beat_the_grid() {
    // overcast.glb's sky through the teapot: the GPU's slices of the sky, taken in passes of rows before the frame
    // (gpu::slice_passes; each row walks the BVH for its own triangles), against the reference's slices at the same
    // 4k² rows, and both rules at k = 4 against the reference's slices at k = 16 (the shadows' truth). Measured at
    // 64 × 48 on Mesa 22.3.6: 2.3e-6 apart at k = 4, 2.2e-6 at k = 8; at 32 × 24, k = 4, 8.1e-7 apart, and against
    // k = 16 the slices err 7.3e-3, the grid 0.54. With the sun too (its slices in the frame, the sky's before it),
    // the same.
    let mut gpu = CheckedRenderer::new();
    let (scene, mut s) = common::sliced("overcast.glb", (32, 24), 4);
    assert!(s.lights.sky.is_some());
    let (apart, sliced_error, grid_error) = slices_against_the_reference_and_the_grid(&mut gpu, &scene, &s);
    eprintln!(
        "sky: GPU slices vs reference {apart:.1e}; against k = 16: slices {sliced_error:.1e}, grid {grid_error:.1e}"
    );
    assert!(apart <= 1e-5, "the GPU's sky slices {apart:e} from the reference's");
    // At 64 rows the slices still err 7.3e-3 at the worst pixel (second order in the rows), the grid 0.54.
    assert!(
        sliced_error <= 2e-2 && grid_error >= 10.0 * sliced_error,
        "{sliced_error:e} against the grid's {grid_error:e}"
    );
    // The sun's slices in the frame and the sky's in passes together.
    s.lights.sun = Some(Sun {
        direction: Vec3::new(0.6, 0.5, 0.3).normalize(),
        irradiance: [1000.0; 3],
        angular_diameter: 0.53f32.to_radians(),
    });
    let both = gpu.render(&scene, &s);
    let reference = cpu::render(&scene, &s, &gpu.reference_options());
    let apart = compare::diff(&both, &reference, &DiffOptions::default()).unwrap().0.max_rel;
    eprintln!("sun and sky: GPU slices vs reference {apart:.1e}");
    assert!(apart <= 1e-5, "the GPU's sun and sky slices {apart:e} from the reference's");
}

#[test]
fn gpu_disk_slices_agree_with_the_reference() {
    // room.gltf's disk skylight over the sphere (64 × 48, k = 4 and 6): the GPU's slices against the reference's to
    // 1e-5 (the diff's), and differing from the GPU's grid at pixels of the skylight's penumbrae; a penumbra's pixel
    // there gathers hundreds of the sphere's triangles under the skylight's wide cone (measured 3.6e-6 and 3.9e-6
    // apart). A light cone holding more than the slices keep refuses the image (gpu::slice_gather).
    let mut gpu = CheckedRenderer::new();
    let (scene, mut s) = common::sliced("room.gltf", (64, 48), 4);
    assert!(!s.lights.disks.is_empty() && s.lights.sky.is_none());
    for k in [4, 6] {
        s.shading.shadow_samples_per_axis = k;
        let sliced = gpu.render(&scene, &s);
        let reference = cpu::render(&scene, &s, &gpu.reference_options());
        let mut grid = s.clone();
        grid.shading.visibility_rule = VisibilityRule::Grid;
        let gridded = gpu.render(&scene, &grid);
        let max_rel = |a: &Image, b: &Image| compare::diff(a, b, &DiffOptions::default()).unwrap().0;
        let (apart, from_grid) = (max_rel(&sliced, &reference), max_rel(&sliced, &gridded));
        eprintln!(
            "room.gltf, k = {k}: {:.1e} from the reference's slices, {:.1e} from the grid",
            apart.max_rel, from_grid.max_rel
        );
        assert!(apart.max_rel <= 1e-5, "{}", apart.text("gpu", "reference"));
        assert!(from_grid.max_rel >= 1e-3, "the slices are the grid: {}", from_grid.text("slices", "grid"));
    }
    // At k = 9 (324 rows) the frame's own slices of the skylight run past Mesa 22's loop budget at the penumbra's
    // pixels (25 of them at 64 x 64, each cutting some 200 gathered triangles a row): the renderer takes the disk's
    // rows in passes before the frame (gpu::slice_passes) and draws the frame again, reading them. The same
    // agreement with the reference's slices (measured on Mesa 22.3.6: see the eprintln).
    s.shading.shadow_samples_per_axis = 9;
    let (passed, timings) = gpu.render_timed(&scene, &s);
    let reference = cpu::render(&scene, &s, &gpu.reference_options());
    let apart = compare::diff(&passed, &reference, &DiffOptions::default()).unwrap().0;
    eprintln!(
        "room.gltf, k = 9: {:.1e} from the reference's slices, lights in passes {:#x}",
        apart.max_rel, timings.lights_in_passes
    );
    assert!(apart.max_rel <= 1e-5, "{}", apart.text("gpu", "reference"));
    // Mesa 22.3.6's lavapipe has the loop limiter; Mesa 25.0.7's did not cut these loops short (docs/platform.md),
    // so its frame keeps the disk's slices.
    let info = gpu.renderer().device_info();
    if sunshade::gpu::frame_probe::probes(info) {
        assert_eq!(timings.lights_in_passes, sunshade::gpu::layout::READ_DISKS, "the disk's slices fit the frame here");
    }
    assert_eq!(timings.probe, None, "a frame of fewer than 128 rows is not probed");
    // From 128 pixels a side a first frame on llvmpipe is probed (gpu::frame_probe: a grid of 4 x 4 blocks drawn with
    // an eighth of the loop budget in reserve). At 128 x 128 and k = 9 the frame runs out in a blob of rows 76 to 89
    // (167 pixels, Mesa 22.3.6); the probe comes near the budget's end there, so the disk's rows are passed from
    // the start and the frame is drawn once. The image is bitwise the one a second render of the same upload draws
    // (which knows the rows from the first and probes nothing), and agrees with the reference's slices.
    let (scene, s) = common::sliced("room.gltf", (128, 128), 9);
    let reference = cpu::render(&scene, &s, &gpu.reference_options());
    let renderer = gpu.renderer();
    let uploaded = renderer.upload(&scene).unwrap();
    let (probed, first) = renderer.render(&uploaded, &s).unwrap();
    let (again, second) = renderer.render(&uploaded, &s).unwrap();
    let apart = compare::diff(&probed, &reference, &DiffOptions::default()).unwrap().0;
    eprintln!(
        "room.gltf at 128 x 128, k = 9: {:.1e} from the reference's slices, probe {:?}",
        apart.max_rel, first.probe
    );
    assert!(apart.max_rel <= 1e-5, "{}", apart.text("gpu", "reference"));
    assert_eq!(common::bits(&probed), common::bits(&again), "the probed frame is the frame drawn again");
    let info = renderer.device_info();
    // llvmpipe before Mesa 25 probes (25.0.7 cuts nothing short).
    let probed = sunshade::gpu::frame_probe::probes(info);
    assert_eq!(first.probe.is_some(), probed, "{first:?}");
    if probed {
        assert!(first.probe.is_some_and(|p| p.ran_out && p.blocks == 64), "{first:?}");
        assert_eq!(first.lights_in_passes, sunshade::gpu::layout::READ_DISKS);
        assert_eq!((second.probe, second.lights_in_passes), (None, first.lights_in_passes), "{second:?}");
    }
}

/// Renders `flags` on `model` (in models/) in two draws, the default (the first settling the pixels the sun's cells
/// and the disk lights' walk prove wholly lit or wholly hidden, the second shading the rest), and in one draw of the
/// whole shader (`ContextOptions::one_draw`): the same bits. The two draws are made both ways a device marks the
/// pixels the first leaves to the second: by the stencil its fragments write where the device exports stencil
/// values (lavapipe does), and by colour and the pass between the draws (`ContextOptions::mark_by_colour`, as a
/// device without the extension does; its pipelines must then be valid without it). Each two-draw frame must have
/// made a first draw's pipeline, so that the comparison is not between two single draws.
fn two_draws_same_bits(model: &str, flags: &[&str]) {
    use sunshade::gpu::ContextOptions;
    use sunshade::testing::{job, CheckedRenderer as Checked};
    let path = format!("{}/models/{model}", env!("CARGO_MANIFEST_DIR"));
    let j = job(&path, flags).unwrap_or_else(|e| panic!("{e}"));
    let mut one = Checked::try_with(ContextOptions { one_draw: true, ..ContextOptions::from_env() })
        .unwrap_or_else(|e| panic!("{e}"));
    let b = one.render_job(&j).unwrap_or_else(|e| panic!("{e}"));
    assert!(b.covered_count() > 0, "{model}: nothing drawn");
    drop(one);
    for by_colour in [false, true] {
        let mut two = if by_colour {
            Checked::try_with(ContextOptions { mark_by_colour: true, ..ContextOptions::from_env() })
                .unwrap_or_else(|e| panic!("{e}"))
        } else {
            common::shadow_ray_renderer()
        };
        let stencil = two.renderer().device_info().stencil_export;
        let a = two.render_job(&j).unwrap_or_else(|e| panic!("{e}"));
        let created: Vec<String> = two.renderer().take_created_pipelines().into_iter().map(|p| p.what).collect();
        assert!(created.iter().any(|p| p.contains("penumbrae later")), "{model} {flags:?}: no first draw: {created:?}");
        assert_eq!(
            created.iter().any(|p| p.contains("marked by stencil")),
            stencil,
            "{model} {flags:?}: first draws {created:?}, stencil export {stencil}"
        );
        assert!(!by_colour || !stencil, "mark_by_colour left the stencil export on");
        let differ = common::bits(&a).iter().zip(common::bits(&b)).filter(|(x, y)| **x != *y).count();
        assert_eq!(
            differ,
            0,
            "{model} {flags:?} (marked by {}): the two draws changed {differ} channel values of the one draw's image",
            if stencil { "stencil" } else { "colour" }
        );
    }
}

#[test]
fn gpu_two_draws_render_the_one_draws_image() {
    let small = ["--width", "96", "--height", "72"];
    // The sun's cells (Lambert), a low sun's long penumbrae, a glossy lobe's rays in the penumbrae.
    two_draws_same_bits("teapot.glb", &small);
    two_draws_same_bits("sunset.glb", &small);
    two_draws_same_bits("brdfs.glb", &[&small[..], &["--sun-elevation", "25"]].concat());
    // Disk lights (their walk's proof), with the sun and alone; alpha-masked occluders.
    two_draws_same_bits("room.gltf", &small);
    two_draws_same_bits("cube.glb", &[&small[..], &["--disk-light", "0.3,2.5,0.2:0,-1,0:0.5:2000"]].concat());
    two_draws_same_bits(
        "gltf-samples/AlphaBlendModeTest/AlphaBlendModeTest.glb",
        &[&small[..], &["--disk-light", "0.3,2.5,0.2:0,-1,0:0.5:2000"]].concat(),
    );
}

#[test]
fn gpu_points_under_more_triangles_than_the_sun_cells_answer_for_are_drawn_once_more_with_the_tree() {
    // 300 triangles stacked along the sun (5° wide, 49° up), their edges in line as seen from the floor below: a
    // floor point at the shadow's edge (the side the stack leans away from, in view) has all 300 partly in its
    // sun cone, past what its cone's list keeps
    // (MAX_SUN_LISTED, shaders/sun_cells.glsl) and above what its cell answers for (MAX_SUN_CELL_TRIANGLES), so
    // its rays need the occluders' tree. The frame is drawn first without the tree (`ShaderVariant::tree_later`),
    // which marks those pixels, then they alone once more with it; the image is the reference's, as for any default render. The
    // grid is 2² so that the rays' walks through the stack stay within llvmpipe's loop budget.
    let l = DVec3::new(0.8, 1.0, 0.3).normalize();
    let mut parts = vec![floor(3.0)];
    for i in 0..300 {
        let h = 0.2 + 0.004 * i as f64;
        let at = (l * (h / l.y)).as_vec3();
        parts.push(MeshData {
            positions: vec![at.to_array(), (at + Vec3::X).to_array(), (at + Vec3::Z).to_array()],
            normals: vec![[0.0, 1.0, 0.0]; 3],
            indices: vec![0, 2, 1],
        });
    }
    let sc = scene(&parts);
    let camera = camera_down(DVec3::new(0.0, 0.0, 0.5), 0.1, 3.0);
    let s = settings(96, 96, camera, sun_lights(l, 5.0), Shadows::Auto, 2);
    let mut gpu = common::shadow_ray_renderer();
    let (g, timings) = gpu.render_timed(&sc, &s);
    let created: Vec<String> = gpu.renderer().take_created_pipelines().into_iter().map(|p| p.what).collect();
    assert!(created.iter().any(|p| p.contains("tree later")), "{created:?}");
    assert!(created.iter().any(|p| p.contains("partly") && !p.contains("later")), "{created:?}");
    let redrawn = timings.tree_redrawn.expect("the stack's penumbra needs the tree");
    let (c, apart) = cpu::checked::checked_reference(&sc, &s, &gpu.reference_options());
    let apart = apart.as_ref().map(|a| (a.mask.as_slice(), a.name, a.allowed_fraction));
    let (report, _) = compare::diff_apart(&g, &c, &DiffOptions::default(), apart).unwrap();
    assert!(report.pass && report.coverage_mismatches.total == 0, "{}", report.text("gpu", "cpu"));
    // The stack's shadow and its penumbra are in view (the test would pass vacuously otherwise).
    let none =
        cpu::render(&sc, &settings(96, 96, camera, sun_lights(l, 5.0), Shadows::None, 1), &gpu.reference_options());
    let shadowed = c.pixels().iter().zip(none.pixels()).filter(|(a, b)| a[0] < b[0]).count();
    eprintln!("{redrawn} pixel(s) drawn again with the tree; {shadowed} shadowed");
    assert!(redrawn > 0 && shadowed > redrawn, "{redrawn} redrawn, {shadowed} shadowed");
}

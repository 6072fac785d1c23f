//! Helpers shared by the integration tests: temporary directories, scene writing, and a GPU renderer with
//! validation on that fails the test on any validation message (including messages at destruction).
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3, DVec4};
use sunshade::authoring::GltfBuilder;
use sunshade::scene::Scene;
use sunshade::Image;

/// A fresh directory under the system temp dir, removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> Self {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("sunshade-test-{}-{tag}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create temp dir");
        TempDir(dir)
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// Writes the scene (`.glb`, or `.gltf` + `.bin`) and returns its path.
    pub fn write(&self, name: &str, b: &GltfBuilder) -> PathBuf {
        let p = self.path(name);
        b.write(&p).expect("write scene");
        p
    }

    /// Names of the files in the directory.
    pub fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .expect("read temp dir")
            .map(|e| e.expect("dir entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[allow(unused_imports)]
pub use sunshade::testing::{assert_no_validation_messages, CheckedRenderer};

/// Relative difference |a − b| / |b| (0 when both are 0).
pub fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / b.abs()
    }
}

/// Loads a scene, panicking with the loader's message.
pub fn load(path: &Path) -> Scene {
    sunshade::scene::load(path).unwrap_or_else(|e| panic!("{e}"))
}

/// Bit patterns of an image, for bitwise comparisons.
pub fn bits(image: &Image) -> Vec<u32> {
    image.pixels().iter().flatten().map(|v| v.to_bits()).collect()
}

/// A renderer that casts shadow rays: by ray queries where it uses them (`gpu::casts_ray_queries`), else by the
/// fragment shader's walk of the occluders' BVH (`gpu::shadow_bvh`). With `SUNSHADE_REQUIRE_RAY_QUERIES=1`
/// (`make test`'s stage on Mesa 25's lavapipe, which also sets `SUNSHADE_RAY_QUERIES=1`, since a CPU device walks
/// by default) it must cast them, so that stage tests them and not the walk.
pub fn shadow_ray_renderer() -> CheckedRenderer {
    let mut gpu = CheckedRenderer::new();
    let info = gpu.renderer().device_info();
    assert!(
        info.ray_query || std::env::var("SUNSHADE_REQUIRE_RAY_QUERIES").map_or(true, |v| v != "1"),
        "SUNSHADE_REQUIRE_RAY_QUERIES=1 but {} casts no ray queries (SUNSHADE_RAY_QUERIES=1 uses a CPU device's)",
        info.name
    );
    gpu
}

/// A scene of these shapes, each a mesh of its own with default tangents, all of `material`.
pub fn scene_of(parts: &[sunshade::authoring::shapes::MeshData], material: sunshade::scene::Material) -> Scene {
    use glam::{Vec3, Vec4};
    let meshes = parts
        .iter()
        .enumerate()
        .map(|(i, m)| sunshade::scene::Mesh {
            name: format!("part {i}"),
            positions: m.positions.iter().map(|p| Vec3::from_array(*p)).collect(),
            normals: m.normals.iter().map(|n| Vec3::from_array(*n)).collect(),
            tangents: m
                .normals
                .iter()
                .map(|n| {
                    sunshade::scene::tangent::default_tangent(Vec3::from_array(*n).as_dvec3()).as_vec3().extend(1.0)
                })
                .collect::<Vec<Vec4>>(),
            indices: m.indices.clone(),
            material: 0,
            ..Default::default()
        })
        .collect();
    Scene { meshes, materials: vec![material], ..Default::default() }
}

/// The max relative error (the diff's floor) of `image` against the converged reference of `scene` with
/// `settings`, refined to `accuracy` (five doublings at most) with `reference`'s options, the truth's unconverged
/// pixels left out; and how many those were.
pub fn error_against_converged(
    scene: &Scene,
    settings: &sunshade::settings::RenderSettings,
    image: &Image,
    accuracy: f64,
    reference: &sunshade::cpu::ReferenceOptions,
) -> (f64, usize) {
    use sunshade::accuracy::converged::{render_converged, ConvergenceOptions};
    let truth = render_converged(scene, settings, reference, &ConvergenceOptions { accuracy, max_refinements: 5 });
    let e = sunshade::accuracy::error::image_error(image, &truth.image, Some(&truth.unconverged_mask())).unwrap();
    (e.max_rel, truth.unconverged.len())
}

/// [`error_against_converged`] outside the penumbrae too (`accuracy::penumbrae`, under the truth's finest shadow
/// rays), what `--tolerance` promises without `--tolerance-in-penumbrae`: the max relative error over every
/// converged pixel, over those outside the penumbrae, the pixels left out as unconverged, and the covered ones in a
/// penumbra.
#[allow(dead_code)]
pub fn error_against_converged_outside_penumbrae(
    scene: &Scene,
    settings: &sunshade::settings::RenderSettings,
    image: &Image,
    accuracy: f64,
    reference: &sunshade::cpu::ReferenceOptions,
) -> (f64, f64, usize, usize) {
    use sunshade::accuracy::converged::{render_converged, ConvergenceOptions};
    use sunshade::accuracy::error::image_error;
    let truth = render_converged(scene, settings, reference, &ConvergenceOptions { accuracy, max_refinements: 5 });
    let (outside, in_penumbrae) =
        sunshade::accuracy::penumbrae::outside_penumbrae_excluded(scene, settings, &truth, reference);
    let everywhere = image_error(image, &truth.image, Some(&truth.unconverged_mask())).unwrap().max_rel;
    let outside_error = image_error(image, &truth.image, Some(&outside)).unwrap().max_rel;
    (everywhere, outside_error, truth.unconverged.len(), in_penumbrae)
}

/// How far the image `--tolerance` wrote to `out` is from the reference of `scene` with `settings` (a fixed fine
/// grid, chosen by the test): its max relative error (the diff's floor), and the `predicted max relative error`
/// line of the render's `stderr`, for the test's report.
#[allow(dead_code)]
pub fn error_against_fine(
    out: &Path,
    scene: &Scene,
    settings: &sunshade::settings::RenderSettings,
    stderr: &str,
) -> (f64, String) {
    let fine = sunshade::cpu::render(scene, settings, &sunshade::cpu::ReferenceOptions::default());
    let image = sunshade::film::read_image(out).unwrap();
    let measured = sunshade::accuracy::error::image_error(&image, &fine, None).unwrap().max_rel;
    let line = stderr.lines().find(|l| l.contains("predicted max relative error")).unwrap_or_default();
    (measured, line.to_string())
}

/// The model `models/{model}` at `width` × `height` (the default camera and sun), shadowed by rays whose visible
/// fractions are taken by slices: `4k²` rows a light for `k²` shadow rays.
pub fn sliced(model: &str, (width, height): (u32, u32), k: u32) -> (Scene, sunshade::settings::RenderSettings) {
    let scene = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models").join(model));
    let mut s = sunshade::settings::resolve(
        &scene,
        width,
        height,
        &Default::default(),
        &sunshade::settings::SunOptions::default(),
    )
    .unwrap();
    s.shading.shadows = sunshade::shading::Shadows::Ray;
    s.shading.shadow_samples_per_axis = k;
    s.shading.visibility_rule = sunshade::shading::VisibilityRule::Slices;
    (scene, s)
}

/// A ray through the point (x, y) of a w × h window [pixels]: origin and unit direction in world space, from the
/// inverse `inv` of the f64 clip-from-world matrix.
pub fn pixel_ray(inv: &DMat4, x: f64, y: f64, w: u32, h: u32) -> (DVec3, DVec3) {
    let ndc = DVec3::new(x / w as f64 * 2.0 - 1.0, y / h as f64 * 2.0 - 1.0, 0.0);
    let unproject = |z: f64| {
        let p = *inv * DVec4::new(ndc.x, ndc.y, z, 1.0);
        p.truncate() / p.w
    };
    let (a, b) = (unproject(0.0), unproject(0.5));
    (a, (b - a).normalize())
}

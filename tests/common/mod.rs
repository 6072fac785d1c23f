//! Helpers shared by the integration tests: temporary directories, scene writing, and a GPU renderer with
//! validation on that fails the test on any validation message (including messages at destruction).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sunshade::authoring::GltfBuilder;
use sunshade::gpu::{ContextOptions, Renderer, ValidationLog};
use sunshade::scene::Scene;
use sunshade::settings::RenderSettings;
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

/// A renderer with the validation layer on. Any validation message fails the test: after each render, and when
/// the renderer is dropped (messages about objects left alive arrive then).
pub struct CheckedRenderer {
    renderer: Option<Renderer>,
    log: Arc<ValidationLog>,
}

impl CheckedRenderer {
    pub fn new() -> Self {
        let renderer = Renderer::new(&ContextOptions { validation: true, ..Default::default() })
            .unwrap_or_else(|e| panic!("GPU tests need Vulkan with validation layers (make setup): {e}"));
        let log = renderer.validation_log();
        Self { renderer: Some(renderer), log }
    }

    pub fn renderer(&mut self) -> &mut Renderer {
        self.renderer.as_mut().expect("alive")
    }

    pub fn render(&mut self, scene: &Scene, settings: &RenderSettings) -> Image {
        let (image, _) = self.renderer().render_scene(scene, settings).unwrap_or_else(|e| panic!("render failed: {e}"));
        assert_no_validation_messages(&self.log);
        image
    }

    pub fn sub_pixel_bits(&self) -> u32 {
        self.renderer.as_ref().expect("alive").device_info().sub_pixel_precision_bits
    }
}

impl Default for CheckedRenderer {
    fn default() -> Self {
        Self::new()
    }
}

impl Drop for CheckedRenderer {
    fn drop(&mut self) {
        drop(self.renderer.take());
        if !std::thread::panicking() {
            assert_no_validation_messages(&self.log);
        }
    }
}

pub fn assert_no_validation_messages(log: &ValidationLog) {
    let messages = log.messages();
    assert!(messages.is_empty(), "{} validation message(s):\n{}", messages.len(), messages.join("\n"));
}

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

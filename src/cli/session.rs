//! What consecutive renders in one process share: a renderer per device and interpolation mode (its pipelines
//! created once), and the scenes loaded recently, each uploaded once per renderer.

use std::path::PathBuf;
use std::time::Duration;

use super::args::SceneArgs;
use super::{load_only, CliError};
use crate::gpu::{ContextOptions, GpuScene, Interpolation, Renderer};
use crate::scene::{BrdfKind, Scene};

/// How many scenes a session keeps loaded (with their uploads) for jobs that reuse them.
pub const KEPT_SCENES: usize = 4;

/// The flags a loaded scene depends on.
#[derive(Clone, Debug, PartialEq)]
struct SceneKey {
    path: PathBuf,
    scene_index: Option<usize>,
    brdf: Option<BrdfKind>,
    merl: Option<PathBuf>,
    merl_lookup: Option<crate::shading::measured::MeasuredLookup>,
    asset_root: Option<PathBuf>,
    allow_outside_uris: bool,
}

impl SceneKey {
    fn of(a: &SceneArgs) -> Self {
        Self {
            path: a.scene.clone(),
            scene_index: a.scene_index,
            brdf: a.brdf,
            merl: a.merl.clone(),
            merl_lookup: a.merl_lookup,
            asset_root: a.asset_root.clone(),
            allow_outside_uris: a.allow_outside_uris,
        }
    }
}

/// What a renderer is created for: `--device` and `--interpolation`.
type RendererKey = (Option<String>, Option<Interpolation>);

struct LoadedScene {
    key: SceneKey,
    scene: Scene,
    /// The scene's upload to each renderer that drew it, by renderer index.
    uploads: Vec<(usize, GpuScene)>,
}

/// Renderers and scenes kept between renders.
#[derive(Default)]
pub struct Session {
    renderers: Vec<(RendererKey, Renderer)>,
    /// Most recently used last.
    scenes: Vec<LoadedScene>,
    pub pipeline_cache_dir: Option<PathBuf>,
}

impl Session {
    /// An empty session whose renderers keep their pipeline cache in `pipeline_cache_dir`.
    pub fn new(pipeline_cache_dir: Option<PathBuf>) -> Self {
        Self { pipeline_cache_dir, ..Default::default() }
    }

    /// The renderer for this device and interpolation mode, created at first use; returns its index.
    pub fn renderer(
        &mut self,
        device: Option<String>,
        interpolation: Option<Interpolation>,
    ) -> Result<usize, CliError> {
        let key = (device, interpolation);
        if let Some(i) = self.renderers.iter().position(|(k, _)| *k == key) {
            return Ok(i);
        }
        let options = ContextOptions {
            device: key.0.clone(),
            interpolation: key.1,
            pipeline_cache_dir: self.pipeline_cache_dir.clone(),
            ..ContextOptions::from_env()
        };
        self.renderers.push((key, Renderer::new(&options)?));
        Ok(self.renderers.len() - 1)
    }

    /// "gpu: DEVICE (DRIVER INFO); interpolation MODE", for the files a renderer's images go to.
    pub fn renderer_description(&self, index: usize) -> String {
        let r = &self.renderers[index].1;
        let i = r.device_info();
        format!("gpu: {} ({} {}); interpolation {}", i.name, i.driver_name, i.driver_info, r.interpolation().name())
    }

    pub fn renderer_mut(&mut self, index: usize) -> &mut Renderer {
        &mut self.renderers[index].1
    }

    /// The scene these flags name, loaded now unless the session has it; returns its index (valid until the next
    /// `load`) and the time spent loading (zero when reused).
    pub fn load(&mut self, a: &SceneArgs) -> Result<(usize, Duration), CliError> {
        let key = SceneKey::of(a);
        if let Some(i) = self.scenes.iter().position(|s| s.key == key) {
            // Most recently used last.
            let s = self.scenes.remove(i);
            self.scenes.push(s);
            return Ok((self.scenes.len() - 1, Duration::ZERO));
        }
        let (scene, load) = load_only(a)?;
        if self.scenes.len() == KEPT_SCENES {
            self.scenes.remove(0);
        }
        self.scenes.push(LoadedScene { key, scene, uploads: Vec::new() });
        Ok((self.scenes.len() - 1, load))
    }

    pub fn scene_ref(&self, s: usize) -> &Scene {
        &self.scenes[s].scene
    }

    /// Uploads loaded scene `s` to renderer `r` unless it was already; returns the time spent.
    pub fn upload(&mut self, s: usize, r: usize) -> Result<Duration, CliError> {
        if self.scenes[s].uploads.iter().any(|(i, _)| *i == r) {
            return Ok(Duration::ZERO);
        }
        let t = std::time::Instant::now();
        let upload = self.renderers[r].1.upload(&self.scenes[s].scene)?;
        self.scenes[s].uploads.push((r, upload));
        Ok(t.elapsed())
    }

    /// The loaded scene `s`, its upload to renderer `r`, and the renderer.
    pub fn parts(&mut self, s: usize, r: usize) -> (&Scene, &GpuScene, &mut Renderer) {
        let loaded = &self.scenes[s];
        let upload = &loaded.uploads.iter().find(|(i, _)| *i == r).expect("uploaded by Session::scene").1;
        (&loaded.scene, upload, &mut self.renderers[r].1)
    }

    /// Saves every renderer's pipeline cache; returns the warnings.
    pub fn save_pipeline_caches(&mut self) -> Vec<String> {
        self.renderers.iter_mut().filter_map(|(_, r)| r.save_pipeline_cache().err()).collect()
    }
}

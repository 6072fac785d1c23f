//! The Khronos sample models in `models/gltf-samples/` (textures, vertex colours, skins, morph targets, alpha
//! modes, texture transforms): each loads without a warning about a texture it uses, and the GPU (lavapipe,
//! validation on) agrees with the CPU reference within `render --check`'s tolerance, with the default Lambert
//! mapping and with the metallic-roughness mapping onto Ward (which reads the metallic-roughness textures).

mod common;

use std::path::{Path, PathBuf};

use common::CheckedRenderer;
use sunshade::compare::DiffOptions;
use sunshade::testing;

fn samples() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/gltf-samples");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        for file in std::fs::read_dir(entry.unwrap().path()).unwrap() {
            let p = file.unwrap().path();
            if matches!(p.extension().and_then(|e| e.to_str()), Some("glb" | "gltf")) {
                out.push(p);
            }
        }
    }
    out.sort();
    assert!(out.len() >= 14, "{out:?}");
    out
}

#[test]
fn samples_load_without_warnings_about_their_textures() {
    for path in samples() {
        let scene = sunshade::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        for w in &scene.warnings {
            // What sunshade says it does not draw: BLEND (drawn opaque) and baked occlusion, by design.
            let by_design = w.contains("occlusionTexture") || w.contains("alphaMode BLEND");
            let texture =
                ["baseColorTexture", "metallicRoughnessTexture", "normalTexture", "emissiveTexture", "TEXCOORD"]
                    .iter()
                    .any(|t| w.contains(t));
            assert!(!texture || by_design, "{}: {w}", path.display());
        }
        let textured = scene.materials.iter().any(|m| m.textures().next().is_some());
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let untextured = ["MetalRoughSpheresNoTextures", "OrientationTest", "SimpleMorph", "SimpleSkin"];
        assert_eq!(textured, !untextured.contains(&name.as_str()), "{name}");
    }
}

#[test]
fn gpu_agrees_with_the_reference_on_every_sample() {
    let mut gpu = CheckedRenderer::new();
    let options = DiffOptions::default();
    for path in samples() {
        for brdf in ["lambert", "ward"] {
            let job = testing::job(&path, &["--width", "96", "--height", "80", "--brdf", brdf]).unwrap();
            let image = gpu.render_job(&job).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(image.covered_count() > 100, "{}: nothing drawn", path.display());
            // As `render --check`: with shadow maps (a device without ray queries) their edges counted apart.
            if let Err(report) = testing::check_against_reference(&job, &image, &gpu.reference_options(), &options) {
                panic!("{} --brdf {brdf}:\n{report}", path.display());
            }
        }
    }
}

#[test]
fn max_texture_size_starts_large_textures_at_a_smaller_level() {
    // AlphaBlendModeTest's 2048² textures drawn from their 256² level: the same texels as that level of the full
    // chain, and GPU and reference still agree.
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("models/gltf-samples/AlphaBlendModeTest/AlphaBlendModeTest.glb");
    let full = sunshade::scene::load(&path).unwrap();
    let options = sunshade::scene::LoadOptions { max_texture_size: Some(256), ..Default::default() };
    let small = sunshade::scene::load_with_options(&path, &options).unwrap();
    for (f, s) in full.textures.iter().zip(&small.textures) {
        let first = &s.levels[0];
        assert!(first.width.max(first.height) <= 256);
        let k = f.levels.len() - s.levels.len();
        assert_eq!(&f.levels[k..], &s.levels[..], "{}", f.name);
    }
    let mut gpu = CheckedRenderer::new();
    let job = testing::job(&path, &["--width", "96", "--height", "80", "--max-texture-size", "256"]).unwrap();
    let image = gpu.render_job(&job).unwrap();
    testing::check_against_reference(&job, &image, &gpu.reference_options(), &DiffOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
}

//! Hostile and unusual glTF files, generated from models/square.gltf: each case is one edit of the file (or of the
//! folder around it) and one asserted expectation: refused with a message naming the problem, or loaded (and then
//! rendered by the reference without a panic).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::TempDir;
use serde_json::{json, Value};
use sunshade::scene::{self, LoadOptions, Scene, UriScope};
use sunshade::settings::{self, CameraOptions, SunOptions};

/// A folder `scene/` holding square.gltf and its .bin, with `outside.bin` (a copy of the .bin) next to the folder.
struct Case {
    dir: TempDir,
    doc: Value,
}

impl Case {
    fn new(tag: &str) -> Self {
        let dir = TempDir::new(tag);
        std::fs::create_dir_all(dir.path("scene")).unwrap();
        let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
        let bin = std::fs::read(models.join("square.bin")).unwrap();
        std::fs::write(dir.path("scene/square.bin"), &bin).unwrap();
        std::fs::write(dir.path("outside.bin"), &bin).unwrap();
        let doc = serde_json::from_slice(&std::fs::read(models.join("square.gltf")).unwrap()).unwrap();
        Case { dir, doc }
    }

    fn scene_dir(&self) -> PathBuf {
        self.dir.path("scene")
    }

    /// Writes the (edited) document and returns its path.
    fn write(&self) -> PathBuf {
        let path = self.dir.path("scene/case.gltf");
        std::fs::write(&path, self.doc.to_string()).unwrap();
        path
    }

    fn load_with(&self, uris: UriScope) -> Result<Scene, String> {
        let path = self.write();
        scene::load_with_options(&path, &LoadOptions { uris, ..Default::default() }).map_err(|e| e.to_string())
    }

    /// Asserts that loading fails with one line that names the file and every one of `names`.
    fn refused(&self, names: &[&str]) {
        self.refused_with(UriScope::SceneFolder, names)
    }

    fn refused_with(&self, uris: UriScope, names: &[&str]) {
        match self.load_with(uris) {
            Ok(_) => panic!("loaded, expected an error naming {names:?}"),
            Err(e) => {
                assert!(e.contains("case.gltf"), "does not name the file: {e}");
                assert_eq!(e.lines().count(), 1, "not one line: {e}");
                for n in names {
                    assert!(e.contains(n), "does not name '{n}': {e}");
                }
            }
        }
    }

    /// Asserts that the file loads and renders on the CPU reference without a panic; returns the scene.
    fn loads(&self) -> Scene {
        let s = self.load_with(UriScope::SceneFolder).unwrap_or_else(|e| panic!("refused: {e}"));
        reference(&s);
        s
    }
}

fn reference(s: &Scene) -> sunshade::Image {
    let settings = settings::resolve(s, 16, 12, &CameraOptions::default(), &SunOptions::default()).unwrap();
    sunshade::cpu::render(s, &settings, &Default::default())
}

/// An edit of the glTF JSON.
type Edit = Box<dyn Fn(&mut Value)>;
/// An edit of a file's bytes.
type ByteEdit = Box<dyn Fn(&mut Vec<u8>)>;

fn buffer_uri(uri: &str) -> impl Fn(&mut Value) + '_ {
    move |d: &mut Value| d["buffers"][0]["uri"] = json!(uri)
}

#[test]
fn uris_stay_inside_the_scene_folder() {
    let mut c = Case::new("uri-parent");
    buffer_uri("../outside.bin")(&mut c.doc);
    c.refused(&["../outside.bin", "outside the asset folder"]);
    // Opting in reads it: --asset-root one level up, or --allow-outside-uris.
    c.load_with(UriScope::Folder(c.dir.0.clone())).unwrap();
    c.load_with(UriScope::Anywhere).unwrap();

    let mut c = Case::new("uri-encoded");
    buffer_uri("%2e%2e/outside.bin")(&mut c.doc);
    c.refused(&["%2e%2e/outside.bin", "outside the asset folder"]);

    let mut c = Case::new("uri-absolute");
    let abs = c.dir.path("outside.bin").display().to_string();
    buffer_uri(&abs)(&mut c.doc);
    c.refused(&[&abs, "absolute path"]);
    c.load_with(UriScope::Anywhere).unwrap();

    let mut c = Case::new("uri-passwd");
    buffer_uri("/etc/passwd")(&mut c.doc);
    c.refused(&["/etc/passwd", "absolute path"]);

    let mut c = Case::new("uri-file-scheme");
    buffer_uri("file:///etc/passwd")(&mut c.doc);
    c.refused(&["not a relative file path"]);

    #[cfg(unix)]
    {
        let mut c = Case::new("uri-symlink");
        std::os::unix::fs::symlink(c.dir.path("outside.bin"), c.scene_dir().join("link.bin")).unwrap();
        buffer_uri("link.bin")(&mut c.doc);
        c.refused(&["link.bin", "outside the asset folder"]);
        // A link that stays inside is fine.
        std::os::unix::fs::symlink(c.scene_dir().join("square.bin"), c.scene_dir().join("inside.bin")).unwrap();
        buffer_uri("inside.bin")(&mut c.doc);
        c.loads();
    }
}

#[test]
fn only_regular_files_are_read_and_only_what_is_declared() {
    let mut c = Case::new("uri-dir");
    std::fs::create_dir(c.scene_dir().join("folder.bin")).unwrap();
    buffer_uri("folder.bin")(&mut c.doc);
    c.refused(&["folder.bin", "a directory"]);

    let mut c = Case::new("uri-device");
    buffer_uri("/dev/zero")(&mut c.doc);
    c.refused(&["absolute path"]);
    c.refused_with(UriScope::Anywhere, &["/dev/zero", "a device"]);

    #[cfg(unix)]
    {
        let mut c = Case::new("uri-fifo");
        let fifo = c.scene_dir().join("pipe.bin");
        assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success(), "mkfifo");
        buffer_uri("pipe.bin")(&mut c.doc);
        c.refused(&["pipe.bin", "a FIFO"]);
        // The scene file itself: a FIFO or a device is refused before it is opened.
        for path in [fifo.as_path(), Path::new("/dev/zero")] {
            let e = scene::load(path).unwrap_err().to_string();
            assert!(e.contains(&path.display().to_string()) && e.contains("not a regular file"), "{e}");
        }
    }

    // byteLength larger than the file: refused before reading, whatever its size.
    for length in [1u64 << 31, u64::MAX, 103] {
        let mut c = Case::new("bytelength");
        c.doc["buffers"][0]["byteLength"] = json!(length);
        c.refused(&["buffer 0", &format!("byteLength {length}")]);
    }
    // Smaller than the file: only the declared bytes are kept, and the accessors must fit in them.
    let mut c = Case::new("bytelength-short");
    c.doc["buffers"][0]["byteLength"] = json!(100);
    c.refused(&["bufferView 2", "out of range of buffer 0 (100 bytes)"]);
}

#[test]
fn dangling_indices_are_errors_naming_the_object() {
    let cases: Vec<(&str, Edit, &[&str])> = vec![
        (
            "position-5",
            Box::new(|d| {
                d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(5);
                d["accessors"] = json!([]);
            }),
            &["POSITION", "accessor 5 does not exist"],
        ),
        ("mesh", Box::new(|d| d["nodes"][0]["mesh"] = json!(9)), &["node 0", "mesh 9 does not exist"]),
        ("child", Box::new(|d| d["nodes"][0]["children"] = json!([7])), &["node 0", "child node 7"]),
        ("scene-node", Box::new(|d| d["scenes"][0]["nodes"] = json!([0, 40])), &["scene 0", "node 40"]),
        ("default-scene", Box::new(|d| d["scene"] = json!(3)), &["scene 3 does not exist"]),
        ("material", Box::new(|d| d["meshes"][0]["primitives"][0]["material"] = json!(2)), &["material 2"]),
        ("view", Box::new(|d| d["accessors"][0]["bufferView"] = json!(99)), &["accessor 0", "bufferView 99"]),
        ("buffer", Box::new(|d| d["bufferViews"][0]["buffer"] = json!(4)), &["bufferView 0", "buffer 4"]),
        ("camera", Box::new(|d| d["nodes"][0]["camera"] = json!(0)), &["node 0", "camera 0 does not exist"]),
        (
            "light",
            Box::new(|d| d["nodes"][1]["extensions"]["KHR_lights_punctual"]["light"] = json!(3)),
            &["node 1", "light 3 does not exist"],
        ),
        ("type", Box::new(|d| d["nodes"][0]["mesh"] = json!("zero")), &["nodes[0].mesh", "invalid type"]),
        ("negative", Box::new(|d| d["accessors"][0]["count"] = json!(-1)), &["accessors[0].count"]),
    ];
    for (name, edit, names) in cases {
        let mut c = Case::new(name);
        edit(&mut c.doc);
        c.refused(names);
    }
}

#[test]
fn counts_offsets_and_lengths_that_overflow_are_refused() {
    for count in [1u64 << 31, u64::MAX] {
        for view in [true, false] {
            let mut c = Case::new("count");
            c.doc["accessors"][0]["count"] = json!(count);
            if !view {
                c.doc["accessors"][0].as_object_mut().unwrap().remove("bufferView");
            }
            c.refused(&["accessor 0"]);
        }
    }
    for offset in [u64::MAX, u64::MAX - 40, 1u64 << 63] {
        let mut c = Case::new("offset");
        c.doc["accessors"][0]["byteOffset"] = json!(offset);
        c.refused(&["accessor 0"]);
        let mut c = Case::new("view-offset");
        c.doc["bufferViews"][0]["byteOffset"] = json!(offset);
        c.refused(&["bufferView 0", "out of range"]);
        let mut c = Case::new("stride");
        c.doc["bufferViews"][0]["byteStride"] = json!(offset);
        c.refused(&["accessor 0"]);
    }
}

#[test]
fn hierarchies_are_walked_without_recursion_and_must_be_trees() {
    // A chain of 10⁵ nested nodes, the mesh at the bottom: loads and renders (this overflowed the stack before).
    let mut c = Case::new("chain");
    let n = 100_000;
    let mut nodes: Vec<Value> = (0..n).map(|i| json!({ "children": [i + 1] })).collect();
    nodes.push(json!({ "mesh": 0 }));
    c.doc["nodes"] = Value::Array(nodes);
    c.doc["scenes"][0]["nodes"] = json!([0]);
    let s = c.loads();
    assert_eq!(s.meshes.len(), 1);

    let mut c = Case::new("cycle");
    c.doc["nodes"][0]["children"] = json!([1]);
    c.doc["nodes"][1]["children"] = json!([0]);
    c.refused(&["reached twice", "cycle"]);

    let mut c = Case::new("self");
    c.doc["nodes"][0]["children"] = json!([0]);
    c.refused(&["node 0 is reached twice"]);

    let mut c = Case::new("two-parents");
    c.doc["nodes"].as_array_mut().unwrap().push(json!({ "children": [0] }));
    c.doc["scenes"][0]["nodes"] = json!([0, 1, 2]);
    c.refused(&["node 0 is reached twice"]);
}

#[test]
fn deep_json_nesting_is_refused_not_a_crash() {
    for depth in [1_000, 100_000] {
        let mut c = Case::new("nesting");
        c.doc["nodes"][0]["extras"] = json!(null);
        let path = c.write();
        let text = std::fs::read_to_string(&path).unwrap();
        let deep = format!("{}{}", "[".repeat(depth), "]".repeat(depth));
        std::fs::write(&path, text.replacen("\"extras\":null", &format!("\"extras\":{deep}"), 1)).unwrap();
        let e = scene::load(&path).unwrap_err().to_string();
        assert!(e.contains("recursion limit"), "{e}");
    }
}

#[test]
fn non_finite_values_and_degenerate_transforms_are_refused() {
    let mut c = Case::new("huge-matrix");
    c.doc["nodes"][0]["matrix"] = json!([3e38, 0, 0, 0, 0, 3e38, 0, 0, 0, 0, 3e38, 0, 3e38, 3e38, 3e38, 1]);
    c.refused(&["vertex", "not finite after the node transform"]);

    let mut c = Case::new("zero-quaternion");
    c.doc["nodes"][0]["rotation"] = json!([0, 0, 0, 0]);
    c.refused(&["node 0", "zero-length transform"]);

    let mut c = Case::new("inf-json");
    c.doc["nodes"][0]["translation"] = json!([0, 0, 0]);
    let path = c.write();
    let text = std::fs::read_to_string(&path).unwrap().replacen("[0,0,0]", "[1e999,0,0]", 1);
    std::fs::write(&path, text).unwrap();
    let e = scene::load(&path).unwrap_err().to_string();
    assert!(e.contains("invalid glTF JSON"), "{e}");

    // NaN in the binary positions.
    let mut c = Case::new("nan-position");
    let bin = c.scene_dir().join("square.bin");
    let mut bytes = std::fs::read(&bin).unwrap();
    bytes[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
    std::fs::write(&bin, bytes).unwrap();
    c.doc["asset"]["generator"] = json!("nan");
    c.refused(&["POSITION accessor 0", "non-finite", "vertex 0"]);

    let mut c = Case::new("camera-scale-0");
    c.doc["cameras"] = json!([{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1 } }]);
    c.doc["nodes"].as_array_mut().unwrap().push(json!({ "camera": 0, "scale": [0, 0, 0] }));
    c.doc["scenes"][0]["nodes"] = json!([0, 1, 2]);
    c.refused(&["camera 0", "no view direction"]);

    // Camera matrices out of f32 range (JSON has no inf or NaN: 1e39 rounds to inf as a glTF float).
    let mut c = Case::new("camera-matrix-inf");
    c.doc["cameras"] = json!([{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1 } }]);
    c.doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "camera": 0, "matrix": [1e39, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1] }));
    c.doc["scenes"][0]["nodes"] = json!([0, 1, 2]);
    c.refused(&["node 2", "non-finite"]);
    let mut c = Case::new("camera-matrix-huge");
    c.doc["cameras"] = json!([{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1 } }]);
    c.doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "camera": 0, "matrix": [3e38, 0, 0, 0, 0, 3e38, 0, 0, 0, 0, 3e38, 0, 3e38, 3e38, 3e38, 1] }));
    c.doc["scenes"][0]["nodes"] = json!([0, 1, 2]);
    // Finite in f64: placed, and rendered (empty) without a panic.
    let s = c.loads();
    assert_eq!(s.cameras.len(), 1);

    let mut c = Case::new("camera-type");
    c.doc["cameras"] = json!([{ "type": "perspective" }]);
    c.doc["nodes"].as_array_mut().unwrap().push(json!({ "camera": 0 }));
    c.doc["scenes"][0]["nodes"] = json!([0, 1, 2]);
    c.refused(&["camera 0", "perspective"]);

    let mut c = Case::new("sun-intensity");
    c.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = json!(-5);
    c.refused(&["light 0", "node 1", "intensity -5"]);
}

#[test]
fn glb_chunk_lengths_past_the_file_are_refused() {
    let dir = TempDir::new("glb");
    let good = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("models/cube.glb")).unwrap();
    let json_len = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
    let edits: Vec<(&str, ByteEdit)> = vec![
        ("total", Box::new(|b| b[8..12].copy_from_slice(&u32::MAX.to_le_bytes()))),
        ("json", Box::new(|b| b[12..16].copy_from_slice(&u32::MAX.to_le_bytes()))),
        ("bin", Box::new(move |b| b[20 + json_len..24 + json_len].copy_from_slice(&u32::MAX.to_le_bytes()))),
        ("cut", Box::new(|b| b.truncate(b.len() - 3))),
        ("header", Box::new(|b| b.truncate(10))),
    ];
    for (name, edit) in edits {
        let mut bytes = good.clone();
        edit(&mut bytes);
        let path = dir.path(&format!("{name}.glb"));
        std::fs::write(&path, bytes).unwrap();
        let e = scene::load(&path).unwrap_err().to_string();
        assert!(e.contains(&format!("{name}.glb")) && e.contains("GLB"), "{name}: {e}");
    }
}

#[test]
fn valid_files_load() {
    // No scene and no `scene`: the root nodes are drawn, with a warning saying so.
    let mut c = Case::new("no-scene");
    let root = c.doc.as_object_mut().unwrap();
    root.remove("scene");
    root.remove("scenes");
    let s = c.loads();
    assert_eq!(s.meshes.len(), 1);
    assert!(s.lights.sun.is_some());
    assert!(s.warnings.iter().any(|w| w.contains("no scene") && w.contains("2 root node")), "{:?}", s.warnings);

    // Nothing to draw at all.
    let mut c = Case::new("empty");
    c.doc = json!({ "asset": { "version": "2.0" } });
    c.refused(&["nothing to draw"]);

    // An accessor without a buffer view is zeros; with sparse values on top.
    let mut c = Case::new("zeros");
    c.doc["accessors"][1].as_object_mut().unwrap().remove("bufferView");
    let s = c.loads();
    assert!(s.meshes[0].normals.iter().all(|n| *n == glam::Vec3::ZERO));
    let mut c = Case::new("sparse-zeros");
    let positions = c.doc["accessors"][0].as_object_mut().unwrap();
    positions.remove("bufferView");
    // Sparse: vertex indices 0..4 (u8, after the 6 index bytes at 96) replaced by the 48 bytes of position data.
    let mut bin = std::fs::read(c.scene_dir().join("square.bin")).unwrap();
    bin.extend([0u8, 1, 2, 3]);
    std::fs::write(c.scene_dir().join("square.bin"), &bin).unwrap();
    c.doc["buffers"][0]["byteLength"] = json!(bin.len());
    c.doc["bufferViews"].as_array_mut().unwrap().push(json!({ "buffer": 0, "byteOffset": 102, "byteLength": 4 }));
    c.doc["accessors"][0]["sparse"] = json!({
        "count": 4,
        "indices": { "bufferView": 3, "componentType": 5121 },
        "values": { "bufferView": 0 }
    });
    let sparse = c.loads();
    let plain = Case::new("plain").loads();
    assert_eq!(sparse.meshes[0].positions, plain.meshes[0].positions);

    // Textures without a source, samplers, images: loaded (textures are not drawn yet, with a warning).
    let mut c = Case::new("texture-no-source");
    c.doc["textures"] = json!([{ "sampler": 0 }]);
    c.doc["samplers"] = json!([{}]);
    c.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": 0 });
    let s = c.loads();
    assert!(s.warnings.iter().any(|w| w.contains("baseColorTexture")), "{:?}", s.warnings);

    // A primitive without POSITION is skipped with a warning, as the spec asks.
    let mut c = Case::new("no-position");
    c.doc["meshes"][0]["primitives"][0]["attributes"].as_object_mut().unwrap().remove("POSITION");
    let s = c.loads();
    assert!(s.meshes.is_empty() && s.warnings.iter().any(|w| w.contains("no POSITION")), "{:?}", s.warnings);

    // KHR_mesh_quantization required: normalized i16 positions, as a quantizer writes them, equal their float
    // twin to the quantization step.
    let mut c = Case::new("quantized");
    let plain = Case::new("plain").loads();
    let mut bin = std::fs::read(c.scene_dir().join("square.bin")).unwrap();
    let at = bin.len() as u64;
    for p in [[-0.5f32, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]] {
        for v in p {
            bin.extend(((v * 2.0 * 32767.0).round() as i16).to_le_bytes());
        }
        bin.extend([0, 0]); // 4-byte aligned elements
    }
    std::fs::write(c.scene_dir().join("square.bin"), &bin).unwrap();
    c.doc["buffers"][0]["byteLength"] = json!(bin.len());
    c.doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "buffer": 0, "byteOffset": at, "byteLength": 32, "byteStride": 8 }));
    c.doc["accessors"][0] =
        json!({ "bufferView": 3, "componentType": 5122, "normalized": true, "count": 4, "type": "VEC3" });
    c.doc["nodes"][0]["scale"] = json!([0.5, 0.5, 0.5]);
    c.doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_mesh_quantization"]);
    c.doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    let q = c.loads();
    assert!(q.warnings.is_empty(), "{:?}", q.warnings);
    for (a, b) in q.meshes[0].positions.iter().zip(&plain.meshes[0].positions) {
        assert!((*a - *b).abs().max_element() < 1.0 / 32767.0, "{a} vs {b}");
    }

    // A required extension sunshade does not implement is refused, naming it.
    let mut c = Case::new("required");
    c.doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    c.refused(&["requires", "KHR_draco_mesh_compression"]);

    let mut c = Case::new("version");
    c.doc["asset"]["version"] = json!("1.0");
    c.refused(&["asset.version '1.0'"]);
}

fn sunshade(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sunshade")).args(args).env("SUNSHADE_VALIDATION", "1").output().unwrap()
}

#[test]
fn cli_refusals_are_one_line_with_the_documented_exit_code() {
    let c = Case::new("cli");
    let good = c.write();
    let out = c.dir.path("out.png");
    let (g, o) = (good.to_str().unwrap(), out.to_str().unwrap());
    let cases: Vec<(Vec<&str>, i32, &str)> = vec![
        (vec!["render", g, "-o", o, "--width", "-5"], 2, "-5 pixels"),
        (vec!["render", g, "-o", o, "--fail-rel", "1e-3"], 2, "--fail-rel applies only with --check"),
        (vec!["render", g, "-o", o, "--sub-pixel-bits", "4"], 2, "--sub-pixel-bits"),
        (vec!["render", g, "-o", o, "--check", "--heatmap", "h.exr"], 2, "heatmap is a PNG"),
        (vec!["render", g, "-o", "/no/such/folder/x.png"], 2, "'/no/such/folder' does not exist"),
        (vec!["reference", g, "-o", o, "--width", "100000", "--height", "100000"], 1, "largest side"),
        (vec!["reference", g, "-o", o, "--width", "16000", "--height", "16000"], 1, "--max-pixels"),
        (vec!["diff", g, g, "--fail-rel=-1"], 2, "must not be negative"),
        (vec!["render", g, "-o", "x.exr", "--exposure", "-3"], 2, "--exposure applies to PNG output only"),
        (vec!["reference", g, "-o", o, "--sun-model", "delta", "--sun-samples", "16"], 2, "--sun-samples"),
        // Checked before the long computation, not after it.
        (vec!["albedo", "--update", "no-such-doc.md"], 2, "no-such-doc.md"),
        (vec!["bench", g, "--update", "no-such-doc.md"], 2, "no-such-doc.md"),
        (vec!["bench", "--brdf-chart", "--update", g], 2, "no '<!-- sunshade brdf-chart: begin"),
    ];
    for (args, code, names) in cases {
        let r = sunshade(&args);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(names), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: not one line: {err}");
        assert!(!err.contains("tip: to pass"), "{args:?}: {err}");
        assert!(!out.exists());
    }
    // A chain of 10⁵ nested nodes through both renderers (this aborted with a stack overflow before).
    let mut c = Case::new("cli-chain");
    let mut nodes: Vec<Value> = (0..100_000).map(|i| json!({ "children": [i + 1] })).collect();
    nodes.push(json!({ "mesh": 0 }));
    c.doc["nodes"] = Value::Array(nodes);
    c.doc["scenes"][0]["nodes"] = json!([0]);
    let p = c.write();
    for cmd in ["render", "reference"] {
        let r = sunshade(&[cmd, p.to_str().unwrap(), "-o", o, "--width", "32", "--height", "32"]);
        assert!(r.status.success(), "{cmd}: {}", String::from_utf8_lossy(&r.stderr));
        std::fs::remove_file(&out).unwrap();
    }
    // An unsupported required extension is a bad file: exit 1, naming the file.
    let mut c = Case::new("cli-ext");
    c.doc["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
    let p = c.write();
    let r = sunshade(&["render", p.to_str().unwrap(), "-o", o]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("case.gltf") && err.contains("EXT_meshopt_compression"), "{err}");
    // A scene whose vertices are all far outside the view: rendered, with a warning that nothing is covered.
    let mut c = Case::new("cli-empty");
    c.doc["cameras"] = json!([{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1 } }]);
    c.doc["nodes"].as_array_mut().unwrap().push(json!({ "camera": 0, "translation": [0, 0, -5] }));
    c.doc["scenes"][0]["nodes"] = json!([0, 1, 2]);
    let p = c.write();
    for cmd in ["render", "reference"] {
        let r = sunshade(&[cmd, p.to_str().unwrap(), "-o", o]);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(r.status.success(), "{err}");
        assert!(err.contains("no pixel is covered") && err.contains("case.gltf"), "{cmd}: {err}");
        std::fs::remove_file(&out).unwrap();
    }
}

/// CRC-32 (ISO-HDLC, PNG's) of `bytes`.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xedb8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

#[test]
fn images_stay_inside_the_folder_and_within_the_texel_budget() {
    let material_with_texture = |image_uri: &str| {
        let uri = image_uri.to_string();
        move |d: &mut Value| {
            d["images"] = json!([{ "uri": uri }]);
            d["textures"] = json!([{ "source": 0 }]);
            d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": 0 });
        }
    };
    let small = sunshade::authoring::png_rgba8(2, 2, &[[9, 9, 9, 255]; 4]);
    // An image outside the folder is refused like a buffer; inside, it is read.
    let mut c = Case::new("image-outside");
    std::fs::write(c.dir.path("outside.png"), &small).unwrap();
    material_with_texture("../outside.png")(&mut c.doc);
    c.refused(&["../outside.png", "outside the asset folder", "image 0"]);
    std::fs::write(c.scene_dir().join("inside.png"), &small).unwrap();
    material_with_texture("inside.png")(&mut c.doc);
    assert_eq!(c.loads().textures.len(), 1);
    // A decompression bomb: a PNG header claiming 16384 × 16384 texels (the pixel data is not even there) is
    // refused from its header, before anything is allocated for it.
    let mut bomb = small.clone();
    // The IHDR chunk's data starts at byte 16: width, height (big-endian), then its CRC over type + data.
    bomb[16..20].copy_from_slice(&16384u32.to_be_bytes());
    bomb[20..24].copy_from_slice(&16384u32.to_be_bytes());
    let crc = crc32(&bomb[12..29]);
    bomb[29..33].copy_from_slice(&crc.to_be_bytes());
    std::fs::write(c.scene_dir().join("bomb.png"), &bomb).unwrap();
    material_with_texture("bomb.png")(&mut c.doc);
    let t = std::time::Instant::now();
    c.refused(&["16384x16384", "budget", "image 0"]);
    assert!(t.elapsed().as_secs_f64() < 2.0, "the budget must be checked before decoding");
    // A data URI image and a truncated PNG.
    use base64::Engine;
    let b64 = base64::engine::general_purpose::STANDARD.encode(&small);
    material_with_texture(&format!("data:image/png;base64,{b64}"))(&mut c.doc);
    assert_eq!(c.loads().textures.len(), 1);
    std::fs::write(c.scene_dir().join("cut.png"), &small[..small.len() - 12]).unwrap();
    material_with_texture("cut.png")(&mut c.doc);
    c.refused(&["image 0"]);
}

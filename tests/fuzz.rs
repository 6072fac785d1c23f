//! Bounded fuzzing on stable Rust: seeded mutations of every model in `models/` through the loader and both
//! renderers at a small size. Asserted for every case: no panic; a refused file gives one line that starts with
//! its path; a loaded one renders on the CPU reference, and every [`GPU_EVERY`]-th loaded one on the GPU with
//! validation on and no validation message.
//!
//! `SUNSHADE_FUZZ_CASES` sets the number of cases per model (default 500: 4000 executions, about 5 s on 2 cores);
//! `SUNSHADE_FUZZ_SEED` the first seed. A failing case prints its model and seed, so it can be replayed alone with
//! `SUNSHADE_FUZZ_SEED=S SUNSHADE_FUZZ_CASES=1`. Long runs: `SUNSHADE_FUZZ_CASES=200000 cargo test --release
//! --test fuzz -- --nocapture` (the count of executions is printed).

mod common;

use std::path::{Path, PathBuf};

use common::{CheckedRenderer, TempDir};
use serde_json::{json, Value};
use sunshade::scene::Scene;
use sunshade::settings::{self, CameraOptions, SunOptions};

const GPU_EVERY: usize = 25;

/// splitmix64: small, seedable, good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
}

/// Values that break parsers: boundaries of every integer width, extremes of floats, wrong types, deep nesting.
fn interesting(rng: &mut Rng) -> Value {
    let deep = || {
        let mut v = json!(0);
        for _ in 0..200 {
            v = json!([v]);
        }
        v
    };
    match rng.below(22) {
        0 => json!(-1),
        1 => json!(0),
        2 => json!(1),
        3 => json!(2),
        4 => json!(255),
        5 => json!(65536),
        6 => json!(2147483648u64),
        7 => json!(4294967295u64),
        8 => json!(u64::MAX),
        9 => json!(9007199254740993u64),
        10 => json!(1e308),
        11 => json!(-1e308),
        12 => json!(3.4e38),
        13 => json!(1e-45),
        14 => json!(0.5),
        15 => json!("x"),
        16 => json!(""),
        17 => json!([]),
        18 => json!({}),
        19 => json!(null),
        20 => json!([0, 0, 0, 0]),
        _ => deep(),
    }
}

/// Every value's JSON pointer.
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    out.push(at.clone());
    match v {
        Value::Array(a) => a.iter().enumerate().for_each(|(i, x)| pointers(x, format!("{at}/{i}"), out)),
        Value::Object(o) => o.iter().for_each(|(k, x)| pointers(x, format!("{at}/{k}"), out)),
        _ => {}
    }
}

const KEYS: &[&str] = &[
    "scene",
    "scenes",
    "nodes",
    "children",
    "mesh",
    "camera",
    "matrix",
    "rotation",
    "scale",
    "translation",
    "accessors",
    "bufferView",
    "byteOffset",
    "byteLength",
    "byteStride",
    "count",
    "componentType",
    "type",
    "normalized",
    "sparse",
    "indices",
    "material",
    "mode",
    "POSITION",
    "NORMAL",
    "TANGENT",
    "TEXCOORD_0",
    "uri",
    "extensionsRequired",
    "extensions",
    "extras",
    "yfov",
    "znear",
    "zfar",
    "ymag",
];

/// One to four structural edits of the glTF JSON: replace a value, delete a key, add a key.
fn mutate_json(doc: &mut Value, rng: &mut Rng) {
    for _ in 0..1 + rng.below(4) {
        let mut all = Vec::new();
        pointers(doc, String::new(), &mut all);
        let target = all[rng.below(all.len())].clone();
        match rng.below(4) {
            0 | 1 => {
                let value = if rng.below(8) == 0 {
                    // A copy of another part of the document: plausible structure in the wrong place.
                    let other = all[rng.below(all.len())].clone();
                    doc.pointer(&other).cloned().unwrap_or(Value::Null)
                } else {
                    interesting(rng)
                };
                if let Some(v) = doc.pointer_mut(&target) {
                    *v = value;
                    if target.is_empty() {
                        return;
                    }
                }
            }
            2 => {
                if let Some((parent, key)) = target.rsplit_once('/') {
                    match doc.pointer_mut(parent) {
                        Some(Value::Object(o)) => {
                            o.remove(key);
                        }
                        Some(Value::Array(a)) => {
                            if let Ok(i) = key.parse::<usize>() {
                                if i < a.len() {
                                    a.remove(i);
                                }
                            }
                        }
                        _ => {}
                    }
                }
            }
            _ => {
                let value = interesting(rng);
                if let Some(Value::Object(o)) = doc.pointer_mut(&target) {
                    o.insert(KEYS[rng.below(KEYS.len())].to_string(), value);
                }
            }
        }
    }
}

/// Byte-level edits: bit flips, interesting bytes and u32s, truncation, a duplicated range.
fn mutate_bytes(bytes: &mut Vec<u8>, rng: &mut Rng) {
    for _ in 0..1 + rng.below(6) {
        if bytes.is_empty() {
            return;
        }
        let at = rng.below(bytes.len());
        match rng.below(5) {
            0 => bytes[at] ^= 1 << rng.below(8),
            1 => bytes[at] = [0u8, 0xFF, 0x7F, 0x80][rng.below(4)],
            2 => {
                let v = [0u32, 1, 0x7FFF_FFFF, 0x8000_0000, 0xFFFF_FFFF, 0x7F80_0000, 0x7FC0_0000][rng.below(7)];
                let at = at & !3;
                if at + 4 <= bytes.len() {
                    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
                }
            }
            3 => bytes.truncate(at),
            _ => {
                let end = (at + 1 + rng.below(64)).min(bytes.len());
                let copy = bytes[at..end].to_vec();
                let to = rng.below(bytes.len());
                bytes.splice(to..to, copy);
            }
        }
    }
}

fn glb_parts(bytes: &[u8]) -> Option<(Value, Vec<u8>)> {
    let len = u32::from_le_bytes(bytes.get(12..16)?.try_into().ok()?) as usize;
    let json = serde_json::from_slice(bytes.get(20..20 + len)?).ok()?;
    let bin = bytes.get(20 + len + 8..).unwrap_or(&[]).to_vec();
    Some((json, bin))
}

fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = json.to_string().into_bytes();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + j.len() + 8 + b.len()) as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&j);
    out.extend((b.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(&b);
    out
}

/// Writes one mutated case of `model` into `dir` and returns the scene path.
fn write_case(model: &Path, dir: &Path, rng: &mut Rng) -> PathBuf {
    let name = model.file_name().unwrap().to_str().unwrap();
    let bytes = std::fs::read(model).unwrap();
    let out = dir.join(name);
    if name.ends_with(".glb") {
        let mutated = match (rng.below(2), glb_parts(&bytes)) {
            (0, Some((mut json, mut bin))) => {
                mutate_json(&mut json, rng);
                if rng.below(3) == 0 {
                    mutate_bytes(&mut bin, rng);
                }
                glb(&json, &bin)
            }
            _ => {
                let mut b = bytes;
                mutate_bytes(&mut b, rng);
                b
            }
        };
        std::fs::write(&out, mutated).unwrap();
    } else {
        let mut doc: Value = serde_json::from_slice(&bytes).unwrap();
        // Its .bin files, mutated now and then.
        for b in doc["buffers"].as_array().cloned().unwrap_or_default() {
            if let Some(uri) = b["uri"].as_str().filter(|u| !u.starts_with("data:")) {
                let mut data = std::fs::read(model.with_file_name(uri)).unwrap();
                if rng.below(3) == 0 {
                    mutate_bytes(&mut data, rng);
                }
                std::fs::write(dir.join(uri), data).unwrap();
            }
        }
        if rng.below(6) == 0 {
            let mut text = doc.to_string().into_bytes();
            mutate_bytes(&mut text, rng);
            std::fs::write(&out, text).unwrap();
        } else {
            mutate_json(&mut doc, rng);
            std::fs::write(&out, doc.to_string()).unwrap();
        }
    }
    out
}

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn render_settings(scene: &Scene) -> Option<settings::RenderSettings> {
    // Settings the scene cannot take (a camera with no view direction after edits) are usage errors, not panics.
    settings::resolve(scene, 8, 6, &CameraOptions::default(), &SunOptions::default()).ok()
}

#[test]
fn mutated_models_never_panic() {
    let models_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut models: Vec<PathBuf> = std::fs::read_dir(&models_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "glb" || e == "gltf"))
        .collect();
    models.sort();
    assert!(models.len() >= 8, "models/ has {} scenes", models.len());
    // Textured and vertex-coloured samples (one file each): images, samplers, texture infos.
    for sample in ["BoxTextured/BoxTextured.glb", "VertexColorTest/VertexColorTest.glb"] {
        models.push(models_dir.join("gltf-samples").join(sample));
    }
    let cases = env_u64("SUNSHADE_FUZZ_CASES", 500);
    let first_seed = env_u64("SUNSHADE_FUZZ_SEED", 1);
    let mut gpu = CheckedRenderer::new();
    let (mut executions, mut loaded, mut refused, mut on_gpu) = (0u64, 0u64, 0u64, 0u64);
    let started = std::time::Instant::now();
    for (m, model) in models.iter().enumerate() {
        for k in 0..cases {
            let seed = first_seed + k + (m as u64) * 1_000_000_007;
            let dir = TempDir::new("fuzz");
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let path = write_case(model, &dir.0, &mut Rng(seed));
                match sunshade::scene::load(&path) {
                    Err(e) => {
                        let e = e.to_string();
                        assert!(e.starts_with(&path.display().to_string()), "error does not name the file: {e}");
                        assert_eq!(e.lines().count(), 1, "not one line: {e}");
                        None
                    }
                    Ok(scene) => {
                        let s = render_settings(&scene);
                        if let Some(s) = &s {
                            sunshade::cpu::render(&scene, s, &Default::default());
                        }
                        Some((scene, s))
                    }
                }
            }));
            executions += 1;
            match result {
                Err(panic) => {
                    eprintln!(
                        "fuzz: {} seed {seed} panicked (replay: SUNSHADE_FUZZ_SEED={} SUNSHADE_FUZZ_CASES=1)",
                        model.display(),
                        seed - (m as u64) * 1_000_000_007
                    );
                    std::panic::resume_unwind(panic);
                }
                Ok(None) => refused += 1,
                Ok(Some((scene, s))) => {
                    loaded += 1;
                    if let Some(s) = s.filter(|_| loaded % GPU_EVERY as u64 == 0) {
                        gpu.render(&scene, &s);
                        on_gpu += 1;
                    }
                }
            }
        }
    }
    println!(
        "fuzz: {executions} executions ({loaded} loaded, {refused} refused, {on_gpu} also on the GPU), 0 panics, {:.1} s",
        started.elapsed().as_secs_f64()
    );
    assert!(loaded > 0 && refused > 0, "the mutations no longer reach both outcomes");
}

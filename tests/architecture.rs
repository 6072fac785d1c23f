//! The data flow is one-way and visible in the folders: no module knows both Vulkan and glTF, the CPU reference
//! never calls into the GPU path, and every shading function in the GLSL has a Rust twin of the same name.

use std::path::Path;

fn sources(dir: &str) -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut out = Vec::new();
    if root.is_file() {
        return vec![(root.display().to_string(), std::fs::read_to_string(&root).unwrap())];
    }
    let mut stack = vec![root];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((p.display().to_string(), std::fs::read_to_string(&p).unwrap()));
            }
        }
    }
    assert!(!out.is_empty(), "no files under {dir}");
    out
}

fn assert_free_of(dir: &str, forbidden: &[&str]) {
    for (path, text) in sources(dir) {
        for f in forbidden {
            assert!(!text.contains(f), "{path} mentions `{f}`");
        }
    }
}

#[test]
fn modules_depend_one_way() {
    assert_free_of("src/scene", &["ash::", "crate::gpu", "crate::cpu", "crate::compare", "crate::cli"]);
    assert_free_of("src/shading", &["ash::", "gltf::", "crate::gpu", "crate::cpu", "crate::compare", "crate::cli"]);
    assert_free_of("src/gpu", &["gltf::", "crate::cpu", "crate::compare", "crate::cli"]);
    assert_free_of("src/cpu", &["ash::", "gltf::", "crate::gpu", "crate::compare", "crate::cli"]);
    assert_free_of("src/compare", &["ash::", "gltf::", "crate::gpu", "crate::cpu", "crate::scene", "crate::cli"]);
    assert_free_of("src/film", &["ash::", "gltf::", "crate::gpu", "crate::cpu", "crate::scene"]);
    assert_free_of("src/visibility", &["ash::", "gltf::", "crate::gpu", "crate::cpu", "crate::compare", "crate::cli"]);
    // Speed against error knows the reference and the comparison; GPU timings come from the command line.
    assert_free_of("src/accuracy", &["ash::", "gltf::", "crate::gpu", "crate::cli"]);
    assert_free_of("src/plot", &["ash::", "gltf::", "crate::gpu", "crate::cpu", "crate::scene", "crate::cli"]);
    // Daylight is astronomy and a clear-sky model: numbers that the settings turn into lights.
    let renderers = ["crate::gpu", "crate::cpu", "crate::shading", "crate::compare", "crate::cli"];
    assert_free_of("src/daylight", &[&["ash::", "gltf::", "crate::scene"][..], &renderers[..]].concat());
    // One render, whoever asks: the command line, batch, test suites and the testing API call the render layer,
    // which knows no command line; neither does the testing API (the same flags, the same image).
    assert_free_of("src/render", &["ash::", "gltf::", "crate::cli", "super::cli"]);
    assert_free_of("src/testing.rs", &["crate::cli", "super::cli"]);
}

/// Names of the functions defined in a GLSL file (a return type, a name, an opening parenthesis at line start).
fn glsl_functions(text: &str) -> Vec<String> {
    const TYPES: [&str; 18] = [
        "float",
        "vec2",
        "vec3",
        "vec4",
        "bool",
        "double",
        "dvec3",
        "uint",
        "int",
        "mat3",
        "REAL",
        "REAL2",
        "REAL3",
        "MaterialGpu",
        "LevelChoice",
        "SurfaceSample",
        "uvec4",
        "SegmentSums",
    ];
    text.lines()
        .filter_map(|line| {
            let mut words = line.split_whitespace();
            let ty = words.next()?;
            let rest = words.next()?;
            (TYPES.contains(&ty) && rest.contains('(')).then(|| rest.split('(').next().unwrap().to_string())
        })
        .collect()
}

/// Whether the Rust sources define a function of this name (generic or not).
fn has_twin(rust: &str, name: &str) -> bool {
    rust.contains(&format!("fn {name}(")) || rust.contains(&format!("fn {name}<"))
}

#[test]
fn every_glsl_shading_function_has_a_rust_twin() {
    let rust: String = sources("src/shading").into_iter().map(|(_, t)| t).collect();
    let mut checked = 0;
    for file in [
        "radiometry.glsl",
        "brdf.glsl",
        "shade.glsl",
        "visibility.glsl",
        "surface.glsl",
        "texture_filter.glsl",
        "measured.glsl",
    ] {
        let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders").join(file)).unwrap();
        for name in glsl_functions(&text) {
            assert!(has_twin(&rust, &name), "shaders/{file}: `{name}` has no Rust function in src/shading");
            checked += 1;
        }
    }
    assert!(checked >= 4, "only {checked} GLSL functions found");
}

/// The shaders do not call the built-ins that lose digits on lavapipe (docs/platform.md): `acos`, `asin` (4e-4),
/// `atan` (2.5e-6), `pow` (`exp2(y log2 x)`: 6e-4 at `pow(0.999, 1e4)`) and `log` (2e-3 near 1). Their accurate
/// replacements live in shaders/math.glsl; only the diagnostic `SUNSHADE_NAIVE_MATH` branches may use them.
#[test]
fn shaders_avoid_inaccurate_builtins() {
    let mut checked = 0;
    for (path, text) in sources("shaders") {
        // Drop comments and the diagnostic branches (from `#ifdef SUNSHADE_NAIVE_MATH` to its own `#else`/`#endif`,
        // nested conditionals counted).
        let mut code = String::new();
        let mut conditionals: Vec<bool> = Vec::new(); // per open `#if`: is this the naive branch?
        for line in text.lines() {
            let line = line.split("//").next().unwrap();
            let directive = line.trim();
            if directive.starts_with("#if") {
                conditionals.push(directive == "#ifdef SUNSHADE_NAIVE_MATH");
            } else if directive.starts_with("#else") || directive.starts_with("#elif") {
                if let Some(naive) = conditionals.last_mut() {
                    *naive = false;
                }
            } else if directive.starts_with("#endif") {
                conditionals.pop();
            } else if !conditionals.iter().any(|&naive| naive) {
                code.push_str(line);
                code.push('\n');
            }
        }
        for builtin in ["acos", "asin", "atan", "pow", "log", "log2"] {
            let pattern = format!("{builtin}(");
            for (i, _) in code.match_indices(&pattern) {
                let before = code[..i].chars().next_back().unwrap_or(' ');
                assert!(
                    before.is_alphanumeric() || before == '_',
                    "{path}: calls `{builtin}`, which loses digits on lavapipe (use shaders/math.glsl)"
                );
            }
        }
        checked += 1;
    }
    assert!(checked >= 6, "only {checked} shader files");
}

/// Every shader file is mirrored by Rust (its functions have twins of the same name, checked here) or declared
/// GPU-only with the reason, so that a new file cannot slip past the mirror.
#[test]
fn every_shader_file_is_mirrored_or_declared_gpu_only() {
    let mirrored: &[(&str, &[&str])] = &[
        ("radiometry.glsl", &["src/shading"]),
        ("brdf.glsl", &["src/shading"]),
        ("shade.glsl", &["src/shading"]),
        ("visibility.glsl", &["src/shading"]),
        ("surface.glsl", &["src/shading"]),
        ("texture_filter.glsl", &["src/shading"]),
        ("measured.glsl", &["src/shading"]),
        ("transform.glsl", &["src/cpu"]),
        // The occluders: the BVH walk and the watertight test (src/visibility), and which hits block a ray
        // (src/cpu/occluders.rs, the reference's occluders).
        ("occluders.glsl", &["src/visibility", "src/cpu"]),
        // The sun's and disk lights' slices: the rule (src/shading) and the walk's reach (src/visibility/bvh.rs).
        ("slices.glsl", &["src/shading", "src/visibility"]),
        // The sun's cells: their layout and classification (src/visibility/sun_cells.rs).
        ("sun_cells.glsl", &["src/visibility"]),
    ];
    // GPU-only: the byte layout (mirrored by src/gpu/layout.rs, checked by its glsl_constants_match test); f32
    // replacements for lavapipe's inaccurate built-ins (Rust uses f64's); the shadow map (the reference casts rays,
    // docs/accuracy.md measures the map against them); the entry points.
    // fragment.glsl: the entry points' vertex fetches and surface inputs (its surface_sample mirrors
    // src/cpu/fragment.rs's); shadow_mask.frag: the alpha test of masked draws in the shadow-map pass.
    let gpu_only = [
        "bindings.glsl",
        "math.glsl",
        "shadow_map.glsl",
        "scene.vert",
        "scene.frag",
        "fragment.glsl",
        "shadow_mask.frag",
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if gpu_only.contains(&name.as_str()) {
            continue;
        }
        let (_, rust_dirs) = mirrored
            .iter()
            .find(|(f, _)| *f == name)
            .unwrap_or_else(|| panic!("shaders/{name} is neither mirrored nor declared GPU-only"));
        let rust: String = rust_dirs.iter().flat_map(|d| sources(d)).map(|(_, t)| t).collect();
        let text = std::fs::read_to_string(dir.join(&name)).unwrap();
        for f in glsl_functions(&text) {
            assert!(has_twin(&rust, &f), "shaders/{name}: `{f}` has no Rust function in {rust_dirs:?}");
        }
    }
}

/// The reference carries every vertex attribute the GPU's vertex layout holds, in the same order.
#[test]
fn vertex_layout_matches_the_references_attributes() {
    use sunshade::gpu::layout::{SurfaceVertex, Vertex};
    assert_eq!(
        sunshade::cpu::clip::ATTRIBUTES * 4,
        std::mem::size_of::<Vertex>() + std::mem::size_of::<SurfaceVertex>()
    );
}

//! The data flow is one-way and visible in the folders: no module knows both Vulkan and glTF, the CPU reference
//! never calls into the GPU path, and every shading function in the GLSL has a Rust twin of the same name.

use std::path::Path;

fn sources(dir: &str) -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut out = Vec::new();
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
}

/// Names of the functions defined in a GLSL file (a return type, a name, an opening parenthesis at line start).
fn glsl_functions(text: &str) -> Vec<String> {
    const TYPES: [&str; 10] = ["float", "vec2", "vec3", "vec4", "bool", "double", "dvec3", "uint", "int", "mat3"];
    text.lines()
        .filter_map(|line| {
            let mut words = line.split_whitespace();
            let ty = words.next()?;
            let rest = words.next()?;
            (TYPES.contains(&ty) && rest.contains('(')).then(|| rest.split('(').next().unwrap().to_string())
        })
        .collect()
}

#[test]
fn every_glsl_shading_function_has_a_rust_twin() {
    let rust: String = sources("src/shading").into_iter().map(|(_, t)| t).collect();
    let mut checked = 0;
    for file in ["radiometry.glsl", "brdf.glsl", "shade.glsl"] {
        let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders").join(file)).unwrap();
        for name in glsl_functions(&text) {
            assert!(
                rust.contains(&format!("fn {name}(")),
                "shaders/{file}: `{name}` has no Rust function in src/shading"
            );
            checked += 1;
        }
    }
    assert!(checked >= 4, "only {checked} GLSL functions found");
}

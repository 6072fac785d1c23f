//! The data flow is one-way and visible in the folders: no module knows both Vulkan and glTF, the CPU reference
//! never calls into the GPU path, and every shader file has its Rust twin at the same relative path, every GLSL
//! function a Rust function of the same name.

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
    // The scene holds material parameters and their mapping onto a model; shading evaluates them.
    assert_free_of(
        "src/scene",
        &["ash::", "crate::gpu", "crate::cpu", "crate::compare", "crate::cli", "crate::shading"],
    );
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

/// The files of `dir` (a module folder of src/) as modules (`lights::sun`), each with the sibling modules its code
/// (not its comments, not its tests) names through `crate::MODULE::` or `super::`.
fn import_graph(dir: &str) -> std::collections::BTreeMap<String, std::collections::BTreeSet<String>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let prefix = format!("crate::{}::", dir.trim_start_matches("src/"));
    let files: Vec<(String, String)> = sources(dir)
        .into_iter()
        .map(|(path, text)| {
            let rel = Path::new(&path).strip_prefix(&root).unwrap().with_extension("");
            let module = rel.to_string_lossy().replace('\\', "/").trim_end_matches("/mod").replace('/', "::");
            let code = text.split("#[cfg(test)]").next().unwrap_or("");
            let code: String =
                code.lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n");
            (module, code)
        })
        .collect();
    let modules: std::collections::BTreeSet<String> = files.iter().map(|(m, _)| m.clone()).collect();
    let mut graph = std::collections::BTreeMap::new();
    for (module, code) in &files {
        let parent = module.rsplit_once("::").map_or("", |(p, _)| p);
        let mut deps = std::collections::BTreeSet::new();
        for (pattern, base) in [(prefix.as_str(), ""), ("super::", parent)] {
            for (i, _) in code.match_indices(pattern) {
                let path: String = code[i + pattern.len()..]
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == ':')
                    .collect();
                let parts: Vec<&str> = path.split("::").filter(|p| !p.is_empty()).collect();
                // The longest prefix of the path that names a module of the folder.
                for n in (1..=parts.len()).rev() {
                    let name = parts[..n].join("::");
                    let full = if base.is_empty() { name } else { format!("{base}::{name}") };
                    if modules.contains(&full) {
                        if &full != module {
                            deps.insert(full);
                        }
                        break;
                    }
                }
            }
        }
        graph.insert(module.clone(), deps);
    }
    graph
}

/// The import circles of a graph: its strongly connected components of more than one module (Tarjan).
fn import_circles(graph: &std::collections::BTreeMap<String, std::collections::BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
        index: std::collections::HashMap<&'a str, usize>,
        low: std::collections::HashMap<&'a str, usize>,
        stack: Vec<&'a str>,
        circles: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        for w in &s.graph[v] {
            if !s.index.contains_key(w.as_str()) {
                visit(s, w);
                let l = s.low[w.as_str()].min(s.low[v]);
                s.low.insert(v, l);
            } else if s.stack.contains(&w.as_str()) {
                let l = s.index[w.as_str()].min(s.low[v]);
                s.low.insert(v, l);
            }
        }
        if s.low[v] == s.index[v] {
            let mut circle = Vec::new();
            while let Some(w) = s.stack.pop() {
                circle.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if circle.len() > 1 {
                circle.sort();
                s.circles.push(circle);
            }
        }
    }
    let mut s =
        State { graph, index: Default::default(), low: Default::default(), stack: Vec::new(), circles: Vec::new() };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.circles
}

/// No import circles between the files of a module folder, so that each file can be read after the ones it uses.
/// One remains, named with why: a type whose methods are split over two files.
#[test]
fn module_folders_have_no_import_circles() {
    let known: &[(&str, &[&str], &str)] =
        &[("src/scene", &["load", "load_mesh"], "the loader's methods are split over the two files")];
    for dir in
        ["src/shading", "src/cli", "src/render", "src/gpu", "src/cpu", "src/visibility", "src/scene", "src/accuracy"]
    {
        let graph = import_graph(dir);
        assert!(graph.len() > 3, "{dir}: only {} files seen", graph.len());
        for circle in import_circles(&graph) {
            let allowed = known.iter().any(|(d, c, _)| *d == dir && circle == *c);
            assert!(allowed, "{dir}: an import circle between {circle:?}");
        }
    }
    // The test sees a circle where there is one.
    let mut g = std::collections::BTreeMap::new();
    g.insert("a".to_string(), ["b".to_string()].into());
    g.insert("b".to_string(), ["c".to_string()].into());
    g.insert("c".to_string(), ["a".to_string()].into());
    g.insert("d".to_string(), ["a".to_string()].into());
    assert_eq!(import_circles(&g), vec![vec!["a".to_string(), "b".to_string(), "c".to_string()]]);
}

/// Names of the functions a GLSL file defines: a line at column 0 of a return type (any: a built-in, a struct,
/// `void`), a name and an opening parenthesis, not ending a prototype (`;`). Bodies are indented, so no statement
/// matches; `#define`s start with `#`.
fn glsl_functions(text: &str) -> Vec<String> {
    text.lines()
        .filter(|line| !line.trim_end().ends_with(';'))
        .filter_map(|line| {
            let mut words = line.splitn(2, char::is_whitespace);
            let ty = words.next()?;
            let rest = words.next()?.trim_start();
            let is_ident = |w: &str| {
                w.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                    && w.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            };
            let name = rest.split('(').next()?.trim_end();
            (is_ident(ty) && is_ident(name) && rest.contains('(') && !["return", "else"].contains(&ty))
                .then(|| name.to_string())
        })
        .collect()
}

/// Whether the Rust source defines a function of this name (generic or not).
fn has_twin(rust: &str, name: &str) -> bool {
    rust.contains(&format!("fn {name}(")) || rust.contains(&format!("fn {name}<"))
}

#[test]
fn the_glsl_parser_sees_every_definition() {
    let text = "vec3 a(vec3 x) {\nvoid b_2(inout float y,\n       float z) {\nWatertightRay c(vec3 o);\n\
                MaterialGpu d(MaterialGpu m) {\n    float e(1.0);\n#define F(x) x\nconst float G = 1.0;\n";
    assert_eq!(glsl_functions(text), ["a", "b_2", "d"]);
}

/// Each shader file that mirrors Rust, with the Rust files that hold its functions' twins: the file at the same
/// relative path (the same name) first, where the pairing is one to one; else the reason the GPU's file gathers
/// several.
const MIRRORED: &[(&str, &[&str], &str)] = &[
    ("lights/sun.glsl", &["src/shading/lights/sun.rs"], ""),
    ("lights/disk.glsl", &["src/shading/lights/disk.rs"], ""),
    ("lights/sky.glsl", &["src/shading/lights/sky.rs"], ""),
    ("brdf.glsl", &["src/shading/brdf.rs"], ""),
    ("brdf/phong.glsl", &["src/shading/brdf/phong.rs"], ""),
    ("brdf/blinn_phong.glsl", &["src/shading/brdf/blinn_phong.rs"], ""),
    ("brdf/ward.glsl", &["src/shading/brdf/ward.rs"], ""),
    ("brdf/metallic_roughness.glsl", &["src/shading/brdf/metallic_roughness.rs"], ""),
    ("shade.glsl", &["src/shading/shade.rs"], ""),
    ("lobe.glsl", &["src/shading/lobe.rs"], ""),
    ("sky_lune.glsl", &["src/shading/sky_lune.rs"], ""),
    ("visibility.glsl", &["src/shading/visibility.rs"], ""),
    (
        "surface.glsl",
        &["src/shading/surface.rs", "src/scene/material.rs"],
        "the metallic-roughness mapping is a material's (scene/material.rs), which the surface applies per pixel",
    ),
    (
        "texture_filter.glsl",
        &["src/shading/texture_filter.rs", "src/scene/texture.rs"],
        "an 8-bit texel's linear value (code_value) belongs to how a texture stores its texels",
    ),
    ("measured.glsl", &["src/shading/measured.rs"], ""),
    ("transform.glsl", &["src/cpu/transform.rs"], ""),
    ("barycentric.glsl", &["src/cpu/barycentric.rs"], ""),
    ("occluders.glsl", &["src/cpu/occluders.rs"], ""),
    ("ray_triangle.glsl", &["src/visibility/ray_triangle.rs"], ""),
    ("bvh.glsl", &["src/visibility/bvh.rs"], ""),
    ("sun_cells.glsl", &["src/visibility/sun_cells.rs"], ""),
    ("disk_cone.glsl", &["src/visibility/disk_cone.rs"], ""),
    (
        "slices.glsl",
        &[
            "src/shading/sun_slices.rs",
            "src/shading/disk_slices.rs",
            "src/shading/sky_slices.rs",
            "src/shading/slices_about_centre.rs",
            "src/shading/slice_buckets.rs",
            "src/visibility/bvh.rs",
        ],
        "the GPU compiles every light's slices as one module behind SUNSHADE_SLICES (build.rs), their helpers \
         shared in one order; the Rust keeps a file per light, and the walk's reach with the BVH",
    ),
];

/// Functions a mirrored shader file defines with no Rust function of the name, and why.
const GPU_ONLY_FUNCTIONS: &[(&str, &str, &str)] = &[
    (
        "sun_cells.glsl",
        "sun_cone_list",
        "a penumbra's rays test only the triangles its cone can meet (the classification's own test): the same \
         answers as the cell's whole range, which the Rust's sun_cells_occluded takes",
    ),
    (
        "sun_cells.glsl",
        "sun_list_bins",
        "a penumbra's listed triangles binned over its cone's directions, so that each ray tests its bin's alone: \
         the same answers as the whole list, which the Rust's sun_cells_occluded takes",
    ),
    ("sun_cells.glsl", "sun_bin_of", "a ray's bin among sun_list_bins' (GPU-only with it)"),
    (
        "sun_cells.glsl",
        "sun_cells_classify",
        "the bound sun_cone_class tests inline (its MAX_SUN_CELL_CLASSIFIED), for the list past the rays' bound",
    ),
    ("ray_triangle.glsl", "watertight_ray", "the Rust's `WatertightRay::new`: GLSL has no methods"),
    (
        "lights/sun.glsl",
        "sun_disk_factor",
        "sun_irradiance_disk over E⊥, found once a pixel and reused by the specular term's projected solid angle, as \
         the driver inlines each call; the Rust calls sun_irradiance_disk for both",
    ),
    (
        "lights/sun.glsl",
        "sun_term",
        "sun_irradiance_visible up to its grid, which irradiance_visible casts for every light by one call (the \
         driver inlines each call); the Rust's returns the irradiance",
    ),
    (
        "lights/disk.glsl",
        "disk_term",
        "disk_irradiance_visible up to its grid, as sun_term's; the Rust's returns the irradiance",
    ),
    (
        "lights/sky.glsl",
        "sky_term",
        "sky_irradiance_visible up to its grid, as sun_term's; the Rust's returns the irradiance",
    ),
    (
        "lights/sun.glsl",
        "sun_specular_segment",
        "the arguments of sun_specular_visible's lobe integral, which radiance_out takes for every light by one \
         call (the driver inlines each call); the Rust integrates in sun_lobe_integral",
    ),
    (
        "lights/disk.glsl",
        "disk_specular_segment",
        "the arguments of disk_specular_visible's lobe integral, as sun_specular_segment's; the Rust integrates in \
         disk_lobe_integral",
    ),
    (
        "sun_cells.glsl",
        "sun_cells_at",
        "the shaded point's sun_cell_range, found once a pixel for every function that reads it, as the driver \
         inlines each call; the Rust calls sun_cell_range where it is used",
    ),
    (
        "surface.glsl",
        "surface_texels",
        "a draw's textures looked up by one call in a loop, as the driver inlines each call; the Rust looks each up \
         where it is used (material_texture)",
    ),
    (
        "lights/disk.glsl",
        "disk_rays_gather",
        "the GPU's shortcut before the grid (src/visibility/disk_cone.rs's walk); the reference casts its rays",
    ),
];

/// Shader files with no Rust twin, and why.
const GPU_ONLY_FILES: &[(&str, &str)] = &[
    ("bindings.glsl", "the byte layout: mirrored by src/gpu/layout.rs, checked by its glsl_constants_match test"),
    ("math.glsl", "f32 replacements for lavapipe's inaccurate built-ins; the Rust computes in f64"),
    ("shadow_map.glsl", "the shadow maps: the reference casts rays (docs/accuracy.md measures the map against them)"),
    (
        "fragment.glsl",
        "the entry points' vertex fetches and surface inputs (surface_sample mirrors src/cpu/fragment.rs)",
    ),
    ("scene.vert", "an entry point"),
    ("scene.frag", "an entry point"),
    ("shadow_mask.frag", "the alpha test of masked draws in the shadow-map pass"),
    ("fullscreen.vert", "one triangle over the target, for the mark between two draws (src/gpu/second_draw.rs)"),
    ("second_draw.frag", "the mark between two draws: a stencil, nothing the reference computes"),
];

/// Every shader file is paired with its Rust twin by path, each of its functions with a Rust function of the same
/// name in the paired files (or declared GPU-only with the reason), or the whole file declared GPU-only: a new file
/// or function cannot slip past the mirror.
#[test]
fn every_shader_file_has_its_rust_twin_by_path() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut functions = 0;
    let shaders = root.join("shaders");
    let mut names: Vec<String> = sources("shaders")
        .into_iter()
        .map(|(path, _)| Path::new(&path).strip_prefix(&shaders).unwrap().to_string_lossy().replace('\\', "/"))
        .collect();
    names.sort();
    for name in names {
        if GPU_ONLY_FILES.iter().any(|(f, _)| *f == name) {
            continue;
        }
        let (_, rust_files, why_several) = MIRRORED
            .iter()
            .find(|(f, _, _)| *f == name)
            .unwrap_or_else(|| panic!("shaders/{name} is neither paired with its Rust twin nor declared GPU-only"));
        // The twin at the same relative path: shaders/lights/sun.glsl ↔ src/shading/lights/sun.rs.
        let stem = name.trim_end_matches(".glsl");
        assert!(
            rust_files[0].ends_with(&format!("/{stem}.rs")) || !why_several.is_empty(),
            "shaders/{name}: its twin is {stem}.rs, not {} (or say why the GPU's file gathers several)",
            rust_files[0]
        );
        let rust: String = rust_files
            .iter()
            .map(|f| std::fs::read_to_string(root.join(f)).unwrap_or_else(|e| panic!("{f}: {e}")))
            .collect();
        let text = std::fs::read_to_string(root.join("shaders").join(&name)).unwrap();
        for f in glsl_functions(&text) {
            let declared = GPU_ONLY_FUNCTIONS.iter().any(|(file, func, _)| *file == name && *func == f);
            assert!(declared || has_twin(&rust, &f), "shaders/{name}: `{f}` has no Rust function in {rust_files:?}");
            functions += 1;
        }
    }
    assert!(functions >= 140, "only {functions} GLSL functions seen");
}

/// GLSL has no exhaustive `match`: so every branch of a shader on the BRDF kind is a `switch (VARIANT_BRDF)` whose
/// `case`s name every kind of shaders/bindings.glsl (as many as the Rust's `Brdf` has variants) with no `default`,
/// and no shader compares with a `BRDF_*` constant outside one. A new BRDF is then a list of switches to extend,
/// each found by this test.
#[test]
fn every_branch_on_the_brdf_kind_names_every_kind() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bindings = std::fs::read_to_string(root.join("shaders/bindings.glsl")).unwrap();
    let kinds: std::collections::BTreeSet<String> = bindings
        .lines()
        .filter_map(|l| l.strip_prefix("#define BRDF_"))
        .map(|rest| format!("BRDF_{}", rest.split_whitespace().next().unwrap()))
        .collect();
    let material = std::fs::read_to_string(root.join("src/scene/material.rs")).unwrap();
    let brdf_enum = &material[material.find("pub enum Brdf {").expect("enum Brdf")..];
    let brdf_enum = &brdf_enum[..brdf_enum.find("\n}").unwrap()];
    let variants = brdf_enum
        .lines()
        .filter(|l| l.starts_with("    ") && !l.starts_with("     ") && l.trim_start().starts_with(char::is_uppercase))
        .count();
    assert_eq!(kinds.len(), variants, "shaders/bindings.glsl's BRDF_* kinds against the Rust's Brdf variants");
    let is_ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut switches = 0;
    for (path, text) in sources("shaders") {
        if path.ends_with("bindings.glsl") {
            continue;
        }
        let code: String = text.lines().map(|l| l.split("//").next().unwrap().to_string() + "\n").collect();
        // Every BRDF_* token is a case label.
        for (i, _) in code.match_indices("BRDF_") {
            if code[..i].chars().next_back().is_some_and(is_ident) {
                continue; // VARIANT_BRDF and the like
            }
            assert!(
                code[..i].trim_end().ends_with("case"),
                "{path}: `{}` outside a `case`: branch on the BRDF kind with a switch naming every kind",
                code[i..].split(|c: char| !is_ident(c)).next().unwrap()
            );
        }
        // Every switch on the kind names each kind once, with no default.
        for (start, _) in code.match_indices("switch (VARIANT_BRDF)") {
            let open = start + code[start..].find('{').unwrap();
            let mut depth = 0;
            let mut end = open;
            for (j, c) in code[open..].char_indices() {
                depth += i32::from(c == '{') - i32::from(c == '}');
                if depth == 0 {
                    end = open + j;
                    break;
                }
            }
            let body = &code[open..end];
            let named: Vec<&str> = body
                .match_indices("case ")
                .map(|(j, _)| body[j + 5..].split(|c: char| !is_ident(c)).next().unwrap())
                .collect();
            let line = code[..start].lines().count() + 1;
            let set: std::collections::BTreeSet<String> = named.iter().map(|s| s.to_string()).collect();
            assert_eq!(set, kinds, "{path}:{line}: a switch on VARIANT_BRDF must name every kind");
            assert_eq!(named.len(), kinds.len(), "{path}:{line}: a kind named twice");
            assert!(!body.contains("default"), "{path}:{line}: no `default` (name each kind)");
            switches += 1;
        }
    }
    assert!(switches >= 8, "only {switches} switches on the BRDF kind seen");
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

/// The reference carries every vertex attribute the GPU's vertex layout holds, in the same order.
#[test]
fn vertex_layout_matches_the_references_attributes() {
    use sunshade::gpu::layout::{SurfaceVertex, Vertex};
    assert_eq!(
        sunshade::cpu::clip::ATTRIBUTES * 4,
        std::mem::size_of::<Vertex>() + std::mem::size_of::<SurfaceVertex>()
    );
}

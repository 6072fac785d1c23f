//! The shaders: SPIR-V compiled ahead of time by build.rs (every variant the renderer can ask for), embedded in
//! the binary; and the GLSL sources of `shaders/`, embedded too, for compiling at run time in development
//! (`SUNSHADE_SHADER_DIR`) and for the tests that check the two agree.
//!
//! `#include "name.glsl"` resolves against the given sources, so the binary runs from any directory.
//! A compile error reports the file and line (shaderc's `file:line: error: ...`), at build time as at run time.

/// Every file in `shaders/`, by name.
pub const SOURCES: &[(&str, &str)] = &[
    ("bindings.glsl", include_str!("../../shaders/bindings.glsl")),
    ("math.glsl", include_str!("../../shaders/math.glsl")),
    ("brdf.glsl", include_str!("../../shaders/brdf.glsl")),
    ("brdf/phong.glsl", include_str!("../../shaders/brdf/phong.glsl")),
    ("brdf/blinn_phong.glsl", include_str!("../../shaders/brdf/blinn_phong.glsl")),
    ("brdf/ward.glsl", include_str!("../../shaders/brdf/ward.glsl")),
    ("measured.glsl", include_str!("../../shaders/measured.glsl")),
    ("shade.glsl", include_str!("../../shaders/shade.glsl")),
    ("lobe.glsl", include_str!("../../shaders/lobe.glsl")),
    ("sky_lune.glsl", include_str!("../../shaders/sky_lune.glsl")),
    ("lights/sun.glsl", include_str!("../../shaders/lights/sun.glsl")),
    ("lights/disk.glsl", include_str!("../../shaders/lights/disk.glsl")),
    ("lights/sky.glsl", include_str!("../../shaders/lights/sky.glsl")),
    ("visibility.glsl", include_str!("../../shaders/visibility.glsl")),
    ("occluders.glsl", include_str!("../../shaders/occluders.glsl")),
    ("ray_triangle.glsl", include_str!("../../shaders/ray_triangle.glsl")),
    ("bvh.glsl", include_str!("../../shaders/bvh.glsl")),
    ("sun_cells.glsl", include_str!("../../shaders/sun_cells.glsl")),
    ("disk_cone.glsl", include_str!("../../shaders/disk_cone.glsl")),
    ("slices.glsl", include_str!("../../shaders/slices.glsl")),
    ("shadow_map.glsl", include_str!("../../shaders/shadow_map.glsl")),
    ("transform.glsl", include_str!("../../shaders/transform.glsl")),
    ("barycentric.glsl", include_str!("../../shaders/barycentric.glsl")),
    ("texture_filter.glsl", include_str!("../../shaders/texture_filter.glsl")),
    ("surface.glsl", include_str!("../../shaders/surface.glsl")),
    ("fragment.glsl", include_str!("../../shaders/fragment.glsl")),
    ("scene.vert", include_str!("../../shaders/scene.vert")),
    ("scene.frag", include_str!("../../shaders/scene.frag")),
    ("shadow_mask.frag", include_str!("../../shaders/shadow_mask.frag")),
    ("fullscreen.vert", include_str!("../../shaders/fullscreen.vert")),
    ("second_draw.frag", include_str!("../../shaders/second_draw.frag")),
];

pub use sunshade_glsl::compile;

/// A shader module compiled by build.rs.
pub struct EmbeddedModule {
    pub stage: &'static str,
    pub defines: &'static [&'static str],
    /// SPIR-V, little-endian words.
    pub spirv: &'static [u8],
}

include!(concat!(env!("OUT_DIR"), "/spirv_modules.rs"));

/// The environment variable naming a folder of GLSL sources to compile at run time instead (development).
pub const SHADER_DIR_VAR: &str = "SUNSHADE_SHADER_DIR";

/// SPIR-V of `stage` with these `#define`s: compiled at run time from `$SUNSHADE_SHADER_DIR` when that is set
/// (every file of [`SOURCES`] read from there), else the module built ahead of time.
pub fn stage_spirv(stage: &str, defines: &[&str]) -> Result<Vec<u32>, String> {
    if let Some(dir) = std::env::var_os(SHADER_DIR_VAR) {
        let dir = std::path::PathBuf::from(dir);
        let files: Vec<(&str, String)> = SOURCES
            .iter()
            .map(|(name, _)| {
                let path = dir.join(name);
                std::fs::read_to_string(&path).map(|text| (*name, text)).map_err(|e| format!("{}: {e}", path.display()))
            })
            .collect::<Result<_, _>>()?;
        let refs: Vec<(&str, &str)> = files.iter().map(|(n, t)| (*n, t.as_str())).collect();
        return compile(stage, &refs, defines);
    }
    embedded(stage, defines).ok_or_else(|| format!("no module {stage} with {defines:?} was built ahead of time"))
}

/// The module build.rs compiled for `stage` with exactly these `#define`s, as words.
pub fn embedded(stage: &str, defines: &[&str]) -> Option<Vec<u32>> {
    let m = MODULES.iter().find(|m| m.stage == stage && m.defines == defines)?;
    Some(m.spirv.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_embedded_stage_compiles() {
        for (name, _) in SOURCES.iter().filter(|(n, _)| !n.ends_with(".glsl")) {
            for defines in [
                &["SUNSHADE_F32_BARYCENTRICS"][..],
                &["SUNSHADE_F64_BARYCENTRICS"][..],
                &["SUNSHADE_DEVICE_INTERPOLATION"][..],
                &["SUNSHADE_F64_BARYCENTRICS", "SUNSHADE_NAIVE_MATH"][..],
            ] {
                let words = compile(name, SOURCES, defines).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(words[0], 0x0723_0203, "{name}: not SPIR-V");
            }
            if name.ends_with(".frag") {
                for rays in ["SUNSHADE_RAY_QUERY", "SUNSHADE_RAY_BVH"] {
                    for defines in [
                        &["SUNSHADE_F64_BARYCENTRICS", rays][..],
                        &["SUNSHADE_F64_BARYCENTRICS", rays, "SUNSHADE_SLICES"],
                    ] {
                        let words = compile(name, SOURCES, defines).unwrap_or_else(|e| panic!("{e}"));
                        assert_eq!(words[0], 0x0723_0203, "{name}: not SPIR-V");
                    }
                }
            }
        }
    }

    #[test]
    fn sources_hold_every_file_of_the_shaders_folder() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
        let mut on_disk = Vec::new();
        let mut folders = vec![root.clone()];
        while let Some(folder) = folders.pop() {
            for entry in std::fs::read_dir(&folder).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    folders.push(path);
                } else {
                    on_disk.push(path.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/"));
                }
            }
        }
        let mut listed: Vec<String> = SOURCES.iter().map(|(name, _)| name.to_string()).collect();
        on_disk.sort();
        listed.sort();
        assert_eq!(listed, on_disk, "shaders/ and SOURCES differ: list a new shader file in SOURCES");
    }

    #[test]
    fn modules_built_ahead_equal_run_time_compilation() {
        // The same shaderc and the same sources: bitwise the same SPIR-V, hence the same images either way.
        // 2 stages × 3 interpolations × (plain, naive math), the fragment stage's 3 with ray queries and 3 with
        // the BVH walk, each with and without slices, the masked shadow-map stage's 3, and the mark's 2
        // (gpu::second_draw).
        assert_eq!(MODULES.len(), 29);
        for m in MODULES {
            let words = compile(m.stage, SOURCES, m.defines).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(embedded(m.stage, m.defines).unwrap(), words, "{} {:?}", m.stage, m.defines);
        }
    }

    #[test]
    fn errors_name_file_and_line() {
        let sources = [
            ("inc.glsl", "float f() {\n  return 1.0;\n}\nfloat g() { return undefined_name; }\n"),
            (
                "broken.frag",
                "#version 450\n#include \"inc.glsl\"\nlayout(location=0) out vec4 o;\nvoid main() { o = vec4(f()); }\n",
            ),
            ("missing.frag", "#version 450\n#include \"nowhere.glsl\"\nvoid main() {}\n"),
        ];
        let err = compile("broken.frag", &sources, &[]).unwrap_err();
        assert!(err.contains("inc.glsl:4"), "{err}");
        let err = compile("missing.frag", &sources, &[]).unwrap_err();
        assert!(err.contains("missing.frag:2") && err.contains("nowhere.glsl"), "{err}");
    }
}

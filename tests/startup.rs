//! What a render process hands the driver: each pipeline's fragment shader specialized for its variant
//! (sunshade_glsl::specialize), valid SPIR-V, within a recorded size per variant, and rendering bitwise the images the
//! whole shader renders. The size budgets pin start-up cost: on lavapipe a pipeline's creation time grows with the
//! code its module calls, each function once a call (docs/platform.md, "What the driver compiles").

mod common;

use sunshade::gpu::layout::*;
use sunshade::gpu::shaders::{embedded, MODULES};
use sunshade::gpu::ContextOptions;
use sunshade::shading::surface::{
    SURFACE_ALPHA_MASK, SURFACE_COLORS, SURFACE_EMISSION, SURFACE_EVAL, SURFACE_NORMAL_MAP,
};
use sunshade::testing::{job, CheckedRenderer};

const ALL_SURFACE: u32 = SURFACE_EVAL | SURFACE_NORMAL_MAP | SURFACE_EMISSION | SURFACE_ALPHA_MASK | SURFACE_COLORS;
const F64: &str = "SUNSHADE_F64_BARYCENTRICS";

/// A variant: a name for messages, the stage and `#define`s of its module, its constants (`ShaderVariant`'s order:
/// brdf, sun, disks, sky, shadows, surface, quantity, visibility, occluders_masked, sun_cells, penumbrae, mark) and its budget:
/// the instructions of its specialized shader with every call inlined (`sunshade_glsl::inlined_instruction_count`,
/// what lavapipe compiles, which creation time follows more closely than the SPIR-V's size), recorded plus about 10%.
struct Pinned {
    name: &'static str,
    stage: &'static str,
    defines: &'static [&'static str],
    constants: [u32; VARIANT_CONSTANTS],
    budget: usize,
}

const PINNED: &[Pinned] = &[
    Pinned {
        name: "teapot.glb's default: Lambert, disk sun, shadow maps",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_MAP,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 4200, // 3730 when recorded
    },
    Pinned {
        name: "square.gltf's default: Lambert, disk sun, no shadows",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_NONE,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 2200, // 1942 when recorded
    },
    Pinned {
        name: "Lambert, delta sun, exact disks, sky, shadow maps",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_LAMBERT,
            SUN_DELTA,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_MAP,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 8200, // 7373 when recorded
    },
    Pinned {
        name: "Phong, disk sun, exact disks, sky, shadow maps",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_PHONG,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_MAP,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 20700, // 18786 when recorded
    },
    Pinned {
        name: "Blinn-Phong, disk sun, exact disks, sky, shadow maps",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_BLINN_PHONG,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_MAP,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 20900, // 18967 when recorded
    },
    Pinned {
        name: "Ward, disk sun, exact disks, sky, shadow maps",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_WARD,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_MAP,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 20500, // 18612 when recorded
    },
    Pinned {
        name: "measured, disk sun, exact disks, sky, shadow maps",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_MEASURED,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_MAP,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 29600, // 26877 when recorded
    },
    Pinned {
        name: "Ward, disk sun, small-source disks, no shadows",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_WARD,
            SUN_DISK,
            DISKS_SMALL_SOURCE,
            0,
            SHADOWS_NONE,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 6100, // 5514 when recorded
    },
    Pinned {
        name: "every surface input (textures, normal map, emission, mask, colours), Lambert, disk sun, maps",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_MAP,
            ALL_SURFACE,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 6900, // 6268 when recorded
    },
    Pinned {
        name: "irradiance under every light, shadow maps",
        stage: "scene.frag",
        defines: &[F64],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_MAP,
            0,
            QUANTITY_IRRADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 8600, // 7745 when recorded
    },
    Pinned {
        name: "shadow rays by the BVH walk: Lambert, disk sun",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            SUN_CELLS_COMPLETE,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 5900, // 5362 when recorded
    },
    Pinned {
        name: "the first of two draws (penumbrae later, marked by stencil), BVH walk: Lambert, disk sun",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            SUN_CELLS_COMPLETE,
            PENUMBRAE_LATER,
            MARK_BY_STENCIL,
        ],
        budget: 3700, // 3327 when recorded
    },
    Pinned {
        name: "shadow rays by the BVH walk: Lambert, disk sun, some points past the sun's cells",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            SUN_CELLS_PARTIAL,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 10200, // 9265 when recorded
    },
    Pinned {
        name:
            "sunset.glb's and brdfs.glb's default: Lambert, disk sun, some points past the sun's cells, the tree later",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            SUN_CELLS_PARTIAL,
            TREE_LATER,
            MARK_BY_COLOUR,
        ],
        budget: 6600, // 5957 when recorded, with the penumbra's bins (CHANGELOG.md: what they save)
    },
    Pinned {
        name: "shadow rays by the BVH walk: Ward, every light",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH"],
        constants: [
            BRDF_WARD,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            SUN_CELLS_PARTIAL,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 38800, // 35251 when recorded
    },
    Pinned {
        name: "slices by the BVH walk: Lambert, every light",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH", "SUNSHADE_SLICES"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_SLICES,
            0,
            SUN_CELLS_PARTIAL,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 42400, // 38464 when recorded
    },
    Pinned {
        name: "a light's rows of slices (a pass), BVH walk",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH", "SUNSHADE_SLICES"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_RAY,
            0,
            QUANTITY_LIGHT_ROWS,
            VISIBILITY_SLICES,
            0,
            SUN_CELLS_COMPLETE,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 32800, // 29816 when recorded
    },
    Pinned {
        name: "shadow rays by ray queries: Lambert, disk sun",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_QUERY"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            SUN_CELLS_COMPLETE,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 5900, // 5351 when recorded
    },
    Pinned {
        name: "shadow rays by ray queries: Ward, every light",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_QUERY"],
        constants: [
            BRDF_WARD,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            SUN_CELLS_PARTIAL,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 26000, // 23551 when recorded
    },
    Pinned {
        name: "shadow rays by ray queries through alpha-masked occluders: Lambert, disk sun",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_QUERY"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            1,
            SUN_CELLS_COMPLETE,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 7100, // 6380 when recorded
    },
    Pinned {
        name: "shadow rays by the BVH walk through alpha-masked occluders: Lambert, disk sun",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            0,
            0,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            1,
            SUN_CELLS_COMPLETE,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 7100, // 6391 when recorded
    },
    Pinned {
        name: "slices with ray queries: Lambert, every light",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_QUERY", "SUNSHADE_SLICES"],
        constants: [
            BRDF_LAMBERT,
            SUN_DISK,
            DISKS_EXACT,
            SKY_PRESENT,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_SLICES,
            0,
            SUN_CELLS_PARTIAL,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 38300, // 34754 when recorded
    },
    Pinned {
        name: "AlphaBlendModeTest.glb's second draw: glTF, disk sun, surface and normal map, BVH walk through masks",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH"],
        constants: [
            BRDF_GLTF,
            SUN_DISK,
            0,
            0,
            SHADOWS_RAY,
            SURFACE_EVAL | SURFACE_NORMAL_MAP,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            1,
            SUN_CELLS_COMPLETE,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 15000, // 13589 when recorded
    },
    Pinned {
        name: "room.gltf's second draw: Lambert, exact disks, BVH walk",
        stage: "scene.frag",
        defines: &[F64, "SUNSHADE_RAY_BVH"],
        constants: [
            BRDF_LAMBERT,
            LIGHT_ABSENT,
            DISKS_EXACT,
            0,
            SHADOWS_RAY,
            0,
            QUANTITY_RADIANCE,
            VISIBILITY_GRID,
            0,
            0,
            PENUMBRAE_HERE,
            MARK_BY_COLOUR,
        ],
        budget: 11200, // 10127 when recorded
    },
    Pinned {
        name: "the shadow maps' alpha-masked pass",
        stage: "shadow_mask.frag",
        defines: &[F64],
        constants: [0, 0, 0, 0, 0, SURFACE_EVAL | SURFACE_ALPHA_MASK, 0, 0, 0, 0, PENUMBRAE_HERE, MARK_BY_COLOUR],
        budget: 2500, // 2271 when recorded
    },
];

fn constants_of(v: [u32; VARIANT_CONSTANTS]) -> Vec<(u32, u32)> {
    (0u32..).zip(v).collect()
}

fn specialized(stage: &str, defines: &[&str], constants: [u32; VARIANT_CONSTANTS]) -> Vec<u32> {
    let words = embedded(stage, defines).unwrap_or_else(|| panic!("no module {stage} {defines:?} built"));
    sunshade_glsl::specialize(&words, &constants_of(constants)).unwrap_or_else(|e| panic!("{stage} {defines:?}: {e}"))
}

fn spirv_val(words: &[u32], what: &str) {
    sunshade_glsl::spirv_val(words).unwrap_or_else(|e| panic!("{what}: {e}"));
}

#[test]
fn variant_sizes_stay_within_their_budgets() {
    let mut over = Vec::new();
    for p in PINNED {
        let words = specialized(p.stage, p.defines, p.constants);
        let n = sunshade_glsl::inlined_instruction_count(&words).unwrap();
        let spirv = sunshade_glsl::instruction_count(&words).unwrap();
        println!("{n:>6} of {:>6} instructions inlined ({spirv:>6} SPIR-V): {}", p.budget, p.name);
        if n > p.budget {
            // The largest shares, so that the message says where the growth may be.
            let largest: Vec<String> = sunshade_glsl::inlined_profile(&words)
                .unwrap()
                .iter()
                .take(5)
                .map(|f| format!("{} ({} × {})", f.short_name(), f.own, f.copies))
                .collect();
            over.push(format!(
                "{}: {n} instructions inlined, over its budget of {}; largest shares (own × copies): {}",
                p.name,
                p.budget,
                largest.join(", ")
            ));
        }
    }
    assert!(
        over.is_empty(),
        "specialized shaders grew past their budgets (each instruction costs pipeline creation on lavapipe; measure \
         with `sunshade bench --startup`, and raise the budget in tests/startup.rs only if the feature is worth it):\n{}",
        over.join("\n")
    );
}

/// Every module built ahead of time, specialized for a spread of variants (every value of every constant, in a
/// pseudo-random mix), is valid SPIR-V; each is smaller than the whole module, and specializing it again changes
/// nothing.
#[test]
fn specialized_modules_are_valid_spirv() {
    let ranges: [u32; VARIANT_CONSTANTS] = [5, 3, 3, 2, 3, ALL_SURFACE + 1, 3, 2, 2, 3, 2, 2];
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = |n: u32| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n as u64) as u32
    };
    // Every fragment module with variants (the mark between two draws, gpu::second_draw, has none).
    for m in MODULES.iter().filter(|m| m.stage.ends_with(".frag") && m.stage != "second_draw.frag") {
        let words = embedded(m.stage, m.defines).unwrap();
        let whole = sunshade_glsl::instruction_count(&words).unwrap();
        for k in 0..4 {
            let mut c: [u32; VARIANT_CONSTANTS] = std::array::from_fn(|i| next(ranges[i]));
            // Each constant at its largest value once.
            if k == 0 {
                c = std::array::from_fn(|i| ranges[i] - 1);
            }
            let what = format!("{} {:?} {c:?}", m.stage, m.defines);
            let out = sunshade_glsl::specialize(&words, &constants_of(c)).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert!(sunshade_glsl::instruction_count(&out).unwrap() < whole, "{what}: nothing removed");
            assert_eq!(sunshade_glsl::specialize(&out, &constants_of(c)).unwrap(), out, "{what}: not idempotent");
            spirv_val(&out, &what);
        }
    }
    for p in PINNED {
        spirv_val(&specialized(p.stage, p.defines, p.constants), p.name);
    }
}

/// Renders `flags` on `scene` with specialized and with whole shaders: the same bits, and no validation message.
fn same_bits(scene: &str, flags: &[&str]) {
    let j = job(format!("{}/models/{scene}", env!("CARGO_MANIFEST_DIR")), flags).unwrap_or_else(|e| panic!("{e}"));
    let mut specialized = CheckedRenderer::new();
    let a = specialized.render_job(&j).unwrap_or_else(|e| panic!("{e}"));
    drop(specialized);
    let mut whole = CheckedRenderer::try_with(ContextOptions { whole_shaders: true, ..Default::default() })
        .unwrap_or_else(|e| panic!("{e}"));
    let b = whole.render_job(&j).unwrap_or_else(|e| panic!("{e}"));
    assert!(common::bits(&a) == common::bits(&b), "{scene} {flags:?}: specialized shaders changed the image");
}

#[test]
fn gpu_specialized_shaders_render_the_same_bits() {
    same_bits("teapot.glb", &["--width", "64", "--height", "48"]);
    same_bits(
        "brdfs.glb",
        &["--width", "64", "--height", "32", "--shadows", "none", "--disk-light", "0,3,2:0,-1,0:0.8:2000"],
    );
    same_bits("room.gltf", &["--width", "48", "--height", "36", "--shadows", "map", "--quantity", "irradiance"]);
    same_bits("gltf-samples/TextureTransformTest/TextureTransformTest.gltf", &["--width", "48", "--height", "48"]);
    same_bits("gltf-samples/AlphaBlendModeTest/AlphaBlendModeTest.glb", &["--width", "64", "--height", "32"]);
}

#[test]
fn gpu_ray_specialized_shaders_render_the_same_bits() {
    same_bits("sunset.glb", &["--width", "24", "--height", "18", "--shadows", "ray", "--shadow-samples", "9"]);
}

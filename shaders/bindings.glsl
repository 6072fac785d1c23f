// Resource bindings and push constants shared by scene.vert and scene.frag.
// Mirrors src/gpu/layout.rs (std430): change both together.
#ifndef SUNSHADE_BINDINGS_GLSL
#define SUNSHADE_BINDINGS_GLSL

// BRDF kinds (MaterialGpu.kind.x); values match gpu::layout::BRDF_*.
#define BRDF_LAMBERT 0u
#define BRDF_PHONG 1u
#define BRDF_BLINN_PHONG 2u
#define BRDF_WARD 3u
#define BRDF_MEASURED 4u
#define BRDF_GLTF 5u

// Which lights a frame has, and their models (the VARIANT_* constants below); values match gpu::layout.
#define LIGHT_ABSENT 0u
#define SUN_DISK 1u
#define SUN_DELTA 2u
#define DISKS_EXACT 1u
#define DISKS_SMALL_SOURCE 2u
#define SKY_PRESENT 1u
// Shadows (VARIANT_SHADOWS); values match gpu::layout.
#define SHADOWS_NONE 0u
#define SHADOWS_RAY 1u
#define SHADOWS_MAP 2u
// The rule for the lights' visible fractions with shadow rays (VARIANT_VISIBILITY); values match gpu::layout.
#define VISIBILITY_GRID 0u
#define VISIBILITY_SLICES 1u
// The coverage alpha of a fragment whose loops llvmpipe's limiter cut short (fragment.glsl's coverage_alpha), and
// the probe loop's iterations; values match gpu::loop_budget.
#define LOOP_BUDGET_SPENT -1.0
// The coverage alpha of a fragment whose slices gathered more triangles than they keep (slices.glsl), set in
// `slices_overflowed`; the value matches gpu::slice_gather.
#define SLICES_OVERFLOWED -2.0
bool slices_overflowed = false;
#define LOOP_PROBE_ITERATIONS 2u
// The coverage alpha of a pixel the first of a frame's two draws leaves to the second (VARIANT_PENUMBRAE), set in
// `left_to_second_draw`; the value matches gpu::second_draw.
#define LEFT_TO_SECOND_DRAW -3.0
bool left_to_second_draw = false;
// What the fragment shader writes (VARIANT_QUANTITY); values match gpu::layout.
#define QUANTITY_RADIANCE 0u
#define QUANTITY_IRRADIANCE 1u
// One pass of a light's slices (slices.glsl's sky_rows_weights, sun_rows_weights, disk_rows_weights: the rows
// lights.light_rows.x and on, .y of them, of the light lights.light_rows.z), written as (visible, whole, 0,
// coverage) for the renderer to sum (gpu::slice_passes).
#define QUANTITY_LIGHT_ROWS 2u
// The light a pass slices (lights.light_rows.z), and its layer of light_fractions: the sky, the sun, disk light i
// at ROWS_OF_DISK + i. Values match gpu::layout.
#define ROWS_OF_SKY 0u
#define ROWS_OF_SUN 1u
#define ROWS_OF_DISK 2u
// The lights whose visible fractions the frame reads from light_fractions, left there by their passes, rather than
// taking them itself (lights.light_rows.w's bits).
#define READ_SKY 1u
#define READ_SUN 2u
#define READ_DISKS 4u

// The pipeline variant (specialization constants, from gpu::layout::ShaderVariant): the BRDF of the draw's
// material, and which lights the frame has with which model. Code for anything else is removed before the driver
// sees the module (sunshade_glsl::specialize), since lavapipe compiles every function a shader calls before it
// folds these constants (docs/platform.md, "What the driver compiles"), and code present in the shader also costs
// time where no pixel runs it (docs/accuracy.md, "Pipeline variants").
layout(constant_id = 0) const uint VARIANT_BRDF = 0u;  // BRDF_*
layout(constant_id = 1) const uint VARIANT_SUN = 0u;   // LIGHT_ABSENT, SUN_DISK or SUN_DELTA
layout(constant_id = 2) const uint VARIANT_DISKS = 0u; // LIGHT_ABSENT, DISKS_EXACT or DISKS_SMALL_SOURCE
layout(constant_id = 3) const uint VARIANT_SKY = 0u;   // LIGHT_ABSENT or SKY_PRESENT
layout(constant_id = 4) const uint VARIANT_SHADOWS = 0u; // SHADOWS_NONE, SHADOWS_MAP, or SHADOWS_RAY (SUNSHADE_RAY_QUERY modules)
layout(constant_id = 5) const uint VARIANT_SURFACE = 0u; // SURFACE_* bits: what the material needs per pixel
layout(constant_id = 6) const uint VARIANT_QUANTITY = 0u; // QUANTITY_RADIANCE, QUANTITY_IRRADIANCE or QUANTITY_LIGHT_ROWS
layout(constant_id = 7) const uint VARIANT_VISIBILITY = 0u; // VISIBILITY_GRID or VISIBILITY_SLICES, with shadow rays
layout(constant_id = 8) const uint VARIANT_OCCLUDERS_MASKED = 0u; // with shadow rays: 1 where a material of the scene
                                                             // is alpha-masked (occluders.glsl's blocks tests it)
layout(constant_id = 9) const uint VARIANT_SUN_CELLS = 0u; // with shadow rays and a sun: SUN_CELLS_*
layout(constant_id = 10) const uint VARIANT_PENUMBRAE = 0u; // with shadow rays: PENUMBRAE_HERE, _LATER, TREE_LATER
layout(constant_id = 11) const uint VARIANT_MARK = 0u; // with PENUMBRAE_LATER: MARK_BY_COLOUR or MARK_BY_STENCIL

// Where a pixel whose lights are neither proven wholly visible nor wholly hidden is shaded (VARIANT_PENUMBRAE;
// gpu::layout's PENUMBRAE_*): by this draw (the whole shader), or by a second draw of the scene after this one
// (gpu::second_draw): this draw then marks it before any ray but the sun cells' (visibility.glsl's
// LEAVE_TO_SECOND_DRAW), and holds no grid and no walk of its own. TREE_LATER: by this draw, which holds no walk
// of the occluders' tree: a pixel whose ray needs it is marked as the first draw marks (LEAVE_THE_TREE), and the
// marked pixels drawn once more with the tree after the frame (gpu::layout's ShaderVariant::tree_later).
#define PENUMBRAE_HERE 0u
#define PENUMBRAE_LATER 1u
#define TREE_LATER 2u

// How the first of two draws marks the pixels it leaves to the second (VARIANT_MARK; gpu::layout's MARK_BY_*): by
// the colour's alpha LEFT_TO_SECOND_DRAW alone, which a pass between the draws turns into the stencil, or by the
// stencil value every fragment of the draw writes besides (scene.frag's marked_coverage_alpha;
// VK_EXT_shader_stencil_export).
#define MARK_BY_COLOUR 0u
#define MARK_BY_STENCIL 1u

// What the sun's cells answer this frame (VARIANT_SUN_CELLS; gpu::layout's SUN_CELLS_*): nothing (the sun's rays
// take occluded), every point's rays (no cell holds more than MAX_SUN_CELL_TRIANGLES: occluded is never needed for
// the sun), or the rays of the points under at most that many (the others take occluded).
#define SUN_CELLS_NONE 0u
#define SUN_CELLS_COMPLETE 1u
#define SUN_CELLS_PARTIAL 2u

// What a draw's material needs per pixel (VARIANT_SURFACE); values match shading::surface::SURFACE_*.
#define SURFACE_EVAL 1u
#define SURFACE_NORMAL_MAP 2u
#define SURFACE_EMISSION 4u
#define SURFACE_ALPHA_MASK 8u
#define SURFACE_COLORS 16u

// Samplers (texture headers' bits: wrap_s | wrap_t << 2 | mag << 4 | min << 5 | mip << 6); values match
// gpu::layout.
#define WRAP_REPEAT 0u
#define WRAP_MIRRORED_REPEAT 1u
#define WRAP_CLAMP_TO_EDGE 2u
#define FILTER_NEAREST 0u
#define FILTER_LINEAR 1u
#define MIP_NONE 0u
#define MIP_NEAREST 1u
#define MIP_LINEAR 2u
// A material slot without a texture.
#define NO_TEXTURE 0xffffffffu

// Texture coordinates and footprints are computed in f64 where the device has it (the same barycentrics as the
// reference's), else in f32.
#ifdef SUNSHADE_F64_BARYCENTRICS
#define REAL double
#define REAL2 dvec2
#define REAL3 dvec3
#define REAL4 dvec4
#else
#define REAL float
#define REAL2 vec2
#define REAL3 vec3
#define REAL4 vec4
#endif

// Disk lights with a shadow map of their own (`--shadows map`); the others stay unoccluded. Matches
// gpu::layout::MAX_DISK_MAPS.
#define MAX_DISK_MAPS 4u

// A material's use of a texture: the texture-coordinate transform (KHR_texture_transform) rows, the texture and
// its coordinate set.
struct TextureRefGpu {
    vec4 row0;     // xyz: m0 m1 m2 (u' = m0 u + m1 v + m2)
    vec4 row1;     // xyz: m3 m4 m5
    uvec4 texture; // x: texture index or NO_TEXTURE; y: TEXCOORD set
};

struct MaterialGpu {
    vec4 kd;     // rgb: diffuse reflectance kd (the albedo for Lambert; pi floor for a measured table); w unused
    vec4 ks;     // rgb: specular reflectance ks (1 for a measured table); w: Phong / Blinn-Phong exponent, or a
                 // measured table's lobe width [rad]
    vec4 params; // x, y: Ward alpha_x, alpha_y; measured: rgb the table's floor [1/sr], w 1 for the nearest lookup;
                 // glTF: x alpha, y metallic
    uvec4 kind;  // x: BRDF kind (the pipeline variant's VARIANT_BRDF); y: 1 if double-sided; z: 1 if alpha MASK;
                 // w: a measured table's first sample in measured_values[]
    vec4 base;   // base colour factor (rgb linear, alpha); glTF's lobe reads the pixel's (surface.glsl)
    vec4 pbr;    // x metallic, y roughness factors; z normal-map scale; w alpha cutoff
    vec4 emission; // rgb: emitted radiance [W/(m^2 sr)] before the emissive texture
    vec4 specular; // glTF's dielectric Fresnel: rgb f0, w f90 (KHR_materials_ior and KHR_materials_specular)
    TextureRefGpu tex[4]; // TEX_BASE, TEX_METALLIC_ROUGHNESS, TEX_NORMAL, TEX_EMISSIVE
};
#define TEX_BASE 0
#define TEX_METALLIC_ROUGHNESS 1
#define TEX_NORMAL 2
#define TEX_EMISSIVE 3

struct SunGpu {
    vec4 direction;  // xyz: unit vector towards the sun (world); w: angular diameter [rad]
    vec4 irradiance; // rgb: E_perp [W/m^2]; w: 1 if the sun is present, else 0
};

struct DiskGpu {
    vec4 center_radius; // xyz: centre [m]; w: radius R [m]
    vec4 direction;     // xyz: unit emission direction; w unused
    vec4 radiance;      // rgb: L0 [W/(m^2 sr)]; w unused
};

// The materials (gpu::layout::MaterialGpu, 320 bytes) as RGBA32UI texels, twenty a material (floats by their
// bits): kd, ks, params, kind, base, pbr, emission, specular, then each texture reference's row0, row1, texture. Read by
// material_at: llvmpipe loads a storage buffer's words lane by lane even where every lane reads the same, and
// fetches a texel in one gather (docs/platform.md, "Loads in the walks").
layout(set = 0, binding = 0) uniform usamplerBuffer material_texels;
#define MATERIAL_TEXELS 20u
MaterialGpu material_at(uint m) {
    int at = int(MATERIAL_TEXELS * m);
    MaterialGpu g;
    g.kd = uintBitsToFloat(texelFetch(material_texels, at));
    g.ks = uintBitsToFloat(texelFetch(material_texels, at + 1));
    g.params = uintBitsToFloat(texelFetch(material_texels, at + 2));
    g.kind = texelFetch(material_texels, at + 3);
    g.base = uintBitsToFloat(texelFetch(material_texels, at + 4));
    g.pbr = uintBitsToFloat(texelFetch(material_texels, at + 5));
    g.emission = uintBitsToFloat(texelFetch(material_texels, at + 6));
    g.specular = uintBitsToFloat(texelFetch(material_texels, at + 7));
    // The four references written out, not looped over: llvmpipe's loop budget counts a loop's iterations.
#define MATERIAL_TEXTURE_REF(k) \
    g.tex[k].row0 = uintBitsToFloat(texelFetch(material_texels, at + 8 + 3 * k)); \
    g.tex[k].row1 = uintBitsToFloat(texelFetch(material_texels, at + 9 + 3 * k)); \
    g.tex[k].texture = texelFetch(material_texels, at + 10 + 3 * k);
    MATERIAL_TEXTURE_REF(0)
    MATERIAL_TEXTURE_REF(1)
    MATERIAL_TEXTURE_REF(2)
    MATERIAL_TEXTURE_REF(3)
#undef MATERIAL_TEXTURE_REF
    return g;
}

// Material m's kind alone (MaterialGpu::kind: its fourth texel), for a test that needs no more of it: each call of
// material_at compiles its twenty fetches.
uvec4 material_kind_at(uint m) {
    return texelFetch(material_texels, int(MATERIAL_TEXELS * m) + 3);
}

layout(std430, set = 0, binding = 1) readonly buffer LightBuffer {
    SunGpu sun;
    vec4 sky;     // rgb: overcast sky radiance [W/(m^2 sr)]; w: 1 if present
    uvec4 counts;   // x: number of disk lights; y unused; z: LOOP_PROBE_ITERATIONS (fragment.glsl); w: samples per axis
                    // (disks, sky: the render's; each draw reads its material's from pc.lobe_samples)
    uvec4 sampling; // x: samples per axis over the sun's disk (the render's; each draw reads its material's from
                    // pc.sun_samples); y: shadow samples per axis (visible fractions);
                    // z: shadow-map filter, 1 PCSS, 2 nearest; w unused (the visibility rule is the variant's,
                    // VARIANT_VISIBILITY)
    mat4 sun_map_from_world; // world -> the sun's shadow map (x, y in [-1, 1], depth in [0, 1]); visibility/shadow_map.rs
    vec4 sun_map;            // x: texel side [m]; y: depth extent [m]; z: size [texels]; w: 0 none, 1 PCSS, 2 nearest
    // The first MAX_DISK_MAPS disk lights' perspective maps (visibility/shadow_map.rs, fit_disk_map): world -> map
    // clip space, and (tan of the half field of view, near [m], far [m], size [texels] or 0 if not rendered).
    mat4 disk_map_from_world[MAX_DISK_MAPS];
    vec4 disk_map[MAX_DISK_MAPS];
    uvec4 light_rows;        // the lights' slices in passes (gpu::slice_passes): x the pass's first row, y its rows,
                             // z its light (ROWS_OF_*); w the lights the frame reads (READ_* bits)
    DiskGpu disks[];
} lights;

// The scene's triangles, for the fragment shader to fetch its triangle's three vertices by gl_PrimitiveID.
layout(std430, set = 0, binding = 2) readonly buffer IndexBuffer {
    uint indices[];
};

// The vertex buffer's FLOATS_PER_VERTEX floats per vertex (the vertex shader's input): position xyz [m], normal
// xyz, tangent xyz and handedness (world space); the offsets below (gpu::layout::Vertex).
#define FLOATS_PER_VERTEX 10u
#define VERTEX_POSITION 0u
#define VERTEX_NORMAL 3u
#define VERTEX_TANGENT 6u
// The same vertices as RGBA32UI texels, three a vertex (floats by their bits): position [m] and 0, normal and 0,
// tangent and handedness (texel offset / 3 of the offsets above). What the fragment shader reads of its
// triangle's corners and the walks of the occluders': llvmpipe fetches a texel in one gather where it loads a
// storage buffer's words lane by lane (docs/platform.md, "Loads in the walks"). Texel k of vertex i as floats:
layout(set = 0, binding = 17) uniform usamplerBuffer vertex_texels;
#define VERTEX_TEXEL(i, k) uintBitsToFloat(texelFetch(vertex_texels, int(3u * (i) + (k))))

// FLOATS_PER_SURFACE_VERTEX floats per vertex, read only by textured materials: TEXCOORD_0 uv, TEXCOORD_1 uv,
// COLOR_0 rgba (gpu::layout::SurfaceVertex).
#define FLOATS_PER_SURFACE_VERTEX 8u
#define SURFACE_VERTEX_UV0 0u
#define SURFACE_VERTEX_UV1 2u
#define SURFACE_VERTEX_COLOR 4u
layout(std430, set = 0, binding = 9) readonly buffer SurfaceVertexBuffer {
    float surface_data[];
};

// Per triangle of the acceleration structure (its primitive order): global vertex indices, and the material
// (bit 31: the mesh has vertex colours); read by ray queries' masked hits (the walks read WALK_RECORD).
layout(std430, set = 0, binding = 10) readonly buffer OccluderTriangles {
    uvec4 occluder_triangles[];
};

// The modules that cast shadow rays: by ray queries or by the shader's walk of the occluders' tree.
#if defined(SUNSHADE_RAY_BVH) || defined(SUNSHADE_RAY_QUERY)
#define SUNSHADE_SHADOW_RAYS
#endif

#ifdef SUNSHADE_SHADOW_RAYS
// The sun's cells (gpu::sun_cells lays out visibility::sun_cells::SunCells): the axes across the sun (u, v) with
// the projection of cell (0, 0)'s corner in w [m]; l the sun's direction, w cells per metre; dims the cells along
// u and v, z where the entries start in data, w unused (VARIANT_SUN_CELLS says what the cells answer).
// data, four words a vec4: each cell's first entry and one past the last cell's last (dims.x dims.y + 1 of them),
// then from word dims.z (a multiple of four) the entries, sixteen words each (sun_cells.glsl).
// Read as a uniform texel buffer of RGBA32UI (floats by their bits), one texel a vec4: texels 0 to 3 the header
// (u, v, l, dims), data from texel 4 (SUN_CELLS_DATA; llvmpipe fetches a texel as one gather where it loads a
// storage buffer's words lane by lane).
layout(set = 0, binding = 15) uniform usamplerBuffer sun_cells_texels;
#define SUN_CELLS_U uintBitsToFloat(texelFetch(sun_cells_texels, 0))
#define SUN_CELLS_V uintBitsToFloat(texelFetch(sun_cells_texels, 1))
#define SUN_CELLS_L uintBitsToFloat(texelFetch(sun_cells_texels, 2))
#define SUN_CELLS_DIMS texelFetch(sun_cells_texels, 3)
#define SUN_CELLS_DATA(i) texelFetch(sun_cells_texels, int(4u + (i)))
#endif

// The modules that walk the occluders' tree: for the shadow rays themselves without ray queries
// (SUNSHADE_RAY_BVH), for the disk lights' proof that their rays are clear (disk_cone.glsl) and the lights' slices
// (SUNSHADE_SLICES, slices.glsl) with ray queries or without: every module with shadow rays.
#ifdef SUNSHADE_SHADOW_RAYS
#define SUNSHADE_WALK
#endif

#ifdef SUNSHADE_WALK
// The occluders' tree (gpu::shadow_bvh::BvhNodeGpu, 32 bytes): a box [m] (padded for the f32 slab test), and a
// leaf's first record (WALK_RECORD) and their count, or an inner node's (count 0) first child (the second follows
// it). One dummy node until a render walks it.
struct BvhNode {
    vec3 lo;
    uint first;
    vec3 hi;
    uint count;
};
// Read as a uniform texel buffer of RGBA32UI, two texels a node (its lo and first, its hi and count; the box's
// floats by their bits): llvmpipe loads a storage buffer's element lane by lane with a bounds test each, a texel
// fetch as one gather (docs/platform.md, "Loads in the walks").
layout(set = 0, binding = 12) uniform usamplerBuffer bvh_node_texels;
// The same tree in depth-first order for the shadow rays' walk without a stack (gpu::shadow_bvh::threaded): a
// node's first is where the walk goes past its subtree, its count a leaf's record or THREADED_INNER.
layout(set = 0, binding = 18) uniform usamplerBuffer threaded_node_texels;
#define THREADED_INNER 0xffffffffu
// Node i of either tree from its two texels.
#define BVH_NODE_FROM(texels, i) \
    bvh_node_from(texelFetch(texels, int(2u * (i))), texelFetch(texels, int(2u * (i) + 1u)))
BvhNode bvh_node_from(uvec4 a, uvec4 b) {
    return BvhNode(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w);
}
BvhNode threaded_node(uint i) {
    return BVH_NODE_FROM(threaded_node_texels, i);
}
BvhNode bvh_node(uint i) {
    return BVH_NODE_FROM(bvh_node_texels, i);
}
// The lights' visible fractions at each pixel, summed by the renderer from their passes of slices
// (gpu::slice_passes): a layer a light (ROWS_OF_*), each row-major (pc.framebuffer_size.x a row), read where
// lights.light_rows.w has the light's READ_* bit; or one unused value. Negative where the pixel's slices could not
// be taken (the grid's rays then).
layout(std430, set = 0, binding = 13) readonly buffer LightFractions {
    float light_fractions[];
};
// The passes' fraction of light `layer` (ROWS_OF_*) at this fragment's pixel.
#define PASSED_FRACTION(layer) \
    light_fractions[((layer) * uint(pc.framebuffer_size.y) + uint(gl_FragCoord.y)) * uint(pc.framebuffer_size.x) \
                    + uint(gl_FragCoord.x)]
// The walk's records (vertex indices and material, as OccluderTriangles) in the tree's leaf order, one RGBA32UI
// texel each: a buffer of their own, since with ray queries OccluderTriangles is in the acceleration structure's
// order (its masked hits read it by primitive index).
layout(set = 0, binding = 14) uniform usamplerBuffer walk_triangles;
#define WALK_RECORD(i) texelFetch(walk_triangles, int(i))
#endif

// Every measured BRDF table the scene's materials use, one after another, each 90 x 90 x 180 samples of rho
// [1/sr] as rgb (a unused: one 16-byte load per sample; gpu::layout::measured_tables); materials naming the same
// file share one copy. One zero sample where no material is measured.
layout(std430, set = 0, binding = 11) readonly buffer MeasuredBuffer {
    vec4 measured_values[];
};

// The textures' texels (gpu::texture_buffers; read by texture_filter.glsl with texelFetch: a plain load of what
// is stored, no filtering or conversion by the device). texels: the code tables (a code's linear value in x:
// CODE_TABLE_LINEAR + code, CODE_TABLE_SRGB + code), then the linear RGBA f32 levels; texel_codes: the 8-bit
// levels' RGBA codes. Uniform texel buffers rather than storage buffers, which lavapipe limits to 128 MiB.
layout(set = 0, binding = 7) uniform samplerBuffer texels;
layout(set = 0, binding = 16) uniform usamplerBuffer texel_codes;
#define TEXELS_LINEAR 0u
#define TEXELS_CODES_LINEAR 1u
#define TEXELS_CODES_SRGB 2u
#define CODE_TABLE_LINEAR 0u
#define CODE_TABLE_SRGB 256u

// Texture t's header at texture_table[t]: (first level entry, level count, sampler bits, 0); a level entry:
// (first texel in its buffer, width, height, TEXELS_*).
layout(std430, set = 0, binding = 8) readonly buffer TextureTable {
    uvec4 texture_table[];
};

// The sun's shadow map (depth, read texel by texel with texelFetch: no filtering by the device).
layout(set = 0, binding = 5) uniform sampler2D shadow_map;
// The disk lights' shadow maps, the same way.
layout(set = 0, binding = 6) uniform sampler2D disk_shadow_maps[MAX_DISK_MAPS];

layout(push_constant) uniform PushConstants {
    mat4 clip_from_world;   // world -> Vulkan clip space (f32, column-major)
    vec4 viewer;            // (eye, 1) for perspective; (unit direction towards the viewer, 0) for orthographic
    vec2 framebuffer_size;  // width, height [pixels]
    uint material;          // index into materials[]
    uint first_index;       // this draw's first index in indices[]
    int vertex_offset;      // added to every index of this draw
    uint sun_samples;       // grid side over the sun's disk for this draw's material (RenderSettings::shading_for)
    uint lobe_samples;      // side of its lobe grids under disk lights and the sky
} pc;

#endif

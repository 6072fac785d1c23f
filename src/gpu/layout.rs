//! Byte layouts shared with the shaders (std430), mirrored by `shaders/bindings.glsl`: change both together.

use bytemuck::{Pod, Zeroable};

use crate::scene::{AlphaMode, Brdf, Light, Lights, Material, Scene, TextureRef};
use crate::settings::RenderSettings;
use crate::shading::{DiskModel, Quantity, ShadingOptions, ShadowMapFilter, SunModel};
use crate::visibility::shadow_map::{DiskMapFrame, SunMapFrame};

pub const BRDF_LAMBERT: u32 = 0;
pub const BRDF_PHONG: u32 = 1;
pub const BRDF_BLINN_PHONG: u32 = 2;
pub const BRDF_WARD: u32 = 3;
pub const BRDF_MEASURED: u32 = 4;
pub const BRDF_GLTF: u32 = 5;
pub const LIGHT_ABSENT: u32 = 0;
pub const SUN_DISK: u32 = 1;
pub const SUN_DELTA: u32 = 2;
pub const DISKS_EXACT: u32 = 1;
pub const DISKS_SMALL_SOURCE: u32 = 2;
pub const SKY_PRESENT: u32 = 1;
pub const SHADOWS_NONE: u32 = 0;
pub const SHADOWS_RAY: u32 = 1;
pub const SHADOWS_MAP: u32 = 2;
/// The lights' visibility rule with shadow rays (`VARIANT_VISIBILITY`): the located grid, or slices
/// (shaders/slices.glsl, a fragment module of their own).
pub const VISIBILITY_GRID: u32 = 0;
pub const VISIBILITY_SLICES: u32 = 1;
/// What the sun's cells answer in a frame with shadow rays and a sun (`VARIANT_SUN_CELLS`; `gpu::sun_cells`):
/// nothing (no cells), every point's sun rays, or those of the points under at most
/// `visibility::sun_cells::MAX_SUN_CELL_TRIANGLES` of their cell's triangles.
pub const SUN_CELLS_NONE: u32 = 0;
pub const SUN_CELLS_COMPLETE: u32 = 1;
pub const SUN_CELLS_PARTIAL: u32 = 2;
/// Where a draw with shadow rays shades the pixels whose lights are neither proven wholly visible nor wholly hidden
/// (`VARIANT_PENUMBRAE`): itself, or a second draw of the scene after it (the first then discards them before any
/// ray but the sun cells'). `TREE_LATER`: itself, but a pixel whose ray would walk the occluders' tree is marked
/// instead, and the marked pixels drawn once more with the tree ([`ShaderVariant::tree_later`]).
pub const PENUMBRAE_HERE: u32 = 0;
pub const PENUMBRAE_LATER: u32 = 1;
pub const TREE_LATER: u32 = 2;
/// How the first of two draws marks the pixels it leaves to the second (`VARIANT_MARK`): by their colour alone (a
/// pass between the draws then sets the stencil where the colour holds the mark), or by the stencil value its
/// fragments write besides (`VK_EXT_shader_stencil_export`; no pass between the draws). `gpu::second_draw`.
pub const MARK_BY_COLOUR: u32 = 0;
pub const MARK_BY_STENCIL: u32 = 1;
/// The specialization constants of a variant ([`ShaderVariant::constants`]).
pub const VARIANT_CONSTANTS: usize = 12;
/// What the fragment shader writes (`VARIANT_QUANTITY`): radiance, or the irradiance at the surface.
pub const QUANTITY_RADIANCE: u32 = 0;
pub const QUANTITY_IRRADIANCE: u32 = 1;
/// One pass of a light's slices (`gpu::slice_passes`): the fragment writes its rows' visible and unoccluded weights.
pub const QUANTITY_LIGHT_ROWS: u32 = 2;
/// `LightsHeader::light_rows[2]`, the light a pass slices, and its layer of the fractions the passes leave: the sky,
/// the sun, disk light `i` at `ROWS_OF_DISK + i`.
pub const ROWS_OF_SKY: u32 = 0;
pub const ROWS_OF_SUN: u32 = 1;
pub const ROWS_OF_DISK: u32 = 2;
/// `LightsHeader::light_rows[3]`'s bits: the lights whose visible fractions the frame reads from the passes' sums
/// rather than taking them itself.
pub const READ_SKY: u32 = 1;
pub const READ_SUN: u32 = 2;
pub const READ_DISKS: u32 = 4;
/// Disk lights with a shadow map of their own (`MAX_DISK_MAPS` in the shaders).
pub const MAX_DISK_MAPS: usize = crate::shading::MAPPED_DISKS;
pub const WRAP_REPEAT: u32 = 0;
pub const WRAP_MIRRORED_REPEAT: u32 = 1;
pub const WRAP_CLAMP_TO_EDGE: u32 = 2;
pub const FILTER_NEAREST: u32 = 0;
pub const FILTER_LINEAR: u32 = 1;
pub const MIP_NONE: u32 = 0;
pub const MIP_NEAREST: u32 = 1;
pub const MIP_LINEAR: u32 = 2;
/// A material slot without a texture.
pub const NO_TEXTURE: u32 = u32::MAX;

/// What one pipeline variant's fragment shader computes: its specialization constants (`VARIANT_*` in
/// `shaders/bindings.glsl`, constant ids 0 to 11). The shader keeps only the code these select; `shadows` also
/// selects the module (with ray queries or without).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ShaderVariant {
    /// `BRDF_*` of the draw's material.
    pub brdf: u32,
    /// `LIGHT_ABSENT`, `SUN_DISK` or `SUN_DELTA`.
    pub sun: u32,
    /// `LIGHT_ABSENT`, `DISKS_EXACT` or `DISKS_SMALL_SOURCE`.
    pub disks: u32,
    /// `LIGHT_ABSENT` or `SKY_PRESENT`.
    pub sky: u32,
    /// `SHADOWS_NONE`, `SHADOWS_RAY` or `SHADOWS_MAP`.
    pub shadows: u32,
    /// `shading::surface::SURFACE_*` bits of the draw's material (0: untextured, opaque, not emissive).
    pub surface: u32,
    /// `QUANTITY_RADIANCE`, `QUANTITY_IRRADIANCE`, or `QUANTITY_LIGHT_ROWS` (`gpu::slice_passes`).
    pub quantity: u32,
    /// `VISIBILITY_GRID` or `VISIBILITY_SLICES` with shadow rays (`VISIBILITY_GRID` without: nothing to take), so
    /// that the grid's pipelines leave the slices' code out (on Mesa 25 with ray queries it cost their creation 0.4 s).
    pub visibility: u32,
    /// With shadow rays, 1 where a material of the scene is alpha-masked (the rays then test their hits' alpha), else
    /// 0; always 0 without shadow rays, so that such scenes share the other variants.
    pub occluders_masked: u32,
    /// With shadow rays and a sun, what the frame's sun cells answer (`SUN_CELLS_*`); `SUN_CELLS_NONE` otherwise.
    pub sun_cells: u32,
    /// `PENUMBRAE_HERE`, `PENUMBRAE_LATER` in the first of a frame's two draws ([`ShaderVariant::first_draw`]), or
    /// `TREE_LATER` ([`ShaderVariant::tree_later`]).
    pub penumbrae: u32,
    /// In a first draw (`PENUMBRAE_LATER`), `MARK_BY_STENCIL` where the device exports stencil values from the
    /// fragment shader; `MARK_BY_COLOUR` otherwise.
    pub mark: u32,
}

impl ShaderVariant {
    /// The variant for a material (its `MaterialGpu::kind[0]`) under these lights, in a scene that has alpha-masked
    /// materials or not, in a frame whose sun cells answer `sun_cells` (`SUN_CELLS_*`).
    pub fn new(
        brdf: u32,
        surface: u32,
        lights: &Lights,
        shading: &ShadingOptions,
        (shadows, scene_masked, sun_cells): (u32, bool, u32),
    ) -> Self {
        // Each kind of light present, with its model: the shader compiles only their terms.
        let (mut sun, mut disks, mut sky) = (LIGHT_ABSENT, LIGHT_ABSENT, LIGHT_ABSENT);
        for light in lights.iter() {
            match light {
                Light::Sun(_) => {
                    sun = match shading.sun {
                        SunModel::Disk => SUN_DISK,
                        SunModel::Delta => SUN_DELTA,
                    }
                }
                Light::Disk { .. } => {
                    disks = match shading.disk {
                        DiskModel::Exact => DISKS_EXACT,
                        DiskModel::SmallSource => DISKS_SMALL_SOURCE,
                    }
                }
                Light::Sky(_) => sky = SKY_PRESENT,
            }
        }
        let quantity = match shading.quantity {
            Quantity::Radiance => QUANTITY_RADIANCE,
            Quantity::Irradiance => QUANTITY_IRRADIANCE,
        };
        let visibility = match shading.visibility_rule {
            crate::shading::VisibilityRule::Slices if shadows == SHADOWS_RAY => VISIBILITY_SLICES,
            _ => VISIBILITY_GRID,
        };
        let occluders_masked = (shadows == SHADOWS_RAY && scene_masked) as u32;
        let sun_cells = if shadows == SHADOWS_RAY && sun != LIGHT_ABSENT { sun_cells } else { SUN_CELLS_NONE };
        let (penumbrae, mark) = (PENUMBRAE_HERE, MARK_BY_COLOUR);
        Self {
            brdf,
            sun,
            disks,
            sky,
            shadows,
            surface,
            quantity,
            visibility,
            occluders_masked,
            sun_cells,
            penumbrae,
            mark,
        }
    }

    /// The variant of this one for the first of two draws, which shades only the pixels whose lights the cheap
    /// proofs settle (the sun's cells, the disk lights' walk: wholly visible or wholly hidden) and leaves the rest
    /// to this variant drawn after it; `None` where such a draw would settle no pixel, and the frame draws once:
    /// without shadow rays or by slices, with the sky (whose grid every pixel casts), small-source disks or a sun
    /// without cells (whose rays go through the tree), and in the slices' passes. It marks those pixels by the
    /// stencil too where the device can (`stencil_export`).
    pub fn first_draw(&self, stencil_export: bool) -> Option<Self> {
        let sun_settles = self.sun == LIGHT_ABSENT || self.sun_cells != SUN_CELLS_NONE;
        let something_settled = (self.sun == SUN_DISK && self.sun_cells != SUN_CELLS_NONE) || self.disks == DISKS_EXACT;
        let first = self.shadows == SHADOWS_RAY
            && self.visibility == VISIBILITY_GRID
            && self.quantity != QUANTITY_LIGHT_ROWS
            && self.sky == LIGHT_ABSENT
            && self.disks != DISKS_SMALL_SOURCE
            && sun_settles
            && something_settled;
        let mark = if stencil_export { MARK_BY_STENCIL } else { MARK_BY_COLOUR };
        first.then_some(Self { penumbrae: PENUMBRAE_LATER, mark, ..*self })
    }

    /// This variant without the occluders' tree: where the only shadow rays it casts are the sun's (no disk light,
    /// no sky, the located grid) and the frame's sun cells are partial, the tree serves only the points under more
    /// of their cell's triangles than the cells answer for whose sun cone lists more than they keep
    /// (shaders/sun_cells.glsl), which few scenes have (none of models/). Such a pixel is marked
    /// (`LEFT_TO_SECOND_DRAW`) rather than shaded, and the marked pixels alone are drawn once more with this
    /// variant after the frame (`gpu::second_draw`, "The tree, once more where needed"): every frame without one skips the tree's compilation, which on lavapipe costs as
    /// much as the rest of the shader (docs/platform.md, "What the driver compiles"). `None` elsewhere.
    pub fn tree_later(&self) -> Option<Self> {
        let only_the_suns_rays = self.shadows == SHADOWS_RAY
            && self.sun_cells == SUN_CELLS_PARTIAL
            && self.disks == LIGHT_ABSENT
            && self.sky == LIGHT_ABSENT
            && self.visibility == VISIBILITY_GRID
            && self.quantity != QUANTITY_LIGHT_ROWS
            && self.penumbrae == PENUMBRAE_HERE;
        only_the_suns_rays.then_some(Self { penumbrae: TREE_LATER, ..*self })
    }

    /// Whether a draw of this variant reads the occluders' tree (`gpu::shadow_bvh`): its rays' walk where the
    /// device casts no ray queries (`rays_walk_bvh`), unless its only rays are the sun's through its cells and the
    /// tree is not theirs to walk (complete cells; partial ones in the first of two draws or with the tree later);
    /// the disk lights' walk that proves their rays clear (`visibility::disk_cone`); the slices' gathering.
    pub fn reads_the_tree(&self, rays_walk_bvh: bool) -> bool {
        if self.shadows != SHADOWS_RAY {
            return false;
        }
        let cells_alone = self.disks == LIGHT_ABSENT
            && self.sky == LIGHT_ABSENT
            && self.visibility == VISIBILITY_GRID
            && (self.sun_cells == SUN_CELLS_COMPLETE
                || (self.sun_cells == SUN_CELLS_PARTIAL && self.penumbrae != PENUMBRAE_HERE));
        self.disks != LIGHT_ABSENT || self.visibility == VISIBILITY_SLICES || (rays_walk_bvh && !cells_alone)
    }

    /// The variant in words, for `-v` and the start-up bench: "Ward · disk sun · exact disks · sky · shadow maps ·
    /// surface 0b00101 · radiance".
    pub fn describe(&self) -> String {
        let pick = |v: u32, names: &[&str]| names.get(v as usize).copied().unwrap_or("?").to_string();
        let mut parts = vec![pick(self.brdf, &["Lambert", "Phong", "Blinn-Phong", "Ward", "measured", "glTF"])];
        let lights = [
            pick(self.sun, &["", "disk sun", "delta sun"]),
            pick(self.disks, &["", "exact disks", "small-source disks"]),
            pick(self.sky, &["", "sky"]),
        ];
        parts.extend(lights.into_iter().filter(|l| !l.is_empty()));
        parts.push(match (self.shadows, self.visibility) {
            (SHADOWS_RAY, VISIBILITY_SLICES) => "shadow rays by slices".into(),
            (s, _) => pick(s, &["no shadows", "shadow rays", "shadow maps"]),
        });
        if self.surface != 0 {
            parts.push(format!("surface {:#07b}", self.surface));
        }
        if self.occluders_masked != 0 {
            parts.push("alpha-masked occluders".into());
        }
        match self.sun_cells {
            SUN_CELLS_COMPLETE => parts.push("sun cells".into()),
            SUN_CELLS_PARTIAL => parts.push("sun cells, partly".into()),
            _ => {}
        }
        match self.penumbrae {
            PENUMBRAE_LATER if self.mark == MARK_BY_STENCIL => parts.push("penumbrae later, marked by stencil".into()),
            PENUMBRAE_LATER => parts.push("penumbrae later".into()),
            TREE_LATER => parts.push("tree later".into()),
            _ => {}
        }
        parts.push(pick(self.quantity, &["radiance", "irradiance", "a light's rows"]));
        parts.join(" · ")
    }

    /// The constants in `constant_id` order.
    pub fn constants(&self) -> [u32; VARIANT_CONSTANTS] {
        [
            self.brdf,
            self.sun,
            self.disks,
            self.sky,
            self.shadows,
            self.surface,
            self.quantity,
            self.visibility,
            self.occluders_masked,
            self.sun_cells,
            self.penumbrae,
            self.mark,
        ]
    }
}

/// One vertex: world position \[m\], unit normal, unit tangent and handedness, interleaved (`FLOATS_PER_VERTEX` =
/// 10 floats and the `VERTEX_*` offsets in the shaders). What only textured materials read is in
/// [`SurfaceVertex`], a buffer of its own, so that untextured draws fetch what they did before textures existed
/// (and a storage buffer of `maxStorageBufferRange`, 128 MiB on lavapipe, holds 3.3 M vertices).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub tangent: [f32; 4],
}

/// A vertex's surface attributes: TEXCOORD_0, TEXCOORD_1 and COLOR_0 (white where the mesh has none)
/// (`FLOATS_PER_SURFACE_VERTEX` = 8 and the `SURFACE_VERTEX_*` offsets in the shaders). With [`Vertex`], the
/// reference's `cpu::clip::ATTRIBUTES`, in the same order.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SurfaceVertex {
    pub uv0: [f32; 2],
    pub uv1: [f32; 2],
    pub color: [f32; 4],
}

/// A material's use of a texture (`TextureRefGpu`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TextureRefGpu {
    pub row0: [f32; 4],
    pub row1: [f32; 4],
    /// Texture index (`NO_TEXTURE` for none), TEXCOORD set.
    pub texture: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MaterialGpu {
    pub kd: [f32; 4],
    pub ks: [f32; 4],
    pub params: [f32; 4],
    pub kind: [u32; 4],
    /// Base colour factor (rgb, alpha).
    pub base: [f32; 4],
    /// Metallic and roughness factors, normal-map scale, alpha cutoff.
    pub pbr: [f32; 4],
    /// Emitted radiance [W/(m²·sr)] before the emissive texture.
    pub emission: [f32; 4],
    /// glTF's dielectric Fresnel: f0 (rgb) and f90.
    pub specular: [f32; 4],
    /// Base colour, metallic-roughness, normal, emissive.
    pub tex: [TextureRefGpu; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SunGpu {
    pub direction: [f32; 4],
    pub irradiance: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DiskGpu {
    pub center_radius: [f32; 4],
    pub direction: [f32; 4],
    pub radiance: [f32; 4],
}

/// The fixed head of the light buffer; `DiskGpu` records follow it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightsHeader {
    pub sun: SunGpu,
    pub sky: [f32; 4],
    /// Disk count, unused, the probe loop's iterations (`loop_budget::LOOP_PROBE_ITERATIONS`; more in a frame's
    /// probe, `frame_probe`), samples per axis for disks and the sky.
    pub counts: [u32; 4],
    /// Samples per axis over the sun's disk, shadow samples per axis (visible fractions), the shadow maps'
    /// filter (1 PCSS, 2 nearest); the rest unused.
    pub sampling: [u32; 4],
    /// World → the sun's shadow map (column-major), `visibility::shadow_map`.
    pub sun_map_from_world: [f32; 16],
    /// Texel side \[m\], depth extent \[m\], size \[texels\], 1 if the map was rendered this frame (else 0).
    pub sun_map: [f32; 4],
    /// World → each of the first disks' shadow maps (column-major), `visibility::shadow_map::fit_disk_map`.
    pub disk_map_from_world: [[f32; 16]; MAX_DISK_MAPS],
    /// tan of the half field of view, near \[m\], far \[m\], size \[texels\] (0: no map this frame).
    pub disk_map: [[f32; 4]; MAX_DISK_MAPS],
    /// The lights' slices in passes (`gpu::slice_passes`): a pass's first row, its rows and its light (`ROWS_OF_*`);
    /// the lights whose fractions the frame reads (`READ_*` bits).
    pub light_rows: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PushConstants {
    pub clip_from_world: [f32; 16],
    pub viewer: [f32; 4],
    pub framebuffer_size: [f32; 2],
    pub material: u32,
    pub first_index: u32,
    pub vertex_offset: i32,
    /// Grid side over the sun's disk for this draw's material (`RenderSettings::shading_for`).
    pub sun_samples_per_axis: u32,
    /// Side of its lobe grids under disk lights and the sky.
    pub lobe_samples_per_axis: u32,
    pub _pad: u32,
}

/// The measured buffer's floats (binding 11): each distinct table the materials use once (materials naming the
/// same file share its `Arc`, and here its one copy), one after another, each sample as RGBA (A: 1 for a valid
/// sample, 0 for a missing one, the linear lookup's weight; one 16-byte load per sample, measured 20–24% faster
/// frames on lavapipe than three scalar loads, for 4/3 the memory); and per
/// material the offset \[samples\] of its table (0 for the others). One zero sample where no material is measured
/// (a binding needs a buffer).
pub fn measured_tables(materials: &[Material]) -> (Vec<f32>, Vec<u32>) {
    let mut data: Vec<f32> = Vec::new();
    let mut seen: Vec<(&std::sync::Arc<crate::scene::measured::MeasuredBrdf>, u32)> = Vec::new();
    let offsets = materials
        .iter()
        .map(|m| match &m.brdf {
            Brdf::Measured { table, .. } => match seen.iter().find(|(t, _)| std::sync::Arc::ptr_eq(t, table)) {
                Some(&(_, offset)) => offset,
                None => {
                    let offset = (data.len() / 4) as u32;
                    let valid = |i: usize| if table.is_missing(i) { 0.0 } else { 1.0 };
                    let samples = table.values.chunks_exact(3).enumerate();
                    data.extend(samples.flat_map(|(i, rgb)| [rgb[0], rgb[1], rgb[2], valid(i)]));
                    seen.push((table, offset));
                    offset
                }
            },
            _ => 0,
        })
        .collect();
    if data.is_empty() {
        data.extend([0.0; 4]);
    }
    (data, offsets)
}

/// A material's record; `measured_offset`: where its measured table (if any) starts in the measured buffer
/// \[samples\] ([`measured_tables`]).
pub fn material_gpu(m: &Material, measured_offset: u32) -> MaterialGpu {
    let (kd, ks) = (m.brdf.kd(), m.brdf.ks());
    let (kind, exponent, params) = match m.brdf {
        Brdf::Lambert { .. } => (BRDF_LAMBERT, 0.0, [0.0; 4]),
        Brdf::Phong { exponent, .. } => (BRDF_PHONG, exponent, [0.0; 4]),
        Brdf::BlinnPhong { exponent, .. } => (BRDF_BLINN_PHONG, exponent, [0.0; 4]),
        Brdf::Ward { alpha_x, alpha_y, .. } => (BRDF_WARD, 0.0, [alpha_x, alpha_y, 0.0, 0.0]),
        Brdf::Measured { ref table, lookup } => {
            let f = table.floor;
            let nearest = f32::from(u8::from(lookup == crate::shading::measured::MeasuredLookup::Nearest));
            (BRDF_MEASURED, table.lobe_width, [f[0], f[1], f[2], nearest])
        }
        Brdf::Gltf { metallic, alpha, .. } => (BRDF_GLTF, 0.0, [alpha, metallic, 0.0, 0.0]),
    };
    let slot = |r: Option<&TextureRef>| match r {
        Some(r) => {
            let t = r.transform;
            TextureRefGpu {
                row0: [t[0], t[1], t[2], 0.0],
                row1: [t[3], t[4], t[5], 0.0],
                texture: [r.texture as u32, r.tex_coord, 0, 0],
            }
        }
        None => TextureRefGpu { row0: [0.0; 4], row1: [0.0; 4], texture: [NO_TEXTURE, 0, 0, 0] },
    };
    let cutoff = match m.alpha {
        AlphaMode::Mask(c) => c,
        AlphaMode::Opaque | AlphaMode::Blend => 0.0,
    };
    // glTF's lobe reads its base colour here (the mapping writes the pixel's; shaders/surface.glsl), and its
    // dielectric's Fresnel (a material's own, also where the mapping follows textures).
    let (b, s) = match m.brdf {
        Brdf::Gltf { base_color, specular, .. } => (base_color, specular),
        Brdf::Lambert { .. }
        | Brdf::Phong { .. }
        | Brdf::BlinnPhong { .. }
        | Brdf::Ward { .. }
        | Brdf::Measured { .. } => (m.pbr.base_color, m.pbr.specular),
    };
    MaterialGpu {
        kd: [kd[0], kd[1], kd[2], 0.0],
        ks: [ks[0], ks[1], ks[2], exponent],
        params,
        kind: [kind, m.double_sided as u32, matches!(m.alpha, AlphaMode::Mask(_)) as u32, measured_offset],
        base: [b[0], b[1], b[2], m.base_alpha],
        pbr: [m.pbr.metallic, m.pbr.roughness, m.normal_texture.map_or(1.0, |(_, s)| s), cutoff],
        emission: [m.emission[0], m.emission[1], m.emission[2], 0.0],
        specular: [s.f0[0], s.f0[1], s.f0[2], s.f90],
        tex: [
            slot(m.base_color_texture.as_ref()),
            slot(m.metallic_roughness_texture.as_ref()),
            slot(m.normal_texture.as_ref().map(|(t, _)| t)),
            slot(m.emissive_texture.as_ref()),
        ],
    }
}

/// The occluder-triangle records of binding 10 (`OccluderTriangles`), in the acceleration structure's primitive
/// order (the meshes' triangles in turn): global vertex indices (each mesh's `vertex_offsets` added) and the
/// material, bit 31 set where the mesh has vertex colours. Only scenes with alpha-masked materials on devices with
/// ray queries read them (`needed`); otherwise one dummy record.
pub fn occluder_records(scene: &Scene, vertex_offsets: &[i32], needed: bool) -> Vec<[u32; 4]> {
    let mut records = Vec::new();
    if needed {
        for (mesh, &offset) in scene.meshes.iter().zip(vertex_offsets) {
            let colors = if mesh.colors.is_empty() { 0 } else { 1 << 31 };
            let o = offset as u32;
            records.extend(
                mesh.indices.chunks_exact(3).map(|t| [t[0] + o, t[1] + o, t[2] + o, mesh.material as u32 | colors]),
            );
        }
    }
    if records.is_empty() {
        records.push([0; 4]);
    }
    records
}

/// The light buffer's bytes.
pub fn lights_bytes(
    lights: &Lights,
    shading: &ShadingOptions,
    sun_map: Option<(&SunMapFrame, u32)>,
    disk_maps: &[Option<(DiskMapFrame, u32)>],
) -> Vec<u8> {
    let filter = match shading.shadow_map_filter {
        ShadowMapFilter::Pcss => 1,
        ShadowMapFilter::Nearest => 2,
    };
    let mut disk_map_from_world = [[0.0f32; 16]; MAX_DISK_MAPS];
    let mut disk_map = [[0.0f32; 4]; MAX_DISK_MAPS];
    for (i, m) in disk_maps.iter().enumerate().take(MAX_DISK_MAPS) {
        if let Some((f, size)) = m {
            disk_map_from_world[i] = f.map_from_world.as_mat4().to_cols_array();
            disk_map[i] = [f.tan_half as f32, f.near as f32, f.far as f32, *size as f32];
        }
    }
    // Each light's record: the sun's and the sky's in the header (w = 1: present), the disks' after it.
    let (mut sun, mut sky, mut disks) = (SunGpu::zeroed(), [0.0; 4], Vec::new());
    for light in lights.iter() {
        match light {
            Light::Sun(s) => {
                sun = SunGpu {
                    direction: [s.direction.x, s.direction.y, s.direction.z, s.angular_diameter],
                    irradiance: [s.irradiance[0], s.irradiance[1], s.irradiance[2], 1.0],
                }
            }
            Light::Disk { disk: d, .. } => disks.push(DiskGpu {
                center_radius: [d.center.x, d.center.y, d.center.z, d.radius],
                direction: [d.direction.x, d.direction.y, d.direction.z, 0.0],
                radiance: [d.radiance[0], d.radiance[1], d.radiance[2], 0.0],
            }),
            Light::Sky(l) => sky = [l[0], l[1], l[2], 1.0],
        }
    }
    let header = LightsHeader {
        sun,
        sky,
        counts: [disks.len() as u32, 0, super::loop_budget::LOOP_PROBE_ITERATIONS, shading.samples_per_axis],
        sampling: [shading.sun_samples_per_axis, shading.shadow_samples_per_axis, filter, 0],
        sun_map_from_world: sun_map.map_or([0.0; 16], |(f, _)| f.map_from_world.as_mat4().to_cols_array()),
        sun_map: sun_map.map_or([0.0; 4], |(f, size)| [f.texel as f32, f.depth_extent as f32, size as f32, 1.0]),
        disk_map_from_world,
        disk_map,
        light_rows: [0, 0, ROWS_OF_SKY, 0],
    };
    let mut bytes = bytemuck::bytes_of(&header).to_vec();
    for disk in &disks {
        bytes.extend_from_slice(bytemuck::bytes_of(disk));
    }
    bytes
}

/// The light buffer's bytes (`lights_bytes`) with the slices' passes' word `light_rows` set.
pub fn with_light_rows(bytes: &[u8], light_rows: [u32; 4]) -> Vec<u8> {
    let mut bytes = bytes.to_vec();
    let at = std::mem::offset_of!(LightsHeader, light_rows);
    bytes[at..at + 16].copy_from_slice(bytemuck::bytes_of(&light_rows));
    bytes
}

/// The light buffer's bytes (`lights_bytes`) with `counts.z`, the probe loop's iterations (shaders/fragment.glsl,
/// `coverage_alpha`), set to `iterations`.
pub fn with_loop_probe(bytes: &[u8], iterations: u32) -> Vec<u8> {
    let mut bytes = bytes.to_vec();
    let at = std::mem::offset_of!(LightsHeader, counts) + 2 * std::mem::size_of::<u32>();
    bytes[at..at + 4].copy_from_slice(&iterations.to_ne_bytes());
    bytes
}

/// Push constants of one draw: the view, and where the draw's triangles start in the index and vertex buffers.
pub fn push_constants(settings: &RenderSettings, material: u32, first_index: u32, vertex_offset: i32) -> PushConstants {
    let shading = settings.shading_for(material as usize);
    PushConstants {
        clip_from_world: settings.clip_from_world().to_cols_array(),
        viewer: settings.viewer().to_array(),
        framebuffer_size: [settings.width as f32, settings.height as f32],
        material,
        first_index,
        vertex_offset,
        sun_samples_per_axis: shading.sun_samples_per_axis,
        lobe_samples_per_axis: shading.samples_per_axis,
        _pad: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glsl_constants_match() {
        let glsl = include_str!("../../shaders/bindings.glsl");
        let constants = [
            ("BRDF_LAMBERT", BRDF_LAMBERT),
            ("BRDF_PHONG", BRDF_PHONG),
            ("BRDF_BLINN_PHONG", BRDF_BLINN_PHONG),
            ("BRDF_WARD", BRDF_WARD),
            ("BRDF_MEASURED", BRDF_MEASURED),
            ("BRDF_GLTF", BRDF_GLTF),
            ("LIGHT_ABSENT", LIGHT_ABSENT),
            ("SUN_DISK", SUN_DISK),
            ("SUN_DELTA", SUN_DELTA),
            ("DISKS_EXACT", DISKS_EXACT),
            ("DISKS_SMALL_SOURCE", DISKS_SMALL_SOURCE),
            ("SKY_PRESENT", SKY_PRESENT),
            ("SHADOWS_NONE", SHADOWS_NONE),
            ("SHADOWS_RAY", SHADOWS_RAY),
            ("SHADOWS_MAP", SHADOWS_MAP),
            ("VISIBILITY_GRID", VISIBILITY_GRID),
            ("VISIBILITY_SLICES", VISIBILITY_SLICES),
            ("SUN_CELLS_NONE", SUN_CELLS_NONE),
            ("SUN_CELLS_COMPLETE", SUN_CELLS_COMPLETE),
            ("PENUMBRAE_HERE", PENUMBRAE_HERE),
            ("PENUMBRAE_LATER", PENUMBRAE_LATER),
            ("TREE_LATER", TREE_LATER),
            ("MARK_BY_COLOUR", MARK_BY_COLOUR),
            ("MARK_BY_STENCIL", MARK_BY_STENCIL),
            ("SUN_CELLS_PARTIAL", SUN_CELLS_PARTIAL),
            ("QUANTITY_RADIANCE", QUANTITY_RADIANCE),
            ("QUANTITY_IRRADIANCE", QUANTITY_IRRADIANCE),
            ("QUANTITY_LIGHT_ROWS", QUANTITY_LIGHT_ROWS),
            ("ROWS_OF_SKY", ROWS_OF_SKY),
            ("ROWS_OF_SUN", ROWS_OF_SUN),
            ("ROWS_OF_DISK", ROWS_OF_DISK),
            ("READ_SKY", READ_SKY),
            ("READ_SUN", READ_SUN),
            ("READ_DISKS", READ_DISKS),
            ("WRAP_REPEAT", WRAP_REPEAT),
            ("WRAP_MIRRORED_REPEAT", WRAP_MIRRORED_REPEAT),
            ("WRAP_CLAMP_TO_EDGE", WRAP_CLAMP_TO_EDGE),
            ("FILTER_NEAREST", FILTER_NEAREST),
            ("FILTER_LINEAR", FILTER_LINEAR),
            ("MIP_NONE", MIP_NONE),
            ("MIP_NEAREST", MIP_NEAREST),
            ("MIP_LINEAR", MIP_LINEAR),
            ("TEXELS_LINEAR", super::super::texture_buffers::TEXELS_LINEAR),
            ("TEXELS_CODES_LINEAR", super::super::texture_buffers::TEXELS_CODES_LINEAR),
            ("TEXELS_CODES_SRGB", super::super::texture_buffers::TEXELS_CODES_SRGB),
            ("CODE_TABLE_LINEAR", super::super::texture_buffers::CODE_TABLE_LINEAR),
            ("CODE_TABLE_SRGB", super::super::texture_buffers::CODE_TABLE_SRGB),
            ("SURFACE_EVAL", crate::shading::surface::SURFACE_EVAL),
            ("SURFACE_NORMAL_MAP", crate::shading::surface::SURFACE_NORMAL_MAP),
            ("SURFACE_EMISSION", crate::shading::surface::SURFACE_EMISSION),
            ("SURFACE_ALPHA_MASK", crate::shading::surface::SURFACE_ALPHA_MASK),
            ("SURFACE_COLORS", crate::shading::surface::SURFACE_COLORS),
        ];
        for (name, value) in constants {
            assert!(glsl.contains(&format!("#define {name} {value}u\n")), "bindings.glsl: {name} is not {value}u");
        }
        assert!(glsl.contains(&format!("#define MAX_DISK_MAPS {MAX_DISK_MAPS}u\n")));
        use super::super::loop_budget::{LOOP_BUDGET_SPENT, LOOP_PROBE_ITERATIONS};
        assert!(glsl.contains(&format!("#define LOOP_PROBE_ITERATIONS {LOOP_PROBE_ITERATIONS}u\n")));
        assert!(glsl.contains(&format!("#define LOOP_BUDGET_SPENT {LOOP_BUDGET_SPENT:.1}\n")));
        let overflowed = super::super::slice_gather::SLICES_OVERFLOWED;
        assert!(glsl.contains(&format!("#define SLICES_OVERFLOWED {overflowed:.1}\n")));
        let slices = include_str!("../../shaders/slices.glsl");
        let most = super::super::slice_gather::MAX_SLICE_TRIANGLES;
        assert!(slices.contains(&format!("#define MAX_SLICE_TRIANGLES {most}\n")));
        assert!(glsl.contains("#define NO_TEXTURE 0xffffffffu\n"));
        // The vertex layout: FLOATS_PER_VERTEX and each attribute's offset in floats.
        assert!(glsl.contains(&format!("#define FLOATS_PER_VERTEX {}u\n", std::mem::size_of::<Vertex>() / 4)));
        let surface = std::mem::size_of::<SurfaceVertex>() / 4;
        assert!(glsl.contains(&format!("#define FLOATS_PER_SURFACE_VERTEX {surface}u\n")));
        for (name, offset) in [
            ("VERTEX_POSITION", std::mem::offset_of!(Vertex, position)),
            ("VERTEX_NORMAL", std::mem::offset_of!(Vertex, normal)),
            ("VERTEX_TANGENT", std::mem::offset_of!(Vertex, tangent)),
            ("SURFACE_VERTEX_UV0", std::mem::offset_of!(SurfaceVertex, uv0)),
            ("SURFACE_VERTEX_UV1", std::mem::offset_of!(SurfaceVertex, uv1)),
            ("SURFACE_VERTEX_COLOR", std::mem::offset_of!(SurfaceVertex, color)),
        ] {
            assert!(glsl.contains(&format!("#define {name} {}u\n", offset / 4)), "bindings.glsl: {name}");
        }
        let variant_constants = [
            "VARIANT_BRDF",
            "VARIANT_SUN",
            "VARIANT_DISKS",
            "VARIANT_SKY",
            "VARIANT_SHADOWS",
            "VARIANT_SURFACE",
            "VARIANT_QUANTITY",
            "VARIANT_VISIBILITY",
            "VARIANT_OCCLUDERS_MASKED",
            "VARIANT_SUN_CELLS",
            "VARIANT_PENUMBRAE",
            "VARIANT_MARK",
        ];
        assert_eq!(
            variant_constants.len(),
            ShaderVariant::new(0, 0, &Default::default(), &Default::default(), (0, false, 0)).constants().len()
        );
        for (id, name) in variant_constants.iter().enumerate() {
            assert!(
                glsl.contains(&format!("layout(constant_id = {id}) const uint {name} ")),
                "{name} is not constant {id}"
            );
        }
    }

    /// Which draws read the occluders' tree: the walk is laid out for them alone, so a variant that walks while
    /// this says no would read the placeholders.
    #[test]
    fn the_tree_is_read_by_the_draws_that_walk_it() {
        let base = ShaderVariant {
            sun: SUN_DISK,
            shadows: SHADOWS_RAY,
            ..ShaderVariant::new(0, 0, &Default::default(), &Default::default(), (0, false, 0))
        };
        let partial = ShaderVariant { sun_cells: SUN_CELLS_PARTIAL, ..base };
        let complete = ShaderVariant { sun_cells: SUN_CELLS_COMPLETE, ..base };
        // The sun's rays alone: through complete cells never; through partial ones in the whole variant only.
        assert!(!complete.reads_the_tree(true) && partial.reads_the_tree(true) && base.reads_the_tree(true));
        assert!(!partial.tree_later().unwrap().reads_the_tree(true));
        assert!(!partial.first_draw(false).unwrap().reads_the_tree(true));
        // With ray queries the rays take the acceleration structure; the disk lights' walk and the slices still read it.
        assert!(!partial.reads_the_tree(false));
        let disks = ShaderVariant { disks: DISKS_EXACT, ..complete };
        assert!(disks.reads_the_tree(false) && disks.first_draw(false).unwrap().reads_the_tree(false));
        assert!(ShaderVariant { visibility: VISIBILITY_SLICES, ..complete }.reads_the_tree(false));
        let sky = ShaderVariant { sky: SKY_PRESENT, ..complete };
        assert!(sky.reads_the_tree(true) && !sky.reads_the_tree(false));
        assert!(!ShaderVariant { shadows: SHADOWS_MAP, ..disks }.reads_the_tree(true));
    }

    /// Every BRDF a variant can hold has its name in `describe` (what `-v` and the start-up bench print).
    #[test]
    fn every_variant_names_its_brdf() {
        let base = ShaderVariant::new(0, 0, &Default::default(), &Default::default(), (0, false, 0));
        for brdf in [BRDF_LAMBERT, BRDF_PHONG, BRDF_BLINN_PHONG, BRDF_WARD, BRDF_MEASURED, BRDF_GLTF] {
            let name = ShaderVariant { brdf, ..base }.describe();
            assert!(!name.contains('?'), "BRDF {brdf}: {name}");
        }
        assert!(ShaderVariant { brdf: BRDF_GLTF, ..base }.describe().starts_with("glTF · "));
    }

    #[test]
    fn sizes_match_std430() {
        assert_eq!(std::mem::size_of::<MaterialGpu>(), 320);
        assert_eq!(std::mem::offset_of!(MaterialGpu, tex), 128);
        assert_eq!(std::mem::size_of::<TextureRefGpu>(), 48);
        // The shader reads a material as texels of 16 bytes, its fields in this order (material_at).
        let glsl = include_str!("../../shaders/bindings.glsl");
        assert!(glsl.contains(&format!("#define MATERIAL_TEXELS {}u\n", std::mem::size_of::<MaterialGpu>() / 16)));
        for (field, texel) in [
            ("kd", std::mem::offset_of!(MaterialGpu, kd)),
            ("ks", std::mem::offset_of!(MaterialGpu, ks)),
            ("params", std::mem::offset_of!(MaterialGpu, params)),
            ("base", std::mem::offset_of!(MaterialGpu, base)),
            ("pbr", std::mem::offset_of!(MaterialGpu, pbr)),
            ("emission", std::mem::offset_of!(MaterialGpu, emission)),
            ("specular", std::mem::offset_of!(MaterialGpu, specular)),
        ] {
            let at = if texel == 0 { "at".to_string() } else { format!("at + {}", texel / 16) };
            let read = format!("g.{field} = uintBitsToFloat(texelFetch(material_texels, {at}));");
            assert!(glsl.contains(&read), "{read}");
        }
        assert!(glsl.contains(&format!(
            "g.kind = texelFetch(material_texels, at + {});",
            std::mem::offset_of!(MaterialGpu, kind) / 16
        )));
        assert_eq!(std::mem::size_of::<LightsHeader>(), 496);
        assert_eq!(std::mem::offset_of!(LightsHeader, light_rows), 480);
        assert_eq!(std::mem::offset_of!(LightsHeader, disk_map_from_world), 160);
        assert_eq!(std::mem::offset_of!(LightsHeader, disk_map), 416);
        assert_eq!(std::mem::offset_of!(LightsHeader, sun_map_from_world), 80);
        assert_eq!(std::mem::size_of::<DiskGpu>(), 48);
        assert_eq!(std::mem::size_of::<PushConstants>(), 112);
        assert_eq!(std::mem::offset_of!(PushConstants, framebuffer_size), 80);
        assert_eq!(std::mem::offset_of!(PushConstants, vertex_offset), 96);
        assert_eq!(std::mem::offset_of!(PushConstants, sun_samples_per_axis), 100);
        assert_eq!(std::mem::offset_of!(PushConstants, lobe_samples_per_axis), 104);
        assert_eq!(std::mem::size_of::<Vertex>(), 40);
        assert_eq!(std::mem::size_of::<SurfaceVertex>(), 32);
    }
}

//! The GPU renderer: upload a scene, draw it offscreen, read the radiance back into an [`Image`].

use std::sync::Arc;
use std::time::{Duration, Instant};

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::accel::SceneAccel;
use super::commands::Commands;
use super::context::{ContextOptions, Device, Interpolation, ValidationLog};
use super::device_info::DeviceInfo;
use super::error::GpuError;
use super::frame_probe;
use super::layout::{
    lights_bytes, material_gpu, measured_tables, occluder_records, push_constants, with_light_rows, MaterialGpu,
    PushConstants, ShaderVariant, SurfaceVertex, Vertex, BRDF_LAMBERT, DISKS_EXACT, LIGHT_ABSENT, MAX_DISK_MAPS,
    QUANTITY_LIGHT_ROWS, ROWS_OF_SKY, SHADOWS_MAP, SHADOWS_NONE, SHADOWS_RAY, SUN_CELLS_COMPLETE, SUN_CELLS_NONE,
    SUN_CELLS_PARTIAL, SUN_DISK,
};
use super::memory::{image_barrier, Buffer, Image2d, TexelBuffer};
use super::pipeline::{CreatedPipeline, ScenePipeline, ShadowRays, COLOR_FORMAT};
use super::second_draw::{self, MarkPass, Tests, SCENE_DEPTH_STENCIL_FORMAT};
use super::shaders;
use super::shadow_bvh::{BvhNodeGpu, WalkSource};
use super::shadow_map::DepthMap;
use super::slice_passes;
use super::texture_buffers::TextureLayout;
use crate::film::{rgba32f_bytes, Image};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::surface::{surface_flags, SURFACE_ALPHA_MASK};
use crate::shading::visibility::MAX_LOCATED_GRID;
use crate::shading::{Shadows, VisibilityRule};
use crate::visibility::shadow_map::{fit_disk_map, fit_sun_map, DiskMapFrame};
use crate::visibility::sun_cells::{SunCells, MAX_SUN_CELL_TRIANGLES};
use crate::visibility::ShadowChoice;
use bytemuck::Zeroable;

/// Wall-clock time of the set-up phases \[s\].
#[derive(Clone, Copy, Debug, Default)]
pub struct SetupTimings {
    /// Loader, instance, device and allocator creation.
    pub instance: Duration,
    /// GLSL → SPIR-V (shaderc) and shader modules; pipelines are created per variant at first use. Runs on other
    /// threads at the same time as `instance`: the two overlap.
    pub shader_compile: Duration,
}

/// Wall-clock time of the phases of one frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimings {
    /// Laying out what the shadow rays read this frame: the sun's cells, and the occluders' BVH where a ray may walk
    /// it (its first frame only).
    pub shadow_setup: Duration,
    /// Creating the pipeline variants this frame needs that no earlier frame created (the device compiles the
    /// specialized shaders here; zero once they exist).
    pub pipelines: Duration,
    /// Recording, submitting and waiting for the draw (the frame time).
    pub render: Duration,
    /// Copying the colour target to host memory and into the [`Image`].
    pub readback: Duration,
    /// The lights whose visible fractions the frame read from their passes of slices (`slice_passes::read_bits`:
    /// `READ_SKY`, `READ_SUN`, `READ_DISKS`), 0 where it took every light itself.
    pub lights_in_passes: u32,
    /// The frame's probe (`frame_probe`), where one was drawn first.
    pub probe: Option<frame_probe::Probe>,
    /// The pixels whose sun rays needed the occluders' tree in a frame drawn without it
    /// (`ShaderVariant::tree_later`), drawn once more with it (their time is in `pipelines` and `render`).
    pub tree_redrawn: Option<usize>,
}

/// What a frame draws besides the lights' passes: the shadow maps' transforms (world → map) where the technique
/// is `map` (the sun's, and the first disk lights', aligned with `Renderer::disk_maps`), with the pipelines that
/// draw each mesh into them, and the scene pass's pipelines, a draw each.
struct FrameDraws<'a> {
    sun_map: Option<glam::DMat4>,
    disk_maps: Vec<Option<glam::DMat4>>,
    map_pipelines: &'a [vk::Pipeline],
    /// Each draw's pipeline: its first draw's where it has one (`ShaderVariant::first_draw`), else its own.
    draw_pipelines: &'a [vk::Pipeline],
    /// Each draw's pipeline for the second draw of the scene, null where its first draw shaded every pixel.
    second_pipelines: &'a [vk::Pipeline],
    /// Whether the scene pass stores its depth and stencil for a draw of the marked pixels after it
    /// (`Renderer::record_marked_pass`).
    keep_depth: bool,
}

/// A scene's geometry and materials on the device.
pub struct GpuScene {
    // The acceleration structure goes before the buffers it was built from.
    accel: Option<SceneAccel>,
    vertices: Option<Buffer>,
    indices: Option<Buffer>,
    materials: TexelBuffer,
    /// Every texture's levels (`texture_buffers`): linear RGBA f32 after the code tables, 8-bit codes, and the
    /// texture table (headers and level records).
    texels: TexelBuffer,
    texel_codes: TexelBuffer,
    texture_table: Buffer,
    /// Texture coordinates and colours per vertex (`SurfaceVertex`), read by textured materials.
    surface_vertices: Buffer,
    /// Per acceleration-structure triangle: vertex indices and material, for alpha-masked shadow-ray hits.
    occluder_triangles: Buffer,
    /// Every vertex as three texels (binding 17): what the fragment shader reads of its triangle, and the walks
    /// of the occluders' corners.
    vertex_texels: TexelBuffer,
    /// One dummy BVH node (binding 12 until the walk is laid out).
    bvh_nodes: TexelBuffer,
    /// Where the pipelines have shadow rays: what the walk is laid out from, and, once a render walks, its
    /// buffers (the nodes, the occluder records in leaf order, the nodes in depth-first order), which then take
    /// bindings 12, 14 and 18.
    walk_source: Option<WalkSource>,
    walk: std::cell::OnceCell<(TexelBuffer, TexelBuffer, TexelBuffer)>,
    /// One dummy record (binding 14 until the walk is laid out).
    no_walk_records: TexelBuffer,
    /// The measured BRDF tables (`layout::measured_tables`).
    measured: Buffer,
    draws: Vec<Draw>,
    /// Whether any triangle can occlude a light from a visible surface (`visibility::can_occlude`).
    can_occlude: bool,
    /// Whether a material of the scene is alpha-masked (`Scene::has_alpha_masks`): shadow rays then test their
    /// hits' alpha (the variants' `occluders_masked`).
    masked: bool,
    /// The scene's bounds (the sun's shadow map is fitted to them).
    bounds: Option<crate::scene::Aabb>,
    /// The fewest rows (`visibility::slice_rows`) at which a frame of this scene that sliced the sun and disk lights
    /// itself ran out of the loop budget (`u32::MAX`: none has): a render with as many takes them in passes from
    /// the start (`slice_passes`) rather than draw a frame that would be cut short (a study's rungs only grow).
    passes_from_rows: std::cell::Cell<u32>,
}

impl GpuScene {
    /// Whether the scene can shadow itself (`visibility::can_occlude`, decided at upload).
    pub fn can_occlude(&self) -> bool {
        self.can_occlude
    }
}

struct Draw {
    first_index: u32,
    index_count: u32,
    vertex_offset: i32,
    material: u32,
    /// The material's `BRDF_*` kind: which pipeline variant draws it.
    brdf: u32,
    /// What the material needs per pixel (`shading::surface::SURFACE_*`), also a variant constant.
    surface: u32,
    double_sided: bool,
}

struct Target {
    color: Image2d,
    depth: Image2d,
    readback: Buffer,
}

/// Renders scenes through Vulkan. Owns its device; everything is released when it is dropped.
pub struct Renderer {
    // Field order is drop order: everything that uses the device goes before `dev`.
    target: Option<Target>,
    lights: Option<Buffer>,
    /// The lights' fractions from their passes of slices (`slice_passes`) of the last frame that took them, and the
    /// one unused value bound at 13 where a frame takes none.
    light_fractions: Option<Buffer>,
    no_light_fractions: Buffer,
    /// The sun's cells of the last frame with shadow rays and a sun (`sun_cells`), and the header bound at 15 where
    /// a frame has none.
    sun_cells: Option<TexelBuffer>,
    no_sun_cells: TexelBuffer,
    sun_map: DepthMap,
    /// The first disk lights' shadow maps (`MAX_DISK_MAPS`).
    disk_maps: Vec<DepthMap>,
    pipeline: ScenePipeline,
    /// The mark between a frame's two draws (`second_draw`).
    mark: MarkPass,
    commands: Commands,
    setup: SetupTimings,
    interpolation: Interpolation,
    /// `ContextOptions::one_draw` (diagnostics).
    one_draw: bool,
    dev: Arc<Device>,
}

impl Renderer {
    /// Creates the device and loads the shaders: SPIR-V built ahead of time (about 0.5 ms), or, with
    /// `SUNSHADE_SHADER_DIR`, compiled at run time while the device is created (shaderc's fixed cost is ~75 ms per
    /// stage here, the two stages compile on two threads, and the interpolation mode is guessed, f64 unless asked
    /// otherwise, and compiled again only when the device turns out to lack f64).
    pub fn new(options: &ContextOptions) -> Result<Self, GpuError> {
        let guess = options.interpolation.unwrap_or(Interpolation::BarycentricF64);
        // Modules built ahead of time take well under a millisecond to load, after the device is known; only a
        // run-time compilation is worth overlapping with device creation.
        let compile_at_run_time = std::env::var_os(shaders::SHADER_DIR_VAR).is_some();
        let (dev, instance, compiled, compile_time) = std::thread::scope(|s| {
            let compiling = compile_at_run_time.then(|| {
                s.spawn(|| {
                    let t = Instant::now();
                    let stages = compile_stages(guess, options.naive_math);
                    (stages, t.elapsed())
                })
            });
            let t = Instant::now();
            let dev = Device::new(options);
            let instance = t.elapsed();
            let (stages, elapsed) = match compiling {
                Some(c) => {
                    let (stages, elapsed) = c.join().expect("the shader compiler thread panicked");
                    (Some(stages), elapsed)
                }
                None => (None, std::time::Duration::ZERO),
            };
            (dev, instance, stages, elapsed)
        });
        let dev = dev?;
        if options.whole_shaders && !dev.info.stencil_export {
            // The shadow rays' whole modules declare the stencil output that the specializer removes from the
            // pipelines that do not write it.
            return Err(GpuError::Unsupported(format!(
                "whole shaders (a diagnostic) need VK_EXT_shader_stencil_export, which {} does not have here",
                dev.info.name
            )));
        }
        let t1 = Instant::now();
        let interpolation = match options.interpolation {
            Some(Interpolation::BarycentricF64) if !dev.info.shader_float64 => {
                return Err(GpuError::Unsupported(format!(
                    "{} has no shaderFloat64 for f64 interpolation",
                    dev.info.name
                )));
            }
            Some(i) => i,
            None if dev.info.shader_float64 => Interpolation::BarycentricF64,
            None => Interpolation::BarycentricF32,
        };
        let (vs, fs) = match compiled {
            Some(stages) if interpolation == guess => stages?,
            _ => compile_stages(interpolation, options.naive_math)?,
        };
        // The fragment shader with shadow rays: by ray queries where the device has them, else by walking the
        // occluders' BVH in the shader (not with the naive-math diagnostic); without and with the slices' code.
        let rays = if options.naive_math {
            None
        } else {
            let (define, kind) = if dev.info.ray_query {
                ("SUNSHADE_RAY_QUERY", ShadowRays::Query)
            } else {
                ("SUNSHADE_RAY_BVH", ShadowRays::Bvh)
            };
            let words = shaders::stage_spirv("scene.frag", &[interpolation_define(interpolation), define])
                .map_err(GpuError::ShaderCompile)?;
            let sliced =
                shaders::stage_spirv("scene.frag", &[interpolation_define(interpolation), define, "SUNSHADE_SLICES"])
                    .map_err(GpuError::ShaderCompile)?;
            Some((words, sliced, kind))
        };
        let shadow_mask = shaders::stage_spirv("shadow_mask.frag", &[interpolation_define(interpolation)])
            .map_err(GpuError::ShaderCompile)?;
        let pipeline = ScenePipeline::new(
            &dev,
            &vs,
            &fs,
            &shadow_mask,
            rays.as_ref().map(|(words, sliced, kind)| (&words[..], &sliced[..], *kind)),
            interpolation == Interpolation::Device,
            options.pipeline_cache_dir.as_deref(),
            options.whole_shaders,
        )?;
        let shader_compile = compile_time + t1.elapsed();
        let commands = Commands::new(&dev)?;
        let mark = MarkPass::new(&dev)?;
        let sun_map = DepthMap::new(&dev, 1)?;
        let disk_maps = (0..MAX_DISK_MAPS).map(|_| DepthMap::new(&dev, 1)).collect::<Result<Vec<_>, _>>()?;
        let no_light_fractions = Buffer::storage(&dev, bytemuck::bytes_of(&-1.0f32), "light fractions (unused)")?;
        let no_sun_cells = TexelBuffer::rgba32ui(&dev, &super::sun_cells::absent(), "sun cells (none)")?;
        let renderer = Self {
            target: None,
            lights: None,
            light_fractions: None,
            no_light_fractions,
            sun_cells: None,
            no_sun_cells,
            sun_map,
            disk_maps,
            pipeline,
            mark,
            commands,
            setup: SetupTimings { instance, shader_compile },
            interpolation,
            // Whole modules declare the stencil output of a first draw that marks by stencil; lavapipe takes it as
            // written by every pipeline of the module, so a second draw's stencil test would fail: they draw once.
            one_draw: options.one_draw || options.whole_shaders,
            dev,
        };
        renderer.check_validation()?;
        Ok(renderer)
    }

    pub fn device_info(&self) -> &DeviceInfo {
        &self.dev.info
    }

    /// How the fragment shader interpolates.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// The pipelines created since the last call (by the frames rendered since), oldest first: what each is, its
    /// fragment stage's size and its creation time (`render -v`, `bench --startup`).
    pub fn take_created_pipelines(&mut self) -> Vec<CreatedPipeline> {
        self.pipeline.take_created()
    }

    pub fn setup_timings(&self) -> SetupTimings {
        self.setup
    }

    /// Bytes of pipeline-cache data read from disk when the renderer was created (0: none, or none valid).
    pub fn pipeline_cache_loaded_bytes(&self) -> usize {
        self.pipeline.cache_loaded_bytes()
    }

    /// Writes the pipeline cache to disk if pipelines were created since the last save (and a cache folder was
    /// given). A failure does not spoil a render: the message is for a warning.
    pub fn save_pipeline_cache(&mut self) -> Result<(), String> {
        self.pipeline.save_cache()
    }

    /// The validation layer's messages (empty without validation). Outlives the renderer.
    pub fn validation_log(&self) -> Arc<ValidationLog> {
        self.dev.validation_log()
    }

    /// Refuses image sizes the device cannot hold: over `maxImageDimension2D`, over the largest single
    /// allocation, or over the device-local heap.
    pub fn check_size(&self, width: u32, height: u32) -> Result<(), GpuError> {
        let info = &self.dev.info;
        let max = info.max_image_dimension_2d.min(info.max_viewport_dimensions[0]).min(info.max_viewport_dimensions[1]);
        if width > max || height > max {
            return Err(GpuError::TooLarge(format!(
                "a {width}x{height} image exceeds the largest image {} supports ({max} pixels per side)",
                info.name
            )));
        }
        let color = rgba32f_bytes(width, height).unwrap_or(u64::MAX);
        let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
        if color > info.max_memory_allocation_size {
            return Err(GpuError::TooLarge(format!(
                "a {width}x{height} RGBA32F image needs {:.2} GiB in one allocation; {} allows {:.2} GiB",
                gib(color),
                info.name,
                gib(info.max_memory_allocation_size)
            )));
        }
        // Colour target + depth (4 bytes/pixel) + host readback buffer.
        let total = color.saturating_mul(2).saturating_add(color / 4);
        if info.device_local_heap_bytes > 0 && total > info.device_local_heap_bytes {
            return Err(GpuError::TooLarge(format!(
                "a {width}x{height} render needs {:.2} GiB of memory; {} has {:.2} GiB",
                gib(total),
                info.name,
                gib(info.device_local_heap_bytes)
            )));
        }
        Ok(())
    }

    /// Copies a scene's triangles and materials to the device.
    pub fn upload(&self, scene: &Scene) -> Result<GpuScene, GpuError> {
        let mut vertices = Vec::new();
        let mut surface_vertices = Vec::new();
        let mut indices = Vec::new();
        let mut draws = Vec::new();
        // With ray queries: every triangle's indices into the whole vertex buffer, for the acceleration structure.
        let rq = self.pipeline.has_ray_queries();
        let bvh = self.pipeline.rays_walk_bvh();
        let mut global_indices = Vec::new();
        let (measured, measured_offsets) = measured_tables(&scene.materials);
        let materials: Vec<_> =
            scene.materials.iter().zip(&measured_offsets).map(|(m, &offset)| material_gpu(m, offset)).collect();
        for mesh in &scene.meshes {
            let vertex_offset = i32::try_from(vertices.len())
                .map_err(|_| GpuError::TooLarge("the scene has more than 2^31 vertices".into()))?;
            draws.push(Draw {
                first_index: indices.len() as u32,
                index_count: mesh.indices.len() as u32,
                vertex_offset,
                material: mesh.material as u32,
                brdf: materials[mesh.material].kind[0],
                surface: surface_flags(&scene.materials[mesh.material], !mesh.colors.is_empty()),
                double_sided: scene.materials[mesh.material].double_sided,
            });
            if rq {
                global_indices.extend(mesh.indices.iter().map(|&i| i + vertex_offset as u32));
            }
            vertices.extend((0..mesh.positions.len()).map(|i| Vertex {
                position: mesh.positions[i].to_array(),
                normal: mesh.normals[i].to_array(),
                tangent: mesh.tangents[i].to_array(),
            }));
            let uv = |set: usize, i: usize| mesh.tex_coords[set].get(i).copied().unwrap_or([0.0; 2]);
            surface_vertices.extend((0..mesh.positions.len()).map(|i| SurfaceVertex {
                uv0: uv(0, i),
                uv1: uv(1, i),
                color: mesh.colors.get(i).copied().unwrap_or([1.0; 4]),
            }));
            indices.extend_from_slice(&mesh.indices);
        }
        let no_material = [MaterialGpu::zeroed()];
        let materials_bytes: &[u8] = bytemuck::cast_slice(if materials.is_empty() { &no_material } else { &materials });
        let textures = TextureLayout::of(scene);
        let limit = self.dev.info.max_storage_buffer_range as u64;
        let vertex_bytes = std::mem::size_of_val(&vertices[..]) as u64;
        if vertex_bytes.max(std::mem::size_of_val(&surface_vertices[..]) as u64) > limit {
            return Err(GpuError::TooLarge(format!(
                "the scene's {} vertices take {:.1} MiB; {} binds at most {:.1} MiB in one storage buffer",
                vertices.len(),
                vertex_bytes as f64 / (1 << 20) as f64,
                self.dev.info.name,
                limit as f64 / (1 << 20) as f64
            )));
        }
        let measured_bytes = std::mem::size_of_val(&measured[..]) as u64;
        if measured_bytes > limit {
            return Err(GpuError::TooLarge(format!(
                "the scene's measured BRDF tables take {:.1} MiB ({} distinct files, 22.2 MiB each); {} binds at most \
                 {:.1} MiB in one storage buffer",
                measured_bytes as f64 / (1 << 20) as f64,
                measured.len() / (4 * crate::scene::measured::MERL_SAMPLES),
                self.dev.info.name,
                limit as f64 / (1 << 20) as f64
            )));
        }
        let texel_limit = self.dev.info.max_texel_buffer_elements as usize;
        let (linear_bytes, code_bytes) = (textures.linear_texels as u64 * 16, textures.code_texels as u64 * 4);
        if textures.linear_texels.max(textures.code_texels) > texel_limit
            || linear_bytes.max(code_bytes) > self.dev.info.max_memory_allocation_size
        {
            return Err(GpuError::TooLarge(format!(
                "the scene's textures and their mip levels are {} texels as 8-bit codes ({:.1} MiB) and {} as f32 \
                 RGBA ({:.1} MiB); {} reads at most {texel_limit} from one texel buffer in one allocation of {:.1} \
                 MiB (--max-texture-size N draws large textures from a smaller mip level)",
                textures.code_texels,
                code_bytes as f64 / (1 << 20) as f64,
                textures.linear_texels,
                linear_bytes as f64 / (1 << 20) as f64,
                self.dev.info.name,
                self.dev.info.max_memory_allocation_size as f64 / (1 << 20) as f64
            )));
        }
        let texels = TexelBuffer::filled(
            &self.dev,
            textures.linear_texels,
            vk::Format::R32G32B32A32_SFLOAT,
            "texels",
            |out: &mut [[f32; 4]]| textures.write_linear(scene, out),
        )?;
        let texel_codes = TexelBuffer::filled(
            &self.dev,
            textures.code_texels,
            vk::Format::R8G8B8A8_UINT,
            "texel codes",
            |out: &mut [[u8; 4]]| textures.write_codes(scene, out),
        )?;
        if surface_vertices.is_empty() {
            surface_vertices.push(SurfaceVertex::zeroed());
        }
        let surface_vertices = Buffer::storage(&self.dev, bytemuck::cast_slice(&surface_vertices), "surface vertices")?;
        let texture_table = Buffer::storage(&self.dev, bytemuck::cast_slice(&textures.table), "texture table")?;
        // With ray queries the vertex buffer is also the acceleration structure's build input.
        let accel_usage = if rq {
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS
        } else {
            vk::BufferUsageFlags::empty()
        };
        // The vertices as texels (binding 17): position, normal and tangent, one RGBA32UI texel each (the floats'
        // bits), which the fragment shader and the walks fetch instead of the storage buffer's words.
        let vertex_texels = TexelBuffer::filled(
            &self.dev,
            3 * vertices.len().max(1),
            vk::Format::R32G32B32A32_UINT,
            "vertex texels",
            |out: &mut [[u32; 4]]| {
                for (o, v) in out.chunks_exact_mut(3).zip(&vertices) {
                    let bits = |a: [f32; 3], w: f32| [a[0], a[1], a[2], w].map(f32::to_bits);
                    let [t0, t1, t2, t3] = v.tangent;
                    o.copy_from_slice(&[bits(v.position, 0.0), bits(v.normal, 0.0), bits([t0, t1, t2], t3)]);
                }
            },
        )?;
        let vertices = (!vertices.is_empty())
            .then(|| {
                Buffer::with_data(
                    &self.dev,
                    bytemuck::cast_slice(&vertices),
                    vk::BufferUsageFlags::VERTEX_BUFFER | accel_usage,
                    "vertices",
                )
            })
            .transpose()?;
        let indices = (!indices.is_empty())
            .then(|| {
                Buffer::with_data(
                    &self.dev,
                    bytemuck::cast_slice(&indices),
                    vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER,
                    "indices",
                )
            })
            .transpose()?;
        let masked = scene.has_alpha_masks();
        let accel = match &vertices {
            Some(vb) if rq && !global_indices.is_empty() => Some(SceneAccel::build(
                &self.dev,
                vb,
                (vb.size / std::mem::size_of::<Vertex>() as u64) as u32,
                std::mem::size_of::<Vertex>() as u64,
                &global_indices,
                !masked,
            )?),
            _ => None,
        };
        let vertex_offsets: Vec<i32> = draws.iter().map(|d| d.vertex_offset).collect();
        // The records in the acceleration structure's order where masked hits read them (else one dummy), and one
        // dummy node. Without ray queries, what the shader's walk needs is laid out when a render first casts rays
        // (`walk`).
        let records = occluder_records(scene, &vertex_offsets, rq && masked);
        let occluder_triangles = Buffer::storage(&self.dev, bytemuck::cast_slice(&records), "occluder triangles")?;
        let bvh_nodes =
            TexelBuffer::rgba32ui(&self.dev, bytemuck::bytes_of(&BvhNodeGpu::zeroed()), "occluder BVH nodes")?;
        let no_walk_records = TexelBuffer::rgba32ui(&self.dev, &[0; 16], "occluder records, leaf order")?;
        // The walk's source where the pipelines have shadow rays: their walk without ray queries, the slices' with.
        let walk_source = (bvh || rq).then(|| WalkSource::new(scene, &vertex_offsets));
        Ok(GpuScene {
            passes_from_rows: std::cell::Cell::new(u32::MAX),
            accel,
            vertices,
            indices,
            materials: TexelBuffer::rgba32ui(&self.dev, materials_bytes, "materials")?,
            texels,
            texel_codes,
            texture_table,
            surface_vertices,
            occluder_triangles,
            vertex_texels,
            bvh_nodes,
            no_walk_records,
            walk_source,
            walk: std::cell::OnceCell::new(),
            measured: Buffer::storage(&self.dev, bytemuck::cast_slice(&measured), "measured BRDFs")?,
            draws,
            // Decided here, once per upload (24 ms for 20k triangles): `auto` renders no shadow pass where it is
            // false, on any device.
            can_occlude: crate::visibility::can_occlude(scene),
            masked,
            bounds: scene.bounds(),
        })
    }

    /// Refuses `visibility_rule: Slices` with shadow maps: slices take the place of shadow rays.
    fn check_slices(&self, technique: Shadows) -> Result<(), GpuError> {
        if technique != Shadows::Map {
            return Ok(());
        }
        Err(GpuError::Unsupported(
            "--visibility slices: slices take the place of shadow rays (--shadows ray); `sunshade reference \
             --visibility slices` takes them for every light"
                .into(),
        ))
    }

    /// The shadow technique for this scene and these settings on this device, and why: `auto` and `ray` cast rays
    /// on any device: the sun's against its cells (`sun_cells`), the other lights' by ray queries where the
    /// renderer casts them (`device_info::casts_ray_queries`) or by the fragment shader's walk of the occluders'
    /// BVH (`shadow_bvh`; the same rays). `map` shadows the sun and the first `MAX_DISK_MAPS` disk lights from their maps and leaves the sky
    /// (and further disks) unoccluded, with a warning where the scene has them.
    pub fn shadow_choice(&self, scene: &GpuScene, settings: &RenderSettings) -> Result<ShadowChoice, GpuError> {
        let requested = settings.shading.shadows;
        let mut choice = crate::visibility::choose(requested, &settings.lights, scene.can_occlude);
        if choice.technique == Shadows::Ray && !self.pipeline.has_shadow_rays() {
            return Err(GpuError::Unsupported(format!(
                "{}: no shadow rays with the naive-math diagnostic: --shadows map or none",
                self.dev.info.name
            )));
        }
        let k = settings.shading.shadow_samples_per_axis;
        if choice.technique == Shadows::Ray && k > MAX_LOCATED_GRID {
            return Err(GpuError::Unsupported(format!(
                "{k}² shadow rays a light: the GPU's visible-fraction grid keeps a column of corners, at most \
                 {MAX_LOCATED_GRID}² (--shadow-samples {})",
                MAX_LOCATED_GRID * MAX_LOCATED_GRID
            )));
        }
        if choice.technique == Shadows::Ray {
            let lights = &settings.lights;
            let mut how = Vec::new();
            if lights.sun.is_some() {
                how.push("the sun's against its cells".to_string());
            }
            if !lights.disks.is_empty() || lights.sky.is_some() {
                let by = if self.pipeline.rays_walk_bvh() {
                    "the fragment shader's walk of the occluders' BVH (a CPU device, or one without ray queries)"
                } else {
                    "ray queries"
                };
                how.push(format!("the other lights' by {by}"));
            }
            if !how.is_empty() {
                choice.reason += &format!(" ({})", how.join("; "));
            }
        }
        if settings.shading.visibility_rule == VisibilityRule::Slices {
            self.check_slices(choice.technique)?;
        }
        if choice.technique == Shadows::Map {
            if settings.lights.disks.len() > MAX_DISK_MAPS {
                choice.reason += &format!(
                    "; only the first {MAX_DISK_MAPS} disk lights have shadow maps: the other {} are unoccluded",
                    settings.lights.disks.len() - MAX_DISK_MAPS
                );
                choice.warning = true;
            }
            if settings.lights.sky.is_some() {
                choice.reason += "; the sky has no shadow map: it is unoccluded (--shadows ray shadows it";
                choice.reason += if self.pipeline.has_ray_queries() {
                    ")"
                } else {
                    ", by the fragment shader's walk of the occluders' BVH: seconds a frame on lavapipe)"
                };
                choice.warning = true;
            }
        }
        Ok(choice)
    }

    /// Uploads and renders in one go.
    pub fn render_scene(
        &mut self,
        scene: &Scene,
        settings: &RenderSettings,
    ) -> Result<(Image, FrameTimings), GpuError> {
        let gpu_scene = self.upload(scene)?;
        self.render(&gpu_scene, settings)
    }

    /// Draws an uploaded scene and reads the radiance back: the sun's shadow-map pass where the technique is
    /// `map`, the sky's passes of slices where its visible fraction is taken by them (`slice_passes`, with rays
    /// walking the BVH and `--visibility slices`), the scene pass, the readback.
    pub fn render(&mut self, scene: &GpuScene, settings: &RenderSettings) -> Result<(Image, FrameTimings), GpuError> {
        Ok(self.render_frame(scene, settings, false)?.expect("a frame that shades every pixel is always drawn"))
    }

    /// The first of the frame's two draws alone (`second_draw`): every pixel whose lights the cheap proofs settle
    /// (each light wholly visible or wholly hidden) shaded, every other left with the coverage alpha
    /// [`second_draw::LEFT_TO_SECOND_DRAW`] (its colour meaningless) for the caller to shade. `None` where a draw
    /// of the frame casts shadow rays without a first draw (the sky, whose grid every pixel casts; a sun without
    /// complete cells; small-source disks), so that no pixel of it is settled; `settings` must ask for the grid
    /// rule (the slices have no first draw either).
    pub fn render_leaving_penumbrae(
        &mut self,
        scene: &GpuScene,
        settings: &RenderSettings,
    ) -> Result<Option<(Image, FrameTimings)>, GpuError> {
        self.render_frame(scene, settings, true)
    }

    /// [`Self::render`], or with `leave` [`Self::render_leaving_penumbrae`].
    fn render_frame(
        &mut self,
        scene: &GpuScene,
        settings: &RenderSettings,
        leave: bool,
    ) -> Result<Option<(Image, FrameTimings)>, GpuError> {
        let (width, height) = (settings.width, settings.height);
        self.check_size(width, height)?;
        self.ensure_target(width, height)?;
        self.lights = None;
        let technique = self.shadow_choice(scene, settings)?.technique;
        // The sun's shadow map, where `map` is the technique and there is a sun and geometry.
        let sun_map = match (technique, &settings.lights.sun, scene.bounds) {
            (Shadows::Map, Some(sun), Some(bounds)) => {
                let size = settings.shading.shadow_map_size;
                if self.sun_map.size != size {
                    self.sun_map = DepthMap::new(&self.dev, size)?;
                }
                Some(fit_sun_map(bounds, sun.direction.as_dvec3(), size))
            }
            _ => None,
        };
        // The first disks' maps, likewise.
        let size = settings.shading.shadow_map_size;
        let mut disk_maps: Vec<Option<(DiskMapFrame, u32)>> = Vec::new();
        if let (Shadows::Map, Some(bounds)) = (technique, scene.bounds) {
            for (i, disk) in settings.lights.disks.iter().take(MAX_DISK_MAPS).enumerate() {
                let frame = fit_disk_map(bounds, disk.center.as_dvec3(), disk.direction.as_dvec3());
                if frame.is_some() && self.disk_maps[i].size != size {
                    self.disk_maps[i] = DepthMap::new(&self.dev, size)?;
                }
                disk_maps.push(frame.map(|f| (f, size)));
            }
        }
        let light_bytes = lights_bytes(
            &settings.lights,
            &settings.shading,
            sun_map.as_ref().map(|f| (f, self.sun_map.size)),
            &disk_maps,
        );
        let any_map = sun_map.is_some() || disk_maps.iter().any(Option::is_some);
        let shadows = match technique {
            // Rays need something to meet: the acceleration structure, or the BVH (every scene with geometry).
            Shadows::Ray if scene.accel.is_some() || self.pipeline.rays_walk_bvh() => SHADOWS_RAY,
            Shadows::Map if any_map => SHADOWS_MAP,
            _ => SHADOWS_NONE,
        };
        // The sun's cells, for the sun's rays (`visibility::sun_cells`): none where a cell would hold too many
        // triangles (the rays then take the BVH's walk or the ray queries).
        let t_shadow_setup = Instant::now();
        self.sun_cells = None;
        let mut sun_cells = SUN_CELLS_NONE;
        if let (SHADOWS_RAY, Some(sun), Some(source)) = (shadows, &settings.lights.sun, &scene.walk_source) {
            let (triangles, records) = source.triangles_and_records();
            let half_angle = 0.5 * sun.angular_diameter as f64;
            // The cells' bytes within a storage buffer's range and a texel buffer's texels (16 bytes each).
            let texel_bytes = (self.dev.info.max_texel_buffer_elements as u64 * 16).min(u32::MAX as u64) as u32;
            let max_entries = super::sun_cells::max_entries(self.dev.info.max_storage_buffer_range.min(texel_bytes));
            if let Some(cells) = SunCells::build(triangles, sun.direction.as_dvec3(), half_angle, max_entries) {
                let count = super::sun_cells::texel_count(&cells);
                let format = vk::Format::R32G32B32A32_UINT;
                self.sun_cells = Some(TexelBuffer::filled(&self.dev, count, format, "sun cells", |out| {
                    super::sun_cells::write(&cells, triangles, records, out)
                })?);
                sun_cells =
                    if cells.fullest() <= MAX_SUN_CELL_TRIANGLES { SUN_CELLS_COMPLETE } else { SUN_CELLS_PARTIAL };
            }
        }
        let mut shadow_setup = t_shadow_setup.elapsed();
        // The pipeline variant of each draw (its material's sun model: `RenderSettings::shading_for`), created now
        // if this is its first frame.
        let t_pipelines = Instant::now();
        let variants: Vec<ShaderVariant> = scene
            .draws
            .iter()
            .map(|draw| {
                let shading = settings.shading_for(draw.material as usize);
                ShaderVariant::new(
                    draw.brdf,
                    draw.surface,
                    &settings.lights,
                    &shading,
                    (shadows, scene.masked, sun_cells),
                )
            })
            .collect();
        // Each draw's first draw, where one settles pixels, made with the others (in parallel) and drawn before them:
        // the pixels it leaves (penumbrae, rays through the tree) are shaded by the whole variant after it.
        let firsts: Vec<Option<ShaderVariant>> = variants
            .iter()
            .map(|v| if self.one_draw && !leave { None } else { v.first_draw(self.dev.info.stencil_export) })
            .collect();
        if leave && variants.iter().zip(&firsts).any(|(v, f)| v.shadows == SHADOWS_RAY && f.is_none()) {
            return Ok(None);
        }
        // The whole variants without the occluders' tree where they can do without it (`ShaderVariant::tree_later`):
        // the pixels whose rays need it are marked, and drawn once more after the frame by `variants`.
        let wholes: Vec<ShaderVariant> =
            variants.iter().map(|v| if leave { *v } else { v.tree_later().unwrap_or(*v) }).collect();
        let tree_later = wholes != variants;
        // What the frame draws: the first draws alone, and the whole variant of a draw without one (nothing of it
        // is left); or every first draw and every whole variant.
        let drawn: Vec<ShaderVariant> = if leave {
            variants.iter().zip(&firsts).map(|(v, f)| f.unwrap_or(*v)).collect()
        } else {
            wholes.iter().copied().chain(firsts.iter().flatten().copied()).collect()
        };
        let (draw_pipelines, second_pipelines) = if leave {
            (self.pipeline.pipelines_of(&drawn)?, vec![vk::Pipeline::null(); variants.len()])
        } else {
            self.first_and_second_pipelines(&wholes, &firsts)?
        };
        let shadow_pipeline = if any_map { Some(self.pipeline.shadow_pipeline()?) } else { None };
        // Alpha-masked draws test their alpha in the maps too (shadow_mask.frag).
        let mut map_pipelines = Vec::new();
        if let Some(opaque) = shadow_pipeline {
            for draw in &scene.draws {
                map_pipelines.push(if draw.surface & SURFACE_ALPHA_MASK != 0 {
                    self.pipeline.shadow_mask_pipeline(draw.surface)?
                } else {
                    opaque
                });
            }
        }
        let pipelines = t_pipelines.elapsed();
        // The walk's buffers, laid out when a drawn variant first reads them (`ShaderVariant::reads_the_tree`).
        let t_walk = Instant::now();
        self.lay_out_walk_for(scene, &drawn)?;
        shadow_setup += t_walk.elapsed();
        let t_render = Instant::now();
        // The lights whose visible fractions the frame reads from their passes of slices (`slice_passes`): the
        // sky's always (a pixel's sky reaches more occluders than a fragment gathers); the sun's and disk lights'
        // where the frame that sliced them itself ran out of llvmpipe's loop budget: it is drawn again.
        let sliced = shadows == SHADOWS_RAY && settings.shading.visibility_rule == VisibilityRule::Slices;
        let mut slots = if sliced && settings.lights.sky.is_some() { vec![ROWS_OF_SKY] } else { Vec::new() };
        let sun_sliced = settings.lights.sun.is_some() && variants.iter().any(|v| v.sun == SUN_DISK);
        let disks_sliced = variants.iter().any(|v| v.disks == DISKS_EXACT);
        let passable = if sliced {
            slice_passes::passable(sun_sliced, if disks_sliced { settings.lights.disks.len() } else { 0 })
        } else {
            Vec::new()
        };
        let rows = crate::shading::visibility::slice_rows(settings.shading.shadow_samples_per_axis);
        if rows >= scene.passes_from_rows.get() {
            slots.extend(&passable);
        }
        let mut passes_pipelines = Duration::ZERO;
        let draws = FrameDraws {
            sun_map: sun_map.as_ref().filter(|_| shadow_pipeline.is_some()).map(|f| f.map_from_world),
            disk_maps: disk_maps
                .iter()
                .map(|f| f.as_ref().filter(|_| shadow_pipeline.is_some()).map(|(f, _)| f.map_from_world))
                .collect(),
            map_pipelines: &map_pipelines,
            draw_pipelines: &draw_pipelines,
            second_pipelines: &second_pipelines,
            keep_depth: tree_later,
        };
        let mut passed = slice_passes::PassedFractions::new((width * height) as usize);
        // A first frame at these rows that slices the sun or disk lights itself is probed first (`frame_probe`), on
        // devices with the loop limiter.
        let mut probing = match passable.first() {
            Some(slot) if !slots.contains(slot) && frame_probe::probes(&self.dev.info) => {
                frame_probe::probe_blocks(width, height)
            }
            _ => None,
        };
        let mut probe = None;
        let (mut tree_pipelines, mut tree_spent, mut tree_redrawn) = (Duration::ZERO, Duration::ZERO, None);
        let (image, lights, light_fractions, readback) = loop {
            passes_pipelines += self.light_fractions(scene, settings, &light_bytes, &variants, &slots, &mut passed)?;
            let light_fractions = match passed.layered() {
                Some(layers) => Some(Buffer::storage(&self.dev, bytemuck::cast_slice(&layers), "light fractions")?),
                None => None,
            };
            let read = slice_passes::read_bits(&slots);
            let frame_bytes = with_light_rows(&light_bytes, [0, 0, 0, read]);
            let probe_ran_out = match probing.take() {
                Some(blocks) => {
                    let t_probe = Instant::now();
                    let bytes = frame_probe::probe_light_bytes(&frame_bytes);
                    let probe_lights = Buffer::storage(&self.dev, &bytes, "the probe's lights")?;
                    self.draw_frame(scene, settings, (&probe_lights, light_fractions.as_ref()), &draws, &blocks)?;
                    let ran_out = super::loop_budget::check(&self.read_back(width, height)?, "").is_err();
                    probe = Some(frame_probe::Probe { blocks: blocks.len(), ran_out, time: t_probe.elapsed() });
                    ran_out
                }
                None => false,
            };
            if !probe_ran_out {
                let lights = Buffer::storage(&self.dev, &frame_bytes, "lights")?;
                self.draw_frame(scene, settings, (&lights, light_fractions.as_ref()), &draws, &[])?;
                let t_readback = Instant::now();
                let mut image = self.read_back(width, height)?;
                if let Some((pixels, _)) =
                    image.alpha_count_and_first(second_draw::LEFT_TO_SECOND_DRAW).filter(|_| tree_later)
                {
                    // Pixels whose rays need the tree: drawn once more, alone, by the variants that have it.
                    let t_tree = Instant::now();
                    let with_tree = self.pipeline.pipelines_of(&variants)?;
                    tree_pipelines = t_tree.elapsed();
                    self.lay_out_walk_for(scene, &variants)?;
                    // SAFETY: as in `draw_frame`: the GPU is idle; the frame kept its depth and stencil.
                    unsafe {
                        self.write_descriptors(
                            scene,
                            &lights,
                            light_fractions.as_ref().unwrap_or(&self.no_light_fractions),
                        );
                        let cb = self.commands.begin(&self.dev)?;
                        self.record_marked_pass(cb, scene, settings, &with_tree);
                        self.commands.submit_and_wait(&self.dev, cb)?;
                    }
                    image = self.read_back(width, height)?;
                    tree_redrawn = Some(pixels);
                    tree_spent = t_tree.elapsed();
                }
                if !leave {
                    second_draw::check(&image).map_err(GpuError::Unsupported)?;
                }
                match super::loop_budget::check(&image, &self.dev.info.name) {
                    Err(_) if !passable.is_empty() && !slots.contains(&passable[0]) => {}
                    Err(e) => return Err(GpuError::LoopBudget(e)),
                    Ok(()) => break (image, lights, light_fractions, t_readback.elapsed() - tree_spent),
                }
            }
            // The probe or the frame ran out with the sun and disk lights in the frame: their rows go to passes, in
            // this frame and in the scene's later frames from these rows on.
            scene.passes_from_rows.set(rows.min(scene.passes_from_rows.get()));
            slots.extend(&passable);
        };
        let render = t_render.elapsed() - passes_pipelines - tree_pipelines - readback;
        let pipelines = pipelines + passes_pipelines + tree_pipelines;
        super::slice_gather::check(&image).map_err(GpuError::Unsupported)?;
        self.lights = Some(lights);
        self.light_fractions = light_fractions;
        self.check_validation()?;
        let lights_in_passes = slice_passes::read_bits(&slots);
        let timings = FrameTimings { shadow_setup, pipelines, render, readback, lights_in_passes, probe, tree_redrawn };
        Ok(Some((image, timings)))
    }

    /// The walk's buffers (`gpu::shadow_bvh`: the tree, its records in leaf order, the tree in depth-first order),
    /// laid out and uploaded once a scene, when a draw of one of `variants` first reads them
    /// (`ShaderVariant::reads_the_tree`).
    fn lay_out_walk_for(&self, scene: &GpuScene, variants: &[ShaderVariant]) -> Result<(), GpuError> {
        let rays_walk = self.pipeline.rays_walk_bvh();
        if !variants.iter().any(|v| v.reads_the_tree(rays_walk)) {
            return Ok(());
        }
        if let (Some(source), None) = (&scene.walk_source, scene.walk.get()) {
            let (nodes, records) = source.layout();
            let threaded = super::shadow_bvh::threaded(&nodes);
            let threaded =
                TexelBuffer::rgba32ui(&self.dev, bytemuck::cast_slice(&threaded), "occluder BVH, depth first")?;
            let nodes = TexelBuffer::rgba32ui(&self.dev, bytemuck::cast_slice(&nodes), "occluder BVH nodes")?;
            let records =
                TexelBuffer::rgba32ui(&self.dev, bytemuck::cast_slice(&records), "occluder records, leaf order")?;
            let _ = scene.walk.set((nodes, records, threaded));
        }
        Ok(())
    }

    /// Each draw's pipeline and the pipeline of its second draw (null where it has no first draw, `firsts`), made
    /// together (in parallel): a draw with a first draw takes it, and its whole variant (`variants`) second.
    fn first_and_second_pipelines(
        &mut self,
        variants: &[ShaderVariant],
        firsts: &[Option<ShaderVariant>],
    ) -> Result<(Vec<vk::Pipeline>, Vec<vk::Pipeline>), GpuError> {
        let every: Vec<ShaderVariant> = variants.iter().copied().chain(firsts.iter().flatten().copied()).collect();
        let made = self.pipeline.pipelines_of(&every)?;
        let (whole_pipelines, mut first_pipelines) = (&made[..variants.len()], made[variants.len()..].iter());
        let mut draw_pipelines = Vec::with_capacity(variants.len());
        let mut second_pipelines = Vec::with_capacity(variants.len());
        for (first, &whole) in firsts.iter().zip(whole_pipelines) {
            // `made` holds a first pipeline for each draw that has a first draw, in order: take one only for those.
            match first.and_then(|_| first_pipelines.next()) {
                Some(&first) => {
                    draw_pipelines.push(first);
                    second_pipelines.push(whole);
                }
                None => {
                    draw_pipelines.push(whole);
                    second_pipelines.push(vk::Pipeline::null());
                }
            }
        }
        Ok((draw_pipelines, second_pipelines))
    }

    /// One frame's draws, with the light buffer `lights` and the passes' fractions (binding 13; the unused one
    /// where `None`): the shadow maps' depth passes (`draws`' maps, where the technique is `map`), then the scene
    /// pass, over the whole image or only a probe's `blocks` (`(x, y, side)`, `frame_probe::probe_blocks`);
    /// submitted and waited for.
    fn draw_frame(
        &mut self,
        scene: &GpuScene,
        settings: &RenderSettings,
        (lights, fractions): (&Buffer, Option<&Buffer>),
        draws: &FrameDraws,
        blocks: &[(u32, u32, u32)],
    ) -> Result<(), GpuError> {
        // SAFETY: all handles are valid and owned by this renderer; the GPU is idle (every submission is waited
        // for), so the descriptor set may be updated and the command buffer re-recorded.
        unsafe {
            self.write_descriptors(scene, lights, fractions.unwrap_or(&self.no_light_fractions));
            let cb = self.commands.begin(&self.dev)?;
            if let Some(to_map) = draws.sun_map {
                self.record_depth_pass(cb, scene, settings, &self.sun_map, to_map, draws.map_pipelines);
            }
            for (map, to_map) in self.disk_maps.iter().zip(&draws.disk_maps).filter_map(|(m, f)| Some((m, (*f)?))) {
                self.record_depth_pass(cb, scene, settings, map, to_map, draws.map_pipelines);
            }
            let pipelines = (draws.draw_pipelines, draws.second_pipelines);
            self.record_scene_pass(cb, scene, settings, pipelines, (blocks, draws.keep_depth));
            self.commands.submit_and_wait(&self.dev, cb)?;
        }
        Ok(())
    }

    /// The visible fractions at every pixel of the lights `slots` (`ROWS_OF_*`) that `passed` does not hold yet,
    /// by their slices, taken in passes before the frame (`slice_passes`) and added to `passed`: each pass draws the
    /// scene with `variants` turned to `QUANTITY_LIGHT_ROWS` and the light buffer `lights` (its bytes) naming the
    /// pass's light and rows; a pass the loop budget cuts short is split in two and drawn again (a single row cut
    /// short refuses the image), one with a row meeting more triangles than a fragment keeps refuses it. The time
    /// spent making the passes' pipelines.
    fn light_fractions(
        &mut self,
        scene: &GpuScene,
        settings: &RenderSettings,
        lights: &[u8],
        variants: &[ShaderVariant],
        slots: &[u32],
        passed: &mut slice_passes::PassedFractions,
    ) -> Result<Duration, GpuError> {
        let slots: Vec<u32> = slots.iter().copied().filter(|&s| !passed.has(s)).collect();
        if slots.is_empty() {
            return Ok(Duration::ZERO);
        }
        let t = Instant::now();
        // A pass's fragment reads neither its draw's BRDF nor its light models, only its surface (alpha masks,
        // normal maps): materials that differ in those alone share a pass's pipeline (room.gltf's five, one).
        let pass_variants: Vec<_> = variants
            .iter()
            .map(|&v| ShaderVariant {
                quantity: QUANTITY_LIGHT_ROWS,
                brdf: BRDF_LAMBERT,
                sun: LIGHT_ABSENT,
                disks: LIGHT_ABSENT,
                ..v
            })
            .collect();
        let pass_pipelines = self.pipeline.pipelines_of(&pass_variants)?;
        let made = t.elapsed();
        let rows = crate::shading::visibility::slice_rows(settings.shading.shadow_samples_per_axis);
        let pixels = (settings.width * settings.height) as usize;
        for slot in slots {
            let mut passes: std::collections::VecDeque<_> = slice_passes::first_passes(rows).into();
            let mut sums = slice_passes::RowSums::new(pixels);
            while let Some((first, count)) = passes.pop_front() {
                let pass_lights =
                    Buffer::storage(&self.dev, &with_light_rows(lights, [first, count, slot, 0]), "lights")?;
                // SAFETY: as in `render`: the GPU is idle between submissions.
                unsafe {
                    self.write_descriptors(scene, &pass_lights, &self.no_light_fractions);
                    let cb = self.commands.begin(&self.dev)?;
                    self.record_scene_pass(cb, scene, settings, (&pass_pipelines, &[]), (&[], false));
                    self.commands.submit_and_wait(&self.dev, cb)?;
                }
                let image = self.read_back(settings.width, settings.height)?;
                match slice_passes::refusal(&image) {
                    None => sums.add(&image),
                    Some(slice_passes::Refusal::Overflowed) => {
                        let light = slice_passes::light_name(slot);
                        return Err(GpuError::Unsupported(slice_passes::overflowed(&image, &light, (first, count))));
                    }
                    Some(slice_passes::Refusal::LoopBudget) if count > 1 => {
                        let half = count / 2;
                        passes.push_front((first + half, count - half));
                        passes.push_front((first, half));
                    }
                    Some(slice_passes::Refusal::LoopBudget) => {
                        super::loop_budget::check(&image, &self.dev.info.name).map_err(GpuError::LoopBudget)?;
                    }
                }
            }
            passed.insert(slot, sums.fractions());
        }
        Ok(made)
    }

    /// The colour and depth targets and the readback buffer, (re)made for this size.
    fn ensure_target(&mut self, width: u32, height: u32) -> Result<(), GpuError> {
        if self.target.as_ref().is_none_or(|t| t.color.width != width || t.color.height != height) {
            self.target = None;
            self.target = Some(Target {
                color: Image2d::new(
                    &self.dev,
                    width,
                    height,
                    COLOR_FORMAT,
                    // Storage: the mark between two draws reads it (`second_draw`).
                    vk::ImageUsageFlags::COLOR_ATTACHMENT
                        | vk::ImageUsageFlags::TRANSFER_SRC
                        | vk::ImageUsageFlags::STORAGE,
                    vk::ImageAspectFlags::COLOR,
                    "colour target",
                )?,
                depth: Image2d::new(
                    &self.dev,
                    width,
                    height,
                    SCENE_DEPTH_STENCIL_FORMAT,
                    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                    vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
                    "depth and stencil target",
                )?,
                readback: Buffer::new(
                    &self.dev,
                    rgba32f_bytes(width, height).expect("checked"),
                    vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuToCpu,
                    "readback",
                )?,
            });
        }
        Ok(())
    }

    /// Bindings 0 materials, 1 lights, 2 indices, 4 the acceleration structure, 5 the sun's map.
    unsafe fn write_descriptors(&self, scene: &GpuScene, lights: &Buffer, light_fractions: &Buffer) {
        let d = &self.dev.device;
        // SAFETY: the caller guarantees the GPU is idle; every handle belongs to this renderer.
        unsafe {
            // Bindings 0 materials, 1 lights, 2 indices, 17 the vertices (only bound when there is geometry).
            if let (Some(_), Some(ib)) = (&scene.vertices, &scene.indices) {
                // 8 the texture table, 9 the surface vertices, 10 the occluder triangles, 11 the measured BRDFs, and
                // 12 the occluders' BVH and 13 the lights' fractions for the pipelines with shadow rays.
                let mut buffers = vec![
                    (1, lights.buffer),
                    (2, ib.buffer),
                    (8, scene.texture_table.buffer),
                    (9, scene.surface_vertices.buffer),
                    (11, scene.measured.buffer),
                ];
                // 10: the occluder records in the acceleration structure's order (ray queries' masked hits).
                buffers.push((10, scene.occluder_triangles.buffer));
                if self.pipeline.has_shadow_rays() {
                    buffers.push((13, light_fractions.buffer));
                }
                let infos: Vec<_> = buffers
                    .into_iter()
                    .map(|(b, buffer)| (b, [vk::DescriptorBufferInfo { buffer, offset: 0, range: vk::WHOLE_SIZE }]))
                    .collect();
                let writes: Vec<_> = infos
                    .iter()
                    .map(|(b, info)| {
                        vk::WriteDescriptorSet::default()
                            .dst_set(self.pipeline.descriptor_set)
                            .dst_binding(*b)
                            .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                            .buffer_info(info)
                    })
                    .collect();
                d.update_descriptor_sets(&writes, &[]);
                // 0: the materials, 7: the f32 texels, 16: the 8-bit codes, 17: the vertices; uniform texel buffers.
                // 12, 14, 18: the walks' tree, records (leaf order) and the tree in depth-first order, and 15 the
                // sun's cells, for the pipelines with shadow rays.
                let (nodes, walk_records, threaded) = scene
                    .walk
                    .get()
                    .map_or((&scene.bvh_nodes, &scene.no_walk_records, &scene.bvh_nodes), |(n, r, t)| (n, r, t));
                let sun_cells = self.sun_cells.as_ref().unwrap_or(&self.no_sun_cells);
                let views = [
                    [scene.texels.view],
                    [scene.texel_codes.view],
                    [nodes.view],
                    [walk_records.view],
                    [sun_cells.view],
                    [scene.vertex_texels.view],
                    [threaded.view],
                    [scene.materials.view],
                ];
                let mut bindings = vec![(0, &views[7]), (7, &views[0]), (16, &views[1]), (17, &views[5])];
                if self.pipeline.has_shadow_rays() {
                    bindings.extend([(12, &views[2]), (14, &views[3]), (15, &views[4]), (18, &views[6])]);
                }
                let writes: Vec<_> = bindings
                    .into_iter()
                    .map(|(binding, view)| {
                        vk::WriteDescriptorSet::default()
                            .dst_set(self.pipeline.descriptor_set)
                            .dst_binding(binding)
                            .descriptor_type(vk::DescriptorType::UNIFORM_TEXEL_BUFFER)
                            .texel_buffer_view(view)
                    })
                    .collect();
                d.update_descriptor_sets(&writes, &[]);
            }
            // Binding 5: the sun's shadow map, 6: the first disks' (valid images in every frame; read only by
            // SHADOWS_MAP pipelines).
            let info = |m: &DepthMap| vk::DescriptorImageInfo {
                sampler: m.sampler,
                image_view: m.image.view,
                image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            };
            let sun_info = [info(&self.sun_map)];
            let disk_infos: Vec<_> = self.disk_maps.iter().map(info).collect();
            let writes = [(5, &sun_info[..]), (6, &disk_infos[..])].map(|(binding, infos)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(self.pipeline.descriptor_set)
                    .dst_binding(binding)
                    .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .image_info(infos)
            });
            d.update_descriptor_sets(&writes, &[]);
            // Binding 4: the top-level acceleration structure, for the pipelines with shadow rays.
            if let Some(accel) = &scene.accel {
                let structures = [accel.top_level()];
                let mut info =
                    vk::WriteDescriptorSetAccelerationStructureKHR::default().acceleration_structures(&structures);
                let write = vk::WriteDescriptorSet::default()
                    .dst_set(self.pipeline.descriptor_set)
                    .dst_binding(4)
                    .descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                    .descriptor_count(1)
                    .push_next(&mut info);
                d.update_descriptor_sets(&[write], &[]);
            }
        }
    }

    /// Records a shadow-map pass into `map`: every draw, depth only, through the map's frame, each with its
    /// pipeline (`draw_pipelines`: the plain depth pipeline, or the alpha-testing one of a masked draw).
    unsafe fn record_depth_pass(
        &self,
        cb: vk::CommandBuffer,
        scene: &GpuScene,
        settings: &RenderSettings,
        map: &DepthMap,
        map_from_world: glam::DMat4,
        draw_pipelines: &[vk::Pipeline],
    ) {
        // SAFETY: `cb` is being recorded by the caller; every handle belongs to this renderer.
        unsafe {
            if let (Some(vb), Some(ib)) = (&scene.vertices, &scene.indices) {
                let map_from_world = map_from_world.as_mat4().to_cols_array();
                let size = map.size as f32;
                map.record(cb, |cb| {
                    // The map's frame and size (a masked draw's barycentrics are the map texel's); the cull mode is
                    // the map's own.
                    self.record_draws(cb, scene, (vb, ib), draw_pipelines, None, |draw| PushConstants {
                        clip_from_world: map_from_world,
                        framebuffer_size: [size, size],
                        ..push_constants(settings, draw.material, draw.first_index, draw.vertex_offset)
                    });
                });
            }
        }
    }

    /// Records the scene pass: targets cleared, every draw with its pipeline variant; where the frame has a second
    /// draw (`second_pipelines` not all null: `second_draw`), the mark and the second draw after it; with
    /// `keep_depth`, the depth and stencil stored for [`Self::record_marked_pass`].
    unsafe fn record_scene_pass(
        &self,
        cb: vk::CommandBuffer,
        scene: &GpuScene,
        settings: &RenderSettings,
        (draw_pipelines, second_pipelines): (&[vk::Pipeline], &[vk::Pipeline]),
        (blocks, keep_depth): (&[(u32, u32, u32)], bool),
    ) {
        let d = &self.dev.device;
        let target = self.target.as_ref().expect("made by ensure_target");
        let (width, height) = (settings.width, settings.height);
        let (Some(vb), Some(ib)) = (&scene.vertices, &scene.indices) else {
            // Nothing to draw: the targets cleared.
            // SAFETY: as below.
            unsafe {
                self.begin_scene_rendering(cb, settings, (true, false));
                d.cmd_end_rendering(cb);
            }
            return;
        };
        let second = second_pipelines.iter().any(|p| *p != vk::Pipeline::null());
        let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: vk::Extent2D { width, height } };
        // The whole image, or the scene drawn once for each of the probe's blocks (`frame_probe`).
        let scissors: Vec<vk::Rect2D> = match blocks {
            [] => vec![area],
            _ => blocks
                .iter()
                .map(|&(x, y, side)| vk::Rect2D {
                    offset: vk::Offset2D { x: x as i32, y: y as i32 },
                    extent: vk::Extent2D { width: side, height: side },
                })
                .collect(),
        };
        // SAFETY: `cb` is being recorded by the caller; every handle belongs to this renderer; the GPU is idle.
        unsafe {
            let buffers = (scene, settings, (vb, ib));
            if second && self.dev.info.stencil_export {
                // The first draw marks by the stencil its fragments write: the second follows in the same rendering.
                self.begin_scene_rendering(cb, settings, (true, keep_depth));
                self.record_scene_draws(cb, buffers, draw_pipelines, Tests::FirstMarkingStencil, &scissors, false);
                self.record_scene_draws(cb, buffers, second_pipelines, Tests::Second, &scissors, true);
                return;
            }
            self.begin_scene_rendering(cb, settings, (true, second || keep_depth));
            self.record_scene_draws(cb, buffers, draw_pipelines, Tests::OneOrFirst, &scissors, true);
            if second {
                self.mark.record(cb, &target.color, &target.depth, area);
                self.begin_scene_rendering(cb, settings, (false, keep_depth));
                self.record_scene_draws(cb, buffers, second_pipelines, Tests::Second, &scissors, true);
            }
        }
    }

    /// Every draw of the scene with `pipelines` under `tests` (`second_draw::set_tests`), in every scissor; the
    /// rendering ended after them where `end`.
    ///
    /// # Safety
    /// `cb` is being recorded inside a rendering of the scene's target.
    unsafe fn record_scene_draws(
        &self,
        cb: vk::CommandBuffer,
        (scene, settings, buffers): (&GpuScene, &RenderSettings, (&Buffer, &Buffer)),
        pipelines: &[vk::Pipeline],
        tests: Tests,
        scissors: &[vk::Rect2D],
        end: bool,
    ) {
        let d = &self.dev.device;
        let cull = |draw: &Draw| if draw.double_sided { vk::CullModeFlags::NONE } else { vk::CullModeFlags::BACK };
        let push = |draw: &Draw| push_constants(settings, draw.material, draw.first_index, draw.vertex_offset);
        // SAFETY: as the caller guarantees; every handle belongs to this renderer.
        unsafe {
            second_draw::set_tests(d, cb, tests);
            for &scissor in scissors {
                d.cmd_set_scissor(cb, 0, &[scissor]);
                self.record_draws(cb, scene, buffers, pipelines, Some(&cull), push);
            }
            if end {
                d.cmd_end_rendering(cb);
            }
        }
    }

    /// Records one more draw of the pixels a frame left marked (`ShaderVariant::tree_later`), after its readback:
    /// the colour made an attachment again, the mark, and every draw with `pipelines` under the second draw's
    /// tests, so that only the marked pixels run them (`second_draw`).
    ///
    /// # Safety
    /// `cb` is being recorded outside a rendering; the GPU is idle; the target holds the frame, its colour as the
    /// readback left it and its depth and stencil stored (`record_scene_pass` with `keep_depth`).
    unsafe fn record_marked_pass(
        &self,
        cb: vk::CommandBuffer,
        scene: &GpuScene,
        settings: &RenderSettings,
        pipelines: &[vk::Pipeline],
    ) {
        let d = &self.dev.device;
        let target = self.target.as_ref().expect("made by ensure_target");
        let (Some(vb), Some(ib)) = (&scene.vertices, &scene.indices) else { return };
        let (width, height) = (settings.width, settings.height);
        let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: vk::Extent2D { width, height } };
        // SAFETY: as the caller guarantees; every handle belongs to this renderer.
        unsafe {
            let to_attachment = [image_barrier(
                target.color.image,
                vk::ImageAspectFlags::COLOR,
                (vk::PipelineStageFlags2::COPY, vk::AccessFlags2::TRANSFER_READ),
                (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            )];
            d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_attachment));
            self.mark.record(cb, &target.color, &target.depth, area);
            self.begin_scene_rendering(cb, settings, (false, false));
            self.record_scene_draws(cb, (scene, settings, (vb, ib)), pipelines, Tests::Second, &[area], true);
        }
    }

    /// Begins a rendering of the scene's target with the viewport set: `clear`, the targets made attachments and
    /// cleared (colour 0, depth 1, stencil 0), else both loaded as the last rendering or the mark left them;
    /// `keep_depth`, the depth and stencil stored for a rendering after this one.
    ///
    /// # Safety
    /// `cb` is being recorded outside a rendering; the target exists.
    unsafe fn begin_scene_rendering(
        &self,
        cb: vk::CommandBuffer,
        settings: &RenderSettings,
        (clear, keep_depth): (bool, bool),
    ) {
        let d = &self.dev.device;
        let target = self.target.as_ref().expect("made by ensure_target");
        let (width, height) = (settings.width, settings.height);
        let depth_layout = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        // SAFETY: as the caller guarantees.
        unsafe {
            if clear {
                let to_attachment = [
                    image_barrier(
                        target.color.image,
                        vk::ImageAspectFlags::COLOR,
                        (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_WRITE),
                        (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                        vk::ImageLayout::UNDEFINED,
                        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    ),
                    image_barrier(
                        target.depth.image,
                        vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
                        (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_WRITE),
                        (
                            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ
                                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
                        ),
                        vk::ImageLayout::UNDEFINED,
                        depth_layout,
                    ),
                ];
                d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_attachment));
            }
            let load = if clear { vk::AttachmentLoadOp::CLEAR } else { vk::AttachmentLoadOp::LOAD };
            let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent: vk::Extent2D { width, height } };
            let color_attachments = [vk::RenderingAttachmentInfo::default()
                .image_view(target.color.view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(load)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } })];
            let depth_attachment = vk::RenderingAttachmentInfo::default()
                .image_view(target.depth.view)
                .image_layout(depth_layout)
                .load_op(load)
                .store_op(if keep_depth { vk::AttachmentStoreOp::STORE } else { vk::AttachmentStoreOp::DONT_CARE })
                .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } });
            d.cmd_begin_rendering(
                cb,
                &vk::RenderingInfo::default()
                    .render_area(area)
                    .layer_count(1)
                    .color_attachments(&color_attachments)
                    .depth_attachment(&depth_attachment)
                    .stencil_attachment(&depth_attachment),
            );
            let viewport = vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: width as f32,
                height: height as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            };
            d.cmd_set_viewport(cb, 0, &[viewport]);
        }
    }

    /// Records every draw of the scene into the pass being recorded: the descriptor set and the scene's vertex and
    /// index buffers bound, each draw with its pipeline (`draw_pipelines`, bound when it changes), its push
    /// constants (`push`) and, where `cull` is given, its cull mode.
    unsafe fn record_draws(
        &self,
        cb: vk::CommandBuffer,
        scene: &GpuScene,
        (vb, ib): (&Buffer, &Buffer),
        draw_pipelines: &[vk::Pipeline],
        cull: Option<&dyn Fn(&Draw) -> vk::CullModeFlags>,
        push: impl Fn(&Draw) -> PushConstants,
    ) {
        let d = &self.dev.device;
        let layout = self.pipeline.layout;
        // SAFETY: `cb` is being recorded by the caller inside a rendering pass; every handle belongs to this
        // renderer.
        unsafe {
            d.cmd_bind_descriptor_sets(
                cb,
                vk::PipelineBindPoint::GRAPHICS,
                layout,
                0,
                &[self.pipeline.descriptor_set],
                &[],
            );
            d.cmd_bind_vertex_buffers(cb, 0, &[vb.buffer], &[0]);
            d.cmd_bind_index_buffer(cb, ib.buffer, 0, vk::IndexType::UINT32);
            let mut bound = vk::Pipeline::null();
            for (draw, &pipeline) in scene.draws.iter().zip(draw_pipelines) {
                // A draw without a pipeline in this list (a second draw it does not need) is skipped.
                if pipeline == vk::Pipeline::null() {
                    continue;
                }
                if pipeline != bound {
                    d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipeline);
                    bound = pipeline;
                }
                let pc = push(draw);
                let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
                d.cmd_push_constants(cb, layout, stages, 0, bytemuck::bytes_of(&pc));
                if let Some(cull) = cull {
                    d.cmd_set_cull_mode(cb, cull(draw));
                }
                d.cmd_draw_indexed(cb, draw.index_count, 1, draw.first_index, draw.vertex_offset, 0);
            }
        }
    }

    /// Copies the colour target into an [`Image`].
    fn read_back(&self, width: u32, height: u32) -> Result<Image, GpuError> {
        let d = &self.dev.device;
        let target = self.target.as_ref().expect("made by ensure_target");
        // SAFETY: the GPU is idle (every submission is waited for); the colour image is in COLOR_ATTACHMENT_OPTIMAL after the render submission.
        unsafe {
            let cb = self.commands.begin(&self.dev)?;
            let to_transfer = [image_barrier(
                target.color.image,
                vk::ImageAspectFlags::COLOR,
                (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                (vk::PipelineStageFlags2::COPY, vk::AccessFlags2::TRANSFER_READ),
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            )];
            d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_transfer));
            let region = vk::BufferImageCopy {
                buffer_offset: 0,
                buffer_row_length: 0,
                buffer_image_height: 0,
                image_subresource: vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                },
                image_offset: vk::Offset3D { x: 0, y: 0, z: 0 },
                image_extent: vk::Extent3D { width, height, depth: 1 },
            };
            d.cmd_copy_image_to_buffer(
                cb,
                target.color.image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                target.readback.buffer,
                &[region],
            );
            let to_host = [vk::BufferMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::HOST)
                .dst_access_mask(vk::AccessFlags2::HOST_READ)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(target.readback.buffer)
                .offset(0)
                .size(vk::WHOLE_SIZE)];
            d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().buffer_memory_barriers(&to_host));
            self.commands.submit_and_wait(&self.dev, cb)?;
        }
        let pixels = copy_pixels(target.readback.mapped());
        let image = Image::from_pixels(width, height, pixels).expect("readback buffer sized for the image");
        Ok(image)
    }

    fn check_validation(&self) -> Result<(), GpuError> {
        let messages = self.validation_log().messages();
        if messages.is_empty() {
            Ok(())
        } else {
            Err(GpuError::Validation(messages))
        }
    }
}

/// The mapped readback buffer as pixels. Copied in parallel blocks: most of the time of a 16 MB copy into a fresh
/// allocation is page faults (measured on lavapipe at 1024²: 9–17 ms serially), which the threads take in
/// parallel.
fn copy_pixels(bytes: &[u8]) -> Vec<[f32; 4]> {
    use rayon::prelude::*;
    let Ok(source) = bytemuck::try_cast_slice::<u8, [f32; 4]>(bytes) else {
        // A mapping not aligned to 4 bytes (allocators align far more): copy byte-wise.
        return bytemuck::pod_collect_to_vec(bytes);
    };
    let mut pixels = vec![[0.0f32; 4]; source.len()];
    const BLOCK: usize = 1 << 14; // 256 KiB
    pixels.par_chunks_mut(BLOCK).zip(source.par_chunks(BLOCK)).for_each(|(d, s)| d.copy_from_slice(s));
    pixels
}

/// SPIR-V of the vertex and fragment stages for an interpolation mode: built ahead of time, or compiled on two
/// threads from `SUNSHADE_SHADER_DIR`.
fn compile_stages(interpolation: Interpolation, naive_math: bool) -> Result<(Vec<u32>, Vec<u32>), GpuError> {
    let mut defines = vec![interpolation_define(interpolation)];
    if naive_math {
        defines.push("SUNSHADE_NAIVE_MATH");
    }
    let (vs, fs) = std::thread::scope(|s| {
        let vs = s.spawn(|| shaders::stage_spirv("scene.vert", &defines));
        let fs = shaders::stage_spirv("scene.frag", &defines);
        (vs.join().expect("the shader compiler thread panicked"), fs)
    });
    Ok((vs.map_err(GpuError::ShaderCompile)?, fs.map_err(GpuError::ShaderCompile)?))
}

/// The `#define` that selects an interpolation mode in the shaders.
fn interpolation_define(interpolation: Interpolation) -> &'static str {
    match interpolation {
        Interpolation::Device => "SUNSHADE_DEVICE_INTERPOLATION",
        Interpolation::BarycentricF32 => "SUNSHADE_F32_BARYCENTRICS",
        Interpolation::BarycentricF64 => "SUNSHADE_F64_BARYCENTRICS",
    }
}

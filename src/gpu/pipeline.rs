//! The scene pipeline: descriptor layout (materials, lights), push constants, and the graphics pipelines for
//! dynamic rendering into RGBA32F colour + D32 depth, one per [`ShaderVariant`] in use, created at first use and
//! kept. Each variant's fragment stage is the shader built ahead of time specialized for the variant's constants
//! ([`sunshade_glsl::specialize`]): the driver is handed only the code the variant can run, since lavapipe compiles
//! everything a module calls before it folds the constants (docs/platform.md, "What the driver compiles").
//!
//! Fixed state: triangle lists, fill, counter-clockwise front faces, depth test LESS with writes, no blending,
//! one sample. The fragment shader reads materials, lights, and the scene's indices and vertices (to interpolate
//! with its own barycentrics), all as storage buffers. Dynamic state: viewport, scissor and cull mode (back for single-sided materials, none for
//! double-sided ones).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use ash::vk;

use super::context::Device;
use super::error::{GpuError, VkContext};
use super::layout::{
    PushConstants, ShaderVariant, Vertex, MAX_DISK_MAPS, SHADOWS_RAY, VARIANT_CONSTANTS, VISIBILITY_SLICES,
};
use super::pipeline_cache::{self, DiskPipelineCache};
use super::second_draw::SCENE_DEPTH_STENCIL_FORMAT;

pub const COLOR_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// A pipeline made for a frame: what it is, the SPIR-V instructions of its fragment stage as the driver got it
/// and as many after every call is inlined (what lavapipe compiles; 0 for none), and how long the driver took to
/// create it.
#[derive(Clone, Debug)]
pub struct CreatedPipeline {
    pub what: String,
    pub instructions: usize,
    pub inlined: usize,
    /// The fragment stage's functions with the largest shares of `inlined` (`sunshade_glsl::inlined_profile`), the
    /// first `LARGEST_SHARES`.
    pub largest: Vec<sunshade_glsl::InlinedFunction>,
    pub time: std::time::Duration,
}

/// How many of a pipeline's largest functions [`CreatedPipeline`] keeps (`render -v` prints them).
pub const LARGEST_SHARES: usize = 4;

pub(crate) struct ScenePipeline {
    dev: Arc<Device>,
    pub set_layout: vk::DescriptorSetLayout,
    pub layout: vk::PipelineLayout,
    pub descriptor_pool: vk::DescriptorPool,
    pub descriptor_set: vk::DescriptorSet,
    vertex_module: vk::ShaderModule,
    /// The fragment stages' SPIR-V as built (specialized per variant when a pipeline is made).
    fragment_spirv: Vec<u32>,
    /// The fragment shader with shadow rays: by ray queries, or by the shader's walk of the occluders' BVH on
    /// devices without them (`ray_bvh`); empty with the naive-math diagnostic.
    ray_spirv: Vec<u32>,
    /// The same with the lights' visible fractions by slices (`SUNSHADE_SLICES`): the variants with
    /// `VISIBILITY_SLICES`, so that the grid's do not compile the slices' code.
    slices_spirv: Vec<u32>,
    /// Diagnostics: hand the driver the whole module and its specialization constants
    /// ([`super::context::ContextOptions::whole_shaders`]).
    whole_shaders: bool,
    ray_bvh: bool,
    with_normals: bool,
    variants: HashMap<ShaderVariant, vk::Pipeline>,
    /// The depth-only pipeline of the sun's shadow map (vertex stage only), created at first use.
    shadow: vk::Pipeline,
    /// The masked draws' shadow-map fragment stage (alpha test, no colour), and its pipelines per
    /// `SURFACE_*` bits, created at first use.
    shadow_mask_spirv: Vec<u32>,
    shadow_masked: HashMap<u32, vk::Pipeline>,
    cache: Option<DiskPipelineCache>,
    /// Variants created since the cache was last saved.
    unsaved: bool,
    /// Pipelines created since [`Self::take_created`] was last called.
    created: Vec<CreatedPipeline>,
}

/// How the fragment shader with shadow rays casts them: by the device's ray queries (`SUNSHADE_RAY_QUERY`,
/// binding 4 the acceleration structure) or by walking the occluders' BVH itself (`SUNSHADE_RAY_BVH`, binding
/// 12 its nodes; `gpu::shadow_bvh`), on devices without ray queries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowRays {
    Query,
    Bvh,
}

impl ScenePipeline {
    /// `with_normals`: the vertex shader also reads the normal (for device interpolation). `cache_dir`: where the
    /// pipeline cache lives on disk (`None`: in memory only). `ray_spirv`: the fragment stage with shadow rays,
    /// without and with the slices' code (`SUNSHADE_SLICES`), and how it casts them. `whole_shaders`: see the
    /// field.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        dev: &Arc<Device>,
        vertex_spirv: &[u32],
        fragment_spirv: &[u32],
        shadow_mask_spirv: &[u32],
        ray_spirv: Option<(&[u32], &[u32], ShadowRays)>,
        with_normals: bool,
        cache_dir: Option<&Path>,
        whole_shaders: bool,
    ) -> Result<Self, GpuError> {
        let d = &dev.device;
        let mut out = Self {
            dev: dev.clone(),
            set_layout: vk::DescriptorSetLayout::null(),
            layout: vk::PipelineLayout::null(),
            descriptor_pool: vk::DescriptorPool::null(),
            descriptor_set: vk::DescriptorSet::null(),
            vertex_module: vk::ShaderModule::null(),
            fragment_spirv: fragment_spirv.to_vec(),
            ray_spirv: ray_spirv.map_or(Vec::new(), |(words, _, _)| words.to_vec()),
            slices_spirv: ray_spirv.map_or(Vec::new(), |(_, sliced, _)| sliced.to_vec()),
            whole_shaders,
            ray_bvh: matches!(ray_spirv, Some((_, _, ShadowRays::Bvh))),
            with_normals,
            variants: HashMap::new(),
            shadow: vk::Pipeline::null(),
            shadow_mask_spirv: shadow_mask_spirv.to_vec(),
            shadow_masked: HashMap::new(),
            cache: None,
            unsaved: false,
            created: Vec::new(),
        };
        // SAFETY: valid device and create infos; on error, Drop destroys what exists so far.
        unsafe {
            // The binding table: 1 lights, 2 indices, 8 the texture table, 9 the surface vertices, 10 the
            // occluder triangles in the acceleration structure's order, 11 the measured BRDF tables (storage
            // buffers); 0 the materials, 7 the f32 texels, 16 the 8-bit ones and 17 the vertices (uniform texel
            // buffers: lavapipe's storage buffers stop at 128 MiB, a texel buffer holds maxTexelBufferElements
            // texels, and llvmpipe fetches a texel in one gather where it loads a storage buffer's words lane by
            // lane: docs/platform.md); 5 the sun's shadow map and 6 the first disks' (always bound: 1 × 1 maps until a
            // shadow pass ran); 4 the scene's top-level acceleration structure, on devices with ray queries; on every
            // device with shadow rays, 13 the lights' fractions from their passes of slices (a storage buffer), and
            // what the walks and the sun's cells read, as uniform texel buffers: 12 the occluders' BVH nodes, 14
            // their records in the tree's leaf order, 15 the sun's cells, 18 the nodes in depth-first order (the
            // shadow rays' walk without ray queries). All read by the fragment shader. The descriptor pool is sized
            // from the same table.
            let mut table = vec![
                (1, vk::DescriptorType::STORAGE_BUFFER, 1),
                (2, vk::DescriptorType::STORAGE_BUFFER, 1),
                (8, vk::DescriptorType::STORAGE_BUFFER, 1),
                (9, vk::DescriptorType::STORAGE_BUFFER, 1),
                (10, vk::DescriptorType::STORAGE_BUFFER, 1),
                (11, vk::DescriptorType::STORAGE_BUFFER, 1),
                (7, vk::DescriptorType::UNIFORM_TEXEL_BUFFER, 1),
                (16, vk::DescriptorType::UNIFORM_TEXEL_BUFFER, 1),
                (17, vk::DescriptorType::UNIFORM_TEXEL_BUFFER, 1),
                (0, vk::DescriptorType::UNIFORM_TEXEL_BUFFER, 1),
                (5, vk::DescriptorType::COMBINED_IMAGE_SAMPLER, 1),
                (6, vk::DescriptorType::COMBINED_IMAGE_SAMPLER, MAX_DISK_MAPS as u32),
            ];
            if let Some((_, _, rays)) = ray_spirv {
                match rays {
                    ShadowRays::Query => table.push((4, vk::DescriptorType::ACCELERATION_STRUCTURE_KHR, 1)),
                    ShadowRays::Bvh => {}
                }
                for binding in [12, 14, 15, 18] {
                    table.push((binding, vk::DescriptorType::UNIFORM_TEXEL_BUFFER, 1));
                }
                table.push((13, vk::DescriptorType::STORAGE_BUFFER, 1));
            }
            let bindings: Vec<_> = table
                .iter()
                .map(|&(binding, ty, count)| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(binding)
                        .descriptor_type(ty)
                        .descriptor_count(count)
                        .stage_flags(vk::ShaderStageFlags::FRAGMENT)
                })
                .collect();
            out.set_layout = d
                .create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None)
                .vk("vkCreateDescriptorSetLayout")?;
            let ranges = [vk::PushConstantRange::default()
                .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
                .offset(0)
                .size(std::mem::size_of::<PushConstants>() as u32)];
            let set_layouts = [out.set_layout];
            out.layout = d
                .create_pipeline_layout(
                    &vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts).push_constant_ranges(&ranges),
                    None,
                )
                .vk("vkCreatePipelineLayout")?;
            let mut pool_sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
            for &(_, ty, count) in &table {
                match pool_sizes.iter_mut().find(|p| p.ty == ty) {
                    Some(p) => p.descriptor_count += count,
                    None => pool_sizes.push(vk::DescriptorPoolSize { ty, descriptor_count: count }),
                }
            }
            out.descriptor_pool = d
                .create_descriptor_pool(
                    &vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&pool_sizes),
                    None,
                )
                .vk("vkCreateDescriptorPool")?;
            out.descriptor_set = d
                .allocate_descriptor_sets(
                    &vk::DescriptorSetAllocateInfo::default()
                        .descriptor_pool(out.descriptor_pool)
                        .set_layouts(&set_layouts),
                )
                .vk("vkAllocateDescriptorSets")?[0];
            out.vertex_module = d
                .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(vertex_spirv), None)
                .vk("vkCreateShaderModule")?;
            let mut hashed = vec![vertex_spirv, fragment_spirv, shadow_mask_spirv];
            hashed.extend(ray_spirv.iter().flat_map(|&(words, sliced, _)| [words, sliced]));
            let name = pipeline_cache::file_name(&dev.info, pipeline_cache::shader_hash(&hashed));
            out.cache = Some(DiskPipelineCache::open(d, cache_dir, &name)?);
        }
        Ok(out)
    }

    /// Bytes of pipeline-cache data loaded from disk at creation.
    pub fn cache_loaded_bytes(&self) -> usize {
        self.cache.as_ref().map_or(0, |c| c.loaded_bytes)
    }

    /// Saves the pipeline cache if variants were created since the last save; `Err` is a message for a warning.
    pub fn save_cache(&mut self) -> Result<(), String> {
        if !std::mem::take(&mut self.unsaved) {
            return Ok(());
        }
        // SAFETY: the cache belongs to this device.
        self.cache.as_ref().map_or(Ok(()), |c| unsafe { c.save(&self.dev.device) })
    }

    /// The depth-only pipeline of the sun's shadow map, created on first use.
    pub fn shadow_pipeline(&mut self) -> Result<vk::Pipeline, GpuError> {
        if self.shadow == vk::Pipeline::null() {
            let cache = self.cache.as_ref().map_or(vk::PipelineCache::null(), |c| c.cache);
            // SAFETY: valid device, layout, module and cache owned by self.
            let (pipeline, made) = unsafe {
                create_pipeline(
                    &self.dev.device,
                    cache,
                    self.layout,
                    (self.vertex_module, None),
                    self.with_normals,
                    None,
                    true,
                    false,
                )?
            };
            self.shadow = pipeline;
            self.created.push(CreatedPipeline { what: "shadow-map depth pass".into(), ..made });
            self.unsaved = true;
        }
        Ok(self.shadow)
    }

    /// The shadow-map pipeline of alpha-masked draws with these `SURFACE_*` bits (depth only, the fragment stage
    /// discarding below the cutoff), created on first use.
    pub fn shadow_mask_pipeline(&mut self, surface: u32) -> Result<vk::Pipeline, GpuError> {
        if let Some(&p) = self.shadow_masked.get(&surface) {
            return Ok(p);
        }
        let cache = self.cache.as_ref().map_or(vk::PipelineCache::null(), |c| c.cache);
        let variant = ShaderVariant {
            brdf: 0,
            sun: 0,
            disks: 0,
            sky: 0,
            shadows: 0,
            surface,
            quantity: 0,
            visibility: 0,
            occluders_masked: 0,
            sun_cells: 0,
            penumbrae: 0,
            mark: 0,
        };
        // SAFETY: valid device, layout, modules and cache owned by self.
        let (p, made) = unsafe {
            create_pipeline(
                &self.dev.device,
                cache,
                self.layout,
                (self.vertex_module, Some(&self.shadow_mask_spirv)),
                self.with_normals,
                Some(variant),
                true,
                self.whole_shaders,
            )?
        };
        self.created
            .push(CreatedPipeline { what: format!("shadow-map alpha-masked pass · surface {surface:#07b}"), ..made });
        self.shadow_masked.insert(surface, p);
        self.unsaved = true;
        Ok(p)
    }

    /// Whether pipelines with shadow rays can be made (the device has ray queries).
    pub fn has_shadow_rays(&self) -> bool {
        !self.ray_spirv.is_empty()
    }

    /// Whether the shadow rays walk the occluders' BVH in the shader (binding 12) rather than query the device's
    /// acceleration structure (binding 4).
    pub fn rays_walk_bvh(&self) -> bool {
        self.ray_bvh
    }

    /// Whether the shadow rays are ray queries (the scene then gets an acceleration structure).
    pub fn has_ray_queries(&self) -> bool {
        self.has_shadow_rays() && !self.ray_bvh
    }

    /// Creates the pipelines of `variants` that do not exist yet, several at once (a thread each, at most as many
    /// as the machine has cores): a driver compiles a pipeline on the thread that asks for it (lavapipe: LLVM, a
    /// few hundred milliseconds a variant), and the pipeline cache is internally synchronized. A variant with
    /// shadow rays on a device without ray queries is refused.
    pub fn prepare_variants(&mut self, variants: &[ShaderVariant]) -> Result<(), GpuError> {
        let mut missing: Vec<ShaderVariant> = Vec::new();
        for &v in variants {
            if v.shadows == SHADOWS_RAY && !self.has_shadow_rays() {
                return Err(GpuError::Unsupported(format!(
                    "{}: no shadow rays with the naive-math diagnostic",
                    self.dev.info.name
                )));
            }
            if !self.variants.contains_key(&v) && !missing.contains(&v) {
                missing.push(v);
            }
        }
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let cache = self.cache.as_ref().map_or(vk::PipelineCache::null(), |c| c.cache);
        let (d, layout, with_normals, whole) = (&self.dev.device, self.layout, self.with_normals, self.whole_shaders);
        let (vertex, fragment, rays, slices) =
            (self.vertex_module, &self.fragment_spirv[..], &self.ray_spirv[..], &self.slices_spirv[..]);
        let mut first_error = None;
        for chunk in missing.chunks(threads) {
            let created: Vec<Result<(vk::Pipeline, CreatedPipeline), GpuError>> = std::thread::scope(|scope| {
                let handles: Vec<_> = chunk
                    .iter()
                    .map(|&variant| {
                        let fs = match (variant.shadows, variant.visibility) {
                            (SHADOWS_RAY, VISIBILITY_SLICES) => slices,
                            (SHADOWS_RAY, _) => rays,
                            _ => fragment,
                        };
                        // SAFETY: valid device, layout, modules and cache, owned by self and alive for the scope;
                        // vkCreateGraphicsPipelines may be called from several threads at once.
                        scope.spawn(move || unsafe {
                            create_pipeline(
                                d,
                                cache,
                                layout,
                                (vertex, Some(fs)),
                                with_normals,
                                Some(variant),
                                false,
                                whole,
                            )
                        })
                    })
                    .collect();
                handles
                    .into_iter()
                    .map(|h| {
                        h.join().unwrap_or_else(|_| Err(GpuError::ShaderCompile("pipeline creation panicked".into())))
                    })
                    .collect()
            });
            // Every pipeline made is kept (and destroyed with the others), whatever failed beside it.
            for (&variant, result) in chunk.iter().zip(created) {
                match result {
                    Ok((p, made)) => {
                        self.variants.insert(variant, p);
                        self.created.push(CreatedPipeline { what: variant.describe(), ..made });
                        self.unsaved = true;
                    }
                    Err(e) => first_error = first_error.or(Some(e)),
                }
            }
        }
        first_error.map_or(Ok(()), Err)
    }

    /// The pipelines created since the last call, oldest first.
    pub fn take_created(&mut self) -> Vec<CreatedPipeline> {
        std::mem::take(&mut self.created)
    }

    /// The pipelines of `variants`, in their order, those that do not exist yet created together
    /// ([`Self::prepare_variants`]).
    pub fn pipelines_of(&mut self, variants: &[ShaderVariant]) -> Result<Vec<vk::Pipeline>, GpuError> {
        self.prepare_variants(variants)?;
        // prepare_variants made each or returned its error.
        let missing = || GpuError::Vulkan { what: "vkCreateGraphicsPipelines", result: vk::Result::ERROR_UNKNOWN };
        variants.iter().map(|v| self.variants.get(v).copied().ok_or_else(missing)).collect()
    }
}

/// A pipeline with the vertex module `vs` and, where given, the fragment stage `fs`'s SPIR-V specialized for
/// `variant`'s constants (the whole module with the constants where `whole`). `depth_only`: a shadow map's pipeline,
/// no colour attachment; its fragment stage (`None`: none) only discards.
#[allow(clippy::too_many_arguments)]
unsafe fn create_pipeline(
    d: &ash::Device,
    cache: vk::PipelineCache,
    layout: vk::PipelineLayout,
    (vs, fs): (vk::ShaderModule, Option<&[u32]>),
    with_normals: bool,
    variant: Option<ShaderVariant>,
    depth_only: bool,
    whole: bool,
) -> Result<(vk::Pipeline, CreatedPipeline), GpuError> {
    let started = std::time::Instant::now();
    let constants = variant.map_or([0; VARIANT_CONSTANTS], |v| v.constants());
    let (mut instructions, mut inlined, mut largest) = (0, 0, Vec::new());
    let module = match fs {
        Some(words) => {
            let specialized;
            let code = if whole {
                words
            } else {
                let pairs: Vec<(u32, u32)> = (0u32..).zip(constants).collect();
                specialized = sunshade_glsl::specialize(words, &pairs).map_err(GpuError::ShaderCompile)?;
                &specialized[..]
            };
            instructions = sunshade_glsl::instruction_count(code).map_err(GpuError::ShaderCompile)?;
            let mut profile = sunshade_glsl::inlined_profile(code).map_err(GpuError::ShaderCompile)?;
            inlined = profile.iter().map(sunshade_glsl::InlinedFunction::inlined).sum();
            profile.truncate(LARGEST_SHARES);
            largest = profile;
            // SAFETY: valid device; SPIR-V built by build.rs, specialized (spirv-val checks both in tests).
            unsafe { d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(code), None) }
                .vk("vkCreateShaderModule")?
        }
        None => vk::ShaderModule::null(),
    };
    // SAFETY: valid device, modules and layout; the module is no longer needed once the pipeline exists (a null
    // module is ignored by the destroy call).
    unsafe {
        let pipeline = create_pipeline_from(d, cache, layout, (vs, module), with_normals, &constants, depth_only);
        d.destroy_shader_module(module, None);
        let made = CreatedPipeline { what: String::new(), instructions, inlined, largest, time: started.elapsed() };
        pipeline.map(|p| (p, made))
    }
}

unsafe fn create_pipeline_from(
    d: &ash::Device,
    cache: vk::PipelineCache,
    layout: vk::PipelineLayout,
    (vs, fs): (vk::ShaderModule, vk::ShaderModule),
    with_normals: bool,
    constants: &[u32; VARIANT_CONSTANTS],
    depth_only: bool,
) -> Result<vk::Pipeline, GpuError> {
    // SAFETY (whole function): valid device and modules.
    unsafe {
        let entries: Vec<vk::SpecializationMapEntry> = (0..constants.len() as u32)
            .map(|i| vk::SpecializationMapEntry { constant_id: i, offset: 4 * i, size: 4 })
            .collect();
        let specialization =
            vk::SpecializationInfo::default().map_entries(&entries).data(bytemuck::cast_slice(constants));
        let all_stages = [
            vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(vs).name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fs)
                .name(c"main")
                .specialization_info(&specialization),
        ];
        let stages = &all_stages[..if fs == vk::ShaderModule::null() { 1 } else { 2 }];
        let vertex_bindings = [vk::VertexInputBindingDescription {
            binding: 0,
            stride: std::mem::size_of::<Vertex>() as u32,
            input_rate: vk::VertexInputRate::VERTEX,
        }];
        // The vertex shader reads the position (and the normal only for device interpolation); otherwise the
        // fragment shader reads whole vertices from a buffer.
        let attribute =
            |location, format, offset| vk::VertexInputAttributeDescription { location, binding: 0, format, offset };
        let all_attributes = [
            attribute(0, vk::Format::R32G32B32_SFLOAT, 0),
            attribute(1, vk::Format::R32G32B32_SFLOAT, 12),
            attribute(2, vk::Format::R32G32B32A32_SFLOAT, 24),
        ];
        let vertex_attributes = &all_attributes[..if with_normals { 3 } else { 1 }];
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&vertex_bindings)
            .vertex_attribute_descriptions(vertex_attributes);
        let input_assembly =
            vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::BACK)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample =
            vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(true)
            .depth_write_enable(true)
            .depth_compare_op(vk::CompareOp::LESS);
        let blend_attachments =
            [vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA)];
        let blend = vk::PipelineColorBlendStateCreateInfo::default()
            .attachments(&blend_attachments[..if depth_only { 0 } else { 1 }]);
        // The scene's pipelines take their depth and stencil tests from the frame (the one draw, or the first or
        // second of two: gpu::second_draw::set_tests); a shadow map's are fixed above, and it has no stencil.
        let dynamic_states = [
            vk::DynamicState::VIEWPORT,
            vk::DynamicState::SCISSOR,
            vk::DynamicState::CULL_MODE,
            vk::DynamicState::DEPTH_COMPARE_OP,
            vk::DynamicState::STENCIL_TEST_ENABLE,
            vk::DynamicState::STENCIL_OP,
            vk::DynamicState::STENCIL_COMPARE_MASK,
            vk::DynamicState::STENCIL_WRITE_MASK,
            vk::DynamicState::STENCIL_REFERENCE,
        ];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default()
            .dynamic_states(&dynamic_states[..if depth_only { 3 } else { dynamic_states.len() }]);
        let all_formats = [COLOR_FORMAT];
        let color_formats = &all_formats[..if depth_only { 0 } else { 1 }];
        let (depth_format, stencil_format) = if depth_only {
            (DEPTH_FORMAT, vk::Format::UNDEFINED)
        } else {
            (SCENE_DEPTH_STENCIL_FORMAT, SCENE_DEPTH_STENCIL_FORMAT)
        };
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(color_formats)
            .depth_attachment_format(depth_format)
            .stencil_attachment_format(stencil_format);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout)
            .push_next(&mut rendering);
        let result = d.create_graphics_pipelines(cache, &[info], None);
        result.map(|p| p[0]).map_err(|(_, result)| GpuError::Vulkan { what: "vkCreateGraphicsPipelines", result })
    }
}

impl Drop for ScenePipeline {
    fn drop(&mut self) {
        let d = &self.dev.device;
        // SAFETY: the device is idle with respect to these objects (renders wait on a fence); null handles are
        // ignored by the destroy calls.
        unsafe {
            for p in self.variants.drain().map(|(_, p)| p).chain(self.shadow_masked.drain().map(|(_, p)| p)) {
                d.destroy_pipeline(p, None);
            }
            d.destroy_pipeline(self.shadow, None);
            d.destroy_shader_module(self.vertex_module, None);
            d.destroy_descriptor_pool(self.descriptor_pool, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
            if let Some(c) = &mut self.cache {
                c.destroy(d);
            }
        }
    }
}

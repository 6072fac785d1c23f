//! A frame in two draws of the scene. On llvmpipe every fragment of a SIMD group runs a branch that any other lane
//! takes, and code that no lane takes still runs, masked (gallivm executes both sides of a divergent `if`): so the
//! located grid and the walk of the tree, which only penumbrae need, cost every pixel of a frame that holds them
//! (docs/platform.md, "Branches no pixel takes"). The frame is therefore drawn twice:
//!
//! 1. **The first draw** (`ShaderVariant::first_draw`, `PENUMBRAE_LATER`): the whole shader but its grids and
//!    walks. A pixel whose lights the cheap proofs settle (the sun's cells: its cone clear of every triangle, or
//!    within an opaque one; the disk lights' walk: every ray clear) is shaded as the whole shader shades it; any
//!    other writes the coverage alpha [`LEFT_TO_SECOND_DRAW`]. Depth is tested and written as in one draw, so that
//!    every pixel keeps the surface one draw would keep (the first drawn of equal depths).
//! 2. **The mark**: the stencil is 1 where the colour's alpha is the mark, 0 elsewhere. Where the device exports
//!    stencil values from the fragment shader (`VK_EXT_shader_stencil_export`; lavapipe does), the first draw's
//!    fragments write it themselves (`MARK_BY_STENCIL`, scene.frag's `marked_coverage_alpha`), the stencil op
//!    replacing the value wherever the depth test passes (`Tests::FirstMarkingStencil`), so the pixel keeps the
//!    mark of the surface that it keeps; no pass between the draws, which share one rendering. Elsewhere a pass sets
//!    it from the colour (`MarkPass`: shaders/second_draw.frag over one triangle covering the target). The first
//!    way saves the pass, its barriers and a second rendering (docs/platform.md, "Branches no pixel takes").
//! 3. **The second draw**: the whole variant, with the depth test `EQUAL` and the stencil test `EQUAL 1`, its pass
//!    setting the stencil to 0. Only the surface the first draw kept reaches a marked pixel (of equal depths, the
//!    first drawn, as in one draw: it clears the mark before the next), and the tests run before the fragment shader,
//!    so no other pixel runs it.
//!
//! The images are bitwise those of one draw, marked either way (tests/shadows.rs,
//! `gpu_two_draws_render_the_one_draws_image`); the diagnostics `SUNSHADE_ONE_DRAW=1` draws once,
//! `SUNSHADE_MARK_BY_COLOUR=1` marks by colour where the device could by stencil.
//!
//! **The tree, once more where needed.** Where the only shadow rays are the sun's and its cells are partial (some
//! points have more triangles above them than the cells answer for: sunset.glb, brdfs.glb), the tree's walk serves
//! only the points whose sun cone also lists more than the shader keeps, and most frames have none. The whole
//! variant is then drawn without the tree (`ShaderVariant::tree_later`, `TREE_LATER`), marking such a pixel as the
//! first draw marks; after the readback, where a pixel holds the mark, the mark is set again and every draw made
//! once more with the variant that has the tree, under the second draw's tests (`Renderer::record_marked_pass`),
//! and the image read back again. The pipelines with the tree are made, and the tree's buffers laid out
//! (`Renderer::lay_out_walk_for`), only then.

use std::sync::Arc;

use ash::vk;

use super::context::Device;
use super::error::{GpuError, VkContext};
use super::memory::{image_barrier, Image2d};
use super::shaders;
use crate::film::Image;

/// The coverage alpha of a pixel the first draw leaves to the second (`LEFT_TO_SECOND_DRAW` in
/// shaders/bindings.glsl and shaders/second_draw.frag).
pub const LEFT_TO_SECOND_DRAW: f32 = -3.0;

pub use super::device_info::SCENE_DEPTH_STENCIL_FORMAT;

/// The mark's pipeline: one triangle over the target, its fragment reading the first draw's colours as a storage
/// image (binding 0) and setting the stencil where they hold the mark.
pub(crate) struct MarkPass {
    dev: Arc<Device>,
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    pipeline: vk::Pipeline,
}

impl MarkPass {
    pub fn new(dev: &Arc<Device>) -> Result<Self, GpuError> {
        let d = &dev.device;
        let mut out = Self {
            dev: dev.clone(),
            set_layout: vk::DescriptorSetLayout::null(),
            layout: vk::PipelineLayout::null(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            pipeline: vk::Pipeline::null(),
        };
        // SAFETY: valid device and create infos; what was made before an error is destroyed by Drop (null handles
        // are ignored).
        unsafe {
            let bindings = [vk::DescriptorSetLayoutBinding::default()
                .binding(0)
                .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::FRAGMENT)];
            out.set_layout = d
                .create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None)
                .vk("vkCreateDescriptorSetLayout")?;
            out.layout = d
                .create_pipeline_layout(
                    &vk::PipelineLayoutCreateInfo::default().set_layouts(std::slice::from_ref(&out.set_layout)),
                    None,
                )
                .vk("vkCreatePipelineLayout")?;
            let sizes = [vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_IMAGE, descriptor_count: 1 }];
            out.pool = d
                .create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes), None)
                .vk("vkCreateDescriptorPool")?;
            out.set = d
                .allocate_descriptor_sets(
                    &vk::DescriptorSetAllocateInfo::default()
                        .descriptor_pool(out.pool)
                        .set_layouts(std::slice::from_ref(&out.set_layout)),
                )
                .vk("vkAllocateDescriptorSets")?[0];
            out.pipeline = create_mark_pipeline(d, out.layout)?;
        }
        Ok(out)
    }

    /// Records the mark between the two draws, outside any rendering: the first draw's colours made readable, the
    /// stencil of `depth` set to 1 where they hold the mark (0 elsewhere: cleared when the first draw began), and
    /// the colours made an attachment again for the second draw.
    ///
    /// # Safety
    /// `cb` is being recorded outside a rendering; the GPU is idle (the descriptor set is updated here); `color`
    /// was last written as a colour attachment and `depth` as a depth-stencil attachment, both in their
    /// attachment-optimal layouts, which they are in again afterwards.
    pub unsafe fn record(&self, cb: vk::CommandBuffer, color: &Image2d, depth: &Image2d, area: vk::Rect2D) {
        let d = &self.dev.device;
        let color_aspect = vk::ImageAspectFlags::COLOR;
        let attachment_write =
            (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE);
        let shader_read = (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::SHADER_STORAGE_READ);
        let tests = vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
        let depth_access =
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE;
        let depth_aspect = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        let depth_layout = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        // SAFETY: as the caller guarantees.
        unsafe {
            let image_info =
                [vk::DescriptorImageInfo::default().image_view(color.view).image_layout(vk::ImageLayout::GENERAL)];
            let write = vk::WriteDescriptorSet::default()
                .dst_set(self.set)
                .dst_binding(0)
                .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                .image_info(&image_info);
            d.update_descriptor_sets(&[write], &[]);
            // The stencil is written by the first draw's tests, then the mark's, then read by the second draw's.
            let depth_tests = image_barrier(
                depth.image,
                depth_aspect,
                (tests, depth_access),
                (tests, depth_access),
                depth_layout,
                depth_layout,
            );
            let to_read = [
                image_barrier(
                    color.image,
                    color_aspect,
                    attachment_write,
                    shader_read,
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    vk::ImageLayout::GENERAL,
                ),
                depth_tests,
            ];
            d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_read));
            let depth_attachment = vk::RenderingAttachmentInfo::default()
                .image_view(depth.view)
                .image_layout(depth_layout)
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::STORE);
            d.cmd_begin_rendering(
                cb,
                &vk::RenderingInfo::default()
                    .render_area(area)
                    .layer_count(1)
                    .depth_attachment(&depth_attachment)
                    .stencil_attachment(&depth_attachment),
            );
            let viewport = vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: area.extent.width as f32,
                height: area.extent.height as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            };
            d.cmd_set_viewport(cb, 0, &[viewport]);
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, self.layout, 0, &[self.set], &[]);
            d.cmd_draw(cb, 3, 1, 0, 0);
            d.cmd_end_rendering(cb);
            let to_attachment = [
                image_barrier(
                    color.image,
                    color_aspect,
                    shader_read,
                    attachment_write,
                    vk::ImageLayout::GENERAL,
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                ),
                depth_tests,
            ];
            d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_attachment));
        }
    }
}

/// The mark's pipeline: no vertex input, no colour attachment, no depth test; the stencil set to 1 wherever the
/// fragment survives (second_draw.frag discards the unmarked).
unsafe fn create_mark_pipeline(d: &ash::Device, layout: vk::PipelineLayout) -> Result<vk::Pipeline, GpuError> {
    let module = |stage: &str| -> Result<vk::ShaderModule, GpuError> {
        let words = shaders::embedded(stage, &[])
            .ok_or_else(|| GpuError::ShaderCompile(format!("no module {stage} was built ahead of time")))?;
        // SAFETY: valid device; SPIR-V built by build.rs.
        unsafe { d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&words), None) }
            .vk("vkCreateShaderModule")
    };
    let vs = module("fullscreen.vert")?;
    let fs = match module("second_draw.frag") {
        Ok(fs) => fs,
        Err(e) => {
            // SAFETY: made above, unused.
            unsafe { d.destroy_shader_module(vs, None) };
            return Err(e);
        }
    };
    let stages = [
        vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::VERTEX).module(vs).name(c"main"),
        vk::PipelineShaderStageCreateInfo::default().stage(vk::ShaderStageFlags::FRAGMENT).module(fs).name(c"main"),
    ];
    let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
    let input_assembly =
        vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .line_width(1.0);
    let multisample =
        vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let mark = vk::StencilOpState::default()
        .fail_op(vk::StencilOp::KEEP)
        .pass_op(vk::StencilOp::REPLACE)
        .depth_fail_op(vk::StencilOp::KEEP)
        .compare_op(vk::CompareOp::ALWAYS)
        .compare_mask(1)
        .write_mask(1)
        .reference(1);
    let depth_stencil = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(false)
        .depth_write_enable(false)
        .stencil_test_enable(true)
        .front(mark)
        .back(mark);
    let blend = vk::PipelineColorBlendStateCreateInfo::default();
    let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .depth_attachment_format(SCENE_DEPTH_STENCIL_FORMAT)
        .stencil_attachment_format(SCENE_DEPTH_STENCIL_FORMAT);
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&input_assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth_stencil)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(layout)
        .push_next(&mut rendering);
    // SAFETY: valid device, modules and layout; the modules are no longer needed once the pipeline exists.
    unsafe {
        let result = d.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None);
        d.destroy_shader_module(vs, None);
        d.destroy_shader_module(fs, None);
        result.map(|p| p[0]).map_err(|(_, result)| GpuError::Vulkan { what: "vkCreateGraphicsPipelines", result })
    }
}

/// Which draw of a frame the scene's pipelines record: what their depth and stencil tests are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Tests {
    /// The one draw, or the first of two that marks by colour: depth `LESS`, no stencil test.
    OneOrFirst,
    /// The first of two whose fragments write the mark as their stencil value (`MARK_BY_STENCIL`): depth `LESS`,
    /// and where it passes the stencil replaced by the fragment's value (by 0 from a pipeline that writes none:
    /// a draw without a first variant), so that each pixel's stencil is the mark of the surface the depth test
    /// keeps, as the mark's pass would set it.
    FirstMarkingStencil,
    /// The second: depth `EQUAL`, stencil `EQUAL 1`, its pass clearing the mark so that a later surface of equal
    /// depth finds it cleared.
    Second,
}

/// Sets the depth and stencil tests of the scene's pipelines (dynamic state) for `tests`.
///
/// # Safety
/// `cb` is being recorded inside a rendering of the scene's target.
pub(crate) unsafe fn set_tests(d: &ash::Device, cb: vk::CommandBuffer, tests: Tests) {
    let faces = vk::StencilFaceFlags::FRONT_AND_BACK;
    let depth = if tests == Tests::Second { vk::CompareOp::EQUAL } else { vk::CompareOp::LESS };
    // (pass op, compare op, reference)
    let (pass, compare, reference) = match tests {
        Tests::FirstMarkingStencil => (vk::StencilOp::REPLACE, vk::CompareOp::ALWAYS, 0),
        _ => (vk::StencilOp::ZERO, vk::CompareOp::EQUAL, 1),
    };
    // SAFETY: as the caller guarantees.
    unsafe {
        d.cmd_set_depth_compare_op(cb, depth);
        d.cmd_set_stencil_test_enable(cb, tests != Tests::OneOrFirst);
        d.cmd_set_stencil_op(cb, faces, vk::StencilOp::KEEP, pass, vk::StencilOp::KEEP, compare);
        d.cmd_set_stencil_compare_mask(cb, faces, 1);
        d.cmd_set_stencil_write_mask(cb, faces, 1);
        d.cmd_set_stencil_reference(cb, faces, reference);
    }
}

/// `Err` where a pixel kept the mark after the second draw (which shades every marked pixel): a broken frame, not
/// an image.
pub fn check(image: &Image) -> Result<(), String> {
    match image.alpha_count_and_first(LEFT_TO_SECOND_DRAW) {
        None => Ok(()),
        Some((count, (x, y))) => Err(format!(
            "{count} pixel(s) (the first at ({x}, {y})) left by the frame's first draw were not shaded by its \
             second (SUNSHADE_ONE_DRAW=1 draws once)"
        )),
    }
}

impl Drop for MarkPass {
    fn drop(&mut self) {
        let d = &self.dev.device;
        // SAFETY: the device is idle with respect to these objects (renders wait on a fence); null handles are
        // ignored by the destroy calls.
        unsafe {
            d.destroy_pipeline(self.pipeline, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mark_is_the_shaders_mark() {
        for file in [include_str!("../../shaders/bindings.glsl"), include_str!("../../shaders/second_draw.frag")] {
            assert!(file.contains(&format!("#define LEFT_TO_SECOND_DRAW {LEFT_TO_SECOND_DRAW:.1}\n")));
        }
    }

    #[test]
    fn marked_pixels_refuse_the_image() {
        let mut image = Image::new(4, 3);
        image.pixels_mut().iter_mut().for_each(|p| p[3] = 1.0);
        assert!(check(&image).is_ok());
        image.pixels_mut()[6][3] = LEFT_TO_SECOND_DRAW;
        let e = check(&image).unwrap_err();
        assert!(e.contains("1 pixel(s)") && e.contains("(2, 1)"), "{e}");
    }
}

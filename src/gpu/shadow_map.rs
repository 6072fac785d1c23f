//! The shadow-map passes: a depth-only render of every triangle (both faces) through a map's frame
//! (`visibility::shadow_map`: orthographic for the sun, perspective for a disk light), into a D32 image the
//! fragment shader then reads texel by texel (bindings 5 and 6).

use std::sync::Arc;

use ash::vk;

use super::commands::Commands;
use super::context::Device;
use super::error::{GpuError, VkContext};
use super::memory::{image_barrier, subresource_range, Image2d};
use super::pipeline::DEPTH_FORMAT;

/// The depth image and the sampler the fragment shader reads it through (nearest; lookups are texelFetch).
pub(crate) struct DepthMap {
    dev: Arc<Device>,
    pub image: Image2d,
    pub sampler: vk::Sampler,
    pub size: u32,
}

impl DepthMap {
    /// A `size` × `size` map, left in SHADER_READ_ONLY_OPTIMAL (cleared to the far plane), so that binding 5 is
    /// valid before any shadow pass ran.
    pub fn new(dev: &Arc<Device>, size: u32) -> Result<Self, GpuError> {
        let image = Image2d::new(
            dev,
            size,
            size,
            DEPTH_FORMAT,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                | vk::ImageUsageFlags::SAMPLED
                | vk::ImageUsageFlags::TRANSFER_DST,
            vk::ImageAspectFlags::DEPTH,
            "shadow map",
        )?;
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0);
        // SAFETY: valid device and create info.
        let sampler = unsafe { dev.device.create_sampler(&info, None) }.vk("vkCreateSampler")?;
        let map = Self { dev: dev.clone(), image, sampler, size };
        // SAFETY: a fresh image; the submission is waited for.
        unsafe {
            let commands = Commands::new(dev)?;
            let cb = commands.begin(dev)?;
            let to_clear = [image_barrier(
                map.image.image,
                vk::ImageAspectFlags::DEPTH,
                (vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE),
                (vk::PipelineStageFlags2::CLEAR, vk::AccessFlags2::TRANSFER_WRITE),
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            )];
            dev.device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_clear));
            dev.device.cmd_clear_depth_stencil_image(
                cb,
                map.image.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 },
                &[subresource_range(vk::ImageAspectFlags::DEPTH)],
            );
            let to_read = [image_barrier(
                map.image.image,
                vk::ImageAspectFlags::DEPTH,
                (vk::PipelineStageFlags2::CLEAR, vk::AccessFlags2::TRANSFER_WRITE),
                (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::SHADER_SAMPLED_READ),
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            )];
            dev.device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_read));
            commands.submit_and_wait(dev, cb)?;
        }
        Ok(map)
    }

    /// Records the pass into `cb`: the map cleared to the far plane, `draw` records the draws (pipeline, push
    /// constants, buffers bound by it), then the map made readable by the fragment shader.
    pub unsafe fn record(&self, cb: vk::CommandBuffer, draw: impl FnOnce(vk::CommandBuffer)) {
        let d = &self.dev.device;
        // SAFETY: the caller records into a command buffer of this device; the map is not in use by the GPU.
        unsafe {
            let to_attachment = [image_barrier(
                self.image.image,
                vk::ImageAspectFlags::DEPTH,
                (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::SHADER_SAMPLED_READ),
                (
                    vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                    vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
                ),
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
            )];
            d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_attachment));
            let extent = vk::Extent2D { width: self.size, height: self.size };
            let area = vk::Rect2D { offset: vk::Offset2D { x: 0, y: 0 }, extent };
            let depth_attachment = vk::RenderingAttachmentInfo::default()
                .image_view(self.image.view)
                .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } });
            d.cmd_begin_rendering(
                cb,
                &vk::RenderingInfo::default().render_area(area).layer_count(1).depth_attachment(&depth_attachment),
            );
            let side = self.size as f32;
            d.cmd_set_viewport(
                cb,
                0,
                &[vk::Viewport { x: 0.0, y: 0.0, width: side, height: side, min_depth: 0.0, max_depth: 1.0 }],
            );
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_set_cull_mode(cb, vk::CullModeFlags::NONE);
            draw(cb);
            d.cmd_end_rendering(cb);
            let to_read = [image_barrier(
                self.image.image,
                vk::ImageAspectFlags::DEPTH,
                (
                    vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                    vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
                ),
                (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::SHADER_SAMPLED_READ),
                vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            )];
            d.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().image_memory_barriers(&to_read));
        }
    }
}

impl Drop for DepthMap {
    fn drop(&mut self) {
        // SAFETY: the GPU is done with the sampler (every submission is waited for).
        unsafe { self.dev.device.destroy_sampler(self.sampler, None) }
    }
}

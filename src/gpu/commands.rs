//! One command pool with one reusable primary command buffer and a fence: record, submit, wait.

use std::sync::Arc;

use ash::vk;

use super::context::Device;
use super::error::{GpuError, VkContext};

/// One command pool with one reusable primary command buffer and a fence.
pub(crate) struct Commands {
    dev: Arc<Device>,
    pool: vk::CommandPool,
    buffer: vk::CommandBuffer,
    fence: vk::Fence,
}

impl Commands {
    pub fn new(dev: &Arc<Device>) -> Result<Self, GpuError> {
        // SAFETY: valid device and create infos.
        unsafe {
            let pool = dev
                .device
                .create_command_pool(
                    &vk::CommandPoolCreateInfo::default()
                        .queue_family_index(dev.queue_family)
                        .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                    None,
                )
                .vk("vkCreateCommandPool")?;
            let mut out = Self { dev: dev.clone(), pool, buffer: vk::CommandBuffer::null(), fence: vk::Fence::null() };
            out.buffer = dev
                .device
                .allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(pool)
                        .level(vk::CommandBufferLevel::PRIMARY)
                        .command_buffer_count(1),
                )
                .vk("vkAllocateCommandBuffers")?[0];
            out.fence = dev.device.create_fence(&vk::FenceCreateInfo::default(), None).vk("vkCreateFence")?;
            Ok(out)
        }
    }

    /// Resets and begins the command buffer (the previous submission has been waited for).
    pub unsafe fn begin(&self, dev: &Device) -> Result<vk::CommandBuffer, GpuError> {
        // SAFETY: the buffer is not pending (submit_and_wait waits for completion).
        unsafe {
            dev.device
                .reset_command_buffer(self.buffer, vk::CommandBufferResetFlags::empty())
                .vk("vkResetCommandBuffer")?;
            dev.device
                .begin_command_buffer(
                    self.buffer,
                    &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .vk("vkBeginCommandBuffer")?;
        }
        Ok(self.buffer)
    }

    pub unsafe fn submit_and_wait(&self, dev: &Device, cb: vk::CommandBuffer) -> Result<(), GpuError> {
        // SAFETY: `cb` was begun by `begin`; the fence is unsignalled (reset after every wait).
        unsafe {
            dev.device.end_command_buffer(cb).vk("vkEndCommandBuffer")?;
            let buffers = [vk::CommandBufferSubmitInfo::default().command_buffer(cb)];
            let submit = [vk::SubmitInfo2::default().command_buffer_infos(&buffers)];
            dev.device.queue_submit2(dev.queue, &submit, self.fence).vk("vkQueueSubmit2")?;
            dev.device.wait_for_fences(&[self.fence], true, u64::MAX).vk("vkWaitForFences")?;
            dev.device.reset_fences(&[self.fence]).vk("vkResetFences")?;
        }
        Ok(())
    }
}

impl Drop for Commands {
    fn drop(&mut self) {
        // SAFETY: nothing is pending (every submission is waited for).
        unsafe {
            self.dev.device.destroy_fence(self.fence, None);
            self.dev.device.destroy_command_pool(self.pool, None);
        }
    }
}

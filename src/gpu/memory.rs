//! Buffers and images with their memory (through gpu-allocator), destroyed on drop.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::context::Device;
use super::error::{GpuError, VkContext};

/// A buffer and its memory.
pub(crate) struct Buffer {
    dev: Arc<Device>,
    pub buffer: vk::Buffer,
    allocation: Option<Allocation>,
    pub size: u64,
}

impl Buffer {
    pub fn new(
        dev: &Arc<Device>,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
        name: &str,
    ) -> Result<Self, GpuError> {
        // SAFETY: valid device; the buffer is bound to memory allocated for its own requirements.
        unsafe {
            let info =
                vk::BufferCreateInfo::default().size(size.max(4)).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
            let buffer = dev.device.create_buffer(&info, None).vk("vkCreateBuffer")?;
            let requirements = dev.device.get_buffer_memory_requirements(buffer);
            let allocation = allocate(dev, name, requirements, location, true);
            let allocation = match allocation {
                Ok(a) => a,
                Err(e) => {
                    dev.device.destroy_buffer(buffer, None);
                    return Err(e);
                }
            };
            let mut out = Self { dev: dev.clone(), buffer, allocation: None, size };
            let bind = dev.device.bind_buffer_memory(buffer, allocation.memory(), allocation.offset());
            out.allocation = Some(allocation);
            bind.vk("vkBindBufferMemory")?;
            Ok(out)
        }
    }

    /// A host-visible buffer holding `bytes`.
    pub fn with_data(
        dev: &Arc<Device>,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
        name: &str,
    ) -> Result<Self, GpuError> {
        let mut b = Self::new(dev, bytes.len() as u64, usage, MemoryLocation::CpuToGpu, name)?;
        b.mapped_mut()[..bytes.len()].copy_from_slice(bytes);
        Ok(b)
    }

    /// A host-visible storage buffer holding `bytes` (the fragment shader's inputs).
    pub fn storage(dev: &Arc<Device>, bytes: &[u8], name: &str) -> Result<Self, GpuError> {
        Self::with_data(dev, bytes, vk::BufferUsageFlags::STORAGE_BUFFER, name)
    }

    /// The mapped memory (host-visible and coherent: gpu-allocator requires coherence for CPU locations).
    pub fn mapped(&self) -> &[u8] {
        let a = self.allocation.as_ref().expect("allocated");
        &a.mapped_slice().expect("host-visible buffer")[..self.size as usize]
    }

    pub fn mapped_mut(&mut self) -> &mut [u8] {
        let size = self.size as usize;
        let a = self.allocation.as_mut().expect("allocated");
        &mut a.mapped_slice_mut().expect("host-visible buffer")[..size]
    }
}

/// A host-visible buffer of texels read through a buffer view (a uniform texel buffer: `texelFetch` returns a
/// texel as stored, with no filtering; RGBA32F as its floats, RGBA8UI as its integer codes), for data larger than
/// `maxStorageBufferRange` allows in a storage buffer.
pub(crate) struct TexelBuffer {
    pub view: vk::BufferView,
    pub buffer: Buffer,
}

impl TexelBuffer {
    /// `count` texels of `T` in `format`, written by `fill` straight into the mapped memory (no host copy).
    pub fn filled<T: bytemuck::Pod>(
        dev: &Arc<Device>,
        count: usize,
        format: vk::Format,
        name: &str,
        fill: impl FnOnce(&mut [T]),
    ) -> Result<Self, GpuError> {
        let limit = dev.info.max_texel_buffer_elements as usize;
        if count > limit {
            return Err(GpuError::TooLarge(format!(
                "the {name} take {count} texels; {} reads at most {limit} from one texel buffer",
                dev.info.name
            )));
        }
        let bytes = (count * std::mem::size_of::<T>()) as u64;
        let mut buffer =
            Buffer::new(dev, bytes, vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER, MemoryLocation::CpuToGpu, name)?;
        fill(bytemuck::cast_slice_mut(buffer.mapped_mut()));
        let info = vk::BufferViewCreateInfo::default().buffer(buffer.buffer).format(format).offset(0).range(bytes);
        // SAFETY: valid device and buffer created with UNIFORM_TEXEL_BUFFER usage.
        let view = unsafe { dev.device.create_buffer_view(&info, None) }.vk("vkCreateBufferView")?;
        Ok(Self { view, buffer })
    }

    /// `bytes` (a multiple of 16) as RGBA32UI texels, four words each: what the shaders read as `usamplerBuffer`
    /// and take floats from by their bits.
    pub fn rgba32ui(dev: &Arc<Device>, bytes: &[u8], name: &str) -> Result<Self, GpuError> {
        debug_assert_eq!(bytes.len() % 16, 0, "{name}: {} bytes", bytes.len());
        Self::filled(dev, bytes.len() / 16, vk::Format::R32G32B32A32_UINT, name, |out: &mut [[u32; 4]]| {
            bytemuck::cast_slice_mut::<[u32; 4], u8>(out).copy_from_slice(bytes)
        })
    }
}

impl Drop for TexelBuffer {
    fn drop(&mut self) {
        // SAFETY: the GPU is done with the view (renders wait on a fence); the buffer is dropped after it.
        unsafe {
            self.buffer.dev.device.destroy_buffer_view(self.view, None);
        }
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: the caller waited for the GPU to finish with this buffer (renders wait on a fence).
        unsafe {
            self.dev.device.destroy_buffer(self.buffer, None);
        }
        if let Some(a) = self.allocation.take() {
            if let Ok(mut allocator) = self.dev.allocator.lock() {
                let _ = allocator.free(a);
            }
        }
    }
}

/// A 2D image with one view.
pub(crate) struct Image2d {
    dev: Arc<Device>,
    pub image: vk::Image,
    pub view: vk::ImageView,
    allocation: Option<Allocation>,
    pub width: u32,
    pub height: u32,
}

impl Image2d {
    pub fn new(
        dev: &Arc<Device>,
        width: u32,
        height: u32,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        aspect: vk::ImageAspectFlags,
        name: &str,
    ) -> Result<Self, GpuError> {
        // SAFETY: valid device and create infos; partial failures destroy what was made.
        unsafe {
            let info = vk::ImageCreateInfo::default()
                .image_type(vk::ImageType::TYPE_2D)
                .format(format)
                .extent(vk::Extent3D { width, height, depth: 1 })
                .mip_levels(1)
                .array_layers(1)
                .samples(vk::SampleCountFlags::TYPE_1)
                .tiling(vk::ImageTiling::OPTIMAL)
                .usage(usage)
                .sharing_mode(vk::SharingMode::EXCLUSIVE)
                .initial_layout(vk::ImageLayout::UNDEFINED);
            let image = dev.device.create_image(&info, None).vk("vkCreateImage")?;
            let requirements = dev.device.get_image_memory_requirements(image);
            let allocation = match allocate(dev, name, requirements, MemoryLocation::GpuOnly, false) {
                Ok(a) => a,
                Err(e) => {
                    dev.device.destroy_image(image, None);
                    return Err(e);
                }
            };
            let mut out =
                Self { dev: dev.clone(), image, view: vk::ImageView::null(), allocation: None, width, height };
            let bind = dev.device.bind_image_memory(image, allocation.memory(), allocation.offset());
            out.allocation = Some(allocation);
            bind.vk("vkBindImageMemory")?;
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format)
                .subresource_range(subresource_range(aspect));
            out.view = dev.device.create_image_view(&view_info, None).vk("vkCreateImageView")?;
            Ok(out)
        }
    }
}

impl Drop for Image2d {
    fn drop(&mut self) {
        // SAFETY: the GPU is done with the image (renders wait on a fence).
        unsafe {
            if self.view != vk::ImageView::null() {
                self.dev.device.destroy_image_view(self.view, None);
            }
            self.dev.device.destroy_image(self.image, None);
        }
        if let Some(a) = self.allocation.take() {
            if let Ok(mut allocator) = self.dev.allocator.lock() {
                let _ = allocator.free(a);
            }
        }
    }
}

/// A layout transition of the whole of `image` with its access scopes `(stages, access)`.
pub(crate) fn image_barrier(
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    old_layout: vk::ImageLayout,
    new_layout: vk::ImageLayout,
) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src.0)
        .src_access_mask(src.1)
        .dst_stage_mask(dst.0)
        .dst_access_mask(dst.1)
        .old_layout(old_layout)
        .new_layout(new_layout)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(subresource_range(aspect))
}

pub(crate) fn subresource_range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

fn allocate(
    dev: &Arc<Device>,
    name: &str,
    requirements: vk::MemoryRequirements,
    location: MemoryLocation,
    linear: bool,
) -> Result<Allocation, GpuError> {
    let mut allocator = dev
        .allocator
        .lock()
        .map_err(|_| GpuError::Allocation { what: name.into(), message: "allocator lock poisoned".into() })?;
    allocator
        .allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        })
        .map_err(|e| GpuError::Allocation { what: name.into(), message: e.to_string() })
}

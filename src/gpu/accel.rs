//! Acceleration structures for the fragment shader's shadow rays (`VK_KHR_acceleration_structure`, queried by
//! `VK_KHR_ray_query`): one bottom level with one geometry, every triangle of the scene, from the scene's vertex
//! buffer (world-space positions, the first 12 bytes of each vertex) and an index buffer of its own whose indices
//! already include each draw's vertex offset, every triangle opaque; one top level with a single identity
//! instance, both faces occluding. Built once per uploaded scene and kept with it.
//!
//! (A geometry per draw with `firstVertex` and `primitiveOffset` gave wrong occluders on lavapipe 25.0; one
//! geometry with global indices leaves nothing to interpret.)

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::commands::Commands;
use super::context::Device;
use super::error::{GpuError, VkContext};
use super::memory::Buffer;

/// An acceleration structure and the buffer it lives in (destroyed before the buffer is freed).
struct Structure {
    loader: ash::khr::acceleration_structure::Device,
    handle: vk::AccelerationStructureKHR,
    _buffer: Buffer,
}

impl Drop for Structure {
    fn drop(&mut self) {
        // SAFETY: the GPU is done with it (every submission is waited for); its buffer is freed after this.
        unsafe { self.loader.destroy_acceleration_structure(self.handle, None) }
    }
}

/// The scene's bottom and top levels (the top dropped first).
pub(crate) struct SceneAccel {
    top: Structure,
    _bottom: Structure,
    _instances: Buffer,
}

fn address(dev: &Device, buffer: &Buffer) -> vk::DeviceAddress {
    // SAFETY: the buffer was created with SHADER_DEVICE_ADDRESS usage on a device with bufferDeviceAddress.
    unsafe { dev.device.get_buffer_device_address(&vk::BufferDeviceAddressInfo::default().buffer(buffer.buffer)) }
}

impl SceneAccel {
    /// Builds both levels over the triangles `indices` (u32, into the whole of `vertices`) of `vertices`
    /// (`vertex_count` of them, stride `vertex_stride` bytes, position first), and waits for the build.
    pub fn build(
        dev: &Arc<Device>,
        vertices: &Buffer,
        vertex_count: u32,
        vertex_stride: u64,
        indices: &[u32],
        opaque: bool,
    ) -> Result<Self, GpuError> {
        let loader = ash::khr::acceleration_structure::Device::new(&dev.instance.instance, &dev.device);
        let index_buffer = Buffer::with_data(
            dev,
            bytemuck::cast_slice(indices),
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            "accel indices",
        )?;
        let (vertex_address, index_address) = (address(dev, vertices), address(dev, &index_buffer));
        let geometries: Vec<vk::AccelerationStructureGeometryKHR> = [()]
            .iter()
            .map(|_| {
                let triangles = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
                    .vertex_format(vk::Format::R32G32B32_SFLOAT)
                    .vertex_data(vk::DeviceOrHostAddressConstKHR { device_address: vertex_address })
                    .vertex_stride(vertex_stride)
                    .max_vertex(vertex_count.saturating_sub(1))
                    .index_type(vk::IndexType::UINT32)
                    .index_data(vk::DeviceOrHostAddressConstKHR { device_address: index_address });
                // Opaque unless a triangle is alpha-masked: then every candidate hit goes to the shader, which
                // confirms it where the triangle's alpha reaches its cutoff (visibility.glsl).
                let flags = if opaque {
                    vk::GeometryFlagsKHR::OPAQUE
                } else {
                    vk::GeometryFlagsKHR::NO_DUPLICATE_ANY_HIT_INVOCATION
                };
                vk::AccelerationStructureGeometryKHR::default()
                    .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
                    .geometry(vk::AccelerationStructureGeometryDataKHR { triangles })
                    .flags(flags)
            })
            .collect();
        let build_ranges = [vk::AccelerationStructureBuildRangeInfoKHR {
            primitive_count: (indices.len() / 3) as u32,
            primitive_offset: 0,
            first_vertex: 0,
            transform_offset: 0,
        }];
        let counts: Vec<u32> = build_ranges.iter().map(|r| r.primitive_count).collect();
        let bottom_info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL)
            .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geometries);
        // SAFETY: valid device with the extension enabled; the infos reference live locals.
        unsafe {
            let mut bottom_sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
            loader.get_acceleration_structure_build_sizes(
                vk::AccelerationStructureBuildTypeKHR::DEVICE,
                &bottom_info,
                &counts,
                &mut bottom_sizes,
            );
            let bottom = create(dev, &loader, vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, bottom_sizes, "blas")?;
            let bottom_address = loader.get_acceleration_structure_device_address(
                &vk::AccelerationStructureDeviceAddressInfoKHR::default().acceleration_structure(bottom.handle),
            );
            let instance = vk::AccelerationStructureInstanceKHR {
                transform: vk::TransformMatrixKHR {
                    matrix: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
                },
                instance_custom_index_and_mask: vk::Packed24_8::new(0, 0xff),
                instance_shader_binding_table_record_offset_and_flags: vk::Packed24_8::new(
                    0,
                    vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE.as_raw() as u8,
                ),
                acceleration_structure_reference: vk::AccelerationStructureReferenceKHR {
                    device_handle: bottom_address,
                },
            };
            // SAFETY: AccelerationStructureInstanceKHR is plain data (64 bytes, no padding).
            let instance_bytes = std::slice::from_raw_parts(
                (&instance as *const vk::AccelerationStructureInstanceKHR).cast::<u8>(),
                std::mem::size_of::<vk::AccelerationStructureInstanceKHR>(),
            );
            let instances = Buffer::with_data(
                dev,
                instance_bytes,
                vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
                    | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
                "tlas instances",
            )?;
            let top_geometry = [vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::INSTANCES)
                .geometry(vk::AccelerationStructureGeometryDataKHR {
                    instances: vk::AccelerationStructureGeometryInstancesDataKHR::default()
                        .data(vk::DeviceOrHostAddressConstKHR { device_address: address(dev, &instances) }),
                })
                .flags(vk::GeometryFlagsKHR::OPAQUE)];
            let top_info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
                .ty(vk::AccelerationStructureTypeKHR::TOP_LEVEL)
                .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
                .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
                .geometries(&top_geometry);
            let mut top_sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
            loader.get_acceleration_structure_build_sizes(
                vk::AccelerationStructureBuildTypeKHR::DEVICE,
                &top_info,
                &[1],
                &mut top_sizes,
            );
            let top = create(dev, &loader, vk::AccelerationStructureTypeKHR::TOP_LEVEL, top_sizes, "tlas")?;

            // One scratch buffer for both builds (a barrier between them), aligned as the device asks.
            let align = dev.info.min_acceleration_structure_scratch_offset_alignment.max(1) as u64;
            let scratch_size = bottom_sizes.build_scratch_size.max(top_sizes.build_scratch_size) + align;
            let scratch = Buffer::new(
                dev,
                scratch_size,
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
                MemoryLocation::GpuOnly,
                "accel scratch",
            )?;
            let scratch_address = address(dev, &scratch).div_ceil(align) * align;
            let scratch_data = vk::DeviceOrHostAddressKHR { device_address: scratch_address };

            let commands = Commands::new(dev)?;
            let cb = commands.begin(dev)?;
            let bottom_build = bottom_info.dst_acceleration_structure(bottom.handle).scratch_data(scratch_data);
            loader.cmd_build_acceleration_structures(cb, &[bottom_build], &[&build_ranges]);
            let between = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
                .src_access_mask(vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR)
                .dst_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
                .dst_access_mask(
                    vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR
                        | vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR,
                )];
            dev.device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().memory_barriers(&between));
            let top_build = top_info.dst_acceleration_structure(top.handle).scratch_data(scratch_data);
            let top_range = [vk::AccelerationStructureBuildRangeInfoKHR {
                primitive_count: 1,
                primitive_offset: 0,
                first_vertex: 0,
                transform_offset: 0,
            }];
            loader.cmd_build_acceleration_structures(cb, &[top_build], &[&top_range]);
            let to_shader = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
                .src_access_mask(vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR)
                .dst_stage_mask(vk::PipelineStageFlags2::FRAGMENT_SHADER)
                .dst_access_mask(vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR)];
            dev.device.cmd_pipeline_barrier2(cb, &vk::DependencyInfo::default().memory_barriers(&to_shader));
            commands.submit_and_wait(dev, cb)?;
            drop(index_buffer);
            Ok(Self { top, _bottom: bottom, _instances: instances })
        }
    }

    /// The top level, for the descriptor set.
    pub fn top_level(&self) -> vk::AccelerationStructureKHR {
        self.top.handle
    }
}

/// An acceleration structure of `ty` in a buffer of the size the device asked for.
unsafe fn create(
    dev: &Arc<Device>,
    loader: &ash::khr::acceleration_structure::Device,
    ty: vk::AccelerationStructureTypeKHR,
    sizes: vk::AccelerationStructureBuildSizesInfoKHR,
    name: &str,
) -> Result<Structure, GpuError> {
    let buffer = Buffer::new(
        dev,
        sizes.acceleration_structure_size,
        vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
        MemoryLocation::GpuOnly,
        name,
    )?;
    let info = vk::AccelerationStructureCreateInfoKHR::default()
        .buffer(buffer.buffer)
        .size(sizes.acceleration_structure_size)
        .ty(ty);
    // SAFETY: valid device and buffer; the structure is destroyed before the buffer (SceneAccel's Drop).
    let handle = unsafe { loader.create_acceleration_structure(&info, None) }.vk("vkCreateAccelerationStructureKHR")?;
    Ok(Structure { loader: loader.clone(), handle, _buffer: buffer })
}

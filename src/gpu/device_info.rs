//! What sunshade needs to know about a physical device, and which device to use.

use ash::vk;

use super::error::GpuError;

/// The depth-stencil format of the scene's target and pipelines: the depth of `pipeline::DEPTH_FORMAT` (the same
/// values) with the stencil that marks the pixels of a frame's second draw (`second_draw`). A device must have it.
pub const SCENE_DEPTH_STENCIL_FORMAT: vk::Format = vk::Format::D32_SFLOAT_S8_UINT;

/// A physical device and the properties that matter to sunshade.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceInfo {
    /// Position in Vulkan's enumeration (what `--device N` names).
    pub index: usize,
    pub name: String,
    pub device_type: vk::PhysicalDeviceType,
    /// Vulkan version the device supports (major, minor, patch).
    pub api_version: (u32, u32, u32),
    pub driver_name: String,
    pub driver_info: String,
    /// Bits of sub-pixel precision in window coordinates (the reference rasterizer snaps to these).
    pub sub_pixel_precision_bits: u32,
    pub viewport_sub_pixel_bits: u32,
    pub max_image_dimension_2d: u32,
    pub max_viewport_dimensions: [u32; 2],
    /// Largest single allocation \[bytes\] (`maxMemoryAllocationSize`).
    pub max_memory_allocation_size: u64,
    /// Size of the largest device-local heap \[bytes\].
    pub device_local_heap_bytes: u64,
    pub max_push_constants_size: u32,
    /// `maxStorageBufferRange` \[bytes\]: the most one storage-buffer binding shows a shader (vertices, texels).
    pub max_storage_buffer_range: u32,
    /// `maxTexelBufferElements`: the most texels one texel buffer holds (the textures' texels).
    pub max_texel_buffer_elements: u32,
    /// `shaderFloat64`: the fragment shader then computes its barycentrics in f64.
    pub shader_float64: bool,
    pub framebuffer_color_sample_counts: vk::SampleCountFlags,
    /// A queue family with graphics (and so transfer) support.
    pub graphics_queue_family: Option<u32>,
    /// Why sunshade cannot use this device, if it cannot.
    pub unusable: Option<String>,
    /// `VK_KHR_ray_query`, `VK_KHR_acceleration_structure` (with `VK_KHR_deferred_host_operations`) and their
    /// features, and `bufferDeviceAddress`: shadow rays by ray queries possible. In a renderer's
    /// (`Renderer::device_info`): whether it casts them so ([`casts_ray_queries`]; it enables them all then).
    pub ray_query: bool,
    /// `VK_EXT_shader_stencil_export`: the first of a frame's two draws marks the pixels it leaves to the second
    /// by the stencil value its fragments write (`gpu::second_draw`), with no pass between the draws. Enabled
    /// wherever the device offers it.
    pub stencil_export: bool,
    /// `minAccelerationStructureScratchOffsetAlignment` (0 without acceleration structures).
    pub min_acceleration_structure_scratch_offset_alignment: u32,
    /// `vendorID`, `deviceID`, `driverVersion` and `pipelineCacheUUID`: what a pipeline cache is valid for.
    pub vendor_id: u32,
    pub device_id: u32,
    pub driver_version: u32,
    pub pipeline_cache_uuid: [u8; 16],
}

/// The environment variable that overrides where ray queries are used (`1`: wherever the device has them, `0`:
/// nowhere), for tests and measurements.
pub const RAY_QUERIES_VAR: &str = "SUNSHADE_RAY_QUERIES";

/// Whether a renderer on this device casts its shadow rays by ray queries rather than by the fragment shader's walk
/// of the occluders' BVH: where the device has them, on a GPU. On a CPU device (lavapipe) both are software, and the
/// shader's walk is the faster (on Mesa 25's lavapipe, overcast.glb's sky 1.3 s against 3.8 s by ray queries,
/// docs/platform.md) and gives the same image on every lavapipe, Mesa 22.3's included, which has none. `choice`
/// (`ContextOptions::ray_queries`), else [`RAY_QUERIES_VAR`], overrides the device's type.
pub fn casts_ray_queries(info: &DeviceInfo, choice: Option<bool>) -> bool {
    let from_env = || match std::env::var(RAY_QUERIES_VAR).as_deref() {
        Ok("1") => Some(true),
        Ok("0") => Some(false),
        _ => None,
    };
    info.ray_query && choice.or_else(from_env).unwrap_or(info.device_type != vk::PhysicalDeviceType::CPU)
}

impl DeviceInfo {
    pub fn type_name(&self) -> &'static str {
        match self.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
            vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
            vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
            vk::PhysicalDeviceType::CPU => "CPU",
            _ => "other",
        }
    }

    /// Preference when no `--device` is given: lower is better.
    fn rank(&self) -> u32 {
        match self.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        }
    }
}

pub(crate) fn describe(instance: &ash::Instance, physical: vk::PhysicalDevice, index: usize) -> DeviceInfo {
    // SAFETY: valid instance and physical device; the chained structs outlive the call.
    unsafe {
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut maint3 = vk::PhysicalDeviceMaintenance3Properties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver).push_next(&mut maint3);
        instance.get_physical_device_properties2(physical, &mut props2);
        let props = props2.properties;
        let limits = props.limits;
        let memory = instance.get_physical_device_memory_properties(physical);
        let heaps = &memory.memory_heaps[..memory.memory_heap_count as usize];
        let device_local_heap_bytes = heaps
            .iter()
            .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
            .map(|h| h.size)
            .max()
            .unwrap_or(0);
        let families = instance.get_physical_device_queue_family_properties(physical);
        let graphics_queue_family =
            families.iter().position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS)).map(|i| i as u32);
        let v = props.api_version;
        let api_version = (vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v));
        let mut features13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut features2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut features13);
        let mut unusable = None;
        let mut shader_float64 = false;
        if v < vk::API_VERSION_1_3 {
            unusable = Some(format!("supports Vulkan {}.{} only (1.3 needed)", api_version.0, api_version.1));
        } else {
            instance.get_physical_device_features2(physical, &mut features2);
            let geometry_shader = features2.features.geometry_shader;
            shader_float64 = features2.features.shader_float64 == vk::TRUE;
            if features13.dynamic_rendering == vk::FALSE || features13.synchronization2 == vk::FALSE {
                unusable = Some("lacks dynamicRendering or synchronization2".into());
            } else if geometry_shader == vk::FALSE {
                unusable = Some("lacks geometryShader (needed for gl_PrimitiveID in fragment shaders)".into());
            } else if !instance
                .get_physical_device_format_properties(physical, SCENE_DEPTH_STENCIL_FORMAT)
                .optimal_tiling_features
                .contains(vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT)
            {
                unusable = Some(
                    "lacks D32_SFLOAT_S8_UINT depth-stencil attachments (the frame's two draws need the stencil)"
                        .into(),
                );
            }
        }
        if graphics_queue_family.is_none() {
            unusable = Some("has no graphics queue".into());
        }
        let text = |s: Result<&std::ffi::CStr, _>| {
            s.map(|c: &std::ffi::CStr| c.to_string_lossy().into_owned()).unwrap_or_default()
        };
        let extensions = instance.enumerate_device_extension_properties(physical).unwrap_or_default();
        let offers = |name: &std::ffi::CStr| extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
        let ray_query = offers(c"VK_KHR_ray_query")
            && offers(c"VK_KHR_acceleration_structure")
            && offers(c"VK_KHR_deferred_host_operations")
            && {
                let mut accel = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
                let mut query = vk::PhysicalDeviceRayQueryFeaturesKHR::default();
                let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
                let mut features = vk::PhysicalDeviceFeatures2::default()
                    .push_next(&mut accel)
                    .push_next(&mut query)
                    .push_next(&mut v12);
                instance.get_physical_device_features2(physical, &mut features);
                accel.acceleration_structure == vk::TRUE
                    && query.ray_query == vk::TRUE
                    && v12.buffer_device_address == vk::TRUE
            };
        let stencil_export = offers(c"VK_EXT_shader_stencil_export");
        let min_acceleration_structure_scratch_offset_alignment = if ray_query {
            let mut accel = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
            let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut accel);
            instance.get_physical_device_properties2(physical, &mut props2);
            accel.min_acceleration_structure_scratch_offset_alignment
        } else {
            0
        };
        DeviceInfo {
            index,
            ray_query,
            stencil_export,
            min_acceleration_structure_scratch_offset_alignment,
            vendor_id: props.vendor_id,
            device_id: props.device_id,
            driver_version: props.driver_version,
            pipeline_cache_uuid: props.pipeline_cache_uuid,
            name: text(props.device_name_as_c_str()),
            device_type: props.device_type,
            api_version,
            driver_name: text(driver.driver_name_as_c_str()),
            driver_info: text(driver.driver_info_as_c_str()),
            sub_pixel_precision_bits: limits.sub_pixel_precision_bits,
            viewport_sub_pixel_bits: limits.viewport_sub_pixel_bits,
            max_image_dimension_2d: limits.max_image_dimension2_d,
            max_viewport_dimensions: limits.max_viewport_dimensions,
            max_memory_allocation_size: maint3.max_memory_allocation_size,
            device_local_heap_bytes,
            max_push_constants_size: limits.max_push_constants_size,
            max_storage_buffer_range: limits.max_storage_buffer_range,
            max_texel_buffer_elements: limits.max_texel_buffer_elements,
            shader_float64,
            framebuffer_color_sample_counts: limits.framebuffer_color_sample_counts,
            graphics_queue_family,
            unusable,
        }
    }
}

/// Picks a device: `selector` is an index or a case-insensitive name substring; without one, the best-ranked
/// usable device (discrete GPU, then integrated, virtual, CPU).
pub(crate) fn choose<'a>(
    devices: &'a [(vk::PhysicalDevice, DeviceInfo)],
    selector: Option<&str>,
) -> Result<(vk::PhysicalDevice, DeviceInfo), GpuError> {
    let list = || devices.iter().map(|(_, d)| format!("{}: {}", d.index, d.name)).collect::<Vec<_>>().join(", ");
    if devices.is_empty() {
        return Err(GpuError::NoDevice("Vulkan reports no physical device".into()));
    }
    let pick = |d: &'a (vk::PhysicalDevice, DeviceInfo)| -> Result<(vk::PhysicalDevice, DeviceInfo), GpuError> {
        match &d.1.unusable {
            Some(why) => Err(GpuError::DeviceNotFound(format!("selects '{}', which {why}", d.1.name))),
            None => Ok((d.0, d.1.clone())),
        }
    };
    match selector {
        Some(s) => {
            if let Ok(i) = s.trim().parse::<usize>() {
                let d = devices.get(i).ok_or_else(|| {
                    GpuError::DeviceNotFound(format!("{s}: no device with that index (devices: {})", list()))
                })?;
                return pick(d);
            }
            let needle = s.to_lowercase();
            let d = devices.iter().find(|(_, d)| d.name.to_lowercase().contains(&needle)).ok_or_else(|| {
                GpuError::DeviceNotFound(format!("'{s}': no device name contains it (devices: {})", list()))
            })?;
            pick(d)
        }
        None => {
            let best = devices.iter().filter(|(_, d)| d.unusable.is_none()).min_by_key(|(_, d)| d.rank());
            match best {
                Some(d) => pick(d),
                None => Err(GpuError::NoDevice(format!(
                    "none of the devices is usable ({})",
                    devices
                        .iter()
                        .map(|(_, d)| format!("{}: {}", d.name, d.unusable.as_deref().unwrap_or("?")))
                        .collect::<Vec<_>>()
                        .join("; ")
                ))),
            }
        }
    }
}

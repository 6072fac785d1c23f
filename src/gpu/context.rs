//! The Vulkan context: instance (no surface), optional validation, device selection, one queue, the allocator.
//!
//! Ownership: every GPU resource holds an `Arc<Device>`, which holds an `Arc<Instance>`, so objects are
//! destroyed in dependency order whatever order the caller drops them in (validation checks this).

use std::ffi::{c_void, CStr, CString};
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::device_info::{self, DeviceInfo};
use super::error::{GpuError, VkContext};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// How the fragment shader gets the position and normal it shades.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The device's interpolated varyings (on lavapipe: f32 plane equations anchored at the window origin).
    Device,
    /// The fragment shader's own perspective-correct barycentrics, in f32.
    BarycentricF32,
    /// The same in f64 (needs `shaderFloat64`): exact weights, f32 interpolation after them.
    BarycentricF64,
}

impl Interpolation {
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Device => "device",
            Interpolation::BarycentricF32 => "f32",
            Interpolation::BarycentricF64 => "f64",
        }
    }
}

impl std::str::FromStr for Interpolation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "device" => Ok(Interpolation::Device),
            "f32" => Ok(Interpolation::BarycentricF32),
            "f64" => Ok(Interpolation::BarycentricF64),
            _ => Err(format!("'{s}' is not an interpolation (device, f32, f64)")),
        }
    }
}

/// How to create the context and renderer.
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable `VK_LAYER_KHRONOS_validation` and collect its messages.
    pub validation: bool,
    /// `--device`: an index into the device list, or a case-insensitive substring of a device name.
    pub device: Option<String>,
    /// `None`: f64 barycentrics where the device has `shaderFloat64`, else f32.
    pub interpolation: Option<Interpolation>,
    /// Diagnostics only: compile the shaders with the textbook formulas (`pow(cos α, e)`, the device's `log`)
    /// instead of the accurate ones, to measure what those gain (`sunshade bench --brdf-chart`).
    pub naive_math: bool,
    /// Where the pipeline cache is kept on disk (`None`: in memory only; the CLI passes
    /// [`super::pipeline_cache::default_dir`] unless `--no-cache`).
    pub pipeline_cache_dir: Option<std::path::PathBuf>,
    /// Diagnostics only: hand the driver each fragment shader whole, with its specialization constants, instead of
    /// the module specialized for the pipeline (`sunshade_glsl::specialize`): for measuring what that saves and
    /// checking that images do not change (`SUNSHADE_WHOLE_SHADERS=1`, tests/startup.rs). Only on a device with
    /// `VK_EXT_shader_stencil_export` (lavapipe), whose capability the whole modules with shadow rays declare; their
    /// frames are drawn once (`one_draw`), as a module that declares the stencil output is taken to write it.
    pub whole_shaders: bool,
    /// Shadow rays by ray queries: `None` where the device has them and is a GPU (`device_info::casts_ray_queries`,
    /// which `SUNSHADE_RAY_QUERIES` overrides), `Some(true)` wherever the device has them, `Some(false)` never.
    pub ray_queries: Option<bool>,
    /// Diagnostics only: shade every pixel in one draw of the whole shader, without the first draw that settles the
    /// pixels the cheap proofs can (`ShaderVariant::first_draw`): for measuring what the two draws save and checking
    /// that images do not change (`SUNSHADE_ONE_DRAW=1`, `bench --shadow-cost`, tests/gpu_render.rs).
    pub one_draw: bool,
    /// Diagnostics only: where the device could mark a first draw's pixels by the stencil its fragments write
    /// (`DeviceInfo::stencil_export`), mark them by colour and the pass between the draws instead, as a device
    /// without `VK_EXT_shader_stencil_export` does (`SUNSHADE_MARK_BY_COLOUR=1`, tests/shadows.rs).
    pub mark_by_colour: bool,
}

impl ContextOptions {
    /// Validation on when the environment variable `SUNSHADE_VALIDATION` is `1`; whole shaders and one draw
    /// and marks by colour (diagnostics) when `SUNSHADE_WHOLE_SHADERS`, `SUNSHADE_ONE_DRAW` and
    /// `SUNSHADE_MARK_BY_COLOUR` are `1`.
    pub fn from_env() -> Self {
        let on = |k: &str| std::env::var(k).is_ok_and(|v| v == "1");
        Self {
            validation: on("SUNSHADE_VALIDATION"),
            whole_shaders: on("SUNSHADE_WHOLE_SHADERS"),
            one_draw: on("SUNSHADE_ONE_DRAW"),
            mark_by_colour: on("SUNSHADE_MARK_BY_COLOUR"),
            ..Default::default()
        }
    }
}

/// Messages the validation layer reported (warnings and errors). Shared, so that a test can still read it after
/// the context is gone (messages about objects left alive arrive at destruction).
#[derive(Debug, Default)]
pub struct ValidationLog {
    messages: Mutex<Vec<String>>,
}

impl ValidationLog {
    pub fn messages(&self) -> Vec<String> {
        self.messages.lock().map(|m| m.clone()).unwrap_or_default()
    }

    fn push(&self, message: String) {
        if let Ok(mut m) = self.messages.lock() {
            m.push(message);
        }
    }
}

/// The Vulkan instance and its debug messenger.
pub(crate) struct Instance {
    /// The loaded Vulkan library; must outlive every handle.
    _entry: ash::Entry,
    pub instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Kept alive while the messenger may call back with a pointer to it.
    pub log: Arc<ValidationLog>,
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: every device (which holds an Arc to this instance) is already destroyed.
        unsafe {
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// The logical device, its one queue and the memory allocator.
pub(crate) struct Device {
    pub instance: Arc<Instance>,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub allocator: ManuallyDrop<Mutex<Allocator>>,
    pub info: DeviceInfo,
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: resources holding an Arc<Device> are gone; the allocator must go before the device.
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
        }
    }
}

impl Instance {
    pub fn new(validation: bool) -> Result<Arc<Self>, GpuError> {
        // SAFETY: loading the system's Vulkan loader library.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| GpuError::NoLoader(e.to_string()))?;
        // SAFETY: plain queries and object creation with valid create infos.
        unsafe {
            let version =
                entry.try_enumerate_instance_version().vk("vkEnumerateInstanceVersion")?.unwrap_or(vk::API_VERSION_1_0);
            if version < vk::API_VERSION_1_3 {
                return Err(GpuError::NoDevice(format!(
                    "the Vulkan loader supports Vulkan {}.{} only",
                    vk::api_version_major(version),
                    vk::api_version_minor(version)
                )));
            }
            let mut layers = Vec::new();
            let mut extensions = Vec::new();
            if validation {
                let available = entry.enumerate_instance_layer_properties().vk("vkEnumerateInstanceLayerProperties")?;
                if !available.iter().any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER)) {
                    return Err(GpuError::NoValidationLayer);
                }
                layers.push(VALIDATION_LAYER.as_ptr());
                extensions.push(ash::ext::debug_utils::NAME.as_ptr());
            }
            let app_name = CString::new("sunshade").expect("no NUL");
            let app = vk::ApplicationInfo::default()
                .application_name(&app_name)
                .application_version(1)
                .engine_name(&app_name)
                .api_version(vk::API_VERSION_1_3);
            let log = Arc::new(ValidationLog::default());
            let mut debug_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE
                        | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&log) as *mut c_void);
            let mut create_info = vk::InstanceCreateInfo::default()
                .application_info(&app)
                .enabled_layer_names(&layers)
                .enabled_extension_names(&extensions);
            if validation {
                // Also catches messages from vkCreateInstance and vkDestroyInstance themselves.
                create_info = create_info.push_next(&mut debug_info);
            }
            let instance = entry.create_instance(&create_info, None).map_err(|result| match result {
                vk::Result::ERROR_INCOMPATIBLE_DRIVER => {
                    GpuError::NoDevice("the Vulkan loader finds no driver (no ICD)".into())
                }
                result => GpuError::Vulkan { what: "vkCreateInstance", result },
            })?;
            let debug = if validation {
                let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
                match loader.create_debug_utils_messenger(&debug_info, None) {
                    Ok(m) => Some((loader, m)),
                    Err(result) => {
                        instance.destroy_instance(None);
                        return Err(GpuError::Vulkan { what: "vkCreateDebugUtilsMessengerEXT", result });
                    }
                }
            } else {
                None
            };
            Ok(Arc::new(Self { _entry: entry, instance, debug, log }))
        }
    }

    /// Every physical device, described.
    pub fn devices(&self) -> Result<Vec<(vk::PhysicalDevice, DeviceInfo)>, GpuError> {
        // SAFETY: valid instance.
        let physicals = unsafe { self.instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
        Ok(physicals.into_iter().enumerate().map(|(i, p)| (p, device_info::describe(&self.instance, p, i))).collect())
    }
}

/// Called by the validation layer; records the message in the [`ValidationLog`] behind `user_data`.
unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes valid callback data; user_data is the ValidationLog the Instance keeps alive.
    unsafe {
        if data.is_null() || user_data.is_null() {
            return vk::FALSE;
        }
        let message = (*data).message_as_c_str().map(|m| m.to_string_lossy().into_owned()).unwrap_or_default();
        if super::drivers::is_own_skip_notice(&message) {
            return vk::FALSE;
        }
        let log = &*(user_data as *const ValidationLog);
        log.push(format!("[{severity:?} {kind:?}] {message}"));
    }
    vk::FALSE
}

impl Device {
    /// Creates the instance and the device chosen by `options.device` (default: a discrete or integrated GPU,
    /// else a CPU device such as lavapipe).
    pub fn new(options: &ContextOptions) -> Result<Arc<Self>, GpuError> {
        let instance = Instance::new(options.validation)?;
        let devices = instance.devices()?;
        let (physical, mut info) = device_info::choose(&devices, options.device.as_deref())?;
        info.ray_query = device_info::casts_ray_queries(&info, options.ray_queries);
        info.stencil_export &= !options.mark_by_colour;
        let queue_family = info.graphics_queue_family.expect("chosen devices have a graphics queue");
        // SAFETY: valid physical device; the create info only enables features the device reported.
        unsafe {
            let priorities = [1.0f32];
            let queue_info =
                [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&priorities)];
            let mut features13 =
                vk::PhysicalDeviceVulkan13Features::default().dynamic_rendering(true).synchronization2(true);
            // geometryShader: the fragment shader reads gl_PrimitiveID (SPIR-V's Geometry capability).
            // shaderFloat64 where present: the fragment shader's barycentrics in f64.
            let features =
                vk::PhysicalDeviceFeatures::default().geometry_shader(true).shader_float64(info.shader_float64);
            // Ray queries (shadow rays) where the renderer casts them: the extensions, their features and buffer
            // device addresses (acceleration structures are built from buffer addresses).
            let rq = info.ray_query;
            let mut features12 = vk::PhysicalDeviceVulkan12Features::default().buffer_device_address(rq);
            let mut accel = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
            let mut query = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
            let mut extensions = Vec::new();
            if rq {
                extensions.extend([
                    ash::khr::acceleration_structure::NAME.as_ptr(),
                    ash::khr::ray_query::NAME.as_ptr(),
                    ash::khr::deferred_host_operations::NAME.as_ptr(),
                ]);
            }
            if info.stencil_export {
                extensions.push(ash::ext::shader_stencil_export::NAME.as_ptr());
            }
            let mut create_info = vk::DeviceCreateInfo::default()
                .queue_create_infos(&queue_info)
                .enabled_features(&features)
                .push_next(&mut features13)
                .push_next(&mut features12)
                .enabled_extension_names(&extensions);
            if rq {
                create_info = create_info.push_next(&mut accel).push_next(&mut query);
            }
            let device = instance.instance.create_device(physical, &create_info, None).vk("vkCreateDevice")?;
            let queue = device.get_device_queue(queue_family, 0);
            let allocator = Allocator::new(&AllocatorCreateDesc {
                instance: instance.instance.clone(),
                device: device.clone(),
                physical_device: physical,
                debug_settings: Default::default(),
                buffer_device_address: info.ray_query,
                allocation_sizes: Default::default(),
            });
            let allocator = match allocator {
                Ok(a) => a,
                Err(e) => {
                    device.destroy_device(None);
                    return Err(GpuError::Allocation { what: "the allocator".into(), message: e.to_string() });
                }
            };
            Ok(Arc::new(Self {
                instance,
                device,
                queue,
                queue_family,
                allocator: ManuallyDrop::new(Mutex::new(allocator)),
                info,
            }))
        }
    }

    pub fn validation_log(&self) -> Arc<ValidationLog> {
        self.instance.log.clone()
    }
}

/// Lists the devices Vulkan reports, for `sunshade info`, without creating a logical device.
pub fn list_devices(options: &ContextOptions) -> Result<(Vec<DeviceInfo>, Result<usize, String>), GpuError> {
    let instance = Instance::new(options.validation)?;
    let devices = instance.devices()?;
    let chosen =
        device_info::choose(&devices, options.device.as_deref()).map(|(_, i)| i.index).map_err(|e| e.to_string());
    Ok((devices.into_iter().map(|(_, i)| i).collect(), chosen))
}

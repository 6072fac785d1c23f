//! Errors of the Vulkan backend, each one line.

use ash::vk;

/// The Debian packages that provide a Vulkan loader and the lavapipe CPU device.
pub const VULKAN_PACKAGES: &str = "libvulkan1 mesa-vulkan-drivers";

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("cannot load the Vulkan loader (libvulkan.so.1): {0}; install the packages {VULKAN_PACKAGES} (or run `make setup`)")]
    NoLoader(String),
    #[error(
        "no usable Vulkan 1.3 device: {0}; install the packages {VULKAN_PACKAGES} for lavapipe (or run `make setup`)"
    )]
    NoDevice(String),
    #[error("--device {0}")]
    DeviceNotFound(String),
    #[error(
        "validation was requested but VK_LAYER_KHRONOS_validation is not installed (install vulkan-validationlayers)"
    )]
    NoValidationLayer,
    #[error("Vulkan call {what} failed: {result}")]
    Vulkan { what: &'static str, result: vk::Result },
    #[error("GPU memory allocation for {what} failed: {message}")]
    Allocation { what: String, message: String },
    #[error("shader compilation failed: {0}")]
    ShaderCompile(String),
    #[error("{0}")]
    TooLarge(String),
    #[error("{0}")]
    Unsupported(String),
    /// llvmpipe's loop limiter cut some pixels' loops short (`gpu::loop_budget`): the image was refused.
    #[error("{0}")]
    LoopBudget(String),
    #[error("{} Vulkan validation message(s); the first: {}", .0.len(), .0.first().map(String::as_str).unwrap_or(""))]
    Validation(Vec<String>),
}

/// Shorthand: attach the name of the failing call to a `vk::Result`.
pub(crate) trait VkContext<T> {
    fn vk(self, what: &'static str) -> Result<T, GpuError>;
}

impl<T> VkContext<T> for Result<T, vk::Result> {
    fn vk(self, what: &'static str) -> Result<T, GpuError> {
        self.map_err(|result| GpuError::Vulkan { what, result })
    }
}

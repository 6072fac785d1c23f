//! The Vulkan renderer (ash). It knows nothing of glTF: it takes a [`Scene`](crate::scene::Scene) and
//! [`RenderSettings`](crate::settings::RenderSettings) and returns an [`Image`](crate::film::Image).
//!
//! - `drivers`: which installed drivers the Vulkan loader opens (Mesa's GPU drivers skipped without a GPU node);
//! - `context`: instance (no surface), validation messages, device choice, queue, allocator;
//! - `device_info`: the properties and limits that matter, and the `--device` choice;
//! - `memory`: buffers and images with their memory;
//! - `shaders`: the embedded GLSL and its run-time compilation;
//! - `layout`: the byte layouts shared with the shaders;
//! - `pipeline`: the graphics pipeline (dynamic rendering, RGBA32F + D32, with S8 for the scene);
//! - `commands`: record, submit, wait;
//! - `accel`: acceleration structures for the shadow rays (ray queries);
//! - `shadow_map`: the sun's shadow-map pass;
//! - `slice_passes`: the lights' slices, taken in passes before the frame where a fragment cannot take them;
//! - `second_draw`: a frame in two draws, the pixels the cheap proofs settle first, the penumbrae after;
//! - `frame_probe`: a sparse first look at a frame, to learn whether it would run out of llvmpipe's loop budget;
//! - `renderer`: upload, draw, readback.

mod accel;
mod commands;
mod context;
mod device_info;
pub mod drivers;
mod error;
pub mod frame_probe;
pub mod layout;
pub mod loop_budget;
mod memory;
mod pipeline;
pub mod pipeline_cache;
mod renderer;
pub mod second_draw;
pub mod shaders;
pub mod shadow_bvh;
mod shadow_map;
pub mod slice_gather;
pub mod slice_passes;
pub mod sun_cells;
pub mod texture_buffers;

pub use context::{list_devices, ContextOptions, Interpolation, ValidationLog};
pub use device_info::{casts_ray_queries, DeviceInfo, RAY_QUERIES_VAR};
pub use error::{GpuError, VULKAN_PACKAGES};
pub use pipeline::CreatedPipeline;
pub use renderer::{FrameTimings, GpuScene, Renderer, SetupTimings};

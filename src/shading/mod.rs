//! Shading: radiometry, BRDFs, and the outgoing radiance at a surface point.
//!
//! This Rust code is the specification. It is written for f64 and used as is by the CPU reference renderer;
//! the GLSL in `shaders/` (`radiometry.glsl`, `brdf.glsl`, `shade.glsl`) mirrors it name for name in f32.

pub mod brdf;
pub mod quadrature;
pub mod radiometry;
mod shade;

pub use shade::{
    disk_geometry, irradiance, radiance_out, safe_normalize, DiskModel, ShadingOptions, SunModel, SurfacePoint,
};

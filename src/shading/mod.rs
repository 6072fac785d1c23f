//! Shading: radiometry, BRDFs, and the outgoing radiance at a surface point.
//!
//! This Rust code is the specification. It is written for f64 and used as is by the CPU reference renderer;
//! the GLSL in `shaders/` (`lights/*.glsl`, `brdf.glsl`, `shade.glsl`, `visibility.glsl`, `surface.glsl`,
//! `texture_filter.glsl`) mirrors it name for name in f32.

pub mod albedo;
pub mod brdf;
pub mod brdf_fit;
pub mod disk_slices;
pub mod lights;
pub mod lobe;
pub mod measured;
pub mod options;
pub mod quadrature;
pub mod quantity;
pub mod radiometry;
pub(crate) mod shade;
pub mod sky_lune;
pub mod sky_slices;
pub mod slice_buckets;
pub mod slices_about_centre;
pub mod sun_slices;
pub mod surface;
pub mod texture_filter;
pub mod visibility;

pub use lights::disk::{disk_geometry, disk_lobe_integral};
pub use lights::sky::sky_lobe_integral;
pub use lights::sun::sun_lobe_integral;
pub use lobe::{
    lobe_about_z, lobe_about_z_rgb, lobe_width, normalized_lobe_integral, orthonormal_to, safe_normalize,
    specular_lobe, SurfacePoint,
};
pub use options::{
    DiskModel, ShadingOptions, SunChoice, SunModel, DEFAULT_SAMPLES_PER_AXIS, DEFAULT_SUN_SAMPLES_PER_AXIS,
};
pub use quantity::Quantity;
pub use shade::{irradiance, irradiance_visible, radiance_out, radiance_out_visible};
pub use visibility::{
    Occlusion, ShadowMapFilter, ShadowedLights, Shadowing, Shadows, Unoccluded, VisibilityRule,
    DEFAULT_SHADOW_MAP_SIZE, DEFAULT_SHADOW_SAMPLES_PER_AXIS, MAPPED_DISKS,
};

//! Exact visibility for the reference renderer: which points see which parts of a light. Ray casting in f64
//! against every triangle, through a BVH, with a watertight ray/triangle test so that rays do not slip through
//! shared edges.
//!
//! It knows neither Vulkan nor glTF: triangles come in as world-space corners. The sample grids and ray origins
//! that both renderers share are in `shading::visibility`.

pub mod bvh;
pub mod disk_cone;
pub mod occluders;
pub mod ray_triangle;
pub mod shadow_map;
pub mod sun_cells;
pub mod technique;

pub use bvh::Bvh;
pub use occluders::{can_occlude, occluder_bvh, occluder_triangles};
pub use ray_triangle::WatertightRay;
pub use technique::{choose, choose_reference, ShadowChoice};

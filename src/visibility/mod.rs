//! Exact visibility for the reference renderer: which points see which parts of a light. Ray casting in f64
//! against every triangle, through a BVH, with a watertight ray/triangle test so that rays do not slip through
//! shared edges.
//!
//! Groundwork for shadows (issue "Shadows"): the renderers do not use it yet. It knows neither Vulkan nor glTF:
//! triangles come in as world-space corners.

pub mod bvh;
pub mod occluders;
pub mod ray_triangle;

pub use bvh::Bvh;
pub use occluders::can_occlude;
pub use ray_triangle::WatertightRay;

//! sunshade: offscreen rendering of glTF 2.0 scenes in physical units, through Vulkan, with an independent CPU
//! reference renderer to check every image against.
//!
//! Data flows one way: glTF file → [`scene`] (world units) → [`shading`] (radiometry and BRDFs; the GLSL in
//! `shaders/` mirrors it) → two renderers, [`gpu`] (Vulkan) and `cpu` (the reference), both producing a
//! [`film::Image`] of radiance in W/(m²·sr) → `compare` → the command line.

pub mod authoring;
pub mod cli;
pub mod compare;
pub mod cpu;
pub mod film;
pub mod gpu;
pub mod scene;
pub mod settings;
pub mod shading;

pub use film::Image;

//! sunshade: offscreen rendering of glTF 2.0 scenes in physical units, through Vulkan, with an independent CPU
//! reference renderer to check every image against.
//!
//! Data flows one way: glTF file → [`scene`] (world units) → [`shading`] (radiometry and BRDFs; the GLSL in
//! `shaders/` mirrors it) → two renderers, [`gpu`] (Vulkan) and `cpu` (the reference), both producing a
//! [`film::Image`] of radiance in W/(m²·sr) → `compare` → the command line. [`testing`] serves users' own image
//! tests.

pub mod accuracy;
pub mod authoring;
/// The command line (`sunshade` binary). Not public API: its items may change at any time; use [`testing`] and
/// the renderers from a program.
#[doc(hidden)]
pub mod cli;
pub mod compare;
pub mod cpu;
pub mod daylight;
pub mod film;
pub mod gpu;
pub mod plot;
pub mod render;
pub mod scene;
pub mod settings;
pub mod shading;
#[cfg(test)]
mod test_rng;
pub mod testing;
pub mod visibility;

pub use film::Image;

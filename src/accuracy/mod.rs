//! Speed against error: how far an image is from the truth, not only from the other renderer.
//!
//! - [`converged`]: the converged reference, the CPU reference with every sampled integral refined until two
//!   doublings of its samples in a row change no pixel by more than a tenth of the accuracy claimed (pixels where
//!   that does not hold are reported);
//! - [`error`]: an image's error against such a truth (max relative with the diff's floor, p99, RMSE, pixels over
//!   1e-2, 1e-3, 1e-4);
//! - [`from_reference`]: the GPU's pixels that f32 leaves further from the reference than `--tolerance` allows,
//!   taken from the reference's image where it was rendered anyway;
//! - [`interpolation`]: the error f32 barycentrics add, bounded per pixel from the triangle's shape and the
//!   radiance's change over that move;
//! - [`pareto`]: which settings of a sweep are on the front of frame time against error;
//! - [`penumbrae`]: the pixels in a penumbra, where `--tolerance` makes no promise unless asked to;
//! - [`bounds`]: the sun models' error bounds, derived next to the code;
//! - [`predicted`]: a render's predicted error from those bounds, and `--tolerance`'s choice of models;
//! - [`refinement`]: the lobe grids' error under disk lights and the sky estimated from a ladder of grids
//!   (Richardson extrapolation with the observed order, Roache's GCI), where no bound is derived;
//! - [`material_study`]: that ladder run per material, each keeping the coarsest grid that meets the tolerance on
//!   its own pixels;
//! - [`trial`]: `--tolerance` on any renderer, with the delta sun tried first where its own image's peak decides,
//!   and the lobe grids' ladder where they need it.
//!
//! This module knows the reference renderer and the comparison, never Vulkan: GPU timings come from the caller.

pub mod bounds;
pub mod converged;
pub mod error;
pub mod from_reference;
pub mod interpolation;
pub mod material_study;
pub mod pareto;
pub mod penumbrae;
pub mod predicted;
pub mod promise;
pub mod refinement;
pub mod trial;

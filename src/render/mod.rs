//! One render, whoever asks for it: `sunshade render`, a `batch` job, a `test` case and the `testing` API all come
//! here, so that the same flags give the same image.
//!
//! ```text
//! flags (flags::SceneArgs, request::RequestArgs) ──► request::load, request::resolve_settings ──► Scene, settings
//!   ──► plan (shadow technique, visibility rule: for_gpu / for_reference) ──► on_gpu / on_reference
//!   ──► Rendered (image, final settings, prediction; --tolerance's pixels refined on the reference, or with
//!       --tolerance-by-study its measurements against the reference)
//! ```

mod error;
pub mod flags;
mod gpu;
pub mod plan;
mod reference;
pub mod refined_pixels;
pub mod request;
mod tolerance;
pub mod warnings;

pub use error::{one_line, RenderError};
pub use gpu::{on_gpu, predicted_barycentrics, Rendered};
pub use reference::on_reference;
pub use request::RequestArgs;
pub use tolerance::beyond_this_device;

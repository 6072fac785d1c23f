//! What `--tolerance` promises ([`Tolerance`]) and what a render within it returns ([`WithinTolerance`], or
//! [`TrialError`]): the types the trial (`super::trial`) and its per-material study (`super::material_study`)
//! share.

use super::predicted::Prediction;

/// What `--tolerance` promises: the max relative error (with the diff's floor) of the image, and whether it holds in
/// penumbrae too (`--tolerance`'s default). Without that (`--tolerance-outside-penumbrae`), the
/// promise holds outside the penumbrae of the sun and of disk lights (where a light is partly hidden), which the
/// prediction names as not bounded (`super::penumbrae` finds them to measure it), and the sky through occluders is
/// refused (its penumbra is every point that sees an occluder above its horizon: nearly the whole image); with it, the
/// shadow rays' grids are refined by the study with every other grid (`lobe_study`), whose first-order convergence in
/// penumbrae (`super::refinement`) makes it costly and refuses what the ladder's finest grid cannot reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    pub max_relative: f64,
    pub in_penumbrae: bool,
}

impl Tolerance {
    /// The promise outside the penumbrae (`--tolerance-outside-penumbrae`).
    pub fn outside_penumbrae(max_relative: f64) -> Self {
        Self { max_relative, in_penumbrae: false }
    }

    /// The promise in penumbrae too (`--tolerance`'s default).
    pub fn everywhere(max_relative: f64) -> Self {
        Self { max_relative, in_penumbrae: true }
    }
}

/// What [`render_within_tolerance`](super::trial::render_within_tolerance) rendered: the render kept and its predicted error (the renders made and not
/// kept, a delta trial or the coarser rungs of a lobe study, were dropped as soon as they had served).
pub struct WithinTolerance<T> {
    pub kept: T,
    pub prediction: Prediction,
}

/// Why [`render_within_tolerance`](super::trial::render_within_tolerance) rendered nothing: no setting can promise the tolerance, or the renderer failed.
pub enum TrialError<E> {
    Tolerance(String),
    Render(E),
}

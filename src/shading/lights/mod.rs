//! The lights, one file each: a light's irradiance term, its specular lobe integrated over it, and its visible
//! fraction, side by side (`shaders/lights/` mirrors each file). The sample grids the visible fractions share are in
//! `shading::visibility`, the lobe integrals' quadrature in `shading::shade`.

pub mod disk;
pub mod sky;
pub mod sun;

/// `|a − b| / |b|`, the lights' tests' relative difference.
#[cfg(test)]
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

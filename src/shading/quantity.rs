//! What a pixel holds: the radiance the camera sees, or the irradiance at the surface point it sees.
//!
//! - **Radiance** `L(x, ω_o)` [W/(m²·sr)] per linear RGB channel: the reflected (and emitted) radiance towards
//!   the viewer, the default.
//! - **Irradiance** `E(x) = ∫ V(x, l) L(x, l) (n·l) dΩ` [W/m²] per channel: the light arriving at the visible
//!   surface point x with its shading normal n, from every light's visible part (`shade::irradiance_visible`,
//!   the same exact per-light formulas and visible fractions the radiance uses), whatever the material
//!   reflects: the lecture's `E(x, y)` over the image. Emission is not irradiance and is left out.

/// The quantity a render's pixels hold (`--quantity`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Quantity {
    #[default]
    Radiance,
    Irradiance,
}

impl Quantity {
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Radiance => "radiance",
            Quantity::Irradiance => "irradiance",
        }
    }

    /// The unit of the pixels' values.
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Radiance => "W/(m²·sr)",
            Quantity::Irradiance => "W/m²",
        }
    }

    /// The unit in ASCII, as image files record it.
    pub fn unit_ascii(self) -> &'static str {
        match self {
            Quantity::Radiance => "W/(m2 sr)",
            Quantity::Irradiance => "W/m2",
        }
    }
}

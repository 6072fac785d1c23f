//! Daylight: where the sun is at a date, time and place ([`solar_position`](mod@solar_position), the NREL Solar
//! Position Algorithm), how the scene is turned on the Earth ([`orientation`]), and what a clear sky delivers ([`clear_sky`]). It turns
//! `--time`/`--location` into a sun direction in scene axes and, unless the user gives them, the sun's `E⊥` and the
//! sky's radiance. Knows neither glTF nor Vulkan: its output is numbers the settings turn into lights.

pub mod clear_sky;
pub mod delta_t;
pub mod instant;
pub mod location;
pub mod orientation;
pub mod solar_position;
mod spa_terms;

pub use clear_sky::{ineichen_perez, ClearSky, ClearSkyInputs};
pub use instant::Instant;
pub use orientation::Orientation;
pub use solar_position::{solar_position, Atmosphere, Location, SolarPosition, SpaOptions};

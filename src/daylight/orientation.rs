//! How a scene sits on the Earth. glTF has no geographic orientation, so sunshade takes it from the user:
//! `north_deg`, the direction of north in the scene's horizontal XZ plane as a scene azimuth (the convention of
//! `--sun-azimuth`: 0° = +Z, 90° = +X). Up is +Y (glTF's). The default, 180°, puts north at −Z, east at +X, south at
//! +Z and west at −X, so a glTF camera's default view (along −Z) looks north.
//!
//! Compass azimuths (clockwise from north seen from above) and scene azimuths (0 = +Z towards 90 = +X, which
//! turns counter-clockwise seen from above, +Y towards the viewer) run in opposite senses: a compass azimuth `A`
//! is the scene azimuth `north_deg − A`.

use glam::DVec3;

/// Scene azimuth of north when none is given \[degrees\]: north is −Z.
pub const DEFAULT_NORTH_DEG: f64 = 180.0;

/// The scene's local horizon frame: unit east, north and up vectors in world axes (right-handed: east × north = up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orientation {
    pub east: DVec3,
    pub north: DVec3,
    pub up: DVec3,
}

impl Orientation {
    /// North at scene azimuth `north_deg` (0 = +Z, 90 = +X), up +Y.
    pub fn from_north(north_deg: f64) -> Self {
        let a = north_deg.to_radians();
        let north = DVec3::new(a.sin(), 0.0, a.cos());
        // East is a quarter turn clockwise from north seen from above: scene azimuth north − 90°.
        let east = DVec3::new(-a.cos(), 0.0, a.sin());
        Self { east, north, up: DVec3::Y }
    }

    /// World direction of a vector given in (east, north, up) components.
    pub fn to_world(&self, enu: [f64; 3]) -> DVec3 {
        self.east * enu[0] + self.north * enu[1] + self.up * enu[2]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_north_is_minus_z_and_the_frame_is_right_handed() {
        let o = Orientation::from_north(DEFAULT_NORTH_DEG);
        assert!((o.north - DVec3::NEG_Z).length() < 1e-15 && (o.east - DVec3::X).length() < 1e-15);
        for north in [0.0, 37.0, 90.0, 180.0, 271.5] {
            let o = Orientation::from_north(north);
            assert!((o.east.cross(o.north) - o.up).length() < 1e-15, "{north}");
            // A compass azimuth A is the scene azimuth north − A: e.g. east (A = 90).
            let a = (north - 90.0f64).to_radians();
            assert!((o.east - DVec3::new(a.sin(), 0.0, a.cos())).length() < 1e-15, "{north}");
        }
    }
}

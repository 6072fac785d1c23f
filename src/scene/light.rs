//! Light sources in world units: the sun, disk skylights and a uniform sky.
//!
//! Radiometric quantities are in W/m² (irradiance) and W/(m²·sr) (radiance), per linear RGB channel.
//! The formulas that turn these into irradiance at a surface live in `shading::radiometry`.

use glam::Vec3;

/// The sun's mean angular diameter seen from the Earth \[degrees\].
pub const SUN_ANGULAR_DIAMETER_DEGREES: f64 = 0.53;

/// The sun: a disk of uniform radiance `L_sun` and angular diameter `δ` in the direction `direction`.
///
/// It is specified by `E⊥`, the irradiance on a surface facing the sun, per channel:
/// `E⊥ = L_sun · π sin²(δ/2)` exactly (the projected solid angle of the sun's cone), which is `L_sun · Ω_sun` to
/// within 5.3·10⁻⁶ relative for the real sun (see `shading::radiometry`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Unit vector from the scene towards the sun, world axes.
    pub direction: Vec3,
    /// `E⊥` [W/m²] per channel.
    pub irradiance: [f32; 3],
    /// Angular diameter `δ` \[rad\] (0.53° by default).
    pub angular_diameter: f32,
}

/// The largest radius and centre coordinate of a disk light \[m\]. The disk formulas square lengths in f32
/// (`R² + f²`); 10¹⁵ m keeps those squares (≤ 1e30 plus the scene's extent) far inside f32's range (3.4e38), so
/// that a disk light never turns an image into inf/inf = NaN.
pub const MAX_DISK_EXTENT_M: f64 = 1e15;

/// A disk skylight: radius `R` \[m\], uniform radiance `L0` [W/(m²·sr)], emitting from one face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskLight {
    /// Centre \[m\], world space.
    pub center: Vec3,
    /// Unit vector in the direction the disk emits (its lit side faces this way).
    pub direction: Vec3,
    /// Radius `R` \[m\].
    pub radius: f32,
    /// Radiance `L0` [W/(m²·sr)] per channel.
    pub radiance: [f32; 3],
}

/// All the lights of a render; their contributions add up.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lights {
    pub sun: Option<Sun>,
    pub disks: Vec<DiskLight>,
    /// Overcast sky: uniform radiance [W/(m²·sr)] per channel over the directions above the horizontal (the
    /// upper hemisphere), `E = π L0 (1 + cos t)/2` on a surface tilted by t and unshadowed; the scene occludes it
    /// where shadows are cast by rays (shadow maps leave it unoccluded).
    pub sky: Option<[f32; 3]>,
}

/// One light of a render, as a loop over [`Lights::iter`] meets it. Every `match` on it names each kind, so that
/// a new kind of light is a compile error wherever a consumer has not said what it does with it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light<'a> {
    Sun(&'a Sun),
    /// Disk light number `index` of [`Lights::disks`] (shadows, maps and slices are kept per disk).
    Disk {
        index: usize,
        disk: &'a DiskLight,
    },
    /// The overcast sky's radiance [W/(m²·sr)] per channel ([`Lights::sky`]).
    Sky(&'a [f32; 3]),
}

impl Lights {
    /// Every light, in the order their terms are summed (the sun, the disks in order, the sky): a fixed order, so
    /// that an image does not depend on how its lights were listed.
    pub fn iter(&self) -> impl Iterator<Item = Light<'_>> {
        let disks = self.disks.iter().enumerate().map(|(index, disk)| Light::Disk { index, disk });
        self.sun.iter().map(Light::Sun).chain(disks).chain(self.sky.iter().map(Light::Sky))
    }

    /// Whether there is no light at all.
    pub fn is_empty(&self) -> bool {
        self.iter().next().is_none()
    }
}

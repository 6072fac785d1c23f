//! A render's shading choices: each light's model (the sun as a disk or a direction, disk lights exact or as
//! small sources), the sample grids of the lobe integrals, and the shadow technique with its grids.

use super::visibility::{ShadowMapFilter, Shadows, DEFAULT_SHADOW_MAP_SIZE, DEFAULT_SHADOW_SAMPLES_PER_AXIS};

/// How the sun is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SunModel {
    /// A disk of angular diameter δ: exact irradiance (also while it sets); specular lobes integrated over it.
    #[default]
    Disk,
    /// A single direction: `E⊥ max(0, cos θ)`, lobes evaluated at the sun's centre.
    Delta,
}

/// How disk lights are evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DiskModel {
    /// The exact irradiance, horizon clipping included; lobes integrated over the disk.
    #[default]
    Exact,
    /// The small-source estimate `L0 A cosθ_r cosθ_d / d²`, lobes evaluated towards the centre.
    SmallSource,
}

/// The sun's model and grid for one material's surfaces (`RenderSettings::sun_per_material`): `--tolerance`
/// chooses the cheapest that meets its bound for each material's lobe, so that a wide lobe or a Lambertian surface
/// does not pay for the sharpest lobe's grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SunChoice {
    pub sun: SunModel,
    /// Grid side over the sun's disk (`SunModel::Disk`).
    pub sun_samples_per_axis: u32,
}

/// Default sample counts (per axis of the stratified grids).
pub const DEFAULT_SUN_SAMPLES_PER_AXIS: u32 = 8;
pub const DEFAULT_SAMPLES_PER_AXIS: u32 = 16;

/// Model choices for a render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadingOptions {
    pub sun: SunModel,
    pub disk: DiskModel,
    /// Grid side for integrating lobes over the sun's disk (`n²` directions).
    pub sun_samples_per_axis: u32,
    /// Grid side for integrating lobes over disk lights and the sky (`n²` samples each).
    pub samples_per_axis: u32,
    /// How shadows are computed.
    pub shadows: Shadows,
    /// Grid side of each light's visible-fraction grid (`n²` shadow rays per light and pixel).
    pub shadow_samples_per_axis: u32,
    /// Side of the sun's shadow map \[texels\] (`--shadows map`).
    pub shadow_map_size: u32,
    /// Its filter.
    pub shadow_map_filter: ShadowMapFilter,
    /// What the pixels hold: radiance, or the irradiance at the surface.
    pub quantity: super::Quantity,
    /// How the reference takes the lights' visible fractions (the GPU's grids, or slices).
    pub visibility_rule: super::visibility::VisibilityRule,
}

impl Default for ShadingOptions {
    fn default() -> Self {
        Self {
            sun: SunModel::Disk,
            disk: DiskModel::Exact,
            sun_samples_per_axis: DEFAULT_SUN_SAMPLES_PER_AXIS,
            samples_per_axis: DEFAULT_SAMPLES_PER_AXIS,
            shadows: Shadows::Auto,
            shadow_samples_per_axis: DEFAULT_SHADOW_SAMPLES_PER_AXIS,
            shadow_map_size: DEFAULT_SHADOW_MAP_SIZE,
            shadow_map_filter: ShadowMapFilter::Pcss,
            quantity: super::Quantity::Radiance,
            visibility_rule: super::visibility::VisibilityRule::Grid,
        }
    }
}

impl std::str::FromStr for SunModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "disk" => Ok(SunModel::Disk),
            "delta" => Ok(SunModel::Delta),
            _ => Err(format!("'{s}' is not a sun model (disk, delta)")),
        }
    }
}

impl std::str::FromStr for DiskModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "exact" => Ok(DiskModel::Exact),
            "small-source" => Ok(DiskModel::SmallSource),
            _ => Err(format!("'{s}' is not a disk model (exact, small-source)")),
        }
    }
}

//! A clear sky: how much of the sun reaches the ground and how bright the sky is, from the sun's zenith angle, the
//! site's elevation and the air's turbidity. The Ineichen–Perez model: P. Ineichen and R. Perez (2002), "A new
//! airmass independent formulation for the Linke turbidity coefficient", Solar Energy 73(3), 151–157, with
//! Kasten & Young's (1989) relative air mass. Broadband (the whole solar spectrum, W/m²): sunshade gives all three
//! channels the same value, a white sun and sky.
//!
//! What it gives a render: the sun's direct normal irradiance `E⊥ = DNI`, and an overcast-style sky of uniform
//! radiance `L_sky = DHI/π`, the radiance of a uniform sky that puts the model's diffuse horizontal irradiance
//! on a horizontal plane (`∫ L cos θ dΩ = π L` over the upper hemisphere). A real clear sky is not uniform (its
//! brightness gathers around the sun and at the horizon, Perez et al. 1993), so on tilted and shaded surfaces the
//! sky's share is an approximation; and sunshade's sky is the upper hemisphere only, so a vertical wall gets
//! `π L/2` from it and nothing from the ground (whose reflected light is not modelled).

/// The total solar irradiance at 1 AU [W/m²] (Kopp & Lean 2011: 1360.8 ± 0.5).
pub const SOLAR_CONSTANT_W_M2: f64 = 1360.8;

/// Linke turbidity when none is given: 3, a typical clear sky of the mid-latitudes (Remund et al. 2003 give
/// monthly climatologies from about 2 in clean mountain air to 6 and more in hazy cities).
pub const DEFAULT_LINKE_TURBIDITY: f64 = 3.0;

/// Inputs of the clear-sky model besides the sun's zenith.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClearSkyInputs {
    /// Linke turbidity `T_L` at air mass 2 (1 = a clean, dry atmosphere; 2–7 usual).
    pub linke_turbidity: f64,
    /// Site elevation above sea level \[m\].
    pub elevation_m: f64,
    /// Site pressure \[mbar\], for the absolute air mass.
    pub pressure_mbar: f64,
    /// Earth–sun distance \[AU\], for the extraterrestrial irradiance `I₀ = SOLAR_CONSTANT / R²`.
    pub distance_au: f64,
}

/// Clear-sky irradiances [W/m²].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClearSky {
    /// Global horizontal irradiance.
    pub ghi: f64,
    /// Direct normal irradiance (the sun's `E⊥`).
    pub dni: f64,
    /// Diffuse horizontal irradiance, `GHI − DNI cos θ_z`.
    pub dhi: f64,
}

impl ClearSky {
    /// Radiance [W/(m²·sr)] of the uniform sky that gives `dhi` on a horizontal plane.
    pub fn sky_radiance(&self) -> f64 {
        self.dhi / std::f64::consts::PI
    }
}

/// Kasten & Young (1989) relative optical air mass at apparent zenith `zenith_deg` (finite to 90°: 37.92 there).
pub fn relative_air_mass(zenith_deg: f64) -> f64 {
    1.0 / (zenith_deg.to_radians().cos() + 0.50572 * (96.07995 - zenith_deg).powf(-1.6364))
}

/// The Ineichen–Perez clear sky at apparent zenith `zenith_deg`; zero at and below the horizon.
pub fn ineichen_perez(zenith_deg: f64, inputs: &ClearSkyInputs) -> ClearSky {
    // At and below the horizon, and for a NaN zenith, no sun and no sky.
    if zenith_deg.is_nan() || zenith_deg >= 90.0 {
        return ClearSky { ghi: 0.0, dni: 0.0, dhi: 0.0 };
    }
    let cos_z = zenith_deg.to_radians().cos();
    let tl = inputs.linke_turbidity;
    let h = inputs.elevation_m;
    let am = relative_air_mass(zenith_deg) * inputs.pressure_mbar / 1013.25;
    let i0 = SOLAR_CONSTANT_W_M2 / (inputs.distance_au * inputs.distance_au);
    let (fh1, fh2) = ((-h / 8000.0).exp(), (-h / 1250.0).exp());
    let (cg1, cg2) = (5.09e-5 * h + 0.868, 3.92e-5 * h + 0.0387);
    let ghi = cg1 * i0 * cos_z * (-cg2 * am * (fh1 + fh2 * (tl - 1.0))).exp();
    let b = 0.664 + 0.163 / fh1;
    let dni_beam = b * i0 * (-0.09 * am * (tl - 1.0)).exp();
    // Ineichen & Perez's limit: the beam may not exceed what the global leaves after a minimum diffuse share.
    let dni_from_ghi = ghi * (1.0 - (0.1 - 0.2 * (-tl).exp()) / (0.1 + 0.882 / fh1)) / cos_z;
    let dni = dni_beam.min(dni_from_ghi).max(0.0);
    ClearSky { ghi, dni, dhi: (ghi - dni * cos_z).max(0.0) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sea_level(tl: f64) -> ClearSkyInputs {
        ClearSkyInputs { linke_turbidity: tl, elevation_m: 0.0, pressure_mbar: 1013.25, distance_au: 1.0 }
    }

    #[test]
    fn magnitudes_of_a_clear_day() {
        // Sun overhead at sea level, T_L 3: about 1050 W/m² global, 900 direct, 100–150 diffuse, as clear-sky
        // measurements go (e.g. Ineichen & Perez's figures).
        let s = ineichen_perez(0.0, &sea_level(3.0));
        assert!((1000.0..1100.0).contains(&s.ghi), "{s:?}");
        assert!((850.0..950.0).contains(&s.dni) && (80.0..200.0).contains(&s.dhi), "{s:?}");
        // Hazier air: less direct, more diffuse; a lower sun: less of everything; below the horizon: nothing.
        let hazy = ineichen_perez(0.0, &sea_level(6.0));
        assert!(hazy.dni < s.dni && hazy.dhi > s.dhi);
        let low = ineichen_perez(80.0, &sea_level(3.0));
        assert!(low.ghi < s.ghi / 4.0 && low.dni < s.dni && low.dni > 0.0);
        assert_eq!(ineichen_perez(90.0, &sea_level(3.0)).ghi, 0.0);
        assert_eq!(ineichen_perez(f64::NAN, &sea_level(3.0)).dni, 0.0);
        // GHI = DNI cos z + DHI by construction.
        for z in [0.0, 30.0, 60.0, 85.0, 89.9] {
            let c = ineichen_perez(z, &sea_level(3.0));
            let closure = c.dni * z.to_radians().cos() + c.dhi - c.ghi;
            assert!(closure.abs() < 1e-9 * c.ghi.max(1.0), "{z}: {c:?}");
        }
        assert!((relative_air_mass(60.0) - 2.0).abs() < 0.01 && (relative_air_mass(90.0) - 37.92).abs() < 0.01);
    }
}

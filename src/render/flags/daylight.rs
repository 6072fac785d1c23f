//! The daylight flags: `--time`, `--location` and the scene's orientation give the sun's direction (the NREL
//! Solar Position Algorithm); the Ineichen–Perez clear sky gives its `E⊥` and the sky's radiance unless
//! `--sun-irradiance`/`--sun-radiance` or `--sky-radiance` say otherwise. `--from/--to/--step` set the instants of
//! an accumulation (`--quantity irradiation|sun-hours`, [`AccumulationArgs`]).

use clap::Args;
use glam::DVec3;

use super::parse_finite;
use crate::daylight::clear_sky::{ineichen_perez, ClearSky, ClearSkyInputs, DEFAULT_LINKE_TURBIDITY};
use crate::daylight::location::parse_location;
use crate::daylight::orientation::{Orientation, DEFAULT_NORTH_DEG};
use crate::daylight::{solar_position, Atmosphere, Instant, Location, SolarPosition, SpaOptions};

fn parse_instant(s: &str) -> Result<Instant, String> {
    Instant::parse(s).map_err(|e| e.to_string())
}

/// A duration: a number with a unit, `90s`, `15min`, `1h`, `1d` (or ISO 8601's `PT1H`, `PT15M`, `P1D`) →
/// seconds, positive.
pub fn parse_duration(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let bad = || format!("'{s}' is not a duration (e.g. 1h, 15min, 90s, 1d, PT30M)");
    let (number, unit_s) = if let Some(iso) = t.strip_prefix('P') {
        let (days, time) = iso.split_once('T').unwrap_or((iso, ""));
        let mut seconds = 0.0;
        if !days.is_empty() {
            seconds += days.strip_suffix('D').and_then(|d| d.parse::<f64>().ok()).ok_or_else(bad)? * 86_400.0;
        }
        let mut rest = time;
        for (unit, scale) in [('H', 3600.0), ('M', 60.0), ('S', 1.0)] {
            if let Some((n, r)) = rest.split_once(unit) {
                seconds += n.parse::<f64>().map_err(|_| bad())? * scale;
                rest = r;
            }
        }
        if !rest.is_empty() {
            return Err(bad());
        }
        (seconds, 1.0)
    } else {
        let split = t.find(|c: char| c.is_ascii_alphabetic()).ok_or_else(bad)?;
        let (n, unit) = t.split_at(split);
        let scale = match unit {
            "s" | "sec" => 1.0,
            "m" | "min" => 60.0,
            "h" | "hour" | "hours" => 3600.0,
            "d" | "day" | "days" => 86_400.0,
            _ => return Err(bad()),
        };
        (n.trim().parse::<f64>().map_err(|_| bad())?, scale)
    };
    let seconds = number * unit_s;
    if !(seconds.is_finite() && seconds >= 1e-3) {
        return Err(format!("'{s}': a step must be at least a millisecond"));
    }
    Ok(seconds)
}

/// The flags that place the scene on the Earth and in time.
#[derive(Args, Clone, Debug, Default)]
pub struct DaylightArgs {
    /// The sun of this instant: ISO 8601 with its UTC offset, e.g. 2026-06-21T12:00:00+02:00 (or Z). Sets the
    /// sun's direction (needs --location) and, unless --sun-irradiance/--sun-radiance and --sky-radiance say
    /// otherwise, its E⊥ and the sky's radiance from a clear sky (docs/daylight.md).
    #[arg(help_heading = "Daylight", long, value_parser = parse_instant, value_name = "ISO8601",
          conflicts_with_all = ["sun_dir", "sun_elevation", "sun_azimuth", "from"], requires = "location")]
    pub time: Option<Instant>,

    /// The place: latitude and longitude [degrees, north and east positive] and elevation [m, default 0].
    #[arg(help_heading = "Daylight", long, value_parser = parse_location, allow_hyphen_values = true,
          value_name = "LAT,LON[,ELEVATION_M]")]
    pub location: Option<Location>,

    /// Where north lies in the scene's XZ plane, as a --sun-azimuth angle (0 = +Z, 90 = +X); the default 180
    /// makes north −Z, east +X, south +Z, west −X.
    #[arg(help_heading = "Daylight", long, default_value_t = DEFAULT_NORTH_DEG, value_parser = parse_finite,
          allow_hyphen_values = true, value_name = "DEGREES")]
    pub north: f64,

    /// The geometric (airless) sun position: no atmospheric refraction (by default the apparent position, with
    /// refraction for --pressure and --temperature).
    #[arg(help_heading = "Daylight", long)]
    pub no_refraction: bool,

    /// Mean air pressure at the site for refraction and air mass [mbar = hPa] (default: the standard atmosphere
    /// at the site's elevation, 1013.25 at sea level).
    #[arg(help_heading = "Daylight", long, value_parser = parse_finite, value_name = "MBAR")]
    pub pressure: Option<f64>,

    /// Mean air temperature at the site for refraction [°C] (default: the standard atmosphere's, 15 at sea level).
    #[arg(help_heading = "Daylight", long, value_parser = parse_finite, allow_hyphen_values = true, value_name = "CELSIUS")]
    pub temperature: Option<f64>,

    /// ΔT = TT − UT [s] (default: Espenak & Meeus's polynomials, e.g. 75 s in 2026; measured 69 s in 2025).
    #[arg(help_heading = "Daylight", long, value_parser = parse_finite, allow_hyphen_values = true, value_name = "SECONDS")]
    pub delta_t: Option<f64>,

    /// UT1 − UTC [s] (IERS Bulletin A; |DUT1| < 0.9 s, 0.0042° of the sun's hour angle per second).
    #[arg(help_heading = "Daylight", long, default_value_t = 0.0, value_parser = parse_finite, allow_hyphen_values = true,
          value_name = "SECONDS")]
    pub delta_ut1: f64,

    /// Linke turbidity of the clear sky (Ineichen–Perez; 2 very clear, 3 typical, 5–7 hazy).
    #[arg(help_heading = "Daylight", long, default_value_t = DEFAULT_LINKE_TURBIDITY, value_parser = parse_finite,
          value_name = "TL")]
    pub linke_turbidity: f64,
}

/// The most steps an accumulation takes (a year in 1-minute steps is 525 600): the list of steps is held in
/// memory.
pub const MAX_STEPS: usize = 10_000_000;

/// The flags of an accumulation over time (`--quantity irradiation|sun-hours`).
#[derive(Args, Clone, Debug, Default)]
pub struct AccumulationArgs {
    /// Start of an accumulation (--quantity irradiation or sun-hours), ISO 8601 like --time.
    #[arg(help_heading = "Accumulation", long, value_parser = parse_instant, value_name = "ISO8601",
          requires_all = ["to", "step", "location"], conflicts_with_all = ["sun_dir", "sun_elevation", "sun_azimuth"])]
    pub from: Option<Instant>,

    /// End of the accumulation (exclusive).
    #[arg(help_heading = "Accumulation", long, value_parser = parse_instant, value_name = "ISO8601", requires = "from")]
    pub to: Option<Instant>,

    /// Length of each step: the sun of each step's midpoint stands for the whole step (e.g. 1h, 15min, PT30M).
    #[arg(help_heading = "Accumulation", long, value_parser = parse_duration, value_name = "DURATION", requires = "from")]
    pub step: Option<f64>,

    /// Render only steps K, K+N, K+2N, … (counting from 0) of the accumulation; add the shards' images with
    /// `sunshade sum`.
    #[arg(help_heading = "Accumulation", long, value_name = "K/N", value_parser = super::parse_shard, requires = "from")]
    pub shard: Option<(usize, usize)>,

    /// `--quantity sun-hours`: a step counts when the direct sun on the surface is at least this [W/m²] (120: the
    /// WMO's threshold of sunshine, here on the surface, through its shadows).
    #[arg(help_heading = "Accumulation", long, default_value_t = 120.0, value_parser = parse_finite, value_name = "W/M2")]
    pub sun_hours_threshold: f64,
}

impl AccumulationArgs {
    /// Refuses values outside what an accumulation takes.
    pub fn check(&self) -> Result<(), String> {
        if self.sun_hours_threshold < 0.0 {
            return Err("--sun-hours-threshold must be non-negative".into());
        }
        if let (Some(from), Some(to)) = (self.from, self.to) {
            if to <= from {
                return Err(format!("--to {to} is not after --from {from}"));
            }
            if let Some(step) = self.step {
                let steps = to.seconds_since(from) / step;
                if steps > MAX_STEPS as f64 {
                    return Err(format!(
                        "--from {from} --to {to} in steps of {step} s makes {steps:.3e} steps; at most {MAX_STEPS}"
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The sun and sky of one instant at one place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DaylightAt {
    pub instant: Instant,
    pub location: Location,
    pub position: SolarPosition,
    /// Unit vector towards the sun in scene axes.
    pub direction: DVec3,
    /// The clear sky at this sun (zero with the sun down).
    pub clear_sky: ClearSky,
}

impl DaylightArgs {
    /// The atmosphere assumed: the flags, else the standard atmosphere at the site's elevation.
    pub fn atmosphere(&self, location: &Location) -> Atmosphere {
        let standard = Atmosphere::standard(location.elevation_m);
        Atmosphere {
            pressure_mbar: self.pressure.unwrap_or(standard.pressure_mbar),
            temperature_c: self.temperature.unwrap_or(standard.temperature_c),
        }
    }

    /// Refuses values outside what the models take.
    pub fn check(&self) -> Result<(), String> {
        if let Some(p) = self.pressure {
            if !(100.0..=1100.0).contains(&p) {
                return Err(format!("--pressure {p}: expected 100..1100 mbar"));
            }
        }
        if let Some(t) = self.temperature {
            if !(-90.0..=60.0).contains(&t) {
                return Err(format!("--temperature {t}: expected -90..60 °C"));
            }
        }
        if !(1.0..=10.0).contains(&self.linke_turbidity) {
            return Err(format!("--linke-turbidity {}: the model holds for 1..10", self.linke_turbidity));
        }
        Ok(())
    }

    /// The sun and clear sky at `instant` (needs `--location`).
    pub fn at(&self, instant: Instant) -> Option<DaylightAt> {
        let location = self.location?;
        let atmosphere = self.atmosphere(&location);
        let options = SpaOptions {
            delta_t_s: self.delta_t,
            delta_ut1_s: self.delta_ut1,
            refraction: (!self.no_refraction).then_some(atmosphere),
        };
        let position = solar_position(instant, &location, &options);
        let direction = Orientation::from_north(self.north).to_world(position.east_north_up());
        let inputs = ClearSkyInputs {
            linke_turbidity: self.linke_turbidity,
            elevation_m: location.elevation_m,
            pressure_mbar: atmosphere.pressure_mbar,
            distance_au: position.distance_au,
        };
        let clear_sky = ineichen_perez(position.zenith_deg, &inputs);
        Some(DaylightAt { instant, location, position, direction, clear_sky })
    }

    /// The daylight of `--time`, if given.
    pub fn at_time(&self) -> Option<DaylightAt> {
        self.at(self.time?)
    }
}

impl DaylightAt {
    /// The warning for a sun below the horizon.
    pub fn below_horizon_warning(&self) -> Option<String> {
        (!self.position.is_up()).then(|| {
            format!(
                "the sun is below the horizon at {} (elevation {:.3}°): no direct sun, and no clear sky",
                self.instant,
                self.position.elevation_deg()
            )
        })
    }

    /// JSON of where the sun is (for `sunshade sun --json` and the settings' record).
    pub fn json(&self, north_deg: f64, linke_turbidity: f64) -> serde_json::Value {
        let p = &self.position;
        let l = &self.location;
        serde_json::json!({
            "time": self.instant.to_string(),
            "location": {"latitude_deg": l.latitude_deg, "longitude_deg": l.longitude_deg, "elevation_m": l.elevation_m},
            "zenith_deg": p.zenith_deg,
            "azimuth_deg": p.azimuth_deg,
            "elevation_deg": p.elevation_deg(),
            "refraction": p.refraction,
            "geometric_zenith_deg": p.geometric_zenith_deg,
            "up": p.is_up(),
            "direction": self.direction.to_array(),
            "north_deg": north_deg,
            "declination_deg": p.declination_deg,
            "hour_angle_deg": p.hour_angle_deg,
            "distance_au": p.distance_au,
            "delta_t_s": p.delta_t_s,
            "clear_sky": {
                "model": "Ineichen-Perez",
                "linke_turbidity": linke_turbidity,
                "dni_w_m2": self.clear_sky.dni,
                "ghi_w_m2": self.clear_sky.ghi,
                "dhi_w_m2": self.clear_sky.dhi,
                "sky_radiance_w_m2_sr": self.clear_sky.sky_radiance(),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations() {
        for (text, seconds) in [
            ("1h", 3600.0),
            ("15min", 900.0),
            ("90s", 90.0),
            ("1d", 86_400.0),
            ("PT30M", 1800.0),
            ("P1DT1H", 90_000.0),
            ("0.5 h", 1800.0),
        ] {
            assert_eq!(parse_duration(text).unwrap(), seconds, "{text}");
        }
        for bad in ["", "1", "h", "-1h", "0s", "1y", "PT1X", "nanh"] {
            assert!(parse_duration(bad).is_err(), "{bad}");
        }
    }
}

//! Where the sun is: the Solar Position Algorithm of Reda & Andreas (2004), "Solar position algorithm for solar
//! radiation applications", Solar Energy 76(5), 577–589 (NREL/TP-560-34302, revised 2008). Stated uncertainty
//! ±0.0003° in zenith and azimuth for the years −2000 to 6000. Equation numbers below are the paper's, section 3.
//!
//! All angles are computed in f64 degrees or radians as the paper writes them. Where precision could be lost:
//! - the sidereal time multiplies days since J2000.0 by ~361°/day; the days come from integer seconds
//!   ([`Instant::days_since_j2000`]), not from a Julian date near 2.45·10⁶, which would hold only ~40 µs
//!   (~1.7·10⁻⁷°) in f64;
//! - the elevation near the zenith: `asin` of a value near 1 loses half the digits (eq. 42), so the horizon
//!   coordinates are taken from the sun's local east/north/up vector with `atan2`, which is well conditioned at
//!   every angle and equal to the paper's eqs. 42–46 otherwise;
//! - the geocentric latitude (eq. 35) is `atan2(0.99664719 sin φ, cos φ)` rather than `atan(0.99664719 tan φ)`,
//!   finite at the poles.

use super::instant::Instant;
use super::spa_terms::{EarthTerm, B0, B1, L0, L1, L2, L3, L4, L5, NUTATION, R0, R1, R2, R3, R4};

/// An observer on the Earth (WGS-84-like ellipsoid as the paper uses it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Location {
    /// Geodetic latitude φ \[degrees\], north positive, −90..90.
    pub latitude_deg: f64,
    /// Longitude σ \[degrees\], east of Greenwich positive, −180..180.
    pub longitude_deg: f64,
    /// Elevation above the ellipsoid \[m\].
    pub elevation_m: f64,
}

/// The atmosphere the refraction correction assumes (eq. 43): annual means at the site.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Atmosphere {
    /// Pressure [mbar = hPa].
    pub pressure_mbar: f64,
    /// Temperature [°C].
    pub temperature_c: f64,
}

impl Atmosphere {
    /// The ICAO standard atmosphere at `elevation_m` (valid in the troposphere, below 11 km): 1013.25 hPa and
    /// 15 °C at sea level, a lapse of 6.5 K/km, `P = P₀ (T/T₀)^5.25588`. sunshade's default when none is given.
    pub fn standard(elevation_m: f64) -> Self {
        let h = elevation_m.clamp(-500.0, 11_000.0);
        let t_kelvin = 288.15 - 0.0065 * h;
        Self { pressure_mbar: 1013.25 * (t_kelvin / 288.15).powf(5.25588), temperature_c: t_kelvin - 273.15 }
    }
}

/// The inputs beyond instant and place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpaOptions {
    /// ΔT = TT − UT \[s\]; `None` takes [`super::delta_t::delta_t_seconds`].
    pub delta_t_s: Option<f64>,
    /// UT1 − UTC \[s\] (|DUT1| < 0.9 s; each second turns the Earth by 0.0042°).
    pub delta_ut1_s: f64,
    /// The atmosphere for refraction, or `None` for the geometric (airless) position.
    pub refraction: Option<Atmosphere>,
}

/// The sun seen from a place at an instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolarPosition {
    /// Topocentric zenith angle θ \[degrees\]: 0 overhead, 90 at the horizon; includes refraction when asked.
    pub zenith_deg: f64,
    /// Topocentric azimuth Φ \[degrees\], clockwise from north (east = 90), 0..360.
    pub azimuth_deg: f64,
    /// Whether `zenith_deg` includes atmospheric refraction.
    pub refraction: bool,
    /// Topocentric zenith without refraction \[degrees\].
    pub geometric_zenith_deg: f64,
    /// Geocentric declination δ and right ascension α \[degrees\]; local hour angle H \[degrees\].
    pub declination_deg: f64,
    pub right_ascension_deg: f64,
    pub hour_angle_deg: f64,
    /// Topocentric declination δ′ \[degrees\] (δ seen from the observer rather than the Earth's centre).
    pub topocentric_declination_deg: f64,
    /// Earth–sun distance R \[AU\].
    pub distance_au: f64,
    /// ΔT used \[s\].
    pub delta_t_s: f64,
    /// Intermediate values of the paper's worked example, for the tests: heliocentric L, B \[degrees\], nutation
    /// Δψ, Δε and true obliquity ε \[degrees\], apparent sun longitude λ \[degrees\].
    pub heliocentric_longitude_deg: f64,
    pub heliocentric_latitude_deg: f64,
    pub nutation_longitude_deg: f64,
    pub nutation_obliquity_deg: f64,
    pub obliquity_deg: f64,
    pub apparent_longitude_deg: f64,
}

impl SolarPosition {
    /// Elevation above the horizon \[degrees\] (90 − zenith).
    pub fn elevation_deg(&self) -> f64 {
        90.0 - self.zenith_deg
    }

    /// Whether the sun's centre is above the horizon.
    pub fn is_up(&self) -> bool {
        self.zenith_deg < 90.0
    }

    /// Unit vector towards the sun in local (east, north, up) axes.
    pub fn east_north_up(&self) -> [f64; 3] {
        let (z, a) = (self.zenith_deg.to_radians(), self.azimuth_deg.to_radians());
        [z.sin() * a.sin(), z.sin() * a.cos(), z.cos()]
    }
}

/// `Σ A cos(B + C·τ)` over one table (eq. 9).
fn periodic_sum(terms: &[EarthTerm], jme: f64) -> f64 {
    terms.iter().map(|&(a, b, c)| a * (b + c * jme).cos()).sum()
}

/// `(Σᵢ Xᵢ τ^i) / 10⁸` (eqs. 10–11) for the series X₀, X₁, ... [rad or AU].
fn series(tables: &[&[EarthTerm]], jme: f64) -> f64 {
    tables.iter().rev().fold(0.0, |acc, t| acc * jme + periodic_sum(t, jme)) / 1e8
}

/// Reduces an angle to [0, 360) degrees.
fn limit_degrees(x: f64) -> f64 {
    x.rem_euclid(360.0)
}

fn cubic(t: f64, c: [f64; 4]) -> f64 {
    ((c[3] * t + c[2]) * t + c[1]) * t + c[0]
}

/// The sun's position seen from `location` at `instant` (UT; see [`Instant`]).
pub fn solar_position(instant: Instant, location: &Location, options: &SpaOptions) -> SolarPosition {
    let ut = instant.plus_seconds(options.delta_ut1_s);
    let delta_t_s = options.delta_t_s.unwrap_or_else(|| super::delta_t::delta_t_seconds(ut.decimal_year()));
    // 3.1–3.2: time scales. `days` is JD − 2451545 (UT), `jce`/`jme` the ephemeris centuries and millennia.
    let days = ut.days_since_j2000();
    let jc = days / 36_525.0;
    let jce = (days + delta_t_s / 86_400.0) / 36_525.0;
    let jme = jce / 10.0;

    // 3.2: the Earth's heliocentric longitude, latitude and radius (eqs. 9–12).
    let l_deg = limit_degrees(series(&[&L0, &L1, &L2, &L3, &L4, &L5], jme).to_degrees());
    let b_deg = series(&[&B0, &B1], jme).to_degrees();
    let r_au = series(&[&R0, &R1, &R2, &R3, &R4], jme);
    // 3.3: geocentric longitude and latitude (eqs. 13–14).
    let theta = limit_degrees(l_deg + 180.0);
    let beta = -b_deg;

    // 3.4: nutation in longitude and obliquity (eqs. 15–23).
    let x = [
        cubic(jce, [297.85036, 445_267.111_480, -0.001_914_2, 1.0 / 189_474.0]),
        cubic(jce, [357.52772, 35_999.050_340, -0.000_160_3, -1.0 / 300_000.0]),
        cubic(jce, [134.96298, 477_198.867_398, 0.008_697_2, 1.0 / 56_250.0]),
        cubic(jce, [93.27191, 483_202.017_538, -0.003_682_5, 1.0 / 327_270.0]),
        cubic(jce, [125.04452, -1_934.136_261, 0.002_070_8, 1.0 / 450_000.0]),
    ];
    let (mut dpsi, mut deps) = (0.0, 0.0);
    for term in &NUTATION {
        let arg: f64 = term.y.iter().zip(x).map(|(&y, x)| f64::from(y) * x).sum::<f64>().to_radians();
        dpsi += (term.a + term.b * jce) * arg.sin();
        deps += (term.c + term.d * jce) * arg.cos();
    }
    let (dpsi, deps) = (dpsi / 36_000_000.0, deps / 36_000_000.0);

    // 3.5: true obliquity of the ecliptic (eqs. 24–25), ε₀ in arc seconds, U = JME/10.
    let u = jme / 10.0;
    let eps0 = [84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67, -39.05, 7.12, 27.87, 5.79, 2.45]
        .iter()
        .rev()
        .fold(0.0, |acc, &k| acc * u + k);
    let eps = eps0 / 3600.0 + deps;

    // 3.6–3.7: aberration and apparent sun longitude (eqs. 26–27).
    let dtau = -20.4898 / (3600.0 * r_au);
    let lambda = theta + dpsi + dtau;

    // 3.8: apparent sidereal time at Greenwich (eqs. 28–29).
    let nu0 =
        limit_degrees(280.46061837 + 360.985_647_366_29 * days + 0.000_387_933 * jc * jc - jc * jc * jc / 38_710_000.0);
    let nu = nu0 + dpsi * eps.to_radians().cos();

    // 3.9–3.10: geocentric right ascension and declination (eqs. 30–31).
    let (lr, er, br) = (lambda.to_radians(), eps.to_radians(), beta.to_radians());
    let alpha = limit_degrees((lr.sin() * er.cos() - br.tan() * er.sin()).atan2(lr.cos()).to_degrees());
    let delta = (br.sin() * er.cos() + br.cos() * er.sin() * lr.sin()).asin().to_degrees();

    // 3.11: local hour angle (eq. 32).
    let h = limit_degrees(nu + location.longitude_deg - alpha);

    // 3.12: topocentric right ascension and declination (eqs. 33–41): parallax of an observer off the
    // Earth's centre.
    let xi = (8.794 / (3600.0 * r_au)).to_radians();
    let phi = location.latitude_deg.to_radians();
    let uu = (0.99664719 * phi.sin()).atan2(phi.cos());
    let e_rel = location.elevation_m / 6_378_140.0;
    let xx = uu.cos() + e_rel * phi.cos();
    let yy = 0.99664719 * uu.sin() + e_rel * phi.sin();
    let (hr, dr) = (h.to_radians(), delta.to_radians());
    let dalpha = (-xx * xi.sin() * hr.sin()).atan2(dr.cos() - xx * xi.sin() * hr.cos());
    let delta_topo = ((dr.sin() - yy * xi.sin()) * dalpha.cos()).atan2(dr.cos() - xx * xi.sin() * hr.cos());
    let h_topo = hr - dalpha;

    // 3.13–3.15: horizon coordinates (eqs. 42–46), from the local east/north/up vector.
    let east = -delta_topo.cos() * h_topo.sin();
    let north = phi.cos() * delta_topo.sin() - phi.sin() * delta_topo.cos() * h_topo.cos();
    let up = phi.sin() * delta_topo.sin() + phi.cos() * delta_topo.cos() * h_topo.cos();
    let e0 = up.atan2(east.hypot(north)).to_degrees();
    let azimuth_deg = limit_degrees(east.atan2(north).to_degrees());

    // 3.13.2: refraction (eq. 43, Bennett's formula with Sæmundsson's form), applied while the sun's upper limb
    // can still be seen (e₀ ≥ −0.8333°: 34′ of horizon refraction plus the 16′ semidiameter); below that the
    // formula is meaningless (it diverges at −5.11°) and the sun is down either way.
    let refraction = options.refraction.filter(|_| e0 >= -0.8333);
    let de = refraction.map_or(0.0, |a| {
        (a.pressure_mbar / 1010.0) * (283.0 / (273.0 + a.temperature_c)) * 1.02
            / (60.0 * (e0 + 10.3 / (e0 + 5.11)).to_radians().tan())
    });
    SolarPosition {
        zenith_deg: 90.0 - (e0 + de),
        azimuth_deg,
        refraction: options.refraction.is_some(),
        geometric_zenith_deg: 90.0 - e0,
        declination_deg: delta,
        right_ascension_deg: alpha,
        hour_angle_deg: h,
        topocentric_declination_deg: delta_topo.to_degrees(),
        distance_au: r_au,
        delta_t_s,
        heliocentric_longitude_deg: l_deg,
        heliocentric_latitude_deg: b_deg,
        nutation_longitude_deg: dpsi,
        nutation_obliquity_deg: deps,
        obliquity_deg: eps,
        apparent_longitude_deg: lambda,
    }
}

//! The sun's position against the published test values of the Solar Position Algorithm, and its noon
//! elevations at the solstices and equinoxes against the astronomy they follow from.

use sunshade::daylight::{solar_position, Atmosphere, Instant, Location, SpaOptions};

/// The paper's worked example (Reda & Andreas 2004, Table A5.1): 2003-10-17 12:30:30 at −7 h, 39.742476° N,
/// 105.1786° W, 1830.14 m, ΔT 67 s, 820 mbar, 11 °C. Values to 10 digits from the table (L, B, R, λ); to 6
/// decimals from the output NREL publishes with its implementation (`spa_tester.c`: H, Δψ, Δε, ε, zenith,
/// azimuth); the zenith 50.11162° and azimuth 194.34024° are these rounded.
#[test]
fn the_papers_example_to_its_printed_digits() {
    let at = Instant::parse("2003-10-17T12:30:30-07:00").unwrap();
    let golden = Location { latitude_deg: 39.742476, longitude_deg: -105.1786, elevation_m: 1830.14 };
    let options = SpaOptions {
        delta_t_s: Some(67.0),
        delta_ut1_s: 0.0,
        refraction: Some(Atmosphere { pressure_mbar: 820.0, temperature_c: 11.0 }),
    };
    let p = solar_position(at, &golden, &options);
    let checks = [
        ("L [deg]", p.heliocentric_longitude_deg, 24.0182616917, 1e-9),
        ("B [deg]", p.heliocentric_latitude_deg, -0.0001011219, 1e-10),
        ("R [AU]", p.distance_au, 0.9965422974, 1e-10),
        ("delta psi [deg]", p.nutation_longitude_deg, -3.998404e-3, 1e-9),
        ("delta epsilon [deg]", p.nutation_obliquity_deg, 1.666568e-3, 1e-9),
        ("epsilon [deg]", p.obliquity_deg, 23.440465, 1e-6),
        ("lambda [deg]", p.apparent_longitude_deg, 204.0085519281, 1e-9),
        ("alpha [deg]", p.right_ascension_deg, 202.22741, 1e-5),
        ("delta [deg]", p.declination_deg, -9.31434, 1e-5),
        ("H [deg]", p.hour_angle_deg, 11.105902, 1e-6),
        ("zenith [deg]", p.zenith_deg, 50.111622, 1e-6),
        ("azimuth [deg]", p.azimuth_deg, 194.340241, 1e-6),
    ];
    let mut failures = Vec::new();
    for (name, got, want, tolerance) in checks {
        if (got - want).abs() > tolerance {
            failures.push(format!("{name}: {got:.10} against {want} (tolerance {tolerance:e})"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(p.refraction && p.is_up());
    // Without refraction the zenith is the geometric one, 90 − e₀ = 90 − 39.872046.
    let airless = solar_position(at, &golden, &SpaOptions { refraction: None, ..options });
    assert!((airless.zenith_deg - (90.0 - 39.872046)).abs() < 1e-6, "{}", airless.zenith_deg);
    assert!(!airless.refraction && airless.azimuth_deg == p.azimuth_deg);
}

fn sea_level(latitude_deg: f64, longitude_deg: f64) -> Location {
    Location { latitude_deg, longitude_deg, elevation_m: 0.0 }
}

const AIRLESS: SpaOptions = SpaOptions { delta_t_s: None, delta_ut1_s: 0.0, refraction: None };

/// The equinoxes and solstices of 2025 and 2026 as the US Naval Observatory publishes them (to the minute, UT):
/// at those instants the sun's apparent longitude is 0°, 90°, 180°, 270° to within the half minute of rounding
/// (the sun moves 0.00068° per minute), and its declination is 0 or ±ε to within its ecliptic latitude (< 1.2″).
#[test]
fn equinoxes_and_solstices_fall_at_their_published_minutes() {
    let events = [
        ("2025-03-20T09:01Z", 0.0),
        ("2025-06-21T02:42Z", 90.0),
        ("2025-09-22T18:19Z", 180.0),
        ("2025-12-21T15:03Z", 270.0),
        ("2026-03-20T14:46Z", 0.0),
        ("2026-06-21T08:24Z", 90.0),
        ("2026-09-23T00:05Z", 180.0),
        ("2026-12-21T20:50Z", 270.0),
    ];
    for (time, longitude) in events {
        let p = solar_position(Instant::parse(time).unwrap(), &sea_level(0.0, 0.0), &AIRLESS);
        let off = (p.apparent_longitude_deg - longitude + 180.0).rem_euclid(360.0) - 180.0;
        assert!(
            off.abs() < 0.6 * 0.000_685,
            "{time}: apparent longitude {} (off {off:e} deg)",
            p.apparent_longitude_deg
        );
        let declination = longitude.to_radians().sin() * p.obliquity_deg;
        assert!((p.declination_deg - declination).abs() < 4e-4, "{time}: declination {}", p.declination_deg);
    }
}

/// Noon elevations at the solstices and equinoxes at several latitudes. Solar noon is the transit, where the sun
/// crosses the meridian (found by bisection on the sign of its eastward component); there its elevation is
/// `90° − |φ − δ′|`, to 1e-4° (in fact 1e-6°). The day's highest sun (found by a ternary search) lies within
/// 1e-3° of it: not exactly at it, since the declination drifts (up to 0.39°/day at the equinoxes).
#[test]
fn noon_elevations_at_solstices_and_equinoxes() {
    for day in ["2026-03-20", "2026-06-21", "2026-09-23", "2026-12-21"] {
        for (latitude, longitude) in
            [(0.0, 0.0), (23.44, 30.0), (47.37, 8.54), (-33.92, 18.42), (64.15, -21.94), (78.22, 15.65)]
        {
            let place = sea_level(latitude, longitude);
            // Solar noon is near 12:00 − longitude/15 h UT; search ±40 min around it.
            let guess = Instant::parse(&format!("{day}T12:00:00Z")).unwrap().plus_seconds(-longitude / 15.0 * 3600.0);
            let at = |t: f64| solar_position(guess.plus_seconds(t), &place, &AIRLESS);
            let eastward = |t: f64| at(t).azimuth_deg.to_radians().sin();
            let (mut lo, mut hi) = (-2400.0, 2400.0);
            assert!(eastward(lo) > 0.0 && eastward(hi) < 0.0, "{day} at {latitude}: no transit within 40 min");
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if eastward(mid) > 0.0 {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            let p = at(0.5 * (lo + hi));
            let expected = 90.0 - (latitude - p.topocentric_declination_deg).abs();
            assert!(
                (p.elevation_deg() - expected).abs() < 1e-4,
                "{day} at {latitude}: {} against {expected}",
                p.elevation_deg()
            );
            let (mut a, mut b) = (-2400.0, 2400.0);
            for _ in 0..80 {
                let (x, y) = (a + (b - a) / 3.0, b - (b - a) / 3.0);
                if at(x).zenith_deg > at(y).zenith_deg {
                    a = x
                } else {
                    b = y
                }
            }
            let highest = at(0.5 * (a + b)).elevation_deg();
            assert!(
                highest >= p.elevation_deg() - 1e-9 && highest - p.elevation_deg() < 1e-3,
                "{day} at {latitude}: highest {highest}"
            );
            // Declination: about 0 at the equinoxes and ±23.44 at the solstices (within a day's motion).
            let solstice = match &day[5..7] {
                "06" => 23.44,
                "12" => -23.44,
                _ => 0.0,
            };
            assert!((p.declination_deg - solstice).abs() < 0.45, "{day}: declination {}", p.declination_deg);
        }
    }
}

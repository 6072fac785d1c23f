//! ΔT = TT − UT \[s\], the difference between the uniform time of the ephemerides and the Earth's rotation.
//!
//! Source: the polynomial expressions of Espenak & Meeus (2006), "Five Millennium Canon of Solar Eclipses"
//! (NASA/TP-2006-214141), also on NASA's eclipse web site, a fit to historical and measured values and to an
//! extrapolation beyond 2005. Their error near the present: the fit gives 75.1 s for 2026, while the IERS measured
//! about 69 s in 2025; 6 s of ΔT moves the sun along the ecliptic by 6 s × 0.0411″/s ≈ 7·10⁻⁵°, inside the
//! algorithm's ±3·10⁻⁴°. A user with a better value gives it (`--delta-t`).

/// ΔT \[s\] at the decimal year `y` (`year + (month − 0.5)/12`), by Espenak & Meeus's piecewise polynomials.
pub fn delta_t_seconds(y: f64) -> f64 {
    let poly = |t: f64, c: &[f64]| c.iter().rev().fold(0.0, |acc, &k| acc * t + k);
    let long_term = |y: f64| {
        let u = (y - 1820.0) / 100.0;
        -20.0 + 32.0 * u * u
    };
    match y {
        y if y < -500.0 => long_term(y),
        y if y < 500.0 => {
            poly(y / 100.0, &[10583.6, -1014.41, 33.78311, -5.952053, -0.1798452, 0.022174192, 0.0090316521])
        }
        y if y < 1600.0 => {
            poly((y - 1000.0) / 100.0, &[1574.2, -556.01, 71.23472, 0.319781, -0.8503463, -0.005050998, 0.0083572073])
        }
        y if y < 1700.0 => poly(y - 1600.0, &[120.0, -0.9808, -0.01532, 1.0 / 7129.0]),
        y if y < 1800.0 => poly(y - 1700.0, &[8.83, 0.1603, -0.0059285, 0.00013336, -1.0 / 1_174_000.0]),
        y if y < 1860.0 => poly(
            y - 1800.0,
            &[13.72, -0.332447, 0.0068612, 0.0041116, -0.00037436, 0.0000121272, -0.0000001699, 0.000000000875],
        ),
        y if y < 1900.0 => poly(y - 1860.0, &[7.62, 0.5737, -0.251754, 0.01680668, -0.0004473624, 1.0 / 233_174.0]),
        y if y < 1920.0 => poly(y - 1900.0, &[-2.79, 1.494119, -0.0598939, 0.0061966, -0.000197]),
        y if y < 1941.0 => poly(y - 1920.0, &[21.20, 0.84493, -0.076100, 0.0020936]),
        y if y < 1961.0 => poly(y - 1950.0, &[29.07, 0.407, -1.0 / 233.0, 1.0 / 2547.0]),
        y if y < 1986.0 => poly(y - 1975.0, &[45.45, 1.067, -1.0 / 260.0, -1.0 / 718.0]),
        y if y < 2005.0 => poly(y - 2000.0, &[63.86, 0.3345, -0.060374, 0.0017275, 0.000651814, 0.00002373599]),
        y if y < 2050.0 => poly(y - 2000.0, &[62.92, 0.32217, 0.005589]),
        y if y < 2150.0 => long_term(y) - 0.5628 * (2150.0 - y),
        y => long_term(y),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measured_values_and_continuity() {
        // Measured ΔT (Espenak & Meeus's table of observed values): 1900 −2.8 s, 1950 29.1, 1975 45.5,
        // 2000 63.8, 2005 64.7.
        for (year, measured) in [(1900.0, -2.8), (1950.0, 29.1), (1975.0, 45.5), (2000.0, 63.8), (2005.0, 64.7)] {
            let dt = delta_t_seconds(year);
            assert!((dt - measured).abs() < 0.5, "{year}: {dt} s against {measured}");
        }
        // The pieces meet: no jump over 2 s at any boundary from 1600 on (the fits' own steps are smaller).
        for edge in [1600.0, 1700.0, 1800.0, 1860.0, 1900.0, 1920.0, 1941.0, 1961.0, 1986.0, 2005.0, 2050.0, 2150.0] {
            let jump = delta_t_seconds(edge) - delta_t_seconds(edge - 1e-9);
            assert!(jump.abs() < 2.0, "{edge}: jump {jump} s");
        }
    }
}

//! Reading a place: `LAT,LON[,ELEVATION_M]` in decimal degrees (north and east positive) and metres.

use super::solar_position::Location;

/// Reads `LAT,LON[,ELEVATION_M]`; refuses latitudes outside ±90°, longitudes outside ±180° and elevations outside
/// −500..11 000 m (the standard atmosphere's range), each with the reason.
pub fn parse_location(text: &str) -> Result<Location, String> {
    let bad = |why: &str| format!("location '{text}': {why} (expected LAT,LON[,ELEVATION_M], e.g. 47.37,8.54,408)");
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if !(2..=3).contains(&parts.len()) {
        return Err(bad("needs two or three numbers"));
    }
    let num = |s: &str, what: &str| -> Result<f64, String> {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(&format!("{what} '{s}' is not a finite number")))
    };
    let latitude_deg = num(parts[0], "latitude")?;
    let longitude_deg = num(parts[1], "longitude")?;
    let elevation_m = if parts.len() == 3 { num(parts[2], "elevation")? } else { 0.0 };
    if latitude_deg.abs() > 90.0 {
        return Err(bad("the latitude must be within -90..90 degrees"));
    }
    if longitude_deg.abs() > 180.0 {
        return Err(bad("the longitude must be within -180..180 degrees"));
    }
    if !(-500.0..=11_000.0).contains(&elevation_m) {
        return Err(bad("the elevation must be within -500..11000 m"));
    }
    Ok(Location { latitude_deg, longitude_deg, elevation_m })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn places_and_refusals() {
        let l = parse_location("39.742476,-105.1786,1830.14").unwrap();
        assert_eq!((l.latitude_deg, l.longitude_deg, l.elevation_m), (39.742476, -105.1786, 1830.14));
        assert_eq!(parse_location(" -33.9, 18.4 ").unwrap().elevation_m, 0.0);
        for (text, why) in [
            ("91,0", "latitude"),
            ("0,181", "longitude"),
            ("1", "two or three"),
            ("a,b", "not a finite"),
            ("0,0,20000", "elevation"),
            ("nan,0", "not a finite"),
        ] {
            let e = parse_location(text).unwrap_err();
            assert!(e.contains(why) && e.contains(text), "{text}: {e}");
        }
    }
}

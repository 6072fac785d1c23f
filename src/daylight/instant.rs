//! An instant of time from ISO 8601 text (`2026-06-21T12:00:00+02:00`), kept as whole seconds and a fraction since
//! J2000.0 (2000-01-01T12:00:00 UT), so that sums of many instants and differences between them lose nothing.
//!
//! Calendar: the proleptic Gregorian calendar, as ISO 8601 defines it (also before 1582). Time scale: the
//! clock time given, after its UTC offset, is taken as UT1 (`UT1 − UTC`, |DUT1| < 0.9 s, is `Location`-independent
//! and can be given to the solar position as `delta_ut1_s`). Leap seconds: `:60` is accepted and counts as the
//! next minute's first second (the instant a leap second ends), the convention of POSIX time.

use std::fmt;

/// Seconds per day.
pub const SECONDS_PER_DAY: f64 = 86_400.0;

/// An instant, UT, as seconds since J2000.0: an integer part and a fraction in [0, 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Instant {
    /// Whole seconds since 2000-01-01T12:00:00 UT.
    pub seconds: i64,
    /// Nanoseconds past `seconds`, 0..1e9.
    pub nanos: u32,
}

/// Why a time could not be read.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeError(pub String);

impl fmt::Display for TimeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for TimeError {}

/// Days from 1970-01-01 to `year-month-day` (proleptic Gregorian), by the era arithmetic of civil calendars
/// (exact in integers for any year i64 can hold here).
pub fn days_from_civil(year: i64, month: u32, day: u32) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400; // [0, 399]
    let m = month as i64;
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + day as i64 - 1; // [0, 365]
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy; // [0, 146096]
    era * 146_097 + doe - 719_468
}

/// The inverse of [`days_from_civil`]: `(year, month, day)`.
pub fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let year = yoe + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

fn is_leap(year: i64) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

fn days_in_month(year: i64, month: u32) -> u32 {
    match month {
        2 if is_leap(year) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Seconds from the Unix epoch (1970-01-01T00:00:00) to J2000.0 (2000-01-01T12:00:00).
const UNIX_TO_J2000_S: i64 = 946_728_000;

/// The years the solar position algorithm is valid for (Reda & Andreas 2004: −2000 to 6000).
pub const YEARS: std::ops::RangeInclusive<i64> = -2000..=6000;

impl Instant {
    /// The instant `year-month-day hour:minute:second` UT.
    pub fn from_utc(year: i64, month: u32, day: u32, hour: u32, minute: u32, second: f64) -> Self {
        let whole = second.floor();
        let unix = days_from_civil(year, month, day) * 86_400 + i64::from(hour) * 3600 + i64::from(minute) * 60;
        let nanos = ((second - whole) * 1e9).round() as u32;
        let (extra, nanos) = if nanos >= 1_000_000_000 { (1, nanos - 1_000_000_000) } else { (0, nanos) };
        Self { seconds: unix - UNIX_TO_J2000_S + whole as i64 + extra, nanos }
    }

    /// Reads `YYYY-MM-DDTHH:MM[:SS[.fff]]` followed by `Z` or `±HH:MM` (a space may stand for `T`; the offset is
    /// required, since a clock time without one names no instant). Years −2000..6000.
    pub fn parse(text: &str) -> Result<Self, TimeError> {
        let bad = |why: &str| TimeError(format!("time '{text}': {why} (expected e.g. 2026-06-21T12:00:00+02:00)"));
        let t = text.trim();
        let (negative_year, t) = match t.strip_prefix('-') {
            Some(rest) => (true, rest),
            None => (false, t.strip_prefix('+').unwrap_or(t)),
        };
        let (date, rest) = t.split_once(['T', 't', ' ']).ok_or_else(|| bad("no 'T' between date and time"))?;
        let mut parts = date.split('-');
        let (Some(y), Some(mo), Some(d), None) = (parts.next(), parts.next(), parts.next(), parts.next()) else {
            return Err(bad("the date is not YYYY-MM-DD"));
        };
        let digits = |s: &str, what: &str| -> Result<u32, TimeError> {
            if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) || s.len() > 9 {
                return Err(bad(&format!("{what} '{s}' is not a number")));
            }
            Ok(s.parse().expect("digits"))
        };
        let year = i64::from(digits(y, "year")?) * if negative_year { -1 } else { 1 };
        if y.len() < 4 {
            return Err(bad("the year needs four digits"));
        }
        let month = digits(mo, "month")?;
        let day = digits(d, "day")?;
        if !(1..=12).contains(&month) {
            return Err(bad("the month is not 1..12"));
        }
        if day < 1 || day > days_in_month(year, month) {
            return Err(bad(&format!("{year}-{month:02} has no day {day}")));
        }
        // Split the clock from its offset: the last 'Z', '+' or '-'.
        let (clock, offset_s) = if let Some(c) = rest.strip_suffix(['Z', 'z']) {
            (c, 0)
        } else if let Some(at) = rest.rfind(['+', '-']) {
            let (c, off) = rest.split_at(at);
            let sign = if off.starts_with('-') { -1 } else { 1 };
            let (oh, om) = off[1..].split_once(':').unwrap_or((&off[1..], "00"));
            let (oh, om) = (digits(oh, "offset hours")?, digits(om, "offset minutes")?);
            if oh > 18 || om > 59 {
                return Err(bad("the UTC offset is out of range"));
            }
            (c, sign * i64::from(oh * 3600 + om * 60))
        } else {
            return Err(bad("no UTC offset (add Z or e.g. +02:00)"));
        };
        let mut hms = clock.split(':');
        let (Some(h), Some(mi)) = (hms.next(), hms.next()) else {
            return Err(bad("the time of day is not HH:MM[:SS]"));
        };
        let s = hms.next().unwrap_or("0");
        if hms.next().is_some() {
            return Err(bad("the time of day is not HH:MM[:SS]"));
        }
        let (hour, minute) = (digits(h, "hour")?, digits(mi, "minute")?);
        let (whole, fraction) = s.split_once(['.', ',']).unwrap_or((s, ""));
        let whole = digits(whole, "second")?;
        let fraction = if fraction.is_empty() {
            0.0
        } else {
            f64::from(digits(fraction, "fraction")?) / 10f64.powi(fraction.len() as i32)
        };
        if hour > 24 || minute > 59 || whole > 60 || (hour == 24 && (minute, whole, fraction) != (0, 0, 0.0)) {
            return Err(bad("the time of day is out of range"));
        }
        let local = Self::from_utc(year, month, day, hour, minute, f64::from(whole) + fraction);
        let utc = Self { seconds: local.seconds - offset_s, nanos: local.nanos };
        // The range holds for the instant in UT (an offset or 24:00 may carry it over a year's end).
        if !YEARS.contains(&utc.civil().0) {
            return Err(bad("the year (in UT) is outside -2000..6000, where the solar position algorithm holds"));
        }
        Ok(utc)
    }

    /// This instant plus `seconds` (may be negative and fractional).
    pub fn plus_seconds(self, seconds: f64) -> Self {
        let whole = seconds.floor();
        let nanos = f64::from(self.nanos) + ((seconds - whole) * 1e9).round();
        let carry = (nanos / 1e9).floor();
        Self { seconds: self.seconds + whole as i64 + carry as i64, nanos: (nanos - carry * 1e9) as u32 }
    }

    /// Seconds from `earlier` to `self` (exact to a nanosecond for spans up to ~100 days, 1 µs for centuries).
    pub fn seconds_since(self, earlier: Self) -> f64 {
        (self.seconds - earlier.seconds) as f64 + (f64::from(self.nanos) - f64::from(earlier.nanos)) * 1e-9
    }

    /// Days since J2000.0, `JD − 2451545`. Computed from the integer seconds, not from `JD` itself: a Julian date
    /// (≈2.46·10⁶) holds only ~40 µs in f64, while this difference keeps ~1 µs over the algorithm's eight
    /// millennia; the sidereal time multiplies it by 361°/day.
    pub fn days_since_j2000(self) -> f64 {
        (self.seconds as f64 + f64::from(self.nanos) * 1e-9) / SECONDS_PER_DAY
    }

    /// The Julian date (UT).
    pub fn julian_day(self) -> f64 {
        2_451_545.0 + self.days_since_j2000()
    }

    /// The UT calendar date `(year, month, day)`.
    pub fn civil(self) -> (i64, u32, u32) {
        civil_from_days((self.seconds + UNIX_TO_J2000_S).div_euclid(86_400))
    }

    /// Year as a decimal, `year + (month − 0.5)/12` (the argument of the ΔT polynomials).
    pub fn decimal_year(self) -> f64 {
        let (year, month, _) = self.civil();
        year as f64 + (f64::from(month) - 0.5) / 12.0
    }
}

impl fmt::Display for Instant {
    /// ISO 8601 in UTC, e.g. `2026-06-21T10:00:00Z` (fractional seconds when there are any).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let unix = self.seconds + UNIX_TO_J2000_S;
        let (y, mo, d) = civil_from_days(unix.div_euclid(86_400));
        let s = unix.rem_euclid(86_400);
        // ISO 8601's expanded years: a sign and at least four digits (`-0627`, not `-627`).
        let sign = if y < 0 { "-" } else { "" };
        write!(f, "{sign}{:04}-{mo:02}-{d:02}T{:02}:{:02}:{:02}", y.abs(), s / 3600, s / 60 % 60, s % 60)?;
        if self.nanos != 0 {
            let frac = format!("{:09}", self.nanos);
            write!(f, ".{}", frac.trim_end_matches('0'))?;
        }
        f.write_str("Z")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calendar_round_trips_and_known_julian_dates() {
        for days in (-1_500_000..1_500_000).step_by(997) {
            let (y, m, d) = civil_from_days(days);
            assert_eq!(days_from_civil(y, m, d), days);
        }
        // J2000.0 and the SPA paper's example (2003-10-17 12:30:30 at −7 h: JD 2452930.312847).
        assert_eq!(Instant::parse("2000-01-01T12:00:00Z").unwrap(), Instant { seconds: 0, nanos: 0 });
        let jd = Instant::parse("2003-10-17T12:30:30-07:00").unwrap().julian_day();
        assert!((jd - 2_452_930.312_847).abs() < 1e-6, "{jd}");
        // Meeus, Astronomical Algorithms, example 7.a: 1957-10-04.81 = JD 2436116.31.
        let jd = Instant::from_utc(1957, 10, 4, 19, 26, 24.0).julian_day();
        assert!((jd - 2_436_116.31).abs() < 1e-9, "{jd}");
    }

    #[test]
    fn offsets_fractions_and_display() {
        let a = Instant::parse("2026-06-21T12:00:00+02:00").unwrap();
        assert_eq!(a.to_string(), "2026-06-21T10:00:00Z");
        let b = Instant::parse("2026-06-21 10:00:00.25Z").unwrap();
        assert_eq!(b.seconds_since(a), 0.25);
        assert_eq!(b.to_string(), "2026-06-21T10:00:00.25Z");
        assert_eq!(Instant::parse("2026-06-21T05:30-04:30").unwrap().to_string(), "2026-06-21T10:00:00Z");
        assert_eq!(Instant::parse("2026-12-31T24:00:00Z").unwrap().to_string(), "2027-01-01T00:00:00Z");
        assert_eq!(a.plus_seconds(-0.5).plus_seconds(0.75).seconds_since(a), 0.25);
    }

    #[test]
    fn bad_times_are_refused_with_a_reason() {
        for (text, why) in [
            ("2026-06-21T12:00:00", "no UTC offset"),
            ("2026-02-29T12:00Z", "has no day 29"),
            ("2026-13-01T12:00Z", "month"),
            ("2026-06-21T25:00Z", "out of range"),
            ("2026-06-21", "no 'T'"),
            ("7000-01-01T00:00Z", "-2000..6000"),
            ("6000-12-31T23:00-05:00", "-2000..6000"),
            ("999999999-01-01T00:00Z", "-2000..6000"),
            ("2026-06-21T12:00+19:00", "offset"),
            ("26-06-21T12:00Z", "four digits"),
            ("2026-06-xxT12:00Z", "not a number"),
        ] {
            let e = Instant::parse(text).unwrap_err().0;
            assert!(e.contains(why) && e.contains(text), "{text}: {e}");
        }
        assert!(Instant::parse("2024-02-29T12:00Z").is_ok());
    }

    /// A small xorshift generator: the fuzz cases are the same on every run.
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    #[test]
    fn every_instant_round_trips_through_its_text() {
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let span =
            Instant::from_utc(6000, 12, 31, 23, 59, 59.0).seconds - Instant::from_utc(-2000, 1, 1, 0, 0, 0.0).seconds;
        let first = Instant::from_utc(-2000, 1, 1, 0, 0, 0.0).seconds;
        for _ in 0..20_000 {
            let t = Instant { seconds: first + (xorshift(&mut rng) % span as u64) as i64, nanos: 0 };
            assert_eq!(Instant::parse(&t.to_string()).unwrap(), t, "{t}");
        }
    }

    #[test]
    fn mutated_times_never_panic_and_errors_name_the_text() {
        let seeds = ["2026-06-21T12:00:00+02:00", "2003-10-17 12:30:30.5-07:00", "-0500-03-01T00:00Z"];
        let alphabet = b"0123456789:-+TZ. ,x";
        let mut rng = 0x1234_5678_9abc_def1u64;
        for k in 0..30_000 {
            let mut text: Vec<u8> = seeds[k % seeds.len()].bytes().collect();
            for _ in 0..1 + xorshift(&mut rng) % 3 {
                let at = (xorshift(&mut rng) as usize) % (text.len() + 1);
                let c = alphabet[(xorshift(&mut rng) as usize) % alphabet.len()];
                match xorshift(&mut rng) % 3 {
                    0 if at < text.len() => text[at] = c,
                    1 if at < text.len() => {
                        text.remove(at);
                    }
                    _ => text.insert(at, c),
                }
            }
            let text = String::from_utf8(text).expect("ASCII");
            match Instant::parse(&text) {
                // A time it takes is one it can write and read back.
                Ok(t) => assert_eq!(Instant::parse(&t.to_string()).unwrap(), t, "{text}"),
                Err(e) => assert!(e.0.contains(&text), "{text}: {e}"),
            }
        }
    }
}

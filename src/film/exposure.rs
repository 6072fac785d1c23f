//! Mapping radiance to display values for 8-bit output.
//!
//! The displayed value of a channel is `clamp(L · 2^EV, 0, 1)`, sRGB-encoded: `EV` is a plain scale in stops, not
//! a camera exposure value (there is no 1/1.2 or ISO factor). `auto` picks `EV = log2(0.8 / p99)`, `p99` being the
//! 99th percentile over covered pixels of each pixel's brightest channel: 99% of the covered pixels display at or
//! below 80% of white (sRGB code 231), so highlights keep headroom below clipping and a uniformly lit surface is
//! a light grey, not a saturated 255; mid-tones (half the p99) display at 40% (code 170).

use super::Image;

/// How radiance is scaled before 8-bit encoding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// Scale by `2^EV`.
    Ev(f64),
    /// Choose EV from the image (see the module documentation).
    Auto,
}

impl Exposure {
    /// The EV applied to this image.
    pub fn ev_for(&self, image: &Image) -> f64 {
        match *self {
            Exposure::Ev(ev) => ev,
            Exposure::Auto => auto_exposure_ev(image),
        }
    }
}

impl std::str::FromStr for Exposure {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.eq_ignore_ascii_case("auto") {
            return Ok(Exposure::Auto);
        }
        match s.parse::<f64>() {
            Ok(ev) if ev.is_finite() => Ok(Exposure::Ev(ev)),
            _ => Err(format!("exposure must be a number of stops or 'auto', got '{s}'")),
        }
    }
}

/// The display value that the 99th percentile maps to under `auto` exposure.
pub const AUTO_EXPOSURE_P99_DISPLAY: f64 = 0.8;

/// `log2(0.8 / p99)`, p99 the 99th percentile of the brightest channel over covered pixels with positive radiance;
/// 0 when there are none.
pub fn auto_exposure_ev(image: &Image) -> f64 {
    let mut peaks: Vec<f32> = image
        .pixels()
        .iter()
        .filter(|p| p[3] > 0.0)
        .map(|p| p[0].max(p[1]).max(p[2]))
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    if peaks.is_empty() {
        return 0.0;
    }
    let k = ((peaks.len() - 1) as f64 * 0.99).round() as usize;
    let (_, p99, _) = peaks.select_nth_unstable_by(k, f32::total_cmp);
    (AUTO_EXPOSURE_P99_DISPLAY / *p99 as f64).log2()
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1], to an 8-bit code.
pub fn srgb_encode(linear: f64) -> u8 {
    // NaN fails both comparisons of clamp's argument check only if we let it through: map it to 0 explicitly.
    let v = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) };
    let encoded = if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    (encoded * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_endpoints_and_midpoint() {
        assert_eq!(srgb_encode(0.0), 0);
        assert_eq!(srgb_encode(1.0), 255);
        assert_eq!(srgb_encode(2.0), 255);
        assert_eq!(srgb_encode(-1.0), 0);
        assert_eq!(srgb_encode(f64::NAN), 0);
        // 18% grey encodes to 118 in sRGB.
        assert_eq!(srgb_encode(0.18), 118);
    }

    #[test]
    fn auto_exposure_maps_percentile_to_one() {
        let mut img = Image::new(10, 10);
        for (i, p) in img.pixels_mut().iter_mut().enumerate() {
            *p = [(i + 1) as f32, 0.0, 0.0, 1.0];
        }
        // 100 covered pixels valued 1..=100: the 99th percentile (index 98) is 99, displayed at 0.8.
        let ev = auto_exposure_ev(&img);
        assert!((ev.exp2() * 99.0 - 0.8).abs() < 1e-12);
        assert_eq!(auto_exposure_ev(&Image::new(3, 3)), 0.0);
        // A uniformly lit surface is not saturated: every pixel at code 231 of 255.
        let mut flat = Image::new(4, 4);
        flat.pixels_mut().iter_mut().for_each(|p| *p = [37.5, 37.5, 37.5, 1.0]);
        let code = srgb_encode(37.5 * auto_exposure_ev(&flat).exp2());
        assert_eq!(code, 231);
    }

    #[test]
    fn parses_exposure() {
        assert_eq!("auto".parse::<Exposure>().unwrap(), Exposure::Auto);
        assert_eq!("-8.5".parse::<Exposure>().unwrap(), Exposure::Ev(-8.5));
        assert!("bright".parse::<Exposure>().is_err());
        assert!("inf".parse::<Exposure>().is_err());
    }
}

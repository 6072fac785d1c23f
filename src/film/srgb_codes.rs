//! The 8-bit sRGB codes of linear values, as [`srgb_encode`] gives them, without a `powf` per channel: a PNG of
//! 512 × 512 pixels needs 786 432 codes, and `powf` in f64 made their encoding cost as much as the frame.
//!
//! `srgb_encode` rises with its argument (the transfer function and the rounding to a code both do), so code `k` is
//! given exactly to the values at or above the least value that `srgb_encode` maps to `k` or more: the code of `v`
//! is the number of those 255 thresholds at or below `v`. The thresholds are found from `srgb_encode` itself, by
//! bisection over the ordered bit patterns of the f64 values in [0, 1] (62 steps each), not from the inverse
//! transfer function, whose own rounding could put a threshold one value off: so every code equals
//! `srgb_encode`'s, bit for bit, wherever the function rises (the test checks the values about each threshold).

use std::sync::OnceLock;

use super::srgb_encode;

/// The least f64 in [0, 1] that `srgb_encode` maps to `k` or more, at index `k − 1`.
fn thresholds() -> &'static [f64; 255] {
    static THRESHOLDS: OnceLock<[f64; 255]> = OnceLock::new();
    THRESHOLDS.get_or_init(|| {
        std::array::from_fn(|i| {
            let k = i as u8 + 1;
            // srgb_encode(lo) < k <= srgb_encode(hi); non-negative f64s are ordered as their bits.
            let (mut lo, mut hi) = (0.0f64.to_bits(), 1.0f64.to_bits());
            while hi - lo > 1 {
                let mid = lo + (hi - lo) / 2;
                if srgb_encode(f64::from_bits(mid)) >= k {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            f64::from_bits(hi)
        })
    })
}

/// `srgb_encode(linear)` by the thresholds: 8 comparisons. NaN and values below the first threshold give 0.
pub fn srgb_code(linear: f64) -> u8 {
    // `t <= NaN` is false for every threshold: NaN counts none, as srgb_encode maps it to 0.
    thresholds().partition_point(|t| *t <= linear) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_equal_the_transfer_functions_about_every_threshold() {
        let mut checked = 0;
        for &t in thresholds() {
            // The 2000 f64 values about each threshold (the rounding's boundary), and the threshold's neighbourhood
            // scaled (values far from every boundary).
            for d in -1000i64..1000 {
                let v = f64::from_bits((t.to_bits() as i64 + d) as u64);
                assert_eq!(srgb_code(v), srgb_encode(v), "{v:e}");
                checked += 1;
            }
            for s in [0.5, 0.9, 0.999, 1.001, 1.1, 2.0] {
                assert_eq!(srgb_code(t * s), srgb_encode(t * s), "{:e}", t * s);
            }
        }
        for v in [f64::NAN, f64::NEG_INFINITY, -1.0, -0.0, 0.0, 1e-300, 0.5, 1.0, 1.0 + 1e-16, 2.0, f64::INFINITY] {
            assert_eq!(srgb_code(v), srgb_encode(v), "{v:e}");
        }
        // A million values spread over [0, 1.2].
        for i in 0..1_000_000u32 {
            let v = i as f64 * 1.2e-6;
            assert_eq!(srgb_code(v), srgb_encode(v), "{v:e}");
        }
        assert!(checked == 255 * 2000);
    }
}

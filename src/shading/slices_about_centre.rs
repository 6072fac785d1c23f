//! A light's slices measured from the chords' middle: the angle `γ = β − π/2` in place of `β` (`sky_slices`), the
//! formulation the GPU's sun slices use in f32 (shaders/slices.glsl, which mirrors these names).
//!
//! **Why.** The sun's chords lie within its half-angle σ (0.0046 rad) of `β = π/2`. In f32, `β` there carries an
//! absolute error of an ulp of π/2, 1.2e-7 rad, which is 1.3e-5 of a chord, and a short interval's `b1 − b0` loses
//! as many digits, so that a row's weights would be good to about 1e-4. `γ` is small on the same chords and keeps
//! f32's relative precision (6e-8 of itself), and so does every quantity below: the pseudo-angle of a direction
//! (`sky_slices::pseudo_angle`, 0 at `γ = 0`) turns into `γ` without passing through π/2 ([`gamma_of`]), the
//! surface's horizon is found from `tan γ₀ = (n·p)/(n·c)` rather than as `φ − π/2` ([`above_about_centre`]), and
//! the weight's integral has no term that cancels on a short interval ([`weight_integral_about_centre`]).
//!
//! With `ω = cos β c + sin β p = −sin γ c + cos γ p`, the weight `(n·ω) sin β dβ` becomes
//! `(n_p cos γ − n_c sin γ) cos γ dγ` (`n_c = n·c`, `n_p = n·p`).
//!
//! The reference keeps its own `β` (f64 has digits to spare); the tests below check that both formulations give
//! the same numbers.

use std::f64::consts::FRAC_PI_2;

use super::sky_slices::{gaps_weight, pseudo_angle};

/// γ of a pseudo-angle `k` (`sky_slices::pseudo_angle`; the direction `(s, t) ∝ (−k, 1 − |k|)`):
/// `atan2(k, 1 − |k|)`, so that γ near 0 keeps the relative precision of `k` (`sky_slices::angle_of` gives
/// `β = γ + π/2`, which does not).
pub fn gamma_of(k: f64) -> f64 {
    k.atan2((1.0 - k.abs()).max(0.0))
}

/// The interval of γ in `[−π/2, π/2]` where `n·ω ≥ 0`: `n·ω = cos γ (n_p − n_c tan γ)`, so below
/// `γ₀ = atan(n_p / n_c)` where `n_c > 0`, above it where `n_c < 0`, everywhere or nowhere (an empty interval
/// `(π/2, −π/2)`) where `n_c = 0`. `γ₀` comes from an `atan2` of the two components, exact near 0, where
/// `above`'s `φ ∓ π/2` would lose the digits of a horizon that crosses the sun.
pub fn above_about_centre(n_c: f64, n_p: f64) -> (f64, f64) {
    if n_c > 0.0 {
        (-FRAC_PI_2, n_p.atan2(n_c))
    } else if n_c < 0.0 {
        ((-n_p).atan2(-n_c), FRAC_PI_2)
    } else if n_p >= 0.0 {
        (-FRAC_PI_2, FRAC_PI_2)
    } else {
        (FRAC_PI_2, -FRAC_PI_2)
    }
}

/// `∫_{g0}^{g1} (n_p cos γ − n_c sin γ) cos γ dγ = n_p (Δ + sin Δ cos(g0 + g1))/2 − n_c sin Δ sin(g0 + g1)/2`,
/// `Δ = g1 − g0`; 0 for an empty interval. For `|g0 + g1| < π/2` (every chord of a light narrower than a
/// half-turn about its middle) both parts of the first term are positive: no cancellation, however short Δ.
pub fn weight_integral_about_centre(n_c: f64, n_p: f64, g0: f64, g1: f64) -> f64 {
    if g1 <= g0 {
        return 0.0;
    }
    let (d, s) = (g1 - g0, g0 + g1);
    0.5 * n_p * (d + d.sin() * s.cos()) - 0.5 * n_c * d.sin() * s.sin()
}

/// The pseudo-angle of γ: that of the direction `(−sin γ, cos γ)`.
pub fn pseudo_angle_of_gamma(g: f64) -> f64 {
    let (s, c) = g.sin_cos();
    pseudo_angle(-s, c)
}

/// The weight over `[lo, hi]` (γ) less the union of `blocked` (pseudo-angles, sorted here by their starts), by
/// the gaps between them; a gap's end at the span's own end keeps its exact γ (`sky_slices::visible_weight` in γ).
pub fn visible_weight_about_centre(n_c: f64, n_p: f64, span: (f64, f64), blocked: &mut [(f64, f64)]) -> f64 {
    let keys = (pseudo_angle_of_gamma(span.0), pseudo_angle_of_gamma(span.1));
    gaps_weight(blocked, (span, keys), gamma_of, |g0, g1| weight_integral_about_centre(n_c, n_p, g0, g1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::sky_slices::{above, angle_of, visible_weight, weight_integral};
    use crate::test_rng::uniform;
    use glam::DVec3;

    #[test]
    fn gamma_of_is_angle_of_less_a_right_angle_and_keeps_small_angles_digits() {
        for k in [-0.999, -0.5, -1e-3, -1e-9, 0.0, 1e-12, 2e-3, 0.7, 1.0] {
            let g = gamma_of(k);
            assert!((g - (angle_of(k) - FRAC_PI_2)).abs() < 1e-15, "{k}");
        }
        // Near 0, γ = k (1 + O(k)), to f64's last digits where β would keep 1e-16 / 1e-9 of them.
        let k = 1e-9;
        assert!((gamma_of(k) / k - 1.0).abs() < 2e-9);
        for g in [-1.2, -4.6e-3, 1e-7, 0.3] {
            assert!((gamma_of(pseudo_angle_of_gamma(g)) / g - 1.0).abs() < 1e-12, "{g}");
        }
    }

    #[test]
    fn the_horizon_and_the_weight_agree_with_the_beta_formulation() {
        let mut next = uniform(5);
        let mut rng = || 0.5 * (next() + 1.0);
        let c = DVec3::new(0.0, 0.0, 1.0);
        let p = DVec3::new(1.0, 0.0, 0.0);
        for _ in 0..2000 {
            let n = DVec3::new(rng() - 0.5, rng() - 0.5, rng() - 0.5).normalize();
            let (n_c, n_p) = (n.dot(c), n.dot(p));
            // The horizon: above's β interval, clipped to the half circle, is this one shifted by π/2.
            let (b0, b1) = above(n, c, p);
            let (g0, g1) = above_about_centre(n_c, n_p);
            if g1 > g0 {
                assert!((b0 - (g0 + FRAC_PI_2)).abs() < 1e-12 && (b1 - (g1 + FRAC_PI_2)).abs() < 1e-12, "{n}");
            }
            // The weight over sub-intervals of a sun-sized chord and of wide ones.
            for width in [1e-3, 0.5, 2.0] {
                let lo = -0.5 * width + 0.1 * width * (rng() - 0.5);
                let hi = lo + width * rng();
                let want = weight_integral(n_c, n_p, lo + FRAC_PI_2, hi + FRAC_PI_2);
                let got = weight_integral_about_centre(n_c, n_p, lo, hi);
                // β's ends carry an ulp of π/2 (2.2e-16) each, the density is at most 1.
                assert!((got - want).abs() <= 1e-12 * (hi - lo) + 1e-15, "{n} [{lo}, {hi}]: {got} against {want}");
            }
        }
    }

    #[test]
    fn the_visible_weight_agrees_with_the_beta_formulation() {
        let mut next = uniform(9);
        let mut rng = || 0.5 * (next() + 1.0);
        for _ in 0..500 {
            let (n_c, n_p) = (rng() - 0.5, rng());
            let span = (-4e-3 + 1e-3 * rng(), 3e-3 + 1e-3 * rng());
            let mut blocked: Vec<(f64, f64)> = (0..(rng() * 5.0) as usize)
                .map(|_| {
                    let a = -6e-3 + 12e-3 * rng();
                    let b = a + 4e-3 * rng();
                    (pseudo_angle_of_gamma(a), pseudo_angle_of_gamma(b))
                })
                .collect();
            let mut copy = blocked.clone();
            let got = visible_weight_about_centre(n_c, n_p, span, &mut blocked);
            let want = visible_weight(n_c, n_p, (span.0 + FRAC_PI_2, span.1 + FRAC_PI_2), &mut copy);
            // β near π/2 keeps 1e-16 of itself absolute, about 3e-14 of these chords' weights.
            let scale = weight_integral_about_centre(n_c.abs(), n_p.abs() + n_c.abs(), span.0, span.1);
            assert!((got - want).abs() <= 1e-11 * scale, "{got} against {want}");
        }
    }
}

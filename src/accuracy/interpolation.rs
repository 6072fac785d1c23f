//! The error of f32 interpolation: a bound on how far the shader's f32 barycentrics are from the exact ones, from
//! the triangle's shape at each pixel, and the radiance's change when a pixel's barycentrics move that far.
//!
//! **The barycentrics** (`shaders/transform.glsl`, `triangle_barycentrics_exact` without shaderFloat64; mirrored
//! by `cpu::barycentric::triangle_barycentrics_f32`): with the pixel's NDC `n` and the clip-space vertices `cᵢ`,
//! `dᵢ = cᵢ.xy − n cᵢ.w`, `b₀ = d₁ × d₂` (and cyclically), `S = (b₀ + b₁) + b₂`, `lᵢ = bᵢ / S`, every operation
//! rounded to f32 (`u = 2⁻²⁴`), none fused. The inputs (`cᵢ` and `n`, both f32) are the ones the exact
//! computation uses, so only these roundings count. To first order in u:
//!
//! - `dᵢ`: a product and a difference, `|δdᵢ| ≤ u (|n wᵢ| + |dᵢ|)` per component;
//! - `b₀ = d₁.x d₂.y − d₁.y d₂.x`: the operands' errors times the other factors, two product roundings and one of
//!   the difference: `|δb₀| ≤ Σ |δd₁||d₂| + |d₁||δd₂| (crosswise) + u (|d₁.x d₂.y| + |d₁.y d₂.x|) + u |b₀|`;
//! - `S`: `|δS| ≤ Σ|δbᵢ| + u (|b₀ + b₁| + |S|)`;
//! - `lᵢ`: `|δlᵢ| ≤ (|δbᵢ| + |lᵢ| |δS|) / |S| + u |lᵢ|`, so that
//!   `Σ|δlᵢ| ≤ (Σ|δbᵢ| + Σ|lᵢ| |δS|) / |S| + u Σ|lᵢ|` ([`f32_barycentric_error`]).
//!
//! The ratio of the products `|dⱼ||dₖ|` to `S` is the triangle's shape as seen from the pixel: `S` is twice the
//! area of the sheared triangle, the products grow with its edges, and the term `u |n wᵢ|` makes a small triangle far
//! from the image's centre worse than the same triangle at the centre (its vertices' offsets from the pixel are
//! small against the coordinates they are differences of). Precision is lost there, in the subtraction of
//! `dᵢ`; the weights' normalisation by `S` keeps the error relative to the triangle, not to the image (docs/accuracy.md).
//! Second-order terms (`u²` times the squared ratio, a small multiple of the first-order bound squared) are allowed
//! for by taking the bound `(1.01 + 4E) E`; above [`MAX_FIRST_ORDER`] no claim is made (an infinite bound). The
//! thin triangles that reach it are surfaces seen edge-on (a sphere's silhouette: a triangle a tenth of a pixel
//! wide), where the weights lose three or four of f32's seven digits.
//!
//! **The radiance**: f32 barycentrics interpolate the position, normal and tangent (and texture coordinates on a
//! device without shaderFloat64); a pixel's radiance `L(l)` is, over so small a move, linear in the barycentrics,
//! so its largest change over the ball `Σ|δlᵢ| ≤ r` is `r maxᵢ |∂L/∂lᵢ|`, reached at one of the ball's six
//! corners `l ± r eᵢ` (the L1 ball's dual norm is the max norm). The reference shades each pixel at those six
//! points (`cpu::barycentric_sensitivity`), unshadowed: a shadow ray that the move carries across an occluder's
//! edge is a fragile ray, the class `render --check` counts apart, not an interpolation error. The bound is the
//! largest change over `max(L, 1% of the image's peak)` (the diff's floor).

use glam::{DVec2, Vec2, Vec4};

use crate::compare::image_peak;
use crate::cpu::{self, ReferenceOptions};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::Shadows;

use super::bounds::FLOOR_FRACTION;

/// f32's unit roundoff, `2⁻²⁴`.
const U: f64 = f32::EPSILON as f64 / 2.0;

/// The largest barycentric error the bound is claimed for.
pub const MAX_FIRST_ORDER: f64 = 0.05;

/// The second-order terms' allowance: the bound `E` is taken as `(1.01 + 4E) E`. Each second-order term is a
/// product of two first-order relative errors, so their sum is a small multiple of `E²`; 4 covers the largest
/// seen on the random triangles of the test (thin ones reach `E` = 0.05).
const SECOND_ORDER: f64 = 4.0;

/// A bound on `Σ|l̃ᵢ − lᵢ|`, the shader's f32 barycentrics against the exact ones, at the pixel whose NDC is `ndc`
/// in the triangle with clip-space vertices `c` (module text). Infinite where the first-order bound exceeds
/// [`MAX_FIRST_ORDER`] or the triangle is degenerate from the pixel (`S = 0`).
pub fn f32_barycentric_error(c: [Vec4; 3], ndc: Vec2) -> f64 {
    let n = ndc.as_dvec2();
    let w = c.map(|v| v.w as f64);
    // Exact in f64: products of two f32 are exact, the difference rounds at 1e-16.
    let d: [DVec2; 3] = std::array::from_fn(|i| DVec2::new(c[i].x as f64 - n.x * w[i], c[i].y as f64 - n.y * w[i]));
    let dd: [DVec2; 3] =
        std::array::from_fn(|i| U * DVec2::new((n.x * w[i]).abs() + d[i].x.abs(), (n.y * w[i]).abs() + d[i].y.abs()));
    let cross = |a: DVec2, b: DVec2| a.x * b.y - a.y * b.x;
    let pairs = [(1, 2), (2, 0), (0, 1)];
    let b = pairs.map(|(j, k)| cross(d[j], d[k]));
    let db = pairs.map(|(j, k)| {
        let (p, q, ep, eq) = (d[j], d[k], dd[j], dd[k]);
        let operands = ep.x * q.y.abs() + p.x.abs() * eq.y + ep.y * q.x.abs() + p.y.abs() * eq.x;
        operands + U * ((p.x * q.y).abs() + (p.y * q.x).abs()) + U * cross(p, q).abs()
    });
    let s = b[0] + b[1] + b[2];
    if s == 0.0 || !s.is_finite() {
        return f64::INFINITY;
    }
    let ds = db.iter().sum::<f64>() + U * ((b[0] + b[1]).abs() + s.abs());
    let l_abs: f64 = b.iter().map(|x| (x / s).abs()).sum();
    let bound = (db.iter().sum::<f64>() + l_abs * ds) / s.abs() + U * l_abs;
    if bound.is_finite() && bound <= MAX_FIRST_ORDER {
        (1.01 + SECOND_ORDER * bound) * bound
    } else {
        f64::INFINITY
    }
}

/// The bound on the relative error (with the diff's floor) that f32 barycentrics add to the reference's image of
/// `scene` with `settings` (module text): the largest change of a pixel's radiance over its barycentric ball,
/// unshadowed, over `max(L, 1% of the peak)`. `options` mirror the device (its sub-pixel bits decide which
/// triangle a pixel sees).
pub fn f32_interpolation_bound(scene: &Scene, settings: &RenderSettings, options: &ReferenceOptions) -> f64 {
    let mut s = settings.clone();
    s.shading.shadows = Shadows::None;
    let (plain, change) = cpu::barycentric_sensitivity(scene, &s, options, &f32_barycentric_error);
    let floor = FLOOR_FRACTION * image_peak(&plain);
    plain
        .pixels()
        .iter()
        .zip(change.pixels())
        .filter(|(p, _)| p[3] > 0.0)
        .flat_map(|(p, c)| (0..3).map(move |k| c[k] as f64 / (p[k].abs() as f64).max(floor)))
        .map(|r| if r.is_nan() { f64::INFINITY } else { r })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::barycentric::{pixel_ndc, triangle_barycentrics_exact, triangle_barycentrics_f32};

    /// A small deterministic generator (xorshift), for reproducible random triangles.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The bound holds for the shader's f32 arithmetic (its Rust mirror) on 200 000 triangles and pixels: ordinary,
    /// thin (aspect up to 1e4, bounds up to the claim's limit), tiny (a hundredth of a pixel) and far off centre,
    /// with w from 0.1 to 100, and the pixel inside the triangle; it is not wildly loose either (the largest error
    /// reaches a tenth of it).
    #[test]
    fn the_f32_barycentric_bound_holds_for_the_shaders_arithmetic() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        let (mut worst_ratio, mut claims, mut largest) = (0.0f64, 0, 0.0f64);
        for case in 0..200_000 {
            let (width, height) = (1024u32, 768u32);
            let (x, y) = ((rng.next() * width as f64) as u32, (rng.next() * height as f64) as u32);
            let ndc = pixel_ndc(x, y, width, height);
            // A triangle around the pixel: size from 1e-4 to 1 in NDC, stretched by up to 1e4 one way.
            let size = 10f64.powf(-4.0 + 4.0 * rng.next());
            let stretch = 10f64.powf(4.0 * rng.next() * (case % 2) as f64);
            let angle = rng.next() * std::f64::consts::TAU;
            let (ca, sa) = (angle.cos(), angle.sin());
            let corner = |u: f64, v: f64| {
                let (u, v) = (u * size * stretch, v * size / stretch.sqrt());
                DVec2::new(ndc.x as f64 + ca * u - sa * v, ndc.y as f64 + sa * u + ca * v)
            };
            let l = [rng.next() + 0.01, rng.next() + 0.01, rng.next() + 0.01];
            let total: f64 = l.iter().sum();
            // Corners placed so that the pixel has barycentrics l/total.
            let p = [corner(-1.0, -1.0), corner(1.0, -0.5), corner(0.2, 1.0)];
            let centroid = (p[0] * l[0] + p[1] * l[1] + p[2] * l[2]) / total;
            let shift = DVec2::new(ndc.x as f64, ndc.y as f64) - centroid;
            let c: [Vec4; 3] = std::array::from_fn(|i| {
                let q = p[i] + shift;
                let w = 10f64.powf(-1.0 + 3.0 * rng.next());
                Vec4::new((q.x * w) as f32, (q.y * w) as f32, 0.5, w as f32)
            });
            let exact = triangle_barycentrics_exact(c, ndc);
            if exact.min_element() <= 0.0 {
                continue; // rounding the corners to f32 moved the pixel out of the triangle
            }
            let f32s = triangle_barycentrics_f32(c, ndc);
            let error: f64 = (0..3).map(|i| (f32s[i] as f64 - exact[i]).abs()).sum();
            let bound = f32_barycentric_error(c, ndc);
            if bound.is_finite() {
                claims += 1;
                assert!(error <= bound, "case {case}: error {error:e} over its bound {bound:e}: {c:?} at {ndc:?}");
                worst_ratio = worst_ratio.max(error / bound);
                largest = largest.max(bound);
            }
        }
        println!("{claims} claims, bounds up to {largest:.1e}; largest error / bound {worst_ratio:.3}");
        assert!(claims > 120_000, "{claims}");
        // Thin triangles reach the second-order regime the bound allows for.
        assert!(largest > 1e-2, "{largest:e}");
        assert!(worst_ratio > 0.1, "the bound is far looser than the arithmetic: {worst_ratio}");
    }
}

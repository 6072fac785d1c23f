//! Texture lookups specified by sunshade, not by the device (docs/textures.md gives the formulas): texel centres
//! at `(i + ½)/N`, wrapping on integer texel coordinates as Vulkan does, a mip level chosen from the UV footprint
//! of the pixel, bilinear and trilinear blends in a fixed order. Mirrored by `shaders/texture_filter.glsl` name
//! for name, so that the GPU and the reference agree to rounding.
//!
//! Precision: texture coordinates, footprints and texel indices are computed in f64 (on the GPU too where the
//! device has shaderFloat64, from the same f64 barycentrics), so both renderers pick the same texels and the
//! same levels, bitwise; the blend weights are then rounded to f32 and the blends done in f32 in the same order
//! on both sides (Rust's f32 arithmetic is IEEE without contraction; the shader marks them `precise`). The level
//! and its blend weight come from `frexp` of the footprint, not from `log2`, whose last bit lavapipe does not
//! round as Rust does.

use crate::scene::texture::{Filter, Level, MipFilter, Texture, Wrap};

/// Coordinates beyond ±2⁴⁰ texels (and NaN) are taken as 0: far past any image, where f64 still counts whole
/// texels exactly.
pub const MAX_TEXEL_COORDINATE: f64 = 1.099_511_627_776e12;

/// A texel index in `[0, n)` for any integer-valued `i` (f64), by the wrap mode: `i − n⌊i/n⌋`; mirrored:
/// `p = i − 2n⌊i/2n⌋`, then `2n − 1 − p` where `p ≥ n`; clamped: `clamp(i, 0, n − 1)`.
pub fn wrap_texel(i: f64, n: u32, wrap: Wrap) -> u32 {
    let n = n as f64;
    let w = match wrap {
        Wrap::Repeat => i - n * (i / n).floor(),
        Wrap::ClampToEdge => i.clamp(0.0, n - 1.0),
        Wrap::MirroredRepeat => {
            let p = i - 2.0 * n * (i / (2.0 * n)).floor();
            if p >= n {
                2.0 * n - 1.0 - p
            } else {
                p
            }
        }
    };
    // The formulas give [0, n) exactly; the clamp only guards the rounding of i/n for |i| near 2⁴⁰.
    w.clamp(0.0, n - 1.0) as u32
}

/// A coordinate in texels of a level: `x` (NaN and beyond ±[`MAX_TEXEL_COORDINATE`] taken as 0).
pub fn texel_coordinate(x: f64) -> f64 {
    if x.abs() < MAX_TEXEL_COORDINATE {
        x
    } else {
        0.0
    }
}

/// The texel `(i, j)` of a level (already wrapped).
pub fn texel(level: &Level, i: u32, j: u32) -> [f32; 4] {
    level.texel((j * level.width + i) as usize)
}

/// One level filtered at `uv` ((0, 0) the image's top-left corner, (1, 1) its bottom-right):
/// nearest `(⌊u w⌋, ⌊v h⌋)`; linear between the four texel centres around `(u w − ½, v h − ½)`, weights
/// `a = x − ⌊x⌋`, `b = y − ⌊y⌋` rounded to f32, blended `((t00 (1−a) + t10 a)(1−b) + (t01 (1−a) + t11 a) b)`.
pub fn filter_level(level: &Level, filter: Filter, wrap: [Wrap; 2], uv: [f64; 2]) -> [f32; 4] {
    let (w, h) = (level.width, level.height);
    match filter {
        Filter::Nearest => {
            let x = texel_coordinate(uv[0] * w as f64).floor();
            let y = texel_coordinate(uv[1] * h as f64).floor();
            texel(level, wrap_texel(x, w, wrap[0]), wrap_texel(y, h, wrap[1]))
        }
        Filter::Linear => {
            let x = texel_coordinate(uv[0] * w as f64 - 0.5);
            let y = texel_coordinate(uv[1] * h as f64 - 0.5);
            let (x0, y0) = (x.floor(), y.floor());
            let a = (x - x0) as f32;
            let b = (y - y0) as f32;
            let (i0, i1) = (wrap_texel(x0, w, wrap[0]), wrap_texel(x0 + 1.0, w, wrap[0]));
            let (j0, j1) = (wrap_texel(y0, h, wrap[1]), wrap_texel(y0 + 1.0, h, wrap[1]));
            let (t00, t10, t01, t11) =
                (texel(level, i0, j0), texel(level, i1, j0), texel(level, i0, j1), texel(level, i1, j1));
            let (ra, rb) = (1.0 - a, 1.0 - b);
            [0, 1, 2, 3].map(|c| {
                let top = t00[c] * ra + t10[c] * a;
                let bottom = t01[c] * ra + t11[c] * a;
                top * rb + bottom * b
            })
        }
    }
}

/// Where a lookup reads: the level(s) and the blend weight of the second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelChoice {
    /// The filter within the level(s): magnification's or minification's.
    pub filter: Filter,
    pub level: usize,
    /// The next level's weight in a trilinear blend (0: one level only).
    pub blend: f32,
}

/// The level of a lookup from the footprint of one pixel: with level-0 size (W, H) and the UV steps to the
/// neighbouring pixel centres `dx = uv_x − uv`, `dy = uv_y − uv`, `ρ² = max(|(dx W, dx' H)|², |(dy W, dy' H)|²)`
/// (texels per pixel, squared). `ρ² ≤ 1` (or NaN): magnification, level 0. Otherwise minification: `ρ = m·2^e`
/// with `m ∈ [½, 1)` ([`split_exponent`], exact), level `d = e − 1 = ⌊log₂ρ⌋`; nearest mip: `d + 1` where `2m² ≥ 1`
/// (`log₂ρ ≥ d + ½`), else d; linear mip: levels d and d + 1 blended by `δ = 2m − 1` (linear in ρ between the
/// levels, continuous across them); beyond the last level, the last level alone.
pub fn choose_level(texture: &Texture, uv: [f64; 2], uv_x: [f64; 2], uv_y: [f64; 2]) -> LevelChoice {
    let l0 = &texture.levels[0];
    let (w, h) = (l0.width as f64, l0.height as f64);
    let (dxu, dxv) = ((uv_x[0] - uv[0]) * w, (uv_x[1] - uv[1]) * h);
    let (dyu, dyv) = ((uv_y[0] - uv[0]) * w, (uv_y[1] - uv[1]) * h);
    let rho2 = (dxu * dxu + dxv * dxv).max(dyu * dyu + dyv * dyv);
    let sampler = &texture.sampler;
    // Written so that NaN takes the first branch.
    if rho2.partial_cmp(&1.0) != Some(std::cmp::Ordering::Greater) {
        return LevelChoice { filter: sampler.mag, level: 0, blend: 0.0 };
    }
    let last = texture.levels.len() - 1;
    if rho2 >= MAX_TEXEL_COORDINATE * MAX_TEXEL_COORDINATE {
        // A footprint past 2⁴⁰ texels (or infinite): the coarsest level the filter reads.
        let level = if sampler.mip == MipFilter::None { 0 } else { last };
        return LevelChoice { filter: sampler.min, level, blend: 0.0 };
    }
    let (m, e) = split_exponent(rho2.sqrt());
    let d = (e - 1).max(0) as usize;
    match sampler.mip {
        MipFilter::None => LevelChoice { filter: sampler.min, level: 0, blend: 0.0 },
        MipFilter::Nearest => {
            let level = if 2.0 * m * m >= 1.0 { d + 1 } else { d };
            LevelChoice { filter: sampler.min, level: level.min(last), blend: 0.0 }
        }
        MipFilter::Linear if d >= last => LevelChoice { filter: sampler.min, level: last, blend: 0.0 },
        MipFilter::Linear => LevelChoice { filter: sampler.min, level: d, blend: (2.0 * m - 1.0) as f32 },
    }
}

/// `x = m · 2^e` with `m ∈ [½, 1)` for finite positive x (C's `frexp`, written on the bits so that the shader's
/// twin is the same operation); (0, 0) for 0.
pub fn split_exponent(x: f64) -> (f64, i32) {
    if x == 0.0 || !x.is_finite() {
        return (0.0, 0);
    }
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i32;
    if exponent == 0 {
        // Subnormal: scale into the normal range first.
        let (m, e) = split_exponent(x * 2f64.powi(64));
        return (m, e - 64);
    }
    let m = f64::from_bits((bits & !(0x7ff << 52)) | (1022 << 52));
    (m, exponent - 1022)
}

/// A texture looked up at `uv` with the footprint given by the UVs at the neighbouring pixel centres (right:
/// `uv_x`, below: `uv_y`), linear RGBA: [`choose_level`], [`filter_level`] on one level or two, the two blended
/// `r0 (1 − δ) + r1 δ` in f32.
pub fn texture_lookup(texture: &Texture, uv: [f64; 2], uv_x: [f64; 2], uv_y: [f64; 2]) -> [f32; 4] {
    let choice = choose_level(texture, uv, uv_x, uv_y);
    let wrap = [texture.sampler.wrap_s, texture.sampler.wrap_t];
    let r0 = filter_level(&texture.levels[choice.level], choice.filter, wrap, uv);
    if choice.blend == 0.0 {
        return r0;
    }
    let r1 = filter_level(&texture.levels[choice.level + 1], choice.filter, wrap, uv);
    let (d, rd) = (choice.blend, 1.0 - choice.blend);
    [0, 1, 2, 3].map(|c| r0[c] * rd + r1[c] * d)
}

/// [`texture_lookup`] with no footprint (`uv_x = uv_y = uv`, as at a shadow ray's hit on a masked occluder): ρ = 0
/// (or NaN) takes level 0 with the magnification filter and no blend, so this is that level filtered, bitwise the
/// same. The shader calls it where the footprint is known to be empty, compiling neither the level choice nor a
/// second level there.
pub fn texture_magnified(texture: &Texture, uv: [f64; 2]) -> [f32; 4] {
    let wrap = [texture.sampler.wrap_s, texture.sampler.wrap_t];
    filter_level(&texture.levels[0], texture.sampler.mag, wrap, uv)
}

/// How near the result of a lookup is to one of its jumps, as a fraction of the decision's own scale: the
/// distance of a `NEAREST` texel coordinate from a texel boundary over `|x| + 1`, of `2m²` from 1 for a nearest
/// mip level, of `ρ²` from 1 where magnification and minification filter differently (over `max(ρ², 1)`); infinity
/// for a lookup whose result is continuous there (bilinear, trilinear). Rust only: the reference uses it to flag
/// pixels that rounding elsewhere (f32 texture coordinates) could send across a jump (docs/textures.md).
pub fn discontinuity_margin(texture: &Texture, uv: [f64; 2], uv_x: [f64; 2], uv_y: [f64; 2]) -> f64 {
    let s = &texture.sampler;
    let l0 = &texture.levels[0];
    let (w, h) = (l0.width as f64, l0.height as f64);
    let (dxu, dxv) = ((uv_x[0] - uv[0]) * w, (uv_x[1] - uv[1]) * h);
    let (dyu, dyv) = ((uv_y[0] - uv[0]) * w, (uv_y[1] - uv[1]) * h);
    let rho2 = (dxu * dxu + dxv * dxv).max(dyu * dyu + dyv * dyv);
    let mut margin = f64::INFINITY;
    if s.mag != s.min || s.mip != MipFilter::None {
        margin = margin.min((rho2 - 1.0).abs() / rho2.max(1.0));
    }
    let choice = choose_level(texture, uv, uv_x, uv_y);
    if s.mip == MipFilter::Nearest && rho2 > 1.0 && rho2.is_finite() {
        let (m, _) = split_exponent(rho2.sqrt());
        margin = margin.min((2.0 * m * m - 1.0).abs());
    }
    if choice.filter == Filter::Nearest {
        let level = &texture.levels[choice.level];
        for x in [uv[0] * level.width as f64, uv[1] * level.height as f64] {
            let x = texel_coordinate(x);
            margin = margin.min((x - x.round()).abs() / (x.abs() + 1.0));
        }
    }
    if margin.is_nan() {
        0.0
    } else {
        margin
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::texture::{Level, Sampler};

    fn checker(n: u32) -> Texture {
        let texels = (0..n * n)
            .map(|k| if (k % n + k / n).is_multiple_of(2) { [1.0; 4] } else { [0.0, 0.0, 0.0, 1.0] })
            .collect();
        Texture::new("checker".into(), Level::linear(n, n, texels), Sampler::default())
    }

    #[test]
    fn wrap_modes_follow_vulkan() {
        let got: Vec<u32> = (-5..6).map(|i| wrap_texel(i as f64, 3, Wrap::Repeat)).collect();
        assert_eq!(got, [1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2]);
        let got: Vec<u32> = (-5..6).map(|i| wrap_texel(i as f64, 3, Wrap::MirroredRepeat)).collect();
        // … 0 1 2 | 2 1 0 | 0 1 2 | 2 1 0 …, with i = 0 at the start of an upright period.
        assert_eq!(got, [1, 2, 2, 1, 0, 0, 1, 2, 2, 1, 0]);
        let got: Vec<u32> = (-2..5).map(|i| wrap_texel(i as f64, 3, Wrap::ClampToEdge)).collect();
        assert_eq!(got, [0, 0, 0, 1, 2, 2, 2]);
        assert_eq!(wrap_texel(texel_coordinate(f64::NAN), 3, Wrap::Repeat), 0);
    }

    #[test]
    fn linear_magnification_hits_texel_centres_and_midpoints() {
        let level = Level::linear(2, 1, vec![[0.0; 4], [1.0; 4]]);
        let f = |u: f64| filter_level(&level, Filter::Linear, [Wrap::ClampToEdge; 2], [u, 0.5])[0];
        assert_eq!(f(0.25), 0.0); // centre of texel 0
        assert_eq!(f(0.75), 1.0); // centre of texel 1
        assert_eq!(f(0.5), 0.5);
        assert_eq!(f(0.375), 0.25);
        assert_eq!(f(0.0), 0.0); // clamped
        let n = |u: f64| filter_level(&level, Filter::Nearest, [Wrap::Repeat; 2], [u, 0.5])[0];
        assert_eq!((n(0.49), n(0.5), n(1.2)), (0.0, 1.0, 0.0));
    }

    #[test]
    fn level_follows_the_footprint() {
        let t = checker(64);
        let at = |texels_per_pixel: f64| {
            let step = texels_per_pixel / 64.0;
            choose_level(&t, [0.3, 0.3], [0.3 + step, 0.3], [0.3, 0.3])
        };
        assert_eq!(at(0.5), LevelChoice { filter: Filter::Linear, level: 0, blend: 0.0 });
        assert_eq!(at(2.0), LevelChoice { filter: Filter::Linear, level: 1, blend: 0.0 });
        assert_eq!(at(3.0), LevelChoice { filter: Filter::Linear, level: 1, blend: 0.5 });
        assert_eq!(at(1e6).level, 6);
        // Continuous across a level change: just below 4 texels a pixel the blend is all level 2.
        let below = at(4.0 - 1e-9);
        assert_eq!(below.level, 1);
        assert!((below.blend - 1.0).abs() < 1e-6);
        // A checker minified to one texel a pixel's footprint of 8: the mean, 0.5.
        let v = texture_lookup(&t, [0.5, 0.5], [0.5 + 8.0 / 64.0, 0.5], [0.5, 0.5 + 8.0 / 64.0]);
        assert!((v[0] - 0.5).abs() < 1e-6, "{v:?}");
    }

    #[test]
    fn a_lookup_without_footprint_is_the_magnified_level_0() {
        let mut rng = crate::test_rng::uniform(7);
        let texels = (0..12 * 5).map(|_| [0, 1, 2, 3].map(|_| rng().abs() as f32)).collect();
        let level0 = Level::linear(12, 5, texels);
        for (mag, min, wrap) in [
            (Filter::Linear, Filter::Nearest, Wrap::Repeat),
            (Filter::Nearest, Filter::Linear, Wrap::MirroredRepeat),
            (Filter::Linear, Filter::Linear, Wrap::ClampToEdge),
        ] {
            let sampler = Sampler { wrap_s: wrap, wrap_t: Wrap::Repeat, mag, min, mip: MipFilter::Linear };
            let t = Texture::new("t".into(), level0.clone(), sampler);
            let mut uvs: Vec<[f64; 2]> = (0..500).map(|_| [rng() * 3.0, rng() * 2.0]).collect();
            uvs.extend([[f64::NAN, 0.3], [f64::INFINITY, 0.5], [0.25, -f64::INFINITY], [1e300, 2.0]]);
            for uv in uvs {
                let lookup = texture_lookup(&t, uv, uv, uv).map(f32::to_bits);
                assert_eq!(texture_magnified(&t, uv).map(f32::to_bits), lookup, "{uv:?} {mag:?} {wrap:?}");
            }
        }
    }

    #[test]
    fn split_exponent_matches_frexp() {
        for x in [1.0, 1.5, 3.0, 1e-300, 7e300, 0.75] {
            let (m, e) = split_exponent(x);
            assert!((0.5..1.0).contains(&m), "{x}");
            assert_eq!(m * 2f64.powi(e), x);
        }
    }
}

//! Textures as both renderers read them: 8-bit images kept as their codes (decoded to linear f32 on lookup,
//! through one table per colour space), other texels as linear f32 RGBA, a mip chain built once here on the CPU,
//! and the sampler's wrap and filter modes. How a texture is looked up (texel centres, wrapping, the
//! level chosen from UV derivatives, the blends) is `shading::texture_filter`, mirrored by
//! `shaders/texture_filter.glsl`; docs/textures.md gives the formulas.

/// How texel coordinates outside [0, N) are brought back, per axis (glTF sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// 10497: `i mod N`.
    Repeat,
    /// 33648: reflected every other period.
    MirroredRepeat,
    /// 33071: `clamp(i, 0, N − 1)`.
    ClampToEdge,
}

/// A filter within one level (glTF `magFilter`, and the first half of `minFilter`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    /// The texel containing the point.
    Nearest,
    /// Bilinear between the four texel centres around the point.
    Linear,
}

/// Which levels minification reads (the second half of glTF's `minFilter`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MipFilter {
    /// Level 0 only (`NEAREST`, `LINEAR`).
    None,
    /// The nearest level (`*_MIPMAP_NEAREST`).
    Nearest,
    /// A blend of the two levels around the footprint (`*_MIPMAP_LINEAR`).
    Linear,
}

/// A glTF sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampler {
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    pub mag: Filter,
    pub min: Filter,
    pub mip: MipFilter,
}

impl Default for Sampler {
    /// glTF leaves absent filters to the implementation: sunshade takes LINEAR magnification and
    /// LINEAR_MIPMAP_LINEAR (trilinear) minification, and REPEAT as the spec says.
    fn default() -> Self {
        Self {
            wrap_s: Wrap::Repeat,
            wrap_t: Wrap::Repeat,
            mag: Filter::Linear,
            min: Filter::Linear,
            mip: MipFilter::Linear,
        }
    }
}

impl Sampler {
    /// From glTF's codes (`None`: absent). Unknown codes are errors naming the code.
    pub fn from_gl(mag: Option<u64>, min: Option<u64>, wrap_s: u64, wrap_t: u64) -> Result<Self, String> {
        let wrap = |code: u64| match code {
            10497 => Ok(Wrap::Repeat),
            33648 => Ok(Wrap::MirroredRepeat),
            33071 => Ok(Wrap::ClampToEdge),
            other => Err(format!("wrap mode {other} is not a glTF wrap mode")),
        };
        let d = Sampler::default();
        let mag = match mag {
            None => d.mag,
            Some(9728) => Filter::Nearest,
            Some(9729) => Filter::Linear,
            Some(other) => return Err(format!("magFilter {other} is not a glTF filter")),
        };
        let (min, mip) = match min {
            None => (d.min, d.mip),
            Some(9728) => (Filter::Nearest, MipFilter::None),
            Some(9729) => (Filter::Linear, MipFilter::None),
            Some(9984) => (Filter::Nearest, MipFilter::Nearest),
            Some(9985) => (Filter::Linear, MipFilter::Nearest),
            Some(9986) => (Filter::Nearest, MipFilter::Linear),
            Some(9987) => (Filter::Linear, MipFilter::Linear),
            Some(other) => return Err(format!("minFilter {other} is not a glTF filter")),
        };
        Ok(Self { wrap_s: wrap(wrap_s)?, wrap_t: wrap(wrap_t)?, mag, min, mip })
    }
}

/// How an image's colour channels are encoded: sRGB (base colour, emission) or linear (metallic-roughness,
/// normals). Alpha is always linear.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    Srgb,
    Linear,
}

/// A level's texels as stored, row by row from the image's top row.
#[derive(Clone, Debug, PartialEq)]
pub enum Texels {
    /// Linear RGBA (16-bit images, the box-filtered mip levels).
    Linear(Vec<[f32; 4]>),
    /// An 8-bit image's RGBA codes as the file stores them: the colour channels encoded in `space`, alpha
    /// linear. Read through [`code_value`], which gives the f32 that decoding to linear would have stored, at a
    /// quarter of the memory.
    Codes { codes: Vec<[u8; 4]>, space: ColorSpace },
}

/// One level of a mip chain: `width × height` texels, row by row from the image's top row (glTF's UV (0, 0) is
/// the top-left corner of the image).
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub width: u32,
    pub height: u32,
    pub texels: Texels,
}

impl Level {
    /// A level of linear RGBA texels.
    pub fn linear(width: u32, height: u32, texels: Vec<[f32; 4]>) -> Self {
        Self { width, height, texels: Texels::Linear(texels) }
    }

    /// Texel `index` (row-major), linear RGBA.
    pub fn texel(&self, index: usize) -> [f32; 4] {
        match &self.texels {
            Texels::Linear(t) => t[index],
            Texels::Codes { codes, space } => {
                let [r, g, b, a] = codes[index];
                let t = channel_tables(*space);
                [t[0][r as usize], t[1][g as usize], t[2][b as usize], t[3][a as usize]]
            }
        }
    }

    /// The least value of channel `c` (0–3) over the level's texels, `f32::min`'s (NaN ignored), infinity for no
    /// texels. 8-bit texels by their codes: each channel's table is increasing, so the least code's value.
    pub fn channel_min(&self, c: usize) -> f32 {
        match &self.texels {
            Texels::Linear(t) => t.iter().map(|p| p[c]).fold(f32::INFINITY, f32::min),
            Texels::Codes { codes, space } => {
                let table = channel_tables(*space)[c];
                codes.iter().map(|p| p[c]).min().map_or(f32::INFINITY, |code| table[code as usize])
            }
        }
    }

    /// How many texels the level holds.
    pub fn len(&self) -> usize {
        match &self.texels {
            Texels::Linear(t) => t.len(),
            Texels::Codes { codes, .. } => codes.len(),
        }
    }

    /// Whether the level holds no texel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The linear value of an 8-bit code in `space`: `code/255` (linear) or the sRGB curve at `code/255`, each
/// computed in f64 and rounded once to f32. The GPU reads the same 256 values from its texel buffer.
pub fn code_value(space: ColorSpace, code: u8) -> f32 {
    code_table(space)[code as usize]
}

/// Each channel's code table for 8-bit texels in `space`: the colour space's for red, green and blue, linear for
/// alpha.
pub fn channel_tables(space: ColorSpace) -> [&'static [f32; 256]; 4] {
    let colour = code_table(space);
    [colour, colour, colour, code_table(ColorSpace::Linear)]
}

/// The 256 values of [`code_value`] in `space`, computed once.
pub fn code_table(space: ColorSpace) -> &'static [f32; 256] {
    use std::sync::OnceLock;
    static TABLES: OnceLock<[[f32; 256]; 2]> = OnceLock::new();
    let tables = TABLES.get_or_init(|| {
        let linear = std::array::from_fn(|c| (c as f64 / 255.0) as f32);
        let srgb = std::array::from_fn(|c| srgb_to_linear(c as u8));
        [linear, srgb]
    });
    match space {
        ColorSpace::Linear => &tables[0],
        ColorSpace::Srgb => &tables[1],
    }
}

/// A texture: its mip chain (level 0 the image itself) and its sampler.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// For messages: the glTF texture and image.
    pub name: String,
    pub levels: Vec<Level>,
    pub sampler: Sampler,
}

impl Texture {
    /// A texture with its mip chain built from `level0` ([`mip_chain`]).
    pub fn new(name: String, level0: Level, sampler: Sampler) -> Self {
        Self { name, levels: mip_chain(level0), sampler }
    }

    /// Drops the levels larger than `max_side` texels on either side, so that the first level kept is the image
    /// (`--max-texture-size`: the box-filtered level of that size stands for it, everywhere both renderers look
    /// it up). Returns how many levels were dropped.
    pub fn limit_size(&mut self, max_side: u32) -> usize {
        let keep_from =
            self.levels.iter().position(|l| l.width.max(l.height) <= max_side.max(1)).unwrap_or(self.levels.len() - 1);
        self.levels.drain(..keep_from);
        keep_from
    }
}

/// A material's use of a texture: which one, which texture-coordinate set, and the affine map applied to the
/// coordinates first (KHR_texture_transform; identity otherwise): `uv' = [m0 m1 m2; m3 m4 m5] (u, v, 1)`, computed
/// in f64 from the extension's offset, rotation and scale and rounded once to f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into `Scene::textures`.
    pub texture: usize,
    /// TEXCOORD_n set (0 or 1).
    pub tex_coord: u32,
    pub transform: [f32; 6],
}

/// The identity transform of [`TextureRef::transform`].
pub const IDENTITY_UV_TRANSFORM: [f32; 6] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// KHR_texture_transform's matrix `T(offset) · R(rotation) · S(scale)`, with the extension's rotation convention
/// (`R = [cos r, sin r; −sin r, cos r]`, counter-clockwise in UV space whose v axis points down).
pub fn uv_transform(offset: [f64; 2], rotation: f64, scale: [f64; 2]) -> [f32; 6] {
    let (s, c) = rotation.sin_cos();
    [c * scale[0], s * scale[1], offset[0], -s * scale[0], c * scale[1], offset[1]].map(|x| x as f32)
}

/// Level sizes halve, rounding down, to 1 × 1 (Vulkan's rule: `max(1, ⌊N/2^k⌋)`).
pub fn level_count(width: u32, height: u32) -> usize {
    32 - width.max(height).max(1).leading_zeros() as usize
}

/// The mip chain: each level a box filter of the one above. A texel of the smaller level covers the interval
/// `[i·N/M, (i+1)·N/M)` of the larger level's texels (N → M = max(1, ⌊N/2⌋) texels); each source texel weighs by
/// the length of its overlap with that interval, divided by N/M. For even N that is the 2 × 2 average; for odd N
/// it spreads over three texels, so no texel is dropped and every level keeps the image's mean. Computed
/// separably in f64 (rows, then columns) from linear texels, rounded once to f32 (so the levels below an 8-bit
/// image are linear f32, not codes).
pub fn mip_chain(level0: Level) -> Vec<Level> {
    let count = level_count(level0.width, level0.height);
    let mut levels = vec![level0];
    while levels.len() < count {
        let prev = levels.last().expect("level 0 is there");
        let (w, h) = ((prev.width / 2).max(1), (prev.height / 2).max(1));
        let next = if prev.width == 2 * w && prev.height == 2 * h { halved(prev) } else { box_filtered(prev, w, h) };
        levels.push(next);
    }
    levels
}

/// The next level of `prev` (w × h texels) by [`box_filter`], separably: output rows in parallel, each from the
/// two or three source rows it covers, filtered across first (a source row shared by two output rows is filtered
/// for each, the same way): every texel is computed alone, so the result does not depend on the order or the split.
fn box_filtered(prev: &Level, w: u32, h: u32) -> Level {
    use rayon::prelude::*;
    let mut texels = vec![[0.0f32; 4]; (w * h) as usize];
    texels.par_chunks_mut(w as usize).enumerate().for_each(|(j, out)| {
        let (first, end) = box_span(prev.height, h, j as u32);
        let across: Vec<Vec<[f64; 4]>> = (first..end)
            .map(|y| {
                let row: Vec<[f64; 4]> =
                    (0..prev.width).map(|x| prev.texel((y * prev.width + x) as usize).map(f64::from)).collect();
                (0..w).map(|i| box_filter(prev.width, w, i, |s| row[s])).collect()
            })
            .collect();
        for (i, texel) in out.iter_mut().enumerate() {
            *texel = box_filter(prev.height, h, j as u32, |s| across[s - first as usize][i]).map(|v| v as f32);
        }
    });
    Level::linear(w, h, texels)
}

/// [`box_filtered`] where both sides are even: each texel from its 2 × 2 source texels, written out with the
/// same f64 operations in the same order as box_filter's even case (across, then down), without the rows it
/// gathers; bitwise the same level.
fn halved(prev: &Level) -> Level {
    // The texels' values, by their codes' tables where 8-bit (what Level::texel reads, without its match each time).
    match &prev.texels {
        Texels::Linear(t) => halved_from(prev.width, prev.height, |k| t[k].map(f64::from)),
        Texels::Codes { codes, space } => {
            let t = channel_tables(*space).map(|table| table.map(f64::from));
            halved_from(prev.width, prev.height, |k| {
                let [r, g, b, a] = codes[k];
                [t[0][r as usize], t[1][g as usize], t[2][b as usize], t[3][a as usize]]
            })
        }
    }
}

/// [`halved`] of a `width` × `height` level whose texel k (row-major) is `texel(k)`.
fn halved_from(width: u32, height: u32, texel: impl Fn(usize) -> [f64; 4] + Sync) -> Level {
    use rayon::prelude::*;
    let (w, h) = (width / 2, height / 2);
    let pair =
        |a: [f64; 4], b: [f64; 4]| -> [f64; 4] { std::array::from_fn(|c| (0.0 + 1.0 * a[c] + 1.0 * b[c]) / 2.0) };
    let at = |x: u32, y: u32| texel((y * width + x) as usize);
    let mut texels = vec![[0.0f32; 4]; (w * h) as usize];
    texels.par_chunks_mut(w as usize).enumerate().for_each(|(j, out)| {
        let (y0, y1) = (2 * j as u32, 2 * j as u32 + 1);
        for (i, texel) in out.iter_mut().enumerate() {
            let (x0, x1) = (2 * i as u32, 2 * i as u32 + 1);
            let (top, bottom) = (pair(at(x0, y0), at(x1, y0)), pair(at(x0, y1), at(x1, y1)));
            *texel = pair(top, bottom).map(|v| v as f32);
        }
    });
    Level::linear(w, h, texels)
}

/// The source texels `[first, end)` that texel `i` of `m` box-filtered from `n` reads (see [`box_filter`]).
fn box_span(n: u32, m: u32, i: u32) -> (u32, u32) {
    let scale = n as f64 / m as f64;
    ((i as f64 * scale).floor() as u32, (((i + 1) as f64 * scale).ceil() as u32).min(n))
}

/// Texel `i` of `m` texels box-filtered from `n` (see [`mip_chain`]).
fn box_filter(n: u32, m: u32, i: u32, texel: impl Fn(usize) -> [f64; 4]) -> [f64; 4] {
    if n == 2 * m {
        // Even n: texels 2i and 2i + 1, each overlapping by exactly 1: the loop's sums below, term for term.
        let (a, b) = (texel(2 * i as usize), texel(2 * i as usize + 1));
        return std::array::from_fn(|c| (0.0 + 1.0 * a[c] + 1.0 * b[c]) / 2.0);
    }
    let scale = n as f64 / m as f64;
    let (lo, hi) = (i as f64 * scale, (i + 1) as f64 * scale);
    let mut sum = [0.0; 4];
    let (first, end) = box_span(n, m, i);
    for s in first..end {
        let overlap = (hi.min(s as f64 + 1.0) - lo.max(s as f64)).max(0.0);
        let t = texel(s as usize);
        for c in 0..4 {
            sum[c] += overlap * t[c];
        }
    }
    sum.map(|v| v / scale)
}

/// sRGB-encoded 8-bit value → linear (IEC 61966-2-1), in f64, rounded once to f32.
pub fn srgb_to_linear(code: u8) -> f32 {
    srgb_decode(code as f64 / 255.0) as f32
}

/// The sRGB transfer function's inverse on an encoded value in [0, 1].
pub fn srgb_decode(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mip_chain_keeps_the_mean_and_halves_down_to_one() {
        // A 5 × 3 ramp: sizes 5×3 → 2×1 → 1×1; every level's mean equals level 0's.
        let texels: Vec<[f32; 4]> = (0..15).map(|i| [i as f32, 1.0, 0.5, 1.0]).collect();
        let levels = mip_chain(Level::linear(5, 3, texels));
        let sizes: Vec<(u32, u32)> = levels.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(5, 3), (2, 1), (1, 1)]);
        for l in &levels {
            let mean = (0..l.len()).map(|i| l.texel(i)[0] as f64).sum::<f64>() / l.len() as f64;
            assert!((mean - 7.0).abs() < 1e-5, "{l:?}");
            assert!((0..l.len()).all(|i| l.texel(i)[1] == 1.0 && l.texel(i)[3] == 1.0));
        }
        // An even size is the 2 × 2 average.
        let l = mip_chain(Level::linear(2, 2, vec![[0.0; 4], [1.0; 4], [2.0; 4], [5.0; 4]]));
        assert_eq!(l[1].texels, Texels::Linear(vec![[2.0; 4]]));
        assert_eq!(level_count(1, 1), 1);
        assert_eq!(level_count(1024, 3), 11);
    }

    #[test]
    fn limiting_the_size_keeps_the_smaller_levels() {
        let level0 = Level::linear(8, 2, vec![[1.0; 4]; 16]);
        let mut t = Texture::new("t".into(), level0, Sampler::default());
        assert_eq!(t.levels.len(), 4);
        assert_eq!(t.limit_size(4), 1);
        assert_eq!((t.levels[0].width, t.levels[0].height, t.levels.len()), (4, 1, 3));
        assert_eq!(t.limit_size(0), 2);
        assert_eq!((t.levels[0].width, t.levels.len()), (1, 1));
    }

    #[test]
    fn srgb_decoding_is_the_standard_curve() {
        assert_eq!(srgb_to_linear(0), 0.0);
        assert_eq!(srgb_to_linear(255), 1.0);
        assert!((srgb_to_linear(10) as f64 - 10.0 / 255.0 / 12.92).abs() < 1e-9);
        assert!((srgb_to_linear(128) - 0.2158605).abs() < 1e-6);
    }

    #[test]
    fn codes_read_as_their_linear_values_and_filter_alike() {
        // A 7 × 5 image of every kind of code, kept as codes and decoded up front: the same texels, the same
        // mip chain, bit for bit.
        let codes: Vec<[u8; 4]> =
            (0..35u32).map(|i| [(i * 7) as u8, (i * 53) as u8, 255 - i as u8, (i * 31) as u8]).collect();
        for space in [ColorSpace::Srgb, ColorSpace::Linear] {
            let decoded: Vec<[f32; 4]> = codes
                .iter()
                .map(|c| {
                    let v = |x: u8| match space {
                        ColorSpace::Srgb => srgb_to_linear(x),
                        ColorSpace::Linear => (x as f64 / 255.0) as f32,
                    };
                    [v(c[0]), v(c[1]), v(c[2]), (c[3] as f64 / 255.0) as f32]
                })
                .collect();
            let kept = mip_chain(Level { width: 7, height: 5, texels: Texels::Codes { codes: codes.clone(), space } });
            let up_front = mip_chain(Level::linear(7, 5, decoded));
            assert_eq!(kept.len(), up_front.len());
            for (k, u) in kept.iter().zip(&up_front) {
                assert_eq!(k.len(), u.len());
                for i in 0..k.len() {
                    assert_eq!(k.texel(i).map(f32::to_bits), u.texel(i).map(f32::to_bits), "{space:?} texel {i}");
                }
            }
            assert!(matches!(kept[1].texels, Texels::Linear(_)));
            // Even sides: the 2 × 2 shortcut is bitwise the separable filter.
            let even = Level { width: 6, height: 4, texels: Texels::Codes { codes: codes[..24].to_vec(), space } };
            let (fast, general) = (halved(&even), box_filtered(&even, 3, 2));
            for i in 0..fast.len() {
                assert_eq!(fast.texel(i).map(f32::to_bits), general.texel(i).map(f32::to_bits), "{space:?} texel {i}");
            }
            // A channel's least value by codes is the least of the decoded texels.
            for (level, c) in [(&kept[0], 0), (&kept[0], 1), (&kept[0], 3), (&kept[1], 2)].into_iter() {
                let each = (0..level.len()).map(|i| level.texel(i)[c]).fold(f32::INFINITY, f32::min);
                assert_eq!(level.channel_min(c).to_bits(), each.to_bits(), "{space:?} channel {c}");
            }
        }
        assert_eq!(code_value(ColorSpace::Srgb, 128), srgb_to_linear(128));
        assert_eq!(code_value(ColorSpace::Linear, 51), 0.2);
    }

    #[test]
    fn samplers_from_gl_codes() {
        let s = Sampler::from_gl(Some(9728), Some(9986), 33648, 33071).unwrap();
        assert_eq!(
            s,
            Sampler {
                wrap_s: Wrap::MirroredRepeat,
                wrap_t: Wrap::ClampToEdge,
                mag: Filter::Nearest,
                min: Filter::Nearest,
                mip: MipFilter::Linear
            }
        );
        assert!(Sampler::from_gl(Some(1), None, 10497, 10497).unwrap_err().contains("magFilter 1"));
        assert!(Sampler::from_gl(None, None, 5, 10497).is_err());
    }

    #[test]
    fn texture_transform_rotates_counter_clockwise() {
        // The extension's example: rotation by π/2 maps u = (1, 0) to (0, −1).
        let m = uv_transform([0.0, 0.0], std::f64::consts::FRAC_PI_2, [1.0, 1.0]);
        let (u, v) = (m[0] * 1.0 + m[2], m[3] * 1.0 + m[5]);
        assert!(u.abs() < 1e-7 && (v + 1.0).abs() < 1e-7, "{u} {v}");
        let m = uv_transform([0.5, 0.25], 0.0, [2.0, 3.0]);
        assert_eq!(m, [2.0, 0.0, 0.5, 0.0, 3.0, 0.25]);
    }
}

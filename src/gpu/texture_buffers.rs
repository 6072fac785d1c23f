//! The textures as the fragment shader reads them: two texel buffers and a table (`TextureTable` and
//! `texture_filter.glsl`'s `texel`). An 8-bit level stays 8-bit codes (`texel_codes`, RGBA8 unsigned integers);
//! the shader turns each code into its linear value through the 256-entry tables that open the f32 buffer
//! (`texels`), the same f32 values `scene::texture::code_value` gives the reference, so both renderers read the
//! same texels bit for bit. Linear f32 levels (the mip levels, 16-bit images) follow the tables.

use crate::scene::texture::{code_table, ColorSpace, Filter, MipFilter, Texels, Wrap};
use crate::scene::Scene;

use super::layout::{
    FILTER_LINEAR, FILTER_NEAREST, MIP_LINEAR, MIP_NEAREST, MIP_NONE, WRAP_CLAMP_TO_EDGE, WRAP_MIRRORED_REPEAT,
    WRAP_REPEAT,
};

/// A level entry's fourth field: where its texels are and how they read.
pub const TEXELS_LINEAR: u32 = 0;
pub const TEXELS_CODES_LINEAR: u32 = 1;
pub const TEXELS_CODES_SRGB: u32 = 2;
/// The first texel of each code table in the f32 buffer (a code's value in the texel's x; y, z, w are 0).
pub const CODE_TABLE_LINEAR: u32 = 0;
pub const CODE_TABLE_SRGB: u32 = 256;
/// The f32 texels the code tables take before the first linear level.
pub const CODE_TABLE_TEXELS: usize = 512;

/// Where every level lies: the texture table (a header per texture, then an entry per level) and how many texels
/// each buffer holds (the f32 one with its code tables; the codes one at least one texel, so that a scene without
/// 8-bit textures binds a valid buffer).
pub struct TextureLayout {
    pub table: Vec<[u32; 4]>,
    pub linear_texels: usize,
    pub code_texels: usize,
}

impl TextureLayout {
    pub fn of(scene: &Scene) -> Self {
        let mut table: Vec<[u32; 4]> = vec![[0; 4]; scene.textures.len()];
        let (mut linear, mut codes) = (CODE_TABLE_TEXELS, 0);
        for (t, texture) in scene.textures.iter().enumerate() {
            table[t] = [table.len() as u32, texture.levels.len() as u32, sampler_bits(texture.sampler), 0];
            for level in &texture.levels {
                let (first, kind) = match &level.texels {
                    Texels::Linear(_) => (&mut linear, TEXELS_LINEAR),
                    Texels::Codes { space: ColorSpace::Linear, .. } => (&mut codes, TEXELS_CODES_LINEAR),
                    Texels::Codes { space: ColorSpace::Srgb, .. } => (&mut codes, TEXELS_CODES_SRGB),
                };
                table.push([*first as u32, level.width, level.height, kind]);
                *first += level.len();
            }
        }
        if table.is_empty() {
            table.push([0; 4]);
        }
        Self { table, linear_texels: linear, code_texels: codes.max(1) }
    }

    /// Writes the code tables and every linear level into `out` (`linear_texels` long).
    pub fn write_linear(&self, scene: &Scene, out: &mut [[f32; 4]]) {
        for (space, first) in [(ColorSpace::Linear, CODE_TABLE_LINEAR), (ColorSpace::Srgb, CODE_TABLE_SRGB)] {
            for (slot, &value) in out[first as usize..].iter_mut().zip(code_table(space)) {
                *slot = [value, 0.0, 0.0, 0.0];
            }
        }
        for (level, entry) in self.levels(scene) {
            if let Texels::Linear(texels) = &level.texels {
                out[entry[0] as usize..][..texels.len()].copy_from_slice(texels);
            }
        }
    }

    /// Writes every 8-bit level's codes into `out` (`code_texels` long).
    pub fn write_codes(&self, scene: &Scene, out: &mut [[u8; 4]]) {
        for (level, entry) in self.levels(scene) {
            if let Texels::Codes { codes, .. } = &level.texels {
                out[entry[0] as usize..][..codes.len()].copy_from_slice(codes);
            }
        }
    }

    /// Every level with its entry in the table.
    fn levels<'a>(
        &'a self,
        scene: &'a Scene,
    ) -> impl Iterator<Item = (&'a crate::scene::texture::Level, [u32; 4])> + 'a {
        scene.textures.iter().enumerate().flat_map(move |(t, texture)| {
            let first = self.table[t][0] as usize;
            texture.levels.iter().enumerate().map(move |(l, level)| (level, self.table[first + l]))
        })
    }
}

/// A sampler as the texture header's third field: wrap S (bits 0–1), wrap T (2–3), magnification (4),
/// minification (5), mip filter (6–7).
fn sampler_bits(s: crate::scene::texture::Sampler) -> u32 {
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => WRAP_REPEAT,
        Wrap::MirroredRepeat => WRAP_MIRRORED_REPEAT,
        Wrap::ClampToEdge => WRAP_CLAMP_TO_EDGE,
    };
    let filter = |f: Filter| match f {
        Filter::Nearest => FILTER_NEAREST,
        Filter::Linear => FILTER_LINEAR,
    };
    let mip = match s.mip {
        MipFilter::None => MIP_NONE,
        MipFilter::Nearest => MIP_NEAREST,
        MipFilter::Linear => MIP_LINEAR,
    };
    wrap(s.wrap_s) | wrap(s.wrap_t) << 2 | filter(s.mag) << 4 | filter(s.min) << 5 | mip << 6
}

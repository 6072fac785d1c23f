//! An RGB8 raster: pixels, lines, filled rectangles and text, written as a PNG.

use std::io;
use std::path::Path;

/// An sRGB colour, 8 bits a channel.
pub type Rgb = [u8; 3];

/// A white canvas of `width × height` pixels, origin at the top left.
#[derive(Clone, Debug)]
pub struct Canvas {
    width: u32,
    height: u32,
    pixels: Vec<Rgb>,
}

/// Side of a glyph [pixels] at scale 1.
pub const GLYPH: i32 = 8;

/// The set pixels `(column, row)` of a character's 8×8 glyph, from its top left; characters outside ASCII are '?'.
fn glyph_pixels(ch: char) -> impl Iterator<Item = (i32, i32)> {
    let code = if ch.is_ascii() { ch as usize } else { '?' as usize };
    let glyph = font8x8::legacy::BASIC_LEGACY[code];
    // font8x8: bit k of a row is column k from the left.
    (0..8).flat_map(move |row| (0..8).filter(move |col| glyph[row] >> col & 1 == 1).map(move |col| (col, row as i32)))
}

impl Canvas {
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![[255; 3]; (width * height) as usize] }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn get(&self, x: u32, y: u32) -> Rgb {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Sets one pixel; outside the canvas nothing happens.
    pub fn set(&mut self, x: i32, y: i32, c: Rgb) {
        if x >= 0 && y >= 0 && (x as u32) < self.width && (y as u32) < self.height {
            self.pixels[(y as u32 * self.width + x as u32) as usize] = c;
        }
    }

    /// Fills the rectangle with corners (x0, y0) and (x1, y1), both included.
    pub fn fill(&mut self, (x0, y0): (i32, i32), (x1, y1): (i32, i32), c: Rgb) {
        for y in y0.min(y1)..=y0.max(y1) {
            for x in x0.min(x1)..=x0.max(x1) {
                self.set(x, y, c);
            }
        }
    }

    /// A line from a to b, both ends included (Bresenham), `thick` pixels wide.
    pub fn line(&mut self, (mut x, mut y): (i32, i32), (x1, y1): (i32, i32), c: Rgb, thick: i32) {
        let (dx, dy) = ((x1 - x).abs(), -(y1 - y).abs());
        let (sx, sy) = (if x < x1 { 1 } else { -1 }, if y < y1 { 1 } else { -1 });
        let mut err = dx + dy;
        let r = thick / 2;
        loop {
            self.fill((x - r, y - r), (x - r + thick - 1, y - r + thick - 1), c);
            if x == x1 && y == y1 {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x += sx;
            }
            if e2 <= dx {
                err += dx;
                y += sy;
            }
        }
    }

    /// Text from its top-left corner, each glyph `8·scale` pixels square; characters outside ASCII draw as '?'.
    pub fn text(&mut self, (x, y): (i32, i32), text: &str, c: Rgb, scale: i32) {
        for (i, ch) in text.chars().enumerate() {
            let gx = x + i as i32 * GLYPH * scale;
            for (col, row) in glyph_pixels(ch) {
                let (px, py) = (gx + col * scale, y + row * scale);
                self.fill((px, py), (px + scale - 1, py + scale - 1), c);
            }
        }
    }

    /// Text drawn upwards (rotated a quarter turn anticlockwise), from its bottom-left corner.
    pub fn text_up(&mut self, (x, y): (i32, i32), text: &str, c: Rgb) {
        for (i, ch) in text.chars().enumerate() {
            let gy = y - i as i32 * GLYPH;
            for (col, row) in glyph_pixels(ch) {
                self.set(x + row, gy - col, c);
            }
        }
    }

    /// Width of `text` at `scale` \[pixels\].
    pub fn text_width(text: &str, scale: i32) -> i32 {
        text.chars().count() as i32 * GLYPH * scale
    }

    /// Writes the canvas as an 8-bit sRGB PNG, atomically.
    pub fn write_png(&self, path: &Path) -> io::Result<()> {
        crate::film::write_atomically(path, |w| {
            let mut encoder = png::Encoder::new(w, self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            let mut writer = encoder.write_header().map_err(io::Error::other)?;
            writer.write_image_data(self.pixels.as_flattened()).map_err(io::Error::other)?;
            writer.finish().map_err(io::Error::other)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_reach_both_ends_and_text_draws_its_glyphs() {
        let mut c = Canvas::new(40, 20);
        c.line((1, 1), (30, 12), [0, 0, 0], 1);
        assert_eq!((c.get(1, 1), c.get(30, 12)), ([0; 3], [0; 3]));
        // Every column between the ends has exactly one pixel of a shallow 1-pixel line.
        for x in 1..=30 {
            assert_eq!((0..20).filter(|&y| c.get(x, y) == [0; 3]).count(), 1, "column {x}");
        }
        let mut t = Canvas::new(16, 8);
        t.text((0, 0), "|.", [0, 0, 0], 1);
        let dark = |x0: u32, x1: u32| {
            (x0..x1).flat_map(|x| (0..8).map(move |y| (x, y))).filter(|&(x, y)| t.get(x, y) == [0; 3]).count()
        };
        // '|' is a vertical bar of several rows; '.' is a small dot.
        assert!(dark(0, 8) >= 6 && dark(8, 16) >= 1 && dark(8, 16) <= 6, "{} {}", dark(0, 8), dark(8, 16));
        // Nothing outside the canvas is touched (no panic either).
        t.text((12, 4), "WW", [0, 0, 0], 2);
    }
}

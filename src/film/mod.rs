//! The one image type both renderers produce: linear radiance in W/(m²·sr) per RGB channel, alpha = coverage.
//!
//! Pixels are stored row-major, top row first (the Vulkan framebuffer's order), as `[r, g, b, a]` in `f32`.
//! A pixel no triangle covers holds radiance 0 and alpha 0; a covered pixel holds alpha 1.

mod atomic;
mod exposure;
mod io;
mod srgb_codes;

pub use atomic::write_atomically;
pub use exposure::{auto_exposure_ev, srgb_encode, Exposure};
pub use io::{
    read_image, read_quantity, read_recorded, write_image, write_image_with, ImageFormat, ImageIoError, Metadata,
};
pub use srgb_codes::srgb_code;

/// An RGBA32F image of linear radiance [W/(m²·sr)] with alpha as coverage.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    pixels: Vec<[f32; 4]>,
}

impl Image {
    /// A `width × height` image with every pixel uncovered (radiance 0, alpha 0).
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![[0.0; 4]; width as usize * height as usize] }
    }

    /// Wraps pixels given row-major, top row first. Returns `None` when the count does not match the size.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<[f32; 4]>) -> Option<Self> {
        (pixels.len() == width as usize * height as usize).then_some(Self { width, height, pixels })
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// All pixels, row-major, top row first.
    pub fn pixels(&self) -> &[[f32; 4]] {
        &self.pixels
    }

    /// How many pixels carry exactly this alpha (a renderer's sentinel: `gpu::loop_budget`, `gpu::slice_gather`),
    /// and where the first one is, `(x, y)`; `None` where none does.
    pub fn alpha_count_and_first(&self, alpha: f32) -> Option<(usize, (u32, u32))> {
        let mut marked = self.pixels.iter().enumerate().filter(|(_, p)| p[3] == alpha).map(|(i, _)| i);
        let first = marked.next()?;
        let w = self.width as usize;
        Some((1 + marked.count(), ((first % w) as u32, (first / w) as u32)))
    }

    pub fn pixels_mut(&mut self) -> &mut [[f32; 4]] {
        &mut self.pixels
    }

    /// The pixel in column `x`, row `y` (row 0 at the top).
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[self.index(x, y)]
    }

    pub fn set(&mut self, x: u32, y: u32, value: [f32; 4]) {
        let i = self.index(x, y);
        self.pixels[i] = value;
    }

    /// Whether the pixel is covered by geometry (alpha > 0).
    pub fn covered(&self, x: u32, y: u32) -> bool {
        self.get(x, y)[3] > 0.0
    }

    /// Number of covered pixels.
    pub fn covered_count(&self) -> usize {
        self.pixels.iter().filter(|p| p[3] > 0.0).count()
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside a {}x{} image", self.width, self.height);
        y as usize * self.width as usize + x as usize
    }
}

/// Bytes an RGBA32F image of this size takes, or `None` on overflow.
pub fn rgba32f_bytes(width: u32, height: u32) -> Option<u64> {
    (width as u64).checked_mul(height as u64)?.checked_mul(16)
}

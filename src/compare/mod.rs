//! Comparing two images: metrics ([`diff`]), a false-colour heatmap ([`heatmap`]) and the perceptual FLIP
//! ([`flip`]).

pub mod flip;
mod heatmap;
mod metrics;

pub use heatmap::{colour_scale, heatmap};
pub use metrics::{
    default_floor, diff, diff_apart, diff_excusing, image_peak, pixel_difference, DiffOptions, DiffReport, Excused,
    PixelDiff, PixelDifference, Split, WorstPixel, F32_SHADING_PEAK_FRACTION,
};

/// Writes a heatmap PNG atomically.
pub fn write_heatmap(path: &std::path::Path, width: u32, height: u32, diffs: &[PixelDiff]) -> std::io::Result<()> {
    let (w, h, px) = heatmap(width, height, diffs);
    let buf = ::image::RgbImage::from_raw(w, h, px).expect("heatmap buffer matches its size");
    crate::film::write_atomically(path, |out| {
        ::image::DynamicImage::ImageRgb8(buf).write_to(out, ::image::ImageFormat::Png).map_err(std::io::Error::other)
    })
}

/// `Ok` where the two images have the same size; else the message every comparison gives.
pub fn same_size(a: &crate::film::Image, b: &crate::film::Image) -> Result<(), String> {
    if (a.width(), a.height()) != (b.width(), b.height()) {
        return Err(format!("sizes differ: {}x{} and {}x{}", a.width(), a.height(), b.width(), b.height()));
    }
    Ok(())
}

/// `|a − b|` per channel, alpha included (coverage mismatches have alpha 1): the float difference image of
/// `diff -o`, like OpenImageIO's `idiff -o`. `Err` when the sizes differ.
pub fn difference_image(a: &crate::film::Image, b: &crate::film::Image) -> Result<crate::film::Image, String> {
    same_size(a, b)?;
    let pixels = a.pixels().iter().zip(b.pixels()).map(|(p, q)| std::array::from_fn(|c| (p[c] - q[c]).abs())).collect();
    Ok(crate::film::Image::from_pixels(a.width(), a.height(), pixels).expect("same size"))
}

//! glTF images → texels (8-bit images as their codes, 16-bit ones as linear f32): PNG and JPEG, from a buffer view, a data URI or a file inside the asset
//! folder (the same rules as buffers). Decoding is bounded: at most [`MAX_TEXTURE_SIDE`] texels a side, checked
//! from the header before the pixels are decoded.

use super::document::{lookup, ImageDef, Root};
use super::files::AssetFiles;
use super::uri::{self, UriTarget};
pub use crate::scene::texture::ColorSpace;
use crate::scene::texture::{srgb_decode, Level, Texels};

/// The longest side of an image sunshade decodes [texels] (lavapipe's `maxImageDimension2D`).
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// The most texels a scene's textures may have, mip levels included: 2^27 (lavapipe's `maxTexelBufferElements`;
/// 2 GiB as f32 RGBA). Checked from each image's header before its pixels are decoded, so that a small
/// compressed file cannot make sunshade allocate gigabytes.
pub const MAX_SCENE_TEXELS: u64 = 1 << 27;

/// The encoded bytes of image `index`, and its MIME type where the file gives one.
pub fn image_bytes(
    root: &Root,
    buffers: &[Vec<u8>],
    files: &AssetFiles,
    index: u64,
    owner: &str,
) -> Result<(Vec<u8>, Option<String>), String> {
    let image: &ImageDef = lookup(&root.images, index, owner, "image")?;
    let what = format!("image {index}");
    match (&image.uri, image.buffer_view) {
        (Some(u), _) => match uri::resolve(u).map_err(|e| format!("{what}: {e}"))? {
            UriTarget::Data(bytes) => Ok((bytes, image.mime_type.clone())),
            UriTarget::File(rel) => {
                let bytes = files.read(&rel, u, None).map_err(|e| format!("{what}: {e}"))?;
                Ok((bytes, image.mime_type.clone()))
            }
        },
        (None, Some(view)) => {
            let v = lookup(&root.buffer_views, view, &what, "bufferView")?;
            let buffer = usize::try_from(v.buffer).ok().and_then(|b| buffers.get(b));
            let buffer =
                buffer.ok_or_else(|| format!("{what}: bufferView {view}: buffer {} does not exist", v.buffer))?;
            let range = usize::try_from(v.byte_offset)
                .ok()
                .zip(usize::try_from(v.byte_length).ok())
                .and_then(|(start, len)| Some(start..start.checked_add(len)?))
                .filter(|r| r.end <= buffer.len())
                .ok_or_else(|| format!("{what}: bufferView {view} is out of range of its buffer"))?;
            Ok((buffer[range].to_vec(), image.mime_type.clone()))
        }
        (None, None) => Err(format!("{what} has neither a uri nor a bufferView")),
    }
}

/// Checks an image before decoding it: PNG or JPEG, at most [`MAX_TEXTURE_SIDE`] a side, not empty, and its mip
/// chain (at most 4/3 of its texels) within `texels_left`, the scene's remaining budget of texels (of
/// [`MAX_SCENE_TEXELS`]), which it is charged with. Reads the header only. `what` names the image in errors.
pub fn check(bytes: &[u8], what: &str, texels_left: &mut u64) -> Result<(), String> {
    let (width, height) = reader(bytes, what)?.into_dimensions().map_err(|e| format!("{what}: {e}"))?;
    if width == 0 || height == 0 {
        return Err(format!("{what}: the image is empty ({width}x{height})"));
    }
    let chain = (width as u64 * height as u64).div_ceil(3) * 4;
    if chain > *texels_left {
        return Err(format!(
            "{what}: a {width}x{height} image (with its mip levels, {chain} texels) exceeds the {} texels left of the \
             scene's budget of {MAX_SCENE_TEXELS}",
            *texels_left
        ));
    }
    *texels_left -= chain;
    Ok(())
}

/// A reader of a PNG or JPEG image, bounded to [`MAX_TEXTURE_SIDE`] a side and 2 GiB of decoding memory.
fn reader<'a>(bytes: &'a [u8], what: &str) -> Result<image::ImageReader<std::io::Cursor<&'a [u8]>>, String> {
    let format = image::guess_format(bytes).map_err(|_| format!("{what}: not a PNG or JPEG image"))?;
    if !matches!(format, image::ImageFormat::Png | image::ImageFormat::Jpeg) {
        return Err(format!("{what}: {format:?} images are not read (PNG and JPEG are)"));
    }
    let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    limits.max_alloc = Some(2 << 30);
    reader.limits(limits);
    Ok(reader)
}

/// Decodes PNG (8 or 16 bits, any channel count) or JPEG that [`check`] passed to RGBA (missing channels: grey
/// to RGB, alpha 1): 8-bit images as their codes in `space` ([`Texels::Codes`]), 16-bit ones to linear f32.
pub fn decode(bytes: &[u8], space: ColorSpace, what: &str) -> Result<Level, String> {
    use image::ImageDecoder;
    let decoder = reader(bytes, what)?.into_decoder().map_err(|e| format!("{what}: {e}"))?;
    let (width, height) = decoder.dimensions();
    if width == 0 || height == 0 {
        return Err(format!("{what}: the image is empty ({width}x{height})"));
    }
    let decoded = image::DynamicImage::from_decoder(decoder).map_err(|e| format!("{what}: {e}"))?;
    let sixteen = matches!(
        decoded.color(),
        image::ColorType::L16 | image::ColorType::La16 | image::ColorType::Rgb16 | image::ColorType::Rgba16
    );
    let texels = if sixteen {
        let rgba = decoded.into_rgba16();
        Texels::Linear(
            rgba.pixels()
                .map(|p| {
                    let c = |v: u16| {
                        let x = v as f64 / 65535.0;
                        match space {
                            ColorSpace::Linear => x as f32,
                            ColorSpace::Srgb => srgb_decode(x) as f32,
                        }
                    };
                    [c(p[0]), c(p[1]), c(p[2]), (p[3] as f64 / 65535.0) as f32]
                })
                .collect(),
        )
    } else {
        // The decoder's RGBA bytes become the texels without a copy where the allocation allows it.
        let bytes = decoded.into_rgba8().into_raw();
        let codes = bytemuck::allocation::try_cast_vec(bytes)
            .unwrap_or_else(|(_, bytes)| bytes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect());
        Texels::Codes { codes, space }
    };
    Ok(Level { width, height, texels })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::texture::srgb_to_linear;

    fn png(width: u32, height: u32, rgba: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.write_header().unwrap().write_image_data(rgba).unwrap();
        out
    }

    #[test]
    fn decodes_png_in_both_colour_spaces() {
        let bytes = png(2, 1, &[255, 128, 0, 255, 10, 20, 30, 128]);
        let budget = &mut MAX_SCENE_TEXELS.clone();
        check(&bytes, "t", budget).unwrap();
        let lin = decode(&bytes, ColorSpace::Linear, "t").unwrap();
        assert_eq!((lin.width, lin.height), (2, 1));
        assert_eq!(lin.texel(0), [1.0, (128.0f64 / 255.0) as f32, 0.0, 1.0]);
        assert!(matches!(lin.texels, Texels::Codes { space: ColorSpace::Linear, .. }));
        let srgb = decode(&bytes, ColorSpace::Srgb, "t").unwrap();
        assert_eq!(*budget, MAX_SCENE_TEXELS - 4);
        let mut small = 3;
        assert!(check(&bytes, "image 7", &mut small).unwrap_err().contains("budget"));
        assert_eq!(small, 3);
        assert_eq!(
            srgb.texel(1),
            [srgb_to_linear(10), srgb_to_linear(20), srgb_to_linear(30), (128.0f64 / 255.0) as f32]
        );
    }

    #[test]
    fn refuses_what_it_cannot_decode() {
        let budget = &mut MAX_SCENE_TEXELS.clone();
        assert!(check(b"not an image", "image 3", budget).unwrap_err().starts_with("image 3"));
        assert!(decode(b"not an image", ColorSpace::Linear, "image 3").unwrap_err().starts_with("image 3"));
        let mut bytes = png(4, 4, &[0; 64]);
        bytes.truncate(bytes.len() - 20);
        assert!(decode(&bytes, ColorSpace::Linear, "image 3").is_err());
    }
}

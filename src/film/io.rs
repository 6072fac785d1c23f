//! Reading and writing images: the format follows the file extension.
//!
//! - `.exr`: OpenEXR, float32 RGBA, linear radiance, unscaled. Read back bit for bit.
//! - `.pfm`: Portable Float Map, float32 RGB (no alpha: read back with alpha 1), little-endian, bottom row first as
//!   the format requires.
//! - `.png`: 8-bit sRGB of `radiance × 2^EV` (see [`super::Exposure`]), alpha = coverage. Read back as code values
//!   `c/255` (not linearised), which is what an 8-bit comparison measures.
//!
//! Every write is atomic (see [`super::write_atomically`]).

use std::io::{self, BufRead, Write};
use std::path::{Path, PathBuf};

use super::{srgb_code, write_atomically, Exposure, Image};

/// The file formats sunshade reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Exr,
    Pfm,
    Png,
}

impl ImageFormat {
    /// The format named by the path's extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "exr" => Some(Self::Exr),
            "pfm" => Some(Self::Pfm),
            "png" => Some(Self::Png),
            _ => None,
        }
    }
}

/// An image file that could not be read or written; the message names the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageIoError {
    #[error("{path}: unsupported image extension (use .exr, .pfm or .png)")]
    UnsupportedExtension { path: PathBuf },
    /// The OS error is part of the message and deliberately not a `source`: a chain printer (anyhow's `{:#}`)
    /// would print it twice.
    #[error("{path}: {error}")]
    Io { path: PathBuf, error: io::Error },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
}

impl ImageIoError {
    fn invalid(path: &Path, message: impl Into<String>) -> Self {
        Self::Invalid { path: path.to_path_buf(), message: message.into() }
    }
}

/// What an image file says about itself, beside its pixels: text attributes (EXR string attributes, PNG tEXt
/// chunks; ASCII) and 4×4 matrices (EXR `m44f` attributes, Imath's layout: row vectors, `p' = p M`, which is
/// glam's column-major array read row by row). PFM has no place for either.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metadata {
    pub text: Vec<(String, String)>,
    pub matrices: Vec<(String, [f32; 16])>,
}

/// Writes `image` to `path` in the format its extension names. `exposure` applies to PNG only; for a PNG the EV
/// applied is returned (and recorded in the file's `sunshade exposure EV` tEXt chunk).
pub fn write_image(image: &Image, path: &Path, exposure: Exposure) -> Result<Option<f64>, ImageIoError> {
    write_image_with(image, path, exposure, &Metadata::default())
}

/// [`write_image`] with metadata in the file.
pub fn write_image_with(
    image: &Image,
    path: &Path,
    exposure: Exposure,
    metadata: &Metadata,
) -> Result<Option<f64>, ImageIoError> {
    let format =
        ImageFormat::from_path(path).ok_or_else(|| ImageIoError::UnsupportedExtension { path: path.to_path_buf() })?;
    let io_err = |error| ImageIoError::Io { path: path.to_path_buf(), error };
    match format {
        ImageFormat::Exr => {
            write_atomically(path, |w| write_exr(image, w, metadata)).map_err(io_err)?;
            Ok(None)
        }
        ImageFormat::Pfm => {
            write_atomically(path, |w| write_pfm(image, w)).map_err(io_err)?;
            Ok(None)
        }
        ImageFormat::Png => {
            let ev = exposure.ev_for(image);
            let scale = ev.exp2();
            let mut data = Vec::with_capacity(image.pixels().len() * 4);
            for p in image.pixels() {
                for c in &p[..3] {
                    data.push(srgb_code(*c as f64 * scale));
                }
                data.push((p[3].clamp(0.0, 1.0) * 255.0).round() as u8);
            }
            write_atomically(path, |w| write_png(w, image.width(), image.height(), &data, ev, metadata))
                .map_err(io_err)?;
            Ok(Some(ev))
        }
    }
}

/// OpenEXR through the `exr` crate: one RGBA f32 layer, ZIP compression over 16-scan-line blocks (lossless, the
/// blocks compressed in parallel), the software's name, the standard camera matrices, and one JSON attribute
/// `sunshade` holding the quantity's unit and the metadata texts.
fn write_exr<W: Write + io::Seek>(image: &Image, w: &mut W, metadata: &Metadata) -> io::Result<()> {
    use exr::meta::attribute::AttributeValue;
    use exr::prelude::{Encoding, Layer, LayerAttributes, SpecificChannels, Text, Vec2, WritableImage};
    let (width, height) = (image.width() as usize, image.height() as usize);
    let pixels = image.pixels();
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let p = pixels[y * width + x];
        (p[0], p[1], p[2], p[3])
    });
    // The layer is named after the quantity the metadata gives (`quantity`: "irradiance W/m2 ..."), radiance by
    // default.
    let quantity = metadata.text.iter().find(|(k, _)| k == "quantity").map(|(_, v)| v.as_str());
    let name = quantity.and_then(|q| q.split(' ').next()).unwrap_or("radiance");
    let mut attributes = LayerAttributes::named(name);
    attributes.software_name = Some(Text::from(format!("sunshade {}", env!("CARGO_PKG_VERSION")).as_str()));
    // One custom attribute, `sunshade`: a JSON object of the quantity and every metadata text (JSON texts nested
    // as JSON). The exr crate keeps custom attributes in a HashMap, whose order changes from process to process;
    // with one, the same image always gives the same bytes.
    let mut all = serde_json::Map::new();
    all.insert("quantity".into(), serde_json::json!("radiance W/(m2 sr) per linear RGB channel; A = coverage"));
    for (key, value) in &metadata.text {
        let v = serde_json::from_str(value).unwrap_or_else(|_| serde_json::Value::String(value.clone()));
        all.insert(key.clone(), v);
    }
    let text = ascii_json(&serde_json::Value::Object(all).to_string());
    attributes.other.insert(Text::from("sunshade"), AttributeValue::Text(Text::from(text.as_str())));
    for (key, m) in &metadata.matrices {
        // The two standard camera matrices have fields of their own in the exr crate; others have no place in
        // the file (a custom attribute would make the byte order of the header vary, see above).
        match key.as_str() {
            "worldToCamera" => attributes.world_to_camera = Some(*m),
            "worldToNDC" => attributes.world_to_normalized_device = Some(*m),
            _ => {}
        }
    }
    let layer = Layer::new((width, height), attributes, Encoding::SMALL_LOSSLESS, channels);
    exr::prelude::Image::from_layer(layer).write().to_buffered(w).map_err(io::Error::other)
}

/// JSON text with every character outside ASCII written as its `\uXXXX` escape (UTF-16 pairs above U+FFFF): the
/// same JSON value, in the bytes an EXR text attribute can hold (the exr crate refuses others, by a panic). Outside
/// strings JSON has only ASCII, so escaping is always valid there.
pub fn ascii_json(json: &str) -> String {
    let mut out = String::with_capacity(json.len());
    for c in json.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            let mut units = [0u16; 2];
            for u in c.encode_utf16(&mut units) {
                out += &format!("\\u{:04x}", u);
            }
        }
    }
    out
}

/// The tEXt keyword under which a PNG records its exposure.
pub const PNG_EXPOSURE_KEYWORD: &str = "sunshade exposure EV";

/// 8-bit RGBA with an sRGB chunk (the values are sRGB-encoded) and tEXt chunks naming the software and the EV.
fn write_png(w: &mut impl Write, width: u32, height: u32, rgba: &[u8], ev: f64, metadata: &Metadata) -> io::Result<()> {
    let mut encoder = png::Encoder::new(w, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    encoder.set_compression(png::Compression::Fast);
    let text =
        |e: &mut png::Encoder<_>, k: &str, v: String| e.add_text_chunk(k.to_string(), v).map_err(io::Error::other);
    text(&mut encoder, "Software", format!("sunshade {}", env!("CARGO_PKG_VERSION")))?;
    text(&mut encoder, PNG_EXPOSURE_KEYWORD, format!("{ev}"))?;
    for (key, value) in &metadata.text {
        // tEXt is Latin-1: the JSON texts go as ASCII.
        text(&mut encoder, key, ascii_json(value))?;
    }
    let mut writer = encoder.write_header().map_err(io::Error::other)?;
    writer.write_image_data(rgba).map_err(io::Error::other)?;
    writer.finish().map_err(io::Error::other)
}

/// Reads an image in the format its extension names.
pub fn read_image(path: &Path) -> Result<Image, ImageIoError> {
    let format =
        ImageFormat::from_path(path).ok_or_else(|| ImageIoError::UnsupportedExtension { path: path.to_path_buf() })?;
    let io_err = |error| ImageIoError::Io { path: path.to_path_buf(), error };
    match format {
        ImageFormat::Pfm => {
            let file = std::fs::File::open(path).map_err(io_err)?;
            read_pfm(&mut io::BufReader::new(file)).map_err(|e| match e.kind() {
                io::ErrorKind::InvalidData | io::ErrorKind::UnexpectedEof => ImageIoError::invalid(path, e.to_string()),
                _ => ImageIoError::Io { path: path.to_path_buf(), error: e },
            })
        }
        ImageFormat::Exr | ImageFormat::Png => {
            let decoded = ::image::ImageReader::open(path)
                .map_err(io_err)?
                .with_guessed_format()
                .map_err(io_err)?
                .decode()
                .map_err(|e| ImageIoError::invalid(path, e.to_string()))?;
            let (w, h) = (decoded.width(), decoded.height());
            let pixels: Vec<[f32; 4]> = if format == ImageFormat::Png {
                decoded.into_rgba8().pixels().map(|p| p.0.map(|c| c as f32 / 255.0)).collect()
            } else {
                decoded.into_rgba32f().pixels().map(|p| p.0).collect()
            };
            Image::from_pixels(w, h, pixels).ok_or_else(|| ImageIoError::invalid(path, "decoded size mismatch"))
        }
    }
}

/// PFM: header `PF\n<w> <h>\n-1.0\n` (negative scale = little-endian), then RGB rows from the bottom up.
/// What a sunshade image holds, as its metadata records it: `(quantity, unit)` in ASCII, e.g.
/// `("irradiation", "Wh/m2")`, from the EXR's `sunshade` attribute or the PNG's `quantity` text; `None` for a PFM
/// (no metadata) or a file sunshade did not write. Reads only the header (EXR) or the text chunks (PNG).
pub fn read_quantity(path: &Path) -> Option<(String, String)> {
    let text = match ImageFormat::from_path(path)? {
        ImageFormat::Pfm => return None,
        ImageFormat::Exr => {
            let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
            let header = meta.headers.first()?;
            let value = header.own_attributes.other.get(&exr::prelude::Text::from("sunshade"))?;
            let exr::meta::attribute::AttributeValue::Text(t) = value else { return None };
            let all: serde_json::Value = serde_json::from_str(&t.to_string()).ok()?;
            all.get("quantity")?.as_str()?.to_string()
        }
        ImageFormat::Png => {
            let file = std::fs::File::open(path).ok()?;
            let reader = png::Decoder::new(io::BufReader::new(file)).read_info().ok()?;
            let chunk = reader.info().uncompressed_latin1_text.iter().find(|t| t.keyword == "quantity")?;
            chunk.text.clone()
        }
    };
    // "NAME UNIT per linear RGB channel; ..."; the unit may hold a space ("W/(m2 sr)"): up to " per ".
    let head = text.split(" per ").next()?;
    let (name, unit) = head.split_once(' ')?;
    Some((name.to_string(), unit.to_string()))
}

/// The metadata an EXR sunshade wrote records (its `sunshade` attribute: the quantity, `sunshadeLights`,
/// `sunshadeSettings`, ...) as a JSON object; `None` for another format or a file without it. Reads only the header.
pub fn read_recorded(path: &Path) -> Option<serde_json::Map<String, serde_json::Value>> {
    if ImageFormat::from_path(path)? != ImageFormat::Exr {
        return None;
    }
    let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
    let value = meta.headers.first()?.own_attributes.other.get(&exr::prelude::Text::from("sunshade"))?;
    let exr::meta::attribute::AttributeValue::Text(t) = value else { return None };
    match serde_json::from_str(&t.to_string()).ok()? {
        serde_json::Value::Object(all) => Some(all),
        _ => None,
    }
}

fn write_pfm(image: &Image, w: &mut impl Write) -> io::Result<()> {
    write!(w, "PF\n{} {}\n-1.0\n", image.width(), image.height())?;
    let width = image.width() as usize;
    let mut row = Vec::with_capacity(width * 12);
    for y in (0..image.height() as usize).rev() {
        row.clear();
        for p in &image.pixels()[y * width..(y + 1) * width] {
            for c in &p[..3] {
                row.extend_from_slice(&c.to_le_bytes());
            }
        }
        w.write_all(&row)?;
    }
    Ok(())
}

fn read_pfm(r: &mut impl BufRead) -> io::Result<Image> {
    let bad = |m: &str| io::Error::new(io::ErrorKind::InvalidData, m.to_string());
    let magic = read_token(r)?;
    let channels = match magic.as_str() {
        "PF" => 3,
        "Pf" => 1,
        _ => return Err(bad("not a PFM file (magic is not PF or Pf)")),
    };
    let width: u32 = read_token(r)?.parse().map_err(|_| bad("bad PFM width"))?;
    let height: u32 = read_token(r)?.parse().map_err(|_| bad("bad PFM height"))?;
    let scale: f64 = read_token(r)?.parse().map_err(|_| bad("bad PFM scale"))?;
    if width == 0 || height == 0 || scale == 0.0 || !scale.is_finite() {
        return Err(bad("PFM header has a zero size or scale"));
    }
    let little_endian = scale < 0.0;
    let count = (width as usize)
        .checked_mul(height as usize)
        .and_then(|n| n.checked_mul(channels * 4))
        .ok_or_else(|| bad("PFM size overflows"))?;
    let mut data = vec![0u8; count];
    r.read_exact(&mut data).map_err(|_| bad("PFM file is shorter than its header says"))?;
    let mut pixels = vec![[0.0f32; 4]; width as usize * height as usize];
    for (i, chunk) in data.chunks_exact(channels * 4).enumerate() {
        let mut px = [0.0f32, 0.0, 0.0, 1.0];
        for c in 0..channels {
            let b: [u8; 4] = chunk[c * 4..c * 4 + 4].try_into().expect("chunk of 4 bytes");
            px[c] = if little_endian { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) };
        }
        if channels == 1 {
            px[1] = px[0];
            px[2] = px[0];
        }
        let (x, y_from_bottom) = (i % width as usize, i / width as usize);
        pixels[(height as usize - 1 - y_from_bottom) * width as usize + x] = px;
    }
    Ok(Image::from_pixels(width, height, pixels).expect("size computed from the header"))
}

/// One whitespace-separated header token; the single whitespace byte after it is consumed too.
fn read_token(r: &mut impl BufRead) -> io::Result<String> {
    let mut token = Vec::new();
    let mut byte = [0u8; 1];
    loop {
        if r.read(&mut byte)? == 0 {
            return Err(io::Error::new(io::ErrorKind::UnexpectedEof, "PFM header ends early"));
        }
        if byte[0].is_ascii_whitespace() {
            if token.is_empty() {
                continue;
            }
            break;
        }
        token.push(byte[0]);
        if token.len() > 32 {
            return Err(io::Error::new(io::ErrorKind::InvalidData, "PFM header token too long"));
        }
    }
    String::from_utf8(token).map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "PFM header is not ASCII"))
}

#[cfg(test)]
mod tests {
    #[test]
    fn ascii_json_is_the_same_json_in_ascii() {
        let v = serde_json::json!({"term": "disk sun 8², Ward α=0.05", "emoji": "\u{1F600}"});
        let a = ascii_json(&v.to_string());
        assert!(a.is_ascii(), "{a}");
        assert_eq!(serde_json::from_str::<serde_json::Value>(&a).unwrap(), v);
    }

    use super::*;
    use crate::film::srgb_encode;

    fn sample() -> Image {
        let mut img = Image::new(3, 2);
        img.set(0, 0, [1.5, 2.25e6, -0.0, 1.0]);
        img.set(2, 1, [1e-30, 3.0, f32::MAX, 1.0]);
        img
    }

    fn tmp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("sunshade-io-{}-{name}", std::process::id()))
    }

    #[test]
    fn exr_round_trip_is_bitwise() {
        let path = tmp("a.exr");
        write_image(&sample(), &path, Exposure::Ev(0.0)).unwrap();
        let back = read_image(&path).unwrap();
        let bits = |i: &Image| i.pixels().iter().flatten().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&sample()));
        std::fs::remove_file(path).unwrap();
    }

    #[test]
    fn pfm_round_trip_keeps_rgb_and_orientation() {
        let path = tmp("a.pfm");
        write_image(&sample(), &path, Exposure::Ev(0.0)).unwrap();
        let back = read_image(&path).unwrap();
        assert_eq!(back.get(0, 0), [1.5, 2.25e6, -0.0, 1.0]);
        assert_eq!(back.get(2, 1), [1e-30, 3.0, f32::MAX, 1.0]);
        assert_eq!(back.get(1, 0), [0.0, 0.0, 0.0, 1.0]);
        std::fs::remove_file(path).unwrap();
    }

    #[test]
    fn png_applies_exposure_and_coverage() {
        let path = tmp("a.png");
        let mut img = Image::new(2, 1);
        img.set(0, 0, [0.5, 1.0, 4.0, 1.0]);
        write_image(&img, &path, Exposure::Ev(-2.0)).unwrap();
        let back = read_image(&path).unwrap();
        let code = |v: f64| srgb_encode(v) as f32 / 255.0;
        assert_eq!(back.get(0, 0), [code(0.125), code(0.25), 1.0, 1.0]);
        assert_eq!(back.get(1, 0), [0.0, 0.0, 0.0, 0.0]);
        std::fs::remove_file(path).unwrap();
    }

    #[test]
    fn png_records_its_exposure_and_srgb() {
        let path = tmp("ev.png");
        let mut img = Image::new(2, 2);
        img.pixels_mut().iter_mut().for_each(|p| *p = [40.0, 40.0, 40.0, 1.0]);
        let ev = write_image(&img, &path, Exposure::Auto).unwrap().expect("a PNG has an EV");
        assert!((ev - (0.8f64 / 40.0).log2()).abs() < 1e-12);
        let decoder = png::Decoder::new(io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let reader = decoder.read_info().unwrap();
        let info = reader.info();
        assert!(info.srgb.is_some(), "no sRGB chunk");
        let text = info.uncompressed_latin1_text.iter().find(|t| t.keyword == PNG_EXPOSURE_KEYWORD).expect("EV chunk");
        assert_eq!(text.text.parse::<f64>().unwrap(), ev);
        assert_eq!(write_image(&img, &tmp("ev.exr"), Exposure::Auto).unwrap(), None);
        std::fs::remove_file(path).unwrap();
        std::fs::remove_file(tmp("ev.exr")).unwrap();
    }

    #[test]
    fn truncated_pfm_is_an_error_naming_the_file() {
        let path = tmp("short.pfm");
        std::fs::write(&path, b"PF\n4 4\n-1.0\n\0\0\0\0").unwrap();
        let err = read_image(&path).unwrap_err().to_string();
        assert!(err.contains("short.pfm") && err.contains("shorter"), "{err}");
        std::fs::remove_file(path).unwrap();
    }

    #[test]
    fn unknown_extension_is_refused() {
        let err = write_image(&sample(), Path::new("x.tiff"), Exposure::Auto).unwrap_err().to_string();
        assert!(err.contains("x.tiff"), "{err}");
    }
}

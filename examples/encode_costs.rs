//! What encoding an image costs, per format and compression (the figures in docs/platform.md, "Encoding"):
//!
//!     cargo run --release --example encode_costs
//!
//! Renders the teapot at 1024² with the CPU reference, then encodes it in memory 5 times per setting (OpenEXR
//! through the exr crate: uncompressed, RLE, ZIP16, ZIP1, PIZ; PNG through the png crate: Balanced, Fast) and
//! prints the median time and the size; last, the cost of writing 16 MiB to the temp folder and of its fsync.

use std::time::{Duration, Instant};

use exr::prelude::*;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn main() {
    let scene = sunshade::scene::load(std::path::Path::new("models/teapot.glb")).expect("models/teapot.glb");
    let settings = sunshade::settings::resolve(&scene, 1024, 1024, &Default::default(), &Default::default()).unwrap();
    let image = sunshade::cpu::render(&scene, &settings, &Default::default());
    let (w, h) = (image.width() as usize, image.height() as usize);
    let px = image.pixels();
    let line = |c: Compression, blocks: Blocks| Encoding { compression: c, blocks, line_order: LineOrder::Increasing };
    for (name, encoding) in [
        ("EXR uncompressed", line(Compression::Uncompressed, Blocks::ScanLines)),
        ("EXR RLE 64² tiles", Encoding::FAST_LOSSLESS),
        ("EXR ZIP16", Encoding::SMALL_LOSSLESS),
        ("EXR ZIP1", line(Compression::ZIP1, Blocks::ScanLines)),
        ("EXR PIZ", line(Compression::PIZ, Blocks::ScanLines)),
    ] {
        let mut size = 0;
        let times = (0..5)
            .map(|_| {
                let t = Instant::now();
                let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
                    let p = px[y * w + x];
                    (p[0], p[1], p[2], p[3])
                });
                let layer = Layer::new((w, h), LayerAttributes::named("radiance"), encoding, channels);
                let mut buf = std::io::Cursor::new(Vec::new());
                exr::prelude::Image::from_layer(layer).write().to_buffered(&mut buf).unwrap();
                size = buf.get_ref().len();
                t.elapsed()
            })
            .collect();
        println!("{name:>18}: median {:7.1} ms, {size:>9} bytes", median(times).as_secs_f64() * 1e3);
    }
    let rgba: Vec<u8> = px
        .iter()
        .flat_map(|p| {
            let c = |v: f32| sunshade::film::srgb_encode(v as f64 / 100.0);
            [c(p[0]), c(p[1]), c(p[2]), (p[3] * 255.0) as u8]
        })
        .collect();
    for (name, compression) in [("PNG Balanced", png::Compression::Balanced), ("PNG Fast", png::Compression::Fast)] {
        let mut size = 0;
        let times = (0..5)
            .map(|_| {
                let t = Instant::now();
                let mut out = Vec::new();
                let mut e = png::Encoder::new(&mut out, w as u32, h as u32);
                e.set_color(png::ColorType::Rgba);
                e.set_depth(png::BitDepth::Eight);
                e.set_compression(compression);
                e.write_header().unwrap().write_image_data(&rgba).unwrap();
                size = out.len();
                t.elapsed()
            })
            .collect();
        println!("{name:>18}: median {:7.1} ms, {size:>9} bytes", median(times).as_secs_f64() * 1e3);
    }
    let data = vec![1u8; 16 << 20];
    let path = std::env::temp_dir().join(format!("sunshade-encode-costs-{}", std::process::id()));
    let t = Instant::now();
    std::fs::write(&path, &data).unwrap();
    let written = t.elapsed();
    std::fs::File::open(&path).unwrap().sync_all().unwrap();
    println!(
        "write 16 MiB {:.1} ms, fsync {:.1} ms",
        written.as_secs_f64() * 1e3,
        (t.elapsed() - written).as_secs_f64() * 1e3
    );
    let _ = std::fs::remove_file(path);
}

//! FLIP against NVIDIA's reference implementation: synthetic images made here, bit for bit the ones the recorded
//! values were computed from, and the means and pixels its Python package (`flip-evaluator` 1.7, the C++ code
//! through pybind11; `flip_evaluator.evaluate(reference, test, "LDR" | "HDR")` with default parameters) gave for
//! them. `SUNSHADE_FLIP_DUMP=DIR cargo test --test flip` writes the images (PFM, linear floats; LDR ones as
//! sRGB-encoded values in [0, 1]) to compute the values again.

use sunshade::compare::flip::{flip, FlipInput, FlipMap, DEFAULT_PPD};
use sunshade::film::Image;

/// A deterministic generator (64-bit LCG, Knuth's constants): the same bits on every machine.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

const W: u32 = 96;
const H: u32 = 64;

/// A scene of smooth gradients, a sharp-edged box, a one-pixel line, a disc and some noise; `variant` 1 moves
/// the box by a pixel, tints the disc, thickens the line and adds other noise, as a renderer's change might.
/// Values in [0, 1] (`scale` multiplies them; `bright` adds a small patch of that radiance).
fn scene(variant: u32, scale: f32, bright: f32) -> Image {
    let mut rng = Lcg(0x5eed + variant as u64);
    let mut pixels = Vec::with_capacity((W * H) as usize);
    for y in 0..H {
        for x in 0..W {
            let (u, v) = (x as f32 / W as f32, y as f32 / H as f32);
            let mut c = [0.15 + 0.6 * u, 0.2 + 0.5 * v, 0.35 + 0.3 * u * v];
            let shift = variant;
            if (20 + shift..44 + shift).contains(&x) && (12..36).contains(&y) {
                c = [0.8, 0.75, 0.2];
            }
            let line = if variant == 1 { 50..52 } else { 50..51 };
            if line.contains(&x) {
                c = [0.05, 0.05, 0.05];
            }
            let (dx, dy) = (x as f32 - 72.0, y as f32 - 40.0);
            if dx * dx + dy * dy < 100.0 {
                c = if variant == 1 { [0.3, 0.55, 0.9] } else { [0.25, 0.5, 0.9] };
            }
            let noise = 0.04 * (rng.next() - 0.5);
            let mut p = [0.0f32; 4];
            for k in 0..3 {
                p[k] = ((c[k] + noise).clamp(0.0, 1.0)) * scale;
            }
            if bright > 0.0 && (4..8).contains(&x) && (50..54).contains(&y) {
                p[0] = bright;
                p[1] = bright * 0.9;
                p[2] = bright * 0.7;
            }
            p[3] = 1.0;
            pixels.push(p);
        }
    }
    Image::from_pixels(W, H, pixels).unwrap()
}

/// Writes an image as a PFM (RGB floats), for the reference implementation.
fn dump(name: &str, image: &Image) {
    let Some(dir) = std::env::var_os("SUNSHADE_FLIP_DUMP") else { return };
    let path = std::path::Path::new(&dir).join(format!("{name}.pfm"));
    sunshade::film::write_image(image, &path, sunshade::film::Exposure::Ev(0.0)).unwrap();
}

/// The map of `test` against `reference`, after dumping both.
fn map(name: &str, reference: &Image, test: &Image, input: FlipInput) -> FlipMap {
    dump(&format!("{name}_reference"), reference);
    dump(&format!("{name}_test"), test);
    let m = flip(reference, test, input, DEFAULT_PPD).unwrap();
    let grey = m.values.iter().map(|&v| [v, v, v, 1.0]).collect();
    dump(&format!("{name}_map"), &Image::from_pixels(m.width, m.height, grey).unwrap());
    m
}

/// sRGB codes in [0, 1], as a PNG read by sunshade holds them.
fn encoded(image: &Image) -> Image {
    let mut out = image.clone();
    for p in out.pixels_mut() {
        for c in &mut p[..3] {
            *c = (*c * 255.0).round() / 255.0;
        }
    }
    out
}

fn assert_close(what: &str, got: f64, expected: f64, tolerance: f64) {
    assert!((got - expected).abs() <= tolerance, "{what}: {got} against the reference implementation's {expected}");
}

/// The map's mean and maximum, and its values at ten pixels `(x, y, value)`, against the reference
/// implementation's (printed to six decimals). Measured: the whole maps differ by at most 6.4e-6 (LDR) and
/// 1.5e-5 (HDR) a pixel, the means by 2e-8 (f32 sums and `exp` in another order).
fn assert_matches(m: &FlipMap, mean: f64, max: f64, pixels: &[(u32, u32, f64)]) {
    let s = m.stats();
    assert_close("mean", s.mean, mean, 1e-6);
    assert_close("max", s.max, max, 2e-5);
    for &(x, y, v) in pixels {
        assert_close(&format!("pixel ({x}, {y})"), m.values[(y * W + x) as usize] as f64, v, 2e-5);
    }
}

#[test]
fn ldr_flip_matches_the_reference_implementation() {
    let m = map("ldr", &encoded(&scene(0, 1.0, 0.0)), &encoded(&scene(1, 1.0, 0.0)), FlipInput::Ldr);
    assert_eq!(m.exposures, None);
    assert_matches(
        &m,
        0.091210,
        0.618416,
        &[
            (3, 2, 0.020813),
            (20, 12, 0.465055),
            (21, 20, 0.434934),
            (43, 30, 0.405496),
            (44, 30, 0.450533),
            (50, 33, 0.365624),
            (51, 5, 0.364841),
            (63, 40, 0.216658),
            (72, 31, 0.232652),
            (88, 59, 0.058725),
        ],
    );
}

#[test]
fn hdr_flip_matches_the_reference_implementation() {
    // Radiance up to 40 with a patch of 3000: the reference chose exposures −10.326338 to −3.149171 in 8 steps.
    let m = map("hdr", &scene(0, 40.0, 3000.0), &scene(1, 40.0, 3000.0), FlipInput::Hdr);
    let (start, stop, count) = m.exposures.unwrap();
    assert_close("start exposure", start as f64, -10.326338, 1e-5);
    assert_close("stop exposure", stop as f64, -3.149171, 1e-5);
    assert_eq!(count, 8);
    assert_matches(
        &m,
        0.076724,
        0.643433,
        &[
            (3, 2, 0.02635),
            (20, 12, 0.338907),
            (21, 20, 0.331701),
            (43, 30, 0.301104),
            (44, 30, 0.367017),
            (50, 33, 0.449634),
            (51, 5, 0.556229),
            (63, 40, 0.166345),
            (72, 31, 0.164586),
            (88, 59, 0.031306),
        ],
    );
}

#[test]
fn identical_images_have_flip_zero_and_hdr_flip_ignores_a_common_scale() {
    let a = scene(0, 40.0, 3000.0);
    assert!(map("same", &a, &a, FlipInput::Hdr).values.iter().all(|&v| v == 0.0));
    // HDR-FLIP chooses its exposures from the reference: scaling both images by 2^k changes nothing but the
    // exposures (by −k stops).
    let (b, c) = (scene(1, 40.0, 3000.0), scene(1, 160.0, 12000.0));
    let (m1, m4) = (map("x1", &a, &b, FlipInput::Hdr), map("x4", &scene(0, 160.0, 12000.0), &c, FlipInput::Hdr));
    assert_close("scaled mean", m4.stats().mean, m1.stats().mean, 1e-6);
    assert_close("exposure shift", (m1.exposures.unwrap().0 - m4.exposures.unwrap().0) as f64, 2.0, 1e-5);
}

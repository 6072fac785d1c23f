//! Textures, vertex colours, alpha masks, normal maps, emission, morph targets and skins: the GPU (lavapipe,
//! validation on) and the CPU reference each against values computed here from the glTF and the formulas of
//! docs/textures.md (not through sunshade's own lookup code), and deformed meshes against pre-posed twins.
//!
//! The scenes are a unit-facing square seen orthographically so that pixel (x, y) of an N × N image sees
//! `uv = ((x + ½)/N, (y + ½)/N)`, lit by a delta sun straight on: `L = base/π · E⊥` (materials read as
//! Lambertian, `--brdf lambert`; glTF's own BRDF is tests/gltf_brdf.rs's).

mod common;

use common::{rel, CheckedRenderer, TempDir};
use glam::{DVec3, Vec3};
use serde_json::json;
use std::f64::consts::PI;
use sunshade::authoring::{png_rgba8, GltfBuilder, Indices, Node, Primitive, Transform};
use sunshade::cpu;
use sunshade::scene::texture::srgb_to_linear;
use sunshade::scene::{Camera, Lights, Projection, Scene, Sun};
use sunshade::settings::RenderSettings;
use sunshade::shading::{Shadows, SunModel};
use sunshade::Image;

const E_PERP: f32 = 1000.0;

/// Loads a scene with its glTF materials read as Lambertian (`--brdf lambert`: the base colour, its texture and
/// vertex colours as the albedo), the BRDF the formulas here assume.
fn load(path: &std::path::Path) -> Scene {
    let mut scene = common::load(path);
    scene.map_brdfs(sunshade::scene::BrdfKind::Lambert);
    scene
}

/// The square (−1, −1)..(1, 1) in z = `z`, facing +z, UV (0, 0) at its top-left corner.
fn square(z: f32, material: usize, colors: Option<Vec<[f32; 4]>>) -> Primitive {
    Primitive {
        positions: vec![[-1.0, -1.0, z], [1.0, -1.0, z], [1.0, 1.0, z], [-1.0, 1.0, z]],
        normals: Some(vec![[0.0, 0.0, 1.0]; 4]),
        tex_coords: Some(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]),
        colors,
        indices: Some(Indices::U8(vec![0, 1, 2, 0, 2, 3])),
        material: Some(material),
        mode: None,
    }
}

fn one_mesh(mut b: GltfBuilder, primitives: &[Primitive]) -> GltfBuilder {
    let m = b.add_mesh("square", primitives);
    let n = b.add_node(Node { mesh: Some(m), ..Default::default() });
    b.add_scene(&[n], None);
    b
}

/// Seen straight on, orthographically, exactly covering the square; a delta sun along `sun` (default +z).
fn settings(n: u32, sun: DVec3) -> RenderSettings {
    let camera = Camera::looking(
        DVec3::new(0.0, 0.0, 5.0),
        -DVec3::Z,
        DVec3::Y,
        Projection::Orthographic { ymag: 1.0, znear: 1.0, zfar: 10.0 },
    )
    .unwrap();
    let lights = Lights {
        sun: Some(Sun { direction: sun.normalize().as_vec3(), irradiance: [E_PERP; 3], angular_diameter: 0.0 }),
        ..Default::default()
    };
    let mut s = RenderSettings::new(n, n, camera, lights);
    s.shading.sun = SunModel::Delta;
    // The expectations are unshadowed (on a device with ray queries, auto would let the front squares shadow the
    // ones behind; tests/shadows.rs tests masked shadows).
    s.shading.shadows = Shadows::None;
    s
}

/// GPU and reference images of a scene.
fn both(scene: &Scene, s: &RenderSettings) -> [Image; 2] {
    let mut gpu = CheckedRenderer::new();
    let g = gpu.render(scene, s);
    let c = cpu::render(scene, s, &gpu.reference_options());
    [g, c]
}

/// Asserts every pixel of both images against `want(x, y)` (RGB radiance) within `tol` relative.
fn assert_matches(images: &[Image; 2], tol: f64, want: impl Fn(u32, u32) -> [f64; 3]) {
    for (image, who) in images.iter().zip(["GPU", "reference"]) {
        let mut worst = 0.0f64;
        for y in 0..image.height() {
            for x in 0..image.width() {
                let got = image.get(x, y);
                let w = want(x, y);
                for c in 0..3 {
                    let e = if w[c] == 0.0 { (got[c] as f64).abs() } else { rel(got[c] as f64, w[c]) };
                    worst = worst.max(e);
                    assert!(e <= tol, "{who} pixel ({x}, {y}) channel {c}: {} against {} (rel {e:e})", got[c], w[c]);
                }
            }
        }
        eprintln!("{who}: worst relative error {worst:e}");
    }
}

/// A texture of `w × h` texels with distinct values (8-bit codes).
fn ramp(w: u32, h: u32) -> Vec<[u8; 4]> {
    (0..w * h).map(|k| [(k * 37 % 251) as u8 + 4, (k * 91 % 239) as u8 + 8, (255 - k * 13 % 200) as u8, 255]).collect()
}

/// Linear value of texel (i, j), channel c, of an sRGB base-colour texture.
fn texel(t: &[[u8; 4]], w: u32, i: i64, j: i64, c: usize) -> f64 {
    srgb_to_linear(t[(j as u32 * w + i as u32) as usize][c]) as f64
}

fn textured_square(texels: &[[u8; 4]], w: u32, h: u32, mag: u32, wrap: u32, extra: serde_json::Value) -> Scene {
    let dir = TempDir::new("textured");
    let mut b = GltfBuilder::new();
    let image = b.add_png_image(&png_rgba8(w, h, texels));
    let t = b.add_texture(image, Some(mag), Some(9729), [wrap, wrap]);
    let mut info = json!({ "index": t });
    if let Some(e) = extra.get("transform") {
        info["extensions"] = json!({ "KHR_texture_transform": e });
    }
    let mat = b.add_material_json(json!({
        "pbrMetallicRoughness": { "baseColorTexture": info, "baseColorFactor": [1.0, 0.5, 0.25, 1.0], "metallicFactor": 0.0 }
    }));
    load(&dir.write("t.glb", &one_mesh(b, &[square(0.0, mat, None)])))
}

const FACTOR: [f64; 3] = [1.0, 0.5, 0.25];

#[test]
fn nearest_and_linear_magnification_follow_the_texel_centres() {
    let (w, h, n) = (4u32, 3u32, 24u32); // 6 and 8 pixels a texel: magnification
    let t = ramp(w, h);
    // NEAREST: the texel containing uv.
    let scene = textured_square(&t, w, h, 9728, 33071, json!({}));
    let s = settings(n, DVec3::Z);
    assert_matches(&both(&scene, &s), 1e-5, |x, y| {
        let (u, v) = ((x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64);
        let (i, j) = ((u * w as f64).floor() as i64, (v * h as f64).floor() as i64);
        [0, 1, 2].map(|c| FACTOR[c] * texel(&t, w, i, j, c) / PI * E_PERP as f64)
    });
    // LINEAR, clamped: bilinear between the centres (i + ½)/w around uv.
    let scene = textured_square(&t, w, h, 9729, 33071, json!({}));
    assert_matches(&both(&scene, &s), 1e-5, |x, y| {
        let (u, v) = ((x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64);
        let (fx, fy) = (u * w as f64 - 0.5, v * h as f64 - 0.5);
        let (i0, j0) = (fx.floor(), fy.floor());
        let (a, bb) = (fx - i0, fy - j0);
        let cl = |i: f64, n: u32| (i.max(0.0) as i64).min(n as i64 - 1);
        [0, 1, 2].map(|c| {
            let at = |di: f64, dj: f64| texel(&t, w, cl(i0 + di, w), cl(j0 + dj, h), c);
            let value = (at(0.0, 0.0) * (1.0 - a) + at(1.0, 0.0) * a) * (1.0 - bb)
                + (at(0.0, 1.0) * (1.0 - a) + at(1.0, 1.0) * a) * bb;
            FACTOR[c] * value / PI * E_PERP as f64
        })
    });
}

/// A 16-bit RGBA PNG (big-endian samples, as PNG stores them).
fn png_rgba16(width: u32, height: u32, rgba: &[[u16; 4]]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Sixteen);
    let data: Vec<u8> = rgba.iter().flatten().flat_map(|v| v.to_be_bytes()).collect();
    enc.write_header().and_then(|mut w| w.write_image_data(&data)).expect("PNG in memory");
    out
}

#[test]
fn eight_and_sixteen_bit_textures_in_one_frame() {
    // Two squares side by side, the left one's base colour an 8-bit sRGB image (kept as codes), the right one's a
    // 16-bit one (decoded to f32): NEAREST, so each pixel is one texel's value by the sRGB curve computed here.
    let (w, h, n) = (4u32, 4u32, 16u32);
    let t8 = ramp(w, h);
    let t16: Vec<[u16; 4]> =
        t8.iter().map(|c| [c[0] as u16 * 257 + 100, c[1] as u16 * 251, c[2] as u16 * 3, 65535]).collect();
    let dir = TempDir::new("bit-depths");
    let mut b = GltfBuilder::new();
    let mut material = |png: Vec<u8>| {
        let image = b.add_png_image(&png);
        let t = b.add_texture(image, Some(9728), Some(9728), [33071, 33071]);
        b.add_material_json(json!({
            "pbrMetallicRoughness": { "baseColorTexture": { "index": t }, "metallicFactor": 0.0 }
        }))
    };
    let (m8, m16) = (material(png_rgba8(w, h, &t8)), material(png_rgba16(w, h, &t16)));
    // Each square squeezed into one half of the view: x in (−1, 0) and (0, 1).
    let half = |material: usize, x0: f32| {
        let mut p = square(0.0, material, None);
        for v in p.positions.iter_mut() {
            v[0] = x0 + (v[0] + 1.0) / 2.0;
        }
        p
    };
    let scene = load(&dir.write("t.glb", &one_mesh(b, &[half(m8, -1.0), half(m16, 0.0)])));
    let srgb = |c: f64| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
    assert_matches(&both(&scene, &settings(2 * n, DVec3::Z)), 1e-5, |x, y| {
        let (half_x, u) = (x / n, ((x % n) as f64 + 0.5) / n as f64);
        let v = (y as f64 + 0.5) / (2 * n) as f64;
        let (i, j) = ((u * w as f64) as usize, (v * h as f64) as usize);
        let k = j * w as usize + i;
        [0, 1, 2].map(|c| {
            let linear = if half_x == 0 { srgb(t8[k][c] as f64 / 255.0) } else { srgb(t16[k][c] as f64 / 65535.0) };
            linear / PI * E_PERP as f64
        })
    });
}

#[test]
fn texture_transform_and_wrap_modes() {
    // KHR_texture_transform (offset, rotation, scale) with REPEAT and MIRRORED_REPEAT, NEAREST: the texel at
    // the transformed coordinate, wrapped.
    let (w, h, n) = (4u32, 4u32, 32u32);
    let t = ramp(w, h);
    let (offset, rotation, scale) = ([0.3, -0.2], 0.4f64, [1.5, 0.75]);
    for (wrap, code) in [("repeat", 10497), ("mirrored", 33648)] {
        let transform = json!({ "offset": offset, "rotation": rotation, "scale": scale });
        let scene = textured_square(&t, w, h, 9728, code, json!({ "transform": transform }));
        let s = settings(n, DVec3::Z);
        let wrap_index = |i: i64, n: i64| -> i64 {
            if wrap == "repeat" {
                i.rem_euclid(n)
            } else {
                let p = i.rem_euclid(2 * n);
                if p >= n {
                    2 * n - 1 - p
                } else {
                    p
                }
            }
        };
        assert_matches(&both(&scene, &s), 1e-5, |x, y| {
            let (u, v) = ((x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64);
            // The extension's matrix T R S, each factor rounded to f32 as glTF stores it.
            let (sn, cs) = (rotation as f32 as f64).sin_cos();
            let (su, sv) = (scale[0] as f32 as f64 * u, scale[1] as f32 as f64 * v);
            let tu = cs * su + sn * sv + offset[0] as f32 as f64;
            let tv = -sn * su + cs * sv + offset[1] as f32 as f64;
            let (i, j) = (
                wrap_index((tu * w as f64).floor() as i64, w as i64),
                wrap_index((tv * h as f64).floor() as i64, h as i64),
            );
            [0, 1, 2].map(|c| FACTOR[c] * texel(&t, w, i, j, c) / PI * E_PERP as f64)
        });
    }
}

#[test]
fn minification_averages_the_texels_under_the_pixel() {
    // A 64 × 64 checker seen at 8 × 8 pixels: 8 texels a pixel, level 3 of the chain, whose texels are each the
    // mean of an 8 × 8 block of the checker: half black, half white, in linear units.
    let w = 64u32;
    let t: Vec<[u8; 4]> = (0..w * w)
        .map(|k| if (k % w + k / w).is_multiple_of(2) { [255, 255, 255, 255] } else { [0, 0, 0, 255] })
        .collect();
    let dir = TempDir::new("minify");
    let mut b = GltfBuilder::new();
    let image = b.add_png_image(&png_rgba8(w, w, &t));
    let tex = b.add_texture(image, Some(9729), Some(9987), [10497, 10497]);
    let mat = b.add_material_json(
        json!({ "pbrMetallicRoughness": { "baseColorTexture": { "index": tex }, "metallicFactor": 0.0 } }),
    );
    let scene = load(&dir.write("m.glb", &one_mesh(b, &[square(0.0, mat, None)])));
    assert_matches(&both(&scene, &settings(8, DVec3::Z)), 1e-5, |_, _| [0.5 / PI * E_PERP as f64; 3]);
}

#[test]
fn vertex_colours_multiply_the_base_colour() {
    // COLOR_0 linear in x and y over the whole square, so that both triangles interpolate it exactly:
    // colour(u, v) = (u, v, 1 − u/2).
    let n = 16u32;
    let colors = vec![[0.0, 1.0, 1.0, 1.0], [1.0, 1.0, 0.5, 1.0], [1.0, 0.0, 0.5, 1.0], [0.0, 0.0, 1.0, 1.0]];
    let dir = TempDir::new("colours");
    let mut b = GltfBuilder::new();
    let mat = b.add_material("c", [0.8, 0.6, 0.4], false, None);
    let scene = load(&dir.write("c.glb", &one_mesh(b, &[square(0.0, mat, Some(colors))])));
    assert_matches(&both(&scene, &settings(n, DVec3::Z)), 1e-5, |x, y| {
        let (u, v) = ((x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64);
        let c = [u, v, 1.0 - 0.5 * u];
        [0, 1, 2].map(|k| [0.8f32, 0.6, 0.4][k] as f64 * c[k] / PI * E_PERP as f64)
    });
}

#[test]
fn alpha_mask_covers_exactly_where_alpha_reaches_the_cutoff() {
    // A 4 × 4 alpha pattern (NEAREST) on a square in front of a grey one: each pixel shows the front square
    // where its texel's alpha ≥ 0.5, the back one elsewhere; both renderers exactly.
    let (w, n) = (4u32, 16u32);
    let alphas = [0u8, 127, 128, 255];
    let t: Vec<[u8; 4]> = (0..w * w).map(|k| [255, 255, 255, alphas[((k * 7 + k / w) % 4) as usize]]).collect();
    let dir = TempDir::new("mask");
    let mut b = GltfBuilder::new();
    let image = b.add_png_image(&png_rgba8(w, w, &t));
    let tex = b.add_texture(image, Some(9728), Some(9728), [33071, 33071]);
    let front = b.add_material_json(json!({
        "alphaMode": "MASK",
        "pbrMetallicRoughness": { "baseColorTexture": { "index": tex }, "metallicFactor": 0.0 }
    }));
    let back = b.add_material("back", [0.25; 3], false, None);
    let scene = load(&dir.write("mask.glb", &one_mesh(b, &[square(0.5, front, None), square(0.0, back, None)])));
    let images = both(&scene, &settings(n, DVec3::Z));
    assert_matches(&images, 1e-5, |x, y| {
        let (i, j) = (x * w / n, y * w / n);
        let alpha = t[(j * w + i) as usize][3] as f64 / 255.0;
        let albedo = if alpha >= 0.5 { srgb_to_linear(255) as f64 } else { 0.25 };
        [albedo / PI * E_PERP as f64; 3]
    });
    assert_eq!(common::bits(&images[0]).len(), common::bits(&images[1]).len());
}

#[test]
fn a_normal_map_tilts_the_shading_normal() {
    // A constant normal map tilted towards +x (the map's right, +u) and +y (the map's up, towards decreasing v:
    // world +y on this square), under a sun from +x +y +z: the lit value follows the cosine between the decoded,
    // normalised map normal in the frame (t = +x, b = +y, n = +z) and the sun. With tangents from MikkTSpace (the
    // file has none) and with the file's TANGENT: the same frame, glTF's handedness.
    let n = 8u32;
    let code = |v: f64| ((v * 0.5 + 0.5) * 255.0).round() as u8;
    let tn = DVec3::new(0.4, 0.3, 1.0).normalize();
    let t = vec![[code(tn.x), code(tn.y), code(tn.z), 255]; 4];
    let sun = DVec3::new(1.0, 1.0, 1.0);
    let s = settings(n, sun);
    let decoded = [0, 1, 2].map(|c| t[0][c] as f64 / 255.0 * 2.0 - 1.0);
    let normal = DVec3::new(decoded[0], decoded[1], decoded[2]).normalize();
    let l = s.lights.sun.unwrap().direction.as_dvec3();
    let want = 0.5 / PI * E_PERP as f64 * normal.dot(l);
    let flipped_y = 0.5 / PI * E_PERP as f64 * DVec3::new(decoded[0], -decoded[1], decoded[2]).normalize().dot(l);
    assert!(rel(want, 0.5 / PI * E_PERP as f64 * l.z) > 0.05 && rel(want, flipped_y) > 0.05, "the tilt must show");
    for file_tangents in [false, true] {
        let dir = TempDir::new("normal-map");
        let mut b = GltfBuilder::new();
        let image = b.add_png_image(&png_rgba8(2, 2, &t));
        let tex = b.add_texture(image, Some(9728), Some(9728), [10497, 10497]);
        let mat = b.add_material_json(json!({
            "normalTexture": { "index": tex },
            "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0 }
        }));
        let mut mb = one_mesh(b, &[square(0.0, mat, None)]);
        let tangents = mb.add_accessor_f32(&[1.0, 0.0, 0.0, 1.0].repeat(4), 4, "VEC4");
        let mut doc = mb.document(Some("nm.bin"));
        if file_tangents {
            doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = json!(tangents);
        }
        std::fs::write(dir.path("nm.bin"), mb.bin()).unwrap();
        std::fs::write(dir.path("nm.gltf"), doc.to_string()).unwrap();
        let scene = load(&dir.path("nm.gltf"));
        assert_matches(&both(&scene, &s), 1e-5, |_, _| [want; 3]);
    }
}

#[test]
fn emission_adds_its_radiance() {
    // emissiveFactor × KHR_materials_emissive_strength × the extras' emission_scale [W/(m²·sr)], on an unlit
    // (black) square, and added to the reflected radiance on a lit one.
    let n = 4u32;
    let dir = TempDir::new("emission");
    let mut b = GltfBuilder::new();
    let mat = b.add_material_json(json!({
        "emissiveFactor": [1.0, 0.5, 0.25],
        "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 4.0 } },
        "extras": { "sunshade": { "emission_scale": 10.0 } },
        "pbrMetallicRoughness": { "baseColorFactor": [0.2, 0.2, 0.2, 1.0], "metallicFactor": 0.0 }
    }));
    let scene = load(&dir.write("e.glb", &one_mesh(b, &[square(0.0, mat, None)])));
    let s = settings(n, DVec3::Z);
    assert_matches(&both(&scene, &s), 1e-5, |_, _| {
        [0, 1, 2].map(|c| [40.0, 20.0, 10.0][c] + 0.2f32 as f64 / PI * E_PERP as f64)
    });
}

/// A square made of two primitives' worth of JSON surgery: a morph target that moves it, at weight 0.5.
#[test]
fn morphed_and_skinned_meshes_equal_their_pre_posed_twins() {
    let dir = TempDir::new("deform");
    let s = settings(32, DVec3::new(0.3, 0.2, 1.0));
    let render = |scene: &Scene| both(scene, &s);
    // The twin: the square moved by (0.25, −0.125, 0) and tilted by moving two corners in z.
    let shift = |p: [f32; 3], k: usize| {
        let d = [[0.5, -0.25, 0.0], [0.5, -0.25, 0.5], [0.5, -0.25, 0.5], [0.5, -0.25, 0.0]][k];
        [0, 1, 2].map(|c| (p[c] as f64 + 0.5 * d[c]) as f32)
    };
    let mut b = GltfBuilder::new();
    let mat = b.add_material("m", [0.7; 3], true, None);
    let base = square(0.0, mat, None);
    let mut twin = base.clone();
    twin.positions = base.positions.iter().enumerate().map(|(k, p)| shift(*p, k)).collect();
    twin.normals = None; // flat normals from the moved corners, as for the morphed square below
    let mut morphed = base.clone();
    morphed.normals = None;
    let twin_scene = load(&dir.write("twin.glb", &one_mesh(b.clone(), &[twin])));
    let mut mb = one_mesh(b, &[morphed]);
    let displacement: Vec<f32> = [[0.5, -0.25, 0.0], [0.5, -0.25, 0.5], [0.5, -0.25, 0.5], [0.5, -0.25, 0.0]]
        .iter()
        .flatten()
        .copied()
        .collect();
    let acc = mb.add_accessor_f32(&displacement, 3, "VEC3");
    let mut doc = mb.document(Some("morph.bin"));
    doc["meshes"][0]["primitives"][0]["targets"] = json!([{ "POSITION": acc }]);
    doc["meshes"][0]["weights"] = json!([0.5]);
    std::fs::write(dir.path("morph.bin"), mb.bin()).unwrap();
    std::fs::write(dir.path("morph.gltf"), doc.to_string()).unwrap();
    let morph_scene = load(&dir.path("morph.gltf"));
    assert_eq!(morph_scene.meshes[0].positions, twin_scene.meshes[0].positions);
    let (a, b2) = (render(&morph_scene), render(&twin_scene));
    assert_eq!(common::bits(&a[0]), common::bits(&b2[0]), "GPU");
    assert_eq!(common::bits(&a[1]), common::bits(&b2[1]), "reference");

    // A skin of two joints: joint 1 translated by (0.5, 0, 0) and rotated 90° about z under joint 0; the right
    // corners follow joint 1 entirely, the left ones joint 0 (at the origin): the twin has those corners placed.
    let mut b = GltfBuilder::new();
    let mat = b.add_material("m", [0.7; 3], true, None);
    let base = square(0.0, mat, None);
    let q = glam::DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2);
    let moved = |p: [f32; 3]| {
        let v = q * DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) + DVec3::new(0.5, 0.0, 0.0);
        [v.x as f32, v.y as f32, v.z as f32]
    };
    let mut twin = base.clone();
    twin.positions = base.positions.iter().map(|&p| if p[0] > 0.0 { moved(p) } else { p }).collect();
    twin.normals = None;
    let mut skinned = base.clone();
    skinned.normals = None;
    let twin_scene = load(&dir.write("skin-twin.glb", &one_mesh(b.clone(), &[twin])));
    let m = b.add_mesh("square", &[skinned]);
    let joint1 = b.add_node(Node {
        transform: Transform::Trs { translation: [0.5, 0.0, 0.0], rotation: q.as_quat().to_array(), scale: [1.0; 3] },
        ..Default::default()
    });
    let joint0 = b.add_node(Node { children: vec![joint1], ..Default::default() });
    let skinned_node = b.add_node(Node { mesh: Some(m), ..Default::default() });
    b.add_scene(&[joint0, skinned_node], None);
    let joints: Vec<f32> = [0.0, 1.0, 1.0, 0.0].iter().flat_map(|&j| [j, 0.0, 0.0, 0.0]).collect();
    let weights: Vec<f32> = [1.0f32; 4].iter().flat_map(|&w| [w, 0.0, 0.0, 0.0]).collect();
    let ja = b.add_accessor_f32(&joints, 4, "VEC4");
    let wa = b.add_accessor_f32(&weights, 4, "VEC4");
    let mut doc = b.document(Some("skin.bin"));
    // JOINTS_0 as float is not glTF's type (u8/u16): write it as unsigned bytes instead.
    let jb = b.bin().len();
    let mut bin = b.bin().to_vec();
    bin.extend([0u8, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0]);
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    let views = doc["bufferViews"].as_array().unwrap().len();
    doc["bufferViews"].as_array_mut().unwrap().push(json!({ "buffer": 0, "byteOffset": jb, "byteLength": 16 }));
    doc["accessors"][ja] = json!({ "bufferView": views, "componentType": 5121, "count": 4, "type": "VEC4" });
    doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = json!(ja);
    doc["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = json!(wa);
    doc["nodes"][skinned_node]["skin"] = json!(0);
    doc["skins"] = json!([{ "joints": [joint0, joint1] }]);
    std::fs::write(dir.path("skin.bin"), &bin).unwrap();
    std::fs::write(dir.path("skin.gltf"), doc.to_string()).unwrap();
    let skin_scene = load(&dir.path("skin.gltf"));
    for (p, q) in skin_scene.meshes[0].positions.iter().zip(&twin_scene.meshes[0].positions) {
        assert!((*p - *q).length() < 1e-6, "{p} against {q}");
    }
    let (a, b2) = (render(&skin_scene), render(&twin_scene));
    let options = sunshade::compare::DiffOptions::default();
    for k in 0..2 {
        sunshade::testing::check_close(&a[k], &b2[k], &options).unwrap_or_else(|e| panic!("{e}"));
    }
    let _ = Vec3::ZERO;
}

#[test]
fn pixels_at_texture_discontinuities_are_flagged_fragile() {
    // 8 texels across 4 pixels: pixel centres land on texel boundaries (u·8 = 2x + 1). With NEAREST the result
    // jumps there, so every pixel is fragile; with LINEAR it is continuous, so none is; an alpha mask whose
    // alpha equals its cutoff is fragile too.
    let dir = TempDir::new("fragile");
    let t = ramp(8, 8);
    for (filter, alpha_mode, want) in [(9728, "OPAQUE", true), (9729, "OPAQUE", false), (9729, "MASK", true)] {
        let mut b = GltfBuilder::new();
        let image = b.add_png_image(&png_rgba8(8, 8, &t));
        let tex = b.add_texture(image, Some(filter), Some(filter), [10497, 10497]);
        let mat = b.add_material_json(json!({
            "alphaMode": alpha_mode,
            "alphaCutoff": 1.0,
            "pbrMetallicRoughness": { "baseColorTexture": { "index": tex }, "metallicFactor": 0.0 }
        }));
        let scene = load(&dir.write(&format!("f{filter}{alpha_mode}.glb"), &one_mesh(b, &[square(0.0, mat, None)])));
        let s = settings(4, DVec3::Z);
        let (image, fragile) = cpu::render_with_fragile_pixels(&scene, &s, &cpu::ReferenceOptions::default());
        assert_eq!(image.covered_count(), 16);
        assert!(fragile.iter().all(|&f| f == want), "filter {filter} {alpha_mode}: {fragile:?}");
    }
}

#[test]
fn quantized_texture_coordinates_equal_their_float_twin() {
    // KHR_mesh_quantization: TEXCOORD_0 as normalized unsigned shorts (0 and 65535 are exactly 0 and 1) gives the
    // image of the float coordinates, bit for bit, on both renderers.
    let (w, h) = (4u32, 3u32);
    let t = ramp(w, h);
    let float = textured_square(&t, w, h, 9729, 33071, json!({}));
    let dir = TempDir::new("quantized-uv");
    let mut b = GltfBuilder::new();
    let image = b.add_png_image(&png_rgba8(w, h, &t));
    let tex = b.add_texture(image, Some(9729), Some(9729), [33071, 33071]);
    let mat = b.add_material_json(json!({
        "pbrMetallicRoughness": { "baseColorTexture": { "index": tex }, "baseColorFactor": [1.0, 0.5, 0.25, 1.0], "metallicFactor": 0.0 }
    }));
    let mb = one_mesh(b, &[square(0.0, mat, None)]);
    let mut doc = mb.document(Some("q.bin"));
    let mut bin = mb.bin().to_vec();
    let offset = bin.len();
    for uv in [[0u16, 65535], [65535, 65535], [65535, 0], [0, 0]] {
        bin.extend(uv.iter().flat_map(|c| c.to_le_bytes()));
    }
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    let view = doc["bufferViews"].as_array().unwrap().len();
    doc["bufferViews"].as_array_mut().unwrap().push(json!({ "buffer": 0, "byteOffset": offset, "byteLength": 16 }));
    let acc = doc["accessors"].as_array().unwrap().len();
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "bufferView": view, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2" }));
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(acc);
    doc["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    std::fs::write(dir.path("q.bin"), &bin).unwrap();
    std::fs::write(dir.path("q.gltf"), doc.to_string()).unwrap();
    let quantized = load(&dir.path("q.gltf"));
    assert_eq!(quantized.meshes[0].tex_coords[0], float.meshes[0].tex_coords[0]);
    let s = settings(24, DVec3::Z);
    let (a, b) = (both(&quantized, &s), both(&float, &s));
    assert_eq!(common::bits(&a[0]), common::bits(&b[0]));
    assert_eq!(common::bits(&a[1]), common::bits(&b[1]));
}

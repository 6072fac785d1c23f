//! The CPU reference renderer: the same image as the GPU path, computed independently of Vulkan.
//!
//! It takes the same [`Scene`] and [`RenderSettings`] and reproduces the device pipeline step by step:
//!
//! 1. [`transform`]: the vertex shader's `clip = M (p, 1)`, the same f32 operations in the same order;
//! 2. [`clip`]: clipping against the view volume as Mesa's draw module does it;
//! 3. [`viewport`]: perspective divide, viewport transform, snapping to the device's sub-pixel grid
//!    (`subPixelPrecisionBits`, a parameter: 8 on lavapipe);
//! 4. [`raster`]: facing and culling from the snapped area, coverage by exact edge functions with the top-left
//!    rule, depth test LESS against a cleared depth of 1;
//! 5. [`barycentric`]: the fragment shader's own perspective-correct barycentrics in the (unclipped) triangle,
//!    which interpolate world position, normal, texture coordinates and colour (`fragment`, as scene.frag does,
//!    with the material evaluated there); depth is interpolated in window space ([`interpolate`]);
//! 6. shading in f64 by [`crate::shading`], the specification the GLSL mirrors, with shadow rays in f64 through a
//!    BVH of every triangle ([`crate::visibility`]) where the scene can shadow itself.
//!
//! Rows are rendered in parallel bands (rayon); triangles are binned by band and kept in submission order, so
//! depth ties resolve as on the device (the first drawn wins). Nothing here calls into `gpu`.

pub mod barycentric;
pub mod checked;
pub mod clip;
mod cone_occluders;
pub mod disk_costs;
mod fragment;
mod frame;
pub mod interpolate;
pub mod map_edges;
mod occluders;
pub mod raster;
pub mod sun_costs;
pub mod transform;
pub mod viewport;

use std::sync::OnceLock;

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use self::barycentric::{pixel_ndc, triangle_barycentrics};
use self::clip::{clip_mask, clip_triangle, ClipVertex, ATTRIBUTES};
use self::fragment::{covers, ray_frame, shade, surface_sample};
pub use self::frame::Frame;
use self::interpolate::Interpolator;
pub use self::occluders::Occluders;
use self::raster::RasterTriangle;
use self::transform::clip_position;
use self::viewport::{snap, Viewport};
use crate::film::Image;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::surface::{discontinuity_margin as surface_discontinuity, surface_flags, SURFACE_ALPHA_MASK};
use crate::shading::{Occlusion, ShadowedLights, Shadows};
pub use crate::visibility::occluder_bvh;
use crate::visibility::ShadowChoice;

/// How the reference mirrors the device.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceOptions {
    /// The device's `subPixelPrecisionBits` (8 on lavapipe).
    pub sub_pixel_bits: u32,
    /// Whether the device fuses the viewport multiply-add for unclipped vertices (see [`viewport`]). lavapipe's
    /// JIT does where the host CPU has FMA: measured on a dense lattice of isolated triangles at 1000×1000, the
    /// fused mirror matched lavapipe's coverage exactly and the unfused one did not.
    pub fused_viewport: bool,
}

impl Default for ReferenceOptions {
    fn default() -> Self {
        Self { sub_pixel_bits: 8, fused_viewport: host_has_fma() }
    }
}

/// The longest side the reference renders \[pixels\]: lavapipe's `maxImageDimension2D`, so that the reference has
/// the GPU's limits.
pub const MAX_DIMENSION: u32 = 16384;

/// The default pixel budget of the reference: 2^27 pixels, the most that lavapipe's largest allocation (2 GiB) holds
/// in RGBA32F. The reference needs 16 bytes a pixel for the image and about 12 more per pixel of a band in flight.
pub const DEFAULT_MAX_PIXELS: u64 = 1 << 27;

/// Refuses an image size the reference would not render (each side ≤ [`MAX_DIMENSION`], `width × height ≤
/// max_pixels`), before anything is allocated.
pub fn check_size(width: u32, height: u32, max_pixels: u64) -> Result<(), String> {
    if width > MAX_DIMENSION || height > MAX_DIMENSION {
        return Err(format!(
            "a {width}x{height} image exceeds the reference's largest side ({MAX_DIMENSION} pixels, as on the GPU)"
        ));
    }
    let pixels = width as u64 * height as u64;
    if pixels > max_pixels {
        return Err(format!(
            "a {width}x{height} image has {pixels} pixels, more than the budget of {max_pixels} (--max-pixels)"
        ));
    }
    Ok(())
}

/// Whether this CPU has fused multiply-add (what lavapipe's JIT uses when it does).
pub fn host_has_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        // aarch64 and other 64-bit targets LLVM supports have FMA in their base instruction set.
        true
    }
}

/// Rows per parallel band.
const BAND_ROWS: u32 = 16;

/// A triangle after clipping and set-up: one of the (possibly several) pieces of a scene triangle.
struct Prepared {
    raster: RasterTriangle,
    /// Depth across this piece, in window space.
    depth: Interpolator,
    /// The scene triangle's clip positions, for the fragment shader's barycentrics.
    pub(crate) clip: [glam::Vec4; 3],
    /// The scene triangle's vertex attributes (world position, normal, tangent, texture coordinates, colour).
    pub(crate) attributes: [[f64; ATTRIBUTES]; 3],
    pub(crate) material: usize,
    /// What the material needs evaluated per pixel (`SURFACE_*` bits of [`surface_flags`]).
    pub(crate) surface: u32,
    /// Double-sided material seen from the back: the normal is reversed.
    pub(crate) flip_normal: bool,
}

/// The reference's shadow technique for this scene and these settings, and why (see
/// [`crate::visibility::choose_reference`]).
pub fn shadow_choice(scene: &Scene, settings: &RenderSettings) -> ShadowChoice {
    // The scene's test runs only where `auto` needs it.
    let can_occlude = settings.shading.shadows != Shadows::Auto || crate::visibility::can_occlude(scene);
    shadow_choice_where(can_occlude, settings)
}

/// [`shadow_choice`] for a caller that has already tested whether the scene can occlude a light
/// (`crate::visibility::can_occlude`).
pub fn shadow_choice_where(scene_can_occlude: bool, settings: &RenderSettings) -> ShadowChoice {
    let requested = settings.shading.shadows;
    let can_occlude = requested != Shadows::Auto || scene_can_occlude;
    crate::visibility::choose_reference(requested, &settings.lights, can_occlude)
}

/// The reference's shadow rays for a render: the occluders they test and the lights they shadow, both from
/// [`shadow_choice`]'s technique (every light for rays; for maps, the lights with a map, as the GPU shadows them,
/// also where `auto` resolved to maps).
struct ShadowRays<'o, 'a> {
    occluders: &'o Occluders<'a>,
    lights: ShadowedLights,
}

/// The render's [`ShadowRays`], or `None` where every light is unoccluded. The occluders are built in `kept` the
/// first time a render casts rays: a render's own, or a [`Frame`]'s for all of its renders.
fn occluders_for<'o, 'a>(
    scene: &'a Scene,
    settings: &RenderSettings,
    kept: &'o OnceLock<Occluders<'a>>,
) -> Option<ShadowRays<'o, 'a>> {
    match shadow_choice(scene, settings).technique {
        Shadows::None => None,
        technique => Some(ShadowRays {
            occluders: kept.get_or_init(|| Occluders::new(scene)),
            lights: ShadowedLights::of(technique),
        }),
    }
}

/// Renders `scene` as the GPU path would, on the CPU; shadows by rays in f64 where [`shadow_choice`] says so.
pub fn render(scene: &Scene, settings: &RenderSettings, options: &ReferenceOptions) -> Image {
    let kept = OnceLock::new();
    let occluders = occluders_for(scene, settings, &kept);
    let shader = plain_shader(scene, settings, occluders.as_ref());
    render_inner(scene, settings, options, None, &shader).0
}

/// The per-pixel work of [`render`]: shading, with these occluders (`None`: every light unoccluded); no pixel is
/// flagged.
fn plain_shader<'a>(
    scene: &'a Scene,
    settings: &'a RenderSettings,
    rays: Option<&'a ShadowRays<'_, '_>>,
) -> impl Fn(&Prepared, (u32, u32), [f64; 3]) -> ([f64; 3], bool) + Sync + 'a {
    let viewer = settings.viewer();
    move |t, xy, w| {
        (shade(scene, settings, t, xy, w, viewer, rays.map(|r| (r.occluders as &dyn Occlusion, r.lights))), false)
    }
}

/// [`render`] for the pixels flagged in `selected` only (row-major, one flag a pixel); every other pixel is left
/// empty (alpha 0). Rasterization is done whole, so a selected pixel gets exactly the value [`render`] gives it;
/// only the shading, where the time goes, is skipped elsewhere. The converged reference refines pixels this way.
pub fn render_selected(
    scene: &Scene,
    settings: &RenderSettings,
    options: &ReferenceOptions,
    selected: &[bool],
) -> Image {
    Frame::new(scene, settings, options).render_selected(settings, Some(selected))
}

/// For each pixel, the material of the surface it sees (`None` where it sees none), by the rasterization and
/// visibility of [`render`] (the device's rules, so the GPU's image covers the same pixels with the same
/// triangles); no shading. `--tolerance`'s study measures each material's pixels with it.
pub fn material_map(scene: &Scene, settings: &RenderSettings, options: &ReferenceOptions) -> Vec<Option<usize>> {
    // The material's index as the "radiance" (exact in f32 for any count of materials a scene can hold).
    let shader = |t: &Prepared, _: (u32, u32), _: [f64; 3]| ([t.material as f64, 0.0, 0.0], false);
    let (image, _) = render_inner(scene, settings, options, None, &shader);
    image.pixels().iter().map(|p| (p[3] > 0.0).then_some(p[0] as usize)).collect()
}

/// For each pixel, its radiance as [`render`] gives it (with `settings`' shadows), and per channel the largest
/// change of that radiance when its barycentrics move to one of the six corners `l ± r eᵢ` of the ball
/// `Σ|δlᵢ| ≤ r`, `r = radius(clip-space vertices, pixel NDC)` (`accuracy::interpolation` takes the largest change
/// over the ball from these corners): `(radiance, change)`, one shading pass. A pixel whose surface reads
/// textures, vertex colours, a normal map, emission or an alpha mask (interpolated there from the barycentrics
/// too, which this does not move) or whose radius is not finite gets an infinite change: no claim.
pub fn barycentric_sensitivity(
    scene: &Scene,
    settings: &RenderSettings,
    options: &ReferenceOptions,
    radius: &(dyn Fn([glam::Vec4; 3], glam::Vec2) -> f64 + Sync),
) -> (Image, Image) {
    use std::sync::atomic::{AtomicU32, Ordering};
    let kept = OnceLock::new();
    let occluders = occluders_for(scene, settings, &kept);
    let rays = occluders.as_ref();
    let viewer = settings.viewer();
    let (width, height) = (settings.width, settings.height);
    // Each pixel's radiance, rounded to f32 as `render` stores it, written by the pass that shades it.
    let centres: Vec<[AtomicU32; 3]> = (0..width as usize * height as usize).map(|_| Default::default()).collect();
    let shader = |t: &Prepared, (x, y): (u32, u32), w: [f64; 3]| {
        let at = |w: [f64; 3]| {
            shade(scene, settings, t, (x, y), w, viewer, rays.map(|r| (r.occluders as &dyn Occlusion, r.lights)))
        };
        let centre = at(w);
        for (slot, value) in centres[(y * width + x) as usize].iter().zip(centre) {
            slot.store((value as f32).to_bits(), Ordering::Relaxed);
        }
        let r = radius(t.clip, pixel_ndc(x, y, width, height));
        if t.surface != 0 || !r.is_finite() {
            return ([f64::INFINITY; 3], false);
        }
        let mut change = [0.0f64; 3];
        for i in 0..3 {
            for sign in [-1.0, 1.0] {
                let mut moved = w;
                moved[i] += sign * r;
                let l = at(moved);
                for c in 0..3 {
                    change[c] = change[c].max((l[c] - centre[c]).abs());
                }
            }
        }
        (change, false)
    };
    let change = render_inner(scene, settings, options, None, &shader).0;
    let mut radiance = Image::new(width, height);
    for ((p, c), centre) in radiance.pixels_mut().iter_mut().zip(change.pixels()).zip(&centres) {
        if c[3] > 0.0 {
            let v = centre.each_ref().map(|a| f32::from_bits(a.load(Ordering::Relaxed)));
            *p = [v[0], v[1], v[2], 1.0];
        }
    }
    (radiance, change)
}

/// How near a shadow ray may pass an occluder's edge before its answer counts as fragile: `2⁻¹⁸` of the
/// coordinates' magnitude, several times the f32 rounding of the GPU's positions and directions (2⁻²³).
pub const FRAGILE_RAY_RELATIVE: f64 = 1.0 / 262144.0;

/// The fragile pixels' class, as a comparison names it ([`render_with_fragile_pixels`]).
pub const FRAGILE_CLASS: &str = "fragile pixels (a shadow ray within 2^-18 of the scene's size from an occluder's \
    edge or an alpha-masked occluder's contour, or a texture lookup or alpha cutoff within 2^-16 of a \
    discontinuity: f32 geometry or texture coordinates may decide the other way)";

/// The most fragile pixels over tolerance a check passes: 0.05% of the compared pixels (a few rays that graze an
/// edge, not a region).
pub const FRAGILE_ALLOWED_FRACTION: f64 = 5e-4;

/// How near a texture lookup or an alpha cutoff may be to a jump of its result before the pixel counts as
/// fragile: `2⁻¹⁶` of the decision's scale (docs/textures.md, "Discontinuities"), above the rounding of f32 texture
/// coordinates from f32 barycentrics (up to ~1e-5 of a thin triangle's weights).
pub const FRAGILE_TEXTURE_RELATIVE: f64 = 1.0 / 65536.0;

/// [`render`], and for each pixel whether it is *fragile*: one of its shadow rays passes within
/// [`FRAGILE_RAY_RELATIVE`] of the scene's size from an occluder's boundary (an edge, or the contour where an
/// alpha-masked occluder's alpha crosses its cutoff: [`Occluders::blocks_near`]), so that the GPU's f32 geometry
/// could answer it the other way ([`crate::visibility::Bvh::occluded_with_margin`]), or one of its texture lookups
/// (or its alpha mask) lies within [`FRAGILE_TEXTURE_RELATIVE`] of a discontinuity (a `NEAREST` texel
/// boundary, a nearest mip level's boundary, the switch between magnification and minification filters, an alpha
/// cutoff). Image-diff tests count GPU/reference differences at those pixels apart, as coverage mismatches at
/// triangle edges are. Slower than [`render`] (every ray traverses with padded boxes and tests edge distances).
pub fn render_with_fragile_pixels(
    scene: &Scene,
    settings: &RenderSettings,
    options: &ReferenceOptions,
) -> (Image, Vec<bool>) {
    let kept = OnceLock::new();
    let occluders = occluders_for(scene, settings, &kept);
    let viewer = settings.viewer();
    let eps = scene.bounds().map_or(0.0, |b| b.min.abs().max(b.max.abs()).max_element()) * FRAGILE_RAY_RELATIVE;
    render_inner(scene, settings, options, None, &|t: &Prepared, (x, y): (u32, u32), w: [f64; 3]| {
        let mut flagged = false;
        let radiance = match &occluders {
            Some(rays) => {
                let rec =
                    Recording { occluders: rays.occluders, eps, fragile: std::sync::atomic::AtomicBool::new(false) };
                let r = shade(scene, settings, t, (x, y), w, viewer, Some((&rec, rays.lights)));
                flagged = rec.fragile.load(std::sync::atomic::Ordering::Relaxed);
                r
            }
            None => shade(scene, settings, t, (x, y), w, viewer, None),
        };
        if t.surface != 0 {
            let s = surface_sample(settings, t, x, y);
            let material = &scene.materials[t.material];
            if surface_discontinuity(material, &scene.textures, &s, t.surface) < FRAGILE_TEXTURE_RELATIVE {
                flagged = true;
            }
        }
        (radiance, flagged)
    })
}

/// [`render`], and for each pixel whether it is a *map edge* ([`map_edges`]): where a `--shadows map` render's
/// lookups can reach an occluder's edge, so that the map may answer otherwise than the reference's rays.
/// Without shadow maps (settings other than `map`, or no occluders) no pixel is flagged. Slower than [`render`]:
/// up to [`map_edges::REACH_GRID`]² more rays per pixel and mapped light.
pub fn render_with_map_edges(
    scene: &Scene,
    settings: &RenderSettings,
    options: &ReferenceOptions,
) -> (Image, Vec<bool>) {
    let kept = OnceLock::new();
    let rays = occluders_for(scene, settings, &kept);
    let reach = map_edges::MapReach::new(scene, settings);
    let viewer = settings.viewer();
    render_inner(scene, settings, options, None, &|t: &Prepared, xy: (u32, u32), w: [f64; 3]| {
        let cast = rays.as_ref().map(|r| (r.occluders as &dyn Occlusion, r.lights));
        let radiance = shade(scene, settings, t, xy, w, viewer, cast);
        let edge = match &rays {
            // Mapped lights: the render's technique is `map` (asked, or `auto` without ray queries).
            Some(r) if r.lights == ShadowedLights::MAPPED => {
                let f = ray_frame(t, w);
                reach.is_edge(r.occluders, f.origin, f.face, f.position, f.normal)
            }
            _ => false,
        };
        (radiance, edge)
    })
}

/// Occluders that remember whether any ray they answered was fragile (one per pixel): it grazed an edge, or met
/// a masked triangle within `eps` of where its alpha crosses the cutoff ([`Occluders::blocks_near`]).
struct Recording<'a> {
    occluders: &'a Occluders<'a>,
    eps: f64,
    fragile: std::sync::atomic::AtomicBool,
}

impl Occlusion for Recording<'_> {
    fn occluded(&self, origin: DVec3, direction: DVec3, t_max: f64) -> bool {
        let Some(ray) = crate::visibility::WatertightRay::new(origin, direction) else { return false };
        let (occluded, fragile) = self.occluders.bvh.occluded_with_margin_where(&ray, 0.0, t_max, self.eps, |i, t| {
            self.occluders.blocks_near(i, origin, direction, t, self.eps)
        });
        if fragile {
            self.fragile.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        occluded
    }
}

/// What [`render_inner`] runs for each visible pixel: `(triangle, (x, y), barycentrics)` → (radiance
/// [W/(m²·sr)], whether to flag the pixel).
type PixelShader<'a> = dyn Fn(&Prepared, (u32, u32), [f64; 3]) -> ([f64; 3], bool) + Sync + 'a;

/// The render: rasterization and visibility as the device does them, then `shade_pixel(triangle, (x, y),
/// barycentrics)` for each visible pixel (only the pixels `selected` flags; `None`: all), which gives its
/// radiance and whether to flag it; the flags come back as a row-major mask.
fn render_inner(
    scene: &Scene,
    settings: &RenderSettings,
    options: &ReferenceOptions,
    selected: Option<&[bool]>,
    shade_pixel: &PixelShader,
) -> (Image, Vec<bool>) {
    shade_rasterized(&rasterize(scene, settings, options), selected, shade_pixel)
}

/// A frame rasterized: its triangles set up, and for each pixel the one it sees. Shading does not change it, so
/// renders of one view with other sample grids share it ([`Frame`]).
struct Rasterized {
    triangles: Vec<Prepared>,
    /// Per pixel (row-major), the index into `triangles` of the nearest triangle covering it (`u32::MAX`: none).
    nearest: Vec<u32>,
    width: u32,
    height: u32,
}

/// Rasterization and visibility as the device does them (the first half of [`render_inner`]).
fn rasterize(scene: &Scene, settings: &RenderSettings, options: &ReferenceOptions) -> Rasterized {
    let (width, height) = (settings.width, settings.height);
    let triangles = prepare(scene, settings, options);

    // Bin triangles into bands of rows, keeping submission order.
    let band_count = height.div_ceil(BAND_ROWS) as usize;
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); band_count];
    for (i, t) in triangles.iter().enumerate() {
        for band in (t.raster.bounds.y0 / BAND_ROWS)..=(t.raster.bounds.y1 / BAND_ROWS) {
            bins[band as usize].push(i as u32);
        }
    }

    // Visibility, band by band: the nearest triangle of each pixel (u32::MAX where none).
    let band_pixels = (BAND_ROWS * width) as usize;
    let mut nearest = vec![u32::MAX; (width * height) as usize];
    nearest.par_chunks_mut(band_pixels).zip(bins.par_iter()).enumerate().for_each(|(band, (visible, bin))| {
        let y0 = band as u32 * BAND_ROWS;
        let rows = visible.len() as u32 / width;
        let mut depth = vec![1.0f64; visible.len()];
        for &ti in bin {
            let t = &triangles[ti as usize];
            let masked = t.surface & SURFACE_ALPHA_MASK != 0;
            t.raster.for_each_covered(y0, y0 + rows, |x, y| {
                let l = t.depth.barycentrics(x, y);
                let z = t.depth.depth(&l);
                let k = ((y - y0) * width + x) as usize;
                // An alpha-masked fragment below its cutoff is discarded before the depth write, as on the
                // device.
                if z < depth[k] && (!masked || covers(scene, settings, t, x, y)) {
                    depth[k] = z;
                    visible[k] = ti;
                }
            });
        }
    });
    Rasterized { triangles, nearest, width, height }
}

/// The second half of [`render_inner`]: `shade_pixel` on each visible pixel of `rasterized` that `selected`
/// flags (`None`: all).
fn shade_rasterized(
    rasterized: &Rasterized,
    selected: Option<&[bool]>,
    shade_pixel: &PixelShader,
) -> (Image, Vec<bool>) {
    let Rasterized { nearest, width, height, .. } = rasterized;
    let (width, height) = (*width, *height);
    // Shading, pixel by pixel: each shaded once, the pixels shared out among the threads as they go rather than
    // by bands, since the costly ones (a penumbra's, `--tolerance`'s refined pixels) gather in a few bands.
    let shaded: Vec<usize> =
        (0..nearest.len()).filter(|&k| nearest[k] != u32::MAX && selected.is_none_or(|m| m[k])).collect();
    let values: Vec<([f64; 3], bool)> =
        shaded.par_iter().with_max_len(64).map(|&k| shade_covered(rasterized, k, shade_pixel)).collect();
    let mut image = Image::new(width, height);
    let mut mask = vec![false; (width * height) as usize];
    for (&k, (radiance, flag)) in shaded.iter().zip(values) {
        mask[k] = flag;
        image.pixels_mut()[k] = stored(radiance);
    }
    (image, mask)
}

/// `shade_pixel` on covered pixel `k` (row-major) of `rasterized`: its triangle, position and barycentrics.
fn shade_covered(rasterized: &Rasterized, k: usize, shade_pixel: &PixelShader) -> ([f64; 3], bool) {
    let Rasterized { triangles, nearest, width, height } = rasterized;
    let (x, y) = (k as u32 % width, k as u32 / width);
    let t = &triangles[nearest[k] as usize];
    let w = triangle_barycentrics(t.clip, pixel_ndc(x, y, *width, *height));
    shade_pixel(t, (x, y), w.to_array())
}

/// A pixel's radiance as an image stores it (f32, alpha 1).
fn stored(radiance: [f64; 3]) -> [f32; 4] {
    [radiance[0] as f32, radiance[1] as f32, radiance[2] as f32, 1.0]
}

/// For each pixel, the distance \[pixels\] from its sample to the nearest edge of any triangle whose bounds
/// contain it (infinity where none does), in the reference's snapped geometry. The image-diff tests use it to
/// check that coverage mismatches lie on triangle edges.
pub fn nearest_edge_distances(
    scene: &Scene,
    settings: &RenderSettings,
    options: &ReferenceOptions,
    pixels: &[(u32, u32)],
) -> Vec<f64> {
    let triangles = prepare(scene, settings, options);
    pixels
        .iter()
        .map(|&(x, y)| {
            triangles
                .iter()
                .filter(|t| {
                    let b = t.raster.bounds;
                    // One pixel of slack: a pixel just outside a triangle's bounds can still be near its edge.
                    x + 1 >= b.x0 && x <= b.x1 + 1 && y + 1 >= b.y0 && y <= b.y1 + 1
                })
                .map(|t| t.raster.edge_distance(x, y, options.sub_pixel_bits))
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

/// Vertex processing, clipping and triangle set-up for every triangle, in submission order.
fn prepare(scene: &Scene, settings: &RenderSettings, options: &ReferenceOptions) -> Vec<Prepared> {
    let m = settings.clip_from_world();
    let viewport = Viewport::new(settings.width, settings.height, options.fused_viewport);
    let bits = options.sub_pixel_bits;
    let mut out = Vec::new();
    for mesh in &scene.meshes {
        let material = &scene.materials[mesh.material];
        let surface = surface_flags(material, !mesh.colors.is_empty());
        // The vertex shader, once per vertex.
        let vertices: Vec<ClipVertex> = (0..mesh.positions.len())
            .map(|i| {
                let (p, n, t) = (mesh.positions[i], mesh.normals[i], mesh.tangents[i]);
                let uv = |set: usize| mesh.tex_coords[set].get(i).copied().unwrap_or([0.0; 2]);
                let ([u0, v0], [u1, v1]) = (uv(0), uv(1));
                let [r, g, b, a] = mesh.colors.get(i).copied().unwrap_or([1.0; 4]);
                let clip = clip_position(&m, p);
                let window = if clip_mask(clip) == 0 { viewport.window_from_vertex(clip) } else { Vec3::NAN };
                let attributes = [p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y, t.z, t.w, u0, v0, u1, v1, r, g, b, a];
                ClipVertex { clip, window, attributes }
            })
            .collect();
        for tri in mesh.indices.chunks_exact(3) {
            let input = [0, 1, 2].map(|k| vertices[tri[k] as usize]);
            clip_triangle(input, &viewport, |t| {
                if t.iter().any(|v| !v.window.is_finite()) {
                    return;
                }
                let fixed = t.map(|v| [snap(v.window.x, bits), snap(v.window.y, bits)]);
                let Some(raster) = RasterTriangle::new(fixed, bits, settings.width, settings.height) else {
                    return;
                };
                if !raster.front_facing && !material.double_sided {
                    return; // back-face culling
                }
                let ordered = raster.order.map(|i| t[i]);
                let Some(depth) = Interpolator::new(ordered.map(|v| v.window), ordered.map(|v| v.clip.w)) else {
                    return;
                };
                out.push(Prepared {
                    clip: input.map(|v| v.clip),
                    attributes: input.map(|v| v.attributes.map(f64::from)),
                    flip_normal: !raster.front_facing,
                    raster,
                    depth,
                    material: mesh.material,
                    surface,
                });
            });
        }
    }
    out
}

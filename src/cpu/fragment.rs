//! The reference's fragment stage, as `shaders/scene.frag` runs it for one pixel: the surface inputs from the
//! fragment's own barycentrics ([`surface_sample`]), the alpha mask ([`covers`]), and the radiance of the surface
//! point with its material evaluated there ([`shade`]: textures, vertex colours, normal map, emission; shadow
//! rays where the scene casts them).

use glam::DVec3;

use super::barycentric::{pixel_ndc, triangle_barycentrics};
use super::clip::ATTRIBUTES;
use super::Prepared;
use crate::scene::tangent::orthonormal_tangent;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::shading::surface::{
    alpha_covers, base_color, emitted_radiance, perturbed_normal, surface_brdf, tangent_space_normal, SurfaceSample,
    SURFACE_COLORS, SURFACE_EMISSION, SURFACE_EVAL, SURFACE_NORMAL_MAP,
};
use crate::shading::visibility::shadow_ray_origin;
use crate::shading::{
    irradiance_visible, radiance_out, radiance_out_visible, safe_normalize, Occlusion, Quantity, ShadowedLights,
    Shadowing, SurfacePoint, VisibilityRule,
};

/// The pixel's surface inputs ([`SurfaceSample`]): each set's texture coordinates at the pixel centre and at
/// its right and lower neighbours, and the vertex colour, interpolated in f64 with the fragment shader's
/// barycentrics (rounded to f32 for the colour), as `shaders/scene.frag` does.
pub(super) fn surface_sample(settings: &RenderSettings, t: &Prepared, x: u32, y: u32) -> SurfaceSample {
    let (width, height) = (settings.width, settings.height);
    let at = |w: DVec3, k: usize| w.x * t.attributes[0][k] + w.y * t.attributes[1][k] + w.z * t.attributes[2][k];
    let centre = triangle_barycentrics(t.clip, pixel_ndc(x, y, width, height));
    let right = triangle_barycentrics(t.clip, pixel_ndc(x + 1, y, width, height));
    let below = triangle_barycentrics(t.clip, pixel_ndc(x, y + 1, width, height));
    let uvs = |w: DVec3| [[at(w, 10), at(w, 11)], [at(w, 12), at(w, 13)]];
    let color = (t.surface & SURFACE_COLORS != 0).then(|| [14, 15, 16, 17].map(|k| at(centre, k) as f32));
    SurfaceSample { uv: uvs(centre), uv_x: uvs(right), uv_y: uvs(below), color }
}

/// Whether an alpha-masked triangle covers pixel (x, y): its base colour's alpha against the cutoff.
pub(super) fn covers(scene: &Scene, settings: &RenderSettings, t: &Prepared, x: u32, y: u32) -> bool {
    let material = &scene.materials[t.material];
    let s = surface_sample(settings, t, x, y);
    alpha_covers(material, base_color(material, &scene.textures, &s)[3])
}

/// Radiance (or irradiance, as the settings' quantity says) at the point of triangle `t` with barycentrics `w`;
/// `shadow_rays`: the occluders and the lights they shadow (`None`: every light unoccluded).
#[allow(clippy::too_many_arguments)]
pub(super) fn shade(
    scene: &Scene,
    settings: &RenderSettings,
    t: &Prepared,
    (x, y): (u32, u32),
    w: [f64; 3],
    viewer: glam::Vec4,
    shadow_rays: Option<(&dyn Occlusion, ShadowedLights)>,
) -> [f64; 3] {
    let a = interpolated(t, w);
    let (position, normal) = position_and_normal(t, &a);
    // Surface frame: the interpolated tangent made orthogonal to the normal; bitangent w (n × t).
    let tangent = orthonormal_tangent(DVec3::new(a[6], a[7], a[8]), normal);
    let handedness = if a[9] < 0.0 { -1.0 } else { 1.0 };
    let bitangent = handedness * normal.cross(tangent);
    let to_viewer = if viewer.w != 0.0 {
        safe_normalize(viewer.truncate().as_dvec3() - position)
    } else {
        viewer.truncate().as_dvec3()
    };
    let material = &scene.materials[t.material];
    let mut point = SurfacePoint { position, normal, tangent, bitangent, to_viewer };
    // The material at this pixel (textures, vertex colours, normal map, emission), as scene.frag evaluates it.
    let mut brdf = std::borrow::Cow::Borrowed(&material.brdf);
    let mut emission = [0.0f64; 3];
    if t.surface != 0 {
        let s = surface_sample(settings, t, x, y);
        let textures = &scene.textures;
        if t.surface & SURFACE_EVAL != 0 {
            brdf = std::borrow::Cow::Owned(surface_brdf(material, textures, &s, base_color(material, textures, &s)));
        }
        if let (Some((r, scale)), true) = (&material.normal_texture, t.surface & SURFACE_NORMAL_MAP != 0) {
            // Back faces of double-sided materials turn the whole frame (the normal and bitangent already are).
            let tn = tangent_space_normal(textures, r, *scale, &s);
            let t_side = if t.flip_normal { -tangent } else { tangent };
            point.normal = perturbed_normal(tn, t_side, bitangent, normal);
            point.tangent = orthonormal_tangent(DVec3::new(a[6], a[7], a[8]), point.normal);
            point.bitangent = handedness * point.normal.cross(point.tangent);
        }
        if t.surface & SURFACE_EMISSION != 0 {
            emission = emitted_radiance(material, textures, &s).map(f64::from);
        }
    }
    let emits = t.surface & SURFACE_EMISSION != 0;
    let add_emission = |r: [f64; 3]| if emits { [0, 1, 2].map(|c| r[c] + emission[c]) } else { r };
    // The material's own sun model and grid where `--tolerance` chose them per material.
    let shading = settings.shading_for(t.material);
    let irradiance = shading.quantity == Quantity::Irradiance;
    let Some((occluders, lights)) = shadow_rays else {
        if irradiance {
            return irradiance_visible(&point, &settings.lights, &shading, None);
        }
        return add_emission(radiance_out(&brdf, &point, &settings.lights, &shading));
    };
    let shadow = Shadowing {
        origin: shadow_origin(t, w, position, normal),
        occluders,
        samples_per_axis: settings.shading.shadow_samples_per_axis,
        lights,
        slices: settings.shading.visibility_rule == VisibilityRule::Slices,
    };
    if irradiance {
        return irradiance_visible(&point, &settings.lights, &shading, Some(&shadow));
    }
    add_emission(radiance_out_visible(&brdf, &point, &settings.lights, &shading, Some(&shadow)))
}

/// The shadow rays' origin for the point `position` with barycentrics `w` and interpolated unit normal `normal`
/// (on the side being shaded) of triangle `t`, from its corners and vertex normals
/// ([`shadow_ray_origin`]).
fn shadow_origin(t: &Prepared, w: [f64; 3], position: DVec3, normal: DVec3) -> DVec3 {
    let sign = if t.flip_normal { -1.0 } else { 1.0 };
    let vertex_normal =
        |k: usize| sign * safe_normalize(DVec3::new(t.attributes[k][3], t.attributes[k][4], t.attributes[k][5]));
    let normals = [vertex_normal(0), vertex_normal(1), vertex_normal(2)];
    shadow_ray_origin(&corners(t), &normals, w, position, normal)
}

/// The world corners [m] of triangle `t`.
fn corners(t: &Prepared) -> [DVec3; 3] {
    [0, 1, 2].map(|k| DVec3::new(t.attributes[k][0], t.attributes[k][1], t.attributes[k][2]))
}

/// Where a pixel's shadow rays leave from: the point [m], its interpolated unit normal (on the side being
/// shaded, before any normal map), the rays' origin and the unit face normal on the normal's side.
pub(super) struct RayFrame {
    pub position: DVec3,
    pub normal: DVec3,
    pub origin: DVec3,
    pub face: DVec3,
}

/// Triangle `t`'s vertex attributes at barycentrics `w`, interpolated in f64.
fn interpolated(t: &Prepared, w: [f64; 3]) -> [f64; ATTRIBUTES] {
    std::array::from_fn(|k| w[0] * t.attributes[0][k] + w[1] * t.attributes[1][k] + w[2] * t.attributes[2][k])
}

/// The point [m] and its unit normal on the side being shaded, from interpolated attributes `a` of triangle `t`.
fn position_and_normal(t: &Prepared, a: &[f64; ATTRIBUTES]) -> (DVec3, DVec3) {
    let normal = safe_normalize(DVec3::new(a[3], a[4], a[5]));
    (DVec3::new(a[0], a[1], a[2]), if t.flip_normal { -normal } else { normal })
}

/// The [`RayFrame`] of the point with barycentrics `w` of triangle `t`, as [`shade`] computes it.
pub(super) fn ray_frame(t: &Prepared, w: [f64; 3]) -> RayFrame {
    let (position, normal) = position_and_normal(t, &interpolated(t, w));
    let p = corners(t);
    let face = safe_normalize((p[1] - p[0]).cross(p[2] - p[0]));
    let face = if face.dot(normal) < 0.0 { -face } else { face };
    RayFrame { position, normal, origin: shadow_origin(t, w, position, normal), face }
}

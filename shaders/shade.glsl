// Outgoing radiance at a surface point: every light's irradiance and its specular lobe, summed. Mirrors
// src/shading/shade.rs name for name: the same formulas and the same deterministic sample points, so that the GPU
// and the CPU reference differ only by rounding.
#ifndef SUNSHADE_SHADE_GLSL
#define SUNSHADE_SHADE_GLSL

#include "bindings.glsl"
#include "brdf.glsl"
#include "measured.glsl"
#include "visibility.glsl"
#include "shadow_map.glsl"
#include "lobe.glsl"
#include "lights/sun.glsl"
#include "lights/disk.glsl"

// Whether this pipeline casts shadow rays (the pipeline variant; only modules built with SUNSHADE_RAY_QUERY can).
const bool SHADOWS_ON = VARIANT_SHADOWS == SHADOWS_RAY;
// Whether it looks the sun up in its shadow map (disk lights and the sky are then unoccluded).
const bool SHADOWS_MAP_ON = VARIANT_SHADOWS == SHADOWS_MAP;

// The sun's and the first disks' visible fractions from their maps, found by irradiance_visible and reused for the
// specular part.
float sun_map_fraction = 1.0;
// The sun's visible fraction from the shadow rays' located grid, found by irradiance_visible: the specular part
// casts its lobe samples' rays only where it is strictly between 0 and 1 (see irradiance_and_sun_fraction).
float sun_ray_fraction = 1.0;
float disk_map_fraction[MAX_DISK_MAPS] = float[](1.0, 1.0, 1.0, 1.0);
// Bit i: the rays of disk light i (the first 32) proven clear by irradiance_visible (disk_rays_proven_clear): its
// lobe's samples then cast none, every one of them getting through.
uint disk_rays_clear = 0u;

#include "sky_lune.glsl"
#include "lights/sky.glsl"

// Irradiance [W/m^2] per channel from the visible part of every light (which, and their models: the pipeline
// variant): each light's exact unoccluded irradiance times its visible fraction (a single ray for a delta sun and
// a small-source disk); every fraction is 1 without shadows.
vec3 irradiance_visible(Frame p) {
    vec3 position = p.position;
    vec3 normal = p.normal;
    uint k = lights.sampling.y;
    vec3 e = vec3(0.0);
    if (VARIANT_SUN != LIGHT_ABSENT && lights.sun.irradiance.w != 0.0) {
        vec3 l = lights.sun.direction.xyz;
        float n_dot_l = dot(normal, l);
        float delta = lights.sun.direction.w;
        vec3 unoccluded;
        if (VARIANT_SUN == SUN_DELTA) {
            unoccluded = sun_irradiance_delta(lights.sun.irradiance.rgb, n_dot_l);
        } else {
            unoccluded = sun_irradiance_disk(lights.sun.irradiance.rgb, n_dot_l, delta);
        }
        float v = 1.0;
        if (SHADOWS_ON && any(greaterThan(unoccluded, vec3(0.0)))) {
            if (VARIANT_SUN == SUN_DELTA) {
                v = sun_visible_along(p.shadow_origin, normal, l) ? 1.0 : 0.0;
            } else {
                // By slices where asked and the shader walks the BVH itself (slices.glsl; `4 k^2` rows, as
                // visibility::slice_rows), or as their passes took them before this one where the frame could not
                // (gpu::slice_passes); the grid where they cannot be taken.
                v = -1.0;
#ifdef SUNSHADE_SLICES
                if (VARIANT_VISIBILITY == VISIBILITY_SLICES) {
                    v = (lights.light_rows.w & READ_SUN) != 0u
                        ? PASSED_FRACTION(ROWS_OF_SUN)
                        : sun_visible_fraction_sliced(p.shadow_origin, normal, l, delta, 4u * k * k);
                }
#endif
                if (v < 0.0) {
                    v = sun_visible_fraction(p.shadow_origin, k, normal, l, delta);
                }
            }
            sun_ray_fraction = v;
        }
        if (SHADOWS_MAP_ON && lights.sun_map.w != 0.0 && any(greaterThan(unoccluded, vec3(0.0)))) {
            bool pcss = VARIANT_SUN != SUN_DELTA && lights.sampling.z == 1u;
            v = sun_visible_fraction_map(p.shadow_origin, k, normal, p.face_normal, l, delta, pcss);
            sun_map_fraction = v;
        }
        e += unoccluded * v;
    }
    for (uint i = 0u; VARIANT_DISKS != LIGHT_ABSENT && i < lights.counts.x; ++i) {
        DiskGpu d = lights.disks[i];
        float omega = VARIANT_DISKS == DISKS_SMALL_SOURCE
            ? disk_projected_solid_angle_small_source(position, normal, d.center_radius.xyz, d.direction.xyz, d.center_radius.w)
            : disk_projected_solid_angle(position, normal, d.center_radius.xyz, d.direction.xyz, d.center_radius.w);
        float v = 1.0;
        if (SHADOWS_ON && omega > 0.0) {
            if (VARIANT_DISKS == DISKS_SMALL_SOURCE) {
                v = visible_to(p.shadow_origin, d.center_radius.xyz) ? 1.0 : 0.0;
            } else {
                // By slices where asked and the shader walks the BVH itself, or by their passes, as the sun's.
                v = -1.0;
#ifdef SUNSHADE_SLICES
                if (VARIANT_VISIBILITY == VISIBILITY_SLICES) {
                    v = (lights.light_rows.w & READ_DISKS) != 0u
                        ? PASSED_FRACTION(ROWS_OF_DISK + i)
                        : disk_visible_fraction_sliced(p.shadow_origin, normal, d.center_radius.xyz, d.direction.xyz,
                                                       d.center_radius.w, 4u * k * k);
                }
#endif
                if (v < 0.0) {
                    uint gathered = disk_rays_gather(p.shadow_origin, position, normal, d.center_radius.xyz,
                                                     d.direction.xyz, d.center_radius.w);
                    if (gathered == DISK_CONE_CLEAR) {
                        v = 1.0;
                        disk_rays_clear |= i < 32u ? 1u << i : 0u;
                    } else {
                        v = disk_visible_fraction(p.shadow_origin, k, position, normal, d.center_radius.xyz,
                                                  d.direction.xyz, d.center_radius.w, gathered == DISK_CONE_LIST);
                    }
                }
            }
        }
        if (SHADOWS_MAP_ON && i < MAX_DISK_MAPS && lights.disk_map[i].w > 0.0 && omega > 0.0) {
            bool pcss = VARIANT_DISKS != DISKS_SMALL_SOURCE && lights.sampling.z == 1u;
            v = disk_visible_fraction_map(i, p.shadow_origin, k, position, normal, p.face_normal, d.center_radius.xyz,
                d.direction.xyz, d.center_radius.w, pcss);
            disk_map_fraction[i] = v;
        }
        omega = omega * v;
        e += d.radiance.rgb * omega;
    }
    if (VARIANT_SKY != LIGHT_ABSENT && lights.sky.w != 0.0) {
        float v = 1.0;
        if (SHADOWS_ON && normal.y > -1.0) {
            // By the slices the sky's passes took before this one, where they did (gpu::slice_passes).
            v = -1.0;
#ifdef SUNSHADE_SLICES
            if ((lights.light_rows.w & READ_SKY) != 0u) {
                v = PASSED_FRACTION(ROWS_OF_SKY);
            }
#endif
            if (v < 0.0) {
                v = sky_visible_fraction(p.shadow_origin, k, normal);
            }
        }
        e += sky_irradiance(lights.sky.rgb, normal.y) * v;
    }
    return e;
}

// Outgoing radiance [W/(m^2 sr)] per channel from the visible part of each light. `p.normal` is unit (or 0) on
// the side being seen.
vec3 radiance_out(MaterialGpu material, Frame p) {
    // An undefined (zero) normal reflects nothing: n.l = 0 would otherwise read as a surface edge-on to every light.
    if (dot(p.normal, p.normal) == 0.0) {
        return vec3(0.0);
    }
    vec3 radiance = lambert_brdf(material.kd.rgb) * irradiance_visible(p);
    if (VARIANT_BRDF == BRDF_LAMBERT) {
        return radiance;
    }
    vec3 specular = vec3(0.0);
    if (VARIANT_SUN != LIGHT_ABSENT && lights.sun.irradiance.w != 0.0) {
        vec3 l = lights.sun.direction.xyz;
        if (VARIANT_SUN == SUN_DELTA) {
            vec3 factor = specular_lobe_rgb(material, p, l) * max(dot(p.normal, l), 0.0);
            if (SHADOWS_ON && any(greaterThan(factor, vec3(0.0))) && !sun_visible_along(p.shadow_origin, p.normal, l)) {
                factor = vec3(0.0);
            }
            if (SHADOWS_MAP_ON) {
                factor *= sun_map_fraction;
            }
            specular += factor * lights.sun.irradiance.rgb;
        } else {
            float delta = lights.sun.direction.w;
            float s = sin(0.5 * delta);
            float radius = tan(0.5 * delta);
            // The lobe's samples cast rays only in the sun's penumbra (see the Rust), which a first draw leaves to
            // the second (its pixels' fractions are exactly 0 or 1).
            bool penumbra = VARIANT_PENUMBRAE == PENUMBRAE_HERE && sun_ray_fraction > 0.0 && sun_ray_fraction < 1.0;
            SegmentSums sums = segment_lobe_integral_visible(material, p, l, -l, radius, pc.sun_samples,
                SHADOWS_ON && penumbra ? RAYS_ALONG : RAYS_NONE);
            vec3 integral = normalized_lobe_integral(sums, sun_projected_solid_angle_above(dot(p.normal, l), delta));
            if (SHADOWS_ON && sun_ray_fraction == 0.0) {
                integral = vec3(0.0);
            }
            // With the map, the lobe is scaled by the disk's visible fraction (an approximation: exact where the
            // sun is wholly visible or wholly hidden).
            if (SHADOWS_MAP_ON) {
                integral *= sun_map_fraction;
            }
            specular += integral * lights.sun.irradiance.rgb / (PI * s * s);
        }
    }
    for (uint i = 0u; VARIANT_DISKS != LIGHT_ABSENT && i < lights.counts.x; ++i) {
        DiskGpu d = lights.disks[i];
        vec3 integral;
        if (VARIANT_DISKS == DISKS_SMALL_SOURCE) {
            vec3 to_center = safe_normalize(d.center_radius.xyz - p.position);
            float omega = disk_projected_solid_angle_small_source(p.position, p.normal, d.center_radius.xyz, d.direction.xyz, d.center_radius.w);
            integral = specular_lobe_rgb(material, p, to_center) * omega;
            if (SHADOWS_ON && any(greaterThan(integral, vec3(0.0))) && !visible_to(p.shadow_origin, d.center_radius.xyz)) {
                integral = vec3(0.0);
            }
        } else {
            // The grid's sum as it is (see disk_lobe_integral in the Rust); no rays where they are proven clear.
            bool clear = i < 32u && (disk_rays_clear & (1u << i)) != 0u;
            integral = segment_lobe_integral_visible(material, p, d.center_radius.xyz - p.position, d.direction.xyz,
                d.center_radius.w, pc.lobe_samples, SHADOWS_ON && !clear ? RAYS_TO_POINT : RAYS_NONE).lobe;
        }
        if (SHADOWS_MAP_ON && i < MAX_DISK_MAPS) {
            integral *= disk_map_fraction[i];
        }
        specular += integral * d.radiance.rgb;
    }
    if (VARIANT_SKY != LIGHT_ABSENT && lights.sky.w != 0.0) {
        specular += sky_lobe_integral_visible(material, p, pc.lobe_samples, SHADOWS_ON) * lights.sky.rgb;
    }
    return radiance + material.ks.rgb * specular;
}

#endif

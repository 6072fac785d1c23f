// Outgoing radiance at a surface point: every light's irradiance and its specular lobe, summed. Mirrors
// src/shading/shade.rs name for name: the same formulas and the same deterministic sample points, so that the GPU
// and the CPU reference differ only by rounding.
#ifndef SUNSHADE_SHADE_GLSL
#define SUNSHADE_SHADE_GLSL

#include "bindings.glsl"
#include "brdf.glsl"
#include "lights/sun.glsl"
#include "lights/disk.glsl"
#include "lights/sky.glsl"

// Irradiance [W/m^2] per channel from the visible part of every light (which, and their models: the pipeline
// variant), in the order of the Rust's Lights::iter: each light's exact unoccluded irradiance times its visible
// fraction (a single ray for a delta sun and a small-source disk); every fraction is 1 without shadows. One loop
// over the lights (light j: the sun at 0, disk light j - 1 from 1, the sky after them), each light's term and
// then, where it leaves one, its located grid, so that the grid and its rays are compiled once (LightTerm).
vec3 irradiance_visible(Frame p) {
    vec3 e = vec3(0.0);
    bool sun = VARIANT_SUN != LIGHT_ABSENT && lights.sun.irradiance.w != 0.0;
    uint disks = VARIANT_DISKS != LIGHT_ABSENT ? lights.counts.x : 0u;
    bool sky = VARIANT_SKY != LIGHT_ABSENT && lights.sky.w != 0.0;
    for (uint j = sun ? 0u : 1u; j < (sky ? disks + 2u : disks + 1u); ++j) {
        // Each call behind its kind's constant, so that a variant compiles only its lights' terms.
        LightTerm term = LightTerm(vec3(0.0), 0.0, false, 1.0, 0u, NO_GRID_LIGHT);
        if (VARIANT_SUN != LIGHT_ABSENT && j == 0u) {
            term = sun_term(p);
        } else if (VARIANT_DISKS != LIGHT_ABSENT && j <= disks) {
            term = disk_term(j - 1u, p);
        } else if (VARIANT_SKY != LIGHT_ABSENT) {
            term = sky_term(p);
        }
        if (SHADOWS_ON && term.v < 0.0) {
            term.v = grid_fraction(p.shadow_origin, term.k, term.grid);
        }
        if (SHADOWS_ON && j == 0u) {
            sun_ray_fraction = term.v;
        }
        e += term.by_omega ? term.e * (term.omega * term.v) : term.e * term.v;
    }
    return e;
}

// Outgoing radiance [W/(m^2 sr)] per channel from the visible part of each light: kd/pi E + ks (sum of the lights'
// specular terms). `p.normal` is unit (or 0) on the side being seen.
vec3 radiance_out(MaterialGpu material, Frame p) {
    // An undefined (zero) normal reflects nothing: n.l = 0 would otherwise read as a surface edge-on to every light.
    if (dot(p.normal, p.normal) == 0.0) {
        return vec3(0.0);
    }
    vec3 radiance = lambert_brdf(material.kd.rgb) * irradiance_visible(p);
    switch (VARIANT_BRDF) {
    case BRDF_LAMBERT:
        return radiance;
    case BRDF_PHONG:
    case BRDF_BLINN_PHONG:
    case BRDF_WARD:
    case BRDF_MEASURED:
    case BRDF_GLTF:
        break;
    }
    // The sun's and the disk lights' terms in one loop, as irradiance_visible's (light j: the sun at 0, disk light
    // j - 1 from 1), each light's lobe integrated by one call of segment_lobe_integral_visible (SegmentAsk).
    vec3 specular = vec3(0.0);
    bool sun = VARIANT_SUN != LIGHT_ABSENT && lights.sun.irradiance.w != 0.0;
    uint disks = VARIANT_DISKS != LIGHT_ABSENT ? lights.counts.x : 0u;
    for (uint j = sun ? 0u : 1u; j < disks + 1u; ++j) {
        bool sun_here = VARIANT_SUN != LIGHT_ABSENT && j == 0u;
        SegmentAsk segment = NO_SEGMENT;
        if (sun_here) {
            segment = sun_specular_segment();
        } else if (VARIANT_DISKS != LIGHT_ABSENT) {
            segment = disk_specular_segment(j - 1u, p);
        }
        SegmentSums sums = NO_SEGMENT_SUMS;
        // Only a disk sun and exact disk lights integrate a segment: the others' variants compile none.
        if ((VARIANT_SUN == SUN_DISK || VARIANT_DISKS == DISKS_EXACT) && segment.wanted) {
            sums = segment_lobe_integral_visible(material, p, segment.q, segment.d, segment.radius,
                                                 segment.per_axis, segment.rays);
        }
        if (sun_here) {
            specular += sun_specular_visible(material, p, sums);
        } else if (VARIANT_DISKS != LIGHT_ABSENT) {
            specular += disk_specular_visible(j - 1u, material, p, sums);
        }
    }
    if (VARIANT_SKY != LIGHT_ABSENT && lights.sky.w != 0.0) {
        specular += sky_specular_visible(material, p);
    }
    return radiance + material.ks.rgb * specular;
}

#endif

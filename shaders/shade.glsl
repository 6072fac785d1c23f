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
// fraction (a single ray for a delta sun and a small-source disk); every fraction is 1 without shadows.
vec3 irradiance_visible(Frame p) {
    vec3 e = vec3(0.0);
    if (VARIANT_SUN != LIGHT_ABSENT && lights.sun.irradiance.w != 0.0) {
        e += sun_irradiance_visible(p);
    }
    for (uint i = 0u; VARIANT_DISKS != LIGHT_ABSENT && i < lights.counts.x; ++i) {
        e += disk_irradiance_visible(i, p);
    }
    if (VARIANT_SKY != LIGHT_ABSENT && lights.sky.w != 0.0) {
        e += sky_irradiance_visible(p);
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
    vec3 specular = vec3(0.0);
    if (VARIANT_SUN != LIGHT_ABSENT && lights.sun.irradiance.w != 0.0) {
        specular += sun_specular_visible(material, p);
    }
    for (uint i = 0u; VARIANT_DISKS != LIGHT_ABSENT && i < lights.counts.x; ++i) {
        specular += disk_specular_visible(i, material, p);
    }
    if (VARIANT_SKY != LIGHT_ABSENT && lights.sky.w != 0.0) {
        specular += sky_specular_visible(material, p);
    }
    return radiance + material.ks.rgb * specular;
}

#endif

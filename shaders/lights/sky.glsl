// The overcast sky in f32: the irradiance it gives a tilted surface, its visible fraction, and the specular lobe
// integrated over it, and its two terms in a shading point's sum (sky_term, sky_specular_visible).
// Mirrors src/shading/lights/sky.rs name for name (see it for the derivations).
// Units: radians, steradians, W/m^2 (irradiance), W/(m^2 sr) (radiance).
#ifndef SUNSHADE_LIGHTS_SKY_GLSL
#define SUNSHADE_LIGHTS_SKY_GLSL

#include "math.glsl"
#include "visibility.glsl"
#include "sky_lune.glsl"
#include "lobe.glsl"

// Irradiance [W/m^2] from a uniform overcast sky of radiance L0: E = pi L0 (1 + cos t)/2.
vec3 sky_irradiance(vec3 radiance, float n_dot_up) {
    return PI * radiance * (0.5 * (1.0 + n_dot_up));
}

// The visible fraction of the sky (directions with y > 0), cosine-weighted, from a point with normal n: -1, the
// located grid over the sky's lune (`grid`) to find it (irradiance_visible; sky_visible_fraction in the Rust).
float sky_visible_fraction(vec3 n, out VisibilityLight grid) {
    grid = sky_lune(n);
    return -1.0;
}

// integral of lobe (n.w)+ over the whole hemisphere about n, per unit radiance: a stratified grid through the
// lobe's inverse CDF, each sample weighted by lobe/pdf, shadow rays for the samples above the horizontal only
// (see the Rust).
vec3 sky_lobe_hemisphere_grid(MaterialGpu m, Frame p, uint asked_per_axis, bool shadowed) {
    vec3 axis = sampling_axis(p);
    vec3 t = orthonormal_to(axis);
    vec3 b = cross(axis, t);
    uint per_axis = sky_grid_per_axis(asked_per_axis);
    float k = float(per_axis);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < per_axis; ++i) {
        float xi1 = (float(i) + 0.5) / k;
        for (uint j = 0u; j < per_axis; ++j) {
            float xi2 = (float(j) + 0.5) / k;
            float phi = 2.0 * PI * xi2;
            vec3 omega;
            vec3 value = lobe_sample(m, p, axis, t, b, xi1, phi, omega);
            // A sample that contributes casts its shadow ray; adding the 0 of a blocked one is skipped.
            if (!any(notEqual(value, vec3(0.0))) || !shadowed || omega.y <= 0.0
                || visible_along(p.shadow_origin, omega)) {
                sum += value;
            }
        }
    }
    return sum / (k * k);
}

// integral of lobe (n.w)+ over the sky (the hemisphere above the horizontal, per unit radiance): the hemisphere's
// inverse-CDF grid less the lower lune while the lobe's peak is above the horizontal, the upper lune's own grid
// once it is below, a blend between; at least 0 where the lobe cannot be negative (see the Rust).
vec3 sky_lobe_integral_visible(MaterialGpu m, Frame p, uint per_axis, bool shadowed) {
    float s = sky_lune_blend(m, p);
    vec3 direct = s > 0.0 ? sky_lobe_in_lune(m, p, per_axis, LUNE_ABOVE, shadowed) : vec3(0.0);
    vec3 by_difference = vec3(0.0);
    if (s < 1.0) {
        by_difference = sky_lobe_hemisphere_grid(m, p, per_axis, shadowed)
            - sky_lobe_in_lune(m, p, per_axis, LUNE_BELOW, false);
        // At least 0 where the lobe cannot be negative (Brdf::lobe_can_be_negative).
        switch (VARIANT_BRDF) {
        case BRDF_GLTF:
            break;
        case BRDF_LAMBERT:
        case BRDF_PHONG:
        case BRDF_BLINN_PHONG:
        case BRDF_WARD:
        case BRDF_MEASURED:
            by_difference = max(by_difference, vec3(0.0));
            break;
        }
    }
    return (1.0 - s) * by_difference + s * direct;
}

// The sky's term of the irradiance [W/m^2] per channel from its visible part, pi L0 (1 + cos t)/2 v
// (sky_irradiance_visible in the Rust), v left to irradiance_visible's grid where it needs one.
LightTerm sky_term(Frame p) {
    vec3 normal = p.normal;
    LightTerm term = LightTerm(sky_irradiance(lights.sky.rgb, normal.y), 0.0, false, 1.0, lights.sampling.y,
                               NO_GRID_LIGHT);
    if (SHADOWS_ON && normal.y > -1.0) {
        // By the slices the sky's passes took before this one, where they did (gpu::slice_passes).
        term.v = -1.0;
#ifdef SUNSHADE_SLICES
        if ((lights.light_rows.w & READ_SKY) != 0u) {
            term.v = PASSED_FRACTION(ROWS_OF_SKY);
        }
#endif
        if (term.v < 0.0) {
            term.v = sky_visible_fraction(normal, term.grid);
        }
    }
    return term;
}

// The sky's specular term [W/(m^2 sr)] per channel, to be scaled by ks (each lobe sample with its shadow ray).
vec3 sky_specular_visible(MaterialGpu material, Frame p) {
    return sky_lobe_integral_visible(material, p, pc.lobe_samples, SHADOWS_ON) * lights.sky.rgb;
}

#endif

// The sun in f32: its irradiance (a delta light, and a disk cut by the horizon), its projected solid angle above
// the horizon, the visible fraction of its disk, and its two terms in a shading point's sum
// (sun_term, sun_specular_visible). Mirrors src/shading/lights/sun.rs name for name (the Rust is the
// specification; its doc comments derive the formulas and say where precision is at stake).
// Units: radians, steradians, W/m^2 (irradiance), W/(m^2 sr) (radiance).
#ifndef SUNSHADE_LIGHTS_SUN_GLSL
#define SUNSHADE_LIGHTS_SUN_GLSL

#include "math.glsl"
#include "visibility.glsl"
#include "shadow_map.glsl"
#include "lobe.glsl"

// Irradiance [W/m^2] from the sun as a direction (delta light): E = E_perp * max(0, n.l).
vec3 sun_irradiance_delta(vec3 irradiance_normal, float n_dot_l) {
    return irradiance_normal * max(n_dot_l, 0.0);
}

// atan(t) - t without cancellation: the series for |t| < 0.5 (14 terms: below f32 rounding), else the difference.
float atan_minus_identity(float t) {
    if (abs(t) >= 0.5) {
        return atan_accurate(t) - t;
    }
    float t2 = t * t;
    float sum = 0.0;
    for (int k = 14; k >= 1; --k) {
        float sign = (k % 2 == 0) ? 1.0 : -1.0;
        sum = sum * t2 + sign / float(2 * k + 1);
    }
    return sum * t2 * t;
}

// The disk sun's irradiance over its normal irradiance E_perp (angular diameter `angular_diameter`, the angle theta
// from the normal): cos theta while the whole disk is above the horizon, 0 below, the cap's share while it sets
// (see the Rust's sun_irradiance_disk for the derivation and the rewriting that avoids the cancellation of two
// terms of ~1/sigma).
float sun_disk_factor(float cos_theta, float angular_diameter) {
    float s = sin(0.5 * angular_diameter);
    float c = cos(0.5 * angular_diameter);
    if (cos_theta >= s) {
        return cos_theta;
    }
    if (cos_theta <= -s) {
        return 0.0;
    }
    float sin_theta = sqrt((1.0 - cos_theta) * (1.0 + cos_theta));
    float k = clamp((c * cos_theta) / (s * sin_theta), -1.0, 1.0);
    float sin_phi0 = sqrt((1.0 - k) * (1.0 + k));
    float pi_minus_phi0 = atan2_accurate(sin_phi0, -k);
    float t = s * sin_theta * sin_phi0 / c;
    float projected = s * s * (cos_theta * pi_minus_phi0 + t) + atan_minus_identity(t);
    return projected / (PI * s * s);
}

// Irradiance [W/m^2] from the sun as a disk of angular diameter `angular_diameter`, exact also while it sets.
vec3 sun_irradiance_disk(vec3 irradiance_normal, float cos_theta, float angular_diameter) {
    return irradiance_normal * sun_disk_factor(cos_theta, angular_diameter);
}

// The projected solid angle [sr] of the sun's cap above the horizon: pi sin^2(delta/2) E / E_perp.
float sun_projected_solid_angle_above(float n_dot_l, float angular_diameter) {
    float s = sin(0.5 * angular_diameter);
    return PI * s * s * sun_disk_factor(n_dot_l, angular_diameter);
}

// The cosine-weighted visible fraction of the sun's disk (direction l, angular diameter [rad]), or -1 where the
// located grid over `grid` is to find it (irradiance_visible). Where the frame has the sun's cells, their
// classification first: a cone that misses every triangle of its cell sees the whole sun (1, what every ray of the
// grid would find), one within an opaque triangle none of it (0, where the whole disk is above the surface's
// horizon so that the grid's weights are all positive); only a penumbra casts the grid's rays, against the cell's
// triangles.
float sun_visible_fraction(vec3 origin, vec3 n, vec3 l, float angular_diameter, out VisibilityLight grid) {
    grid = NO_GRID_LIGHT;
    uint kind = GRID_LIGHT_SUN;
#ifdef SUNSHADE_SHADOW_RAYS
    float sin_sigma = sin(0.5 * angular_diameter);
    uint cone = sun_cone_class(origin, n, l, sin_sigma);
    if (cone == SUN_CONE_MISSES) {
        return 1.0;
    }
    if (cone == SUN_CONE_COVERED && dot(n, l) > sin_sigma + SUN_CONE_MARGIN) {
        return 0.0;
    }
    kind = cone == SUN_CONE_UNKNOWN ? GRID_LIGHT_SUN : GRID_LIGHT_SUN_CELLS;
    // A penumbra's rays (the grid's here, the lobe's in radiance_out) test only the triangles its cone can meet,
    // where they are few: also past the cell's bound on its rays, where they would otherwise walk the tree.
    if (VARIANT_PENUMBRAE != PENUMBRAE_LATER && (cone == SUN_CONE_PARTIAL || sun_cells_classify(origin))) {
        sun_cone_list(origin, n, l, sin_sigma);
        kind = sun_listed_valid ? GRID_LIGHT_SUN_CELLS : kind;
    }
#endif
    vec3 t = orthonormal_to(l);
    grid = VisibilityLight(kind, vec3(0.0), n, l, vec3(0.0), t, cross(l, t), tan(0.5 * angular_diameter), 0.0);
    return -1.0;
}

// The disk sun's sun_disk_factor at the shaded point, found by sun_term and reused by
// sun_specular_visible for the cap's projected solid angle (sun_projected_solid_angle_above: pi sin^2(delta/2)
// times it), so that the driver, which inlines every call, compiles the formula once.
float sun_disk_factor_here = 0.0;
// The sun's visible fraction from the shadow rays' located grid, found by irradiance_visible: the specular
// term casts its lobe samples' rays only where it is strictly between 0 and 1 (see sun_specular_visible).
float sun_ray_fraction = 1.0;
// The sun's visible fraction from its shadow map, found by sun_term and reused by the specular term.
float sun_map_fraction = 1.0;

// The sun's term of the irradiance [W/m^2] per channel from its visible part, E v (the delta or the disk model, the
// pipeline variant's; sun_irradiance_visible in the Rust), v left to irradiance_visible's grid where the sun needs
// one; keeps v in sun_map_fraction (maps) for sun_specular_visible (irradiance_visible keeps the rays' in
// sun_ray_fraction).
LightTerm sun_term(Frame p) {
    vec3 normal = p.normal;
    uint k = lights.sampling.y;
    vec3 l = lights.sun.direction.xyz;
    float n_dot_l = dot(normal, l);
    float delta = lights.sun.direction.w;
    vec3 unoccluded;
    if (VARIANT_SUN == SUN_DELTA) {
        unoccluded = sun_irradiance_delta(lights.sun.irradiance.rgb, n_dot_l);
    } else {
        // sun_irradiance_disk, its factor kept for the specular term.
        sun_disk_factor_here = sun_disk_factor(n_dot_l, delta);
        unoccluded = lights.sun.irradiance.rgb * sun_disk_factor_here;
    }
    LightTerm term = LightTerm(unoccluded, 0.0, false, 1.0, k, NO_GRID_LIGHT);
    if (SHADOWS_ON && any(greaterThan(unoccluded, vec3(0.0)))) {
#ifdef SUNSHADE_SHADOW_RAYS
        sun_cells_at(p.shadow_origin);
#endif
        if (VARIANT_SUN == SUN_DELTA) {
            term.v = sun_visible_along(p.shadow_origin, normal, l) ? 1.0 : 0.0;
        } else {
            // By slices where asked and the shader walks the BVH itself (slices.glsl; `4 k^2` rows, as
            // visibility::slice_rows), or as their passes took them before this one where the frame could not
            // (gpu::slice_passes); the grid where they cannot be taken.
            term.v = -1.0;
#ifdef SUNSHADE_SLICES
            if (VARIANT_VISIBILITY == VISIBILITY_SLICES) {
                term.v = (lights.light_rows.w & READ_SUN) != 0u
                    ? PASSED_FRACTION(ROWS_OF_SUN)
                    : sun_visible_fraction_sliced(p.shadow_origin, normal, l, delta, 4u * k * k);
            }
#endif
            if (term.v < 0.0) {
                term.v = sun_visible_fraction(p.shadow_origin, normal, l, delta, term.grid);
            }
        }
    }
    if (SHADOWS_MAP_ON && lights.sun_map.w != 0.0 && any(greaterThan(unoccluded, vec3(0.0)))) {
        bool pcss = VARIANT_SUN != SUN_DELTA && lights.sampling.z == 1u;
        term.v = sun_visible_fraction_map(p.shadow_origin, k, normal, p.face_normal, l, delta, pcss);
        sun_map_fraction = term.v;
    }
    return term;
}

// The segment the disk sun's specular term integrates the lobe over (its cap, as a disk of radius tan(delta/2) one
// unit away along l), for radiance_out's one call of segment_lobe_integral_visible; none for a delta sun.
SegmentAsk sun_specular_segment() {
    if (VARIANT_SUN == SUN_DELTA) {
        return NO_SEGMENT;
    }
    vec3 l = lights.sun.direction.xyz;
    float delta = lights.sun.direction.w;
    float radius = tan(0.5 * delta);
    // The lobe's samples cast rays only in the sun's penumbra (see the Rust), which a first draw leaves to the
    // second (its pixels' fractions are exactly 0 or 1).
    bool penumbra = VARIANT_PENUMBRAE != PENUMBRAE_LATER && sun_ray_fraction > 0.0 && sun_ray_fraction < 1.0;
    return SegmentAsk(true, l, -l, radius, pc.sun_samples, SHADOWS_ON && penumbra ? RAYS_ALONG : RAYS_NONE);
}

// The sun's specular term [W/(m^2 sr)] per channel, to be scaled by ks: the lobe at its centre (delta) or
// integrated over its disk (`sums`, sun_specular_segment's), visible part only (see the Rust).
vec3 sun_specular_visible(MaterialGpu material, Frame p, SegmentSums sums) {
    vec3 l = lights.sun.direction.xyz;
    if (VARIANT_SUN == SUN_DELTA) {
        vec3 factor = specular_lobe_rgb(material, p, l) * max(dot(p.normal, l), 0.0);
        if (SHADOWS_ON && any(greaterThan(factor, vec3(0.0))) && !sun_visible_along(p.shadow_origin, p.normal, l)) {
            factor = vec3(0.0);
        }
        if (SHADOWS_MAP_ON) {
            factor *= sun_map_fraction;
        }
        return factor * lights.sun.irradiance.rgb;
    }
    float delta = lights.sun.direction.w;
    float s = sin(0.5 * delta);
    // sun_projected_solid_angle_above(dot(p.normal, l), delta), from the factor sun_term found.
    vec3 integral = normalized_lobe_integral(sums, PI * s * s * sun_disk_factor_here);
    if (SHADOWS_ON && sun_ray_fraction == 0.0) {
        integral = vec3(0.0);
    }
    // With the map, the lobe is scaled by the disk's visible fraction (an approximation: exact where the sun is
    // wholly visible or wholly hidden).
    if (SHADOWS_MAP_ON) {
        integral *= sun_map_fraction;
    }
    return integral * lights.sun.irradiance.rgb / (PI * s * s);
}

#endif

// The sky's lobe integrals near the horizon: the lune of the hemisphere the horizontal splits off, its grid graded
// across the edge, the blend between the hemisphere's grid and the lune's. Mirrors src/shading/sky_lune.rs name for
// name (see it for the derivations). A part of shade.glsl, included by it in place: it uses the lobe integrals
// and the graded grids defined before it there.
#ifndef SUNSHADE_SKY_LUNE_GLSL
#define SUNSHADE_SKY_LUNE_GLSL

// Which lune of the hemisphere the horizontal splits off (see sky_lune.rs).
const uint LUNE_BELOW = 0u;
const uint LUNE_ABOVE = 1u;
// How much narrower than a lobe's tail the lune grid is graded across its edge (sky_lune::SKY_TAIL_GRADING).
const float SKY_TAIL_GRADING = 8.0;

// The least n.v at which grazing_narrowing narrows a lobe in proportion (sky_lune::GRAZING_FLOOR).
const float GRAZING_FLOOR = 0.05;

// How much narrower than its width an isotropic Ward lobe is along the unit direction u at its peak: 1 in the
// plane of incidence, n.v across it (at least GRAZING_FLOOR); 1 for every other lobe (see sky_lune.rs).
// 1 - (n.v)^2 = |n x v|^2, so no normalization where n x v is rounding.
float grazing_narrowing(MaterialGpu m, Frame p, vec3 u) {
    // Every kind by name, so that a new one says whether its lobe narrows.
    bool isotropic_ward = false;
    switch (VARIANT_BRDF) {
    case BRDF_WARD:
        isotropic_ward = m.params.x == m.params.y;
        break;
    case BRDF_LAMBERT:
    case BRDF_PHONG:
    case BRDF_BLINN_PHONG:
    case BRDF_MEASURED:
    case BRDF_GLTF:
        isotropic_ward = false;
        break;
    }
    if (!isotropic_ward) {
        return 1.0;
    }
    vec3 nxv = cross(p.normal, p.to_viewer);
    float sin2 = dot(nxv, nxv);
    float scale = min((1.0 - GRAZING_FLOOR * GRAZING_FLOOR) / max(sin2, 1e-30), 1.0);
    float along = dot(nxv, u);
    return sqrt(max(1.0 - scale * along * along, 0.0));
}

// Up's part across the normal n (xyz: up - (n.up) n = sin(t) b) and the surface's tilt t from up (w), by atan2 of
// that part's length and n.up (see the Rust).
vec4 up_across(vec3 n) {
    vec3 across = vec3(0.0, 1.0, 0.0) - n.y * n;
    return vec4(across, atan2_accurate(length(across), n.y));
}

// The lobe at the sky's direction nearest its peak, relative to the peak, under which sky_beyond_lobe gives the
// upper lune's grid all the weight (sky_lune::SKY_REACH).
const float SKY_REACH = 1e-2;

// How surely the sky lies beyond the lobe (0 to 1): 1 - q/SKY_REACH, q the lobe at the sky's direction nearest its
// peak r over the lobe at r; 0 while r is in the sky (see sky_lune.rs).
float sky_beyond_lobe(MaterialGpu m, Frame p, vec3 r) {
    if (!(r.y < 0.0)) {
        return 0.0;
    }
    vec3 n = p.normal;
    vec3 flat_r = vec3(r.x, 0.0, r.z);
    vec3 nearest;
    if (dot(n, flat_r) > 0.0) {
        nearest = normalize(flat_r);
    } else {
        vec3 apex = cross(vec3(0.0, 1.0, 0.0), n);
        if (dot(apex, apex) == 0.0) {
            return 1.0;
        }
        apex = normalize(apex);
        nearest = dot(apex, r) < 0.0 ? -apex : apex;
    }
    float peak = specular_lobe(m, p, r);
    float q = peak > 0.0 ? specular_lobe(m, p, nearest) / peak : 0.0;
    return clamp(1.0 - q / SKY_REACH, 0.0, 1.0);
}

// How far the sky's lobe integral is taken over the upper lune directly rather than as the hemisphere's less the
// lower lune's: 0 with the lobe's peak (the mirror of the viewer) above the horizontal by more than a quarter of
// its width (at most 1 rad), 1 below by more than that, linear between, or 1 - q/SKY_REACH where that is more
// (sky_beyond_lobe), scaled by the tilt from up over that quarter width (at most 1; see sky_lune.rs).
float sky_lune_blend(MaterialGpu m, Frame p) {
    vec3 n = p.normal;
    vec3 r = mirror(p.to_viewer, n);
    float quarter = 0.25 * min(lobe_width(m), 1.0);
    float tilt = up_across(n).w;
    float below = 1.0;
    switch (VARIANT_BRDF) {
    case BRDF_MEASURED:
        // A table takes the upper lune wherever the surface is tilted (see the Rust).
        below = 1.0;
        break;
    case BRDF_LAMBERT:
    case BRDF_PHONG:
    case BRDF_BLINN_PHONG:
    case BRDF_WARD:
    case BRDF_GLTF:
        below = max(clamp(0.5 - r.y / (2.0 * quarter), 0.0, 1.0), sky_beyond_lobe(m, p, r));
        break;
    }
    return below * min(tilt / quarter, 1.0);
}

// integral of lobe (n.w)+ over one lune of the hemisphere (LUNE_BELOW or LUNE_ABOVE the horizontal), per unit
// radiance: a midpoint grid in lune coordinates w = cos(lambda) (cos(psi) n + sin(psi) b) + sin(lambda) e, graded
// about the lobe's peak; the upper lune's samples cast shadow rays where `shadowed` (see sky_lune.rs).
vec3 sky_lobe_in_lune(MaterialGpu m, Frame p, uint per_axis, uint lune, bool shadowed) {
    vec3 n = p.normal;
    vec4 up = up_across(n);
    vec3 across = up.xyz;
    float sin_t = length(across);
    float tilt = up.w;
    float psi_lo = lune == LUNE_BELOW ? -0.5 * PI : tilt - 0.5 * PI;
    float psi_hi = lune == LUNE_BELOW ? tilt - 0.5 * PI : 0.5 * PI;
    switch (VARIANT_BRDF) {
    case BRDF_LAMBERT:
        return vec3(0.0);
    case BRDF_PHONG:
    case BRDF_BLINN_PHONG:
    case BRDF_WARD:
    case BRDF_MEASURED:
    case BRDF_GLTF:
        break;
    }
    if (!(psi_hi > psi_lo)) {
        return vec3(0.0);
    }
    vec3 b = sin_t > 0.0 ? across / sin_t : orthonormal_to(n);
    vec3 e = cross(n, b);
    vec3 r = mirror(p.to_viewer, n);
    float psi_r = atan2_accurate(dot(r, b), dot(r, n));
    float rn = dot(r, n);
    float rb = dot(r, b);
    float lambda_r = atan2_accurate(dot(r, e), sqrt(rn * rn + rb * rb));
    float cos_lambda_r = cos(lambda_r);
    float outside = max(max(psi_r - psi_hi, psi_lo - psi_r), 0.0) * cos_lambda_r;
    // A peak beyond the lune's edge: its tail graded narrower across the edge (see sky_lune.rs).
    float width = lobe_width(m);
    float w_psi = outside > 0.0 ? width * width / (width + SKY_TAIL_GRADING * outside) : width;
    float psi_c = clamp(psi_r, psi_lo, psi_hi);
    // Each axis' direction on the sphere at the grid's centre, for a lobe narrower across the plane of incidence.
    float spc = sin(psi_c);
    float cpc = cos(psi_c);
    float slr = sin(lambda_r);
    float f_psi = grazing_narrowing(m, p, -spc * n + cpc * b);
    float f_lambda = grazing_narrowing(m, p, -slr * (cpc * n + spc * b) + cos_lambda_r * e);
    float width_psi = min(w_psi * f_psi / max(cos_lambda_r, 1e-30), 16.0 * (psi_hi - psi_lo));
    float width_lambda = min(width * f_lambda, 16.0 * PI);
    GradedAxis psi_axis = graded_axis(psi_lo, psi_hi, psi_c, width_psi);
    GradedAxis lambda_axis = graded_axis(-0.5 * PI, 0.5 * PI, lambda_r, width_lambda);
    float k = float(per_axis);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < per_axis; ++i) {
        vec2 pw = graded_point(psi_axis, (float(i) + 0.5) / k);
        float sp = sin(pw.x);
        float cp = cos(pw.x);
        for (uint j = 0u; j < per_axis; ++j) {
            vec2 lw = graded_point(lambda_axis, (float(j) + 0.5) / k);
            float sl = sin(lw.x);
            float cl = cos(lw.x);
            vec3 omega = cl * (cp * n + sp * b) + sl * e;
            float weight = cl * cl * max(cp, 0.0) * pw.y * lw.y;
            vec3 value = specular_lobe_rgb(m, p, omega) * weight;
            if (lune == LUNE_BELOW || !any(greaterThan(value, vec3(0.0))) || !shadowed
                || visible_along(p.shadow_origin, omega)) {
                sum += value;
            }
        }
    }
    return sum / (k * k);
}

#endif

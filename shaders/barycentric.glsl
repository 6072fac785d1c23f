// The perspective-correct barycentrics of a fragment. Mirrors src/cpu/barycentric.rs. Included by transform.glsl.
#ifndef SUNSHADE_BARYCENTRIC_GLSL
#define SUNSHADE_BARYCENTRIC_GLSL

#include "bindings.glsl"

// Normalised device coordinates of the centre of the pixel at window position `frag` (gl_FragCoord.xy), in f32:
// (2 frag / size) - 1, the division rounded once.
vec2 pixel_ndc(vec2 frag) {
    precise vec2 ndc = (2.0 * frag) / pc.framebuffer_size - 1.0;
    return ndc;
}

// Perspective-correct barycentrics of the pixel whose NDC is `ndc` in the triangle with clip-space vertices
// c0, c1, c2 (2D homogeneous rasterization, Olano & Greer 1997): with the vertices sheared so the pixel's ray is
// the w axis, d = (x - ndc_x w, y - ndc_y w), the weights are the 2x2 determinants b0 = d1 x d2, b1 = d2 x d0,
// b2 = d0 x d1, normalised. Inside the triangle they share one sign, so the sum does not cancel.
// Precision: an error e in a weight moves an interpolated attribute by e times its variation across the
// triangle (the weights sum to 1), not by e times its gradient times the window position as plane equations
// anchored at the window origin do. This also holds for triangles the device clipped (w < 0 vertices included).
//
// With SUNSHADE_F64_BARYCENTRICS (devices with shaderFloat64) the arithmetic is done in f64: products of f32
// values are exact there, so the weights carry ~1e-16 relative error and only the f32 interpolation that follows
// rounds. Without it, the f32 version below loses up to ~1e-5 in the weights of thin triangles (measured on
// lavapipe; docs/accuracy.md).
#ifdef SUNSHADE_F64_BARYCENTRICS
dvec3 triangle_barycentrics_exact(vec4 c0, vec4 c1, vec4 c2, vec2 ndc) {
    dvec2 n = dvec2(ndc);
    precise dvec2 d0 = dvec2(c0.xy) - n * double(c0.w);
    precise dvec2 d1 = dvec2(c1.xy) - n * double(c1.w);
    precise dvec2 d2 = dvec2(c2.xy) - n * double(c2.w);
    precise double b0 = d1.x * d2.y - d1.y * d2.x;
    precise double b1 = d2.x * d0.y - d2.y * d0.x;
    precise double b2 = d0.x * d1.y - d0.y * d1.x;
    precise double sum = b0 + b1 + b2;
    if (sum == 0.0) {
        return dvec3(1.0 / 3.0);
    }
    return dvec3(b0, b1, b2) / sum;
}
#else
vec3 triangle_barycentrics_exact(vec4 c0, vec4 c1, vec4 c2, vec2 ndc) {
    precise vec2 d0 = c0.xy - ndc * c0.w;
    precise vec2 d1 = c1.xy - ndc * c1.w;
    precise vec2 d2 = c2.xy - ndc * c2.w;
    precise float b0 = d1.x * d2.y - d1.y * d2.x;
    precise float b1 = d2.x * d0.y - d2.y * d0.x;
    precise float b2 = d0.x * d1.y - d0.y * d1.x;
    precise float sum = b0 + b1 + b2;
    if (sum == 0.0) {
        return vec3(1.0 / 3.0);
    }
    precise vec3 l = vec3(b0, b1, b2) / sum;
    return l;
}
#endif

// The barycentrics rounded to f32, for the f32 interpolation of position, normal and tangent. Texture
// coordinates use triangle_barycentrics_exact (f64 where the device has it), as the reference does.
vec3 triangle_barycentrics(vec4 c0, vec4 c1, vec4 c2, vec2 ndc) {
    return vec3(triangle_barycentrics_exact(c0, c1, c2, ndc));
}

#endif

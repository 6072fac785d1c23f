// The vertex transform (mirrored by src/cpu/transform.rs) and, from barycentric.glsl, the perspective-correct
// barycentrics of a fragment.
#ifndef SUNSHADE_TRANSFORM_GLSL
#define SUNSHADE_TRANSFORM_GLSL

#include "bindings.glsl"

// clip = M (p, 1), evaluated as ((c0 x + c1 y) + c2 z) + c3, column by column. `precise` forbids fusing a multiply
// and an add into one FMA, so each product and sum is rounded to f32 exactly as the CPU reference does it, and
// the fragment shader recomputes bit-identical clip positions.
vec4 clip_position(vec3 p) {
    precise vec4 clip = pc.clip_from_world[0] * p.x;
    clip = clip + pc.clip_from_world[1] * p.y;
    clip = clip + pc.clip_from_world[2] * p.z;
    clip = clip + pc.clip_from_world[3];
    return clip;
}

#include "barycentric.glsl"

#endif

#version 450
// World-space triangles to clip space. src/cpu/transform.rs repeats this arithmetic exactly, in f32.
#include "bindings.glsl"

layout(location = 0) in vec3 in_position; // world [m]
layout(location = 1) in vec3 in_normal;   // world, unit

layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;

void main() {
    // clip = M (p, 1), evaluated as ((c0 x + c1 y) + c2 z) + c3, column by column. `precise` forbids fusing a
    // multiply and an add into one FMA, so each product and sum is rounded to f32 exactly as the CPU does it.
    precise vec4 clip = pc.clip_from_world[0] * in_position.x;
    clip = clip + pc.clip_from_world[1] * in_position.y;
    clip = clip + pc.clip_from_world[2] * in_position.z;
    clip = clip + pc.clip_from_world[3];
    gl_Position = clip;
    v_position = in_position;
    v_normal = in_normal;
}

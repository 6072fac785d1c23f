#version 450
// World-space triangles to clip space. src/cpu/transform.rs repeats this arithmetic exactly, in f32.
#include "transform.glsl"

layout(location = 0) in vec3 in_position; // world [m]

#ifdef SUNSHADE_DEVICE_INTERPOLATION
// Only for `--interpolation device`: let the device interpolate position and normal (plane equations).
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec4 in_tangent;
layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec4 v_tangent;
#endif

void main() {
    gl_Position = clip_position(in_position);
#ifdef SUNSHADE_DEVICE_INTERPOLATION
    v_position = in_position;
    v_normal = in_normal;
    v_tangent = in_tangent;
#endif
}

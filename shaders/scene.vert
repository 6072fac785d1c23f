#version 450
// World-space triangles to clip space. src/cpu/transform.rs repeats this arithmetic exactly, in f32.
#include "transform.glsl"

layout(location = 0) in vec3 in_position; // world [m]

void main() {
    gl_Position = clip_position(in_position);
}

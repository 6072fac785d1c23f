#version 450
// Radiance of each covered pixel, linear, in W/(m^2 sr); alpha 1 marks coverage.
#include "bindings.glsl"
#include "shade.glsl"

layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;

layout(location = 0) out vec4 out_radiance;

void main() {
    MaterialGpu material = materials[pc.material];
    vec3 normal = safe_normalize(v_normal);
    // Only double-sided materials reach here with back faces (single-sided ones are culled); glTF reverses
    // their normal.
    if (!gl_FrontFacing) {
        normal = -normal;
    }
    vec3 to_viewer = pc.viewer.w != 0.0 ? safe_normalize(pc.viewer.xyz - v_position) : pc.viewer.xyz;
    out_radiance = vec4(radiance_out(material, v_position, normal, to_viewer), 1.0);
}

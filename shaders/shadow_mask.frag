#version 460
// The depth pass of a shadow map, for alpha-masked draws: the fragment is discarded where the base colour's alpha
// is below the cutoff, as scene.frag discards it for the camera, so that the maps let light through the cut-outs
// as the shadow rays do (src/cpu/occluders.rs). No colour output. The push constants hold the map's
// clip_from_world and its size in framebuffer_size, so the barycentrics, texture coordinates and footprint are
// the map texel's.
#include "bindings.glsl"
#include "transform.glsl"
#include "surface.glsl"
#include "fragment.glsl"

void main() {
    MaterialGpu material = material_at(pc.material);
    SurfaceSample s = surface_sample();
    if (!alpha_covers(material, base_color(material, s, surface_texels(material, s, 1u << TEX_BASE)).a)) {
        discard;
    }
}

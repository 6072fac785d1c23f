#version 450
// The mark between a frame's two draws (gpu::second_draw): a pixel whose colour the first draw left to the second
// (its coverage alpha LEFT_TO_SECOND_DRAW, as bindings.glsl's) keeps its fragment, which the pipeline's stencil
// op marks for the second draw; every other pixel's fragment is discarded.

#define LEFT_TO_SECOND_DRAW -3.0

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D first_draw;

void main() {
    if (imageLoad(first_draw, ivec2(gl_FragCoord.xy)).a != LEFT_TO_SECOND_DRAW) {
        discard;
    }
}

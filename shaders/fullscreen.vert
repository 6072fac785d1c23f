#version 450
// One triangle over the whole viewport (clip-space corners (-1, -1), (3, -1), (-1, 3)), for a pass over every
// pixel of the target: the mark between a frame's two draws (second_draw.frag, gpu::second_draw).

void main() {
    vec2 corner = vec2(float((gl_VertexIndex & 1) << 2) - 1.0, float((gl_VertexIndex & 2) << 1) - 1.0);
    gl_Position = vec4(corner, 0.0, 1.0);
}

#version 330 core
// Copies the stored populations of the body's force window (the texels that hold its nodes,
// shaders/paired_layout.glsl) into a slot of the band area or a band of an atlas (five RGBA32F
// attachments, as the state), one per step, so that the windows of a whole `step(n)` are read
// back at once instead of once per step (a read stalls llvmpipe's queue).
// @LATTICE
// @INCLUDE paired_layout.glsl
uniform ivec2 shift;   // state texel = target texel + shift

layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;
layout(location = 3) out vec4 out3;
layout(location = 4) out vec4 out4;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy) + shift;
    out0 = texelFetch(G0, p, 0);
    out1 = texelFetch(G1, p, 0);
    out2 = texelFetch(G2, p, 0);
    out3 = texelFetch(G3, p, 0);
    out4 = texelFetch(G4, p, 0);
}

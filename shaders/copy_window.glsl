#version 330 core
// Copies the stored populations of the body's force window into a band of an atlas (three
// RGBA32F attachments, as the state), one band per step, so that the windows of a whole
// `step(n)` are read back at once instead of once per step (a read stalls llvmpipe's queue).
// @LATTICE

uniform sampler2D G0;
uniform sampler2D G1;
uniform sampler2D G2;
uniform ivec2 shift;   // node = atlas texel + shift

layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy) + shift;
    out0 = texelFetch(G0, p, 0);
    out1 = texelFetch(G1, p, 0);
    out2 = texelFetch(G2, p, 0);
}

#version 330 core
// A quad covering the viewport, drawn without vertex buffers (TRIANGLE_STRIP, 4 vertices).
// uv = (0,0) at the lattice's lower-left corner, (1,1) at its upper-right corner.
out vec2 uv;

void main() {
    vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
    uv = corner;
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}

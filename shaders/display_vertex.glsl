#version 330 core
// A quad covering the viewport, drawn without vertex buffers (TRIANGLE_STRIP, 4 vertices).
// uv = (0,0) at the lattice's lower-left corner, (1,1) at its upper-right corner; with
// flip_y = 1 the lattice's top row lands in the framebuffer's first row (the window reads the
// picture back into a QImage, whose first row is its top).
uniform float flip_y;
out vec2 uv;

void main() {
    vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
    uv = vec2(corner.x, mix(corner.y, 1.0 - corner.y, flip_y));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}

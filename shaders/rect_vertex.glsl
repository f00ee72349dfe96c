#version 330 core
// Vertex stage shared by every lattice pass: rectangles given in texel (node) coordinates,
// corners on integer texel edges, so that a rectangle covers exactly the nodes inside it.
// @LATTICE
uniform vec2 grid_size;   // (nx, ny) of the target
in vec2 in_pos;           // texel coordinates of a corner
void main() {
    gl_Position = vec4(in_pos / grid_size * 2.0 - 1.0, 0.0, 1.0);
}

#version 460
// Depth-only: the rasterizer writes the depth, the fragment shader nothing.
void main() {
}

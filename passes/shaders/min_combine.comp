#version 460
#extension GL_GOOGLE_include_directive : require
// The visibility of a light shadowed through several frusta (a point light's cube faces): the minimum over
// the frusta's outputs, each lit (1) outside its own frustum. mode 0 copies the first frustum's output into
// the combined image, mode 1 folds in another (a light with no frustum recorded gets its 1 from a clear).
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32f) uniform readonly image2D frustum;
#include "output_format.glsl"
layout(set = 0, binding = 1, OUTPUT_FORMAT) uniform image2D combined;
layout(push_constant) uniform Push {
    uint width;
    uint height;
    uint mode;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) {
        return;
    }
    float v = imageLoad(frustum, p).r;
    if (pc.mode != 0u) {
        v = min(v, imageLoad(combined, p).r);
    }
    imageStore(combined, p, vec4(v));
}

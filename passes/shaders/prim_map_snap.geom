#version 460
#extension GL_GOOGLE_include_directive : require
// Tier-1 emulation on hardware with a better conservative-raster tier: D3D12 Tier 1 may cull triangles
// that are degenerate after the rasterizer snaps vertices to its sub-pixel grid (8 bits: 1/256 texel).
// This pass snaps the same way and drops those triangles; everything else goes to the hardware
// conservative rasterizer unchanged. The zero-area test uses exact 64-bit integer products.
#include "map_push.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
layout(push_constant) uniform Push { MapPush pc; };

// Exact sign of a.x * b.y - a.y * b.x for integer vectors.
int cross_sign(ivec2 a, ivec2 b) {
    int hi0, lo0, hi1, lo1;
    imulExtended(a.x, b.y, hi0, lo0);
    imulExtended(a.y, b.x, hi1, lo1);
    if (hi0 != hi1) {
        return hi0 > hi1 ? 1 : -1;
    }
    if (lo0 != lo1) {
        return uint(lo0) > uint(lo1) ? 1 : -1;
    }
    return 0;
}

void main() {
    ivec2 q[3];
    for (int i = 0; i < 3; ++i) {
        vec4 c = gl_in[i].gl_Position;
        if (c.w <= 0.0) {
            return;
        }
        q[i] = ivec2(round((c.xy / c.w * 0.5 + 0.5) * float(pc.size) * 256.0));
    }
    if (cross_sign(q[1] - q[0], q[2] - q[0]) == 0) {
        return;
    }
    for (int i = 0; i < 3; ++i) {
        gl_Position = gl_in[i].gl_Position;
        gl_PrimitiveID = gl_PrimitiveIDIn;
        EmitVertex();
    }
    EndPrimitive();
}

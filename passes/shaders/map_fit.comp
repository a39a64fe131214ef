#version 460
#extension GL_GOOGLE_include_directive : require
// One invocation. mode 0: resets the map state for a new frame. mode 1: fits the map to the receivers'
// light-space bounds (padded by 1/256 of their extent): `to_texels` maps frame coordinates to homogeneous
// texel space, the light's view-projection followed by the 2D affine fit.
#include "map_state.glsl"
#include "map_push.glsl"

layout(local_size_x = 1) in;
layout(set = 0, binding = 0) buffer State { MapState ms; };
layout(push_constant) uniform Push { MapPush pc; };

const uint MIN_GRID = 16u;

void main() {
    if (pc.mode == 0u) {
        ms.to_texels = mat4(1.0);
        ms.bounds = uvec4(0xFFFFFFFFu, 0xFFFFFFFFu, 0u, 0u);
        ms.receivers = uvec4(0u);
        ms.fit = vec4(0.0);
        ms.totals = uvec4(0u, 0u, pc.capacity, 0u);
        ms.stats = uvec4(0u);
        return;
    }
    if (ms.bounds.x > ms.bounds.z || ms.bounds.y > ms.bounds.w) {
        return;     // no receivers: no pixel traces a ray, the map stays empty
    }
    vec2 lo = vec2(unordered(ms.bounds.x), unordered(ms.bounds.y));
    vec2 hi = vec2(unordered(ms.bounds.z), unordered(ms.bounds.w));
    vec2 extent = max(hi - lo, max(abs(lo), abs(hi)) * 1e-6 + 1e-30);
    lo -= extent / 256.0;
    hi += extent / 256.0;
    // With receiver culling, a texel holds a list only where a ray origin lies, so a grid much finer than
    // the rays only multiplies the binning work of large triangles (a face of a point light that sees a
    // handful of pixels would otherwise spread every triangle over N^2 texels). The grid keeps about 16
    // texels per ray origin, at least MIN_GRID and at most N per side; without culling (a debug mode whose
    // lists are compared texel by texel), always N.
    uint n = pc.size;
    if (pc.cull != 0u) {
        n = clamp(4u * uint(ceil(sqrt(float(ms.receivers.w)))), min(MIN_GRID, pc.size), pc.size);
    }
    ms.fit.y = float(n);
    vec2 s = float(n) / (hi - lo);
    // texel * w = s * (clip.xy - lo * clip.w)
    mat4 fit = mat4(1.0);
    fit[0][0] = s.x;
    fit[1][1] = s.y;
    fit[3][0] = -lo.x * s.x;
    fit[3][1] = -lo.y * s.y;
    ms.to_texels = fit * pc.light_view_proj;
    ms.fit.x = 1.0;
}

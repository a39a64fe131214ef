#version 460
#extension GL_GOOGLE_include_directive : require
// The first steps of the hierarchy's build (passes::bvh), one invocation per triangle:
// mode 0: the bounds of the triangles' box centres (ordered-float atomics into the header, which starts as
//         an empty box);
// mode 1: each triangle's 30-bit Morton code of its box centre within those bounds (the sort key) and its
//         index (the value).
// A triangle with a NaN coordinate can never be hit (every test of it fails): it gets key 0 and an empty
// box (bvh_build.comp), so that it never enlarges a box.
#include "triangle.glsl"
#include "map_state.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(set = 0, binding = 1) buffer Header { uvec4 centre_lo; uvec4 centre_hi; };
layout(set = 0, binding = 2) writeonly buffer Keys { uint keys[]; };
layout(set = 0, binding = 3) writeonly buffer Values { uint values[]; };
layout(push_constant) uniform Push { uint triangles; uint mode; } pc;

// Spreads the low 10 bits of v to every third bit.
uint spread_bits(uint v) {
    v = (v | (v << 16)) & 0x030000FFu;
    v = (v | (v << 8)) & 0x0300F00Fu;
    v = (v | (v << 4)) & 0x030C30C3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.triangles) {
        return;
    }
    vec3 a = tris[i].v[0].xyz, b = tris[i].v[1].xyz, c = tris[i].v[2].xyz;
    bool hittable = !any(isnan(a)) && !any(isnan(b)) && !any(isnan(c));
    vec3 centre = 0.5 * (min(min(a, b), c) + max(max(a, b), c));
    bool finite = hittable && !any(isinf(centre));
    if (pc.mode == 0u) {
        if (finite) {
            atomicMin(centre_lo.x, ordered(centre.x));
            atomicMin(centre_lo.y, ordered(centre.y));
            atomicMin(centre_lo.z, ordered(centre.z));
            atomicMax(centre_hi.x, ordered(centre.x));
            atomicMax(centre_hi.y, ordered(centre.y));
            atomicMax(centre_hi.z, ordered(centre.z));
        }
        return;
    }
    uint key = 0u;
    if (finite) {
        vec3 lo = vec3(unordered(centre_lo.x), unordered(centre_lo.y), unordered(centre_lo.z));
        vec3 hi = vec3(unordered(centre_hi.x), unordered(centre_hi.y), unordered(centre_hi.z));
        vec3 extent = hi - lo;
        vec3 unit = vec3(extent.x > 0.0 ? (centre.x - lo.x) / extent.x : 0.0,
                         extent.y > 0.0 ? (centre.y - lo.y) / extent.y : 0.0,
                         extent.z > 0.0 ? (centre.z - lo.z) / extent.z : 0.0);
        uvec3 q = uvec3(clamp(unit * 1024.0, vec3(0.0), vec3(1023.0)));
        key = (spread_bits(q.x) << 2) | (spread_bits(q.y) << 1) | spread_bits(q.z);
    }
    keys[i] = key;
    values[i] = i;
}

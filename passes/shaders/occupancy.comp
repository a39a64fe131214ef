#version 460
#extension GL_GOOGLE_include_directive : require
// Occupancy view of the primitive map and its statistics for the frame report. Colours: black without a
// list, grey levels the list length on a log scale (white at OCCUPANCY_WHITE entries or more), dark blue
// texels with ray origins but an empty list, red texels past the entry capacity (traced exhaustively).
#include "map_state.glsl"

#define OCCUPANCY_WHITE 256.0

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) readonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 1) readonly buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 2, rgba8) uniform writeonly image2D occupancy;
layout(set = 0, binding = 3) buffer State { MapState ms; };
layout(push_constant) uniform Push { uint size; } pc;

// Per-workgroup sums and maximum in shared memory: one global atomic each per workgroup.
shared uint group_stats[4];

void tally(uvec2 t) {
    uint texel = t.y * pc.size + t.x;
    uint count = offsets[texel + 1u] - offsets[texel];
    bool past = offsets[texel + 1u] > ms.totals.z;
    bool receives = receiver[texel] != 0u;
    vec4 colour = vec4(vec3(min(log2(1.0 + float(count)) / log2(1.0 + OCCUPANCY_WHITE), 1.0)), 1.0);
    if (past) {
        colour = vec4(1.0, 0.0, 0.0, 1.0);
    } else if (count == 0u && receives) {
        colour = vec4(0.0, 0.0, 0.25, 1.0);
    }
    imageStore(occupancy, ivec2(t), colour);
    if (count > 0u) {
        atomicAdd(group_stats[0], 1u);
        atomicMax(group_stats[1], count);
    }
    if (past && count > 0u) {
        atomicAdd(group_stats[2], 1u);
    }
    if (receives) {
        atomicAdd(group_stats[3], 1u);
    }
    if (texel == 0u) {
        ms.totals.y = offsets[pc.size * pc.size];
    }
}

void main() {
    uint lid = gl_LocalInvocationIndex;
    if (lid < 4u) {
        group_stats[lid] = 0u;
    }
    barrier();
    uvec2 t = gl_GlobalInvocationID.xy;
    if (t.x < pc.size && t.y < pc.size) {
        tally(t);
    }
    barrier();
    if (lid == 0u) {
        atomicAdd(ms.stats.x, group_stats[0]);
        atomicMax(ms.stats.y, group_stats[1]);
        atomicAdd(ms.stats.z, group_stats[2]);
        atomicAdd(ms.stats.w, group_stats[3]);
    }
}

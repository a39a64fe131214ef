#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// The primitive map's statistics for the frame report and the capacity's growth (entries needed, texels
// with a list, longest list, texels past the capacity; the receivers pass counts the texels with ray
// origins), and, when asked, its occupancy view (the only reader of the receiver map after the build). Colours: black without a list, grey levels the list length on a log scale (white at
// OCCUPANCY_WHITE entries or more), dark blue texels with ray origins but an empty list, red texels past
// the entry capacity (traced exhaustively). The texels are laid out in rows of N (a point light's face
// grids follow one another), and the view shows the first N rows. Each invocation tallies a 2x2 quad of
// texels; the sums reach memory once per subgroup (shared) and once per workgroup (global).
#include "map_state.glsl"

#define OCCUPANCY_WHITE 256.0

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) readonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 1) readonly buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 2, rgba8) uniform writeonly image2D occupancy;
layout(set = 0, binding = 3) buffer State { MapState ms; };
layout(push_constant) uniform Push { uint size; uint view; uint texels; } pc;

shared uint group_stats[3];

void main() {
    uint lid = gl_LocalInvocationIndex;
    if (lid < 3u) {
        group_stats[lid] = 0u;
    }
    barrier();
    uint capacity = ms.totals.z;
    uvec3 mine = uvec3(0u);     // texels with a list, longest list, texels past capacity
    for (uint q = 0u; q < 4u; ++q) {
        uvec2 t = gl_GlobalInvocationID.xy * 2u + uvec2(q & 1u, q >> 1u);
        uint texel = t.y * pc.size + t.x;
        if (t.x >= pc.size || texel >= pc.texels) {
            continue;
        }
        uint end = offsets[texel + 1u];
        uint count = end - offsets[texel];
        bool past = count > 0u && end > capacity;
        mine += uvec3(count > 0u ? 1u : 0u, 0u, past ? 1u : 0u);
        mine.y = max(mine.y, count);
        if (pc.view != 0u && t.y < pc.size) {
            bool receives = receiver[texel] != 0u;
            vec4 colour = vec4(vec3(min(log2(1.0 + float(count)) / log2(1.0 + OCCUPANCY_WHITE), 1.0)), 1.0);
            if (past) {
                colour = vec4(1.0, 0.0, 0.0, 1.0);
            } else if (count == 0u && receives) {
                colour = vec4(0.0, 0.0, 0.25, 1.0);
            }
            imageStore(occupancy, ivec2(t), colour);
        }
        if (texel == 0u) {
            ms.totals.y = offsets[pc.texels];
        }
    }
    uvec2 sums = subgroupAdd(mine.xz);
    uint longest = subgroupMax(mine.y);
    if (subgroupElect()) {
        atomicAdd(group_stats[0], sums.x);
        atomicMax(group_stats[1], longest);
        atomicAdd(group_stats[2], sums.y);
    }
    barrier();
    if (lid == 0u) {
        atomicAdd(ms.stats.x, group_stats[0]);
        atomicMax(ms.stats.y, group_stats[1]);
        atomicAdd(ms.stats.z, group_stats[2]);
    }
}

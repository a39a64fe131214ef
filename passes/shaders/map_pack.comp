#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// Packs the scanned list offsets (one u32 per texel, plus the total, in the build scratch) into the map's
// list offsets (map_offsets.glsl: a u32 per 16 texels and a u16 per texel), and tallies the map's
// statistics for the frame report and the capacity's growth: entries needed, texels with a list, longest
// list, and the texels traced exhaustively (a list past the capacity, every texel of a group whose local
// offsets overflowed). One invocation per group of 16 texels, and one more for the final group holding the
// total; the sums reach memory once per subgroup (shared) and once per workgroup (global).
#include "map_state.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer Scanned { uint scanned[]; };
layout(set = 0, binding = 1) buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 2) buffer State { MapState ms; };
layout(push_constant) uniform Push { uint texels; } pc;
#include "map_offsets.glsl"

shared uint group_stats[3];

// The offset of texel t's list; the total of all lists for every t at or past the last texel.
uint offset_of(uint t) {
    return scanned[min(t, pc.texels)];
}

void main() {
    uint lid = gl_LocalInvocationIndex;
    if (lid < 3u) {
        group_stats[lid] = 0u;
    }
    barrier();
    uint g = gl_GlobalInvocationID.x;
    uint groups = (pc.texels + OFFSET_GROUP - 1u) / OFFSET_GROUP;
    uvec3 mine = uvec3(0u);     // texels with a list, longest list, texels past capacity
    if (g <= groups) {
        uint first = g * OFFSET_GROUP;
        uint base = offset_of(first);
        // Overflowed too: a group whose lists end at 2^31 entries or more, where the bases' top bit is the
        // mark (its last list's end is the next group's base).
        bool overflow = offset_of(first + OFFSET_GROUP - 1u) - base > 0xFFFFu
            || offset_of(first + OFFSET_GROUP) >= OFFSET_GROUP_OVERFLOW;
        offsets[g * OFFSET_GROUP_WORDS] = base | (overflow ? OFFSET_GROUP_OVERFLOW : 0u);
        uint capacity = ms.totals.z;
        uint begin = base;
        for (uint i = 0u; i < OFFSET_GROUP; i += 2u) {
            uint middle = offset_of(first + i + 1u);
            uint end = offset_of(first + i + 2u);
            offsets[g * OFFSET_GROUP_WORDS + 1u + i / 2u] =
                overflow ? 0u : (begin - base) | ((middle - base) << 16);
            uvec2 count = uvec2(middle - begin, end - middle);
            bvec2 listed = greaterThan(count, uvec2(0u));
            bvec2 real = lessThan(uvec2(first + i, first + i + 1u), uvec2(pc.texels));
            bvec2 past = bvec2(real.x && (overflow || (listed.x && middle > capacity)),
                               real.y && (overflow || (listed.y && end > capacity)));
            mine += uvec3(uint(listed.x) + uint(listed.y), 0u, uint(past.x) + uint(past.y));
            mine.y = max(mine.y, max(count.x, count.y));
            begin = end;
        }
        if (g == 0u) {
            ms.totals.y = offset_of(pc.texels);
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

#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// Packs the scanned list offsets (one u32 per texel, plus the total, in the build scratch; the scan is
// saturating, so an offset at or past 2^31 only marks its group) into the map's list offsets
// (map_offsets.glsl: a u32 per 16 texels and a 16-bit field per texel, bit 15 marking a texel whose list
// passed the list limit, from the count's bitmask), and tallies the map's statistics for the frame report and
// the capacity's growth: entries needed, texels with a list, longest list, texels past the capacity (a list
// past it, every texel of a group whose local offsets overflowed) and texels past the list limit (mode 0).
// The fill uses the scanned offsets as its cursors: mode 1 gives every texel whose list is not kept the
// capacity as its cursor, so that the fill writes none of its entries (its count leaves the cursor far below
// 2^32).
// One invocation per group of 16 texels, and one more for the final group holding the total; the sums reach
// memory once per subgroup (shared) and once per workgroup (global).
#include "map_state.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) buffer Scanned { uint scanned[]; };
layout(set = 0, binding = 1) buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 2) buffer State { MapState ms; };
layout(set = 0, binding = 3) readonly buffer Capped { uint capped[]; };
layout(push_constant) uniform Push { uint texels; uint mode; } pc;
#include "map_offsets.glsl"

shared uint group_stats[4];

// The offset of texel t's list; the total of all lists for every t at or past the last texel.
uint offset_of(uint t) {
    return scanned[min(t, pc.texels)];
}

bool is_capped(uint t) {
    return t < pc.texels && (capped[t >> 5] & (1u << (t & 31u))) != 0u;
}

// Mode 1: the cursors of the texels of group g whose lists are not kept.
void reset_cursors(uint g) {
    uint capacity = ms.totals.z;
    for (uint t = g * OFFSET_GROUP; t < min((g + 1u) * OFFSET_GROUP, pc.texels); ++t) {
        uint begin, end;
        if (!list_range(t, begin, end) || (end > capacity && end > begin)) {
            scanned[t] = capacity;
        }
    }
}

void main() {
    if (pc.mode == 1u) {
        reset_cursors(gl_GlobalInvocationID.x);
        return;
    }
    uint lid = gl_LocalInvocationIndex;
    if (lid < 4u) {
        group_stats[lid] = 0u;
    }
    barrier();
    uint g = gl_GlobalInvocationID.x;
    uint groups = (pc.texels + OFFSET_GROUP - 1u) / OFFSET_GROUP;
    uvec4 mine = uvec4(0u);     // texels with a list, longest list, texels past capacity, texels capped
    if (g <= groups) {
        uint first = g * OFFSET_GROUP;
        uint base = offset_of(first);
        uint capacity = ms.totals.z;
        // Overflowed too: a group whose lists end at 2^31 entries or more, where the bases' top bit is the
        // mark (its last list's end is the next group's base).
        bool overflow = offset_of(first + OFFSET_GROUP - 1u) - base > OFFSET_LOCAL_MAX
            || offset_of(first + OFFSET_GROUP) >= OFFSET_GROUP_OVERFLOW;
        offsets[g * OFFSET_GROUP_WORDS] = base | (overflow ? OFFSET_GROUP_OVERFLOW : 0u);
        for (uint i = 0u; i < OFFSET_GROUP; i += 2u) {
            uint fields[2];
            for (uint h = 0u; h < 2u; ++h) {
                uint t = first + i + h;
                uint begin = offset_of(t), end = offset_of(t + 1u);
                bool cut = is_capped(t);
                fields[h] = overflow ? 0u : (begin - base) | (cut ? OFFSET_CAPPED : 0u);
                bool real = t < pc.texels;
                // A saturated end leaves the list's length unknown (its group overflowed).
                uint count = end == 0xFFFFFFFFu ? 0u : end - begin;
                bool past = real && (overflow || (count > 0u && end > capacity));
                mine += uvec4(uint(real && count > 0u), 0u, uint(past), uint(cut));
                mine.y = max(mine.y, real ? count : 0u);
            }
            offsets[g * OFFSET_GROUP_WORDS + 1u + i / 2u] = fields[0] | (fields[1] << 16);
        }
        if (g == 0u) {
            ms.totals.y = offset_of(pc.texels);
        }
    }
    uvec3 sums = subgroupAdd(mine.xzw);
    uint longest = subgroupMax(mine.y);
    if (subgroupElect()) {
        atomicAdd(group_stats[0], sums.x);
        atomicMax(group_stats[1], longest);
        atomicAdd(group_stats[2], sums.y);
        atomicAdd(group_stats[3], sums.z);
    }
    barrier();
    if (lid == 0u) {
        atomicAdd(ms.stats.x, group_stats[0]);
        atomicMax(ms.stats.y, group_stats[1]);
        atomicAdd(ms.stats.z, group_stats[2]);
        atomicAdd(ms.routes.z, group_stats[3]);
    }
}

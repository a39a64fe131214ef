#version 460
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// Exclusive prefix sum over blocks of 1024 u32 (256 threads x 4), saturating: every sum is the exact sum, or
// 0xFFFFFFFF where the exact sum reaches 2^32, so that no offset wraps silently (passes::scan). In two
// dispatches when the block totals are few enough for every workgroup to sum those before its own (flat),
// else one level per 1024-fold reduction.
// mode 0: scans each block of `input` into `data` (the two may be the same buffer) and writes the block's
//         total to sums[block] (a level of the multi-level scan, upwards).
// mode 1: adds sums[block] (the scanned totals of the level above) to every element of the block.
// mode 2: writes each block's total to sums[block] (flat, first dispatch).
// mode 3: scans each block into `data`, starting from the sum of sums[0 .. block), which the workgroup adds
//         up itself (flat, second dispatch).
// Input values above `cap` are read as 0 (the primitive map's counts of texels past its list limit).
// Within a block: each thread sums its 4 elements, subgroups scan the thread totals, the first subgroup
// scans the subgroup totals. A subgroup's sums are taken of the values' high and low 16 bits apart (neither
// can wrap for subgroups of up to 65536 invocations) and joined with saturation.
layout(local_size_x = 256) in;
layout(set = 0, binding = 0) readonly buffer Input { uint input_data[]; };
layout(set = 0, binding = 1) buffer Data { uint data[]; };
layout(set = 0, binding = 2) buffer Sums { uint sums[]; };
layout(push_constant) uniform Push { uint n; uint mode; uint cap; uint pad; } pc;

const uint SATURATED = 0xFFFFFFFFu;

shared uint subgroup_base[256];
shared uint block_start;

uint sat_add(uint a, uint b) {
    uint s = a + b;
    return s < a ? SATURATED : s;
}

// hi * 2^16 + lo, saturated.
uint join(uint hi, uint lo) {
    return hi >= 0x10000u ? SATURATED : sat_add(hi << 16, lo);
}

uint sat_subgroup_inclusive(uint x) {
    return join(subgroupInclusiveAdd(x >> 16), subgroupInclusiveAdd(x & 0xFFFFu));
}

uint sat_subgroup_exclusive(uint x) {
    return join(subgroupExclusiveAdd(x >> 16), subgroupExclusiveAdd(x & 0xFFFFu));
}

uint sat_subgroup_total(uint x) {
    return join(subgroupAdd(x >> 16), subgroupAdd(x & 0xFFFFu));
}

// The saturated sum of `x` over the workgroup (every invocation gets it).
uint sat_workgroup_total(uint x) {
    uint t = sat_subgroup_total(x);
    if (subgroupElect()) {
        subgroup_base[gl_SubgroupID] = t;
    }
    barrier();
    uint total = 0u;
    for (uint i = 0u; i < gl_NumSubgroups; ++i) {
        total = sat_add(total, subgroup_base[i]);
    }
    barrier();
    return total;
}

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint block = gl_WorkGroupID.x;
    uint base = block * 1024u + lid * 4u;
    if (pc.mode == 1u) {
        uint add = sums[block];
        for (uint i = 0u; i < 4u; ++i) {
            if (base + i < pc.n) {
                data[base + i] = sat_add(data[base + i], add);
            }
        }
        return;
    }
    uvec4 v = uvec4(0u);
    for (uint i = 0u; i < 4u; ++i) {
        if (base + i < pc.n) {
            uint value = input_data[base + i];
            v[i] = value > pc.cap ? 0u : value;
        }
    }
    uint total = sat_add(sat_add(v.x, v.y), sat_add(v.z, v.w));
    if (pc.mode == 2u) {
        uint block_total = sat_workgroup_total(total);
        if (lid == 0u) {
            sums[block] = block_total;
        }
        return;
    }
    uint start = 0u;
    if (pc.mode == 3u) {
        uint before = 0u;
        for (uint i = lid; i < block; i += 256u) {
            before = sat_add(before, sums[i]);
        }
        start = sat_workgroup_total(before);
    }
    uint exclusive = sat_subgroup_exclusive(total);
    uint inclusive = sat_subgroup_inclusive(total);
    if (gl_SubgroupInvocationID == gl_SubgroupSize - 1u) {
        subgroup_base[gl_SubgroupID] = inclusive;
    }
    barrier();
    if (gl_SubgroupID == 0u) {
        uint carry = 0u;
        for (uint first = 0u; first < gl_NumSubgroups; first += gl_SubgroupSize) {
            uint i = first + gl_SubgroupInvocationID;
            uint t = i < gl_NumSubgroups ? subgroup_base[i] : 0u;
            uint s = sat_subgroup_exclusive(t);
            uint chunk = sat_subgroup_total(t);
            if (i < gl_NumSubgroups) {
                subgroup_base[i] = sat_add(carry, s);
            }
            carry = sat_add(carry, chunk);
        }
    }
    barrier();
    uint running = sat_add(sat_add(start, subgroup_base[gl_SubgroupID]), exclusive);
    for (uint i = 0u; i < 4u; ++i) {
        if (base + i < pc.n) {
            data[base + i] = running;
        }
        running = sat_add(running, v[i]);
    }
    if (lid == 255u && pc.mode == 0u) {
        sums[block] = running;
    }
}

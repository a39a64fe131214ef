#version 460
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// Exclusive prefix sum over blocks of 1024 u32 (256 threads x 4), in two dispatches when the block totals
// are few enough for every workgroup to sum those before its own (flat), else one level per 1024-fold
// reduction.
// mode 0: scans each block of `input` into `data` (the two may be the same buffer) and writes the block's
//         total to sums[block] (a level of the multi-level scan, upwards).
// mode 1: adds sums[block] (the scanned totals of the level above) to every element of the block.
// mode 2: writes each block's total to sums[block] (flat, first dispatch).
// mode 3: scans each block into `data`, starting from the sum of sums[0 .. block), which the workgroup adds
//         up itself (flat, second dispatch).
// Within a block: each thread sums its 4 elements, subgroups scan the thread totals, the first subgroup
// scans the subgroup totals.
layout(local_size_x = 256) in;
layout(set = 0, binding = 0) readonly buffer Input { uint input_data[]; };
layout(set = 0, binding = 1) buffer Data { uint data[]; };
layout(set = 0, binding = 2) buffer Sums { uint sums[]; };
layout(push_constant) uniform Push { uint n; uint mode; } pc;

shared uint subgroup_base[256];
shared uint block_sum;

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint block = gl_WorkGroupID.x;
    uint base = block * 1024u + lid * 4u;
    if (lid == 0u) {
        block_sum = 0u;
    }
    barrier();
    if (pc.mode == 1u) {
        uint add = sums[block];
        for (uint i = 0u; i < 4u; ++i) {
            if (base + i < pc.n) {
                data[base + i] += add;
            }
        }
        return;
    }
    uvec4 v = uvec4(0u);
    for (uint i = 0u; i < 4u; ++i) {
        if (base + i < pc.n) {
            v[i] = input_data[base + i];
        }
    }
    uint total = v.x + v.y + v.z + v.w;
    if (pc.mode == 2u) {
        uint block_total = subgroupAdd(total);
        if (subgroupElect()) {
            atomicAdd(block_sum, block_total);
        }
        barrier();
        if (lid == 0u) {
            sums[block] = block_sum;
        }
        return;
    }
    uint start = 0u;
    if (pc.mode == 3u) {
        uint before = 0u;
        for (uint i = lid; i < block; i += 256u) {
            before += sums[i];
        }
        before = subgroupAdd(before);
        if (subgroupElect()) {
            atomicAdd(block_sum, before);
        }
        barrier();
        start = block_sum;
    }
    uint inclusive = subgroupInclusiveAdd(total);
    if (gl_SubgroupInvocationID == gl_SubgroupSize - 1u) {
        subgroup_base[gl_SubgroupID] = inclusive;
    }
    barrier();
    if (gl_SubgroupID == 0u) {
        uint carry = 0u;
        for (uint first = 0u; first < gl_NumSubgroups; first += gl_SubgroupSize) {
            uint i = first + gl_SubgroupInvocationID;
            uint t = i < gl_NumSubgroups ? subgroup_base[i] : 0u;
            uint s = subgroupInclusiveAdd(t);
            if (i < gl_NumSubgroups) {
                subgroup_base[i] = carry + s - t;
            }
            carry += subgroupAdd(t);
        }
    }
    barrier();
    uint running = start + subgroup_base[gl_SubgroupID] + inclusive - total;
    for (uint i = 0u; i < 4u; ++i) {
        if (base + i < pc.n) {
            data[base + i] = running;
        }
        running += v[i];
    }
    if (lid == 255u && pc.mode == 0u) {
        sums[block] = running;
    }
}

#version 460
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
// One pass of a stable least-significant-digit radix sort of (key, value) pairs by the 4-bit digit of the
// keys at `shift` (passes::bvh): blocks of 1024 pairs, one workgroup each.
// mode 0: counts each block's digits into digit_counts[digit * blocks + block];
// (the exclusive scan of digit_counts then gives each block's first slot of each digit)
// mode 1: scatters each block's pairs in order to those slots: in rounds of 256, each pair after the pairs
//         of its digit in earlier rounds, earlier subgroups and earlier invocations of its subgroup (found by
//         ballots of the digit's bits), so that equal digits keep their order.
layout(local_size_x = 256) in;
layout(set = 0, binding = 0) readonly buffer KeysIn { uint keys_in[]; };
layout(set = 0, binding = 1) readonly buffer ValuesIn { uint values_in[]; };
layout(set = 0, binding = 2) writeonly buffer KeysOut { uint keys_out[]; };
layout(set = 0, binding = 3) writeonly buffer ValuesOut { uint values_out[]; };
layout(set = 0, binding = 4) buffer DigitCounts { uint digit_counts[]; };
layout(push_constant) uniform Push { uint n; uint shift; uint mode; uint blocks; } pc;

const uint DIGITS = 16u;
const uint ROUND = 256u;
const uint BLOCK = 1024u;

shared uint digit_base[DIGITS];
// [subgroup][digit]: the pairs of each digit in each subgroup of the round, then where they start.
shared uint subgroup_digits[ROUND * DIGITS];

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint block = gl_WorkGroupID.x;
    uint first = block * BLOCK;
    if (pc.mode == 0u) {
        if (lid < DIGITS) {
            digit_base[lid] = 0u;
        }
        barrier();
        for (uint i = lid; i < BLOCK; i += ROUND) {
            if (first + i < pc.n) {
                atomicAdd(digit_base[(keys_in[first + i] >> pc.shift) & 0xFu], 1u);
            }
        }
        barrier();
        if (lid < DIGITS) {
            digit_counts[lid * pc.blocks + block] = digit_base[lid];
        }
        return;
    }
    if (lid < DIGITS) {
        digit_base[lid] = digit_counts[lid * pc.blocks + block];
    }
    uint subgroups = gl_NumSubgroups;
    uvec4 below = gl_SubgroupLtMask;
    for (uint round = 0u; round < BLOCK; round += ROUND) {
        for (uint i = lid; i < subgroups * DIGITS; i += ROUND) {
            subgroup_digits[i] = 0u;
        }
        barrier();
        uint at = first + round + lid;
        bool valid = at < pc.n;
        uint key = valid ? keys_in[at] : 0u;
        uint digit = (key >> pc.shift) & 0xFu;
        // The invocations of this subgroup holding a pair of the same digit.
        uvec4 same = subgroupBallot(valid);
        for (uint bit = 0u; bit < 4u; ++bit) {
            uvec4 set = subgroupBallot(((digit >> bit) & 1u) != 0u);
            same &= ((digit >> bit) & 1u) != 0u ? set : ~set;
        }
        uint rank = bitCount(same.x & below.x) + bitCount(same.y & below.y) + bitCount(same.z & below.z)
            + bitCount(same.w & below.w);
        if (valid && rank == 0u) {
            subgroup_digits[gl_SubgroupID * DIGITS + digit] =
                bitCount(same.x) + bitCount(same.y) + bitCount(same.z) + bitCount(same.w);
        }
        barrier();
        if (lid < DIGITS) {
            uint running = digit_base[lid];
            for (uint s = 0u; s < subgroups; ++s) {
                uint count = subgroup_digits[s * DIGITS + lid];
                subgroup_digits[s * DIGITS + lid] = running;
                running += count;
            }
            digit_base[lid] = running;
        }
        barrier();
        if (valid) {
            uint slot = subgroup_digits[gl_SubgroupID * DIGITS + digit] + rank;
            keys_out[slot] = key;
            values_out[slot] = values_in[at];
        }
        barrier();
    }
}

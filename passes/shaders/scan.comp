#version 460
// Exclusive prefix sum, one level of a multi-level scan over blocks of 1024 u32 (256 threads x 4).
// mode 0: scans each block in place and writes the block's total to sums[block].
// mode 1: adds sums[block] (the scanned totals of the level above) to every element of the block.
layout(local_size_x = 256) in;
layout(set = 0, binding = 0) buffer Data { uint data[]; };
layout(set = 0, binding = 1) buffer Sums { uint sums[]; };
layout(push_constant) uniform Push { uint n; uint mode; } pc;

shared uint partial[256];

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint block = gl_WorkGroupID.x;
    uint base = block * 1024u + lid * 4u;
    if (pc.mode == 1u) {
        uint add = sums[block];
        for (uint i = 0u; i < 4u; ++i) {
            if (base + i < pc.n) {
                data[base + i] += add;
            }
        }
        return;
    }
    uint v[4];
    uint total = 0u;
    for (uint i = 0u; i < 4u; ++i) {
        v[i] = base + i < pc.n ? data[base + i] : 0u;
        total += v[i];
    }
    partial[lid] = total;
    barrier();
    for (uint offset = 1u; offset < 256u; offset <<= 1u) {
        uint t = lid >= offset ? partial[lid - offset] : 0u;
        barrier();
        partial[lid] += t;
        barrier();
    }
    uint running = partial[lid] - total;
    for (uint i = 0u; i < 4u; ++i) {
        if (base + i < pc.n) {
            data[base + i] = running;
        }
        running += v[i];
    }
    if (lid == 255u) {
        sums[block] = partial[255];
    }
}

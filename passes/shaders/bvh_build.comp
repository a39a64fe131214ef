#version 460
#extension GL_GOOGLE_include_directive : require
// The hierarchy over the triangles sorted by Morton code (passes::bvh): a linear BVH (Karras 2012).
// mode 0: one invocation per internal node i: the range of sorted triangles it covers and where it splits
//         (the highest bit at which the range's keys differ, the keys' positions breaking ties), its two
//         children and their parent links; it clears the node's arrival count. Over one triangle, node 0
//         holds it as both children.
// mode 1: one invocation per triangle, from its leaf upwards: each child's box is written into its parent,
//         and the second child to arrive at a node (an atomic count) goes on with the union of the two; the
//         first stops. Boxes are the exact f32 bounds of the vertices, so every box holds its triangles.
#include "triangle.glsl"
#include "bvh.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(set = 0, binding = 1) readonly buffer Keys { uint keys[]; };
layout(set = 0, binding = 2) readonly buffer Values { uint values[]; };
layout(set = 0, binding = 3) coherent buffer Nodes { BvhNode nodes[]; };
// The parent of each leaf (sorted position), then of each internal node; bit 31: the right child.
layout(set = 0, binding = 4) buffer Parents { uint parents[]; };
layout(set = 0, binding = 5) coherent buffer Arrivals { uint arrivals[]; };
layout(push_constant) uniform Push { uint triangles; uint mode; } pc;

const uint RIGHT = 0x80000000u;

// Length of the common prefix of the (key, position) pairs at sorted positions i and j; -1 out of range.
int delta(int i, int j) {
    int n = int(pc.triangles);
    if (j < 0 || j >= n) {
        return -1;
    }
    uint a = keys[i], b = keys[j];
    if (a == b) {
        return 32 + (31 - findMSB(uint(i ^ j)));
    }
    return 31 - findMSB(a ^ b);
}

// The exact box of triangle t (empty for a triangle with a NaN coordinate, which no test can hit).
void triangle_box(uint t, out vec3 lo, out vec3 hi) {
    vec3 a = tris[t].v[0].xyz, b = tris[t].v[1].xyz, c = tris[t].v[2].xyz;
    if (any(isnan(a)) || any(isnan(b)) || any(isnan(c))) {
        lo = vec3(1.0 / 0.0);
        hi = vec3(-1.0 / 0.0);
        return;
    }
    lo = min(min(a, b), c);
    hi = max(max(a, b), c);
}

void write_child(uint node, bool right, vec3 lo, vec3 hi) {
    if (right) {
        nodes[node].right_lo.xyz = lo;
        nodes[node].right_hi.xyz = hi;
    } else {
        nodes[node].left_lo.xyz = lo;
        nodes[node].left_hi.xyz = hi;
    }
}

void hierarchy(int i) {
    int n = int(pc.triangles);
    if (n == 1) {
        uint leaf = BVH_LEAF | values[0];
        vec3 lo, hi;
        triangle_box(values[0], lo, hi);
        nodes[0] = BvhNode(vec4(lo, uintBitsToFloat(leaf)), vec4(hi, 0.0), vec4(lo, uintBitsToFloat(leaf)),
                           vec4(hi, 0.0));
        return;
    }
    int d = delta(i, i + 1) > delta(i, i - 1) ? 1 : -1;
    int delta_min = delta(i, i - d);
    int reach = 2;
    while (delta(i, i + reach * d) > delta_min) {
        reach *= 2;
    }
    int len = 0;
    for (int t = reach / 2; t >= 1; t /= 2) {
        if (delta(i, i + (len + t) * d) > delta_min) {
            len += t;
        }
    }
    int j = i + len * d;
    int delta_node = delta(i, j);
    int split = 0;
    int step = len;
    do {
        step = (step + 1) / 2;
        if (delta(i, i + (split + step) * d) > delta_node) {
            split += step;
        }
    } while (step > 1);
    int gamma = i + split * d + min(d, 0);
    bool left_leaf = min(i, j) == gamma;
    bool right_leaf = max(i, j) == gamma + 1;
    uint left = left_leaf ? (BVH_LEAF | values[gamma]) : uint(gamma);
    uint right = right_leaf ? (BVH_LEAF | values[gamma + 1]) : uint(gamma + 1);
    nodes[i].left_lo.w = uintBitsToFloat(left);
    nodes[i].right_lo.w = uintBitsToFloat(right);
    parents[left_leaf ? uint(gamma) : uint(n + gamma)] = uint(i);
    parents[right_leaf ? uint(gamma + 1) : uint(n + gamma + 1)] = uint(i) | RIGHT;
    arrivals[i] = 0u;
}

void boxes(uint leaf) {
    uint n = pc.triangles;
    if (n < 2u) {
        return;
    }
    vec3 lo, hi;
    triangle_box(values[leaf], lo, hi);
    uint link = parents[leaf];
    // At most one step per level: the depth is below 64 (each level's common prefix is longer).
    for (uint level = 0u; level < 64u; ++level) {
        uint node = link & ~RIGHT;
        write_child(node, (link & RIGHT) != 0u, lo, hi);
        memoryBarrierBuffer();
        if (atomicAdd(arrivals[node], 1u) == 0u) {
            return;     // the sibling's invocation finishes the node
        }
        memoryBarrierBuffer();
        BvhNode both = nodes[node];
        lo = min(both.left_lo.xyz, both.right_lo.xyz);
        hi = max(both.left_hi.xyz, both.right_hi.xyz);
        if (node == 0u) {
            return;
        }
        link = parents[n + node];
    }
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (pc.mode == 0u) {
        if (i + 1u < max(pc.triangles, 2u)) {
            hierarchy(int(i));
        }
    } else if (i < pc.triangles) {
        boxes(i);
    }
}

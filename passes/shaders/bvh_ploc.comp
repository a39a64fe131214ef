#version 460
#extension GL_GOOGLE_include_directive : require
// The rays' hierarchy by locally-ordered clustering (PLOC, Meister and Bittner 2018) over the triangles
// sorted by Morton code (passes::bvh). Clusters start as the sorted triangles; each iteration every
// cluster finds its nearest neighbour among the RADIUS clusters on either side (the smallest surface area
// of the two boxes' union; ties to the pair of lower indices, so the order is total and its least pair is
// always mutual), mutual neighbours merge into a new node, and the clusters left are compacted in order.
// mode 0: one invocation per triangle: its leaf as a cluster; invocation 0 resets the state.
// mode 1: one invocation per cluster: its nearest neighbour (with `forced`, its pair 2k, 2k + 1 instead:
//         the iterations past the clustering's budget merge what is left pairwise, in order).
// mode 2: one invocation per cluster: the lower cluster of a mutual pair writes their node in its place.
// mode 3: one invocation per cluster: the clusters left, compacted by the scanned keep flags.
// Modes 1 and 2 without `forced` leave the last TAIL clusters or fewer (mode 3 carries them over) to
// mode 4: one workgroup: the iterations of modes 1 to 3 over at most TAIL clusters, in place, until one is
//         left (each iteration merges at least the least pair; at most TAIL_ITERATIONS).
// mode 5: one invocation: whether the clustering built the whole hierarchy (one cluster left, node 0, no
//         path 64 deep); if not (one triangle, more clusters left than the pairs could merge, a path
//         too deep), `linear` is set. With `forced` set (no clustering recorded), always.
// mode 6: one invocation per node: the hierarchy in depth-first order (each node's left child right after
//         it, then the left subtree, then the right child), so that a walk reads neighbouring nodes: its
//         place is found from its ancestors' (parent links) and the sizes of their left subtrees.
// mode 7: one invocation per node: with `linear` set, the linear hierarchy (which bvh_build.comp has built
//         since in the same buffer) copied.
// The nodes are made in the linear hierarchy's buffer, free until its build.
// Nodes are numbered down from triangles - 2 as they are made, so that the last, the root, is node 0.
// The cluster counts alternate between two words by the iteration's parity, so that mode 3 can write the
// next count while the others still read this one.
#include "triangle.glsl"
#include "bvh.glsl"

layout(local_size_x = 64) in;
// A cluster: its box, the node or leaf it is (lo.w, uint bits) and its depth (hi.w, uint bits).
struct Cluster {
    vec4 lo;
    vec4 hi;
};
layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(set = 0, binding = 1) readonly buffer Values { uint values[]; };
// The nodes as made (the linear hierarchy's buffer).
layout(set = 0, binding = 2) buffer Built { BvhNode built[]; };
layout(set = 0, binding = 3) buffer State {
    uint counts[2];
    uint made;      // nodes made so far
    uint deepest;   // the deepest cluster's depth
    uint linear;    // 1: the rays' hierarchy is a copy of the linear one
};
layout(set = 0, binding = 4) coherent buffer ClustersIn { Cluster clusters[]; };
layout(set = 0, binding = 5) coherent buffer ClustersOut { Cluster next[]; };
layout(set = 0, binding = 6) coherent buffer Neighbours { uint neighbour[]; };
layout(set = 0, binding = 7) readonly buffer Positions { uint position[]; };
layout(set = 0, binding = 8) writeonly buffer Keep { uint keep[]; };
// Per node made: its parent (RIGHT set for a right child) and the internal nodes of its subtree.
layout(set = 0, binding = 9) coherent buffer Links { uvec2 links[]; };
layout(set = 0, binding = 10) writeonly buffer RayNodes { BvhNode nodes[]; };
layout(push_constant) uniform Push { uint triangles; uint mode; uint parity; uint forced; } pc;

const uint RADIUS = 16u;
const uint MAX_DEPTH = 63u;
const uint TAIL = 1024u;
const uint TAIL_ITERATIONS = 64u;
const uint RIGHT = 0x80000000u;

shared vec4 window_lo[64 + 2 * RADIUS];
shared vec4 window_hi[64 + 2 * RADIUS];

// Half the surface area of the union of two boxes; +inf for a box of infinite or NaN extent.
float union_area(vec3 alo, vec3 ahi, vec3 blo, vec3 bhi) {
    vec3 d = max(ahi, bhi) - min(alo, blo);
    float a = d.x * d.y + d.y * d.z + d.z * d.x;
    return isnan(a) ? 1.0 / 0.0 : a;
}

// Whether cluster i is the higher of a mutual pair (it merges into the lower one).
bool merged_away(uint i) {
    uint j = neighbour[i];
    return j < i && neighbour[j] == i;
}

// Cluster i's nearest neighbour among the n clusters, reading boxes from `clusters`.
uint nearest(uint i, uint n) {
    vec3 lo = clusters[i].lo.xyz, hi = clusters[i].hi.xyz;
    uint best = i;
    float best_area = 1.0 / 0.0;
    for (uint j = i >= RADIUS ? i - RADIUS : 0u; j <= min(i + RADIUS, n - 1u); ++j) {
        float a = union_area(lo, hi, clusters[j].lo.xyz, clusters[j].hi.xyz);
        if (j != i && (a < best_area || best == i)) {
            best = j;
            best_area = a;
        }
    }
    return best;
}

// The internal nodes of the subtree of `child` (a node made, or a leaf).
uint subtree_nodes(uint child) {
    return (child & BVH_LEAF) != 0u ? 0u : links[child].y;
}

// If cluster i is the lower of a mutual pair: their node, written in cluster i's place.
void merge(uint i) {
    uint j = neighbour[i];
    if (j <= i || neighbour[j] != i) {
        return;
    }
    Cluster l = clusters[i], r = clusters[j];
    uint node = pc.triangles - 2u - atomicAdd(made, 1u);
    built[node] = BvhNode(l.lo, l.hi, r.lo, r.hi);
    uint left = floatBitsToUint(l.lo.w), right = floatBitsToUint(r.lo.w);
    links[node].y = 1u + subtree_nodes(left) + subtree_nodes(right);
    if ((left & BVH_LEAF) == 0u) {
        links[left].x = node;
    }
    if ((right & BVH_LEAF) == 0u) {
        links[right].x = node | RIGHT;
    }
    uint depth = max(floatBitsToUint(l.hi.w), floatBitsToUint(r.hi.w)) + 1u;
    atomicMax(deepest, depth);
    clusters[i] = Cluster(vec4(min(l.lo.xyz, r.lo.xyz), uintBitsToFloat(node)),
                          vec4(max(l.hi.xyz, r.hi.xyz), uintBitsToFloat(depth)));
}

shared uint chunk_kept[64];

// Mode 4: the iterations over the last clusters (at most TAIL) in one workgroup, compacting through
// `next`; each invocation compacts a contiguous chunk.
void tail(uint n) {
    uint lid = gl_LocalInvocationIndex;
    for (uint it = 0u; it < TAIL_ITERATIONS && n > 1u; ++it) {
        for (uint i = lid; i < n; i += 64u) {
            neighbour[i] = nearest(i, n);
        }
        memoryBarrierBuffer();
        barrier();
        for (uint i = lid; i < n; i += 64u) {
            merge(i);
        }
        memoryBarrierBuffer();
        barrier();
        uint chunk = (n + 63u) / 64u;
        uint begin = min(lid * chunk, n), end = min(begin + chunk, n);
        uint kept = 0u;
        for (uint i = begin; i < end; ++i) {
            kept += merged_away(i) ? 0u : 1u;
        }
        chunk_kept[lid] = kept;
        barrier();
        uint before = 0u, total = 0u;
        for (uint c = 0u; c < 64u; ++c) {
            before += c < lid ? chunk_kept[c] : 0u;
            total += chunk_kept[c];
        }
        for (uint i = begin; i < end; ++i) {
            if (!merged_away(i)) {
                next[before] = clusters[i];
                before += 1u;
            }
        }
        memoryBarrierBuffer();
        barrier();
        n = total;
        for (uint i = lid; i < n; i += 64u) {
            clusters[i] = next[i];
        }
        memoryBarrierBuffer();
        barrier();
    }
    if (lid == 0u) {
        counts[pc.parity] = n;
    }
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    uint n = counts[pc.parity];
    if (pc.mode == 0u) {
        if (i == 0u) {
            counts[0] = pc.triangles;
            counts[1] = pc.triangles;
            made = 0u;
            deepest = 0u;
            linear = 0u;
        }
        if (i < pc.triangles) {
            uint t = values[i];
            vec3 a = tris[t].v[0].xyz, b = tris[t].v[1].xyz, c = tris[t].v[2].xyz;
            vec3 lo = vec3(1.0 / 0.0), hi = vec3(-1.0 / 0.0);   // NaN: an empty box, never hit
            if (!any(isnan(a)) && !any(isnan(b)) && !any(isnan(c))) {
                lo = min(min(a, b), c);
                hi = max(max(a, b), c);
            }
            clusters[i] = Cluster(vec4(lo, uintBitsToFloat(BVH_LEAF | t)), vec4(hi, 0.0));
        }
        return;
    }
    if (pc.mode >= 1u && pc.mode <= 2u && pc.forced == 0u && n <= TAIL) {
        return;     // left to mode 4 (mode 3 carries them over to the next iteration's parity)
    }
    if (pc.mode == 4u) {
        if (n <= TAIL) {
            tail(n);
        }
        return;
    }
    if (pc.mode == 1u) {
        if (pc.forced != 0u) {
            if (i < n) {
                uint j = i ^ 1u;
                neighbour[i] = j < n ? j : i;
            }
            return;
        }
        // The workgroup's clusters and RADIUS on either side, through shared memory.
        uint first = gl_WorkGroupID.x * 64u;
        uint lid = gl_LocalInvocationIndex;
        for (uint w = lid; w < 64u + 2u * RADIUS; w += 64u) {
            int k = int(first + w) - int(RADIUS);
            if (k >= 0 && uint(k) < n) {
                window_lo[w] = clusters[k].lo;
                window_hi[w] = clusters[k].hi;
            }
        }
        barrier();
        if (i >= n) {
            return;
        }
        vec3 lo = window_lo[lid + RADIUS].xyz, hi = window_hi[lid + RADIUS].xyz;
        uint lowest = i >= RADIUS ? i - RADIUS : 0u;
        uint highest = min(i + RADIUS, n - 1u);
        uint best = i;
        float best_area = 1.0 / 0.0;
        // Ascending with a strict comparison: of equal areas the lowest pair wins (all j < i before i's
        // own pairs, whose lower index is i).
        for (uint j = lowest; j <= highest; ++j) {
            if (j == i) {
                continue;
            }
            uint w = j + RADIUS - first;
            float a = union_area(lo, hi, window_lo[w].xyz, window_hi[w].xyz);
            if (a < best_area || best == i) {
                best = j;
                best_area = a;
            }
        }
        neighbour[i] = best;
        return;
    }
    if (pc.mode == 2u) {
        if (i >= n) {
            return;
        }
        keep[i] = merged_away(i) ? 0u : 1u;
        merge(i);
        return;
    }
    if (pc.mode == 3u) {
        if (i >= n) {
            return;
        }
        bool carried = pc.forced == 0u && n <= TAIL;
        bool kept = carried || !merged_away(i);
        uint at = carried ? i : position[i];
        if (kept) {
            next[at] = clusters[i];
        }
        if (i == n - 1u) {
            counts[1u - pc.parity] = at + (kept ? 1u : 0u);
        }
        return;
    }
    if (pc.mode == 5u) {
        if (i == 0u) {
            bool whole = n == 1u && floatBitsToUint(clusters[0].lo.w) == 0u && deepest <= MAX_DEPTH;
            linear = whole && pc.forced == 0u ? 0u : 1u;
        }
        return;
    }
    if (i + 1u >= max(pc.triangles, 2u) || (linear != 0u) != (pc.mode == 7u)) {
        return;
    }
    if (pc.mode == 7u) {
        nodes[i] = built[i];
        return;
    }
    uint place = 0u;
    uint at = i;
    for (uint step = 0u; step <= MAX_DEPTH && at != 0u; ++step) {
        uint link = links[at].x;
        uint parent = link & ~RIGHT;
        place += 1u + ((link & RIGHT) != 0u ? subtree_nodes(floatBitsToUint(built[parent].left_lo.w)) : 0u);
        at = parent;
    }
    BvhNode node = built[i];
    uint left = floatBitsToUint(node.left_lo.w), right = floatBitsToUint(node.right_lo.w);
    if ((left & BVH_LEAF) == 0u) {
        node.left_lo.w = uintBitsToFloat(place + 1u);
    }
    if ((right & BVH_LEAF) == 0u) {
        node.right_lo.w = uintBitsToFloat(place + 1u + subtree_nodes(left));
    }
    nodes[place] = node;
}

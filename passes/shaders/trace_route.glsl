// Where a pixel of a trace finds the triangles that may block it: its texel's list, or the BVH (passes::bvh)
// where the map holds no complete list for it (no list built this frame: the bin items passed the bin
// budget; a point light's frame that kept more (triangle, face) pairs than its bin items hold; a texel in a
// group whose offsets overflowed, whose list passed the list limit or the entry capacity; a pixel the
// receiver pass gave no ray, never seen). Needs the includer's writable `ms` (MapState), `offsets[]` and
// map_offsets.glsl, and the subgroup arithmetic extension; the walks are counted in the state for the
// frame report.

// Texel `texel`'s complete list, entries[begin, end); false where the pixel walks the BVH.
bool complete_list(uint texel, out uint begin, out uint end) {
    begin = 0u;
    end = 0u;
    if (texel == TEXEL_NO_RAY || ms.routes.y != 0u || ms.grid.z > ms.grid.w) {
        return false;
    }
    // An empty list is complete wherever it lies; a list is complete when it ends within the capacity.
    return list_range(texel, begin, end) && (end <= ms.totals.z || begin == end);
}

// Counts a pixel's walk of the BVH, and whether it finished (once per subgroup of walking pixels).
void count_walk(bool finished) {
    uvec2 counts = subgroupAdd(uvec2(1u, finished ? 0u : 1u));
    if (subgroupElect()) {
        atomicAdd(ms.walks.x, counts.x);
        if (counts.y > 0u) {
            atomicAdd(ms.walks.y, counts.y);
        }
    }
}

// Counts a pixel of the area trace whose bundle gave up and whose open samples walked the BVH one by one.
void count_sample_walks() {
    uint count = subgroupAdd(1u);
    if (subgroupElect()) {
        atomicAdd(ms.walks.z, count);
    }
}

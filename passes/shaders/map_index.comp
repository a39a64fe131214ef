#version 460
#extension GL_GOOGLE_include_directive : require
// The bin walk's search index (map_bin.glsl): after the scan of the bin triangles' tile counts, entry k
// holds the bin triangle whose items hold item k * chunk (chunk = the items over SEARCH_INDEX_SIZE, rounded
// up), so that map_bin.comp looks an item's triangle up between two neighbouring entries rather than over
// every bin triangle. One invocation per entry, each a binary search over the bin triangles: all of them
// run side by side, where a walk of each triangle's entries would leave a large triangle's invocation
// writing thousands of them alone.
#include "map_state.glsl"
#include "map_push.glsl"
#include "map_bin.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer TileOffsets { uint tile_offsets[]; };
layout(set = 0, binding = 1) writeonly buffer SearchIndex { uint search_index[]; };
layout(set = 0, binding = 2) readonly buffer State { MapState faces[]; };
layout(push_constant) uniform Push { MapPush pc; };

void main() {
    uint entry = gl_GlobalInvocationID.x;
    uint bins = bin_count(pc, faces[0].grid.z);
    uint items = tile_offsets[bins];
    if (items == 0u) {
        return;
    }
    uint chunk = search_chunk(items);
    if (entry > (items - 1u) / chunk) {
        return;     // past the entries in use
    }
    // The last bin triangle whose first item is at or before item entry * chunk (those without items share
    // their successor's offset and are never found).
    uint item = entry * chunk;
    uint lo = 0u, hi = bins;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (tile_offsets[mid] <= item) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    search_index[entry] = lo;
}

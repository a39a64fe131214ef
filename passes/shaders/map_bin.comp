#version 460
#extension GL_GOOGLE_include_directive : require
// Compute binning of the primitive map, load-balanced over bin items: item i is one 4x4-texel tile of one
// triangle's bounding box, found by binary search in the scanned tile offsets, so a large triangle (a
// ground plane, a wall) is spread over many threads instead of stalling one.
// mode 0 counts the accepted (triangle, texel) pairs, mode 1 stores them (map_store.glsl).
#include "map_state.glsl"
#include "map_push.glsl"
#include "map_bin.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer BinTris { BinTri bin_tris[]; };
layout(set = 0, binding = 1) readonly buffer TileOffsets { uint tile_offsets[]; };
layout(set = 0, binding = 2) readonly buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 3) buffer Counts { uint counts[]; };
layout(set = 0, binding = 4) readonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 5) writeonly buffer Entries { uint entries[]; };
layout(push_constant) uniform Push { MapPush pc; };
#include "map_store.glsl"

void main() {
    uint items = tile_offsets[pc.triangles];
    for (uint item = gl_GlobalInvocationID.x; item < items; item += pc.tile_threads) {
        // The last triangle whose first item is at or before `item` (triangles without items share
        // their successor's offset and are never found).
        uint lo = 0u, hi = pc.triangles;
        while (hi - lo > 1u) {
            uint mid = (lo + hi) / 2u;
            if (tile_offsets[mid] <= item) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        BinTri bt = bin_tris[lo];
        uint k = item - tile_offsets[lo];
        uvec2 bmin = uvec2(bt.info.x & 0xFFFFu, bt.info.x >> 16);
        uvec2 bmax = uvec2(bt.info.y & 0xFFFFu, bt.info.y >> 16);
        uvec2 t0 = bmin + uvec2(k % bt.info.w, k / bt.info.w) * BIN_TILE;
        uvec2 t1 = min(t0 + (BIN_TILE - 1u), bmax);
        for (uint y = t0.y; y <= t1.y; ++y) {
            for (uint x = t0.x; x <= t1.x; ++x) {
                uint texel = y * pc.size + x;
                if (bin_accepts(bt, receiver[texel], vec2(x, y) + 0.5, pc.cull != 0u)) {
                    bin_store(lo, texel);
                }
            }
        }
    }
}

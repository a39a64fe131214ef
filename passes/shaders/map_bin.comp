#version 460
#extension GL_GOOGLE_include_directive : require
// Compute binning of the primitive map, load-balanced over bin items: item i is one 4x4-texel tile of one
// bin triangle's bounding box, found by binary search in the scanned tile offsets, so a large triangle (a
// ground plane, a wall) is spread over many threads instead of stalling one. A tile the triangle cannot
// reach is skipped whole (bin_tile_overlaps), and a texel's receiver word is read only where the triangle
// overlaps it. A light of one frustum has one
// bin triangle per prim-buffer triangle; a point light one per (triangle, face) pair its setup kept.
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
layout(set = 0, binding = 6) readonly buffer State { MapState faces[]; };
layout(set = 0, binding = 7) readonly buffer PairOwners { uint pair_owner[]; };
layout(push_constant) uniform Push { MapPush pc; };
#include "map_store.glsl"

void main() {
    uint bins = pc.faces == 1u ? pc.triangles : min(faces[0].grid.z, pc.pairs);
    uint items = tile_offsets[bins];
    for (uint item = gl_GlobalInvocationID.x; item < items; item += pc.tile_threads) {
        // The last bin triangle whose first item is at or before `item` (those without items share
        // their successor's offset and are never found).
        uint lo = 0u, hi = bins;
        while (hi - lo > 1u) {
            uint mid = (lo + hi) / 2u;
            if (tile_offsets[mid] <= item) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        BinTri bt = bin_tris[lo];
        uint owner = pc.faces == 1u ? lo : pair_owner[lo];
        uint tri = owner & 0x1FFFFFFFu;
        uvec4 grid = faces[owner >> 29].grid;
        uint k = item - tile_offsets[lo];
        uvec2 bmin = uvec2(bt.info.x & 0xFFFFu, bt.info.x >> 16);
        uvec2 bmax = uvec2(bt.info.y & 0xFFFFu, bt.info.y >> 16);
        uvec2 t0 = bmin + uvec2(k % bt.info.w, k / bt.info.w) * BIN_TILE;
        uvec2 t1 = min(t0 + (BIN_TILE - 1u), bmax);
        // The tile's texel centres span [t0, t1] + 0.5.
        if (!bin_tile_overlaps(bt, (vec2(t0) + vec2(t1)) * 0.5 + 0.5, (vec2(t1) - vec2(t0)) * 0.5)) {
            continue;
        }
        for (uint y = t0.y; y <= t1.y; ++y) {
            for (uint x = t0.x; x <= t1.x; ++x) {
                uint texel = texel_index(grid, uvec2(x, y));
                if (bin_accepts(bt, texel, vec2(x, y) + 0.5, pc.cull != 0u)) {
                    bin_store(tri, texel);
                }
            }
        }
    }
}

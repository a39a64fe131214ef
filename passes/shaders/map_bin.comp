#version 460
#extension GL_GOOGLE_include_directive : require
// Compute binning of the primitive map, load-balanced over bin items: item i is one 4x4-texel tile of one
// bin triangle's bounding box, found by binary search in the scanned tile offsets between two entries of the
// search index (map_index.comp), so a large triangle (a ground plane, a wall) is spread over many threads
// instead of stalling one. A tile the triangle cannot reach is skipped whole (bin_tile_overlaps), as is one
// whose 4x4-texel tiles hold no ray origin or only nearer ones (tiles_may_accept), and a texel's receiver
// word is read only where the triangle overlaps it. A light of one frustum has one bin triangle per
// prim-buffer triangle; a point light one per (triangle, face) pair its setup kept.
// mode 0 counts the accepted (triangle, texel) pairs (map_store.glsl) and appends them to the pair list;
// mode 1 stores them: from the pair list when it holds every pair the count accepted (one walk in all),
// else by walking the tiles again.
// A frame whose bin items pass the bin budget (per pixel with a ray) walks nothing: the count marks it in the state (routes.y), no
// list is built, and every pixel walks the BVH, whose cost follows the pixel's rays rather than the
// footprints' sizes (a large light's widened footprints cover most of the map).
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_basic : require
#include "map_state.glsl"
#include "map_push.glsl"
#include "map_bin.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer BinTris { BinTri bin_tris[]; };
layout(set = 0, binding = 1) readonly buffer TileOffsets { uint tile_offsets[]; };
layout(set = 0, binding = 2) readonly buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 3) buffer Counts { uint counts[]; };
layout(set = 0, binding = 4) writeonly buffer Entries { uint entries[]; };
layout(set = 0, binding = 5) buffer State { MapState faces[]; };
layout(set = 0, binding = 6) readonly buffer PairOwners { uint pair_owner[]; };
layout(set = 0, binding = 7) buffer PairList { uvec2 pair_list[]; };
layout(set = 0, binding = 8) readonly buffer SearchIndex { uint search_index[]; };
layout(set = 0, binding = 9) buffer Capped { uint capped[]; };
layout(push_constant) uniform Push { MapPush pc; };
#include "map_store.glsl"

// The pairs this invocation accepted in its tile (count mode), appended to the pair list together with the
// rest of its subgroup's: one atomic per subgroup and round.
uint accepted[16];

// Whether a texel in [t0, t1] may accept the triangle under receiver culling: the largest receiver word of
// the (at most 2x2) 4x4-texel tiles they lie in is at least every texel's, so when it is 0 (no ray origin)
// or below the triangle's nearest depth key, bin_accepts rejects every texel of the range.
bool tiles_may_accept(BinTri bt, uvec4 grid, uvec2 t0, uvec2 t1) {
    uvec2 a0 = t0 & ~uvec2(3u), a1 = t1 & ~uvec2(3u);
    uint word = 0u;
    for (uint y = a0.y; y <= a1.y; y += 4u) {
        for (uint x = a0.x; x <= a1.x; x += 4u) {
            word = max(word, receiver[tile_word(grid, uvec2(x, y), pc.texels)]);
        }
    }
    return word != 0u && bt.cmd.w <= unordered(word);
}

void main() {
    uint bins = bin_count(pc, faces[0].grid.z);
    uint items = tile_offsets[bins];
    uint rays = 0u;
    for (uint f = 0u; f < pc.faces; ++f) {
        rays += faces[f].receivers.x;
    }
    bool skipped = float(items) > pc.bin_budget * float(rays);
    if (pc.mode == 0u && gl_GlobalInvocationID.x == 0u) {
        faces[0].routes.xy = uvec2(items, skipped ? 1u : 0u);
    }
    if (skipped) {
        return;
    }
    uint listed = faces[0].totals.x;
    if (pc.mode == 1u && pc.list_capacity > 0u && listed <= pc.list_capacity) {
        // Fill from the pair list the count wrote: no second walk.
        for (uint i = gl_GlobalInvocationID.x; i < listed; i += pc.tile_threads) {
            uvec2 p = pair_list[i];
            bin_store(p.x, p.y);
        }
        return;
    }
    uint chunk = search_chunk(items);
    // Rounds of one item per invocation; every invocation of a workgroup runs every round of its
    // workgroup (the subgroup operations below need the whole subgroup).
    for (uint round_base = gl_WorkGroupID.x * gl_WorkGroupSize.x; round_base < items;
         round_base += pc.tile_threads) {
        uint item = round_base + gl_LocalInvocationID.x;
        uint count = 0u;
        uint tri = 0u;
        if (item < items) {
            // The last bin triangle whose first item is at or before `item` (those without items share
            // their successor's offset and are never found): at or after the one holding item
            // entry * chunk and at or before the one holding item (entry + 1) * chunk (map_index.comp).
            uint entry = item / chunk;
            uint lo = search_index[entry];
            uint hi = entry + 1u <= (items - 1u) / chunk ? search_index[entry + 1u] + 1u : bins;
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
            tri = owner & 0x1FFFFFFFu;
            uint face = owner >> 29;
            uvec4 grid = faces[face].grid;
            // Area shadows: the footprint's widening, and the deepest ray origin of the frustum.
            vec2 widen = faces[face].fit.zw;
            float deepest = unordered(faces[face].receivers.z);
            uint k = item - tile_offsets[lo];
            uvec2 bmin = uvec2(bt.info.x & 0xFFFFu, bt.info.x >> 16);
            uvec2 bmax = uvec2(bt.info.y & 0xFFFFu, bt.info.y >> 16);
            uvec2 t0 = bmin + uvec2(k % bt.info.w, k / bt.info.w) * BIN_TILE;
            uvec2 t1 = min(t0 + (BIN_TILE - 1u), bmax);
            // The tile's texel centres span [t0, t1] + 0.5.
            if (pc.emitter_radius > 0.0) {
                // A spot or point light: the emitter's reach over this tile's receivers rather than the
                // grid's (map_fit.comp): R |row - T row_w| is convex in the texel coordinate T, so its
                // largest value over the tile's texels, with a texel of slack for the receivers' projection
                // error, is at the ends of that range.
                mat4 m = faces[face].to_texels;
                vec3 rx = vec3(m[0][0], m[1][0], m[2][0]);
                vec3 ry = vec3(m[0][1], m[1][1], m[2][1]);
                vec3 rw = vec3(m[0][3], m[1][3], m[2][3]);
                vec2 lo = vec2(t0) - 1.0, hi = vec2(t1) + 2.0;
                float reach = max(max(length(rx - lo.x * rw), length(rx - hi.x * rw)),
                                  max(length(ry - lo.y * rw), length(ry - hi.y * rw)));
                widen.x = min(widen.x, pc.emitter_radius * reach * (1.0 + 1.0 / 1024.0));
            }
            float widest = widen.x == 0.0 ? 0.0 : penumbra_texels(bt, deepest, widen);
            if (bin_tile_overlaps(bt, (vec2(t0) + vec2(t1)) * 0.5 + 0.5, (vec2(t1) - vec2(t0)) * 0.5,
                                  widest)
                && (pc.cull == 0u || tiles_may_accept(bt, grid, t0, t1))) {
                for (uint y = t0.y; y <= t1.y; ++y) {
                    for (uint x = t0.x; x <= t1.x; ++x) {
                        uint texel = texel_index(grid, uvec2(x, y));
                        if (bin_accepts(bt, texel, vec2(x, y) + 0.5, pc.cull != 0u, widen, deepest)) {
                            bin_store(tri, texel);
                            accepted[count] = texel;
                            count += 1u;
                        }
                    }
                }
            }
        }
        if (pc.mode == 0u && pc.list_capacity > 0u) {
            uint total = subgroupAdd(count);
            uint first = 0u;
            if (subgroupElect() && total > 0u) {
                first = atomicAdd(faces[0].totals.x, total);
            }
            uint at = subgroupBroadcastFirst(first) + subgroupExclusiveAdd(count);
            for (uint j = 0u; j < count; ++j) {
                if (at + j < pc.list_capacity) {
                    pair_list[at + j] = uvec2(tri, accepted[j]);
                }
            }
        }
    }
}

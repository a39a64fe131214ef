// The texel test and the store of the compute and raster binning paths (after map_bin.glsl). Needs the
// includer's `receiver`, `counts`, `capped`, `entries` and `pc`.

// Whether `texel`, centred at `centre`, gets triangle `t`: it overlaps the triangle, and (with `cull`) a
// ray origin lies in it and the triangle is not wholly farther from the light than all of them. The
// includer's `receiver[texel]` is the texel's word of the receiver map: 0 without a ray origin, else the
// ordered largest depth key (plus its error) of its ray origins; for hard shadows it is read only for
// overlapped texels. Without `cull`, every overlapped texel is accepted (a debug mode whose lists tests
// compare with exact binning).
// Area shadows (`widen` = the frustum's fit.zw, x > 0; map_fit.comp): the footprint grows by the penumbra
// the triangle can cast on the texel's deepest receiver (the whole map's, `deepest`, without `cull`;
// map_bin.glsl's penumbra_span).
bool bin_accepts(BinTri t, uint texel, vec2 centre, bool cull, vec2 widen, float deepest) {
    if (widen.x == 0.0) {
        if (!bin_overlaps(t, centre, 0.0)) {
            return false;
        }
        if (!cull) {
            return true;
        }
        uint word = receiver[texel];
        return word != 0u && t.cmd.w <= unordered(word);
    }
    float reach = deepest;
    if (cull) {
        uint word = receiver[texel];
        if (word == 0u || t.cmd.w > unordered(word)) {
            return false;
        }
        reach = unordered(word);
    }
    return bin_overlaps(t, centre, penumbra_texels(t, reach, widen));
}

// Counts (mode 0) or stores (mode 1) triangle `tri` in the list of `texel`.
// Count: each pair adds pc.count_scale (1 but in tests that push the sums of entries past 2^32); the count
// that passes the list limit marks the texel in the `capped` bitmask (its list is not kept: the scan takes
// its count as 0, and its pixels walk the BVH).
// Fill: the counts hold the scanned offsets of the lists by then, and serve as each list's cursor.
// Nothing is written at or past the entry capacity: the cursor of a texel whose list is not kept starts
// there (map_pack.comp), and such texels walk the BVH.
void bin_store(uint tri, uint texel) {
    if (pc.mode == 0u) {
        uint before = atomicAdd(counts[texel], pc.count_scale);
        if (before <= pc.list_limit && pc.list_limit - before < pc.count_scale) {
            atomicOr(capped[texel >> 5], 1u << (texel & 31u));
        }
        return;
    }
    uint slot = atomicAdd(counts[texel], 1u);
    if (slot < pc.capacity) {
        entries[slot] = tri;
    }
}

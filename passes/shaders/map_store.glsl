// Counts (mode 0) or stores (mode 1) triangle `tri` in the list of `texel`; shared by the compute and
// raster binning paths. Needs the includer's `counts`, `offsets`, `entries` and `pc`.
// Fill: the slot is offsets[texel] + (counts[texel] -= 1), so the counts return to 0 for the next frame.
// Nothing is written at or past the entry capacity: such texels are traced exhaustively, and reported.
void bin_store(uint tri, uint texel) {
    if (pc.mode == 0u) {
        atomicAdd(counts[texel], 1u);
        return;
    }
    uint slot = offsets[texel] + atomicAdd(counts[texel], 0xFFFFFFFFu) - 1u;
    if (slot < pc.capacity) {
        entries[slot] = tri;
    }
}

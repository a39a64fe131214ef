// Mirrors passes::gpu_types::MapState (192 bytes): the primitive map's per-frame GPU state of one frustum,
// written by the map passes and read by the ray trace. The map covers the light-space bounds of the
// receivers the camera sees (fitted every frame on the GPU), so nothing of it is spent on what no pixel can
// look up. A point light's map holds one state per cube face (+X, -X, +Y, -Y, +Z, -Z), their grids packed
// one after another in one texel array; the first state also holds the map's totals and statistics.
struct MapState {
    mat4 to_texels;     // frame coordinates -> homogeneous map texel space: texel = floor(xy / w)
    uvec4 bounds;       // ordered-float light NDC bounds of the ray origins: min x, min y, max x, max y
    uvec4 receivers;    // x: pixels with a ray, y: ordered max texel-space error of a ray origin's
                        // projection, z: ordered max depth key (plus error) of the ray origins, w: pixels
                        // with a ray inside the light's frustum, counted by the bounds pass
    vec4 fit;           // x: 1 when the map has receivers, y: texels per side of the fitted grid (at most
                        // N; fewer when few rays need it, see map_fit.comp), z: area shadows: directional,
                        // texels a footprint widens per unit of depth key above a receiver; spot or point
                        // light, the emitter's reach in texels (0: hard), w: area shadows of a spot or
                        // point light, the emitter's depth extent (0: otherwise)
    uvec4 totals;       // x: (triangle, texel) pairs the count appended to the pair list, y: entries needed,
                        // z: entry capacity, w: triangles kept by the setup's culling
    uvec4 stats;        // x: texels with a list, y: longest list, z: texels past the capacity (traced
                        // exhaustively), w: texels with receivers
    uvec4 grid;         // x: index of the grid's first texel, y: texels per grid row; first state only: z
                        // (triangle, face) pairs a point light's setup kept, w: pairs the bin items hold
    uvec4 routes;       // first state only: x: bin items (4x4-texel tiles of the footprints; saturated), y: 1
                        // when they passed the bin budget, so that no list was built and every pixel walks
                        // the BVH, z: texels whose list passed the list limit (walked through the BVH),
                        // w: unused
    uvec4 walks;        // first state only, written by the trace: x: pixels that walked the BVH, y: walks
                        // that could not finish (never on a conforming device), z: area trace: pixels
                        // whose bundle passed its walk budget, their open samples walked one by one,
                        // w: area trace: those of them whose tile skipped their bundle
};

// The texel index of texel `t` of the grid whose state's `grid` is `grid`.
uint texel_index(uvec4 grid, uvec2 t) {
    return grid.x + t.y * grid.y + t.x;
}

// The index in the receiver map of the tile word of texel `t` (after the map's `texels` texel words): the
// largest word of the texels of its 4x4 tile, of the tiles sharing its index (distinct tiles of one grid
// never do, their first texels' indices differing by multiples of 4; tiles of neighbouring grids of a cube
// map may: their word is then the largest of theirs, which only keeps more).
uint tile_word(uvec4 grid, uvec2 t, uint texels) {
    return texels + (texel_index(grid, t & ~uvec2(3u)) >> 2);
}

// Monotonic float <-> uint encoding for atomicMin/atomicMax on floats; 0 is below every encoded value, so
// a zero-cleared word means "nothing recorded".
uint ordered(float f) {
    uint b = floatBitsToUint(f);
    return (b & 0x80000000u) != 0u ? ~b : (b | 0x80000000u);
}

float unordered(uint u) {
    return uintBitsToFloat((u & 0x80000000u) != 0u ? (u & 0x7FFFFFFFu) : ~u);
}

// Texel of a pixel's ray origin, written by the receiver pass and read by the ray trace.
const uint TEXEL_NO_RAY = 0xFFFFFFFFu;      // no shadow ray from this pixel
const uint TEXEL_OUTSIDE = 0xFFFFFFFEu;     // the ray origin lies outside the light's frustum: lit

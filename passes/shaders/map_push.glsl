// Mirrors passes::gpu_types::MapPush (80 bytes): push constants of the primitive-map passes.
struct MapPush {
    vec4 to_light;          // xyz: direction towards the light (directional); w: 1 for a spot light
    uint size;              // N: texels per side
    uint mode;              // pass-specific mode
    uint front_only;        // 1: keep only triangles facing the light
    uint triangles;         // triangles in the prim buffer
    uint capacity;          // entry capacity
    uint tile_threads;      // threads of the binning dispatch (grid-stride over the bin items)
    uint guard;             // 1: guard words follow the entries and must stay untouched
    uint cull;              // 1: bin only into texels with ray origins, and not behind all of them
    uint faces;             // frusta in the map: 1, or 6 for a point light's cube faces
    uint pairs;             // (triangle, face) pairs the bin items hold (a point light's map)
    uint texels;            // texels of the map's grids together
    uint list_capacity;     // (triangle, texel) pairs the pair list holds (compute binning; 0: none)
    float penumbra;         // area shadows: tan(angular radius) of the light (0: hard, no widening)
    uint pad0, pad1, pad2;
};

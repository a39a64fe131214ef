// Mirrors passes::gpu_types::MapPush (96 bytes): push constants of the primitive-map passes.
struct MapPush {
    vec4 to_light;          // directional: xyz the direction towards the light, w 0; spot or point light:
                            // xyz its position (frame coordinates), w 1
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
    float penumbra;         // area shadows, directional: tan(angular radius) of the light (0: otherwise)
    float emitter_radius;   // area shadows, spot or point light: the emitter's radius (0: otherwise)
    float near_radius;      // ... triangles nearer the light than this go into every texel with receivers
    float depth_floor;      // ... no point of a farther triangle below this depth key blocks a receiver
    uint list_limit;        // a texel whose list would pass this many entries keeps none (it walks the BVH)
    float bin_budget;       // bin items per pixel with a ray past which no list is built (every pixel walks
                            // the BVH)
    uint count_scale;       // entries each accepted pair counts (1; more in tests of huge sums)
    uint pad;
};

// Mirrors passes::gpu_types::HybridPush (16 bytes).
struct HybridPush {
    uint width;
    uint height;
    float world_space_scale;        // WSS
    float hard_shadow_percentage;   // PHS
};

// Mirrors passes::gpu_types::FxaaPush (32 bytes).
struct FxaaPush {
    uint width;
    uint height;
    uint max_steps;         // longest search along an edge, in steps (1, 1, 1, 1, 2, 2, 2, 2, then 4 pixels)
    uint pad0;
    vec4 params;            // x: relative contrast threshold, y: absolute contrast threshold, z: sub-pixel amount
};

// Mirrors passes::gpu_types::PrimMapPush (96 bytes).
struct PrimMapPush {
    mat4 light_view_proj;       // light view-projection in the frame (origin-relative) coordinates
    vec4 to_light;              // xyz: direction towards the light (directional)
    uint size;                  // N
    uint depth;                 // d
    uint front_only;            // 1: store only triangles facing the light
    uint pad0;
};

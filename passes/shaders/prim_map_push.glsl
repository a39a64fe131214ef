// Mirrors passes::gpu_types::PrimMapPush (112 bytes).
struct PrimMapPush {
    mat4 light_view_proj_rel;   // light view-projection relative to `origin`
    vec4 origin;                // xyz: world origin of light_view_proj_rel
    vec4 to_light;              // xyz: direction towards the light (directional)
    uint size;                  // N
    uint depth;                 // d
    uint front_only;            // 1: store only triangles facing the light
    uint pad0;
};

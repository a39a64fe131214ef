// Mirrors passes::gpu_types::ShadowMapPush (64 bytes).
struct ShadowMapPush {
    mat4 light_view_proj;   // frame coordinates -> light clip space
};

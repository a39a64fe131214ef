// Mirrors passes::gpu_types::GpuLight (208 bytes): the light in frame coordinates.
struct GpuLight {
    mat4 view_proj;         // frame coordinates -> light clip space (standard depth, near 0)
    mat4 inv_view_proj;     // its inverse
    vec4 lin_num;           // linear depth of NDC c = (x, y, d, 1) is dot(lin_num, c) / dot(lin_den, c)
    vec4 lin_den;
    vec4 position;          // spot: xyz position, w = 1; directional: 0
    vec4 direction;         // xyz: direction of travel (directional) or view axis (spot)
    vec4 params;            // x: texel world size (per unit depth for spot), y: emitter size, z: map size,
                            // w: 0 directional, 1 spot
};

// Mirrors passes::gpu_types::GpuTriangle (48 bytes): world-space vertices, w = 1.
struct Triangle {
    vec4 v[3];
};

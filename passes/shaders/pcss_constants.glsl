// Mirrors passes::gpu_types::PcssConstants (352 bytes).
#include "light.glsl"

#define MODE_PCSS_STANDARD 0u
#define MODE_PCSS_SHRINKING 1u
#define MODE_CLASSIC_TEST 2u

struct PcssConstants {
    mat4 inv_view_proj_rel; // inverse(proj * view) with the camera at the origin
    vec4 camera_pos;        // xyz: camera in frame coordinates, w: radians per pixel
    uvec4 dims;             // screen width, height, shadow-map size, mode
    uvec4 taps;             // x: blocker-search taps, y: PCF taps
    vec4 radii;             // x: largest search radius, y / z: smallest / largest filter radius (texels)
    vec4 bias;              // x, y: classic constant / slope bias (texels); z: receiver-plane tolerance
                            // (texels of slope); w: constant tolerance (texels of world size)
    GpuLight light;
};

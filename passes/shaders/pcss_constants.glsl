// Mirrors passes::gpu_types::PcssConstants (448 bytes).
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
    mat4 view_to_world;     // the camera's rotation, view to world (for view-space normals)
    uvec4 surface_mode;     // the engine's normal: see engine_surface.glsl
    vec4 surface;           // x: the depth of background pixels, y: a view-Z image's relative precision,
                            // z: the normal image's precision
};

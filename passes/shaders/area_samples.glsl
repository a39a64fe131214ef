// Mirrors passes::gpu_types::AreaSamples (2064 bytes): the light samples of the area trace, the same
// directions for every pixel (passes::area::area_sample_directions).
struct AreaSamples {
    vec4 center;        // xyz: unit direction towards the light's centre; w: bound on |dirs[i] - center|
    vec4 dirs[128];     // directions towards the light (unit); the first RayTraceConstants.misc.w are used
};

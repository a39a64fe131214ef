// Mirrors passes::gpu_types::AreaSamples (4144 bytes): the light samples of the area trace, the same
// directions for every pixel (passes::area::area_sample_directions), and a grid over their gnomonic
// coordinates (w.axis_u / w.center, w.axis_v / w.center) that finds the samples a triangle may hide.
#define SAMPLE_GRID 8u
struct AreaSamples {
    vec4 center;            // xyz: unit direction towards the light's centre; w: bound on |dirs[i] - center|
    vec4 axis_u;            // xyz: first axis of the grid's plane; w: the grid's half-extent (gnomonic)
    vec4 axis_v;            // xyz: second axis; w: grid cells per gnomonic unit
    uvec4 u_range[64];      // [a * SAMPLE_GRID + b]: samples whose u may lie in grid columns a..=b
    uvec4 v_range[64];      // [a * SAMPLE_GRID + b]: samples whose v may lie in grid rows a..=b
    vec4 dirs[128];         // directions towards the light (unit); the first RayTraceConstants.misc.w used
};

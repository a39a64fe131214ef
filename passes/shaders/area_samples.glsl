// Mirrors passes::gpu_types::AreaSamples (2096 bytes): the light samples of the area trace, the same
// directions for every pixel (passes::area::area_sample_directions), and the light's frame in which the
// edge table (passes::area::AreaEdgeTable) places a triangle edge's line.
#define EDGE_ANGLES 64u
#define EDGE_OFFSETS 64u
struct AreaSamples {
    vec4 center;            // xyz: unit direction towards the light's centre C; w: bound on |dirs[i] - C|
    vec4 axis_u;            // xyz: first axis of the light's frame; w: half-extent of the table's offsets
    vec4 axis_v;            // xyz: second axis; w: offset cells per gnomonic unit
    vec4 dirs[128];         // directions towards the light (unit); the first RayTraceConstants.misc.w used
};

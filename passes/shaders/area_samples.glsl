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

// A spot or point light's emitter disc facing the receiver point `receiver` (reference::disc_basis): its
// axes are the rotation taking +Y to the unit direction from the receiver towards the light's centre
// `centre`, applied to +X and +Z, scaled by the emitter's radius. Sample i is the point
// centre + dirs[i].x * u + dirs[i].y * v.
void disc_axes(vec3 centre, vec3 receiver, float radius, out vec3 u, out vec3 v) {
    vec3 d = normalize(centre - receiver);
    float inv = 1.0 / (1.0 + d.y);
    vec3 t1 = vec3(1.0, 0.0, 0.0), t2 = vec3(0.0, 0.0, -1.0);
    if (!isinf(inv) && !isnan(inv)) {
        t1 = vec3(1.0 - d.x * d.x * inv, -d.x, -d.x * d.z * inv);
        t2 = vec3(-d.z * d.x * inv, -d.z, 1.0 - d.z * d.z * inv);
    }
    u = radius * t1;
    v = radius * t2;
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Evaluates the passes' lower bound on a point's distance to a triangle (f32_bounds.glsl, distance_below,
// by which map_setup.comp culls an area light's triangles) for each query, for the test that holds it
// against the exact distance.
#include "f32_bounds.glsl"

layout(local_size_x = 64) in;

// One query: the point and the triangle's vertices (w unused).
struct Query {
    vec4 p;
    vec4 a;
    vec4 b;
    vec4 c;
};

layout(set = 0, binding = 0) readonly buffer Queries { Query queries[]; };
layout(set = 0, binding = 1) writeonly buffer Bounds { float bounds[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < pc.count) {
        Query q = queries[i];
        bounds[i] = distance_below(q.p.xyz, q.a.xyz, q.b.xyz, q.c.xyz);
    }
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Deep primitive map raster: one vertex per prim-buffer vertex, projected into light space.
#include "triangle.glsl"
#include "prim_map_push.glsl"

layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(push_constant) uniform Push { PrimMapPush pc; };
layout(location = 0) out vec3 out_world;

void main() {
    vec3 p = tris[gl_VertexIndex / 3].v[gl_VertexIndex % 3].xyz;
    out_world = p;
    gl_Position = pc.light_view_proj * vec4(p, 1.0);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer: pulls world-space triangles from the prim buffer (gl_PrimitiveID = prim buffer slot).
#include "triangle.glsl"
#include "gbuffer_push.glsl"

layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(push_constant) uniform Push { GBufferPush pc; };
layout(location = 0) out vec3 out_rel_pos;

void main() {
    vec3 p = tris[gl_VertexIndex / 3].v[gl_VertexIndex % 3].xyz;
    vec3 rel = p - pc.camera_pos.xyz;
    out_rel_pos = rel;
    gl_Position = pc.view_proj_rel * vec4(rel, 1.0);
}

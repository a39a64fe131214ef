#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer: pulls the scene's triangles from its index and vertex buffers (gl_VertexIndex = index slot),
// and hands the fragments its triangle's geometric normal (the same for its three vertices).
#include "gbuffer_push.glsl"

layout(push_constant) uniform Push { GBufferPush pc; };
#include "gbuffer_scene.glsl"
layout(location = 0) out vec3 out_rel_pos;
layout(location = 1) flat out vec3 out_triangle_normal;

void main() {
    uint index = uint(gl_VertexIndex);
    vec3 rel = frame_vertex(index) - pc.camera_pos.xyz;
    out_rel_pos = rel;
    out_triangle_normal = triangle_normal(index / 3u);
    gl_Position = pc.view_proj_rel * vec4(rel, 1.0);
}

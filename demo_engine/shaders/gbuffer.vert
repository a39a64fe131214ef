#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer: drawn through the scene's index buffer; pulls vertex gl_VertexIndex from its positions.
#include "gbuffer_push.glsl"

layout(push_constant) uniform Push { GBufferPush pc; };
#include "gbuffer_scene.glsl"
layout(location = 0) out vec3 out_rel_pos;

void main() {
    vec3 rel = frame_vertex(uint(gl_VertexIndex)) - pc.camera_pos.xyz;
    out_rel_pos = rel;
    gl_Position = pc.view_proj_rel * vec4(rel, 1.0);
}

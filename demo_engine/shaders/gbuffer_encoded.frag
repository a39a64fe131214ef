#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer for analysis: frame-relative position, the exact geometric normal facing the camera (world xyz,
// coverage in w), and the same normal as the engine's normal target stores it.
#include "gbuffer_push.glsl"

layout(push_constant) uniform Push { GBufferPush pc; };
#include "gbuffer_scene.glsl"
#include "gbuffer_surface.glsl"
layout(location = 0) in vec3 rel_pos;
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_engine_normal;

void main() {
    vec3 n = facing_normal(triangle_normal(gl_PrimitiveID), rel_pos);
    out_position = vec4(rel_pos + pc.camera_pos.xyz, 1.0);
    out_normal = vec4(n, 1.0);
    out_engine_normal = encode_normal(n);
}

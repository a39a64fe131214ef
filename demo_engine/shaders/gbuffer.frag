#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer for analysis: frame-relative position and the exact geometric normal of the visible triangle,
// facing the camera (world xyz, coverage in w), which the plugin reads as it is.
#include "gbuffer_push.glsl"

layout(push_constant) uniform Push { GBufferPush pc; };
#include "gbuffer_scene.glsl"
#include "gbuffer_surface.glsl"
layout(location = 0) in vec3 rel_pos;
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;

void main() {
    out_position = vec4(rel_pos + pc.camera_pos.xyz, 1.0);
    out_normal = vec4(facing_normal(triangle_normal(gl_PrimitiveID), rel_pos), 1.0);
}

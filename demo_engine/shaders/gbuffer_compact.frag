#version 460
#extension GL_GOOGLE_include_directive : require
// Compact G-buffer: depth and the engine's normal target alone (what the plugin reads).
#include "gbuffer_push.glsl"

layout(push_constant) uniform Push { GBufferPush pc; };
#include "gbuffer_scene.glsl"
#include "gbuffer_surface.glsl"
layout(location = 0) in vec3 rel_pos;
layout(location = 0) out vec4 out_engine_normal;

void main() {
    out_engine_normal = encode_normal(facing_normal(triangle_normal(gl_PrimitiveID), rel_pos));
}

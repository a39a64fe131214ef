#version 460
#extension GL_GOOGLE_include_directive : require
// Compact G-buffer: depth and the engine's normal target alone (what the plugin reads).
#include "triangle.glsl"
#include "gbuffer_push.glsl"

layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(push_constant) uniform Push { GBufferPush pc; };
#include "gbuffer_surface.glsl"
layout(location = 0) in vec3 rel_pos;
layout(location = 0) out vec4 out_engine_normal;

void main() {
    out_engine_normal = encode_normal(facing_normal(gl_PrimitiveID, rel_pos));
}

#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer: frame-relative position and the exact geometric normal of the visible triangle, facing the camera.
#include "triangle.glsl"
#include "gbuffer_push.glsl"

layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(push_constant) uniform Push { GBufferPush pc; };
layout(location = 0) in vec3 rel_pos;
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;

void main() {
    Triangle t = tris[gl_PrimitiveID];
    vec3 c = cross(t.v[1].xyz - t.v[0].xyz, t.v[2].xyz - t.v[0].xyz);
    float len = length(c);
    vec3 n = len > 0.0 ? c / len : vec3(0.0);
    // Face the camera, decided geometrically (independent of winding and projection handedness).
    if (dot(n, -rel_pos) < 0.0) {
        n = -n;
    }
    out_position = vec4(rel_pos + pc.camera_pos.xyz, 1.0);
    out_normal = vec4(n, 1.0);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Conventional shadow map: depth from the light of every prim-buffer triangle (both faces, depth clamp on,
// so casters between the light and its near plane still occlude).
#include "triangle.glsl"
#include "shadow_map_push.glsl"

layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(push_constant) uniform Push { ShadowMapPush pc; };

void main() {
    vec3 p = tris[gl_VertexIndex / 3].v[gl_VertexIndex % 3].xyz;
    gl_Position = pc.light_view_proj * vec4(p, 1.0);
}

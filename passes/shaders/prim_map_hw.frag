#version 460
#extension GL_GOOGLE_include_directive : require
// Hardware conservative raster path: the rasterizer already overestimates coverage.
#include "triangle.glsl"
#include "prim_map_push.glsl"

layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(push_constant) uniform Push { PrimMapPush pc; };
#include "prim_map_append.glsl"

void main() {
    if (pc.front_only != 0u) {
        // Facing decided from the triangle itself, as in the software path.
        Triangle t = tris[gl_PrimitiveID];
        if (dot(cross(t.v[1].xyz - t.v[0].xyz, t.v[2].xyz - t.v[0].xyz), pc.to_light.xyz) <= 0.0) {
            return;
        }
    }
    append_primitive(uint(gl_PrimitiveID));
}

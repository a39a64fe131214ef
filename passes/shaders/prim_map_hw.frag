#version 460
#extension GL_GOOGLE_include_directive : require
// Hardware conservative raster path: the rasterizer already overestimates coverage.
#include "prim_map_push.glsl"

layout(push_constant) uniform Push { PrimMapPush pc; };
#include "prim_map_append.glsl"

void main() {
    append_primitive(uint(gl_PrimitiveID));
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Software conservative raster: exact separating-axis test of the texel square (grown by ACCEPT_MARGIN)
// against the triangle — the two texel axes (box) and the triangle's edge normals — computed relative
// to the triangle's vertices so it stays accurate far from the map origin.
#include "prim_map_push.glsl"
#include "prim_map_sw.glsl"

layout(push_constant) uniform Push { PrimMapPush pc; };
#include "prim_map_append.glsl"

layout(location = 0) flat in vec4 in_p01;
layout(location = 1) flat in vec4 in_p2m;
layout(location = 2) flat in vec4 in_box;

float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }

bool edge_overlaps(vec2 a, vec2 b, vec2 centre) {
    vec2 e = b - a;
    return cross2(e, centre - a) + (0.5 + ACCEPT_MARGIN) * (abs(e.x) + abs(e.y)) >= 0.0;
}

void main() {
    vec2 centre = gl_FragCoord.xy;
    if (any(lessThan(centre, in_box.xy)) || any(greaterThan(centre, in_box.zw))) {
        return;
    }
    vec2 a = in_p01.xy, b = in_p01.zw, c = in_p2m.xy;
    int mode = int(in_p2m.z);
    if (mode == MODE_TRIANGLE) {
        if (!edge_overlaps(a, b, centre) || !edge_overlaps(b, c, centre) || !edge_overlaps(c, a, centre)) {
            return;
        }
    } else if (mode == MODE_SEGMENT) {
        vec2 e = b - a;
        if (abs(cross2(e, centre - a)) > (0.5 + ACCEPT_MARGIN) * (abs(e.x) + abs(e.y))) {
            return;
        }
    }
    append_primitive(uint(gl_PrimitiveID));
}

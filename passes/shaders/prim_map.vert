#version 460
#extension GL_GOOGLE_include_directive : require
// Raster binning paths: one vertex per corner of each set-up triangle (map_setup.comp), in texel space.
// A triangle is pushed out by its margin (plus RASTER_MARGIN for the rasterizer's vertex snapping), so a
// conservative rasterizer generates every texel whose square, grown by the margin, touches it; segments,
// points and covers become a triangle enclosing their bounding box. Culled triangles land outside the map.
#include "map_state.glsl"
#include "map_push.glsl"
#include "map_bin.glsl"
#include "map_raster.glsl"

layout(set = 0, binding = 0) readonly buffer BinTris { BinTri bin_tris[]; };
layout(push_constant) uniform Push { MapPush pc; };

void main() {
    uint corner = uint(gl_VertexIndex) % 3u;
    BinTri bt = bin_tris[uint(gl_VertexIndex) / 3u];
    if (bt.info.w == 0u) {
        gl_Position = vec4(4.0, 4.0, 0.5, 1.0);
        return;
    }
    vec2 q;
    if (bt.info.z == MODE_TRIANGLE) {
        q = dilated_corner(bt, corner, bt.cmd.z + RASTER_MARGIN);
    } else {
        vec2 lo = vec2(bin_box_min(bt));
        vec2 hi = vec2(bin_box_max(bt)) + 1.0;
        q = corner == 0u ? lo : (corner == 1u ? vec2(2.0 * hi.x - lo.x, lo.y) : vec2(lo.x, 2.0 * hi.y - lo.y));
    }
    gl_Position = vec4(q / float(pc.size) * 2.0 - 1.0, 0.5, 1.0);
}

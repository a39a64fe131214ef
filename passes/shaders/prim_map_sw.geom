#version 460
#extension GL_GOOGLE_include_directive : require
// Software conservative raster (GPU Gems 2, ch. 42): emits a polygon covering the centre of every texel
// whose square, grown by the triangle's margin, may touch the triangle: the triangle with each edge pushed
// out by half a texel plus the margin, or the texel-centre box of its bounding box when that is smaller
// (acute and sliver triangles, segments, covers). The fragment shader makes the exact test.
#include "map_state.glsl"
#include "map_push.glsl"
#include "map_bin.glsl"
#include "map_raster.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 4) out;
layout(set = 0, binding = 0) readonly buffer BinTris { BinTri bin_tris[]; };
layout(push_constant) uniform Push { MapPush pc; };

void emit(vec2 q) {
    gl_PrimitiveID = gl_PrimitiveIDIn;
    gl_Position = vec4(q / float(pc.size) * 2.0 - 1.0, 0.5, 1.0);
    EmitVertex();
}

void main() {
    BinTri bt = bin_tris[uint(gl_PrimitiveIDIn)];
    if (bt.info.w == 0u) {
        return;
    }
    vec2 rlo = vec2(bin_box_min(bt)) + 0.5 - RASTER_MARGIN;
    vec2 rhi = vec2(bin_box_max(bt)) + 0.5 + RASTER_MARGIN;
    if (bt.info.z == MODE_TRIANGLE) {
        float grow = 0.5 + bt.cmd.z + RASTER_MARGIN;
        vec2 v[3] = vec2[3](dilated_corner(bt, 0u, grow), dilated_corner(bt, 1u, grow),
                            dilated_corner(bt, 2u, grow));
        float tri_area = 0.5 * abs(cross2(v[1] - v[0], v[2] - v[0]));
        if (tri_area < (rhi.x - rlo.x) * (rhi.y - rlo.y)) {
            emit(v[0]);
            emit(v[1]);
            emit(v[2]);
            EndPrimitive();
            return;
        }
    }
    emit(rlo);
    emit(vec2(rhi.x, rlo.y));
    emit(vec2(rlo.x, rhi.y));
    emit(rhi);
    EndPrimitive();
}

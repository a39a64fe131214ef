#version 460
#extension GL_GOOGLE_include_directive : require
// Software conservative raster (GPU Gems 2, ch. 42): emits a polygon covering the centre of every texel
// whose square may touch the triangle — the triangle with each edge pushed out by the texel's
// semi-diagonal, or its grown bounding box when that is smaller (acute and sliver triangles) — and hands
// the fragment shader the exact data for the final texel/triangle overlap test.
#include "prim_map_push.glsl"
#include "prim_map_sw.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 4) out;
layout(push_constant) uniform Push { PrimMapPush pc; };
layout(location = 0) in vec3 in_world[];
layout(location = 0) flat out vec4 out_p01;   // texel-space p0.xy, p1.xy
layout(location = 1) flat out vec4 out_p2m;   // p2.xy, mode, unused
layout(location = 2) flat out vec4 out_box;   // accepted pixel-centre box (min.xy, max.xy)

float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }

void emit(vec2 q, vec4 p01, vec4 p2m, vec4 box) {
    out_p01 = p01;
    out_p2m = p2m;
    out_box = box;
    gl_PrimitiveID = gl_PrimitiveIDIn;
    gl_Position = vec4(q / float(pc.size) * 2.0 - 1.0, 0.5, 1.0);
    EmitVertex();
}

void main() {
    if (pc.front_only != 0u) {
        vec3 n = cross(in_world[1] - in_world[0], in_world[2] - in_world[0]);
        if (dot(n, pc.to_light.xyz) <= 0.0) {
            return;
        }
    }
    float size = float(pc.size);
    vec2 p[3];
    for (int i = 0; i < 3; ++i) {
        vec4 c = gl_in[i].gl_Position;
        if (c.w <= 0.0) {
            // Behind a perspective light: conservatively cover the whole map.
            vec4 box = vec4(-1.0, -1.0, size + 1.0, size + 1.0);
            vec4 p2m = vec4(0.0, 0.0, float(MODE_BOX), 0.0);
            emit(vec2(-1.0, -1.0), vec4(0.0), p2m, box);
            emit(vec2(size + 1.0, -1.0), vec4(0.0), p2m, box);
            emit(vec2(-1.0, size + 1.0), vec4(0.0), p2m, box);
            emit(vec2(size + 1.0, size + 1.0), vec4(0.0), p2m, box);
            EndPrimitive();
            return;
        }
        p[i] = (c.xy / c.w * 0.5 + 0.5) * size;
    }
    float grow = 0.5 + ACCEPT_MARGIN;
    vec2 lo = min(min(p[0], p[1]), p[2]);
    vec2 hi = max(max(p[0], p[1]), p[2]);
    vec4 box = vec4(lo - grow, hi + grow);
    vec2 e[3] = vec2[3](p[1] - p[0], p[2] - p[1], p[0] - p[2]);
    float area2 = cross2(e[0], -e[2]);
    int longest = 0;
    for (int i = 1; i < 3; ++i) {
        if (dot(e[i], e[i]) > dot(e[longest], e[longest])) {
            longest = i;
        }
    }
    float lmax = length(e[longest]);
    int mode = MODE_TRIANGLE;
    if (lmax == 0.0) {
        mode = MODE_BOX;
    } else if (abs(area2) / lmax < ACCEPT_MARGIN * 0.25) {
        mode = MODE_SEGMENT;
    }
    // Counter-clockwise order (positive area) for the fragment test.
    vec2 a = p[0], b = p[1], c = p[2];
    if (mode == MODE_TRIANGLE && area2 < 0.0) {
        b = p[2];
        c = p[1];
    }
    if (mode == MODE_SEGMENT) {
        a = p[longest];
        b = p[(longest + 1) % 3];
        c = b;
    }
    vec4 p01 = vec4(a, b);
    vec4 p2m = vec4(c, float(mode), 0.0);
    vec2 rlo = box.xy - RASTER_MARGIN;
    vec2 rhi = box.zw + RASTER_MARGIN;
    float box_area = (rhi.x - rlo.x) * (rhi.y - rlo.y);
    if (mode == MODE_TRIANGLE) {
        // Dilated triangle: vertex i is where the pushed-out edges meeting at it intersect.
        vec2 q[3] = vec2[3](a, b, c);
        vec2 ed[3] = vec2[3](b - a, c - b, a - c);
        float det = cross2(ed[2], ed[0]);
        vec2 v[3];
        for (int i = 0; i < 3; ++i) {
            vec2 ep = ed[(i + 2) % 3];
            vec2 en = ed[i];
            float rp = (grow + RASTER_MARGIN) * (abs(ep.x) + abs(ep.y));
            float rn = (grow + RASTER_MARGIN) * (abs(en.x) + abs(en.y));
            v[i] = q[i] + (ep * rn - en * rp) / det;
        }
        float tri_area = 0.5 * abs(cross2(v[1] - v[0], v[2] - v[0]));
        if (tri_area < box_area) {
            emit(v[0], p01, p2m, box);
            emit(v[1], p01, p2m, box);
            emit(v[2], p01, p2m, box);
            EndPrimitive();
            return;
        }
    }
    emit(rlo, p01, p2m, box);
    emit(vec2(rhi.x, rlo.y), p01, p2m, box);
    emit(vec2(rlo.x, rhi.y), p01, p2m, box);
    emit(rhi, p01, p2m, box);
    EndPrimitive();
}

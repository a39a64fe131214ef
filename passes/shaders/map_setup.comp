#version 460
#extension GL_GOOGLE_include_directive : require
// Per triangle: culls what can never shadow a ray origin of this frame, projects the rest into the fitted
// map and counts the 4x4-texel tiles of its bounding box (the bin items, scanned into offsets next).
// Culled: zero-area triangles with two equal vertices (the ray test's determinant is exactly 0 for them,
// so they never hit), back faces in front-only mode, triangles outside the receivers' texels, and
// triangles wholly farther from the light than every ray origin.
#include "triangle.glsl"
#include "map_state.glsl"
#include "map_project.glsl"
#include "map_push.glsl"
#include "map_bin.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(set = 0, binding = 1) buffer State { MapState ms; };
layout(set = 0, binding = 2) writeonly buffer BinTris { BinTri bin_tris[]; };
layout(set = 0, binding = 3) writeonly buffer TileCounts { uint tile_counts[]; };
layout(push_constant) uniform Push { MapPush pc; };

// Projected coordinates beyond this many texels cover the whole clamped box (no edge functions that could
// overflow).
const float FAR_TEXELS = 1048576.0;
// Triangles thinner than this (texels) are binned as the segment of their longest edge.
const float SEGMENT_THICKNESS = 1.0 / 16.0;

uint pack_texel(ivec2 t) { return uint(t.x) | (uint(t.y) << 16); }

uint setup(uint index, out BinTri bt) {
    bt.ab = vec4(0.0);
    bt.cmd = vec4(0.0);
    bt.info = uvec4(0u);
    if (ms.fit.x == 0.0) {
        return 0u;
    }
    vec3 v0 = tris[index].v[0].xyz, v1 = tris[index].v[1].xyz, v2 = tris[index].v[2].xyz;
    if (v0 == v1 || v1 == v2 || v2 == v0) {
        return 0u;
    }
    if (pc.front_only != 0u && dot(cross(v1 - v0, v2 - v0), pc.to_light.xyz) <= 0.0) {
        return 0u;
    }
    bool perspective = pc.to_light.w != 0.0;
    Projected p[3] = Projected[3](project(ms.to_texels, v0, perspective),
                                  project(ms.to_texels, v1, perspective),
                                  project(ms.to_texels, v2, perspective));
    int last = int(pc.size) - 1;
    ivec2 lo_t = ivec2(0), hi_t = ivec2(last);
    uint mode = MODE_COVER;
    float min_depth = -1.0 / 0.0;
    bool behind = p[0].w <= 0.0 || p[1].w <= 0.0 || p[2].w <= 0.0;
    if (!behind) {
        min_depth = min(min(p[0].depth - p[0].depth_err, p[1].depth - p[1].depth_err),
                        p[2].depth - p[2].depth_err);
        if (pc.cull != 0u && min_depth > unordered(ms.receivers.z)) {
            return 0u;  // behind every ray origin as seen from the light
        }
        float err = max(max(max(p[0].xy_err.x, p[0].xy_err.y), max(p[1].xy_err.x, p[1].xy_err.y)),
                        max(p[2].xy_err.x, p[2].xy_err.y));
        float margin = ACCEPT_MARGIN + err + 2.0 * unordered(ms.receivers.y);
        vec2 lo = min(min(p[0].xy, p[1].xy), p[2].xy) - margin;
        vec2 hi = max(max(p[0].xy, p[1].xy), p[2].xy) + margin;
        if (any(greaterThan(lo, vec2(float(last) + 1.0))) || any(lessThan(hi, vec2(0.0)))) {
            return 0u;  // outside the map: no ray origin projects there
        }
        lo_t = clamp(ivec2(floor(lo)), ivec2(0), ivec2(last));
        hi_t = clamp(ivec2(floor(hi)), ivec2(0), ivec2(last));
        bool far = any(greaterThan(abs(vec4(lo, hi)), vec4(FAR_TEXELS)));
        if (!far) {
            vec2 a = p[0].xy, b = p[1].xy, c = p[2].xy;
            vec2 e[3] = vec2[3](b - a, c - b, a - c);
            float area2 = cross2(e[0], -e[2]);
            int longest = 0;
            for (int i = 1; i < 3; ++i) {
                if (dot(e[i], e[i]) > dot(e[longest], e[longest])) {
                    longest = i;
                }
            }
            float lmax = length(e[longest]);
            if (lmax == 0.0) {
                mode = MODE_POINT;
            } else if (abs(area2) / lmax < SEGMENT_THICKNESS) {
                // A sliver: the segment of its longest edge, with the margin grown by the sliver's
                // thickness (the triangle lies within that distance of the segment). No raster path can
                // lose it to vertex snapping.
                mode = MODE_SEGMENT;
                margin += abs(area2) / lmax;
                a = p[longest].xy;
                b = p[(longest + 1) % 3].xy;
                c = b;
            } else {
                mode = MODE_TRIANGLE;
                if (area2 < 0.0) {
                    b = p[2].xy;
                    c = p[1].xy;
                }
            }
            bt.ab = vec4(a, b);
            bt.cmd.xy = c;
        }
        bt.cmd.z = margin;
    }
    bt.cmd.w = min_depth;
    uvec2 tiles = (uvec2(hi_t - lo_t) + BIN_TILE) / BIN_TILE;
    bt.info = uvec4(pack_texel(lo_t), pack_texel(hi_t), mode, tiles.x);
    return tiles.x * tiles.y;
}

shared uint group_kept;

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        group_kept = 0u;
    }
    barrier();
    uint index = gl_GlobalInvocationID.x;
    if (index < pc.triangles) {
        BinTri bt;
        uint tiles = setup(index, bt);
        bin_tris[index] = bt;
        tile_counts[index] = tiles;
        if (tiles > 0u) {
            atomicAdd(group_kept, 1u);
        }
    } else if (index == pc.triangles) {
        tile_counts[index] = 0u;    // the exclusive scan's last element becomes the total
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u && group_kept > 0u) {
        atomicAdd(ms.totals.w, group_kept);
    }
}

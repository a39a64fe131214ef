#version 460
#extension GL_GOOGLE_include_directive : require
// Per triangle and frustum (a point light's six cube faces, or the light's one): culls what can never
// shadow a ray origin of this frame, projects the rest into the frustum's fitted grid and counts the
// 4x4-texel tiles of its bounding box (the bin items, scanned into offsets next). A light of one frustum
// writes triangle i's bin item at i (the raster paths draw them in that order); a point light appends the
// (triangle, face) pairs it keeps, up to the pairs the bin items hold, and counts them all (a frame that
// keeps more traces exhaustively, and the pairs grow for the next one).
// Culled: zero-area triangles with two equal vertices (the ray test's determinant is exactly 0 for them,
// so they never hit), back faces in front-only mode, triangles outside the receivers' texels, triangles
// wholly farther from the light than every ray origin, and, for a perspective light, triangles wholly on or
// behind the light's plane. Triangles that cross that plane keep exactly their part in front of it
// (clipped_setup). Area shadows widen each footprint by the penumbra it can cast (map_bin.glsl's
// penumbra_span); for a spot or point light, triangles within the near radius of its centre are listed in
// every texel with receivers, and farther ones are culled below a depth floor that grows with their
// distance from the light (passes::area::LocalAreaReach).
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_basic : require
#include "triangle.glsl"
#include "f32_bounds.glsl"
#include "map_state.glsl"
#include "map_project.glsl"
#include "map_push.glsl"
#include "map_bin.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer Prims { Triangle tris[]; };
layout(set = 0, binding = 1) buffer State { MapState faces[]; };
layout(set = 0, binding = 2) writeonly buffer BinTris { BinTri bin_tris[]; };
layout(set = 0, binding = 3) writeonly buffer TileCounts { uint tile_counts[]; };
layout(set = 0, binding = 4) writeonly buffer PairOwners { uint pair_owner[]; };
layout(push_constant) uniform Push { MapPush pc; };

// Projected coordinates beyond this many texels cover the whole clamped box (no edge functions that could
// overflow).
const float FAR_TEXELS = 1048576.0;
// Triangles thinner than this (texels) are binned as the segment of their longest edge.
const float SEGMENT_THICKNESS = 1.0 / 16.0;

uint pack_texel(ivec2 t) { return uint(t.x) | (uint(t.y) << 16); }

// Rounds a bound computed in f32 (a few positive terms) up past its own rounding.
const float ROUND_UP = 1.0 + 1.0 / 65536.0;

// The homogeneous line through two homogeneous texel points (their cross product: the light's plane through
// an edge) and a bound on how far the computed coefficients are from the exact line through the exact
// points (the points' projection error, propagated, plus the rounding of the products).
struct Line {
    vec3 l;
    vec3 e;
};

Line edge_line(HPoint a, HPoint b) {
    precise vec3 l = vec3(a.h.y * b.h.z - a.h.z * b.h.y, a.h.z * b.h.x - a.h.x * b.h.z,
                          a.h.x * b.h.y - a.h.y * b.h.x);
    vec3 aa = abs(a.h), ab = abs(b.h);
    vec3 e = cross_mag(a.err, ab) + cross_mag(aa, b.err) + cross_mag(a.err, b.err)
           + 4.0 * U * cross_mag(aa, ab);
    return Line(l, e * ROUND_UP);
}

// Clips the convex polygon `poly` (n vertices) to the half-plane dot(l, (x, y, 1)) + slack >= 0.
int clip_polygon(inout vec2 poly[8], int n, vec3 l, float slack) {
    vec2 kept[8];
    int m = 0;
    for (int i = 0; i < n; ++i) {
        vec2 a = poly[i], b = poly[(i + 1) % n];
        float fa = dot(l, vec3(a, 1.0)) + slack, fb = dot(l, vec3(b, 1.0)) + slack;
        if (fa >= 0.0) {
            kept[m++] = a;
        }
        if ((fa >= 0.0) != (fb >= 0.0)) {
            kept[m++] = a + clamp(fa / (fa - fb), 0.0, 1.0) * (b - a);
        }
    }
    poly = kept;
    return m;
}

// Bounding box (lo, hi) of the map square [0, N]^2 where every line, times `orientation`, is >= minus its
// slack; false when that is empty.
bool clipped_box(float n, vec3 l[3], vec3 slack, float orientation, out vec2 lo, out vec2 hi) {
    vec2 poly[8] = vec2[8](vec2(0.0), vec2(n, 0.0), vec2(n), vec2(0.0, n), vec2(0.0), vec2(0.0),
                           vec2(0.0), vec2(0.0));
    int count = 4;
    for (int i = 0; i < 3 && count > 0; ++i) {
        if (l[i] != vec3(0.0)) {
            count = clip_polygon(poly, count, orientation * l[i], slack[i]);
        }
    }
    lo = vec2(1.0 / 0.0);
    hi = vec2(-1.0 / 0.0);
    for (int i = 0; i < count; ++i) {
        lo = min(lo, poly[i]);
        hi = max(hi, poly[i]);
    }
    return count > 0;
}

// A triangle of a perspective light that reaches the light's plane (a vertex on or behind it, within its
// projection error) or lies so close to it that its projection leaves the edge-function range.
//
// Why this is exact: only the part of a triangle in front of the light's plane can block a segment from a
// receiver in front of it to the light (every point of such a segment has w > 0). The light's rays through
// texel point p = (x, y, 1) hit the triangle in front of the light iff p = sum(l_i * h_i) with l_i >= 0,
// h_i the vertices' homogeneous texel coordinates (x, y, w); by Cramer's rule l_i = det(p, h_j, h_k) / D,
// D = det(h0, h1, h2). So the test is: every edge function E_i(p) = dot(p, h_j x h_k) has the sign of D
// (Olano & Greer 1997, homogeneous rasterization). It needs no division by w and no clipped vertices, and
// keeps exactly the front part of the triangle: the part behind the plane is never accepted. The bound on
// each E_i's error (the vertices' projection error propagated through the cross product, the products'
// rounding, and the evaluation at any texel of the map) becomes extra margin in texels, like every other
// triangle's. When |D| is within its error bound the light lies in the triangle's plane (up to rounding)
// and both signs are accepted: the projection is then a band around one line. The bounding box clips the
// map square to the three half-planes with one more texel of slack and grows by one texel, which absorbs
// the rounding of the clip. With a known orientation, each edge's error bound is folded into that edge
// (its constant term), and the edges are stored oriented. `box_widen`: an area light's widest penumbra
// (texels), by which the bounding box grows (each texel's own widening is added by the binning).
// Area shadows of a spot or point light keep the part in front of the plane too: their setup has already
// culled what lies below its depth floor, and a part nearer the plane than the floor only adds texels.
uint clipped_setup(float n, HPoint h[3], float min_depth, float margin_base, float box_widen, inout BinTri bt) {
    Line lines[3] = Line[3](edge_line(h[1], h[2]), edge_line(h[2], h[0]), edge_line(h[0], h[1]));
    precise float d = dot(h[0].h, lines[0].l);
    float d_err = (dot(h[0].err, abs(lines[0].l)) + dot(abs(h[0].h), lines[0].e)
                   + dot(h[0].err, lines[0].e) + 4.0 * U * dot(abs(h[0].h), abs(lines[0].l))) * ROUND_UP;
    float orientation = abs(d) > d_err ? sign(d) : 0.0;
    // Any texel centre, grown by the base margin, lies within this distance of the map's origin per axis.
    float reach = n + 1.0 + margin_base;
    vec3 l[3];
    float slack_of[3] = float[3](0.0, 0.0, 0.0);
    float extra = 0.0;
    for (int i = 0; i < 3; ++i) {
        vec3 c = lines[i].l, e = lines[i].e;
        float s = max(max(abs(c.x), abs(c.y)), abs(c.z));
        if (s > 0.0) {
            int ex;
            frexp(s, ex);   // scale by a power of two (exact) so that no product below overflows
            c = ldexp(c, ivec3(-ex));
            e = ldexp(e, ivec3(-ex));
        }
        float slack = ((e.x + 4.0 * U * abs(c.x)) * reach + (e.y + 4.0 * U * abs(c.y)) * reach
                       + e.z + 4.0 * U * abs(c.z)) * ROUND_UP;
        float norm = abs(c.x) + abs(c.y);
        float grow = slack / norm;
        if (!(grow <= FAR_TEXELS)) {
            l[i] = vec3(0.0);   // no usable edge: it accepts every texel (conservative)
        } else {
            l[i] = c;
            slack_of[i] = slack;
            extra = max(extra, grow);
        }
    }
    float margin = margin_base;
    if (orientation != 0.0) {
        // A known orientation: each edge keeps its own error bound, folded into its constant term (with
        // the addition's rounding), so that an ill-conditioned edge (one pointing at the light projects to
        // almost a point) does not widen the other two.
        for (int i = 0; i < 3; ++i) {
            if (l[i] != vec3(0.0)) {
                vec3 o = orientation * l[i];
                float grown = slack_of[i] * ROUND_UP;
                o.z = (o.z + grown) + 2.0 * U * (abs(o.z) + grown);
                l[i] = o;
            }
        }
        orientation = 1.0;
    } else {
        margin += extra;    // either orientation: one margin for the three edges, tested both ways
    }
    // Half a texel, the margin, the clip's one texel of slack, and an area light's widest penumbra.
    float g = 1.5 + margin + box_widen;
    vec3 slack = g * vec3(abs(l[0].x) + abs(l[0].y), abs(l[1].x) + abs(l[1].y), abs(l[2].x) + abs(l[2].y));
    vec2 lo = vec2(1.0 / 0.0), hi = vec2(-1.0 / 0.0);
    bool any_part = false;
    for (int k = 0; k < 2; ++k) {
        float o = k == 0 ? 1.0 : -1.0;
        vec2 blo, bhi;
        if ((orientation == 0.0 || orientation == o) && clipped_box(n, l, slack, o, blo, bhi)) {
            lo = min(lo, blo);
            hi = max(hi, bhi);
            any_part = true;
        }
    }
    if (!any_part) {
        return 0u;  // no part of it in front of the light projects into the map
    }
    int last = int(n) - 1;
    ivec2 lo_t = clamp(ivec2(floor(lo)) - 1, ivec2(0), ivec2(last));
    ivec2 hi_t = clamp(ivec2(floor(hi)) + 1, ivec2(0), ivec2(last));
    bt.ab = vec4(l[0], l[1].x);
    bt.cmd = vec4(l[1].yz, margin, min_depth);
    bt.ext = vec4(l[2], orientation);
    uvec2 tiles = (uvec2(hi_t - lo_t) + BIN_TILE) / BIN_TILE;
    bt.info = uvec4(pack_texel(lo_t), pack_texel(hi_t), MODE_CLIPPED, tiles.x);
    return tiles.x * tiles.y;
}

// The bin item of the triangle (v0, v1, v2) in frustum `f`: its tiles (0: culled). Area shadows of a spot
// or point light: `distance` is a lower bound on the triangle's distance from the light's centre; within
// the near radius, the triangle is listed in every texel of the frustum's grid with receivers.
uint setup(uint f, vec3 v0, vec3 v1, vec3 v2, float distance, out BinTri bt) {
    bool near = pc.emitter_radius > 0.0 && distance < pc.near_radius;
    bt.ab = vec4(0.0);
    bt.cmd = vec4(0.0);
    bt.info = uvec4(0u);
    bt.ext = vec4(0.0);
    if (faces[f].fit.x == 0.0) {
        return 0u;
    }
    mat4 to_texels = faces[f].to_texels;
    float n = faces[f].fit.y;
    int last = int(n) - 1;
    if (near) {
        // Never culled by depth (nearest below every key) and never widened: the whole grid.
        bt.cmd.zw = vec2(ACCEPT_MARGIN, -1.0 / 0.0);
        uint side = (uint(last) + BIN_TILE) / BIN_TILE;
        bt.info = uvec4(0u, pack_texel(ivec2(last)), MODE_COVER, side);
        return side * side;
    }
    bool perspective = pc.to_light.w != 0.0;
    // Area shadows of a spot or point light: a point of this triangle that blocks a receiver of the
    // frustum lies at least `distance` from the light, within the angle from the frustum's axis that makes
    // the depth floor of the near radius (passes::area::LocalAreaReach), so its depth key is at least
    // distance * depth_floor / near_radius: the triangle is culled below that and widened as no nearer.
    float floor_key = pc.emitter_radius > 0.0
        ? distance * (pc.depth_floor / pc.near_radius) * (1.0 - 1.0 / 1048576.0) : 0.0;
    float margin = ACCEPT_MARGIN + 2.0 * unordered(faces[f].receivers.y);
    HPoint h[3];
    bool reaches_plane = false;
    if (perspective) {
        h = HPoint[3](project_h(to_texels, v0), project_h(to_texels, v1), project_h(to_texels, v2));
        if (h[0].h.z + h[0].err.z <= floor_key && h[1].h.z + h[1].err.z <= floor_key
            && h[2].h.z + h[2].err.z <= floor_key) {
            return 0u;  // wholly on or behind the light's plane (or its floor): it blocks no segment
        }
        reaches_plane = h[0].h.z - h[0].err.z <= 0.0 || h[1].h.z - h[1].err.z <= 0.0
                     || h[2].h.z - h[2].err.z <= 0.0;
    }
    Projected p[3] = Projected[3](project(to_texels, v0, perspective), project(to_texels, v1, perspective),
                                  project(to_texels, v2, perspective));
    float min_depth = min(min(p[0].depth - p[0].depth_err, p[1].depth - p[1].depth_err),
                          p[2].depth - p[2].depth_err);
    if (pc.emitter_radius > 0.0) {
        min_depth = max(min_depth, floor_key);
    }
    float deepest = unordered(faces[f].receivers.z);
    if (pc.cull != 0u && min_depth > deepest) {
        return 0u;  // behind every ray origin as seen from the light
    }
    // Area shadows: the bounding box also holds the texels the triangle's penumbra can reach on the
    // frustum's deepest ray origin (map_store.glsl widens per texel, by the texel's own deepest one).
    float widest = faces[f].fit.z == 0.0 ? 0.0 : penumbra_span(deepest, min_depth, faces[f].fit.zw);
    if (reaches_plane) {
        return clipped_setup(n, h, min_depth, margin, widest, bt);
    }
    uint mode = MODE_COVER;
    float err = max(max(max(p[0].xy_err.x, p[0].xy_err.y), max(p[1].xy_err.x, p[1].xy_err.y)),
                    max(p[2].xy_err.x, p[2].xy_err.y));
    // The per-texel edge functions (map_bin.glsl) are products of differences of coordinates up to R
    // texels: their rounding, in texels, is within 8u R (doubled here), beyond ACCEPT_MARGIN once R
    // reaches tens of thousands of texels.
    vec2 reach = max(max(abs(p[0].xy), abs(p[1].xy)), max(abs(p[2].xy), vec2(n)));
    margin += err + 16.0 * U * max(reach.x, reach.y);
    vec2 lo = min(min(p[0].xy, p[1].xy), p[2].xy) - (margin + widest);
    vec2 hi = max(max(p[0].xy, p[1].xy), p[2].xy) + (margin + widest);
    bool far = any(greaterThan(abs(vec4(lo, hi)), vec4(FAR_TEXELS)));
    if (far && perspective) {
        return clipped_setup(n, h, min_depth, ACCEPT_MARGIN + 2.0 * unordered(faces[f].receivers.y), widest,
                             bt);
    }
    if (any(greaterThan(lo, vec2(float(last) + 1.0))) || any(lessThan(hi, vec2(0.0)))) {
        return 0u;  // outside the map: no ray origin projects there
    }
    ivec2 lo_t = clamp(ivec2(floor(lo)), ivec2(0), ivec2(last));
    ivec2 hi_t = clamp(ivec2(floor(hi)), ivec2(0), ivec2(last));
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
    bt.cmd.zw = vec2(margin, min_depth);
    uvec2 tiles = (uvec2(hi_t - lo_t) + BIN_TILE) / BIN_TILE;
    bt.info = uvec4(pack_texel(lo_t), pack_texel(hi_t), mode, tiles.x);
    return tiles.x * tiles.y;
}

shared uint group_kept;

// At least the tangent of a cube face's half-angle (passes::light::CUBE_FACE_TAN_HALF, 1 + 1/256), with
// room for the rounding of the test below.
const float FACE_PYRAMID_TAN = 1.02;

// Whether the triangle may meet the pyramid of cube face `f` (+X, -X, +Y, -Y, +Z, -Z) around a point light
// at `light` (hard shadows: every segment of the face ends at the light): the pyramid is the intersection
// of four half-spaces through the light, |u| <= T d and |w| <= T d for the depth d along the face's axis
// and the two other coordinates u, w, so a triangle whose three vertices lie outside one of them lies
// wholly outside it (and outside the face's frustum, which the pyramid
// holds). A cheap test before the face's projection; the setup decides the rest exactly.
bool meets_face_pyramid(uint f, vec3 light, vec3 v0, vec3 v1, vec3 v2) {
    uint axis = f / 2u;
    float s = (f & 1u) == 0u ? 1.0 : -1.0;
    uvec4 outside = uvec4(0u);     // vertices outside each half-space
    for (uint i = 0u; i < 3u; ++i) {
        vec3 rel = (i == 0u ? v0 : (i == 1u ? v1 : v2)) - light;
        float reach = FACE_PYRAMID_TAN * s * rel[axis];
        float u = rel[(axis + 1u) % 3u];
        float w = rel[(axis + 2u) % 3u];
        outside += uvec4(bvec4(u > reach, -u > reach, w > reach, -w > reach));
    }
    return !any(equal(outside, uvec4(3u)));
}

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        group_kept = 0u;
    }
    barrier();
    uint index = gl_GlobalInvocationID.x;
    vec3 v0 = vec3(0.0), v1 = vec3(0.0), v2 = vec3(0.0);
    bool live = index < pc.triangles;
    if (live) {
        v0 = tris[index].v[0].xyz;
        v1 = tris[index].v[1].xyz;
        v2 = tris[index].v[2].xyz;
        // Zero area with two equal vertices, or a back face in front-only mode: culled in every frustum.
        // Area shadows keep a triangle that faces any direction of the light's cone: within its angular
        // radius r of facing (sin r < tan r = penumbra, with room for the rounding).
        vec3 c = cross(v1 - v0, v2 - v0);
        float facing = pc.penumbra == 0.0 ? 0.0 : -pc.penumbra * (1.0 + 1.0 / 1024.0) * length(c);
        live = v0 != v1 && v1 != v2 && v2 != v0
            && (pc.front_only == 0u || dot(c, pc.to_light.xyz) > facing);
    }
    // Area shadows of a spot or point light: how near the light's centre the triangle may come (within the
    // near radius it may block any receiver; passes::area::LocalAreaReach).
    float distance = live && pc.emitter_radius > 0.0 ? distance_below(pc.to_light.xyz, v0, v1, v2) : 0.0;
    bool kept = false;
    if (pc.faces == 1u) {
        if (index < pc.triangles) {
            BinTri bt = BinTri(vec4(0.0), vec4(0.0), uvec4(0u), vec4(0.0));
            uint tiles = live ? setup(0u, v0, v1, v2, distance, bt) : 0u;
            bin_tris[index] = bt;
            tile_counts[index] = tiles;
            kept = tiles > 0u;
        } else if (index == pc.triangles) {
            tile_counts[index] = 0u;    // the exclusive scan's last element becomes the total
        }
    } else {
        // Every invocation runs the loop (its subgroup operations need the whole subgroup): one atomic per
        // subgroup and face reserves the slots of the pairs kept.
        for (uint f = 0u; f < pc.faces; ++f) {
            BinTri bt = BinTri(vec4(0.0), vec4(0.0), uvec4(0u), vec4(0.0));
            // Hard shadows only: an area light's segments end on its emitter, off the pyramid's apex.
            bool meets = live
                && (pc.emitter_radius > 0.0 || meets_face_pyramid(f, pc.to_light.xyz, v0, v1, v2));
            uint tiles = meets ? setup(f, v0, v1, v2, distance, bt) : 0u;
            bool keep = tiles > 0u;
            uint count = subgroupAdd(keep ? 1u : 0u);
            uint first = 0u;
            if (subgroupElect() && count > 0u) {
                first = atomicAdd(faces[0].grid.z, count);
            }
            uint slot = subgroupBroadcastFirst(first) + subgroupExclusiveAdd(keep ? 1u : 0u);
            if (keep && slot < pc.pairs) {
                bin_tris[slot] = bt;
                tile_counts[slot] = tiles;
                pair_owner[slot] = index | (f << 29);
            }
            kept = kept || keep;
        }
    }
    if (kept) {
        atomicAdd(group_kept, 1u);
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u && group_kept > 0u) {
        atomicAdd(faces[0].totals.w, group_kept);
    }
}

#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_basic : require
// The primitive map's receivers: every pixel's shadow ray origin (the same ray the ray trace will trace,
// from shadow_ray.glsl), placed in light space, in its frustum: the light's one frustum, or a point light's
// cube face (face_of).
// - mode 0 (bounds): each frustum's light-space bounds of its ray origins, which the fit pass turns into
//   its grid's texel transform (a sample-distribution fit: the map covers what the camera sees, not the
//   scene).
// - mode 1 (mark): each pixel's texel (read back by the ray trace, so both agree on it bit for bit), and
//   per texel the largest depth key of its ray origins: a triangle farther from the light than all of them
//   cannot shadow the texel, and a texel without ray origins needs no list at all. The same per 4x4 tile
//   of texels (map_state.glsl's tile_word), for the bin walk to skip whole tiles. The texels first marked
//   are counted (the map's texels with receivers).
// - mode 2 (texels): each pixel's texel alone, exactly as mode 1 writes it, for a ray trace whose pixel
//   texels another light's build overwrote since (the lights share them).
// Each invocation places a 2x2 quad of pixels; the per-frustum counters are reduced per subgroup, then per
// workgroup, so that one global atomic per frustum and 16x16 pixels reaches memory (every pixel of the
// frame would otherwise contend for the same few words), and a subgroup whose receivers share one texel
// updates it once, and only when it raises the texel's value (values only grow, so a stale read errs
// towards the atomic).
#include "ray_trace_constants.glsl"
#include "map_state.glsl"
#include "map_project.glsl"
#include "map_push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Constants { RayTraceConstants k; mat4 frusta[6]; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2) uniform sampler2D normal_tex;
layout(set = 0, binding = 3) buffer State { MapState faces[]; };
layout(set = 0, binding = 4) buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 5) writeonly buffer PixelTexels { uint pixel_texel[]; };
layout(push_constant) uniform Push { MapPush pc; };
#include "shadow_ray.glsl"

const uint NONE = 0xFFFFFFFFu;

// Per frustum: mode 0 min x, min y, max x, max y, rays; mode 1 receivers, largest error, largest depth key
// (and in the first frustum's fourth word, the texels first marked).
shared uint group_words[6][5];

// The frustum of ray origin `o`: 0 for a light of one frustum; for a point light the cube face (+X, -X,
// +Y, -Y, +Z, -Z) of the largest component of the direction from the light. The segment from `o` to the
// light then lies in that face's frustum (each face is a little wider than 90 degrees, see
// passes::light::CUBE_FACE_TAN_HALF), and both modes and every pass agree on the face.
uint face_of(vec3 o) {
    if (pc.faces == 1u) {
        return 0u;
    }
    vec3 rel = o - k.light_pos.xyz;
    vec3 a = abs(rel);
    if (a.x >= a.y && a.x >= a.z) {
        return rel.x >= 0.0 ? 0u : 1u;
    }
    if (a.y >= a.z) {
        return rel.y >= 0.0 ? 2u : 3u;
    }
    return rel.z >= 0.0 ? 4u : 5u;
}

// Raises receiver word `w` (NONE: none) to at least `reach`; words only grow, so a stale read errs towards
// the atomic.
void raise(uint w, uint reach) {
    if (w != NONE && receiver[w] < reach) {
        atomicMax(receiver[w], reach);
    }
}

// This invocation's part so far, for frustum `held` (NONE: nothing yet).
uvec4 held_words = uvec4(0u);
uint held_rays = 0u;
uint held = NONE;

void to_group(uint f, uvec4 w, uint rays) {
    if (pc.mode == 0u) {
        atomicMin(group_words[f][0], w.x);
        atomicMin(group_words[f][1], w.y);
        atomicMax(group_words[f][2], w.z);
        atomicMax(group_words[f][3], w.w);
        atomicAdd(group_words[f][4], rays);
    } else {
        atomicAdd(group_words[f][0], w.x);
        atomicMax(group_words[f][1], w.y);
        atomicMax(group_words[f][2], w.z);
    }
}

// Adds one ray origin's words to frustum `f`'s part; a quad spanning two frusta (a point light's face
// boundary) hands the first one's part to the workgroup at once.
void add(uint f, uvec4 w) {
    if (held != f) {
        if (held != NONE) {
            to_group(held, held_words, held_rays);
        }
        held = f;
        held_words = pc.mode == 0u ? uvec4(NONE, NONE, 0u, 0u) : uvec4(0u);
        held_rays = 0u;
    }
    if (pc.mode == 0u) {
        held_words = uvec4(min(held_words.xy, w.xy), max(held_words.zw, w.zw));
        held_rays += 1u;
    } else {
        held_words = uvec4(held_words.x + w.x, max(held_words.yz, w.yz), 0u);
    }
}

void main() {
    uint lid = gl_LocalInvocationIndex;
    if (lid < 30u) {
        group_words[lid / 5u][lid % 5u] = pc.mode == 0u && lid % 5u < 2u ? NONE : 0u;
    }
    barrier();

    uint open_texel = NONE;
    uint open_reach = 0u;
    uint open_tile = NONE;
    uint open_tile_reach = 0u;
    uint marked = 0u;
    bool perspective = pc.to_light.w != 0.0;
    for (uint q = 0u; q < 4u; ++q) {
        ivec2 px = ivec2(gl_GlobalInvocationID.xy) * 2 + ivec2(q & 1u, q >> 1u);
        if (px.x >= int(k.dims.x) || px.y >= int(k.dims.y)) {
            continue;
        }
        uint pixel = uint(px.y) * k.dims.x + uint(px.x);
        vec3 o, dir;
        float t_max;
        bool traced = shadow_ray(px, o, dir, t_max) == SHADOW_RAY_TRACE;
        uint f = face_of(o);
        vec4 lc = frusta[f] * vec4(o, 1.0);
        vec2 ndc = lc.xy / lc.w;
        bool inside = lc.w > 0.0 && all(greaterThanEqual(ndc, vec2(-1.0))) && all(lessThan(ndc, vec2(1.0)));
        if (pc.mode == 0u) {
            if (traced && inside) {
                uvec2 key = uvec2(ordered(ndc.x), ordered(ndc.y));
                add(f, uvec4(key, key));
            }
            continue;
        }
        if (!traced || !inside || faces[f].fit.x == 0.0) {
            // Outside a light's one frustum: lit. A point light's faces cover every direction, so a ray
            // origin outside its own face, or in a face the fit left without a grid (neither is ever seen),
            // is traced exhaustively: exact.
            pixel_texel[pixel] = traced && !inside && pc.faces == 1u ? TEXEL_OUTSIDE : TEXEL_NO_RAY;
            continue;
        }
        Projected pr = project(faces[f].to_texels, o, perspective);
        int last = int(faces[f].fit.y) - 1;
        uvec2 texel = uvec2(clamp(ivec2(floor(pr.xy)), ivec2(0), ivec2(last)));
        uint index = texel_index(faces[f].grid, texel);
        pixel_texel[pixel] = index;
        if (pc.mode == 2u) {
            continue;
        }
        // Largest depth key of the texel, rounded up by its error bound (and the bound's own rounding).
        uint reach = ordered(pr.depth + pr.depth_err * 2.0);
        add(f, uvec4(1u, ordered(max(pr.xy_err.x, pr.xy_err.y)), reach, 0u));
        if (index != open_texel) {
            if (open_texel != NONE && receiver[open_texel] < open_reach
                && atomicMax(receiver[open_texel], open_reach) == 0u) {
                marked += 1u;
            }
            open_texel = index;
            open_reach = 0u;
        }
        open_reach = max(open_reach, reach);
        uint tile = tile_word(faces[f].grid, texel, pc.texels);
        if (tile != open_tile) {
            raise(open_tile, open_tile_reach);
            open_tile = tile;
            open_tile_reach = 0u;
        }
        open_tile_reach = max(open_tile_reach, reach);
    }

    // Each frustum held in the subgroup (usually one), reduced across it.
    uint present = subgroupOr(held != NONE ? 1u << held : 0u);
    while (present != 0u) {
        uint f = findLSB(present);
        present &= present - 1u;
        bool mine = held == f;
        if (pc.mode == 0u) {
            uvec2 lo = subgroupMin(mine ? held_words.xy : uvec2(NONE));
            uvec2 hi = subgroupMax(mine ? held_words.zw : uvec2(0u));
            uint rays = subgroupAdd(mine ? held_rays : 0u);
            if (subgroupElect()) {
                to_group(f, uvec4(lo, hi), rays);
            }
        } else {
            uint count = subgroupAdd(mine ? held_words.x : 0u);
            uvec2 top = subgroupMax(mine ? held_words.yz : uvec2(0u));
            if (subgroupElect()) {
                to_group(f, uvec4(count, top, 0u), 0u);
            }
        }
    }
    if (pc.mode == 1u) {
        // The open texels: once per subgroup when all of them are the same texel.
        bool open = open_texel != NONE;
        uint first = subgroupMin(open_texel);
        bool shared_texel = first == subgroupMax(open ? open_texel : 0u);
        if (shared_texel) {
            uint m = subgroupMax(open_reach);
            if (subgroupElect() && receiver[first] < m && atomicMax(receiver[first], m) == 0u) {
                marked += 1u;
            }
        } else if (open && receiver[open_texel] < open_reach
                   && atomicMax(receiver[open_texel], open_reach) == 0u) {
            marked += 1u;
        }
        // The open tiles likewise.
        uint first_tile = subgroupMin(open_tile);
        if (first_tile == subgroupMax(open_tile != NONE ? open_tile : 0u)) {
            uint m = subgroupMax(open_tile_reach);
            if (subgroupElect()) {
                raise(first_tile, m);
            }
        } else {
            raise(open_tile, open_tile_reach);
        }
        uint group_marked = subgroupAdd(marked);
        if (subgroupElect() && group_marked > 0u) {
            atomicAdd(group_words[0][3], group_marked);
        }
    }
    barrier();
    if (lid == 0u && pc.mode == 1u && group_words[0][3] > 0u) {
        atomicAdd(faces[0].stats.w, group_words[0][3]);
    }
    if (lid >= pc.faces) {
        return;
    }
    uint f = lid;
    if (pc.mode == 0u) {
        if (group_words[f][0] <= group_words[f][2]) {
            atomicMin(faces[f].bounds.x, group_words[f][0]);
            atomicMin(faces[f].bounds.y, group_words[f][1]);
            atomicMax(faces[f].bounds.z, group_words[f][2]);
            atomicMax(faces[f].bounds.w, group_words[f][3]);
            atomicAdd(faces[f].receivers.w, group_words[f][4]);
        }
    } else if (group_words[f][0] > 0u) {
        atomicAdd(faces[f].receivers.x, group_words[f][0]);
        atomicMax(faces[f].receivers.y, group_words[f][1]);
        atomicMax(faces[f].receivers.z, group_words[f][2]);
    }
}

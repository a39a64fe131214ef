#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// The primitive map's receivers: every pixel's shadow ray origin (the same ray the ray trace will trace,
// from shadow_ray.glsl), placed in light space.
// - mode 0 (bounds): the light-space bounds of the ray origins, which the fit pass turns into the map's
//   texel transform (a sample-distribution fit: the map covers what the camera sees, not the scene).
// - mode 1 (mark): each pixel's texel (read back by the ray trace, so both agree on it bit for bit), and
//   per texel the largest depth key of its ray origins: a triangle farther from the light than all of them
//   cannot shadow the texel, and a texel without ray origins needs no list at all.
// Each invocation places a 2x2 quad of pixels; the global counters are reduced per subgroup, then per
// workgroup, so that one global atomic per 16x16 pixels reaches memory (every pixel of the frame would
// otherwise contend for the same few words), and a subgroup whose receivers share one texel updates it
// once, and only when it raises the texel's value (values only grow, so a stale read errs towards the
// atomic).
#include "ray_trace_constants.glsl"
#include "map_state.glsl"
#include "map_project.glsl"
#include "map_push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Constants { RayTraceConstants k; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2) uniform sampler2D normal_tex;
layout(set = 0, binding = 3) buffer State { MapState ms; };
layout(set = 0, binding = 4) buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 5) writeonly buffer PixelTexels { uint pixel_texel[]; };
layout(push_constant) uniform Push { MapPush pc; };
#include "shadow_ray.glsl"

const uint NONE = 0xFFFFFFFFu;

shared uint group_words[5];

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        group_words[0] = pc.mode == 0u ? NONE : 0u;
        group_words[1] = pc.mode == 0u ? NONE : 0u;
        group_words[2] = 0u;
        group_words[3] = 0u;
        group_words[4] = 0u;
    }
    barrier();

    // This invocation's part: mode 0 its bounds (min x, min y, max x, max y); mode 1 its receiver count,
    // largest projection error and largest depth key, and the texel it has not yet written.
    uvec4 mine = pc.mode == 0u ? uvec4(NONE, NONE, 0u, 0u) : uvec4(0u);
    uint open_texel = NONE;
    uint open_reach = 0u;
    uint mine_rays = 0u;
    mat4 to_texels = ms.to_texels;
    for (uint q = 0u; q < 4u; ++q) {
        ivec2 px = ivec2(gl_GlobalInvocationID.xy) * 2 + ivec2(q & 1u, q >> 1u);
        if (px.x >= int(k.dims.x) || px.y >= int(k.dims.y)) {
            continue;
        }
        uint pixel = uint(px.y) * k.dims.x + uint(px.x);
        vec3 o, dir;
        float t_max;
        bool traced = shadow_ray(px, o, dir, t_max) == SHADOW_RAY_TRACE;
        vec4 lc = pc.light_view_proj * vec4(o, 1.0);
        vec2 ndc = lc.xy / lc.w;
        bool inside = lc.w > 0.0 && all(greaterThanEqual(ndc, vec2(-1.0))) && all(lessThan(ndc, vec2(1.0)));
        if (pc.mode == 0u) {
            if (traced && inside) {
                mine_rays += 1u;
                mine = uvec4(min(mine.xy, uvec2(ordered(ndc.x), ordered(ndc.y))),
                             max(mine.zw, uvec2(ordered(ndc.x), ordered(ndc.y))));
            }
            continue;
        }
        if (!traced || !inside) {
            pixel_texel[pixel] = traced ? TEXEL_OUTSIDE : TEXEL_NO_RAY;
            continue;
        }
        Projected pr = project(to_texels, o, pc.to_light.w != 0.0);
        int last = int(ms.fit.y) - 1;
        ivec2 texel = clamp(ivec2(floor(pr.xy)), ivec2(0), ivec2(last));
        uint index = uint(texel.y) * pc.size + uint(texel.x);
        pixel_texel[pixel] = index;
        // Largest depth key of the texel, rounded up by its error bound (and the bound's own rounding).
        uint reach = ordered(pr.depth + pr.depth_err * 2.0);
        mine = uvec4(mine.x + 1u, max(mine.y, ordered(max(pr.xy_err.x, pr.xy_err.y))), max(mine.z, reach), 0u);
        if (index != open_texel) {
            if (open_texel != NONE && receiver[open_texel] < open_reach) {
                atomicMax(receiver[open_texel], open_reach);
            }
            open_texel = index;
            open_reach = 0u;
        }
        open_reach = max(open_reach, reach);
    }

    if (pc.mode == 0u) {
        uvec2 lo = subgroupMin(mine.xy);
        uvec2 hi = subgroupMax(mine.zw);
        uint rays = subgroupAdd(mine_rays);
        if (subgroupElect() && lo.x <= hi.x) {
            atomicMin(group_words[0], lo.x);
            atomicMin(group_words[1], lo.y);
            atomicMax(group_words[2], hi.x);
            atomicMax(group_words[3], hi.y);
            atomicAdd(group_words[4], rays);
        }
    } else {
        uint count = subgroupAdd(mine.x);
        uint err = subgroupMax(mine.y);
        uint reach = subgroupMax(mine.z);
        if (subgroupElect() && count > 0u) {
            atomicAdd(group_words[0], count);
            atomicMax(group_words[1], err);
            atomicMax(group_words[2], reach);
        }
        // The open texels: once per subgroup when all of them are the same texel.
        bool open = open_texel != NONE;
        uint first = subgroupMin(open_texel);
        bool shared_texel = first == subgroupMax(open ? open_texel : 0u);
        if (shared_texel) {
            uint m = subgroupMax(open_reach);
            if (subgroupElect() && receiver[first] < m) {
                atomicMax(receiver[first], m);
            }
        } else if (open && receiver[open_texel] < open_reach) {
            atomicMax(receiver[open_texel], open_reach);
        }
    }
    barrier();
    if (gl_LocalInvocationIndex != 0u) {
        return;
    }
    if (pc.mode == 0u) {
        if (group_words[0] <= group_words[2]) {
            atomicMin(ms.bounds.x, group_words[0]);
            atomicMin(ms.bounds.y, group_words[1]);
            atomicMax(ms.bounds.z, group_words[2]);
            atomicMax(ms.bounds.w, group_words[3]);
            atomicAdd(ms.receivers.w, group_words[4]);
        }
    } else if (group_words[0] > 0u) {
        atomicAdd(ms.receivers.x, group_words[0]);
        atomicMax(ms.receivers.y, group_words[1]);
        atomicMax(ms.receivers.z, group_words[2]);
    }
}

#version 460
#extension GL_GOOGLE_include_directive : require
// The primitive map's receivers: every pixel's shadow ray origin (the same ray the ray trace will trace,
// from shadow_ray.glsl), placed in light space.
// - mode 0 (bounds): the light-space bounds of the ray origins, which the fit pass turns into the map's
//   texel transform (a sample-distribution fit: the map covers what the camera sees, not the scene).
// - mode 1 (mark): each pixel's texel (read back by the ray trace, so both agree on it bit for bit), and
//   per texel the largest depth key of its ray origins: a triangle farther from the light than all of them
//   cannot shadow the texel, and a texel without ray origins needs no list at all.
#include "ray_trace_constants.glsl"
#include "map_state.glsl"
#include "map_project.glsl"
#include "map_push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Constants { RayTraceConstants k; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2) uniform sampler2D normal_tex;
layout(set = 0, binding = 3) coherent buffer State { MapState ms; };
layout(set = 0, binding = 4) coherent buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 5) writeonly buffer PixelTexels { uint pixel_texel[]; };
layout(push_constant) uniform Push { MapPush pc; };
#include "shadow_ray.glsl"

// Per-workgroup reductions in shared memory: one global atomic per workgroup instead of one per pixel
// (every pixel of the frame would otherwise contend for the same few words).
shared uint group_bounds[4];
shared uint group_receivers[3];

void place(ivec2 px) {
    uint pixel = uint(px.y) * k.dims.x + uint(px.x);
    vec3 o, dir;
    float t_max;
    bool traced = shadow_ray(px, o, dir, t_max) == SHADOW_RAY_TRACE;
    vec4 lc = pc.light_view_proj * vec4(o, 1.0);
    vec2 ndc = lc.xy / lc.w;
    bool inside = lc.w > 0.0 && all(greaterThanEqual(ndc, vec2(-1.0))) && all(lessThan(ndc, vec2(1.0)));
    if (pc.mode == 0u) {
        if (traced && inside) {
            atomicMin(group_bounds[0], ordered(ndc.x));
            atomicMin(group_bounds[1], ordered(ndc.y));
            atomicMax(group_bounds[2], ordered(ndc.x));
            atomicMax(group_bounds[3], ordered(ndc.y));
        }
        return;
    }
    if (!traced) {
        pixel_texel[pixel] = TEXEL_NO_RAY;
        return;
    }
    if (!inside) {
        pixel_texel[pixel] = TEXEL_OUTSIDE;
        return;
    }
    Projected pr = project(ms.to_texels, o, pc.to_light.w != 0.0);
    int last = int(pc.size) - 1;
    ivec2 texel = clamp(ivec2(floor(pr.xy)), ivec2(0), ivec2(last));
    uint index = uint(texel.y) * pc.size + uint(texel.x);
    pixel_texel[pixel] = index;
    // Largest depth key of the texel, rounded up by its error bound (and the bound's own rounding).
    float reach = pr.depth + pr.depth_err * 2.0;
    atomicMax(receiver[index], ordered(reach));
    atomicAdd(group_receivers[0], 1u);
    atomicMax(group_receivers[1], ordered(max(pr.xy_err.x, pr.xy_err.y)));
    atomicMax(group_receivers[2], ordered(reach));
}

void main() {
    uint lid = gl_LocalInvocationIndex;
    if (lid == 0u) {
        group_bounds[0] = 0xFFFFFFFFu;
        group_bounds[1] = 0xFFFFFFFFu;
        group_bounds[2] = 0u;
        group_bounds[3] = 0u;
        group_receivers[0] = 0u;
        group_receivers[1] = 0u;
        group_receivers[2] = 0u;
    }
    barrier();
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x < int(k.dims.x) && px.y < int(k.dims.y)) {
        place(px);
    }
    barrier();
    if (lid != 0u) {
        return;
    }
    if (pc.mode == 0u) {
        if (group_bounds[0] <= group_bounds[2]) {
            atomicMin(ms.bounds.x, group_bounds[0]);
            atomicMin(ms.bounds.y, group_bounds[1]);
            atomicMax(ms.bounds.z, group_bounds[2]);
            atomicMax(ms.bounds.w, group_bounds[3]);
        }
    } else if (group_receivers[0] > 0u) {
        atomicAdd(ms.receivers.x, group_receivers[0]);
        atomicMax(ms.receivers.y, group_receivers[1]);
        atomicMax(ms.receivers.z, group_receivers[2]);
    }
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Exact soft shadows of a sized directional light: per pixel, which of the light's N sample directions
// (area_samples.glsl, the same for every pixel) reach the light, tested against every triangle of the
// pixel's texel list in a primitive map whose footprints are widened by their penumbra (map_store.glsl).
// The visibility is the visible fraction, k / N: no noise, no filter, the same output for the same input.
//
// The ray test is the triple-product form of the watertight test, for all N directions from the pixel's
// one ray origin o at once. With a, b, c the triangle's vertices relative to o and D = det(a, b, c), a
// direction w reaches the triangle (at a positive distance) iff w = alpha a + beta b + gamma c with alpha,
// beta, gamma >= 0, i.e. iff the three edge functions (b x c).w = alpha D, (c x a).w = beta D and
// (a x b).w = gamma D all have the sign of D (Cramer's rule). Each edge's normal is computed from its two
// vertices in an order fixed by their world positions, so a shared edge gets exactly opposite normals in
// its two triangles, and a direction exactly through the edge counts as blocked by both (>= 0): no leak
// through a closed mesh. D = 0 (o in the triangle's plane, or a degenerate triangle) blocks nothing.
// Each edge function is linear in w, and every sample lies within `spread` of the centre direction C, so
// E(w) lies within |n| spread of E(C): a triangle is rejected for every sample, or taken as blocking every
// sample, with one evaluation, exactly as the per-sample evaluation would decide (the margin covers the
// rounding of both). Only triangles across the penumbra's edge are tested sample by sample, and only on
// the samples still open that lie near their projection (candidates): a sample outside the grown bounding
// box of the projected vertices lies far outside the triangle, where the per-sample test says no.
// A sample towards which the receiver's normal does not face is blocked, as the reference has it.
#include "triangle.glsl"
#include "ray_trace_constants.glsl"
#include "map_state.glsl"
#include "area_samples.glsl"

#define CONSIDER1(i) if ((i) < total) { consider(i); }
#define CONSIDER4(i) CONSIDER1(i) CONSIDER1((i) + 1u) CONSIDER1((i) + 2u) CONSIDER1((i) + 3u)

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Constants { RayTraceConstants k; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2) uniform sampler2D normal_tex;
layout(set = 0, binding = 3) readonly buffer State { MapState ms; };
layout(set = 0, binding = 4) readonly buffer PixelTexels { uint pixel_texel[]; };
layout(set = 0, binding = 5) readonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 6) readonly buffer Entries { uint entries[]; };
layout(set = 0, binding = 7) readonly buffer Prims { Triangle tris[]; };
layout(set = 0, binding = 8, r32f) uniform writeonly image2D visibility;
layout(set = 0, binding = 9) uniform Samples { AreaSamples samples; };
#include "shadow_ray.glsl"

// The workgroup's copy of the sample table's directions and grid ranges: the trace reads them at indices
// that differ from pixel to pixel, which a uniform buffer serves one index at a time.
shared vec3 sample_dirs[128];
shared uvec4 u_ranges[SAMPLE_GRID * SAMPLE_GRID];
shared uvec4 v_ranges[SAMPLE_GRID * SAMPLE_GRID];

vec3 origin;
uint sample_count;
uvec4 all_samples;  // bit i of word i / 32: sample i exists
uvec4 blocked;      // bit i: sample i is blocked

// Relative margin of the one-evaluation decisions: far above the f32 rounding of the edge functions.
const float DECIDE_MARGIN = 1e-5;

// rp x rq for the edge from world vertex p to q (rp, rq: relative to the ray origin), computed in an order
// fixed by p and q, so that the edge from q to p gives exactly the opposite vector.
vec3 edge_normal(vec3 p, vec3 q, vec3 rp, vec3 rq) {
    bool swap = p.x > q.x || (p.x == q.x && (p.y > q.y || (p.y == q.y && p.z > q.z)));
    vec3 u = swap ? rq : rp;
    vec3 v = swap ? rp : rq;
    precise vec3 n = vec3(u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x);
    return swap ? -n : n;
}

// The samples the triangle of vertices a, b, c (relative to the ray origin) may hide: with every vertex in
// front (towards the light's side of the plane through the origin orthogonal to the centre C), those whose
// gnomonic coordinates may lie in the bounding box of the vertices' (grown by far more than its rounding);
// else every sample.
uvec4 candidates(vec3 a, vec3 b, vec3 c) {
    vec3 h = vec3(dot(a, samples.center.xyz), dot(b, samples.center.xyz), dot(c, samples.center.xyz));
    if (!all(greaterThan(h, vec3(0.0)))) {
        return all_samples;
    }
    vec3 eu = samples.axis_u.xyz, ev = samples.axis_v.xyz;
    vec3 gu = vec3(dot(a, eu), dot(b, eu), dot(c, eu)) / h;
    vec3 gv = vec3(dot(a, ev), dot(b, ev), dot(c, ev)) / h;
    vec2 lo = vec2(min(min(gu.x, gu.y), gu.z), min(min(gv.x, gv.y), gv.z));
    vec2 hi = vec2(max(max(gu.x, gu.y), gu.z), max(max(gv.x, gv.y), gv.z));
    float extent = samples.axis_u.w;
    float grow = 1e-4 * (extent + max(max(abs(lo.x), abs(lo.y)), max(abs(hi.x), abs(hi.y))));
    lo -= grow;
    hi += grow;
    if (any(greaterThan(lo, vec2(extent))) || any(lessThan(hi, vec2(-extent)))) {
        return uvec4(0u);
    }
    float last = float(SAMPLE_GRID - 1u);
    uvec2 first = uvec2(clamp(floor((lo + extent) * samples.axis_v.w), vec2(0.0), vec2(last)));
    uvec2 final = uvec2(clamp(floor((hi + extent) * samples.axis_v.w), vec2(0.0), vec2(last)));
    return u_ranges[first.x * SAMPLE_GRID + final.x] & v_ranges[first.y * SAMPLE_GRID + final.y];
}

void consider(uint index) {
    if (index >= uint(tris.length())) {
        return;
    }
    vec3 p0 = tris[index].v[0].xyz, p1 = tris[index].v[1].xyz, p2 = tris[index].v[2].xyz;
    precise vec3 a = p0 - origin;
    precise vec3 b = p1 - origin;
    precise vec3 c = p2 - origin;
    vec3 na = edge_normal(p1, p2, b, c);
    vec3 nb = edge_normal(p2, p0, c, a);
    vec3 nc = edge_normal(p0, p1, a, b);
    precise float det = dot(a, na);
    if (det == 0.0) {
        return;
    }
    if (det < 0.0) {
        na = -na;
        nb = -nb;
        nc = -nc;
    }
    vec3 centre = samples.center.xyz;
    vec3 at_centre = vec3(dot(na, centre), dot(nb, centre), dot(nc, centre));
    vec3 span = vec3(length(na), length(nb), length(nc)) * (samples.center.w + DECIDE_MARGIN);
    if (any(lessThan(at_centre + span, vec3(0.0)))) {
        return;     // every sample misses it
    }
    if (all(greaterThan(at_centre - span, vec3(0.0)))) {
        blocked = all_samples;  // it covers every sample
        return;
    }
    // The samples still open that it may hide, tested one by one.
    uvec4 open = candidates(a, b, c) & all_samples & ~blocked;
    for (uint word = 0u; word < 4u; ++word) {
        uint bits = open[word];
        while (bits != 0u) {
            uint bit = findLSB(bits);
            bits &= bits - 1u;
            vec3 w = sample_dirs[word * 32u + bit];
            if (dot(na, w) >= 0.0 && dot(nb, w) >= 0.0 && dot(nc, w) >= 0.0) {
                blocked[word] |= 1u << bit;
            }
        }
    }
}

bool all_blocked() {
    return blocked == all_samples;
}

void main() {
    sample_count = k.misc.w;
    uint lid = gl_LocalInvocationIndex;
    for (uint i = lid; i < sample_count; i += 64u) {
        sample_dirs[i] = samples.dirs[i].xyz;
    }
    u_ranges[lid] = samples.u_range[lid];     // 64 ranges, one per invocation of the 8x8 workgroup
    v_ranges[lid] = samples.v_range[lid];
    barrier();
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= int(k.dims.x) || px.y >= int(k.dims.y)) {
        return;
    }
    vec3 dir;
    float t_max;
    int ray = shadow_ray(px, origin, dir, t_max);
    if (ray != SHADOW_RAY_TRACE) {
        imageStore(visibility, px, vec4(ray == SHADOW_RAY_LIT ? 1.0 : 0.0));
        return;
    }
    uint texel = pixel_texel[uint(px.y) * k.dims.x + uint(px.x)];
    if (texel == TEXEL_OUTSIDE) {
        imageStore(visibility, px, vec4(1.0));
        return;
    }
    all_samples = uvec4(0u);
    blocked = uvec4(0u);
    vec3 n = shadow_ray_normal;
    for (uint i = 0u; i < sample_count; ++i) {
        all_samples[i >> 5u] |= 1u << (i & 31u);
        if (dot(n, sample_dirs[i]) <= 0.0) {
            blocked[i >> 5u] |= 1u << (i & 31u);
        }
    }
    uint begin = texel == TEXEL_NO_RAY ? 0u : offsets[texel];
    uint end = texel == TEXEL_NO_RAY ? 0u : offsets[texel + 1u];
    bool binned = ms.grid.z <= ms.grid.w;
    if (texel != TEXEL_NO_RAY && binned && (end <= ms.totals.z || begin == end)) {
        for (uint i = begin; i < end && !all_blocked(); ++i) {
            consider(entries[i]);
        }
    } else {
        // Past the entry capacity: every triangle, exact (unrolled: see ray_trace.comp on llvmpipe's loop
        // cap).
        uint total = min(k.misc.y, uint(tris.length()));
        for (uint base = 0u; base < total && !all_blocked(); base += 16u) {
            CONSIDER4(base) CONSIDER4(base + 4u) CONSIDER4(base + 8u) CONSIDER4(base + 12u)
        }
    }
    uvec4 seen = blocked & all_samples;
    uint hidden = bitCount(seen.x) + bitCount(seen.y) + bitCount(seen.z) + bitCount(seen.w);
    imageStore(visibility, px, vec4(float(sample_count - hidden) / float(sample_count)));
}

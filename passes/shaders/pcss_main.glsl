// PCSS (percentage-closer soft shadows) over the conventional shadow map, and the classic single-tap
// shadow-map test; included by pcss.comp (hard edge from the shadow map) and pcss_rt.comp (hard edge from
// the ray-traced visibility). Visibility convention: 1 = lit.
//
// - Receiver: P is rebuilt from the engine's depth as in the ray trace, in frame coordinates. Receivers
//   facing away from the light are 0, receivers outside the light's frustum 1, like the ray trace.
// - Receiver-plane depth: the receiver's plane (the engine's normal, decoded by engine_surface.glsl) is a plane in the
//   light's NDC too (projective maps keep planes), so its depth at any shadow-map texel centre is
//   d_r + g . (texel - uv). Every tap compares the stored depth with the receiver plane at that texel's
//   centre, where the rasterizer computed the stored depth, so planar receivers need no depth bias beyond
//   rounding (tolerances are fractions of a texel). Slopes steeper than TAN_MAX are clamped.
// - Blocker search: taps on a Vogel disc (golden-angle spiral) rotated per pixel by interleaved gradient
//   noise, over the projection of the cone from the receiver to the emitter at the light's near plane.
// - Penumbra: directional light of angular radius a: (z_r - z_b) tan(a); spot light of radius R:
//   R (z_r - z_b) / z_b; both in texels at the receiver, clamped.
// - PCF over that radius. Shrinking filter: where the hard result is lit the output is exactly 1, and
//   nothing else is computed there (hard edge from the ray trace when the plan has it, else the shadow
//   map's own test at the receiver's texel); inside the hard shadow saturate(2 * PCF) keeps only the inner
//   half of the penumbra, which then starts at the hard edge and grows inwards.
#include "pcss_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Constants { PcssConstants k; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2) uniform sampler2D normal_tex;
layout(set = 0, binding = 3) uniform sampler2D shadow_map;
#include "engine_surface.glsl"
#include "output_format.glsl"
layout(set = 0, binding = 4, OUTPUT_FORMAT) uniform writeonly image2D result;
#ifdef HARD_EDGE_FROM_RAY_TRACE
layout(set = 0, binding = 5, r32f) uniform readonly image2D rt_visibility;
#endif

const float GOLDEN_ANGLE = 2.39996323;
const float TAN_MAX = 8.0;

// Receiver state shared by the helpers below.
vec2 uv;        // receiver in shadow-map texels
float d_r;      // receiver NDC depth
vec2 g;         // receiver-plane NDC depth per texel
float tol;      // NDC depth tolerance
float map_size;

float lin_depth(vec2 ndc, float d) {
    vec4 c = vec4(ndc, d, 1.0);
    return dot(k.light.lin_num, c) / dot(k.light.lin_den, c);
}

// d(linear depth) / d(NDC depth) at (ndc, d).
float lin_slope(vec2 ndc, float d) {
    vec4 c = vec4(ndc, d, 1.0);
    float num = dot(k.light.lin_num, c);
    float den = dot(k.light.lin_den, c);
    return (k.light.lin_num.z * den - num * k.light.lin_den.z) / (den * den);
}

bool is_spot() {
    return k.light.params.w != 0.0;
}

float texel_world(float z) {
    return is_spot() ? k.light.params.x * z : k.light.params.x;
}

// Penumbra half-width in texels at a receiver at linear depth zr behind a blocker edge at zb.
float penumbra_texels(float zr, float zb) {
    float size = k.light.params.y;
    if (is_spot()) {
        return size * (zr - zb) / (max(zb, 1e-30) * k.light.params.x * zr);
    }
    return size * (zr - zb) / k.light.params.x;
}

bool inside(ivec2 t) {
    return all(greaterThanEqual(t, ivec2(0))) && all(lessThan(t, ivec2(int(map_size))));
}

// Whether texel t holds an occluder in front of the receiver plane; its linear depth in z_b.
bool occludes(ivec2 t, out float z_b) {
    z_b = 0.0;
    if (!inside(t)) {
        return false;   // outside the map: no recorded occluder
    }
    float ds = texelFetch(shadow_map, t, 0).r;
    vec2 c = vec2(t) + 0.5;
    if (ds < d_r + dot(g, c - uv) - tol) {
        z_b = lin_depth(c / map_size * 2.0 - 1.0, ds);
        return true;
    }
    return false;
}

vec2 vogel(uint i, uint count, float rotation) {
    float r = sqrt((float(i) + 0.5) / float(count));
    float a = float(i) * GOLDEN_ANGLE + rotation;
    return r * vec2(cos(a), sin(a));
}

void store(ivec2 px, float v) {
    imageStore(result, px, vec4(v));
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= int(k.dims.x) || px.y >= int(k.dims.y)) {
        return;
    }
    vec3 rel;
    float depth;
    vec3 n;
    if (!engine_receiver(px, k.inv_view_proj_rel, k.dims.xy, k.surface_mode, k.surface, k.view_to_world, rel,
                         depth, n)) {
        store(px, 1.0);     // background
        return;
    }
    vec3 p = k.camera_pos.xyz + rel;
    vec3 to_light = is_spot() ? normalize(k.light.position.xyz - p) : -k.light.direction.xyz;
    float cos_t = dot(n, to_light);
    if (!faces_light(px, n, to_light, depth, rel, k.inv_view_proj_rel, k.dims.xy, k.surface)) {
        store(px, 0.0);     // the visible side faces away from the light
        return;
    }
    // Facing decided within the normal's precision may leave a cosine at or below 0: keep the slope finite.
    cos_t = max(cos_t, 1e-4);
    vec4 lc = k.light.view_proj * vec4(p, 1.0);
    if (!(lc.w > 0.0)) {
        store(px, 1.0);     // behind a spot light
        return;
    }
    vec3 lndc = lc.xyz / lc.w;
    map_size = float(k.dims.z);
    uv = (lndc.xy * 0.5 + 0.5) * map_size;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(map_size)))) {
        store(px, 1.0);     // outside the light's map
        return;
    }
    d_r = lndc.z;
    float z_r = lin_depth(lndc.xy, d_r);
    float slope = max(lin_slope(lndc.xy, d_r), 1e-30);
    float tw = texel_world(z_r);

    if (k.dims.w == MODE_CLASSIC_TEST) {
        // The conventional test: nearest texel, constant + slope-scaled bias along the light.
        ivec2 t = ivec2(floor(uv));
        float ds = texelFetch(shadow_map, t, 0).r;
        float z_s = lin_depth((vec2(t) + 0.5) / map_size * 2.0 - 1.0, ds);
        float tan_t = sqrt(max(1.0 - cos_t * cos_t, 0.0)) / cos_t;
        float bias = tw * (k.bias.x + k.bias.y * min(tan_t, 10.0));
        store(px, z_s < z_r - bias ? 0.0 : 1.0);
        return;
    }

    // Receiver plane in the light's NDC: (n, -n.p) times the inverse view-projection.
    vec4 plane = vec4(n, -dot(n, p)) * k.light.inv_view_proj;
    float g_max = TAN_MAX * tw / slope;
    g = plane.z != 0.0 ? -plane.xy / plane.z * (2.0 / map_size) : vec2(0.0);
    g = clamp(g, vec2(-g_max), vec2(g_max));
    float footprint = length(rel) * k.camera_pos.w * (1.0 / 64.0);
    tol = (abs(g.x) + abs(g.y)) * k.bias.z + (tw * k.bias.w + footprint) / slope;

    if (k.dims.w == MODE_PCSS_SHRINKING) {
        // Outside the hard shadow the shrinking result is exactly 1: skip the search and the PCF there.
#ifdef HARD_EDGE_FROM_RAY_TRACE
        bool hard_lit = imageLoad(rt_visibility, px).r > 0.5;
#else
        float unused;
        bool hard_lit = !occludes(ivec2(floor(uv)), unused);
#endif
        if (hard_lit) {
            store(px, 1.0);
            return;
        }
    }

    float rotation = 6.2831853 * fract(52.9829189 * fract(dot(vec2(px), vec2(0.06711056, 0.00583715))));

    // Blocker search.
    float z_near = lin_depth(lndc.xy, 0.0);
    float r_search = clamp(penumbra_texels(z_r, z_near), k.radii.y, k.radii.x);
    uint search_taps = max(k.taps.x, 1u);
    float blockers = 0.0;
    float z_sum = 0.0;
    for (uint i = 0u; i < search_taps; ++i) {
        vec2 o = vogel(i, search_taps, rotation) * r_search;
        float z_b;
        if (occludes(ivec2(floor(uv + o)), z_b)) {
            blockers += 1.0;
            z_sum += z_b;
        }
    }
    float vis = 1.0;
    if (blockers > 0.0) {
        float z_b = z_sum / blockers;
        float r_filter = clamp(penumbra_texels(z_r, z_b), k.radii.y, k.radii.z);
        uint pcf_taps = max(k.taps.y, 1u);
        float lit = 0.0;
        for (uint i = 0u; i < pcf_taps; ++i) {
            vec2 o = vogel(i, pcf_taps, rotation) * r_filter;
            float unused;
            if (!occludes(ivec2(floor(uv + o)), unused)) {
                lit += 1.0;
            }
        }
        vis = lit / float(pcf_taps);
    }
    if (k.dims.w == MODE_PCSS_SHRINKING) {
        // Inside the hard shadow: keep the inner half of the penumbra, which starts at the hard edge.
        vis = clamp(2.0 * vis, 0.0, 1.0);
    }
    store(px, vis);
}

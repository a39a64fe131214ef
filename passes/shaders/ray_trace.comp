#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
// Per-pixel shadow ray through the deep primitive map.
//
// Numerics (see README "Numerical design"):
// - Everything is in frame coordinates (relative to an origin near the scene), so precision does not
//   depend on where the scene sits in the world. The receiver point P is rebuilt from depth relative to
//   the camera, then offset along its geometric normal by a bound on its own error: a fraction of the
//   pixel footprint (depth interpolation and vertex snapping move P by less than that) plus a few ulps
//   of |P| (the rounding of camera + offset). No world-space bias.
// - Ray/triangle test: watertight (Woop, Benthin, Wald 2013), two-sided, no epsilons. Edge functions are
//   `precise` so that a shared edge gives exactly opposite values in both triangles: a ray through an edge
//   or vertex of a closed mesh always hits at least one triangle. Zero-determinant (degenerate or
//   edge-on) triangles are rejected without dividing.
// - The list of the ray origin's texel holds every triangle that may cross the ray (see map_bin.glsl);
//   where the map holds no complete list (trace_route.glsl), the ray walks the BVH over the prim buffer
//   (bvh_traverse.glsl), testing every triangle whose box it meets with the same test: the same answer.
// - Directional light: the ray runs along -light_dir without end. Spot light: the ray runs from the offset
//   origin to the light position and only hits before it count (t < distance). The texel is the ray
//   origin's under the light's projection: orthographic or perspective, every point of the shadow ray
//   projects into that texel, because the ray is parallel to the projection direction or passes through
//   the centre of projection.
#include "triangle.glsl"
#include "ray_trace_constants.glsl"
#include "map_state.glsl"
#include "bvh.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Constants { RayTraceConstants k; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2) uniform sampler2D normal_tex;
layout(set = 0, binding = 3) buffer State { MapState ms; };
layout(set = 0, binding = 4) readonly buffer PixelTexels { uint pixel_texel[]; };
layout(set = 0, binding = 5) readonly buffer Offsets { uint offsets[]; };
#include "map_offsets.glsl"
layout(set = 0, binding = 6) readonly buffer Entries { uint entries[]; };
layout(set = 0, binding = 7) readonly buffer Prims { Triangle tris[]; };
#include "output_format.glsl"
layout(set = 0, binding = 8, OUTPUT_FORMAT) uniform writeonly image2D visibility;
layout(set = 0, binding = 9, r32f) uniform writeonly image2D blocker;
// The rays' BVH (passes::bvh): one ray per pixel.
layout(set = 0, binding = 10) readonly buffer Bvh { BvhNode bvh_nodes[]; };
#include "shadow_ray.glsl"
#include "trace_route.glsl"
#include "bvh_traverse.glsl"

// Ray in Woop's sheared space.
int kx, ky, kz;
float sx, sy, sz;
vec3 origin;

void setup_ray(vec3 o, vec3 d) {
    vec3 ad = abs(d);
    kz = (ad.x > ad.y) ? ((ad.x > ad.z) ? 0 : 2) : ((ad.y > ad.z) ? 1 : 2);
    kx = (kz + 1) % 3;
    ky = (kx + 1) % 3;
    sx = d[kx] / d[kz];
    sy = d[ky] / d[kz];
    sz = 1.0 / d[kz];
    origin = o;
}

// Returns the hit distance along the ray, or -1.
// Exact rounding error of the f32 product p = a * b (Dekker's TwoProduct with Veltkamp splitting, no
// fma: some drivers, lavapipe among them, lower fma() to an unfused multiply-add).
float product_error(float a, float b, float p) {
    precise float ca = 4097.0 * a;
    precise float ah = ca - (ca - a);
    precise float al = a - ah;
    precise float cb = 4097.0 * b;
    precise float bh = cb - (cb - b);
    precise float bl = b - bh;
    precise float e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    return e;
}

// a * b - c * d with both products' rounding errors recovered: its sign is exact in all but
// pathological double cancellations, and swapping the pairs negates the result exactly, so a shared edge
// still gets opposite values in its two triangles.
float edge_refined(float a, float b, float c, float d) {
    precise float p = a * b;
    precise float q = c * d;
    precise float r = (p - q) + (product_error(a, b, p) - product_error(c, d, q));
    return r;
}

float intersect(Triangle t) {
    precise vec3 a = t.v[0].xyz - origin;
    precise vec3 b = t.v[1].xyz - origin;
    precise vec3 c = t.v[2].xyz - origin;
    precise float ax = a[kx] - sx * a[kz];
    precise float ay = a[ky] - sy * a[kz];
    precise float bx = b[kx] - sx * b[kz];
    precise float by = b[ky] - sy * b[kz];
    precise float cx = c[kx] - sx * c[kz];
    precise float cy = c[ky] - sy * c[kz];
    precise float u = cx * by - cy * bx;
    precise float v = ax * cy - ay * cx;
    precise float w = bx * ay - by * ax;
    if (u == 0.0 || v == 0.0 || w == 0.0) {
        // Woop et al. recompute in double when an edge function rounds to zero; the error-free products
        // do the same without shaderFloat64. Without this, tiny distant triangles lying almost along
        // the ray gave (0, 0, +) and a false hit.
        u = edge_refined(cx, by, cy, bx);
        v = edge_refined(ax, cy, ay, cx);
        w = edge_refined(bx, ay, by, ax);
    }
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) {
        return -1.0;
    }
    precise float det = u + v + w;
    if (det == 0.0) {
        return -1.0;
    }
    precise float tt = u * (sz * a[kz]) + v * (sz * b[kz]) + w * (sz * c[kz]);
    float dist = tt / det;
    return dist > 0.0 ? dist : -1.0;
}

void consider(uint index, inout float nearest) {
    if (index < uint(tris.length())) {
        float d = intersect(tris[index]);
        if (d > 0.0 && d < nearest) {
            nearest = d;
        }
    }
}

// The BVH walk's test of one triangle (bvh_traverse.glsl): the nearest hit so far bounds the walk.
float walk_nearest;
bool walk_first_hit;
float walk_t_max;

void bvh_visit(uint index, uvec4 samples) {
    consider(index, walk_nearest);
    bvh_cone_t_end = walk_nearest;
}

bool bvh_done() {
    return walk_first_hit && walk_nearest < walk_t_max;
}


void write(ivec2 px, float vis, float bd) {
    imageStore(visibility, px, vec4(vis));
    if (k.misc.z != 0u) {
        imageStore(blocker, px, vec4(bd));
    }
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= int(k.dims.x) || px.y >= int(k.dims.y)) {
        return;
    }
    vec3 o, dir;
    float t_max;
    int ray = shadow_ray(px, o, dir, t_max);
    if (ray != SHADOW_RAY_TRACE) {
        write(px, ray == SHADOW_RAY_LIT ? 1.0 : 0.0, ray == SHADOW_RAY_LIT ? -1.0 : 0.0);
        return;
    }
    setup_ray(o, dir);
    // The texel the receiver pass placed this ray origin in (the one whose list it filled).
    uint texel = pixel_texel[uint(px.y) * k.dims.x + uint(px.x)];
    if (texel == TEXEL_OUTSIDE) {
        write(px, 1.0, -1.0);   // outside the light's frustum: no recorded occluder
        return;
    }
    float nearest = t_max;
    // Without a blocker-distance output (hard shadows) any hit before the light decides the pixel, so the
    // walk stops after the first; otherwise it finds the nearest.
    bool first_hit = k.misc.z == 0u;
    uint begin, end;
    if (complete_list(texel, begin, end)) {
        // Checked every 8 entries, so that the walk within them keeps its loads in flight.
        for (uint i = begin; i < end && !(first_hit && nearest < t_max); i += 8u) {
            uint stop = min(i + 8u, end);
            for (uint j = i; j < stop; ++j) {
                consider(entries[j], nearest);
            }
        }
    } else {
        walk_nearest = nearest;
        walk_first_hit = first_hit;
        walk_t_max = t_max;
        bvh_set_cone(o, dir, 0.0, t_max);
        count_walk(bvh_walk(k.misc.y, uvec4(1u, 0u, 0u, 0u), 0xFFFFFFFFu));
        nearest = walk_nearest;
    }
    if (nearest < t_max) {
        write(px, 0.0, nearest);
    } else {
        write(px, 1.0, -1.0);
    }
}

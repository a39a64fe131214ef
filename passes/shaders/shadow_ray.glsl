// The shadow ray of a screen pixel, shared by every tracer of the frame (the primitive-map ray trace, the
// receiver passes that fit and cull the map, and the ray-tracing-pipeline peer) so that all of them trace
// exactly the same rays. The includer declares `k` (RayTraceConstants), `depth_tex` and `normal_tex`.

#include "engine_surface.glsl"
//
// The receiver point P is rebuilt from depth relative to the camera, then offset along its geometric
// normal by a bound on its own error: a fraction of the pixel footprint, a few ulps of |P|, and how far the
// depth format's precision lets P move along its view ray. No world-space bias. Any depth convention works
// (reversed or standard Z, finite or infinite far plane, or a linear view-Z image): P is rebuilt through the
// engine's own projection. Directional light: the ray runs along -light_dir without end. Spot light: the ray runs
// from the offset origin to the light position and only hits before it count (t < t_max).

const int SHADOW_RAY_TRACE = 0;     // trace o + t * dir, 0 < t < t_max
const int SHADOW_RAY_LIT = 1;       // no ray: background, or the receiver is at the emitter
const int SHADOW_RAY_FACING_AWAY = 2;   // no ray: the visible side faces away from the light

// The receiver's normal (world space, towards the camera) and point (frame coordinates, before the ray
// origin's offset), set by shadow_ray once it found a receiver.
vec3 shadow_ray_normal = vec3(0.0);
vec3 shadow_ray_receiver = vec3(0.0);

int shadow_ray(ivec2 px, out vec3 o, out vec3 dir, out float t_max) {
    o = vec3(0.0);
    dir = vec3(0.0, 0.0, 1.0);
    t_max = 1.0 / 0.0;
    vec3 rel;
    float depth;
    vec3 n;
    if (!engine_receiver(px, k.inv_view_proj_rel, k.dims.xy, k.surface_mode, k.surface, k.view_to_world, rel,
                         depth, n)) {
        return SHADOW_RAY_LIT;
    }
    vec3 p = k.camera_pos.xyz + rel;
    shadow_ray_receiver = p;
    bool spot = k.light_pos.w != 0.0;
    vec3 to_light = spot ? k.light_pos.xyz - p : -k.light_dir.xyz;
    shadow_ray_normal = n;
    if (k.light_dir.w > 0.0) {
        // Area shadows: the receiver faces away from every direction of the light's cone (angular radius r:
        // tan r = light_dir.w for a directional light; a spot or point light's emitter of radius
        // light_dir.w seen from distance d, sin r <= light_dir.w / d) only when its normal, within its own
        // precision, turns more than r past perpendicular; the area trace decides each sample's facing
        // itself.
        float sin_r = spot ? min(k.light_dir.w / length(to_light), 1.0)
                           : k.light_dir.w / sqrt(1.0 + k.light_dir.w * k.light_dir.w);
        if (dot(n, normalize(to_light)) < -(sin_r + k.surface.z) * (1.0 + 1.0 / 1024.0) - 1e-6) {
            return SHADOW_RAY_FACING_AWAY;
        }
    } else if (!faces_light(px, n, to_light, depth, rel, k.inv_view_proj_rel, k.dims.xy, k.surface)) {
        return SHADOW_RAY_FACING_AWAY;
    }
    vec3 ap = abs(p);
    // The depth buffer holds the depth within q of the surface's: one step of a D16 or D24 format
    // (k.offset.w: rounded either way), or 2^-23 of the value for a float format (either rounding). P moves along
    // its view ray by at most the distance from P to the points rebuilt from depth - q and depth + q (the
    // first kept in front of the far plane: a normalized depth that close to it may lie anywhere behind).
    // A view-Z image holds z within its relative precision (k.surface.y), and P scales with z along its ray
    // from the camera; twice that covers the rounding of the ray's construction.
    float depth_error;
    if (k.surface.y > 0.0) {
        depth_error = 2.0 * k.surface.y * length(rel);
    } else {
        float q = max(k.offset.w, depth * 1.1920929e-7);
        vec2 ndc = (vec2(px) + 0.5) / vec2(k.dims.xy) * 2.0 - 1.0;
        vec4 h = k.inv_view_proj_rel * vec4(ndc, depth, 1.0);
        // h is affine in depth: moving depth by t moves h by t times the matrix's depth column.
        vec4 h_near = h + q * k.inv_view_proj_rel[2];
        vec4 h_far = h + (max(depth - q, 0.5 * depth) - depth) * k.inv_view_proj_rel[2];
        depth_error = max(length(h_near.xyz / h_near.w - rel), length(h_far.xyz / h_far.w - rel));
    }
    float delta = length(rel) * k.offset.x * k.offset.y + max(max(ap.x, ap.y), ap.z) * k.offset.z
        + depth_error;
    o = p + n * delta;
    dir = to_light;
    if (spot) {
        vec3 d = k.light_pos.xyz - o;
        t_max = length(d);
        if (!(t_max > 0.0)) {
            return SHADOW_RAY_LIT;
        }
        dir = d / t_max;
    }
    return SHADOW_RAY_TRACE;
}

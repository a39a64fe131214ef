// The shadow ray of a screen pixel, shared by every tracer of the frame (the primitive-map ray trace, the
// receiver passes that fit and cull the map, and the ray-tracing-pipeline peer) so that all of them trace
// exactly the same rays. The includer declares `k` (RayTraceConstants), `depth_tex` and `normal_tex`.
//
// The receiver point P is rebuilt from depth relative to the camera, then offset along its geometric
// normal by a bound on its own error: a fraction of the pixel footprint plus a few ulps of |P|. No
// world-space bias. Directional light: the ray runs along -light_dir without end. Spot light: the ray runs
// from the offset origin to the light position and only hits before it count (t < t_max).

const int SHADOW_RAY_TRACE = 0;     // trace o + t * dir, 0 < t < t_max
const int SHADOW_RAY_LIT = 1;       // no ray: background, or the receiver is at the emitter
const int SHADOW_RAY_FACING_AWAY = 2;   // no ray: the visible side faces away from the light

int shadow_ray(ivec2 px, out vec3 o, out vec3 dir, out float t_max) {
    o = vec3(0.0);
    dir = vec3(0.0, 0.0, 1.0);
    t_max = 1.0 / 0.0;
    float depth = texelFetch(depth_tex, px, 0).r;
    vec4 normal = texelFetch(normal_tex, px, 0);
    if (depth <= 0.0 || normal.w == 0.0) {
        return SHADOW_RAY_LIT;
    }
    vec2 ndc = (vec2(px) + 0.5) / vec2(k.dims.xy) * 2.0 - 1.0;
    vec4 h = k.inv_view_proj_rel * vec4(ndc, depth, 1.0);
    vec3 rel = h.xyz / h.w;
    vec3 p = k.camera_pos.xyz + rel;
    bool spot = k.light_pos.w != 0.0;
    vec3 to_light = spot ? k.light_pos.xyz - p : -k.light_dir.xyz;
    vec3 n = normal.xyz;
    if (dot(n, to_light) <= 0.0) {
        return SHADOW_RAY_FACING_AWAY;
    }
    vec3 ap = abs(p);
    float delta = length(rel) * k.offset.x * k.offset.y + max(max(ap.x, ap.y), ap.z) * k.offset.z;
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

// The engine's surface at a pixel: whether it holds geometry, its point, and its normal in world orientation
// facing the camera, decoded from the engine's normal image as it is, or derived from depth. Needs the
// includer's `depth_tex` and `normal_tex`. Mirrors passes::surface.
//
// The depth image holds the projection's depth (surface.y == 0) or a linear view-space z (surface.y > 0:
// its relative precision), as `HrtsFrame::view` gives it; a view-Z pixel holding 0, a value that is not
// finite or one of magnitude 65504 or more is background.
//
// mode.x: the encoding. 0: xyz as stored, w = 0 on background (the plugin's original contract); 1: xyz;
//   2: octahedral in the first two channels; 3: none (derived from depth).
// mode.y: 1 when the channels are normalized to [0, 1] (unorm formats): they map to [-1, 1].
// mode.z: 1 when the normal is in view space (rotated to world by view_to_world).
// Coverage: a pixel holds geometry iff its depth is positive and differs from `background` (the depth the
// projection gives infinitely far away, clamped to [0, 1]: 0 for reversed Z, 1 for standard Z), and, in
// mode 0, its normal's w is not 0.

const uint NORMAL_XYZ_COVERAGE = 0u;
const uint NORMAL_XYZ = 1u;
const uint NORMAL_OCTAHEDRAL = 2u;
const uint NORMAL_FROM_DEPTH = 3u;

vec3 octahedral_decode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = max(-n.z, 0.0);
    n.x += n.x >= 0.0 ? -t : t;
    n.y += n.y >= 0.0 ? -t : t;
    return n;
}

// The point of pixel `px` at `depth`, relative to the camera.
vec3 surface_point(ivec2 px, float depth, mat4 inv_view_proj_rel, uvec2 dims) {
    vec2 ndc = (vec2(px) + 0.5) / vec2(dims) * 2.0 - 1.0;
    vec4 h = inv_view_proj_rel * vec4(ndc, depth, 1.0);
    return h.xyz / h.w;
}

bool covered(float depth, float background) {
    return depth > 0.0 && depth != background;
}

// The engine's point at `px` relative to the camera, and the value its depth image holds there; false on
// background. A view-space z picks the point on the pixel's ray (through two points of it) whose view z it
// is: the view's z axis is the last row of the view rotation, the inverse of `view_to_world`'s.
bool engine_point(ivec2 px, mat4 inv_view_proj_rel, uvec2 dims, vec4 surface, mat4 view_to_world,
                  out vec3 rel, out float stored) {
    stored = texelFetch(depth_tex, px, 0).r;
    rel = vec3(0.0);
    if (surface.y == 0.0) {
        if (!covered(stored, surface.x)) {
            return false;
        }
        rel = surface_point(px, stored, inv_view_proj_rel, dims);
        return true;
    }
    if (!(stored != 0.0 && abs(stored) < 65504.0)) {
        return false;
    }
    vec3 a = surface_point(px, 0.25, inv_view_proj_rel, dims);
    vec3 b = surface_point(px, 0.75, inv_view_proj_rel, dims);
    vec3 z_axis = transpose(inverse(mat3(view_to_world)))[2];
    float za = dot(a, z_axis);
    float zb = dot(b, z_axis);
    rel = a + (stored - za) / (zb - za) * (b - a);
    return true;
}

// The neighbour of `px` along `axis` (one of its two sides) most likely on the same plane as `px`. A
// plane's depth is affine in screen space: on a side whose next two pixels q1, q2 hold geometry, the
// plane test is 2 d(q1) - d(q2) - d(px) (0 when both continue the centre's plane); on a side with one pixel,
// d(q1) - d(px). The side where it is smaller is taken. Returns the difference of positions, neighbour minus
// centre, signed along +axis, and its score; false if neither side holds geometry.
bool surface_step(ivec2 px, ivec2 axis, vec3 center, float depth, mat4 inv_view_proj_rel, uvec2 dims,
                  float background, out vec3 step_vec, out float score) {
    step_vec = vec3(0.0);
    score = 1.0 / 0.0;
    bool found = false;
    for (int side = -1; side <= 1; side += 2) {
        ivec2 q1 = px + axis * side;
        ivec2 q2 = px + axis * (2 * side);
        if (q1.x < 0 || q1.y < 0 || q1.x >= int(dims.x) || q1.y >= int(dims.y)) {
            continue;
        }
        float d1 = texelFetch(depth_tex, q1, 0).r;
        if (!covered(d1, background)) {
            continue;
        }
        float error = abs(d1 - depth);
        if (q2.x >= 0 && q2.y >= 0 && q2.x < int(dims.x) && q2.y < int(dims.y)) {
            float d2 = texelFetch(depth_tex, q2, 0).r;
            if (covered(d2, background)) {
                error = abs(2.0 * d1 - d2 - depth);
            }
        }
        if (found && !(error < score)) {
            continue;
        }
        score = error;
        step_vec = (surface_point(q1, d1, inv_view_proj_rel, dims) - center) * float(side);
        found = true;
    }
    return found;
}

// The normal at `px` derived from depth, facing the camera: two steps along the surface, along x and y, or,
// where an axis has no neighbour holding geometry or a worse one than a diagonal, along the better diagonal
// (a sliver of surface between a silhouette and the background). A pixel with no two steps on its surface
// gets a normal facing the camera; false then.
bool derived_normal(ivec2 px, float depth, vec3 rel, mat4 inv_view_proj_rel, uvec2 dims, float background,
                    out vec3 n) {
    vec3 dx, dy, da, db;
    float sx, sy, sa, sb;
    bool has_x = surface_step(px, ivec2(1, 0), rel, depth, inv_view_proj_rel, dims, background, dx, sx);
    bool has_y = surface_step(px, ivec2(0, 1), rel, depth, inv_view_proj_rel, dims, background, dy, sy);
    bool has_a = surface_step(px, ivec2(1, 1), rel, depth, inv_view_proj_rel, dims, background, da, sa);
    bool has_b = surface_step(px, ivec2(1, -1), rel, depth, inv_view_proj_rel, dims, background, db, sb);
    vec3 diagonal = (has_a && (!has_b || sa <= sb)) ? da : db;
    float sd = (has_a && (!has_b || sa <= sb)) ? sa : sb;
    bool has_d = has_a || has_b;
    if (has_d && (!has_x || sd < sx) && has_y) {
        dx = diagonal;
        has_x = true;
    } else if (has_d && (!has_y || sd < sy) && has_x) {
        dy = diagonal;
        has_y = true;
    }
    vec3 c = cross(dx, dy);
    bool found = has_x && has_y && dot(c, c) > 0.0;
    n = found ? normalize(c) : -normalize(rel);
    if (dot(n, rel) > 0.0) {
        n = -n;
    }
    return found;
}

// The normal at `px`, whose point `engine_point` found at `rel` with the stored `depth`. Normals derived
// from depth need a depth image of the projection's depth (the plugin refuses them with view Z).
bool engine_surface(ivec2 px, float depth, vec3 rel, mat4 inv_view_proj_rel, uvec2 dims, uvec4 mode,
                    mat4 view_to_world, float background, out vec3 n) {
    n = vec3(0.0, 0.0, 1.0);
    if (mode.x == NORMAL_FROM_DEPTH) {
        derived_normal(px, depth, rel, inv_view_proj_rel, dims, background, n);
        return true;
    }
    vec4 v = texelFetch(normal_tex, px, 0);
    if (mode.x == NORMAL_XYZ_COVERAGE && v.w == 0.0) {
        return false;
    }
    vec4 s = mode.y != 0u ? v * 2.0 - 1.0 : v;
    n = mode.x == NORMAL_OCTAHEDRAL ? octahedral_decode(s.xy) : s.xyz;
    if (mode.z != 0u) {
        n = mat3(view_to_world) * n;
    }
    if (!(dot(n, n) > 0.0)) {
        return false;
    }
    n = normalize(n);
    if (dot(n, rel) > 0.0) {
        n = -n;     // the side the camera sees
    }
    return true;
}

// The receiver at `px`: its point relative to the camera, the value its depth image holds and its normal
// (engine_point, then engine_surface); false on background.
bool engine_receiver(ivec2 px, mat4 inv_view_proj_rel, uvec2 dims, uvec4 mode, vec4 surface,
                     mat4 view_to_world, out vec3 rel, out float depth, out vec3 n) {
    n = vec3(0.0, 0.0, 1.0);
    return engine_point(px, inv_view_proj_rel, dims, surface, view_to_world, rel, depth)
        && engine_surface(px, depth, rel, inv_view_proj_rel, dims, mode, view_to_world, surface.x, n);
}

// Whether the surface at `px` (normal `n` from engine_surface) faces a light in direction `to_light`. The
// engine's normal decides, unless it lies within its own precision (surface.z: the sine of the largest
// angle by which the encoding tilts it) of perpendicular to the light: then the normal derived from a depth
// image of the projection's depth decides where it agrees with the engine's within that precision, as on a
// surface's interior, where it holds the plane far better than an 8-bit channel does.
bool faces_light(ivec2 px, vec3 n, vec3 to_light, float depth, vec3 rel, mat4 inv_view_proj_rel,
                 uvec2 dims, vec4 surface) {
    float c = dot(n, normalize(to_light));
    vec3 d;
    // The derived normal is taken only where it describes the same surface: within twice the encoding's
    // tilt of the engine's normal (not at a silhouette or a thin part, where the neighbours lie elsewhere).
    if (abs(c) > surface.z || surface.y > 0.0
        || !derived_normal(px, depth, rel, inv_view_proj_rel, dims, surface.x, d)
        || length(cross(d, n)) > 2.0 * surface.z || dot(d, n) <= 0.0) {
        return c > 0.0;
    }
    return dot(d, to_light) > 0.0;
}

#version 460
#extension GL_GOOGLE_include_directive : require
// One invocation: fits each frustum's grid to its receivers' light-space bounds (padded by 1/256 of their
// extent): `to_texels` maps frame coordinates to homogeneous texel space, the frustum's view-projection
// followed by the 2D affine fit; `grid` places the grid in the map's texels. (The host resets the state
// of every frustum for each frame: passes::gpu_types::MapState::reset.)
#include "ray_trace_constants.glsl"
#include "map_state.glsl"
#include "map_push.glsl"

layout(local_size_x = 1) in;
layout(set = 0, binding = 0) buffer State { MapState faces[]; };
layout(set = 0, binding = 1) uniform Constants { RayTraceConstants k; mat4 frusta[6]; };
layout(push_constant) uniform Push { MapPush pc; };

const uint MIN_GRID = 16u;

void main() {
    uint rays = 0u;
    for (uint f = 0u; f < pc.faces; ++f) {
        rays += faces[f].receivers.w;
    }
    uint min_grid = min(MIN_GRID, pc.size);
    uint base = 0u;
    for (uint f = 0u; f < pc.faces; ++f) {
        uvec4 b = faces[f].bounds;
        if (b.x > b.z || b.y > b.w) {
            continue;   // no receivers: no pixel traces a ray through this frustum, its grid stays empty
        }
        vec2 lo = vec2(unordered(b.x), unordered(b.y));
        vec2 hi = vec2(unordered(b.z), unordered(b.w));
        vec2 extent = max(hi - lo, max(abs(lo), abs(hi)) * 1e-6 + 1e-30);
        lo -= extent / 256.0;
        hi += extent / 256.0;
        // With receiver culling, a texel holds a list only where a ray origin lies, so a grid much finer
        // than the rays only multiplies the binning work of large triangles (a face of a point light that
        // sees a handful of pixels would otherwise spread every triangle over N^2 texels). The grid keeps
        // about 16 texels per ray origin, at least MIN_GRID and at most N per side; without culling (a
        // debug mode whose lists are compared texel by texel), always N. A point light's faces share N^2
        // texels (plus MIN_GRID^2 each) in proportion to their rays.
        uint n = pc.size;
        uint rays_f = faces[f].receivers.w;
        if (pc.cull != 0u) {
            n = clamp(4u * uint(ceil(sqrt(float(rays_f)))), min_grid, pc.size);
        }
        uint stride = pc.size;
        if (pc.faces > 1u) {
            uint left = pc.texels - base;
            if (left == 0u) {
                // No texel left (the shares' rounding never uses up the minimum grids' spare texels at the
                // sizes validated): the face gets no grid and its rays are traced exhaustively, exact.
                continue;
            }
            uint share = uint(float(pc.size) * sqrt(float(rays_f) / float(max(rays, 1u))));
            n = min(n, max(share, min_grid));
            n = max(min(n, uint(sqrt(float(left)))), 1u);
            while (n > 1u && n * n > left) {
                n -= 1u;
            }
            stride = n;
        }
        faces[f].fit.y = float(n);
        vec2 s = float(n) / (hi - lo);
        // texel * w = s * (clip.xy - lo * clip.w)
        mat4 fit = mat4(1.0);
        fit[0][0] = s.x;
        fit[1][1] = s.y;
        fit[3][0] = -lo.x * s.x;
        fit[3][1] = -lo.y * s.y;
        faces[f].to_texels = fit * frusta[f];
        faces[f].fit.x = 1.0;
        if (pc.penumbra > 0.0) {
            // Area shadows (orthographic light): a shadow ray within the light's angular radius r of its
            // axis moves at most tan(r) sideways per unit it climbs towards the light, so its texel moves
            // at most tan(r) |row x or y| / |row z| texels per unit of depth key it climbs. The relative and
            // absolute terms cover the rounding of the rows and of the axes' orthogonality.
            mat4 m = faces[f].to_texels;
            float rx = length(vec3(m[0][0], m[1][0], m[2][0]));
            float ry = length(vec3(m[0][1], m[1][1], m[2][1]));
            float rz = length(vec3(m[0][2], m[1][2], m[2][2]));
            faces[f].fit.z = (pc.penumbra * (1.0 + 1.0 / 4096.0) + 1e-6) * max(rx, ry) / rz;
        }
        if (pc.emitter_radius > 0.0) {
            // Area shadows of a spot or point light of emitter radius R (passes::area::LocalAreaReach): a point
            // q = x + t (s - x) of a segment from a receiver x to an emitter point s = P + d (|d| <= R) lies
            // t |(row_x - T row_w) . d| / w(q) <= t R |row_x - T row_w| / w(q) texels from x's texel T along
            // x (rows: the linear part of to_texels; likewise y). Over the grid's texels, with one texel of
            // slack, |row_x - T row_w| is largest at an end: fit.z is R times the largest such norm, and
            // fit.w the emitter's depth extent R |row_w| (map_bin.glsl's penumbra_span takes t / w(q) from
            // there).
            mat4 m = faces[f].to_texels;
            vec3 rx = vec3(m[0][0], m[1][0], m[2][0]);
            vec3 ry = vec3(m[0][1], m[1][1], m[2][1]);
            vec3 rw = vec3(m[0][3], m[1][3], m[2][3]);
            float far_end = float(n) + 1.0;
            float widest = max(max(length(rx + rw), length(rx - far_end * rw)),
                               max(length(ry + rw), length(ry - far_end * rw)));
            faces[f].fit.z = pc.emitter_radius * widest * (1.0 + 1.0 / 1024.0);
            faces[f].fit.w = pc.emitter_radius * length(rw) * (1.0 + 1.0 / 1024.0);
        }
        faces[f].grid.xy = uvec2(base, stride);
        if (pc.faces > 1u) {
            base += n * n;
        }
    }
}

#version 460
#extension GL_GOOGLE_include_directive : require
// FXAA (fast approximate anti-aliasing, after Lottes) over the ray-traced visibility, which is its own
// "luma". A pixel whose 4-neighbourhood has no contrast above the threshold is copied unchanged; otherwise
// the edge orientation comes from second differences over the 3x3 block, the edge is followed both ways
// (on the half-pixel line between the pixel and its neighbour across the edge) until the pair average
// departs from the edge value, and the pixel is blended towards that neighbour by its position along the
// edge span (plus a sub-pixel term). The result is therefore only ever a mix of a pixel and one of its
// 4-neighbours: FXAA changes pixels adjacent to a visibility edge and nothing else.
#include "fxaa_push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32f) uniform readonly image2D src;
#include "output_format.glsl"
layout(set = 0, binding = 1, OUTPUT_FORMAT) uniform writeonly image2D dst;
layout(push_constant) uniform Push { FxaaPush pc; };

float at(ivec2 q) {
    return imageLoad(src, clamp(q, ivec2(0), ivec2(int(pc.width) - 1, int(pc.height) - 1))).r;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) {
        return;
    }
    float m = at(p);
    float n = at(p + ivec2(0, -1));
    float s = at(p + ivec2(0, 1));
    float e = at(p + ivec2(1, 0));
    float w = at(p + ivec2(-1, 0));
    float lo = min(m, min(min(n, s), min(e, w)));
    float hi = max(m, max(max(n, s), max(e, w)));
    float range = hi - lo;
    if (range < max(pc.params.y, hi * pc.params.x)) {
        imageStore(dst, p, vec4(m));
        return;
    }
    float nw = at(p + ivec2(-1, -1));
    float ne = at(p + ivec2(1, -1));
    float sw = at(p + ivec2(-1, 1));
    float se = at(p + ivec2(1, 1));
    // Variation across rows (an edge running along x) versus across columns.
    float across_rows = 2.0 * abs(n + s - 2.0 * m) + abs(nw + sw - 2.0 * w) + abs(ne + se - 2.0 * e);
    float across_cols = 2.0 * abs(e + w - 2.0 * m) + abs(nw + ne - 2.0 * n) + abs(sw + se - 2.0 * s);
    bool along_x = across_rows >= across_cols;
    float before = along_x ? n : w;
    float after = along_x ? s : e;
    bool to_after = abs(after - m) >= abs(before - m);
    float other = to_after ? after : before;
    float gradient = abs(other - m);
    ivec2 normal = along_x ? ivec2(0, to_after ? 1 : -1) : ivec2(to_after ? 1 : -1, 0);
    ivec2 tangent = along_x ? ivec2(1, 0) : ivec2(0, 1);
    float edge = 0.5 * (m + other);
    float threshold = 0.25 * gradient;

    // Follow the edge both ways on the line between the pixel and `other`.
    int back = 0;
    int ahead = 0;
    float end_back = 0.0;
    float end_ahead = 0.0;
    bool found_back = false;
    bool found_ahead = false;
    for (uint i = 0u; i < pc.max_steps && !(found_back && found_ahead); ++i) {
        int step = i < 4u ? 1 : (i < 8u ? 2 : 4);
        if (!found_back) {
            back += step;
            ivec2 q = p - tangent * back;
            end_back = 0.5 * (at(q) + at(q + normal)) - edge;
            found_back = abs(end_back) >= threshold;
        }
        if (!found_ahead) {
            ahead += step;
            ivec2 q = p + tangent * ahead;
            end_ahead = 0.5 * (at(q) + at(q + normal)) - edge;
            found_ahead = abs(end_ahead) >= threshold;
        }
    }
    bool back_nearer = back < ahead;
    float distance = float(min(back, ahead));
    float span = float(back + ahead);
    float end_value = back_nearer ? end_back : end_ahead;
    // Blend only when the nearer end of the edge turns away from this pixel's side of the step.
    bool below = m < edge;
    float offset = ((end_value < 0.0) != below) ? 0.5 - distance / span : 0.0;
    // Sub-pixel aliasing: a pixel that differs from its whole neighbourhood.
    float average = (2.0 * (n + s + e + w) + nw + ne + sw + se) / 12.0;
    float sub = clamp(abs(average - m) / range, 0.0, 1.0);
    sub = smoothstep(0.0, 1.0, sub);
    offset = max(offset, sub * sub * pc.params.z);
    imageStore(dst, p, vec4(mix(m, other, offset)));
}

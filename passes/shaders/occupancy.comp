#version 460
#extension GL_GOOGLE_include_directive : require
// The primitive map's occupancy view, when asked for (the only reader of the receiver map after the build;
// map_pack.comp tallies the statistics). Colours: black without a list, grey levels the list length on a
// log scale (white at OCCUPANCY_WHITE entries or more), dark blue texels with ray origins but an empty
// list, red texels traced exhaustively (past the entry capacity, or in a group whose offsets overflowed).
// The texels are laid out in rows of N (a point light's face grids follow one another), and the view shows
// the first N rows. Each invocation draws a 2x2 quad of texels.
#include "map_state.glsl"

#define OCCUPANCY_WHITE 256.0

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) readonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 1) readonly buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 2, rgba8) uniform writeonly image2D occupancy;
layout(set = 0, binding = 3) readonly buffer State { MapState ms; };
layout(push_constant) uniform Push { uint size; uint texels; } pc;
#include "map_offsets.glsl"

void main() {
    uint capacity = ms.totals.z;
    for (uint q = 0u; q < 4u; ++q) {
        uvec2 t = gl_GlobalInvocationID.xy * 2u + uvec2(q & 1u, q >> 1u);
        uint texel = t.y * pc.size + t.x;
        if (t.x >= pc.size || t.y >= pc.size || texel >= pc.texels) {
            continue;
        }
        uint begin, end;
        bool complete = list_range(texel, begin, end);
        uint count = end - begin;
        bool receives = receiver[texel] != 0u;
        vec4 colour = vec4(vec3(min(log2(1.0 + float(count)) / log2(1.0 + OCCUPANCY_WHITE), 1.0)), 1.0);
        if (!complete || (count > 0u && end > capacity)) {
            colour = vec4(1.0, 0.0, 0.0, 1.0);
        } else if (count == 0u && receives) {
            colour = vec4(0.0, 0.0, 0.25, 1.0);
        }
        imageStore(occupancy, ivec2(t), colour);
    }
}

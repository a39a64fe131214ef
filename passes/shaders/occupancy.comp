#version 460
#extension GL_GOOGLE_include_directive : require
// Occupancy view of the deep primitive map — black empty, grey levels count/d, white full (count == d),
// red where the list overflowed (count > d) — and the map statistics of the frame report.
#include "map_stats.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32ui) uniform readonly uimage2D count_map;
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D occupancy;
layout(set = 0, binding = 2) buffer Stats { MapStats stats; };
layout(push_constant) uniform Push { uint size; uint depth; } pc;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= int(pc.size) || t.y >= int(pc.size)) {
        return;
    }
    uint count = imageLoad(count_map, t).r;
    bool overflow = count > pc.depth;
    vec4 colour = overflow ? vec4(1.0, 0.0, 0.0, 1.0) : vec4(vec3(float(count) / float(pc.depth)), 1.0);
    imageStore(occupancy, t, colour);
    if (count > 0u) {
        atomicAdd(stats.occupied_texels, 1u);
        atomicAdd(stats.stored_entries, min(count, pc.depth));
        atomicMax(stats.max_count, count);
    }
    if (overflow) {
        atomicAdd(stats.overflowed_texels, 1u);
    }
}

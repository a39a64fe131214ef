#version 460
#extension GL_GOOGLE_include_directive : require
// Hybrid lerp factor (Story, GDC 2015): L = saturate(BD / WSS * PHS) from the ray-traced blocker distance
// BD. Pixels without a blocker (lit or background, BD < 0) get L = 0: the hybrid there is the ray-traced
// result, which is lit. Receivers facing away from the light have BD = 0, so L = 0 as well.
#include "hybrid_push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32f) uniform readonly image2D blocker_distance;
layout(set = 0, binding = 1, r32f) uniform writeonly image2D lerp_factor;
layout(push_constant) uniform Push { HybridPush pc; };

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) {
        return;
    }
    float bd = imageLoad(blocker_distance, p).r;
    float l = bd > 0.0 ? clamp(bd / pc.world_space_scale * pc.hard_shadow_percentage, 0.0, 1.0) : 0.0;
    imageStore(lerp_factor, p, vec4(l));
}

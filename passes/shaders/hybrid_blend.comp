#version 460
#extension GL_GOOGLE_include_directive : require
// Hybrid blend (Story, GDC 2015): FS = lerp(RTS, PCSS, L). RTS is the ray-traced visibility, after FXAA
// when antialiasing is on.
#include "hybrid_push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32f) uniform readonly image2D rts;
layout(set = 0, binding = 1, r32f) uniform readonly image2D pcss;
layout(set = 0, binding = 2, r32f) uniform readonly image2D lerp_factor;
#include "output_format.glsl"
layout(set = 0, binding = 3, OUTPUT_FORMAT) uniform writeonly image2D result;
layout(push_constant) uniform Push { HybridPush pc; };

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) {
        return;
    }
    float hard = imageLoad(rts, p).r;
    float soft = imageLoad(pcss, p).r;
    float l = imageLoad(lerp_factor, p).r;
    // Written out rather than mix(): exactly RTS at L = 0 and exactly PCSS at L = 1.
    imageStore(result, p, vec4(hard * (1.0 - l) + soft * l));
}

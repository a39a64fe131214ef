#version 460
#extension GL_GOOGLE_include_directive : require
// Raster binning paths (hardware, software, tier-1 emulation): the rasterizer proposes texels, the exact
// shared test of map_bin.glsl decides, and the pass counts (mode 0) or fills (mode 1) exactly as the
// compute path does (map_bin.comp).
#include "map_state.glsl"
#include "map_push.glsl"
#include "map_bin.glsl"
#include "map_raster.glsl"

layout(set = 0, binding = 0) readonly buffer BinTris { BinTri bin_tris[]; };
layout(set = 0, binding = 1) readonly buffer Receivers { uint receiver[]; };
layout(set = 0, binding = 2) buffer Counts { uint counts[]; };
layout(set = 0, binding = 3) writeonly buffer Entries { uint entries[]; };
layout(set = 0, binding = 4) buffer Capped { uint capped[]; };
layout(push_constant) uniform Push { MapPush pc; };
#include "map_store.glsl"

void main() {
    uint tri = uint(gl_PrimitiveID);
    BinTri bt = bin_tris[tri];
    uvec2 t = uvec2(gl_FragCoord.xy);
    if (!in_bin_box(bt, t)) {
        return;
    }
    uint texel = t.y * pc.size + t.x;
    if (!bin_accepts(bt, texel, vec2(t) + 0.5, pc.cull != 0u, vec2(0.0), 0.0)) {
        return;
    }
    bin_store(tri, texel);
}

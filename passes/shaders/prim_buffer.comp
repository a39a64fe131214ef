#version 460
#extension GL_GOOGLE_include_directive : require
// Prim buffer build: transforms a draw's indexed triangles to world space and stores them at
// draw-call offset + primitive id (the seed's "hash draw call ID with SV_PrimitiveID").
#include "triangle.glsl"
#include "prim_buffer_push.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0) readonly buffer Vertices { float vertices[]; };
layout(set = 0, binding = 1) readonly buffer Indices { uint indices[]; };
layout(set = 0, binding = 2) writeonly buffer Prims { Triangle tris[]; };
layout(push_constant) uniform Push { PrimBufferPush pc; };

bool fetch(uint index, out vec4 world) {
    uint base = pc.vertex_offset + index * pc.vertex_stride;
    uint last = pc.vertex_format == 0u ? base + 2u : base + 1u;
    if (index >= pc.vertex_count || last >= uint(vertices.length())) {
        world = vec4(0.0, 0.0, 0.0, 1.0);
        return false;
    }
    vec3 p;
    if (pc.vertex_format == 0u) {
        p = vec3(vertices[base], vertices[base + 1u], vertices[base + 2u]);
    } else {
        // Four 16-bit components in two words, x and y in the first (x in its low half), z and w in the second.
        uint xy = floatBitsToUint(vertices[base]);
        uint zw = floatBitsToUint(vertices[base + 1u]);
        if (pc.vertex_format == 1u) {
            p = vec3(unpackHalf2x16(xy), unpackHalf2x16(zw).x);
        } else if (pc.vertex_format == 2u) {
            p = vec3(unpackSnorm2x16(xy), unpackSnorm2x16(zw).x);
        } else {
            p = vec3(unpackUnorm2x16(xy), unpackUnorm2x16(zw).x);
        }
    }
    world = vec4((pc.model * vec4(p, 1.0)).xyz, 1.0);
    return true;
}

void main() {
    uint prim = gl_GlobalInvocationID.x;
    uint slot = pc.prim_offset + prim;
    if (prim >= pc.triangle_count || slot >= uint(tris.length())) {
        return;
    }
    Triangle t;
    bool valid = true;
    for (uint k = 0u; k < 3u; ++k) {
        uint i = pc.first_index + prim * 3u + k;
        uint word = pc.index_16bit != 0u ? i / 2u : i;
        bool ok = word < uint(indices.length());
        vec4 w = vec4(0.0, 0.0, 0.0, 1.0);
        if (ok) {
            uint index = indices[word];
            if (pc.index_16bit != 0u) {
                index = (i & 1u) != 0u ? index >> 16u : index & 0xFFFFu;
            }
            int vertex = int(index) + pc.base_vertex;
            ok = vertex >= 0 && fetch(uint(vertex), w);
        }
        valid = valid && ok;
        t.v[k] = w;
    }
    if (!valid) {
        // Out-of-range indices give a zero-area triangle: never rasterized, never hit.
        t.v[1] = t.v[0];
        t.v[2] = t.v[0];
    }
    tris[slot] = t;
}

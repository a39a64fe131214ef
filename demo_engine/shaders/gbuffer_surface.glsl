// The G-buffer's surface: the exact geometric normal of the visible triangle, facing the camera, and the
// engine-style encodings of it the demo can store. Needs the includer's `pc` (GBufferPush).

// The triangle's unit normal `n` (gbuffer_scene.glsl's triangle_normal), turned to face the camera from
// the fragment at `rel_pos`.
vec3 facing_normal(vec3 n, vec3 rel_pos) {
    // Face the camera, decided geometrically (independent of winding and projection handedness).
    if (dot(n, -rel_pos) < 0.0) {
        n = -n;
    }
    return n;
}

vec2 octahedral_encode(vec3 n) {
    vec2 p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if (n.z >= 0.0) {
        return p;
    }
    return (1.0 - abs(p.yx)) * vec2(p.x >= 0.0 ? 1.0 : -1.0, p.y >= 0.0 ? 1.0 : -1.0);
}

// `n` (world space) as the engine's normal target stores it: pc.camera_pos.w holds the code, bit 0
// octahedral (else xyz), bit 1 unorm channels ([-1, 1] to [0, 1]), bit 2 view space (pc.view_rows).
vec4 encode_normal(vec3 n) {
    uint code = uint(pc.camera_pos.w);
    if ((code & 4u) != 0u) {
        n = vec3(dot(pc.view_rows[0].xyz, n), dot(pc.view_rows[1].xyz, n), dot(pc.view_rows[2].xyz, n));
    }
    vec4 e = (code & 1u) != 0u ? vec4(octahedral_encode(n), 0.0, 1.0) : vec4(n, 1.0);
    return (code & 2u) != 0u ? vec4(e.xyz * 0.5 + 0.5, 1.0) : e;
}

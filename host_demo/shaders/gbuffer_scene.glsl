// The scene's meshes as the demo keeps them (host_demo::scene_buffers): u32 indices, three per triangle,
// and tightly packed f32 world positions. Needs the includer's `pc` (GBufferPush).
layout(set = 0, binding = 0) readonly buffer Indices { uint indices[]; };
layout(set = 0, binding = 1) readonly buffer Positions { float positions[]; };

// Index `i`'s vertex relative to the frame origin: one f32 subtraction per coordinate, which rounds it
// exactly as the plugin's prim buffer does (its model matrix is the translation by minus the origin).
// Reads past either buffer give the origin (the upload validates the indices; this keeps reads in bounds).
vec3 frame_vertex(uint i) {
    uint v = i < uint(indices.length()) ? indices[i] : 0u;
    if (3u * v + 2u >= uint(positions.length())) {
        return vec3(0.0);
    }
    return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]) - pc.origin.xyz;
}

// The unit geometric normal of triangle `t` (zero for a degenerate one), wound as its vertices are.
vec3 triangle_normal(uint t) {
    vec3 a = frame_vertex(3u * t);
    vec3 c = cross(frame_vertex(3u * t + 1u) - a, frame_vertex(3u * t + 2u) - a);
    float len = length(c);
    return len > 0.0 ? c / len : vec3(0.0);
}

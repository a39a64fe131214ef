// The scene's meshes as the demo keeps them (demo_engine::scene_buffers): tightly packed f32 world positions
// (drawn through its u32 index buffer) and an f32 xyz unit normal per triangle. Needs the includer's `pc`
// (GBufferPush).
layout(set = 0, binding = 0) readonly buffer Positions { float positions[]; };
layout(set = 0, binding = 1) readonly buffer Normals { float normals[]; };

// Vertex `v` relative to the frame origin: one f32 subtraction per coordinate, which rounds it exactly
// as the plugin's prim buffer does (its model matrix is the translation by minus the origin). A vertex
// past the buffer gives the origin (the upload validates the indices; this keeps reads in bounds).
vec3 frame_vertex(uint v) {
    if (3u * v + 2u >= uint(positions.length())) {
        return vec3(0.0);
    }
    return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]) - pc.origin.xyz;
}

// The unit geometric normal of triangle `t` (zero for a degenerate one, or past the buffer).
vec3 triangle_normal(uint t) {
    if (3u * t + 2u >= uint(normals.length())) {
        return vec3(0.0);
    }
    return vec3(normals[3u * t], normals[3u * t + 1u], normals[3u * t + 2u]);
}

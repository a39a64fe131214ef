// Mirrors demo_engine::gbuffer::GBufferPush (144 bytes).
struct GBufferPush {
    mat4 view_proj_rel;     // proj * view with the camera at the origin
    vec4 camera_pos;        // xyz: camera in frame coordinates, w: the engine normal's code (gbuffer_surface.glsl)
    vec4 view_rows[3];      // the view rotation's rows (world to view, for view-space normals)
    vec4 origin;            // xyz: the frame origin in world coordinates (f32)
};

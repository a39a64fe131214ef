// Mirrors host_demo::gbuffer::GBufferPush (80 bytes).
struct GBufferPush {
    mat4 view_proj_rel;     // proj * view with the camera at the origin
    vec4 camera_pos;        // xyz: camera in frame coordinates
};

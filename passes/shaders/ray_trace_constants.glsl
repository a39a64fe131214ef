// Mirrors passes::gpu_types::RayTraceConstants (320 bytes). Positions are in frame coordinates
// (relative to the geometry's frame origin).
struct RayTraceConstants {
    mat4 inv_view_proj_rel;     // inverse(proj * view) with the camera at the origin
    mat4 light_view_proj;       // light view-projection in frame coordinates
    vec4 camera_pos;            // xyz: camera in frame coordinates
    vec4 light_dir;             // xyz: direction the light travels (unit); w: area shadows: tan(angular
                                // radius) of a directional light, a spot or point light's emitter radius
                                // (0: hard shadows)
    uvec4 dims;                 // screen width, height, primitive map N; w: the ray-tracing peers, 1 for a
                                // point light (its cube holds every direction), else 0
    vec4 offset;                // x: radians per pixel, y: offset in pixels, z: relative float bound of |P|,
                                // w: one step of a normalized depth format (0 for float depth)
    uvec4 misc;                 // x: 1 = front-only map, y: triangles in the prim buffer,
                                // z: ray trace: 1 = store the blocker distance; area trace: the bundle's
                                // walk budget per 64 open samples (passes::area::AreaConfig), w: area
                                // trace: light samples per pixel
    vec4 light_pos;             // spot light: xyz position in frame coordinates, w = 1; directional: w = 0
    mat4 view_to_world;         // the camera's rotation, view to world (for view-space normals)
    uvec4 surface_mode;         // the engine's normal: see engine_surface.glsl
    vec4 surface;               // x: the depth of background pixels, y: a view-Z image's relative precision,
                                // z: the normal image's precision (engine_surface.glsl)
                                // (0: the depth image holds the projection's depth)
};

//! Host mirrors of the structs shared with shaders. Each has a GLSL include of the same layout in
//! `shaders/`; the size assertions below keep the two sides from drifting.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec4, Vec4};

/// A world-space triangle in the prim buffer (`triangle.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuTriangle {
    /// Vertices, w = 1.
    pub v: [Vec4; 3],
}

/// Push constants of the prim-buffer build (`prim_buffer_push.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct PrimBufferPush {
    /// Object to world.
    pub model: Mat4,
    /// First index of the draw.
    pub first_index: u32,
    /// Triangles in the draw.
    pub triangle_count: u32,
    /// Draw-call offset into the prim buffer.
    pub prim_offset: u32,
    /// Vertex stride in floats.
    pub vertex_stride: u32,
    /// Offset of vertex 0 in floats.
    pub vertex_offset: u32,
    /// Addressable vertices.
    pub vertex_count: u32,
    /// Padding.
    pub pad: [u32; 2],
}

/// Push constants of the G-buffer (`gbuffer_push.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GBufferPush {
    /// proj * view with the camera at the origin.
    pub view_proj_rel: Mat4,
    /// Camera position in frame coordinates (xyz).
    pub camera_pos: Vec4,
}

/// Push constants of the primitive-map raster (`prim_map_push.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct PrimMapPush {
    /// Light view-projection in frame coordinates.
    pub light_view_proj: Mat4,
    /// Direction towards the light (xyz).
    pub to_light: Vec4,
    /// Map size N.
    pub size: u32,
    /// Map depth d.
    pub depth: u32,
    /// 1 = store only triangles facing the light.
    pub front_only: u32,
    /// Padding.
    pub pad: u32,
}

/// Constants of the ray trace (`ray_trace_constants.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct RayTraceConstants {
    /// inverse(proj * view) with the camera at the origin.
    pub inv_view_proj_rel: Mat4,
    /// Light view-projection in frame coordinates.
    pub light_view_proj: Mat4,
    /// Camera position in frame coordinates (xyz).
    pub camera_pos: Vec4,
    /// Direction the light travels (xyz, unit).
    pub light_dir: Vec4,
    /// Screen width, height, map N, d.
    pub dims: UVec4,
    /// x: radians per pixel, y: ray-origin offset in pixels, z: relative float bound of |P|.
    pub offset: Vec4,
    /// x: front-only map flag, y: triangles in the prim buffer.
    pub misc: UVec4,
}

/// Push constants of the occupancy view (`occupancy.comp`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct OccupancyPush {
    /// Map size N.
    pub size: u32,
    /// Map depth d.
    pub depth: u32,
}

/// Statistics written by the occupancy pass (`occupancy.comp`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct MapStats {
    /// Texels whose count exceeds d.
    pub overflowed_texels: u32,
    /// Largest count of any texel.
    pub max_count: u32,
    /// Texels with at least one triangle.
    pub occupied_texels: u32,
    /// Sum of min(count, d): stored indices.
    pub stored_entries: u32,
}

const _: () = {
    assert!(std::mem::size_of::<GpuTriangle>() == 48);
    assert!(std::mem::size_of::<PrimBufferPush>() == 96);
    assert!(std::mem::offset_of!(PrimBufferPush, first_index) == 64);
    assert!(std::mem::size_of::<GBufferPush>() == 80);
    assert!(std::mem::size_of::<PrimMapPush>() == 96);
    assert!(std::mem::offset_of!(PrimMapPush, size) == 80);
    assert!(std::mem::size_of::<RayTraceConstants>() == 208);
    assert!(std::mem::offset_of!(RayTraceConstants, dims) == 160);
    assert!(std::mem::offset_of!(RayTraceConstants, offset) == 176);
    assert!(std::mem::size_of::<OccupancyPush>() == 8);
    assert!(std::mem::size_of::<MapStats>() == 16);
};

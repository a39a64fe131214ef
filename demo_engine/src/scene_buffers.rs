//! The scene's meshes as the demo keeps them, as an engine keeps its own: world positions (f32 xyz), u32
//! indices and a flat normal per triangle in storage buffers, one draw per object. The G-buffer draws
//! them through the index buffer ([`crate::gbuffer::GBufferPass`]) and the plugin reads them where they
//! are ([`hrts::Context::set_geometry_vulkan`]).

use anyhow::{Context as _, Result};
use glam::{DVec3, Vec3};
use rhi::{Buffer, BufferUsage, Device};
use scene::Scene;

/// The scene's vertex, index and normal buffers, its draws and its frame origin.
pub struct SceneBuffers {
    vertices: Buffer,
    indices: Buffer,
    /// Per triangle: its unit geometric normal (f32 xyz; zero for a degenerate triangle).
    normals: Buffer,
    vertex_count: u32,
    index_count: u32,
    /// Per object, in order: its first index and index count.
    draws: Vec<(u32, u32)>,
    origin: Vec3,
}

impl SceneBuffers {
    /// Uploads `scene` (validated first: its objects cover its triangles in order, its positions are
    /// finite and its indices in range). The frame origin is the centre of its bounds in f32.
    pub fn upload(device: &Device, scene: &Scene) -> Result<Self> {
        scene.validate().context("the scene to upload")?;
        let positions: Vec<f32> = scene.positions.iter().flat_map(|p| p.to_array()).collect();
        let origin = scene.bounds().center();
        // From the vertices relative to the frame origin, as the G-buffer places them.
        let normals: Vec<f32> = scene
            .indices
            .chunks_exact(3)
            .flat_map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| scene.positions[i as usize] - origin);
                (b - a).cross(c - a).normalize_or_zero().to_array()
            })
            .collect();
        let usage = BufferUsage::STORAGE;
        Ok(Self {
            vertices: device.create_buffer_init(
                "scene vertices",
                bytemuck::cast_slice(&positions),
                usage,
            )?,
            indices: device.create_buffer_init(
                "scene indices",
                bytemuck::cast_slice(&scene.indices),
                usage | BufferUsage::INDEX,
            )?,
            normals: device.create_buffer_init(
                "scene triangle normals",
                bytemuck::cast_slice(&normals),
                usage,
            )?,
            vertex_count: u32::try_from(scene.positions.len()).context("too many vertices")?,
            index_count: u32::try_from(scene.indices.len()).context("too many indices")?,
            draws: scene
                .objects
                .iter()
                .map(|o| (o.first_triangle * 3, o.triangle_count * 3))
                .collect(),
            origin,
        })
    }

    /// The frame origin: the centre of the scene's bounds (f32, in world coordinates), which the G-buffer
    /// subtracts from every vertex as the plugin's prim buffer does.
    pub fn origin(&self) -> DVec3 {
        self.origin.as_dvec3()
    }

    /// Triangles of the scene (the G-buffer draws them all, in order).
    pub fn triangle_count(&self) -> u32 {
        self.index_count / 3
    }

    /// The vertex buffer: tightly packed f32 xyz.
    pub fn vertices(&self) -> &Buffer {
        &self.vertices
    }

    /// The index buffer: u32, three per triangle (index and storage usage).
    pub fn indices(&self) -> &Buffer {
        &self.indices
    }

    /// The triangles' unit normals: f32 xyz, one per triangle.
    pub fn normals(&self) -> &Buffer {
        &self.normals
    }

    /// The draws of the objects marked in `casters` (one flag per object), as the plugin takes them.
    pub fn caster_draws(&self, casters: &[bool]) -> Vec<hrts::Draw> {
        self.draws
            .iter()
            .zip(casters)
            .filter(|(_, &casts)| casts)
            .map(|(&(first_index, index_count), _)| hrts::Draw {
                first_index,
                index_count,
                transform: glam::Mat4::IDENTITY,
                base_vertex: 0,
            })
            .collect()
    }

    /// The scene as the plugin takes it: one mesh of these buffers with `draws`
    /// ([`SceneBuffers::caster_draws`]), bounded by `bounds` (which enclose them; the plugin's frame origin
    /// is their centre).
    pub fn plugin_mesh<'a>(
        &self,
        draws: &'a [hrts::Draw],
        bounds: hrts::Bounds,
    ) -> hrts::VulkanMesh<'a> {
        hrts::VulkanMesh {
            vertex_buffer: self.vertices.raw_handle(),
            vertex_buffer_size: self.vertices.size(),
            vertex_offset: 0,
            vertex_stride: 12,
            vertex_count: self.vertex_count,
            index_buffer: self.indices.raw_handle(),
            index_buffer_size: self.indices.size(),
            index_offset: 0,
            index_type: hrts::IndexType::Uint32,
            index_count: self.index_count,
            draws,
            bounds,
            vertex_format: 0,
            position_scale: Vec3::ZERO,
            position_offset: Vec3::ZERO,
        }
    }
}

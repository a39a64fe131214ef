//! Prim buffer build: triangles in frame coordinates (world minus the frame origin), mesh after mesh and
//! draw after draw, at `draw_call_offset + primitive_id`.
//!
//! Reads: each mesh's vertex buffer (or the one it reads this frame) and index buffer. Writes: prim
//! buffer.
//!
//! Files by job: `geometry` (meshes, layouts and draws), `shared` (the prim buffer shared by the lights
//! of a context: what a frame rebuilds).

mod geometry;
mod shared;

pub use geometry::{Draw, Geometry, IndexFormat, IndexLayout, Mesh, VertexFormat, VertexLayout};
pub(crate) use shared::PrimBufferClaim;
pub use shared::{MeshVertices, SharedGeometry, MAP_SCRATCH_SETS};

use crate::gpu_types::{GpuTriangle, PrimBufferPush};
use crate::shaders::shader;
use crate::PassError;
use glam::{DMat4, Mat4};
use rhi::{
    BindGroup, BindingKind, Buffer, BufferUsage, ComputePipeline, Device, Encoder, MemoryLocation,
    Resource,
};

/// What one draw's dispatch of a prim-buffer build reads.
struct DrawSource<'g> {
    /// The bind group of the vertex buffer it reads (with its mesh's index buffer and the prim buffer).
    group: &'g BindGroup,
    /// Where the positions are in that buffer.
    vertex: VertexLayout,
    /// Stored positions to world.
    model: Mat4,
}

/// The prim buffer and the compute pass that fills it.
pub struct PrimBufferPass {
    pipeline: ComputePipeline,
    /// One bind group per mesh: its vertex and index buffers and the prim buffer.
    groups: Vec<BindGroup>,
    prims: Buffer,
}

impl PrimBufferPass {
    /// Creates the prim buffer for `geometry`.
    pub fn new(device: &Device, geometry: &Geometry) -> Result<Self, PassError> {
        let bytes =
            u64::from(geometry.triangle_count()) * std::mem::size_of::<GpuTriangle>() as u64;
        let prims = device.create_buffer(
            "prim buffer",
            bytes,
            BufferUsage::STORAGE
                | BufferUsage::COPY_SRC
                | device.acceleration_structure_input_usage(),
            MemoryLocation::GpuOnly,
        )?;
        let pipeline = device.create_compute_pipeline(
            "prim buffer build",
            &shader("prim_buffer.comp")?,
            &[BindingKind::StorageBuffer; 3],
            std::mem::size_of::<PrimBufferPush>() as u32,
        )?;
        let mut pass = Self {
            pipeline,
            groups: Vec::with_capacity(geometry.meshes().len()),
            prims,
        };
        for mesh in geometry.meshes() {
            let group = pass.bind(device, mesh, &mesh.vertices)?;
            pass.groups.push(group);
        }
        Ok(pass)
    }

    /// A bind group reading `mesh`'s indices and the positions in `vertices` (the mesh's own, or a vertex
    /// buffer it reads in some frames), writing the prim buffer.
    fn bind(
        &self,
        device: &Device,
        mesh: &Mesh,
        vertices: &Buffer,
    ) -> Result<BindGroup, PassError> {
        Ok(device.create_bind_group(
            self.pipeline.layout(),
            &[
                Resource::Buffer(vertices),
                Resource::Buffer(&mesh.indices),
                Resource::Buffer(&self.prims),
            ],
        )?)
    }

    /// The prim buffer (`GpuTriangle` per slot).
    pub fn prims(&self) -> &Buffer {
        &self.prims
    }

    /// Records one dispatch per draw, each with its object-to-world transform in `models` (one per draw
    /// over all meshes, in order; the draws' own when `None`).
    pub fn record(
        &self,
        enc: &mut Encoder<'_>,
        geometry: &Geometry,
        models: Option<&[Mat4]>,
    ) -> Result<(), PassError> {
        if models.is_some_and(|m| m.len() != geometry.draw_count()) {
            return Err(PassError::InvalidGeometry(format!(
                "{} transforms for {} draws",
                models.map_or(0, <[Mat4]>::len),
                geometry.draw_count()
            )));
        }
        self.record_draws(enc, geometry, |mesh, draw, d| {
            Some(DrawSource {
                group: &self.groups[mesh],
                vertex: geometry.meshes()[mesh].vertex,
                model: models.map_or(d.model, |m| m[draw]),
            })
        })?;
        Ok(())
    }

    /// Records one dispatch for each draw `source` gives a source (called with the draw's mesh, its index
    /// over all meshes and the draw, for every draw in prim-buffer order); the slots of the others keep
    /// what they hold. Returns the triangles written.
    fn record_draws<'g>(
        &self,
        enc: &mut Encoder<'_>,
        geometry: &Geometry,
        mut source: impl FnMut(usize, usize, &Draw) -> Option<DrawSource<'g>>,
    ) -> Result<u32, PassError> {
        if self.groups.len() != geometry.meshes().len() {
            return Err(PassError::InvalidGeometry(format!(
                "the prim buffer was created for {} meshes, the geometry has {}",
                self.groups.len(),
                geometry.meshes().len()
            )));
        }
        enc.begin_pass("prim buffer");
        let (mut offset, mut written) = (0u32, 0u32);
        for (i, (mesh, d)) in geometry.draws().enumerate() {
            let count = d.index_count / 3;
            let from = source(mesh, i, d);
            if let Some(from) = from.filter(|_| count > 0) {
                let index = geometry.meshes()[mesh].index;
                let model =
                    (DMat4::from_translation(-geometry.origin()) * from.model.as_dmat4()).as_mat4();
                let push = PrimBufferPush {
                    model,
                    first_index: index.element_offset() + d.first_index,
                    triangle_count: count,
                    prim_offset: offset,
                    vertex_stride: from.vertex.stride / 4,
                    vertex_offset: from.vertex.word_offset(),
                    vertex_count: from.vertex.count,
                    index_16bit: u32::from(index.format == IndexFormat::U16),
                    base_vertex: d.base_vertex,
                    vertex_format: from.vertex.format.code(),
                    pad: [0; 3],
                };
                enc.dispatch(
                    &self.pipeline,
                    from.group,
                    bytemuck::bytes_of(&push),
                    [count.div_ceil(64), 1, 1],
                )?;
                written += count;
            }
            offset += count;
        }
        enc.end_pass();
        Ok(written)
    }
}

//! Prim buffer build: triangles in frame coordinates (world minus the frame origin) at
//! `draw_call_offset + primitive_id`.
//!
//! Reads: vertex buffer, index buffer. Writes: prim buffer.

use crate::gpu_types::{GpuTriangle, PrimBufferPush};
use crate::{shader, PassError};
use glam::{DMat4, DVec3, Mat4};
use rhi::{
    BindGroup, BindingKind, Buffer, BufferUsage, ComputePipeline, Device, Encoder, MemoryLocation,
    Resource,
};

/// One draw call of the engine's geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Draw {
    /// First index in the index buffer.
    pub first_index: u32,
    /// Number of indices (a multiple of 3).
    pub index_count: u32,
    /// Object-to-world transform.
    pub model: Mat4,
}

/// Triangle geometry on the GPU: packed float3 positions, u32 indices, draws.
pub struct Geometry {
    vertices: Buffer,
    indices: Buffer,
    vertex_count: u32,
    draws: Vec<Draw>,
    triangle_count: u32,
    origin: DVec3,
}

impl Geometry {
    /// Uploads positions (xyz packed) and a triangle-list index buffer, validating every draw.
    ///
    /// `origin` is the frame origin, a world point near the geometry: the prim buffer and every pass work
    /// in coordinates relative to it (transforms are rebased in f64), so precision does not depend on
    /// where the scene sits in the world.
    pub fn upload(
        device: &Device,
        positions: &[f32],
        indices: &[u32],
        draws: &[Draw],
        origin: DVec3,
    ) -> Result<Self, PassError> {
        if !origin.is_finite() {
            return Err(PassError::InvalidGeometry(
                "the frame origin is not finite".into(),
            ));
        }
        if positions.is_empty() || !positions.len().is_multiple_of(3) {
            return Err(PassError::InvalidGeometry(
                "positions must be a non-empty list of xyz triples".into(),
            ));
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(PassError::InvalidGeometry(format!(
                "vertex {} has a non-finite coordinate",
                i / 3
            )));
        }
        let vertex_count = u32::try_from(positions.len() / 3)
            .map_err(|_| PassError::InvalidGeometry("too many vertices".into()))?;
        if let Some(&i) = indices.iter().find(|&&i| i >= vertex_count) {
            return Err(PassError::InvalidGeometry(format!(
                "index {i} is out of range ({vertex_count} vertices)"
            )));
        }
        let mut triangle_count = 0u32;
        for (n, d) in draws.iter().enumerate() {
            let end = u64::from(d.first_index) + u64::from(d.index_count);
            if !d.index_count.is_multiple_of(3) || end > indices.len() as u64 {
                return Err(PassError::InvalidGeometry(format!(
                    "draw {n} does not cover whole triangles of the index buffer"
                )));
            }
            if !d.model.is_finite() {
                return Err(PassError::InvalidGeometry(format!(
                    "draw {n} has a non-finite transform"
                )));
            }
            triangle_count = triangle_count
                .checked_add(d.index_count / 3)
                .ok_or_else(|| PassError::InvalidGeometry("too many triangles".into()))?;
        }
        if triangle_count == 0 {
            return Err(PassError::InvalidGeometry("no triangles".into()));
        }
        let usage = BufferUsage::STORAGE;
        Ok(Self {
            vertices: device.create_buffer_init(
                "vertices",
                bytemuck::cast_slice(positions),
                usage,
            )?,
            indices: device.create_buffer_init("indices", bytemuck::cast_slice(indices), usage)?,
            vertex_count,
            draws: draws.to_vec(),
            triangle_count,
            origin,
        })
    }

    /// The frame origin (world coordinates).
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// Total triangles over all draws (= prim buffer length).
    pub fn triangle_count(&self) -> u32 {
        self.triangle_count
    }
}

/// The prim buffer and the compute pass that fills it.
pub struct PrimBufferPass {
    pipeline: ComputePipeline,
    group: BindGroup,
    prims: Buffer,
}

impl PrimBufferPass {
    /// Creates the prim buffer for `geometry`.
    pub fn new(device: &Device, geometry: &Geometry) -> Result<Self, PassError> {
        let bytes = u64::from(geometry.triangle_count) * std::mem::size_of::<GpuTriangle>() as u64;
        let prims = device.create_buffer(
            "prim buffer",
            bytes,
            BufferUsage::STORAGE | BufferUsage::COPY_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let pipeline = device.create_compute_pipeline(
            "prim buffer build",
            &shader("prim_buffer.comp")?,
            &[BindingKind::StorageBuffer; 3],
            std::mem::size_of::<PrimBufferPush>() as u32,
        )?;
        let group = device.create_bind_group(
            pipeline.layout(),
            &[
                Resource::Buffer(&geometry.vertices),
                Resource::Buffer(&geometry.indices),
                Resource::Buffer(&prims),
            ],
        )?;
        Ok(Self {
            pipeline,
            group,
            prims,
        })
    }

    /// The prim buffer (`GpuTriangle` per slot).
    pub fn prims(&self) -> &Buffer {
        &self.prims
    }

    /// Records one dispatch per draw.
    pub fn record(&self, enc: &mut Encoder<'_>, geometry: &Geometry) -> Result<(), PassError> {
        enc.begin_pass("prim buffer");
        let mut offset = 0u32;
        for d in &geometry.draws {
            let count = d.index_count / 3;
            if count == 0 {
                continue;
            }
            let model = (DMat4::from_translation(-geometry.origin) * d.model.as_dmat4()).as_mat4();
            let push = PrimBufferPush {
                model,
                first_index: d.first_index,
                triangle_count: count,
                prim_offset: offset,
                vertex_stride: 3,
                vertex_offset: 0,
                vertex_count: geometry.vertex_count,
                pad: [0; 2],
            };
            enc.dispatch(
                &self.pipeline,
                &self.group,
                bytemuck::bytes_of(&push),
                [count.div_ceil(64), 1, 1],
            )?;
            offset += count;
        }
        enc.end_pass();
        Ok(())
    }
}

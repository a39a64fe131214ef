//! Prim buffer build: triangles in frame coordinates (world minus the frame origin) at
//! `draw_call_offset + primitive_id`.
//!
//! Reads: vertex buffer, index buffer. Writes: prim buffer.

use crate::gpu_types::{GpuTriangle, PrimBufferPush};
use crate::primitive_map::MapScratchPool;
use crate::{shader, PassError};
use glam::{DMat4, DVec3, Mat4};
use rhi::{
    BindGroup, BindingKind, Buffer, BufferUsage, ComputePipeline, Device, Encoder, MemoryLocation,
    Resource,
};
use std::sync::{Arc, Mutex};

/// One draw call of the engine's geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Draw {
    /// First index in the index buffer.
    pub first_index: u32,
    /// Number of indices (a multiple of 3).
    pub index_count: u32,
    /// Object-to-world transform.
    pub model: Mat4,
    /// Added to every index of the draw before it addresses a vertex (may be negative): a mesh stored at
    /// vertex `base_vertex` of a shared vertex buffer.
    pub base_vertex: i32,
}

/// Index element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IndexFormat {
    /// 16-bit indices.
    U16,
    /// 32-bit indices.
    U32,
}

impl IndexFormat {
    fn bytes(self) -> u64 {
        match self {
            Self::U16 => 2,
            Self::U32 => 4,
        }
    }
}

/// Where positions are in a vertex buffer: `R32G32B32_SFLOAT` at `offset + i * stride` bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VertexLayout {
    /// Byte offset of vertex 0 (multiple of 4).
    pub offset: u64,
    /// Byte stride (multiple of 4, at least the position's size).
    pub stride: u32,
    /// Number of vertices.
    pub count: u32,
    /// How a position is stored.
    pub format: VertexFormat,
}

/// How a vertex position is stored. Normalized formats give values in [-1, 1] (snorm) or [0, 1] (unorm),
/// which the draw's transform maps to the object's coordinates (a dequantization scale and offset folded
/// into it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VertexFormat {
    /// Three 32-bit floats.
    Float3,
    /// Four 16-bit floats (w ignored).
    Half4,
    /// Four 16-bit signed normalized integers (w ignored).
    Snorm16x4,
    /// Four 16-bit unsigned normalized integers (w ignored).
    Unorm16x4,
}

impl VertexFormat {
    /// Bytes a position takes.
    pub fn bytes(self) -> u32 {
        match self {
            Self::Float3 => 12,
            Self::Half4 | Self::Snorm16x4 | Self::Unorm16x4 => 8,
        }
    }

    /// The shader's code for the format (`prim_buffer.comp`).
    fn code(self) -> u32 {
        match self {
            Self::Float3 => 0,
            Self::Half4 => 1,
            Self::Snorm16x4 => 2,
            Self::Unorm16x4 => 3,
        }
    }
}

/// Where indices are in an index buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IndexLayout {
    /// Byte offset of index 0 (multiple of the index size; for 16-bit indices a multiple of 4).
    pub offset: u64,
    /// Element type.
    pub format: IndexFormat,
    /// Number of indices.
    pub count: u32,
}

/// Triangle geometry on the GPU: vertex and index buffers (the plugin's own or the engine's), draws,
/// and the frame origin.
pub struct Geometry {
    vertices: Buffer,
    indices: Buffer,
    vertex: VertexLayout,
    index: IndexLayout,
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
        let count = u32::try_from(positions.len() / 3)
            .map_err(|_| PassError::InvalidGeometry("too many vertices".into()))?;
        for d in draws {
            let used = indices
                .iter()
                .skip(d.first_index as usize)
                .take(d.index_count as usize);
            if let Some(&i) = used.into_iter().find(|&&i| {
                !(0..i64::from(count)).contains(&(i64::from(i) + i64::from(d.base_vertex)))
            }) {
                return Err(PassError::InvalidGeometry(format!(
                    "index {i} plus base vertex {} is out of range ({count} vertices)",
                    d.base_vertex
                )));
            }
        }
        let index_count = u32::try_from(indices.len())
            .map_err(|_| PassError::InvalidGeometry("too many indices".into()))?;
        if index_count == 0 {
            return Err(PassError::InvalidGeometry("no indices".into()));
        }
        let usage = BufferUsage::STORAGE;
        Self::from_buffers(
            device.create_buffer_init("vertices", bytemuck::cast_slice(positions), usage)?,
            VertexLayout {
                offset: 0,
                stride: 12,
                count,
                format: VertexFormat::Float3,
            },
            device.create_buffer_init("indices", bytemuck::cast_slice(indices), usage)?,
            IndexLayout {
                offset: 0,
                format: IndexFormat::U32,
                count: index_count,
            },
            draws,
            origin,
        )
    }

    /// Geometry in existing buffers (e.g. the engine's, wrapped with `Device::external_buffer`; they need
    /// storage-buffer usage). Layouts and draws are validated against the buffer sizes; an index that is
    /// out of range at run time makes its triangle degenerate (never rasterized, never hit).
    pub fn from_buffers(
        vertices: Buffer,
        vertex: VertexLayout,
        indices: Buffer,
        index: IndexLayout,
        draws: &[Draw],
        origin: DVec3,
    ) -> Result<Self, PassError> {
        let bad = |m: String| Err(PassError::InvalidGeometry(m));
        if !origin.is_finite() {
            return bad("the frame origin is not finite".into());
        }
        let position_bytes = vertex.format.bytes();
        if vertex.stride < position_bytes
            || !vertex.stride.is_multiple_of(4)
            || !vertex.offset.is_multiple_of(4)
            || vertex.count == 0
        {
            return bad(format!("vertex layout {vertex:?}: stride must be a multiple of 4 and >= {position_bytes}, offset a multiple of 4, count > 0"));
        }
        // Checked: an offset near u64::MAX must not wrap past the bounds check.
        let vertex_end = u64::from(vertex.count - 1)
            .checked_mul(u64::from(vertex.stride))
            .and_then(|b| b.checked_add(vertex.offset))
            .and_then(|b| b.checked_add(u64::from(position_bytes)));
        if vertex_end.is_none_or(|end| end > vertices.size()) {
            return bad(format!(
                "{} vertices of stride {} at offset {} do not fit the vertex buffer of {} bytes",
                vertex.count,
                vertex.stride,
                vertex.offset,
                vertices.size()
            ));
        }
        let word_aligned = index.offset.is_multiple_of(4);
        if !word_aligned || index.count == 0 {
            return bad(format!(
                "index layout {index:?}: offset must be a multiple of 4, count > 0"
            ));
        }
        let index_end = (u64::from(index.count) * index.format.bytes()).checked_add(index.offset);
        if index_end.is_none_or(|end| end > indices.size()) {
            return bad(format!(
                "{} indices at offset {} do not fit the index buffer of {} bytes",
                index.count,
                index.offset,
                indices.size()
            ));
        }
        // The shaders address both buffers in 32-bit words and elements.
        if u32::try_from(vertex.offset / 4).is_err()
            || u32::try_from(index.offset / index.format.bytes()).is_err()
        {
            return bad(format!(
                "vertex offset {} or index offset {} is beyond what the shaders address (2^32 words or indices)",
                vertex.offset, index.offset
            ));
        }
        let mut triangle_count = 0u32;
        for (n, d) in draws.iter().enumerate() {
            let end = u64::from(d.first_index) + u64::from(d.index_count);
            if !d.index_count.is_multiple_of(3) || end > u64::from(index.count) {
                return bad(format!(
                    "draw {n} does not cover whole triangles of the index buffer"
                ));
            }
            if !d.model.is_finite() {
                return bad(format!("draw {n} has a non-finite transform"));
            }
            triangle_count = triangle_count
                .checked_add(d.index_count / 3)
                .ok_or_else(|| PassError::InvalidGeometry("too many triangles".into()))?;
        }
        if triangle_count == 0 {
            return bad("no triangles".into());
        }
        Ok(Self {
            vertices,
            indices,
            vertex,
            index,
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

    /// The vertex buffer and its layout.
    pub fn vertices(&self) -> (&Buffer, VertexLayout) {
        (&self.vertices, self.vertex)
    }

    /// The index buffer and its layout.
    pub fn indices(&self) -> (&Buffer, IndexLayout) {
        (&self.indices, self.index)
    }

    /// The draws.
    pub fn draws(&self) -> &[Draw] {
        &self.draws
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

    /// Records one dispatch per draw, each with its object-to-world transform in `models` (one per draw;
    /// the draws' own when `None`).
    pub fn record(
        &self,
        enc: &mut Encoder<'_>,
        geometry: &Geometry,
        models: Option<&[Mat4]>,
    ) -> Result<(), PassError> {
        if models.is_some_and(|m| m.len() != geometry.draws.len()) {
            return Err(PassError::InvalidGeometry(format!(
                "{} transforms for {} draws",
                models.map_or(0, <[Mat4]>::len),
                geometry.draws.len()
            )));
        }
        enc.begin_pass("prim buffer");
        let mut offset = 0u32;
        for (i, d) in geometry.draws.iter().enumerate() {
            let count = d.index_count / 3;
            if count == 0 {
                continue;
            }
            let model = models.map_or(d.model, |m| m[i]);
            let model = (DMat4::from_translation(-geometry.origin) * model.as_dmat4()).as_mat4();
            let push = PrimBufferPush {
                model,
                first_index: (geometry.index.offset / geometry.index.format.bytes()) as u32
                    + d.first_index,
                triangle_count: count,
                prim_offset: offset,
                vertex_stride: geometry.vertex.stride / 4,
                vertex_offset: (geometry.vertex.offset / 4) as u32,
                vertex_count: geometry.vertex.count,
                index_16bit: u32::from(geometry.index.format == IndexFormat::U16),
                base_vertex: d.base_vertex,
                vertex_format: geometry.vertex.format.code(),
                pad: [0; 3],
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

/// Who records the shared prim buffer in a frame (see [`SharedGeometry`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PrimBufferClaim {
    /// The caller records the build this frame.
    Record,
    /// Another light's pipeline records it this frame, before the caller's passes.
    RebuiltByAnother,
    /// It is up to date (static geometry, built by an earlier frame).
    UpToDate,
}

/// The scene's geometry and its prim buffer, shared by the pipelines of several lights (one context): in
/// each frame the first light that needs the prim buffer records its build and the others read it.
pub struct SharedGeometry {
    geometry: Geometry,
    pass: PrimBufferPass,
    state: Mutex<PrimBufferState>,
    map_scratch: MapScratchPool,
}

#[derive(Debug, Clone)]
struct PrimBufferState {
    dynamic: bool,
    built: bool,
    claimed: Option<u64>,
    /// The draws' transforms when set after creation ([`SharedGeometry::set_transforms`]).
    models: Option<Vec<Mat4>>,
}

impl SharedGeometry {
    /// Creates the prim buffer of `geometry`. `dynamic`: the vertex or index buffers change between frames,
    /// so the prim buffer is rebuilt every frame (else once).
    pub fn new(device: &Device, geometry: Geometry, dynamic: bool) -> Result<Arc<Self>, PassError> {
        let pass = PrimBufferPass::new(device, &geometry)?;
        Ok(Arc::new(Self {
            geometry,
            pass,
            state: Mutex::new(PrimBufferState {
                dynamic,
                built: false,
                claimed: None,
                models: None,
            }),
            map_scratch: MapScratchPool::default(),
        }))
    }

    /// The geometry.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The prim buffer (triangles in frame coordinates).
    pub fn prims(&self) -> &Buffer {
        self.pass.prims()
    }

    /// The build scratch the primitive maps over this geometry share (one light's map is built at a time).
    pub fn map_scratch(&self) -> &MapScratchPool {
        &self.map_scratch
    }

    /// Whether the prim buffer is rebuilt every frame.
    pub fn is_dynamic(&self) -> bool {
        self.lock().dynamic
    }

    /// Makes the geometry dynamic (rebuilt every frame) or static (kept once built).
    pub fn set_dynamic(&self, dynamic: bool) {
        self.lock().dynamic = dynamic;
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, PrimBufferState> {
        self.state
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Decides, for a pipeline beginning `frame`, who records the prim buffer this frame.
    pub(crate) fn claim(&self, frame: u64) -> PrimBufferClaim {
        let mut s = self.lock();
        if s.claimed == Some(frame) {
            PrimBufferClaim::RebuiltByAnother
        } else if !s.built || s.dynamic {
            s.claimed = Some(frame);
            PrimBufferClaim::Record
        } else {
            PrimBufferClaim::UpToDate
        }
    }

    /// Records the build of the prim buffer (by the pipeline whose claim was [`PrimBufferClaim::Record`]).
    pub(crate) fn record(&self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        let models = self.lock().models.clone();
        self.pass.record(enc, &self.geometry, models.as_deref())?;
        self.lock().built = true;
        Ok(())
    }

    /// Moves the draws: `models` holds one object-to-world transform per draw. The next frame rebuilds the
    /// prim buffer (once, for every light) and everything that depends on it; frames already recorded keep
    /// the transforms they were recorded with.
    pub fn set_transforms(&self, models: &[Mat4]) -> Result<(), PassError> {
        if models.len() != self.geometry.draws.len() {
            return Err(PassError::InvalidGeometry(format!(
                "{} transforms for {} draws",
                models.len(),
                self.geometry.draws.len()
            )));
        }
        if let Some(i) = models.iter().position(|m| !m.is_finite()) {
            return Err(PassError::InvalidGeometry(format!(
                "transform {i} is not finite"
            )));
        }
        let mut s = self.lock();
        s.models = Some(models.to_vec());
        s.built = false;
        Ok(())
    }

    /// Whether the prim buffer was built (or its build recorded) by some frame.
    pub(crate) fn is_built(&self) -> bool {
        self.lock().built
    }
}

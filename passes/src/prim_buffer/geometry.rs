//! The geometry the prim buffer is built from: meshes, each with a vertex and an index buffer of its own
//! (their layouts and formats may differ from mesh to mesh) and the draws reading them, and the frame
//! origin.

use crate::PassError;
use glam::{DVec3, Mat4};
use rhi::{Buffer, BufferUsage, Device};

/// One draw call of a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Draw {
    /// First index in the mesh's index buffer.
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
    pub(super) fn bytes(self) -> u64 {
        match self {
            Self::U16 => 2,
            Self::U32 => 4,
        }
    }
}

/// Where positions are in a vertex buffer: `format` at `offset + i * stride` bytes.
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

impl VertexLayout {
    /// Checks the layout against a vertex buffer of `buffer_size` bytes: stride and offset multiples of 4,
    /// the stride at least a position's size, at least one vertex, every position inside the buffer, and
    /// vertex 0 within the 2^32 words the shader addresses.
    pub fn check(&self, buffer_size: u64) -> Result<(), PassError> {
        let bad = |m: String| Err(PassError::InvalidGeometry(m));
        let position_bytes = self.format.bytes();
        if self.stride < position_bytes
            || !self.stride.is_multiple_of(4)
            || !self.offset.is_multiple_of(4)
            || self.count == 0
        {
            return bad(format!("vertex layout {self:?}: stride must be a multiple of 4 and >= {position_bytes}, offset a multiple of 4, count > 0"));
        }
        // Checked: an offset near u64::MAX must not wrap past the bounds check.
        let end = u64::from(self.count - 1)
            .checked_mul(u64::from(self.stride))
            .and_then(|b| b.checked_add(self.offset))
            .and_then(|b| b.checked_add(u64::from(position_bytes)));
        if end.is_none_or(|end| end > buffer_size) {
            return bad(format!(
                "{} vertices of stride {} at offset {} do not fit the vertex buffer of {buffer_size} bytes",
                self.count, self.stride, self.offset
            ));
        }
        if u32::try_from(self.offset / 4).is_err() {
            return bad(format!(
                "vertex offset {} is beyond what the shaders address (2^32 words)",
                self.offset
            ));
        }
        Ok(())
    }

    /// Vertex 0's offset in 32-bit words (within `u32` once [`VertexLayout::check`]ed).
    pub(super) fn word_offset(&self) -> u32 {
        (self.offset / 4) as u32
    }
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
    pub(super) fn code(self) -> u32 {
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

impl IndexLayout {
    /// Index 0's position in elements of the index format (within `u32` once checked by
    /// [`Mesh::from_buffers`]).
    pub(super) fn element_offset(&self) -> u32 {
        (self.offset / self.format.bytes()) as u32
    }
}

/// One mesh: a vertex and an index buffer of its own (the plugin's or the engine's), their layouts, and
/// the draws that read them.
pub struct Mesh {
    pub(super) vertices: Buffer,
    pub(super) indices: Buffer,
    pub(super) vertex: VertexLayout,
    pub(super) index: IndexLayout,
    draws: Vec<Draw>,
    triangle_count: u32,
}

impl Mesh {
    /// Uploads positions (xyz packed) and a triangle-list index buffer, validating every draw.
    pub fn upload(
        device: &Device,
        positions: &[f32],
        indices: &[u32],
        draws: &[Draw],
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
        )
    }

    /// A mesh in existing buffers (e.g. the engine's, wrapped with `Device::external_buffer`; they need
    /// storage-buffer usage). Layouts and draws are validated against the buffer sizes; an index that is
    /// out of range at run time makes its triangle degenerate (never rasterized, never hit).
    pub fn from_buffers(
        vertices: Buffer,
        vertex: VertexLayout,
        indices: Buffer,
        index: IndexLayout,
        draws: &[Draw],
    ) -> Result<Self, PassError> {
        let bad = |m: String| Err(PassError::InvalidGeometry(m));
        vertex.check(vertices.size())?;
        if !index.offset.is_multiple_of(4) || index.count == 0 {
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
        // The shader addresses the index buffer in elements.
        if u32::try_from(index.offset / index.format.bytes()).is_err() {
            return bad(format!(
                "index offset {} is beyond what the shaders address (2^32 indices)",
                index.offset
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
        })
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

    /// Triangles over the mesh's draws.
    pub fn triangle_count(&self) -> u32 {
        self.triangle_count
    }
}

/// Triangle geometry on the GPU: meshes (vertex and index buffers, the plugin's own or the engine's, and
/// their draws) and the frame origin. The prim buffer holds the triangles mesh after mesh, draw after
/// draw.
pub struct Geometry {
    meshes: Vec<Mesh>,
    triangle_count: u32,
    origin: DVec3,
}

impl Geometry {
    /// Geometry of `meshes` (at least one).
    ///
    /// `origin` is the frame origin, a world point near the geometry: the prim buffer and every pass work
    /// in coordinates relative to it (transforms are rebased in f64), so precision does not depend on
    /// where the scene sits in the world.
    pub fn new(meshes: Vec<Mesh>, origin: DVec3) -> Result<Self, PassError> {
        if !origin.is_finite() {
            return Err(PassError::InvalidGeometry(
                "the frame origin is not finite".into(),
            ));
        }
        if meshes.is_empty() {
            return Err(PassError::InvalidGeometry("no meshes".into()));
        }
        let triangle_count = meshes
            .iter()
            .try_fold(0u32, |sum, m| sum.checked_add(m.triangle_count))
            .ok_or_else(|| PassError::InvalidGeometry("too many triangles".into()))?;
        Ok(Self {
            meshes,
            triangle_count,
            origin,
        })
    }

    /// One mesh uploaded from positions (xyz packed) and a triangle-list index buffer
    /// ([`Mesh::upload`]), with the frame origin `origin` ([`Geometry::new`]).
    pub fn upload(
        device: &Device,
        positions: &[f32],
        indices: &[u32],
        draws: &[Draw],
        origin: DVec3,
    ) -> Result<Self, PassError> {
        Self::new(
            vec![Mesh::upload(device, positions, indices, draws)?],
            origin,
        )
    }

    /// The frame origin (world coordinates).
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// Total triangles over all meshes (= prim buffer length).
    pub fn triangle_count(&self) -> u32 {
        self.triangle_count
    }

    /// The meshes, in prim-buffer order.
    pub fn meshes(&self) -> &[Mesh] {
        &self.meshes
    }

    /// Every draw, mesh after mesh, with the index of its mesh.
    pub fn draws(&self) -> impl Iterator<Item = (usize, &Draw)> {
        self.meshes
            .iter()
            .enumerate()
            .flat_map(|(i, m)| m.draws.iter().map(move |d| (i, d)))
    }

    /// Number of draws over all meshes.
    pub fn draw_count(&self) -> usize {
        self.meshes.iter().map(|m| m.draws.len()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(offset: u64, stride: u32, count: u32, format: VertexFormat) -> VertexLayout {
        VertexLayout {
            offset,
            stride,
            count,
            format,
        }
    }

    #[test]
    fn vertex_layouts_are_checked_against_the_buffer() {
        // 4 float3 vertices of stride 16 after 64 bytes end at 64 + 3 * 16 + 12 = 124 bytes.
        let l = layout(64, 16, 4, VertexFormat::Float3);
        assert!(l.check(124).is_ok());
        assert!(l.check(123).is_err());
        // 16-bit positions take 8 bytes.
        assert!(layout(0, 8, 2, VertexFormat::Snorm16x4).check(16).is_ok());
        assert!(layout(0, 8, 2, VertexFormat::Float3).check(64).is_err());
        // Misaligned offset or stride, no vertices.
        assert!(layout(2, 16, 4, VertexFormat::Float3).check(1024).is_err());
        assert!(layout(0, 14, 4, VertexFormat::Float3).check(1024).is_err());
        assert!(layout(0, 16, 0, VertexFormat::Float3).check(1024).is_err());
        // An end that wraps past 2^64 fails, not passes.
        assert!(layout(u64::MAX - 3, 16, 1, VertexFormat::Float3)
            .check(u64::MAX)
            .is_err());
        // Beyond the shader's 2^32 words.
        assert!(layout(1 << 34, 16, 1, VertexFormat::Float3)
            .check(u64::MAX)
            .is_err());
    }
}

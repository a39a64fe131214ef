//! Geometry intake: the engine's CPU arrays or Vulkan buffers, checked and kept to rebuild the passes.

use crate::convert::{bounds, enum_value, finite, mat4};
use crate::error::{check_aligned, invalid, ApiError, ApiResult};
use crate::types::*;
use crate::version::read_elements;
use glam::{DVec3, Vec3};
use passes::{Draw, Geometry, IndexFormat, IndexLayout, Mesh, VertexFormat, VertexLayout};
use rhi::{BufferUsage, Device, Format};

/// The frame origin of geometry within `lo..hi`: the centre, rounded to f32. Then the frame coordinates
/// of f32 world positions near it (vertex minus origin) are differences of numbers on the same f32 grid,
/// and computing them loses nothing.
fn frame_origin(lo: DVec3, hi: DVec3) -> DVec3 {
    ((lo + hi) * 0.5).as_vec3().as_dvec3()
}

/// Geometry as the engine described it, kept to rebuild the passes after a configuration change.
pub(crate) enum GeometrySource {
    Cpu {
        positions: Vec<f32>,
        indices: Vec<u32>,
        draws: Vec<Draw>,
        origin: DVec3,
        bounds: [DVec3; 2],
    },
    Vulkan {
        meshes: Vec<VulkanMesh>,
        origin: DVec3,
        /// The union of the meshes' bounds.
        bounds: [DVec3; 2],
        /// Whether `bounds` still hold (not after the draws were moved).
        bounds_hold: bool,
    },
}

/// The draws moved to new transforms, checked by [`GeometrySource::moved`].
pub(crate) struct MovedDraws {
    /// Each draw's object-to-world transform, over all meshes in order.
    models: Vec<glam::Mat4>,
    /// Each draw's transform from stored positions to world.
    pub(crate) stored_to_world: Vec<glam::Mat4>,
    /// The new bounds of CPU geometry.
    cpu_bounds: Option<[DVec3; 2]>,
}

/// One mesh in the engine's buffers.
pub(crate) struct VulkanMesh {
    vertices: (u64, u64),
    vertex: VertexLayout,
    indices: (u64, u64),
    index: IndexLayout,
    draws: Vec<Draw>,
    /// Stored position to object space (`position_scale`, `position_offset`), applied before each
    /// draw's transform.
    dequantize: glam::Mat4,
}

impl GeometrySource {
    /// What moving the draws to `models` (one object-to-world transform each, over all meshes in order)
    /// gives, checked and changing nothing yet: each draw's transform from stored positions to world
    /// (finite: a Vulkan mesh's dequantization is applied to it), and CPU geometry's new bounds.
    pub(crate) fn moved(&self, models: &[glam::Mat4]) -> ApiResult<MovedDraws> {
        let draws = match self {
            Self::Cpu { draws, .. } => draws.len(),
            Self::Vulkan { meshes, .. } => meshes.iter().map(|m| m.draws.len()).sum(),
        };
        if models.len() != draws {
            return Err(invalid(format!(
                "draw_count {} differs from the {draws} draws of the geometry (over all its meshes)",
                models.len(),
            )));
        }
        let (stored_to_world, cpu_bounds) = match self {
            Self::Cpu {
                positions,
                indices,
                draws,
                ..
            } => {
                let moved: Vec<Draw> = draws
                    .iter()
                    .zip(models)
                    .map(|(d, &model)| Draw { model, ..*d })
                    .collect();
                let bounds = draw_bounds(positions, indices, &moved)?;
                (models.to_vec(), Some(bounds))
            }
            Self::Vulkan { meshes, .. } => {
                let dequantize = meshes
                    .iter()
                    .flat_map(|m| m.draws.iter().map(|_| m.dequantize));
                (
                    models.iter().zip(dequantize).map(|(m, d)| *m * d).collect(),
                    None,
                )
            }
        };
        if let Some(i) = stored_to_world.iter().position(|m| !m.is_finite()) {
            return Err(invalid(format!(
                "transform {i} is finite, but not once its mesh's dequantization (position_scale, position_offset) is applied"
            )));
        }
        Ok(MovedDraws {
            models: models.to_vec(),
            stored_to_world,
            cpu_bounds,
        })
    }

    /// Moves the draws as [`GeometrySource::moved`] checked: CPU geometry takes its new bounds; the bounds
    /// given with Vulkan geometry no longer hold (frames may give theirs).
    pub(crate) fn move_draws(&mut self, moved: MovedDraws) {
        let draws: Vec<&mut Draw> = match self {
            Self::Cpu { draws, .. } => draws.iter_mut().collect(),
            Self::Vulkan { meshes, .. } => meshes.iter_mut().flat_map(|m| &mut m.draws).collect(),
        };
        for (d, m) in draws.into_iter().zip(moved.models) {
            d.model = m;
        }
        match (self, moved.cpu_bounds) {
            (Self::Cpu { bounds, .. }, Some(moved)) => *bounds = moved,
            (Self::Vulkan { bounds_hold, .. }, _) => *bounds_hold = false,
            (Self::Cpu { .. }, None) => {}
        }
    }

    /// World-space bounds (min, max) of every triangle in every frame, for culling: always for CPU
    /// geometry (copied once), for the engine's buffers only while they do not change (`dynamic` false:
    /// the engine's `bounds` describe what it gave).
    pub(crate) fn cull_bounds(&self, dynamic: bool) -> Option<[DVec3; 2]> {
        match self {
            Self::Cpu { bounds, .. } => Some(*bounds),
            Self::Vulkan {
                bounds,
                bounds_hold,
                ..
            } => (!dynamic && *bounds_hold).then_some(*bounds),
        }
    }

    /// The number of meshes.
    pub(crate) fn mesh_count(&self) -> usize {
        match self {
            Self::Cpu { .. } => 1,
            Self::Vulkan { meshes, .. } => meshes.len(),
        }
    }

    /// Where mesh `mesh`'s positions are in its vertex buffer (a CPU mesh's: packed xyz from 0).
    pub(crate) fn vertex_layout(&self, mesh: usize) -> Option<VertexLayout> {
        match self {
            Self::Cpu { positions, .. } => (mesh == 0).then_some(VertexLayout {
                offset: 0,
                stride: 12,
                count: (positions.len() / 3) as u32,
                format: VertexFormat::Float3,
            }),
            Self::Vulkan { meshes, .. } => meshes.get(mesh).map(|m| m.vertex),
        }
    }
}

/// The caller's `count` draws at `ptr`, `stride` bytes apart, checked.
fn draws_from(ptr: *const HrtsDraw, count: u32, stride: usize) -> ApiResult<Vec<Draw>> {
    if count == 0 {
        return Err(invalid("draw_count is 0"));
    }
    read_elements(ptr, count as usize, stride, "draws")?
        .iter()
        .enumerate()
        .map(|(i, d)| {
            finite(&d.transform, &format!("draws[{i}].transform"))?;
            Ok(Draw {
                first_index: d.first_index,
                index_count: d.index_count,
                model: mat4(&d.transform),
                base_vertex: d.base_vertex,
            })
        })
        .collect()
}

/// World-space bounds (min, max) of the vertices `draws` reference, each moved by its transform.
fn draw_bounds(positions: &[f32], indices: &[u32], draws: &[Draw]) -> ApiResult<[DVec3; 2]> {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for d in draws {
        let model = d.model.as_dmat4();
        for &i in indices
            .iter()
            .skip(d.first_index as usize)
            .take(d.index_count as usize)
        {
            let vertex = usize::try_from(i64::from(i) + i64::from(d.base_vertex)).ok();
            let Some(p) = vertex.and_then(|v| positions.get(v * 3..v * 3 + 3)) else {
                return Err(invalid(format!(
                    "index {i} plus base_vertex {} is out of range ({} vertices)",
                    d.base_vertex,
                    positions.len() / 3
                )));
            };
            let w = model.transform_point3(Vec3::from_slice(p).as_dvec3());
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    if !lo.is_finite() || !hi.is_finite() {
        return Err(invalid("the draws reference no vertices"));
    }
    Ok([lo, hi])
}

/// The geometry of `hrts_set_geometry_cpu`, copied and checked.
pub(crate) fn cpu_geometry(g: &HrtsCpuGeometry) -> ApiResult<GeometrySource> {
    if g.positions.is_null() || g.indices.is_null() {
        return Err(ApiError::new(
            HrtsResult::ErrorNullPointer,
            "positions and indices must be non-NULL",
        ));
    }
    if g.vertex_count == 0 || g.index_count == 0 {
        return Err(invalid("vertex_count and index_count must be positive"));
    }
    check_aligned(g.positions, "positions")?;
    check_aligned(g.indices, "indices")?;
    if g.vertex_stride < 12 || !g.vertex_stride.is_multiple_of(4) {
        return Err(invalid(format!(
            "vertex_stride {} must be a multiple of 4 and at least 12",
            g.vertex_stride
        )));
    }
    let floats = (g.vertex_count as usize - 1) * (g.vertex_stride as usize / 4) + 3;
    // SAFETY: aligned; the caller guarantees the arrays hold `vertex_count` strided positions and
    // `index_count` indices (documented contract); they are copied before returning.
    let raw = unsafe { std::slice::from_raw_parts(g.positions, floats) };
    let step = g.vertex_stride as usize / 4;
    let positions: Vec<f32> = (0..g.vertex_count as usize)
        .flat_map(|i| raw[i * step..i * step + 3].to_vec())
        .collect();
    finite(&positions, "positions")?;
    // SAFETY: as above.
    let indices = unsafe { std::slice::from_raw_parts(g.indices, g.index_count as usize) }.to_vec();
    let draws = draws_from(g.draws, g.draw_count, g.draw_stride)?;
    let [lo, hi] = draw_bounds(&positions, &indices, &draws)?;
    for (n, d) in draws.iter().enumerate() {
        if !d.index_count.is_multiple_of(3)
            || u64::from(d.first_index) + u64::from(d.index_count) > indices.len() as u64
        {
            return Err(invalid(format!(
                "draw {n} does not cover whole triangles of the index array"
            )));
        }
    }
    Ok(GeometrySource::Cpu {
        positions,
        indices,
        draws,
        origin: frame_origin(lo, hi),
        bounds: [lo, hi],
    })
}

/// The geometry of `hrts_set_geometry_vulkan` (one mesh, `listed` false) or
/// `hrts_set_geometry_vulkan_meshes` (`listed`: messages name the mesh), checked (its buffers are wrapped
/// once to check them).
pub(crate) fn vulkan_geometry(
    device: &Device,
    meshes: &[HrtsVulkanGeometry],
    listed: bool,
) -> ApiResult<GeometrySource> {
    if meshes.is_empty() {
        return Err(invalid("mesh_count is 0"));
    }
    let named = |i: usize, e: ApiError| match listed {
        true => ApiError {
            message: format!("meshes[{i}]: {}", e.message),
            ..e
        },
        false => e,
    };
    let mut checked = Vec::with_capacity(meshes.len());
    let mut wrapped = Vec::with_capacity(meshes.len());
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for (i, g) in meshes.iter().enumerate() {
        let (mesh, [mesh_lo, mesh_hi]) = vulkan_mesh(g).map_err(|e| named(i, e))?;
        wrapped.push(mesh_from(device, &mesh).map_err(|e| named(i, e))?);
        checked.push(mesh);
        lo = lo.min(mesh_lo);
        hi = hi.max(mesh_hi);
    }
    let origin = frame_origin(lo, hi);
    Geometry::new(wrapped, origin)?;
    Ok(GeometrySource::Vulkan {
        meshes: checked,
        origin,
        bounds: [lo, hi],
        bounds_hold: true,
    })
}

/// One mesh of the engine, checked but for its buffers' sizes, and its bounds.
fn vulkan_mesh(g: &HrtsVulkanGeometry) -> ApiResult<(VulkanMesh, [DVec3; 2])> {
    if g.vertex_buffer == 0 || g.index_buffer == 0 {
        return Err(ApiError::new(
            HrtsResult::ErrorNullPointer,
            "vertex_buffer and index_buffer must be non-NULL",
        ));
    }
    let format = enum_value(
        g.index_type,
        &[
            (HrtsIndexType::Uint16 as u32, IndexFormat::U16),
            (HrtsIndexType::Uint32 as u32, IndexFormat::U32),
        ],
        "index_type",
        "HrtsIndexType",
    )?;
    let bounds = bounds(&g.bounds)?;
    let draws = draws_from(g.draws, g.draw_count, g.draw_stride)?;
    let stored = match g.vertex_format {
        0 => Some(Format::Rgb32Float),
        raw => i32::try_from(raw)
            .ok()
            .and_then(Format::position_from_raw_vk),
    };
    let vertex_format = match stored {
        Some(Format::Rgb32Float) => VertexFormat::Float3,
        Some(Format::Rgba16Float) => VertexFormat::Half4,
        Some(Format::Rgba16Snorm) => VertexFormat::Snorm16x4,
        Some(Format::Rgba16Unorm) => VertexFormat::Unorm16x4,
        _ => {
            return Err(ApiError::new(
                HrtsResult::ErrorInvalidEnum,
                format!(
                    "vertex_format {} is not R32G32B32_SFLOAT ({}, or 0), R16G16B16A16_SFLOAT ({}), _SNORM ({}) or _UNORM ({})",
                    g.vertex_format,
                    Format::Rgb32Float.raw_vk(),
                    Format::Rgba16Float.raw_vk(),
                    Format::Rgba16Snorm.raw_vk(),
                    Format::Rgba16Unorm.raw_vk()
                ),
            ))
        }
    };
    finite(&g.position_scale, "position_scale")?;
    finite(&g.position_offset, "position_offset")?;
    let scale = match Vec3::from_array(g.position_scale) {
        Vec3::ZERO => Vec3::ONE,
        s if s.cmpeq(Vec3::ZERO).any() => {
            return Err(invalid(format!(
                "position_scale {s} has a zero axis (all zero means no dequantization)"
            )))
        }
        s => s,
    };
    let dequantize = glam::Mat4::from_scale_rotation_translation(
        scale,
        glam::Quat::IDENTITY,
        Vec3::from_array(g.position_offset),
    );
    let mesh = VulkanMesh {
        vertices: (g.vertex_buffer, g.vertex_buffer_size),
        vertex: VertexLayout {
            offset: g.vertex_offset,
            stride: g.vertex_stride,
            count: g.vertex_count,
            format: vertex_format,
        },
        indices: (g.index_buffer, g.index_buffer_size),
        index: IndexLayout {
            offset: g.index_offset,
            format,
            count: g.index_count,
        },
        draws,
        dequantize,
    };
    Ok((mesh, bounds))
}

/// A Vulkan mesh over the engine's buffers, its dequantization folded into its draws' transforms.
fn mesh_from(device: &Device, m: &VulkanMesh) -> ApiResult<Mesh> {
    let draws: Vec<Draw> = m
        .draws
        .iter()
        .map(|d| Draw {
            model: d.model * m.dequantize,
            ..*d
        })
        .collect();
    // SAFETY: the engine guarantees its buffers are live and of the stated sizes (contract).
    let (vb, ib) = unsafe {
        (
            device.external_buffer(m.vertices.0, m.vertices.1, BufferUsage::STORAGE)?,
            device.external_buffer(m.indices.0, m.indices.1, BufferUsage::STORAGE)?,
        )
    };
    Ok(Mesh::from_buffers(vb, m.vertex, ib, m.index, &draws)?)
}

pub(crate) fn geometry_from(device: &Device, source: &GeometrySource) -> ApiResult<Geometry> {
    Ok(match source {
        GeometrySource::Cpu {
            positions,
            indices,
            draws,
            origin,
            ..
        } => Geometry::upload(device, positions, indices, draws, *origin)?,
        GeometrySource::Vulkan { meshes, origin, .. } => Geometry::new(
            meshes
                .iter()
                .map(|m| mesh_from(device, m))
                .collect::<ApiResult<Vec<Mesh>>>()?,
            *origin,
        )?,
    })
}

/// The meshes frame `f` deforms (`HrtsFrame::deformed`), each checked against `geometry`'s meshes: in
/// range, given once, its buffer non-NULL and holding the mesh's vertices at its offset.
pub(crate) fn deformed_meshes(
    f: &HrtsFrame,
    geometry: Option<&GeometrySource>,
) -> ApiResult<Vec<HrtsMeshVertices>> {
    let count = f.deformed_count as usize;
    if count == 0 {
        return Ok(Vec::new());
    }
    if f.deformed.is_null() {
        return Err(ApiError::new(
            HrtsResult::ErrorNullPointer,
            format!("deformed is NULL with deformed_count {count}"),
        ));
    }
    let deformed = read_elements(f.deformed, count, f.deformed_stride, "deformed")?;
    let geometry = geometry.ok_or_else(|| {
        ApiError::new(
            HrtsResult::ErrorInvalidState,
            "set the geometry before deforming its meshes",
        )
    })?;
    let meshes = geometry.mesh_count();
    if count > meshes {
        return Err(invalid(format!(
            "deformed_count {count} exceeds the {meshes} meshes of the geometry"
        )));
    }
    for (i, v) in deformed.iter().enumerate() {
        let mesh = v.mesh as usize;
        let layout = geometry.vertex_layout(mesh).ok_or_else(|| {
            invalid(format!(
                "deformed[{i}].mesh {mesh} is out of range: the geometry has {meshes} meshes"
            ))
        })?;
        if let Some(j) = deformed[..i].iter().position(|o| o.mesh == v.mesh) {
            return Err(invalid(format!(
                "deformed[{i}].mesh {mesh} is deformed twice (deformed[{j}] names it too)"
            )));
        }
        if v.vertex_buffer == 0 {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                format!("deformed[{i}].vertex_buffer is NULL"),
            ));
        }
        let at = VertexLayout {
            offset: v.vertex_offset,
            ..layout
        };
        at.check(v.vertex_buffer_size).map_err(|e| {
            let e = ApiError::from(e);
            ApiError {
                message: format!("deformed[{i}] (mesh {mesh}): {}", e.message),
                ..e
            }
        })?;
    }
    Ok(deformed.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One CPU mesh of 4 vertices.
    fn quad() -> GeometrySource {
        GeometrySource::Cpu {
            positions: vec![0.0; 12],
            indices: vec![0, 1, 2, 0, 2, 3],
            draws: Vec::new(),
            origin: DVec3::ZERO,
            bounds: [DVec3::ZERO; 2],
        }
    }

    fn frame(deformed: &[HrtsMeshVertices]) -> HrtsFrame {
        // SAFETY: every field of `HrtsFrame` is an integer, a float or a raw pointer: all zeros is valid.
        let mut f: HrtsFrame = unsafe { std::mem::zeroed() };
        f.deformed = deformed.as_ptr();
        f.deformed_count = deformed.len() as u32;
        f
    }

    fn vertices(mesh: u32, size: u64, offset: u64) -> HrtsMeshVertices {
        HrtsMeshVertices {
            mesh,
            vertex_buffer: 1,
            vertex_buffer_size: size,
            vertex_offset: offset,
        }
    }

    #[test]
    fn deformed_meshes_are_checked_against_the_geometry() {
        let g = quad();
        let ok = [vertices(0, 64, 16)];
        assert_eq!(deformed_meshes(&frame(&ok), Some(&g)).unwrap(), ok);
        assert!(deformed_meshes(&frame(&[]), None).unwrap().is_empty());
        let code = |v: &[HrtsMeshVertices], g: Option<&GeometrySource>| {
            deformed_meshes(&frame(v), g).map_err(|e| (e.code, e.message))
        };
        let mut null = frame(&ok);
        null.deformed = std::ptr::null();
        assert_eq!(
            deformed_meshes(&null, Some(&g)).unwrap_err().code,
            HrtsResult::ErrorNullPointer
        );
        assert_eq!(
            code(&ok, None).unwrap_err().0,
            HrtsResult::ErrorInvalidState
        );
        let (c, m) = code(&[vertices(1, 64, 0)], Some(&g)).unwrap_err();
        assert!(
            c == HrtsResult::ErrorInvalidArgument && m.contains("deformed[0].mesh 1"),
            "{m}"
        );
        // 4 float3 vertices at offset 16 end at 64 bytes.
        let (c, m) = code(&[vertices(0, 63, 16)], Some(&g)).unwrap_err();
        assert!(
            c == HrtsResult::ErrorInvalidArgument && m.contains("deformed[0] (mesh 0)"),
            "{m}"
        );
        let (c, m) = code(&[vertices(0, 64, 0), vertices(0, 64, 0)], Some(&g)).unwrap_err();
        assert!(
            c == HrtsResult::ErrorInvalidArgument && m.contains("deformed_count 2"),
            "{m}"
        );
        let mut unbound = vertices(0, 64, 0);
        unbound.vertex_buffer = 0;
        assert_eq!(
            code(&[unbound], Some(&g)).unwrap_err().0,
            HrtsResult::ErrorNullPointer
        );
    }
}

//! Hardware ray tracing, DXR 1.0 style: acceleration structures built by the driver
//! (`VK_KHR_acceleration_structure`) and ray-tracing pipelines with a shader binding table
//! (`VK_KHR_ray_tracing_pipeline`). Available only on a device the RHI created where the device supports
//! them; elsewhere every entry point fails with [`RhiError::MissingFeature`] naming what is missing.

use crate::accel::{triangles, AccelerationStructure, BottomLevel, TopLevel};
use crate::device::Device;
use crate::encoder::{Barrier, Encoder};
use crate::error::{Result, RhiError, VkResultExt};
use crate::pipeline::{BindGroup, BindingKind, PipelineLayout};
use crate::resources::{Buffer, MemoryLocation};
use crate::rt_device::{align_up, RayTracingDevice, RayTracingLimits};
use ash::vk;

/// Every shader stage mask that contains a shader stage also gets the ray-tracing shader stage, so that a
/// D3D12-style state covers ray-tracing shaders too.
pub(crate) fn with_ray_tracing_stages(stages: vk::PipelineStageFlags2) -> vk::PipelineStageFlags2 {
    if stages.intersects(crate::conv::SHADER_STAGES) {
        stages | vk::PipelineStageFlags2::RAY_TRACING_SHADER_KHR
    } else {
        stages
    }
}

/// One region of a shader binding table, relative to the table's base.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SbtRegion {
    /// Byte offset from the table's base (a multiple of `shaderGroupBaseAlignment`).
    pub offset: u64,
    /// Bytes between records (a multiple of `shaderGroupHandleAlignment`).
    pub stride: u64,
    /// Bytes of the region.
    pub size: u64,
}

/// Layout of a table with one ray-generation record, then `miss` miss records, then `hit` hit-group
/// records. The ray-generation region's size equals its stride, as `vkCmdTraceRaysKHR` requires.
pub(crate) fn sbt_layout(limits: &RayTracingLimits, miss: u32, hit: u32) -> Result<[SbtRegion; 3]> {
    let stride = align_up(
        u64::from(limits.handle_size),
        u64::from(limits.handle_alignment),
    );
    if stride > u64::from(limits.max_stride) {
        return Err(RhiError::Limit {
            what: "shader group stride".into(),
            value: stride,
            limit: limits.max_stride.into(),
        });
    }
    let base = u64::from(limits.base_alignment);
    let raygen = SbtRegion {
        offset: 0,
        stride,
        size: stride,
    };
    let miss = SbtRegion {
        offset: align_up(raygen.size, base),
        stride,
        size: stride * u64::from(miss),
    };
    let hit = SbtRegion {
        offset: align_up(miss.offset + miss.size, base),
        stride,
        size: stride * u64::from(hit),
    };
    Ok([raygen, miss, hit])
}

/// Bytes of a `VkAccelerationStructureInstanceKHR`.
const INSTANCE_BYTES: usize = 64;

/// The `VkAccelerationStructureInstanceKHR` of `blas_address` with an identity transform, custom index 0,
/// mask 0xFF, hit-group offset 0, two-sided (facing cull disabled) and opaque.
pub(crate) fn instance_record(blas_address: u64) -> [u8; INSTANCE_BYTES] {
    let identity: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let mask = 0xFFu32 << 24;
    let flags = (vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE
        | vk::GeometryInstanceFlagsKHR::FORCE_OPAQUE)
        .as_raw();
    let mut record = [0u8; INSTANCE_BYTES];
    record[..48].copy_from_slice(bytemuck::cast_slice(&identity));
    record[48..52].copy_from_slice(&mask.to_le_bytes());
    record[52..56].copy_from_slice(&(flags << 24).to_le_bytes());
    record[56..].copy_from_slice(&blas_address.to_le_bytes());
    record
}

/// Orders everything recorded before a build (writes of its inputs, earlier builds, traces reading the
/// structure it rewrites) before the build's reads and writes.
fn before_build() -> vk::MemoryBarrier2<'static> {
    vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
        .dst_access_mask(
            vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR
                | vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR
                | vk::AccessFlags2::SHADER_READ,
        )
}

/// Makes a build's result visible to later builds and ray-tracing shaders.
fn after_build() -> vk::MemoryBarrier2<'static> {
    vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
        .src_access_mask(vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR)
        .dst_stage_mask(
            vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR
                | vk::PipelineStageFlags2::RAY_TRACING_SHADER_KHR,
        )
        .dst_access_mask(vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR)
}

/// Device address of `buffer` rounded up to `alignment`, and that address's offset in the buffer.
fn aligned_address(buffer: &Buffer, alignment: u64) -> (u64, u64) {
    let address = buffer.device_address();
    let aligned = align_up(address, alignment);
    (aligned, aligned - address)
}

/// Triangles of a bottom-level structure: non-indexed `R32G32B32_SFLOAT` positions, `stride` bytes apart,
/// three vertices per triangle, opaque.
#[derive(Clone, Copy)]
pub struct TriangleGeometry<'a> {
    /// The vertices, from offset 0. Created with [`crate::BufferUsage::ACCELERATION_STRUCTURE_INPUT`]; it
    /// must outlive every build of the structure, as a bound buffer must outlive its bind group's use.
    pub vertices: &'a Buffer,
    /// Bytes between consecutive vertices (e.g. 16 for `vec4` positions with w ignored).
    pub stride: u64,
    /// Triangles (3 vertices each).
    pub triangle_count: u32,
}

fn instances(address: u64) -> vk::AccelerationStructureGeometryKHR<'static> {
    let data = vk::AccelerationStructureGeometryInstancesDataKHR::default()
        .array_of_pointers(false)
        .data(vk::DeviceOrHostAddressConstKHR {
            device_address: address,
        });
    vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::INSTANCES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { instances: data })
}

/// Description of a ray-tracing pipeline: one ray-generation shader, one miss shader, and one empty
/// triangle hit group (never invoked by opaque rays that skip closest-hit shaders).
pub struct RayTracingPipelineDesc<'a> {
    /// Debug name.
    pub name: &'a str,
    /// Ray-generation shader SPIR-V.
    pub raygen: &'a [u32],
    /// Miss shader SPIR-V.
    pub miss: &'a [u32],
    /// Descriptor bindings.
    pub bindings: &'a [BindingKind],
    /// Push-constant bytes (0 = none).
    pub push_constant_size: u32,
}

/// A ray-tracing pipeline with its shader binding table.
pub struct RayTracingPipeline {
    layout: PipelineLayout,
    raw: vk::Pipeline,
    /// Ray-generation, miss and hit regions of the table.
    regions: [vk::StridedDeviceAddressRegionKHR; 3],
    /// The shader binding table the regions point into.
    table: Buffer,
}

impl RayTracingPipeline {
    /// The pipeline's layout (for bind groups).
    pub fn layout(&self) -> &PipelineLayout {
        &self.layout
    }
}

impl Drop for RayTracingPipeline {
    fn drop(&mut self) {
        // SAFETY: GPU work using the pipeline has completed before the owner drops it.
        unsafe { self.layout.shared.device.destroy_pipeline(self.raw, None) };
    }
}

impl Device {
    /// Whether acceleration structures and ray-tracing pipelines can be used; the error names what the
    /// device lacks.
    pub fn ray_tracing_support(&self) -> Result<()> {
        self.rt().map(|_| ())
    }

    fn rt(&self) -> Result<&RayTracingDevice> {
        self.shared
            .ray_tracing
            .as_ref()
            .map_err(|missing| RhiError::MissingFeature(format!("ray tracing ({missing})")))
    }

    /// Creates an acceleration structure of `ty` for `geometry` with `primitives` primitives, with
    /// storage and scratch memory sized by the driver.
    fn create_acceleration_structure(
        &self,
        name: &str,
        ty: vk::AccelerationStructureTypeKHR,
        geometry: vk::AccelerationStructureGeometryKHR<'_>,
        primitives: u32,
    ) -> Result<AccelerationStructure> {
        let rt = self.rt()?;
        let geometries = [geometry];
        let info = build_info(ty, &geometries);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        // SAFETY: valid device with acceleration structures enabled; `info` and its geometry outlive the call.
        unsafe {
            rt.accel.get_acceleration_structure_build_sizes(
                vk::AccelerationStructureBuildTypeKHR::DEVICE,
                &info,
                &[primitives],
                &mut sizes,
            )
        };
        let storage = self.create_raw_buffer(
            name,
            sizes.acceleration_structure_size,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        let scratch_alignment = u64::from(rt.limits.scratch_alignment);
        let scratch = self.create_raw_buffer(
            &format!("{name} scratch"),
            sizes.build_scratch_size.max(1) + scratch_alignment,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        let create = vk::AccelerationStructureCreateInfoKHR::default()
            .buffer(storage.raw)
            .offset(0)
            .size(sizes.acceleration_structure_size)
            .ty(ty);
        // SAFETY: `storage` is a live buffer with ACCELERATION_STRUCTURE_STORAGE usage of at least `size`
        // bytes; the structure is destroyed before it (AccelerationStructure::drop).
        let raw = unsafe { rt.accel.create_acceleration_structure(&create, None) }
            .call("vkCreateAccelerationStructureKHR")?;
        self.set_name(
            vk::ObjectType::ACCELERATION_STRUCTURE_KHR,
            ash::vk::Handle::as_raw(raw),
            name,
        );
        let address_info =
            vk::AccelerationStructureDeviceAddressInfoKHR::default().acceleration_structure(raw);
        // SAFETY: `raw` is a live acceleration structure of this device.
        let address = unsafe {
            rt.accel
                .get_acceleration_structure_device_address(&address_info)
        };
        Ok(AccelerationStructure {
            shared: self.shared.clone(),
            raw,
            address,
            scratch_address: aligned_address(&scratch, scratch_alignment).0,
            _storage: storage,
            _scratch: scratch,
        })
    }

    /// Creates a bottom-level acceleration structure for `geometry` (built by
    /// [`Encoder::build_bottom_level`]).
    pub fn create_bottom_level(
        &self,
        name: &str,
        geometry: &TriangleGeometry<'_>,
    ) -> Result<BottomLevel> {
        self.rt()?;
        let input = vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS
            | vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR;
        if !geometry.vertices.usage.contains(input) {
            return Err(RhiError::InvalidArgument(format!(
                "{name}: the vertex buffer lacks ACCELERATION_STRUCTURE_INPUT usage"
            )));
        }
        let vertices = u64::from(geometry.triangle_count) * 3;
        let needed = (vertices.saturating_sub(1))
            .checked_mul(geometry.stride)
            .and_then(|last| last.checked_add(12));
        if geometry.triangle_count == 0
            || geometry.stride < 12
            || needed.is_none_or(|n| n > geometry.vertices.size())
        {
            return Err(RhiError::InvalidArgument(format!(
                "{name}: {} triangles at a stride of {} bytes do not fit a vertex buffer of {} bytes",
                geometry.triangle_count,
                geometry.stride,
                geometry.vertices.size()
            )));
        }
        let address = geometry.vertices.device_address();
        let inner = self.create_acceleration_structure(
            name,
            vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
            triangles(address, geometry.stride, geometry.triangle_count),
            geometry.triangle_count,
        )?;
        Ok(BottomLevel {
            inner,
            vertices: address,
            stride: geometry.stride,
            triangle_count: geometry.triangle_count,
        })
    }

    /// Creates a top-level acceleration structure with one instance of `bottom` (built by
    /// [`Encoder::build_top_level`] after the bottom level).
    pub fn create_top_level(&self, name: &str, bottom: BottomLevel) -> Result<TopLevel> {
        self.rt()?;
        // Instance addresses must be 16-byte aligned.
        let mut instances = self.create_raw_buffer(
            &format!("{name} instances"),
            INSTANCE_BYTES as u64 + 16,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::CpuToGpu,
        )?;
        let (instances_address, offset) = aligned_address(&instances, 16);
        instances.write(offset, &instance_record(bottom.inner.address))?;
        let inner = self.create_acceleration_structure(
            name,
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            self::instances(instances_address),
            1,
        )?;
        Ok(TopLevel {
            inner,
            _instances: instances,
            instances_address,
            bottom,
        })
    }

    /// Creates a ray-tracing pipeline and its shader binding table.
    pub fn create_ray_tracing_pipeline(
        &self,
        desc: &RayTracingPipelineDesc<'_>,
    ) -> Result<RayTracingPipeline> {
        let rt = self.rt()?;
        let regions = sbt_layout(&rt.limits, 1, 1)?;
        let layout = self.create_layout(desc.bindings, desc.push_constant_size)?;
        let raygen = self.create_module(desc.raygen)?;
        let miss = self.create_module(desc.miss)?;
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::RAYGEN_KHR)
                .module(raygen.raw)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::MISS_KHR)
                .module(miss.raw)
                .name(c"main"),
        ];
        let general = |stage: u32| {
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(vk::RayTracingShaderGroupTypeKHR::GENERAL)
                .general_shader(stage)
                .closest_hit_shader(vk::SHADER_UNUSED_KHR)
                .any_hit_shader(vk::SHADER_UNUSED_KHR)
                .intersection_shader(vk::SHADER_UNUSED_KHR)
        };
        let groups = [
            general(0),
            general(1),
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(vk::RayTracingShaderGroupTypeKHR::TRIANGLES_HIT_GROUP)
                .general_shader(vk::SHADER_UNUSED_KHR)
                .closest_hit_shader(vk::SHADER_UNUSED_KHR)
                .any_hit_shader(vk::SHADER_UNUSED_KHR)
                .intersection_shader(vk::SHADER_UNUSED_KHR),
        ];
        let info = vk::RayTracingPipelineCreateInfoKHR::default()
            .stages(&stages)
            .groups(&groups)
            .max_pipeline_ray_recursion_depth(1)
            .layout(layout.raw);
        // SAFETY: valid modules and layout; every referenced struct outlives the call.
        let raw = unsafe {
            rt.pipeline.create_ray_tracing_pipelines(
                vk::DeferredOperationKHR::null(),
                vk::PipelineCache::null(),
                &[info],
                None,
            )
        }
        .map_err(|(_, e)| RhiError::Vulkan {
            call: "vkCreateRayTracingPipelinesKHR",
            result: e,
        })?[0];
        let pipeline = RayTracingPipeline {
            layout,
            raw,
            regions: [vk::StridedDeviceAddressRegionKHR::default(); 3],
            table: self.create_raw_buffer(
                &format!("{} shader binding table", desc.name),
                regions[2].offset + regions[2].size + u64::from(rt.limits.base_alignment),
                vk::BufferUsageFlags::SHADER_BINDING_TABLE_KHR
                    | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
                MemoryLocation::CpuToGpu,
            )?,
        };
        self.set_name(
            vk::ObjectType::PIPELINE,
            ash::vk::Handle::as_raw(raw),
            desc.name,
        );
        self.fill_binding_table(rt, pipeline, &regions, groups.len() as u32)
    }

    /// Writes the group handles of `pipeline` into its table, one group per region, and points the
    /// regions at them.
    fn fill_binding_table(
        &self,
        rt: &RayTracingDevice,
        mut pipeline: RayTracingPipeline,
        regions: &[SbtRegion; 3],
        groups: u32,
    ) -> Result<RayTracingPipeline> {
        let handle_size = rt.limits.handle_size as usize;
        // SAFETY: `pipeline.raw` is a live ray-tracing pipeline with `groups` groups.
        let handles = unsafe {
            rt.pipeline.get_ray_tracing_shader_group_handles(
                pipeline.raw,
                0,
                groups,
                groups as usize * handle_size,
            )
        }
        .call("vkGetRayTracingShaderGroupHandlesKHR")?;
        let (base, offset) = aligned_address(&pipeline.table, u64::from(rt.limits.base_alignment));
        for (i, (region, handle)) in regions.iter().zip(handles.chunks(handle_size)).enumerate() {
            pipeline.table.write(offset + region.offset, handle)?;
            pipeline.regions[i] = vk::StridedDeviceAddressRegionKHR {
                device_address: base + region.offset,
                stride: region.stride,
                size: region.size,
            };
        }
        Ok(pipeline)
    }
}

fn build_info<'a>(
    ty: vk::AccelerationStructureTypeKHR,
    geometries: &'a [vk::AccelerationStructureGeometryKHR<'a>],
) -> vk::AccelerationStructureBuildGeometryInfoKHR<'a> {
    vk::AccelerationStructureBuildGeometryInfoKHR::default()
        .ty(ty)
        .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
        .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
        .geometries(geometries)
}

impl Encoder<'_> {
    /// Records a full build of `structure` from `geometry` with `primitives` primitives, ordered after
    /// every earlier command and before later builds and ray-tracing shaders.
    fn build(
        &mut self,
        ty: vk::AccelerationStructureTypeKHR,
        structure: &AccelerationStructure,
        geometry: vk::AccelerationStructureGeometryKHR<'_>,
        primitives: u32,
    ) -> Result<()> {
        let device = self.device;
        let rt = device.rt()?;
        let geometries = [geometry];
        let info = build_info(ty, &geometries)
            .dst_acceleration_structure(structure.raw)
            .scratch_data(vk::DeviceOrHostAddressKHR {
                device_address: structure.scratch_address,
            });
        let range =
            [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(primitives)];
        let d = &device.shared.device;
        // SAFETY: recording command buffer outside a render pass; the structure, its scratch memory and
        // the inputs are live and sized for `primitives` at creation; the barriers order the build.
        unsafe {
            d.cmd_pipeline_barrier2(
                self.cmd,
                &vk::DependencyInfo::default().memory_barriers(&[before_build()]),
            );
            rt.accel
                .cmd_build_acceleration_structures(self.cmd, &[info], &[&range]);
            d.cmd_pipeline_barrier2(
                self.cmd,
                &vk::DependencyInfo::default().memory_barriers(&[after_build()]),
            );
        }
        Ok(())
    }

    /// Records a full build of `bottom` from its vertices.
    pub fn build_bottom_level(&mut self, bottom: &BottomLevel) -> Result<()> {
        self.build(
            vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
            &bottom.inner,
            bottom.geometry(),
            bottom.triangle_count,
        )
    }

    /// Records a full build of `top` over its bottom level, which must have been built before.
    pub fn build_top_level(&mut self, top: &TopLevel) -> Result<()> {
        // The instance record was written on the host before any submission that reads it.
        self.build(
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            &top.inner,
            instances(top.instances_address),
            1,
        )
    }

    /// [`Encoder::barriers`] whose shader scopes also cover ray-tracing shaders: the transitions of the
    /// resources a ray-tracing pipeline reads or writes.
    pub fn ray_tracing_barriers(&mut self, barriers: &[Barrier<'_>]) -> Result<()> {
        self.device.rt()?;
        self.record_barriers(barriers, with_ray_tracing_stages);
        Ok(())
    }

    /// Binds a ray-tracing pipeline and its resources and launches `extent` ray-generation invocations.
    pub fn trace_rays(
        &mut self,
        pipeline: &RayTracingPipeline,
        group: &BindGroup,
        push: &[u8],
        extent: [u32; 3],
    ) -> Result<()> {
        let rt = self.device.rt()?;
        crate::encoder::check_push(push, pipeline.layout.push_constant_size)?;
        let invocations = extent.iter().map(|&e| u64::from(e)).product::<u64>();
        if invocations > u64::from(rt.limits.max_invocations) {
            return Err(RhiError::Limit {
                what: "ray dispatch invocations".into(),
                value: invocations,
                limit: rt.limits.max_invocations.into(),
            });
        }
        let [raygen, miss, hit] = &pipeline.regions;
        // SAFETY: live pipeline and set created for its layout; push size and dispatch size checked; the
        // binding table regions were filled at creation.
        unsafe {
            self.bind(
                vk::PipelineBindPoint::RAY_TRACING_KHR,
                pipeline.raw,
                &pipeline.layout,
                group,
                push,
            );
            rt.pipeline.cmd_trace_rays(
                self.cmd,
                raygen,
                miss,
                hit,
                &vk::StridedDeviceAddressRegionKHR::default(),
                extent[0],
                extent[1],
                extent[2],
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn align_up_rounds_to_multiples() {
        assert_eq!(align_up(0, 64), 0);
        assert_eq!(align_up(1, 64), 64);
        assert_eq!(align_up(64, 64), 64);
        assert_eq!(align_up(65, 64), 128);
        assert_eq!(align_up(13, 0), 13);
        assert_eq!(align_up(13, 1), 13);
    }

    fn limits(handle: u32, handle_alignment: u32, base: u32) -> RayTracingLimits {
        RayTracingLimits {
            handle_size: handle,
            handle_alignment,
            base_alignment: base,
            max_stride: 4096,
            max_invocations: 1 << 30,
            scratch_alignment: 128,
        }
    }

    #[test]
    fn binding_table_of_nvidia_limits() {
        // NVIDIA: 32-byte handles, 32-byte handle alignment, 64-byte base alignment.
        let [raygen, miss, hit] = sbt_layout(&limits(32, 32, 64), 1, 1).unwrap();
        assert_eq!(
            raygen,
            SbtRegion {
                offset: 0,
                stride: 32,
                size: 32
            }
        );
        assert_eq!(
            miss,
            SbtRegion {
                offset: 64,
                stride: 32,
                size: 32
            }
        );
        assert_eq!(
            hit,
            SbtRegion {
                offset: 128,
                stride: 32,
                size: 32
            }
        );
    }

    #[test]
    fn binding_table_strides_honour_handle_alignment() {
        // A handle smaller than its alignment: records are padded; regions start at base alignment.
        let [raygen, miss, hit] = sbt_layout(&limits(20, 32, 256), 2, 3).unwrap();
        assert_eq!(raygen.size, raygen.stride);
        assert_eq!(raygen.stride, 32);
        assert_eq!(
            miss,
            SbtRegion {
                offset: 256,
                stride: 32,
                size: 64
            }
        );
        assert_eq!(
            hit,
            SbtRegion {
                offset: 512,
                stride: 32,
                size: 96
            }
        );
    }

    #[test]
    fn binding_table_rejects_a_stride_above_the_limit() {
        let l = RayTracingLimits {
            max_stride: 16,
            ..limits(32, 32, 64)
        };
        assert!(matches!(sbt_layout(&l, 1, 1), Err(RhiError::Limit { .. })));
    }

    #[test]
    fn instance_record_layout() {
        let r = instance_record(0x0123_4567_89AB_CDEF);
        let floats: Vec<f32> = r[..48]
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        // Row-major 3x4 identity.
        assert_eq!(
            floats,
            [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        );
        // Custom index 0, mask 0xFF.
        assert_eq!(
            u32::from_le_bytes(r[48..52].try_into().unwrap()),
            0xFF00_0000
        );
        // Hit-group offset 0; flags: facing cull disabled (0x1) | force opaque (0x4).
        assert_eq!(
            u32::from_le_bytes(r[52..56].try_into().unwrap()),
            0x0500_0000
        );
        assert_eq!(
            u64::from_le_bytes(r[56..].try_into().unwrap()),
            0x0123_4567_89AB_CDEF
        );
        assert_eq!(
            INSTANCE_BYTES,
            std::mem::size_of::<vk::AccelerationStructureInstanceKHR>()
        );
    }

    #[test]
    fn shader_scopes_cover_ray_tracing_shaders() {
        use vk::PipelineStageFlags2 as S;
        assert!(with_ray_tracing_stages(S::COMPUTE_SHADER).contains(S::RAY_TRACING_SHADER_KHR));
        assert!(with_ray_tracing_stages(crate::conv::SHADER_STAGES)
            .contains(crate::conv::SHADER_STAGES | S::RAY_TRACING_SHADER_KHR));
        assert_eq!(with_ray_tracing_stages(S::ALL_TRANSFER), S::ALL_TRANSFER);
        assert_eq!(with_ray_tracing_stages(S::TOP_OF_PIPE), S::TOP_OF_PIPE);
        assert_eq!(with_ray_tracing_stages(S::ALL_COMMANDS), S::ALL_COMMANDS);
    }
}

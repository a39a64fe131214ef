//! Compute and graphics pipelines from SPIR-V, their layouts, and bind groups (descriptor sets).

use crate::accel::TopLevel;
use crate::conv::Format;
use crate::device::{Device, Shared};
use crate::error::{Result, RhiError, VkResultExt};
use crate::resources::{Buffer, Image};
use ash::vk;
use std::sync::Arc;

/// One binding of a pipeline's single descriptor set (binding index = position in the list).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BindingKind {
    /// Structured buffer (UAV or SRV).
    StorageBuffer,
    /// Constant buffer.
    UniformBuffer,
    /// UAV texture (storage image, `GENERAL` layout).
    StorageImage,
    /// SRV texture read with `texelFetch` through a nearest sampler (`SHADER_READ_ONLY_OPTIMAL` layout).
    SampledImage,
    /// Top-level acceleration structure (DXR `RaytracingAccelerationStructure`).
    AccelerationStructure,
}

fn descriptor_type(k: BindingKind) -> vk::DescriptorType {
    match k {
        BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
        BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
        BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
        BindingKind::SampledImage => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        BindingKind::AccelerationStructure => vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
    }
}

/// A resource bound to one binding.
#[derive(Clone, Copy)]
pub enum Resource<'a> {
    /// A whole buffer.
    Buffer(&'a Buffer),
    /// A whole image (all layers).
    Image(&'a Image),
    /// A top-level acceleration structure.
    AccelerationStructure(&'a TopLevel),
}

/// Descriptor-set layout plus pipeline layout (one set, one push-constant range).
pub struct PipelineLayout {
    pub(crate) shared: Arc<Shared>,
    set_layout: vk::DescriptorSetLayout,
    pub(crate) raw: vk::PipelineLayout,
    kinds: Vec<BindingKind>,
    pub(crate) push_constant_size: u32,
}

/// A set of resources bound to a pipeline layout.
pub struct BindGroup {
    shared: Arc<Shared>,
    pool: vk::DescriptorPool,
    pub(crate) set: vk::DescriptorSet,
    kinds: Vec<BindingKind>,
}

/// A compute pipeline.
pub struct ComputePipeline {
    pub(crate) layout: PipelineLayout,
    pub(crate) raw: vk::Pipeline,
}

/// Depth test state of a graphics pipeline.
#[derive(Debug, Clone, Copy)]
pub struct DepthState {
    /// Depth attachment format.
    pub format: Format,
    /// Write depth.
    pub write: bool,
    /// Pass if the incoming depth is greater (reversed Z) rather than less.
    pub greater: bool,
}

/// Description of a graphics pipeline (vertices pulled from buffers). Viewport and scissor are dynamic.
pub struct GraphicsPipelineDesc<'a> {
    /// Debug name.
    pub name: &'a str,
    /// Vertex shader SPIR-V.
    pub vertex: &'a [u32],
    /// Optional geometry shader SPIR-V.
    pub geometry: Option<&'a [u32]>,
    /// Fragment shader SPIR-V.
    pub fragment: &'a [u32],
    /// Descriptor bindings.
    pub bindings: &'a [BindingKind],
    /// Push-constant bytes (0 = none).
    pub push_constant_size: u32,
    /// Colour attachment formats.
    pub color_formats: &'a [Format],
    /// Depth attachment and test.
    pub depth: Option<DepthState>,
    /// Hardware conservative rasterization with this extra overestimation in pixels (None = off).
    pub conservative_extra_overestimation: Option<f32>,
    /// Clamp depth instead of clipping against the near/far planes.
    pub depth_clamp: bool,
}

/// A graphics pipeline.
pub struct GraphicsPipeline {
    pub(crate) layout: PipelineLayout,
    pub(crate) raw: vk::Pipeline,
}

impl ComputePipeline {
    /// The pipeline's layout (for bind groups).
    pub fn layout(&self) -> &PipelineLayout {
        &self.layout
    }
}

impl GraphicsPipeline {
    /// The pipeline's layout (for bind groups).
    pub fn layout(&self) -> &PipelineLayout {
        &self.layout
    }
}

impl Device {
    pub(crate) fn create_layout(
        &self,
        kinds: &[BindingKind],
        push_constant_size: u32,
    ) -> Result<PipelineLayout> {
        let d = &self.shared.device;
        let samplers = [self.shared.nearest_sampler];
        let bindings: Vec<_> = kinds
            .iter()
            .enumerate()
            .map(|(i, &k)| {
                let b = vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(descriptor_type(k))
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::ALL);
                if k == BindingKind::SampledImage {
                    b.immutable_samplers(&samplers)
                } else {
                    b
                }
            })
            .collect();
        // SAFETY: valid device; `bindings` and `samplers` outlive the call.
        let set_layout = unsafe {
            d.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )
        }
        .call("vkCreateDescriptorSetLayout")?;
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::ALL)
            .offset(0)
            .size(push_constant_size)];
        let set_layouts = [set_layout];
        let mut info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if push_constant_size > 0 {
            info = info.push_constant_ranges(&ranges);
        }
        // SAFETY: as above.
        let raw = match unsafe { d.create_pipeline_layout(&info, None) } {
            Ok(l) => l,
            Err(e) => {
                // SAFETY: unused layout.
                unsafe { d.destroy_descriptor_set_layout(set_layout, None) };
                return Err(RhiError::Vulkan {
                    call: "vkCreatePipelineLayout",
                    result: e,
                });
            }
        };
        Ok(PipelineLayout {
            shared: self.shared.clone(),
            set_layout,
            raw,
            kinds: kinds.to_vec(),
            push_constant_size,
        })
    }

    pub(crate) fn create_module(&self, spirv: &[u32]) -> Result<ShaderModule> {
        // SAFETY: `spirv` is SPIR-V produced by glslang at build time.
        let m = unsafe {
            self.shared
                .device
                .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(spirv), None)
        }
        .call("vkCreateShaderModule")?;
        Ok(ShaderModule {
            shared: self.shared.clone(),
            raw: m,
        })
    }

    /// Creates a compute pipeline (entry point `main`).
    pub fn create_compute_pipeline(
        &self,
        name: &str,
        spirv: &[u32],
        bindings: &[BindingKind],
        push_constant_size: u32,
    ) -> Result<ComputePipeline> {
        let layout = self.create_layout(bindings, push_constant_size)?;
        let module = self.create_module(spirv)?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module.raw)
            .name(c"main");
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout.raw)
            .flags(self.statistics_flags());
        // SAFETY: valid module and layout.
        let raw = unsafe {
            self.shared
                .device
                .create_compute_pipelines(vk::PipelineCache::null(), &[info], None)
        }
        .map_err(|(_, e)| RhiError::Vulkan {
            call: "vkCreateComputePipelines",
            result: e,
        })?[0];
        self.set_name(vk::ObjectType::PIPELINE, ash::vk::Handle::as_raw(raw), name);
        if let Ok(capture) = &self.shared.pipeline_statistics {
            capture.record(name, raw);
        }
        Ok(ComputePipeline { layout, raw })
    }

    /// Creates a graphics pipeline for dynamic rendering.
    pub fn create_graphics_pipeline(
        &self,
        desc: &GraphicsPipelineDesc<'_>,
    ) -> Result<GraphicsPipeline> {
        let caps = &self.shared.caps;
        if desc.geometry.is_some() && !caps.geometry_shader {
            return Err(RhiError::MissingFeature("geometryShader".into()));
        }
        if desc.conservative_extra_overestimation.is_some() && !caps.hardware_conservative_raster()
        {
            return Err(RhiError::MissingFeature(
                "VK_EXT_conservative_rasterization".into(),
            ));
        }
        let layout = self.create_layout(desc.bindings, desc.push_constant_size)?;
        let vs = self.create_module(desc.vertex)?;
        let gs = desc.geometry.map(|g| self.create_module(g)).transpose()?;
        let fs = self.create_module(desc.fragment)?;
        let mut stages = vec![vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(vs.raw)
            .name(c"main")];
        if let Some(gs) = &gs {
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::GEOMETRY)
                    .module(gs.raw)
                    .name(c"main"),
            );
        }
        stages.push(
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fs.raw)
                .name(c"main"),
        );
        // Vertices are pulled from storage buffers: no fixed-function vertex input.
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        let ia = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let vp = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let mut conservative = vk::PipelineRasterizationConservativeStateCreateInfoEXT::default()
            .conservative_rasterization_mode(vk::ConservativeRasterizationModeEXT::OVERESTIMATE)
            .extra_primitive_overestimation_size(
                desc.conservative_extra_overestimation.unwrap_or(0.0),
            );
        let mut raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .depth_clamp_enable(desc.depth_clamp && caps.depth_clamp)
            .line_width(1.0);
        if desc.conservative_extra_overestimation.is_some() {
            raster = raster.push_next(&mut conservative);
        }
        let ms = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let ds = match desc.depth {
            Some(d) => vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(true)
                .depth_write_enable(d.write)
                .depth_compare_op(if d.greater {
                    vk::CompareOp::GREATER
                } else {
                    vk::CompareOp::LESS
                }),
            None => vk::PipelineDepthStencilStateCreateInfo::default(),
        };
        let blend_attachments: Vec<_> = desc
            .color_formats
            .iter()
            .map(|_| {
                vk::PipelineColorBlendAttachmentState::default()
                    .color_write_mask(vk::ColorComponentFlags::RGBA)
            })
            .collect();
        let blend =
            vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let color_formats: Vec<vk::Format> = desc.color_formats.iter().map(|f| f.to_vk()).collect();
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&color_formats)
            .depth_attachment_format(
                desc.depth
                    .map_or(vk::Format::UNDEFINED, |d| d.format.to_vk()),
            );
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&ia)
            .viewport_state(&vp)
            .rasterization_state(&raster)
            .multisample_state(&ms)
            .depth_stencil_state(&ds)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout.raw)
            .flags(self.statistics_flags())
            .push_next(&mut rendering);
        // SAFETY: every referenced struct and module outlives the call.
        let raw = unsafe {
            self.shared
                .device
                .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
        }
        .map_err(|(_, e)| RhiError::Vulkan {
            call: "vkCreateGraphicsPipelines",
            result: e,
        })?[0];
        self.set_name(
            vk::ObjectType::PIPELINE,
            ash::vk::Handle::as_raw(raw),
            desc.name,
        );
        if let Ok(capture) = &self.shared.pipeline_statistics {
            capture.record(desc.name, raw);
        }
        Ok(GraphicsPipeline { layout, raw })
    }

    /// The creation flags that capture a pipeline's statistics, where the device does.
    fn statistics_flags(&self) -> vk::PipelineCreateFlags {
        if self.shared.pipeline_statistics.is_ok() {
            vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR
        } else {
            vk::PipelineCreateFlags::empty()
        }
    }

    /// Binds `resources` (in binding order) to a new descriptor set of `layout`.
    pub fn create_bind_group(
        &self,
        layout: &PipelineLayout,
        resources: &[Resource<'_>],
    ) -> Result<BindGroup> {
        if resources.len() != layout.kinds.len() {
            return Err(RhiError::InvalidArgument(format!(
                "bind group has {} resources, layout expects {}",
                resources.len(),
                layout.kinds.len()
            )));
        }
        let d = &self.shared.device;
        let group = self.allocate_group(layout)?;
        let set = group.set;
        let mut buffer_infos = Vec::new();
        let mut image_infos = Vec::new();
        let mut structures = Vec::new();
        for (i, (r, &k)) in resources.iter().zip(&layout.kinds).enumerate() {
            match (r, k) {
                (Resource::Buffer(b), BindingKind::StorageBuffer | BindingKind::UniformBuffer) => {
                    buffer_infos.push((
                        i,
                        k,
                        vk::DescriptorBufferInfo::default()
                            .buffer(b.raw)
                            .range(vk::WHOLE_SIZE),
                    ))
                }
                (Resource::Image(img), BindingKind::StorageImage | BindingKind::SampledImage)
                    if img.view == vk::ImageView::null() =>
                {
                    return Err(RhiError::InvalidArgument(format!(
                        "binding {i}: image was created without a sampled or storage usage"
                    )));
                }
                (Resource::Image(img), BindingKind::StorageImage) => image_infos.push((
                    i,
                    k,
                    vk::DescriptorImageInfo::default()
                        .image_view(img.view)
                        .image_layout(vk::ImageLayout::GENERAL),
                )),
                (Resource::Image(img), BindingKind::SampledImage) => image_infos.push((
                    i,
                    k,
                    vk::DescriptorImageInfo::default()
                        .image_view(img.view)
                        .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL),
                )),
                (Resource::AccelerationStructure(tlas), BindingKind::AccelerationStructure) => {
                    structures.push((i, [tlas.inner.raw]))
                }
                _ => {
                    return Err(RhiError::InvalidArgument(format!(
                        "binding {i}: resource does not match {k:?}"
                    )));
                }
            }
        }
        let mut writes = Vec::new();
        for (i, k, info) in &buffer_infos {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(*i as u32)
                    .descriptor_type(descriptor_type(*k))
                    .buffer_info(std::slice::from_ref(info)),
            );
        }
        for (i, k, info) in &image_infos {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(*i as u32)
                    .descriptor_type(descriptor_type(*k))
                    .image_info(std::slice::from_ref(info)),
            );
        }
        let mut structure_infos: Vec<_> = structures
            .iter()
            .map(|(_, raw)| {
                vk::WriteDescriptorSetAccelerationStructureKHR::default()
                    .acceleration_structures(raw)
            })
            .collect();
        for ((i, _), info) in structures.iter().zip(&mut structure_infos) {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(*i as u32)
                    .descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                    .descriptor_count(1)
                    .push_next(info),
            );
        }
        // SAFETY: all handles are live; the infos outlive the call.
        unsafe { d.update_descriptor_sets(&writes, &[]) };
        Ok(group)
    }

    /// A bind group of `layout` with an allocated, unwritten descriptor set.
    fn allocate_group(&self, layout: &PipelineLayout) -> Result<BindGroup> {
        let d = &self.shared.device;
        let mut sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
        for &k in &layout.kinds {
            let ty = descriptor_type(k);
            match sizes.iter_mut().find(|s| s.ty == ty) {
                Some(s) => s.descriptor_count += 1,
                None => sizes.push(vk::DescriptorPoolSize {
                    ty,
                    descriptor_count: 1,
                }),
            }
        }
        let pool_info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(1)
            .pool_sizes(&sizes);
        // SAFETY: valid device; the pool is destroyed with the BindGroup.
        let pool =
            unsafe { d.create_descriptor_pool(&pool_info, None) }.call("vkCreateDescriptorPool")?;
        let mut group = BindGroup {
            shared: self.shared.clone(),
            pool,
            set: vk::DescriptorSet::null(),
            kinds: layout.kinds.clone(),
        };
        let layouts = [layout.set_layout];
        // SAFETY: the pool has room for exactly this set.
        group.set = unsafe {
            d.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(pool)
                    .set_layouts(&layouts),
            )
        }
        .call("vkAllocateDescriptorSets")?[0];
        Ok(group)
    }

    /// A new bind group of the same layout as `group` whose binding `binding` is `resource` (a buffer or an
    /// image that replaced the one bound, e.g. after growing it) and whose other bindings are `group`'s.
    /// `group` is left as it was, so frames in flight that use it stay valid; drop it once they completed.
    pub fn rebound(
        &self,
        layout: &PipelineLayout,
        group: &BindGroup,
        binding: u32,
        resource: Resource<'_>,
    ) -> Result<BindGroup> {
        let kind = group.kinds.get(binding as usize).copied();
        let buffer_info;
        let image_info;
        let write = vk::WriteDescriptorSet::default()
            .dst_binding(binding)
            .descriptor_count(1);
        let write = match (kind, resource) {
            (
                Some(kind @ (BindingKind::StorageBuffer | BindingKind::UniformBuffer)),
                Resource::Buffer(buffer),
            ) => {
                buffer_info = [vk::DescriptorBufferInfo::default()
                    .buffer(buffer.raw)
                    .range(vk::WHOLE_SIZE)];
                write
                    .descriptor_type(descriptor_type(kind))
                    .buffer_info(&buffer_info)
            }
            (Some(kind @ BindingKind::StorageImage), Resource::Image(image))
                if image.view != vk::ImageView::null() =>
            {
                image_info = [vk::DescriptorImageInfo::default()
                    .image_view(image.view)
                    .image_layout(vk::ImageLayout::GENERAL)];
                write
                    .descriptor_type(descriptor_type(kind))
                    .image_info(&image_info)
            }
            _ => {
                return Err(RhiError::InvalidArgument(format!(
                    "binding {binding} of the group is not a buffer or storage image binding of the resource's kind"
                )))
            }
        };
        if layout.kinds != group.kinds {
            return Err(RhiError::InvalidArgument(
                "the layout is not the bind group's".into(),
            ));
        }
        let fresh = self.allocate_group(layout)?;
        let write = write.dst_set(fresh.set);
        let copies: Vec<vk::CopyDescriptorSet<'_>> = (0..group.kinds.len() as u32)
            .filter(|&i| i != binding)
            .map(|i| {
                vk::CopyDescriptorSet::default()
                    .src_set(group.set)
                    .src_binding(i)
                    .dst_set(fresh.set)
                    .dst_binding(i)
                    .descriptor_count(1)
            })
            .collect();
        // SAFETY: `fresh` is new and unused; `group` is only read (copying from a set in use is allowed);
        // both have the same layout; the resource is live and of the binding's kind.
        unsafe { self.shared.device.update_descriptor_sets(&[write], &copies) };
        Ok(fresh)
    }
}

pub(crate) struct ShaderModule {
    shared: Arc<Shared>,
    pub(crate) raw: vk::ShaderModule,
}

impl Drop for ShaderModule {
    fn drop(&mut self) {
        // SAFETY: modules are only needed during pipeline creation.
        unsafe { self.shared.device.destroy_shader_module(self.raw, None) };
    }
}

impl Drop for PipelineLayout {
    fn drop(&mut self) {
        // SAFETY: the owning pipeline is destroyed first (field order) and the GPU is done with it.
        unsafe {
            self.shared.device.destroy_pipeline_layout(self.raw, None);
            self.shared
                .device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // SAFETY: GPU work using the pipeline has completed before the owner drops it.
        unsafe { self.layout.shared.device.destroy_pipeline(self.raw, None) };
    }
}

impl Drop for GraphicsPipeline {
    fn drop(&mut self) {
        // SAFETY: as for ComputePipeline.
        unsafe { self.layout.shared.device.destroy_pipeline(self.raw, None) };
    }
}

impl Drop for BindGroup {
    fn drop(&mut self) {
        // SAFETY: destroying the pool frees its set; GPU work using it has completed.
        unsafe { self.shared.device.destroy_descriptor_pool(self.pool, None) };
    }
}

//! Command recording with D3D12-flavoured barriers, per-pass debug labels and GPU timestamps.

use crate::conv::{enabled_stages, state_scope, uav_barrier, ResourceState};
use crate::device::Device;
use crate::error::{Result, RhiError, VkResultExt};
use crate::pipeline::{BindGroup, ComputePipeline, GraphicsPipeline, PipelineLayout};
use crate::resources::{subresource_range, Buffer, Image};
use ash::vk;
use std::sync::{Arc, Mutex};

/// Records commands into a command buffer (the RHI's own, or an engine's).
pub struct Encoder<'a> {
    pub(crate) device: &'a Device,
    pub(crate) cmd: vk::CommandBuffer,
    timer: Option<GpuTimer>,
    open_pass: Option<usize>,
    render_extent: (u32, u32),
}

/// A barrier, in D3D12 terms.
pub enum Barrier<'a> {
    /// Orders storage (UAV) writes before later storage reads/writes, in every shader stage.
    Uav,
    /// Image state transition (layout change plus execution/memory dependency).
    Image {
        /// The image.
        image: &'a Image,
        /// State before.
        before: ResourceState,
        /// State after.
        after: ResourceState,
    },
    /// Orders every earlier command and its memory writes before every later command: what separates the
    /// work of one frame from the frames before it that reuse the same resources.
    Full,
    /// Global memory dependency for buffers between two states.
    Global {
        /// State before.
        before: ResourceState,
        /// State after.
        after: ResourceState,
    },
}

/// Colour attachment of a render pass, cleared at the start.
pub struct ColorTarget<'a> {
    /// The image (in `RenderTarget` state).
    pub image: &'a Image,
    /// Clear value.
    pub clear: [f32; 4],
}

/// Depth attachment of a render pass, cleared at the start.
pub struct DepthTarget<'a> {
    /// The image (in `DepthWrite` state).
    pub image: &'a Image,
    /// Clear depth.
    pub clear: f32,
}

/// Timestamp queries bracketing named passes, resolved to milliseconds after the GPU finishes.
/// Cloning shares the same queries.
#[derive(Clone)]
pub struct GpuTimer {
    inner: Arc<TimerInner>,
}

struct TimerInner {
    device: Arc<crate::device::Shared>,
    pool: vk::QueryPool,
    capacity: u32,
    names: Mutex<Vec<String>>,
    period_ns: f64,
}

/// GPU time of one pass.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTiming {
    /// Pass name.
    pub name: String,
    /// GPU milliseconds between the pass's begin and end timestamps.
    pub ms: f64,
}

impl Device {
    /// Creates a timer for up to `max_passes` passes per recording. Fails if the queue has no timestamps.
    pub fn create_timer(&self, max_passes: u32) -> Result<GpuTimer> {
        if !self.shared.caps.timestamps {
            return Err(RhiError::MissingFeature("timestamp queries".into()));
        }
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(max_passes * 2);
        // SAFETY: valid device; destroyed in Drop.
        let pool = unsafe { self.shared.device.create_query_pool(&info, None) }
            .call("vkCreateQueryPool")?;
        Ok(GpuTimer {
            inner: Arc::new(TimerInner {
                device: self.shared.clone(),
                pool,
                capacity: max_passes,
                names: Mutex::new(Vec::new()),
                period_ns: f64::from(self.shared.caps.timestamp_period_ns),
            }),
        })
    }
}

impl GpuTimer {
    /// Reads the timings of the last recording, waiting for them; call after its submission was made.
    pub fn resolve(&self) -> Result<Vec<PassTiming>> {
        self.read(true).map(|t| t.unwrap_or_default())
    }

    /// Reads the timings of the last recording if the GPU has written all of them, else `None`.
    pub fn try_resolve(&self) -> Result<Option<Vec<PassTiming>>> {
        self.read(false)
    }

    fn read(&self, wait: bool) -> Result<Option<Vec<PassTiming>>> {
        let t = &self.inner;
        let names = t.names.lock().map(|n| n.clone()).unwrap_or_default();
        let n = names.len();
        if n == 0 {
            return Ok(Some(Vec::new()));
        }
        let mut data = vec![0u64; n * 2];
        let flags = if wait {
            vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT
        } else {
            vk::QueryResultFlags::TYPE_64
        };
        // SAFETY: queries 0..2n were reset and written by the last recording.
        match unsafe {
            t.device
                .device
                .get_query_pool_results(t.pool, 0, &mut data, flags)
        } {
            Ok(()) => {}
            Err(vk::Result::NOT_READY) if !wait => return Ok(None),
            Err(result) => {
                return Err(RhiError::Vulkan {
                    call: "vkGetQueryPoolResults",
                    result,
                })
            }
        }
        Ok(Some(
            names
                .iter()
                .enumerate()
                .map(|(i, name)| PassTiming {
                    name: name.clone(),
                    ms: data[2 * i + 1].saturating_sub(data[2 * i]) as f64 * t.period_ns * 1e-6,
                })
                .collect(),
        ))
    }
}

impl Drop for TimerInner {
    fn drop(&mut self) {
        // SAFETY: results were read after completion, or the recording was never submitted.
        unsafe { self.device.device.destroy_query_pool(self.pool, None) };
    }
}

impl<'a> Encoder<'a> {
    pub(crate) fn new(device: &'a Device, cmd: vk::CommandBuffer) -> Self {
        Self {
            device,
            cmd,
            timer: None,
            open_pass: None,
            render_extent: (0, 0),
        }
    }

    /// Wraps an engine's command buffer, which must be in the recording state, outside a render pass.
    ///
    /// # Safety
    /// `command_buffer` must be a valid `VkCommandBuffer` of `device`'s `VkDevice` in the recording state,
    /// used by no other thread while the encoder lives.
    pub unsafe fn from_raw_handle(device: &'a Device, command_buffer: u64) -> Self {
        Self::new(device, ash::vk::Handle::from_raw(command_buffer))
    }

    /// The `VkCommandBuffer` handle, for recording through a component that speaks raw Vulkan (a C ABI).
    pub fn raw_handle(&self) -> u64 {
        ash::vk::Handle::as_raw(self.cmd)
    }

    /// The device this encoder records for.
    pub fn device(&self) -> &'a Device {
        self.device
    }

    fn d(&self) -> &ash::Device {
        &self.device.shared.device
    }

    /// `stages` without those the device's enabled features rule out of barriers.
    fn enabled(&self, stages: vk::PipelineStageFlags2) -> vk::PipelineStageFlags2 {
        enabled_stages(stages, self.device.shared.caps.geometry_shader)
    }

    /// Starts timing passes with `timer` (resets its queries; must be outside a render pass).
    pub fn attach_timer(&mut self, timer: &GpuTimer) {
        let t = &timer.inner;
        if let Ok(mut names) = t.names.lock() {
            names.clear();
        }
        // SAFETY: recording command buffer, outside a render pass; the pool belongs to this device.
        unsafe {
            self.d()
                .cmd_reset_query_pool(self.cmd, t.pool, 0, t.capacity * 2)
        };
        self.timer = Some(timer.clone());
    }

    /// Goes on timing passes with `timer` after the passes an earlier command buffer of the same submission
    /// order recorded with it (no reset: the queries were reset by that command buffer's `attach_timer`).
    pub fn continue_timer(&mut self, timer: &GpuTimer) {
        self.timer = Some(timer.clone());
    }

    /// Records the next passes without timestamps, until a timer is attached or continued.
    pub fn stop_timing(&mut self) {
        self.timer = None;
    }

    /// Opens a named pass: a debug label and a begin timestamp (when a timer is attached).
    pub fn begin_pass(&mut self, name: &str) {
        if let Some(utils) = &self.device.shared.debug_utils {
            if let Ok(cname) = std::ffi::CString::new(name) {
                let label = vk::DebugUtilsLabelEXT::default().label_name(&cname);
                // SAFETY: recording command buffer; the label outlives the call.
                unsafe { utils.cmd_begin_debug_utils_label(self.cmd, &label) };
            }
        }
        let cmd = self.cmd;
        if let Some(timer) = &self.timer {
            let t = &timer.inner;
            let Ok(mut names) = t.names.lock() else {
                return;
            };
            let i = names.len() as u32;
            if i < t.capacity {
                names.push(name.to_owned());
                // SAFETY: query 2i was reset by attach_timer.
                unsafe {
                    self.device.shared.device.cmd_write_timestamp2(
                        cmd,
                        vk::PipelineStageFlags2::ALL_COMMANDS,
                        t.pool,
                        2 * i,
                    )
                };
                self.open_pass = Some(i as usize);
            } else {
                log::warn!("GPU timer full: pass '{name}' is not timed");
                self.open_pass = None;
            }
        }
    }

    /// Closes the pass opened by [`Encoder::begin_pass`].
    pub fn end_pass(&mut self) {
        let cmd = self.cmd;
        if let (Some(i), Some(timer)) = (self.open_pass.take(), &self.timer) {
            // SAFETY: query 2i+1 was reset by attach_timer.
            unsafe {
                self.device.shared.device.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    timer.inner.pool,
                    2 * i as u32 + 1,
                )
            };
        }
        if let Some(utils) = &self.device.shared.debug_utils {
            // SAFETY: matches the label begun in begin_pass.
            unsafe { utils.cmd_end_debug_utils_label(cmd) };
        }
    }

    /// Records barriers (synchronization2).
    pub fn barriers(&mut self, barriers: &[Barrier<'_>]) {
        self.record_barriers(barriers, |stages| stages);
    }

    /// Records `barriers` with every stage mask passed through `widen` (e.g. to add ray-tracing stages).
    pub(crate) fn record_barriers(
        &mut self,
        barriers: &[Barrier<'_>],
        widen: impl Fn(vk::PipelineStageFlags2) -> vk::PipelineStageFlags2,
    ) {
        let mut memory = Vec::new();
        let mut images = Vec::new();
        for b in barriers {
            match b {
                Barrier::Uav => memory.push(uav_barrier()),
                Barrier::Full => memory.push(
                    vk::MemoryBarrier2::default()
                        .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                        .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
                        .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                        .dst_access_mask(
                            vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE,
                        ),
                ),
                Barrier::Global { before, after } => {
                    let (_, ss, sa) = state_scope(*before);
                    let (_, ds, da) = state_scope(*after);
                    memory.push(
                        vk::MemoryBarrier2::default()
                            .src_stage_mask(ss)
                            .src_access_mask(sa)
                            .dst_stage_mask(ds)
                            .dst_access_mask(da),
                    );
                }
                Barrier::Image {
                    image,
                    before,
                    after,
                } => {
                    let (ol, ss, sa) = state_scope(*before);
                    let (nl, ds, da) = state_scope(*after);
                    images.push(
                        vk::ImageMemoryBarrier2::default()
                            .src_stage_mask(ss)
                            .src_access_mask(sa)
                            .dst_stage_mask(ds)
                            .dst_access_mask(da)
                            .old_layout(ol)
                            .new_layout(nl)
                            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                            .image(image.raw)
                            .subresource_range(
                                subresource_range(image.format(), image.layers())
                                    .base_array_layer(image.base_layer()),
                            ),
                    );
                }
            }
        }
        let stages = |s| self.enabled(widen(s));
        for b in &mut memory {
            b.src_stage_mask = stages(b.src_stage_mask);
            b.dst_stage_mask = stages(b.dst_stage_mask);
        }
        for b in &mut images {
            b.src_stage_mask = stages(b.src_stage_mask);
            b.dst_stage_mask = stages(b.dst_stage_mask);
        }
        let dep = vk::DependencyInfo::default()
            .memory_barriers(&memory)
            .image_memory_barriers(&images);
        // SAFETY: recording command buffer; every image is live.
        unsafe { self.d().cmd_pipeline_barrier2(self.cmd, &dep) };
    }

    /// Clears all layers of a colour image (in `CopyDest` state) to `value` in every channel: integer
    /// formats take it as it is, float formats as the bits of an `f32`.
    pub fn clear_uint(&mut self, image: &Image, value: u32) {
        self.clear_uint_layer_range(image, 0, image.layers(), value);
    }

    /// Clears layer `layer` of a colour image (in `CopyDest` state) to `value`, as
    /// [`Encoder::clear_uint`] does.
    pub fn clear_uint_layer(&mut self, image: &Image, layer: u32, value: u32) -> Result<()> {
        if layer >= image.layers() {
            return Err(RhiError::InvalidArgument(format!(
                "layer {layer} of an image of {} layers",
                image.layers()
            )));
        }
        self.clear_uint_layer_range(image, layer, 1, value);
        Ok(())
    }

    fn clear_uint_layer_range(&mut self, image: &Image, first: u32, count: u32, value: u32) {
        let clear = vk::ClearColorValue { uint32: [value; 4] };
        let range =
            subresource_range(image.format(), count).base_array_layer(image.base_layer() + first);
        // SAFETY: the image is in TRANSFER_DST_OPTIMAL (CopyDest) by contract; the layers exist.
        unsafe {
            self.d().cmd_clear_color_image(
                self.cmd,
                image.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &clear,
                &[range],
            )
        };
    }

    /// Fills a buffer with a repeated `u32`.
    pub fn fill_buffer(&mut self, buffer: &Buffer, value: u32) {
        // SAFETY: whole-buffer fill of a live buffer with TRANSFER_DST usage.
        unsafe {
            self.d()
                .cmd_fill_buffer(self.cmd, buffer.raw, 0, vk::WHOLE_SIZE, value)
        };
    }

    /// Writes `data` into `buffer` at `offset` from the command buffer (`vkCmdUpdateBuffer`): the data is
    /// copied into the recording, so frames in flight each see their own. The update waits for earlier
    /// shader reads of the buffer and is visible to later uniform and storage reads. `data` is at most
    /// 65,536 bytes, a multiple of 4, and the buffer has `COPY_DST` usage.
    pub fn update_buffer(&mut self, buffer: &Buffer, offset: u64, data: &[u8]) -> Result<()> {
        let end = offset.checked_add(data.len() as u64);
        if data.is_empty()
            || data.len() > 65_536
            || !data.len().is_multiple_of(4)
            || !offset.is_multiple_of(4)
            || end.is_none_or(|e| e > buffer.size())
        {
            return Err(RhiError::InvalidArgument(format!(
                "buffer update of {} bytes at offset {offset} into {} bytes: needs 4..=65536 bytes, \
                 multiples of 4, within the buffer",
                data.len(),
                buffer.size()
            )));
        }
        let (_, reader_stages, reader_access) = state_scope(ResourceState::ShaderResource);
        let (_, copy_stages, copy_access) = state_scope(ResourceState::CopyDest);
        let (reader_stages, copy_stages) = (self.enabled(reader_stages), self.enabled(copy_stages));
        let barrier = |src, src_access, dst, dst_access| {
            vk::BufferMemoryBarrier2::default()
                .src_stage_mask(src)
                .src_access_mask(src_access)
                .dst_stage_mask(dst)
                .dst_access_mask(dst_access)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(buffer.raw)
                .offset(offset)
                .size(data.len() as u64)
        };
        let before = [barrier(
            reader_stages,
            vk::AccessFlags2::NONE,
            copy_stages,
            copy_access,
        )];
        let after = [barrier(
            copy_stages,
            copy_access,
            reader_stages,
            reader_access,
        )];
        let d = self.d();
        // SAFETY: recording command buffer outside a render pass; a live buffer; size, offset and alignment
        // checked above; the barriers only name that buffer.
        unsafe {
            d.cmd_pipeline_barrier2(
                self.cmd,
                &vk::DependencyInfo::default().buffer_memory_barriers(&before),
            );
            d.cmd_update_buffer(self.cmd, buffer.raw, offset, data);
            d.cmd_pipeline_barrier2(
                self.cmd,
                &vk::DependencyInfo::default().buffer_memory_barriers(&after),
            );
        }
        Ok(())
    }

    /// Binds a pipeline, its bind group (set 0) and its push constants.
    ///
    /// # Safety
    /// `pipeline` was created with `layout`, `group` for that layout, and `push` fits its push range;
    /// all are live until the command buffer completes.
    pub(crate) unsafe fn bind(
        &self,
        point: vk::PipelineBindPoint,
        pipeline: vk::Pipeline,
        layout: &PipelineLayout,
        group: &BindGroup,
        push: &[u8],
    ) {
        let d = self.d();
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_bind_pipeline(self.cmd, point, pipeline);
            d.cmd_bind_descriptor_sets(self.cmd, point, layout.raw, 0, &[group.set], &[]);
            if !push.is_empty() {
                d.cmd_push_constants(self.cmd, layout.raw, vk::ShaderStageFlags::ALL, 0, push);
            }
        }
    }

    /// Binds a compute pipeline and its resources and dispatches `groups` workgroups.
    pub fn dispatch(
        &mut self,
        pipeline: &ComputePipeline,
        group: &BindGroup,
        push: &[u8],
        groups: [u32; 3],
    ) -> Result<()> {
        check_push(push, pipeline.layout.push_constant_size)?;
        let limit = self.device.shared.caps.max_compute_work_group_count;
        if groups.iter().zip(limit).any(|(&g, l)| g > l) {
            return Err(RhiError::Limit {
                what: "dispatch size".into(),
                value: groups.iter().copied().max().unwrap_or(0).into(),
                limit: limit.iter().copied().min().unwrap_or(0).into(),
            });
        }
        let d = self.d();
        // SAFETY: live pipeline and set created for its layout; push size and group counts checked.
        unsafe {
            self.bind(
                vk::PipelineBindPoint::COMPUTE,
                pipeline.raw,
                &pipeline.layout,
                group,
                push,
            );
            d.cmd_dispatch(self.cmd, groups[0], groups[1], groups[2]);
        }
        Ok(())
    }

    /// Begins dynamic rendering over `extent` with cleared targets (none for UAV-only rasterization).
    pub fn begin_rendering(
        &mut self,
        extent: (u32, u32),
        colors: &[ColorTarget<'_>],
        depth: Option<DepthTarget<'_>>,
    ) {
        let color_infos: Vec<_> = colors
            .iter()
            .map(|c| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(c.image.view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue {
                        color: vk::ClearColorValue { float32: c.clear },
                    })
            })
            .collect();
        let depth_info = depth.map(|dt| {
            vk::RenderingAttachmentInfo::default()
                .image_view(dt.image.view)
                .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: dt.clear,
                        stencil: 0,
                    },
                })
        });
        let mut info = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: vk::Extent2D {
                    width: extent.0,
                    height: extent.1,
                },
            })
            .layer_count(1)
            .color_attachments(&color_infos);
        if let Some(di) = depth_info.as_ref() {
            info = info.depth_attachment(di);
        }
        self.render_extent = extent;
        // SAFETY: attachments are live and in the stated layouts; the infos outlive the call.
        unsafe { self.d().cmd_begin_rendering(self.cmd, &info) };
    }

    /// Ends dynamic rendering.
    pub fn end_rendering(&mut self) {
        // SAFETY: paired with begin_rendering.
        unsafe { self.d().cmd_end_rendering(self.cmd) };
    }

    /// Draws `vertex_count` vertices (no vertex buffers: shaders pull them) over the whole render area.
    pub fn draw(
        &mut self,
        pipeline: &GraphicsPipeline,
        group: &BindGroup,
        push: &[u8],
        vertex_count: u32,
    ) -> Result<()> {
        self.bind_graphics(pipeline, group, push)?;
        // SAFETY: inside begin_rendering, with the pipeline, its set and the dynamic state bound.
        unsafe { self.d().cmd_draw(self.cmd, vertex_count, 1, 0, 0) };
        Ok(())
    }

    /// Draws the first `index_count` `u32` indices of `indices` (a buffer with
    /// [`BufferUsage::INDEX`](crate::BufferUsage::INDEX);
    /// no vertex buffers: the vertex shader pulls vertex `gl_VertexIndex`) over the whole render area.
    pub fn draw_indexed(
        &mut self,
        pipeline: &GraphicsPipeline,
        group: &BindGroup,
        push: &[u8],
        indices: &Buffer,
        index_count: u32,
    ) -> Result<()> {
        let index_usage = indices.usage.contains(vk::BufferUsageFlags::INDEX_BUFFER);
        if !index_usage || u64::from(index_count) * 4 > indices.size() {
            return Err(RhiError::InvalidArgument(format!(
                "{index_count} u32 indices drawn from a buffer of {} bytes{}",
                indices.size(),
                if index_usage {
                    ""
                } else {
                    " without index usage"
                }
            )));
        }
        self.bind_graphics(pipeline, group, push)?;
        // SAFETY: inside begin_rendering, with the pipeline, its set and the dynamic state bound; the
        // buffer has index usage and holds the indices drawn (checked).
        unsafe {
            self.d()
                .cmd_bind_index_buffer(self.cmd, indices.raw, 0, vk::IndexType::UINT32);
            self.d().cmd_draw_indexed(self.cmd, index_count, 1, 0, 0, 0);
        }
        Ok(())
    }

    /// Binds `pipeline` with `group` and `push`, and a viewport and scissor of the whole render area.
    fn bind_graphics(
        &mut self,
        pipeline: &GraphicsPipeline,
        group: &BindGroup,
        push: &[u8],
    ) -> Result<()> {
        check_push(push, pipeline.layout.push_constant_size)?;
        let (w, h) = self.render_extent;
        let d = self.d();
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: w as f32,
            height: h as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        let scissor = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: vk::Extent2D {
                width: w,
                height: h,
            },
        };
        // SAFETY: inside begin_rendering; pipeline and set are live and match; push size checked.
        unsafe {
            self.bind(
                vk::PipelineBindPoint::GRAPHICS,
                pipeline.raw,
                &pipeline.layout,
                group,
                push,
            );
            d.cmd_set_viewport(self.cmd, 0, &[viewport]);
            d.cmd_set_scissor(self.cmd, 0, &[scissor]);
        }
        Ok(())
    }

    /// Copies all layers of `image` (in `CopySource` state) tightly packed into `buffer`.
    pub fn copy_image_to_buffer(&mut self, image: &Image, buffer: &Buffer) -> Result<()> {
        self.copy_image_to_buffer_at(image, buffer, 0)
    }

    /// [`Encoder::copy_image_to_buffer`] at byte `offset` (a multiple of 4) of `buffer`.
    pub fn copy_image_to_buffer_at(
        &mut self,
        image: &Image,
        buffer: &Buffer,
        offset: u64,
    ) -> Result<()> {
        let fits = offset
            .checked_add(image.byte_size())
            .is_some_and(|end| end <= buffer.size());
        if !fits || !offset.is_multiple_of(4) {
            return Err(RhiError::InvalidArgument(format!(
                "read-back of {} bytes at offset {offset} does not fit a buffer of {} bytes (or the offset is not a multiple of 4)",
                image.byte_size(),
                buffer.size(),
            )));
        }
        let region = vk::BufferImageCopy::default()
            .buffer_offset(offset)
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(image.format().view_aspect())
                    .mip_level(0)
                    .base_array_layer(image.base_layer())
                    .layer_count(image.layers()),
            )
            .image_extent(vk::Extent3D {
                width: image.width(),
                height: image.height(),
                depth: 1,
            });
        // SAFETY: sizes checked above; the image is in TRANSFER_SRC_OPTIMAL by contract.
        unsafe {
            self.d().cmd_copy_image_to_buffer(
                self.cmd,
                image.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer.raw,
                &[region],
            )
        };
        Ok(())
    }

    /// Copies all of `src` (in `CopySource` state) into `dst` (in `CopyDest` state): same size and format.
    pub fn copy_image(&mut self, src: &Image, dst: &Image) -> Result<()> {
        if (src.width(), src.height(), src.layers(), src.format())
            != (dst.width(), dst.height(), dst.layers(), dst.format())
        {
            return Err(RhiError::InvalidArgument(
                "image copy between different sizes or formats".into(),
            ));
        }
        self.record_image_copy(src, dst, 0, src.layers());
        Ok(())
    }

    /// Copies the single-layer image `src` into array layer `layer` of `dst` (same size and format).
    pub fn copy_image_into_layer(&mut self, src: &Image, dst: &Image, layer: u32) -> Result<()> {
        if (src.width(), src.height(), src.format()) != (dst.width(), dst.height(), dst.format())
            || src.layers() != 1
            || layer >= dst.layers()
        {
            return Err(RhiError::InvalidArgument(format!(
                "image copy into layer {layer} of {} needs one source layer of the same size and format",
                dst.layers()
            )));
        }
        self.record_image_copy(src, dst, layer, 1);
        Ok(())
    }

    /// Writes one-layer `src` into layer `layer` of `dst` (same size, any formats the device blits between:
    /// see [`crate::Device::can_blit`]), converting texels as a blit does; `src` in `CopySource`, `dst` in
    /// `CopyDest` state.
    pub fn blit_into_layer(&mut self, src: &Image, dst: &Image, layer: u32) -> Result<()> {
        if (src.width(), src.height()) != (dst.width(), dst.height())
            || src.layers() != 1
            || layer >= dst.layers()
            || src.format().is_depth()
            || dst.format().is_depth()
        {
            return Err(RhiError::InvalidArgument(format!(
                "blit into layer {layer} of {} needs one colour source layer of the same size",
                dst.layers()
            )));
        }
        let subresource = |base| layers_of(vk::ImageAspectFlags::COLOR, base, 1);
        let corner = vk::Offset3D {
            x: src.width() as i32,
            y: src.height() as i32,
            z: 1,
        };
        let region = vk::ImageBlit::default()
            .src_subresource(subresource(src.base_layer()))
            .src_offsets([vk::Offset3D::default(), corner])
            .dst_subresource(subresource(dst.base_layer() + layer))
            .dst_offsets([vk::Offset3D::default(), corner]);
        // SAFETY: checked sizes, layers and aspects; the images are in the stated layouts by contract and
        // the caller checked the formats' blit support.
        unsafe {
            self.d().cmd_blit_image(
                self.cmd,
                src.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
                vk::Filter::NEAREST,
            )
        };
        Ok(())
    }

    /// Records the copy of `layers` layers of `src`, from its first, into `dst` from layer `dst_layer`
    /// (checked by the callers).
    fn record_image_copy(&mut self, src: &Image, dst: &Image, dst_layer: u32, layers: u32) {
        let subresource = |base| layers_of(src.format().view_aspect(), base, layers);
        let region = vk::ImageCopy::default()
            .src_subresource(subresource(src.base_layer()))
            .dst_subresource(subresource(dst.base_layer() + dst_layer))
            .extent(vk::Extent3D {
                width: src.width(),
                height: src.height(),
                depth: 1,
            });
        // SAFETY: the callers checked sizes, formats and layers; the images are in the stated layouts by
        // contract.
        unsafe {
            self.d().cmd_copy_image(
                self.cmd,
                src.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            )
        };
    }

    /// Copies `src` into `dst` (whole `src`).
    pub fn copy_buffer(&mut self, src: &Buffer, dst: &Buffer) -> Result<()> {
        self.copy_buffer_at(src, dst, 0)
    }

    /// Copies the whole of `src` into `dst` at byte `dst_offset`.
    pub fn copy_buffer_at(&mut self, src: &Buffer, dst: &Buffer, dst_offset: u64) -> Result<()> {
        if dst_offset
            .checked_add(src.size())
            .is_none_or(|end| end > dst.size())
        {
            return Err(RhiError::InvalidArgument(
                "copy destination is smaller than the source at that offset".into(),
            ));
        }
        let region = vk::BufferCopy {
            src_offset: 0,
            dst_offset,
            size: src.size(),
        };
        // SAFETY: sizes checked; both buffers live with the right usages.
        unsafe {
            self.d()
                .cmd_copy_buffer(self.cmd, src.raw, dst.raw, &[region])
        };
        Ok(())
    }
}

pub(crate) fn check_push(push: &[u8], declared: u32) -> Result<()> {
    if push.len() as u64 > u64::from(declared) || !push.len().is_multiple_of(4) {
        return Err(RhiError::InvalidArgument(format!(
            "push constants of {} bytes do not fit the layout's {declared} bytes",
            push.len()
        )));
    }
    Ok(())
}

/// One-off submissions on a device of the RHI's own (they need an [`Encoder`]; a layer above the device).
impl Device {
    /// Records commands with `record`, submits them and waits for completion. Only on a device of the RHI's
    /// own: an adopted device's queue belongs to the engine, which synchronises its use.
    pub fn submit_and_wait<R>(
        &self,
        record: impl FnOnce(&mut Encoder<'_>) -> Result<R>,
    ) -> Result<R> {
        self.require_owned("submit_and_wait")?;
        let mut submitter = self
            .submitter
            .lock()
            .map_err(|_| RhiError::InvalidArgument("submission lock poisoned".into()))?;
        let s = &mut *submitter;
        let d = &self.shared.device;
        // SAFETY: the pool, its command buffer, the fence and the queue are used only under the lock held
        // until this returns; the command buffer and the fence are created once and reused (see `Submitter`:
        // never freed while the device lives); every submission is waited for before this returns, so
        // neither is pending when it is reset.
        unsafe {
            if s.cmd == vk::CommandBuffer::null() {
                let alloc = vk::CommandBufferAllocateInfo::default()
                    .command_pool(s.pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1);
                s.cmd = d
                    .allocate_command_buffers(&alloc)
                    .call("vkAllocateCommandBuffers")?[0];
            }
            if s.fence == vk::Fence::null() {
                s.fence = d
                    .create_fence(&vk::FenceCreateInfo::default(), None)
                    .call("vkCreateFence")?;
            }
            let cmd = s.cmd;
            // A recording that failed half-way left the command buffer recording: reset it either way.
            d.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .call("vkResetCommandBuffer")?;
            d.begin_command_buffer(
                cmd,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )
            .call("vkBeginCommandBuffer")?;
            let mut enc = Encoder::new(self, cmd);
            let r = record(&mut enc)?;
            d.end_command_buffer(cmd).call("vkEndCommandBuffer")?;
            let cmds = [cmd];
            let submit = vk::SubmitInfo::default().command_buffers(&cmds);
            d.queue_submit(self.shared.queue, &[submit], s.fence)
                .call("vkQueueSubmit")?;
            d.wait_for_fences(&[s.fence], true, u64::MAX)
                .call("vkWaitForFences")?;
            d.reset_fences(&[s.fence]).call("vkResetFences")?;
            Ok(r)
        }
    }
}

/// `count` layers from `base` of mip 0 of an image's `aspect`, for copies and blits.
fn layers_of(aspect: vk::ImageAspectFlags, base: u32, count: u32) -> vk::ImageSubresourceLayers {
    vk::ImageSubresourceLayers::default()
        .aspect_mask(aspect)
        .mip_level(0)
        .base_array_layer(base)
        .layer_count(count)
}

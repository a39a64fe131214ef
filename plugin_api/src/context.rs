//! The plugin context behind the C ABI: state, validation of every input, and recording into the
//! engine's command buffer.

use crate::types::*;
use glam::{DVec3, Mat4, Vec3};
use passes::{
    BinningPath, BinningRequest, Draw, FaceMode, FrameInputs, Geometry, IndexFormat, IndexLayout,
    Light, PassError, PassId, PassStatus, PenumbraFilter, PrimitiveMapConfig, ResourceId,
    ResourceSet, ShadowConfig, ShadowInputs, ShadowMode, ShadowPipeline, SkipReason, VertexLayout,
};
use rhi::{
    Barrier, BufferUsage, Device, Encoder, Format, Image, ImageDesc, ImageUsage,
    ResourceState as S, RhiError,
};

/// An error to return through the C ABI: a result code and a message.
#[derive(Debug)]
pub(crate) struct ApiError {
    pub(crate) code: HrtsResult,
    pub(crate) message: String,
}

impl ApiError {
    pub(crate) fn new(code: HrtsResult, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }
}

impl From<PassError> for ApiError {
    fn from(e: PassError) -> Self {
        let code = match &e {
            PassError::Rhi(r) => return r.into(),
            PassError::InvalidConfig(_) | PassError::InvalidGeometry(_) => {
                HrtsResult::ErrorInvalidArgument
            }
            PassError::Unsupported(_) => HrtsResult::ErrorUnsupported,
        };
        Self::new(code, e.to_string())
    }
}

impl From<&RhiError> for ApiError {
    fn from(e: &RhiError) -> Self {
        let code = match e {
            _ if e.is_out_of_memory() => HrtsResult::ErrorOutOfMemory,
            RhiError::MissingFeature(_)
            | RhiError::NoDevice(_)
            | RhiError::Loader(_)
            | RhiError::ValidationUnavailable => HrtsResult::ErrorUnsupported,
            RhiError::InvalidArgument(_) | RhiError::Limit { .. } => {
                HrtsResult::ErrorInvalidArgument
            }
            RhiError::Vulkan { .. } | RhiError::Allocation { .. } => HrtsResult::ErrorVulkan,
        };
        Self::new(code, e.to_string())
    }
}

impl From<RhiError> for ApiError {
    fn from(e: RhiError) -> Self {
        (&e).into()
    }
}

pub(crate) type ApiResult<T> = Result<T, ApiError>;

fn invalid(message: impl Into<String>) -> ApiError {
    ApiError::new(HrtsResult::ErrorInvalidArgument, message)
}

/// Checks a caller-provided `struct_size`.
pub(crate) fn check_size<T>(size: u32, name: &str) -> ApiResult<()> {
    let expected = std::mem::size_of::<T>();
    if size as usize != expected {
        return Err(ApiError::new(
            HrtsResult::ErrorStructSize,
            format!("{name}.struct_size is {size}, this library's {name} is {expected} bytes (header/library mismatch)"),
        ));
    }
    Ok(())
}

/// The frame origin of geometry within `lo..hi`: the centre, rounded to f32. Then the frame coordinates
/// of f32 world positions near it (vertex minus origin) are differences of numbers on the same f32 grid,
/// and computing them loses nothing.
fn frame_origin(lo: DVec3, hi: DVec3) -> DVec3 {
    ((lo + hi) * 0.5).as_vec3().as_dvec3()
}

fn finite(values: &[f32], what: &str) -> ApiResult<()> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(invalid(format!("{what} contains NaN or infinity")))
    }
}

/// Geometry as the engine described it, kept to rebuild the passes after a configuration change.
enum GeometrySource {
    Cpu {
        positions: Vec<f32>,
        indices: Vec<u32>,
        draws: Vec<Draw>,
        origin: DVec3,
    },
    Vulkan {
        vertices: (u64, u64),
        vertex: VertexLayout,
        indices: (u64, u64),
        index: IndexLayout,
        draws: Vec<Draw>,
        origin: DVec3,
    },
}

#[derive(Clone, Copy)]
struct TargetSource {
    width: u32,
    height: u32,
    depth: u64,
    normal: u64,
    output: u64,
}

/// The passes and the engine images they are bound to (the pipeline drops first).
struct Built {
    pipeline: ShadowPipeline,
    depth: Image,
    normal: Image,
    output: Image,
}

/// Where the recording of frames stands.
#[derive(Default)]
struct FrameProgress {
    /// The frame being recorded: its camera and light, and the last `HrtsPass` recorded.
    open: Option<(FrameInputs, u32)>,
    /// Whether a frame was recorded to its end since the passes were built.
    completed: bool,
}

/// Pass-mask bits of the passes that read the engine's depth and normal images.
const DEPTH_NORMAL_READERS: u32 = 1 << HrtsPass::RayTrace as u32
    | 1 << HrtsPass::ShadowMapTest as u32
    | 1 << HrtsPass::Pcss as u32;

/// The plugin's resources by their C value (`HrtsResource`), in that order.
const RESOURCES: [ResourceId; HRTS_RESOURCE_COUNT] = [
    ResourceId::ShadowMap,
    ResourceId::PrimListOffsets,
    ResourceId::PrimListEntries,
    ResourceId::Occupancy,
    ResourceId::RtVisibility,
    ResourceId::BlockerDistance,
    ResourceId::ShadowMapVisibility,
    ResourceId::Pcss,
    ResourceId::RtAntialiased,
    ResourceId::LerpFactor,
    ResourceId::Hybrid,
    ResourceId::Lit,
];

/// The pipeline's passes by their C value (`HrtsPass`); `HRTS_PASS_OUTPUT_COPY` is the context's own.
fn pass_from_index(index: u32) -> Option<PassId> {
    PassId::ALL.get(index as usize).copied()
}

/// State of one plugin context.
pub(crate) struct Context {
    built: Option<Built>,
    device: Device,
    config: ShadowConfig,
    geometry: Option<GeometrySource>,
    targets: Option<TargetSource>,
    progress: FrameProgress,
    pub(crate) last_error: std::ffi::CString,
}

fn image_usage(vk_usage: u32) -> ImageUsage {
    const TRANSFER_SRC: u32 = 0x1;
    const TRANSFER_DST: u32 = 0x2;
    const SAMPLED: u32 = 0x4;
    const STORAGE: u32 = 0x8;
    const COLOR: u32 = 0x10;
    const DEPTH: u32 = 0x20;
    let mut u = ImageUsage::default();
    for (bit, ours) in [
        (TRANSFER_SRC, ImageUsage::COPY_SRC),
        (TRANSFER_DST, ImageUsage::COPY_DST),
        (SAMPLED, ImageUsage::SAMPLED),
        (STORAGE, ImageUsage::STORAGE),
        (COLOR, ImageUsage::COLOR_TARGET),
        (DEPTH, ImageUsage::DEPTH_TARGET),
    ] {
        if vk_usage & bit != 0 {
            u = u | ours;
        }
    }
    u
}

fn require_usage(
    vk_usage: u32,
    needed: ImageUsage,
    what: &str,
    needed_name: &str,
) -> ApiResult<ImageUsage> {
    let usage = image_usage(vk_usage);
    if !usage.contains(needed) {
        return Err(ApiError::new(
            HrtsResult::ErrorImageUsage,
            format!("{what} was not created with {needed_name} usage (usage flags 0x{vk_usage:x})"),
        ));
    }
    Ok(usage)
}

fn mat4(m: &[f32; 16]) -> Mat4 {
    Mat4::from_cols_array(m)
}

fn draws_from(ptr: *const HrtsDraw, count: u32) -> ApiResult<Vec<Draw>> {
    if count == 0 {
        return Err(invalid("draw_count is 0"));
    }
    if ptr.is_null() {
        return Err(ApiError::new(HrtsResult::ErrorNullPointer, "draws is NULL"));
    }
    // SAFETY: the caller guarantees `ptr` points at `count` draws (documented contract).
    let draws = unsafe { std::slice::from_raw_parts(ptr, count as usize) };
    draws
        .iter()
        .enumerate()
        .map(|(i, d)| {
            finite(&d.transform, &format!("draws[{i}].transform"))?;
            Ok(Draw {
                first_index: d.first_index,
                index_count: d.index_count,
                model: mat4(&d.transform),
            })
        })
        .collect()
}

impl Context {
    /// Creates a context on an adopted or own device.
    pub(crate) fn new(info: &HrtsContextCreateInfo) -> ApiResult<Self> {
        if info.api_version >> 22 != HRTS_API_VERSION >> 22 {
            return Err(ApiError::new(
                HrtsResult::ErrorVersion,
                format!(
                    "caller built against API {}.x, this library is {}.x",
                    info.api_version >> 22,
                    HRTS_API_VERSION >> 22
                ),
            ));
        }
        let device = if info.vulkan.is_null() {
            let filter = if info.device_name_filter.is_null() {
                None
            } else {
                // SAFETY: a non-NULL filter is a NUL-terminated string (documented contract).
                let s = unsafe { std::ffi::CStr::from_ptr(info.device_name_filter) };
                Some(
                    s.to_str()
                        .map_err(|_| invalid("device_name_filter is not UTF-8"))?
                        .to_owned(),
                )
            };
            Device::new_headless(&rhi::DeviceDesc {
                validation: info.enable_validation,
                device_filter: filter,
            })?
        } else {
            // SAFETY: non-NULL, checked above; the caller guarantees it points at a HrtsVulkanDevice.
            let v = unsafe { &*info.vulkan };
            check_size::<HrtsVulkanDevice>(v.struct_size, "HrtsVulkanDevice")?;
            let gipa = v.get_instance_proc_addr.ok_or_else(|| {
                ApiError::new(
                    HrtsResult::ErrorNullPointer,
                    "get_instance_proc_addr is NULL",
                )
            })?;
            if v.instance == 0 || v.physical_device == 0 || v.device == 0 {
                return Err(ApiError::new(
                    HrtsResult::ErrorNullPointer,
                    "instance, physical_device and device must be non-NULL",
                ));
            }
            if !v.fragment_stores_and_atomics {
                return Err(ApiError::new(
                    HrtsResult::ErrorUnsupported,
                    "the device must enable fragmentStoresAndAtomics (the primitive map's UAV writes)",
                ));
            }
            let mut extensions = Vec::new();
            if v.enabled_extension_count > 0 {
                if v.enabled_extensions.is_null() {
                    return Err(ApiError::new(
                        HrtsResult::ErrorNullPointer,
                        "enabled_extensions is NULL but its count is not 0",
                    ));
                }
                // SAFETY: the caller guarantees `enabled_extension_count` valid C strings.
                let names = unsafe {
                    std::slice::from_raw_parts(
                        v.enabled_extensions,
                        v.enabled_extension_count as usize,
                    )
                };
                for &n in names {
                    if n.is_null() {
                        return Err(ApiError::new(
                            HrtsResult::ErrorNullPointer,
                            "an enabled extension name is NULL",
                        ));
                    }
                    // SAFETY: non-NULL NUL-terminated string.
                    extensions.push(
                        unsafe { std::ffi::CStr::from_ptr(n) }
                            .to_string_lossy()
                            .into_owned(),
                    );
                }
            }
            let desc = rhi::AdoptDesc {
                get_instance_proc_addr: gipa,
                instance: v.instance,
                physical_device: v.physical_device,
                device: v.device,
                queue_family_index: v.queue_family_index,
                queue_index: v.queue_index,
                enabled_extensions: extensions,
                enabled_features: rhi::EnabledFeatures {
                    geometry_shader: v.geometry_shader,
                    fragment_stores_and_atomics: v.fragment_stores_and_atomics,
                    depth_clamp: v.depth_clamp,
                    shader_float64: false,
                },
                debug_utils: v.debug_utils,
            };
            // SAFETY: the caller guarantees the handles are valid, belong together and outlive the context.
            unsafe { Device::adopt(desc) }?
        };
        Ok(Self {
            built: None,
            device,
            config: ShadowConfig::default(),
            geometry: None,
            targets: None,
            progress: FrameProgress::default(),
            last_error: std::ffi::CString::default(),
        })
    }

    pub(crate) fn capabilities(&self, out: &mut HrtsCapabilities) -> ApiResult<()> {
        check_size::<HrtsCapabilities>(out.struct_size, "HrtsCapabilities")?;
        let caps = self.device.capabilities();
        let default_path = passes::choose_binning_path(caps, BinningRequest::Auto)
            .map_or(HrtsBinningPath::Compute, binning_path_to_c);
        out.conservative_raster_tier = caps.conservative_raster_tier as u32;
        out.default_binning_path = default_path as u32;
        out.geometry_shader = caps.geometry_shader;
        out.timestamps = caps.timestamps;
        out.ray_query = caps.ray_query;
        out.ray_tracing_pipeline = caps.ray_tracing_pipeline;
        out.fragment_shader_interlock = caps.fragment_shader_interlock;
        out.max_map_size = caps.max_image_dimension_2d;
        out.max_map_entry_budget_kib =
            (caps.max_storage_buffer_range >> 10).min(u64::from(u32::MAX)) as u32;
        out.max_storage_buffer_range = caps.max_storage_buffer_range;
        out.device_name = [0; 128];
        for (dst, src) in out
            .device_name
            .iter_mut()
            .zip(caps.device_name.bytes().take(127))
        {
            *dst = src as std::ffi::c_char;
        }
        Ok(())
    }

    pub(crate) fn configure(&mut self, c: &HrtsConfig) -> ApiResult<()> {
        let config = shadow_config(c)?;
        let caps = self.device.capabilities();
        config.map.validate(caps)?;
        passes::choose_binning_path(caps, config.map.binning)?;
        if config.shadow_map.size == 0 || config.shadow_map.size > caps.max_image_dimension_2d {
            return Err(invalid(format!(
                "shadow_map_size {} must be within 1..={}",
                config.shadow_map.size, caps.max_image_dimension_2d
            )));
        }
        self.config = config;
        self.invalidate();
        Ok(())
    }

    pub(crate) fn set_geometry_cpu(&mut self, g: &HrtsCpuGeometry) -> ApiResult<()> {
        check_size::<HrtsCpuGeometry>(g.struct_size, "HrtsCpuGeometry")?;
        if g.positions.is_null() || g.indices.is_null() {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                "positions and indices must be non-NULL",
            ));
        }
        if g.vertex_count == 0 || g.index_count == 0 {
            return Err(invalid("vertex_count and index_count must be positive"));
        }
        if g.vertex_stride < 12 || !g.vertex_stride.is_multiple_of(4) {
            return Err(invalid(format!(
                "vertex_stride {} must be a multiple of 4 and at least 12",
                g.vertex_stride
            )));
        }
        let floats = (g.vertex_count as usize - 1) * (g.vertex_stride as usize / 4) + 3;
        // SAFETY: the caller guarantees the arrays hold `vertex_count` strided positions and `index_count`
        // indices (documented contract); they are copied before returning.
        let raw = unsafe { std::slice::from_raw_parts(g.positions, floats) };
        let step = g.vertex_stride as usize / 4;
        let positions: Vec<f32> = (0..g.vertex_count as usize)
            .flat_map(|i| raw[i * step..i * step + 3].to_vec())
            .collect();
        finite(&positions, "positions")?;
        // SAFETY: as above.
        let indices =
            unsafe { std::slice::from_raw_parts(g.indices, g.index_count as usize) }.to_vec();
        let draws = draws_from(g.draws, g.draw_count)?;
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for d in &draws {
            let model = d.model.as_dmat4();
            for &i in indices
                .iter()
                .skip(d.first_index as usize)
                .take(d.index_count as usize)
            {
                let Some(p) = positions.get(i as usize * 3..i as usize * 3 + 3) else {
                    return Err(invalid(format!(
                        "index {i} is out of range ({} vertices)",
                        g.vertex_count
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
        for (n, d) in draws.iter().enumerate() {
            if !d.index_count.is_multiple_of(3)
                || u64::from(d.first_index) + u64::from(d.index_count) > indices.len() as u64
            {
                return Err(invalid(format!(
                    "draw {n} does not cover whole triangles of the index array"
                )));
            }
        }
        self.geometry = Some(GeometrySource::Cpu {
            positions,
            indices,
            draws,
            origin: frame_origin(lo, hi),
        });
        self.invalidate();
        Ok(())
    }

    pub(crate) fn set_geometry_vulkan(&mut self, g: &HrtsVulkanGeometry) -> ApiResult<()> {
        check_size::<HrtsVulkanGeometry>(g.struct_size, "HrtsVulkanGeometry")?;
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
        finite(&g.bounds, "bounds")?;
        let lo = Vec3::from_slice(&g.bounds[..3]).as_dvec3();
        let hi = Vec3::from_slice(&g.bounds[3..]).as_dvec3();
        if lo.cmpgt(hi).any() {
            return Err(invalid("bounds min exceeds max"));
        }
        let draws = draws_from(g.draws, g.draw_count)?;
        let vertex = VertexLayout {
            offset: g.vertex_offset,
            stride: g.vertex_stride,
            count: g.vertex_count,
        };
        let index = IndexLayout {
            offset: g.index_offset,
            format,
            count: g.index_count,
        };
        let source = GeometrySource::Vulkan {
            vertices: (g.vertex_buffer, g.vertex_buffer_size),
            vertex,
            indices: (g.index_buffer, g.index_buffer_size),
            index,
            draws,
            origin: frame_origin(lo, hi),
        };
        geometry_from(&self.device, &source)?;
        self.geometry = Some(source);
        self.invalidate();
        Ok(())
    }

    pub(crate) fn set_targets(&mut self, t: &HrtsTargets) -> ApiResult<()> {
        check_size::<HrtsTargets>(t.struct_size, "HrtsTargets")?;
        if t.depth_image == 0 || t.normal_image == 0 || t.output_image == 0 {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                "depth_image, normal_image and output_image must be non-NULL",
            ));
        }
        let max = self.device.capabilities().max_image_dimension_2d;
        if t.width == 0 || t.height == 0 || t.width > max || t.height > max {
            return Err(invalid(format!(
                "target size {}x{} must be within 1..={max}",
                t.width, t.height
            )));
        }
        require_usage(t.depth_usage, ImageUsage::SAMPLED, "depth_image", "SAMPLED")?;
        require_usage(
            t.normal_usage,
            ImageUsage::SAMPLED,
            "normal_image",
            "SAMPLED",
        )?;
        require_usage(
            t.output_usage,
            ImageUsage::COPY_DST,
            "output_image",
            "TRANSFER_DST",
        )?;
        self.targets = Some(TargetSource {
            width: t.width,
            height: t.height,
            depth: t.depth_image,
            normal: t.normal_image,
            output: t.output_image,
        });
        self.invalidate();
        Ok(())
    }

    /// Forgets the passes (rebuilt on the next recording) and the frame in progress.
    fn invalidate(&mut self) {
        self.built = None;
        self.progress = FrameProgress::default();
    }

    /// Builds the passes if a configuration, geometry or targets call dropped them.
    fn ensure_built(&mut self) -> ApiResult<&mut Built> {
        if self.built.is_none() {
            self.progress = FrameProgress::default();
            self.built = Some(build(
                &self.device,
                self.config,
                self.geometry.as_ref(),
                self.targets,
            )?);
        }
        self.built
            .as_mut()
            .ok_or_else(|| ApiError::new(HrtsResult::ErrorInternal, "passes not built"))
    }

    pub(crate) fn record_passes(&mut self, f: &HrtsFrame, mask: u32) -> ApiResult<()> {
        check_size::<HrtsFrame>(f.struct_size, "HrtsFrame")?;
        if f.command_buffer == 0 {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                "command_buffer is NULL",
            ));
        }
        if mask == 0 || mask & !HRTS_PASS_MASK_ALL != 0 {
            return Err(invalid(format!(
                "pass mask 0x{mask:x} must be a non-empty set of HRTS_PASS_MASK_ALL (0x{HRTS_PASS_MASK_ALL:x}) bits"
            )));
        }
        let inputs = frame_inputs(f)?;
        let mut used_layouts = Vec::new();
        if mask & DEPTH_NORMAL_READERS != 0 {
            used_layouts.extend([
                ("depth_layout", f.depth_layout),
                ("normal_layout", f.normal_layout),
            ]);
        }
        let copy_output = mask & 1 << HrtsPass::OutputCopy as u32 != 0;
        if copy_output {
            used_layouts.push(("output_layout_after", f.output_layout_after));
        }
        for (what, layout) in used_layouts {
            if layout <= 0 {
                return Err(invalid(format!(
                    "{what} {layout} is not a usable VkImageLayout"
                )));
            }
        }
        self.ensure_built()?;
        let lowest = mask.trailing_zeros();
        let highest = 31 - mask.leading_zeros();
        let continues = match self.progress.open {
            Some((open_inputs, last)) if lowest > last => {
                if open_inputs != inputs {
                    return Err(invalid(
                        "the camera and light must stay the same across the calls of one frame",
                    ));
                }
                true
            }
            _ => false,
        };
        let (device, built) = match self.built.as_mut() {
            Some(b) => (&self.device, b),
            None => return Err(ApiError::new(HrtsResult::ErrorInternal, "passes not built")),
        };
        if !continues {
            self.progress.open = None;
            built.pipeline.begin_frame(&inputs)?;
        }
        let passes: Vec<PassId> = (0..HRTS_PASS_COUNT as u32)
            .filter(|i| mask & 1 << i != 0)
            .filter_map(pass_from_index)
            .collect();
        if copy_output {
            if let Some(missing) = built
                .pipeline
                .passes_to_record()
                .into_iter()
                .find(|p| !passes.contains(p))
            {
                return Err(ApiError::new(
                    HrtsResult::ErrorInvalidState,
                    format!(
                        "pass '{}' runs this frame and has not been recorded: record it before (or with) the output copy",
                        missing.name()
                    ),
                ));
            }
        }
        // SAFETY: the engine guarantees the command buffer is recording, outside a render pass, on this
        // device and used by no other thread during the call (documented contract).
        let mut enc = unsafe { Encoder::from_raw_handle(device, f.command_buffer) };
        let reads_depth = mask & DEPTH_NORMAL_READERS != 0;
        if reads_depth {
            engine_inputs(&mut enc, built, f, true);
        }
        let recorded = built.pipeline.record_passes(&mut enc, &passes);
        if reads_depth {
            engine_inputs(&mut enc, built, f, false);
        }
        recorded.map_err(|e| match e {
            PassError::InvalidConfig(m) => ApiError::new(HrtsResult::ErrorInvalidState, m),
            other => other.into(),
        })?;
        if copy_output {
            record_output_copy(&mut enc, built, f)?;
            self.progress = FrameProgress {
                open: None,
                completed: true,
            };
        } else {
            self.progress.open = Some((inputs, highest));
        }
        Ok(())
    }

    /// The passes, once a frame was recorded to its end and no other is being recorded.
    fn finished_frame(&self) -> ApiResult<&Built> {
        match (&self.built, &self.progress) {
            (
                Some(built),
                FrameProgress {
                    open: None,
                    completed: true,
                },
            ) => Ok(built),
            (_, FrameProgress { open: Some(_), .. }) => Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                "a frame is being recorded: record its remaining passes through HRTS_PASS_OUTPUT_COPY first",
            )),
            _ => Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                "no frame has been recorded to its end since the last configuration, geometry or targets call",
            )),
        }
    }

    pub(crate) fn report(&self, out: &mut HrtsFrameReport) -> ApiResult<()> {
        check_size::<HrtsFrameReport>(out.struct_size, "HrtsFrameReport")?;
        let built = self.finished_frame()?;
        let report = built.pipeline.try_report()?.ok_or_else(|| {
            ApiError::new(
                HrtsResult::ErrorInvalidState,
                "the last recorded frame has not completed on the GPU: read the report after its fence signalled",
            )
        })?;
        out.binning_path = binning_path_to_c(report.binning_path) as u32;
        out.tier = report.binning_path.tier() as u32;
        let st = &report.stats;
        out.texels_past_capacity = st.texels_past_capacity;
        out.longest_list = st.longest_list;
        out.texels_with_list = st.texels_with_list;
        out.entries = st.entries;
        out.entry_capacity = st.capacity;
        out.receiver_pixels = st.receiver_pixels;
        out.receiver_texels = st.receiver_texels;
        out.triangles_binned = st.triangles_binned;
        out.map_to_texels = report.map_to_texels.to_cols_array();
        out.pass_count = report.timings.len().min(HRTS_MAX_REPORTED_PASSES) as u32;
        for (slot, t) in out.passes.iter_mut().zip(&report.timings) {
            slot.name = [0; 32];
            for (dst, src) in slot.name.iter_mut().zip(t.name.bytes().take(31)) {
                *dst = src as std::ffi::c_char;
            }
            slot.milliseconds = t.ms;
        }
        out.pass_status = [HrtsPassStatus::NotInPlan as u32; HRTS_PASS_COUNT];
        for (i, &(_, status)) in report.passes.iter().enumerate() {
            out.pass_status[i] = match status {
                PassStatus::Ran => HrtsPassStatus::Ran,
                PassStatus::Skipped(SkipReason::UpToDate) => HrtsPassStatus::UpToDate,
                PassStatus::Skipped(SkipReason::NotRequested) => HrtsPassStatus::NotInPlan,
            } as u32;
        }
        out.pass_status[HrtsPass::OutputCopy as usize] = HrtsPassStatus::Ran as u32;
        out.resource_bytes = [0; HRTS_RESOURCE_COUNT];
        out.prim_buffer_bytes = 0;
        for r in &report.resources {
            if let Some(i) = RESOURCES.iter().position(|&id| id == r.resource) {
                out.resource_bytes[i] = r.bytes;
            } else if r.resource == ResourceId::PrimBuffer {
                out.prim_buffer_bytes = r.bytes;
            }
        }
        out.output_resource = resource_index(report.output)?;
        Ok(())
    }

    pub(crate) fn resource_info(
        &mut self,
        resource: u32,
        out: &mut HrtsResourceInfo,
    ) -> ApiResult<()> {
        check_size::<HrtsResourceInfo>(out.struct_size, "HrtsResourceInfo")?;
        let id = resource_id(resource)?;
        let built = self.ensure_built()?;
        match (built.pipeline.image(id), built.pipeline.buffer(id)) {
            (Some(image), _) => {
                out.allocated = true;
                out.width = image.width();
                out.height = image.height();
                out.layers = image.layers();
                out.format = image.format().raw_vk();
                out.bytes = image.byte_size();
            }
            (None, Some(buffer)) => {
                out.allocated = true;
                out.width = (buffer.size() / 4).min(u64::from(u32::MAX)) as u32;
                out.height = 1;
                out.layers = 1;
                out.format = Format::R32Uint.raw_vk();
                out.bytes = buffer.size();
            }
            (None, None) => {
                out.allocated = false;
                (out.width, out.height, out.layers, out.format, out.bytes) = (0, 0, 0, 0, 0);
            }
        }
        Ok(())
    }

    pub(crate) fn record_readback(&self, r: &HrtsResourceReadback) -> ApiResult<()> {
        check_size::<HrtsResourceReadback>(r.struct_size, "HrtsResourceReadback")?;
        if r.command_buffer == 0 || r.buffer == 0 {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                "command_buffer and buffer must be non-NULL",
            ));
        }
        let id = resource_id(r.resource)?;
        let built = self.finished_frame()?;
        let (image, list) = (built.pipeline.image(id), built.pipeline.buffer(id));
        let bytes = match (image, list) {
            (Some(image), _) => image.byte_size(),
            (None, Some(list)) => list.size(),
            (None, None) => {
                return Err(ApiError::new(
                    HrtsResult::ErrorInvalidState,
                    format!(
                        "{} is not allocated by this configuration: add it to extra_outputs",
                        id.name()
                    ),
                ))
            }
        };
        let fits = r
            .offset
            .checked_add(bytes)
            .is_some_and(|end| end <= r.buffer_size);
        if !fits || !r.offset.is_multiple_of(4) {
            return Err(invalid(format!(
                "{} needs {} bytes at a multiple-of-4 offset: offset {} in a buffer of {} bytes does not do",
                id.name(),
                bytes,
                r.offset,
                r.buffer_size
            )));
        }
        // SAFETY: the engine guarantees a live buffer of `buffer_size` bytes with TRANSFER_DST usage.
        let buffer = unsafe {
            self.device
                .external_buffer(r.buffer, r.buffer_size, BufferUsage::COPY_DST)?
        };
        let state = if id == ResourceId::ShadowMap {
            S::ShaderResource
        } else {
            S::UnorderedAccess
        };
        // SAFETY: as for `record_passes`.
        let mut enc = unsafe { Encoder::from_raw_handle(&self.device, r.command_buffer) };
        match (image, list) {
            (Some(image), _) => {
                enc.barriers(&[Barrier::Image {
                    image,
                    before: state,
                    after: S::CopySource,
                }]);
                enc.copy_image_to_buffer_at(image, &buffer, r.offset)?;
                enc.barriers(&[Barrier::Image {
                    image,
                    before: S::CopySource,
                    after: state,
                }]);
            }
            (None, Some(list)) => {
                enc.barriers(&[Barrier::Global {
                    before: S::UnorderedAccess,
                    after: S::CopySource,
                }]);
                enc.copy_buffer_at(list, &buffer, r.offset)?;
            }
            (None, None) => {}
        }
        enc.barriers(&[
            Barrier::Global {
                before: S::CopyDest,
                after: S::Engine(0),
            },
            Barrier::Global {
                before: S::CopyDest,
                after: S::HostRead,
            },
        ]);
        Ok(())
    }
}

pub(crate) fn resource_id(value: u32) -> ApiResult<ResourceId> {
    RESOURCES.get(value as usize).copied().ok_or_else(|| {
        ApiError::new(
            HrtsResult::ErrorInvalidEnum,
            format!("resource {value} is not a HrtsResource value"),
        )
    })
}

pub(crate) fn resource_index(id: ResourceId) -> ApiResult<u32> {
    RESOURCES
        .iter()
        .position(|&r| r == id)
        .map(|i| i as u32)
        .ok_or_else(|| {
            ApiError::new(
                HrtsResult::ErrorInternal,
                format!("{} has no HrtsResource value", id.name()),
            )
        })
}

fn geometry_from(device: &Device, source: &GeometrySource) -> ApiResult<Geometry> {
    Ok(match source {
        GeometrySource::Cpu {
            positions,
            indices,
            draws,
            origin,
        } => Geometry::upload(device, positions, indices, draws, *origin)?,
        GeometrySource::Vulkan {
            vertices,
            vertex,
            indices,
            index,
            draws,
            origin,
        } => {
            // SAFETY: the engine guarantees its buffers are live and of the stated sizes (contract).
            let (vb, ib) = unsafe {
                (
                    device.external_buffer(vertices.0, vertices.1, BufferUsage::STORAGE)?,
                    device.external_buffer(indices.0, indices.1, BufferUsage::STORAGE)?,
                )
            };
            Geometry::from_buffers(vb, *vertex, ib, *index, draws, *origin)?
        }
    })
}

/// Creates the passes over the engine's geometry and images.
fn build(
    device: &Device,
    config: ShadowConfig,
    source: Option<&GeometrySource>,
    targets: Option<TargetSource>,
) -> ApiResult<Built> {
    let (Some(source), Some(t)) = (source, targets) else {
        return Err(ApiError::new(
            HrtsResult::ErrorInvalidState,
            "set geometry and targets before recording",
        ));
    };
    let geometry = geometry_from(device, source)?;
    let wrap = |name, handle, format, usage| {
        let desc = ImageDesc {
            name,
            format,
            width: t.width,
            height: t.height,
            layers: 1,
            usage,
        };
        // SAFETY: the engine guarantees its images are live and match the description (contract).
        unsafe { device.external_image(handle, &desc) }
    };
    let depth = wrap(
        "engine depth",
        t.depth,
        Format::D32Float,
        ImageUsage::SAMPLED,
    )?;
    let normal = wrap(
        "engine normal",
        t.normal,
        Format::Rgba32Float,
        ImageUsage::SAMPLED,
    )?;
    let output = wrap(
        "engine visibility",
        t.output,
        Format::R32Float,
        ImageUsage::COPY_DST,
    )?;
    let pipeline = ShadowPipeline::new(
        device,
        geometry,
        &ShadowInputs {
            depth: &depth,
            normal: &normal,
        },
        config,
    )?;
    Ok(Built {
        pipeline,
        depth,
        normal,
        output,
    })
}

/// Transitions the engine's depth and normal images from their layouts to `ShaderResource` (`to_shader`)
/// or back.
fn engine_inputs(enc: &mut Encoder<'_>, b: &Built, f: &HrtsFrame, to_shader: bool) {
    let transition = |image, layout| {
        let (before, after) = if to_shader {
            (S::Engine(layout), S::ShaderResource)
        } else {
            (S::ShaderResource, S::Engine(layout))
        };
        Barrier::Image {
            image,
            before,
            after,
        }
    };
    enc.barriers(&[
        transition(&b.depth, f.depth_layout),
        transition(&b.normal, f.normal_layout),
    ]);
}

/// Copies the pipeline's final visibility into the engine's output image.
fn record_output_copy(enc: &mut Encoder<'_>, b: &Built, f: &HrtsFrame) -> ApiResult<()> {
    let vis = b.pipeline.output();
    enc.begin_pass("output copy");
    enc.barriers(&[
        Barrier::Image {
            image: vis,
            before: S::UnorderedAccess,
            after: S::CopySource,
        },
        Barrier::Image {
            image: &b.output,
            before: S::Engine(f.output_layout_before),
            after: S::CopyDest,
        },
    ]);
    enc.copy_image(vis, &b.output)?;
    enc.barriers(&[
        Barrier::Image {
            image: &b.output,
            before: S::CopyDest,
            after: S::Engine(f.output_layout_after),
        },
        Barrier::Image {
            image: vis,
            before: S::CopySource,
            after: S::UnorderedAccess,
        },
    ]);
    enc.end_pass();
    Ok(())
}

/// The camera and light of a frame (every field checked).
fn frame_inputs(f: &HrtsFrame) -> ApiResult<FrameInputs> {
    finite(&f.view, "view")?;
    finite(&f.proj, "proj")?;
    finite(&f.camera_position, "camera_position")?;
    finite(&f.light_direction, "light_direction")?;
    finite(&f.light_view_proj, "light_view_proj")?;
    finite(&f.light_position, "light_position")?;
    let dir = Vec3::from_array(f.light_direction);
    if dir.length_squared() == 0.0 {
        return Err(invalid("light_direction is zero"));
    }
    let view_proj = mat4(&f.light_view_proj);
    let spot = enum_value(
        f.light_type,
        &[
            (HrtsLightType::Directional as u32, false),
            (HrtsLightType::Spot as u32, true),
        ],
        "light_type",
        "HrtsLightType",
    )?;
    // Passed on as given: the passes normalise in f64 (normalising here in f32 would round twice).
    let direction = dir;
    let light = if spot {
        Light::Spot {
            position: Vec3::from_array(f.light_position),
            direction,
            view_proj,
        }
    } else {
        Light::Directional {
            direction,
            view_proj,
        }
    };
    Ok(FrameInputs {
        view: mat4(&f.view),
        proj: mat4(&f.proj),
        camera_position: Vec3::from_array(f.camera_position),
        light,
    })
}

fn enum_value<T>(value: u32, variants: &[(u32, T)], field: &str, type_name: &str) -> ApiResult<T>
where
    T: Copy,
{
    variants
        .iter()
        .find(|(v, _)| *v == value)
        .map(|(_, t)| *t)
        .ok_or_else(|| {
            ApiError::new(
                HrtsResult::ErrorInvalidEnum,
                format!("{field} {value} is not a {type_name} value"),
            )
        })
}

fn positive(value: f32, field: &str) -> ApiResult<f32> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(invalid(format!(
            "{field} must be a positive finite number, got {value}"
        )))
    }
}

fn non_negative(value: f32, field: &str) -> ApiResult<f32> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(invalid(format!(
            "{field} must be a non-negative finite number, got {value}"
        )))
    }
}

fn taps(value: u32, field: &str) -> ApiResult<u32> {
    if (1..=256).contains(&value) {
        Ok(value)
    } else {
        Err(invalid(format!(
            "{field} must be within 1..=256, got {value}"
        )))
    }
}

/// `HrtsShadowMode` values and the modes they name (both directions use this one table).
const MODES: [(u32, ShadowMode); 4] = [
    (HrtsShadowMode::None as u32, ShadowMode::None),
    (HrtsShadowMode::Hard as u32, ShadowMode::Hard),
    (HrtsShadowMode::Soft as u32, ShadowMode::Soft),
    (HrtsShadowMode::Hybrid as u32, ShadowMode::Hybrid),
];

/// `HrtsFaces` values.
const FACES: [(u32, FaceMode); 2] = [
    (HrtsFaces::Both as u32, FaceMode::Both),
    (HrtsFaces::FrontOnly as u32, FaceMode::FrontOnly),
];

/// The C value of a binning path in use.
fn binning_path_to_c(path: BinningPath) -> HrtsBinningPath {
    match path {
        BinningPath::Compute => HrtsBinningPath::Compute,
        BinningPath::Hardware(_) => HrtsBinningPath::Hardware,
        BinningPath::Software => HrtsBinningPath::Software,
        BinningPath::EmulatedTier1 { .. } => HrtsBinningPath::EmulatedTier1,
    }
}

/// `HrtsBinningPath` values as requests.
const BINNING_REQUESTS: [(u32, BinningRequest); 5] = [
    (HrtsBinningPath::Auto as u32, BinningRequest::Auto),
    (HrtsBinningPath::Compute as u32, BinningRequest::Compute),
    (HrtsBinningPath::Hardware as u32, BinningRequest::Hardware),
    (HrtsBinningPath::Software as u32, BinningRequest::Software),
    (
        HrtsBinningPath::EmulatedTier1 as u32,
        BinningRequest::EmulateTier1,
    ),
];

/// `HrtsPenumbraFilter` values.
const FILTERS: [(u32, PenumbraFilter); 2] = [
    (
        HrtsPenumbraFilter::Shrinking as u32,
        PenumbraFilter::Shrinking,
    ),
    (
        HrtsPenumbraFilter::Standard as u32,
        PenumbraFilter::Standard,
    ),
];

/// The C value of `value` in `table` (every table covers its whole Rust enum).
fn c_value<T: PartialEq>(value: T, table: &[(u32, T)]) -> u32 {
    table
        .iter()
        .find(|(_, t)| *t == value)
        .map_or(u32::MAX, |&(c, _)| c)
}

/// The plugin's configuration from the C one (every field checked).
fn shadow_config(c: &HrtsConfig) -> ApiResult<ShadowConfig> {
    check_size::<HrtsConfig>(c.struct_size, "HrtsConfig")?;
    let mode = enum_value(c.mode, &MODES, "mode", "HrtsShadowMode")?;
    let faces = enum_value(c.faces, &FACES, "faces", "HrtsFaces")?;
    let binning = enum_value(
        c.binning_path,
        &BINNING_REQUESTS,
        "binning_path",
        "HrtsBinningPath",
    )?;
    if u64::from(c.map_entry_budget_kib) << 10 < passes::MIN_ENTRY_BUDGET {
        return Err(invalid(format!(
            "map_entry_budget_kib {} is below the minimum of {}",
            c.map_entry_budget_kib,
            passes::MIN_ENTRY_BUDGET >> 10
        )));
    }
    let filter = enum_value(c.pcss_filter, &FILTERS, "pcss_filter", "HrtsPenumbraFilter")?;
    if c.extra_outputs >> HRTS_RESOURCE_COUNT != 0 {
        return Err(ApiError::new(
            HrtsResult::ErrorInvalidEnum,
            format!(
                "extra_outputs 0x{:x} has bits of no HrtsResource",
                c.extra_outputs
            ),
        ));
    }
    let extra_outputs = RESOURCES
        .iter()
        .enumerate()
        .filter(|(i, _)| c.extra_outputs & 1 << i != 0)
        .fold(ResourceSet::EMPTY, |set, (_, &r)| set.with(r));
    let mut config = ShadowConfig {
        mode,
        antialiasing: c.antialiasing,
        static_light: c.static_light,
        static_geometry: !c.dynamic_geometry,
        extra_outputs,
        map: PrimitiveMapConfig {
            size: c.map_size,
            faces,
            binning,
            entry_budget: u64::from(c.map_entry_budget_kib) << 10,
            guard: c.guard_entries,
            receiver_culling: !c.debug_bin_all_texels,
            initial_entries: c.map_initial_entries,
        },
        ..ShadowConfig::default()
    };
    config.shadow_map.size = c.shadow_map_size;
    config.shadow_map.constant_bias =
        non_negative(c.shadow_map_constant_bias, "shadow_map_constant_bias")?;
    config.shadow_map.slope_bias = non_negative(c.shadow_map_slope_bias, "shadow_map_slope_bias")?;
    config.pcss.filter = filter;
    config.pcss.max_search_radius = positive(c.pcss_max_search_radius, "pcss_max_search_radius")?;
    config.pcss.min_filter_radius =
        non_negative(c.pcss_min_filter_radius, "pcss_min_filter_radius")?;
    config.pcss.max_filter_radius = positive(c.pcss_max_filter_radius, "pcss_max_filter_radius")?;
    config.pcss.angular_radius = positive(c.pcss_angular_radius, "pcss_angular_radius")?;
    config.pcss.spot_radius = positive(c.pcss_spot_radius, "pcss_spot_radius")?;
    config.pcss.blocker_search_taps = taps(c.pcss_blocker_search_taps, "pcss_blocker_search_taps")?;
    config.pcss.pcf_taps = taps(c.pcss_pcf_taps, "pcss_pcf_taps")?;
    config.hybrid.world_space_scale =
        positive(c.hybrid_world_space_scale, "hybrid_world_space_scale")?;
    config.hybrid.hard_shadow_percentage = positive(
        c.hybrid_hard_shadow_percentage,
        "hybrid_hard_shadow_percentage",
    )?;
    config.pcss.validate()?;
    Ok(config)
}

/// The C configuration of `config`, the inverse of [`shadow_config`]. Fails if an extra output has no
/// `HrtsResource` value.
pub(crate) fn config_to_c(config: &ShadowConfig) -> ApiResult<HrtsConfig> {
    let extra_outputs = config.extra_outputs.iter().try_fold(0u32, |bits, r| {
        resource_index(r).map(|i| bits | 1 << i).map_err(|_| {
            invalid(format!(
                "{} cannot be requested through the C ABI",
                r.name()
            ))
        })
    })?;
    Ok(HrtsConfig {
        struct_size: std::mem::size_of::<HrtsConfig>() as u32,
        mode: c_value(config.mode, &MODES),
        antialiasing: config.antialiasing,
        static_light: config.static_light,
        map_size: config.map.size,
        map_entry_budget_kib: (config.map.entry_budget >> 10).min(u64::from(u32::MAX)) as u32,
        faces: c_value(config.map.faces, &FACES),
        binning_path: c_value(config.map.binning, &BINNING_REQUESTS),
        shadow_map_size: config.shadow_map.size,
        pcss_angular_radius: config.pcss.angular_radius,
        pcss_spot_radius: config.pcss.spot_radius,
        pcss_blocker_search_taps: config.pcss.blocker_search_taps,
        pcss_pcf_taps: config.pcss.pcf_taps,
        hybrid_world_space_scale: config.hybrid.world_space_scale,
        hybrid_hard_shadow_percentage: config.hybrid.hard_shadow_percentage,
        pcss_filter: c_value(config.pcss.filter, &FILTERS),
        pcss_max_search_radius: config.pcss.max_search_radius,
        pcss_min_filter_radius: config.pcss.min_filter_radius,
        pcss_max_filter_radius: config.pcss.max_filter_radius,
        shadow_map_constant_bias: config.shadow_map.constant_bias,
        shadow_map_slope_bias: config.shadow_map.slope_bias,
        dynamic_geometry: !config.static_geometry,
        extra_outputs,
        guard_entries: config.map.guard,
        debug_bin_all_texels: !config.map.receiver_culling,
        map_initial_entries: config.map.initial_entries,
    })
}

/// Fills `out` with the defaults of [`ShadowConfig::default`].
pub(crate) fn config_defaults(out: &mut HrtsConfig) -> ApiResult<()> {
    check_size::<HrtsConfig>(out.struct_size, "HrtsConfig")?;
    *out = config_to_c(&ShadowConfig::default())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c_pass_values_are_the_pipeline_order() {
        let pairs = [
            (HrtsPass::PrimBuffer, PassId::PrimBuffer),
            (HrtsPass::ShadowMap, PassId::ShadowMap),
            (HrtsPass::PrimitiveMap, PassId::PrimitiveMap),
            (HrtsPass::Occupancy, PassId::Occupancy),
            (HrtsPass::RayTrace, PassId::RayTrace),
            (HrtsPass::ShadowMapTest, PassId::ShadowMapTest),
            (HrtsPass::Pcss, PassId::Pcss),
            (HrtsPass::Fxaa, PassId::Fxaa),
            (HrtsPass::LerpFactor, PassId::LerpFactor),
            (HrtsPass::Blend, PassId::Blend),
            (HrtsPass::FillLit, PassId::FillLit),
        ];
        assert_eq!(pairs.len(), PassId::ALL.len());
        for (c, rust) in pairs {
            assert_eq!(pass_from_index(c as u32), Some(rust));
        }
        assert_eq!(pass_from_index(HrtsPass::OutputCopy as u32), None);
        assert_eq!(HrtsPass::OutputCopy as usize + 1, HRTS_PASS_COUNT);
        assert_eq!(HRTS_PASS_MASK_ALL, (1 << HRTS_PASS_COUNT) - 1);
        assert_eq!(
            HRTS_PASS_MASK_LIGHT_SPACE | HRTS_PASS_MASK_SCREEN_SPACE,
            HRTS_PASS_MASK_ALL
        );
        assert_eq!(HRTS_PASS_MASK_LIGHT_SPACE & HRTS_PASS_MASK_SCREEN_SPACE, 0);
        assert_eq!(HRTS_PASS_MASK_LIGHT_SPACE & DEPTH_NORMAL_READERS, 0);
    }

    #[test]
    fn c_resource_values_name_the_pipeline_resources() {
        let pairs = [
            (HrtsResource::ShadowMap, ResourceId::ShadowMap),
            (HrtsResource::PrimListOffsets, ResourceId::PrimListOffsets),
            (HrtsResource::PrimListEntries, ResourceId::PrimListEntries),
            (HrtsResource::Occupancy, ResourceId::Occupancy),
            (HrtsResource::RtVisibility, ResourceId::RtVisibility),
            (HrtsResource::BlockerDistance, ResourceId::BlockerDistance),
            (
                HrtsResource::ShadowMapVisibility,
                ResourceId::ShadowMapVisibility,
            ),
            (HrtsResource::Pcss, ResourceId::Pcss),
            (HrtsResource::RtAntialiased, ResourceId::RtAntialiased),
            (HrtsResource::LerpFactor, ResourceId::LerpFactor),
            (HrtsResource::Hybrid, ResourceId::Hybrid),
            (HrtsResource::Lit, ResourceId::Lit),
        ];
        assert_eq!(pairs.len(), HRTS_RESOURCE_COUNT);
        for (c, rust) in pairs {
            assert_eq!(resource_id(c as u32).ok(), Some(rust));
            assert_eq!(resource_index(rust).ok(), Some(c as u32));
        }
        assert!(resource_id(HRTS_RESOURCE_COUNT as u32).is_err());
    }

    #[test]
    fn configurations_round_trip_through_c() {
        let mut c = config_to_c(&ShadowConfig::default()).expect("defaults");
        config_defaults(&mut c).expect("defaults");
        assert_eq!(shadow_config(&c).expect("valid"), ShadowConfig::default());
        let mut other = ShadowConfig {
            mode: ShadowMode::Soft,
            antialiasing: false,
            static_geometry: false,
            static_light: true,
            extra_outputs: ResourceSet::of(&[ResourceId::RtVisibility, ResourceId::Lit]),
            ..ShadowConfig::default()
        };
        other.map.faces = FaceMode::FrontOnly;
        other.map.binning = BinningRequest::EmulateTier1;
        other.map.guard = true;
        other.pcss.filter = PenumbraFilter::Standard;
        other.shadow_map.slope_bias = 2.5;
        let c = config_to_c(&other).expect("representable");
        assert_eq!(shadow_config(&c).expect("valid"), other);
        other.extra_outputs = ResourceSet::of(&[ResourceId::PrimBuffer]);
        assert!(config_to_c(&other).is_err());
    }
}

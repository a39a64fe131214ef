//! The demo's frames through the plugin's C ABI, the way an engine integrates it. The demo owns the
//! device, the scene's vertex and index buffers, a G-buffer and the visibility image (a layer per
//! light: the plugin shades any number of lights, each with its own configuration); the plugin adopts
//! the device (`hrts_context_create`), reads the scene from the demo's buffers
//! (`hrts_set_geometry_vulkan_meshes`) and records into the demo's command buffer (`hrts_record_passes`): the
//! light-space passes before the G-buffer, the screen-space passes and the output copy after it. Debug
//! images come back through `hrts_record_resource_readback`, the report through `hrts_get_frame_report`.
//! So what the demo shows is what an integrator gets.

use crate::gbuffer::{GBufferLayout, GBufferPass, GBufferPush, GBufferTargets};
use crate::{read_images, upload_scene, CameraMatrices, FrameImages, FrameOutput, View};
use anyhow::{bail, Context as _, Result};
use glam::Mat4;
use hrts::*;
use passes::prim_buffer::PrimBufferPass;
use passes::MapStats;
use passes::{
    BinningPath, FrameInputs, FrameReport, Geometry, Light, PassId, PassStatus, ResourceId,
    ResourceReport, ShadowConfig, SkipReason,
};
use rhi::{
    Barrier, Buffer, BufferUsage, ConservativeRasterTier, Device, Format, GpuTimer, Image,
    ImageDesc, ImageUsage, MemoryLocation, PassTiming, ResourceState as S,
};
use scene::{Aabb, Scene};
use std::ffi::{c_char, CStr, CString};

/// The line the demo's commands print first: the device and the plugin's API version.
pub fn device_banner(caps: &rhi::Capabilities) -> String {
    format!(
        "device: {} ({}, {}); shadows through the plugin's C ABI, {}",
        caps.device_name,
        caps.device_type,
        caps.driver,
        api_version()
    )
}

/// "libhrts API major.minor.patch", as the loaded library reports it.
pub fn api_version() -> String {
    let v = hrts_get_api_version();
    format!(
        "libhrts API {}.{}.{}",
        v >> 22,
        (v >> 12) & 0x3ff,
        v & 0xfff
    )
}

/// A live plugin context, destroyed on drop.
struct Context(*mut HrtsContext);

impl Context {
    /// Turns a result code into an error carrying the context's message.
    fn check(&self, call: &str, result: HrtsResult) -> Result<()> {
        if result == HrtsResult::Ok {
            return Ok(());
        }
        // SAFETY: `self.0` is live; both strings are NUL-terminated and outlive this statement.
        let (name, message) = unsafe {
            (
                CStr::from_ptr(hrts_result_name(result as i32)),
                CStr::from_ptr(hrts_last_error(self.0)),
            )
        };
        bail!(
            "{call}: {} ({})",
            name.to_string_lossy(),
            message.to_string_lossy()
        )
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // SAFETY: created by hrts_context_create and destroyed only here; the demo waited for its GPU work.
        unsafe { hrts_context_destroy(self.0) };
    }
}

/// What one plugin light's passes did in a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LightFrameReport {
    /// The plugin's report of the light, as the Rust [`FrameReport`].
    pub report: FrameReport,
    /// How many times the plugin built the light's passes since the context was created
    /// (`HrtsFrameReport::light_builds`).
    pub light_builds: u32,
    /// Frusta the plugin shadowed the light through this frame (`HrtsFrameReport::frusta`: up to 6 for a
    /// point light).
    pub frusta: u32,
    /// Frusta of the light the plugin skipped this frame, holding no receiver in view within range
    /// (`HrtsFrameReport::frusta_culled`).
    pub frusta_culled: u32,
    /// The plugin's decision for the light, in words (`HrtsFrameReport::decision_reason`).
    pub decision: String,
    /// GPU milliseconds of all of the light's passes (`HrtsFrameReport::gpu_milliseconds`).
    pub gpu_ms: f64,
}

/// What a frame of several lights did.
#[derive(Debug, Clone, PartialEq)]
pub struct LightsFrame {
    /// The frame's index (`HrtsFrame::frame_index`).
    pub frame_index: u64,
    /// One report per plugin light, in configuration order (none when no light was given to the plugin).
    pub lights: Vec<LightFrameReport>,
    /// The demo's own GPU times (the G-buffer) and, when the plugin recorded passes, [`SCREEN_SPACE_WALL`].
    pub host_timings: Vec<PassTiming>,
}

/// The demo frame driven through the C ABI, for any number of lights: the plugin gets the lights it is
/// configured with (none: it records nothing, and the demo draws its G-buffer alone), and writes light
/// `i`'s visibility to layer `i` of the demo's visibility image.
pub struct PluginRenderer {
    context: Context,
    geometry: Geometry,
    prim_buffer: PrimBufferPass,
    gbuffer: GBufferPass,
    targets: GBufferTargets,
    /// The visibility image, one layer per light (none before lights are configured).
    output: Option<Image>,
    /// Visibility images replaced by one with more layers: the plugin retired the passes writing them
    /// once the frames recorded so far complete, so they are kept as long as the renderer.
    replaced_outputs: Vec<Image>,
    /// The configurations the plugin holds, one per light.
    configured: Vec<ShadowConfig>,
    /// Usage of the visibility image: with storage usage, each light's last pass writes its layer
    /// directly (its final output can then only be read from the visibility image).
    output_usage: ImageUsage,
    timer: GpuTimer,
    dynamic_geometry: bool,
    /// The bounds of the shadow casters, given with every frame: the demo does not animate its scenes, so
    /// they hold in every frame even when the geometry counts as moving.
    bounds: Aabb,
    frames: u64,
    frames_with_plugin_passes: u64,
    native_tier: ConservativeRasterTier,
    /// The camera of the last frame: a compact G-buffer's read-back rebuilds positions and world normals
    /// through it.
    last_camera: Option<CameraMatrices>,
}

impl PluginRenderer {
    /// Uploads `view`'s scene into the demo's buffers, creates the G-buffer and the visibility image for
    /// its size, and a plugin context on `device` configured with `config` (one light), asking for the
    /// blocker distance when it traces rays (the demo compares it with the exact reference).
    pub fn new(device: &Device, view: &View, config: impl Into<ShadowConfig>) -> Result<Self> {
        Self::with_layout(device, view, config, GBufferLayout::ANALYSIS)
    }

    /// [`PluginRenderer::new`] with a G-buffer of `layout`.
    pub fn with_layout(
        device: &Device,
        view: &View,
        config: impl Into<ShadowConfig>,
        layout: GBufferLayout,
    ) -> Result<Self> {
        let config = crate::renderer::with_blocker_distance(config.into());
        let mut renderer = Self::for_scene(
            device,
            &view.scene,
            view.width,
            view.height,
            !config.static_geometry,
            layout,
        )?;
        renderer.configure_lights(device, &[config])?;
        Ok(renderer)
    }

    /// Uploads `scene` into the demo's buffers, creates the G-buffer for a `width` x `height` frame and a
    /// plugin context on `device` that has the geometry but no light yet ([`PluginRenderer::configure_lights`]).
    /// `dynamic_geometry`: the demo rebuilds its own prim buffer every frame, as the plugin does when a
    /// light's configuration says so. `layout`: what the G-buffer keeps. Every object casts shadows.
    pub fn for_scene(
        device: &Device,
        scene: &Scene,
        width: u32,
        height: u32,
        dynamic_geometry: bool,
        layout: GBufferLayout,
    ) -> Result<Self> {
        let casters = vec![true; scene.objects.len()];
        Self::for_scene_casters(
            device,
            scene,
            &casters,
            width,
            height,
            dynamic_geometry,
            layout,
        )
    }

    /// [`PluginRenderer::for_scene`] where only the objects marked in `casters` (one flag per object) cast
    /// shadows: the G-buffer draws every object, the plugin is given the casters alone (their draws, with
    /// their bounds), as an engine leaves floors or decals out of its shadow casters.
    pub fn for_scene_casters(
        device: &Device,
        scene: &Scene,
        casters: &[bool],
        width: u32,
        height: u32,
        dynamic_geometry: bool,
        layout: GBufferLayout,
    ) -> Result<Self> {
        if width == 0 || height == 0 {
            bail!("frame size must be non-zero");
        }
        if casters.len() != scene.objects.len() {
            bail!(
                "the scene has {} objects but {} shadow-caster flags",
                scene.objects.len(),
                casters.len()
            );
        }
        let bounds = scene.objects_bounds(casters);
        if !casters.iter().any(|&c| c) || bounds == Aabb::empty() {
            bail!("no object of the scene casts shadows: the plugin needs at least one caster");
        }
        let geometry = upload_scene(device, scene).context("uploading the scene")?;
        let prim_buffer = PrimBufferPass::new(device, &geometry)?;
        let gbuffer = GBufferPass::new(device, prim_buffer.prims(), &layout)?;
        let targets = GBufferTargets::new(device, width, height, layout)?;
        let context = create_context(device)?;
        set_geometry(&context, &geometry, casters, &bounds)?;
        Ok(Self {
            context,
            geometry,
            prim_buffer,
            gbuffer,
            targets,
            output: None,
            replaced_outputs: Vec::new(),
            configured: Vec::new(),
            output_usage: ImageUsage::COPY_DST | ImageUsage::COPY_SRC | ImageUsage::SAMPLED,
            timer: device.create_timer(4)?,
            dynamic_geometry,
            bounds,
            frames: 0,
            frames_with_plugin_passes: 0,
            last_camera: None,
            native_tier: device.capabilities().conservative_raster_tier,
        })
    }

    /// Gives the visibility image storage usage, as an engine whose output the lights write directly
    /// (`HrtsFrameReport::output_direct`): the final outputs are then read from it, not read back as
    /// resources. Takes effect when the lights are next configured with more layers than the image has.
    pub fn write_outputs_directly(&mut self) {
        self.output_usage = self.output_usage | ImageUsage::STORAGE;
    }

    /// Gives the plugin one configuration per light (`hrts_configure_lights`; none: later frames give the
    /// plugin nothing). The plugin keeps the passes of every light whose configuration is unchanged, unless
    /// the number of lights changes. A visibility image with too few layers is replaced
    /// (`hrts_set_targets`, which rebuilds every light).
    pub fn configure_lights(&mut self, device: &Device, configs: &[ShadowConfig]) -> Result<()> {
        if configs.is_empty() || configs == self.configured.as_slice() {
            self.configured = configs.to_vec();
            return Ok(());
        }
        let layers = configs.len() as u32;
        if self.output.as_ref().is_none_or(|o| o.layers() < layers) {
            let output = device.create_image(&ImageDesc {
                name: "visibility",
                format: Format::R32Float,
                width: self.targets.depth.width(),
                height: self.targets.depth.height(),
                layers,
                usage: self.output_usage,
            })?;
            let t = &self.targets;
            let c_targets = HrtsTargets {
                struct_size: size_of::<HrtsTargets>() as u32,
                width: t.depth.width(),
                height: t.depth.height(),
                depth_image: t.depth.raw_handle(),
                depth_usage: t.depth.raw_usage(),
                depth_format: t.depth.format().raw_vk() as u32,
                normal_image: t.normal.raw_handle(),
                normal_usage: t.normal.raw_usage(),
                normal_format: t.normal.format().raw_vk() as u32,
                normal_encoding: normal_encoding(t.layout.surface.encoding) as u32,
                normal_space: match t.layout.surface.space {
                    passes::NormalSpace::World => HrtsNormalSpace::World,
                    passes::NormalSpace::View => HrtsNormalSpace::View,
                } as u32,
                output_image: output.raw_handle(),
                output_usage: output.raw_usage(),
                output_layers: layers,
                output_format: output.format().raw_vk() as u32,
            };
            // SAFETY: live context; the images live as long as the renderer, which destroys the context
            // first.
            self.context.check("hrts_set_targets", unsafe {
                hrts_set_targets(self.context.0, &c_targets)
            })?;
            self.replaced_outputs.extend(self.output.replace(output));
        }
        let c_configs = configs
            .iter()
            .map(config_to_c)
            .collect::<Result<Vec<_>, _>>()
            .map_err(anyhow::Error::msg)?;
        // SAFETY: live context; `c_configs` holds `layers` valid configurations.
        self.context.check("hrts_configure_lights", unsafe {
            hrts_configure_lights(self.context.0, layers, c_configs.as_ptr())
        })?;
        self.configured = configs.to_vec();
        Ok(())
    }

    /// The demo's prim buffer (`GpuTriangle`s relative to the frame origin), filled by the first frame.
    pub fn prims(&self) -> &Buffer {
        self.prim_buffer.prims()
    }

    /// The demo's G-buffer; after a frame, depth and normal are in `ShaderResource` state.
    pub fn targets(&self) -> &GBufferTargets {
        &self.targets
    }

    /// The scene's geometry as uploaded.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// Frames rendered in which the plugin recorded passes (a frame without lights records none).
    pub fn frames_with_plugin_passes(&self) -> u64 {
        self.frames_with_plugin_passes
    }

    /// Renders one frame of one light ([`PluginRenderer::render_lights`]) and returns the plugin's report
    /// plus the G-buffer's GPU time and [`SCREEN_SPACE_WALL`].
    pub fn render(&mut self, device: &Device, inputs: &FrameInputs) -> Result<FrameReport> {
        let frame =
            self.render_lights(device, &CameraMatrices::of_frame(inputs), &[inputs.light])?;
        let Some(light) = frame.lights.into_iter().next() else {
            bail!("the frame reported no light");
        };
        let mut report = light.report;
        report.timings.extend(frame.host_timings);
        Ok(report)
    }

    /// Renders one frame and waits for it, in two submissions: the demo's prim buffer (first frame, or
    /// every frame with dynamic geometry), the plugin's light-space passes and the demo's G-buffer; then
    /// the plugin's screen-space passes (primitive map, ray trace, soft shadows) and output copy. `lights`
    /// holds one light per configured light (none: the plugin records nothing). Returns the plugin's
    /// report of each light, the G-buffer's GPU time and, with lights, [`SCREEN_SPACE_WALL`]: the host's
    /// wall clock of the second submission (what a CPU device such as lavapipe spends on it: its
    /// timestamps do not see compute work).
    pub fn render_lights(
        &mut self,
        device: &Device,
        camera: &CameraMatrices,
        lights: &[Light],
    ) -> Result<LightsFrame> {
        self.render_c_lights(device, camera, lights.iter().map(c_light).collect())
    }

    /// [`render_lights`](Self::render_lights) with the lights as the C ABI takes them (point lights, spot
    /// lights whose frusta the plugin fits).
    pub fn render_c_lights(
        &mut self,
        device: &Device,
        camera: &CameraMatrices,
        c_lights: Vec<HrtsLight>,
    ) -> Result<LightsFrame> {
        let lights = &c_lights;
        if lights.len() != self.configured.len() {
            bail!(
                "{} lights given for a frame, {} configured",
                lights.len(),
                self.configured.len()
            );
        }
        let push = GBufferPush::for_camera(camera, self.geometry.origin(), &self.targets.layout)?;
        self.last_camera = Some(*camera);
        let tris = self.geometry.triangle_count();
        let rebuild_prims = self.frames == 0 || self.dynamic_geometry;
        let with_plugin = !c_lights.is_empty();
        let t = &self.targets;
        let frame_in =
            |command_buffer| c_frame(command_buffer, self.frames, camera, &c_lights, &self.bounds);
        device.submit_and_wait(|enc| {
            if rebuild_prims {
                self.prim_buffer
                    .record(enc, &self.geometry, None)
                    .map_err(recording_error)?;
                enc.barriers(&[Barrier::Uav]);
            }
            enc.attach_timer(&self.timer);
            if with_plugin {
                self.record_passes(&frame_in(enc.raw_handle()), HRTS_PASS_MASK_LIGHT_SPACE)?;
            }
            enc.barriers(&t.to_render());
            self.gbuffer
                .record(enc, t, &push, tris)
                .map_err(recording_error)?;
            enc.barriers(&[
                Barrier::Image {
                    image: &t.normal,
                    before: S::RenderTarget,
                    after: S::ShaderResource,
                },
                Barrier::Image {
                    image: &t.depth,
                    before: S::DepthWrite,
                    after: S::ShaderResource,
                },
            ]);
            Ok(())
        })?;
        let mut reports = Vec::new();
        let mut host_timings = Vec::new();
        if with_plugin {
            let start = std::time::Instant::now();
            device.submit_and_wait(|enc| {
                self.record_passes(&frame_in(enc.raw_handle()), HRTS_PASS_MASK_SCREEN_SPACE)
            })?;
            let wall = start.elapsed().as_secs_f64() * 1e3;
            for light in 0..c_lights.len() as u32 {
                reports.push(self.report(self.frames, light)?);
            }
            host_timings.extend(self.timer.resolve()?);
            host_timings.push(PassTiming {
                name: SCREEN_SPACE_WALL.into(),
                ms: wall,
            });
            self.frames_with_plugin_passes += 1;
        } else {
            host_timings.extend(self.timer.resolve()?);
        }
        let frame_index = self.frames;
        self.frames += 1;
        Ok(LightsFrame {
            frame_index,
            lights: reports,
            host_timings,
        })
    }

    fn record_passes(&self, frame: &HrtsFrame, mask: u32) -> rhi::Result<()> {
        // SAFETY: live context; the command buffer is recording outside a render pass.
        let result = unsafe { hrts_record_passes(self.context.0, frame, mask) };
        self.context
            .check("hrts_record_passes", result)
            .map_err(recording_error)
    }

    /// The plugin's report of `light` in frame `frame` (completed), as the Rust [`FrameReport`].
    fn report(&self, frame: u64, light: u32) -> Result<LightFrameReport> {
        // SAFETY: plain-old-data C struct; every field is valid zeroed.
        let mut r: HrtsFrameReport = unsafe { std::mem::zeroed() };
        r.struct_size = size_of::<HrtsFrameReport>() as u32;
        // SAFETY: live context, valid out pointer.
        self.context.check("hrts_get_frame_report", unsafe {
            hrts_get_frame_report(self.context.0, frame, light, &mut r)
        })?;
        let timings = r.passes[..r.pass_count as usize]
            .iter()
            .map(|p| PassTiming {
                // SAFETY: the plugin NUL-terminates every name within the array.
                name: unsafe { CStr::from_ptr(p.name.as_ptr()) }
                    .to_string_lossy()
                    .into_owned(),
                ms: p.milliseconds,
            })
            .collect();
        let binning_path = match r.binning_path {
            v if v == HrtsBinningPath::Software as u32 => BinningPath::Software,
            v if v == HrtsBinningPath::Compute as u32 => BinningPath::Compute,
            v if v == HrtsBinningPath::EmulatedTier1 as u32 => BinningPath::EmulatedTier1 {
                native: self.native_tier,
            },
            _ => BinningPath::Hardware(match r.tier {
                1 => ConservativeRasterTier::Tier1,
                2 => ConservativeRasterTier::Tier2,
                _ => ConservativeRasterTier::Tier3,
            }),
        };
        let passes = PassId::ALL
            .iter()
            .map(|&p| {
                let status = match r.pass_status[p as usize] {
                    s if s == HrtsPassStatus::Ran as u32 => PassStatus::Ran,
                    s if s == HrtsPassStatus::UpToDate as u32 => {
                        PassStatus::Skipped(SkipReason::UpToDate)
                    }
                    s if s == HrtsPassStatus::Shared as u32 => {
                        PassStatus::Skipped(SkipReason::Shared)
                    }
                    s if s == HrtsPassStatus::Culled as u32 => {
                        PassStatus::Skipped(SkipReason::Culled)
                    }
                    _ => PassStatus::Skipped(SkipReason::NotRequested),
                };
                (p, status)
            })
            .collect();
        let mut resources: Vec<ResourceReport> = (0..HRTS_RESOURCE_COUNT as u32)
            .filter(|&h| r.resource_bytes[h as usize] > 0)
            .filter_map(|h| {
                resource_from_c(h).map(|resource| ResourceReport {
                    resource,
                    bytes: r.resource_bytes[h as usize],
                })
            })
            .collect();
        if r.prim_buffer_bytes > 0 {
            resources.insert(
                0,
                ResourceReport {
                    resource: ResourceId::PrimBuffer,
                    bytes: r.prim_buffer_bytes,
                },
            );
        }
        let output = resource_from_c(r.output_resource)
            .context("the report names an unknown output resource")?;
        let report = FrameReport {
            timings,
            binning_path,
            stats: MapStats {
                receiver_pixels: r.receiver_pixels,
                receiver_texels: r.receiver_texels,
                triangles_binned: r.triangles_binned,
                texels_with_list: r.texels_with_list,
                longest_list: r.longest_list,
                entries: r.entries,
                capacity: r.entry_capacity,
                texels_past_capacity: r.texels_past_capacity,
                pairs: r.bin_pairs,
                pair_capacity: r.bin_pair_capacity,
                texels_past_limit: r.texels_past_limit,
                bin_items: r.bin_items,
                lists_skipped: r.frusta_without_lists > 0,
                pixels_walked: r.pixels_walked,
                walks_unfinished: r.walks_unfinished,
            },
            map_to_texels: Mat4::from_cols_array(&r.map_to_texels),
            passes,
            resources,
            output,
            map_scratch_bytes: r.map_scratch_bytes,
            prim_triangles_rebuilt: r.prim_triangles_rebuilt,
        };
        Ok(LightFrameReport {
            report,
            light_builds: r.light_builds,
            frusta: r.frusta,
            frusta_culled: r.frusta_culled,
            // SAFETY: the plugin NUL-terminates the reason within the array.
            decision: unsafe { CStr::from_ptr(r.decision_reason.as_ptr()) }
                .to_string_lossy()
                .into_owned(),
            gpu_ms: r.gpu_milliseconds,
        })
    }

    /// Reads back the last frame's G-buffer and the visibility of every light (one vector per layer of
    /// the visibility image; none without lights).
    pub fn read_frame(&self, device: &Device) -> Result<(FrameImages, Vec<Vec<f32>>)> {
        let own = self.targets.outputs();
        let mut images: Vec<(&Image, S)> = own.iter().map(|&(i, s, _)| (i, s)).collect();
        let compact = self.targets.analysis.is_none();
        if compact {
            images.push((&self.targets.normal, S::ShaderResource));
            images.push((&self.targets.depth, S::ShaderResource));
        }
        let output = self.output.as_ref().filter(|_| !self.configured.is_empty());
        images.extend(output.map(|o| (o, S::ShaderResource)));
        let mut bytes = read_images(device, &images)?;
        let layers = match output {
            Some(_) => {
                let all: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes.pop().unwrap_or_default());
                let pixels =
                    self.targets.depth.width() as usize * self.targets.depth.height() as usize;
                all.chunks_exact(pixels)
                    .take(self.configured.len())
                    .map(<[f32]>::to_vec)
                    .collect()
            }
            None => Vec::new(),
        };
        let origin = self.geometry.origin();
        let mut frame = FrameImages::default();
        if compact {
            let camera = self.last_camera.context("no frame rendered")?;
            let (width, height) = (self.targets.depth.width(), self.targets.depth.height());
            let depth = bytes.pop().unwrap_or_default();
            let normal = bytes.pop().unwrap_or_default();
            frame = crate::gbuffer::decode_compact(
                &self.targets.layout,
                &camera,
                (width, height),
                &normal,
                &depth,
            )?;
        }
        for ((_, _, output), bytes) in own.iter().zip(&bytes) {
            frame.insert(*output, bytes, origin);
        }
        Ok((frame, layers))
    }

    /// Reads back the last frame of light 0 ([`PluginRenderer::read_back_light`]).
    pub fn read_back(&self, device: &Device, with_entries: bool) -> Result<FrameImages> {
        self.read_back_light(device, 0, with_entries)
    }

    /// Reads back the last frame: the demo's G-buffer, `light`'s layer of the visibility image, and every
    /// plugin resource of [`FrameImages`] the light's configuration allocates (the list entries only if
    /// `with_entries`) through `hrts_record_resource_readback`.
    pub fn read_back_light(
        &self,
        device: &Device,
        light: u32,
        with_entries: bool,
    ) -> Result<FrameImages> {
        let (mut frame, mut layers) = self.read_frame(device)?;
        if light as usize >= layers.len() {
            bail!(
                "light {light} does not exist ({} configured)",
                self.configured.len()
            );
        }
        frame.output = layers.swap_remove(light as usize);
        let origin = self.geometry.origin();
        let mut sources: Vec<(Destination, ResourceId)> = FrameOutput::PIPELINE
            .iter()
            .map(|&(output, id)| (Destination::Image(output), id))
            .collect();
        sources.push((Destination::ListOffsets, ResourceId::PrimListOffsets));
        if with_entries {
            sources.push((Destination::ListEntries, ResourceId::PrimListEntries));
        }
        let mut wanted = Vec::new();
        for &(output, id) in &sources {
            let resource = resource_to_c(id).context("a read-back resource has no C value")?;
            // SAFETY: plain-old-data C struct; every field is valid zeroed.
            let mut info: HrtsResourceInfo = unsafe { std::mem::zeroed() };
            info.struct_size = size_of::<HrtsResourceInfo>() as u32;
            // SAFETY: live context, valid out pointer.
            self.context.check("hrts_get_resource_info", unsafe {
                hrts_get_resource_info(self.context.0, light, resource, &mut info)
            })?;
            if info.allocated != 0 {
                let buffer = device.create_buffer(
                    id.name(),
                    info.bytes,
                    BufferUsage::COPY_DST,
                    MemoryLocation::GpuToCpu,
                )?;
                wanted.push((output, resource, buffer));
            }
        }
        device.submit_and_wait(|enc| {
            for (_, resource, buffer) in &wanted {
                let readback = HrtsResourceReadback {
                    struct_size: size_of::<HrtsResourceReadback>() as u32,
                    command_buffer: enc.raw_handle(),
                    resource: *resource,
                    light,
                    buffer: buffer.raw_handle(),
                    buffer_size: buffer.size(),
                    offset: 0,
                };
                // SAFETY: live context; recording command buffer; the buffer outlives the submission.
                let result = unsafe { hrts_record_resource_readback(self.context.0, &readback) };
                self.context
                    .check("hrts_record_resource_readback", result)
                    .map_err(recording_error)?;
            }
            Ok(())
        })?;
        for (output, _, buffer) in &wanted {
            let bytes = buffer.read()?;
            match *output {
                Destination::Image(image) => frame.insert(image, bytes, origin),
                Destination::ListOffsets => {
                    let packed: Vec<u32> = bytemuck::pod_collect_to_vec(bytes);
                    frame.list_offsets =
                        passes::unpack_list_offsets(&packed, passes::packed_texels(packed.len()))
                            .map_err(anyhow::Error::msg)?;
                }
                Destination::ListEntries => {
                    frame.list_entries = bytemuck::pod_collect_to_vec(bytes)
                }
            }
        }
        Ok(frame)
    }
}

/// Where a read-back resource goes in [`FrameImages`].
#[derive(Clone, Copy)]
enum Destination {
    Image(FrameOutput),
    ListOffsets,
    ListEntries,
}

/// Timing name of the host's wall clock around the screen-space submission of a frame.
pub const SCREEN_SPACE_WALL: &str = "screen-space submission (wall clock)";

/// An error while recording, in the form `Device::submit_and_wait` passes on.
fn recording_error(e: impl std::fmt::Display) -> rhi::RhiError {
    rhi::RhiError::InvalidArgument(format!("{e:#}"))
}

/// The C encoding of `encoding`.
fn normal_encoding(encoding: passes::NormalEncoding) -> HrtsNormalEncoding {
    match encoding {
        passes::NormalEncoding::XyzCoverage => HrtsNormalEncoding::XyzCoverage,
        passes::NormalEncoding::Xyz => HrtsNormalEncoding::Xyz,
        passes::NormalEncoding::Octahedral => HrtsNormalEncoding::Octahedral,
        passes::NormalEncoding::FromDepth => HrtsNormalEncoding::None,
    }
}

/// A context adopting `device`.
fn create_context(device: &Device) -> Result<Context> {
    let desc = device.adopt_desc();
    let names = desc
        .enabled_extensions
        .iter()
        .map(|n| CString::new(n.as_str()))
        .collect::<Result<Vec<_>, _>>()?;
    let name_ptrs: Vec<*const c_char> = names.iter().map(|n| n.as_ptr()).collect();
    let f = desc.enabled_features;
    let vulkan = HrtsVulkanDevice {
        struct_size: size_of::<HrtsVulkanDevice>() as u32,
        get_instance_proc_addr: Some(desc.get_instance_proc_addr),
        instance: desc.instance,
        physical_device: desc.physical_device,
        device: desc.device,
        queue_family_index: desc.queue_family_index,
        queue_index: desc.queue_index,
        enabled_extensions: name_ptrs.as_ptr(),
        enabled_extension_count: name_ptrs.len() as u32,
        geometry_shader: f.geometry_shader.into(),
        fragment_stores_and_atomics: f.fragment_stores_and_atomics.into(),
        depth_clamp: f.depth_clamp.into(),
        debug_utils: desc.debug_utils.into(),
    };
    let info = HrtsContextCreateInfo {
        struct_size: size_of::<HrtsContextCreateInfo>() as u32,
        api_version: HRTS_API_VERSION,
        vulkan: &vulkan,
        device_name_filter: std::ptr::null(),
        enable_validation: 0,
        frames_in_flight: 0,
    };
    let mut context = std::ptr::null_mut();
    // SAFETY: valid structs; the names outlive the call; the device outlives the context (the renderer
    // that holds it borrows nothing but is dropped before the demo's device by every caller).
    let result = unsafe { hrts_context_create(&info, &mut context) };
    if result != HrtsResult::Ok {
        // SAFETY: NULL context: the thread's last error.
        let message = unsafe { CStr::from_ptr(hrts_last_error(std::ptr::null())) };
        bail!(
            "hrts_context_create: {:?} ({})",
            result,
            message.to_string_lossy()
        );
    }
    Ok(Context(context))
}

/// Hands the demo's meshes (their vertex and index buffers) to the plugin with the draws of the objects
/// marked in `casters` (the demo's draws are its objects, in order, over all meshes; a mesh without a
/// caster is left out), each mesh with the casters' `bounds`, which enclose its draws given (the plugin's
/// frame origin is their centre).
fn set_geometry(
    context: &Context,
    geometry: &Geometry,
    casters: &[bool],
    bounds: &Aabb,
) -> Result<()> {
    let mut b = [0.0f32; 6];
    b[..3].copy_from_slice(&bounds.min.to_array());
    b[3..].copy_from_slice(&bounds.max.to_array());
    let mut casts = casters.iter();
    let draws: Vec<Vec<HrtsDraw>> = geometry
        .meshes()
        .iter()
        .map(|m| {
            m.draws()
                .iter()
                .filter(|_| casts.next().copied().unwrap_or(false))
                .map(|d| HrtsDraw {
                    first_index: d.first_index,
                    index_count: d.index_count,
                    transform: d.model.to_cols_array(),
                    base_vertex: d.base_vertex,
                })
                .collect()
        })
        .collect();
    let meshes: Vec<HrtsVulkanGeometry> = geometry
        .meshes()
        .iter()
        .zip(&draws)
        .filter(|(_, draws)| !draws.is_empty())
        .map(|(m, draws)| {
            let (vertices, vertex) = m.vertices();
            let (indices, index) = m.indices();
            HrtsVulkanGeometry {
                struct_size: size_of::<HrtsVulkanGeometry>() as u32,
                vertex_buffer: vertices.raw_handle(),
                vertex_buffer_size: vertices.size(),
                vertex_offset: vertex.offset,
                vertex_stride: vertex.stride,
                vertex_count: vertex.count,
                index_buffer: indices.raw_handle(),
                index_buffer_size: indices.size(),
                index_offset: index.offset,
                index_type: match index.format {
                    passes::IndexFormat::U16 => HrtsIndexType::Uint16,
                    passes::IndexFormat::U32 => HrtsIndexType::Uint32,
                } as u32,
                index_count: index.count,
                draws: draws.as_ptr(),
                draw_count: draws.len() as u32,
                bounds: b,
                vertex_format: 0,
                position_scale: [0.0; 3],
                position_offset: [0.0; 3],
                draw_stride: size_of::<HrtsDraw>(),
            }
        })
        .collect();
    // SAFETY: live context; `meshes` holds `meshes.len()` meshes whose draws outlive the call; the buffers
    // live as long as the renderer, which destroys the context first.
    context.check("hrts_set_geometry_vulkan_meshes", unsafe {
        hrts_set_geometry_vulkan_meshes(context.0, meshes.as_ptr(), meshes.len() as u32)
    })
}

/// The C light of `light`.
fn c_light(light: &Light) -> HrtsLight {
    match *light {
        Light::Directional {
            direction,
            view_proj,
        } => c_directional_light(direction, view_proj),
        Light::Spot {
            position,
            direction,
            view_proj,
        } => HrtsLight {
            light_type: HrtsLightType::Spot as u32,
            view_proj: view_proj.to_cols_array(),
            direction: direction.to_array(),
            ..c_point_light(position, 0.0)
        },
        Light::Point { position, range } => c_point_light(position, range.unwrap_or(0.0)),
    }
}

/// The C directional light travelling along `direction`, with the orthographic `view_proj` enclosing the
/// scene.
pub fn c_directional_light(direction: glam::Vec3, view_proj: glam::Mat4) -> HrtsLight {
    HrtsLight {
        light_type: HrtsLightType::Directional as u32,
        position: [0.0; 3],
        direction: direction.to_array(),
        view_proj: view_proj.to_cols_array(),
        range: 0.0,
        outer_cone: 0.0,
    }
}

/// The C point light at `position` within `range` (0: unlimited): the plugin shadows it through its cube
/// faces and writes their minimum to the light's layer.
pub fn c_point_light(position: glam::Vec3, range: f32) -> HrtsLight {
    HrtsLight {
        light_type: HrtsLightType::Point as u32,
        position: position.to_array(),
        direction: [0.0; 3],
        view_proj: [0.0; 16],
        range,
        outer_cone: 0.0,
    }
}

/// The C spot light at `position` along `direction` with a cone of half-angle `outer_cone` within `range`
/// (0: unlimited), without a matrix: the plugin fits its frusta.
pub fn c_fitted_spot_light(
    position: glam::Vec3,
    direction: glam::Vec3,
    outer_cone: f32,
    range: f32,
) -> HrtsLight {
    HrtsLight {
        light_type: HrtsLightType::Spot as u32,
        direction: direction.to_array(),
        outer_cone,
        ..c_point_light(position, range)
    }
}

/// The C frame `frame_index` of `camera` with `lights`, recorded into `command_buffer`; depth and normal
/// are sampled (`SHADER_READ_ONLY_OPTIMAL`) and the visibility image is left ready for sampling.
fn c_frame(
    command_buffer: u64,
    frame_index: u64,
    camera: &CameraMatrices,
    lights: &[HrtsLight],
    bounds: &Aabb,
) -> HrtsFrame {
    let sampled = S::ShaderResource.raw_layout();
    HrtsFrame {
        struct_size: size_of::<HrtsFrame>() as u32,
        command_buffer,
        frame_index,
        view: camera.view.to_cols_array(),
        proj: camera.proj.to_cols_array(),
        camera_position: camera.position.to_array(),
        lights: lights.as_ptr(),
        light_count: lights.len() as u32,
        depth_layout: sampled,
        normal_layout: sampled,
        output_layout_before: S::Undefined.raw_layout(),
        output_layout_after: sampled,
        bounds: [
            bounds.min.x,
            bounds.min.y,
            bounds.min.z,
            bounds.max.x,
            bounds.max.y,
            bounds.max.z,
        ],
        has_bounds: 1,
        deformed: std::ptr::null(),
        deformed_count: 0,
        light_stride: size_of::<HrtsLight>(),
        deformed_stride: size_of::<HrtsMeshVertices>(),
    }
}

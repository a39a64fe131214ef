//! The demo's frames through the plugin's safe API over its C ABI, the way an engine integrates it. The
//! demo owns the device, the scene's vertex and index buffers, a G-buffer and the visibility image (a
//! layer per light: the plugin shades any number of lights, each with its own configuration); the plugin
//! adopts the device ([`hrts::Context::adopt`]), reads the scene from the demo's buffers
//! ([`hrts::Context::set_geometry_vulkan`]) and records into the demo's command buffer
//! ([`hrts::Context::record_passes`]): the light-space passes before the G-buffer, the screen-space passes
//! and the output copy after it. Debug images come back through
//! [`hrts::Context::record_resource_readback`], the report through [`hrts::Context::frame_report`]. So
//! what the demo shows is what an integrator gets.

use crate::gbuffer::{GBufferLayout, GBufferPass, GBufferPush, GBufferTargets};
use crate::scene_buffers::SceneBuffers;
use crate::{read_images, CameraMatrices, FrameImages, FrameOutput, View};
use anyhow::{bail, Context as _, Result};
use rhi::{
    Barrier, BufferUsage, Device, Format, GpuTimer, Image, ImageDesc, ImageUsage, MemoryLocation,
    ResourceState as S,
};
use scene::{Aabb, Scene};
use std::ffi::CString;

/// `config` asking for the ray trace's blocker distance when its mode traces hard rays (hard, hybrid): the
/// demo compares blocker distances with the exact reference, and the plugin allocates them only when
/// asked (or for the hybrid).
pub fn with_blocker_distance(mut config: hrts::Config) -> hrts::Config {
    if matches!(
        config.mode,
        hrts::ShadowMode::Hard | hrts::ShadowMode::Hybrid
    ) {
        config.extra_outputs = config.extra_outputs.with(hrts::Resource::BlockerDistance);
    }
    config
}

/// What a frame of several lights did.
#[derive(Debug, Clone, PartialEq)]
pub struct LightsFrame {
    /// The frame's index ([`hrts::Frame::frame_index`]).
    pub frame_index: u64,
    /// The plugin's report of each light, in configuration order (none when no light was given to the
    /// plugin).
    pub lights: Vec<hrts::FrameReport>,
    /// The demo's own GPU times (the G-buffer) and, when the plugin recorded passes, [`SCREEN_SPACE_WALL`].
    pub host_timings: Vec<hrts::PassTiming>,
}

/// The demo frame driven through the plugin's API, for any number of lights: the plugin gets the lights
/// it is configured with (none: it records nothing, and the demo draws its G-buffer alone), and writes
/// light `i`'s visibility to layer `i` of the demo's visibility image.
pub struct PluginRenderer {
    /// The plugin's context, dropped first: it uses the buffers and images of the fields after it.
    context: hrts::Context,
    scene: SceneBuffers,
    gbuffer: GBufferPass,
    targets: GBufferTargets,
    /// The visibility image, one layer per light (none before lights are configured).
    output: Option<Image>,
    /// Visibility images replaced by one with more layers: the plugin retired the passes writing them
    /// once the frames recorded so far complete, so they are kept as long as the renderer.
    replaced_outputs: Vec<Image>,
    /// The configurations the plugin holds, one per light.
    configured: Vec<hrts::Config>,
    /// Usage of the visibility image: with storage usage, each light's last pass writes its layer
    /// directly (its final output can then only be read from the visibility image).
    output_usage: ImageUsage,
    /// Format of the visibility image: `R32Float`, `R16Float` or `R8Unorm` (read back as `f32`).
    output_format: Format,
    timer: GpuTimer,
    /// The bounds of the shadow casters, given with every frame: the demo does not animate its scenes, so
    /// they hold in every frame even when the geometry counts as moving.
    bounds: Aabb,
    frames: u64,
    frames_with_plugin_passes: u64,
    /// The camera of the last frame: a compact G-buffer's read-back rebuilds positions and world normals
    /// through it.
    last_camera: Option<CameraMatrices>,
}

impl PluginRenderer {
    /// Uploads `view`'s scene into the demo's buffers, creates the G-buffer and the visibility image for
    /// its size, and a plugin context on `device` configured with `config` (one light), asking for the
    /// blocker distance when it traces rays (the demo compares it with the exact reference).
    pub fn new(device: &Device, view: &View, config: hrts::Config) -> Result<Self> {
        Self::with_layout(device, view, config, GBufferLayout::ANALYSIS)
    }

    /// [`PluginRenderer::new`] with a G-buffer of `layout`.
    pub fn with_layout(
        device: &Device,
        view: &View,
        config: hrts::Config,
        layout: GBufferLayout,
    ) -> Result<Self> {
        let config = with_blocker_distance(config);
        let mut renderer = Self::for_scene(device, &view.scene, view.width, view.height, layout)?;
        renderer.configure_lights(device, &[config])?;
        Ok(renderer)
    }

    /// Uploads `scene` into the demo's buffers, creates the G-buffer for a `width` x `height` frame and a
    /// plugin context on `device` that has the geometry but no light yet ([`PluginRenderer::configure_lights`]).
    /// `layout`: what the G-buffer keeps. Every object casts shadows.
    pub fn for_scene(
        device: &Device,
        scene: &Scene,
        width: u32,
        height: u32,
        layout: GBufferLayout,
    ) -> Result<Self> {
        let casters = vec![true; scene.objects.len()];
        Self::for_scene_casters(device, scene, &casters, width, height, layout)
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
        let scene = SceneBuffers::upload(device, scene).context("uploading the scene")?;
        let draws = scene.caster_draws(casters);
        let mesh = scene.plugin_mesh(&draws, plugin_bounds(&bounds));
        let context = create_context(device)?;
        // SAFETY: the buffers are the demo device's, of their sizes; they live as long as the renderer,
        // which drops the context first.
        unsafe { context.set_geometry_vulkan(&[mesh]) }?;
        let gbuffer = GBufferPass::new(device, &scene, &layout)?;
        let targets = GBufferTargets::new(device, width, height, layout)?;
        Ok(Self {
            context,
            scene,
            gbuffer,
            targets,
            output: None,
            replaced_outputs: Vec::new(),
            configured: Vec::new(),
            output_usage: ImageUsage::COPY_DST | ImageUsage::COPY_SRC | ImageUsage::SAMPLED,
            output_format: Format::R32Float,
            timer: device.create_timer(4)?,
            bounds,
            frames: 0,
            frames_with_plugin_passes: 0,
            last_camera: None,
        })
    }

    /// Gives the visibility image storage usage, as an engine whose output the lights write directly
    /// ([`hrts::FrameReport::output_direct`]): the final outputs are then read from it, not read back as
    /// resources. Takes effect when the lights are next configured with more layers than the image has.
    pub fn write_outputs_directly(&mut self) {
        self.output_usage = self.output_usage | ImageUsage::STORAGE;
    }

    /// Gives the visibility image `format` (`R32Float`, the default, `R16Float` or `R8Unorm`), as an
    /// engine whose shadow mask is half float or 8-bit; read back, it is converted to `f32`. Takes effect
    /// when the image is next created (the lights first configured).
    pub fn set_output_format(&mut self, format: Format) {
        self.output_format = format;
    }

    /// Gives the plugin one configuration per light ([`hrts::Context::configure_lights`], each as the C
    /// ABI carries it; none: later frames give the plugin nothing). The plugin keeps the passes of every
    /// light whose configuration is unchanged, unless the number of lights changes. A visibility image with
    /// too few layers is replaced ([`hrts::Context::set_targets`], which rebuilds every light).
    pub fn configure_lights(&mut self, device: &Device, configs: &[hrts::Config]) -> Result<()> {
        if configs.is_empty() || configs == self.configured {
            self.configured = configs.to_vec();
            return Ok(());
        }
        let layers = configs.len() as u32;
        if self.output.as_ref().is_none_or(|o| o.layers() < layers) {
            let output = device.create_image(&ImageDesc {
                name: "visibility",
                format: self.output_format,
                width: self.targets.depth.width(),
                height: self.targets.depth.height(),
                layers,
                usage: self.output_usage,
            })?;
            let t = &self.targets;
            let targets = hrts::Targets {
                width: t.depth.width(),
                height: t.depth.height(),
                depth: target_image(&t.depth),
                normal: target_image(&t.normal),
                normal_encoding: t.layout.normal_encoding,
                normal_space: t.layout.normal_space,
                output: target_image(&output),
                output_layers: layers,
            };
            // SAFETY: the images are the demo device's, created as `targets` states; they live as long as
            // the renderer, which drops the context first (and keeps replaced outputs).
            unsafe { self.context.set_targets(&targets) }?;
            self.replaced_outputs.extend(self.output.replace(output));
        }
        self.context.configure_lights(configs)?;
        self.configured = configs.to_vec();
        Ok(())
    }

    /// The demo's G-buffer; after a frame, depth and normal are in `ShaderResource` state.
    pub fn targets(&self) -> &GBufferTargets {
        &self.targets
    }

    /// The scene's buffers as uploaded.
    pub fn scene(&self) -> &SceneBuffers {
        &self.scene
    }

    /// Frames rendered in which the plugin recorded passes (a frame without lights records none).
    pub fn frames_with_plugin_passes(&self) -> u64 {
        self.frames_with_plugin_passes
    }

    /// Renders one frame of one light ([`PluginRenderer::render_lights`]) and returns the plugin's report
    /// plus the G-buffer's GPU time and [`SCREEN_SPACE_WALL`].
    pub fn render_light(
        &mut self,
        device: &Device,
        camera: &CameraMatrices,
        light: hrts::Light,
    ) -> Result<hrts::FrameReport> {
        let frame = self.render_lights(device, camera, &[light])?;
        let Some(mut report) = frame.lights.into_iter().next() else {
            bail!("the frame reported no light");
        };
        report.timings.extend(frame.host_timings);
        Ok(report)
    }

    /// Renders one frame and waits for it, in two submissions: the plugin's light-space passes and the
    /// demo's G-buffer; then the plugin's screen-space passes (primitive map, ray trace, soft shadows) and
    /// output copy. `lights` holds one light per configured light, as the plugin takes it (point lights,
    /// spot lights whose frusta the plugin fits, directional lights fitted to the casters; none: the
    /// plugin records nothing). Returns the plugin's report of each light, the G-buffer's GPU time and,
    /// with lights, [`SCREEN_SPACE_WALL`]: the host's wall clock of the second submission (what a CPU
    /// device such as lavapipe spends on it: its timestamps do not see compute work).
    pub fn render_lights(
        &mut self,
        device: &Device,
        camera: &CameraMatrices,
        lights: &[hrts::Light],
    ) -> Result<LightsFrame> {
        if lights.len() != self.configured.len() {
            bail!(
                "{} lights given for a frame, {} configured",
                lights.len(),
                self.configured.len()
            );
        }
        let push = GBufferPush::for_camera(camera, self.scene.origin(), &self.targets.layout)?;
        self.last_camera = Some(*camera);
        let with_plugin = !lights.is_empty();
        let t = &self.targets;
        let frame = plugin_frame(self.frames, camera, lights, &self.bounds);
        device.submit_and_wait(|enc| {
            enc.attach_timer(&self.timer);
            if with_plugin {
                // SAFETY: the demo's recording command buffer, outside a render pass, submitted and waited
                // for here.
                unsafe {
                    self.context.record_passes(
                        enc.raw_handle(),
                        &frame,
                        hrts::PassMask::LIGHT_SPACE,
                    )
                }
                .map_err(recording_error)?;
            }
            enc.barriers(&t.to_render());
            self.gbuffer
                .record(enc, t, &push, &self.scene)
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
                // SAFETY: as for the light-space passes.
                unsafe {
                    self.context.record_passes(
                        enc.raw_handle(),
                        &frame,
                        hrts::PassMask::SCREEN_SPACE,
                    )
                }
                .map_err(recording_error)
            })?;
            let wall = start.elapsed().as_secs_f64() * 1e3;
            for light in 0..lights.len() as u32 {
                reports.push(self.context.frame_report(self.frames, light)?);
            }
            host_timings.extend(self.host_timings()?);
            host_timings.push(hrts::PassTiming {
                name: SCREEN_SPACE_WALL.into(),
                milliseconds: wall,
            });
            self.frames_with_plugin_passes += 1;
        } else {
            host_timings.extend(self.host_timings()?);
        }
        let frame_index = self.frames;
        self.frames += 1;
        Ok(LightsFrame {
            frame_index,
            lights: reports,
            host_timings,
        })
    }

    /// The G-buffer's GPU time of the frame last submitted, as the plugin's reports give times.
    fn host_timings(&self) -> Result<Vec<hrts::PassTiming>> {
        Ok(self
            .timer
            .resolve()?
            .into_iter()
            .map(|t| hrts::PassTiming {
                name: t.name,
                milliseconds: t.ms,
            })
            .collect())
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
                let all = visibility_values(self.output_format, &bytes.pop().unwrap_or_default());
                let pixels =
                    self.targets.depth.width() as usize * self.targets.depth.height() as usize;
                all.chunks_exact(pixels)
                    .take(self.configured.len())
                    .map(<[f32]>::to_vec)
                    .collect()
            }
            None => Vec::new(),
        };
        let origin = self.scene.origin();
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
    /// `with_entries`) through [`hrts::Context::record_resource_readback`].
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
        let origin = self.scene.origin();
        let mut sources: Vec<(Destination, hrts::Resource)> = FrameOutput::PIPELINE
            .iter()
            .map(|&(output, resource)| (Destination::Image(output), resource))
            .collect();
        sources.push((Destination::ListOffsets, hrts::Resource::PrimListOffsets));
        if with_entries {
            sources.push((Destination::ListEntries, hrts::Resource::PrimListEntries));
        }
        let mut wanted = Vec::new();
        for &(output, resource) in &sources {
            if let Some(info) = self.context.resource_info(light, resource)? {
                let buffer = device.create_buffer(
                    resource.name(),
                    info.bytes,
                    BufferUsage::COPY_DST,
                    MemoryLocation::GpuToCpu,
                )?;
                wanted.push((output, resource, buffer));
            }
        }
        device.submit_and_wait(|enc| {
            for (_, resource, buffer) in &wanted {
                let readback = hrts::ResourceReadback {
                    resource: *resource,
                    light,
                    buffer: buffer.raw_handle(),
                    buffer_size: buffer.size(),
                    offset: 0,
                };
                // SAFETY: the demo's recording command buffer, outside a render pass; the buffer is the
                // demo device's, of its size, and outlives the submission waited for here.
                unsafe {
                    self.context
                        .record_resource_readback(enc.raw_handle(), &readback)
                }
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
                    frame.list_offsets = hrts::unpack_list_offsets(&packed)?;
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

/// One of the demo's images as the plugin takes it.
fn target_image(image: &Image) -> hrts::TargetImage {
    hrts::TargetImage {
        image: image.raw_handle(),
        usage: image.raw_usage(),
        format: image.format().raw_vk() as u32,
    }
}

/// The plugin's bounds of `bounds`.
fn plugin_bounds(bounds: &Aabb) -> hrts::Bounds {
    hrts::Bounds {
        min: bounds.min,
        max: bounds.max,
    }
}

/// A context adopting `device`.
fn create_context(device: &Device) -> Result<hrts::Context> {
    let desc = device.adopt_desc();
    let f = desc.enabled_features;
    let vulkan = hrts::VulkanDevice {
        get_instance_proc_addr: Some(desc.get_instance_proc_addr),
        instance: desc.instance,
        physical_device: desc.physical_device,
        device: desc.device,
        queue_family_index: desc.queue_family_index,
        queue_index: desc.queue_index,
        enabled_extensions: desc
            .enabled_extensions
            .iter()
            .map(|n| CString::new(n.as_str()))
            .collect::<Result<_, _>>()?,
        geometry_shader: f.geometry_shader,
        fragment_stores_and_atomics: f.fragment_stores_and_atomics,
        depth_clamp: f.depth_clamp,
        debug_utils: desc.debug_utils,
    };
    // SAFETY: the handles are the demo's live device, as it was created; it outlives the context (the
    // renderer that holds it borrows nothing but is dropped before the demo's device by every caller).
    Ok(unsafe { hrts::Context::adopt(&vulkan, 0) }?)
}

/// Frame `frame_index` of `camera` with `lights`; depth and normal are sampled
/// (`SHADER_READ_ONLY_OPTIMAL`) and the visibility image is left ready for sampling.
fn plugin_frame<'a>(
    frame_index: u64,
    camera: &CameraMatrices,
    lights: &'a [hrts::Light],
    bounds: &Aabb,
) -> hrts::Frame<'a> {
    let sampled = S::ShaderResource.raw_layout();
    hrts::Frame {
        frame_index,
        view: camera.view,
        proj: camera.proj,
        camera_position: camera.position,
        lights,
        depth_layout: sampled,
        normal_layout: sampled,
        output_layout_before: S::Undefined.raw_layout(),
        output_layout_after: sampled,
        bounds: Some(plugin_bounds(bounds)),
        deformed: &[],
    }
}

/// The visibility values of an image of `format` (`R32Float`, `R16Float` or `R8Unorm`) read back as bytes.
fn visibility_values(format: Format, bytes: &[u8]) -> Vec<f32> {
    match format {
        Format::R16Float => bytes
            .chunks_exact(2)
            .map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32())
            .collect(),
        Format::R8Unorm => bytes.iter().map(|&b| f32::from(b) / 255.0).collect(),
        _ => bytemuck::pod_collect_to_vec(bytes),
    }
}

//! The render world: the plugin's context on Bevy's device, each shadowed light tagged for the replaced
//! shadow module, the targets (the camera's prepasses, the visibility array and the depth array Bevy's PBR
//! shader reads), and the frame recorded between Bevy's prepass and main pass.

use crate::device::SharedFeatures;
use crate::extract::{mat4, vec3, ExtractedScene, SceneLight};
use crate::HrtsStatus;
use anyhow::{anyhow, Context as _, Result};
use bevy::core_pipeline::core_3d::prepare_prepass_textures;
use bevy::core_pipeline::prepass::{DepthPrepass, NormalPrepass, ViewPrepassTextures};
use bevy::core_pipeline::schedule::{Core3d, Core3dSystems};
use bevy::pbr::{
    prepare_lights, ExtractedDirectionalLight, ExtractedPointLight, ViewShadowBindings,
};
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::render_resource::{Texture, TextureView};
use bevy::render::renderer::{RenderAdapter, RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::sync_world::MainEntity;
use bevy::render::view::ExtractedView;
use bevy::render::{Render, RenderApp, RenderSystems};
use hrts_wgpu::{ShadowFrame, ShadowTargets, Shadows, SpanTimer};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// Frames the plugin's context keeps in flight (Bevy's renderer waits for no frame of its own).
const FRAMES_IN_FLIGHT: u32 = 3;

/// The plugin's settings, in both worlds.
#[derive(Resource, Clone)]
pub(crate) struct PluginSettings {
    /// The configuration every light starts from.
    pub(crate) config: hrts::Config,
    /// The core features of Bevy's device, once created.
    pub(crate) enabled: SharedFeatures,
    /// What the render world reports to the main world.
    pub(crate) status: SharedStatus,
}

/// [`HrtsStatus`] as the render world last wrote it.
#[derive(Clone, Default)]
pub(crate) struct SharedStatus(Arc<Mutex<HrtsStatus>>);

impl SharedStatus {
    fn lock(&self) -> MutexGuard<'_, HrtsStatus> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Copies the render world's status into the main world's [`HrtsStatus`].
pub(crate) fn publish_status(shared: SharedStatus) -> impl FnMut(ResMut<HrtsStatus>) {
    move |mut status| *status = shared.lock().clone()
}

/// The visibility array the plugin writes and the depth array Bevy's shader reads it from.
struct Mask {
    size: (u32, u32),
    layers: u32,
    /// `R32Float`, one layer per light: the plugin's output.
    visibility: Texture,
    /// `Depth32Float`, the same layers: bound where Bevy binds its directional shadow maps.
    depth: Texture,
    depth_view: TextureView,
    layer_views: Vec<TextureView>,
    fill_bind_group: wgpu::BindGroup,
}

/// The pass copying the visibility into the depth array.
struct Fill {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

/// The render world's state.
#[derive(Resource, Default)]
pub(crate) struct RenderState {
    shadows: Option<Mutex<Shadows>>,
    fill: Option<Fill>,
    mask: Option<Mask>,
    /// The configurations given to the plugin, one per light.
    configs: Vec<hrts::Config>,
    geometry_set: bool,
    /// The raw images the targets were last set with.
    targets: Option<[u64; 3]>,
    /// The render-world view shadowed this frame, and its lights.
    view: Option<Entity>,
    lights: Vec<SceneLight>,
    bounds: [glam::Vec3; 2],
    /// Frames recorded.
    frames: u64,
    /// Frames completed on the GPU (every frame below this one has).
    completed: Arc<AtomicU64>,
    /// The frames in flight: each one's index and number of lights, oldest first.
    in_flight: std::collections::VecDeque<(u64, u32)>,
    /// Times each frame's span on the GPU, from the plugin's first pass to the end of the copy.
    span: Option<SpanTimer>,
    /// The meshes changed since the plugin last took them.
    geometry_dirty: bool,
    /// A 1×1 depth array of 1.0 (lit), one layer per light: what the views read when the plugin does not
    /// shadow them.
    lit: Option<(u32, Texture, TextureView)>,
    /// The view and projection (Vulkan clip conventions) of the last frame recorded.
    matrices: Option<(Mat4, Mat4)>,
    /// Bevy's device, to wait for the plugin's frames before its context goes.
    device: Option<wgpu::Device>,
}

impl Drop for RenderState {
    /// Waits for the GPU before the context goes: it may free nothing a frame in flight uses.
    fn drop(&mut self) {
        if let Some(device) = &self.device {
            let _ = device.poll(wgpu::PollType::wait_indefinitely());
        }
    }
}

/// Adds the render world's resources and systems.
pub(crate) fn add_render_systems(app: &mut App) {
    let settings = app.world().resource::<PluginSettings>().clone();
    let capture = app.world().resource::<HrtsCapture>().clone();
    let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
        return;
    };
    render_app
        .insert_resource(settings)
        .insert_resource(capture)
        .init_resource::<RenderState>()
        .add_systems(
            Render,
            (
                tag_lights
                    .in_set(RenderSystems::CreateViews)
                    .before(prepare_lights),
                prepare_shadows
                    .in_set(RenderSystems::PrepareResources)
                    .after(prepare_prepass_textures),
                (capture_visibility, span_submitted).in_set(RenderSystems::Cleanup),
            ),
        )
        .add_systems(
            Core3d,
            record_shadows
                .after(Core3dSystems::Prepass)
                .before(Core3dSystems::MainPass),
        );
}

/// Tags the depth bias of each light the plugin shadows with -(layer + 1), for the replaced shadow module
/// (every view reads such a light's layer: the plugin's visibility, or 1 where the plugin did not shadow
/// the view).
fn tag_lights(
    scene: Res<ExtractedScene>,
    mut points: Query<(&MainEntity, &mut ExtractedPointLight)>,
    mut suns: Query<(&MainEntity, &mut ExtractedDirectionalLight)>,
) {
    let layer = |main: &MainEntity| {
        scene
            .lights
            .iter()
            .position(|l| l.entity == main.id())
            .map(|i| -(i as f32 + 1.0))
    };
    // Volumetric fog samples shadow maps the plugin's lights no longer have: it is not lit by them.
    for (main, mut light) in &mut points {
        if let Some(tag) = layer(main) {
            light.shadow_depth_bias = tag;
            light.volumetric = false;
        }
    }
    for (main, mut light) in &mut suns {
        if let Some(tag) = layer(main) {
            light.shadow_depth_bias = tag;
            light.volumetric = false;
        }
    }
}

/// The configuration of one light: the plugin's, with the light's mode and size.
fn light_config(base: &hrts::Config, light: &SceneLight) -> hrts::Config {
    let mut config = hrts::Config {
        mode: light.mode.unwrap_or(hrts::ShadowMode::Auto),
        ..*base
    };
    match light.light {
        hrts::Light::Directional { .. } => {
            if light.mode.is_none() {
                config.pcss_angular_radius = 0.0;
            }
        }
        _ => {
            config.pcss_spot_radius = match (light.mode, light.radius) {
                (None, r) => r.max(0.0),
                (Some(_), r) if r > 0.0 => r,
                (Some(_), _) => base.pcss_spot_radius,
            }
        }
    }
    config
}

/// The views the plugin may shadow: those with depth and normal prepasses.
type ShadowedViews<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static ViewPrepassTextures,
        &'static mut ViewShadowBindings,
        Option<&'static ExtractedCamera>,
    ),
    (With<DepthPrepass>, With<NormalPrepass>),
>;

/// Adopts Bevy's device, hands the plugin the frame's lights, meshes and targets, and binds the depth array
/// in the place of the directional shadow maps of the camera it shadows.
#[allow(clippy::too_many_arguments)]
fn prepare_shadows(
    mut state: ResMut<RenderState>,
    settings: Res<PluginSettings>,
    scene: Res<ExtractedScene>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    adapter: Res<RenderAdapter>,
    mut views: ShadowedViews,
) {
    state.view = None;
    state.geometry_dirty |= scene.geometry_changed;
    // Every view with prepasses reads the lit array, unless the plugin shadows it below.
    let layers = (scene.lights.len() as u32).max(1);
    if state.lit.as_ref().is_none_or(|(n, ..)| *n != layers) {
        state.lit = Some(lit_array(&device, &queue, layers));
    }
    if let Some((_, texture, view)) = &state.lit {
        for (_, _, mut bindings, _) in &mut views {
            bindings.directional_light_depth_texture = texture.clone();
            bindings.directional_light_depth_texture_view = view.clone();
        }
    }
    let result = prepare(
        &mut state, &settings, &scene, &device, &queue, &adapter, &mut views,
    );
    let mut status = settings.status.lock();
    status.error = result.err().map(|e| format!("{e:#}"));
    status.skipped_meshes = scene
        .skipped
        .iter()
        .map(|(id, why)| format!("{id}: {why}"))
        .collect();
}

/// A `Depth32Float` array of `layers` layers of one texel each, cleared to 1 (lit).
fn lit_array(
    device: &RenderDevice,
    queue: &RenderQueue,
    layers: u32,
) -> (u32, Texture, TextureView) {
    let texture = depth_array(device, "hrts lit", (1, 1), layers);
    clear_layers(device, queue, &texture, layers);
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    (layers, texture, view)
}

/// A `Depth32Float` array Bevy's PBR shader may read and a render pass may write.
fn depth_array(device: &RenderDevice, label: &str, size: (u32, u32), layers: u32) -> Texture {
    array_texture(
        device,
        label,
        size,
        layers,
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    )
}

/// A single-sample 2D array texture of `layers` layers.
fn array_texture(
    device: &RenderDevice,
    label: &str,
    (width, height): (u32, u32),
    layers: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Clears every layer of a depth array to 1 (lit), submitted at once.
fn clear_layers(device: &RenderDevice, queue: &RenderQueue, texture: &wgpu::Texture, layers: u32) {
    let mut encoder = device
        .wgpu_device()
        .create_command_encoder(&Default::default());
    for layer in 0..layers {
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: layer,
            array_layer_count: Some(1),
            ..Default::default()
        });
        depth_pass(&mut encoder, "hrts lit", &view);
    }
    queue.submit([encoder.finish()]);
}

/// A render pass writing one depth layer, cleared to 1 first.
fn depth_pass<'a>(
    encoder: &'a mut wgpu::CommandEncoder,
    label: &str,
    view: &wgpu::TextureView,
) -> wgpu::RenderPass<'a> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

fn prepare(
    state: &mut RenderState,
    settings: &PluginSettings,
    scene: &ExtractedScene,
    device: &RenderDevice,
    queue: &RenderQueue,
    adapter: &RenderAdapter,
    views: &mut ShadowedViews,
) -> Result<()> {
    // The camera with the lowest `Camera::order` (then the lowest render-world entity) of those that render
    // their whole target: the plugin's passes cover the prepasses' whole extent.
    let Some((entity, prepass, mut bindings, _)) = views
        .iter_mut()
        .filter(|(_, _, _, camera)| camera.is_none_or(|c| c.viewport.is_none()))
        .min_by_key(|(e, _, _, camera)| (camera.map_or(isize::MAX, |c| c.order), *e))
    else {
        return Ok(());
    };
    let (Some(depth), Some(normal)) = (&prepass.depth, &prepass.normal) else {
        return Ok(());
    };
    if depth.texture.texture.sample_count() != 1 {
        return Err(anyhow!(
            "the camera's prepasses are multisampled: the plugin reads one sample per pixel (Msaa::Off)"
        ));
    }
    if scene.lights.is_empty() || scene.draws.is_empty() {
        return Ok(());
    }
    let wgpu_device = device.wgpu_device();
    if state.shadows.is_none() {
        let enabled = settings
            .enabled
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .ok_or_else(|| {
                anyhow!(
                    "Bevy's device was not created through Vulkan with the plugin's features: add \
                     HrtsShadowsPlugin before DefaultPlugins, with Bevy's Vulkan backend"
                )
            })?;
        let shadows = Shadows::adopt(adapter, wgpu_device, enabled, FRAMES_IN_FLIGHT)
            .context("adopting Bevy's device")?;
        state.shadows = Some(Mutex::new(shadows));
        state.device = Some(wgpu_device.clone());
        state.span = SpanTimer::new(wgpu_device, queue);
    }
    let configs: Vec<hrts::Config> = scene
        .lights
        .iter()
        .map(|l| light_config(&settings.config, l))
        .collect();
    let shadows = state
        .shadows
        .as_ref()
        .map(|s| s.lock().unwrap_or_else(|e| e.into_inner()))
        .context("no context")?;
    if configs != state.configs {
        shadows.context().configure_lights(&configs)?;
        state.configs = configs;
    }
    if state.geometry_dirty || !state.geometry_set {
        set_geometry(&shadows, scene)?;
        state.geometry_set = true;
        state.geometry_dirty = false;
    } else {
        let transforms: Vec<glam::Mat4> = scene.draws.iter().map(|&(_, t)| t).collect();
        shadows.context().set_draw_transforms(&transforms)?;
    }
    let size = (prepass.size.width, prepass.size.height);
    let layers = scene.lights.len() as u32;
    if state
        .mask
        .as_ref()
        .is_none_or(|m| m.size != size || m.layers != layers)
    {
        let fill = state.fill.get_or_insert_with(|| Fill::new(wgpu_device));
        state.mask = Some(Mask::new(device, queue, fill, size, layers));
    }
    let mask = state.mask.as_ref().context("no mask")?;
    let key = [
        raw_image(&depth.texture.texture)?,
        raw_image(&normal.texture.texture)?,
        raw_image(&mask.visibility)?,
    ];
    if state.targets != Some(key) {
        shadows.set_targets(&ShadowTargets {
            depth: &depth.texture.texture,
            normal: &normal.texture.texture,
            normal_encoding: hrts::NormalEncoding::Xyz,
            normal_space: hrts::NormalSpace::World,
            shadow: &mask.visibility,
        })?;
        state.targets = Some(key);
    }
    bindings.directional_light_depth_texture = mask.depth.clone();
    bindings.directional_light_depth_texture_view = mask.depth_view.clone();
    state.bounds = scene_bounds(scene);
    drop(shadows);
    state.view = Some(entity);
    state.lights = scene.lights.clone();
    Ok(())
}

/// Hands the plugin the meshes' positions and indices, one draw per caster entity.
fn set_geometry(shadows: &Shadows, scene: &ExtractedScene) -> Result<()> {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut ranges = Vec::new();
    for mesh in &scene.meshes {
        ranges.push((
            indices.len() as u32,
            mesh.indices.len() as u32,
            positions.len() as i32,
        ));
        positions.extend_from_slice(&mesh.positions);
        indices.extend_from_slice(&mesh.indices);
    }
    let draws: Vec<hrts::Draw> = scene
        .draws
        .iter()
        .map(|&(mesh, transform)| {
            let (first_index, index_count, base_vertex) = ranges[mesh];
            hrts::Draw {
                first_index,
                index_count,
                transform,
                base_vertex,
            }
        })
        .collect();
    shadows.context().set_geometry_cpu(&hrts::CpuGeometry {
        positions: &positions,
        indices: &indices,
        draws: &draws,
    })?;
    Ok(())
}

/// World-space bounds of the casters (min, max).
fn scene_bounds(scene: &ExtractedScene) -> [glam::Vec3; 2] {
    let mut bounds = [
        glam::Vec3::splat(f32::INFINITY),
        glam::Vec3::splat(f32::NEG_INFINITY),
    ];
    // Each draw's object-space box, its eight corners transformed: a bound of the transformed vertices.
    for &(mesh, transform) in &scene.draws {
        let [min, max] = scene.meshes[mesh].bounds;
        for corner in 0..8 {
            let p = glam::Vec3::select(
                glam::BVec3::new(corner & 1 != 0, corner & 2 != 0, corner & 4 != 0),
                max,
                min,
            );
            let p = transform.transform_point3(p);
            bounds = [bounds[0].min(p), bounds[1].max(p)];
        }
    }
    bounds
}

/// The `VkImage` of a texture of Bevy's device.
fn raw_image(texture: &wgpu::Texture) -> Result<u64> {
    use ash::vk::Handle;
    // SAFETY: a live texture of Bevy's device; the guard is dropped before returning.
    let hal =
        unsafe { texture.as_hal::<wgpu::hal::api::Vulkan>() }.context("not a Vulkan texture")?;
    // SAFETY: as above.
    Ok(unsafe { hal.raw_handle() }.as_raw())
}

/// Records the plugin's frame for the shadowed view, then copies its visibility into the depth array.
fn record_shadows(
    view: ViewQuery<(&ExtractedView, &ViewPrepassTextures)>,
    mut state: ResMut<RenderState>,
    settings: Res<PluginSettings>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    mut ctx: RenderContext,
) {
    if state.view != Some(view.entity()) {
        return;
    }
    let (extracted, prepass) = view.into_inner();
    let result = record(&mut state, extracted, prepass, &device, &queue, &mut ctx);
    let mut status = settings.status.lock();
    match result {
        Ok(times) => {
            status.gpu_milliseconds = times.passes.or(status.gpu_milliseconds);
            status.gpu_span_milliseconds = times.span.or(status.gpu_span_milliseconds);
            status.frames = state.frames;
            status.lights = state.lights.iter().map(|l| l.entity).collect();
            status.error = None;
        }
        Err(e) => status.error = Some(format!("{e:#}")),
    }
}

fn record(
    state: &mut RenderState,
    view: &ExtractedView,
    prepass: &ViewPrepassTextures,
    device: &RenderDevice,
    queue: &RenderQueue,
    ctx: &mut RenderContext,
) -> Result<GpuTimes> {
    let (Some(shadows), Some(mask), Some(fill)) = (&state.shadows, &state.mask, &state.fill) else {
        return Ok(GpuTimes::default());
    };
    // The frame takes its index now: one that fails while recording has used it.
    let index = state.frames;
    state.frames += 1;
    // The plugin's contract: frame `index - FRAMES_IN_FLIGHT` has completed when frame `index` is
    // recorded. Bevy waits for no frame: the plugin waits when the GPU is that far behind.
    let completed = state.completed.clone();
    queue.on_submitted_work_done(move || {
        completed.fetch_max(index, Ordering::AcqRel);
    });
    let in_flight = u64::from(FRAMES_IN_FLIGHT);
    if index >= in_flight && state.completed.load(Ordering::Acquire) + in_flight <= index {
        device
            .wgpu_device()
            .poll(wgpu::PollType::wait_indefinitely())
            .context("waiting for the frame in flight before the last ones")?;
    }
    let (Some(depth), Some(normal)) = (&prepass.depth, &prepass.normal) else {
        return Ok(GpuTimes::default());
    };
    // The newest frame in flight the GPU completed (read before this frame takes the oldest one's place).
    let gpu_milliseconds = {
        let shadows = shadows.lock().unwrap_or_else(|e| e.into_inner());
        state
            .in_flight
            .iter()
            .rev()
            .find_map(|&(frame, lights)| shadows.gpu_milliseconds(frame, lights).ok())
            .flatten()
    };
    let world_from_view = view.world_from_view.to_matrix();
    let lights: Vec<hrts::Light> = state.lights.iter().map(|l| l.light).collect();
    let frame = ShadowFrame {
        index,
        view: mat4(world_from_view.inverse()),
        proj: mat4(view.clip_from_view),
        camera_position: vec3(view.world_from_view.translation()),
        lights: &lights,
        bounds: state.bounds,
    };
    let targets = ShadowTargets {
        depth: &depth.texture.texture,
        normal: &normal.texture.texture,
        normal_encoding: hrts::NormalEncoding::Xyz,
        normal_space: hrts::NormalSpace::World,
        shadow: &mask.visibility,
    };
    let mut span = None;
    if let Some(timer) = &mut state.span {
        timer.begin(device.wgpu_device(), ctx.command_encoder());
        span = timer.take().last().copied();
    }
    let commands = shadows.lock().unwrap_or_else(|e| e.into_inner()).record(
        device.wgpu_device(),
        ctx.command_encoder(),
        &targets,
        &frame,
    )?;
    ctx.add_command_buffer(commands);
    fill.record(ctx.command_encoder(), mask);
    if let Some(timer) = &mut state.span {
        timer.end(ctx.command_encoder());
    }
    let vulkan_clip = Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0));
    state.matrices = Some((world_from_view.inverse(), vulkan_clip * view.clip_from_view));
    state.in_flight.push_back((index, lights.len() as u32));
    if state.in_flight.len() > FRAMES_IN_FLIGHT as usize {
        state.in_flight.pop_front();
    }
    Ok(GpuTimes {
        passes: gpu_milliseconds,
        span,
    })
}

/// The GPU times of the last frame the GPU completed that the plugin could read.
#[derive(Default)]
struct GpuTimes {
    /// The plugin's passes, over all lights.
    passes: Option<f64>,
    /// From the plugin's first pass to the end of the copy into the depth array.
    span: Option<f64>,
}

/// Once Bevy submitted the frame: reads its span back when the GPU completes it.
fn span_submitted(mut state: ResMut<RenderState>) {
    if let Some(timer) = &mut state.span {
        timer.submitted();
    }
}

impl Fill {
    fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("hrts visibility into depth"),
            source: wgpu::ShaderSource::Wgsl(include_str!("fill_depth.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("hrts visibility into depth"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("hrts visibility into depth"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("hrts visibility into depth"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vertex"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fragment"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self { layout, pipeline }
    }

    /// Copies every layer of `mask`'s visibility into its depth array.
    fn record(&self, encoder: &mut wgpu::CommandEncoder, mask: &Mask) {
        for (layer, target) in (0u32..).zip(&mask.layer_views) {
            let mut pass = depth_pass(encoder, "hrts visibility into depth", target);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &mask.fill_bind_group, &[]);
            pass.draw(0..3, layer..layer + 1);
        }
    }
}

impl Mask {
    /// The arrays for `layers` lights at `width` × `height`, the depth array lit until a frame writes it.
    fn new(
        device: &RenderDevice,
        queue: &RenderQueue,
        fill: &Fill,
        (width, height): (u32, u32),
        layers: u32,
    ) -> Self {
        let visibility = array_texture(
            device,
            "hrts visibility",
            (width, height),
            layers,
            wgpu::TextureFormat::R32Float,
            wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = depth_array(device, "hrts visibility as depth", (width, height), layers);
        clear_layers(device, queue, &depth, layers);
        let array = wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        };
        let depth_view = depth.create_view(&array);
        let layer_views = (0..layers)
            .map(|layer| {
                depth.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let visibility_view = visibility.create_view(&array);
        let fill_bind_group = device
            .wgpu_device()
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("hrts visibility into depth"),
                layout: &fill.layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&visibility_view),
                }],
            });
        Self {
            size: (width, height),
            layers,
            visibility,
            depth,
            depth_view,
            layer_views,
            fill_bind_group,
        }
    }
}

/// The plugin's visibility of each light in the last frame it recorded, read back.
#[derive(Debug, Clone)]
pub struct HrtsVisibility {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// One image per light, in [`HrtsStatus::lights`] order: row-major, the top row first.
    pub layers: Vec<Vec<f32>>,
    /// The view matrix of the frame (world to view).
    pub view: Mat4,
    /// Its projection, in Vulkan's clip conventions (y down, depth 0..1, Bevy's reversed Z).
    pub proj: Mat4,
}

/// A read-back of the plugin's visibility, asked for in the main world and made in the render world (which
/// may run on its own thread, a frame behind): for tests and headless captures.
#[derive(Resource, Clone, Default)]
pub struct HrtsCapture(Arc<Mutex<CaptureState>>);

#[derive(Default)]
struct CaptureState {
    requested: bool,
    result: Option<Result<HrtsVisibility, String>>,
}

impl HrtsCapture {
    /// Asks for the visibility of the next frame the plugin records (after it completes on the GPU).
    pub fn request(&self) {
        let mut state = self.lock();
        state.requested = true;
        state.result = None;
    }

    /// The visibility asked for, once read back (an error if it could not be).
    pub fn take(&self) -> Option<Result<HrtsVisibility, String>> {
        self.lock().result.take()
    }

    fn lock(&self) -> MutexGuard<'_, CaptureState> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Reads the visibility back after the frame's submission, if asked.
fn capture_visibility(
    state: Res<RenderState>,
    capture: Res<HrtsCapture>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
) {
    let mut asked = capture.lock();
    if !asked.requested || state.view.is_none() {
        return;
    }
    asked.requested = false;
    asked.result = Some(read_visibility(&state, &device, &queue).map_err(|e| format!("{e:#}")));
}

fn read_visibility(
    state: &RenderState,
    device: &RenderDevice,
    queue: &RenderQueue,
) -> Result<HrtsVisibility> {
    let (Some(mask), Some((view, proj))) = (&state.mask, state.matrices) else {
        return Err(anyhow!("no frame recorded"));
    };
    let device = device.wgpu_device();
    let mut encoder = device.create_command_encoder(&Default::default());
    let copies: Vec<hrts_wgpu::ReadBack> = (0..mask.layers)
        .map(|layer| {
            hrts_wgpu::ReadBack::record_layer(device, &mut encoder, &mask.visibility, layer)
        })
        .collect();
    queue.submit([encoder.finish()]);
    let layers = copies
        .iter()
        .map(|c| c.texels(device, wgpu::TextureFormat::R32Float))
        .collect::<Result<Vec<_>>>()?;
    Ok(HrtsVisibility {
        width: mask.size.0,
        height: mask.size.1,
        layers,
        view,
        proj,
    })
}

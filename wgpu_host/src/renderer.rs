//! A small deferred renderer on wgpu: a G-buffer pass (depth, normals), the plugin's shadows, a shading
//! pass, and read-backs for tests and pictures.

use crate::conventions::{Conventions, IndexType};
use crate::meshes::{meshes_of, Mesh};
use anyhow::{bail, Context as _, Result};
use glam::Mat4;
use hrts::{FrameReport, NormalEncoding, NormalSpace, ShadowMode};
use hrts_wgpu::{
    self as shadows, shared_buffer, ReadBack, ShadowFrame, ShadowMesh, ShadowTargets, Shadows,
    SharedBuffer,
};
use scene::{Aabb, Camera, DirectionalLight, Scene};

/// The wgpu device, opened with what the plugin adopts.
pub struct Gpu {
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    enabled: shadows::EnabledFeatures,
}

impl Gpu {
    /// Opens the first Vulkan adapter whose name contains `HRTS_DEVICE` (any when unset), with wgpu's
    /// validation (the Khronos layer) when `validation` is set.
    pub fn new(validation: bool) -> Result<Self> {
        let flags = if validation {
            wgpu::InstanceFlags::VALIDATION
        } else {
            wgpu::InstanceFlags::empty()
        };
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN,
            flags,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let filter = std::env::var("HRTS_DEVICE").unwrap_or_default();
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
        let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
        let adapter = adapters
            .into_iter()
            .find(|a| a.get_info().name.contains(&filter))
            .with_context(|| {
                format!("no Vulkan adapter named like {filter:?} (found {names:?}); run scripts/setup.sh for lavapipe")
            })?;
        let features = adapter.features() & wgpu::Features::DEPTH32FLOAT_STENCIL8;
        let (device, queue, enabled) = shadows::open_device(&adapter, features)?;
        Ok(Self {
            adapter,
            device,
            queue,
            enabled,
        })
    }

    /// The adapter's name.
    pub fn name(&self) -> String {
        self.adapter.get_info().name
    }
}

/// One mesh on the GPU.
struct GpuMesh {
    mesh: Mesh,
    vertices: SharedBuffer,
    indices: SharedBuffer,
    index_count: u32,
    index_format: wgpu::IndexFormat,
}

/// A rendered frame, read back.
pub struct Frame {
    /// The plugin's visibility per pixel, row-major from the top (1 = lit).
    pub visibility: Vec<f32>,
    /// The shaded image, RGBA8, row-major from the top.
    pub color: Vec<u8>,
    /// The plugin's report of the frame.
    pub report: FrameReport,
}

/// The renderer: meshes, G-buffer, shadow image, shading, and the plugin's context.
pub struct Renderer {
    // First: the context goes before the images and buffers it reads.
    shadows: Shadows,
    conventions: Conventions,
    width: u32,
    height: u32,
    meshes: Vec<GpuMesh>,
    transforms: Vec<Mat4>,
    instances: wgpu::Buffer,
    camera: wgpu::Buffer,
    shade_constants: wgpu::Buffer,
    depth: wgpu::Texture,
    normal: wgpu::Texture,
    view_z: Option<wgpu::Texture>,
    shadow: wgpu::Texture,
    color: wgpu::Texture,
    gbuffer: wgpu::RenderPipeline,
    gbuffer_group: wgpu::BindGroup,
    shade: wgpu::RenderPipeline,
    shade_group: wgpu::BindGroup,
    frame: u64,
}

/// The G-buffer pass's constants (`gbuffer.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CameraConstants {
    view_proj: [f32; 16],
    view: [f32; 16],
    eye: [f32; 4],
    normal_code: u32,
    pad: [u32; 3],
}

/// The shading pass's constants (`shade.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadeConstants {
    to_light: [f32; 4],
    normal_code: u32,
    far_depth: f32,
    pad: [u32; 2],
}

impl Renderer {
    /// A renderer of `scene` at `width` x `height` with `conventions`, its shadows in `mode`.
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        conventions: Conventions,
        width: u32,
        height: u32,
        mode: ShadowMode,
    ) -> Result<Self> {
        let device = &gpu.device;
        let meshes: Vec<GpuMesh> = meshes_of(scene, conventions.index)
            .into_iter()
            .map(|mesh| upload(gpu, mesh, conventions.index))
            .collect::<Result<_>>()?;
        let transforms: Vec<Mat4> = meshes.iter().map(|m| m.mesh.rest).collect();
        let uniform = |label, size| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let instances = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("instances"),
            size: (transforms.len() * 64) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let camera = uniform("camera", size_of::<CameraConstants>() as u64);
        let shade_constants = uniform("shade", size_of::<ShadeConstants>() as u64);
        let texture = |label, format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as U;
        let depth = texture(
            "depth",
            conventions.depth_format,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
        );
        let normal = texture(
            "normals",
            conventions.normals.format(),
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
        );
        let view_z = conventions
            .view_z
            .map(|format| texture("view z", format, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING));
        // An R32Float shadow image with storage usage is written by the plugin's last pass directly.
        let storage = if conventions.shadow_format == wgpu::TextureFormat::R32Float {
            U::STORAGE_BINDING
        } else {
            U::empty()
        };
        let shadow = texture(
            "shadow",
            conventions.shadow_format,
            U::COPY_DST | U::TEXTURE_BINDING | U::COPY_SRC | storage,
        );
        let color = texture(
            "color",
            wgpu::TextureFormat::Rgba8Unorm,
            U::RENDER_ATTACHMENT | U::COPY_SRC,
        );
        // The plugin writes the shadow image outside wgpu: wgpu must not clear it as never written.
        let texel = conventions
            .shadow_format
            .block_copy_size(None)
            .context("shadow format")?;
        gpu.queue.write_texture(
            shadow.as_image_copy(),
            &vec![0; (width * height * texel) as usize],
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(width * texel),
                rows_per_image: None,
            },
            shadow.size(),
        );
        let (gbuffer, gbuffer_group) = gbuffer_pipeline(device, &conventions, &camera, &instances);
        let (shade, shade_group) =
            shade_pipeline(device, &shade_constants, &depth, &normal, &shadow);
        let shadows = Shadows::new(&gpu.adapter, device, gpu.enabled, 2, mode)?;
        let renderer = Self {
            conventions,
            width,
            height,
            meshes,
            transforms,
            instances,
            camera,
            shade_constants,
            depth,
            normal,
            view_z,
            shadow,
            color,
            gbuffer,
            gbuffer_group,
            shade,
            shade_group,
            shadows,
            frame: 0,
        };
        renderer.shadows.set_meshes(&renderer.shadow_meshes())?;
        renderer.shadows.set_targets(&renderer.targets())?;
        Ok(renderer)
    }

    /// The meshes (their transforms at rest and names).
    pub fn meshes(&self) -> Vec<&Mesh> {
        self.meshes.iter().map(|m| &m.mesh).collect()
    }

    /// Moves the instances: one transform per mesh (see [`Renderer::meshes`]).
    pub fn move_instances(&mut self, transforms: &[Mat4]) -> Result<()> {
        if transforms.len() != self.meshes.len() {
            bail!(
                "{} transforms for {} meshes",
                transforms.len(),
                self.meshes.len()
            );
        }
        self.transforms = transforms.to_vec();
        self.shadows.move_instances(transforms)
    }

    /// World-space bounds of the scene as it stands.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::empty();
        for (m, t) in self.meshes.iter().zip(&self.transforms) {
            let mb = m.mesh.bounds(*t);
            b.extend(mb.min);
            b.extend(mb.max);
        }
        b
    }

    fn shadow_meshes(&self) -> Vec<ShadowMesh<'_>> {
        self.meshes
            .iter()
            .zip(&self.transforms)
            .map(|(m, t)| {
                let b = m.mesh.bounds(*t);
                ShadowMesh {
                    vertices: &m.vertices,
                    vertex_count: m.mesh.positions.len() as u32,
                    indices: &m.indices,
                    index_count: m.index_count,
                    index_format: m.index_format,
                    instances: std::slice::from_ref(t),
                    bounds: [b.min, b.max],
                }
            })
            .collect()
    }

    fn targets(&self) -> ShadowTargets<'_> {
        let n = self.conventions.normals;
        ShadowTargets {
            depth: self.view_z.as_ref().unwrap_or(&self.depth),
            normal: &self.normal,
            normal_encoding: if n.octahedral() {
                NormalEncoding::Octahedral
            } else {
                NormalEncoding::Xyz
            },
            normal_space: if n.view_space() {
                NormalSpace::View
            } else {
                NormalSpace::World
            },
            shadow: &self.shadow,
        }
    }

    /// Renders a frame through `camera` lit by `light`, and reads it back.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        camera: &Camera,
        light: &DirectionalLight,
    ) -> Result<Frame> {
        let (device, queue) = (&gpu.device, &gpu.queue);
        self.frame += 1;
        let bounds = self.bounds();
        let aspect = self.width as f32 / self.height as f32;
        let far = 2.0
            * bounds
                .corners()
                .iter()
                .map(|c| c.distance(camera.position))
                .fold(0.0, f32::max);
        let proj = self.conventions.depth.projection(
            camera.fov_y_radians,
            aspect,
            camera.near,
            far.max(camera.near * 2.0),
        );
        let view = camera.view();
        let normal_code = self.conventions.normals.code();
        queue.write_buffer(&self.instances, 0, bytemuck::cast_slice(&self.transforms));
        queue.write_buffer(
            &self.camera,
            0,
            bytemuck::bytes_of(&CameraConstants {
                view_proj: (proj * view).to_cols_array(),
                view: view.to_cols_array(),
                eye: camera.position.extend(1.0).to_array(),
                normal_code,
                pad: [0; 3],
            }),
        );
        let to_light = -light.direction;
        let to_light = if self.conventions.normals.view_space() {
            view.transform_vector3(to_light)
        } else {
            to_light
        };
        queue.write_buffer(
            &self.shade_constants,
            0,
            bytemuck::bytes_of(&ShadeConstants {
                to_light: to_light.extend(0.0).to_array(),
                normal_code,
                far_depth: self.conventions.depth.clear_depth(),
                pad: [0; 2],
            }),
        );
        let mut gbuffer = device.create_command_encoder(&Default::default());
        self.record_gbuffer(&mut gbuffer);
        let lights = [hrts::Light::Directional {
            direction: light.direction,
            view_proj: Some(light.view_proj(&bounds)),
        }];
        let frame = ShadowFrame {
            index: self.frame,
            view,
            proj,
            camera_position: camera.position,
            lights: &lights,
            bounds: [bounds.min, bounds.max],
        };
        let plugin = self
            .shadows
            .record(device, &mut gbuffer, &self.targets(), &frame)?;
        let mut shading = device.create_command_encoder(&Default::default());
        self.record_shading(&mut shading);
        let shadow_read = ReadBack::record(device, &mut shading, &self.shadow);
        let color_read = ReadBack::record(device, &mut shading, &self.color);
        let submission = queue.submit([gbuffer.finish(), plugin, shading.finish()]);
        device.poll(wgpu::PollType::Wait {
            submission_index: Some(submission),
            timeout: None,
        })?;
        let visibility = shadow_read.texels(device, self.conventions.shadow_format)?;
        let color = color_read.bytes(device)?;
        let report = self.shadows.report(self.frame)?;
        Ok(Frame {
            visibility,
            color,
            report,
        })
    }

    fn record_gbuffer(&self, encoder: &mut wgpu::CommandEncoder) {
        let depth_view = self.depth.create_view(&Default::default());
        let normal_view = self.normal.create_view(&Default::default());
        let view_z_view = self
            .view_z
            .as_ref()
            .map(|t| t.create_view(&Default::default()));
        let has_stencil = self.conventions.depth_format.has_stencil_aspect();
        let cleared = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("g-buffer"),
            color_attachments: &[
                cleared(&normal_view),
                view_z_view.as_ref().and_then(cleared),
            ],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(self.conventions.depth.clear_depth()),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: has_stencil.then_some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0),
                    store: wgpu::StoreOp::Store,
                }),
            }),
            ..Default::default()
        });
        pass.set_pipeline(&self.gbuffer);
        pass.set_bind_group(0, &self.gbuffer_group, &[]);
        for (i, m) in self.meshes.iter().enumerate() {
            pass.set_vertex_buffer(0, m.vertices.buffer.slice(..));
            pass.set_index_buffer(m.indices.buffer.slice(..), m.index_format);
            pass.draw_indexed(0..m.index_count, 0, i as u32..i as u32 + 1);
        }
    }

    fn record_shading(&self, encoder: &mut wgpu::CommandEncoder) {
        let view = self.color.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shading"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&self.shade);
        pass.set_bind_group(0, &self.shade_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

fn upload(gpu: &Gpu, mesh: Mesh, index: IndexType) -> Result<GpuMesh> {
    use wgpu::BufferUsages as U;
    let (contents, index_format) = match index {
        IndexType::U16 => {
            let short: Vec<u16> = mesh.indices.iter().map(|&i| i as u16).collect();
            (
                bytemuck::cast_slice(&short).to_vec(),
                wgpu::IndexFormat::Uint16,
            )
        }
        IndexType::U32 => (
            bytemuck::cast_slice(&mesh.indices).to_vec(),
            wgpu::IndexFormat::Uint32,
        ),
    };
    let positions: &[u8] = bytemuck::cast_slice(&mesh.positions);
    let vertices = shared_buffer(&gpu.device, &mesh.name, positions.len() as u64, U::VERTEX)?;
    let indices = shared_buffer(&gpu.device, &mesh.name, contents.len() as u64, U::INDEX)?;
    write_padded(&gpu.queue, &vertices.buffer, positions);
    write_padded(&gpu.queue, &indices.buffer, &contents);
    Ok(GpuMesh {
        index_count: mesh.indices.len() as u32,
        mesh,
        vertices,
        indices,
        index_format,
    })
}

/// Writes `bytes` at the start of `buffer`, zero-padded to the copy alignment.
fn write_padded(queue: &wgpu::Queue, buffer: &wgpu::Buffer, bytes: &[u8]) {
    let mut padded = bytes.to_vec();
    padded.resize(
        bytes
            .len()
            .next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT as usize),
        0,
    );
    queue.write_buffer(buffer, 0, &padded);
}

fn gbuffer_pipeline(
    device: &wgpu::Device,
    conventions: &Conventions,
    camera: &wgpu::Buffer,
    instances: &wgpu::Buffer,
) -> (wgpu::RenderPipeline, wgpu::BindGroup) {
    let module = device.create_shader_module(wgpu::include_wgsl!("../shaders/gbuffer.wgsl"));
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("g-buffer"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            }],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: conventions.depth_format,
            depth_write_enabled: Some(true),
            depth_compare: Some(conventions.depth.compare()),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some(if conventions.view_z.is_some() {
                "fs_view_z"
            } else {
                "fs"
            }),
            compilation_options: Default::default(),
            targets: &[
                Some(conventions.normals.format().into()),
                conventions.view_z.map(Into::into),
            ],
        }),
        multiview_mask: None,
        cache: None,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("g-buffer"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: camera.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: instances.as_entire_binding(),
            },
        ],
    });
    (pipeline, group)
}

fn shade_pipeline(
    device: &wgpu::Device,
    constants: &wgpu::Buffer,
    depth: &wgpu::Texture,
    normal: &wgpu::Texture,
    shadow: &wgpu::Texture,
) -> (wgpu::RenderPipeline, wgpu::BindGroup) {
    let module = device.create_shader_module(wgpu::include_wgsl!("../shaders/shade.wgsl"));
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("shading"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::TextureFormat::Rgba8Unorm.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let depth_view = depth.create_view(&wgpu::TextureViewDescriptor {
        aspect: wgpu::TextureAspect::DepthOnly,
        ..Default::default()
    });
    let normal_view = normal.create_view(&Default::default());
    let shadow_view = shadow.create_view(&Default::default());
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("shading"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: constants.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&depth_view),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&normal_view),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(&shadow_view),
            },
        ],
    });
    (pipeline, group)
}

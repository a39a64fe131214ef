//! The plugin on a wgpu device, in one file: the device wgpu opens with what the plugin adopts, the
//! context, the host's meshes and images handed over as they are, and the frame recorded into a wgpu
//! command encoder through wgpu-hal's Vulkan interop, all through the plugin's safe API ([`hrts`]). What a
//! renderer on wgpu (`wgpu_host`, `bevy_hrts`) writes to add the plugin.

mod span_timer;

pub use span_timer::SpanTimer;

use anyhow::{bail, Context as _, Result};
use ash::vk::{self, Handle};
use glam::Mat4;
use hrts::{NormalEncoding, NormalSpace, ShadowMode};
use std::ffi::{c_char, c_void};
use wgpu::hal::api::Vulkan;

/// What the plugin needs to know of the features wgpu enabled.
#[derive(Debug, Clone, Copy, Default)]
pub struct EnabledFeatures {
    geometry_shader: bool,
    fragment_stores_and_atomics: bool,
    depth_clamp: bool,
}

impl EnabledFeatures {
    /// What the plugin reads of the core features a device is created with (a `CreateDeviceCallback`'s
    /// `device_features.get_core()`).
    pub fn of(core: &vk::PhysicalDeviceFeatures) -> Self {
        Self {
            geometry_shader: core.geometry_shader == vk::TRUE,
            fragment_stores_and_atomics: core.fragment_stores_and_atomics == vk::TRUE,
            depth_clamp: core.depth_clamp == vk::TRUE,
        }
    }
}

/// Opens a wgpu device on `adapter` with `features`, adding the two Vulkan 1.3 features the plugin records
/// with (`synchronization2`, `dynamicRendering`) to what wgpu enables itself.
pub fn open_device(
    adapter: &wgpu::Adapter,
    features: wgpu::Features,
) -> Result<(wgpu::Device, wgpu::Queue, EnabledFeatures)> {
    let mut sync2 = vk::PhysicalDeviceSynchronization2Features::default().synchronization2(true);
    let mut dynamic_rendering =
        vk::PhysicalDeviceDynamicRenderingFeatures::default().dynamic_rendering(true);
    let mut enabled = EnabledFeatures::default();
    let open = {
        // SAFETY: the adapter outlives the guard; the callback only adds features the plugin checks for.
        let hal = unsafe { adapter.as_hal::<Vulkan>() }.context("the adapter is not Vulkan")?;
        let (sync2, dynamic_rendering, enabled) =
            (&mut sync2, &mut dynamic_rendering, &mut enabled);
        let callback: Box<wgpu::hal::vulkan::CreateDeviceCallback<'_>> = Box::new(move |args| {
            *enabled = EnabledFeatures::of(&args.device_features.get_core());
            let info = std::mem::take(args.create_info);
            *args.create_info = info.push_next(sync2).push_next(dynamic_rendering);
        });
        // SAFETY: the features are supported by every Vulkan 1.3 device, which the plugin requires.
        unsafe {
            hal.open_with_callback(
                features,
                &adapter.limits(),
                &wgpu::MemoryHints::Performance,
                Some(callback),
            )
        }?
    };
    let desc = wgpu::DeviceDescriptor {
        label: Some("wgpu_host"),
        required_features: features,
        ..Default::default()
    };
    // SAFETY: `open` was created from this adapter with `features`.
    let (device, queue) = unsafe { adapter.create_device_from_hal(open, &desc) }?;
    Ok((device, queue, enabled))
}

/// The renderer's images the plugin reads and writes.
pub struct ShadowTargets<'a> {
    /// Depth buffer, or linear view-Z image (its usage includes `TEXTURE_BINDING`).
    pub depth: &'a wgpu::Texture,
    /// Normal target (`TEXTURE_BINDING`), encoded as `normal_encoding` says.
    pub normal: &'a wgpu::Texture,
    /// Octahedral or xyz.
    pub normal_encoding: NormalEncoding,
    /// View or world space.
    pub normal_space: NormalSpace,
    /// The shadow image the plugin writes, one layer per light (`COPY_DST`).
    pub shadow: &'a wgpu::Texture,
}

/// A wgpu buffer the renderer created through Vulkan (wgpu does not expose a buffer's `VkBuffer`), so
/// that the plugin can read it.
pub struct SharedBuffer {
    /// The buffer, for wgpu.
    pub buffer: wgpu::Buffer,
    /// Its `VkBuffer`.
    pub raw: u64,
}

/// Creates a device-local buffer of `size` bytes for wgpu `usage` that the plugin may read as a storage
/// buffer; wgpu owns it (and frees its memory) from then on.
pub fn shared_buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> Result<SharedBuffer> {
    let size = size.next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
    // SAFETY: the guard lives through this function, the device beyond it.
    let hal = unsafe { device.as_hal::<Vulkan>() }.context("the device is not Vulkan")?;
    let raw_device = hal.raw_device();
    let info = vk::BufferCreateInfo::default()
        .size(size)
        .usage(
            vk::BufferUsageFlags::VERTEX_BUFFER
                | vk::BufferUsageFlags::INDEX_BUFFER
                | vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
        )
        .sharing_mode(vk::SharingMode::EXCLUSIVE);
    // SAFETY: valid create info on a live device.
    let raw = unsafe { raw_device.create_buffer(&info, None) }?;
    // SAFETY: `raw` was created above.
    let needs = unsafe { raw_device.get_buffer_memory_requirements(raw) };
    let instance = hal.shared_instance().raw_instance();
    // SAFETY: the physical device belongs to the instance.
    let types =
        unsafe { instance.get_physical_device_memory_properties(hal.raw_physical_device()) };
    let type_index = (0..types.memory_type_count)
        .filter(|&i| needs.memory_type_bits & (1 << i) != 0)
        .max_by_key(|&i| {
            types.memory_types[i as usize]
                .property_flags
                .contains(vk::MemoryPropertyFlags::DEVICE_LOCAL)
        })
        .context("no memory type for a vertex buffer")?;
    let alloc = vk::MemoryAllocateInfo::default()
        .allocation_size(needs.size)
        .memory_type_index(type_index);
    // SAFETY: a valid allocation for `raw`'s requirements, bound once, then handed to wgpu, which frees
    // both when the wgpu buffer is dropped.
    let buffer = unsafe {
        let memory = raw_device.allocate_memory(&alloc, None)?;
        raw_device.bind_buffer_memory(raw, memory, 0)?;
        let hal_buffer = wgpu::hal::vulkan::Buffer::from_raw_managed(raw, memory, 0, size);
        device.create_buffer_from_hal::<Vulkan>(
            hal_buffer,
            &wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            },
        )
    };
    Ok(SharedBuffer {
        buffer,
        raw: raw.as_raw(),
    })
}

/// One of the renderer's meshes: its own vertex buffer of `Float32x3` positions and index buffer, and
/// its instances.
pub struct ShadowMesh<'a> {
    /// Vertex buffer.
    pub vertices: &'a SharedBuffer,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Index buffer.
    pub indices: &'a SharedBuffer,
    /// Number of indices.
    pub index_count: u32,
    /// 16- or 32-bit indices.
    pub index_format: wgpu::IndexFormat,
    /// Object-to-world transform of each instance.
    pub instances: &'a [Mat4],
    /// World-space bounds of the instances (min, max).
    pub bounds: [glam::Vec3; 2],
}

/// A frame's camera, in wgpu's conventions, and its lights.
pub struct ShadowFrame<'a> {
    /// Increasing frame counter.
    pub index: u64,
    /// World to view.
    pub view: Mat4,
    /// View to clip as wgpu takes it (clip y up).
    pub proj: Mat4,
    /// Camera position.
    pub camera_position: glam::Vec3,
    /// The lights, one per configured light (Vulkan clip conventions for their matrices).
    pub lights: &'a [hrts::Light],
    /// World-space bounds of the scene this frame (min, max): the plugin culls by them as instances move.
    pub bounds: [glam::Vec3; 2],
}

/// The plugin's context on the renderer's device.
pub struct Shadows {
    context: hrts::Context,
    adapter: wgpu::Adapter,
}

impl Shadows {
    /// Adopts `device` (opened by [`open_device`] on `adapter`) with one directional light in `mode` (hard:
    /// the exact ray-traced visibility, without FXAA).
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        enabled: EnabledFeatures,
        frames_in_flight: u32,
        mode: ShadowMode,
    ) -> Result<Self> {
        let shadows = Self::adopt(adapter, device, enabled, frames_in_flight)?;
        shadows.context.configure(&hrts::Config {
            mode,
            // Hard shadows as the rays give them, without FXAA: exact per pixel.
            antialiasing: mode != ShadowMode::Hard,
            ..hrts::Config::default()
        })?;
        Ok(shadows)
    }

    /// Adopts `device`, opened on `adapter` with the plugin's features added (as [`open_device`] adds
    /// them) and `enabled` among its core features, with the plugin's default configuration.
    pub fn adopt(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        enabled: EnabledFeatures,
        frames_in_flight: u32,
    ) -> Result<Self> {
        // SAFETY: the guard is dropped at the end of this function; the handles stay valid as long as
        // `device`, which the caller keeps beyond the context.
        let hal = unsafe { device.as_hal::<Vulkan>() }.context("the device is not Vulkan")?;
        let shared = hal.shared_instance();
        let vulkan = hrts::VulkanDevice {
            // SAFETY: the same function pointer type, with the loader's C calling convention.
            get_instance_proc_addr: Some(unsafe {
                std::mem::transmute::<
                    vk::PFN_vkGetInstanceProcAddr,
                    unsafe extern "C" fn(
                        *mut c_void,
                        *const c_char,
                    ) -> Option<unsafe extern "C" fn()>,
                >(shared.entry().static_fn().get_instance_proc_addr)
            }),
            instance: shared.raw_instance().handle().as_raw(),
            physical_device: hal.raw_physical_device().as_raw(),
            device: hal.raw_device().handle().as_raw(),
            queue_family_index: hal.queue_family_index(),
            queue_index: 0,
            enabled_extensions: hal
                .enabled_device_extensions()
                .iter()
                .map(|&n| n.to_owned())
                .collect(),
            geometry_shader: enabled.geometry_shader,
            fragment_stores_and_atomics: enabled.fragment_stores_and_atomics,
            depth_clamp: enabled.depth_clamp,
            debug_utils: shared.extensions().contains(&ash::ext::debug_utils::NAME),
        };
        // SAFETY: wgpu's live device, opened with the features stated, which the caller keeps beyond the
        // context.
        let context = unsafe { hrts::Context::adopt(&vulkan, frames_in_flight) }?;
        Ok(Self {
            context,
            adapter: adapter.clone(),
        })
    }

    /// The plugin's context, for what this file does not wrap (lights, CPU geometry, reports).
    pub fn context(&self) -> &hrts::Context {
        &self.context
    }

    /// Hands the meshes to the plugin: their buffers as they are, one draw per instance.
    pub fn set_meshes(&self, meshes: &[ShadowMesh<'_>]) -> Result<()> {
        let draws: Vec<Vec<hrts::Draw>> = meshes
            .iter()
            .map(|m| {
                m.instances
                    .iter()
                    .map(|&transform| hrts::Draw {
                        first_index: 0,
                        index_count: m.index_count,
                        transform,
                        base_vertex: 0,
                    })
                    .collect()
            })
            .collect();
        let geometry: Vec<hrts::VulkanMesh> = meshes
            .iter()
            .zip(&draws)
            .map(|(m, draws)| {
                let [min, max] = m.bounds;
                hrts::VulkanMesh {
                    vertex_buffer: m.vertices.raw,
                    vertex_buffer_size: m.vertices.buffer.size(),
                    vertex_offset: 0,
                    vertex_stride: 12,
                    vertex_count: m.vertex_count,
                    index_buffer: m.indices.raw,
                    index_buffer_size: m.indices.buffer.size(),
                    index_offset: 0,
                    index_type: match m.index_format {
                        wgpu::IndexFormat::Uint16 => hrts::IndexType::Uint16,
                        wgpu::IndexFormat::Uint32 => hrts::IndexType::Uint32,
                    },
                    index_count: m.index_count,
                    draws,
                    bounds: hrts::Bounds { min, max },
                    vertex_format: vk::Format::R32G32B32_SFLOAT.as_raw() as u32,
                    position_scale: glam::Vec3::ZERO,
                    position_offset: glam::Vec3::ZERO,
                }
            })
            .collect();
        // SAFETY: the buffers are live storage buffers of the adopted device, of their sizes; the renderer
        // keeps them beyond the context.
        Ok(unsafe { self.context.set_geometry_vulkan(&geometry) }?)
    }

    /// Moves the instances: one transform per instance of every mesh, in mesh order.
    pub fn move_instances(&self, transforms: &[Mat4]) -> Result<()> {
        Ok(self.context.set_draw_transforms(transforms)?)
    }

    /// Hands the renderer's images to the plugin.
    pub fn set_targets(&self, targets: &ShadowTargets<'_>) -> Result<()> {
        let size = targets.depth.size();
        // SAFETY: the adapter outlives the guard.
        let adapter = unsafe { self.adapter.as_hal::<Vulkan>() }.context("not a Vulkan adapter")?;
        let image = |t: &wgpu::Texture| -> Result<hrts::TargetImage> {
            // SAFETY: a live texture of the adopted device.
            let hal = unsafe { t.as_hal::<Vulkan>() }.context("not a Vulkan texture")?;
            Ok(hrts::TargetImage {
                // SAFETY: as above.
                image: unsafe { hal.raw_handle() }.as_raw(),
                usage: vulkan_usage(t),
                format: adapter.texture_format_as_raw(t.format()).as_raw() as u32,
            })
        };
        let targets = hrts::Targets {
            width: size.width,
            height: size.height,
            depth: image(targets.depth)?,
            normal: image(targets.normal)?,
            normal_encoding: targets.normal_encoding,
            normal_space: targets.normal_space,
            output: image(targets.shadow)?,
            output_layers: targets.shadow.depth_or_array_layers(),
        };
        // SAFETY: live textures of the adopted device, created with the usages and formats stated; the
        // renderer keeps them beyond the context.
        Ok(unsafe { self.context.set_targets(&targets) }?)
    }

    /// Records the frame's shadows: `before` leaves the targets in the states the plugin reads them in,
    /// then the plugin's passes go into their own command encoder (wgpu records its passes when an encoder
    /// finishes, so hal commands in the same encoder would run before them). Submit the two buffers in
    /// order; wgpu's next use of the shadow image waits for the plugin's copy into it.
    pub fn record(
        &self,
        device: &wgpu::Device,
        before: &mut wgpu::CommandEncoder,
        targets: &ShadowTargets<'_>,
        frame: &ShadowFrame,
    ) -> Result<wgpu::CommandBuffer> {
        let state = |texture, state| wgpu::TextureTransition {
            texture,
            selector: None,
            state,
        };
        before.transition_resources(
            std::iter::empty(),
            [
                state(targets.depth, wgpu::TextureUses::RESOURCE),
                state(targets.normal, wgpu::TextureUses::RESOURCE),
                state(targets.shadow, wgpu::TextureUses::COPY_DST),
            ]
            .into_iter(),
        );
        let vulkan_clip = Mat4::from_scale(glam::Vec3::new(1.0, -1.0, 1.0));
        // The layouts wgpu gives a sampled texture: depth formats are read in a depth read-only layout.
        let depth_layout = if targets.depth.format().is_depth_stencil_format() {
            vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL
        } else {
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL
        };
        let transfer_dst = vk::ImageLayout::TRANSFER_DST_OPTIMAL.as_raw();
        let [min, max] = frame.bounds;
        let plugin_frame = hrts::Frame {
            frame_index: frame.index,
            view: frame.view,
            proj: vulkan_clip * frame.proj,
            camera_position: frame.camera_position,
            lights: frame.lights,
            depth_layout: depth_layout.as_raw(),
            normal_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL.as_raw(),
            output_layout_before: transfer_dst,
            output_layout_after: transfer_dst,
            bounds: Some(hrts::Bounds { min, max }),
            deformed: &[],
        };
        let mut plugin = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("shadows"),
        });
        // SAFETY: nothing else records into `plugin` while the callback runs; the plugin leaves the command
        // buffer open and the images in the layouts wgpu's states above give them; the renderer submits
        // the buffer and waits for its frames before it drops the context.
        unsafe {
            plugin.as_hal_mut::<Vulkan, _, _>(|encoder| {
                let encoder = encoder.context("not a Vulkan command encoder")?;
                let command_buffer = encoder.raw_handle().as_raw();
                anyhow::Ok(self.context.record_frame(command_buffer, &plugin_frame)?)
            })
        }?;
        Ok(plugin.finish())
    }

    /// The report of frame `frame_index` (completed on the GPU).
    pub fn report(&self, frame_index: u64) -> Result<hrts::FrameReport> {
        Ok(self.context.frame_report(frame_index, 0)?)
    }

    /// GPU milliseconds of the passes of frame `frame_index`'s `lights` lights (completed on the GPU);
    /// `None` if the frame has no timings (a device without timestamps).
    pub fn gpu_milliseconds(&self, frame_index: u64, lights: u32) -> Result<Option<f64>> {
        let mut sum = 0.0;
        let mut timed = false;
        for light in 0..lights {
            let report = self.context.frame_report(frame_index, light)?;
            sum += report.gpu_milliseconds;
            timed |= !report.timings.is_empty();
        }
        Ok(timed.then_some(sum))
    }
}

/// The `VkImageUsageFlags` of a texture's wgpu usages.
fn vulkan_usage(texture: &wgpu::Texture) -> u32 {
    let u = texture.usage();
    let depth = texture.format().is_depth_stencil_format();
    let mut flags = vk::ImageUsageFlags::empty();
    for (wgpu_usage, vulkan) in [
        (
            wgpu::TextureUsages::COPY_SRC,
            vk::ImageUsageFlags::TRANSFER_SRC,
        ),
        (
            wgpu::TextureUsages::COPY_DST,
            vk::ImageUsageFlags::TRANSFER_DST,
        ),
        (
            wgpu::TextureUsages::TEXTURE_BINDING,
            vk::ImageUsageFlags::SAMPLED,
        ),
        (
            wgpu::TextureUsages::STORAGE_BINDING,
            vk::ImageUsageFlags::STORAGE,
        ),
        (
            wgpu::TextureUsages::RENDER_ATTACHMENT,
            if depth {
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
            } else {
                vk::ImageUsageFlags::COLOR_ATTACHMENT
            },
        ),
    ] {
        if u.contains(wgpu_usage) {
            flags |= vulkan;
        }
    }
    flags.as_raw()
}

/// One layer of a texture copied into a mappable buffer.
pub struct ReadBack {
    buffer: wgpu::Buffer,
    width: u32,
    height: u32,
    texel: u32,
    row_pitch: u32,
}

impl ReadBack {
    /// Records the copy of `texture`'s first layer.
    pub fn record(
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
    ) -> Self {
        Self::record_layer(device, encoder, texture, 0)
    }

    /// Records the copy of layer `layer` of `texture` (a single-sample colour texture with `COPY_SRC`).
    pub fn record_layer(
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        layer: u32,
    ) -> Self {
        let texel = texture.format().block_copy_size(None).unwrap_or(4);
        let (width, height) = (texture.width(), texture.height());
        let row_pitch = (width * texel).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size: u64::from(row_pitch) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer,
                },
                ..texture.as_image_copy()
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row_pitch),
                    rows_per_image: None,
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        Self {
            buffer,
            width,
            height,
            texel,
            row_pitch,
        }
    }

    /// The texels' bytes, tightly packed (after the submission completed).
    pub fn bytes(&self, device: &wgpu::Device) -> Result<Vec<u8>> {
        let slice = self.buffer.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            let _ = sender.send(result);
        });
        device.poll(wgpu::PollType::wait_indefinitely())?;
        receiver
            .recv()
            .context("the read-back's mapping was dropped")?
            .context("mapping the read-back")?;
        let mapped = slice.get_mapped_range();
        let row = (self.width * self.texel) as usize;
        let bytes = (0..self.height as usize)
            .flat_map(|y| {
                let start = y * self.row_pitch as usize;
                mapped[start..start + row].to_vec()
            })
            .collect();
        drop(mapped);
        self.buffer.unmap();
        Ok(bytes)
    }

    /// The texels of a one-channel `format` as f32 (after the submission completed), row by row from the
    /// top.
    pub fn texels(&self, device: &wgpu::Device, format: wgpu::TextureFormat) -> Result<Vec<f32>> {
        let bytes = self.bytes(device)?;
        Ok(match format {
            wgpu::TextureFormat::R8Unorm => bytes.iter().map(|&b| f32::from(b) / 255.0).collect(),
            wgpu::TextureFormat::R16Float => bytes
                .chunks_exact(2)
                .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32())
                .collect(),
            wgpu::TextureFormat::R32Float => bytemuck::pod_collect_to_vec(&bytes),
            other => bail!("shadow format {other:?} is not R8Unorm, R16Float or R32Float"),
        })
    }
}

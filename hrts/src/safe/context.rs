//! [`Context`]: a plugin context, destroyed on drop, and the devices it is created on.

use super::config::Config;
use super::enums::{PassMask, Resource};
use super::error::{check, Error, Result};
use super::frame::{Frame, ResourceReadback, Targets};
use super::geometry::{CpuGeometry, VulkanMesh};
use super::report::{Capabilities, FrameReport, ResourceInfo};
use crate::types::*;
use glam::{Mat4, Vec3};
use std::ffi::{c_char, CString};
use std::ptr::NonNull;

/// The engine's Vulkan device, adopted (never destroyed) by the plugin (`HrtsVulkanDevice`). The handles
/// are raw Vulkan handles.
#[derive(Debug, Clone)]
pub struct VulkanDevice {
    /// The engine's `vkGetInstanceProcAddr` (`None`: the plugin loads the Vulkan loader itself).
    pub get_instance_proc_addr: HrtsGetInstanceProcAddr,
    /// `VkInstance` (created for Vulkan 1.3 or later).
    pub instance: u64,
    /// `VkPhysicalDevice`.
    pub physical_device: u64,
    /// `VkDevice`, created with Vulkan 1.3 `dynamicRendering` and `synchronization2` enabled.
    pub device: u64,
    /// Queue family of the command buffers the plugin records into (graphics + compute).
    pub queue_family_index: u32,
    /// Queue index within that family.
    pub queue_index: u32,
    /// Device extensions the engine enabled.
    pub enabled_extensions: Vec<CString>,
    /// Whether `geometryShader` is enabled (needed by the software conservative-raster path).
    pub geometry_shader: bool,
    /// Whether `fragmentStoresAndAtomics` is enabled (required).
    pub fragment_stores_and_atomics: bool,
    /// Whether `depthClamp` is enabled.
    pub depth_clamp: bool,
    /// Whether the instance enabled `VK_EXT_debug_utils` (per-pass debug labels).
    pub debug_utils: bool,
}

/// A device of the plugin's own, for simple hosts and capability queries.
#[derive(Debug, Clone, Default)]
pub struct HeadlessOptions {
    /// Pick the device whose name contains this (`None`: the best GPU, else lavapipe).
    pub device_name_filter: Option<CString>,
    /// Enable the Khronos validation layer.
    pub enable_validation: bool,
    /// The most frames recorded before waiting for the oldest, 1..=`HRTS_MAX_FRAMES_IN_FLIGHT` (0: 3).
    pub frames_in_flight: u32,
}

/// A plugin context: the configured lights, the geometry, the engine's images and the passes built on
/// them. Dropping it destroys it (`hrts_context_destroy`); the engine must have waited for every frame it
/// recorded.
///
/// Every method calls the `hrts_*` function it names, so what a Rust host gets is what a C engine gets.
/// Methods that hand the plugin raw Vulkan handles are `unsafe`: the plugin checks every number, size and
/// enumeration, but it cannot check that a handle names a live object. The context is a handle to the
/// plugin's state, so its methods take `&self`, as a wgpu device's do; it may move to another thread but
/// is never used from two at once (`Send`, not `Sync`), as the C ABI requires.
///
/// ```no_run
/// use hrts::glam::{Mat4, Vec3};
/// use hrts::{Config, Context, CpuGeometry, Draw, HeadlessOptions, ShadowMode};
///
/// # fn main() -> Result<(), hrts::Error> {
/// let context = Context::headless(&HeadlessOptions::default())?;
/// println!("shadows on {}", context.capabilities()?.device_name);
/// context.configure(&Config { mode: ShadowMode::Hard, ..Config::default() })?;
/// let positions = [Vec3::ZERO, Vec3::X, Vec3::Z];
/// let draw = Draw { first_index: 0, index_count: 3, transform: Mat4::IDENTITY, base_vertex: 0 };
/// context.set_geometry_cpu(&CpuGeometry { positions: &positions, indices: &[0, 1, 2], draws: &[draw] })?;
/// // An engine adopts its device instead (`Context::adopt`), hands over its images
/// // (`Context::set_targets`) and records each frame into its command buffer (`Context::record_frame`).
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct Context {
    handle: NonNull<HrtsContext>,
}

// SAFETY: the C ABI may be called on a context from any thread, one at a time; `Context` is not `Sync`, so
// no two threads call it at once.
unsafe impl Send for Context {}

/// `len` as a C count of `what`.
fn count(call: &'static str, what: &str, len: usize) -> Result<u32> {
    u32::try_from(len).map_err(|_| {
        Error::new(
            call,
            HrtsResult::ErrorInvalidArgument,
            format!("{len} {what} are more than a C count holds"),
        )
    })
}

impl Context {
    /// Creates a context on the engine's `device` (`hrts_context_create`). `frames_in_flight`: the most
    /// frames the engine records before waiting for the oldest to complete, 1..=`HRTS_MAX_FRAMES_IN_FLIGHT`
    /// (0: 3).
    ///
    /// # Safety
    /// The handles in `device` are live Vulkan objects created as its fields state, and they outlive the
    /// context.
    pub unsafe fn adopt(device: &VulkanDevice, frames_in_flight: u32) -> Result<Self> {
        const CALL: &str = "hrts_context_create";
        let names: Vec<*const c_char> = device
            .enabled_extensions
            .iter()
            .map(|n| n.as_ptr())
            .collect();
        let vulkan = HrtsVulkanDevice {
            struct_size: size_of::<HrtsVulkanDevice>() as u32,
            get_instance_proc_addr: device.get_instance_proc_addr,
            instance: device.instance,
            physical_device: device.physical_device,
            device: device.device,
            queue_family_index: device.queue_family_index,
            queue_index: device.queue_index,
            enabled_extensions: names.as_ptr(),
            enabled_extension_count: count(CALL, "extensions", names.len())?,
            geometry_shader: device.geometry_shader.into(),
            fragment_stores_and_atomics: device.fragment_stores_and_atomics.into(),
            depth_clamp: device.depth_clamp.into(),
            debug_utils: device.debug_utils.into(),
        };
        Self::create(&HrtsContextCreateInfo {
            struct_size: size_of::<HrtsContextCreateInfo>() as u32,
            api_version: HRTS_API_VERSION,
            vulkan: &vulkan,
            device_name_filter: std::ptr::null(),
            enable_validation: 0,
            frames_in_flight,
        })
    }

    /// Creates a context on a device of the plugin's own (`hrts_context_create` without a Vulkan device).
    pub fn headless(options: &HeadlessOptions) -> Result<Self> {
        Self::create(&HrtsContextCreateInfo {
            struct_size: size_of::<HrtsContextCreateInfo>() as u32,
            api_version: HRTS_API_VERSION,
            vulkan: std::ptr::null(),
            device_name_filter: options
                .device_name_filter
                .as_ref()
                .map_or(std::ptr::null(), |f| f.as_ptr()),
            enable_validation: options.enable_validation.into(),
            frames_in_flight: options.frames_in_flight,
        })
    }

    /// `hrts_context_create` with `info`, whose pointers are valid.
    fn create(info: &HrtsContextCreateInfo) -> Result<Self> {
        let mut handle = std::ptr::null_mut();
        // SAFETY: `info` and what it points at are valid for the call; `handle` is writable. (The Vulkan
        // objects of an adopted device are the caller's contract.)
        check("hrts_context_create", unsafe {
            crate::hrts_context_create(info, &mut handle)
        })?;
        NonNull::new(handle)
            .map(|handle| Self { handle })
            .ok_or_else(|| {
                Error::new(
                    "hrts_context_create",
                    HrtsResult::ErrorInternal,
                    "succeeded without a context",
                )
            })
    }

    fn raw(&self) -> *mut HrtsContext {
        self.handle.as_ptr()
    }

    /// The device's capabilities (`hrts_get_capabilities`).
    pub fn capabilities(&self) -> Result<Capabilities> {
        const CALL: &str = "hrts_get_capabilities";
        // SAFETY: plain data; all zeros is a valid value.
        let mut c: HrtsCapabilities = unsafe { std::mem::zeroed() };
        c.struct_size = size_of::<HrtsCapabilities>() as u32;
        // SAFETY: a live context; `c` is valid with its size set.
        check(CALL, unsafe {
            crate::hrts_get_capabilities(self.raw(), &mut c)
        })?;
        Capabilities::from_c(CALL, &c)
    }

    /// Sets one light's configuration (`hrts_configure`): [`Context::configure_lights`] with one light.
    pub fn configure(&self, config: &Config) -> Result<()> {
        // SAFETY: a live context; a valid configuration.
        check("hrts_configure", unsafe {
            crate::hrts_configure(self.raw(), &config.to_c())
        })
    }

    /// Sets the lights, one configuration each, 1..=`HRTS_MAX_LIGHTS` (`hrts_configure_lights`). A light
    /// whose configuration is unchanged keeps its passes; what is replaced is destroyed once the frames
    /// recorded so far completed.
    pub fn configure_lights(&self, configs: &[Config]) -> Result<()> {
        const CALL: &str = "hrts_configure_lights";
        let c: Vec<HrtsConfig> = configs.iter().copied().map(Config::to_c).collect();
        let light_count = count(CALL, "configurations", c.len())?;
        // SAFETY: a live context; `c` holds `light_count` valid configurations.
        check(CALL, unsafe {
            crate::hrts_configure_lights(self.raw(), light_count, c.as_ptr())
        })
    }

    /// Sets the shadow casters from CPU arrays, copied (`hrts_set_geometry_cpu`).
    pub fn set_geometry_cpu(&self, geometry: &CpuGeometry<'_>) -> Result<()> {
        const CALL: &str = "hrts_set_geometry_cpu";
        let draws: Vec<HrtsDraw> = geometry.draws.iter().map(|d| d.to_c()).collect();
        let c = HrtsCpuGeometry {
            struct_size: size_of::<HrtsCpuGeometry>() as u32,
            positions: geometry.positions.as_ptr().cast(),
            vertex_count: count(CALL, "positions", geometry.positions.len())?,
            vertex_stride: size_of::<Vec3>() as u32,
            indices: geometry.indices.as_ptr(),
            index_count: count(CALL, "indices", geometry.indices.len())?,
            draws: draws.as_ptr(),
            draw_count: count(CALL, "draws", draws.len())?,
            draw_stride: size_of::<HrtsDraw>(),
        };
        // SAFETY: a live context; the arrays hold the counts stated and outlive the call.
        check(CALL, unsafe {
            crate::hrts_set_geometry_cpu(self.raw(), &c)
        })
    }

    /// Sets the shadow casters from the engine's meshes, each with its buffers, layout and draws, as they
    /// are (`hrts_set_geometry_vulkan_meshes`). The prim buffer holds the triangles mesh after mesh, draw
    /// after draw: [`Context::set_draw_transforms`] takes the draws in that order.
    ///
    /// # Safety
    /// The buffers are live `VkBuffer`s of the adopted device of the sizes stated. They stay alive until
    /// the context is dropped or, after the next geometry call, until every frame recorded before that call
    /// has completed.
    pub unsafe fn set_geometry_vulkan(&self, meshes: &[VulkanMesh<'_>]) -> Result<()> {
        const CALL: &str = "hrts_set_geometry_vulkan_meshes";
        let draws: Vec<Vec<HrtsDraw>> = meshes
            .iter()
            .map(|m| m.draws.iter().map(|d| d.to_c()).collect())
            .collect();
        for d in &draws {
            count(CALL, "draws", d.len())?;
        }
        let c: Vec<HrtsVulkanGeometry> = meshes
            .iter()
            .zip(&draws)
            .map(|(m, draws)| m.to_c(draws))
            .collect();
        let mesh_count = count(CALL, "meshes", c.len())?;
        // SAFETY: a live context; `c` holds `mesh_count` meshes whose draws outlive the call; the buffers
        // are the caller's contract.
        check(CALL, unsafe {
            crate::hrts_set_geometry_vulkan_meshes(self.raw(), c.as_ptr(), mesh_count)
        })
    }

    /// Moves the geometry's draws, as an engine moves its instances every frame
    /// (`hrts_set_draw_transforms`): one object-to-world transform per draw of the last geometry call,
    /// in mesh order. The next frame rebuilds the prim-buffer slots of the draws that moved.
    pub fn set_draw_transforms(&self, transforms: &[Mat4]) -> Result<()> {
        const CALL: &str = "hrts_set_draw_transforms";
        let draw_count = count(CALL, "transforms", transforms.len())?;
        // SAFETY: a live context; a `Mat4` is 16 contiguous floats, column-major, so `transforms` holds
        // 16 * draw_count aligned floats.
        check(CALL, unsafe {
            crate::hrts_set_draw_transforms(self.raw(), draw_count, transforms.as_ptr().cast())
        })
    }

    /// Sets the engine's images: depth and normal read, the visibility output written, one layer per
    /// light (`hrts_set_targets`).
    ///
    /// # Safety
    /// The images are live `VkImage`s of the adopted device created as `targets` states. Replaced images
    /// stay alive until the frames recorded so far completed.
    pub unsafe fn set_targets(&self, targets: &Targets) -> Result<()> {
        // SAFETY: a live context; a valid struct; the images are the caller's contract.
        check("hrts_set_targets", unsafe {
            crate::hrts_set_targets(self.raw(), &targets.to_c())
        })
    }

    /// Records every pass of `frame` into `command_buffer` (`hrts_record_frame`).
    ///
    /// # Safety
    /// As for [`Context::record_passes`].
    pub unsafe fn record_frame(&self, command_buffer: u64, frame: &Frame<'_>) -> Result<()> {
        const CALL: &str = "hrts_record_frame";
        let lights = frame_lights(CALL, frame)?;
        // SAFETY: a live context; a valid frame whose lights outlive the call; the command buffer is the
        // caller's contract.
        check(CALL, unsafe {
            crate::hrts_record_frame(self.raw(), &frame.to_c(command_buffer, &lights))
        })
    }

    /// Records the passes of `passes` of `frame` into `command_buffer` (`hrts_record_passes`), so that the
    /// engine places them in its frame: typically [`PassMask::LIGHT_SPACE`] before its depth pass and
    /// [`PassMask::SCREEN_SPACE`] after its G-buffer, in the same or a later command buffer of the same
    /// queue, submitted in recording order. The C function's documentation states the rules of frames
    /// recorded pass by pass, frames in flight and image layouts.
    ///
    /// # Safety
    /// `command_buffer` is a `VkCommandBuffer` of the adopted device's queue family in the recording state,
    /// outside a render pass; the engine submits it, and waits for it before it drops the context. The
    /// frame's deformed vertex buffers are live `VkBuffer`s until the frame completed.
    pub unsafe fn record_passes(
        &self,
        command_buffer: u64,
        frame: &Frame<'_>,
        passes: PassMask,
    ) -> Result<()> {
        const CALL: &str = "hrts_record_passes";
        let lights = frame_lights(CALL, frame)?;
        // SAFETY: a live context; a valid frame whose lights outlive the call; the command buffer is the
        // caller's contract.
        check(CALL, unsafe {
            crate::hrts_record_passes(
                self.raw(),
                &frame.to_c(command_buffer, &lights),
                passes.bits(),
            )
        })
    }

    /// The shape of `light`'s `resource` under the current configuration, geometry and targets, or `None`
    /// if the configuration does not allocate it (`hrts_get_resource_info`).
    pub fn resource_info(&self, light: u32, resource: Resource) -> Result<Option<ResourceInfo>> {
        // SAFETY: plain data; all zeros is a valid value.
        let mut c: HrtsResourceInfo = unsafe { std::mem::zeroed() };
        c.struct_size = size_of::<HrtsResourceInfo>() as u32;
        // SAFETY: a live context; `c` is valid with its size set.
        check("hrts_get_resource_info", unsafe {
            crate::hrts_get_resource_info(self.raw(), light, resource as u32, &mut c)
        })?;
        Ok((c.allocated != 0).then_some(ResourceInfo {
            width: c.width,
            height: c.height,
            layers: c.layers,
            format: c.format,
            bytes: c.bytes,
        }))
    }

    /// Records a copy of a plugin resource, as the last complete frame left it, into an engine buffer
    /// (`hrts_record_resource_readback`): [`ResourceInfo::bytes`] are written at the offset.
    ///
    /// # Safety
    /// `command_buffer` is as for [`Context::record_passes`]; the buffer is a live `VkBuffer` of the
    /// adopted device of the size stated, alive until the command buffer completed.
    pub unsafe fn record_resource_readback(
        &self,
        command_buffer: u64,
        readback: &ResourceReadback,
    ) -> Result<()> {
        // SAFETY: a live context; a valid struct; the command buffer and the buffer are the caller's
        // contract.
        check("hrts_record_resource_readback", unsafe {
            crate::hrts_record_resource_readback(self.raw(), &readback.to_c(command_buffer))
        })
    }

    /// What `light`'s passes did in frame `frame_index`, one of the last `frames_in_flight` frames
    /// recorded (`hrts_get_frame_report`). Fails with `HrtsResult::NotReady` while the GPU has not
    /// finished the frame: ask after its fence signalled.
    pub fn frame_report(&self, frame_index: u64, light: u32) -> Result<FrameReport> {
        const CALL: &str = "hrts_get_frame_report";
        // SAFETY: plain data; all zeros is a valid value.
        let mut c: HrtsFrameReport = unsafe { std::mem::zeroed() };
        c.struct_size = size_of::<HrtsFrameReport>() as u32;
        // SAFETY: a live context; `c` is valid with its size set.
        check(CALL, unsafe {
            crate::hrts_get_frame_report(self.raw(), frame_index, light, &mut c)
        })?;
        FrameReport::from_c(CALL, &c)
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // SAFETY: the handle is live (created by `hrts_context_create`) and destroyed only here; the
        // recording calls' contract has the engine wait for the context's frames first. Destroying a live
        // context cannot fail.
        unsafe { crate::hrts_context_destroy(self.raw()) };
    }
}

/// The C lights of `frame`.
fn frame_lights(call: &'static str, frame: &Frame<'_>) -> Result<Vec<HrtsLight>> {
    count(call, "lights", frame.lights.len())?;
    count(call, "deformed meshes", frame.deformed.len())?;
    Ok(frame.lights.iter().map(|l| l.to_c()).collect())
}

// `set_draw_transforms` hands `Mat4`s over as 16 floats each, `set_geometry_cpu` `Vec3`s as 3.
const _: () = assert!(size_of::<Mat4>() == 16 * size_of::<f32>());
const _: () = assert!(size_of::<Vec3>() == 3 * size_of::<f32>());

//! Device creation (headless, self-owned) and adoption of an engine's Vulkan objects.

use crate::caps::{
    device_extensions, device_type_name, has_extension, read_capabilities, Capabilities,
};
use crate::conv::Format;
use crate::error::{Result, RhiError, VkResultExt};
use crate::pipeline_stats::{
    self, capture_state, PipelineStatistics, StatisticsCapture, StatisticsUnavailable,
};
use crate::rt_device::{ray_tracing_missing, RayTracingDevice, RayTracingFeatures};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_void, CStr};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

// `adopt` and `adopt_desc` transmute between `vkGetInstanceProcAddr` function-pointer types whose ABI is
// the same only where Vulkan's calling convention is C and pointers are 64-bit: fail the build elsewhere.
const _: () = assert!(
    usize::BITS == 64,
    "the adoption of an engine's Vulkan objects assumes a 64-bit target"
);

/// What to do when no Vulkan driver or device is found.
const NO_DRIVER_ADVICE: &str = "Run scripts/setup.sh from the checkout (it installs Mesa's lavapipe, a CPU Vulkan \
     driver, with the Vulkan loader and validation layers), or install your GPU's Vulkan driver; check that \
     VK_ICD_FILENAMES / VK_DRIVER_FILES, if set, name an existing driver manifest.";
/// How to create a headless device.
#[derive(Debug, Clone, Default)]
pub struct DeviceDesc {
    /// Enable `VK_LAYER_KHRONOS_validation`; device creation fails if the layer is missing.
    pub validation: bool,
    /// With `validation`: also enable the layer's synchronization validation (hazards between commands,
    /// command buffers and submissions, reported as errors whose message ids begin with `SYNC-HAZARD-`),
    /// through whichever of `VK_EXT_layer_settings` and `VK_EXT_validation_features` the installed layer
    /// offers ([`Device::synchronization_validation`] tells which); device creation fails if it offers
    /// neither.
    pub synchronization_validation: bool,
    /// Only accept devices whose name contains this (case-insensitive), e.g. "llvmpipe" or "NVIDIA".
    pub device_filter: Option<String>,
    /// Enable `VK_KHR_pipeline_executable_properties` where the device offers it, and capture what the
    /// driver says of every pipeline created (registers, spills, instructions, as it names them):
    /// [`Device::pipeline_statistics`], and logged under the target `hrts::pipeline_statistics`.
    pub pipeline_statistics: bool,
}

impl DeviceDesc {
    /// Reads `HRTS_VALIDATION` (1/true enables validation), `HRTS_DEVICE` (device-name filter) and
    /// `HRTS_PIPELINE_STATISTICS` (1/true captures the pipelines' statistics).
    pub fn from_env() -> Self {
        let device_filter = std::env::var("HRTS_DEVICE").ok().filter(|s| !s.is_empty());
        Self {
            validation: env_flag("HRTS_VALIDATION"),
            synchronization_validation: false,
            device_filter,
            pipeline_statistics: env_flag("HRTS_PIPELINE_STATISTICS"),
        }
    }
}

/// Whether the environment variable `name` is 1, true, yes or on.
fn env_flag(name: &str) -> bool {
    std::env::var(name).is_ok_and(|v| matches!(v.as_str(), "1" | "true" | "yes" | "on"))
}

/// How synchronization validation was enabled on a device's instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SyncValidation {
    /// `VK_EXT_layer_settings`: the layer's `validate_sync` setting.
    LayerSettings,
    /// `VK_EXT_validation_features`: `VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT`.
    ValidationFeatures,
}

impl SyncValidation {
    /// The instance extension that carries it.
    pub fn extension(self) -> &'static str {
        match self {
            Self::LayerSettings => "VK_EXT_layer_settings",
            Self::ValidationFeatures => "VK_EXT_validation_features",
        }
    }
}

/// Validation-layer messages seen so far on a device.
#[derive(Debug, Default)]
pub struct ValidationLog {
    errors: AtomicU32,
    warnings: AtomicU32,
    hazards: AtomicU32,
    messages: Mutex<Vec<String>>,
}

impl ValidationLog {
    /// Number of validation errors reported.
    pub fn errors(&self) -> u32 {
        self.errors.load(Ordering::SeqCst)
    }
    /// Number of validation warnings reported.
    pub fn warnings(&self) -> u32 {
        self.warnings.load(Ordering::SeqCst)
    }
    /// Number of synchronization hazards reported (message ids `SYNC-HAZARD-*`, whatever their severity;
    /// those reported as errors are counted by [`ValidationLog::errors`] too).
    pub fn hazards(&self) -> u32 {
        self.hazards.load(Ordering::SeqCst)
    }
    /// The first messages (errors and warnings), for test failure output.
    pub fn messages(&self) -> Vec<String> {
        self.messages.lock().map(|m| m.clone()).unwrap_or_default()
    }
    fn record(&self, error: bool, hazard: bool, text: String) {
        if hazard {
            self.hazards.fetch_add(1, Ordering::SeqCst);
        }
        if error {
            self.errors.fetch_add(1, Ordering::SeqCst);
            log::error!("validation: {text}");
        } else {
            self.warnings.fetch_add(1, Ordering::SeqCst);
            log::warn!("validation: {text}");
        }
        if let Ok(mut m) = self.messages.lock() {
            if m.len() < 64 {
                m.push(text);
            }
        }
    }
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: `user` is the `ValidationLog` kept alive by `Shared` for the messenger's lifetime; `data` is
    // valid for the duration of the callback per the Vulkan spec. No panic may unwind into the driver.
    let _ = std::panic::catch_unwind(|| unsafe {
        let log = &*(user as *const ValidationLog);
        let text = if data.is_null() || (*data).p_message.is_null() {
            String::from("(no message)")
        } else {
            CStr::from_ptr((*data).p_message)
                .to_string_lossy()
                .into_owned()
        };
        let hazard = !data.is_null()
            && !(*data).p_message_id_name.is_null()
            && CStr::from_ptr((*data).p_message_id_name)
                .to_bytes()
                .starts_with(b"SYNC-HAZARD-");
        if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            log.record(true, hazard, text);
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            log.record(false, hazard, text);
        }
    });
    vk::FALSE
}

/// State shared by the device and every resource created from it.
pub(crate) struct Shared {
    entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    physical: vk::PhysicalDevice,
    queue_family: u32,
    queue_index: u32,
    enabled_extensions: Vec<String>,
    enabled_features: EnabledFeatures,
    pub(crate) device: ash::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) caps: Capabilities,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    pub(crate) debug_utils: Option<ash::ext::debug_utils::Device>,
    pub(crate) nearest_sampler: vk::Sampler,
    /// Acceleration structures and ray-tracing pipelines, or why they are unavailable.
    pub(crate) ray_tracing: std::result::Result<RayTracingDevice, String>,
    /// The pipelines' statistics, when asked for and offered; else why not.
    pub(crate) pipeline_statistics: std::result::Result<StatisticsCapture, StatisticsUnavailable>,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    validation: Arc<ValidationLog>,
    sync_validation: Option<SyncValidation>,
    owned: bool,
}

impl Drop for Shared {
    fn drop(&mut self) {
        // SAFETY: every resource holds an Arc<Shared>, so none is alive now; the device is idle after the wait
        // (an adopted device's engine has finished the plugin's work: its contract).
        unsafe {
            if self.owned {
                let _ = self.device.device_wait_idle();
            }
            self.device.destroy_sampler(self.nearest_sampler, None);
            ManuallyDrop::drop(&mut self.allocator);
            if self.owned {
                self.device.destroy_device(None);
                if let Some((utils, messenger)) = self.messenger.take() {
                    utils.destroy_debug_utils_messenger(messenger, None);
                }
                self.instance.destroy_instance(None);
            }
        }
    }
}

/// A Vulkan device with a graphics+compute queue, a memory allocator and its capabilities.
pub struct Device {
    pub(crate) shared: Arc<Shared>,
    /// `submit_and_wait`'s command pool, command buffer and fence; its lock also serialises this device's
    /// own queue submissions, so `Device` may be shared between threads.
    pub(crate) submitter: Mutex<Submitter>,
}

/// The command buffer and fence that every `submit_and_wait` of a device reuses (created by the first),
/// and their pool.
///
/// Reused rather than allocated and freed per submission: Debian 12's Khronos validation layer (1.3.239)
/// retires submissions on a thread of its own, which can drop the last reference to a command buffer the
/// application has just freed; its destructor then erases the command buffer's debug labels from a map
/// of the instance without the lock that the application thread's label calls take, corrupting the heap
/// (docs/heap_corruption.md; fixed in the layer after 1.3.239). A command buffer that is never freed
/// while the device lives is never destroyed on that thread.
pub(crate) struct Submitter {
    pub(crate) pool: vk::CommandPool,
    /// Null until the first submission.
    pub(crate) cmd: vk::CommandBuffer,
    /// Null until the first submission; unsignalled between submissions.
    pub(crate) fence: vk::Fence,
}

/// `vkGetInstanceProcAddr` as a plain C function pointer (`VkInstance` is a pointer-sized handle).
pub type RawGetInstanceProcAddr = unsafe extern "C" fn(
    instance: *mut c_void,
    name: *const std::ffi::c_char,
) -> Option<unsafe extern "C" fn()>;

/// Core features an engine enabled on its device that the passes care about.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EnabledFeatures {
    /// `geometryShader` (software conservative raster, G-buffer primitive ids).
    pub geometry_shader: bool,
    /// `fragmentStoresAndAtomics` (required: the primitive map's UAV writes).
    pub fragment_stores_and_atomics: bool,
    /// `depthClamp`.
    pub depth_clamp: bool,
    /// `shaderFloat64`.
    pub shader_float64: bool,
}

/// The engine's Vulkan objects handed to [`Device::adopt`], as raw handles. The RHI never destroys them.
#[derive(Debug, Clone)]
pub struct AdoptDesc {
    /// `vkGetInstanceProcAddr` of the engine's loader.
    pub get_instance_proc_addr: RawGetInstanceProcAddr,
    /// The engine's `VkInstance` (Vulkan 1.3).
    pub instance: u64,
    /// The `VkPhysicalDevice` the engine's device was created from.
    pub physical_device: u64,
    /// The engine's `VkDevice`; it must have Vulkan 1.3 `dynamicRendering` and `synchronization2` enabled.
    pub device: u64,
    /// Family of the queue the engine submits the plugin's work on (graphics + compute).
    pub queue_family_index: u32,
    /// Index of that queue within its family.
    pub queue_index: u32,
    /// Device extensions the engine enabled.
    pub enabled_extensions: Vec<String>,
    /// Core features the engine enabled.
    pub enabled_features: EnabledFeatures,
    /// Whether the engine's instance enabled `VK_EXT_debug_utils` (per-pass labels are emitted if so).
    pub debug_utils: bool,
}

const REQUIRED_API: u32 = vk::API_VERSION_1_3;

struct Candidate {
    pd: vk::PhysicalDevice,
    name: String,
    rank: u32,
    family: u32,
}

impl Device {
    /// Creates an instance and a device of its own: the best GPU if any passes selection, else a CPU device
    /// such as lavapipe. Logs every device and why it was rejected.
    pub fn new_headless(desc: &DeviceDesc) -> Result<Self> {
        // SAFETY: loading the system Vulkan loader; the Entry keeps it loaded for the device's lifetime.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| RhiError::Loader(e.to_string()))?;
        let validation_layer = c"VK_LAYER_KHRONOS_validation";
        // SAFETY: plain enumeration calls on a loaded entry.
        let layers = unsafe { entry.enumerate_instance_layer_properties() }
            .call("vkEnumerateInstanceLayerProperties")?;
        let inst_exts = unsafe { entry.enumerate_instance_extension_properties(None) }
            .call("vkEnumerateInstanceExtensionProperties")?;
        let has_layer = layers
            .iter()
            .any(|l| l.layer_name_as_c_str() == Ok(validation_layer));
        if desc.validation && !has_layer {
            return Err(RhiError::ValidationUnavailable);
        }
        let has_debug_utils = inst_exts
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::debug_utils::NAME));
        let sync_validation = if desc.validation && desc.synchronization_validation {
            // SAFETY: a plain enumeration call naming an installed layer.
            let layer_exts =
                unsafe { entry.enumerate_instance_extension_properties(Some(validation_layer)) }
                    .call("vkEnumerateInstanceExtensionProperties")?;
            let offers = |name: &CStr| {
                layer_exts
                    .iter()
                    .any(|e| e.extension_name_as_c_str() == Ok(name))
            };
            let mechanism = if offers(ash::ext::layer_settings::NAME) {
                SyncValidation::LayerSettings
            } else if offers(ash::ext::validation_features::NAME) {
                SyncValidation::ValidationFeatures
            } else {
                return Err(RhiError::MissingFeature(
                    "synchronization validation: the validation layer offers neither VK_EXT_layer_settings nor \
                     VK_EXT_validation_features"
                        .into(),
                ));
            };
            log::info!(
                "synchronization validation on, through {}",
                mechanism.extension()
            );
            Some(mechanism)
        } else {
            None
        };
        let app_name = c"hybrid-rt-shadows";
        let app = vk::ApplicationInfo::default()
            .application_name(app_name)
            .engine_name(app_name)
            .api_version(REQUIRED_API);
        let layer_ptrs: Vec<*const std::ffi::c_char> = if desc.validation {
            vec![validation_layer.as_ptr()]
        } else {
            vec![]
        };
        let mut ext_ptrs: Vec<*const std::ffi::c_char> = if has_debug_utils {
            vec![ash::ext::debug_utils::NAME.as_ptr()]
        } else {
            vec![]
        };
        ext_ptrs.extend(sync_validation.map(|m| match m {
            SyncValidation::LayerSettings => ash::ext::layer_settings::NAME.as_ptr(),
            SyncValidation::ValidationFeatures => ash::ext::validation_features::NAME.as_ptr(),
        }));
        let validate_sync: vk::Bool32 = vk::TRUE;
        // One VkBool32 (ash's `values` takes bytes and would count 4 values).
        let settings = [vk::LayerSettingEXT {
            value_count: 1,
            p_values: std::ptr::from_ref(&validate_sync).cast(),
            ..vk::LayerSettingEXT::default()
                .layer_name(validation_layer)
                .setting_name(c"validate_sync")
                .ty(vk::LayerSettingTypeEXT::BOOL32)
        }];
        let mut layer_settings = vk::LayerSettingsCreateInfoEXT::default().settings(&settings);
        let sync_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation_features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync_features);
        let validation = Arc::new(ValidationLog::default());
        let mut messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                    | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(debug_callback))
            .user_data(Arc::as_ptr(&validation) as *mut c_void);
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layer_ptrs)
            .enabled_extension_names(&ext_ptrs);
        if desc.validation && has_debug_utils {
            info = info.push_next(&mut messenger_info);
        }
        match sync_validation {
            Some(SyncValidation::LayerSettings) => info = info.push_next(&mut layer_settings),
            Some(SyncValidation::ValidationFeatures) => {
                info = info.push_next(&mut validation_features)
            }
            None => {}
        }
        // SAFETY: all pointers in `info` outlive the call.
        let instance = match unsafe { entry.create_instance(&info, None) } {
            Ok(instance) => instance,
            Err(vk::Result::ERROR_INCOMPATIBLE_DRIVER) => {
                return Err(RhiError::NoDevice(format!(
                    "vkCreateInstance found no Vulkan driver (ERROR_INCOMPATIBLE_DRIVER). {NO_DRIVER_ADVICE}"
                )))
            }
            Err(result) => {
                return Err(RhiError::Vulkan {
                    call: "vkCreateInstance",
                    result,
                })
            }
        };
        let messenger = if desc.validation && has_debug_utils {
            let utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
            // SAFETY: `messenger_info` points at `validation`, which `Shared` keeps alive past the messenger.
            let m = unsafe { utils.create_debug_utils_messenger(&messenger_info, None) }
                .call("vkCreateDebugUtilsMessengerEXT")?;
            Some((utils, m))
        } else {
            None
        };
        let destroy_instance =
            |messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>| {
                // SAFETY: nothing was created from the instance except the messenger, destroyed first.
                unsafe {
                    if let Some((u, m)) = messenger {
                        u.destroy_debug_utils_messenger(m, None);
                    }
                    instance.destroy_instance(None);
                }
            };
        let chosen = match select_physical_device(&instance, desc.device_filter.as_deref()) {
            Ok(c) => c,
            Err(e) => {
                destroy_instance(messenger);
                return Err(e);
            }
        };
        log::info!("using Vulkan device '{}'", chosen.name);
        let exts = device_extensions(&instance, chosen.pd);
        let mut enable: Vec<&CStr> = Vec::new();
        if has_extension(&exts, ash::ext::conservative_rasterization::NAME) {
            enable.push(ash::ext::conservative_rasterization::NAME);
        }
        let rt_missing = ray_tracing_missing(
            |name| has_extension(&exts, name),
            ray_tracing_features(&instance, chosen.pd, &exts),
        );
        let statistics = capture_state(
            desc.pipeline_statistics,
            has_extension(&exts, pipeline_stats::EXTENSION)
                && pipeline_executable_info(&instance, chosen.pd),
        );
        if statistics.is_ok() {
            enable.push(pipeline_stats::EXTENSION);
        } else if statistics == Err(StatisticsUnavailable::NotOffered) {
            log::warn!(
                "pipeline statistics unavailable: the device lacks {}",
                pipeline_stats::EXTENSION.to_string_lossy()
            );
        }
        let ray_tracing = rt_missing.is_empty();
        if ray_tracing {
            enable.extend(RayTracingDevice::EXTENSIONS);
        } else {
            log::info!(
                "ray tracing unavailable: the device lacks {}",
                rt_missing.join(", ")
            );
        }
        // SAFETY: `chosen.pd` was enumerated from `instance`.
        let supported = unsafe { instance.get_physical_device_features(chosen.pd) };
        let features = vk::PhysicalDeviceFeatures::default()
            .geometry_shader(supported.geometry_shader == vk::TRUE)
            .fragment_stores_and_atomics(true)
            .vertex_pipeline_stores_and_atomics(
                supported.vertex_pipeline_stores_and_atomics == vk::TRUE,
            )
            .depth_clamp(supported.depth_clamp == vk::TRUE)
            .shader_float64(supported.shader_float64 == vk::TRUE);
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true);
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default().buffer_device_address(true);
        let mut f_accel = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default()
            .acceleration_structure(true);
        let mut f_rt_pipeline =
            vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default().ray_tracing_pipeline(true);
        let mut f_statistics = vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default()
            .pipeline_executable_info(true);
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(chosen.family)
            .queue_priorities(&priorities)];
        let enable_ptrs: Vec<*const std::ffi::c_char> = enable.iter().map(|n| n.as_ptr()).collect();
        let mut dinfo = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&enable_ptrs)
            .enabled_features(&features)
            .push_next(&mut f13);
        if ray_tracing {
            dinfo = dinfo
                .push_next(&mut f12)
                .push_next(&mut f_accel)
                .push_next(&mut f_rt_pipeline);
        }
        if statistics.is_ok() {
            dinfo = dinfo.push_next(&mut f_statistics);
        }
        // SAFETY: the chained structs outlive the call; features were checked during selection.
        let device = match unsafe { instance.create_device(chosen.pd, &dinfo, None) } {
            Ok(d) => d,
            Err(e) => {
                destroy_instance(messenger);
                return Err(RhiError::Vulkan {
                    call: "vkCreateDevice",
                    result: e,
                });
            }
        };
        let enabled: Vec<String> = enable
            .iter()
            .map(|n| n.to_string_lossy().into_owned())
            .collect();
        // SAFETY: queue 0 of `chosen.family` was requested above.
        let queue = unsafe { device.get_device_queue(chosen.family, 0) };
        Self::from_parts(PartsDesc {
            entry,
            instance,
            physical: chosen.pd,
            device,
            queue,
            queue_family: chosen.family,
            queue_index: 0,
            enabled_extensions: enabled,
            features,
            has_debug_utils,
            messenger,
            validation,
            sync_validation,
            owned: true,
            pipeline_statistics: statistics,
            ray_tracing: if ray_tracing {
                Ok(())
            } else {
                Err(rt_missing.join(", "))
            },
        })
    }

    /// Adopts an engine's instance, device and queue without owning them.
    ///
    /// # Safety
    /// All handles must be valid, belong together, and outlive the returned `Device`; the device must have
    /// been created with Vulkan 1.3 `dynamicRendering` and `synchronization2`, and the features and extensions
    /// listed in `desc` must be exactly those enabled. The engine must externally synchronise queue access.
    pub unsafe fn adopt(desc: AdoptDesc) -> Result<Self> {
        use ash::vk::Handle;
        // SAFETY: on every target where Vulkan's "system" calling convention is C (all 64-bit ones) this is
        // the ABI of vkGetInstanceProcAddr: a dispatchable handle is a pointer, the result an optional fn.
        let gipa: vk::PFN_vkGetInstanceProcAddr =
            unsafe { std::mem::transmute(desc.get_instance_proc_addr) };
        let static_fn = ash::StaticFn {
            get_instance_proc_addr: gipa,
        };
        let (instance, device) = (
            vk::Instance::from_raw(desc.instance),
            vk::Device::from_raw(desc.device),
        );
        // SAFETY: the caller guarantees the function pointer and handles are valid and belong together.
        let entry = unsafe { ash::Entry::from_static_fn(static_fn.clone()) };
        // SAFETY: as above.
        let instance = unsafe { ash::Instance::load(&static_fn, instance) };
        let problems = adoption_problems(
            &instance,
            vk::PhysicalDevice::from_raw(desc.physical_device),
            &desc,
        );
        if !problems.is_empty() {
            return Err(RhiError::MissingFeature(format!(
                "the adopted device cannot run the plugin: {}",
                problems.join("; ")
            )));
        }
        // SAFETY: as above.
        let device = unsafe { ash::Device::load(instance.fp_v1_0(), device) };
        // The engine's queue is never fetched: the plugin only records into the engine's command buffers
        // (`submit_and_wait` refuses adopted devices), and the family's queue count above is only a
        // plausibility check of what the engine created.
        let queue = vk::Queue::null();
        let f = desc.enabled_features;
        let features = vk::PhysicalDeviceFeatures::default()
            .geometry_shader(f.geometry_shader)
            .fragment_stores_and_atomics(f.fragment_stores_and_atomics)
            .depth_clamp(f.depth_clamp)
            .shader_float64(f.shader_float64);
        // The engine enabled the extension and HRTS_PIPELINE_STATISTICS asks for the capture (which also
        // needs the extension's pipelineExecutableInfo feature, enabled by the engine).
        let pipeline_statistics = capture_state(
            env_flag("HRTS_PIPELINE_STATISTICS"),
            desc.enabled_extensions
                .iter()
                .any(|e| e.as_bytes() == pipeline_stats::EXTENSION.to_bytes()),
        );
        Self::from_parts(PartsDesc {
            entry,
            instance,
            physical: vk::PhysicalDevice::from_raw(desc.physical_device),
            device,
            queue,
            queue_family: desc.queue_family_index,
            queue_index: desc.queue_index,
            enabled_extensions: desc.enabled_extensions,
            features,
            has_debug_utils: desc.debug_utils,
            messenger: None,
            validation: Arc::new(ValidationLog::default()),
            sync_validation: None,
            owned: false,
            pipeline_statistics,
            ray_tracing: Err(
                "an adopted device (the RHI cannot tell whether the engine enabled bufferDeviceAddress, \
                 accelerationStructure and rayTracingPipeline)"
                    .into(),
            ),
        })
    }

    fn from_parts(p: PartsDesc) -> Result<Self> {
        // SAFETY: `p.physical` belongs to `p.instance`.
        let families = unsafe {
            p.instance
                .get_physical_device_queue_family_properties(p.physical)
        };
        let ts_bits = families
            .get(p.queue_family as usize)
            .map_or(0, |f| f.timestamp_valid_bits);
        let caps = read_capabilities(
            &p.instance,
            p.physical,
            &p.enabled_extensions,
            &p.features,
            ts_bits,
        );
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: p.instance.clone(),
            device: p.device.clone(),
            physical_device: p.physical,
            debug_settings: Default::default(),
            buffer_device_address: p.ray_tracing.is_ok(),
            allocation_sizes: Default::default(),
        })
        .map_err(|e| RhiError::Allocation {
            name: "allocator".into(),
            message: e.to_string(),
        })?;
        let sampler_info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
        // SAFETY: valid device; the sampler is destroyed in `Shared::drop`.
        let nearest_sampler =
            unsafe { p.device.create_sampler(&sampler_info, None) }.call("vkCreateSampler")?;
        let debug_utils = p
            .has_debug_utils
            .then(|| ash::ext::debug_utils::Device::new(&p.instance, &p.device));
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(p.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and queue family.
        let command_pool = unsafe { p.device.create_command_pool(&pool_info, None) }
            .call("vkCreateCommandPool")?;
        let ray_tracing = p
            .ray_tracing
            .map(|()| RayTracingDevice::new(&p.instance, &p.device, p.physical));
        let pipeline_statistics = p
            .pipeline_statistics
            .map(|()| StatisticsCapture::new(&p.instance, &p.device));
        let shared = Arc::new(Shared {
            entry: p.entry,
            instance: p.instance,
            physical: p.physical,
            queue_family: p.queue_family,
            queue_index: p.queue_index,
            enabled_extensions: p.enabled_extensions,
            enabled_features: EnabledFeatures {
                geometry_shader: p.features.geometry_shader != 0,
                fragment_stores_and_atomics: p.features.fragment_stores_and_atomics != 0,
                depth_clamp: p.features.depth_clamp != 0,
                shader_float64: p.features.shader_float64 != 0,
            },
            device: p.device,
            queue: p.queue,
            caps,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            debug_utils,
            nearest_sampler,
            ray_tracing,
            pipeline_statistics,
            messenger: p.messenger,
            validation: p.validation,
            sync_validation: p.sync_validation,
            owned: p.owned,
        });
        Ok(Self {
            shared,
            submitter: Mutex::new(Submitter {
                pool: command_pool,
                cmd: vk::CommandBuffer::null(),
                fence: vk::Fence::null(),
            }),
        })
    }

    /// This device's objects as raw handles: what another component (such as the plugin's C ABI) needs to
    /// adopt it with [`Device::adopt`]. Valid while `self` lives.
    pub fn adopt_desc(&self) -> AdoptDesc {
        use ash::vk::Handle;
        let s = &self.shared;
        // SAFETY: Vulkan's "system" calling convention is C on every 64-bit target and a dispatchable
        // handle is a pointer, so both function types have the same ABI (the inverse of `adopt`'s).
        let get_instance_proc_addr: RawGetInstanceProcAddr =
            unsafe { std::mem::transmute(s.entry.static_fn().get_instance_proc_addr) };
        AdoptDesc {
            get_instance_proc_addr,
            instance: s.instance.handle().as_raw(),
            physical_device: s.physical.as_raw(),
            device: s.device.handle().as_raw(),
            queue_family_index: s.queue_family,
            queue_index: s.queue_index,
            enabled_extensions: s.enabled_extensions.clone(),
            enabled_features: s.enabled_features,
            debug_utils: s.debug_utils.is_some(),
        }
    }

    /// The device's capabilities.
    pub fn capabilities(&self) -> &Capabilities {
        &self.shared.caps
    }

    /// What the driver said of every pipeline created so far on this device, where it was created with
    /// [`DeviceDesc::pipeline_statistics`] and offers them; else why it captures none.
    pub fn pipeline_statistics(
        &self,
    ) -> std::result::Result<Vec<PipelineStatistics>, StatisticsUnavailable> {
        match &self.shared.pipeline_statistics {
            Ok(capture) => Ok(capture.recorded()),
            Err(why) => Err(*why),
        }
    }

    /// Whether optimally tiled images of `format` can be sampled (depth formats through their depth
    /// aspect).
    pub fn can_sample(&self, format: Format) -> bool {
        self.optimal_features(format)
            .contains(vk::FormatFeatureFlags::SAMPLED_IMAGE)
    }

    /// Whether optimally tiled images of `format` can be shader storage images.
    pub fn can_store(&self, format: Format) -> bool {
        self.optimal_features(format)
            .contains(vk::FormatFeatureFlags::STORAGE_IMAGE)
    }

    /// Whether images of `format` can be rendered to with optimal tiling: as a colour attachment, or as a
    /// depth attachment for depth formats.
    pub fn can_render(&self, format: Format) -> bool {
        let needed = if format.is_depth() {
            vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT
        } else {
            vk::FormatFeatureFlags::COLOR_ATTACHMENT
        };
        self.optimal_features(format).contains(needed)
    }

    /// Whether [`crate::Encoder::blit_into_layer`] can write optimally tiled images of `dst` from images
    /// of `src`.
    pub fn can_blit(&self, src: Format, dst: Format) -> bool {
        self.optimal_features(src)
            .contains(vk::FormatFeatureFlags::BLIT_SRC)
            && self
                .optimal_features(dst)
                .contains(vk::FormatFeatureFlags::BLIT_DST)
    }

    fn optimal_features(&self, format: Format) -> vk::FormatFeatureFlags {
        // SAFETY: the physical device belongs to this instance.
        unsafe {
            self.shared
                .instance
                .get_physical_device_format_properties(self.shared.physical, format.to_vk())
        }
        .optimal_tiling_features
    }

    /// Validation messages seen so far (empty unless validation is on).
    pub fn validation(&self) -> &ValidationLog {
        &self.shared.validation
    }

    /// How synchronization validation was enabled ([`DeviceDesc::synchronization_validation`]), or `None`
    /// where it is off (always on an adopted device: its instance is the engine's).
    pub fn synchronization_validation(&self) -> Option<SyncValidation> {
        self.shared.sync_validation
    }

    /// Waits until the GPU is idle. Only on a device of the RHI's own (see `Device::submit_and_wait`).
    pub fn wait_idle(&self) -> Result<()> {
        self.require_owned("wait_idle")?;
        let _queue = self
            .submitter
            .lock()
            .map_err(|_| RhiError::InvalidArgument("submission lock poisoned".into()))?;
        // SAFETY: valid device; its only queue is used under the lock held here.
        unsafe { self.shared.device.device_wait_idle() }.call("vkDeviceWaitIdle")
    }

    /// Whether this device was created by the RHI (rather than adopted from an engine).
    pub fn is_owned(&self) -> bool {
        self.shared.owned
    }

    pub(crate) fn require_owned(&self, what: &str) -> Result<()> {
        if self.shared.owned {
            Ok(())
        } else {
            Err(RhiError::InvalidArgument(format!(
                "{what} needs a device of the RHI's own: an adopted device's queues belong to the engine"
            )))
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        let s = match self.submitter.get_mut() {
            Ok(s) => &*s,
            Err(poisoned) => &*poisoned.into_inner(),
        };
        // SAFETY: the command buffer (freed with its pool) and the fence are used by `submit_and_wait` alone,
        // which waits for its submission. A device of our own is waited idle; an adopted one never submits
        // (`submit_and_wait` refuses it: its queues are the engine's), so it is not waited on here.
        unsafe {
            if self.shared.owned {
                let _ = self.shared.device.device_wait_idle();
            }
            if s.fence != vk::Fence::null() {
                self.shared.device.destroy_fence(s.fence, None);
            }
            self.shared.device.destroy_command_pool(s.pool, None);
        }
    }
}

struct PartsDesc {
    entry: ash::Entry,
    instance: ash::Instance,
    physical: vk::PhysicalDevice,
    device: ash::Device,
    queue: vk::Queue,
    queue_family: u32,
    queue_index: u32,
    enabled_extensions: Vec<String>,
    features: vk::PhysicalDeviceFeatures,
    has_debug_utils: bool,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    validation: Arc<ValidationLog>,
    sync_validation: Option<SyncValidation>,
    owned: bool,
    /// Ok if the pipelines' statistics are asked for and the device was created with
    /// `VK_KHR_pipeline_executable_properties` and its `pipelineExecutableInfo` feature, else why not.
    pipeline_statistics: std::result::Result<(), StatisticsUnavailable>,
    /// Ok if the device was created with ray tracing enabled, else what is missing.
    ray_tracing: std::result::Result<(), String>,
}

/// Whether `pd` supports `pipelineExecutableInfo` (it offers `VK_KHR_pipeline_executable_properties`).
fn pipeline_executable_info(instance: &ash::Instance, pd: vk::PhysicalDevice) -> bool {
    let mut f = vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f);
    // SAFETY: `pd` belongs to `instance`; the chained struct outlives the call.
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    f.pipeline_executable_info == vk::TRUE
}

/// The ray-tracing features `pd` supports (queried only for the extensions it has).
fn ray_tracing_features(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    exts: &[String],
) -> RayTracingFeatures {
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut accel = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
    let mut pipeline = vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f12);
    if has_extension(exts, ash::khr::acceleration_structure::NAME) {
        f2 = f2.push_next(&mut accel);
    }
    if has_extension(exts, ash::khr::ray_tracing_pipeline::NAME) {
        f2 = f2.push_next(&mut pipeline);
    }
    // SAFETY: `pd` belongs to `instance`; the chain holds only structs of extensions `pd` has and outlives
    // the call.
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    RayTracingFeatures {
        buffer_device_address: f12.buffer_device_address == vk::TRUE,
        acceleration_structure: accel.acceleration_structure == vk::TRUE,
        ray_tracing_pipeline: pipeline.ray_tracing_pipeline == vk::TRUE,
    }
}

/// What the engine's physical device lacks, or what the engine claims it enabled that the device does not
/// support, for the plugin to adopt it (empty: nothing).
fn adoption_problems(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    desc: &AdoptDesc,
) -> Vec<String> {
    let mut problems = Vec::new();
    // SAFETY: the caller of `adopt` guarantees `pd` belongs to `instance`.
    let props = unsafe { instance.get_physical_device_properties(pd) };
    if props.api_version < REQUIRED_API {
        problems.push(format!(
            "Vulkan {}.{} (1.3 needed)",
            vk::api_version_major(props.api_version),
            vk::api_version_minor(props.api_version)
        ));
        return problems;
    }
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f13);
    // SAFETY: as above; the chain outlives the call.
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    let core = f2.features;
    for (supported, name) in [
        (f13.dynamic_rendering, "dynamicRendering (required)"),
        (f13.synchronization2, "synchronization2 (required)"),
    ] {
        if supported == vk::FALSE {
            problems.push(format!("no {name}"));
        }
    }
    let f = desc.enabled_features;
    for (claimed, supported, name) in [
        (f.geometry_shader, core.geometry_shader, "geometryShader"),
        (
            f.fragment_stores_and_atomics,
            core.fragment_stores_and_atomics,
            "fragmentStoresAndAtomics",
        ),
        (f.depth_clamp, core.depth_clamp, "depthClamp"),
        (f.shader_float64, core.shader_float64, "shaderFloat64"),
    ] {
        if claimed && supported == vk::FALSE {
            problems.push(format!("{name} is claimed enabled but not supported"));
        }
    }
    // SAFETY: as above.
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    match families.get(desc.queue_family_index as usize) {
        None => problems.push(format!(
            "queue family {} does not exist ({} families)",
            desc.queue_family_index,
            families.len()
        )),
        Some(family) => {
            let needed = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
            if !family.queue_flags.contains(needed) {
                problems.push(format!(
                    "queue family {} lacks graphics and compute",
                    desc.queue_family_index
                ));
            }
            if desc.queue_index >= family.queue_count {
                problems.push(format!(
                    "queue {} does not exist in family {} ({} queues)",
                    desc.queue_index, desc.queue_family_index, family.queue_count
                ));
            }
        }
    }
    let supported = device_extensions(instance, pd);
    for ext in &desc.enabled_extensions {
        if !supported.iter().any(|s| s == ext) {
            problems.push(format!(
                "extension {ext} is claimed enabled but not supported"
            ));
        }
    }
    problems
}

/// Why a physical device cannot run the plugin, or None if it can.
fn rejection_reason(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    filter: Option<&str>,
    name: &str,
) -> Option<String> {
    if let Some(f) = filter {
        if !name.to_lowercase().contains(&f.to_lowercase()) {
            return Some(format!("name does not match HRTS_DEVICE filter '{f}'"));
        }
    }
    // SAFETY: `pd` was enumerated from `instance`.
    let props = unsafe { instance.get_physical_device_properties(pd) };
    if props.api_version < REQUIRED_API {
        return Some(format!(
            "Vulkan {}.{} < 1.3",
            vk::api_version_major(props.api_version),
            vk::api_version_minor(props.api_version)
        ));
    }
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f13);
    // SAFETY: as above; the chain outlives the call.
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    let core = f2.features;
    let mut missing = Vec::new();
    if f13.dynamic_rendering == vk::FALSE {
        missing.push("dynamicRendering");
    }
    if f13.synchronization2 == vk::FALSE {
        missing.push("synchronization2");
    }
    if core.fragment_stores_and_atomics == vk::FALSE {
        missing.push("fragmentStoresAndAtomics");
    }
    if !missing.is_empty() {
        return Some(format!("missing {}", missing.join(", ")));
    }
    None
}

fn select_physical_device(instance: &ash::Instance, filter: Option<&str>) -> Result<Candidate> {
    // SAFETY: valid instance.
    let pds =
        unsafe { instance.enumerate_physical_devices() }.call("vkEnumeratePhysicalDevices")?;
    let mut best: Option<Candidate> = None;
    let mut report = Vec::new();
    for pd in pds {
        // SAFETY: `pd` was just enumerated.
        let props = unsafe { instance.get_physical_device_properties(pd) };
        let name = props
            .device_name_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let kind = device_type_name(props.device_type);
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
        let family = families.iter().position(|f| {
            f.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
        });
        let reason = rejection_reason(instance, pd, filter, &name).or_else(|| {
            family
                .is_none()
                .then(|| "no graphics+compute queue".to_owned())
        });
        match (reason, family) {
            (None, Some(family)) => {
                let rank = match props.device_type {
                    vk::PhysicalDeviceType::DISCRETE_GPU => 4,
                    vk::PhysicalDeviceType::INTEGRATED_GPU => 3,
                    vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
                    vk::PhysicalDeviceType::CPU => 1,
                    _ => 0,
                };
                report.push(format!("'{name}' ({kind}): suitable, rank {rank}"));
                if best.as_ref().is_none_or(|b| rank > b.rank) {
                    best = Some(Candidate {
                        pd,
                        name,
                        rank,
                        family: family as u32,
                    });
                }
            }
            (reason, _) => {
                let r = reason.unwrap_or_default();
                log::info!("rejected Vulkan device '{name}' ({kind}): {r}");
                report.push(format!("'{name}' ({kind}): rejected, {r}"));
            }
        }
    }
    for line in &report {
        log::debug!("device selection: {line}");
    }
    best.ok_or_else(|| {
        if report.is_empty() {
            RhiError::NoDevice(format!("no Vulkan devices found. {NO_DRIVER_ADVICE}"))
        } else {
            RhiError::NoDevice(report.join("; "))
        }
    })
}

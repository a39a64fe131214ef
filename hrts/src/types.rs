//! The C-visible types. Structs start with `struct_size` (the caller's `sizeof`), which says the version of
//! the caller's header they were built with; arrays of structs without one come with a stride
//! (`HRTS_API_VERSION` says how versions are read). Enumerations passed *in* are `uint32_t` fields whose
//! values are listed by the matching enum; unknown values are rejected with `HRTS_RESULT_ERROR_INVALID_ENUM`.

use std::ffi::c_char;

/// Version of this header: `(major << 22) | (minor << 12) | patch`.
///
/// Versions. A minor version adds functions, enum values, and fields at the end of structs, never
/// elsewhere, and a struct it extends grows (a new field never takes the trailing padding of an older
/// version). A library reads the structs of every minor version of its major version from 5.1 on:
/// - `struct_size` (the `sizeof` of the caller's header) says a struct's version. The library reads the
///   fields that version has and gives the newer ones the defaults their documentation states ("API 5.x:
///   ..."); a struct the library fills is written up to the caller's `struct_size` only, the fields of
///   newer versions left out.
/// - Arrays of structs without a `struct_size` (`HrtsDraw`, `HrtsLight`, `HrtsMeshVertices`) are read at
///   the stride given beside them (`draw_stride`, `light_stride`, `deformed_stride`): the caller's `sizeof`
///   of the element, which says its version. A stride of 0, as in the structs of callers before 5.8,
///   reads the element as API 5.1 to 5.8 define it. An array of structs with a `struct_size`
///   (`hrts_configure_lights`, `hrts_set_geometry_vulkan_meshes`) is read at its first element's, which
///   every element must have.
/// - A size or stride that is the size of no version this library reads, or of a newer version than
///   the library's (the caller's header is newer), fails with `HRTS_RESULT_ERROR_STRUCT_SIZE` and a
///   message listing the sizes it reads.
/// - `hrts_context_create` refuses (`HRTS_RESULT_ERROR_VERSION`) another major version, a minor version
///   newer than the library's, and 5.0, whose headers changed layouts without changing the version
///   (`HrtsDraw` 72 then 76 bytes): its structs cannot be told apart.
pub const HRTS_API_VERSION: u32 = 5 << 22 | 11 << 12;

/// A flag in the C structs: 0 is false, any other value true. (A Rust `bool` would make any byte but 0
/// and 1 undefined behaviour when the engine writes it.)
pub type HrtsBool = u32;

/// The most lights one context shades (`hrts_configure_lights`); a point light counts once.
pub const HRTS_MAX_LIGHTS: u32 = 64;

/// The most frames in flight a context supports (`HrtsContextCreateInfo::frames_in_flight`).
pub const HRTS_MAX_FRAMES_IN_FLIGHT: u32 = 8;
const _: () = assert!(HRTS_MAX_FRAMES_IN_FLIGHT == passes::MAX_FRAMES_IN_FLIGHT);

/// Result of every call. Append-only: values never change meaning.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsResult {
    /// Success.
    Ok = 0,
    /// A required pointer argument was NULL.
    ErrorNullPointer = 1,
    /// A `struct_size` or an array's element stride is the size of no version of the struct this library
    /// reads (header/library mismatch, or a header newer than the library).
    ErrorStructSize = 2,
    /// The caller's `api_version` is of another major version, a newer minor version than the library's,
    /// or 5.0.
    ErrorVersion = 3,
    /// An enumeration field holds an unknown value.
    ErrorInvalidEnum = 4,
    /// A value is out of range (zero or absurd sizes, NaN, mismatched dimensions, ...).
    ErrorInvalidArgument = 5,
    /// The context is not live (never created, or destroyed).
    ErrorInvalidContext = 6,
    /// The call needs a state not reached yet (e.g. recording before geometry and targets are set).
    ErrorInvalidState = 7,
    /// The device lacks a feature the request needs.
    ErrorUnsupported = 8,
    /// A Vulkan call failed, or the device was lost.
    ErrorVulkan = 9,
    /// GPU or host memory ran out.
    ErrorOutOfMemory = 10,
    /// An image lacks a usage, format or size the plugin needs.
    ErrorImageUsage = 11,
    /// A bug inside the plugin was caught at the boundary; the context may be unusable.
    ErrorInternal = 12,
    /// The frame asked about has not completed on the GPU yet (not an error of the caller: ask again).
    NotReady = 13,
}

impl HrtsResult {
    /// Every result, in value order.
    pub const ALL: [Self; 14] = [
        Self::Ok,
        Self::ErrorNullPointer,
        Self::ErrorStructSize,
        Self::ErrorVersion,
        Self::ErrorInvalidEnum,
        Self::ErrorInvalidArgument,
        Self::ErrorInvalidContext,
        Self::ErrorInvalidState,
        Self::ErrorUnsupported,
        Self::ErrorVulkan,
        Self::ErrorOutOfMemory,
        Self::ErrorImageUsage,
        Self::ErrorInternal,
        Self::NotReady,
    ];

    /// The result of a C value, if it names one.
    pub fn from_c(value: i32) -> Option<Self> {
        Self::ALL.get(usize::try_from(value).ok()?).copied()
    }

    /// The C name of the result (`HRTS_RESULT_` and the variant's name in upper snake case).
    pub fn c_name(self) -> String {
        let mut name = String::from("HRTS_RESULT");
        for c in format!("{self:?}").chars() {
            if c.is_ascii_uppercase() {
                name.push('_');
            }
            name.push(c.to_ascii_uppercase());
        }
        name
    }
}

/// Conservative-rasterization path (input field values and report values).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsBinningPath {
    /// The compute path (the fastest measured on every device).
    Auto = 0,
    /// Hardware conservative raster (`VK_EXT_conservative_rasterization`).
    Hardware = 1,
    /// Geometry-shader dilation + exact per-texel test.
    Software = 2,
    /// Hardware conservative raster made to behave like D3D12 Tier 1 (1/2 px uncertainty, post-snap
    /// degenerate triangles culled) on a device with a better tier: for tier-fallback tests.
    EmulatedTier1 = 3,
    /// Compute-shader binning over 4×4-texel tiles of each triangle's bounding box.
    Compute = 4,
}

/// How PCSS shapes the penumbra.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsPenumbraFilter {
    /// The talk's shrinking penumbra: it grows only inwards from the hard shadow edge (no halo in the
    /// hybrid blend).
    Shrinking = 0,
    /// Classic PCSS: the penumbra straddles the hard edge.
    Standard = 1,
}

/// A pass of the frame, in linear (recording) order. Bit `1 << pass` in a pass mask.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsPass {
    /// Triangles in frame coordinates from the geometry (first frame, or every frame if dynamic).
    PrimBuffer = 0,
    /// Depth from the light, for PCSS.
    ShadowMap = 1,
    /// Clear and conservative raster of the deep primitive map.
    PrimitiveMap = 2,
    /// Occupancy view and statistics of the primitive map (overflow count of the report).
    Occupancy = 3,
    /// Shadow rays through the primitive map: hard visibility and blocker distance (reads depth, normal).
    RayTrace = 4,
    /// Classic single-tap shadow-map test (comparison output; reads depth, normal).
    ShadowMapTest = 5,
    /// Blocker search, penumbra estimate and PCF (reads depth, normal).
    Pcss = 6,
    /// FXAA over the ray-traced visibility.
    Fxaa = 7,
    /// Hybrid lerp factor from the blocker distance.
    LerpFactor = 8,
    /// Hybrid blend.
    Blend = 9,
    /// Fills the output with 1 (mode none).
    FillLit = 10,
    /// Copies the final visibility into the engine's output image.
    OutputCopy = 11,
}

/// Number of `HrtsPass` values.
pub const HRTS_PASS_COUNT: usize = 12;
/// The light-space passes (they read neither depth nor normal: record them before the engine's depth):
/// prim buffer and shadow map.
pub const HRTS_PASS_MASK_LIGHT_SPACE: u32 = 0x3;
/// The passes that read the engine's depth and normal, and the output copy: the primitive map is fitted to
/// the receivers the camera sees, so it comes after the depth too.
pub const HRTS_PASS_MASK_SCREEN_SPACE: u32 = 0xFFC;
/// Every pass.
pub const HRTS_PASS_MASK_ALL: u32 = 0xFFF;

/// What a frame did with a pass (report values).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsPassStatus {
    /// The configuration does not need the pass: it never runs.
    NotInPlan = 0,
    /// Recorded this frame.
    Ran = 1,
    /// Skipped: its inputs did not change since it last ran (static geometry, static light).
    UpToDate = 2,
    /// Shared by the context's lights (the prim buffer) and recorded this frame by an earlier light.
    Shared = 3,
    /// Not recorded: no frustum of the light holds a receiver in view within its range that a shadow caster
    /// may shadow this frame (see `HrtsLightDecision`).
    Culled = 4,
}

/// What the plugin decided for a light in a frame (`HrtsFrameReport::decision`), from the camera, the light's
/// frusta and range, and the bounds of the shadow casters when they are known (`HrtsFrame::bounds`, or
/// those of CPU geometry or of static Vulkan geometry).
///
/// The rule: a frustum is skipped (its pixels lit, 1) only when no shadow it traces can fall on a receiver
/// in view. Receivers are bounded by the camera alone (its frustum, widened by 1% to hold every ray origin)
/// and the light's range, never by the casters' bounds: geometry left out of the casters (floors, terrain,
/// decals) still receives, and a caster outside the view shadows receivers inside it. A frustum is skipped
/// when it holds no receiver in view within the range, or, for hard and area shadows, when the casters'
/// bounds swept away from the light (from every point of its emitter, or along every direction of a sized
/// sun) miss every receiver in view within the range and the frustum. Soft and hybrid shadows (shadow maps)
/// are culled by the view and the range alone. Where it is not skipped, a frustum's shadows are as exact
/// as its mode.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsLightDecision {
    /// Shadowed through the frusta that may shadow a receiver in view within the light's range (all, or
    /// some of a point light's or wide spot light's faces: `frusta_culled` says how many were skipped).
    Shadowed = 0,
    /// No frustum of the light may shadow a receiver in view within its range: no pass ran and its output
    /// layer is 1.
    OutOfView = 1,
}

/// A resource the plugin allocates (for the report, `hrts_get_resource_info` and
/// `hrts_record_resource_readback`). Bit `1 << resource` in `HrtsConfig::extra_outputs`.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsResource {
    /// Light-space depth, `D32_SFLOAT`, shadow_map_size².
    ShadowMap = 0,
    /// Primitive map list offsets, packed: a buffer of `uint32_t` (`R32_UINT`) holding the texels (t = y·N + x)
    /// in groups of 16, 9 words per group and one group more than the N² texels need. Word 0 of group g
    /// is the offset of texel 16g's list (bit 31 set: the group's lists are not kept, their texels are
    /// traced against every triangle); word 1 + i/2 holds texel 16g + i's offset from it in its low 16 bits
    /// for even i, its high 16 bits for odd i. Texel t holds entries [offset(t), offset(t + 1)); the last
    /// group's word 0 is the entries of all lists.
    PrimListOffsets = 1,
    /// Primitive map list entries, a buffer of `uint32_t` triangle indices (`R32_UINT`, width = capacity).
    PrimListEntries = 2,
    /// Occupancy view, `R8G8B8A8_UNORM`, N² (grey: list length on a log scale; red: no list kept, its pixels
    /// walk the BVH: past the capacity or the list limit, or in an overflowed group of the packed offsets).
    Occupancy = 3,
    /// Ray-traced visibility, `R32_SFLOAT`, 1 = lit.
    RtVisibility = 4,
    /// Ray-traced blocker distance, `R32_SFLOAT`: allocated for the hybrid (its lerp factor reads it) or
    /// when `extra_outputs` asks for it (or for the lerp factor).
    BlockerDistance = 5,
    /// Classic shadow-map visibility, `R32_SFLOAT`.
    ShadowMapVisibility = 6,
    /// PCSS visibility, `R32_SFLOAT`.
    Pcss = 7,
    /// FXAA'd ray-traced visibility, `R32_SFLOAT`.
    RtAntialiased = 8,
    /// Hybrid lerp factor, `R32_SFLOAT`.
    LerpFactor = 9,
    /// Hybrid visibility, `R32_SFLOAT`.
    Hybrid = 10,
    /// Constant 1, `R32_SFLOAT` (mode none).
    Lit = 11,
}

/// Number of `HrtsResource` values.
pub const HRTS_RESOURCE_COUNT: usize = 12;

/// Which faces are stored in the primitive map.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsFaces {
    /// Both faces (open geometry).
    Both = 0,
    /// Faces towards the light only (closed meshes).
    FrontOnly = 1,
}

/// What the plugin computes (the frame plan runs only the passes this needs).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsShadowMode {
    /// No shadow: the output is 1 everywhere and no pass runs.
    None = 0,
    /// Ray-traced hard shadows through the deep primitive map.
    Hard = 1,
    /// Soft shadows only: shadow map + PCSS.
    Soft = 2,
    /// The talk's hybrid: lerp(ray-traced, PCSS, saturate(BD / WSS * PHS)).
    Hybrid = 3,
    /// Exact soft shadows of a sized light: the visible fraction of `area_samples` light samples per pixel,
    /// each tested exactly against the triangles the primitive map lists, widened by their penumbra. A
    /// directional light's samples are directions within `pcss_angular_radius`; a spot or point light's
    /// are points of its spherical emitter of radius `pcss_spot_radius` (on the disc through its centre
    /// facing the pixel). Noise-free and deterministic; compute binning only; a point light is one cube map.
    Area = 4,
    /// The plugin chooses per light by its size: `HRTS_SHADOW_MODE_HARD` for a light of zero size
    /// (`pcss_angular_radius` 0 for a directional light, `pcss_spot_radius` 0 for a spot or point light),
    /// `HRTS_SHADOW_MODE_AREA` for a sized one. The frame report's `decision_reason` says which ("auto:
    /// hard (zero-size light)" or "auto: area (sized light)"). A light whose choice changes (its type, or
    /// its configured size) has its passes rebuilt.
    Auto = 5,
}

/// Light type.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsLightType {
    /// Parallel light along `direction`: the engine's orthographic `view_proj`, or, when `view_proj` is all
    /// zeros, the frustum the plugin fits to the shadow casters' bounds every frame.
    Directional = 0,
    /// Spot light at `position` pointing along `direction`: the engine's perspective `view_proj`, or, when
    /// `view_proj` is all zeros, frusta the plugin fits to `outer_cone` and `range`.
    Spot = 1,
    /// Point light at `position`, shining in every direction within `range`. With hard or area shadows
    /// (or none) and compute binning, the plugin builds the six cube faces around it as one primitive map (each
    /// pixel's ray looks up the face its direction from the light falls in; faces share the map's
    /// texels in proportion to their rays) and traces it once; otherwise it shadows it through the six
    /// faces as frusta and writes their minimum to the light's output layer.
    Point = 2,
}

/// How the engine's normal image encodes the surface normal (`HrtsTargets::normal_encoding`). The normal
/// may be a shading normal: a receiver whose normal faces away from the light is in its own shadow, as the
/// engine shades it, and the ray origin moves off the surface along it (a quantized encoding tilts it by
/// under 0.5°, inside the offset's margin). Where the normal lies within its encoding's tilt of
/// perpendicular to the light (a grazing light), the normal derived from a depth image decides which side
/// faces the light wherever the two agree within that tilt, so an 8-bit normal does not flip a plane lit
/// 0.1° from grazing into shadow.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsNormalEncoding {
    /// xyz, w = 0 on background pixels and nonzero on geometry (the original contract).
    XyzCoverage = 0,
    /// xyz; background pixels are those whose depth is the projection's far value.
    Xyz = 1,
    /// Octahedral in the first two channels; background known by depth.
    Octahedral = 2,
    /// No normal image: the plugin derives the normal from depth (the neighbouring pixels on the same
    /// surface); background known by depth.
    None = 3,
}

/// The space of the engine's normals (`HrtsTargets::normal_space`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsNormalSpace {
    /// World space.
    World = 0,
    /// View space of `HrtsFrame::view`.
    View = 1,
}

/// Index element type of engine geometry.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HrtsIndexType {
    /// `VK_INDEX_TYPE_UINT16`.
    Uint16 = 0,
    /// `VK_INDEX_TYPE_UINT32`.
    Uint32 = 1,
}

/// `PFN_vkGetInstanceProcAddr` (cast the loader's `vkGetInstanceProcAddr` to this type); may be NULL.
pub type HrtsGetInstanceProcAddr = Option<
    unsafe extern "C" fn(
        instance: *mut std::ffi::c_void,
        name: *const c_char,
    ) -> Option<unsafe extern "C" fn()>,
>;

/// Opaque plugin context. A handle is never a valid address: it names a registry slot and the
/// generation of the context in it, so a handle of a destroyed context stays invalid even after another
/// context reuses the slot.
pub struct HrtsContext {
    _opaque: (),
}

/// The engine's Vulkan objects, adopted (never destroyed) by the plugin.
#[repr(C)]
pub struct HrtsVulkanDevice {
    /// `sizeof(HrtsVulkanDevice)`.
    pub struct_size: u32,
    /// The engine's `PFN_vkGetInstanceProcAddr`.
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
    /// Device extensions the engine enabled (array of NUL-terminated names; may be NULL if count is 0).
    pub enabled_extensions: *const *const c_char,
    /// Number of entries in `enabled_extensions`.
    pub enabled_extension_count: u32,
    /// Whether `geometryShader` is enabled (needed by the software conservative-raster path).
    pub geometry_shader: HrtsBool,
    /// Whether `fragmentStoresAndAtomics` is enabled (required).
    pub fragment_stores_and_atomics: HrtsBool,
    /// Whether `depthClamp` is enabled.
    pub depth_clamp: HrtsBool,
    /// Whether the instance enabled `VK_EXT_debug_utils` (per-pass debug labels).
    pub debug_utils: HrtsBool,
}

/// How to create a context.
#[repr(C)]
pub struct HrtsContextCreateInfo {
    /// `sizeof(HrtsContextCreateInfo)`.
    pub struct_size: u32,
    /// `HRTS_API_VERSION` of the caller's header.
    pub api_version: u32,
    /// The engine's device to adopt, or NULL for a headless device of the plugin's own (simple hosts,
    /// capability queries).
    pub vulkan: *const HrtsVulkanDevice,
    /// Own device only: pick the device whose name contains this (NULL: best GPU, else lavapipe).
    pub device_name_filter: *const c_char,
    /// Own device only: enable the Khronos validation layer.
    pub enable_validation: HrtsBool,
    /// The most frames the engine records before waiting for the oldest to complete, 1..=
    /// `HRTS_MAX_FRAMES_IN_FLIGHT` (0: 3). Recording frame `frame_index` states that every frame up to
    /// `frame_index - frames_in_flight` has completed on the GPU.
    pub frames_in_flight: u32,
}

/// What the device can do.
#[repr(C)]
pub struct HrtsCapabilities {
    /// `sizeof(HrtsCapabilities)`, set by the caller.
    pub struct_size: u32,
    /// D3D12 conservative-raster tier: 0 none, 1..3.
    pub conservative_raster_tier: u32,
    /// Binning path `HRTS_BINNING_PATH_AUTO` resolves to (`HrtsBinningPath`).
    pub default_binning_path: u32,
    /// Geometry shaders available (software path possible).
    pub geometry_shader: HrtsBool,
    /// Timestamp queries available (per-pass GPU times in the report).
    pub timestamps: HrtsBool,
    /// `VK_KHR_ray_query` present.
    pub ray_query: HrtsBool,
    /// `VK_KHR_ray_tracing_pipeline` present.
    pub ray_tracing_pipeline: HrtsBool,
    /// `VK_EXT_fragment_shader_interlock` present.
    pub fragment_shader_interlock: HrtsBool,
    /// Largest primitive map size N.
    pub max_map_size: u32,
    /// Largest primitive-map entry budget in KiB (the device's largest storage buffer).
    pub max_map_entry_budget_kib: u32,
    /// `maxStorageBufferRange` in bytes.
    pub max_storage_buffer_range: u64,
    /// Device name (NUL-terminated, truncated to fit).
    pub device_name: [c_char; 128],
}

/// Plugin configuration. `hrts_config_defaults` fills the documented defaults; changing the configuration
/// rebuilds the passes on the next recording.
#[repr(C)]
pub struct HrtsConfig {
    /// `sizeof(HrtsConfig)`.
    pub struct_size: u32,
    /// `HrtsShadowMode` (default hybrid).
    pub mode: u32,
    /// FXAA over the ray-traced shadow (default true).
    pub antialiasing: HrtsBool,
    /// The light does not move between frames: the shadow map is kept (default false). The primitive map
    /// follows the camera and is rebuilt every frame.
    pub static_light: HrtsBool,
    /// Primitive map N: texels per side of the light-space grid fitted to the receivers each frame,
    /// 1..=max_map_size, or 0 (the default) for the plugin's choice by trace: 512 for hard and area
    /// shadows, 1024 for the hybrid (`HrtsFrameReport::map_size` and `HrtsLightPlan::map_size` say which).
    /// It moves cost, never exactness. API 5.11: 0 was refused before, and the default was 1024.
    pub map_size: u32,
    /// Largest memory of the primitive map's list entries in KiB, at least 4 (default 262144 = 256 MiB,
    /// capped by the device's largest storage buffer). The lists take what the frame needs and grow to
    /// fit; a texel whose list does not fit is traced against every triangle (exact, slower) and counted
    /// in the report.
    pub map_entry_budget_kib: u32,
    /// `HrtsFaces` (default both).
    pub faces: u32,
    /// `HrtsBinningPath` (default auto).
    pub binning_path: u32,
    /// Shadow map size (default 3072, as in the talk).
    pub shadow_map_size: u32,
    /// PCSS: angular radius of a directional emitter in radians (default 0.02). Positive; 0 (a light of no
    /// size) only with `HRTS_SHADOW_MODE_AUTO`.
    pub pcss_angular_radius: f32,
    /// Radius of a spot or point light's spherical emitter in world units (default 0.05): PCSS, the
    /// hybrid and area shadows. Positive; 0 (a light of no size) only with `HRTS_SHADOW_MODE_AUTO`.
    pub pcss_spot_radius: f32,
    /// PCSS blocker-search taps (default 16).
    pub pcss_blocker_search_taps: u32,
    /// PCSS PCF taps (default 32).
    pub pcss_pcf_taps: u32,
    /// Hybrid blend: world-space scale WSS (default 1).
    pub hybrid_world_space_scale: f32,
    /// Hybrid blend: percentage of hard shadow PHS (default 4).
    pub hybrid_hard_shadow_percentage: f32,
    /// `HrtsPenumbraFilter` (default shrinking).
    pub pcss_filter: u32,
    /// PCSS: largest blocker-search radius in shadow-map texels (default 48).
    pub pcss_max_search_radius: f32,
    /// PCSS: smallest PCF radius in texels (default 1).
    pub pcss_min_filter_radius: f32,
    /// PCSS: largest PCF radius in texels (default 32).
    pub pcss_max_filter_radius: f32,
    /// Classic shadow-map test: constant depth bias in texels of world size (default 1).
    pub shadow_map_constant_bias: f32,
    /// Classic shadow-map test: slope-scaled depth bias (default 1).
    pub shadow_map_slope_bias: f32,
    /// The geometry changes every frame: the prim buffer is rebuilt each frame (default false: built once
    /// per `hrts_set_geometry_*`).
    pub dynamic_geometry: HrtsBool,
    /// Resources to produce besides those the mode needs, for `hrts_record_resource_readback` (bit
    /// `1 << HrtsResource`; default 0). E.g. the shadow-map visibility for comparisons.
    pub extra_outputs: u32,
    /// Debug: 4096 words after the list entries, filled with `0xFFFFFFFF` and never written: a read-back of
    /// `HRTS_RESOURCE_PRIM_LIST_ENTRIES` shows any write past the capacity (default false).
    pub guard_entries: HrtsBool,
    /// Debug: bin every texel of the fitted grid, not only those holding ray origins, and keep triangles
    /// behind every ray origin: lists comparable with exact conservative binning (default false).
    pub debug_bin_all_texels: HrtsBool,
    /// Entries the primitive map's lists start with (default 0: estimated from map_size and the
    /// triangles). An engine that knows its scene can size them and avoid the frame of a growth.
    pub map_initial_entries: u32,
    /// (Triangle, face) pairs a point light's cube map starts with (default 0: two per triangle, at least
    /// 1024; at most six per triangle). A frame that keeps more walks every pixel of the light through the
    /// BVH (exact; `bin_pairs` in the frame report) and the pairs grow to fit from the next frame on. API 5.4: 0 for a configuration of
    /// 5.1 to 5.3.
    pub map_initial_pairs: u32,
    /// Area shadows: light samples per pixel, 1..=128 (default 64). API 5.5: 64 for a configuration of 5.1
    /// to 5.4.
    pub area_samples: u32,
    /// A texel whose list would hold more than this many entries keeps none: its pixels walk the BVH over
    /// the prim buffer instead, which then costs less (default 0: the plugin's choice, 256 entries, 1024
    /// for the hybrid, whose trace finds the nearest blocker; `0xFFFFFFFF`: no limit). It moves cost, never
    /// exactness. API 5.9: older callers get the default.
    pub map_list_limit: u32,
    /// Bin items (4x4-texel tiles of the triangles' footprints, widened by their penumbrae for area
    /// shadows) per pixel with a shadow ray past which a frame builds no list and every pixel walks the
    /// BVH (default 8; infinity: always lists; 0: always the BVH). It moves cost, never exactness. API
    /// 5.9: older callers get the default.
    pub map_bin_budget: f32,
    /// Area shadows: where a pixel walks the BVH with a wide bundle of segments or rays (an emitter's radius
    /// over a twentieth of its distance; a directional light's angular bound over a tenth), the nodes and
    /// triangles the bundle's walk may visit per 64 samples still open, scaled by (0.3 / width)^2 (width:
    /// radius over distance), before each open sample walks its own segment or ray (default 64; 0: each sample's own walk at once; `0xFFFFFFFF`: the bundle
    /// always). The bundle costs less where few triangles straddle it (small lights), the samples' own
    /// walks where many do (large lights). It moves cost, never exactness. API 5.10: older callers get the
    /// default.
    pub area_walk_budget: u32,
}

/// One draw of the geometry: an element of `draws`, read at `draw_stride`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct HrtsDraw {
    /// First index of the draw.
    pub first_index: u32,
    /// Index count (a multiple of 3).
    pub index_count: u32,
    /// Object-to-world matrix, column-major.
    pub transform: [f32; 16],
    /// Added to every index of the draw before it addresses a vertex (may be negative), as in
    /// `vkCmdDrawIndexed`'s `vertexOffset`.
    pub base_vertex: i32,
}

/// Geometry in CPU arrays (copied by the call).
#[repr(C)]
pub struct HrtsCpuGeometry {
    /// `sizeof(HrtsCpuGeometry)`.
    pub struct_size: u32,
    /// Positions: `vertex_count` float3 at `vertex_stride` bytes apart.
    pub positions: *const f32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Bytes between consecutive positions (>= 12, multiple of 4).
    pub vertex_stride: u32,
    /// Triangle-list indices (32-bit).
    pub indices: *const u32,
    /// Number of indices.
    pub index_count: u32,
    /// Draws.
    pub draws: *const HrtsDraw,
    /// Number of draws.
    pub draw_count: u32,
    /// Bytes from one draw to the next: `sizeof(HrtsDraw)` of the caller's header. API 5.8: 0 (as in the
    /// struct of a caller of 5.1 to 5.7) reads the 76-byte `HrtsDraw` of API 5.1 to 5.8.
    pub draw_stride: usize,
}

/// One mesh in the engine's Vulkan buffers (need `VK_BUFFER_USAGE_STORAGE_BUFFER_BIT`); read, never
/// written. `hrts_set_geometry_vulkan` takes the whole geometry as one mesh,
/// `hrts_set_geometry_vulkan_meshes` a list of meshes, each with buffers, layouts, formats and draws of
/// its own.
#[repr(C)]
pub struct HrtsVulkanGeometry {
    /// `sizeof(HrtsVulkanGeometry)`.
    pub struct_size: u32,
    /// `VkBuffer` holding positions (`vertex_format`).
    pub vertex_buffer: u64,
    /// Size of the vertex buffer in bytes.
    pub vertex_buffer_size: u64,
    /// Byte offset of vertex 0 (multiple of 4).
    pub vertex_offset: u64,
    /// Bytes between vertices (at least the position's size: 12, or 8 for 16-bit formats; a multiple of 4).
    pub vertex_stride: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// `VkBuffer` holding indices.
    pub index_buffer: u64,
    /// Size of the index buffer in bytes.
    pub index_buffer_size: u64,
    /// Byte offset of index 0 (multiple of 4).
    pub index_offset: u64,
    /// `HrtsIndexType`.
    pub index_type: u32,
    /// Number of indices.
    pub index_count: u32,
    /// Draws.
    pub draws: *const HrtsDraw,
    /// Number of draws.
    pub draw_count: u32,
    /// World-space bounds of all the mesh's draws (min xyz, max xyz): they must hold every triangle the
    /// plugin is given (the shadow casters); a box that is empty, inverted or all zero (a zero-initialised
    /// struct) is refused. The plugin culls lights by the union of every mesh's bounds
    /// (`HrtsLightDecision`), and the frame origin is its centre (rounded to f32, so that vertex minus
    /// origin is exact for f32 vertices).
    pub bounds: [f32; 6],
    /// `VkFormat` of a position: `VK_FORMAT_R32G32B32_SFLOAT` (or 0), or 16-bit
    /// `VK_FORMAT_R16G16B16A16_SFLOAT`, `_SNORM` or `_UNORM` (w ignored).
    pub vertex_format: u32,
    /// Dequantization: a stored position q (normalized to [-1, 1] or [0, 1] for snorm and unorm) is the
    /// object-space point `q * position_scale + position_offset`, per axis. A scale of 0 on every axis means
    /// 1 (no dequantization).
    pub position_scale: [f32; 3],
    /// See `position_scale`.
    pub position_offset: [f32; 3],
    /// Bytes from one draw to the next: `sizeof(HrtsDraw)` of the caller's header. API 5.8: 0 (as in the
    /// struct of a caller of 5.1 to 5.7) reads the 76-byte `HrtsDraw` of API 5.1 to 5.8.
    pub draw_stride: usize,
}

/// The engine's images the plugin reads and writes. All are 2D, one mip, same size; depth and normal have one
/// layer, the output `output_layers` (one per light).
#[repr(C)]
pub struct HrtsTargets {
    /// `sizeof(HrtsTargets)`.
    pub struct_size: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The engine's depth `VkImage` (`depth_format`, usage includes SAMPLED), as its projection writes it:
    /// reversed or standard Z, finite or infinite far plane (the plugin rebuilds positions through
    /// `HrtsFrame::proj`), or a linear view-Z image.
    pub depth_image: u64,
    /// Usage flags the depth image was created with (`VkImageUsageFlags`).
    pub depth_usage: u32,
    /// `VkFormat` of the depth image: `VK_FORMAT_D16_UNORM`, `VK_FORMAT_X8_D24_UNORM_PACK32`,
    /// `VK_FORMAT_D24_UNORM_S8_UINT`, `VK_FORMAT_D32_SFLOAT` or `VK_FORMAT_D32_SFLOAT_S8_UINT` (sampled
    /// through its depth aspect; its layouts are given for both aspects), or 0 for `VK_FORMAT_D32_SFLOAT`.
    /// `VK_FORMAT_R32_SFLOAT` or `VK_FORMAT_R16_SFLOAT`: a linear view-Z image (as NRD's view-Z input): the
    /// view-space z of the surface under `HrtsFrame::view` (negative in front of a right-handed camera); 0,
    /// a value that is not finite, or one of magnitude 65504 or more marks background. Normals derived from
    /// depth (`HRTS_NORMAL_ENCODING_NONE`) need a depth format. The ray origins move off the surface by the
    /// format's depth error, so shadows stay exact at the points the depth describes; a coarse format (D16
    /// with a near plane close to the camera, R16 view Z) moves contact shadows' start by that error.
    pub depth_format: u32,
    /// The engine's normal `VkImage` (`normal_format`, usage includes SAMPLED), encoded as
    /// `normal_encoding` says; ignored (may be 0) with `HRTS_NORMAL_ENCODING_NONE`.
    pub normal_image: u64,
    /// Usage flags of the normal image.
    pub normal_usage: u32,
    /// `VkFormat` of the normal image, or 0 for `VK_FORMAT_R32G32B32A32_SFLOAT`. xyz encodings take
    /// `R32G32B32A32_SFLOAT`, `R16G16B16A16_SFLOAT`, `A2B10G10R10_UNORM_PACK32` or `R8G8B8A8_UNORM`;
    /// octahedral ones `R16G16_SNORM`, `R16G16_UNORM`, `R16G16_SFLOAT` or `A2B10G10R10_UNORM_PACK32`.
    /// Normalized (unorm) channels map [0, 1] to [-1, 1].
    pub normal_format: u32,
    /// `HrtsNormalEncoding` of the normal image.
    pub normal_encoding: u32,
    /// `HrtsNormalSpace` of the normals.
    pub normal_space: u32,
    /// Visibility `VkImage` the plugin writes (`output_format`, usage includes TRANSFER_DST): 1 = lit.
    /// Light `i`'s visibility goes to array layer `i`.
    pub output_image: u64,
    /// Usage flags of the output image.
    pub output_usage: u32,
    /// Array layers of the output image: at least the number of lights when a frame is recorded.
    pub output_layers: u32,
    /// `VkFormat` of the output image: `VK_FORMAT_R32_SFLOAT` (or 0), `VK_FORMAT_R16_SFLOAT` or
    /// `VK_FORMAT_R8_UNORM`. With STORAGE usage (and a device that supports storage images of the format),
    /// each light's last pass writes its layer directly, with no copy; otherwise each layer is copied in
    /// (`R32_SFLOAT`) or converted by a blit (the device must support blits from `R32_SFLOAT` to it).
    pub output_format: u32,
}

/// One light of a frame: an element of `HrtsFrame::lights`, read at `light_stride`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HrtsLight {
    /// `HrtsLightType`.
    pub light_type: u32,
    /// Spot and point lights: emitter position in world space (ignored for directional lights).
    pub position: [f32; 3],
    /// Direction the light travels, or the spot light's axis (need not be normalised; non-zero; ignored
    /// for point lights).
    pub direction: [f32; 3],
    /// The light's view-projection enclosing shadow casters and receivers (column-major): orthographic
    /// for a directional light, perspective with its eye at `position` for a spot light, or all zeros for
    /// the plugin to fit the light's frusta itself (ignored for point lights).
    ///
    /// A fitted directional frustum is orthographic along `direction`, fitted every frame to the shadow
    /// casters' bounds (`HrtsFrame::bounds` when `has_bounds` is set, else those of CPU geometry or of
    /// Vulkan geometry that does not change): their extent across the light maps exactly onto the
    /// frustum, their depth range widened by 1% on both sides plus a tiny margin (receivers beyond that
    /// depth range are shadowed all the same). A receiver outside the frustum across the light is lit: no
    /// caster lies on its hard shadow ray, but a sized sun's penumbra may reach past the casters' extent
    /// (give a `view_proj` that also covers those receivers). A frame that knows no bounds (Vulkan
    /// geometry that moves or is deformed, without `has_bounds`) is refused with a message. A fitted spot
    /// light frustum has its near plane at `range / 1024` (0.01 without a range) and its far plane at
    /// infinity.
    pub view_proj: [f32; 16],
    /// Spot and point lights: distance beyond which the light has no effect, or 0 for unlimited. It sets
    /// the near plane of the frusta the plugin fits. A frustum that can shadow no receiver in view within
    /// the range is not recorded (`HrtsLightDecision` states the rule), and a pixel it alone would shade
    /// is lit (1): beyond the range the visibility may be 1 where geometry blocks the light, since the
    /// light does not reach there. Within the range shadows are exact.
    pub range: f32,
    /// Spot lights whose frusta the plugin fits: half-angle of the cone in radians, in (0, π/2]. Up to
    /// π/3 one frustum covers it; wider cones use the five cube faces around the axis. Ignored otherwise.
    pub outer_cone: f32,
}

/// One frame to record into the engine's command buffer.
#[repr(C)]
pub struct HrtsFrame {
    /// `sizeof(HrtsFrame)`.
    pub struct_size: u32,
    /// `VkCommandBuffer` in the recording state, outside a render pass, from `queue_family_index`.
    pub command_buffer: u64,
    /// The engine's frame counter: it increases from frame to frame (gaps allowed) and stays the same
    /// across the calls that record one frame pass by pass. Recording frame `f` states that every frame
    /// up to `f - frames_in_flight` has completed on the GPU.
    pub frame_index: u64,
    /// World-to-view matrix, column-major.
    pub view: [f32; 16],
    /// View-to-clip matrix, column-major, Vulkan clip conventions (depth 0..1), the projection that wrote the
    /// depth image: reversed or standard Z, finite or infinite far plane.
    pub proj: [f32; 16],
    /// Camera position in world space.
    pub camera_position: [f32; 3],
    /// The lights, one per configured light, in the order of `hrts_configure_lights`.
    pub lights: *const HrtsLight,
    /// Number of entries in `lights`: the number of configured lights.
    pub light_count: u32,
    /// `VkImageLayout` of the depth image when the commands run; it is restored afterwards.
    pub depth_layout: i32,
    /// `VkImageLayout` of the normal image when the commands run; restored afterwards.
    pub normal_layout: i32,
    /// `VkImageLayout` of the output image before (its contents are discarded): in the call with
    /// `HRTS_PASS_OUTPUT_COPY`, or, for a light that writes its layer directly
    /// (`HrtsFrameReport::output_direct`), in the call recording the light's last screen-space pass.
    pub output_layout_before: i32,
    /// `VkImageLayout` the output image is left in.
    pub output_layout_after: i32,
    /// World-space bounds (min xyz, max xyz) of every triangle of the geometry this frame (the shadow
    /// casters; receivers that cast nothing need not be inside), read when `has_bounds` is set. A box that
    /// is empty, inverted or all zero (a zero-initialised struct) is refused. They let the plugin cull
    /// light frusta whose shadows cannot reach the view (`HrtsLightDecision` states the rule) when the
    /// geometry moves; without them it culls moving Vulkan geometry by the view and the lights' ranges
    /// alone (CPU geometry and static Vulkan geometry use the bounds they were given). A directional light
    /// given without a `view_proj` is fitted to them.
    pub bounds: [f32; 6],
    /// Whether `bounds` holds this frame's bounds.
    pub has_bounds: HrtsBool,
    /// The meshes deformed this frame (`deformed_count` entries; may be NULL if the count is 0): each
    /// reads its positions from a vertex buffer of this frame instead of its own, and its triangles are
    /// rebuilt this frame (from its own vertex buffer again in the next frame that does not deform it).
    /// Read by the call that begins the frame alone (the frame's later calls deform the same meshes): the
    /// array may be freed once that call returned. A deformed mesh's bounds do not hold: give the frame's in
    /// `bounds`, or the plugin culls by the view and the lights' ranges alone.
    pub deformed: *const HrtsMeshVertices,
    /// Number of entries in `deformed`.
    pub deformed_count: u32,
    /// Bytes from one entry of `lights` to the next: `sizeof(HrtsLight)` of the caller's header. API 5.8: 0
    /// (as in the struct of a caller of 5.1 to 5.7) reads the 100-byte `HrtsLight` of API 5.1 to 5.8.
    pub light_stride: usize,
    /// Bytes from one entry of `deformed` to the next: `sizeof(HrtsMeshVertices)` of the caller's header.
    /// API 5.8: 0 (as in the struct of a caller of 5.1 to 5.7) reads the 32-byte `HrtsMeshVertices` of API
    /// 5.1 to 5.8.
    pub deformed_stride: usize,
}

/// Where one mesh's positions are in one frame (an element of `HrtsFrame::deformed`, read at
/// `deformed_stride`): a vertex buffer of that frame, such as one of a ring of skinning outputs, one per
/// frame in flight. It holds the mesh's vertex count in the mesh's `vertex_format` and `vertex_stride`,
/// and must stay alive until the frame completed. The plugin writes the buffer's descriptors anew in each
/// frame that gives it and never reads them in another frame: once the frame completed, the engine may
/// destroy the buffer, and a buffer created after it may get its handle.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HrtsMeshVertices {
    /// Index of the mesh in the last geometry call (0 for `hrts_set_geometry_vulkan` and
    /// `hrts_set_geometry_cpu`).
    pub mesh: u32,
    /// `VkBuffer` holding the positions (`VK_BUFFER_USAGE_STORAGE_BUFFER_BIT`).
    pub vertex_buffer: u64,
    /// Size of the vertex buffer in bytes.
    pub vertex_buffer_size: u64,
    /// Byte offset of vertex 0 (multiple of 4).
    pub vertex_offset: u64,
}

/// The engine's host allocator. The plugin's host memory (not Vulkan's) goes through it for the whole
/// process once installed with `hrts_set_allocation_callbacks`.
#[repr(C)]
pub struct HrtsAllocationCallbacks {
    /// `sizeof(HrtsAllocationCallbacks)`.
    pub struct_size: u32,
    /// Passed back to both functions.
    pub user_data: *mut std::ffi::c_void,
    /// Returns `size` bytes aligned to `alignment` (a power of two), or NULL.
    pub allocate: Option<
        unsafe extern "C" fn(
            user_data: *mut std::ffi::c_void,
            size: usize,
            alignment: usize,
        ) -> *mut std::ffi::c_void,
    >,
    /// Frees memory returned by `allocate`, with the size and alignment it was allocated with.
    pub free: Option<
        unsafe extern "C" fn(
            user_data: *mut std::ffi::c_void,
            memory: *mut std::ffi::c_void,
            size: usize,
            alignment: usize,
        ),
    >,
}

/// Memory the plugin holds, process-wide (all contexts).
#[repr(C)]
pub struct HrtsMemoryStats {
    /// `sizeof(HrtsMemoryStats)`, set by the caller.
    pub struct_size: u32,
    /// Host bytes allocated by the plugin and not freed (0 unless `host_bytes_counted`).
    pub host_bytes: u64,
    /// Whether the plugin counts its host memory: true in its shared and static libraries, whose global
    /// allocator counts it; false when a Rust program links the plugin's rlib and keeps its own allocator.
    pub host_bytes_counted: HrtsBool,
    /// GPU bytes allocated by the plugin and not freed (excludes what the Vulkan driver keeps internally).
    pub gpu_bytes: u64,
}

/// GPU time of one pass.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct HrtsPassTiming {
    /// Pass name (NUL-terminated, truncated).
    pub name: [c_char; 32],
    /// Milliseconds.
    pub milliseconds: f64,
}

/// Maximum passes in a report (every pass of a light shadowed through six cube faces fits).
pub const HRTS_MAX_REPORTED_PASSES: usize = 128;

/// What one light's passes did in one frame (`hrts_get_frame_report`).
#[repr(C)]
pub struct HrtsFrameReport {
    /// `sizeof(HrtsFrameReport)`, set by the caller.
    pub struct_size: u32,
    /// `HrtsBinningPath` used.
    pub binning_path: u32,
    /// Conservative-raster tier used (0 for the compute and software paths).
    pub tier: u32,
    /// Texels whose pixels walked the BVH because their list did not fit the entry capacity, and every
    /// texel of a group of 16 whose lists' offsets did not fit the packed list offsets (exact).
    pub texels_past_capacity: u32,
    /// Longest list of any texel.
    pub longest_list: u32,
    /// Number of valid entries in `passes`.
    pub pass_count: u32,
    /// Per-pass GPU times.
    pub passes: [HrtsPassTiming; HRTS_MAX_REPORTED_PASSES],
    /// Texels holding at least one triangle.
    pub texels_with_list: u32,
    /// Entries (texel, triangle) the frame needed.
    pub entries: u32,
    /// `HrtsPassStatus` of each `HrtsPass` this frame.
    pub pass_status: [u32; HRTS_PASS_COUNT],
    /// Bytes of each `HrtsResource` the plugin allocated (0: not allocated), with the buffers that serve
    /// it: `HRTS_RESOURCE_PRIM_LIST_OFFSETS` counts the primitive map's other buffers,
    /// `HRTS_RESOURCE_RT_VISIBILITY` an area trace's own buffers (light samples, edge tables, sample bands,
    /// tile history; those alone when the light writes its layer of the output directly: `output_direct`).
    pub resource_bytes: [u64; HRTS_RESOURCE_COUNT],
    /// The `HrtsResource` copied into the output image (or written into it directly: `output_direct`).
    pub output_resource: u32,
    /// Bytes of the prim buffer (triangles in frame coordinates; 0 if the plan has none), shared by the
    /// context's lights.
    pub prim_buffer_bytes: u64,
    /// Bytes of the scratch shared by the context's lights and frusta: the primitive map's (per-triangle bin
    /// items, per-texel counts and receivers, and the screen-size texel of each pixel's ray origin; 0 if the
    /// light has no primitive map), and the ray trace's visibility that the lights' FXAA read in the same
    /// recording call (hard shadows with antialiasing, its `HRTS_RESOURCE_RT_VISIBILITY` not in
    /// `extra_outputs`: it is then no resource of the light's own, and cannot be read back; a call that
    /// records a light's ray trace without its FXAA gives the light an image of its own from then on).
    pub map_scratch_bytes: u64,
    /// Entries the lists could hold this frame (they grow to fit from the next frame on).
    pub entry_capacity: u32,
    /// Pixels that traced a shadow ray.
    pub receiver_pixels: u32,
    /// Primitive-map texels holding at least one ray origin.
    pub receiver_texels: u32,
    /// Triangles binned (not culled as degenerate, back-facing, outside or behind every receiver).
    pub triangles_binned: u32,
    /// The primitive map's fit this frame: frame coordinates to homogeneous texel space, 16 floats,
    /// column-major (frame coordinates are world minus the geometry's origin).
    pub map_to_texels: [f32; 16],
    /// How many times this light's passes were built since the context was created: a configuration,
    /// geometry or targets call that changed nothing of this light leaves it as it was.
    pub light_builds: u32,
    /// Frusta the light was shadowed through this frame: those of its frusta (1, or the cube faces of a
    /// point light (6) or of a wide spot light (5)) that may shadow a receiver in view within its range
    /// (`HrtsLightDecision`). A point light built as one cube map counts as 1.
    /// Statistics and pass times above are summed over them, memory over every frustum (the longest
    /// list is the longest of any; `map_to_texels` is the first recorded frustum's).
    pub frusta: u32,
    /// Frusta of the light skipped this frame: they can shadow no receiver in view within its range.
    pub frusta_culled: u32,
    /// `HrtsLightDecision` of the light this frame.
    pub decision: u32,
    /// Why, in words (NUL-terminated, truncated to fit): the frusta recorded and those culled, by name;
    /// under `HRTS_SHADOW_MODE_AUTO`, the mode chosen and why ("auto: hard (zero-size light)").
    pub decision_reason: [c_char; 128],
    /// GPU milliseconds of all of this light's passes in the frame (every frustum, the minimum over
    /// them, and the light's share of nothing else).
    pub gpu_milliseconds: f64,
    /// Triangles whose prim-buffer slots the frame rewrote (shared by the context's lights, whichever
    /// recorded the build): every triangle on the first frame, those of the draws moved by
    /// `hrts_set_draw_transforms` and of the meshes deformed (`HrtsFrame::deformed`), every triangle each
    /// frame with `dynamic_geometry`; 0 when the prim buffer was up to date.
    pub prim_triangles_rebuilt: u32,
    /// Whether the light's last pass wrote its layer of the output image directly, with no copy: the
    /// output has STORAGE usage in a format the lights write (`HrtsTargets::output_format`). The layer is
    /// then in the GENERAL layout between that pass and the output-copy call, which takes it to
    /// `output_layout_after`; the configuration must not read the final output back through
    /// `extra_outputs`. API 5.3.
    pub output_direct: HrtsBool,
    /// A point light shadowed as one cube map: the (triangle, face) pairs its setup kept this frame (0
    /// for other lights). Past `bin_pair_capacity`, the frame traced every ray of the light against every
    /// triangle (exact, slower) and the pairs grow to fit from the next frame on. API 5.4: not written into
    /// the report of a caller of 5.1 to 5.3.
    pub bin_pairs: u32,
    /// The (triangle, face) pairs the light's cube map held this frame. API 5.4, as `bin_pairs`.
    pub bin_pair_capacity: u32,
    /// Texels whose list passed `map_list_limit` and was not kept: their pixels walked the BVH. API 5.9:
    /// this field and the ones after it are written for callers of 5.9 and later.
    pub texels_past_limit: u32,
    /// Bin items (4x4-texel tiles of the footprints) of the frame's lists (saturated at `0xFFFFFFFF`).
    pub bin_items: u32,
    /// Frusta whose bin items passed `map_bin_budget`: they built no list, every pixel walked the BVH.
    pub frusta_without_lists: u32,
    /// Pixels that walked the BVH rather than a list (texels past the capacity or the list limit, frusta
    /// without lists).
    pub pixels_walked: u32,
    /// BVH walks that could not finish (a driver that ends long loops early): 0 on a conforming device.
    pub walks_unfinished: u32,
    /// Reserved, written 0: API 5.9's report ends with this padding, which no later field may take.
    pub reserved_5_9: u32,
    /// Area shadows: pixels whose bundle passed `area_walk_budget`, or whose tile skipped it since most of
    /// its bundles gave up in an earlier frame, so that each of their open samples walked the BVH on its
    /// own. API 5.10: written for callers of 5.10 and later.
    pub pixels_walked_per_sample: u32,
    /// Reserved, written 0: API 5.10's report ends with this padding, which no later field may take.
    pub reserved_5_10: u32,
    /// N of the light's primitive map (`HrtsConfig::map_size`, or the plugin's choice for the light's
    /// trace); 0 if its passes have none. API 5.11: written for callers of 5.11 and later.
    pub map_size: u32,
    /// Reserved, written 0: keeps the report a multiple of 8 bytes, which no later field may take.
    pub reserved_5_11: u32,
}

/// What the plugin would do with one light in a view, decided without a context or a device
/// (`hrts_plan_lights`): the decision, frusta and reason the light's `HrtsFrameReport` gives for a frame
/// of the same camera, light, configuration and casters' bounds. API 5.10.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HrtsLightPlan {
    /// `sizeof(HrtsLightPlan)`.
    pub struct_size: u32,
    /// `HrtsLightDecision`: shadowed, or out of view (no frustum may shadow a receiver in view within
    /// its range: no pass would run and its layer would be 1).
    pub decision: u32,
    /// Frusta the light would be shadowed through (`HrtsFrameReport::frusta`).
    pub frusta: u32,
    /// Frusta it would skip (`HrtsFrameReport::frusta_culled`).
    pub frusta_culled: u32,
    /// The `HrtsShadowMode` its passes would run: the configuration's, or under `HRTS_SHADOW_MODE_AUTO`
    /// the one the light's size chooses (hard for a zero-size light, area for a sized one).
    pub mode: u32,
    /// Why, in words (NUL-terminated, truncated to fit), as `HrtsFrameReport::decision_reason`.
    pub decision_reason: [c_char; 128],
    /// The passes of the light's plan in that mode (bit `1 << HrtsPass`): those whose
    /// `HrtsFrameReport::pass_status` is not `HRTS_PASS_STATUS_NOT_IN_PLAN`. 0 when out of view.
    pub passes: u32,
    /// The resources of the light's plan that have an `HrtsResource` value (bit `1 << HrtsResource`):
    /// what its passes write, held by the light or shared by the context's lights (the report's
    /// `resource_bytes` counts those the light holds). 0 when out of view.
    pub resources: u32,
    /// N of the light's primitive map (`HrtsFrameReport::map_size`): the configuration's, or the plugin's
    /// choice for the trace of its mode; 0 when its plan has no primitive map or it is out of view. API
    /// 5.11: written for callers of 5.11 and later.
    pub map_size: u32,
}

/// A copy of a plugin resource into an engine buffer, recorded after a complete frame.
#[repr(C)]
pub struct HrtsResourceReadback {
    /// `sizeof(HrtsResourceReadback)`.
    pub struct_size: u32,
    /// `VkCommandBuffer` in the recording state, outside a render pass, submitted after the frame's.
    pub command_buffer: u64,
    /// `HrtsResource` to copy (allocated by the configuration: see `HrtsConfig::extra_outputs`).
    pub resource: u32,
    /// The light whose resource to copy.
    pub light: u32,
    /// Destination `VkBuffer` (usage includes TRANSFER_DST).
    pub buffer: u64,
    /// Size of the destination buffer in bytes.
    pub buffer_size: u64,
    /// Byte offset of the copy in the buffer (a multiple of 4); `HrtsResourceInfo::bytes` are written.
    pub offset: u64,
}

/// Shape of a plugin resource, for reading it back.
#[repr(C)]
pub struct HrtsResourceInfo {
    /// `sizeof(HrtsResourceInfo)`, set by the caller.
    pub struct_size: u32,
    /// Whether the current configuration allocates it.
    pub allocated: HrtsBool,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Array layers.
    pub layers: u32,
    /// `VkFormat`.
    pub format: i32,
    /// Bytes of a tightly packed read-back of all layers (layer-major, rows top to bottom).
    pub bytes: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_are_listed_in_value_order_with_their_c_names() {
        for (i, r) in HrtsResult::ALL.iter().enumerate() {
            assert_eq!(*r as usize, i);
            assert_eq!(HrtsResult::from_c(i as i32), Some(*r));
        }
        assert_eq!(HrtsResult::from_c(-1), None);
        assert_eq!(HrtsResult::from_c(HrtsResult::ALL.len() as i32), None);
        assert_eq!(HrtsResult::Ok.c_name(), "HRTS_RESULT_OK");
        assert_eq!(
            HrtsResult::ErrorInvalidArgument.c_name(),
            "HRTS_RESULT_ERROR_INVALID_ARGUMENT"
        );
        assert_eq!(HrtsResult::NotReady.c_name(), "HRTS_RESULT_NOT_READY");
    }
}

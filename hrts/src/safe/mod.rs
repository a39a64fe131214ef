//! The safe Rust API over the C ABI, re-exported at the crate root: what every Rust host uses.
//!
//! Each method calls the `hrts_*` function it names, so a Rust host gets exactly what a C engine gets;
//! this layer only turns Rust types into the C structs (sizes, strides, pointers, flags) and back,
//! destroys the context on drop, and turns result codes into [`Error`]s carrying the plugin's message.
//!
//! - [`Context`]: [`Context::adopt`] the engine's device (or [`Context::headless`]), then
//!   [`Context::configure_lights`] with a [`Config`] per light, [`Context::set_geometry_vulkan`] (or
//!   [`Context::set_geometry_cpu`]), [`Context::set_targets`], and per frame [`Context::record_passes`]
//!   (or [`Context::record_frame`]) with a [`Frame`] of [`Light`]s; after the frame completed,
//!   [`Context::frame_report`] gives each light's [`FrameReport`].
//! - [`plan_lights`]: which lights a view needs shadowed, before any context exists.
//! - The C enumerations under their Rust names ([`ShadowMode`], [`Resource`], [`Pass`], ...), and
//!   [`api_version`] and [`memory_stats`].

mod config;
mod context;
mod enums;
mod error;
mod frame;
mod geometry;
mod plan;
mod report;

pub use config::Config;
pub use context::{Context, HeadlessOptions, VulkanDevice};
pub use enums::{
    BinningPath, Faces, IndexType, LightDecision, NormalEncoding, NormalSpace, Pass, PassMask,
    PassStatus, PenumbraFilter, Resource, ResourceSet, ShadowMode,
};
pub use error::{Error, Result};
pub use frame::{Frame, Light, MeshVertices, ResourceReadback, SpotFrustum, TargetImage, Targets};
pub use geometry::{Bounds, CpuGeometry, Draw, VulkanMesh};
pub use plan::{plan_lights, LightPlan, PlanView};
pub use report::{
    unpack_list_offsets, Capabilities, FrameReport, ListOffsets, MapStats, MemoryStats, PassTiming,
    ResourceInfo,
};

use crate::types::{HrtsMemoryStats, HRTS_API_VERSION};

/// A version of the C ABI: `major.minor.patch`.
///
/// ```
/// let library = hrts::api_version();
/// assert_eq!(library, hrts::ApiVersion::HEADER);
/// println!("libhrts API {library}");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ApiVersion {
    /// Changes break callers.
    pub major: u32,
    /// Adds functions, enumeration values and struct fields at their ends.
    pub minor: u32,
    /// Fixes.
    pub patch: u32,
}

impl ApiVersion {
    /// The version of `hrts.h` this crate was built with (`HRTS_API_VERSION`).
    pub const HEADER: Self = Self::from_packed(HRTS_API_VERSION);

    /// The version of a packed `(major << 22) | (minor << 12) | patch`.
    pub const fn from_packed(packed: u32) -> Self {
        Self {
            major: packed >> 22,
            minor: (packed >> 12) & 0x3ff,
            patch: packed & 0xfff,
        }
    }
}

impl std::fmt::Display for ApiVersion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}.{}", self.major, self.minor, self.patch)
    }
}

/// The library's API version (`hrts_get_api_version`).
pub fn api_version() -> ApiVersion {
    ApiVersion::from_packed(crate::hrts_get_api_version())
}

/// The memory the plugin holds now, over all contexts (`hrts_get_memory_stats`).
///
/// ```
/// let stats = hrts::memory_stats()?;
/// // A Rust program linking the rlib keeps its own allocator: the plugin does not count host bytes.
/// assert_eq!(stats.host_bytes, None);
/// # Ok::<(), hrts::Error>(())
/// ```
pub fn memory_stats() -> Result<MemoryStats> {
    let mut c = HrtsMemoryStats {
        struct_size: size_of::<HrtsMemoryStats>() as u32,
        host_bytes: 0,
        host_bytes_counted: 0,
        gpu_bytes: 0,
    };
    // SAFETY: `c` is valid with its size set.
    error::check("hrts_get_memory_stats", unsafe {
        crate::hrts_get_memory_stats(&mut c)
    })?;
    Ok(MemoryStats {
        host_bytes: (c.host_bytes_counted != 0).then_some(c.host_bytes),
        gpu_bytes: c.gpu_bytes,
    })
}

//! The RHI's error type: one enum, one `VkResult` mapper.

use ash::vk;

/// Everything that can go wrong below the passes.
#[derive(Debug, thiserror::Error)]
pub enum RhiError {
    /// The Vulkan loader (libvulkan.so.1) could not be loaded.
    #[error("cannot load the Vulkan loader: {0} (install libvulkan1 and a driver, e.g. mesa-vulkan-drivers)")]
    Loader(String),
    /// A Vulkan call returned an error code.
    #[error("{call} failed: {result:?}")]
    Vulkan {
        /// The Vulkan entry point that failed.
        call: &'static str,
        /// Its result code.
        result: vk::Result,
    },
    /// No physical device passed selection; the message lists every device and why it was rejected.
    #[error("no suitable Vulkan device: {0}")]
    NoDevice(String),
    /// The device lacks a feature that the requested operation needs.
    #[error("the device lacks {0}")]
    MissingFeature(String),
    /// Validation layers were requested but are not installed.
    #[error("validation requested but VK_LAYER_KHRONOS_validation is not installed (install vulkan-validationlayers)")]
    ValidationUnavailable,
    /// GPU memory allocation failed.
    #[error("GPU allocation of {name} failed: {message}")]
    Allocation {
        /// The resource being allocated.
        name: String,
        /// The allocator's message.
        message: String,
    },
    /// A resource request exceeds a device limit.
    #[error("{what} exceeds the device limit ({value} > {limit})")]
    Limit {
        /// What was requested.
        what: String,
        /// Requested value.
        value: u64,
        /// The device's limit.
        limit: u64,
    },
    /// An argument is invalid (zero size, unsupported combination, ...).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
}

impl RhiError {
    /// Whether the error means GPU or host memory ran out.
    pub fn is_out_of_memory(&self) -> bool {
        match self {
            Self::Allocation { .. } => true,
            Self::Vulkan { result, .. } => {
                matches!(
                    *result,
                    vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY
                )
            }
            _ => false,
        }
    }
}

/// Result alias for the RHI.
pub type Result<T> = std::result::Result<T, RhiError>;

/// Attaches the failing call's name to a `VkResult`.
pub(crate) trait VkResultExt<T> {
    fn call(self, call: &'static str) -> Result<T>;
}

impl<T> VkResultExt<T> for std::result::Result<T, vk::Result> {
    fn call(self, call: &'static str) -> Result<T> {
        self.map_err(|result| RhiError::Vulkan { call, result })
    }
}

//! Errors of the passes.

/// What can go wrong when building or running the passes.
#[derive(Debug, thiserror::Error)]
pub enum PassError {
    /// The RHI failed.
    #[error(transparent)]
    Rhi(#[from] rhi::RhiError),
    /// A configuration value is out of range.
    #[error("invalid configuration: {0}")]
    InvalidConfig(String),
    /// The requested path needs a device feature the device lacks.
    #[error("unsupported on this device: {0}")]
    Unsupported(String),
    /// Geometry is malformed.
    #[error("invalid geometry: {0}")]
    InvalidGeometry(String),
}

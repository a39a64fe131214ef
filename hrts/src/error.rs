//! Errors returned through the C ABI: a result code and a message.

use crate::types::*;
use passes::PassError;
use rhi::RhiError;

/// An error to return through the C ABI: a result code and a message.
#[derive(Debug)]
pub(crate) struct ApiError {
    pub(crate) code: HrtsResult,
    pub(crate) message: String,
}

impl ApiError {
    pub(crate) fn new(code: HrtsResult, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }
}

impl From<PassError> for ApiError {
    fn from(e: PassError) -> Self {
        let code = match &e {
            PassError::Rhi(r) => return r.into(),
            PassError::InvalidConfig(_) | PassError::InvalidGeometry(_) => {
                HrtsResult::ErrorInvalidArgument
            }
            PassError::Unsupported(_) => HrtsResult::ErrorUnsupported,
        };
        Self::new(code, e.to_string())
    }
}

impl From<&RhiError> for ApiError {
    fn from(e: &RhiError) -> Self {
        let code = match e {
            _ if e.is_out_of_memory() => HrtsResult::ErrorOutOfMemory,
            RhiError::MissingFeature(_)
            | RhiError::NoDevice(_)
            | RhiError::Loader(_)
            | RhiError::ValidationUnavailable => HrtsResult::ErrorUnsupported,
            RhiError::InvalidArgument(_) | RhiError::Limit { .. } => {
                HrtsResult::ErrorInvalidArgument
            }
            RhiError::Vulkan { .. } | RhiError::Allocation { .. } => HrtsResult::ErrorVulkan,
        };
        Self::new(code, e.to_string())
    }
}

impl From<RhiError> for ApiError {
    fn from(e: RhiError) -> Self {
        (&e).into()
    }
}

pub(crate) type ApiResult<T> = Result<T, ApiError>;

pub(crate) fn invalid(message: impl Into<String>) -> ApiError {
    ApiError::new(HrtsResult::ErrorInvalidArgument, message)
}

/// Checks the caller's pointer `p` (`what` names it) is aligned for `T`, before the plugin reads a `T` or
/// a slice of them there.
pub(crate) fn check_aligned<T>(p: *const T, what: &str) -> ApiResult<()> {
    if p.is_aligned() {
        Ok(())
    } else {
        Err(invalid(format!(
            "{what} is not aligned to {} bytes",
            std::mem::align_of::<T>()
        )))
    }
}

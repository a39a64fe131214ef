//! [`Error`]: a failed `hrts_*` call, with its result code and the plugin's message.

use crate::types::HrtsResult;

/// What a call of the safe API returns: `E` is [`Error`] unless stated.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A call into the plugin that failed: the C function that failed, its `HrtsResult` and the message the
/// plugin gave (`hrts_get_last_error`). Shown as `hrts_configure_lights: HRTS_RESULT_ERROR_INVALID_ARGUMENT
/// (primitive map size 70000 must be ...)`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{call}: {} ({message})", code.c_name())]
pub struct Error {
    call: &'static str,
    code: HrtsResult,
    message: String,
}

impl Error {
    /// An error of `call` with `code` and `message`.
    pub(crate) fn new(call: &'static str, code: HrtsResult, message: impl Into<String>) -> Self {
        Self {
            call,
            code,
            message: message.into(),
        }
    }

    /// The C function that failed (`hrts_record_passes`), or the conversion that did.
    pub fn call(&self) -> &'static str {
        self.call
    }

    /// The result code: never `HrtsResult::Ok`. `HrtsResult::NotReady` from
    /// [`Context::frame_report`](crate::Context::frame_report) means "ask again after the frame's fence
    /// signalled", not a misuse.
    pub fn code(&self) -> HrtsResult {
        self.code
    }

    /// The plugin's message: what was wrong and with which argument.
    pub fn message(&self) -> &str {
        &self.message
    }
}

/// `Ok` for `HrtsResult::Ok`, else the error of `call` with the message of the calling thread's last call
/// into the plugin (the call that just returned `result`).
pub(crate) fn check(call: &'static str, result: HrtsResult) -> Result<()> {
    if result == HrtsResult::Ok {
        Ok(())
    } else {
        Err(Error::new(call, result, last_error_message()))
    }
}

/// The message of the calling thread's last call into the plugin (`hrts_get_last_error` with a NULL
/// context: another thread's calls on the same context cannot replace it).
fn last_error_message() -> String {
    // SAFETY: a NULL context names the calling thread's last call; a NULL buffer asks for the size only.
    let needed = unsafe { crate::hrts_get_last_error(std::ptr::null(), std::ptr::null_mut(), 0) };
    let mut buffer = vec![0u8; needed.max(1)];
    // SAFETY: `buffer` holds `buffer.len()` writable bytes.
    unsafe {
        crate::hrts_get_last_error(std::ptr::null(), buffer.as_mut_ptr().cast(), buffer.len())
    };
    c_string(&buffer)
}

/// The text of a NUL-terminated string in a byte array of a C struct (up to its first NUL; all of it if
/// there is none).
pub(crate) fn c_string(bytes: &[u8]) -> String {
    let text = bytes.split(|&b| b == 0).next().unwrap_or_default();
    String::from_utf8_lossy(text).into_owned()
}

/// The bytes of a `c_char` array of a C struct.
pub(crate) fn c_chars(chars: &[std::ffi::c_char]) -> String {
    let bytes: Vec<u8> = chars.iter().map(|&c| c as u8).collect();
    c_string(&bytes)
}

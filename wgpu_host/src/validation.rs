//! wgpu-hal reports the Vulkan validation layer's messages through `log`: this logger counts the errors
//! among them (and prints warnings and errors), so that tests can require silence.

use std::sync::{Mutex, OnceLock};

static MESSAGES: Mutex<Vec<String>> = Mutex::new(Vec::new());

struct ValidationLog;

impl log::Log for ValidationLog {
    fn enabled(&self, metadata: &log::Metadata<'_>) -> bool {
        metadata.level() <= log::Level::Warn
    }

    fn log(&self, record: &log::Record<'_>) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let line = format!("{} {}: {}", record.level(), record.target(), record.args());
        eprintln!("{line}");
        if record.level() == log::Level::Error {
            MESSAGES
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .push(line);
        }
    }

    fn flush(&self) {}
}

/// Installs the logger (once per process; later calls do nothing).
pub fn install() {
    static INSTALLED: OnceLock<()> = OnceLock::new();
    INSTALLED.get_or_init(|| {
        if log::set_logger(&ValidationLog).is_ok() {
            log::set_max_level(log::LevelFilter::Warn);
        }
    });
}

/// The error messages logged so far (validation errors among them).
pub fn errors() -> Vec<String> {
    MESSAGES.lock().unwrap_or_else(|p| p.into_inner()).clone()
}

/// Whether the Khronos validation layer is installed (wgpu enables it only when it is, and says so in a
/// warning otherwise): tests that require silence require the layer first.
pub fn layer_installed() -> bool {
    // SAFETY: loading the system's Vulkan loader; nothing else holds it in an inconsistent state.
    let Ok(entry) = (unsafe { ash::Entry::load() }) else {
        return false;
    };
    // SAFETY: a loaded entry.
    let layers = unsafe { entry.enumerate_instance_layer_properties() }.unwrap_or_default();
    layers.iter().any(|l| {
        l.layer_name_as_c_str()
            .is_ok_and(|n| n == c"VK_LAYER_KHRONOS_validation")
    })
}

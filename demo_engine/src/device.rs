//! The engine's GPU device: opened as the command line asks ([`open_device`]), checked for validation
//! errors ([`check_validation`]), and named in reports ([`DeviceSummary`], [`device_banner`]).

/// The engine's GPU device: the RHI's.
pub use rhi::Device;
use serde::Serialize;

/// Opens the device the command line asks for: a name filter (else `HRTS_DEVICE`), validation layers if
/// `validation` (or `HRTS_VALIDATION=1`), with their synchronization validation, whose hazards count as
/// validation errors.
pub fn open_device(filter: Option<String>, validation: bool) -> anyhow::Result<Device> {
    let mut desc = rhi::DeviceDesc::from_env();
    desc.validation |= validation;
    desc.synchronization_validation = desc.validation;
    if filter.is_some() {
        desc.device_filter = filter;
    }
    Ok(Device::new_headless(&desc)?)
}

/// Fails if the validation layers reported errors on `device`.
pub fn check_validation(device: &Device) -> anyhow::Result<()> {
    let errors = device.validation().errors();
    if errors > 0 {
        anyhow::bail!(
            "{errors} Vulkan validation errors (first: {:?})",
            device.validation().messages().first()
        );
    }
    Ok(())
}

/// What a device is, as the demo's reports name it (`frame.json`'s `device`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct DeviceSummary {
    /// The device's name ("llvmpipe (LLVM 15.0.6, 256 bits)", "NVIDIA H100 80GB HBM3").
    pub name: String,
    /// The driver's name and version.
    pub driver: String,
    /// The Vulkan version the device offers.
    pub api_version: String,
    /// CPU, integrated, discrete…
    pub device_type: String,
}

impl DeviceSummary {
    /// The summary of `device`.
    pub fn of(device: &Device) -> Self {
        let caps = device.capabilities();
        Self {
            name: caps.device_name.clone(),
            driver: caps.driver.clone(),
            api_version: caps.api_version.clone(),
            device_type: caps.device_type.clone(),
        }
    }
}

/// The line the demo's commands print first: the device and the plugin's API version.
pub fn device_banner(device: &Device) -> String {
    let d = DeviceSummary::of(device);
    format!(
        "device: {} ({}, {}); shadows through the plugin's C ABI, {}",
        d.name,
        d.device_type,
        d.driver,
        api_version()
    )
}

/// "libhrts API major.minor.patch", as the loaded library reports it.
pub fn api_version() -> String {
    format!("libhrts API {}", hrts::api_version())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--validation` (and `HRTS_VALIDATION=1`) brings synchronization validation along.
    #[test]
    fn a_validated_device_has_synchronization_validation() {
        let device = open_device(None, true).expect("a device with validation layers");
        assert!(device.synchronization_validation().is_some());
        assert_eq!(device.validation().errors(), 0);
    }
}

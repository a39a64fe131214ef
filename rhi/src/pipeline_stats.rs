//! What the driver says each pipeline costs (`VK_KHR_pipeline_executable_properties`): per shader stage,
//! the statistics it names (registers, spills, instructions, local memory ...), captured when a pipeline is
//! created on a device that asked for them ([`crate::DeviceDesc::pipeline_statistics`]) and logged under
//! the target `hrts::pipeline_statistics`.

use ash::vk;
use std::sync::Mutex;

/// The statistics the driver reports for one executable (a shader stage, or a part of one) of a pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct PipelineStatistics {
    /// The pipeline's name (as given at its creation).
    pub pipeline: String,
    /// The executable's name as the driver gives it (for example the stage).
    pub executable: String,
    /// Each statistic's name and value as the driver names and reports it.
    pub values: Vec<(String, String)>,
}

/// Why a device captures no pipeline statistics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StatisticsUnavailable {
    /// Nobody asked ([`crate::DeviceDesc::pipeline_statistics`], `HRTS_PIPELINE_STATISTICS`).
    NotAsked,
    /// Asked, but the device does not offer `VK_KHR_pipeline_executable_properties` with its
    /// `pipelineExecutableInfo` feature (an adopted device: the engine did not enable the extension).
    NotOffered,
}

/// Whether a device captures the statistics: asked for, and offered.
pub(crate) fn capture_state(
    asked: bool,
    offered: bool,
) -> std::result::Result<(), StatisticsUnavailable> {
    match (asked, offered) {
        (false, _) => Err(StatisticsUnavailable::NotAsked),
        (true, false) => Err(StatisticsUnavailable::NotOffered),
        (true, true) => Ok(()),
    }
}

/// A device's capture of the statistics.
pub(crate) struct StatisticsCapture {
    loader: ash::khr::pipeline_executable_properties::Device,
    recorded: Mutex<Vec<PipelineStatistics>>,
}

/// The name of the extension the capture needs.
pub(crate) const EXTENSION: &std::ffi::CStr = ash::khr::pipeline_executable_properties::NAME;

/// A statistic's value as text: integers and booleans as they are, floats with the precision they need.
pub(crate) fn statistic_text(
    format: vk::PipelineExecutableStatisticFormatKHR,
    value: vk::PipelineExecutableStatisticValueKHR,
) -> String {
    // SAFETY: the format names the member of the union the driver wrote.
    unsafe {
        match format {
            vk::PipelineExecutableStatisticFormatKHR::BOOL32 => (value.b32 != 0).to_string(),
            vk::PipelineExecutableStatisticFormatKHR::INT64 => value.i64.to_string(),
            vk::PipelineExecutableStatisticFormatKHR::UINT64 => value.u64.to_string(),
            vk::PipelineExecutableStatisticFormatKHR::FLOAT64 => value.f64.to_string(),
            other => format!("(format {})", other.as_raw()),
        }
    }
}

impl StatisticsCapture {
    /// The capture of `device`, which was created with the extension and its `pipelineExecutableInfo`
    /// feature.
    pub(crate) fn new(instance: &ash::Instance, device: &ash::Device) -> Self {
        Self {
            loader: ash::khr::pipeline_executable_properties::Device::new(instance, device),
            recorded: Mutex::new(Vec::new()),
        }
    }

    /// Reads and logs the statistics of `pipeline` (created with `CAPTURE_STATISTICS`), named `name`. A
    /// driver that reports none, or fails to, only leaves the pipeline out.
    pub(crate) fn record(&self, name: &str, pipeline: vk::Pipeline) {
        let info = vk::PipelineInfoKHR::default().pipeline(pipeline);
        // SAFETY: a live pipeline of the loader's device, created with CAPTURE_STATISTICS.
        let Ok(executables) = (unsafe { self.loader.get_pipeline_executable_properties(&info) })
        else {
            return;
        };
        let mut found = Vec::new();
        for (index, executable) in executables.iter().enumerate() {
            let info = vk::PipelineExecutableInfoKHR::default()
                .pipeline(pipeline)
                .executable_index(index as u32);
            // SAFETY: as above; `index` is one of the executables the driver listed.
            let Ok(statistics) = (unsafe { self.loader.get_pipeline_executable_statistics(&info) })
            else {
                continue;
            };
            let text = |s: Result<&std::ffi::CStr, _>| {
                s.map_or_else(|_| String::new(), |s| s.to_string_lossy().into_owned())
            };
            let values: Vec<(String, String)> = statistics
                .iter()
                .map(|s| (text(s.name_as_c_str()), statistic_text(s.format, s.value)))
                .collect();
            let executable = text(executable.name_as_c_str());
            log::info!(
                target: "hrts::pipeline_statistics",
                "{name} [{executable}]: {}",
                values
                    .iter()
                    .map(|(k, v)| format!("{k} {v}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            found.push(PipelineStatistics {
                pipeline: name.to_owned(),
                executable,
                values,
            });
        }
        if let Ok(mut recorded) = self.recorded.lock() {
            recorded.extend(found);
        }
    }

    /// Every pipeline's statistics recorded so far.
    pub(crate) fn recorded(&self) -> Vec<PipelineStatistics> {
        self.recorded.lock().map(|r| r.clone()).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vk::PipelineExecutableStatisticFormatKHR as F;
    use vk::PipelineExecutableStatisticValueKHR as V;

    #[test]
    fn a_capture_needs_both_the_request_and_the_offer() {
        use StatisticsUnavailable::*;
        assert_eq!(capture_state(false, true), Err(NotAsked));
        assert_eq!(capture_state(false, false), Err(NotAsked));
        assert_eq!(capture_state(true, false), Err(NotOffered));
        assert_eq!(capture_state(true, true), Ok(()));
    }

    #[test]
    fn statistics_read_the_member_their_format_names() {
        assert_eq!(statistic_text(F::BOOL32, V { b32: 1 }), "true");
        assert_eq!(statistic_text(F::INT64, V { i64: -3 }), "-3");
        assert_eq!(statistic_text(F::UINT64, V { u64: 128 }), "128");
        assert_eq!(statistic_text(F::FLOAT64, V { f64: 0.5 }), "0.5");
        assert_eq!(statistic_text(F::from_raw(7), V { u64: 1 }), "(format 7)");
    }
}

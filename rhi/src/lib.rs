//! A thin RHI over Vulkan that speaks D3D12 notions — conservative-raster tiers, UAVs, UAV barriers,
//! resource states — and maps them to Vulkan features and extensions. It creates its own headless device
//! or adopts an engine's. This is the only crate of the project that depends on `ash`.
//!
//! Layers, lowest first: a module uses (`crate::…`) only modules of the layers below it (a test checks):
//! 1. `error`, `conv`
//! 2. `caps`
//! 3. `rt_device`, `pipeline_stats`
//! 4. `device`
//! 5. `resources`
//! 6. `accel`
//! 7. `pipeline`
//! 8. `encoder`
//! 9. `raytracing`

mod accel;
mod caps;
pub mod conv;
mod device;
mod encoder;
mod error;
mod pipeline;
mod pipeline_stats;
mod raytracing;
mod resources;
mod rt_device;

pub use accel::{BottomLevel, TopLevel};
pub use caps::Capabilities;
pub use conv::{ConservativeRasterTier, Format, ResourceState};
pub use device::{
    AdoptDesc, Device, DeviceDesc, EnabledFeatures, RawGetInstanceProcAddr, SyncValidation,
    ValidationLog,
};
pub use encoder::{Barrier, ColorTarget, DepthTarget, Encoder, GpuTimer, PassTiming};
pub use error::{Result, RhiError};
pub use pipeline::{
    BindGroup, BindingKind, ComputePipeline, DepthState, GraphicsPipeline, GraphicsPipelineDesc,
    PipelineLayout, Resource,
};
pub use pipeline_stats::{PipelineStatistics, StatisticsUnavailable};
pub use raytracing::{RayTracingPipeline, RayTracingPipelineDesc, TriangleGeometry};
pub use resources::{
    live_gpu_allocation_bytes, Buffer, BufferUsage, Image, ImageDesc, ImageUsage, MemoryLocation,
};

#[cfg(test)]
mod layering {
    /// The layers written at the top of this file, lowest first: each a list of module names.
    fn layers() -> Vec<Vec<String>> {
        include_str!("lib.rs")
            .lines()
            .filter_map(|l| l.strip_prefix("//! "))
            .filter_map(|l| {
                let (number, rest) = l.split_once(". ")?;
                number.parse::<u32>().ok()?;
                Some(
                    rest.split('`')
                        .skip(1)
                        .step_by(2)
                        .map(str::to_owned)
                        .collect(),
                )
            })
            .collect()
    }

    /// The modules a source file uses through `crate::…` paths, comments aside.
    fn uses(source: &str) -> std::collections::BTreeSet<String> {
        source
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .flat_map(|l| l.match_indices("crate::").map(move |(i, _)| &l[i + 7..]))
            .map(|rest| {
                rest.chars()
                    .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                    .collect::<String>()
            })
            .filter(|m| !m.is_empty())
            .collect()
    }

    /// Every module uses only modules of lower layers: the `use crate::` graph has no cycle.
    #[test]
    fn modules_use_only_lower_layers() {
        let layers = layers();
        assert_eq!(layers.len(), 9, "{layers:?}");
        let layer_of = |m: &str| layers.iter().position(|l| l.iter().any(|x| x == m));
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut checked = 0;
        for entry in std::fs::read_dir(&dir).expect("src") {
            let path = entry.expect("entry").path();
            let name = path.file_stem().unwrap().to_string_lossy().into_owned();
            if name == "lib" {
                continue;
            }
            let own = layer_of(&name).unwrap_or_else(|| panic!("{name} is in no layer"));
            for used in uses(&std::fs::read_to_string(&path).expect("source")) {
                let theirs = layer_of(&used).unwrap_or_else(|| panic!("{used} is in no layer"));
                assert!(
                    theirs < own || (theirs == own && used == name),
                    "{name} (layer {}) uses {used} (layer {})",
                    own + 1,
                    theirs + 1
                );
            }
            checked += 1;
        }
        assert_eq!(checked, 11);
    }
}

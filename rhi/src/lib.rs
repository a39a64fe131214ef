//! A thin RHI over Vulkan that speaks D3D12 notions — conservative-raster tiers, UAVs, UAV barriers,
//! resource states — and maps them to Vulkan features and extensions. It creates its own headless device
//! or adopts an engine's. This is the only crate of the project that depends on `ash`.

mod caps;
pub mod conv;
mod device;
mod encoder;
mod error;
mod pipeline;
mod raytracing;
mod resources;

pub use caps::Capabilities;
pub use conv::{ConservativeRasterTier, Format, ResourceState};
pub use device::{
    AdoptDesc, Device, DeviceDesc, EnabledFeatures, RawGetInstanceProcAddr, ValidationLog,
};
pub use encoder::{Barrier, ColorTarget, DepthTarget, Encoder, GpuTimer, PassTiming};
pub use error::{Result, RhiError};
pub use pipeline::{
    BindGroup, BindingKind, ComputePipeline, DepthState, GraphicsPipeline, GraphicsPipelineDesc,
    PipelineLayout, Resource,
};
pub use raytracing::{
    BottomLevel, RayTracingPipeline, RayTracingPipelineDesc, TopLevel, TriangleGeometry,
};
pub use resources::{
    live_gpu_allocation_bytes, Buffer, BufferUsage, Image, ImageDesc, ImageUsage, MemoryLocation,
};

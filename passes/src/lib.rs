//! The render passes of hybrid ray-traced shadows (deep primitive map, after Jon Story, GDC 2015), each a
//! short unit that declares what it reads and writes, and the [`ShadowPipeline`] that strings them
//! together.

#![forbid(unsafe_code)]

pub mod area;
pub mod bvh;
mod error;
pub mod frame_plan;
pub mod fxaa;
pub mod gpu_types;
pub mod hybrid;
pub mod light;
pub mod min_combine;
pub mod pcss;
pub mod prim_buffer;
pub mod primitive_map;
pub mod ray_trace;
pub mod retire;
pub mod rt_peer;
pub mod scan;
mod screen_pass;
mod shaders;
pub mod shadow_map;
pub mod shadow_pipeline;
pub mod surface;
pub mod view_cull;

pub use area::{AreaConfig, DEFAULT_AREA_SAMPLES, MAX_AREA_SAMPLES};
pub use error::PassError;
pub use frame_plan::{
    FramePlan, PassId, PassStatus, PenumbraFilter, PlanRequest, ResourceId, ResourceSet,
    ShadowMode, SkipReason,
};
pub use gpu_types::MapStats;
pub use hybrid::HybridConfig;
pub use light::{
    directional_light_frustum, frustum_names, point_light_faces, spot_light_frusta, Light,
    CUBE_MAP_NAME,
};
pub use min_combine::MinCombine;
pub use pcss::PcssConfig;
pub use prim_buffer::{
    Draw, Geometry, IndexFormat, IndexLayout, Mesh, MeshVertices, SharedGeometry, VertexFormat,
    VertexLayout, MAP_SCRATCH_SETS,
};
pub use primitive_map::{
    choose_binning_path, packed_offset_words, packed_texels, unpack_list_offsets, BinningPath,
    BinningRequest, FaceMode, ListOffsets, PrimitiveMapConfig, DEFAULT_ENTRY_BUDGET, GUARD_VALUE,
    GUARD_WORDS, MIN_ENTRY_BUDGET, MIN_FITTED_ENTRIES, NEAREST_HIT_MAP_SIZE, PLUGINS_CHOICE_SIZE,
    TRACED_MAP_SIZE,
};
pub use retire::MAX_FRAMES_IN_FLIGHT;
pub use shadow_map::ShadowMapConfig;
pub use shadow_pipeline::{
    camera_in_frame, FitBatch, FrameInputs, FrameReport, ListBatch, ResourceReport, ShadowConfig,
    ShadowInputs, ShadowPipeline, FIT_BATCH_PASS, LIST_BATCH_PASS,
};
pub use surface::{NormalEncoding, NormalSpace, SurfaceInput};
pub use view_cull::{Casters, ViewVolume};

pub use shaders::{shader, shader_names};

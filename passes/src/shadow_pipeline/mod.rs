//! The engine-facing unit: the passes of one view of one light, chosen by the [`FramePlan`] from what the
//! configuration asks for, recorded into any command buffer. It reads the engine's depth and normal images
//! and writes one final visibility image (1 = lit): ray-traced, PCSS, hybrid or FXAA'd, whichever the
//! plan's final output is. The C ABI and the demo host both drive it.
//!
//! Linear order of the passes (each runs only if the plan keeps it):
//! prim buffer → shadow map → primitive map → occupancy → ray trace → classic shadow-map test → PCSS →
//! FXAA (on the ray-traced visibility) → lerp factor → hybrid blend | fill lit.
//!
//! Files by job: `config` (what a pipeline is asked for), `build` (creating the passes its plan needs),
//! `frame` (beginning a frame: constants and schedule), `record` (recording the passes with their
//! barriers), `report` (what a completed frame did).

mod batch;
mod build;
mod config;
mod frame;
mod record;
mod report;

pub use batch::{FitBatch, ListBatch, FIT_BATCH_PASS, LIST_BATCH_PASS};
pub use config::{FrameInputs, ShadowConfig, ShadowInputs};
pub use report::{FrameReport, ResourceReport};

use crate::frame_plan::{FramePlan, PassId, PassStatus, ResourceId, ResourceSet};
use crate::fxaa::FxaaPass;
use crate::gpu_types::{AreaSamples, MapPush, PcssConstants, RayTraceConstants};
use crate::hybrid::{BlendPass, LerpFactorPass};
use crate::light::{rebased, Light, LightFrame};
use crate::pcss::PcssPass;
use crate::prim_buffer::{Geometry, SharedGeometry};
use crate::primitive_map::{BinningPath, PrimitiveMap, ScratchBindings};
use crate::ray_trace::RayTracePass;
use crate::retire::RetireQueue;
use crate::shadow_map::ShadowMapPass;
use crate::PassError;
use glam::{DMat4, DVec3, Mat4, UVec4, Vec3};
use rhi::{BindGroup, Buffer, GpuTimer, Image};
use std::sync::Arc;

/// Derived per-frame constants.
struct FrameConstants {
    light: LightFrame,
    map: MapPush,
    ray: RayTraceConstants,
    pcss: PcssConstants,
    /// The light samples of an area trace (area shadows only).
    area: Option<Box<AreaSamples>>,
}

/// A frame begun and being recorded.
struct FrameState {
    constants: FrameConstants,
    light: Light,
    /// The frame's index and its slot in the ring.
    index: u64,
    slot: usize,
    /// Whether this pipeline records the shared prim buffer's build this frame.
    records_prims: bool,
    /// Index in the linear order of the first pass neither recorded nor passed over yet.
    next: usize,
    /// Whether a recording of this frame has reset and attached the GPU timer.
    timer_started: bool,
    /// Whether the frame's completion marker is recorded.
    marked: bool,
    /// Whether the primitive map's fit was recorded ahead of the pass, batched with other lights'
    /// ([`FitBatch`]): the pass then records the lists alone.
    map_fitted: bool,
    /// Whether the primitive map's lists were recorded ahead of the pass, batched with other lights'
    /// ([`ListBatch`]): the pass then records nothing.
    map_listed: bool,
}

/// What the ring keeps of one frame in flight: its GPU timer, the map state read back, and its schedule.
struct FrameSlot {
    /// The frame whose recording last used this slot.
    frame: Option<u64>,
    timer: GpuTimer,
    stats_readback: Buffer,
    /// Whether the frame recorded the copy of the map state into `stats_readback`.
    map_state_recorded: bool,
    statuses: Vec<(PassId, PassStatus)>,
    /// Written by the GPU when the frame's last pass has run: the frame's index plus one.
    completion: Buffer,
}

/// What growing the primitive map or giving a light its own ray-trace visibility replaced, held while frames in
/// flight may still use it.
enum RetiredMap {
    Entries {
        _entries: Buffer,
        _bindings: Box<ScratchBindings>,
        _ray_groups: Vec<BindGroup>,
    },
    Pairs {
        _bindings: Box<ScratchBindings>,
    },
    /// The shared ray-trace visibility's view and the bind groups that used it, replaced by an image of
    /// the light's own.
    SharedVisibility {
        _image: Image,
        _groups: Vec<BindGroup>,
    },
}

/// The passes of one view of one light, and the resources the plan allocates for them.
pub struct ShadowPipeline {
    config: ShadowConfig,
    plan: FramePlan,
    shared: Arc<SharedGeometry>,
    shadow_map: Option<ShadowMapPass>,
    map: Option<PrimitiveMap>,
    ray: Option<RayTracePass>,
    shadow_map_test: Option<PcssPass>,
    pcss: Option<PcssPass>,
    fxaa: Option<FxaaPass>,
    lerp: Option<LerpFactorPass>,
    blend: Option<BlendPass>,
    lit: Option<Image>,
    slots: Vec<FrameSlot>,
    binning_path: BinningPath,
    /// Resources whose contents are valid from an earlier recording.
    valid: ResourceSet,
    /// The light of the last recording that rendered the light-space maps.
    maps_light: Option<Light>,
    /// The frame being recorded (from `begin_frame` to the end of its linear order).
    frame: Option<FrameState>,
    /// The index of the last frame begun.
    last_frame: Option<u64>,
    /// List entries the newest completed map build needed (grows the map before the next build).
    needed_entries: u32,
    /// (Triangle, face) pairs the newest completed build of a point light's map kept (grows it likewise).
    needed_pairs: u32,
    retired: RetireQueue<RetiredMap>,
    /// Whether storage writes were recorded and not yet followed by a UAV barrier, and the plan's
    /// resources among what they wrote.
    pending_uav: Option<ResourceSet>,
    /// The schedule of the last frame begun, in linear order.
    statuses: Vec<(PassId, PassStatus)>,
    width: u32,
    height: u32,
    /// The engine's depth format: its precision is part of the ray-origin offset; `R32Float` and
    /// `R16Float` images hold linear view Z.
    depth_format: rhi::Format,
    /// How the passes decode the engine's normal ([`crate::surface::SurfaceInput::mode`]).
    surface_mode: UVec4,
    /// The engine's normal image's precision ([`crate::surface::SurfaceInput::normal_precision`]).
    normal_precision: f32,
    /// Whether the ray trace writes the visibility the lights' FXAA share ([`ShadowPipeline::is_shared`]).
    rt_shared: bool,
    /// The set of the geometry's map scratch this pipeline's map takes
    /// ([`SharedGeometry::map_scratch`]).
    scratch_set: usize,
}

impl ShadowPipeline {
    /// The configuration.
    pub fn config(&self) -> &ShadowConfig {
        &self.config
    }

    /// The frame plan.
    pub fn plan(&self) -> &FramePlan {
        &self.plan
    }

    /// The final visibility image of the plan (`R32_SFLOAT`, 1 = lit), in `UnorderedAccess` state after
    /// [`ShadowPipeline::record`]. The engine may transition or copy it; the next `record` rewrites it.
    pub fn output(&self) -> &Image {
        match self.image(self.plan.final_output()) {
            Some(image) => image,
            // `new` returns an error rather than a pipeline whose plan's final output is not allocated.
            None => unreachable!("the final output is allocated by ShadowPipeline::new"),
        }
    }

    /// The image holding `resource`, if the plan allocated it (screen-space and light-space images).
    pub fn image(&self, resource: ResourceId) -> Option<&Image> {
        use ResourceId as R;
        match resource {
            R::ShadowMap => self.shadow_map.as_ref().map(|s| &s.depth),
            R::Occupancy => self.map.as_ref().and_then(PrimitiveMap::occupancy_view),
            R::RtVisibility => self.ray.as_ref().map(|r| &r.visibility),
            R::BlockerDistance => self.ray.as_ref().and_then(|r| r.blocker_distance.as_ref()),
            R::ShadowMapVisibility => self.shadow_map_test.as_ref().map(|p| &p.output),
            R::Pcss => self.pcss.as_ref().map(|p| &p.output),
            R::RtAntialiased => self.fxaa.as_ref().map(|f| &f.output),
            R::LerpFactor => self.lerp.as_ref().map(|l| &l.output),
            R::Hybrid => self.blend.as_ref().map(|b| &b.output),
            R::Lit => self.lit.as_ref(),
            R::SceneGeometry
            | R::Light
            | R::Depth
            | R::Normal
            | R::PrimBuffer
            | R::PrimListOffsets
            | R::PrimListEntries => None,
        }
    }

    /// The buffer holding `resource`, if the plan allocated it: the primitive map's list offsets (packed:
    /// [`crate::unpack_list_offsets`] reads them) and list entries.
    pub fn buffer(&self, resource: ResourceId) -> Option<&Buffer> {
        match resource {
            ResourceId::PrimListOffsets => self.map.as_ref().map(|m| &m.offsets),
            ResourceId::PrimListEntries => self.map.as_ref().map(|m| &m.entries),
            ResourceId::PrimBuffer => self.prims(),
            _ => None,
        }
    }

    /// Whether `resource` is held in an image the lights share rather than one of the pipeline's own: the
    /// ray trace's visibility when only the light's FXAA reads it, in the same recording call. Its report
    /// lists it as shared scratch, not as the light's; it cannot be read back (it holds whichever light's
    /// ray trace was recorded last): ask for it in `extra_outputs` to keep an image of the light's own. A
    /// recording call that holds the ray trace without the FXAA (a host recording every light's ray trace
    /// before any FXAA) gives the light an image of its own from then on, so nothing else writes it between
    /// the two.
    pub fn is_shared(&self, resource: ResourceId) -> bool {
        resource == ResourceId::RtVisibility && self.rt_shared
    }

    /// Bytes of `resource` if the pipeline allocated it, with the buffers that serve it: the list offsets
    /// count the map's other buffers, the ray trace's visibility an area trace's own buffers
    /// ([`RayTracePass::area_buffer_bytes`]).
    fn resource_bytes(&self, resource: ResourceId) -> Option<u64> {
        match resource {
            ResourceId::PrimListOffsets => self.map.as_ref().map(|m| {
                m.bytes() - m.entries.size() - m.occupancy_view().map_or(0, Image::byte_size)
            }),
            ResourceId::RtVisibility => self
                .ray
                .as_ref()
                .map(|r| r.visibility.byte_size() + r.area_buffer_bytes()),
            r => self
                .buffer(r)
                .map(Buffer::size)
                .or_else(|| self.image(r).map(Image::byte_size)),
        }
    }

    /// The prim buffer (triangles in frame coordinates), if the plan has it.
    pub fn prims(&self) -> Option<&Buffer> {
        self.plan
            .runs(PassId::PrimBuffer)
            .then(|| self.shared.prims())
    }

    /// The geometry.
    pub fn geometry(&self) -> &Geometry {
        self.shared.geometry()
    }

    /// The geometry and prim buffer this pipeline shares with other lights' pipelines.
    pub fn shared_geometry(&self) -> &Arc<SharedGeometry> {
        &self.shared
    }

    /// GPU objects replaced (by the map's growth) and held until the frames that used them completed.
    pub fn retired_objects(&self) -> usize {
        self.retired.len()
    }

    /// The primitive map, if the plan has it.
    pub fn primitive_map(&self) -> Option<&PrimitiveMap> {
        self.map.as_ref()
    }

    /// The ray-trace outputs, if the plan has them.
    pub fn ray_trace(&self) -> Option<&RayTracePass> {
        self.ray.as_ref()
    }

    /// Camera-relative view-projection and the camera in frame coordinates (for a host G-buffer that
    /// rasterizes the prim buffer).
    pub fn camera_in_frame(&self, inputs: &FrameInputs) -> Result<(Mat4, Vec3), PassError> {
        camera_in_frame(inputs, self.geometry().origin())
    }
}

/// Camera-relative view-projection (view translated to the camera in f64) and the camera position in
/// the coordinates of the frame whose origin is `origin`: what a G-buffer rasterizing the prim buffer
/// (triangles relative to `origin`) needs.
pub fn camera_in_frame(inputs: &FrameInputs, origin: DVec3) -> Result<(Mat4, Vec3), PassError> {
    let view_proj_rel = camera_relative(inputs).as_mat4();
    let camera_frame = (inputs.camera_position.as_dvec3() - origin).as_vec3();
    if !view_proj_rel.is_finite() || !camera_frame.is_finite() {
        return Err(PassError::InvalidConfig(
            "camera matrices are not finite".into(),
        ));
    }
    Ok((view_proj_rel, camera_frame))
}

/// The view-projection of coordinates relative to the camera, in f64.
fn camera_relative(inputs: &FrameInputs) -> DMat4 {
    inputs.proj.as_dmat4() * rebased(inputs.view, inputs.camera_position.as_dvec3())
}

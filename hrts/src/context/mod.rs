//! The plugin context behind the C ABI: its device, lights, geometry and targets, the passes built from
//! them, and what reconfiguration retired while frames in flight may still use it.

mod build;
mod geometry;
mod lights;
mod plan;
pub(crate) use plan::plan_lights;
mod report;
pub(crate) mod schedule;
mod targets;

use crate::convert::{binning_path_to_c, FrameLight, LightShape};
use crate::error::{invalid, ApiError, ApiResult};
use crate::geometry::GeometrySource;
use crate::types::*;
use crate::version::{major_minor, OLDEST_MINOR};
use passes::retire::RetireQueue;
use passes::{
    BinningRequest, FitBatch, ListBatch, MinCombine, ShadowConfig, ShadowPipeline, SharedGeometry,
    SurfaceInput,
};
use rhi::{Device, Format, Image, ImageUsage};
use schedule::FrameSchedule;
use std::sync::Arc;

/// The passes of one light: one pipeline per frustum it is shadowed through and, for several, the
/// minimum over their outputs.
pub(crate) struct LightPasses {
    pub(crate) frusta: Vec<ShadowPipeline>,
    pub(crate) combine: Option<MinCombine>,
    /// Whether the light's last pass writes its layer of the engine's output directly (no copy).
    pub(crate) direct: bool,
}

impl LightPasses {
    /// The light's visibility, copied to its layer of the engine's output.
    pub(crate) fn output(&self) -> &Image {
        self.combine
            .as_ref()
            .map_or_else(|| self.frusta[0].output(), |c| &c.output)
    }

    /// The pipeline of a light of one frustum: its resources can be described and read back.
    pub(crate) fn single(&self, light: u32) -> ApiResult<&ShadowPipeline> {
        match self.frusta.as_slice() {
            [one] => Ok(one),
            many => Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                format!(
                    "light {light} is shadowed through {} frusta (a point light's cube faces or a wide spot \
                     light's): its per-frustum resources cannot be read back; its visibility is in its output layer",
                    many.len()
                ),
            )),
        }
    }
}

/// The passes of every light and the engine images they are bound to (the pipelines drop first).
pub(crate) struct Built {
    /// The passes of each light; `None` for a light reconfigured since (rebuilt before the next frame).
    pub(crate) lights: Vec<Option<LightPasses>>,
    pub(crate) shared: Arc<SharedGeometry>,
    pub(crate) depth: Image,
    /// The engine's normal image, or, with normals derived from depth, a 1×1 image of the plugin's own.
    pub(crate) normal: Image,
    /// Whether `normal` is the engine's (its layouts are the engine's to give).
    pub(crate) engine_normal: bool,
    /// How the passes decode the normal.
    pub(crate) surface: SurfaceInput,
    pub(crate) output: Image,
    /// Each layer of the output, when lights may write theirs directly (`R32_SFLOAT`, `R16_SFLOAT` or
    /// `R8_UNORM` with storage usage); empty otherwise.
    pub(crate) output_layers: Vec<Image>,
}

impl Built {
    /// The built pipelines of the frusta `recorded[light][frustum]` marks, with the index of their light.
    pub(crate) fn scheduled<'a>(
        &'a self,
        recorded: &'a [Vec<bool>],
    ) -> impl Iterator<Item = (usize, &'a ShadowPipeline)> {
        self.lights
            .iter()
            .zip(recorded)
            .enumerate()
            .filter_map(|(i, (l, r))| l.as_ref().map(|l| (i, l, r)))
            .flat_map(|(i, l, r)| {
                l.frusta
                    .iter()
                    .zip(r)
                    .filter(|(_, &on)| on)
                    .map(move |(p, _)| (i, p))
            })
    }

    /// [`Built::scheduled`], mutable.
    pub(crate) fn scheduled_mut<'a>(
        &'a mut self,
        recorded: &'a [Vec<bool>],
    ) -> impl Iterator<Item = (usize, &'a mut ShadowPipeline)> {
        self.lights
            .iter_mut()
            .zip(recorded)
            .enumerate()
            .filter_map(|(i, (l, r))| l.as_mut().map(|l| (i, l, r)))
            .flat_map(|(i, l, r)| {
                l.frusta
                    .iter_mut()
                    .zip(r)
                    .filter(|(_, &on)| on)
                    .map(move |(p, _)| (i, p))
            })
    }

    /// The passes of `light`, once built.
    pub(crate) fn light(&self, light: u32) -> ApiResult<&LightPasses> {
        match self.lights.get(light as usize) {
            Some(Some(p)) => Ok(p),
            Some(None) => Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                format!("light {light} was reconfigured and has not been recorded since"),
            )),
            None => Err(invalid(format!(
                "light {light} does not exist ({} configured)",
                self.lights.len()
            ))),
        }
    }
}

/// The engine images, as handles and shape.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) struct TargetSource {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) depth: u64,
    pub(crate) depth_format: Format,
    pub(crate) output_format: Format,
    /// The engine's normal image (`None`: normals derived from depth).
    pub(crate) normal: Option<u64>,
    pub(crate) normal_format: Format,
    pub(crate) surface: SurfaceInput,
    pub(crate) output: u64,
    pub(crate) output_layers: u32,
    /// Usage of the output image: with storage usage, lights write their layers directly.
    pub(crate) output_usage: ImageUsage,
}

/// What reconfiguration replaced, held until the frames that used it completed.
pub(crate) struct Retired {
    _pipelines: Vec<LightPasses>,
    _built: Option<Built>,
}

impl Retired {
    /// Lights' passes replaced by a rebuild.
    pub(crate) fn light_passes(pipelines: Vec<LightPasses>) -> Self {
        Self {
            _pipelines: pipelines,
            _built: None,
        }
    }
}

/// Where the recording of frames stands.
#[derive(Default)]
pub(crate) struct FrameProgress {
    /// The frame being recorded: its index, camera and lights, and the last `HrtsPass` recorded.
    pub(crate) open: Option<OpenFrame>,
    /// The last frame recorded to its end (through the output copy) since the passes were built.
    pub(crate) completed: Option<u64>,
}

/// A frame recorded pass by pass and not finished yet.
pub(crate) struct OpenFrame {
    pub(crate) index: u64,
    pub(crate) inputs: Vec<FrameLight>,
    pub(crate) last_pass: u32,
    /// Whether the call that began the frame gave deformed meshes (their bounds do not hold).
    pub(crate) deforms: bool,
}

/// State of one plugin context.
pub(crate) struct Context {
    pub(crate) built: Option<Built>,
    pub(crate) retired: RetireQueue<Retired>,
    pub(crate) device: Device,
    pub(crate) frames_in_flight: u32,
    /// One configuration per light.
    pub(crate) lights: Vec<ShadowConfig>,
    pub(crate) geometry: Option<GeometrySource>,
    pub(crate) targets: Option<TargetSource>,
    pub(crate) progress: FrameProgress,
    /// The index of the last frame begun.
    pub(crate) last_frame: Option<u64>,
    /// A read-back recorded after frame `f` is submitted after that frame's commands, so it may still be
    /// pending while frame `f + 1` is: it counts as a use in frame `f + 1` for what is retired after it.
    pub(crate) readback_frame: Option<u64>,
    /// How many times each light's passes were built.
    pub(crate) light_builds: Vec<u32>,
    /// How each light was last shadowed: its frusta (its passes hold one pipeline per frustum), and
    /// whether its one frustum is a point light's cube map.
    pub(crate) frusta: Vec<LightShape>,
    /// Which frusta the last `frames_in_flight` frames recorded, oldest first.
    pub(crate) schedules: std::collections::VecDeque<FrameSchedule>,
    /// The lights' primitive-map fits recorded together, timed per frame in flight; created with the
    /// first recording (its GPU timers need timestamps, as the passes do).
    pub(crate) fit_batch: Option<FitBatch>,
    /// The lights' primitive-map lists recorded together in groups over different scratch sets, timed per
    /// frame in flight; created with the first recording.
    pub(crate) list_batch: Option<ListBatch>,
}

impl Context {
    /// Creates a context on an adopted or own device.
    pub(crate) fn new(info: &HrtsContextCreateInfo) -> ApiResult<Self> {
        let (major, minor) = major_minor(info.api_version);
        let (ours, our_minor) = major_minor(HRTS_API_VERSION);
        let refused = if major != ours {
            Some(format!(
                "this library is API {ours}.{our_minor}: it reads no other major version"
            ))
        } else if minor > our_minor {
            Some(format!(
                "this library is API {ours}.{our_minor}, older than the caller's header: use a library of API {major}.{minor} or later"
            ))
        } else if minor < OLDEST_MINOR {
            Some(format!(
                "the {ours}.0 headers changed struct layouts without changing the version (HrtsDraw 72 then 76 bytes), so a {ours}.0 caller's structs cannot be told apart: rebuild against a header of {ours}.{OLDEST_MINOR} or later"
            ))
        } else {
            None
        };
        if let Some(why) = refused {
            return Err(ApiError::new(
                HrtsResult::ErrorVersion,
                format!("the caller's header is API {major}.{minor}: {why}"),
            ));
        }
        let frames_in_flight = match info.frames_in_flight {
            0 => ShadowConfig::default().frames_in_flight,
            n if n <= HRTS_MAX_FRAMES_IN_FLIGHT => n,
            n => {
                return Err(invalid(format!(
                    "frames_in_flight {n} must be within 0..={HRTS_MAX_FRAMES_IN_FLIGHT}"
                )))
            }
        };
        let device = crate::adopt::device(info)?;
        Ok(Self {
            built: None,
            retired: RetireQueue::default(),
            device,
            frames_in_flight,
            lights: vec![ShadowConfig {
                frames_in_flight,
                ..ShadowConfig::default()
            }],
            geometry: None,
            targets: None,
            progress: FrameProgress::default(),
            last_frame: None,
            readback_frame: None,
            light_builds: vec![0],
            frusta: vec![LightShape::default()],
            schedules: Default::default(),
            fit_batch: None,
            list_batch: None,
        })
    }

    pub(crate) fn capabilities(&self, out: &mut HrtsCapabilities) -> ApiResult<()> {
        let caps = self.device.capabilities();
        let default_path = passes::choose_binning_path(caps, BinningRequest::Auto)
            .map_or(HrtsBinningPath::Compute, binning_path_to_c);
        out.conservative_raster_tier = caps.conservative_raster_tier as u32;
        out.default_binning_path = default_path as u32;
        out.geometry_shader = caps.geometry_shader.into();
        out.timestamps = caps.timestamps.into();
        out.ray_query = caps.ray_query.into();
        out.ray_tracing_pipeline = caps.ray_tracing_pipeline.into();
        out.fragment_shader_interlock = caps.fragment_shader_interlock.into();
        out.max_map_size = caps.max_image_dimension_2d;
        out.max_map_entry_budget_kib =
            (caps.max_storage_buffer_range >> 10).min(u64::from(u32::MAX)) as u32;
        out.max_storage_buffer_range = caps.max_storage_buffer_range;
        out.device_name = [0; 128];
        for (dst, src) in out
            .device_name
            .iter_mut()
            .zip(caps.device_name.bytes().take(127))
        {
            *dst = src as std::ffi::c_char;
        }
        Ok(())
    }

    /// Holds `retired` until the frames recorded so far completed (drops it now if none was recorded).
    pub(crate) fn retire(&mut self, retired: Retired) {
        if let Some(last) = self.last_frame.max(self.readback_frame) {
            self.retired.retire(last, retired);
        }
    }

    /// Retires every pass (rebuilt on the next recording) and forgets the frame in progress.
    fn retire_built(&mut self) {
        if let Some(built) = self.built.take() {
            self.retire(Retired {
                _pipelines: Vec::new(),
                _built: Some(built),
            });
        }
        self.progress = FrameProgress::default();
    }
}

//! The plugin context behind the C ABI: its device, lights, geometry and targets, the passes built from
//! them, and what reconfiguration retired while frames in flight may still use it.

use crate::convert::finite;
use crate::convert::{
    binning_path_to_c, require_usage, resource_id, resource_index, shadow_config, surface_input,
    FrameLight, LightShape, RESOURCES,
};
use crate::error::{invalid, ApiError, ApiResult};
use crate::geometry::{cpu_geometry, geometry_from, vulkan_geometry, GeometrySource};
use crate::types::*;
use crate::version::{major_minor, OLDEST_MINOR};
use passes::retire::{completed_before, RetireQueue};
use passes::{
    BinningRequest, Casters, FrameReport, MinCombine, NormalEncoding, PassStatus, ResourceId,
    ShadowConfig, ShadowInputs, ShadowPipeline, SharedGeometry, SkipReason, SurfaceInput,
    ViewVolume,
};
use rhi::{Device, Format, Image, ImageDesc, ImageUsage};
use std::sync::Arc;

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
    /// Usage of the output image: with storage usage and `R32_SFLOAT`, lights write their layers directly.
    pub(crate) output_usage: ImageUsage,
}

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
    /// Each layer of the output, when lights may write theirs directly (`R32_SFLOAT` with storage usage);
    /// empty otherwise.
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

/// What reconfiguration replaced, held until the frames that used it completed.
pub(crate) struct Retired {
    _pipelines: Vec<LightPasses>,
    _built: Option<Built>,
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

/// Which frusta of each light a frame recorded: those where a caster may shadow a receiver in view within
/// the light's range ([`passes::ViewVolume::may_shadow`]).
pub(crate) struct FrameSchedule {
    pub(crate) index: u64,
    pub(crate) lights: Vec<LightSchedule>,
}

/// One light's frusta in a frame: recorded or culled, with their names for the report.
pub(crate) struct LightSchedule {
    pub(crate) kind: HrtsLightType,
    pub(crate) recorded: Vec<bool>,
    pub(crate) names: Vec<&'static str>,
    /// The mode auto chose for the light and why ([`ShadowConfig::auto_reason`]); `None` for a mode given.
    pub(crate) auto: Option<&'static str>,
}

impl LightSchedule {
    /// The light's decision and its reason in words, with the mode auto chose for it.
    pub(crate) fn decision(&self) -> (HrtsLightDecision, String) {
        let (decision, reason) = self.frusta_decision();
        match self.auto {
            Some(auto) => (decision, format!("{reason}; {auto}")),
            None => (decision, reason),
        }
    }

    /// The light's decision by the frusta recorded, and its reason in words.
    fn frusta_decision(&self) -> (HrtsLightDecision, String) {
        let kind = match self.kind {
            HrtsLightType::Directional => "directional light",
            HrtsLightType::Spot => "spot light",
            HrtsLightType::Point => "point light",
        };
        let recorded = self.recorded.iter().filter(|&&r| r).count();
        let culled: Vec<&str> = self
            .names
            .iter()
            .zip(&self.recorded)
            .filter(|(_, &r)| !r)
            .map(|(&n, _)| n)
            .collect();
        match (recorded, self.recorded.len()) {
            (0, _) => (
                HrtsLightDecision::OutOfView,
                format!("{kind}: no caster may shadow a receiver in view within range; lit"),
            ),
            (_, 1) if self.names == passes::CUBE_MAP_NAME => (
                HrtsLightDecision::Shadowed,
                format!(
                    "{kind}: receivers in view within range; its six cube faces built as one map"
                ),
            ),
            (_, 1) => (
                HrtsLightDecision::Shadowed,
                format!("{kind}: its frustum holds receivers in view"),
            ),
            (_, n) if culled.is_empty() => (
                HrtsLightDecision::Shadowed,
                format!("{kind}: all {n} frusta hold receivers in view within range"),
            ),
            (r, n) => (
                HrtsLightDecision::Shadowed,
                format!(
                    "{kind}: {r} of {n} frusta hold receivers in view within range; culled {}",
                    culled.join(" ")
                ),
            ),
        }
    }
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

    /// Sets one configuration per light. Lights whose configuration is unchanged keep their passes; a
    /// changed light's passes are rebuilt; a changed light count rebuilds all.
    pub(crate) fn configure_lights(&mut self, configs: &[HrtsConfig]) -> ApiResult<()> {
        if configs.is_empty() || configs.len() > HRTS_MAX_LIGHTS as usize {
            return Err(invalid(format!(
                "light count {} must be within 1..={HRTS_MAX_LIGHTS}",
                configs.len()
            )));
        }
        let lights = configs
            .iter()
            .enumerate()
            .map(|(i, c)| {
                self.checked_config(c).map_err(|e| ApiError {
                    message: format!("light {i}: {}", e.message),
                    ..e
                })
            })
            .collect::<ApiResult<Vec<_>>>()?;
        if lights.len() != self.lights.len() {
            self.retire_built();
        } else if let Some(built) = self.built.as_mut() {
            let mut replaced = Vec::new();
            for ((old, new), slot) in self.lights.iter().zip(&lights).zip(&mut built.lights) {
                if old != new {
                    replaced.extend(slot.take());
                }
            }
            built
                .shared
                .set_dynamic(lights.iter().any(|c| !c.static_geometry));
            if !replaced.is_empty() {
                self.retire(Retired {
                    _pipelines: replaced,
                    _built: None,
                });
                self.progress = FrameProgress::default();
            }
        }
        self.light_builds.resize(lights.len(), 0);
        self.frusta.resize(lights.len(), LightShape::default());
        self.lights = lights;
        Ok(())
    }

    /// The shadow casters' bounds this frame: `frame_bounds` when the engine gave them, else the geometry's
    /// own bounds when they hold (not when the frame `deforms` a mesh, nor for Vulkan geometry that moves).
    pub(crate) fn scene_bounds(
        &self,
        frame_bounds: Option<[glam::DVec3; 2]>,
        deforms: bool,
    ) -> Option<[glam::DVec3; 2]> {
        let dynamic = self.lights.iter().any(|c| !c.static_geometry);
        frame_bounds.or_else(|| {
            self.geometry
                .as_ref()
                .filter(|_| !deforms)
                .and_then(|g| g.cull_bounds(dynamic))
        })
    }

    /// Which frusta of each light may change a pixel in view this frame ([`ViewVolume::may_shadow`]): those
    /// holding receivers in view within the light's range that a caster within the casters' `bounds` (when
    /// they are known: [`Context::scene_bounds`]) may shadow; and the mode auto chose for it. A light
    /// shadowed through shadow maps (soft, hybrid) is culled by the view and its range alone.
    pub(crate) fn schedule(
        &self,
        lights: &[FrameLight],
        bounds: Option<[glam::DVec3; 2]>,
    ) -> Vec<LightSchedule> {
        let camera = lights.first().and_then(|l| l.frusta.first()).map(|f| {
            ViewVolume::new(
                f.proj.as_dmat4() * f.view.as_dmat4(),
                f.camera_position.as_dvec3(),
            )
        });
        lights
            .iter()
            .zip(&self.lights)
            .map(|(light, config)| {
                let directional = light.kind == HrtsLightType::Directional;
                let casters =
                    bounds
                        .zip(config.traced_light_size(directional))
                        .map(|(bounds, size)| Casters {
                            bounds,
                            light_size: f64::from(size),
                        });
                LightSchedule {
                    kind: light.kind,
                    auto: config.auto_reason(directional),
                    recorded: light
                        .frusta
                        .iter()
                        .map(|f| {
                            camera.as_ref().is_none_or(|c| {
                                c.may_shadow(&f.light, light.range, casters.as_ref())
                            })
                        })
                        .collect(),
                    names: (0..light.frusta.len())
                        .map(|k| light.frustum_name(k))
                        .collect(),
                }
            })
            .collect()
    }

    /// Keeps the schedule of frame `index` for its reports, with those of the frames in flight before it.
    pub(crate) fn keep_schedule(&mut self, index: u64, lights: Vec<LightSchedule>) {
        while self.schedules.len() >= self.frames_in_flight as usize {
            self.schedules.pop_front();
        }
        self.schedules.push_back(FrameSchedule { index, lights });
    }

    /// Takes how each light is shadowed this frame: a light whose number of frusta changed (a spot light
    /// turned point light, say), or whose resolved configuration did (mode auto choosing otherwise for a
    /// light that changed kind), has its passes rebuilt.
    pub(crate) fn set_frusta(&mut self, frusta: &[LightShape]) {
        let mut replaced = Vec::new();
        for (i, ((&new, old), configured)) in frusta
            .iter()
            .zip(&mut self.frusta)
            .zip(&self.lights)
            .enumerate()
        {
            let rebuild =
                new.frusta != old.frusta || new.config(configured) != old.config(configured);
            *old = new;
            if rebuild {
                if let Some(passes) = self.built.as_mut().and_then(|b| b.lights[i].take()) {
                    replaced.push(passes);
                }
            }
        }
        if !replaced.is_empty() {
            self.retire(Retired {
                _pipelines: replaced,
                _built: None,
            });
            self.progress = FrameProgress::default();
        }
    }

    /// A configuration checked against the device.
    fn checked_config(&self, c: &HrtsConfig) -> ApiResult<ShadowConfig> {
        let config = ShadowConfig {
            frames_in_flight: self.frames_in_flight,
            ..shadow_config(c)?
        };
        let caps = self.device.capabilities();
        config.map.validate(caps)?;
        passes::choose_binning_path(caps, config.map.binning)?;
        if config.shadow_map.size == 0 || config.shadow_map.size > caps.max_image_dimension_2d {
            return Err(invalid(format!(
                "shadow_map_size {} must be within 1..={}",
                config.shadow_map.size, caps.max_image_dimension_2d
            )));
        }
        Ok(config)
    }

    pub(crate) fn set_geometry_cpu(&mut self, g: &HrtsCpuGeometry) -> ApiResult<()> {
        self.geometry = Some(cpu_geometry(g)?);
        self.retire_built();
        Ok(())
    }

    /// Sets the engine's meshes: one (`listed` false: `hrts_set_geometry_vulkan`) or a list whose
    /// messages name the mesh.
    pub(crate) fn set_geometry_vulkan(
        &mut self,
        meshes: &[HrtsVulkanGeometry],
        listed: bool,
    ) -> ApiResult<()> {
        self.geometry = Some(vulkan_geometry(&self.device, meshes, listed)?);
        self.retire_built();
        Ok(())
    }

    /// Moves the geometry's draws: `transforms` holds 16 floats (column-major) per draw, over all meshes in
    /// order. Everything is checked before anything changes.
    pub(crate) fn set_draw_transforms(&mut self, transforms: &[f32]) -> ApiResult<()> {
        finite(transforms, "transforms")?;
        let models: Vec<glam::Mat4> = transforms
            .chunks_exact(16)
            .map(glam::Mat4::from_cols_slice)
            .collect();
        let geometry = self.geometry.as_mut().ok_or_else(|| {
            ApiError::new(
                HrtsResult::ErrorInvalidState,
                "set the geometry before moving its draws",
            )
        })?;
        let moved = geometry.moved(&models)?;
        if let Some(built) = &self.built {
            built.shared.set_transforms(&moved.stored_to_world)?;
        }
        geometry.move_draws(moved);
        Ok(())
    }

    pub(crate) fn set_targets(&mut self, t: &HrtsTargets) -> ApiResult<()> {
        let surface = surface_input(t)?;
        let derived = surface.encoding == NormalEncoding::FromDepth;
        if t.depth_image == 0 || (t.normal_image == 0 && !derived) || t.output_image == 0 {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                "depth_image, normal_image (unless normal_encoding is NONE) and output_image must be non-NULL",
            ));
        }
        let caps = self.device.capabilities();
        let max = caps.max_image_dimension_2d;
        if t.width == 0 || t.height == 0 || t.width > max || t.height > max {
            return Err(invalid(format!(
                "target size {}x{} must be within 1..={max}",
                t.width, t.height
            )));
        }
        if t.output_layers == 0 || t.output_layers > caps.max_image_array_layers {
            return Err(invalid(format!(
                "output_layers {} must be within 1..={}",
                t.output_layers, caps.max_image_array_layers
            )));
        }
        let view_z = [Format::R32Float, Format::R16Float];
        let depth_format = match t.depth_format {
            0 => Format::D32Float,
            raw => i32::try_from(raw)
                .ok()
                .and_then(|raw| {
                    Format::depth_from_raw_vk(raw)
                        .or_else(|| view_z.into_iter().find(|f| f.raw_vk() == raw))
                })
                .ok_or_else(|| {
                    let accepted: Vec<String> = Format::DEPTH
                        .iter()
                        .chain(&view_z)
                        .map(|f| f.raw_vk().to_string())
                        .collect();
                    ApiError::new(
                        HrtsResult::ErrorInvalidEnum,
                        format!(
                            "depth_format {raw} is not a depth format the plugin reads: one of {} (D16_UNORM, X8_D24_UNORM_PACK32, D24_UNORM_S8_UINT, D32_SFLOAT, D32_SFLOAT_S8_UINT, or view Z in R32_SFLOAT, R16_SFLOAT), or 0 for D32_SFLOAT",
                            accepted.join(", ")
                        ),
                    )
                })?,
        };
        if derived && view_z.contains(&depth_format) {
            return Err(invalid(format!(
                "normal_encoding NONE derives normals from the projection's depth; depth_format {} is a view-Z image: give the engine's normals",
                depth_format.raw_vk()
            )));
        }
        if !self.device.can_sample(depth_format) {
            return Err(ApiError::new(
                HrtsResult::ErrorUnsupported,
                format!(
                    "the device cannot sample depth_format {} ({depth_format:?}) with optimal tiling",
                    depth_format.raw_vk()
                ),
            ));
        }
        let output_format = match t.output_format {
            0 => Format::R32Float,
            raw => i32::try_from(raw)
                .ok()
                .and_then(Format::visibility_from_raw_vk)
                .ok_or_else(|| {
                    ApiError::new(
                        HrtsResult::ErrorInvalidEnum,
                        format!(
                            "output_format {raw} is not a visibility format the plugin writes: R8_UNORM (9), R16_SFLOAT (76) or R32_SFLOAT (100), or 0 for R32_SFLOAT"
                        ),
                    )
                })?,
        };
        if output_format != Format::R32Float
            && !self.device.can_blit(Format::R32Float, output_format)
        {
            return Err(ApiError::new(
                HrtsResult::ErrorUnsupported,
                format!(
                    "the device cannot blit R32_SFLOAT into output_format {} ({output_format:?})",
                    output_format.raw_vk()
                ),
            ));
        }
        require_usage(t.depth_usage, ImageUsage::SAMPLED, "depth_image", "SAMPLED")?;
        let normal_format = match t.normal_format {
            0 => Format::Rgba32Float,
            raw => i32::try_from(raw)
                .ok()
                .and_then(Format::normal_from_raw_vk)
                .ok_or_else(|| {
                    ApiError::new(
                        HrtsResult::ErrorInvalidEnum,
                        format!(
                            "normal_format {raw} is not a normal format the plugin reads: R32G32B32A32_SFLOAT, R16G16B16A16_SFLOAT, A2B10G10R10_UNORM_PACK32, R8G8B8A8_UNORM, R16G16_SNORM, R16G16_UNORM or R16G16_SFLOAT, or 0 for R32G32B32A32_SFLOAT"
                        ),
                    )
                })?,
        };
        if !derived {
            if !surface.accepts(normal_format) {
                return Err(invalid(format!(
                    "normal_format {} ({normal_format:?}, {} channels) cannot hold {:?} normals: xyz needs four channels",
                    normal_format.raw_vk(),
                    normal_format.channels(),
                    surface.encoding
                )));
            }
            if !self.device.can_sample(normal_format) {
                return Err(ApiError::new(
                    HrtsResult::ErrorUnsupported,
                    format!(
                        "the device cannot sample normal_format {} ({normal_format:?})",
                        normal_format.raw_vk()
                    ),
                ));
            }
            require_usage(
                t.normal_usage,
                ImageUsage::SAMPLED,
                "normal_image",
                "SAMPLED",
            )?;
        }
        let output_usage = require_usage(
            t.output_usage,
            ImageUsage::COPY_DST,
            "output_image",
            "TRANSFER_DST",
        )?;
        self.targets = Some(TargetSource {
            width: t.width,
            height: t.height,
            depth: t.depth_image,
            depth_format,
            output_format,
            normal: (!derived).then_some(t.normal_image),
            normal_format,
            surface,
            output: t.output_image,
            output_layers: t.output_layers,
            output_usage,
        });
        self.retire_built();
        Ok(())
    }

    /// Holds `retired` until the frames recorded so far completed (drops it now if none was recorded).
    fn retire(&mut self, retired: Retired) {
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

    /// Builds what a configuration, geometry or targets call retired: everything, or the lights
    /// reconfigured.
    pub(crate) fn ensure_built(&mut self) -> ApiResult<&mut Built> {
        if self.built.is_none() {
            self.built = Some(self.build_shared()?);
        }
        let (device, lights, builds) = (&self.device, &self.lights, &mut self.light_builds);
        let built = self
            .built
            .as_mut()
            .ok_or_else(|| ApiError::new(HrtsResult::ErrorInternal, "passes not built"))?;
        for (i, ((slot, config), &shape)) in built
            .lights
            .iter_mut()
            .zip(lights)
            .zip(&self.frusta)
            .enumerate()
        {
            if slot.is_none() {
                let config = shape.config(config);
                // The light's layer, written directly unless the configuration reads the final output
                // back (from the pipeline's own image).
                let read_back = config
                    .extra_outputs
                    .contains(config.plan_request().final_output());
                let layer = built.output_layers.get(i).filter(|_| !read_back);
                let passes = (|| -> Result<LightPasses, passes::PassError> {
                    let inputs = ShadowInputs {
                        depth: &built.depth,
                        normal: &built.normal,
                        surface: built.surface,
                        direct_output: layer.filter(|_| shape.frusta == 1),
                    };
                    let frusta = (0..shape.frusta)
                        .map(|_| {
                            ShadowPipeline::with_shared_geometry(
                                device,
                                built.shared.clone(),
                                &inputs,
                                config,
                            )
                        })
                        .collect::<Result<Vec<_>, _>>()?;
                    let combine = if frusta.len() > 1 {
                        let outputs: Vec<&Image> = frusta.iter().map(|p| p.output()).collect();
                        let output = layer.map(Image::alias).transpose()?;
                        Some(MinCombine::new(device, &outputs, output)?)
                    } else {
                        None
                    };
                    Ok(LightPasses {
                        frusta,
                        combine,
                        direct: layer.is_some(),
                    })
                })()
                .map_err(|e| {
                    let e = ApiError::from(e);
                    ApiError {
                        message: format!("light {i}: {}", e.message),
                        ..e
                    }
                })?;
                *slot = Some(passes);
                builds[i] += 1;
            }
        }
        Ok(built)
    }

    /// The geometry and engine images, with no light's passes yet.
    fn build_shared(&self) -> ApiResult<Built> {
        let (Some(source), Some(t)) = (self.geometry.as_ref(), self.targets) else {
            return Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                "set geometry and targets before recording",
            ));
        };
        let device = &self.device;
        let geometry = geometry_from(device, source)?;
        let dynamic = self.lights.iter().any(|c| !c.static_geometry);
        let shared = SharedGeometry::new(device, geometry, dynamic)?;
        let wrap = |name, handle, format, usage, layers| {
            let desc = ImageDesc {
                name,
                format,
                width: t.width,
                height: t.height,
                layers,
                usage,
            };
            // SAFETY: the engine guarantees its images are live and match the description (contract).
            unsafe { device.external_image(handle, &desc) }
        };
        let direct =
            t.output_format == Format::R32Float && t.output_usage.contains(ImageUsage::STORAGE);
        let output_layers = if direct {
            (0..t.output_layers)
                .map(|layer| {
                    let desc = ImageDesc {
                        name: "engine visibility layer",
                        format: Format::R32Float,
                        width: t.width,
                        height: t.height,
                        layers: 1,
                        usage: ImageUsage::STORAGE | ImageUsage::COPY_DST,
                    };
                    // SAFETY: the engine guarantees its output is live, R32_SFLOAT with storage usage, of
                    // `output_layers` layers (contract; checked against its stated usage and format).
                    unsafe { device.external_image_layer(t.output, &desc, layer) }
                })
                .collect::<Result<Vec<_>, _>>()?
        } else {
            Vec::new()
        };
        Ok(Built {
            output_layers,
            lights: (0..self.lights.len()).map(|_| None).collect(),
            shared,
            depth: wrap(
                "engine depth",
                t.depth,
                t.depth_format,
                ImageUsage::SAMPLED,
                1,
            )?,
            normal: match t.normal {
                Some(handle) => wrap(
                    "engine normal",
                    handle,
                    t.normal_format,
                    ImageUsage::SAMPLED,
                    1,
                )?,
                // Normals derived from depth: an image of the plugin's own is bound, never read.
                None => device.create_image(&ImageDesc {
                    name: "normal (derived from depth; not read)",
                    format: Format::Rgba32Float,
                    width: 1,
                    height: 1,
                    layers: 1,
                    usage: ImageUsage::SAMPLED,
                })?,
            },
            engine_normal: t.normal.is_some(),
            surface: t.surface,
            output: wrap(
                "engine visibility",
                t.output,
                t.output_format,
                ImageUsage::COPY_DST,
                t.output_layers,
            )?,
        })
    }

    /// Starts frame `index`: checks that it follows the last one, and drops what only completed frames
    /// used.
    pub(crate) fn begin_frame(&mut self, index: u64) -> ApiResult<()> {
        if let Some(last) = self.last_frame.filter(|&last| index <= last) {
            return Err(invalid(format!(
                "frame_index {index} must be greater than the last frame's ({last})"
            )));
        }
        self.retired
            .release_completed(completed_before(index, self.frames_in_flight));
        Ok(())
    }

    /// The passes, once a frame was recorded to its end and no other is being recorded.
    pub(crate) fn finished_frame(&self) -> ApiResult<&Built> {
        match (&self.built, &self.progress) {
            (
                Some(built),
                FrameProgress {
                    open: None,
                    completed: Some(_),
                },
            ) => Ok(built),
            (_, FrameProgress { open: Some(_), .. }) => Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                "a frame is being recorded: record its remaining passes through HRTS_PASS_OUTPUT_COPY first",
            )),
            _ => Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                "no frame has been recorded to its end since the last configuration, geometry or targets call",
            )),
        }
    }

    pub(crate) fn report(
        &self,
        frame_index: u64,
        light: u32,
        out: &mut HrtsFrameReport,
    ) -> ApiResult<()> {
        let built = self.built.as_ref().ok_or_else(|| {
            ApiError::new(
                HrtsResult::ErrorInvalidState,
                "no frame has been recorded since the last configuration, geometry or targets call",
            )
        })?;
        let passes = built.light(light)?;
        let schedule = self
            .schedules
            .iter()
            .find(|s| s.index == frame_index)
            .and_then(|s| s.lights.get(light as usize))
            .filter(|s| s.recorded.len() == passes.frusta.len())
            .ok_or_else(|| {
                invalid(format!(
                    "frame {frame_index} is not among the last {} frames recorded with light {light}'s passes as they are",
                    self.frames_in_flight
                ))
            })?;
        let reports = passes
            .frusta
            .iter()
            .zip(&schedule.recorded)
            .filter(|(_, &r)| r)
            .map(|(p, _)| {
                p.try_report_frame(frame_index)
                    .map_err(|e| ApiError::new(HrtsResult::ErrorInvalidArgument, e.to_string()))?
                    .ok_or_else(|| {
                        ApiError::new(
                            HrtsResult::NotReady,
                            format!("frame {frame_index} has not completed on the GPU: ask after its fence signalled"),
                        )
                    })
            })
            .collect::<ApiResult<Vec<FrameReport>>>()?;
        let first_pipeline = &passes.frusta[0];
        out.binning_path = binning_path_to_c(first_pipeline.binning_path()) as u32;
        out.tier = first_pipeline.binning_path().tier() as u32;
        let sum = |f: fn(&FrameReport) -> u32| {
            reports.iter().map(f).fold(0u32, |a, b| a.saturating_add(b))
        };
        out.texels_past_capacity = sum(|r| r.stats.texels_past_capacity);
        out.longest_list = reports
            .iter()
            .map(|r| r.stats.longest_list)
            .max()
            .unwrap_or(0);
        out.texels_with_list = sum(|r| r.stats.texels_with_list);
        out.entries = sum(|r| r.stats.entries);
        out.entry_capacity = sum(|r| r.stats.capacity);
        out.receiver_pixels = sum(|r| r.stats.receiver_pixels);
        out.receiver_texels = sum(|r| r.stats.receiver_texels);
        out.triangles_binned = sum(|r| r.stats.triangles_binned);
        out.bin_pairs = sum(|r| r.stats.pairs);
        out.bin_pair_capacity = sum(|r| r.stats.pair_capacity);
        out.texels_past_limit = sum(|r| r.stats.texels_past_limit);
        out.bin_items = sum(|r| r.stats.bin_items);
        out.frusta_without_lists = sum(|r| u32::from(r.stats.lists_skipped));
        out.pixels_walked = sum(|r| r.stats.pixels_walked);
        out.walks_unfinished = sum(|r| r.stats.walks_unfinished);
        out.map_to_texels = reports
            .first()
            .map_or([0.0; 16], |r| r.map_to_texels.to_cols_array());
        let timings: Vec<_> = reports.iter().flat_map(|r| &r.timings).collect();
        out.pass_count = timings.len().min(HRTS_MAX_REPORTED_PASSES) as u32;
        for (slot, t) in out.passes.iter_mut().zip(&timings) {
            slot.name = [0; 32];
            for (dst, src) in slot.name.iter_mut().zip(t.name.bytes().take(31)) {
                *dst = src as std::ffi::c_char;
            }
            slot.milliseconds = t.ms;
        }
        out.gpu_milliseconds = timings.iter().fold(0.0, |sum, t| sum + t.ms);
        out.pass_status = [HrtsPassStatus::NotInPlan as u32; HRTS_PASS_COUNT];
        let planned = first_pipeline.plan();
        for (i, &pass) in passes::PassId::ALL.iter().enumerate() {
            let statuses: Vec<PassStatus> = reports.iter().map(|r| r.passes[i].1).collect();
            out.pass_status[i] = match statuses.first() {
                _ if statuses.contains(&PassStatus::Ran) => HrtsPassStatus::Ran,
                None if planned.runs(pass) => HrtsPassStatus::Culled,
                None => HrtsPassStatus::NotInPlan,
                Some(PassStatus::Ran) => HrtsPassStatus::Ran,
                Some(PassStatus::Skipped(SkipReason::UpToDate)) => HrtsPassStatus::UpToDate,
                Some(PassStatus::Skipped(SkipReason::NotRequested)) => HrtsPassStatus::NotInPlan,
                Some(PassStatus::Skipped(SkipReason::Shared)) => HrtsPassStatus::Shared,
                Some(PassStatus::Skipped(SkipReason::Culled)) => HrtsPassStatus::Culled,
            } as u32;
        }
        out.pass_status[HrtsPass::OutputCopy as usize] = HrtsPassStatus::Ran as u32;
        out.resource_bytes = [0; HRTS_RESOURCE_COUNT];
        out.prim_buffer_bytes = 0;
        out.map_scratch_bytes = passes
            .frusta
            .iter()
            .map(ShadowPipeline::map_scratch_bytes)
            .max()
            .unwrap_or(0);
        let output = planned.final_output();
        // A layer written directly is the engine's memory, not the plugin's.
        let engine_owned = |r: ResourceId| passes.direct && passes.combine.is_none() && r == output;
        for r in passes.frusta.iter().flat_map(|p| p.resources()) {
            if engine_owned(r.resource) {
                continue;
            }
            if let Some(i) = RESOURCES.iter().position(|&id| id == r.resource) {
                out.resource_bytes[i] += r.bytes;
            } else if r.resource == ResourceId::PrimBuffer {
                out.prim_buffer_bytes = r.bytes;
            }
        }
        if let (Some(combine), Some(i), false) = (
            &passes.combine,
            RESOURCES.iter().position(|&id| id == output),
            passes.direct,
        ) {
            out.resource_bytes[i] += combine.bytes();
        }
        out.output_resource = resource_index(output)?;
        out.output_direct = passes.direct.into();
        out.light_builds = self.light_builds.get(light as usize).copied().unwrap_or(0);
        out.frusta = reports.len() as u32;
        out.frusta_culled = (schedule.recorded.len() - reports.len()) as u32;
        let (decision, reason) = schedule.decision();
        out.decision = decision as u32;
        out.prim_triangles_rebuilt = built.shared.triangles_rebuilt(frame_index);
        out.decision_reason = [0; 128];
        for (dst, src) in out.decision_reason.iter_mut().zip(reason.bytes().take(127)) {
            *dst = src as std::ffi::c_char;
        }
        Ok(())
    }

    pub(crate) fn resource_info(
        &mut self,
        light: u32,
        resource: u32,
        out: &mut HrtsResourceInfo,
    ) -> ApiResult<()> {
        let id = resource_id(resource)?;
        let pipeline = self.ensure_built()?.light(light)?.single(light)?;
        match (pipeline.image(id), pipeline.buffer(id)) {
            (Some(image), _) => {
                out.allocated = 1;
                out.width = image.width();
                out.height = image.height();
                out.layers = image.layers();
                out.format = image.format().raw_vk();
                out.bytes = image.byte_size();
            }
            (None, Some(buffer)) => {
                out.allocated = 1;
                out.width = (buffer.size() / 4).min(u64::from(u32::MAX)) as u32;
                out.height = 1;
                out.layers = 1;
                out.format = Format::R32Uint.raw_vk();
                out.bytes = buffer.size();
            }
            (None, None) => {
                out.allocated = 0;
                (out.width, out.height, out.layers, out.format, out.bytes) = (0, 0, 0, 0, 0);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use passes::ShadowMode;

    /// Under mode auto a light's passes are built for the mode its kind's size gives, and its report says
    /// which and why.
    #[test]
    fn auto_lights_are_built_and_reported_by_their_size() {
        let mut auto = ShadowConfig {
            mode: ShadowMode::Auto,
            ..ShadowConfig::default()
        };
        auto.pcss.angular_radius = 0.0;
        let sun = LightShape::default();
        let lamp = LightShape {
            cube: true,
            directional: false,
            ..sun
        };
        assert_eq!(sun.config(&auto).mode, ShadowMode::Hard);
        let lamp_config = lamp.config(&auto);
        assert_eq!(lamp_config.mode, ShadowMode::Area);
        assert!(lamp_config.map.cube);
        let schedule = |kind, config: &ShadowConfig| LightSchedule {
            kind,
            recorded: vec![true],
            names: vec!["whole"],
            auto: config.auto_reason(kind == HrtsLightType::Directional),
        };
        let (decision, reason) = schedule(HrtsLightType::Directional, &auto).decision();
        assert_eq!(decision, HrtsLightDecision::Shadowed);
        assert_eq!(
            reason,
            "directional light: its frustum holds receivers in view; auto: hard (zero-size light)"
        );
        let (_, reason) = schedule(HrtsLightType::Spot, &auto).decision();
        assert!(reason.ends_with("; auto: area (sized light)"), "{reason}");
        let (_, reason) = schedule(HrtsLightType::Spot, &ShadowConfig::default()).decision();
        assert_eq!(reason, "spot light: its frustum holds receivers in view");
    }
}

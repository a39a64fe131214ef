//! Beginning a frame: its constants and the schedule of its passes.

use super::{
    camera_in_frame, camera_relative, FrameConstants, FrameInputs, FrameState, ShadowPipeline,
};
use crate::area::{area_samples, check_angular_radius, local_area_reach, local_area_samples};
use crate::frame_plan::{PassId, PassStatus, ResourceId, ResourceSet, ShadowMode, SkipReason};
use crate::gpu_types::{MapPush, PcssConstants, RayTraceConstants};
use crate::light::{Light, LightFrame};
use crate::prim_buffer::PrimBufferClaim;
use crate::primitive_map::FaceMode;
use crate::ray_trace::{RAY_OFFSET_FLOAT_BOUND, RAY_OFFSET_PIXELS};
use crate::retire::completed_before;
use crate::surface;
use crate::PassError;
use bytemuck::Zeroable;
use glam::{UVec4, Vec4};

impl ShadowPipeline {
    fn constants(&self, inputs: &FrameInputs) -> Result<FrameConstants, PassError> {
        let origin = self.geometry().origin();
        let (_, camera_frame) = camera_in_frame(inputs, origin)?;
        let inv_view_proj_rel = camera_relative(inputs).inverse().as_mat4();
        let light = LightFrame::new(&inputs.light, origin)?;
        if !inv_view_proj_rel.is_finite() {
            return Err(PassError::InvalidConfig(
                "camera matrices are not finite or invertible".into(),
            ));
        }
        let cfg = self.config.map;
        let point = matches!(inputs.light, Light::Point { .. });
        if point != cfg.cube {
            return Err(PassError::InvalidConfig(if point {
                "a point light needs a pipeline whose primitive map is a cube (PrimitiveMapConfig::cube)"
                    .into()
            } else {
                format!(
                    "this pipeline's primitive map is a point light's cube; the frame gave a {} light",
                    inputs.light.kind_name()
                )
            }));
        }
        if light.position.is_some() && cfg.faces == FaceMode::FrontOnly {
            return Err(PassError::InvalidConfig(
                "a front-only primitive map needs a directional light: store both faces for a spot light"
                    .into(),
            ));
        }
        let radians_per_pixel = (2.0 / (inputs.proj.y_axis.y * self.height as f32)).abs();
        let front_only = u32::from(cfg.faces == FaceMode::FrontOnly);
        let dir = light.direction;
        let sm = self.config.shadow_map;
        let view_to_world = surface::view_to_world(inputs.view);
        let surface =
            surface::surface_vector(inputs.proj, self.depth_format, self.normal_precision);
        let pc = self.config.pcss;
        let area = self.config.mode == ShadowMode::Area;
        let samples = self.config.area.samples;
        // Area shadows: a directional light widens footprints by its angular radius; a spot or point light
        // by its emitter's radius, within the reach of every frustum (the same shape for a cube's faces).
        let (penumbra, emitter_radius, reach) = match (area, light.position) {
            (false, _) => (0.0, 0.0, None),
            (true, None) => {
                check_angular_radius(pc.angular_radius)?;
                (pc.angular_radius.tan(), 0.0, None)
            }
            (true, Some(position)) => {
                let reach = local_area_reach(light.frusta[0], position, pc.spot_radius)?;
                (0.0, pc.spot_radius, Some(reach))
            }
        };
        Ok(FrameConstants {
            light,
            area: area.then(|| {
                Box::new(if light.position.is_some() {
                    local_area_samples(samples)
                } else {
                    area_samples(dir, pc.angular_radius, samples)
                })
            }),
            map: MapPush {
                to_light: light.position.map_or((-dir).extend(0.0), |p| p.extend(1.0)),
                size: cfg.size,
                front_only,
                penumbra,
                emitter_radius,
                near_radius: reach.map_or(0.0, |r| r.near_radius),
                depth_floor: reach.map_or(0.0, |r| r.depth_floor),
                ..MapPush::zeroed()
            },
            ray: RayTraceConstants {
                inv_view_proj_rel,
                light_view_proj: light.view_proj,
                camera_pos: camera_frame.extend(1.0),
                light_dir: dir.extend(if emitter_radius > 0.0 {
                    emitter_radius
                } else {
                    penumbra
                }),
                dims: UVec4::new(self.width, self.height, cfg.size, 0),
                offset: Vec4::new(
                    radians_per_pixel,
                    RAY_OFFSET_PIXELS,
                    RAY_OFFSET_FLOAT_BOUND,
                    self.depth_format.depth_quantum(),
                ),
                misc: UVec4::new(
                    front_only,
                    self.geometry().triangle_count(),
                    if area {
                        self.config.area.bundle_walk_budget
                    } else {
                        0
                    },
                    if area { samples } else { 0 },
                ),
                light_pos: light.position.map_or(Vec4::ZERO, |p| p.extend(1.0)),
                view_to_world,
                surface_mode: self.surface_mode,
                surface,
            },
            pcss: PcssConstants {
                inv_view_proj_rel,
                camera_pos: camera_frame.extend(radians_per_pixel),
                dims: UVec4::new(self.width, self.height, sm.size, 0),
                taps: UVec4::new(pc.blocker_search_taps, pc.pcf_taps, 0, 0),
                radii: Vec4::new(
                    pc.max_search_radius,
                    pc.min_filter_radius,
                    pc.max_filter_radius,
                    0.0,
                ),
                bias: Vec4::new(
                    sm.constant_bias,
                    sm.slope_bias,
                    PLANE_TOLERANCE_TEXELS,
                    CONSTANT_TOLERANCE_TEXELS,
                ),
                light: light.gpu(sm.size, pc.light_size(light.position.is_some())),
                view_to_world,
                surface_mode: self.surface_mode,
                surface,
            },
        })
    }

    /// Plans the next frame (its index one past the last begun, 0 at first): see
    /// [`ShadowPipeline::begin_frame_at`].
    pub fn begin_frame(&mut self, inputs: &FrameInputs) -> Result<(), PassError> {
        let index = self.last_frame.map_or(0, |f| f + 1);
        self.begin_frame_at(inputs, index)
    }

    /// Plans frame `index` (no commands): computes its constants and decides which passes run and which are
    /// skipped as up to date. Then [`ShadowPipeline::record_passes`] records them, in one call or several,
    /// in linear order.
    ///
    /// Frames in flight: indices increase from frame to frame (gaps are allowed), and beginning frame
    /// `index` states that the recordings of every frame up to `index - frames_in_flight` have completed on
    /// the GPU. Beginning the frame being recorded again (the same index) abandons it, as does beginning a
    /// later one before it was recorded to its end: the outputs of its unrecorded passes count as stale.
    pub fn begin_frame_at(&mut self, inputs: &FrameInputs, index: u64) -> Result<(), PassError> {
        let open = self.frame.as_ref().map(|f| (f.index, f.records_prims));
        let reopening = open.is_some_and(|(i, _)| i == index);
        if let Some(last) = self
            .last_frame
            .filter(|&last| index < last || (index == last && !reopening))
        {
            return Err(PassError::InvalidConfig(format!(
                "frame index {index} does not follow the last frame begun ({last}): frame indices must increase"
            )));
        }
        if index == u64::MAX {
            return Err(PassError::InvalidConfig(
                "frame index u64::MAX is reserved".into(),
            ));
        }
        let constants = self.constants(inputs)?;
        if let Some(open) = self.frame.take() {
            for &(pass, status) in &self.statuses[open.next..] {
                if status == PassStatus::Ran {
                    self.valid = self.valid.difference(self.plan.writes(pass));
                }
            }
        }
        let frames = self.config.frames_in_flight;
        self.retired
            .release_completed(completed_before(index, frames));
        let slot = (index % u64::from(frames)) as usize;
        if !reopening {
            // The newest completed frame's map state says how many list entries the map needed, which the
            // next build grows to: the frame that used this slot before has completed (the contract), and
            // a later one may have too (its completion marker says so).
            if let Some(state) = self.newest_completed_map_state(completed_before(index, frames))? {
                self.needed_entries = state.totals.y;
                self.needed_pairs = state.grid.z;
            }
        }
        let claim = match (self.plan.runs(PassId::PrimBuffer), open) {
            (false, _) => PrimBufferClaim::UpToDate,
            (true, Some((_, true))) if reopening => PrimBufferClaim::Record,
            (true, _) => self.shared.claim(index),
        };
        let mut changed = ResourceSet::of(&[ResourceId::Depth, ResourceId::Normal]);
        if claim != PrimBufferClaim::UpToDate {
            changed = changed.with(ResourceId::SceneGeometry);
        }
        if !self.config.static_light || self.maps_light != Some(inputs.light) {
            changed = changed.with(ResourceId::Light);
        }
        let prims = ResourceSet::of(&[ResourceId::PrimBuffer]);
        self.valid = if self.shared.is_built() {
            self.valid.union(prims)
        } else {
            self.valid.difference(prims)
        };
        self.statuses = self.plan.schedule(changed, self.valid);
        if claim == PrimBufferClaim::RebuiltByAnother {
            self.statuses[PassId::PrimBuffer as usize].1 = PassStatus::Skipped(SkipReason::Shared);
        }
        let s = &mut self.slots[slot];
        s.frame = Some(index);
        s.map_state_recorded = false;
        s.statuses = self.statuses.clone();
        self.last_frame = Some(index);
        self.frame = Some(FrameState {
            constants,
            light: inputs.light,
            index,
            slot,
            records_prims: claim == PrimBufferClaim::Record,
            next: 0,
            timer_started: false,
            marked: false,
            map_fitted: false,
            map_listed: false,
        });
        Ok(())
    }
}

/// PCSS receiver-plane tolerance, in texels of the receiver plane's depth slope: covers the rasterizer's
/// sub-texel vertex snapping (1/256 texel) with margin.
const PLANE_TOLERANCE_TEXELS: f32 = 1.0 / 16.0;
/// PCSS constant tolerance, in texels of world size at the receiver.
const CONSTANT_TOLERANCE_TEXELS: f32 = 1.0 / 32.0;

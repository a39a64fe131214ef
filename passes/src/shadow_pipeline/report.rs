//! What a frame did: timings, map statistics, pass statuses and resource sizes, read back once the GPU
//! has finished it.

use super::{FrameSlot, ShadowPipeline};
use crate::frame_plan::{PassId, PassStatus, ResourceId};
use crate::gpu_types::{MapState, MapStats};
use crate::primitive_map::BinningPath;
use crate::PassError;
use bytemuck::Zeroable;
use glam::Mat4;
use rhi::PassTiming;

/// Bytes a resource of the plan takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ResourceReport {
    /// The resource.
    pub resource: ResourceId,
    /// Its size in bytes.
    pub bytes: u64,
}

/// What a frame did.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    /// GPU time per pass that ran this frame, in recording order.
    pub timings: Vec<PassTiming>,
    /// The binning path of the primitive map (the path the device would use when the plan has no
    /// primitive map; compute if it has none).
    pub binning_path: BinningPath,
    /// Statistics of the primitive map as last built (zero without a primitive map).
    pub stats: MapStats,
    /// The primitive map's fitted transform, frame coordinates to homogeneous texel space, as last built
    /// (zero without a primitive map).
    pub map_to_texels: Mat4,
    /// Every pass of the linear order: ran this frame, or skipped and why.
    pub passes: Vec<(PassId, PassStatus)>,
    /// Every resource the pipeline allocated, with its size.
    pub resources: Vec<ResourceReport>,
    /// The resource [`ShadowPipeline::output`] holds.
    pub output: ResourceId,
    /// GPU bytes of the primitive map's scratch (build scratch, receiver map, screen-size pixel texels),
    /// shared by the maps of every light over the same geometry (not in `resources`; 0 without a primitive
    /// map).
    pub map_scratch_bytes: u64,
    /// Triangles whose prim-buffer slots the frame rewrote, whichever light's pipeline recorded the build
    /// (0 when the prim buffer was up to date).
    pub prim_triangles_rebuilt: u32,
}

impl FrameReport {
    /// Whether `pass` ran this frame.
    pub fn ran(&self, pass: PassId) -> bool {
        self.passes.contains(&(pass, PassStatus::Ran))
    }

    /// Why `pass` was skipped this frame (`None` if it ran).
    pub fn status(&self, pass: PassId) -> Option<PassStatus> {
        self.passes
            .iter()
            .find(|(p, _)| *p == pass)
            .map(|&(_, s)| s)
    }

    /// Total bytes of the allocated resources.
    pub fn total_bytes(&self) -> u64 {
        self.resources.iter().map(|r| r.bytes).sum()
    }
}

impl ShadowPipeline {
    /// Every resource the pipeline allocated, with its size (what a frame report lists).
    pub fn resources(&self) -> Vec<ResourceReport> {
        self.plan
            .resources()
            .iter()
            .filter(|&r| !self.is_shared(r))
            .filter_map(|r| {
                self.resource_bytes(r)
                    .map(|bytes| ResourceReport { resource: r, bytes })
            })
            .collect()
    }

    /// GPU bytes of the scratch this pipeline shares with the other lights' (the primitive map's build
    /// scratch, receiver map and screen-size pixel texels; the ray trace's visibility when the lights'
    /// FXAA share it: [`ShadowPipeline::is_shared`]; 0 without either).
    pub fn map_scratch_bytes(&self) -> u64 {
        let map = self
            .map
            .as_ref()
            .map_or(0, |_| self.shared.map_scratch_bytes());
        let visibility = match &self.ray {
            Some(ray) if self.rt_shared => ray.visibility.byte_size(),
            _ => 0,
        };
        map + visibility
    }

    /// The binning path of the primitive map (what the device would use when the plan has none).
    pub fn binning_path(&self) -> BinningPath {
        self.binning_path
    }

    /// Timings and statistics of the last frame begun, waiting for its GPU timestamps; call after its
    /// submission was made.
    pub fn report(&self) -> Result<FrameReport, PassError> {
        let slot = self.slot_of(self.last_frame)?;
        let timings = slot.timer.resolve()?;
        if !self
            .last_frame
            .is_some_and(|f| slot_completed(slot, f).unwrap_or(false))
        {
            return Err(PassError::InvalidConfig(
                "the last frame has not completed: report after its submission finished".into(),
            ));
        }
        self.report_with(slot, timings)
    }

    /// [`ShadowPipeline::report`] without waiting: `None` while the GPU has not finished the frame.
    pub fn try_report(&self) -> Result<Option<FrameReport>, PassError> {
        self.try_report_frame(self.last_frame.unwrap_or(u64::MAX))
    }

    /// The report of frame `index` if the GPU has finished it (`None` while not), from the ring of the last
    /// `frames_in_flight` frames begun; an error for a frame no longer (or never) in the ring.
    pub fn try_report_frame(&self, index: u64) -> Result<Option<FrameReport>, PassError> {
        let slot = self.slot_of(Some(index))?;
        if !slot_completed(slot, index)? {
            return Ok(None);
        }
        match slot.timer.try_resolve()? {
            Some(timings) => self.report_with(slot, timings).map(Some),
            None => Ok(None),
        }
    }

    fn slot_of(&self, index: Option<u64>) -> Result<&FrameSlot, PassError> {
        let frames = u64::from(self.config.frames_in_flight);
        index
            .and_then(|i| {
                self.slots
                    .get((i % frames) as usize)
                    .filter(|s| s.frame == Some(i))
            })
            .ok_or_else(|| {
                PassError::InvalidConfig(match (index, self.last_frame) {
                    (Some(i), Some(last)) => format!(
                        "frame {i} is not among the last {frames} frames begun (the last is {last})"
                    ),
                    _ => "no frame has been begun".into(),
                })
            })
    }

    /// The map state a slot's frame read back, once that frame has completed (the caller's contract).
    /// The map state of the newest frame in the ring that built the map and has completed: by the caller's
    /// contract (up to `completed`), or by its completion marker.
    pub(super) fn newest_completed_map_state(
        &self,
        completed: Option<u64>,
    ) -> Result<Option<MapState>, PassError> {
        let mut newest: Option<(u64, &FrameSlot)> = None;
        for s in &self.slots {
            let Some(frame) = s.frame.filter(|_| s.map_state_recorded) else {
                continue;
            };
            let done = completed.is_some_and(|c| frame <= c) || slot_completed(s, frame)?;
            if done && newest.is_none_or(|(f, _)| frame > f) {
                newest = Some((frame, s));
            }
        }
        newest.map(|(_, s)| Ok(read_states(s)?[0])).transpose()
    }

    fn report_with(
        &self,
        slot: &FrameSlot,
        timings: Vec<PassTiming>,
    ) -> Result<FrameReport, PassError> {
        let states = match slot.map_state_recorded {
            true => read_states(slot)?,
            false => vec![MapState::zeroed()],
        };
        let resources = self.resources();
        Ok(FrameReport {
            timings,
            binning_path: self.binning_path,
            stats: MapStats::from_states(&states),
            map_to_texels: states[0].to_texels,
            passes: slot.statuses.clone(),
            resources,
            output: self.plan.final_output(),
            map_scratch_bytes: self.map_scratch_bytes(),
            prim_triangles_rebuilt: slot.frame.map_or(0, |f| self.shared.triangles_rebuilt(f)),
        })
    }
}

/// The map states of every frustum a slot's frame read back (at least one).
fn read_states(slot: &FrameSlot) -> Result<Vec<MapState>, PassError> {
    let bytes = slot.stats_readback.read()?;
    let states: Vec<MapState> = bytes
        .chunks_exact(std::mem::size_of::<MapState>())
        .map(bytemuck::pod_read_unaligned)
        .collect();
    if states.is_empty() {
        return Err(PassError::InvalidConfig(
            "the map state read-back holds no state".into(),
        ));
    }
    Ok(states)
}

/// Whether the GPU has run frame `frame`'s recording in `slot` to its end (its completion marker).
fn slot_completed(slot: &FrameSlot, frame: u64) -> Result<bool, PassError> {
    Ok(slot.completion.read_u64_volatile(0)? == frame.wrapping_add(1))
}

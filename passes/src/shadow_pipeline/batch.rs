//! Several lights' primitive maps recorded as batches, so that the lights' dispatches run side by side
//! instead of each light's waiting for the last one's:
//! - [`FitBatch`]: every light's fit, each phase of every light followed by one barrier.
//! - [`ListBatch`]: the lists of a group of lights whose maps take different scratch sets, each round of
//!   steps followed by one barrier.
//!
//! Each batch is timed as one pass, in a GPU timer of its own per frame in flight.
//!
//! Reads: depth, normal, each light's constants, the prim buffer (lists). Writes: each light's map state
//! (its fit), list offsets and entries, and its scratch set (lists).

use super::ShadowPipeline;
use crate::frame_plan::PassId;
use crate::primitive_map::{FitPhase, PrimitiveMap};
use crate::PassError;
use rhi::{Barrier, Device, Encoder, GpuTimer};

/// The name of the fit batch's timed pass.
pub const FIT_BATCH_PASS: &str = "primitive map: fit (batched)";

/// The name of the list batch's timed pass.
pub const LIST_BATCH_PASS: &str = "primitive map: lists (batched)";

/// Groups a list batch times in one frame (each group one timed pass): as many as a context's frusta can
/// form (64 lights of 6 frusta, in groups of at least two).
const LIST_GROUPS_TIMED: u32 = 192;

/// A GPU timer per frame in flight, with the frame that last recorded into each.
struct BatchTimers {
    /// Per slot (frame index modulo the frames in flight): the frame that last recorded a batch there, and
    /// the timer.
    slots: Vec<(Option<u64>, GpuTimer)>,
}

impl BatchTimers {
    fn new(device: &Device, frames_in_flight: u32, passes: u32) -> Result<Self, PassError> {
        let slots = (0..frames_in_flight.max(1))
            .map(|_| Ok((None, device.create_timer(passes)?)))
            .collect::<Result<_, PassError>>()?;
        Ok(Self { slots })
    }

    /// Times the next passes of `enc` in frame `frame_index`'s timer: attached (reset) by the frame's
    /// first batch, continued by the later ones.
    fn time(&mut self, enc: &mut Encoder<'_>, frame_index: u64) {
        let slot = (frame_index % self.slots.len() as u64) as usize;
        let (frame, timer) = &mut self.slots[slot];
        if *frame == Some(frame_index) {
            enc.continue_timer(timer);
        } else {
            *frame = Some(frame_index);
            enc.attach_timer(timer);
        }
    }

    /// The GPU milliseconds of frame `frame_index`'s passes, summed: `None` while its queries are not
    /// available, or if a later frame took its slot (or it recorded none).
    fn milliseconds(&self, frame_index: u64) -> Result<Option<f64>, PassError> {
        let slot = (frame_index % self.slots.len() as u64) as usize;
        match &self.slots[slot] {
            (Some(frame), timer) if *frame == frame_index => Ok(timer
                .try_resolve()?
                .map(|t| t.iter().map(|t| t.ms).sum::<f64>())),
            _ => Ok(None),
        }
    }
}

/// The batched fits of the lights recorded into one call, with a GPU timer per frame in flight.
pub struct FitBatch(BatchTimers);

impl FitBatch {
    /// A batch for `frames_in_flight` frames in flight (at least 1).
    pub fn new(device: &Device, frames_in_flight: u32) -> Result<Self, PassError> {
        Ok(Self(BatchTimers::new(device, frames_in_flight, 1)?))
    }

    /// Records the fits of those `pipelines` whose map [`ShadowPipeline::fits_map_in`] `passes`, batched,
    /// when there are at least two (one light gains nothing: its pass records its fit as before). Depth
    /// and normal must be in `ShaderResource` state. Returns the indices (in `pipelines`) of the lights
    /// fitted, empty if none was.
    pub fn record(
        &mut self,
        enc: &mut Encoder<'_>,
        frame_index: u64,
        pipelines: &mut [&mut ShadowPipeline],
        passes: &[PassId],
    ) -> Result<Vec<usize>, PassError> {
        let fitted: Vec<usize> = (0..pipelines.len())
            .filter(|&i| pipelines[i].fits_map_in(passes))
            .collect();
        if fitted.len() < 2 {
            return Ok(Vec::new());
        }
        self.0.time(enc, frame_index);
        enc.begin_pass(FIT_BATCH_PASS);
        let mut outcome = Ok(());
        for phase in FitPhase::ALL {
            for &i in &fitted {
                outcome = outcome.and_then(|()| pipelines[i].record_map_fit(enc, phase));
            }
            enc.barriers(&[phase.barrier_after()]);
        }
        enc.end_pass();
        enc.stop_timing();
        outcome.map(|()| fitted)
    }

    /// The GPU milliseconds of frame `frame_index`'s batch: `None` while its queries are not available,
    /// or if a later frame's batch took its slot (or it recorded none).
    pub fn milliseconds(&self, frame_index: u64) -> Result<Option<f64>, PassError> {
        self.0.milliseconds(frame_index)
    }
}

/// The batched lists of groups of lights, with a GPU timer per frame in flight.
pub struct ListBatch(BatchTimers);

impl ListBatch {
    /// A batch for `frames_in_flight` frames in flight (at least 1).
    pub fn new(device: &Device, frames_in_flight: u32) -> Result<Self, PassError> {
        Ok(Self(BatchTimers::new(
            device,
            frames_in_flight,
            LIST_GROUPS_TIMED,
        )?))
    }

    /// Records the lists of those `pipelines` whose map [`ShadowPipeline::lists_map_in`] `passes`,
    /// batched, when there are at least two and their maps take different scratch sets
    /// ([`ShadowPipeline::scratch_set`]); [`ListBatch::groups`] forms such groups. Returns the indices (in
    /// `pipelines`) of the lights whose lists it recorded, empty if none.
    pub fn record(
        &mut self,
        enc: &mut Encoder<'_>,
        frame_index: u64,
        pipelines: &mut [&mut ShadowPipeline],
        passes: &[PassId],
    ) -> Result<Vec<usize>, PassError> {
        let listed: Vec<usize> = (0..pipelines.len())
            .filter(|&i| pipelines[i].lists_map_in(passes))
            .collect();
        let mut sets: Vec<usize> = listed.iter().map(|&i| pipelines[i].scratch_set()).collect();
        sets.sort_unstable();
        sets.dedup();
        if listed.len() < 2 || sets.len() < listed.len() {
            return Ok(Vec::new());
        }
        let steps: Vec<_> = listed
            .iter()
            .map(|&i| pipelines[i].map_list_steps())
            .collect();
        let rounds = steps.iter().map(Vec::len).max().unwrap_or(0);
        self.0.time(enc, frame_index);
        enc.begin_pass(LIST_BATCH_PASS);
        enc.barriers(&PrimitiveMap::BEFORE_LISTS);
        let mut outcome = Ok(());
        for round in 0..rounds {
            let (mut transfers, mut storage) = (false, false);
            for (&i, steps) in listed.iter().zip(&steps) {
                let Some(&step) = steps.get(round) else {
                    continue;
                };
                match step.barrier_after() {
                    Barrier::Uav => storage = true,
                    _ => transfers = true,
                }
                outcome = outcome.and_then(|()| pipelines[i].record_map_list_step(enc, step));
            }
            if transfers {
                enc.barriers(&[Barrier::Global {
                    before: rhi::ResourceState::CopyDest,
                    after: rhi::ResourceState::UnorderedAccess,
                }]);
            }
            if storage {
                enc.barriers(&[Barrier::Uav]);
            }
        }
        enc.end_pass();
        enc.stop_timing();
        outcome.map(|()| listed)
    }

    /// Splits `sets` (the scratch set of each light's map, in recording order) into groups of consecutive
    /// lights whose maps take different sets: the ranges of lights a [`ListBatch::record`] may batch.
    pub fn groups(sets: &[usize]) -> Vec<std::ops::Range<usize>> {
        let mut groups = Vec::new();
        let mut start = 0;
        for i in 0..sets.len() {
            if sets[start..i].contains(&sets[i]) {
                groups.push(start..i);
                start = i;
            }
        }
        if start < sets.len() {
            groups.push(start..sets.len());
        }
        groups
    }

    /// The GPU milliseconds of frame `frame_index`'s batches, summed: `None` while its queries are not
    /// available, or if a later frame's batches took its slot (or it recorded none).
    pub fn milliseconds(&self, frame_index: u64) -> Result<Option<f64>, PassError> {
        self.0.milliseconds(frame_index)
    }
}

#[cfg(test)]
mod tests {
    use super::ListBatch;

    #[test]
    fn groups_hold_different_sets() {
        assert_eq!(ListBatch::groups(&[]), Vec::<std::ops::Range<usize>>::new());
        assert_eq!(ListBatch::groups(&[0, 1, 2, 3, 0, 1]), vec![0..4, 4..6]);
        assert_eq!(ListBatch::groups(&[2, 2, 2]), vec![0..1, 1..2, 2..3]);
        assert_eq!(ListBatch::groups(&[0, 1, 0, 2, 3]), vec![0..2, 2..5]);
    }
}

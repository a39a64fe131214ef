//! Several lights' primitive-map fits recorded as one batch: each phase of every light, then one barrier,
//! so that the lights' small dispatches run side by side instead of one light's waiting for the last.
//! Timed as one pass, in a GPU timer of the batch's own per frame in flight.
//!
//! Reads: depth, normal, each light's constants. Writes: each light's map state (its fit).

use super::ShadowPipeline;
use crate::frame_plan::PassId;
use crate::primitive_map::FitPhase;
use crate::PassError;
use rhi::{Device, Encoder, GpuTimer};

/// The name of the batch's timed pass.
pub const FIT_BATCH_PASS: &str = "primitive map: fit (batched)";

/// The batched fits of the lights recorded into one call, with a GPU timer per frame in flight.
pub struct FitBatch {
    /// Per slot (frame index modulo the frames in flight): the frame that last recorded a batch there, and
    /// the timer.
    slots: Vec<(Option<u64>, GpuTimer)>,
}

impl FitBatch {
    /// A batch for `frames_in_flight` frames in flight (at least 1).
    pub fn new(device: &Device, frames_in_flight: u32) -> Result<Self, PassError> {
        let slots = (0..frames_in_flight.max(1))
            .map(|_| Ok((None, device.create_timer(1)?)))
            .collect::<Result<_, PassError>>()?;
        Ok(Self { slots })
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
        let slot = (frame_index % self.slots.len() as u64) as usize;
        let (frame, timer) = &mut self.slots[slot];
        *frame = Some(frame_index);
        enc.attach_timer(timer);
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
        let slot = (frame_index % self.slots.len() as u64) as usize;
        match &self.slots[slot] {
            (Some(frame), timer) if *frame == frame_index => {
                Ok(timer.try_resolve()?.and_then(|t| t.first().map(|t| t.ms)))
            }
            _ => Ok(None),
        }
    }
}

//! Recording a frame's passes, in linear order, with the barriers between them.

use super::{FrameInputs, FrameState, RetiredMap, ShadowPipeline};
use crate::frame_plan::{PassId, PassStatus, ResourceSet};
use crate::gpu_types::ShadowMapPush;
use crate::primitive_map::{FitPhase, ListStep, PrimitiveMap};
use crate::screen_pass::visibility_image;
use crate::PassError;
use rhi::{Barrier, Device, Encoder, Image, ResourceState as S};

impl ShadowPipeline {
    /// The passes the current frame runs and has not recorded yet.
    pub fn passes_to_record(&self) -> Vec<PassId> {
        self.frame.as_ref().map_or_else(Vec::new, |f| {
            self.statuses[f.next..]
                .iter()
                .filter(|(_, s)| *s == PassStatus::Ran)
                .map(|&(p, _)| p)
                .collect()
        })
    }

    /// Records `passes` of the frame begun by [`ShadowPipeline::begin_frame`] (those the frame skips
    /// record nothing). Calls go forward through the linear order: every pass requested must come after
    /// those of earlier calls of the frame, and every pass the frame runs up to the last one requested
    /// must be requested. Calls may use different command buffers submitted in recording order; the
    /// first one resets the GPU timer, later ones (even with no pass) go on timing into it.
    ///
    /// States: depth and normal must be in `ShaderResource` state for the screen-space passes (ray trace,
    /// shadow-map test, PCSS); every image a pass writes is left in `UnorderedAccess` state (the shadow
    /// map in `ShaderResource`), [`ShadowPipeline::output`] included.
    ///
    /// Contract: the frames-in-flight rule of [`ShadowPipeline::begin_frame_at`] (constants go into the
    /// command buffer; read-backs have one slot per frame in flight), and every recording is submitted:
    /// passes skipped as up to date reuse what the recording that last ran them wrote.
    pub fn record_passes(
        &mut self,
        enc: &mut Encoder<'_>,
        passes: &[PassId],
    ) -> Result<(), PassError> {
        self.with_frame(|this, frame| this.record_forward(enc, frame, passes))
    }

    /// Runs `f` on the frame begun by [`ShadowPipeline::begin_frame`] (taken out of the pipeline for the
    /// call); fails if none was.
    fn with_frame<T>(
        &mut self,
        f: impl FnOnce(&mut Self, &mut FrameState) -> Result<T, PassError>,
    ) -> Result<T, PassError> {
        let Some(mut frame) = self.frame.take() else {
            return Err(PassError::InvalidConfig(
                "no frame: call begin_frame first".into(),
            ));
        };
        let outcome = f(self, &mut frame);
        self.frame = Some(frame);
        outcome
    }

    /// Records every pass of a frame: [`ShadowPipeline::begin_frame`], then
    /// [`ShadowPipeline::record_passes`] of the whole linear order.
    pub fn record(&mut self, enc: &mut Encoder<'_>, inputs: &FrameInputs) -> Result<(), PassError> {
        self.begin_frame(inputs)?;
        self.record_passes(enc, PassId::ALL)
    }

    /// Makes the allocations the frame's recording of `passes` needs (the primitive map's lists growing
    /// to what earlier frames needed), so that [`ShadowPipeline::record_passes`] allocates nothing: a
    /// host that records several pipelines into one command buffer can fail before any of them records.
    pub fn prepare_record(&mut self, device: &Device, passes: &[PassId]) -> Result<(), PassError> {
        let index = match &self.frame {
            Some(frame) => frame.index,
            None => {
                return Err(PassError::InvalidConfig(
                    "no frame: call begin_frame first".into(),
                ))
            }
        };
        if passes.contains(&PassId::PrimitiveMap) && self.plan.runs(PassId::PrimitiveMap) {
            self.grow_map(device, index)?;
        }
        self.own_visibility_if_split(device, passes, index)
    }

    /// Times the next passes recorded into `enc` in the current frame's GPU timer, as part of this
    /// pipeline's frame report (work a host records for it after its passes, such as combining a light's
    /// frusta). Does nothing before a frame was begun.
    pub fn continue_timing(&self, enc: &mut Encoder<'_>) {
        if let Some(frame) = &self.frame {
            enc.continue_timer(&self.slots[frame.slot].timer);
        }
    }

    /// Whether a recording of `passes` (accepted by [`ShadowPipeline::check_record`]) builds the primitive
    /// map and its fit may be recorded ahead ([`ShadowPipeline::record_map_fit`]): the pass runs this frame
    /// and is neither recorded nor fitted yet.
    pub fn fits_map_in(&self, passes: &[PassId]) -> bool {
        self.builds_map_in(passes, |f| {
            f.next <= PassId::PrimitiveMap as usize && !f.map_fitted
        })
    }

    /// Whether a recording of `passes` builds the primitive map (the pass runs this frame) and the
    /// frame's state is `ready` for a part of it recorded ahead.
    fn builds_map_in(&self, passes: &[PassId], ready: impl Fn(&FrameState) -> bool) -> bool {
        let map = PassId::PrimitiveMap;
        self.map.is_some()
            && passes.contains(&map)
            && self.statuses[map as usize].1 == PassStatus::Ran
            && self.frame.as_ref().is_some_and(ready)
    }

    /// Records `phase` of the primitive map's fit ahead of the primitive-map pass, which then records the
    /// lists alone; for a light whose map [`ShadowPipeline::fits_map_in`] the call's passes. Every phase
    /// touches only this light's own buffers (and reads depth and normal, in `ShaderResource` state), so
    /// several lights' phases may be recorded together, each phase of every light followed by one
    /// [`FitPhase::barrier_after`] ([`super::FitBatch`] does).
    pub fn record_map_fit(
        &mut self,
        enc: &mut Encoder<'_>,
        phase: FitPhase,
    ) -> Result<(), PassError> {
        self.with_frame(|this, frame| this.record_map_fit_in(enc, frame, phase))
    }

    fn record_map_fit_in(
        &mut self,
        enc: &mut Encoder<'_>,
        frame: &mut FrameState,
        phase: FitPhase,
    ) -> Result<(), PassError> {
        if phase == FitPhase::Reset {
            if frame.map_fitted || frame.next > PassId::PrimitiveMap as usize {
                return Err(PassError::InvalidConfig(
                    "the primitive map's fit is already recorded this frame".into(),
                ));
            }
            self.grow_map(enc.device(), frame.index)?;
            frame.map_fitted = true;
        } else if !frame.map_fitted {
            return Err(PassError::InvalidConfig(
                "the primitive map's fit must begin with its reset".into(),
            ));
        }
        let c = &frame.constants;
        let map = self
            .map
            .as_mut()
            .ok_or_else(|| PassError::InvalidConfig("the plan has no primitive map".into()))?;
        map.record_fit_phase(enc, phase, &c.ray, &c.map, c.light.frusta())
    }

    /// The set of the geometry's build scratch this pipeline's map takes: maps over different sets may be
    /// built side by side ([`super::ListBatch`]).
    pub fn scratch_set(&self) -> usize {
        self.scratch_set
    }

    /// Whether a recording of `passes` builds the primitive map's lists and they may be recorded ahead
    /// ([`ShadowPipeline::record_map_list_step`]): the map's fit was recorded ahead
    /// ([`ShadowPipeline::record_map_fit`]), every pass before the map's that runs is recorded, and the
    /// lists are not yet.
    pub fn lists_map_in(&self, passes: &[PassId]) -> bool {
        let map = PassId::PrimitiveMap as usize;
        self.builds_map_in(passes, |f| {
            f.map_fitted
                && !f.map_listed
                && f.next <= map
                && self.statuses[f.next..map]
                    .iter()
                    .all(|&(_, s)| s != PassStatus::Ran)
        })
    }

    /// The steps of the lists' build of a map that [`ShadowPipeline::lists_map_in`] the call's passes.
    pub fn map_list_steps(&self) -> Vec<ListStep> {
        self.map
            .as_ref()
            .map_or_else(Vec::new, PrimitiveMap::list_steps)
    }

    /// Records `step` of the primitive map's lists ahead of its pass, which then records nothing. Every
    /// step touches the map's own buffers and its scratch set ([`ShadowPipeline::scratch_set`]), so the
    /// steps of lights over different sets may be interleaved, each round of steps followed by their
    /// [`ListStep::barrier_after`] and the first preceded by [`PrimitiveMap::BEFORE_LISTS`]
    /// ([`super::ListBatch`] does). The last step marks the lists recorded.
    pub fn record_map_list_step(
        &mut self,
        enc: &mut Encoder<'_>,
        step: ListStep,
    ) -> Result<(), PassError> {
        self.with_frame(|this, frame| {
            if !frame.map_fitted || frame.map_listed {
                return Err(PassError::InvalidConfig(
                    "the primitive map's lists are recorded ahead only once, after its fit".into(),
                ));
            }
            let map = this
                .map
                .as_mut()
                .ok_or_else(|| PassError::InvalidConfig("the plan has no primitive map".into()))?;
            map.record_list_step(enc, step)?;
            frame.map_listed = step == ListStep::Fill;
            Ok(())
        })
    }

    /// Whether [`ShadowPipeline::record_passes`] would accept `passes` now (without recording anything).
    pub fn check_record(&self, passes: &[PassId]) -> Result<(), PassError> {
        let frame = self
            .frame
            .as_ref()
            .ok_or_else(|| PassError::InvalidConfig("no frame: call begin_frame first".into()))?;
        self.check_forward(frame, passes)
    }

    /// The order checks of a recording call: passes after those already recorded, none that runs left out.
    fn check_forward(&self, frame: &FrameState, passes: &[PassId]) -> Result<(), PassError> {
        if let Some(&first) = passes.iter().min().filter(|&&p| (p as usize) < frame.next) {
            return Err(PassError::InvalidConfig(format!(
                "pass '{}' comes before a pass already recorded this frame: record passes in linear order",
                first.name()
            )));
        }
        let runs = |p: PassId| self.statuses[p as usize].1 == PassStatus::Ran;
        if let Some(last) = passes.iter().max() {
            if let Some(missing) = PassId::ALL[frame.next..=*last as usize]
                .iter()
                .find(|&&p| runs(p) && !passes.contains(&p))
            {
                return Err(PassError::InvalidConfig(format!(
                    "pass '{}' runs this frame: record it (it comes before '{}')",
                    missing.name(),
                    last.name()
                )));
            }
        }
        Ok(())
    }

    fn record_forward(
        &mut self,
        enc: &mut Encoder<'_>,
        frame: &mut FrameState,
        passes: &[PassId],
    ) -> Result<(), PassError> {
        self.check_forward(frame, passes)?;
        let last = passes.iter().max().copied();
        let statuses = self.statuses.clone();
        let runs = |p: PassId| statuses[p as usize].1 == PassStatus::Ran;
        self.own_visibility_if_split(enc.device(), passes, frame.index)?;
        // Checked: from here on the call records.
        let timer = &self.slots[frame.slot].timer;
        if frame.timer_started {
            enc.continue_timer(timer);
        } else {
            // The frame's first recording: separate it from the earlier frames in flight that used the same
            // resources (write-after-read and write-after-write across frames).
            enc.barriers(&[Barrier::Full]);
            enc.attach_timer(timer);
            frame.timer_started = true;
        }
        let Some(last) = last else {
            return self.mark_if_finished(enc, frame);
        };
        for &pass in &PassId::ALL[frame.next..=last as usize] {
            if runs(pass) {
                self.record_pass(enc, pass, frame)?;
                self.valid = self.valid.union(self.plan.writes(pass));
                if matches!(pass, PassId::ShadowMap | PassId::PrimitiveMap) {
                    self.maps_light = Some(frame.light);
                }
            }
            frame.next = pass as usize + 1;
        }
        self.flush_uav(enc);
        self.mark_if_finished(enc, frame)
    }

    /// Once no pass of the frame is left to record, has the GPU mark the slot with the frame after
    /// everything recorded before, so a report can tell whether the frame has completed without a fence.
    fn mark_if_finished(
        &mut self,
        enc: &mut Encoder<'_>,
        frame: &mut FrameState,
    ) -> Result<(), PassError> {
        let finished = self.statuses[frame.next..]
            .iter()
            .all(|&(_, s)| s != PassStatus::Ran);
        if !finished || frame.marked {
            return Ok(());
        }
        frame.marked = true;
        let marker = (frame.index + 1).to_le_bytes();
        enc.barriers(&[Barrier::Full]);
        enc.update_buffer(&self.slots[frame.slot].completion, 0, &marker)?;
        enc.barriers(&[Barrier::Global {
            before: S::CopyDest,
            after: S::HostRead,
        }]);
        Ok(())
    }

    /// Makes the storage writes of the passes recorded since the last UAV barrier visible.
    fn flush_uav(&mut self, enc: &mut Encoder<'_>) {
        if self.pending_uav.take().is_some() {
            enc.barriers(&[Barrier::Uav]);
        }
    }

    /// Discards the screen-space outputs of `pass` and makes them UAVs.
    fn outputs_to_uav(&self, enc: &mut Encoder<'_>, pass: PassId) {
        let to_uav: Vec<Barrier<'_>> = self
            .plan
            .writes(pass)
            .iter()
            .filter_map(|r| self.image(r))
            .map(|image| Barrier::Image {
                image,
                before: S::Undefined,
                after: S::UnorderedAccess,
            })
            .collect();
        enc.barriers(&to_uav);
    }

    /// Records one pass with the barriers around it. A UAV barrier precedes a pass that reads what
    /// earlier passes wrote since the last one; the screen-space passes that do not read each other's
    /// outputs (shadow-map test, PCSS, FXAA, lerp factor) share one after them.
    fn record_pass(
        &mut self,
        enc: &mut Encoder<'_>,
        pass: PassId,
        frame: &FrameState,
    ) -> Result<(), PassError> {
        let c = &frame.constants;
        let independent = matches!(
            pass,
            PassId::ShadowMapTest | PassId::Pcss | PassId::Fxaa | PassId::LerpFactor
        );
        let reads_pending = self
            .pending_uav
            .is_some_and(|written| self.plan.reads(pass).intersects(written));
        if !independent || reads_pending {
            self.flush_uav(enc);
        }
        let tris = self.geometry().triangle_count();
        match pass {
            PassId::PrimBuffer => {
                if frame.records_prims {
                    self.shared.record(enc, frame.index)?;
                }
            }
            PassId::ShadowMap => {
                if let Some(sm) = &self.shadow_map {
                    let push = ShadowMapPush {
                        light_view_proj: c.light.view_proj,
                    };
                    sm.record(enc, &push, tris)?;
                }
            }
            // Recorded ahead, batched with other lights' lists, and followed by the batch's barrier.
            PassId::PrimitiveMap if frame.map_listed => return Ok(()),
            PassId::PrimitiveMap => {
                self.grow_map(enc.device(), frame.index)?;
                if let Some(map) = self.map.as_mut() {
                    if frame.map_fitted {
                        map.record_lists(enc)?;
                    } else {
                        map.record(enc, &c.ray, &c.map, c.light.frusta())?;
                    }
                }
            }
            PassId::Occupancy => {
                if let Some(map) = &self.map {
                    map.record_occupancy(enc)?;
                }
            }
            PassId::RayTrace => {
                if let Some(map) = self.map.as_mut() {
                    map.record_pixel_texels(enc)?;
                }
                self.outputs_to_uav(enc, pass);
                if let Some(ray) = self.ray.as_mut() {
                    ray.record(enc, &c.ray, c.area.as_deref())?;
                }
                // The map's state with the build's statistics and the trace's walks, for the report.
                if let Some(map) = &self.map {
                    let slot = &mut self.slots[frame.slot];
                    map.record_state_readback(enc, &slot.stats_readback)?;
                    slot.map_state_recorded = true;
                }
            }
            PassId::ShadowMapTest => {
                self.outputs_to_uav(enc, pass);
                if let Some(p) = self.shadow_map_test.as_mut() {
                    p.record(enc, &c.pcss)?;
                }
            }
            PassId::Pcss => {
                self.outputs_to_uav(enc, pass);
                if let Some(p) = self.pcss.as_mut() {
                    p.record(enc, &c.pcss)?;
                }
            }
            PassId::Fxaa => {
                self.outputs_to_uav(enc, pass);
                if let Some(f) = &self.fxaa {
                    f.record(enc)?;
                }
            }
            PassId::LerpFactor => {
                self.outputs_to_uav(enc, pass);
                if let Some(l) = &self.lerp {
                    l.record(enc, &self.config.hybrid)?;
                }
            }
            PassId::Blend => {
                self.outputs_to_uav(enc, pass);
                if let Some(b) = &self.blend {
                    b.record(enc, &self.config.hybrid)?;
                }
            }
            PassId::FillLit => {
                if let Some(lit) = &self.lit {
                    record_fill_lit(enc, lit);
                }
            }
        }
        self.pending_uav = Some(
            self.pending_uav
                .unwrap_or(ResourceSet::EMPTY)
                .union(self.plan.writes(pass)),
        );
        Ok(())
    }

    /// Fits the primitive map's entries (grown or shrunk, [`PrimitiveMap::fit_entries`]) and grows its
    /// (triangle, face) pairs to what the newest completed build needed, and rebinds the ray trace to the entries; the replaced objects are held until the frames
    /// before `frame` completed.
    fn grow_map(&mut self, device: &Device, frame: u64) -> Result<(), PassError> {
        let Some(map) = self.map.as_mut() else {
            return Ok(());
        };
        let mut retired = Vec::new();
        let pool = self.shared.map_scratch(self.scratch_set);
        if let Some((entries, bindings)) =
            map.fit_entries(device, pool, self.shared.prims(), self.needed_entries)?
        {
            let ray_groups = match self.ray.as_mut() {
                Some(ray) => ray.rebind_entries(device, map)?,
                None => Vec::new(),
            };
            retired.push(RetiredMap::Entries {
                _entries: entries,
                _bindings: Box::new(bindings),
                _ray_groups: ray_groups,
            });
        }
        if let Some(bound) = map.grow_pairs(device, pool, self.shared.prims(), self.needed_pairs)? {
            retired.push(RetiredMap::Pairs {
                _bindings: Box::new(bound),
            });
        }
        if let Some(last_user) = frame.checked_sub(1) {
            for r in retired {
                self.retired.retire(last_user, r);
            }
        }
        Ok(())
    }

    /// Gives the ray trace an image of the light's own, in place of the visibility the lights' FXAA share,
    /// when a recording call of `passes` in frame `frame` holds the ray trace without the FXAA (another
    /// light's ray trace could then overwrite the shared image before this light's FXAA reads it). The
    /// replaced view and bind groups are held until the frames before `frame` completed.
    fn own_visibility_if_split(
        &mut self,
        device: &Device,
        passes: &[PassId],
        frame: u64,
    ) -> Result<(), PassError> {
        let split = passes.contains(&PassId::RayTrace) && !passes.contains(&PassId::Fxaa);
        let (true, true, Some(ray), Some(fxaa)) =
            (self.rt_shared, split, self.ray.as_mut(), self.fxaa.as_mut())
        else {
            return Ok(());
        };
        let (width, height) = (ray.visibility.width(), ray.visibility.height());
        // Everything that can fail comes before the FXAA takes its new group: a failure changes nothing.
        let own = visibility_image(device, "rt visibility", width, height)?;
        let fxaa_group = fxaa.rebound_input(device, &own)?;
        let (image, mut groups) = ray.replace_visibility(device, own)?;
        groups.push(fxaa.use_group(fxaa_group));
        self.rt_shared = false;
        let retired = RetiredMap::SharedVisibility {
            _image: image,
            _groups: groups,
        };
        if let Some(last_user) = frame.checked_sub(1) {
            self.retired.retire(last_user, retired);
        }
        Ok(())
    }
}

/// Fills the lit image (mode none) with 1 and leaves it in `UnorderedAccess` state.
fn record_fill_lit(enc: &mut Encoder<'_>, lit: &Image) {
    enc.begin_pass(PassId::FillLit.name());
    enc.barriers(&[Barrier::Image {
        image: lit,
        before: S::Undefined,
        after: S::CopyDest,
    }]);
    enc.clear_uint(lit, 1.0f32.to_bits());
    enc.barriers(&[Barrier::Image {
        image: lit,
        before: S::CopyDest,
        after: S::UnorderedAccess,
    }]);
    enc.end_pass();
}

//! Recording into the engine's command buffers: each frame's schedule of the lights' frusta (what is
//! rebuilt, what is recorded), every light's passes of a frame (whole or pass by pass), the copy of each
//! light's visibility into the engine's output, and resource read-backs.

use crate::context::schedule::{schedule, FrameSchedule, LightSchedule};
use crate::context::{Built, Context, FrameProgress, OpenFrame, Retired};
use crate::convert::{
    frame_bounds, frame_inputs, pass_from_index, resource_id, FrameLight, LightShape,
};
use crate::error::{invalid, ApiError, ApiResult};
use crate::geometry::deformed_meshes;
use crate::types::*;
use passes::retire::completed_before;
use passes::{MeshVertices, PassError, PassId, ResourceId};
use rhi::{Barrier, BufferUsage, Encoder, Format, Image, ResourceState as S};

/// Pass-mask bits of the passes that read the engine's depth and normal images (the primitive map fits
/// itself to the receivers).
pub(crate) const DEPTH_NORMAL_READERS: u32 = 1 << HrtsPass::PrimitiveMap as u32
    | 1 << HrtsPass::RayTrace as u32
    | 1 << HrtsPass::ShadowMapTest as u32
    | 1 << HrtsPass::Pcss as u32;

impl Context {
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

    /// Which frusta of each light may change a pixel in view this frame: [`schedule`] with the context's
    /// configurations.
    pub(crate) fn schedule(
        &self,
        lights: &[FrameLight],
        bounds: Option<[glam::DVec3; 2]>,
    ) -> Vec<LightSchedule> {
        schedule(&self.lights, lights, bounds)
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
            self.retire(Retired::light_passes(replaced));
            self.progress = FrameProgress::default();
        }
    }
}

impl Context {
    pub(crate) fn record_passes(&mut self, f: &HrtsFrame, mask: u32) -> ApiResult<()> {
        if f.command_buffer == 0 {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                "command_buffer is NULL",
            ));
        }
        if mask == 0 || mask & !HRTS_PASS_MASK_ALL != 0 {
            return Err(invalid(format!(
                "pass mask 0x{mask:x} must be a non-empty set of HRTS_PASS_MASK_ALL (0x{HRTS_PASS_MASK_ALL:x}) bits"
            )));
        }
        if f.frame_index == u64::MAX {
            return Err(invalid("frame_index UINT64_MAX is reserved"));
        }
        let lowest = mask.trailing_zeros();
        let highest = 31 - mask.leading_zeros();
        // A call of the frame being recorded that goes on after its last pass continues it, with the
        // meshes its first call deformed; any other call begins a frame and alone reads `deformed` (the
        // engine may free the array once that call returned).
        let continued = match &self.progress.open {
            Some(open) if open.index == f.frame_index && lowest > open.last_pass => Some(open),
            Some(open) if open.index == f.frame_index => {
                return Err(invalid(format!(
                    "frame {} is being recorded up to pass {}: a call of the same frame must go on after it",
                    open.index, open.last_pass
                )))
            }
            _ => None,
        };
        let deformed = match continued {
            Some(_) => Vec::new(),
            None => deformed_meshes(f, self.geometry.as_ref())?,
        };
        let deforms = continued.map_or(!deformed.is_empty(), |open| open.deforms);
        let bounds = self.scene_bounds(frame_bounds(f)?, deforms);
        let inputs = frame_inputs(f, bounds)?;
        if inputs.len() != self.lights.len() {
            return Err(invalid(format!(
                "light_count {} differs from the {} lights configured",
                inputs.len(),
                self.lights.len()
            )));
        }
        let inputs: Vec<FrameLight> = inputs
            .into_iter()
            .zip(&self.lights)
            .map(|(light, config)| light.shadowed_as(config))
            .collect();
        if continued.is_some_and(|open| open.inputs != inputs) {
            return Err(invalid(
                "the camera and lights must stay the same across the calls of one frame",
            ));
        }
        let continues = continued.is_some();
        let mut used_layouts = Vec::new();
        if mask & DEPTH_NORMAL_READERS != 0 {
            used_layouts.push(("depth_layout", f.depth_layout));
            if self.targets.is_none_or(|t| t.normal.is_some()) {
                used_layouts.push(("normal_layout", f.normal_layout));
            }
        }
        let copy_output = mask & 1 << HrtsPass::OutputCopy as u32 != 0;
        if copy_output {
            used_layouts.push(("output_layout_after", f.output_layout_after));
        }
        for (what, layout) in used_layouts {
            if layout <= 0 {
                return Err(invalid(format!(
                    "{what} {layout} is not a usable VkImageLayout"
                )));
            }
        }
        if let Some(t) = self
            .targets
            .filter(|t| t.output_layers < self.lights.len() as u32)
        {
            return Err(invalid(format!(
                "the output image has {} layers for {} lights",
                t.output_layers,
                self.lights.len()
            )));
        }
        if !continues {
            self.begin_frame(f.frame_index)?;
        }
        self.set_frusta(&inputs.iter().map(FrameLight::shape).collect::<Vec<_>>());
        // A frame's later calls (same camera and lights) record the frusta its first call chose.
        let kept = self
            .schedules
            .back()
            .filter(|s| continues && s.index == f.frame_index);
        let mut schedule = match kept {
            Some(_) => None,
            None => Some(self.schedule(&inputs, bounds)),
        };
        let recorded: Vec<Vec<bool>> = schedule
            .as_deref()
            .or(kept.map(|s| s.lights.as_slice()))
            .map(|lights| lights.iter().map(|l| l.recorded.clone()).collect())
            .unwrap_or_default();
        self.ensure_built()?;
        if self.fit_batch.is_none() {
            self.fit_batch = Some(passes::FitBatch::new(&self.device, self.frames_in_flight)?);
        }
        if self.list_batch.is_none() {
            self.list_batch = Some(passes::ListBatch::new(&self.device, self.frames_in_flight)?);
        }
        let frame_index = f.frame_index;
        let (device, built) = match self.built.as_mut() {
            Some(b) => (&self.device, b),
            None => return Err(ApiError::new(HrtsResult::ErrorInternal, "passes not built")),
        };
        if !continues {
            // The frame's vertex buffers are bound before any light claims the prim buffer's build (the
            // meshes they deform are rebuilt), and before anything is recorded.
            let vertices = deformed
                .iter()
                .map(|v| {
                    // SAFETY: the engine guarantees a live buffer of the stated size with storage usage,
                    // alive until the frame completed (documented contract).
                    let buffer = unsafe {
                        device.external_buffer(
                            v.vertex_buffer,
                            v.vertex_buffer_size,
                            BufferUsage::STORAGE,
                        )?
                    };
                    Ok(MeshVertices {
                        mesh: v.mesh as usize,
                        buffer,
                        offset: v.vertex_offset,
                    })
                })
                .collect::<ApiResult<Vec<_>>>()?;
            let completed = completed_before(frame_index, self.frames_in_flight);
            built
                .shared
                .set_frame_vertices(device, frame_index, completed, vertices)?;
            self.progress.open = None;
            self.last_frame = Some(frame_index);
            for ((passes, light), recorded) in built
                .lights
                .iter_mut()
                .flatten()
                .zip(&inputs)
                .zip(&recorded)
            {
                for ((pipeline, frustum_inputs), _) in passes
                    .frusta
                    .iter_mut()
                    .zip(&light.frusta)
                    .zip(recorded)
                    .filter(|(_, &r)| r)
                {
                    pipeline.begin_frame_at(frustum_inputs, frame_index)?;
                }
            }
        }
        let passes: Vec<PassId> = (0..HRTS_PASS_COUNT as u32)
            .filter(|i| mask & 1 << i != 0)
            .filter_map(pass_from_index)
            .collect();
        if copy_output {
            for (i, pipeline) in built.scheduled(&recorded) {
                if let Some(missing) = pipeline
                    .passes_to_record()
                    .into_iter()
                    .find(|p| !passes.contains(p))
                {
                    return Err(ApiError::new(
                        HrtsResult::ErrorInvalidState,
                        format!(
                            "pass '{}' of light {i} runs this frame and has not been recorded: record it before (or with) the output copy",
                            missing.name()
                        ),
                    ));
                }
            }
        }
        // Every light accepts the passes before anything is recorded: a failed call records nothing.
        for (i, pipeline) in built.scheduled(&recorded) {
            pipeline.check_record(&passes).map_err(|e| {
                ApiError::new(HrtsResult::ErrorInvalidState, format!("light {i}: {e}"))
            })?;
        }
        // Every light allocates what its recording needs before any records: an allocation failure leaves
        // the command buffer untouched.
        for (i, pipeline) in built.scheduled_mut(&recorded) {
            pipeline.prepare_record(device, &passes).map_err(|e| {
                let e = ApiError::from(e);
                ApiError {
                    message: format!("light {i}: {}", e.message),
                    ..e
                }
            })?;
        }
        // SAFETY: the engine guarantees the command buffer is recording, outside a render pass, on this
        // device and used by no other thread during the call (documented contract).
        let mut enc = unsafe { Encoder::from_raw_handle(device, f.command_buffer) };
        let reads_depth = mask & DEPTH_NORMAL_READERS != 0;
        if reads_depth {
            engine_inputs(&mut enc, built, f, true);
        }
        // The lights' fits first, batched (each phase of every light, then one barrier), when several
        // build their maps in this call: their passes then record the lists alone (or nothing, where a
        // list batch below records them).
        let mut frame_lights = match schedule.as_mut() {
            Some(lights) => Some(lights),
            None => self.schedules.back_mut().map(|s| &mut s.lights),
        };
        let batching = reads_depth && passes.contains(&PassId::PrimitiveMap);
        let mut outcome = Ok(());
        if let Some(batch) = self.fit_batch.as_mut().filter(|_| batching) {
            let (lights, mut pipelines): (Vec<usize>, Vec<&mut passes::ShadowPipeline>) =
                built.scheduled_mut(&recorded).unzip();
            match batch.record(&mut enc, frame_index, &mut pipelines, &passes) {
                Ok(fitted) => {
                    count_batched(&mut frame_lights, &lights, &fitted, |l| &mut l.fits_batched)
                }
                Err(e) => outcome = Err(e),
            }
        }
        match self.list_batch.as_mut().filter(|_| batching) {
            // Every light's passes before its map, then groups of lights whose maps take different scratch
            // sets: the group's lists batched (each round of steps, then one barrier), then each light's
            // passes from its map on.
            Some(batch) => {
                let (lights, mut pipelines): (Vec<usize>, Vec<&mut passes::ShadowPipeline>) =
                    built.scheduled_mut(&recorded).unzip();
                let (before, after): (Vec<PassId>, Vec<PassId>) = passes
                    .iter()
                    .partition(|&&p| (p as usize) < PassId::PrimitiveMap as usize);
                for pipeline in pipelines.iter_mut() {
                    outcome = outcome.and_then(|()| pipeline.record_passes(&mut enc, &before));
                }
                let sets: Vec<usize> = pipelines.iter().map(|p| p.scratch_set()).collect();
                for group in passes::ListBatch::groups(&sets) {
                    if outcome.is_err() {
                        break;
                    }
                    let members = &mut pipelines[group.clone()];
                    match batch.record(&mut enc, frame_index, members, &after) {
                        Ok(listed) => {
                            let listed: Vec<usize> =
                                listed.iter().map(|i| group.start + i).collect();
                            count_batched(&mut frame_lights, &lights, &listed, |l| {
                                &mut l.lists_batched
                            });
                        }
                        Err(e) => outcome = Err(e),
                    }
                    for pipeline in pipelines[group].iter_mut() {
                        outcome = outcome.and_then(|()| pipeline.record_passes(&mut enc, &after));
                    }
                }
            }
            None => {
                for (_, pipeline) in built.scheduled_mut(&recorded) {
                    outcome = outcome.and_then(|()| pipeline.record_passes(&mut enc, &passes));
                }
            }
        }
        if reads_depth {
            engine_inputs(&mut enc, built, f, false);
        }
        outcome.map_err(|e| match e {
            PassError::InvalidConfig(m) => ApiError::new(HrtsResult::ErrorInvalidState, m),
            other => other.into(),
        })?;
        if copy_output {
            record_output_copy(&mut enc, built, f, &recorded)?;
            self.progress = FrameProgress {
                open: None,
                completed: Some(frame_index),
            };
        } else {
            self.progress.open = Some(OpenFrame {
                index: frame_index,
                inputs,
                last_pass: highest,
                deforms,
            });
        }
        if let Some(schedule) = schedule.filter(|_| !continues) {
            self.keep_schedule(frame_index, schedule);
        }
        Ok(())
    }

    pub(crate) fn record_readback(&mut self, r: &HrtsResourceReadback) -> ApiResult<()> {
        if r.command_buffer == 0 || r.buffer == 0 {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                "command_buffer and buffer must be non-NULL",
            ));
        }
        let id = resource_id(r.resource)?;
        let light = self.finished_frame()?.light(r.light)?;
        let pipeline = light.single(r.light)?;
        if light.direct && id == pipeline.plan().final_output() {
            return Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                format!(
                    "{} of light {} is written into its layer of the output image directly: read the output (or add it to extra_outputs for a copy of the plugin's own)",
                    id.name(),
                    r.light
                ),
            ));
        }
        if pipeline.is_shared(id) {
            return Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                format!(
                    "{} of light {} is held in an image the lights' FXAA passes share (only the light's FXAA reads it): add it to extra_outputs to read it back",
                    id.name(),
                    r.light
                ),
            ));
        }
        let (image, list) = (pipeline.image(id), pipeline.buffer(id));
        let bytes = match (image, list) {
            (Some(image), _) => image.byte_size(),
            (None, Some(list)) => list.size(),
            (None, None) => {
                return Err(ApiError::new(
                    HrtsResult::ErrorInvalidState,
                    format!(
                        "{} is not allocated by light {}'s configuration: add it to extra_outputs",
                        id.name(),
                        r.light
                    ),
                ))
            }
        };
        let fits = r
            .offset
            .checked_add(bytes)
            .is_some_and(|end| end <= r.buffer_size);
        if !fits || !r.offset.is_multiple_of(4) {
            return Err(invalid(format!(
                "{} needs {} bytes at a multiple-of-4 offset: offset {} in a buffer of {} bytes does not do",
                id.name(),
                bytes,
                r.offset,
                r.buffer_size
            )));
        }
        // SAFETY: the engine guarantees a live buffer of `buffer_size` bytes with TRANSFER_DST usage.
        let buffer = unsafe {
            self.device
                .external_buffer(r.buffer, r.buffer_size, BufferUsage::COPY_DST)?
        };
        let state = if id == ResourceId::ShadowMap {
            S::ShaderResource
        } else {
            S::UnorderedAccess
        };
        // SAFETY: as for `record_passes`.
        let mut enc = unsafe { Encoder::from_raw_handle(&self.device, r.command_buffer) };
        match (image, list) {
            (Some(image), _) => {
                enc.barriers(&[Barrier::Image {
                    image,
                    before: state,
                    after: S::CopySource,
                }]);
                enc.copy_image_to_buffer_at(image, &buffer, r.offset)?;
                enc.barriers(&[Barrier::Image {
                    image,
                    before: S::CopySource,
                    after: state,
                }]);
            }
            (None, Some(list)) => {
                enc.barriers(&[Barrier::Global {
                    before: S::UnorderedAccess,
                    after: S::CopySource,
                }]);
                enc.copy_buffer_at(list, &buffer, r.offset)?;
            }
            (None, None) => {}
        }
        enc.barriers(&[
            Barrier::Global {
                before: S::CopyDest,
                after: S::Engine(0),
            },
            Barrier::Global {
                before: S::CopyDest,
                after: S::HostRead,
            },
        ]);
        self.readback_frame = self.last_frame.map(|f| f + 1);
        Ok(())
    }
}

/// Transitions the engine's depth and normal images from their layouts to `ShaderResource` (`to_shader`)
/// or back.
fn engine_inputs(enc: &mut Encoder<'_>, b: &Built, f: &HrtsFrame, to_shader: bool) {
    let transition = |image, layout| {
        let (before, after) = if to_shader {
            (S::Engine(layout), S::ShaderResource)
        } else {
            (S::ShaderResource, S::Engine(layout))
        };
        Barrier::Image {
            image,
            before,
            after,
        }
    };
    let normal = if b.engine_normal {
        transition(&b.normal, f.normal_layout)
    } else {
        // The plugin's own stand-in, bound but never read: made readable, its contents undefined.
        Barrier::Image {
            image: &b.normal,
            before: if to_shader {
                S::Undefined
            } else {
                S::ShaderResource
            },
            after: S::ShaderResource,
        }
    };
    enc.barriers(&[transition(&b.depth, f.depth_layout), normal]);
}

/// Copies each light's final visibility into its layer of the engine's output image: for a light of
/// several frusta, first the minimum over those recorded (`recorded[light][frustum]`); a light of one
/// frustum that was not recorded gets 1 in its layer.
fn record_output_copy(
    enc: &mut Encoder<'_>,
    b: &Built,
    f: &HrtsFrame,
    recorded: &[Vec<bool>],
) -> ApiResult<()> {
    let combines: Vec<_> = b
        .lights
        .iter()
        .flatten()
        .zip(recorded)
        .filter_map(|(l, r)| l.combine.as_ref().map(|c| (l, c, r)))
        .collect();
    if !combines.is_empty() {
        enc.barriers(&[Barrier::Uav]);
        for (light, combine, recorded) in combines {
            // Timed with the light's last frustum recorded this frame, so that the light's report holds
            // its whole cost; a light with none recorded only fills its layer with 1, untimed.
            match light.frusta.iter().zip(recorded).rev().find(|(_, &r)| r) {
                Some((timed, _)) => timed.continue_timing(enc),
                None => enc.stop_timing(),
            }
            combine.record(enc, recorded)?;
        }
    }
    let lit =
        |l: &crate::context::LightPasses, r: &[bool]| l.combine.is_none() && !r.contains(&true);
    if !b.output_layers.is_empty() {
        return record_output_layers(enc, b, f, recorded, lit);
    }
    // The layer of each light, and the visibility to copy into it (none: fill with 1).
    let layers: Vec<(u32, Option<&Image>)> = b
        .lights
        .iter()
        .flatten()
        .zip(recorded)
        .enumerate()
        .map(|(layer, (l, r))| (layer as u32, (!lit(l, r)).then(|| l.output())))
        .collect();
    let outputs: Vec<&Image> = layers.iter().filter_map(|&(_, image)| image).collect();
    let each = |before, after| -> Vec<Barrier<'_>> {
        outputs
            .iter()
            .map(|&image| Barrier::Image {
                image,
                before,
                after,
            })
            .collect()
    };
    enc.begin_pass("output copy");
    let mut to_copy = each(S::UnorderedAccess, S::CopySource);
    to_copy.push(Barrier::Image {
        image: &b.output,
        before: S::Engine(f.output_layout_before),
        after: S::CopyDest,
    });
    enc.barriers(&to_copy);
    let same_format = b.output.format() == Format::R32Float;
    for &(layer, vis) in &layers {
        match vis {
            Some(vis) if same_format => enc.copy_image_into_layer(vis, &b.output, layer)?,
            Some(vis) => enc.blit_into_layer(vis, &b.output, layer)?,
            None => enc.clear_uint_layer(&b.output, layer, 1.0f32.to_bits())?,
        }
    }
    let mut back = each(S::CopySource, S::UnorderedAccess);
    back.push(Barrier::Image {
        image: &b.output,
        before: S::CopyDest,
        after: S::Engine(f.output_layout_after),
    });
    enc.barriers(&back);
    enc.end_pass();
    Ok(())
}

/// [`record_output_copy`] into an output image the lights may write directly (storage
/// usage), layer by layer: a layer its light wrote goes to `output_layout_after`; the others get their
/// light's visibility copied in, or 1 for a light with no frustum recorded.
fn record_output_layers(
    enc: &mut Encoder<'_>,
    b: &Built,
    f: &HrtsFrame,
    recorded: &[Vec<bool>],
    lit: impl Fn(&crate::context::LightPasses, &[bool]) -> bool,
) -> ApiResult<()> {
    let after = S::Engine(f.output_layout_after);
    enc.begin_pass("output copy");
    for ((light, r), layer) in b
        .lights
        .iter()
        .flatten()
        .zip(recorded)
        .zip(&b.output_layers)
    {
        let unlit = lit(light, r);
        if light.direct && !unlit {
            enc.barriers(&[Barrier::Image {
                image: layer,
                before: S::UnorderedAccess,
                after,
            }]);
            continue;
        }
        let source = (!unlit).then(|| light.output());
        let mut to_copy = vec![Barrier::Image {
            image: layer,
            before: S::Engine(f.output_layout_before),
            after: S::CopyDest,
        }];
        to_copy.extend(source.map(|image| Barrier::Image {
            image,
            before: S::UnorderedAccess,
            after: S::CopySource,
        }));
        enc.barriers(&to_copy);
        match source {
            Some(image) if layer.format() == Format::R32Float => {
                enc.copy_image_into_layer(image, layer, 0)?
            }
            Some(image) => enc.blit_into_layer(image, layer, 0)?,
            None => enc.clear_uint_layer(layer, 0, 1.0f32.to_bits())?,
        }
        let mut back = vec![Barrier::Image {
            image: layer,
            before: S::CopyDest,
            after,
        }];
        back.extend(source.map(|image| Barrier::Image {
            image,
            before: S::CopySource,
            after: S::UnorderedAccess,
        }));
        enc.barriers(&back);
    }
    enc.end_pass();
    Ok(())
}

/// Counts in each light's schedule the frusta a batch recorded: `batched` indexes `lights`, which gives
/// each scheduled frustum's light; `counter` picks the schedule's count.
fn count_batched(
    frame_lights: &mut Option<&mut Vec<LightSchedule>>,
    lights: &[usize],
    batched: &[usize],
    counter: impl Fn(&mut LightSchedule) -> &mut u32,
) {
    if let Some(frame_lights) = frame_lights {
        for &i in batched {
            if let Some(l) = lights.get(i).and_then(|&l| frame_lights.get_mut(l)) {
                *counter(l) += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::DEPTH_NORMAL_READERS;
    use crate::types::HRTS_PASS_MASK_LIGHT_SPACE;

    #[test]
    fn light_space_passes_read_no_depth_or_normals() {
        assert_eq!(HRTS_PASS_MASK_LIGHT_SPACE & DEPTH_NORMAL_READERS, 0);
    }
}

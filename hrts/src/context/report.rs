//! Reporting: a light's frame report (statistics, timings, pass statuses, memory and decision) and the
//! description of its resources.

use super::schedule::LightSchedule;
use super::Context;
use crate::convert::{binning_path_to_c, resource_id, resource_index, RESOURCES};
use crate::error::{invalid, ApiError, ApiResult};
use crate::types::*;
use passes::{
    FrameReport, PassStatus, ResourceId, ShadowPipeline, SkipReason, FIT_BATCH_PASS,
    LIST_BATCH_PASS,
};
use rhi::Format;
use rhi::PassTiming;

impl Context {
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
        let frame_schedule = self.schedules.iter().find(|s| s.index == frame_index);
        let schedule = frame_schedule
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
        out.map_size = first_pipeline
            .primitive_map()
            .map_or(0, |m| m.config().size);
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
        out.pixels_walked_per_sample = sum(|r| r.stats.pixels_walked_per_sample);
        out.map_to_texels = reports
            .first()
            .map_or([0.0; 16], |r| r.map_to_texels.to_cols_array());
        // The light's share of the frame's batched fits and lists: each batch's time over the frusta it
        // recorded.
        let not_ready = || {
            ApiError::new(
                HrtsResult::NotReady,
                format!("frame {frame_index} has not completed on the GPU: ask after its fence signalled"),
            )
        };
        let internal =
            |e: passes::PassError| ApiError::new(HrtsResult::ErrorInternal, e.to_string());
        let share = |count: fn(&LightSchedule) -> u32,
                     ms: Option<Result<Option<f64>, passes::PassError>>,
                     name: &str|
         -> ApiResult<Option<PassTiming>> {
            if count(schedule) == 0 {
                return Ok(None);
            }
            let total: u32 = frame_schedule.map_or(0, |s| s.lights.iter().map(count).sum());
            let ms = ms
                .ok_or_else(|| ApiError::new(HrtsResult::ErrorInternal, "no batch"))?
                .map_err(internal)?
                .ok_or_else(not_ready)?;
            Ok(Some(PassTiming {
                name: name.to_owned(),
                ms: ms * f64::from(count(schedule)) / f64::from(total.max(1)),
            }))
        };
        let fit_share = share(
            |l| l.fits_batched,
            self.fit_batch.as_ref().map(|b| b.milliseconds(frame_index)),
            FIT_BATCH_PASS,
        )?;
        let list_share = share(
            |l| l.lists_batched,
            self.list_batch
                .as_ref()
                .map(|b| b.milliseconds(frame_index)),
            LIST_BATCH_PASS,
        )?;
        let batch_share = fit_share.into_iter().chain(list_share);
        let batch_share: Vec<PassTiming> = batch_share.collect();
        let timings: Vec<_> = batch_share
            .iter()
            .chain(reports.iter().flat_map(|r| &r.timings))
            .collect();
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
        for (pipeline, r) in passes
            .frusta
            .iter()
            .flat_map(|p| p.resources().into_iter().map(move |r| (p, r)))
        {
            // The engine's layer is not counted; the buffers that serve it (an area trace's) are.
            let bytes = if engine_owned(r.resource) {
                let image = pipeline.image(r.resource).map_or(0, rhi::Image::byte_size);
                r.bytes.saturating_sub(image)
            } else {
                r.bytes
            };
            if let Some(i) = RESOURCES.iter().position(|&id| id == r.resource) {
                out.resource_bytes[i] += bytes;
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
        out.decision_reason = super::plan::reason_to_c(&reason);
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
        // A resource the lights share is not the light's own ([`passes::ShadowPipeline::is_shared`]).
        let own = !pipeline.is_shared(id);
        match (pipeline.image(id).filter(|_| own), pipeline.buffer(id)) {
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

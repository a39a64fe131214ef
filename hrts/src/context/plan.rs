//! Planning lights without a context (`hrts_plan_lights`): the decision each light's frame report would
//! give for a view, from the same conversion and culling a frame's recording runs.

use super::schedule::schedule;
use crate::convert::{
    frame_bounds, frame_inputs, mode_to_c, resource_index, shadow_config, FrameLight,
};
use crate::error::{ApiError, ApiResult};
use crate::types::*;
use passes::FramePlan;

/// For each light of `f` (configured by `configs`, one per light: the caller reads `f.light_count` of each), what a frame of its camera, lights and
/// casters' bounds would do with it (`struct_size` left 0).
pub(crate) fn plan_lights(configs: &[HrtsConfig], f: &HrtsFrame) -> ApiResult<Vec<HrtsLightPlan>> {
    let configs = configs
        .iter()
        .enumerate()
        .map(|(i, c)| {
            shadow_config(c).map_err(|e| ApiError {
                message: format!("configs[{i}]: {}", e.message),
                ..e
            })
        })
        .collect::<ApiResult<Vec<_>>>()?;
    let bounds = frame_bounds(f)?;
    let lights: Vec<FrameLight> = frame_inputs(f, bounds)?
        .into_iter()
        .zip(&configs)
        .map(|(light, config)| light.shadowed_as(config))
        .collect();
    let schedules = schedule(&configs, &lights, bounds);
    Ok(lights
        .iter()
        .zip(&configs)
        .zip(&schedules)
        .map(|((light, config), schedule)| {
            let (decision, reason) = schedule.decision();
            let recorded = schedule.recorded.iter().filter(|&&r| r).count() as u32;
            let config = light.shape().config(config);
            let (passes, resources, map_size) = match decision {
                HrtsLightDecision::Shadowed => {
                    let (passes, resources) = plan_bits(&FramePlan::derive(config.plan_request()));
                    let map_size = config.built_map().map_or(0, |m| m.size);
                    (passes, resources, map_size)
                }
                HrtsLightDecision::OutOfView => (0, 0, 0),
            };
            HrtsLightPlan {
                struct_size: 0,
                decision: decision as u32,
                frusta: recorded,
                frusta_culled: schedule.recorded.len() as u32 - recorded,
                mode: mode_to_c(config.mode),
                decision_reason: reason_to_c(&reason),
                passes,
                resources,
                map_size,
            }
        })
        .collect())
}

/// The `HrtsPass` bits of `plan`'s passes and the `HrtsResource` bits of its resources (those with a
/// value: not the engine's inputs, the light or the scene's geometry).
fn plan_bits(plan: &FramePlan) -> (u32, u32) {
    let passes = plan
        .passes()
        .iter()
        .fold(0, |bits, &p| bits | 1 << p as u32);
    let resources = plan
        .resources()
        .iter()
        .filter_map(|r| resource_index(r).ok())
        .fold(0, |bits, r| bits | 1 << r);
    (passes, resources)
}

/// `reason` as a NUL-terminated C string of at most 127 bytes.
pub(crate) fn reason_to_c(reason: &str) -> [std::ffi::c_char; 128] {
    let mut out = [0; 128];
    for (dst, src) in out.iter_mut().zip(reason.bytes().take(127)) {
        *dst = src as std::ffi::c_char;
    }
    out
}

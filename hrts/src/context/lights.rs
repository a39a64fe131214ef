//! Lights: each light's configuration, checked against the device, and the frames' schedules kept for
//! the reports ([`super::schedule`] decides them).

use super::schedule::{schedule, FrameSchedule, LightSchedule};
use super::{Context, FrameProgress, Retired};
use crate::convert::{shadow_config, FrameLight, LightShape};
use crate::error::{invalid, ApiError, ApiResult};
use crate::types::*;
use passes::ShadowConfig;

impl Context {
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
}

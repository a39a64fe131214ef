//! Lights: each light's configuration, checked against the device. Which of their frusta a frame records
//! is [`super::schedule`]'s; the recording keeps each frame's schedule for its reports.

use super::{Context, FrameProgress, Retired};
use crate::convert::{shadow_config, LightShape};
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
                self.retire(Retired::light_passes(replaced));
                self.progress = FrameProgress::default();
            }
        }
        self.light_builds.resize(lights.len(), 0);
        self.frusta.resize(lights.len(), LightShape::default());
        self.lights = lights;
        Ok(())
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

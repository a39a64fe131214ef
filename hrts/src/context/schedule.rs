//! Light scheduling and decisions: which frusta of each light a frame records, and the decision and
//! reason its report gives.

use crate::convert::FrameLight;
use crate::types::*;
use passes::{Casters, ShadowConfig, ViewVolume};

/// Which frusta of each light a frame recorded: those where a caster may shadow a receiver in view within
/// the light's range ([`passes::ViewVolume::may_shadow`]).
pub(crate) struct FrameSchedule {
    pub(crate) index: u64,
    pub(crate) lights: Vec<LightSchedule>,
}

/// One light's frusta in a frame: recorded or culled, with their names for the report.
pub(crate) struct LightSchedule {
    pub(crate) kind: HrtsLightType,
    pub(crate) recorded: Vec<bool>,
    pub(crate) names: Vec<&'static str>,
    /// The mode auto chose for the light and why ([`ShadowConfig::auto_reason`]); `None` for a mode given.
    pub(crate) auto: Option<&'static str>,
    /// How many of its frusta had their primitive-map fit recorded in the frame's batch
    /// ([`passes::FitBatch`]).
    pub(crate) fits_batched: u32,
    /// How many of its frusta had their primitive map's lists recorded in one of the frame's list batches
    /// ([`passes::ListBatch`]).
    pub(crate) lists_batched: u32,
}

impl LightSchedule {
    /// The light's decision and its reason in words, with the mode auto chose for it.
    pub(crate) fn decision(&self) -> (HrtsLightDecision, String) {
        let (decision, reason) = self.frusta_decision();
        match self.auto {
            Some(auto) => (decision, format!("{reason}; {auto}")),
            None => (decision, reason),
        }
    }

    /// The light's decision by the frusta recorded, and its reason in words.
    fn frusta_decision(&self) -> (HrtsLightDecision, String) {
        let kind = match self.kind {
            HrtsLightType::Directional => "directional light",
            HrtsLightType::Spot => "spot light",
            HrtsLightType::Point => "point light",
        };
        let recorded = self.recorded.iter().filter(|&&r| r).count();
        let culled: Vec<&str> = self
            .names
            .iter()
            .zip(&self.recorded)
            .filter(|(_, &r)| !r)
            .map(|(&n, _)| n)
            .collect();
        match (recorded, self.recorded.len()) {
            (0, _) => (
                HrtsLightDecision::OutOfView,
                format!("{kind}: no caster may shadow a receiver in view within range; lit"),
            ),
            (_, 1) if self.names == passes::CUBE_MAP_NAME => (
                HrtsLightDecision::Shadowed,
                format!(
                    "{kind}: receivers in view within range; its six cube faces built as one map"
                ),
            ),
            (_, 1) => (
                HrtsLightDecision::Shadowed,
                format!("{kind}: its frustum holds receivers in view"),
            ),
            (_, n) if culled.is_empty() => (
                HrtsLightDecision::Shadowed,
                format!("{kind}: all {n} frusta hold receivers in view within range"),
            ),
            (r, n) => (
                HrtsLightDecision::Shadowed,
                format!(
                    "{kind}: {r} of {n} frusta hold receivers in view within range; culled {}",
                    culled.join(" ")
                ),
            ),
        }
    }
}

/// Which frusta of each light (configured by `configs`, in order) may change a pixel in view this frame
/// ([`ViewVolume::may_shadow`]): those holding receivers in view within the light's range that a caster
/// within the casters' `bounds` (when they are known) may shadow; and the mode auto chose for it. A light
/// shadowed through shadow maps (soft, hybrid) is culled by the view and its range alone.
pub(crate) fn schedule(
    configs: &[ShadowConfig],
    lights: &[FrameLight],
    bounds: Option<[glam::DVec3; 2]>,
) -> Vec<LightSchedule> {
    let camera = lights.first().and_then(|l| l.frusta.first()).map(|f| {
        ViewVolume::new(
            f.proj.as_dmat4() * f.view.as_dmat4(),
            f.camera_position.as_dvec3(),
        )
    });
    lights
        .iter()
        .zip(configs)
        .map(|(light, config)| {
            let directional = light.kind == HrtsLightType::Directional;
            let casters =
                bounds
                    .zip(config.traced_light_size(directional))
                    .map(|(bounds, size)| Casters {
                        bounds,
                        light_size: f64::from(size),
                    });
            LightSchedule {
                kind: light.kind,
                auto: config.auto_reason(directional),
                fits_batched: 0,
                lists_batched: 0,
                recorded: light
                    .frusta
                    .iter()
                    .map(|f| {
                        camera
                            .as_ref()
                            .is_none_or(|c| c.may_shadow(&f.light, light.range, casters.as_ref()))
                    })
                    .collect(),
                names: (0..light.frusta.len())
                    .map(|k| light.frustum_name(k))
                    .collect(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convert::LightShape;
    use passes::ShadowMode;

    /// Under mode auto a light's passes are built for the mode its kind's size gives, and its report says
    /// which and why.
    #[test]
    fn auto_lights_are_built_and_reported_by_their_size() {
        let mut auto = ShadowConfig {
            mode: ShadowMode::Auto,
            ..ShadowConfig::default()
        };
        auto.pcss.angular_radius = 0.0;
        let sun = LightShape::default();
        let lamp = LightShape {
            cube: true,
            directional: false,
            ..sun
        };
        assert_eq!(sun.config(&auto).mode, ShadowMode::Hard);
        let lamp_config = lamp.config(&auto);
        assert_eq!(lamp_config.mode, ShadowMode::Area);
        assert!(lamp_config.map.cube);
        let schedule = |kind, config: &ShadowConfig| LightSchedule {
            kind,
            recorded: vec![true],
            names: vec!["whole"],
            auto: config.auto_reason(kind == HrtsLightType::Directional),
            fits_batched: 0,
            lists_batched: 0,
        };
        let (decision, reason) = schedule(HrtsLightType::Directional, &auto).decision();
        assert_eq!(decision, HrtsLightDecision::Shadowed);
        assert_eq!(
            reason,
            "directional light: its frustum holds receivers in view; auto: hard (zero-size light)"
        );
        let (_, reason) = schedule(HrtsLightType::Spot, &auto).decision();
        assert!(reason.ends_with("; auto: area (sized light)"), "{reason}");
        let (_, reason) = schedule(HrtsLightType::Spot, &ShadowConfig::default()).decision();
        assert_eq!(reason, "spot light: its frustum holds receivers in view");
    }
}

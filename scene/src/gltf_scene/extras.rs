//! The `hrts` object in the `extras` of glTF nodes and lights (schema: the module documentation
//! of [`gltf_scene`](super)).

use std::path::Path;

use serde_json::Value;

use crate::{LightKind, LightSize, SceneError};

/// The settings of one `extras.hrts` object; `None` where a key is absent.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub(super) struct Hrts {
    pub(super) is_static: Option<bool>,
    pub(super) casts_shadows: Option<bool>,
    pub(super) radius: Option<f32>,
    pub(super) angular_radius: Option<f32>,
}

impl Hrts {
    /// Each setting of `self`, else of `fallback`.
    pub(super) fn or(self, fallback: Hrts) -> Hrts {
        Hrts {
            is_static: self.is_static.or(fallback.is_static),
            casts_shadows: self.casts_shadows.or(fallback.casts_shadows),
            radius: self.radius.or(fallback.radius),
            angular_radius: self.angular_radius.or(fallback.angular_radius),
        }
    }

    /// An error naming the first key that needs a light, for a node without a light (`has_mesh`:
    /// whether it has a mesh, which takes `casts_shadows`).
    pub(super) fn reject_light_keys(&self, has_mesh: bool) -> Result<(), String> {
        if !has_mesh && self.casts_shadows.is_some() {
            return Err("\"casts_shadows\" applies to mesh and light nodes, but this node has neither a mesh nor a KHR_lights_punctual light".into());
        }
        let present = [
            ("radius", self.radius.is_some()),
            ("angular_radius", self.angular_radius.is_some()),
        ];
        match present.iter().find(|(_, present)| *present) {
            Some((key, _)) => Err(format!(
                "\"{key}\" applies to lights, but this node has no KHR_lights_punctual light"
            )),
            None => Ok(()),
        }
    }

    /// The light size for a light of `kind`: 0 or absent gives [`LightSize::Zero`]. Negative
    /// sizes are passed on for [`SceneLight`](crate::SceneLight) validation to report.
    pub(super) fn size(&self, kind: &LightKind) -> Result<LightSize, String> {
        let nonzero = |value: Option<f32>, size: fn(f32) -> LightSize| match value {
            Some(v) if v != 0.0 => size(v),
            _ => LightSize::Zero,
        };
        match (kind, self.radius, self.angular_radius) {
            (LightKind::Directional { .. }, Some(_), _) => Err(
                "\"radius\" applies to spot and point lights; directional lights take \"angular_radius\" (radians)".into(),
            ),
            (LightKind::Directional { .. }, None, angular) => {
                Ok(nonzero(angular, LightSize::AngularRadius))
            }
            (_, _, Some(_)) => Err(
                "\"angular_radius\" applies to directional lights; spot and point lights take \"radius\" (metres)".into(),
            ),
            (_, radius, None) => Ok(nonzero(radius, LightSize::Radius)),
        }
    }
}

/// The `hrts` settings in `extras` (of the node or light described by `owner`). Extras that are
/// absent, not an object, or without an `hrts` key give no settings.
pub(super) fn parse(
    extras: &gltf::json::Extras,
    path: &Path,
    owner: &str,
) -> Result<Hrts, SceneError> {
    let invalid = |message: String| SceneError::InvalidExtras {
        path: path.to_owned(),
        owner: owner.to_owned(),
        message,
    };
    let Some(raw) = extras else {
        return Ok(Hrts::default());
    };
    let extras: Value = serde_json::from_str(raw.get()).map_err(|e| invalid(e.to_string()))?;
    let Some(hrts) = extras.get("hrts") else {
        return Ok(Hrts::default());
    };
    let Value::Object(map) = hrts else {
        return Err(invalid(format!("\"hrts\" must be an object, found {hrts}")));
    };
    let boolean = |key: &str, value: &Value| {
        value
            .as_bool()
            .ok_or_else(|| invalid(format!("\"{key}\" must be true or false, found {value}")))
    };
    let number = |key: &str, value: &Value| {
        value
            .as_f64()
            .map(|v| v as f32)
            .filter(|v| v.is_finite())
            .ok_or_else(|| invalid(format!("\"{key}\" must be a finite number, found {value}")))
    };
    let mut settings = Hrts::default();
    for (key, value) in map {
        match key.as_str() {
            "static" => settings.is_static = Some(boolean(key, value)?),
            "casts_shadows" => settings.casts_shadows = Some(boolean(key, value)?),
            "radius" => settings.radius = Some(number(key, value)?),
            "angular_radius" => settings.angular_radius = Some(number(key, value)?),
            _ => {
                return Err(SceneError::UnknownExtrasKey {
                    path: path.to_owned(),
                    owner: owner.to_owned(),
                    key: key.clone(),
                })
            }
        }
    }
    Ok(settings)
}

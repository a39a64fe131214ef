//! Lights as a scene declares them: kind, placement, colour, size and the flags the frame plan
//! needs (does it cast shadows, does it move).

use std::f32::consts::FRAC_PI_2;
use std::path::Path;

use glam::Vec3;

use crate::{error::MEMORY_PATH, SceneError};

/// The kind of a light and where it is, in world space.
///
/// Directions are unit vectors along which the light travels (from the light towards the scene),
/// as for [`DirectionalLight`](crate::DirectionalLight).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightKind {
    /// Light from infinitely far away, travelling along `direction`.
    Directional {
        /// Unit vector along which the light travels.
        direction: Vec3,
    },
    /// A cone of light from `position` around `direction`.
    Spot {
        /// Position in metres.
        position: Vec3,
        /// Unit vector along the axis of the cone, away from the light.
        direction: Vec3,
        /// Angle in radians from the axis where the intensity starts to fall off, in
        /// `[0, outer_cone)`.
        inner_cone: f32,
        /// Angle in radians from the axis where the intensity reaches zero, in `(0, pi/2]`.
        outer_cone: f32,
        /// Distance in metres beyond which the light has no effect; `None` for unlimited.
        range: Option<f32>,
    },
    /// Light in every direction from `position`.
    Point {
        /// Position in metres.
        position: Vec3,
        /// Distance in metres beyond which the light has no effect; `None` for unlimited.
        range: Option<f32>,
    },
}

impl LightKind {
    /// The direction of a directional or spot light; `None` for a point light.
    pub fn direction(&self) -> Option<Vec3> {
        match *self {
            LightKind::Directional { direction } | LightKind::Spot { direction, .. } => {
                Some(direction)
            }
            LightKind::Point { .. } => None,
        }
    }

    /// The position of a spot or point light; `None` for a directional light.
    pub fn position(&self) -> Option<Vec3> {
        match *self {
            LightKind::Spot { position, .. } | LightKind::Point { position, .. } => Some(position),
            LightKind::Directional { .. } => None,
        }
    }
}

/// The extent of a light, which decides how soft its shadows are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightSize {
    /// No extent: hard shadows. The default.
    Zero,
    /// A directional light seen as a disc of this angular radius, in radians, in `(0, pi/2)`
    /// (the sun: about 0.00465).
    AngularRadius(f32),
    /// A spot or point light that is a sphere of this radius, in metres, positive.
    Radius(f32),
}

impl LightSize {
    /// Whether the light has no extent (hard shadows).
    pub fn is_zero(&self) -> bool {
        matches!(self, LightSize::Zero)
    }
}

/// A light of a scene, with everything the renderer needs to decide how to shadow it.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneLight {
    /// Name (for glTF: the node's name, else the light's, else `light<index>`).
    pub name: String,
    /// Kind and world-space placement.
    pub kind: LightKind,
    /// Linear RGB colour, each component finite and non-negative.
    pub color: Vec3,
    /// Intensity, finite and non-negative: candela for spot and point lights, lux for
    /// directional lights (the glTF `KHR_lights_punctual` units).
    pub intensity: f32,
    /// Extent; [`LightSize::AngularRadius`] only for directional lights, [`LightSize::Radius`]
    /// only for spot and point lights.
    pub size: LightSize,
    /// Whether the light casts shadows at all.
    pub casts_shadows: bool,
    /// Whether the light never moves or changes, so that work derived from it can be kept
    /// from one frame to the next.
    pub is_static: bool,
}

impl SceneLight {
    /// Checks the invariants documented on the fields and on [`LightKind`], reporting problems
    /// as [`SceneError::InvalidLight`] against the path `<memory>`.
    pub fn validate(&self) -> Result<(), SceneError> {
        self.check().map_err(|message| SceneError::InvalidLight {
            path: Path::new(MEMORY_PATH).to_owned(),
            light: format!("light \"{}\"", self.name),
            message,
        })
    }

    /// What is wrong with the light, if anything.
    pub(crate) fn check(&self) -> Result<(), String> {
        let finite_non_negative = |v: f32| v.is_finite() && v >= 0.0;
        if !self.color.to_array().into_iter().all(finite_non_negative) {
            return Err(format!(
                "color {} must be finite and non-negative",
                self.color
            ));
        }
        if !finite_non_negative(self.intensity) {
            return Err(format!(
                "intensity {} must be finite and non-negative",
                self.intensity
            ));
        }
        if let Some(position) = self.kind.position() {
            if !position.is_finite() {
                return Err(format!("position {position} is not finite"));
            }
        }
        if let Some(direction) = self.kind.direction() {
            if !direction.is_finite() || (direction.length() - 1.0).abs() > 1e-4 {
                return Err(format!(
                    "direction {direction} is not a unit vector (is the light's node scaled to zero?)"
                ));
            }
        }
        if let LightKind::Spot {
            inner_cone,
            outer_cone,
            ..
        } = self.kind
        {
            let outer_valid = outer_cone > 0.0 && outer_cone <= FRAC_PI_2;
            if !outer_valid {
                return Err(format!(
                    "spot outer cone angle {outer_cone} rad must be in (0, pi/2]"
                ));
            }
            let inner_valid = inner_cone >= 0.0 && inner_cone < outer_cone;
            if !inner_valid {
                return Err(format!(
                    "spot inner cone angle {inner_cone} rad must be in [0, outer cone angle {outer_cone})"
                ));
            }
        }
        if let LightKind::Spot {
            range: Some(range), ..
        }
        | LightKind::Point {
            range: Some(range), ..
        } = self.kind
        {
            let valid = range > 0.0 && range.is_finite();
            if !valid {
                return Err(format!("range {range} m must be positive and finite"));
            }
        }
        let directional = matches!(self.kind, LightKind::Directional { .. });
        match self.size {
            LightSize::Zero => {}
            LightSize::AngularRadius(_) if !directional => {
                return Err("an angular radius applies to directional lights only; spot and point lights take a radius".into());
            }
            LightSize::Radius(_) if directional => {
                return Err("a radius applies to spot and point lights only; directional lights take an angular radius".into());
            }
            LightSize::AngularRadius(a) | LightSize::Radius(a) if a < 0.0 => {
                return Err(format!("negative size {a}"));
            }
            LightSize::AngularRadius(a) => {
                let valid = a > 0.0 && a < FRAC_PI_2;
                if !valid {
                    return Err(format!("angular radius {a} rad must be in (0, pi/2)"));
                }
            }
            LightSize::Radius(r) => {
                let valid = r > 0.0 && r.is_finite();
                if !valid {
                    return Err(format!("radius {r} m must be positive and finite"));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot() -> SceneLight {
        SceneLight {
            name: "spot".into(),
            kind: LightKind::Spot {
                position: Vec3::new(0.0, 3.0, 0.0),
                direction: Vec3::NEG_Y,
                inner_cone: 0.2,
                outer_cone: 0.5,
                range: Some(10.0),
            },
            color: Vec3::ONE,
            intensity: 100.0,
            size: LightSize::Radius(0.05),
            casts_shadows: true,
            is_static: false,
        }
    }

    fn message(light: &SceneLight) -> String {
        let error = light.validate().unwrap_err();
        assert!(matches!(error, SceneError::InvalidLight { .. }));
        error.to_string()
    }

    #[test]
    fn accessors() {
        let light = spot();
        light.validate().unwrap();
        assert_eq!(light.kind.position(), Some(Vec3::new(0.0, 3.0, 0.0)));
        assert_eq!(light.kind.direction(), Some(Vec3::NEG_Y));
        let point = LightKind::Point {
            position: Vec3::ONE,
            range: None,
        };
        assert_eq!(
            (point.position(), point.direction()),
            (Some(Vec3::ONE), None)
        );
        let sun = LightKind::Directional {
            direction: Vec3::NEG_Y,
        };
        assert_eq!((sun.position(), sun.direction()), (None, Some(Vec3::NEG_Y)));
        assert!(LightSize::Zero.is_zero());
        assert!(!LightSize::Radius(1.0).is_zero());
    }

    #[test]
    fn invalid_lights_are_reported() {
        let with_kind = |kind| SceneLight { kind, ..spot() };
        let with_cones = |inner_cone, outer_cone| {
            with_kind(LightKind::Spot {
                position: Vec3::ZERO,
                direction: Vec3::NEG_Y,
                inner_cone,
                outer_cone,
                range: None,
            })
        };
        assert!(message(&with_cones(0.1, 2.0)).contains("outer cone"));
        assert!(message(&with_cones(0.6, 0.5)).contains("inner cone"));
        assert!(message(&with_cones(0.5, 0.5)).contains("inner cone"));
        assert!(message(&with_cones(-0.1, 0.5)).contains("inner cone"));
        with_cones(0.0, FRAC_PI_2).validate().unwrap();
        assert!(message(&SceneLight {
            size: LightSize::Radius(-0.5),
            ..spot()
        })
        .contains("negative size"));
        assert!(message(&SceneLight {
            size: LightSize::AngularRadius(0.01),
            ..spot()
        })
        .contains("directional lights only"));
        let sun = with_kind(LightKind::Directional {
            direction: Vec3::NEG_Y,
        });
        assert!(message(&SceneLight {
            size: LightSize::Radius(0.5),
            ..sun.clone()
        })
        .contains("spot and point lights only"));
        assert!(message(&SceneLight {
            size: LightSize::AngularRadius(2.0),
            ..sun.clone()
        })
        .contains("angular radius"));
        assert!(message(&with_kind(LightKind::Directional {
            direction: Vec3::ZERO
        }))
        .contains("unit vector"));
        assert!(message(&SceneLight {
            intensity: f32::NAN,
            ..spot()
        })
        .contains("intensity"));
        assert!(message(&SceneLight {
            color: Vec3::new(1.0, -1.0, 0.0),
            ..spot()
        })
        .contains("color"));
        assert!(message(&with_kind(LightKind::Point {
            position: Vec3::ZERO,
            range: Some(0.0)
        }))
        .contains("range"));
        assert!(message(&with_kind(LightKind::Point {
            position: Vec3::NAN,
            range: None
        }))
        .contains("position"));
        let error = message(&with_cones(0.6, 0.5));
        assert!(error.starts_with("<memory>: light \"spot\": "), "{error}");
    }
}

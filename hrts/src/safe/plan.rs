//! [`plan_lights`]: what the plugin would do with each light in a view, without a context or a device.

use super::enums::{decode, LightDecision, PassMask, ResourceSet, ShadowMode};
use super::error::{c_chars, check, Result};
use super::geometry::Bounds;
use super::{Config, Light};
use crate::types::{HrtsFrame, HrtsLightPlan};
use glam::{Mat4, Vec3};

/// The view lights are planned for: the camera of a frame, and the bounds of its shadow casters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanView {
    /// World to view.
    pub view: Mat4,
    /// View to clip in Vulkan's conventions (depth 0..1).
    pub proj: Mat4,
    /// Camera position in world space.
    pub camera_position: Vec3,
    /// World-space bounds of every shadow caster (`None`: unknown; the view and the ranges alone cull,
    /// and a directional light needs its own `view_proj`).
    pub casters: Option<Bounds>,
}

/// What the plugin would do with one light in a view (`HrtsLightPlan`): the decision, frusta, mode and
/// reason its [`FrameReport`](crate::FrameReport) gives for a frame of that view.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LightPlan {
    /// Shadowed, or out of view (no frustum may shadow a receiver in view within its range).
    pub decision: LightDecision,
    /// Frusta it would be shadowed through.
    pub frusta: u32,
    /// Frusta it would skip.
    pub frusta_culled: u32,
    /// The mode its passes would run (under [`ShadowMode::Auto`], the one its size chooses).
    pub mode: ShadowMode,
    /// Why, in words.
    pub reason: String,
    /// The passes of its plan in that mode (those its frame report lists as in the plan); none when out
    /// of view.
    pub passes: PassMask,
    /// The resources of its plan (held by the light or shared by the context's lights); none when out of
    /// view.
    pub resources: ResourceSet,
    /// N of its primitive map: the configuration's [`Config::map_size`](crate::Config::map_size), or the
    /// plugin's choice for the trace of its mode; 0 when its plan has none or it is out of view.
    pub map_size: u32,
    /// The names of the frusta it is planned through (shadowed and skipped), as reports name them: "cube"
    /// for a point light shadowed as one cube map, its faces ("+X" ... "-Z") for one shadowed face by face,
    /// a wide spot light's faces ("front", "right", "left", "up", "down"), else "whole".
    pub frustum_names: &'static [&'static str],
}

/// Plans `lights` (configured by `configs`, one per light) for `view` without a context or a device
/// (`hrts_plan_lights`): for a host that decides which lights to configure.
///
/// ```
/// use hrts::{plan_lights, Bounds, Config, Light, LightDecision, Pass, PlanView, Resource};
/// use hrts::glam::{Mat4, Vec3};
///
/// let eye = Vec3::new(0.0, 2.0, 6.0);
/// let view = PlanView {
///     view: Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Y),
///     proj: Mat4::perspective_infinite_reverse_rh(1.0, 16.0 / 9.0, 0.1),
///     camera_position: eye,
///     casters: Some(Bounds { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) }),
/// };
/// // A lamp far behind the camera whose range reaches nothing in view, and one over the scene.
/// let far = Light::Point { position: Vec3::new(0.0, 2.0, 60.0), range: Some(5.0) };
/// let near = Light::Point { position: Vec3::new(0.0, 3.0, 0.0), range: None };
/// let plans = plan_lights(&[Config::default(), Config::default()], &[far, near], &view)?;
/// assert_eq!(plans[0].decision, LightDecision::OutOfView);
/// assert_eq!(plans[1].decision, LightDecision::Shadowed);
/// // The default configuration is the talk's hybrid: the ray-traced hard shadow blended with PCSS.
/// let hybrid = [Pass::ShadowMap, Pass::PrimitiveMap, Pass::RayTrace, Pass::Pcss, Pass::Blend];
/// assert!(hybrid.iter().all(|&p| plans[1].passes.contains(p)));
/// assert!(plans[1].resources.contains(Resource::PrimListEntries));
/// assert_eq!(plans[1].passes.iter().next().map(Pass::name), Some("prim buffer"));
/// // The plugin's choice of the primitive map's N: 1024 for the hybrid's nearest-hit lists, 512 for
/// // hard shadows.
/// assert_eq!(plans[1].map_size, 1024);
/// let hard = Config { mode: hrts::ShadowMode::Hard, ..Config::default() };
/// assert_eq!(plan_lights(&[hard], &[near], &view)?[0].map_size, 512);
/// # Ok::<(), hrts::Error>(())
/// ```
pub fn plan_lights(
    configs: &[Config],
    lights: &[Light],
    view: &PlanView,
) -> Result<Vec<LightPlan>> {
    const CALL: &str = "hrts_plan_lights";
    let c_configs: Vec<_> = configs.iter().copied().map(Config::to_c).collect();
    let c_lights: Vec<_> = lights.iter().map(|l| l.to_c()).collect();
    if c_configs.len() != c_lights.len() {
        return Err(super::error::Error::new(
            CALL,
            crate::types::HrtsResult::ErrorInvalidArgument,
            format!(
                "{} configurations for {} lights: give one per light",
                c_configs.len(),
                c_lights.len()
            ),
        ));
    }
    let frame = HrtsFrame {
        struct_size: size_of::<HrtsFrame>() as u32,
        command_buffer: 0,
        frame_index: 0,
        view: view.view.to_cols_array(),
        proj: view.proj.to_cols_array(),
        camera_position: view.camera_position.to_array(),
        lights: c_lights.as_ptr(),
        light_count: c_lights.len() as u32,
        depth_layout: 0,
        normal_layout: 0,
        output_layout_before: 0,
        output_layout_after: 0,
        bounds: view.casters.map_or([0.0; 6], Bounds::to_c),
        has_bounds: view.casters.is_some().into(),
        deformed: std::ptr::null(),
        deformed_count: 0,
        light_stride: size_of::<crate::types::HrtsLight>(),
        deformed_stride: size_of::<crate::types::HrtsMeshVertices>(),
    };
    let mut plans = vec![
        HrtsLightPlan {
            struct_size: size_of::<HrtsLightPlan>() as u32,
            decision: 0,
            frusta: 0,
            frusta_culled: 0,
            mode: 0,
            decision_reason: [0; 128],
            passes: 0,
            resources: 0,
            map_size: 0,
        };
        c_lights.len()
    ];
    let configs_ptr = c_configs
        .first()
        .map_or(std::ptr::null(), |c| c as *const _);
    // SAFETY: the configurations and plans hold one struct per light, each with its size set; the frame
    // points at the lights, which outlive the call.
    check(CALL, unsafe {
        crate::hrts_plan_lights(configs_ptr, &frame, plans.as_mut_ptr())
    })?;
    plans
        .iter()
        .zip(lights)
        .map(|(p, light)| {
            let frusta = (p.frusta + p.frusta_culled) as usize;
            Ok(LightPlan {
                decision: decode(CALL, "decision", p.decision)?,
                frusta: p.frusta,
                frusta_culled: p.frusta_culled,
                mode: decode(CALL, "mode", p.mode)?,
                reason: c_chars(&p.decision_reason),
                passes: PassMask::from_bits(CALL, "passes", p.passes)?,
                resources: ResourceSet::from_bits(CALL, "resources", p.resources)?,
                map_size: p.map_size,
                frustum_names: match light {
                    _ if frusta == 0 => &[],
                    Light::Point { .. } if frusta == 1 => &passes::CUBE_MAP_NAME,
                    _ => passes::frustum_names(frusta),
                },
            })
        })
        .collect()
}

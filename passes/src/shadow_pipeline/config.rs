//! What a pipeline is asked to compute ([`ShadowConfig`]), for which camera and light ([`FrameInputs`]),
//! from which engine images ([`ShadowInputs`]).

use crate::area::AreaConfig;
use crate::frame_plan::{FramePlan, PassId, PlanRequest, ResourceId, ResourceSet, ShadowMode};
use crate::hybrid::HybridConfig;
use crate::light::Light;
use crate::pcss::PcssConfig;
use crate::primitive_map::PrimitiveMapConfig;
use crate::shadow_map::ShadowMapConfig;
#[cfg(doc)]
use crate::surface::NormalEncoding;
use crate::surface::SurfaceInput;
use glam::{Mat4, Vec3};
use rhi::Image;

/// Camera and light of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameInputs {
    /// World to view.
    pub view: Mat4,
    /// View to clip, Vulkan conventions (depth 0..1): the projection that wrote the depth image, reversed
    /// or standard Z, finite or infinite far plane.
    pub proj: Mat4,
    /// Camera position in world space.
    pub camera_position: Vec3,
    /// The light.
    pub light: Light,
}

/// What the pipeline computes and how: the requested outputs (per light: none, hard, soft, hybrid or area;
/// antialiasing), what may be cached across frames, and the settings of each technique.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowConfig {
    /// The light's shadow mode (default hybrid).
    pub mode: ShadowMode,
    /// FXAA over the ray-traced visibility (default on; no effect without a ray-traced shadow).
    pub antialiasing: bool,
    /// The vertex and index buffers do not change between frames: the prim buffer is built once
    /// (default true). When false it is rebuilt every frame, and everything downstream with it.
    pub static_geometry: bool,
    /// The light does not move: with static geometry, the shadow map and the primitive map are kept from
    /// the frame that built them for as long as the frame's light equals that frame's (default false).
    pub static_light: bool,
    /// The deep primitive map.
    pub map: PrimitiveMapConfig,
    /// The shadow map.
    pub shadow_map: ShadowMapConfig,
    /// PCSS.
    pub pcss: PcssConfig,
    /// The hybrid blend.
    pub hybrid: HybridConfig,
    /// Area shadows (the light's size is `pcss.angular_radius`, as for PCSS and the hybrid).
    pub area: AreaConfig,
    /// Resources to produce besides the final output (comparison views, debug images, a host G-buffer
    /// drawing the prim buffer). Empty by default.
    pub extra_outputs: ResourceSet,
    /// The most frames recorded and not yet completed on the GPU (1..=[`MAX_FRAMES_IN_FLIGHT`](crate::MAX_FRAMES_IN_FLIGHT), default 3):
    /// when frame `f` is begun, every frame up to `f - frames_in_flight` has completed. Per-frame
    /// read-backs and timers are ring-buffered this deep, and replaced GPU objects are held as long.
    pub frames_in_flight: u32,
}

impl Default for ShadowConfig {
    /// The talk's full technique: hybrid with FXAA, 1K×1K×32 primitive map, 3K shadow map, shrinking PCSS.
    fn default() -> Self {
        Self {
            mode: ShadowMode::Hybrid,
            antialiasing: true,
            static_geometry: true,
            static_light: false,
            map: PrimitiveMapConfig::default(),
            shadow_map: ShadowMapConfig::default(),
            pcss: PcssConfig::default(),
            hybrid: HybridConfig::default(),
            area: AreaConfig::default(),
            extra_outputs: ResourceSet::EMPTY,
            frames_in_flight: 3,
        }
    }
}

impl From<PrimitiveMapConfig> for ShadowConfig {
    /// A primitive-map configuration alone asks for ray-traced hard shadows without antialiasing: the
    /// output is the exact ray-traced visibility.
    fn from(map: PrimitiveMapConfig) -> Self {
        Self {
            mode: ShadowMode::Hard,
            antialiasing: false,
            map,
            ..Self::default()
        }
    }
}

impl ShadowConfig {
    /// Whether a point light under this configuration is shadowed as one cube map
    /// ([`PrimitiveMapConfig::cube`]): hard, area or auto shadows (or none) with compute binning. Soft and
    /// hybrid shadows need a shadow map per frustum: such a point light is shadowed through its six faces as
    /// spot lights, and the minimum over them.
    pub fn shadows_point_as_cube(&self) -> bool {
        matches!(
            self.mode,
            ShadowMode::Hard | ShadowMode::None | ShadowMode::Area | ShadowMode::Auto
        ) && matches!(
            self.map.binning,
            crate::BinningRequest::Auto | crate::BinningRequest::Compute
        ) && self.map.faces == crate::FaceMode::Both
    }

    /// The size of a light under this configuration, by its kind: the angular radius of a `directional`
    /// light (`pcss.angular_radius`, radians), else the radius of the spot or point light's emitter
    /// (`pcss.spot_radius`, world units).
    pub fn light_size(&self, directional: bool) -> f32 {
        if directional {
            self.pcss.angular_radius
        } else {
            self.pcss.spot_radius
        }
    }

    /// The size of the light whose segments the output of this configuration traces, once resolved
    /// ([`ShadowConfig::resolved`]) for a `directional` light or a spot or point light: 0 for hard shadows
    /// (and none), the light's size ([`ShadowConfig::light_size`]) for area shadows. `None` for the
    /// shadow-map modes (soft, hybrid), whose filters reach past those segments. A frustum whose receivers
    /// in view no caster can block along such segments is not recorded ([`crate::ViewVolume::may_shadow`]).
    pub fn traced_light_size(&self, directional: bool) -> Option<f32> {
        match self.resolved(directional).mode {
            ShadowMode::Hard | ShadowMode::None => Some(0.0),
            ShadowMode::Area => Some(self.light_size(directional)),
            ShadowMode::Soft | ShadowMode::Hybrid | ShadowMode::Auto => None,
        }
    }

    /// This configuration for one light, `directional` or a spot or point light: [`ShadowMode::Auto`]
    /// resolved by the light's size ([`ShadowConfig::light_size`], [`ShadowMode::for_light_size`]): hard
    /// shadows for a light of zero size, area shadows for a sized one. Any other mode is kept.
    pub fn resolved(&self, directional: bool) -> Self {
        match self.mode {
            ShadowMode::Auto => Self {
                mode: ShadowMode::for_light_size(self.light_size(directional)),
                ..*self
            },
            _ => *self,
        }
    }

    /// Why [`ShadowConfig::resolved`] gives the light its mode, for reports: "auto: hard (zero-size light)"
    /// or "auto: area (sized light)"; `None` for a mode given as it is.
    pub fn auto_reason(&self, directional: bool) -> Option<&'static str> {
        (self.mode == ShadowMode::Auto).then(|| match self.resolved(directional).mode {
            ShadowMode::Area => "auto: area (sized light)",
            _ => "auto: hard (zero-size light)",
        })
    }

    /// The primitive map a pipeline of this (resolved) configuration builds, with the plugin's choices of N
    /// and list limit made for its trace ([`PrimitiveMapConfig::for_nearest_hit`] where the trace finds
    /// each ray's nearest blocker, the hybrid's blocker distance); `None` if its plan has no primitive map.
    pub fn built_map(&self) -> Option<PrimitiveMapConfig> {
        let plan = FramePlan::derive(self.plan_request());
        let nearest_hit = plan
            .writes(PassId::RayTrace)
            .contains(ResourceId::BlockerDistance);
        plan.runs(PassId::PrimitiveMap).then(|| {
            if nearest_hit {
                self.map.for_nearest_hit()
            } else {
                self.map.with_size_for(false)
            }
        })
    }

    /// The frame-plan request of this configuration.
    pub fn plan_request(&self) -> PlanRequest {
        PlanRequest {
            mode: self.mode,
            antialiasing: self.antialiasing,
            filter: self.pcss.filter,
            extra_outputs: self.extra_outputs,
        }
    }
}

/// The engine's images the pipeline reads, bound at creation.
pub struct ShadowInputs<'a> {
    /// Depth as `FrameInputs::proj` writes it (any [`rhi::Format::DEPTH`] format, sampled through its depth
    /// aspect), or a linear view-Z image (`R32Float` or `R16Float`: the view-space z of `FrameInputs::view`;
    /// 0, non-finite or of magnitude 65504 or more on background), `ShaderResource` state when the passes run.
    pub depth: &'a Image,
    /// The engine's normal image, as `surface` says it encodes the normal (for
    /// [`NormalEncoding::FromDepth`], any image: it is bound but not read), `ShaderResource` state.
    pub normal: &'a Image,
    /// How `normal` encodes the surface normal and in which space.
    pub surface: SurfaceInput,
    /// An engine's image (`R32_SFLOAT`, one layer, storage usage, of the depth image's size; typically a layer
    /// of its output, `Device::external_image_layer`) that the pass producing the final visibility writes
    /// directly, instead of an image of the pipeline's own that is then copied (none: its own). Its former
    /// contents are discarded; it is left in `UnorderedAccess` state.
    pub direct_output: Option<&'a Image>,
    /// Which of the geometry's sets of map build scratch the primitive map takes (modulo
    /// [`crate::MAP_SCRATCH_SETS`]): pipelines whose lists a [`crate::ListBatch`] builds side by side take
    /// different sets; each set is allocated once a map takes it.
    pub scratch_set: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Auto resolves by the size of the light's own kind: a directional light's angular radius, a spot or
    /// point light's emitter radius; other modes stay.
    #[test]
    fn auto_resolves_by_the_size_of_the_lights_kind() {
        let mut auto = ShadowConfig {
            mode: ShadowMode::Auto,
            ..ShadowConfig::default()
        };
        auto.pcss.angular_radius = 0.0;
        auto.pcss.spot_radius = 0.1;
        let sun = auto.resolved(true);
        assert_eq!(sun.mode, ShadowMode::Hard);
        assert_eq!(
            sun,
            ShadowConfig {
                mode: ShadowMode::Hard,
                ..auto
            }
        );
        assert_eq!(auto.auto_reason(true), Some("auto: hard (zero-size light)"));
        assert_eq!(auto.resolved(false).mode, ShadowMode::Area);
        assert_eq!(auto.auto_reason(false), Some("auto: area (sized light)"));
        auto.pcss.angular_radius = 0.01;
        auto.pcss.spot_radius = 0.0;
        assert_eq!(auto.resolved(true).mode, ShadowMode::Area);
        assert_eq!(auto.resolved(false).mode, ShadowMode::Hard);
        let hybrid = ShadowConfig::default();
        for directional in [false, true] {
            assert_eq!(hybrid.resolved(directional), hybrid);
            assert_eq!(hybrid.auto_reason(directional), None);
        }
        assert!(auto.shadows_point_as_cube() && auto.resolved(false).shadows_point_as_cube());
    }

    /// Under the plugin's choice of N, a trace that stops at the first blocker (hard, area) gets the
    /// coarser grid, the hybrid's nearest-hit trace the finer one; a given N is kept; a mode without a
    /// primitive map builds none.
    #[test]
    fn the_built_map_takes_the_size_its_trace_chooses() {
        use crate::primitive_map::{NEAREST_HIT_MAP_SIZE, TRACED_MAP_SIZE};
        let with = |mode, size| ShadowConfig {
            mode,
            map: PrimitiveMapConfig {
                size,
                ..PrimitiveMapConfig::default()
            },
            ..ShadowConfig::default()
        };
        let size = |c: ShadowConfig| c.built_map().map(|m| m.size);
        assert_eq!(size(with(ShadowMode::Hard, 0)), Some(TRACED_MAP_SIZE));
        assert_eq!(size(with(ShadowMode::Area, 0)), Some(TRACED_MAP_SIZE));
        assert_eq!(
            size(with(ShadowMode::Hybrid, 0)),
            Some(NEAREST_HIT_MAP_SIZE)
        );
        assert_eq!(size(ShadowConfig::default()), Some(NEAREST_HIT_MAP_SIZE));
        assert_eq!(size(with(ShadowMode::Soft, 0)), None);
        for mode in [ShadowMode::Hard, ShadowMode::Area, ShadowMode::Hybrid] {
            assert_eq!(size(with(mode, 300)), Some(300));
        }
    }
}

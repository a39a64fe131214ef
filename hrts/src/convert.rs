//! Conversion between the C types and the Rust ones, checking every value.

use crate::error::{invalid, ApiError, ApiResult};
use crate::types::*;
use crate::version::read_elements;
use glam::{Mat4, Vec3};
use passes::{
    BinningPath, BinningRequest, FaceMode, FrameInputs, Light, NormalEncoding, NormalSpace, PassId,
    PenumbraFilter, PrimitiveMapConfig, ResourceId, ResourceSet, ShadowConfig, ShadowMode,
    SurfaceInput,
};
use rhi::ImageUsage;

pub(crate) fn finite(values: &[f32], what: &str) -> ApiResult<()> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(invalid(format!("{what} contains NaN or infinity")))
    }
}

/// The plugin's resources by their C value (`HrtsResource`), in that order.
pub(crate) const RESOURCES: [ResourceId; HRTS_RESOURCE_COUNT] = [
    ResourceId::ShadowMap,
    ResourceId::PrimListOffsets,
    ResourceId::PrimListEntries,
    ResourceId::Occupancy,
    ResourceId::RtVisibility,
    ResourceId::BlockerDistance,
    ResourceId::ShadowMapVisibility,
    ResourceId::Pcss,
    ResourceId::RtAntialiased,
    ResourceId::LerpFactor,
    ResourceId::Hybrid,
    ResourceId::Lit,
];

/// The pipeline's passes by their C value (`HrtsPass`); `HRTS_PASS_OUTPUT_COPY` is the context's own.
pub(crate) fn pass_from_index(index: u32) -> Option<PassId> {
    PassId::ALL.get(index as usize).copied()
}

fn image_usage(vk_usage: u32) -> ImageUsage {
    const TRANSFER_SRC: u32 = 0x1;
    const TRANSFER_DST: u32 = 0x2;
    const SAMPLED: u32 = 0x4;
    const STORAGE: u32 = 0x8;
    const COLOR: u32 = 0x10;
    const DEPTH: u32 = 0x20;
    let mut u = ImageUsage::default();
    for (bit, ours) in [
        (TRANSFER_SRC, ImageUsage::COPY_SRC),
        (TRANSFER_DST, ImageUsage::COPY_DST),
        (SAMPLED, ImageUsage::SAMPLED),
        (STORAGE, ImageUsage::STORAGE),
        (COLOR, ImageUsage::COLOR_TARGET),
        (DEPTH, ImageUsage::DEPTH_TARGET),
    ] {
        if vk_usage & bit != 0 {
            u = u | ours;
        }
    }
    u
}

pub(crate) fn require_usage(
    vk_usage: u32,
    needed: ImageUsage,
    what: &str,
    needed_name: &str,
) -> ApiResult<ImageUsage> {
    let usage = image_usage(vk_usage);
    if !usage.contains(needed) {
        return Err(ApiError::new(
            HrtsResult::ErrorImageUsage,
            format!("{what} was not created with {needed_name} usage (usage flags 0x{vk_usage:x})"),
        ));
    }
    Ok(usage)
}

pub(crate) fn mat4(m: &[f32; 16]) -> Mat4 {
    Mat4::from_cols_array(m)
}

pub(crate) fn resource_id(value: u32) -> ApiResult<ResourceId> {
    RESOURCES.get(value as usize).copied().ok_or_else(|| {
        ApiError::new(
            HrtsResult::ErrorInvalidEnum,
            format!("resource {value} is not a HrtsResource value"),
        )
    })
}

pub(crate) fn resource_index(id: ResourceId) -> ApiResult<u32> {
    RESOURCES
        .iter()
        .position(|&r| r == id)
        .map(|i| i as u32)
        .ok_or_else(|| {
            ApiError::new(
                HrtsResult::ErrorInternal,
                format!("{} has no HrtsResource value", id.name()),
            )
        })
}

/// The camera and each light of a frame (every field checked): per light, one `FrameInputs` per frustum
/// it is shadowed through. `scene_bounds` are the bounds a directional light without a `view_proj` is
/// fitted to (`None`: unknown this frame).
pub(crate) fn frame_inputs(
    f: &HrtsFrame,
    scene_bounds: Option<[glam::DVec3; 2]>,
) -> ApiResult<Vec<FrameLight>> {
    finite(&f.view, "view")?;
    finite(&f.proj, "proj")?;
    finite(&f.camera_position, "camera_position")?;
    if f.light_count == 0 || f.light_count > HRTS_MAX_LIGHTS {
        return Err(invalid(format!(
            "light_count {} must be within 1..={HRTS_MAX_LIGHTS}",
            f.light_count
        )));
    }
    let lights = read_elements(f.lights, f.light_count as usize, f.light_stride, "lights")?;
    lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let (kind, range, frusta) = light_frusta(l, i, scene_bounds)?;
            Ok(FrameLight {
                frusta: frusta
                    .into_iter()
                    .map(|light| FrameInputs {
                        view: mat4(&f.view),
                        proj: mat4(&f.proj),
                        camera_position: Vec3::from_array(f.camera_position),
                        light,
                    })
                    .collect(),
                kind,
                range,
            })
        })
        .collect()
}

/// How the engine's normal image encodes the normal (`normal_encoding`, `normal_space`).
pub(crate) fn surface_input(t: &HrtsTargets) -> ApiResult<SurfaceInput> {
    normal_input(t.normal_encoding, t.normal_space)
}

/// The passes' reading of normals of `HrtsNormalEncoding` `encoding` in `HrtsNormalSpace` `space`.
pub(crate) fn normal_input(encoding: u32, space: u32) -> ApiResult<SurfaceInput> {
    let encoding = enum_value(
        encoding,
        &[
            (
                HrtsNormalEncoding::XyzCoverage as u32,
                NormalEncoding::XyzCoverage,
            ),
            (HrtsNormalEncoding::Xyz as u32, NormalEncoding::Xyz),
            (
                HrtsNormalEncoding::Octahedral as u32,
                NormalEncoding::Octahedral,
            ),
            (HrtsNormalEncoding::None as u32, NormalEncoding::FromDepth),
        ],
        "normal_encoding",
        "HrtsNormalEncoding",
    )?;
    let space = enum_value(
        space,
        &[
            (HrtsNormalSpace::World as u32, NormalSpace::World),
            (HrtsNormalSpace::View as u32, NormalSpace::View),
        ],
        "normal_space",
        "HrtsNormalSpace",
    )?;
    Ok(SurfaceInput { encoding, space })
}

/// The frame's geometry bounds, when the engine gives them (`has_bounds`).
pub(crate) fn frame_bounds(f: &HrtsFrame) -> ApiResult<Option<[glam::DVec3; 2]>> {
    if f.has_bounds == 0 {
        return Ok(None);
    }
    bounds(&f.bounds).map(Some)
}

/// World-space bounds of shadow casters given as min xyz, max xyz: finite, min not above max on any
/// axis (an empty or inverted box holds no triangle), and not all six zero (the box of a zero-initialised
/// struct, which would cull every light whose shadows do not reach the origin).
pub(crate) fn bounds(b: &[f32; 6]) -> ApiResult<[glam::DVec3; 2]> {
    finite(b, "bounds")?;
    if b.iter().all(|&v| v == 0.0) {
        return Err(invalid(
            "bounds are all zero (a zero-initialised struct?): give min xyz and max xyz of every shadow caster",
        ));
    }
    let lo = Vec3::from_slice(&b[..3]).as_dvec3();
    let hi = Vec3::from_slice(&b[3..]).as_dvec3();
    if lo.cmpgt(hi).any() {
        return Err(invalid(format!(
            "bounds are empty or inverted: min {lo} exceeds max {hi} (give min xyz, then max xyz)"
        )));
    }
    Ok([lo, hi])
}

/// One light of a frame: the frusta it is shadowed through (the camera in each), its type and range.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FrameLight {
    pub(crate) frusta: Vec<FrameInputs>,
    pub(crate) kind: HrtsLightType,
    /// The range of a spot or point light (`None`: unlimited, or a directional light).
    pub(crate) range: Option<f32>,
}

impl FrameLight {
    /// The name of frustum `frustum` in reports: a point light's cube face, a wide spot light's face, a
    /// point light's whole cube.
    pub(crate) fn frustum_name(&self, frustum: usize) -> &'static str {
        if self.is_cube() {
            return passes::CUBE_MAP_NAME[0];
        }
        passes::frustum_names(self.frusta.len())
            .get(frustum)
            .copied()
            .unwrap_or("whole")
    }

    /// Whether the light is a point light shadowed as one cube map.
    pub(crate) fn is_cube(&self) -> bool {
        matches!(self.frusta.as_slice(), [one] if matches!(one.light, Light::Point { .. }))
    }

    /// How the light is shadowed: its frusta, whether the one is a cube, and whether it is directional.
    pub(crate) fn shape(&self) -> LightShape {
        LightShape {
            frusta: self.frusta.len(),
            cube: self.is_cube(),
            directional: self.kind == HrtsLightType::Directional,
        }
    }

    /// The light as `config` shadows it: a point light whose configuration allows it
    /// ([`ShadowConfig::shadows_point_as_cube`]) as one cube map instead of its six faces.
    pub(crate) fn shadowed_as(mut self, config: &ShadowConfig) -> Self {
        if self.kind == HrtsLightType::Point && config.shadows_point_as_cube() {
            if let Some(first) = self.frusta.first().cloned() {
                if let Some(position) = first.light.position() {
                    self.frusta = vec![FrameInputs {
                        light: Light::Point {
                            position,
                            range: self.range,
                        },
                        ..first
                    }];
                }
            }
        }
        self
    }
}

/// The type, range and frusta of `lights[index]` (every field checked): the light as given, or the
/// frusta the plugin fits to a point light, or to a spot or directional light without a `view_proj` (a
/// directional light's to `scene_bounds`, which must then be known).
fn light_frusta(
    l: &HrtsLight,
    index: usize,
    scene_bounds: Option<[glam::DVec3; 2]>,
) -> ApiResult<(HrtsLightType, Option<f32>, Vec<Light>)> {
    let field = |name: &str| format!("lights[{index}].{name}");
    finite(&l.direction, &field("direction"))?;
    finite(&l.view_proj, &field("view_proj"))?;
    finite(&l.position, &field("position"))?;
    let kind = enum_value(
        l.light_type,
        &[
            (
                HrtsLightType::Directional as u32,
                HrtsLightType::Directional,
            ),
            (HrtsLightType::Spot as u32, HrtsLightType::Spot),
            (HrtsLightType::Point as u32, HrtsLightType::Point),
        ],
        &field("light_type"),
        "HrtsLightType",
    )?;
    let position = Vec3::from_array(l.position);
    if kind != HrtsLightType::Directional && !(l.range.is_finite() && l.range >= 0.0) {
        return Err(invalid(format!(
            "{} must be 0 (unlimited) or a positive finite distance, got {}",
            field("range"),
            l.range
        )));
    }
    let range = (l.range > 0.0 && kind != HrtsLightType::Directional).then_some(l.range);
    if kind == HrtsLightType::Point {
        return Ok((
            kind,
            range,
            passes::point_light_faces(position, range).to_vec(),
        ));
    }
    let direction = Vec3::from_array(l.direction);
    if direction.length_squared() == 0.0 {
        return Err(invalid(format!("{} is zero", field("direction"))));
    }
    let fitted = l.view_proj.iter().all(|&x| x == 0.0);
    if kind == HrtsLightType::Spot && fitted {
        if !(l.outer_cone > 0.0 && l.outer_cone <= std::f32::consts::FRAC_PI_2) {
            return Err(invalid(format!(
                "{} must be within (0, pi/2] radians for a spot light whose frusta the plugin fits, got {}",
                field("outer_cone"),
                l.outer_cone
            )));
        }
        return Ok((
            kind,
            range,
            passes::spot_light_frusta(position, direction, l.outer_cone, range),
        ));
    }
    if kind == HrtsLightType::Directional && fitted {
        let Some([lo, hi]) = scene_bounds else {
            return Err(invalid(format!(
                "{} is all zeros: the plugin fits a directional light's frustum to the shadow casters' bounds, and this \
                 frame has none (Vulkan geometry that moves or is deformed has no bounds of its own): give the \
                 frame's bounds (has_bounds) or the light's view_proj",
                field("view_proj")
            )));
        };
        let light = passes::directional_light_frustum(direction, [lo.as_vec3(), hi.as_vec3()])
            .map_err(|e| invalid(format!("{}: {e}", field("view_proj"))))?;
        return Ok((kind, range, vec![light]));
    }
    let view_proj = mat4(&l.view_proj);
    // Passed on as given: the passes normalise in f64 (normalising here in f32 would round twice).
    let light = if kind == HrtsLightType::Spot {
        Light::Spot {
            position,
            direction,
            view_proj,
        }
    } else {
        Light::Directional {
            direction,
            view_proj,
        }
    };
    Ok((kind, range, vec![light]))
}

pub(crate) fn enum_value<T>(
    value: u32,
    variants: &[(u32, T)],
    field: &str,
    type_name: &str,
) -> ApiResult<T>
where
    T: Copy,
{
    variants
        .iter()
        .find(|(v, _)| *v == value)
        .map(|(_, t)| *t)
        .ok_or_else(|| {
            ApiError::new(
                HrtsResult::ErrorInvalidEnum,
                format!("{field} {value} is not a {type_name} value"),
            )
        })
}

fn positive(value: f32, field: &str) -> ApiResult<f32> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(invalid(format!(
            "{field} must be a positive finite number, got {value}"
        )))
    }
}

fn non_negative(value: f32, field: &str) -> ApiResult<f32> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(invalid(format!(
            "{field} must be a non-negative finite number, got {value}"
        )))
    }
}

fn taps(value: u32, field: &str) -> ApiResult<u32> {
    if (1..=256).contains(&value) {
        Ok(value)
    } else {
        Err(invalid(format!(
            "{field} must be within 1..=256, got {value}"
        )))
    }
}

/// The `HrtsShadowMode` value of `mode`.
pub(crate) fn mode_to_c(mode: ShadowMode) -> u32 {
    MODES
        .iter()
        .find(|(_, m)| *m == mode)
        .map_or(HrtsShadowMode::Auto as u32, |(c, _)| *c)
}

/// The passes' mode of `mode`.
pub(crate) fn mode_from_c(mode: HrtsShadowMode) -> ShadowMode {
    MODES
        .iter()
        .find(|(c, _)| *c == mode as u32)
        .map_or(ShadowMode::Auto, |&(_, m)| m)
}

/// `HrtsShadowMode` values and the modes they name (both directions use this one table).
const MODES: [(u32, ShadowMode); 6] = [
    (HrtsShadowMode::None as u32, ShadowMode::None),
    (HrtsShadowMode::Hard as u32, ShadowMode::Hard),
    (HrtsShadowMode::Soft as u32, ShadowMode::Soft),
    (HrtsShadowMode::Hybrid as u32, ShadowMode::Hybrid),
    (HrtsShadowMode::Area as u32, ShadowMode::Area),
    (HrtsShadowMode::Auto as u32, ShadowMode::Auto),
];

/// `HrtsFaces` values.
const FACES: [(u32, FaceMode); 2] = [
    (HrtsFaces::Both as u32, FaceMode::Both),
    (HrtsFaces::FrontOnly as u32, FaceMode::FrontOnly),
];

/// The C value of a binning path in use.
pub(crate) fn binning_path_to_c(path: BinningPath) -> HrtsBinningPath {
    match path {
        BinningPath::Compute => HrtsBinningPath::Compute,
        BinningPath::Hardware(_) => HrtsBinningPath::Hardware,
        BinningPath::Software => HrtsBinningPath::Software,
        BinningPath::EmulatedTier1 { .. } => HrtsBinningPath::EmulatedTier1,
    }
}

/// `HrtsBinningPath` values as requests.
const BINNING_REQUESTS: [(u32, BinningRequest); 5] = [
    (HrtsBinningPath::Auto as u32, BinningRequest::Auto),
    (HrtsBinningPath::Compute as u32, BinningRequest::Compute),
    (HrtsBinningPath::Hardware as u32, BinningRequest::Hardware),
    (HrtsBinningPath::Software as u32, BinningRequest::Software),
    (
        HrtsBinningPath::EmulatedTier1 as u32,
        BinningRequest::EmulateTier1,
    ),
];

/// `HrtsPenumbraFilter` values.
const FILTERS: [(u32, PenumbraFilter); 2] = [
    (
        HrtsPenumbraFilter::Shrinking as u32,
        PenumbraFilter::Shrinking,
    ),
    (
        HrtsPenumbraFilter::Standard as u32,
        PenumbraFilter::Standard,
    ),
];

/// The C value of `value` in `table` (every table covers its whole Rust enum).
fn c_value<T: PartialEq>(value: T, table: &[(u32, T)]) -> u32 {
    table
        .iter()
        .find(|(_, t)| *t == value)
        .map_or(u32::MAX, |&(c, _)| c)
}

/// The plugin's configuration from the C one (every field checked).
pub(crate) fn shadow_config(c: &HrtsConfig) -> ApiResult<ShadowConfig> {
    let mode = enum_value(c.mode, &MODES, "mode", "HrtsShadowMode")?;
    let faces = enum_value(c.faces, &FACES, "faces", "HrtsFaces")?;
    let binning = enum_value(
        c.binning_path,
        &BINNING_REQUESTS,
        "binning_path",
        "HrtsBinningPath",
    )?;
    if u64::from(c.map_entry_budget_kib) << 10 < passes::MIN_ENTRY_BUDGET {
        return Err(invalid(format!(
            "map_entry_budget_kib {} is below the minimum of {}",
            c.map_entry_budget_kib,
            passes::MIN_ENTRY_BUDGET >> 10
        )));
    }
    let filter = enum_value(c.pcss_filter, &FILTERS, "pcss_filter", "HrtsPenumbraFilter")?;
    if c.extra_outputs >> HRTS_RESOURCE_COUNT != 0 {
        return Err(ApiError::new(
            HrtsResult::ErrorInvalidEnum,
            format!(
                "extra_outputs 0x{:x} has bits of no HrtsResource",
                c.extra_outputs
            ),
        ));
    }
    let extra_outputs = RESOURCES
        .iter()
        .enumerate()
        .filter(|(i, _)| c.extra_outputs & 1 << i != 0)
        .fold(ResourceSet::EMPTY, |set, (_, &r)| set.with(r));
    let mut config = ShadowConfig {
        mode,
        antialiasing: c.antialiasing != 0,
        static_light: c.static_light != 0,
        static_geometry: c.dynamic_geometry == 0,
        extra_outputs,
        map: PrimitiveMapConfig {
            size: c.map_size,
            faces,
            binning,
            entry_budget: u64::from(c.map_entry_budget_kib) << 10,
            guard: c.guard_entries != 0,
            receiver_culling: c.debug_bin_all_texels == 0,
            initial_entries: c.map_initial_entries,
            cube: false,
            initial_pairs: c.map_initial_pairs,
            list_limit: c.map_list_limit,
            bin_budget: c.map_bin_budget,
            debug_count_scale: 1,
        },
        ..ShadowConfig::default()
    };
    config.shadow_map.size = c.shadow_map_size;
    config.shadow_map.constant_bias =
        non_negative(c.shadow_map_constant_bias, "shadow_map_constant_bias")?;
    config.shadow_map.slope_bias = non_negative(c.shadow_map_slope_bias, "shadow_map_slope_bias")?;
    config.pcss.filter = filter;
    config.pcss.max_search_radius = positive(c.pcss_max_search_radius, "pcss_max_search_radius")?;
    config.pcss.min_filter_radius =
        non_negative(c.pcss_min_filter_radius, "pcss_min_filter_radius")?;
    config.pcss.max_filter_radius = positive(c.pcss_max_filter_radius, "pcss_max_filter_radius")?;
    // A light of no size is what mode auto shadows hard; every other mode needs a size.
    let light_size = if mode == ShadowMode::Auto {
        non_negative
    } else {
        positive
    };
    config.pcss.angular_radius = light_size(c.pcss_angular_radius, "pcss_angular_radius")?;
    config.pcss.spot_radius = light_size(c.pcss_spot_radius, "pcss_spot_radius")?;
    config.pcss.blocker_search_taps = taps(c.pcss_blocker_search_taps, "pcss_blocker_search_taps")?;
    config.pcss.pcf_taps = taps(c.pcss_pcf_taps, "pcss_pcf_taps")?;
    config.hybrid.world_space_scale =
        positive(c.hybrid_world_space_scale, "hybrid_world_space_scale")?;
    config.hybrid.hard_shadow_percentage = positive(
        c.hybrid_hard_shadow_percentage,
        "hybrid_hard_shadow_percentage",
    )?;
    config.pcss.validate()?;
    config.area.samples = c.area_samples;
    config.area.bundle_walk_budget = c.area_walk_budget;
    // Mode auto gives a sized directional light area shadows.
    if mode == ShadowMode::Area || (mode == ShadowMode::Auto && config.pcss.angular_radius > 0.0) {
        config.area.validate(config.pcss.angular_radius)?;
    }
    Ok(config)
}

/// The C configuration of `config`, the inverse of [`shadow_config`]. Fails if an extra output has no
/// `HrtsResource` value.
pub(crate) fn config_to_c(config: &ShadowConfig) -> ApiResult<HrtsConfig> {
    let extra_outputs = config.extra_outputs.iter().try_fold(0u32, |bits, r| {
        resource_index(r).map(|i| bits | 1 << i).map_err(|_| {
            invalid(format!(
                "{} cannot be requested through the C ABI",
                r.name()
            ))
        })
    })?;
    Ok(HrtsConfig {
        struct_size: std::mem::size_of::<HrtsConfig>() as u32,
        mode: c_value(config.mode, &MODES),
        antialiasing: config.antialiasing.into(),
        static_light: config.static_light.into(),
        map_size: config.map.size,
        map_entry_budget_kib: (config.map.entry_budget >> 10).min(u64::from(u32::MAX)) as u32,
        faces: c_value(config.map.faces, &FACES),
        binning_path: c_value(config.map.binning, &BINNING_REQUESTS),
        shadow_map_size: config.shadow_map.size,
        pcss_angular_radius: config.pcss.angular_radius,
        pcss_spot_radius: config.pcss.spot_radius,
        pcss_blocker_search_taps: config.pcss.blocker_search_taps,
        pcss_pcf_taps: config.pcss.pcf_taps,
        hybrid_world_space_scale: config.hybrid.world_space_scale,
        hybrid_hard_shadow_percentage: config.hybrid.hard_shadow_percentage,
        pcss_filter: c_value(config.pcss.filter, &FILTERS),
        pcss_max_search_radius: config.pcss.max_search_radius,
        pcss_min_filter_radius: config.pcss.min_filter_radius,
        pcss_max_filter_radius: config.pcss.max_filter_radius,
        shadow_map_constant_bias: config.shadow_map.constant_bias,
        shadow_map_slope_bias: config.shadow_map.slope_bias,
        dynamic_geometry: (!config.static_geometry).into(),
        extra_outputs,
        guard_entries: config.map.guard.into(),
        debug_bin_all_texels: (!config.map.receiver_culling).into(),
        map_initial_entries: config.map.initial_entries,
        map_initial_pairs: config.map.initial_pairs,
        area_samples: config.area.samples,
        map_list_limit: config.map.list_limit,
        map_bin_budget: config.map.bin_budget,
        area_walk_budget: config.area.bundle_walk_budget,
    })
}

/// How a light is shadowed in a frame: through how many frusta, whether its one frustum is a point
/// light's cube map, and whether it is a directional light (mode auto chooses by the size of its kind).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct LightShape {
    pub(crate) frusta: usize,
    pub(crate) cube: bool,
    pub(crate) directional: bool,
}

impl Default for LightShape {
    /// Before any frame: one frustum of a directional light.
    fn default() -> Self {
        Self {
            frusta: 1,
            cube: false,
            directional: true,
        }
    }
}

impl LightShape {
    /// The configuration the light's passes are built with: `configured` with mode auto resolved for the
    /// light's kind, and a cube primitive map for a point light shadowed as one.
    pub(crate) fn config(&self, configured: &ShadowConfig) -> ShadowConfig {
        let mut config = configured.resolved(self.directional);
        config.map.cube = self.cube;
        config
    }
}

/// Fills `out` with the defaults of [`ShadowConfig::default`].
pub(crate) fn config_defaults(out: &mut HrtsConfig) -> ApiResult<()> {
    *out = config_to_c(&ShadowConfig::default())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c_pass_values_are_the_pipeline_order() {
        let pairs = [
            (HrtsPass::PrimBuffer, PassId::PrimBuffer),
            (HrtsPass::ShadowMap, PassId::ShadowMap),
            (HrtsPass::PrimitiveMap, PassId::PrimitiveMap),
            (HrtsPass::Occupancy, PassId::Occupancy),
            (HrtsPass::RayTrace, PassId::RayTrace),
            (HrtsPass::ShadowMapTest, PassId::ShadowMapTest),
            (HrtsPass::Pcss, PassId::Pcss),
            (HrtsPass::Fxaa, PassId::Fxaa),
            (HrtsPass::LerpFactor, PassId::LerpFactor),
            (HrtsPass::Blend, PassId::Blend),
            (HrtsPass::FillLit, PassId::FillLit),
        ];
        assert_eq!(pairs.len(), PassId::ALL.len());
        for (c, rust) in pairs {
            assert_eq!(pass_from_index(c as u32), Some(rust));
        }
        assert_eq!(pass_from_index(HrtsPass::OutputCopy as u32), None);
        assert_eq!(HrtsPass::OutputCopy as usize + 1, HRTS_PASS_COUNT);
        assert_eq!(HRTS_PASS_MASK_ALL, (1 << HRTS_PASS_COUNT) - 1);
        assert_eq!(
            HRTS_PASS_MASK_LIGHT_SPACE | HRTS_PASS_MASK_SCREEN_SPACE,
            HRTS_PASS_MASK_ALL
        );
        assert_eq!(HRTS_PASS_MASK_LIGHT_SPACE & HRTS_PASS_MASK_SCREEN_SPACE, 0);
    }

    #[test]
    fn c_resource_values_name_the_pipeline_resources() {
        let pairs = [
            (HrtsResource::ShadowMap, ResourceId::ShadowMap),
            (HrtsResource::PrimListOffsets, ResourceId::PrimListOffsets),
            (HrtsResource::PrimListEntries, ResourceId::PrimListEntries),
            (HrtsResource::Occupancy, ResourceId::Occupancy),
            (HrtsResource::RtVisibility, ResourceId::RtVisibility),
            (HrtsResource::BlockerDistance, ResourceId::BlockerDistance),
            (
                HrtsResource::ShadowMapVisibility,
                ResourceId::ShadowMapVisibility,
            ),
            (HrtsResource::Pcss, ResourceId::Pcss),
            (HrtsResource::RtAntialiased, ResourceId::RtAntialiased),
            (HrtsResource::LerpFactor, ResourceId::LerpFactor),
            (HrtsResource::Hybrid, ResourceId::Hybrid),
            (HrtsResource::Lit, ResourceId::Lit),
        ];
        assert_eq!(pairs.len(), HRTS_RESOURCE_COUNT);
        for (c, rust) in pairs {
            assert_eq!(resource_id(c as u32).ok(), Some(rust));
            assert_eq!(resource_index(rust).ok(), Some(c as u32));
        }
        assert!(resource_id(HRTS_RESOURCE_COUNT as u32).is_err());
    }

    #[test]
    fn configurations_round_trip_through_c() {
        let mut c = config_to_c(&ShadowConfig::default()).expect("defaults");
        config_defaults(&mut c).expect("defaults");
        assert_eq!(shadow_config(&c).expect("valid"), ShadowConfig::default());
        let mut other = ShadowConfig {
            mode: ShadowMode::Soft,
            antialiasing: false,
            static_geometry: false,
            static_light: true,
            extra_outputs: ResourceSet::of(&[ResourceId::RtVisibility, ResourceId::Lit]),
            ..ShadowConfig::default()
        };
        other.map.faces = FaceMode::FrontOnly;
        other.map.binning = BinningRequest::EmulateTier1;
        other.map.guard = true;
        other.pcss.filter = PenumbraFilter::Standard;
        other.shadow_map.slope_bias = 2.5;
        let c = config_to_c(&other).expect("representable");
        assert_eq!(shadow_config(&c).expect("valid"), other);
        other.extra_outputs = ResourceSet::of(&[ResourceId::PrimBuffer]);
        assert!(config_to_c(&other).is_err());
    }

    /// Mode auto takes lights of no size (radii of 0), which every other mode refuses.
    #[test]
    fn mode_auto_takes_a_light_of_no_size() {
        let mut c = config_to_c(&ShadowConfig::default()).expect("defaults");
        c.pcss_angular_radius = 0.0;
        c.pcss_spot_radius = 0.0;
        for mode in [HrtsShadowMode::Hard, HrtsShadowMode::Area] {
            c.mode = mode as u32;
            let e = shadow_config(&c).expect_err("no size refused").message;
            assert!(
                e.contains("pcss_angular_radius must be a positive finite number"),
                "{e}"
            );
        }
        c.mode = HrtsShadowMode::Auto as u32;
        let auto = shadow_config(&c).expect("auto takes no size");
        assert_eq!(auto.mode, ShadowMode::Auto);
        assert_eq!(auto.resolved(true).mode, ShadowMode::Hard);
        assert_eq!(config_to_c(&auto).expect("representable").mode, c.mode);
        c.pcss_spot_radius = -1.0;
        assert!(shadow_config(&c).is_err());
        // A sized sun may get area shadows: its size and samples are checked as for mode area.
        c.pcss_spot_radius = 0.0;
        c.pcss_angular_radius = 2.0;
        let e = shadow_config(&c).expect_err("2 rad").message;
        assert!(e.contains("angular radius"), "{e}");
    }

    fn c_light(light_type: HrtsLightType, direction: [f32; 3]) -> HrtsLight {
        HrtsLight {
            light_type: light_type as u32,
            position: [0.0; 3],
            direction,
            view_proj: [0.0; 16],
            range: 0.0,
            outer_cone: 0.0,
        }
    }

    /// A directional light without a matrix is fitted to the scene's bounds, as
    /// `passes::directional_light_frustum` fits it; without bounds, or without a direction, it is refused.
    #[test]
    fn a_directional_light_without_a_matrix_is_fitted_to_the_bounds() {
        let sun = c_light(HrtsLightType::Directional, [0.3, -1.0, 0.2]);
        let bounds = [
            glam::DVec3::new(-4.0, 0.0, -3.0),
            glam::DVec3::new(4.0, 2.5, 5.0),
        ];
        let (kind, range, frusta) = light_frusta(&sun, 0, Some(bounds)).expect("fitted");
        assert_eq!((kind, range), (HrtsLightType::Directional, None));
        let expected = passes::directional_light_frustum(
            Vec3::new(0.3, -1.0, 0.2),
            [bounds[0].as_vec3(), bounds[1].as_vec3()],
        )
        .expect("fits");
        assert_eq!(frusta, [expected]);
        let e = light_frusta(&sun, 2, None).expect_err("no bounds").message;
        assert!(
            e.contains("lights[2].view_proj") && e.contains("bounds") && e.contains("has_bounds"),
            "{e}"
        );
        let dark = c_light(HrtsLightType::Directional, [0.0; 3]);
        let e = light_frusta(&dark, 0, Some(bounds))
            .expect_err("no direction")
            .message;
        assert!(e.contains("lights[0].direction is zero"), "{e}");
        // A matrix given is kept.
        let mut given = sun;
        given.view_proj = expected.view_proj().to_cols_array();
        given.view_proj[12] += 0.5;
        let (_, _, frusta) = light_frusta(&given, 0, None).expect("given");
        assert_eq!(frusta[0].view_proj().to_cols_array(), given.view_proj);
    }

    /// Bounds of shadow casters: a box, possibly flat or a point; refused when not finite, empty or
    /// inverted, or all zero (a zero-initialised struct).
    #[test]
    fn bounds_must_be_a_box_of_casters() {
        let b = bounds(&[-1.0, 0.0, -2.0, 1.0, 3.0, 2.0]).expect("a box");
        assert_eq!(
            b,
            [
                glam::DVec3::new(-1.0, 0.0, -2.0),
                glam::DVec3::new(1.0, 3.0, 2.0)
            ]
        );
        bounds(&[-1.0, 0.0, -2.0, 1.0, 0.0, 2.0]).expect("a flat box");
        bounds(&[1.0, 2.0, 3.0, 1.0, 2.0, 3.0]).expect("a point");
        let e = bounds(&[0.0; 6]).expect_err("all zero").message;
        assert!(
            e.contains("all zero") && e.contains("zero-initialised"),
            "{e}"
        );
        let e = bounds(&[0.0, 0.0, 0.0, -0.0, 0.0, 0.0])
            .expect_err("all zero")
            .message;
        assert!(e.contains("all zero"), "{e}");
        let e = bounds(&[5.0, 0.0, -2.0, 1.0, 3.0, 2.0])
            .expect_err("inverted")
            .message;
        assert!(e.contains("empty or inverted") && e.contains("min"), "{e}");
        let e = bounds(&[f32::INFINITY, 0.0, 0.0, -f32::INFINITY, 1.0, 1.0])
            .expect_err("empty")
            .message;
        assert!(e.contains("NaN or infinity"), "{e}");
        let e = bounds(&[0.0, f32::NAN, 0.0, 1.0, 1.0, 1.0])
            .expect_err("NaN")
            .message;
        assert!(e.contains("NaN or infinity"), "{e}");
    }
}

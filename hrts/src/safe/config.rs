//! [`Config`]: one light's configuration (`HrtsConfig`).

use super::enums::{decode, BinningPath, Faces, PenumbraFilter, ResourceSet, ShadowMode};
use super::error::{check, Result};
use crate::types::HrtsConfig;

/// One light's configuration: what the plugin computes and with which settings. Each field is the
/// `HrtsConfig` field of the same name (its documentation in `hrts.h` states ranges and versions).
/// [`Config::default`] is what `hrts_config_defaults` fills: hybrid shadows with FXAA, the plugin's choice
/// of primitive map N (1024 for the hybrid), both faces, automatic binning, 3K shadow map, shrinking PCSS. A configuration is checked
/// when it is given to [`Context::configure_lights`](crate::Context::configure_lights).
///
/// ```
/// use hrts::{Config, ShadowMode};
///
/// let config = Config {
///     mode: ShadowMode::Hard,
///     antialiasing: false,
///     map_size: 2048,
///     ..Config::default()
/// };
/// assert_eq!(Config::default().mode, ShadowMode::Hybrid);
/// assert_ne!(config, Config::default());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Config {
    /// What the plugin computes; the frame plan runs only the passes it needs (default hybrid).
    pub mode: ShadowMode,
    /// FXAA over the ray-traced shadow (default true).
    pub antialiasing: bool,
    /// The light does not move between frames: the shadow map is kept (default false).
    pub static_light: bool,
    /// Primitive map N: texels per side of the light-space grid fitted to the receivers each frame,
    /// 1..=[`Capabilities::max_map_size`](crate::Capabilities::max_map_size), or 0 (the default) for the
    /// plugin's choice by trace: 512 for hard and area shadows, 1024 for the hybrid
    /// ([`MapStats::map_size`](crate::MapStats::map_size) says which). It moves cost, never exactness.
    pub map_size: u32,
    /// Largest memory of the primitive map's list entries in KiB, at least 4 (default 262144).
    pub map_entry_budget_kib: u32,
    /// Which faces the primitive map stores (default both).
    pub faces: Faces,
    /// The conservative-rasterization path (default auto).
    pub binning_path: BinningPath,
    /// Shadow map size (default 3072).
    pub shadow_map_size: u32,
    /// Angular radius of a directional emitter in radians (default 0.02): PCSS, area shadows. Positive;
    /// 0 (a light of no size) only with [`ShadowMode::Auto`].
    pub pcss_angular_radius: f32,
    /// Radius of a spot or point light's spherical emitter in world units (default 0.05). Positive; 0
    /// only with [`ShadowMode::Auto`].
    pub pcss_spot_radius: f32,
    /// PCSS blocker-search taps (default 16).
    pub pcss_blocker_search_taps: u32,
    /// PCSS PCF taps (default 32).
    pub pcss_pcf_taps: u32,
    /// Hybrid blend: world-space scale WSS (default 1).
    pub hybrid_world_space_scale: f32,
    /// Hybrid blend: percentage of hard shadow PHS (default 4).
    pub hybrid_hard_shadow_percentage: f32,
    /// How PCSS shapes the penumbra (default shrinking).
    pub pcss_filter: PenumbraFilter,
    /// PCSS: largest blocker-search radius in shadow-map texels (default 48).
    pub pcss_max_search_radius: f32,
    /// PCSS: smallest PCF radius in texels (default 1).
    pub pcss_min_filter_radius: f32,
    /// PCSS: largest PCF radius in texels (default 32).
    pub pcss_max_filter_radius: f32,
    /// Classic shadow-map test: constant depth bias in texels of world size (default 1).
    pub shadow_map_constant_bias: f32,
    /// Classic shadow-map test: slope-scaled depth bias (default 1).
    pub shadow_map_slope_bias: f32,
    /// The geometry changes every frame: the prim buffer is rebuilt each frame (default false).
    pub dynamic_geometry: bool,
    /// Resources to produce besides those the mode needs, to read back with
    /// [`Context::record_resource_readback`](crate::Context::record_resource_readback) (default none).
    pub extra_outputs: ResourceSet,
    /// Debug: guard words after the list entries that show any write past the capacity (default false).
    pub guard_entries: bool,
    /// Debug: bin every texel of the fitted grid and keep triangles behind every ray origin (default
    /// false).
    pub debug_bin_all_texels: bool,
    /// Entries the lists start with (default 0: estimated).
    pub map_initial_entries: u32,
    /// (Triangle, face) pairs a point light's cube map starts with (default 0: estimated).
    pub map_initial_pairs: u32,
    /// Area shadows: light samples per pixel, 1..=128 (default 64).
    pub area_samples: u32,
    /// Longest list a texel keeps; longer ones walk the BVH (default 0: the plugin's choice, 256 entries,
    /// 1024 for the hybrid; `u32::MAX`: no limit).
    pub map_list_limit: u32,
    /// Bin items per pixel with a shadow ray past which a frame walks the BVH instead of building lists
    /// (default 8; infinity: always lists; 0: always the BVH).
    pub map_bin_budget: f32,
    /// Area shadows: the nodes and triangles a pixel's walk of the BVH with a wide bundle of segments or
    /// rays may visit per 64 open samples (scaled by the bundle's width), before each open sample walks
    /// its own (default 256; 0: each sample's own walk at once; `u32::MAX`: the bundle always). It moves
    /// cost, never exactness.
    pub area_walk_budget: u32,
}

impl Default for Config {
    /// The plugin's defaults, from `hrts_config_defaults`.
    ///
    /// # Panics
    /// Never: the call fails only for a struct of another header version, and this one is the library's.
    fn default() -> Self {
        // SAFETY: plain data; all zeros is a valid value, overwritten by the call.
        let mut c: HrtsConfig = unsafe { std::mem::zeroed() };
        c.struct_size = size_of::<HrtsConfig>() as u32;
        // SAFETY: `c` is valid with its size set.
        check("hrts_config_defaults", unsafe {
            crate::hrts_config_defaults(&mut c)
        })
        .and_then(|()| Self::from_c("hrts_config_defaults", &c))
        .expect("the library fills the configuration of its own header")
    }
}

impl Config {
    /// The C configuration.
    pub(crate) fn to_c(self) -> HrtsConfig {
        HrtsConfig {
            struct_size: size_of::<HrtsConfig>() as u32,
            mode: self.mode as u32,
            antialiasing: self.antialiasing.into(),
            static_light: self.static_light.into(),
            map_size: self.map_size,
            map_entry_budget_kib: self.map_entry_budget_kib,
            faces: self.faces as u32,
            binning_path: self.binning_path as u32,
            shadow_map_size: self.shadow_map_size,
            pcss_angular_radius: self.pcss_angular_radius,
            pcss_spot_radius: self.pcss_spot_radius,
            pcss_blocker_search_taps: self.pcss_blocker_search_taps,
            pcss_pcf_taps: self.pcss_pcf_taps,
            hybrid_world_space_scale: self.hybrid_world_space_scale,
            hybrid_hard_shadow_percentage: self.hybrid_hard_shadow_percentage,
            pcss_filter: self.pcss_filter as u32,
            pcss_max_search_radius: self.pcss_max_search_radius,
            pcss_min_filter_radius: self.pcss_min_filter_radius,
            pcss_max_filter_radius: self.pcss_max_filter_radius,
            shadow_map_constant_bias: self.shadow_map_constant_bias,
            shadow_map_slope_bias: self.shadow_map_slope_bias,
            dynamic_geometry: self.dynamic_geometry.into(),
            extra_outputs: self.extra_outputs.bits(),
            guard_entries: self.guard_entries.into(),
            debug_bin_all_texels: self.debug_bin_all_texels.into(),
            map_initial_entries: self.map_initial_entries,
            map_initial_pairs: self.map_initial_pairs,
            area_samples: self.area_samples,
            map_list_limit: self.map_list_limit,
            map_bin_budget: self.map_bin_budget,
            area_walk_budget: self.area_walk_budget,
        }
    }

    /// The configuration of a C one that `call` wrote (its enumerations checked).
    pub(crate) fn from_c(call: &'static str, c: &HrtsConfig) -> Result<Self> {
        Ok(Self {
            mode: decode(call, "mode", c.mode)?,
            antialiasing: c.antialiasing != 0,
            static_light: c.static_light != 0,
            map_size: c.map_size,
            map_entry_budget_kib: c.map_entry_budget_kib,
            faces: decode(call, "faces", c.faces)?,
            binning_path: decode(call, "binning_path", c.binning_path)?,
            shadow_map_size: c.shadow_map_size,
            pcss_angular_radius: c.pcss_angular_radius,
            pcss_spot_radius: c.pcss_spot_radius,
            pcss_blocker_search_taps: c.pcss_blocker_search_taps,
            pcss_pcf_taps: c.pcss_pcf_taps,
            hybrid_world_space_scale: c.hybrid_world_space_scale,
            hybrid_hard_shadow_percentage: c.hybrid_hard_shadow_percentage,
            pcss_filter: decode(call, "pcss_filter", c.pcss_filter)?,
            pcss_max_search_radius: c.pcss_max_search_radius,
            pcss_min_filter_radius: c.pcss_min_filter_radius,
            pcss_max_filter_radius: c.pcss_max_filter_radius,
            shadow_map_constant_bias: c.shadow_map_constant_bias,
            shadow_map_slope_bias: c.shadow_map_slope_bias,
            dynamic_geometry: c.dynamic_geometry != 0,
            extra_outputs: ResourceSet::from_bits(call, "extra_outputs", c.extra_outputs)?,
            guard_entries: c.guard_entries != 0,
            debug_bin_all_texels: c.debug_bin_all_texels != 0,
            map_initial_entries: c.map_initial_entries,
            map_initial_pairs: c.map_initial_pairs,
            area_samples: c.area_samples,
            map_list_limit: c.map_list_limit,
            map_bin_budget: c.map_bin_budget,
            area_walk_budget: c.area_walk_budget,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_c_defaults_and_round_trip() {
        let config = Config::default();
        let c = config.to_c();
        let passes_default = passes::ShadowConfig::default();
        assert_eq!(c.map_size, passes_default.map.size);
        assert_eq!(config.mode, ShadowMode::Hybrid);
        assert!(config.antialiasing && !config.dynamic_geometry);
        assert_eq!(Config::from_c("test", &c).unwrap(), config);
    }
}

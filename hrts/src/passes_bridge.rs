//! Conversions between the safe API's types and the `passes` crate's, for Rust hosts that still hold
//! `passes` types: host_demo's configurations and reports, which it shares with the frame it renders
//! through the Rust passes directly. A host on the plugin's public API needs none of them; they go when
//! host_demo holds the plugin's own types.

use crate::convert;
use crate::safe::{Config, Error, NormalEncoding, NormalSpace, Resource, Result};

/// The plugin configuration of a `passes` one: the `HrtsConfig` that `hrts_configure` reads back as
/// `config` (settings the C ABI does not carry are left out). Fails if an extra output has no
/// [`Resource`].
pub fn config(config: &passes::ShadowConfig) -> Result<Config> {
    const CALL: &str = "hrts::passes_bridge::config";
    let c = convert::config_to_c(config).map_err(|e| Error::new(CALL, e.code, e.message))?;
    Config::from_c(CALL, &c)
}

/// The pipeline resource of a plugin resource.
pub fn resource_id(resource: Resource) -> passes::ResourceId {
    convert::RESOURCES[resource as usize]
}

/// The plugin resource of a pipeline resource, if the C ABI names it.
pub fn resource(id: passes::ResourceId) -> Option<Resource> {
    let value = convert::resource_index(id).ok()?;
    crate::safe::decode("hrts::passes_bridge::resource", "resource", value).ok()
}

/// How the passes read an engine normal image of `encoding` in `space`, as the C ABI converts them.
pub fn surface_input(encoding: NormalEncoding, space: NormalSpace) -> Result<passes::SurfaceInput> {
    const CALL: &str = "hrts::passes_bridge::surface_input";
    convert::normal_input(encoding as u32, space as u32)
        .map_err(|e| Error::new(CALL, e.code, e.message))
}

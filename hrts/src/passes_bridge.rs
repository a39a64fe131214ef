//! Conversions between the safe API's types and the `passes` crate's, for the code that drives the passes
//! directly beside the plugin: the lab's tools and the tests that compare the plugin with the passes. A
//! host on the plugin's public API (the demo, an engine) needs none of them.

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

/// How the passes read an engine normal image of `encoding` in `space`, as the C ABI converts them.
pub fn surface_input(encoding: NormalEncoding, space: NormalSpace) -> Result<passes::SurfaceInput> {
    const CALL: &str = "hrts::passes_bridge::surface_input";
    convert::normal_input(encoding as u32, space as u32)
        .map_err(|e| Error::new(CALL, e.code, e.message))
}

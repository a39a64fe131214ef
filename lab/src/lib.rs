//! The lab: the tools that measure and check the plugin from inside, where the demo (`host_demo`) shows
//! it through its public API alone. They drive the passes directly where a check needs what no engine
//! sees (the ray-tracing-pipeline peer, a primitive map's lists, the tier matrix's raster paths, the
//! shadow rays of a frame), and the demo's plugin frame everywhere else.
//!
//! - [`mod@bench`] (with [`area_bench`] and [`light_bench`]): the talk's timing tables, every model of the
//!   models folder, sized and many lights in scenes, against the GPU's ray-tracing pipeline ([`peer`]);
//! - [`hardcases`]: the hard numerical cases against the exact f64 reference;
//! - [`report`] (`accuracy`) and [`tradeoff`]: what accuracy costs in time, for hard and soft shadows;
//! - [`compare`]: the talk's side-by-sides;
//! - [`tiers`]: every conservative-raster path against exact binning;
//! - [`ray_dump`]: a frame's shadow rays for `scripts/embree_compare.py`;
//! - [`accuracy`]: the counts all of them compare with the exact reference;
//! - [`frames`]: the demo's frames in the passes' terms.

pub mod accuracy;
pub mod area_bench;
pub mod bench;
mod bench_models;
pub mod compare;
pub mod frames;
pub mod hardcases;
pub mod light_bench;
pub mod peer;
pub mod ray_dump;
pub mod report;
pub mod tiers;
pub mod tradeoff;

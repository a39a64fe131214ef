//! The primitive map's pipelines, created by [`PrimitiveMap`](super::PrimitiveMap) and bound by its
//! scratch ([`super::scratch`]).

use crate::scan::ScanPipeline;
use rhi::{ComputePipeline, GraphicsPipeline};

/// The binning pipelines of the path in use.
pub(super) enum Binner {
    Compute(ComputePipeline),
    Raster(GraphicsPipeline),
}

/// The map's pipelines.
pub(super) struct MapPipelines {
    pub(super) fit: ComputePipeline,
    pub(super) receivers: ComputePipeline,
    pub(super) setup: ComputePipeline,
    pub(super) index: ComputePipeline,
    pub(super) scan: ScanPipeline,
    pub(super) binner: Binner,
    pub(super) pack: ComputePipeline,
    pub(super) occupancy: ComputePipeline,
}

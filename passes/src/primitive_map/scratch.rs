//! The buffers the primitive maps that take one scratch set of a geometry share, because each map uses
//! them only while it is built and traced, and such maps are built one after another (maps over different
//! sets may be built side by side): bin triangles, tile offsets, pair owners and per-texel counts, the
//! receiver map, and the screen-size pixel texels.

use super::pipelines::{Binner, MapPipelines};
use crate::scan::PrefixScan;
use crate::PassError;
use rhi::{BindGroup, Buffer, BufferUsage, Device, MemoryLocation, Resource};

/// Bytes of one bin triangle (`BinTri` in `map_bin.glsl`).
const BIN_TRI_BYTES: u64 = 64;

/// Bytes of one (triangle, texel) pair of the pair list (`map_bin.comp`).
pub(super) const PAIR_BYTES: u64 = 8;

/// Entries of the bin walk's search index (`SEARCH_INDEX_SIZE` in `map_bin.glsl`, built by
/// `map_index.comp`): the bin triangle holding every ⌈items / 65536⌉-th item.
pub(super) const SEARCH_INDEX_WORDS: u64 = 65536;

/// Words of a receiver map of `texels` texels: one per texel, then one per 4×4-texel tile of the grids (the
/// largest of its texels' words, `map_state.glsl`'s `tile_word`), which lets the bin walk skip a tile whose
/// texels hold no ray origin, or only origins nearer the light than the triangle.
pub(super) fn receiver_words(texels: u64) -> u64 {
    texels + texels / 4 + 2
}

/// A GPU-only storage buffer of `bytes` (at least 4) with `usage` besides storage.
pub(super) fn storage_buffer(
    device: &Device,
    name: &str,
    bytes: u64,
    usage: BufferUsage,
) -> Result<Buffer, rhi::RhiError> {
    device.create_buffer(
        name,
        bytes.max(4),
        BufferUsage::STORAGE | usage,
        MemoryLocation::GpuOnly,
    )
}

/// The buffers a map uses only while it is built (bin triangles, their tile offsets and owners, per-texel
/// counts), shared by every map that takes the same scratch set: their builds are recorded one after
/// another with barriers between them (each clears the counts first), so one set serves all of them.
pub struct MapScratch {
    pub(super) bin_tris: Buffer,
    pub(super) tile_offsets: Buffer,
    pub(super) pair_owners: Buffer,
    pub(super) counts: Buffer,
    /// One bit per texel: its count passed the list limit (`map_store.glsl`).
    pub(super) capped: Buffer,
    pub(super) search_index: Buffer,
    /// The texels the counts hold.
    pub(super) texels: u64,
    /// The bin triangles the buffers hold.
    pub(super) bins: u32,
    /// The (triangle, face) owners held (0 until a point light's map asked for some).
    pub(super) owners: u32,
}

impl MapScratch {
    /// GPU bytes of the scratch.
    pub fn bytes(&self) -> u64 {
        [
            &self.bin_tris,
            &self.tile_offsets,
            &self.pair_owners,
            &self.counts,
            &self.capped,
            &self.search_index,
        ]
        .iter()
        .map(|b| b.size())
        .sum()
    }
}

/// One scratch set, shared by the maps that take it: it grows to the largest map asked for; a map keeps
/// the scratch it was created with until it needs a larger one (the pool's newer, larger one serves the
/// maps created or grown after).
#[derive(Default)]
pub struct MapScratchPool {
    current: std::sync::Mutex<Option<std::sync::Arc<MapScratch>>>,
    /// The receiver map (one `u32` per texel) shared by the maps that draw no occupancy view.
    receivers: std::sync::Mutex<Option<std::sync::Arc<Buffer>>>,
    /// The pixel texels (one `u32` per screen pixel) shared by the maps, with the id of the map that last
    /// recorded a write of them.
    pixel_texels: std::sync::Mutex<Option<SharedTexels>>,
    /// The compute binning's pair list: the (triangle, texel) pairs the count accepted, 8 bytes each.
    pair_list: std::sync::Mutex<Option<std::sync::Arc<Buffer>>>,
}

/// Screen-size pixel texels shared by the maps of one scratch set, and which map last recorded their write.
#[derive(Clone)]
pub struct SharedTexels {
    pub(super) buffer: std::sync::Arc<Buffer>,
    pub(super) writer: std::sync::Arc<std::sync::atomic::AtomicU64>,
}

/// The value in `slot` if `fits` accepts it, else `make`'s from the value there (if any), which then
/// takes the slot.
fn shared_in<T: Clone>(
    slot: &std::sync::Mutex<Option<T>>,
    fits: impl Fn(&T) -> bool,
    make: impl FnOnce(Option<&T>) -> Result<T, PassError>,
) -> Result<T, PassError> {
    let mut current = slot
        .lock()
        .map_err(|_| PassError::InvalidConfig("map scratch pool poisoned".into()))?;
    if let Some(value) = current.as_ref().filter(|v| fits(v)) {
        return Ok(value.clone());
    }
    let value = make(current.as_ref())?;
    *current = Some(value.clone());
    Ok(value)
}

/// `bytes` of the value in `slot` (0 when empty).
fn bytes_in<T>(slot: &std::sync::Mutex<Option<T>>, bytes: impl Fn(&T) -> u64) -> u64 {
    slot.lock()
        .ok()
        .and_then(|v| v.as_ref().map(&bytes))
        .unwrap_or(0)
}

impl MapScratchPool {
    /// Scratch with counts for `texels` texels, `bins` bin triangles and `owners` (triangle, face) owners:
    /// the pool's, or a new one as large as the largest asked for so far.
    pub fn get(
        &self,
        device: &Device,
        texels: u64,
        bins: u32,
        owners: u32,
    ) -> Result<std::sync::Arc<MapScratch>, PassError> {
        let fits = |s: &std::sync::Arc<MapScratch>| {
            s.texels >= texels && s.bins >= bins && s.owners >= owners
        };
        shared_in(&self.current, fits, |old| {
            let (texels, bins, owners) = old.map_or((texels, bins, owners), |s| {
                (s.texels.max(texels), s.bins.max(bins), s.owners.max(owners))
            });
            let storage = |name, bytes, usage| storage_buffer(device, name, bytes, usage);
            Ok(std::sync::Arc::new(MapScratch {
                bin_tris: storage(
                    "primitive map bin triangles",
                    u64::from(bins) * BIN_TRI_BYTES,
                    BufferUsage::default(),
                )?,
                tile_offsets: storage(
                    "primitive map tile offsets",
                    (u64::from(bins) + 1) * 4,
                    BufferUsage::default(),
                )?,
                pair_owners: storage(
                    "primitive map pair owners",
                    u64::from(owners) * 4,
                    BufferUsage::default(),
                )?,
                counts: storage(
                    "primitive map counts",
                    (texels + 1) * 4,
                    BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
                )?,
                capped: storage(
                    "primitive map capped texels",
                    (texels / 32 + 1) * 4,
                    BufferUsage::COPY_DST,
                )?,
                search_index: storage(
                    "primitive map search index",
                    SEARCH_INDEX_WORDS * 4,
                    BufferUsage::default(),
                )?,
                texels,
                bins,
                owners,
            }))
        })
    }

    /// A receiver map of at least `texels` texels and their tile words ([`receiver_words`]): the pool's, or
    /// a new one as large.
    pub fn receivers(
        &self,
        device: &Device,
        texels: u64,
    ) -> Result<std::sync::Arc<Buffer>, PassError> {
        shared_in(
            &self.receivers,
            |r| r.size() >= receiver_words(texels) * 4,
            |_| {
                Ok(std::sync::Arc::new(storage_buffer(
                    device,
                    "primitive map receivers",
                    receiver_words(texels) * 4,
                    BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
                )?))
            },
        )
    }

    /// Pixel texels for `pixels` pixels: the pool's, or new ones as large.
    pub(super) fn pixel_texels(
        &self,
        device: &Device,
        pixels: u64,
    ) -> Result<SharedTexels, PassError> {
        shared_in(
            &self.pixel_texels,
            |t| t.buffer.size() >= pixels * 4,
            |_| {
                Ok(SharedTexels {
                    buffer: std::sync::Arc::new(storage_buffer(
                        device,
                        "primitive map pixel texels",
                        pixels * 4,
                        BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
                    )?),
                    writer: std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0)),
                })
            },
        )
    }

    /// A pair list of at least `pairs` pairs, or as many as the device's largest storage buffer holds: the
    /// pool's, or a new one as large. A frame whose pairs do not fit it walks the tiles again to fill.
    pub(super) fn pair_list(
        &self,
        device: &Device,
        pairs: u32,
    ) -> Result<std::sync::Arc<Buffer>, PassError> {
        let largest = device.capabilities().max_storage_buffer_range / PAIR_BYTES * PAIR_BYTES;
        let bytes = (u64::from(pairs) * PAIR_BYTES).min(largest);
        shared_in(
            &self.pair_list,
            |l| l.size() >= bytes,
            |_| {
                Ok(std::sync::Arc::new(storage_buffer(
                    device,
                    "primitive map pair list",
                    bytes,
                    BufferUsage::default(),
                )?))
            },
        )
    }

    /// GPU bytes of the pool's current scratch, receiver map, pixel texels and pair list (0 before any
    /// map asked for them).
    pub fn bytes(&self) -> u64 {
        bytes_in(&self.current, |s| s.bytes())
            + bytes_in(&self.receivers, |r| r.size())
            + bytes_in(&self.pixel_texels, |t| t.buffer.size())
            + bytes_in(&self.pair_list, |l| l.size())
    }
}

/// What a map binds of its scratch: replaced together when a point light's map outgrows its pairs.
pub struct ScratchBindings {
    pub(super) scratch: std::sync::Arc<MapScratch>,
    /// The compute binning's pair list (none for the raster paths).
    pub(super) pair_list: Option<std::sync::Arc<Buffer>>,
    pub(super) setup_group: BindGroup,
    /// Builds the bin walk's search index from the scanned tile offsets.
    pub(super) index_group: BindGroup,
    pub(super) bin_group: BindGroup,
    pub(super) tile_scan: PrefixScan,
    /// The counts scanned in place into the lists' offsets (the fill's cursors).
    pub(super) offset_scan: PrefixScan,
    /// Packs the scanned offsets into the map's list offsets and tallies its statistics.
    pub(super) pack_group: BindGroup,
}

/// The buffers the scratch bindings pair with the scratch.
pub(super) struct BindTargets<'a> {
    pub(super) prims: &'a Buffer,
    pub(super) state: &'a Buffer,
    pub(super) receivers: &'a Buffer,
    pub(super) offsets: &'a Buffer,
    pub(super) entries: &'a Buffer,
    /// The pool the pair list comes from, and the pairs it must hold (the entry capacity).
    pub(super) pool: &'a MapScratchPool,
    pub(super) entry_capacity: u32,
}

impl ScratchBindings {
    /// Binds `scratch` for a map of `texels` texels and `bins` bin triangles, with a pair list from the
    /// pool as large as the map's entry capacity (compute binning).
    pub(super) fn new(
        device: &Device,
        pipes: &MapPipelines,
        scratch: std::sync::Arc<MapScratch>,
        t: &BindTargets<'_>,
        (texels, bins): (u64, u32),
    ) -> Result<Self, PassError> {
        let b = Resource::Buffer;
        let s = &*scratch;
        let setup_group = device.create_bind_group(
            pipes.setup.layout(),
            &[
                b(t.prims),
                b(t.state),
                b(&s.bin_tris),
                b(&s.tile_offsets),
                b(&s.pair_owners),
            ],
        )?;
        let mut pair_list = None;
        let bin_group = match &pipes.binner {
            Binner::Compute(p) => {
                let list = t.pool.pair_list(device, t.entry_capacity)?;
                let group = device.create_bind_group(
                    p.layout(),
                    &[
                        b(&s.bin_tris),
                        b(&s.tile_offsets),
                        b(t.receivers),
                        b(&s.counts),
                        b(t.entries),
                        b(t.state),
                        b(&s.pair_owners),
                        b(&list),
                        b(&s.search_index),
                        b(&s.capped),
                    ],
                )?;
                pair_list = Some(list);
                group
            }
            Binner::Raster(p) => device.create_bind_group(
                p.layout(),
                &[
                    b(&s.bin_tris),
                    b(t.receivers),
                    b(&s.counts),
                    b(t.entries),
                    b(&s.capped),
                ],
            )?,
        };
        let tile_scan = PrefixScan::new(
            device,
            &pipes.scan,
            &s.tile_offsets,
            &s.tile_offsets,
            bins + 1,
        )?;
        let offset_scan = PrefixScan::new(
            device,
            &pipes.scan,
            &s.counts,
            &s.counts,
            (texels + 1) as u32,
        )?;
        let index_group = device.create_bind_group(
            pipes.index.layout(),
            &[
                Resource::Buffer(&s.tile_offsets),
                Resource::Buffer(&s.search_index),
                Resource::Buffer(t.state),
            ],
        )?;
        let pack_group = device.create_bind_group(
            pipes.pack.layout(),
            &[
                Resource::Buffer(&s.counts),
                Resource::Buffer(t.offsets),
                Resource::Buffer(t.state),
                Resource::Buffer(&s.capped),
            ],
        )?;
        Ok(Self {
            scratch,
            pair_list,
            setup_group,
            index_group,
            bin_group,
            tile_scan,
            offset_scan,
            pack_group,
        })
    }
}

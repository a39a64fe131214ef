//! Host mirrors of the structs shared with shaders. Each has a GLSL include of the same layout in
//! `shaders/`; the size assertions below keep the two sides from drifting.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec4, Vec4};

/// A world-space triangle in the prim buffer (`triangle.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuTriangle {
    /// Vertices, w = 1.
    pub v: [Vec4; 3],
}

/// Push constants of the prim-buffer build (`prim_buffer_push.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct PrimBufferPush {
    /// Object to world.
    pub model: Mat4,
    /// First index of the draw.
    pub first_index: u32,
    /// Triangles in the draw.
    pub triangle_count: u32,
    /// Draw-call offset into the prim buffer.
    pub prim_offset: u32,
    /// Vertex stride in floats.
    pub vertex_stride: u32,
    /// Offset of vertex 0 in floats.
    pub vertex_offset: u32,
    /// Addressable vertices.
    pub vertex_count: u32,
    /// 1 for packed u16 indices, 0 for u32.
    pub index_16bit: u32,
    /// Added to every index of the draw before it addresses a vertex (may be negative).
    pub base_vertex: i32,
    /// How positions are stored (`prim_buffer::VertexFormat`).
    pub vertex_format: u32,
    /// Padding.
    pub pad: [u32; 3],
}

/// Push constants of the primitive-map passes (`map_push.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct MapPush {
    /// Directional light: the direction towards it (xyz), w 0. Spot or point light: its position in frame
    /// coordinates (xyz), w 1.
    pub to_light: Vec4,
    /// Map size N.
    pub size: u32,
    /// Pass-specific mode.
    pub mode: u32,
    /// 1 = keep only triangles facing the light.
    pub front_only: u32,
    /// Triangles in the prim buffer.
    pub triangles: u32,
    /// Entry capacity.
    pub capacity: u32,
    /// Threads of the binning dispatch.
    pub tile_threads: u32,
    /// 1 = guard words follow the entries.
    pub guard: u32,
    /// 1 = bin only into texels with ray origins, and skip triangles behind all of them.
    pub cull: u32,
    /// Frusta in the map: 1, or 6 for a point light's cube faces.
    pub faces: u32,
    /// (Triangle, face) pairs the bin items hold (a point light's map; 0 otherwise).
    pub pairs: u32,
    /// Texels of the map's grids together.
    pub texels: u32,
    /// (Triangle, texel) pairs the compute binning's pair list holds (0: none).
    pub list_capacity: u32,
    /// Area shadows of a directional light: the tangent of the light's angular radius, by which a
    /// triangle's footprint widens per unit of depth above a receiver (0: otherwise).
    pub penumbra: f32,
    /// Area shadows of a spot or point light: the emitter's radius (frame units; 0: otherwise).
    pub emitter_radius: f32,
    /// Area shadows of a spot or point light: triangles nearer the light than this are listed in every
    /// texel with receivers (the area trace's `LocalAreaReach`).
    pub near_radius: f32,
    /// Area shadows of a spot or point light: a depth key below which no point of a farther triangle can
    /// block a receiver of the frustum (the area trace's `LocalAreaReach`).
    pub depth_floor: f32,
    /// A texel whose list would pass this many entries keeps none: its pixels walk the BVH.
    pub list_limit: u32,
    /// Bin items (4×4-texel tiles of the footprints) per pixel with a ray past which no list is built and
    /// every pixel walks the BVH.
    pub bin_budget: f32,
    /// Entries each accepted (triangle, texel) pair counts ([`crate::PrimitiveMapConfig::debug_count_scale`]).
    pub count_scale: u32,
    /// Padding.
    pub pad: u32,
}

/// Constants of the primitive map's passes: the ray trace's (the receivers trace the same rays), and the
/// view-projection of each of the light's frusta in frame coordinates (one, or a point light's six cube
/// faces; unused ones repeat the first).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct MapConstants {
    /// The ray trace's constants.
    pub ray: RayTraceConstants,
    /// The frusta's view-projections.
    pub frusta: [Mat4; 6],
}

/// Constants of the ray trace (`ray_trace_constants.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct RayTraceConstants {
    /// inverse(proj * view) with the camera at the origin.
    pub inv_view_proj_rel: Mat4,
    /// Light view-projection in frame coordinates.
    pub light_view_proj: Mat4,
    /// Camera position in frame coordinates (xyz).
    pub camera_pos: Vec4,
    /// Direction the light travels (xyz, unit); w: area shadows, the tangent of a directional light's
    /// angular radius or a spot or point light's emitter radius (0: hard shadows).
    pub light_dir: Vec4,
    /// Screen width, height, map N, unused.
    pub dims: UVec4,
    /// x: radians per pixel, y: ray-origin offset in pixels, z: relative float bound of |P|, w: one step of
    /// a normalized depth format (0 for float depth).
    pub offset: Vec4,
    /// x: front-only map flag, y: triangles in the prim buffer, z: the ray trace: 1 = it stores the blocker
    /// distance; the area trace: the bundle's walk budget ([`crate::area::AreaConfig::bundle_walk_budget`]),
    /// w: the area trace's light samples per pixel.
    pub misc: UVec4,
    /// Spot light: position in frame coordinates (xyz), w = 1; directional light: w = 0.
    pub light_pos: Vec4,
    /// The camera's rotation, view to world (for view-space normals).
    pub view_to_world: Mat4,
    /// How the engine's normal image encodes the normal ([`crate::surface::SurfaceInput::mode`]).
    pub surface_mode: UVec4,
    /// x: the depth of background pixels ([`crate::surface::background_depth`]).
    pub surface: Vec4,
}

/// The primitive map's per-frame GPU state of one frustum (`map_state.glsl`), read back for the frame
/// report. A point light's map has one per cube face; the first also holds the totals and statistics.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct MapState {
    /// Frame coordinates to homogeneous texel space, fitted to the receivers.
    pub to_texels: Mat4,
    /// Ordered-float light NDC bounds of the ray origins (min x, min y, max x, max y).
    pub bounds: UVec4,
    /// x: pixels with a shadow ray, y: ordered largest texel error of a ray origin, z: ordered largest
    /// depth key of the ray origins, w: pixels with a ray inside the light's frustum (bounds pass).
    pub receivers: UVec4,
    /// x: 1 when the map has receivers, y: texels per side of the fitted grid (N, or fewer with receiver
    /// culling when few rays need it), z: area shadows of a directional light: texels a triangle's
    /// footprint widens per unit of depth key above a receiver; of a spot or point light: the emitter's
    /// reach in texels (0: hard shadows), w: a spot or point light's emitter depth extent (0: otherwise).
    pub fit: Vec4,
    /// x: (triangle, texel) pairs the compute count appended to the pair list, y: entries needed, z: entry
    /// capacity, w: triangles binned (kept by the culling).
    pub totals: UVec4,
    /// x: texels with a list, y: longest list, z: texels past the capacity, w: texels with receivers.
    pub stats: UVec4,
    /// x: the grid's first texel, y: texels per grid row; first state only: z (triangle, face) pairs a
    /// point light's setup kept, w: pairs the bin items held.
    pub grid: UVec4,
    /// First state only: x: bin items (saturated), y: 1 when they passed the bin budget (no list built:
    /// every pixel walks the BVH), z: texels whose list passed the list limit (walked through the BVH).
    pub routes: UVec4,
    /// First state only, written by the trace: x: pixels that walked the BVH, y: walks that could not
    /// finish (never on a conforming device), z: the area trace's pixels whose bundle passed its walk
    /// budget ([`crate::area::AreaConfig::bundle_walk_budget`]), w: those of them whose tile skipped their
    /// bundle ([`crate::ray_trace::TILE_SKIP_FRAMES`]).
    pub walks: UVec4,
}

impl MapState {
    /// The state of frustum `frustum` at the start of a frame's build: nothing fitted, bounds empty, no
    /// receivers, totals and statistics zero; the first frustum's holds the entry capacity and the
    /// (triangle, face) pairs the bin items hold.
    pub fn reset(frustum: usize, capacity: u32, pairs: u32) -> Self {
        let first = |v: u32| if frustum == 0 { v } else { 0 };
        Self {
            to_texels: Mat4::IDENTITY,
            bounds: UVec4::new(u32::MAX, u32::MAX, 0, 0),
            receivers: UVec4::ZERO,
            fit: Vec4::ZERO,
            totals: UVec4::new(0, 0, first(capacity), 0),
            stats: UVec4::ZERO,
            grid: UVec4::new(0, 0, 0, first(pairs)),
            routes: UVec4::ZERO,
            walks: UVec4::ZERO,
        }
    }
}

/// What the primitive map held in a frame (decoded from [`MapState`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MapStats {
    /// Pixels that traced a shadow ray.
    pub receiver_pixels: u32,
    /// Texels holding at least one ray origin.
    pub receiver_texels: u32,
    /// Triangles the setup kept (not culled as degenerate, back-facing, outside or behind every receiver).
    pub triangles_binned: u32,
    /// Texels holding at least one triangle.
    pub texels_with_list: u32,
    /// Longest list of any texel.
    pub longest_list: u32,
    /// Entries (texel, triangle) the frame needed.
    pub entries: u32,
    /// Entries the map could hold this frame (it grows to fit from the next frame on, within its budget).
    pub capacity: u32,
    /// Texels whose list did not fit the capacity, and every texel of a group of 16 whose lists' offsets
    /// did not fit the packed offsets' 15 bits: their pixels walk the BVH (exact).
    pub texels_past_capacity: u32,
    /// Texels whose list passed the map's list limit, kept out of the lists: their pixels walk the BVH,
    /// which costs less than such a list.
    pub texels_past_limit: u32,
    /// Bin items (4×4-texel tiles of the triangles' footprints) the frame's lists would have walked.
    pub bin_items: u32,
    /// Whether the bin items passed the map's bin budget: no list was built, every pixel walked the BVH.
    pub lists_skipped: bool,
    /// Pixels that walked the BVH rather than a list.
    pub pixels_walked: u32,
    /// BVH walks that could not finish (never on a conforming device: a failure the tests check for).
    pub walks_unfinished: u32,
    /// Area shadows: pixels whose bundle of segments or rays passed its walk budget
    /// ([`crate::area::AreaConfig::bundle_walk_budget`]), or whose tile skipped it
    /// ([`MapStats::pixels_skipping_bundle`]), so that each of their open samples walked the BVH on its
    /// own (the same answer, for less than the bundle's wide walk).
    pub pixels_walked_per_sample: u32,
    /// Area shadows: of [`MapStats::pixels_walked_per_sample`], the pixels that skipped their bundle, since
    /// most of their tile's gave up in an earlier frame ([`crate::ray_trace::TILE_SKIP_FRAMES`]).
    pub pixels_skipping_bundle: u32,
    /// A point light's (triangle, face) pairs kept by the setup (0 for a light of one frustum). Past the
    /// pairs the map held (`pair_capacity`), the frame traced every ray exhaustively (exact, slower), and
    /// the map grows for the next.
    pub pairs: u32,
    /// The (triangle, face) pairs the map held this frame.
    pub pair_capacity: u32,
}

impl MapStats {
    /// Decodes the statistics of the read-back states of a map's frusta (the first holds the totals).
    pub fn from_states(states: &[MapState]) -> Self {
        let zero = MapState::zeroed();
        let s = states.first().unwrap_or(&zero);
        Self {
            receiver_pixels: states.iter().map(|f| f.receivers.x).sum(),
            receiver_texels: s.stats.w,
            triangles_binned: s.totals.w,
            texels_with_list: s.stats.x,
            longest_list: s.stats.y,
            entries: s.totals.y,
            capacity: s.totals.z,
            texels_past_capacity: s.stats.z,
            texels_past_limit: s.routes.z,
            bin_items: s.routes.x,
            lists_skipped: s.routes.y != 0,
            pixels_walked: s.walks.x,
            walks_unfinished: s.walks.y,
            pixels_walked_per_sample: s.walks.z,
            pixels_skipping_bundle: s.walks.w,
            pairs: s.grid.z,
            pair_capacity: s.grid.w,
        }
    }

    /// Mean list length over the texels holding a list.
    pub fn mean_list(&self) -> f64 {
        if self.texels_with_list == 0 {
            0.0
        } else {
            f64::from(self.entries) / f64::from(self.texels_with_list)
        }
    }
}

/// A light in frame coordinates, as light-space passes read it (`light.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuLight {
    /// View-projection of frame coordinates.
    pub view_proj: Mat4,
    /// Its inverse.
    pub inv_view_proj: Mat4,
    /// Linear depth of NDC `c = (x, y, d, 1)` is `dot(lin_num, c) / dot(lin_den, c)` (world units along
    /// the light axis).
    pub lin_num: Vec4,
    /// See `lin_num`.
    pub lin_den: Vec4,
    /// Spot: position in frame coordinates, w = 1. Directional: zero.
    pub position: Vec4,
    /// Unit direction of travel (directional) or view axis (spot), w = 0.
    pub direction: Vec4,
    /// x: world size of a shadow-map texel (directional) or that size per unit of linear depth (spot);
    /// y: emitter size (tangent of the angular radius, or radius); z: shadow-map size; w: 0 directional,
    /// 1 spot.
    pub params: Vec4,
}

/// Push constants of the shadow-map raster (`shadow_map.vert`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct ShadowMapPush {
    /// Light view-projection of frame coordinates.
    pub light_view_proj: Mat4,
}

/// Constants of PCSS and of the classic shadow-map test (`pcss_constants.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct PcssConstants {
    /// inverse(proj * view) with the camera at the origin.
    pub inv_view_proj_rel: Mat4,
    /// Camera position in frame coordinates (xyz), w: radians per pixel.
    pub camera_pos: Vec4,
    /// Screen width, height, shadow-map size, mode (0 PCSS standard, 1 PCSS shrinking, 2 classic test).
    pub dims: UVec4,
    /// x: blocker-search taps, y: PCF taps.
    pub taps: UVec4,
    /// x: largest blocker-search radius, y: smallest and z: largest filter radius (texels).
    pub radii: Vec4,
    /// x, y: classic test constant and slope bias (texels); z: receiver-plane tolerance (texels of
    /// slope); w: constant tolerance (texels of world size).
    pub bias: Vec4,
    /// The light.
    pub light: GpuLight,
    /// The camera's rotation, view to world (for view-space normals).
    pub view_to_world: Mat4,
    /// How the engine's normal image encodes the normal ([`crate::surface::SurfaceInput::mode`]).
    pub surface_mode: UVec4,
    /// x: the depth of background pixels ([`crate::surface::background_depth`]).
    pub surface: Vec4,
}

/// Push constants of FXAA (`fxaa.comp`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct FxaaPush {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Longest edge search, in steps.
    pub max_steps: u32,
    /// Padding.
    pub pad: u32,
    /// x: relative contrast threshold, y: absolute contrast threshold, z: sub-pixel amount, w: unused.
    pub params: Vec4,
}

/// Push constants of the lerp factor and the blend (`lerp_factor.comp`, `hybrid_blend.comp`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct HybridPush {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// WSS: world-space scale.
    pub world_space_scale: f32,
    /// PHS: percentage of hard shadow.
    pub hard_shadow_percentage: f32,
}

/// Most light samples per pixel (the bits of the area trace's sample mask).
pub const MAX_AREA_SAMPLES: u32 = 128;

/// The area trace's light samples (`area_samples.glsl`), built by the area trace's `area_samples`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct AreaSamples {
    /// xyz: the unit direction towards the light's centre C; w: a bound on the distance of every sample
    /// direction from it.
    pub center: Vec4,
    /// xyz: the first axis of the light's frame (unit, orthogonal to C); w: the half-extent of the edge
    /// table's line offsets (the area trace's `AreaEdgeTable`).
    pub axis_u: Vec4,
    /// xyz: the second axis; w: offset cells per gnomonic unit.
    pub axis_v: Vec4,
    /// The sample directions towards the light (xyz, unit; w unused); the first `samples` are used.
    pub dirs: [Vec4; MAX_AREA_SAMPLES as usize],
}

const _: () = {
    assert!(std::mem::size_of::<GpuTriangle>() == 48);
    assert!(std::mem::size_of::<PrimBufferPush>() == 112);
    assert!(std::mem::offset_of!(PrimBufferPush, first_index) == 64);
    assert!(std::mem::size_of::<MapPush>() == 96);
    assert!(std::mem::offset_of!(MapPush, penumbra) == 64);
    assert!(std::mem::size_of::<AreaSamples>() == 2096);
    assert!(std::mem::offset_of!(AreaSamples, dirs) == 48);
    assert!(std::mem::offset_of!(MapPush, size) == 16);
    assert!(std::mem::size_of::<RayTraceConstants>() == 320);
    assert!(std::mem::offset_of!(RayTraceConstants, light_pos) == 208);
    assert!(std::mem::offset_of!(RayTraceConstants, dims) == 160);
    assert!(std::mem::offset_of!(RayTraceConstants, offset) == 176);
    assert!(std::mem::size_of::<MapState>() == 192);
    assert!(std::mem::offset_of!(MapState, routes) == 160);
    assert!(std::mem::size_of::<MapConstants>() == 704);
    assert!(std::mem::offset_of!(MapState, totals) == 112);
    assert!(std::mem::offset_of!(MapState, grid) == 144);
    assert!(std::mem::size_of::<GpuLight>() == 208);
    assert!(std::mem::offset_of!(GpuLight, params) == 192);
    assert!(std::mem::size_of::<ShadowMapPush>() == 64);
    assert!(std::mem::size_of::<PcssConstants>() == 448);
    assert!(std::mem::offset_of!(PcssConstants, light) == 144);
    assert!(std::mem::size_of::<FxaaPush>() == 32);
    assert!(std::mem::size_of::<HybridPush>() == 16);
};

/// A uniform buffer for one `T`, in GPU memory, written by [`rhi::Encoder::update_buffer`] when a pass is
/// recorded (so that each frame in flight reads its own constants).
pub(crate) fn constant_buffer<T: bytemuck::Pod>(
    device: &rhi::Device,
    name: &str,
) -> Result<rhi::Buffer, crate::PassError> {
    Ok(device.create_buffer(
        name,
        std::mem::size_of::<T>() as u64,
        rhi::BufferUsage::UNIFORM | rhi::BufferUsage::COPY_DST,
        rhi::MemoryLocation::GpuOnly,
    )?)
}

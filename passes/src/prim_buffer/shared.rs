//! The prim buffer shared by the pipelines of a context's lights, and what each frame rebuilds of it: the
//! draws moved since it was last built, the meshes that read a vertex buffer of the frame (deformed), or
//! everything when the geometry changes every frame.

use super::{DrawSource, Geometry, PrimBufferPass, VertexLayout};
use crate::bvh::{BvhBuilder, SceneBvh};
use crate::primitive_map::MapScratchPool;
use crate::retire::MAX_FRAMES_IN_FLIGHT;
use crate::PassError;
use glam::Mat4;
use rhi::{BindGroup, Buffer, Device, Encoder};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

/// Who records the shared prim buffer in a frame (see [`SharedGeometry`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PrimBufferClaim {
    /// The caller records the build this frame.
    Record,
    /// Another light's pipeline records it this frame, before the caller's passes.
    RebuiltByAnother,
    /// It is up to date (nothing moved or deformed since an earlier frame built it).
    UpToDate,
}

/// A mesh's positions in one frame: a vertex buffer of that frame (an engine skinning into one buffer per
/// frame in flight) that the mesh's draws read instead of the mesh's own, with the mesh's stride, format
/// and vertex count.
pub struct MeshVertices {
    /// The mesh (its index in [`Geometry::meshes`]).
    pub mesh: usize,
    /// The vertex buffer (storage-buffer usage).
    pub buffer: Buffer,
    /// Byte offset of vertex 0 in `buffer` (a multiple of 4).
    pub offset: u64,
}

/// The bind group of a vertex buffer a frame reads instead of a mesh's own, written for that frame: kept
/// while the frame may be in flight, never reused by another frame (the engine may destroy the buffer
/// once the frame completed, and its handle may then name another buffer).
struct FrameVertices {
    group: BindGroup,
    /// The frame that reads it.
    frame: u64,
}

/// A mesh that reads a vertex buffer of the frame.
struct FrameMesh {
    mesh: usize,
    vertex: VertexLayout,
    /// Its [`FrameVertices`] entry.
    entry: usize,
}

/// The sets of build scratch the primitive maps over one geometry take in turn: up to this many lights'
/// lists are built side by side, each set allocated once a map takes it.
pub const MAP_SCRATCH_SETS: usize = 4;

/// The scene's geometry and its prim buffer, shared by the pipelines of several lights (one context): in
/// each frame the first light that needs the prim buffer records its build and the others read it. A
/// build rewrites only the slots that no longer hold what the frame needs.
pub struct SharedGeometry {
    geometry: Geometry,
    pass: PrimBufferPass,
    /// The hierarchy over the prim buffer, rebuilt with it.
    bvh: SceneBvh,
    state: Mutex<PrimBufferState>,
    /// [`MAP_SCRATCH_SETS`] sets of the maps' build scratch.
    map_scratch: Vec<MapScratchPool>,
    /// The ray traces' visibility that each light's FXAA reads right after, shared
    /// ([`SharedGeometry::antialias_source`]); freed when no pipeline holds it any more.
    antialias_source: Mutex<std::sync::Weak<rhi::Image>>,
}

struct PrimBufferState {
    /// The engine's buffers change every frame: every draw is rebuilt every frame.
    dynamic: bool,
    claimed: Option<u64>,
    /// Each draw's transform from stored positions to world, over all meshes in order.
    models: Vec<Mat4>,
    /// The transform each draw's slots were last built with from its mesh's own vertex buffer (`None`:
    /// never built, or last built from a vertex buffer of a frame).
    built_with: Vec<Option<Mat4>>,
    /// The frame whose per-frame vertex buffers were set last, and the meshes reading them.
    frame_meshes: Option<(u64, Vec<FrameMesh>)>,
    /// The vertex buffers the frames in flight read instead of their meshes' own.
    frame_vertices: Vec<FrameVertices>,
    /// The triangles each recent frame's build rewrote.
    rebuilt: VecDeque<(u64, u32)>,
    /// Whether a build clustered the rays' hierarchy: the first whose meshes were not deformed.
    clustered: bool,
}

impl PrimBufferState {
    /// The meshes that read vertex buffers of `frame`.
    fn deformed_in(&self, frame: u64) -> &[FrameMesh] {
        match &self.frame_meshes {
            Some((f, meshes)) if *f == frame => meshes,
            _ => &[],
        }
    }

    /// Whether every draw's slots hold its current transform applied to its mesh's own vertices.
    fn current(&self) -> bool {
        self.built_with
            .iter()
            .zip(&self.models)
            .all(|(built, model)| *built == Some(*model))
    }

    /// Whether a build rewrites draw `draw`'s slots (`deformed`: its mesh reads a vertex buffer of the
    /// frame).
    fn rebuilds(&self, draw: usize, deformed: bool) -> bool {
        self.dynamic || deformed || self.built_with[draw] != Some(self.models[draw])
    }

    /// How a build in `frame` makes the rays' hierarchy: clustered by the geometry's first build whose meshes
    /// are not deformed, a copy of the linear one by any later build (draws moved, meshes deformed), since
    /// geometry that changes may change every frame and the clustering costs about ten times the linear
    /// build (2.4-3.3 ms against 0.2-0.3 ms on an H200). Dynamic geometry has no clustering at all.
    fn rays_builder(&self, frame: u64) -> BvhBuilder {
        if self.clustered || !self.deformed_in(frame).is_empty() {
            BvhBuilder::Linear
        } else {
            BvhBuilder::Clustered
        }
    }

    /// Whether `frame` must rebuild some of the prim buffer.
    fn stale(&self, frame: u64) -> bool {
        self.dynamic || !self.deformed_in(frame).is_empty() || !self.current()
    }
}

impl SharedGeometry {
    /// Creates the prim buffer of `geometry`. `dynamic`: the vertex or index buffers change between frames,
    /// so the prim buffer is rebuilt every frame (else what moved or deformed).
    pub fn new(device: &Device, geometry: Geometry, dynamic: bool) -> Result<Arc<Self>, PassError> {
        let pass = PrimBufferPass::new(device, &geometry)?;
        let bvh = SceneBvh::new(device, pass.prims(), geometry.triangle_count(), !dynamic)?;
        let models: Vec<Mat4> = geometry.draws().map(|(_, d)| d.model).collect();
        Ok(Arc::new(Self {
            state: Mutex::new(PrimBufferState {
                dynamic,
                claimed: None,
                built_with: vec![None; models.len()],
                models,
                frame_meshes: None,
                frame_vertices: Vec::new(),
                rebuilt: VecDeque::new(),
                clustered: false,
            }),
            geometry,
            pass,
            bvh,
            map_scratch: (0..MAP_SCRATCH_SETS)
                .map(|_| MapScratchPool::default())
                .collect(),
            antialias_source: Mutex::new(std::sync::Weak::new()),
        }))
    }

    /// The geometry.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The prim buffer (triangles in frame coordinates).
    pub fn prims(&self) -> &Buffer {
        self.pass.prims()
    }

    /// The bounding volume hierarchy over the prim buffer (rebuilt whenever the prim buffer is).
    pub fn bvh(&self) -> &SceneBvh {
        &self.bvh
    }

    /// Build scratch set `set` (modulo [`MAP_SCRATCH_SETS`]), shared by the primitive maps over this
    /// geometry that take it: they are built one after another, while maps over different sets may be
    /// built side by side ([`crate::ListBatch`]).
    pub fn map_scratch(&self, set: usize) -> &MapScratchPool {
        &self.map_scratch[set % MAP_SCRATCH_SETS]
    }

    /// GPU bytes of every scratch set allocated so far.
    pub fn map_scratch_bytes(&self) -> u64 {
        self.map_scratch.iter().map(MapScratchPool::bytes).sum()
    }

    /// The `width` x `height` `R32_SFLOAT` visibility the lights' ray traces write and their FXAA reads
    /// right after, in the same recording call: the one the pipelines hold, or a new one (which then serves
    /// the pipelines built after) if they hold none of that size.
    pub(crate) fn antialias_source(
        &self,
        device: &Device,
        width: u32,
        height: u32,
    ) -> Result<Arc<rhi::Image>, PassError> {
        let mut slot = self
            .antialias_source
            .lock()
            .map_err(|_| PassError::InvalidConfig("shared image poisoned".into()))?;
        if let Some(image) = slot
            .upgrade()
            .filter(|s| (s.width(), s.height()) == (width, height))
        {
            return Ok(image);
        }
        let image = Arc::new(crate::screen_pass::visibility_image(
            device,
            "rt visibility (shared by the lights' FXAA)",
            width,
            height,
        )?);
        *slot = Arc::downgrade(&image);
        Ok(image)
    }

    /// Whether the prim buffer is rebuilt every frame.
    pub fn is_dynamic(&self) -> bool {
        self.lock().dynamic
    }

    /// Makes the geometry dynamic (rebuilt every frame) or static (kept once built, but for what moves
    /// or deforms).
    pub fn set_dynamic(&self, dynamic: bool) {
        self.lock().dynamic = dynamic;
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, PrimBufferState> {
        self.state
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Decides, for a pipeline beginning `frame`, who records the prim buffer this frame.
    pub(crate) fn claim(&self, frame: u64) -> PrimBufferClaim {
        let mut s = self.lock();
        if s.claimed == Some(frame) {
            PrimBufferClaim::RebuiltByAnother
        } else if s.stale(frame) {
            s.claimed = Some(frame);
            PrimBufferClaim::Record
        } else {
            PrimBufferClaim::UpToDate
        }
    }

    /// Records frame `frame`'s build of the prim buffer (by the pipeline whose claim was
    /// [`PrimBufferClaim::Record`]): a dispatch for each draw whose slots do not hold what the frame needs
    /// (every draw of dynamic geometry; the draws moved since they were last built, or never built; the
    /// draws of the meshes reading a vertex buffer of the frame, and of those that did in the frame that
    /// last built them).
    pub(crate) fn record(&self, enc: &mut Encoder<'_>, frame: u64) -> Result<(), PassError> {
        let mut guard = self.lock();
        let s = &*guard;
        let deformed = s.deformed_in(frame);
        let mut rebuilt = vec![false; s.models.len()];
        let triangles = self
            .pass
            .record_draws(enc, &self.geometry, |mesh, draw, _| {
                let from_frame = deformed.iter().find(|m| m.mesh == mesh);
                if !s.rebuilds(draw, from_frame.is_some()) {
                    return None;
                }
                let model = s.models[draw];
                rebuilt[draw] = true;
                Some(match from_frame {
                    Some(m) => DrawSource {
                        group: &s.frame_vertices[m.entry].group,
                        vertex: m.vertex,
                        model,
                    },
                    None => DrawSource {
                        group: &self.pass.groups[mesh],
                        vertex: self.geometry.meshes()[mesh].vertex,
                        model,
                    },
                })
            })?;
        if triangles > 0 {
            let builder = s.rays_builder(frame);
            enc.barriers(&[rhi::Barrier::Uav]);
            enc.begin_pass("bvh build");
            self.bvh.record_build(enc, builder)?;
            enc.end_pass();
        }
        let deformed_meshes: Vec<usize> = deformed.iter().map(|m| m.mesh).collect();
        let s = &mut *guard;
        s.clustered |= triangles > 0 && deformed_meshes.is_empty();
        for ((draw, (mesh, _)), _) in self
            .geometry
            .draws()
            .enumerate()
            .zip(&rebuilt)
            .filter(|(_, &r)| r)
        {
            s.built_with[draw] = (!deformed_meshes.contains(&mesh)).then_some(s.models[draw]);
        }
        match s.rebuilt.iter_mut().find(|(f, _)| *f == frame) {
            // The frame begun again (abandoned, then recorded anew): its recordings add up.
            Some((_, sum)) => *sum = sum.saturating_add(triangles),
            None => {
                if s.rebuilt.len() > MAX_FRAMES_IN_FLIGHT as usize {
                    s.rebuilt.pop_front();
                }
                s.rebuilt.push_back((frame, triangles));
            }
        }
        Ok(())
    }

    /// Triangles whose slots frame `frame`'s build rewrote (0 when the prim buffer was up to date, or for a
    /// frame more than [`MAX_FRAMES_IN_FLIGHT`] builds ago).
    pub fn triangles_rebuilt(&self, frame: u64) -> u32 {
        self.lock()
            .rebuilt
            .iter()
            .find(|(f, _)| *f == frame)
            .map_or(0, |&(_, t)| t)
    }

    /// Moves the draws: `models` holds one object-to-world transform per draw, over all meshes in order.
    /// The next frame rebuilds the slots of the draws whose transform changed (once, for every light) and
    /// everything that depends on the prim buffer; frames already recorded keep the transforms they were
    /// recorded with.
    pub fn set_transforms(&self, models: &[Mat4]) -> Result<(), PassError> {
        let draws = self.geometry.draw_count();
        if models.len() != draws {
            return Err(PassError::InvalidGeometry(format!(
                "{} transforms for {draws} draws",
                models.len(),
            )));
        }
        if let Some(i) = models.iter().position(|m| !m.is_finite()) {
            return Err(PassError::InvalidGeometry(format!(
                "transform {i} is not finite"
            )));
        }
        self.lock().models = models.to_vec();
        Ok(())
    }

    /// Sets the vertex buffers frame `frame` reads instead of its meshes' own (none: every mesh reads its
    /// own); those meshes' draws are rebuilt in that frame, and again from their own vertices in the next
    /// frame that does not deform them. Each buffer gets a bind group written for this frame, dropped once
    /// the frame completed: `completed` is the last frame known to have completed on the GPU (everything
    /// up to `frame - frames_in_flight`). A frame never reuses an earlier frame's bind group, even for the
    /// same handle: the engine may have destroyed that buffer and created another at the same handle.
    /// Checks every entry before it changes anything.
    pub fn set_frame_vertices(
        &self,
        device: &Device,
        frame: u64,
        completed: Option<u64>,
        vertices: Vec<MeshVertices>,
    ) -> Result<(), PassError> {
        let meshes = self.geometry.meshes();
        let mut layouts = Vec::with_capacity(vertices.len());
        for (i, v) in vertices.iter().enumerate() {
            let what = format!("frame vertices {i} (mesh {})", v.mesh);
            let mesh = meshes.get(v.mesh).ok_or_else(|| {
                PassError::InvalidGeometry(format!(
                    "{what}: the geometry has {} meshes",
                    meshes.len()
                ))
            })?;
            if vertices[..i].iter().any(|o| o.mesh == v.mesh) {
                return Err(PassError::InvalidGeometry(format!(
                    "{what}: the mesh is given twice"
                )));
            }
            let vertex = VertexLayout {
                offset: v.offset,
                ..mesh.vertex
            };
            vertex.check(v.buffer.size()).map_err(|e| match e {
                PassError::InvalidGeometry(m) => PassError::InvalidGeometry(format!("{what}: {m}")),
                other => other,
            })?;
            layouts.push(vertex);
        }
        let mut s = self.lock();
        // The entries of the last frame's meshes move when those of completed frames go.
        s.frame_meshes = None;
        if let Some(done) = completed {
            s.frame_vertices.retain(|v| v.frame > done);
        }
        let mut frame_meshes = Vec::with_capacity(vertices.len());
        for (v, vertex) in vertices.into_iter().zip(layouts) {
            let group = self.pass.bind(device, &meshes[v.mesh], &v.buffer)?;
            s.frame_vertices.push(FrameVertices { group, frame });
            frame_meshes.push(FrameMesh {
                mesh: v.mesh,
                vertex,
                entry: s.frame_vertices.len() - 1,
            });
        }
        s.frame_meshes = Some((frame, frame_meshes));
        Ok(())
    }

    /// Whether every draw's slots hold its current transform applied to its mesh's own vertices.
    pub(crate) fn is_built(&self) -> bool {
        self.lock().current()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prim_buffer::VertexFormat;
    use glam::Vec3;

    fn state(draws: usize) -> PrimBufferState {
        PrimBufferState {
            dynamic: false,
            claimed: None,
            models: vec![Mat4::IDENTITY; draws],
            built_with: vec![None; draws],
            frame_meshes: None,
            frame_vertices: Vec::new(),
            rebuilt: VecDeque::new(),
            clustered: false,
        }
    }

    #[test]
    fn only_the_first_build_of_undeformed_meshes_clusters() {
        let mut s = state(2);
        assert_eq!(s.rays_builder(0), BvhBuilder::Clustered);
        s.frame_meshes = Some((
            0,
            vec![FrameMesh {
                mesh: 0,
                entry: 0,
                vertex: VertexLayout {
                    offset: 0,
                    stride: 12,
                    count: 3,
                    format: VertexFormat::Float3,
                },
            }],
        ));
        assert_eq!(s.rays_builder(0), BvhBuilder::Linear);
        assert_eq!(s.rays_builder(1), BvhBuilder::Clustered);
        s.clustered = true;
        assert_eq!(s.rays_builder(1), BvhBuilder::Linear);
    }

    #[test]
    fn a_frame_rebuilds_what_moved_or_deforms() {
        let mut s = state(3);
        assert!(
            s.stale(0) && (0..3).all(|d| s.rebuilds(d, false)),
            "never built"
        );
        s.built_with = s.models.iter().copied().map(Some).collect();
        assert!(s.current() && !s.stale(1));
        s.models[1] = Mat4::from_translation(Vec3::X);
        assert!(s.stale(2));
        assert_eq!(
            (0..3).map(|d| s.rebuilds(d, false)).collect::<Vec<_>>(),
            [false, true, false],
            "only the moved draw"
        );
        s.built_with[1] = Some(s.models[1]);
        assert!(!s.stale(3));
        let vertex = VertexLayout {
            offset: 0,
            stride: 12,
            count: 3,
            format: VertexFormat::Float3,
        };
        s.frame_meshes = Some((
            4,
            vec![FrameMesh {
                mesh: 0,
                vertex,
                entry: 0,
            }],
        ));
        assert!(
            s.stale(4) && s.deformed_in(4).len() == 1,
            "deformed in frame 4"
        );
        assert!(!s.stale(5) && s.deformed_in(5).is_empty(), "not in frame 5");
        assert!(s.rebuilds(0, true) && !s.rebuilds(0, false));
        s.dynamic = true;
        assert!(s.stale(5) && s.rebuilds(2, false), "dynamic: everything");
    }
}

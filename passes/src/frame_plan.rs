//! The frame plan (DESIGN §4): which passes run, and which resources exist, for what a light asks for.
//!
//! Passes have typed ids and one fixed linear order (a valid execution order of the whole technique).
//! [`FramePlan::derive`] walks that order backwards from the requested outputs: a pass is live when a
//! needed resource is one of its writes, and its reads then become needed. Resources are allocated only
//! when a live pass writes them. [`FramePlan::schedule`] then decides, per frame, which live passes must
//! run: a pass is skipped when every input it reads is unchanged since it last ran (static geometry, a
//! static and unchanged light). Both are pure functions, unit-tested without a GPU.

/// What one light asks of the pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShadowMode {
    /// No shadow: the output is 1 (lit) everywhere and no shadow pass runs.
    None,
    /// Ray-traced hard shadows through the deep primitive map (antialiased with FXAA if requested).
    Hard,
    /// Soft shadows only: shadow map + PCSS.
    Soft,
    /// The talk's hybrid: `lerp(ray-traced, PCSS, L)` with `L` from the ray-traced blocker distance.
    #[default]
    Hybrid,
    /// Exact soft shadows of a sized light: the visible fraction of a fixed set of light samples per pixel,
    /// each tested exactly against the triangles of the pixel's list in a primitive map whose footprints
    /// are widened by the penumbra they cast (no shadow map, no filter, no denoiser).
    Area,
    /// Chosen per light by its size ([`ShadowConfig::resolved`](crate::ShadowConfig::resolved)):
    /// [`ShadowMode::Hard`] for a light of zero size, [`ShadowMode::Area`] for a sized one. Pipelines are
    /// built for the mode it resolves to; unresolved, it plans only what both share (the ray-traced
    /// visibility, without antialiasing).
    Auto,
}

impl ShadowMode {
    /// "none", "hard", "soft", "hybrid", "area" or "auto".
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Hard => "hard",
            Self::Soft => "soft",
            Self::Hybrid => "hybrid",
            Self::Area => "area",
            Self::Auto => "auto",
        }
    }

    /// Whether the mode traces shadow rays through the primitive map (hard, hybrid and area, and so auto).
    pub fn traces_rays(self) -> bool {
        matches!(self, Self::Hard | Self::Hybrid | Self::Area | Self::Auto)
    }

    /// The mode [`ShadowMode::Auto`] chooses for a light of `size` (its angular radius, or its emitter's
    /// radius): exact ray-traced hard shadows for a light of zero size, exact soft (area) shadows for a
    /// sized one.
    pub fn for_light_size(size: f32) -> Self {
        if size > 0.0 {
            Self::Area
        } else {
            Self::Hard
        }
    }
}

/// How PCSS shapes the penumbra.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PenumbraFilter {
    /// Classic PCSS: the penumbra straddles the hard shadow edge, half of it outside the hard shadow.
    Standard,
    /// The talk's shrinking penumbra: the penumbra only grows inwards from the hard shadow edge, so the
    /// soft result is lit wherever the hard result is lit and the hybrid blend has no halo.
    #[default]
    Shrinking,
}

macro_rules! ids {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident = $text:literal),* $(,)? }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum $name {
            $($(#[$vdoc])* $variant),*
        }
        impl $name {
            /// Every id, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant),*];
            /// Human-readable name (also the GPU timing label of a pass).
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $text),*
                }
            }
        }
    };
}

ids!(
    /// A pass of the frame. Declaration order is the linear execution order.
    PassId {
        /// Triangles in frame coordinates from the vertex and index buffers.
        PrimBuffer = "prim buffer",
        /// Depth from the light (the conventional shadow map), square, for PCSS.
        ShadowMap = "shadow map",
        /// The primitive map: receivers placed and fitted, triangles culled, counted, scanned and binned into
        /// exact per-texel lists.
        PrimitiveMap = "primitive map",
        /// The primitive map statistics (entries, list lengths, capacity) read back, and its occupancy view.
        Occupancy = "occupancy",
        /// Shadow rays through the primitive map: hard visibility and blocker distance.
        RayTrace = "ray trace",
        /// The classic single-tap shadow-map test with a depth bias (for comparison, not for the hybrid).
        ShadowMapTest = "shadow map test",
        /// Blocker search, penumbra estimate and PCF over the shadow map.
        Pcss = "PCSS",
        /// FXAA over the ray-traced visibility.
        Fxaa = "FXAA",
        /// `L = saturate(BD / WSS * PHS)` from the ray-traced blocker distance.
        LerpFactor = "lerp factor",
        /// `FS = lerp(RTS, PCSS, L)`.
        Blend = "hybrid blend",
        /// Fills the output with 1 (mode none).
        FillLit = "fill lit",
    }
);

ids!(
    /// A resource a pass reads or writes.
    ResourceId {
        /// The engine's vertex and index buffers (external).
        SceneGeometry = "scene geometry",
        /// The light of the frame (external parameters: matrices, position, direction).
        Light = "light",
        /// The engine's depth buffer (external, rewritten every frame).
        Depth = "depth",
        /// The engine's normal buffer (external, rewritten every frame).
        Normal = "normal",
        /// Triangles in frame coordinates.
        PrimBuffer = "prim buffer",
        /// Light-space depth, `D32_SFLOAT`, size².
        ShadowMap = "shadow map",
        /// Primitive map list offsets, N² + 1 `u32` (with the receiver map, per-pixel texels and the fit).
        PrimListOffsets = "prim list offsets",
        /// Primitive map list entries: triangle indices, as many as the frame needs.
        PrimListEntries = "prim list entries",
        /// Occupancy view N² RGBA8 and the map statistics.
        Occupancy = "occupancy",
        /// Ray-traced visibility (1 = lit).
        RtVisibility = "rt visibility",
        /// Ray-traced blocker distance.
        BlockerDistance = "blocker distance",
        /// Classic shadow-map visibility (comparison output).
        ShadowMapVisibility = "shadow map visibility",
        /// PCSS visibility.
        Pcss = "pcss visibility",
        /// FXAA'd ray-traced visibility.
        RtAntialiased = "rt visibility (FXAA)",
        /// Hybrid lerp factor.
        LerpFactor = "lerp factor",
        /// Hybrid visibility.
        Hybrid = "hybrid visibility",
        /// Constant 1 (mode none).
        Lit = "lit",
    }
);

impl ResourceId {
    /// Whether the engine owns it (never allocated by the pipeline).
    pub fn is_external(self) -> bool {
        matches!(
            self,
            Self::SceneGeometry | Self::Light | Self::Depth | Self::Normal
        )
    }

    fn bit(self) -> u32 {
        1 << (self as u32)
    }
}

/// A set of resources (a bit set over [`ResourceId`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct ResourceSet(u32);

impl ResourceSet {
    /// The empty set.
    pub const EMPTY: Self = Self(0);

    /// The set of `ids`.
    pub fn of(ids: &[ResourceId]) -> Self {
        ids.iter().fold(Self::EMPTY, |s, &r| s.with(r))
    }

    /// This set plus `r`.
    #[must_use]
    pub fn with(self, r: ResourceId) -> Self {
        Self(self.0 | r.bit())
    }

    /// Whether `r` is in the set.
    pub fn contains(self, r: ResourceId) -> bool {
        self.0 & r.bit() != 0
    }

    /// Whether the sets share a resource.
    pub fn intersects(self, other: Self) -> bool {
        self.0 & other.0 != 0
    }

    /// The union.
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }

    /// This set without the members of `other`.
    #[must_use]
    pub fn difference(self, other: Self) -> Self {
        Self(self.0 & !other.0)
    }

    /// The members, in [`ResourceId`] order.
    pub fn iter(self) -> impl Iterator<Item = ResourceId> {
        ResourceId::ALL
            .iter()
            .copied()
            .filter(move |&r| self.contains(r))
    }
}

/// What the caller asks of the plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PlanRequest {
    /// The light's shadow mode.
    pub mode: ShadowMode,
    /// FXAA over the ray-traced visibility (ignored when the mode has no ray-traced shadow).
    pub antialiasing: bool,
    /// PCSS penumbra filter. A shrinking filter takes its hard edge from the ray trace when the plan runs it
    /// anyway, else from the shadow map's own single-tap test.
    pub filter: PenumbraFilter,
    /// Resources the caller wants besides the final output (debug views, comparison images, a host
    /// G-buffer that rasterizes the prim buffer).
    pub extra_outputs: ResourceSet,
}

impl PlanRequest {
    /// The resource holding the final visibility of `mode` (with or without antialiasing).
    pub fn final_output(&self) -> ResourceId {
        match self.mode {
            ShadowMode::None => ResourceId::Lit,
            ShadowMode::Hard if self.antialiasing => ResourceId::RtAntialiased,
            ShadowMode::Hard | ShadowMode::Area | ShadowMode::Auto => ResourceId::RtVisibility,
            ShadowMode::Soft => ResourceId::Pcss,
            ShadowMode::Hybrid => ResourceId::Hybrid,
        }
    }
}

/// Where the shrinking PCSS filter takes its hard edge from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HardEdge {
    /// The ray-traced visibility (exact): PCSS is 1 wherever the ray trace is lit.
    RayTrace,
    /// The shadow map's own single-tap test at the receiver.
    ShadowMap,
}

/// The passes and resources of a request, derived once at creation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FramePlan {
    request: PlanRequest,
    live: Vec<PassId>,
    resources: ResourceSet,
    hard_edge: HardEdge,
}

/// The resources a request asks for: its final output and its extra outputs.
fn outputs(request: &PlanRequest) -> ResourceSet {
    request.extra_outputs.with(request.final_output())
}

/// Whether the ray trace writes the blocker distance: the hybrid's lerp factor reads it, or the caller asked
/// for it (or for the lerp factor). Otherwise it is not allocated (a screen-size image saved per light).
fn writes_blocker_distance(request: &PlanRequest) -> bool {
    let outputs = outputs(request);
    request.mode == ShadowMode::Hybrid
        || outputs.contains(ResourceId::BlockerDistance)
        || outputs.contains(ResourceId::LerpFactor)
}

/// What a live pass reads and writes under a request.
fn io(pass: PassId, request: &PlanRequest, hard_edge: HardEdge) -> (ResourceSet, ResourceSet) {
    use ResourceId as R;
    let screen = [R::Depth, R::Normal];
    let (reads, writes): (Vec<R>, Vec<R>) = match pass {
        PassId::PrimBuffer => (vec![R::SceneGeometry], vec![R::PrimBuffer]),
        PassId::ShadowMap => (vec![R::PrimBuffer, R::Light], vec![R::ShadowMap]),
        PassId::PrimitiveMap => (
            [&screen[..], &[R::PrimBuffer, R::Light]].concat(),
            vec![R::PrimListOffsets, R::PrimListEntries],
        ),
        // The view, when asked for (the statistics are read back after the ray trace).
        PassId::Occupancy => (
            vec![R::PrimListOffsets],
            if outputs(request).contains(R::Occupancy) {
                vec![R::Occupancy]
            } else {
                vec![]
            },
        ),
        PassId::RayTrace => (
            [
                &screen[..],
                &[
                    R::PrimBuffer,
                    R::PrimListOffsets,
                    R::PrimListEntries,
                    R::Light,
                ],
            ]
            .concat(),
            if writes_blocker_distance(request) {
                vec![R::RtVisibility, R::BlockerDistance]
            } else {
                vec![R::RtVisibility]
            },
        ),
        PassId::ShadowMapTest => (
            [&screen[..], &[R::ShadowMap, R::Light]].concat(),
            vec![R::ShadowMapVisibility],
        ),
        PassId::Pcss => {
            let mut r = [&screen[..], &[R::ShadowMap, R::Light]].concat();
            if request.filter == PenumbraFilter::Shrinking && hard_edge == HardEdge::RayTrace {
                r.push(R::RtVisibility);
            }
            (r, vec![R::Pcss])
        }
        PassId::Fxaa => (vec![R::RtVisibility], vec![R::RtAntialiased]),
        PassId::LerpFactor => (vec![R::BlockerDistance], vec![R::LerpFactor]),
        PassId::Blend => {
            let rts = if request.antialiasing {
                R::RtAntialiased
            } else {
                R::RtVisibility
            };
            (vec![rts, R::Pcss, R::LerpFactor], vec![R::Hybrid])
        }
        PassId::FillLit => (vec![], vec![R::Lit]),
    };
    (ResourceSet::of(&reads), ResourceSet::of(&writes))
}

/// Backward culling: the live passes (in linear order) for `needed` outputs.
fn cull(request: &PlanRequest, hard_edge: HardEdge, mut needed: ResourceSet) -> Vec<PassId> {
    let mut live = Vec::new();
    for &pass in PassId::ALL.iter().rev() {
        let (reads, writes) = io(pass, request, hard_edge);
        if writes.intersects(needed) {
            needed = needed.union(reads);
            live.push(pass);
        }
    }
    live.reverse();
    live
}

impl FramePlan {
    /// Derives the plan of `request` (pure).
    pub fn derive(request: PlanRequest) -> Self {
        let outputs = outputs(&request);
        // First without PCSS's optional read of the ray trace: PCSS takes its hard edge from the ray trace
        // only when something else already needs the ray trace, so asking for soft shadows never pulls in
        // the primitive map.
        let first = cull(&request, HardEdge::ShadowMap, outputs);
        let hard_edge = if first.contains(&PassId::RayTrace) {
            HardEdge::RayTrace
        } else {
            HardEdge::ShadowMap
        };
        let live = cull(&request, hard_edge, outputs);
        let resources = live
            .iter()
            .map(|&p| io(p, &request, hard_edge).1)
            .fold(ResourceSet::EMPTY, ResourceSet::union);
        Self {
            request,
            live,
            resources,
            hard_edge,
        }
    }

    /// The request.
    pub fn request(&self) -> &PlanRequest {
        &self.request
    }

    /// Live passes in execution order.
    pub fn passes(&self) -> &[PassId] {
        &self.live
    }

    /// Whether `pass` is live.
    pub fn runs(&self, pass: PassId) -> bool {
        self.live.contains(&pass)
    }

    /// Resources the pipeline allocates (written by a live pass).
    pub fn resources(&self) -> ResourceSet {
        self.resources
    }

    /// Where the shrinking PCSS filter takes its hard edge from.
    pub fn hard_edge(&self) -> HardEdge {
        self.hard_edge
    }

    /// The resource holding the final visibility.
    pub fn final_output(&self) -> ResourceId {
        self.request.final_output()
    }

    /// What `pass` reads under this plan.
    pub fn reads(&self, pass: PassId) -> ResourceSet {
        io(pass, &self.request, self.hard_edge).0
    }

    /// What `pass` writes.
    pub fn writes(&self, pass: PassId) -> ResourceSet {
        io(pass, &self.request, self.hard_edge).1
    }

    /// Decides which passes run this frame (pure). `changed` holds the external inputs that changed since
    /// the last frame (or that the caller declared dynamic); `valid` the resources whose contents are
    /// still valid from earlier frames. A live pass runs when one of its reads changed (or was rewritten
    /// earlier in this frame), when one of its writes is not valid, or when it writes the final output
    /// (the engine reads it and may transition it between frames). Returns every pass of the linear
    /// order with its status.
    pub fn schedule(&self, changed: ResourceSet, valid: ResourceSet) -> Vec<(PassId, PassStatus)> {
        let mut dirty = changed;
        PassId::ALL
            .iter()
            .map(|&pass| {
                if !self.runs(pass) {
                    return (pass, PassStatus::Skipped(SkipReason::NotRequested));
                }
                let (reads, writes) = io(pass, &self.request, self.hard_edge);
                let missing = writes.iter().any(|w| !valid.contains(w));
                let run =
                    reads.intersects(dirty) || missing || writes.contains(self.final_output());
                if run {
                    dirty = dirty.union(writes);
                    (pass, PassStatus::Ran)
                } else {
                    (pass, PassStatus::Skipped(SkipReason::UpToDate))
                }
            })
            .collect()
    }
}

/// Whether a pass ran this frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PassStatus {
    /// Recorded this frame.
    Ran,
    /// Not recorded.
    Skipped(SkipReason),
}

/// Why a pass did not run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkipReason {
    /// No requested output depends on it (culled; its resources are not allocated).
    NotRequested,
    /// Everything it reads is unchanged since it last ran (static geometry; a static light whose
    /// parameters did not change), so its outputs from an earlier frame are reused.
    UpToDate,
    /// Shared with other lights' pipelines (the prim buffer), and built this frame by another of them.
    Shared,
    /// The frustum holds no receiver in view within the light's range this frame: nothing of it is
    /// recorded (a host that culls frusta, as the plugin does with [`crate::ViewVolume`], reports it).
    Culled,
}

impl SkipReason {
    /// A sentence for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Self::NotRequested => "culled: no requested output depends on it",
            Self::UpToDate => "inputs unchanged since it last ran: earlier output reused",
            Self::Shared => "shared by the lights: built this frame by another light's passes",
            Self::Culled => "the frustum holds no receiver in view within the light's range",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use PassId as P;
    use ResourceId as R;

    fn plan(mode: ShadowMode, aa: bool) -> FramePlan {
        FramePlan::derive(PlanRequest {
            mode,
            antialiasing: aa,
            filter: PenumbraFilter::Shrinking,
            extra_outputs: ResourceSet::EMPTY,
        })
    }

    #[test]
    fn area_runs_the_map_and_its_ray_trace_alone_and_ignores_antialiasing() {
        for aa in [false, true] {
            let p = plan(ShadowMode::Area, aa);
            assert_eq!(p.passes(), &[P::PrimBuffer, P::PrimitiveMap, P::RayTrace]);
            assert_eq!(p.final_output(), R::RtVisibility);
            assert!(!p.resources().contains(R::BlockerDistance));
            assert!(!p.resources().contains(R::ShadowMap));
        }
    }

    /// Auto chooses hard or area per light by its size; unresolved, it plans what both share: the ray
    /// trace through the map, without antialiasing.
    #[test]
    fn auto_chooses_by_size_and_unresolved_plans_what_hard_and_area_share() {
        assert_eq!(ShadowMode::for_light_size(0.0), ShadowMode::Hard);
        assert_eq!(ShadowMode::for_light_size(1e-6), ShadowMode::Area);
        for aa in [false, true] {
            let p = plan(ShadowMode::Auto, aa);
            assert_eq!(p.passes(), plan(ShadowMode::Area, aa).passes());
            assert_eq!(p.passes(), plan(ShadowMode::Hard, false).passes());
            assert_eq!(p.final_output(), R::RtVisibility);
        }
        assert!(ShadowMode::Auto.traces_rays());
    }

    #[test]
    fn hybrid_with_aa_runs_everything_but_the_comparison_passes() {
        let p = plan(ShadowMode::Hybrid, true);
        assert_eq!(
            p.passes(),
            &[
                P::PrimBuffer,
                P::ShadowMap,
                P::PrimitiveMap,
                P::RayTrace,
                P::Pcss,
                P::Fxaa,
                P::LerpFactor,
                P::Blend
            ]
        );
        assert_eq!(p.final_output(), R::Hybrid);
        assert_eq!(p.hard_edge(), HardEdge::RayTrace);
        assert!(p.reads(P::Pcss).contains(R::RtVisibility));
        assert!(p.reads(P::Blend).contains(R::RtAntialiased));
        assert!(!p.resources().contains(R::ShadowMapVisibility));
        assert!(!p.resources().contains(R::Lit));
    }

    #[test]
    fn hybrid_without_aa_blends_the_raw_ray_trace() {
        let p = plan(ShadowMode::Hybrid, false);
        assert!(!p.runs(P::Fxaa));
        assert!(!p.resources().contains(R::RtAntialiased));
        assert!(p.reads(P::Blend).contains(R::RtVisibility));
    }

    #[test]
    fn hard_never_allocates_a_shadow_map() {
        let p = plan(ShadowMode::Hard, false);
        assert_eq!(p.passes(), &[P::PrimBuffer, P::PrimitiveMap, P::RayTrace]);
        assert!(!p.resources().contains(R::ShadowMap));
        assert_eq!(p.final_output(), R::RtVisibility);
        let aa = plan(ShadowMode::Hard, true);
        assert_eq!(aa.final_output(), R::RtAntialiased);
        assert!(aa.runs(P::Fxaa));
    }

    #[test]
    fn the_blocker_distance_exists_for_the_hybrid_or_when_asked_for() {
        let hard = plan(ShadowMode::Hard, true);
        assert!(!hard.resources().contains(R::BlockerDistance));
        assert!(!hard.writes(P::RayTrace).contains(R::BlockerDistance));
        assert!(plan(ShadowMode::Hybrid, true)
            .resources()
            .contains(R::BlockerDistance));
        let asked = FramePlan::derive(PlanRequest {
            extra_outputs: ResourceSet::of(&[R::BlockerDistance]),
            ..hard.request
        });
        assert_eq!(asked.passes(), hard.passes());
        assert!(asked.writes(P::RayTrace).contains(R::BlockerDistance));
    }

    #[test]
    fn the_occupancy_view_exists_only_when_asked_for() {
        let stats_only = plan(ShadowMode::Hard, false);
        assert!(!stats_only.runs(P::Occupancy));
        assert!(!stats_only.resources().contains(R::Occupancy));
        let with_view = FramePlan::derive(PlanRequest {
            extra_outputs: ResourceSet::of(&[R::Occupancy]),
            ..stats_only.request
        });
        assert!(with_view.runs(P::Occupancy));
        assert!(with_view.resources().contains(R::Occupancy));
    }

    #[test]
    fn soft_never_builds_the_primitive_map() {
        let p = plan(ShadowMode::Soft, true);
        assert_eq!(p.passes(), &[P::PrimBuffer, P::ShadowMap, P::Pcss]);
        assert_eq!(p.hard_edge(), HardEdge::ShadowMap);
        assert!(!p.reads(P::Pcss).contains(R::RtVisibility));
        for r in [
            R::PrimListOffsets,
            R::PrimListEntries,
            R::RtVisibility,
            R::Occupancy,
        ] {
            assert!(!p.resources().contains(r), "{r:?}");
        }
    }

    #[test]
    fn none_runs_only_the_fill() {
        let p = plan(ShadowMode::None, true);
        assert_eq!(p.passes(), &[P::FillLit]);
        assert_eq!(p.resources(), ResourceSet::of(&[R::Lit]));
    }

    #[test]
    fn extras_pull_in_their_producers_only() {
        let p = FramePlan::derive(PlanRequest {
            mode: ShadowMode::Hard,
            antialiasing: false,
            filter: PenumbraFilter::Shrinking,
            extra_outputs: ResourceSet::of(&[R::Pcss, R::ShadowMapVisibility]),
        });
        assert!(p.runs(P::ShadowMap) && p.runs(P::Pcss) && p.runs(P::ShadowMapTest));
        assert!(!p.runs(P::Blend) && !p.runs(P::LerpFactor));
        // The ray trace runs anyway, so the shrinking filter uses its exact edge.
        assert_eq!(p.hard_edge(), HardEdge::RayTrace);
        let standard = FramePlan::derive(PlanRequest {
            filter: PenumbraFilter::Standard,
            ..*p.request()
        });
        assert!(!standard.reads(P::Pcss).contains(R::RtVisibility));
    }

    #[test]
    fn externals_are_never_allocated() {
        for mode in [
            ShadowMode::None,
            ShadowMode::Hard,
            ShadowMode::Soft,
            ShadowMode::Hybrid,
        ] {
            let p = plan(mode, true);
            assert!(p.resources().iter().all(|r| !r.is_external()), "{mode:?}");
            // Every read is external or produced by an earlier live pass.
            let mut available = ResourceSet::EMPTY;
            for &pass in p.passes() {
                for r in p.reads(pass).iter() {
                    assert!(
                        r.is_external() || available.contains(r),
                        "{pass:?} reads {r:?}"
                    );
                }
                available = available.union(p.writes(pass));
            }
            assert!(available.contains(p.final_output()));
        }
    }

    fn ran(schedule: &[(PassId, PassStatus)]) -> Vec<PassId> {
        schedule
            .iter()
            .filter(|(_, s)| *s == PassStatus::Ran)
            .map(|(p, _)| *p)
            .collect()
    }

    #[test]
    fn first_frame_runs_every_live_pass() {
        let p = plan(ShadowMode::Hybrid, true);
        let all_external = ResourceSet::of(&[R::SceneGeometry, R::Light, R::Depth, R::Normal]);
        let s = p.schedule(all_external, ResourceSet::EMPTY);
        assert_eq!(s.len(), PassId::ALL.len());
        assert_eq!(ran(&s), p.passes());
        assert!(s.contains(&(
            P::ShadowMapTest,
            PassStatus::Skipped(SkipReason::NotRequested)
        )));
    }

    #[test]
    fn static_geometry_and_light_skip_the_light_space_passes() {
        let p = plan(ShadowMode::Hybrid, true);
        let valid = p.resources();
        let screen_only = ResourceSet::of(&[R::Depth, R::Normal]);
        let s = p.schedule(screen_only, valid);
        // The primitive map is fitted to the receivers in the depth buffer: it follows the camera.
        assert_eq!(
            ran(&s),
            &[
                P::PrimitiveMap,
                P::RayTrace,
                P::Pcss,
                P::Fxaa,
                P::LerpFactor,
                P::Blend
            ]
        );
        for pass in [P::PrimBuffer, P::ShadowMap] {
            assert!(s.contains(&(pass, PassStatus::Skipped(SkipReason::UpToDate))));
        }
        // A moving light re-renders the shadow map but not the prim buffer.
        let s = p.schedule(screen_only.with(R::Light), valid);
        assert_eq!(ran(&s)[..3], [P::ShadowMap, P::PrimitiveMap, P::RayTrace]);
        // Dynamic geometry rebuilds everything downstream of the prim buffer.
        let s = p.schedule(screen_only.with(R::SceneGeometry), valid);
        assert_eq!(ran(&s), p.passes());
    }

    #[test]
    fn the_final_output_is_always_written() {
        let p = plan(ShadowMode::None, false);
        let s = p.schedule(ResourceSet::EMPTY, p.resources());
        assert_eq!(ran(&s), &[P::FillLit]);
    }

    #[test]
    fn sets() {
        let s = ResourceSet::of(&[R::Pcss, R::Depth]);
        assert!(s.contains(R::Pcss) && !s.contains(R::Hybrid));
        assert_eq!(s.iter().collect::<Vec<_>>(), vec![R::Depth, R::Pcss]);
        assert!(s.intersects(ResourceSet::of(&[R::Depth])));
        assert!(!s.intersects(ResourceSet::EMPTY));
        assert!(ResourceId::ALL.len() <= 32);
    }
}

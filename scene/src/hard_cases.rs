//! The hard numerical cases of ray-traced shadows through a deep primitive map, as data.
//!
//! Every case is generated deterministically: a [`Scene`] (or the error that loading it must produce),
//! a directional light, an optional camera, the frame and primitive-map sizes it is meant for, and what
//! must hold besides agreement with the exact reference ([`Check`]s that are decided analytically from the
//! receiver positions, so that they do not depend on the reference's tolerance classification).
//!
//! The renderer that runs them (the `host_demo hardcases` subcommand and the `hard_cases` integration
//! test) lives outside this crate; this module knows nothing about GPUs.
//!
//! Families ([`Family`]):
//! - **shared edges**: closed or edge-sharing blockers whose shadow rays pass exactly through shared edges
//!   and vertices (a triangle fan, a grid plate, a box built from grids, a UV sphere), light straight down
//!   and a camera in the plane `x = 0`, so that a whole pixel column of receivers lies under the `x = 0`
//!   edges and the centre pixel under the fan's centre vertex and the sphere's poles;
//! - **grazing**: light at 80°, 89° and 89.9° from the normal of a tilted tessellated plane and of the top
//!   facet of a large tube (no acne);
//! - **contact**: a box standing on a plane under the same grazing lights (no peter-panning);
//! - **scale**: the demo scene translated by 1e3, 1e4, 1e5 and scaled by 1e-3 and 1e3, camera and light
//!   following;
//! - **small triangles**: sub-texel, needle and zero-area triangles;
//! - **texel boundaries**: triangles whose vertices are primitive-map texel corners;
//! - **frustum border**: triangles crossing the border and the near and far planes of a light matrix
//!   that covers only part of the scene (a fitted matrix encloses every vertex by construction);
//! - **coplanar**: overlapping coplanar faces, a decal on the ground and boxes stacked face to face;
//! - **thin geometry**: thin closed plates and zero-thickness foliage cards;
//! - **models**: real models from the shared model folder;
//! - **non-finite**: NaN/Inf input, which must be rejected at load time;
//! - **overflow**: entry budgets of 1 to 4 entries per texel, which must be passed without writing out of
//!   bounds.

use std::f64::consts::TAU;
use std::path::Path;

use glam::{DMat4, DQuat, DVec3, Mat4, Vec3};

use crate::obj::parse_obj;
use crate::scene::ground_square;
use crate::{
    load_obj, procedural_default, Aabb, Camera, DirectionalLight, MeshBuilder, Scene, SceneError,
    SplitMix64,
};

/// A group of related cases (one integration test each).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Family {
    /// Shadow rays through shared edges and vertices of closed or edge-sharing blockers: no leaks.
    SharedEdges,
    /// Grazing light on planes and curved surfaces: no acne.
    Grazing,
    /// A box standing on a plane under grazing light: no peter-panning.
    Contact,
    /// Translated and scaled copies of one scene: same result as the original.
    Scale,
    /// Sub-texel, needle and zero-area triangles.
    SmallTriangles,
    /// Triangles with vertices on primitive-map texel corners.
    TexelBoundaries,
    /// Triangles crossing the border and the depth range of the light's map.
    FrustumBorder,
    /// Coplanar overlapping faces.
    Coplanar,
    /// Thin closed plates and zero-thickness cards.
    ThinGeometry,
    /// Real models.
    Models,
    /// NaN/Inf input geometry: rejected at load time.
    NonFinite,
    /// Primitive-map lists past an entry budget of 1 to 4 entries per texel.
    Overflow,
}

impl Family {
    /// Every family, in table order.
    pub const ALL: [Family; 12] = [
        Family::SharedEdges,
        Family::Grazing,
        Family::Contact,
        Family::Scale,
        Family::SmallTriangles,
        Family::TexelBoundaries,
        Family::FrustumBorder,
        Family::Coplanar,
        Family::ThinGeometry,
        Family::Models,
        Family::NonFinite,
        Family::Overflow,
    ];

    /// Short kebab-case name (used on the command line).
    pub fn name(self) -> &'static str {
        match self {
            Family::SharedEdges => "shared-edges",
            Family::Grazing => "grazing",
            Family::Contact => "contact",
            Family::Scale => "scale",
            Family::SmallTriangles => "small-triangles",
            Family::TexelBoundaries => "texel-boundaries",
            Family::FrustumBorder => "frustum-border",
            Family::Coplanar => "coplanar",
            Family::ThinGeometry => "thin-geometry",
            Family::Models => "models",
            Family::NonFinite => "non-finite",
            Family::Overflow => "overflow",
        }
    }

    /// The family called `name` (see [`Family::name`]).
    pub fn from_name(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// Frame size in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

/// Whether the primitive map of a case may or must overflow (lists past the entry capacity).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Overflow {
    /// No texel may pass the entry capacity: the case tests the texel lists, not the exhaustive fallback.
    Forbidden,
    /// Overflow is allowed (its fallback is exact).
    Allowed,
    /// At least one texel must pass the entry capacity: the case tests the fallback.
    Required,
}

/// The deep primitive map a case is meant for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MapSpec {
    /// N: texels per side.
    pub size: u32,
    /// Entry budget of the primitive map's lists, in entries (past it, texels are traced exhaustively),
    /// or `None` for the default budget.
    pub entry_budget: Option<u32>,
    /// Store only light-facing triangles (closed meshes); otherwise both faces.
    pub front_faces_only: bool,
    /// Allocate guard words past the entry capacity, which must stay untouched.
    pub guard: bool,
    /// Bin only into texels with ray origins, and skip triangles behind all of them (the default); off,
    /// every texel of the fitted grid gets every triangle over it.
    pub receiver_culling: bool,
    /// Whether overflow is expected.
    pub overflow: Overflow,
}

impl MapSpec {
    /// Both faces, no guard layer, overflow forbidden.
    pub const fn new(size: u32) -> Self {
        Self {
            size,
            entry_budget: None,
            front_faces_only: false,
            guard: false,
            receiver_culling: true,
            overflow: Overflow::Forbidden,
        }
    }
}

/// A convex blocker described analytically.
#[derive(Debug, Clone, PartialEq)]
pub enum Solid {
    /// A ball contained in the blocker (for a tessellated sphere: its inscribed ball).
    Ball {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// An axis-aligned box filled by the blocker.
    Box(Aabb),
    /// A planar convex polygon (vertices in order, either orientation) covered by the blocker.
    Polygon(Vec<Vec3>),
}

/// What must hold for a case besides agreement with the exact reference, decided per pixel from the
/// GPU's receiver position with a margin of a few pixel footprints.
#[derive(Debug, Clone, PartialEq)]
pub enum Check {
    /// Every receiver whose shadow ray passes through the solid shrunk by the margin must be shadowed;
    /// a lit one is a **leak**.
    Shadowed(Solid),
    /// Every light-facing receiver inside the box must be lit (nothing lies between it and the light); a
    /// shadowed one is **acne**.
    Lit(Aabb),
    /// The box stands on a horizontal receiver at its `min.y`: every such receiver whose shadow ray enters
    /// the box's footprint (shrunk by the margin) below its top (lowered by the margin) must be shadowed.
    /// The largest screen distance between a lit one and the footprint edge is the **contact gap**, which
    /// must stay below one pixel (no peter-panning).
    Contact(Aabb),
    /// The visibility image must equal the one of the case named `base` (rendered earlier in the same
    /// family) on every pixel that neither reference puts near an edge, and differ on at most
    /// `max_differing_pixels` pixels in all.
    SameAs {
        /// Name of the base case.
        base: &'static str,
        /// Largest number of pixels allowed to differ.
        max_differing_pixels: usize,
    },
}

/// What a case expects.
#[derive(Debug, Clone, PartialEq)]
pub enum Expectation {
    /// The scene loads and renders; visibility matches the exact reference outside near-edge pixels, no
    /// output is NaN/Inf, and the checks hold.
    Renders(Vec<Check>),
    /// Loading must fail with [`SceneError::NonFinite`].
    RejectedAtLoad,
}

/// One hard case.
#[derive(Debug)]
pub struct HardCase {
    /// Unique name (the row of the table).
    pub name: &'static str,
    /// Family.
    pub family: Family,
    /// What the scene contains and why it is hard.
    pub description: &'static str,
    /// The scene, or the error loading it produced.
    pub scene: Result<Scene, SceneError>,
    /// Direction the light travels.
    pub light_direction: Vec3,
    /// Camera; `None`: framed automatically by the renderer.
    pub camera: Option<Camera>,
    /// Light view-projection replacing the one fitted to the scene bounds; `None`: fitted.
    pub light_view_proj: Option<Mat4>,
    /// Frame size.
    pub frame: Frame,
    /// Primitive map.
    pub map: MapSpec,
    /// What must hold.
    pub expectation: Expectation,
}

/// Every case of every family, in table order. Model cases read `models` (the shared model folder); a
/// missing model gives a case whose scene is the load error.
pub fn all(models: &Path) -> Vec<HardCase> {
    Family::ALL
        .into_iter()
        .flat_map(|f| family(f, models))
        .collect()
}

/// The cases of one family, in table order (see [`all`]).
pub fn family(family: Family, models: &Path) -> Vec<HardCase> {
    match family {
        Family::SharedEdges => shared_edges(),
        Family::Grazing => grazing(),
        Family::Contact => contact(),
        Family::Scale => scale(),
        Family::SmallTriangles => small_triangles(),
        Family::TexelBoundaries => texel_boundaries(),
        Family::FrustumBorder => frustum_border(),
        Family::Coplanar => coplanar(),
        Family::ThinGeometry => thin_geometry(),
        Family::Models => real_models(models),
        Family::NonFinite => non_finite(),
        Family::Overflow => overflow(),
    }
}

/// Odd frame: the centre pixel column and row have NDC x = 0 and y = 0 exactly, so their camera rays lie
/// in the camera's vertical and horizontal planes through the target.
const FRAME: Frame = Frame {
    width: 193,
    height: 145,
};

/// A case rendering `scene` with both faces stored in the standard frame; add its checks with
/// [`HardCase::checking`].
fn case(
    name: &'static str,
    family: Family,
    description: &'static str,
    scene: Scene,
    light_direction: Vec3,
    camera: Option<Camera>,
    map: MapSpec,
) -> HardCase {
    HardCase {
        name,
        family,
        description,
        scene: Ok(scene),
        light_direction,
        camera,
        light_view_proj: None,
        frame: FRAME,
        map,
        expectation: Expectation::Renders(Vec::new()),
    }
}

impl HardCase {
    /// This case with `checks` to hold besides agreement with the reference.
    fn checking(self, checks: Vec<Check>) -> Self {
        Self {
            expectation: Expectation::Renders(checks),
            ..self
        }
    }
}

/// A 45° camera at `position` looking at `target` (up +Y), near plane at 1% of the distance.
fn look(position: Vec3, target: Vec3) -> Camera {
    Camera {
        position,
        target,
        up: Vec3::Y,
        fov_y_radians: 45f32.to_radians(),
        near: 0.01 * (target - position).length(),
    }
}

/// The ground object: a horizontal square of side `side` centred on the origin at y = 0.
fn ground(side: f32) -> Scene {
    ground_square("ground", Vec3::ZERO, side)
}

/// `scene` with the objects of every mesh appended.
fn with(mut scene: Scene, meshes: impl IntoIterator<Item = Scene>) -> Scene {
    for m in meshes {
        scene.append(&m);
    }
    scene
}

/// Axis-aligned box from f64 corners (rounded to f32).
fn aabb(min: [f64; 3], max: [f64; 3]) -> Aabb {
    Aabb {
        min: DVec3::from(min).as_vec3(),
        max: DVec3::from(max).as_vec3(),
    }
}

/// `(cos, sin)` of `2π · num / den`, reduced to the first octant with exact integer arithmetic, so that
/// angles related by quarter turns and mirror symmetries give bit-identical magnitudes and angles on the
/// axes give exact zeros and ones.
fn circle(num: i64, den: i64) -> (f64, f64) {
    let full = 8 * den;
    let mut q = (8 * num).rem_euclid(full);
    let (mut cos_sign, mut sin_sign) = (1.0, 1.0);
    if q > full / 2 {
        q = full - q;
        sin_sign = -1.0;
    }
    if q > full / 4 {
        q = full / 2 - q;
        cos_sign = -1.0;
    }
    let swap = q > full / 8;
    if swap {
        q = full / 4 - q;
    }
    let x = TAU * q as f64 / full as f64;
    let (c, s) = if swap {
        (x.sin(), x.cos())
    } else {
        (x.cos(), x.sin())
    };
    (cos_sign * c, sin_sign * s)
}

/// `points` rounded to f32.
fn rounded<const N: usize>(points: [DVec3; N]) -> [Vec3; N] {
    points.map(|p| p.as_vec3())
}

/// Adds the vertex `p` rounded to f32.
fn add_vertex(mesh: &mut MeshBuilder, p: DVec3) -> u32 {
    mesh.vertex(p.as_vec3())
}

/// Adds a grid of `nu` x `nv` quads over the parallelogram spanned from `corner` by `u` and `v`, facing
/// `u × v`, with shared vertices (computed in f64).
fn add_grid(mesh: &mut MeshBuilder, corner: DVec3, u: DVec3, v: DVec3, nu: u32, nv: u32) {
    let first = mesh.positions().len() as u32;
    for j in 0..=nv {
        for i in 0..=nu {
            add_vertex(
                mesh,
                corner + u * (f64::from(i) / f64::from(nu)) + v * (f64::from(j) / f64::from(nv)),
            );
        }
    }
    let at = |i: u32, j: u32| first + j * (nu + 1) + i;
    for j in 0..nv {
        for i in 0..nu {
            mesh.connect_quad([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
}

/// Adds a closed box whose faces are grids of `n[axis]` cells per axis, wound outwards. Every vertex is
/// taken from one lattice of coordinates, so vertices on shared edges are bit-identical.
fn add_lattice_box(mesh: &mut MeshBuilder, min: DVec3, max: DVec3, n: [u32; 3]) {
    let coordinate = |axis: usize, i: u32| -> f64 {
        if i == n[axis] {
            max[axis]
        } else {
            min[axis] + (max[axis] - min[axis]) * f64::from(i) / f64::from(n[axis])
        }
    };
    let [nx, ny, nz] = n;
    type Face = (u32, u32, fn(u32, u32, [u32; 3]) -> [u32; 3]);
    let faces: [Face; 6] = [
        (nz, ny, |i, j, [nx, _, nz]| [nx, j, nz - i]),
        (nz, ny, |i, j, _| [0, j, i]),
        (nx, nz, |i, j, [_, ny, nz]| [i, ny, nz - j]),
        (nx, nz, |i, j, _| [i, 0, j]),
        (nx, ny, |i, j, [_, _, nz]| [i, j, nz]),
        (nx, ny, |i, j, [nx, _, _]| [nx - i, j, 0]),
    ];
    for (nu, nv, lattice) in faces {
        let first = mesh.positions().len() as u32;
        for j in 0..=nv {
            for i in 0..=nu {
                let [x, y, z] = lattice(i, j, n);
                add_vertex(
                    mesh,
                    DVec3::new(coordinate(0, x), coordinate(1, y), coordinate(2, z)),
                );
            }
        }
        let at = |i: u32, j: u32| first + j * (nu + 1) + i;
        for j in 0..nv {
            for i in 0..nu {
                mesh.connect_quad([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
}

/// Adds a closed sphere of `rings` latitude bands and `segments` meridians, poles on the vertical axis,
/// meridian 0 towards +x, wound outwards. Unlike [`MeshBuilder::add_sphere`], its vertices come from
/// [`circle`], so that vertices related by the sphere's symmetries are bit-identical mirror images.
fn add_uv_sphere(mesh: &mut MeshBuilder, center: DVec3, radius: f64, rings: u32, segments: u32) {
    let bottom = add_vertex(mesh, center - DVec3::Y * radius);
    let ring_starts: Vec<u32> = (1..rings)
        .map(|k| {
            let (c, s) = circle(i64::from(k), 2 * i64::from(rings));
            let (y, rho) = (center.y - radius * c, radius * s);
            let start = mesh.positions().len() as u32;
            for j in 0..segments {
                let (cj, sj) = circle(i64::from(j), i64::from(segments));
                add_vertex(
                    mesh,
                    DVec3::new(center.x + rho * cj, y, center.z - rho * sj),
                );
            }
            start
        })
        .collect();
    let top = add_vertex(mesh, center + DVec3::Y * radius);
    let (first, last) = (ring_starts[0], ring_starts[ring_starts.len() - 1]);
    for j in 0..segments {
        let k = (j + 1) % segments;
        mesh.connect_triangle([bottom, first + k, first + j]);
        for pair in ring_starts.windows(2) {
            let (lo, up) = (pair[0], pair[1]);
            mesh.connect_quad([lo + j, lo + k, up + k, up + j]);
        }
        mesh.connect_triangle([top, last + j, last + k]);
    }
}

/// Adds an open tube along z (no caps), `segments` facets wound outwards; one facet faces exactly +y.
fn add_tube(mesh: &mut MeshBuilder, center: DVec3, radius: f64, half_length: f64, segments: u32) {
    let n = i64::from(segments);
    let first = mesh.positions().len() as u32;
    for j in 0..n {
        // Vertex j at π/2 + (2j + 1)π/n: the facet between the last and the first vertex is centred on +y.
        let (c, s) = circle(n + 4 * j + 2, 4 * n);
        for z in [-half_length, half_length] {
            add_vertex(mesh, center + DVec3::new(radius * c, radius * s, z));
        }
    }
    for j in 0..segments {
        let k = (j + 1) % segments;
        let (a, d) = (first + 2 * j, first + 2 * j + 1);
        let (b, c) = (first + 2 * k, first + 2 * k + 1);
        mesh.connect_quad([a, b, c, d]);
    }
}

/// Adds a horizontal disc of `n` fan triangles sharing the centre vertex, facing +y; rim vertex 0 towards
/// +x. Returns the rim polygon.
fn add_fan_disc(mesh: &mut MeshBuilder, center: DVec3, radius: f64, n: u32) -> Vec<Vec3> {
    let hub = add_vertex(mesh, center);
    let rim: Vec<u32> = (0..n)
        .map(|k| {
            let (c, s) = circle(i64::from(k), i64::from(n));
            add_vertex(mesh, center + DVec3::new(radius * c, 0.0, radius * s))
        })
        .collect();
    for k in 0..n as usize {
        let next = rim[(k + 1) % rim.len()];
        mesh.connect_triangle([hub, next, rim[k]]);
    }
    rim.iter().map(|&i| mesh.positions()[i as usize]).collect()
}

/// Radius of the largest ball around `center` inside the convex closed mesh `scene`: the smallest distance
/// from `center` to a triangle's plane (f64).
fn inscribed_radius(scene: &Scene, center: Vec3) -> f32 {
    let c = center.as_dvec3();
    (0..scene.triangle_count())
        .filter_map(|t| {
            let [a, b, d] = scene.triangle(t).map(|p| p.as_dvec3());
            let n = (b - a).cross(d - a).normalize_or_zero();
            (n != DVec3::ZERO).then(|| n.dot(a - c).abs())
        })
        .fold(f64::INFINITY, f64::min) as f32
}

/// The four corners of an axis-aligned horizontal rectangle at height `y`.
fn rectangle(x: [f64; 2], y: f64, z: [f64; 2]) -> Vec<Vec3> {
    [(x[0], z[0]), (x[1], z[0]), (x[1], z[1]), (x[0], z[1])]
        .map(|(x, z)| DVec3::new(x, y, z).as_vec3())
        .to_vec()
}

/// A horizontal quad facing +y over the rectangle `x` × `z` at height `y`.
fn plate(name: &str, x: [f64; 2], y: f64, z: [f64; 2]) -> Scene {
    let mut m = MeshBuilder::new();
    m.add_quad(rounded([
        DVec3::new(x[0], y, z[1]),
        DVec3::new(x[1], y, z[1]),
        DVec3::new(x[1], y, z[0]),
        DVec3::new(x[0], y, z[0]),
    ]));
    m.into_scene(name)
}

/// A closed box of 12 triangles.
fn solid_box(name: &str, min: [f64; 3], max: [f64; 3]) -> Scene {
    let mut m = MeshBuilder::new();
    add_lattice_box(&mut m, DVec3::from(min), DVec3::from(max), [1, 1, 1]);
    m.into_scene(name)
}

fn shared_edges() -> Vec<HardCase> {
    let down = Vec3::NEG_Y;
    let camera = Some(look(Vec3::new(0.0, 0.45, 2.5), Vec3::ZERO));
    let closed = MapSpec {
        front_faces_only: true,
        ..MapSpec::new(256)
    };

    let mut fan = MeshBuilder::new();
    let rim = add_fan_disc(&mut fan, DVec3::new(0.0, 1.0, 0.0), 1.0, 96);
    let mut plate_grid = MeshBuilder::new();
    add_grid(
        &mut plate_grid,
        DVec3::new(-1.0, 1.0, 1.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -2.0),
        32,
        32,
    );
    let mut grid_box = MeshBuilder::new();
    let (box_min, box_max) = ([-0.75, 0.75, -0.75], [0.75, 1.5, 0.75]);
    add_lattice_box(
        &mut grid_box,
        DVec3::from(box_min),
        DVec3::from(box_max),
        [8, 4, 8],
    );
    let mut sphere = MeshBuilder::new();
    let center = Vec3::new(0.0, 1.2, 0.0);
    add_uv_sphere(&mut sphere, center.as_dvec3(), 0.8, 24, 48);
    let sphere = sphere.into_scene("sphere");
    let radius = inscribed_radius(&sphere, center);

    vec![
        case(
            "fan disc (96 triangles, shared centre)",
            Family::SharedEdges,
            "A horizontal disc of 96 thin fan triangles 1 m above the ground, light straight \
             down: the receiver under the centre sends its ray through the vertex shared by all \
             96, the centre pixel column through the edges on x = 0 and the centre row through \
             the edges on z = 0.",
            with(ground(4.0), [fan.into_scene("fan")]),
            down,
            camera,
            MapSpec::new(256),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rim))]),
        case(
            "grid plate (32x32 quads)",
            Family::SharedEdges,
            "A 2 m plate of 2,048 triangles 1 m above the ground, light straight down: the centre \
             column and row of receivers lie exactly under grid edges and vertices.",
            with(ground(4.0), [plate_grid.into_scene("plate")]),
            down,
            camera,
            MapSpec::new(256),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rectangle(
            [-1.0, 1.0],
            1.0,
            [-1.0, 1.0],
        )))]),
        case(
            "closed grid box (front faces only)",
            Family::SharedEdges,
            "A floating closed box whose faces are 8x4x8 grids, bit-identical vertices on every \
             seam; only light-facing triangles are stored, so a single layer of shared edges must \
             stop every ray.",
            with(ground(4.0), [grid_box.into_scene("box")]),
            down,
            camera,
            closed,
        )
        .checking(vec![Check::Shadowed(Solid::Box(aabb(box_min, box_max)))]),
        case(
            "closed UV sphere (front faces only)",
            Family::SharedEdges,
            "A floating closed UV sphere (24 rings, 48 meridians); the centre receiver's ray \
             passes through both poles, where 48 triangles meet, and the centre column along \
             meridian edges.",
            with(ground(4.0), [sphere]),
            down,
            camera,
            closed,
        )
        .checking(vec![Check::Shadowed(Solid::Ball { center, radius })]),
    ]
}

/// `(name, degrees)` of the grazing angles.
const GRAZING: [(&str, &str, &str, f64); 3] = [
    ("plane 80°", "tube 80°", "contact 80°", 80.0),
    ("plane 89°", "tube 89°", "contact 89°", 89.0),
    ("plane 89.9°", "tube 89.9°", "contact 89.9°", 89.9),
];

fn grazing() -> Vec<HardCase> {
    let mut cases = Vec::new();
    let rotation = DQuat::from_axis_angle(DVec3::new(1.0, 0.0, 0.5).normalize(), 0.35);
    let center = DVec3::new(0.0, 1.0, 0.0);
    let (normal, tangent, bitangent) = (
        rotation * DVec3::Y,
        rotation * DVec3::X,
        rotation * DVec3::Z,
    );
    let mut plane = MeshBuilder::new();
    add_grid(
        &mut plane,
        center + rotation * DVec3::new(-2.0, 0.0, 2.0),
        rotation * DVec3::new(4.0, 0.0, 0.0),
        rotation * DVec3::new(0.0, 0.0, -4.0),
        12,
        12,
    );
    let plane = plane.into_scene("tilted plane");
    let mut plane_bounds = plane.bounds();
    plane_bounds.min -= Vec3::splat(1e-3);
    plane_bounds.max += Vec3::splat(1e-3);

    let radius = 20.0;
    let mut tube = MeshBuilder::new();
    add_tube(&mut tube, DVec3::ZERO, radius, 20.0, 512);
    let tube = tube.into_scene("tube");
    let mut tube_bounds = tube.bounds();
    tube_bounds.min -= Vec3::splat(1e-2);
    tube_bounds.max += Vec3::splat(1e-2);

    for (plane_name, tube_name, _, degrees) in GRAZING {
        let theta = degrees.to_radians();
        let to_light = normal * theta.cos() + tangent * theta.sin();
        cases.push(
            case(
                plane_name,
                Family::Grazing,
                "A 4 m plane of 288 triangles, tilted so that its f32 vertices are not exactly \
             coplanar, lit at a grazing angle from its normal: every receiver on it must be lit.",
                plane.clone(),
                (-to_light).as_vec3(),
                Some(look(
                    (center + normal * 3.0 + bitangent * 3.0).as_vec3(),
                    center.as_vec3(),
                )),
                MapSpec::new(256),
            )
            .checking(vec![Check::Lit(plane_bounds)]),
        );

        // The top facet's normal is +y; light at `theta` from it, in the xy plane.
        let to_light = DVec3::new(-theta.sin(), theta.cos(), 0.0);
        let mid = (90.0 + degrees).to_radians() * 0.5;
        let target = DVec3::new(mid.cos(), mid.sin(), 0.0) * radius;
        let outward = target.normalize();
        cases.push(
            case(
                tube_name,
                Family::Grazing,
                "A convex tube of radius 20 m and 512 facets (one facing exactly up), light at a \
             grazing angle from the top facet's normal; the view holds the terminator: every \
             light-facing facet must be lit.",
                tube.clone(),
                (-to_light).as_vec3(),
                Some(look(
                    (target + outward * 6.0 + DVec3::Z * 5.0).as_vec3(),
                    target.as_vec3(),
                )),
                MapSpec::new(256),
            )
            .checking(vec![Check::Lit(tube_bounds)]),
        );
    }
    cases
}

fn contact() -> Vec<HardCase> {
    let (min, max) = ([-0.5, 0.0, -0.5], [0.5, 1.0, 0.5]);
    let scene = with(ground(24.0), [solid_box("box", min, max)]);
    let azimuth = 20f64.to_radians();
    GRAZING
        .into_iter()
        .map(|(_, _, name, degrees)| {
            let theta = degrees.to_radians();
            let travel = DVec3::new(
                theta.sin() * azimuth.cos(),
                -theta.cos(),
                theta.sin() * azimuth.sin(),
            );
            case(
                name,
                Family::Contact,
                "A 1 m box standing on a 24 m ground plane (its bottom face coplanar with the \
                 ground), lit at a grazing angle from the vertical: the contact shadow must start \
                 at the box's footprint.",
                scene.clone(),
                travel.as_vec3(),
                Some(look(Vec3::new(3.0, 1.6, 3.5), Vec3::new(0.9, 0.0, 0.5))),
                MapSpec::new(256),
            )
            .checking(vec![Check::Contact(aabb(min, max))])
        })
        .collect()
}

/// Largest number of pixels of a translated copy whose visibility may differ from the original's, for
/// translations by 1e3, 1e4 and 1e5 (0.05%, 0.15% and 0.5% of the frame). The passes work relative to the
/// scene, but the input itself is f32: at 1e5 every vertex and the camera move by up to 3.9 mm when
/// translated (0.05 px at the camera's distance), which flips pixels lying on shadow edges and silhouettes;
/// the exact answer changes with them. Measured on lavapipe: 8, 27 and 91 pixels.
const TRANSLATED_DIFFERING_PIXELS: [usize; 3] = [14, 42, 140];
/// The same for the copies scaled by 1e-3 and 1e3: their rounding is relative (6e-8, 1e-5 px), so no pixel
/// may differ. Measured on lavapipe: 0 and 0.
const SCALED_DIFFERING_PIXELS: usize = 0;

fn scale() -> Vec<HardCase> {
    let base = procedural_default();
    let mut focus = Aabb::empty();
    for o in base.objects.iter().filter(|o| o.name != "ground") {
        for t in o.first_triangle..o.first_triangle + o.triangle_count {
            base.triangle(t as usize)
                .into_iter()
                .for_each(|p| focus.extend(p));
        }
    }
    let camera = Camera::frame(&focus, FRAME.width as f32 / FRAME.height as f32);
    let light = DirectionalLight::slanted().direction;
    let map = MapSpec {
        overflow: Overflow::Allowed,
        ..MapSpec::new(256)
    };
    let same = |max_differing_pixels| {
        vec![Check::SameAs {
            base: "demo scene",
            max_differing_pixels,
        }]
    };
    let description =
        "The demo scene (7,010 triangles: character, fence, foliage, sphere), camera and light \
         following the transform.";
    let mut cases = vec![case(
        "demo scene",
        Family::Scale,
        description,
        base.clone(),
        light,
        Some(camera),
        map,
    )];
    let offset = Vec3::new(1.0, 0.5, -0.75);
    for ((name, t), bound) in [
        ("translated by 1e3", 1e3),
        ("translated by 1e4", 1e4),
        ("translated by 1e5", 1e5),
    ]
    .into_iter()
    .zip(TRANSLATED_DIFFERING_PIXELS)
    {
        let o = offset * t;
        cases.push(
            case(
                name,
                Family::Scale,
                description,
                base.translated(o),
                light,
                Some(Camera {
                    position: camera.position + o,
                    target: camera.target + o,
                    ..camera
                }),
                map,
            )
            .checking(same(bound)),
        );
    }
    for (name, s) in [("scaled by 1e-3", 1e-3), ("scaled by 1e3", 1e3)] {
        cases.push(
            case(
                name,
                Family::Scale,
                description,
                base.scaled(s),
                light,
                Some(Camera {
                    position: camera.position * s,
                    target: camera.target * s,
                    near: camera.near * s,
                    ..camera
                }),
                map,
            )
            .checking(same(SCALED_DIFFERING_PIXELS)),
        );
    }
    cases
}

fn small_triangles() -> Vec<HardCase> {
    let light = DirectionalLight::slanted().direction;
    let camera = Some(look(Vec3::new(0.9, 1.5, 1.9), Vec3::new(0.2, 0.25, 0.0)));
    // Ground of 4 m on a 128 map: texels of 1/32 m.
    let texel = 4.0 / 128.0;

    let mut fine = MeshBuilder::new();
    add_grid(
        &mut fine,
        DVec3::new(-0.25, 0.6, 0.25),
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -0.5),
        48,
        48,
    );

    let mut rng = SplitMix64::new(0xd057);
    let mut dust = MeshBuilder::new();
    for _ in 0..1500 {
        let c = DVec3::new(
            f64::from(rng.uniform_f32(-1.0, 1.0)) * 0.5,
            0.3 + f64::from(rng.next_f32()) * 0.5,
            f64::from(rng.uniform_f32(-1.0, 1.0)) * 0.5,
        );
        let size = texel * (0.1 + 0.3 * f64::from(rng.next_f32()));
        let mut corner = || {
            DVec3::new(
                f64::from(rng.uniform_f32(-1.0, 1.0)),
                f64::from(rng.uniform_f32(-1.0, 1.0)),
                f64::from(rng.uniform_f32(-1.0, 1.0)),
            ) * size
        };
        let tri = [c + corner(), c + corner(), c + corner()];
        dust.add_triangle(rounded(tri));
    }

    // Needles: a star of 64 isolated needles 1 m long and 10 µm wide, and a plate cut into 1,000 slivers
    // fanning out from one corner.
    let mut needles = MeshBuilder::new();
    for k in 0..64 {
        let (c, s) = circle(k, 64);
        let dir = DVec3::new(c, 0.0, s);
        let side = DVec3::new(-s, 0.0, c) * 5e-6;
        let hub = DVec3::new(0.0, 0.4, 0.0) + dir * 0.02;
        needles.add_triangle(rounded([
            hub - side,
            hub + dir * 0.5 + side * 0.5,
            hub + side,
        ]));
    }
    let mut slivers = MeshBuilder::new();
    let apex = DVec3::new(-0.5, 0.7, -0.5);
    let rim: Vec<DVec3> = (0..=500)
        .map(|i| DVec3::new(0.5, 0.7, -0.5 + f64::from(i) / 500.0))
        .chain((1..=500).map(|i| DVec3::new(0.5 - f64::from(i) / 500.0, 0.7, 0.5)))
        .collect();
    for pair in rim.windows(2) {
        slivers.add_triangle(rounded([apex, pair[1], pair[0]]));
    }

    // Zero-area triangles inside and next to a plate: collinear ones along its interior edges, ones with
    // repeated vertices, and points.
    let mut zero = MeshBuilder::new();
    add_grid(
        &mut zero,
        DVec3::new(-0.5, 0.6, 0.5),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
        8,
        8,
    );
    let mut degenerate = MeshBuilder::new();
    for i in 0..=8 {
        for j in 0..8 {
            let (u, v0, v1) = (
                -0.5 + f64::from(i) / 8.0,
                -0.5 + f64::from(j) / 8.0,
                -0.5 + f64::from(j + 1) / 8.0,
            );
            let (a, b) = (DVec3::new(u, 0.6, v0), DVec3::new(u, 0.6, v1));
            degenerate.add_triangle(rounded([a, b, (a + b) * 0.5]));
            degenerate.add_triangle(rounded([a, a, b]));
            let (c, d) = (DVec3::new(v0, 0.6, u), DVec3::new(v1, 0.6, u));
            degenerate.add_triangle(rounded([c, (c + d) * 0.5, d]));
            degenerate.add_triangle(rounded([c, c, c]));
        }
    }
    for k in 0..100 {
        let p = DVec3::new(
            f64::from(rng.uniform_f32(-1.0, 1.0)),
            0.2 + f64::from(rng.next_f32()),
            f64::from(rng.uniform_f32(-1.0, 1.0)),
        );
        if k % 2 == 0 {
            degenerate.add_triangle(rounded([p, p, p]));
        } else {
            degenerate.add_triangle(rounded([p, p + DVec3::X * 0.1, p + DVec3::X * 0.3]));
        }
    }

    vec![
        case(
            "sub-texel plate (4,608 triangles)",
            Family::SmallTriangles,
            "A 0.5 m plate of cells a third of a texel wide: no triangle covers a texel centre, \
             so only conservative rasterization finds them.",
            with(ground(4.0), [fine.into_scene("fine plate")]),
            light,
            camera,
            MapSpec::new(128),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rectangle(
            [-0.25, 0.25],
            0.6,
            [-0.25, 0.25],
        )))]),
        case(
            "sub-texel dust (1,500 triangles)",
            Family::SmallTriangles,
            "1,500 randomly oriented triangles 0.1 to 0.4 texels across, scattered in a 1 m box.",
            with(ground(4.0), [dust.into_scene("dust")]),
            light,
            camera,
            MapSpec::new(128),
        ),
        case(
            "needles (aspect 1e5) and slivers",
            Family::SmallTriangles,
            "64 needles 0.5 m long and 10 µm wide, and a 1 m plate cut into 1,000 slivers fanning \
             out from one corner (aspect up to 1,400).",
            with(
                ground(4.0),
                [needles.into_scene("needles"), slivers.into_scene("slivers")],
            ),
            light,
            camera,
            MapSpec::new(128),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rectangle(
            [-0.5, 0.5],
            0.7,
            [-0.5, 0.5],
        )))]),
        case(
            "zero-area triangles",
            Family::SmallTriangles,
            "An 8x8 plate with 288 zero-area triangles on its edges (collinear, repeated \
             vertices) and 100 more in the air: rejected by the ray test without NaN/Inf, never a \
             blocker.",
            with(
                ground(4.0),
                [
                    zero.into_scene("plate"),
                    degenerate.into_scene("degenerate"),
                ],
            ),
            light,
            camera,
            MapSpec::new(128),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rectangle(
            [-0.5, 0.5],
            0.6,
            [-0.5, 0.5],
        )))]),
    ]
}

/// The point at height `y` whose light-space projection is the corner `(i, j)` of texel grid `n`
/// (computed in f64 through the inverse of `light_view_proj`).
fn texel_corner(inverse: DMat4, n: u32, i: i64, j: i64, y: f64) -> DVec3 {
    let ndc = |k: i64| k as f64 / f64::from(n) * 2.0 - 1.0;
    let a = inverse.project_point3(DVec3::new(ndc(i), ndc(j), 0.0));
    let b = inverse.project_point3(DVec3::new(ndc(i), ndc(j), 1.0));
    a + (b - a) * ((y - a.y) / (b.y - a.y))
}

/// Map size of the texel-boundary cases.
const TEXEL_MAP: u32 = 128;
/// Height of the texel-boundary blockers.
const TEXEL_BLOCKER_HEIGHT: f64 = 0.5;

/// Blockers with every vertex on a texel corner of the map fitted to the scene (ground of 4 m, blockers
/// at [`TEXEL_BLOCKER_HEIGHT`]), and the polygon of the texel-aligned plate among them.
fn texel_blockers(light: DirectionalLight) -> (Scene, Vec<Vec3>) {
    let bounds = aabb([-2.0, 0.0, -2.0], [2.0, TEXEL_BLOCKER_HEIGHT, 2.0]);
    let inverse = light.view_proj(&bounds).as_dmat4().inverse();
    let n = TEXEL_MAP;
    let c = i64::from(n / 2);
    let p = |i: i64, j: i64| texel_corner(inverse, n, c + i, c + j, TEXEL_BLOCKER_HEIGHT);
    let mut m = MeshBuilder::new();
    // A plate of 32x32 texel-sized cells.
    for j in -16..16 {
        for i in -16..16 {
            m.add_quad(rounded([
                p(i, j),
                p(i + 1, j),
                p(i + 1, j + 1),
                p(i, j + 1),
            ]));
        }
    }
    let outline = [p(-16, -16), p(16, -16), p(16, 16), p(-16, 16)]
        .map(|p| p.as_vec3())
        .to_vec();
    // A square of 8x8 texels cut along its diagonal through texel corners.
    m.add_triangle(rounded([p(20, -4), p(28, -4), p(20, 4)]));
    m.add_triangle(rounded([p(28, -4), p(28, 4), p(20, 4)]));
    // A strip exactly one texel wide.
    m.add_quad(rounded([p(-28, -16), p(-27, -16), p(-27, 16), p(-28, 16)]));
    // Half a texel.
    m.add_triangle(rounded([p(-22, 20), p(-21, 20), p(-22, 21)]));
    // A triangle touching its neighbour texel at a single corner.
    m.add_triangle(rounded([p(20, 20), p(22, 21), p(21, 22)]));
    (with(ground(4.0), [m.into_scene("texel-aligned")]), outline)
}

fn texel_boundaries() -> Vec<HardCase> {
    let camera = Some(look(Vec3::new(0.0, 0.3, 2.5), Vec3::ZERO));
    let map = MapSpec::new(TEXEL_MAP);
    let down = DirectionalLight {
        direction: Vec3::NEG_Y,
    };
    let slanted = DirectionalLight::slanted();
    let (vertical_scene, vertical_outline) = texel_blockers(down);
    let (slanted_scene, slanted_outline) = texel_blockers(slanted);
    vec![
        case(
            "texel corners, light straight down",
            Family::TexelBoundaries,
            "Blockers whose vertices are exactly (in f32) on corners of the 128x128 map's texels: \
             a plate of texel-sized cells, a diagonal through texel corners, a strip one texel \
             wide, half a texel, a triangle touching a texel at one corner; the centre pixel \
             column's rays run along a texel boundary.",
            vertical_scene,
            down.direction,
            camera,
            map,
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(vertical_outline))]),
        case(
            "texel corners, slanted light",
            Family::TexelBoundaries,
            "The same blockers on texel corners of a slanted light's map (to f32 rounding).",
            slanted_scene,
            slanted.direction,
            camera,
            map,
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(slanted_outline))]),
    ]
}

fn frustum_border() -> Vec<HardCase> {
    let light = DirectionalLight::slanted();
    let mut tilted = MeshBuilder::new();
    let tilted_corners = [
        DVec3::new(-0.8, 0.3, 0.5),
        DVec3::new(0.8, 0.3, 0.5),
        DVec3::new(0.0, 5.0, 0.9),
    ];
    tilted.add_triangle(rounded(tilted_corners));
    let mut card = MeshBuilder::new();
    let card_corners = [
        DVec3::new(-0.5, -3.0, 0.0),
        DVec3::new(-0.5, -3.0, 0.4),
        DVec3::new(-0.5, 0.8, 0.4),
        DVec3::new(-0.5, 0.8, 0.0),
    ];
    card.add_quad(rounded(card_corners));
    let scene = with(
        ground(2.0),
        [
            plate("strip along x", [-10.0, 10.0], 0.6, [-0.6, -0.1]),
            plate("strip along z", [0.2, 0.7], 0.9, [-10.0, 10.0]),
            tilted.into_scene("tilted"),
            card.into_scene("card"),
        ],
    );
    let map_box = aabb([-1.0, 0.0, -1.0], [1.0, 1.0, 1.0]);
    vec![HardCase {
        light_view_proj: Some(light.view_proj(&map_box)),
        ..case(
            "beyond the map's border and depth range",
            Family::FrustumBorder,
            "A fitted light matrix encloses every vertex, so this case replaces it by one \
             enclosing only the 2 m ground and heights 0 to 1 m: two 20 m strips cross the map's \
             border, a tilted triangle rises 4 m above its near plane and a card reaches 3 m \
             below its far plane. Receivers are all inside the map; blockers must be kept \
             wherever they overlap it.",
            scene,
            light.direction,
            Some(look(Vec3::new(0.2, 0.45, 2.6), Vec3::new(0.0, 0.0, -0.2))),
            MapSpec::new(128),
        )
        .checking(vec![
            Check::Shadowed(Solid::Polygon(rectangle([-10.0, 10.0], 0.6, [-0.6, -0.1]))),
            Check::Shadowed(Solid::Polygon(rectangle([0.2, 0.7], 0.9, [-10.0, 10.0]))),
            Check::Shadowed(Solid::Polygon(tilted_corners.map(|p| p.as_vec3()).to_vec())),
            Check::Shadowed(Solid::Polygon(card_corners.map(|p| p.as_vec3()).to_vec())),
        ])
    }]
}

fn coplanar() -> Vec<HardCase> {
    let light = DirectionalLight::slanted().direction;
    let mut second = MeshBuilder::new();
    // Same plane as the first plate, the other diagonal.
    second.add_quad(rounded([
        DVec3::new(0.6, 0.5, 0.5),
        DVec3::new(0.6, 0.5, -0.3),
        DVec3::new(-0.2, 0.5, -0.3),
        DVec3::new(-0.2, 0.5, 0.5),
    ]));
    let overlapping = with(
        ground(4.0),
        [
            plate("plate", [-0.6, 0.2], 0.5, [-0.5, 0.3]),
            second.into_scene("overlapping plate"),
            plate("decal", [0.8, 1.4], 0.0, [-1.4, -0.8]),
        ],
    );
    let (lower_min, lower_max) = ([-0.5, 0.0, -0.5], [0.5, 0.5, 0.5]);
    let (upper_min, upper_max) = ([-0.25, 0.5, -0.3], [0.35, 0.9, 0.2]);
    let stacked = with(
        ground(4.0),
        [
            solid_box("lower box", lower_min, lower_max),
            solid_box("upper box", upper_min, upper_max),
        ],
    );
    let steep = Vec3::new(0.8, -0.55, 0.35).normalize();
    vec![
        case(
            "overlapping coplanar plates and a decal",
            Family::Coplanar,
            "Two plates in the same plane overlapping over half their area (different diagonals), \
             and a decal quad lying exactly on the ground: no acne on the decal, no leak under \
             the plates.",
            overlapping,
            light,
            Some(look(Vec3::new(1.2, 1.6, 2.4), Vec3::new(0.3, 0.0, -0.2))),
            MapSpec::new(128),
        )
        .checking(vec![
            Check::Shadowed(Solid::Polygon(rectangle([-0.6, 0.2], 0.5, [-0.5, 0.3]))),
            Check::Shadowed(Solid::Polygon(rectangle([-0.2, 0.6], 0.5, [-0.3, 0.5]))),
            Check::Lit(aabb([0.8, -1e-3, -1.4], [1.4, 1e-3, -0.8])),
        ]),
        case(
            "boxes stacked face to face (front faces only)",
            Family::Coplanar,
            "A closed box standing on another, the upper box's bottom face coplanar with the \
             lower box's top face, the lower box's bottom coplanar with the ground: both contact \
             shadows must start at the footprints.",
            stacked,
            steep,
            Some(look(Vec3::new(2.2, 1.8, 2.4), Vec3::new(0.3, 0.3, 0.2))),
            MapSpec {
                front_faces_only: true,
                ..MapSpec::new(128)
            },
        )
        .checking(vec![
            Check::Contact(aabb(lower_min, lower_max)),
            Check::Contact(aabb(upper_min, upper_max)),
        ]),
    ]
}

fn thin_geometry() -> Vec<HardCase> {
    let light = DirectionalLight::slanted().direction;
    let mut slats = MeshBuilder::new();
    for k in 0..6 {
        let x = 0.7 + 0.1 * f64::from(k);
        add_lattice_box(
            &mut slats,
            DVec3::new(x, 0.0, -0.4),
            DVec3::new(x + 0.002, 0.8, 0.4),
            [1, 1, 1],
        );
    }
    let thin = with(
        ground(4.0),
        [
            solid_box("floating plate", [-0.5, 0.6, -0.5], [0.5, 0.6001, 0.5]),
            slats.into_scene("slats"),
            solid_box("plate on the ground", [-1.2, 0.0, 0.6], [-0.6, 5e-4, 1.2]),
        ],
    );
    let mut checks = vec![Check::Shadowed(Solid::Polygon(rectangle(
        [-0.5, 0.5],
        0.60005,
        [-0.5, 0.5],
    )))];
    for k in 0..6 {
        let x = 0.701 + 0.1 * f64::from(k);
        checks.push(Check::Shadowed(Solid::Polygon(
            [(-0.4, 0.0), (0.4, 0.0), (0.4, 0.8), (-0.4, 0.8)]
                .map(|(z, y)| DVec3::new(x, y, z).as_vec3())
                .to_vec(),
        )));
    }

    let mut rng = SplitMix64::new(0xf011a6e);
    let mut cards = MeshBuilder::new();
    let mut card_checks = Vec::new();
    for k in 0..5 {
        let base = DVec3::new(
            -1.0 + 0.5 * f64::from(k),
            0.0,
            -0.6 + 0.3 * f64::from(k % 2),
        );
        let yaw = f64::from(rng.next_f32()) * std::f64::consts::PI;
        for turn in [0.0, std::f64::consts::FRAC_PI_2] {
            let across = DQuat::from_rotation_y(yaw + turn) * DVec3::X * 0.3;
            let corners = [
                base - across + DVec3::Y * 0.05,
                base + across + DVec3::Y * 0.05,
                base + across + DVec3::Y * 0.85,
                base - across + DVec3::Y * 0.85,
            ];
            cards.add_quad(rounded(corners));
            // Cards seen nearly edge-on by the light cast slivers of shadow: too thin to judge.
            let normal = (corners[1] - corners[0])
                .cross(corners[3] - corners[0])
                .normalize();
            if normal.dot(light.as_dvec3()).abs() > 0.3 {
                card_checks.push(Check::Shadowed(Solid::Polygon(
                    corners.map(|p| p.as_vec3()).to_vec(),
                )));
            }
        }
    }
    for _ in 0..300 {
        let c = DVec3::new(0.9, 0.6, 0.7)
            + DVec3::new(
                f64::from(rng.uniform_f32(-1.0, 1.0)),
                f64::from(rng.uniform_f32(-1.0, 1.0)),
                f64::from(rng.uniform_f32(-1.0, 1.0)),
            ) * 0.3;
        let q = DQuat::from_euler(
            glam::EulerRot::YXZ,
            f64::from(rng.next_f32()) * TAU,
            f64::from(rng.uniform_f32(-1.0, 1.0)),
            f64::from(rng.uniform_f32(-1.0, 1.0)) * 3.0,
        );
        cards.add_triangle(rounded([
            c,
            c + q * DVec3::new(0.12, 0.0, 0.03),
            c + q * DVec3::new(0.05, 0.0, 0.06),
        ]));
    }
    let foliage = with(ground(4.0), [cards.into_scene("cards and leaves")]);
    vec![
        case(
            "thin closed plates",
            Family::ThinGeometry,
            "A floating closed plate 0.1 mm thick, six 2 mm slats standing on the ground and a \
             0.5 mm plate lying on it, all thinner than the shadow ray's origin offset.",
            thin,
            light,
            Some(look(Vec3::new(1.0, 1.7, 2.6), Vec3::new(0.3, 0.2, 0.0))),
            MapSpec::new(128),
        )
        .checking(checks),
        case(
            "foliage cards",
            Family::ThinGeometry,
            "Five pairs of crossed zero-thickness cards intersecting each other, and 300 randomly \
             oriented leaf triangles, both faces stored.",
            foliage,
            light,
            Some(look(Vec3::new(0.6, 3.2, 1.8), Vec3::new(0.3, 0.0, -0.3))),
            MapSpec::new(128),
        )
        .checking(card_checks),
    ]
}

fn real_models(models: &Path) -> Vec<HardCase> {
    let load = |file: &str| load_obj(&models.join(file));
    let cornell = case(
        "Cornell box (06)",
        Family::Models,
        "The Cornell box (36 triangles: quads, negative indices, block footprints coplanar with \
         the floor), lit through its open front.",
        Scene::default(),
        Vec3::new(0.35, -0.45, 1.0),
        Some(look(
            Vec3::new(278.0, 273.0, -800.0),
            Vec3::new(278.0, 273.0, 280.0),
        )),
        MapSpec::new(256),
    );
    let veach = case(
        "Veach MIS plates (07)",
        Family::Models,
        "Four zero-thickness plates at grazing angles over a large floor and wall.",
        Scene::default(),
        Vec3::new(0.0, -0.35, -1.0),
        Some(look(Vec3::new(0.0, 2.0, 15.0), Vec3::new(0.0, -2.0, 2.5))),
        MapSpec::new(256),
    );
    let pine = case(
        "small pine (08)",
        Family::Models,
        "A pine of 82 zero-thickness foliage cards (1,650 triangles) on a ground plane.",
        Scene::default(),
        DirectionalLight::slanted().direction,
        None,
        MapSpec::new(256),
    );
    let sponza = case(
        "Sponza (04)",
        Family::Models,
        "Dabrovic Sponza (66K triangles, 10 duplicate triangles), seen from inside the atrium \
         under a steep sun.",
        Scene::default(),
        Vec3::new(0.3, -1.0, 0.12),
        Some(look(Vec3::new(-12.0, 2.5, 0.5), Vec3::new(4.0, 4.0, -1.0))),
        MapSpec::new(512),
    );
    let conference = case(
        "conference room (05)",
        Family::Models,
        "The conference room (277K triangles, thin chair legs, large floor).",
        Scene::default(),
        Vec3::new(0.35, -1.0, 0.25),
        Some(look(
            Vec3::new(-900.0, 400.0, 550.0),
            Vec3::new(400.0, 80.0, -300.0),
        )),
        MapSpec::new(512),
    );
    let files = [
        (cornell, load("06_cornell_box/cornell_box.obj")),
        (veach, load("07_veach_mi_plates.obj")),
        (
            pine,
            load("08_smallpine_1650.obj").map(|s| s.with_ground_plane()),
        ),
        (sponza, load("04_dabrovic_sponza_66k.obj")),
        (conference, load("05_conference_clean_277k.obj")),
    ];
    files
        .into_iter()
        .map(|(c, scene)| HardCase { scene, ..c })
        .collect()
}

fn non_finite() -> Vec<HardCase> {
    let rejected = |name: &'static str, description: &'static str, scene| HardCase {
        name,
        family: Family::NonFinite,
        description,
        scene,
        light_direction: DirectionalLight::slanted().direction,
        camera: None,
        light_view_proj: None,
        frame: FRAME,
        map: MapSpec::new(64),
        expectation: Expectation::RejectedAtLoad,
    };
    let obj = |file: &str, text: &str| parse_obj(text.as_bytes(), Path::new(file));
    let mut in_memory = with(ground(4.0), [solid_box("box", [0.0; 3], [1.0; 3])]);
    in_memory.positions[5].z = f32::NAN;
    vec![
        rejected(
            "NaN vertex (OBJ)",
            "`v nan 1 0` in an OBJ file.",
            obj("nan.obj", "v 0 0 0\nv nan 1 0\nv 0 0 1\nf 1 2 3\n"),
        ),
        rejected(
            "infinite vertex (OBJ)",
            "`v 1 inf 0` and `v -inf 0 0` in an OBJ file.",
            obj("inf.obj", "v 0 0 0\nv 1 inf 0\nv -inf 0 1\nf 1 2 3\n"),
        ),
        rejected(
            "overflowing vertex 1e39 (OBJ)",
            "`v 0 0 1e39`: finite text that overflows f32 to infinity.",
            obj("overflow.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1e39\nf 1 2 3\n"),
        ),
        rejected(
            "NaN in an in-memory scene",
            "A scene built in memory with a NaN coordinate, checked by `Scene::validate`.",
            in_memory.validate().map(|()| in_memory.clone()),
        ),
    ]
}

/// A lit ground whose central texels overflow (a grid buried just under it), and 1,000 slivers 2 to 4 cm
/// long, 60 to 100 m away, each lying along a line through the centre: under the vertical light, every
/// receiver near the centre is within millimetres of some sliver's line, where the sliver's f32 edge
/// functions round to zero. The exhaustive fallback of overflowed texels tests the shadow ray against all
/// of them.
fn far_slivers() -> (Scene, Aabb) {
    let mut buried = MeshBuilder::new();
    add_grid(
        &mut buried,
        DVec3::new(-0.5, -0.05, 0.5),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
        16,
        16,
    );
    let mut rng = SplitMix64::new(0x511_4e25);
    let mut slivers = MeshBuilder::new();
    for k in 0..1000 {
        let (c, s) = circle(k, 1000);
        let radial = DVec3::new(c, 0.0, s);
        let across = DVec3::new(-s, 0.0, c);
        let r = 60.0 + 40.0 * f64::from(rng.next_f32());
        let p = radial * r + DVec3::Y * (0.05 + 0.5 * f64::from(rng.next_f32()));
        slivers.add_triangle(rounded([
            p,
            p + radial * 0.02 + DVec3::Y * 0.01,
            p + radial * 0.04 + across * 1e-5,
        ]));
    }
    let scene = with(
        ground(4.0),
        [
            buried.into_scene("buried grid"),
            slivers.into_scene("far slivers"),
        ],
    );
    (scene, aabb([-0.5, -1e-3, -0.5], [0.5, 1e-3, 0.5]))
}

fn overflow() -> Vec<HardCase> {
    let scene = procedural_default();
    let frame = Frame {
        width: 161,
        height: 121,
    };
    let camera = Camera::frame(
        &aabb([-3.5, 0.0, -3.5], [3.5, 1.8, 3.5]),
        frame.width as f32 / frame.height as f32,
    );
    let mut cases: Vec<HardCase> = [
        ("entry budget 1K", 1024),
        ("entry budget 2K", 2048),
        ("entry budget 4K", 4096),
        ("entry budget 8K", 8192),
    ]
    .into_iter()
    .map(|(name, budget)| HardCase {
        frame,
        ..case(
            name,
            Family::Overflow,
            "The demo scene in a 128x128 map with an entry budget of 1K to 8K entries and guard \
             words: texels past the capacity; nothing may be written past it and those texels \
             are traced exhaustively.",
            scene.clone(),
            DirectionalLight::slanted().direction,
            Some(camera),
            MapSpec {
                guard: true,
                overflow: Overflow::Required,
                entry_budget: Some(budget),
                ..MapSpec::new(128)
            },
        )
    })
    .collect();
    let (slivers, lit) = far_slivers();
    cases.push(
        case(
            "exhaustive fallback vs far slivers",
            Family::Overflow,
            "A lit ground over a buried grid whose lists pass a budget of 1K entries, light straight \
             down, and 1,000 tiny slivers 60 to 100 m away, each along a line through the centre: \
             traced exhaustively, no sliver may shadow the ground.",
            slivers,
            Vec3::NEG_Y,
            Some(look(Vec3::new(0.6, 1.2, 1.6), Vec3::ZERO)),
            MapSpec {
                guard: true,
                overflow: Overflow::Required,
                entry_budget: Some(1024),
                // The buried grid lies behind every ray origin: culled, its lists would stay empty.
                receiver_culling: false,
                ..MapSpec::new(128)
            },
        )
        .checking(vec![Check::Lit(lit)]),
    );
    cases
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;

    fn models() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/models")
    }

    /// Every directed edge (by vertex position) occurs once and its reverse once.
    fn assert_watertight(scene: &Scene) {
        let key = |p: Vec3| p.to_array().map(f32::to_bits);
        let mut edges = HashMap::<([u32; 3], [u32; 3]), u32>::new();
        for t in 0..scene.triangle_count() {
            let [a, b, c] = scene.triangle(t).map(key);
            for e in [(a, b), (b, c), (c, a)] {
                *edges.entry(e).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "edge used {n} times");
            assert_eq!(edges.get(&(b, a)), Some(&1), "open edge");
        }
    }

    fn object(scene: &Scene, name: &str) -> Scene {
        let o = scene.objects.iter().find(|o| o.name == name).unwrap();
        let range =
            3 * o.first_triangle as usize..3 * (o.first_triangle + o.triangle_count) as usize;
        Scene {
            positions: scene.positions.clone(),
            indices: scene.indices[range].to_vec(),
            objects: Vec::new(),
        }
    }

    #[test]
    fn circle_is_exactly_symmetric() {
        assert_eq!(circle(0, 96), (1.0, 0.0));
        assert_eq!(circle(24, 96), (0.0, 1.0));
        assert_eq!(circle(48, 96), (-1.0, 0.0));
        assert_eq!(circle(72, 96), (0.0, -1.0));
        for k in 0..96 {
            let (c, s) = circle(k, 96);
            assert!((c - (TAU * k as f64 / 96.0).cos()).abs() < 1e-15);
            assert!((s - (TAU * k as f64 / 96.0).sin()).abs() < 1e-15);
            assert_eq!(circle(96 - k, 96), (c, -s));
            assert_eq!(circle(48 - k, 96), (-c, s));
        }
    }

    #[test]
    fn every_case_is_well_formed_and_deterministic() {
        let cases = all(&models());
        let mut names = std::collections::HashSet::new();
        for c in &cases {
            assert!(names.insert(c.name), "duplicate name {}", c.name);
            assert!(c.light_direction.is_finite() && c.light_direction.length() > 0.0);
            assert!(
                c.frame.width > 0
                    && c.frame.height > 0
                    && c.map.size > 0
                    && c.map.entry_budget != Some(0)
            );
            match (&c.scene, &c.expectation) {
                (Ok(s), Expectation::Renders(_)) => s.validate().unwrap(),
                (Err(e), Expectation::RejectedAtLoad) => {
                    assert!(matches!(e, SceneError::NonFinite { .. }), "{}: {e}", c.name)
                }
                (other, _) => panic!("{}: {other:?}", c.name),
            }
        }
        for f in Family::ALL {
            assert_eq!(Family::from_name(f.name()), Some(f));
            assert!(cases.iter().any(|c| c.family == f));
        }
        let again = all(&models());
        for (a, b) in cases.iter().zip(&again) {
            assert_eq!(a.scene.as_ref().ok(), b.scene.as_ref().ok(), "{}", a.name);
        }
    }

    #[test]
    fn closed_meshes_are_watertight() {
        let cases = shared_edges();
        assert_watertight(&object(cases[2].scene.as_ref().unwrap(), "box"));
        assert_watertight(&object(cases[3].scene.as_ref().unwrap(), "sphere"));
        for c in coplanar().iter().skip(1) {
            let s = c.scene.as_ref().unwrap();
            assert_watertight(&object(s, "lower box"));
            assert_watertight(&object(s, "upper box"));
        }
    }

    #[test]
    fn shared_edges_lie_on_the_axes() {
        let cases = shared_edges();
        let fan = object(cases[0].scene.as_ref().unwrap(), "fan");
        let on_axis = (0..fan.triangle_count())
            .flat_map(|t| fan.triangle(t))
            .filter(|p| p.x == 0.0 || p.z == 0.0)
            .count();
        // Each of the 96 triangles has the hub; 4 rim vertices on the axes, each in 2 triangles.
        assert_eq!(on_axis, 96 + 8);
        let Expectation::Renders(checks) = &cases[3].expectation else {
            panic!()
        };
        let Check::Shadowed(Solid::Ball { radius, .. }) = checks[0] else {
            panic!()
        };
        assert!(radius > 0.79 && radius < 0.8, "{radius}");
    }

    #[test]
    fn tube_has_a_facet_facing_up() {
        let mut m = MeshBuilder::new();
        add_tube(&mut m, DVec3::ZERO, 20.0, 20.0, 512);
        let s = m.into_scene("tube");
        let up = (0..s.triangle_count()).filter(|&t| {
            let [a, b, c] = s.triangle(t);
            (b - a).cross(c - a).normalize() == Vec3::Y
        });
        assert_eq!(up.count(), 2);
    }

    #[test]
    fn texel_corners_are_exact_under_a_vertical_light() {
        let down = DirectionalLight {
            direction: Vec3::NEG_Y,
        };
        let (scene, _) = texel_blockers(down);
        let m = down.view_proj(&scene.bounds()).as_dmat4();
        assert_eq!(scene.bounds(), aabb([-2.0, 0.0, -2.0], [2.0, 0.5, 2.0]));
        let blockers = object(&scene, "texel-aligned");
        for p in blockers
            .indices
            .iter()
            .map(|&i| blockers.positions[i as usize])
        {
            let t = (m.project_point3(p.as_dvec3()).truncate() * 0.5 + 0.5) * f64::from(TEXEL_MAP);
            assert_eq!(t, t.round(), "{p} projects to {t}");
        }
        let (slanted, _) = texel_blockers(DirectionalLight::slanted());
        assert_eq!(slanted.bounds(), scene.bounds());
    }

    #[test]
    fn frustum_border_case_crosses_its_map() {
        let c = frustum_border().pop().unwrap();
        let m = c.light_view_proj.unwrap();
        let s = c.scene.unwrap();
        let clip: Vec<Vec3> = s.positions.iter().map(|&p| m.project_point3(p)).collect();
        assert!(clip.iter().any(|p| p.x.abs() > 1.0 || p.y.abs() > 1.0));
        assert!(clip.iter().any(|p| p.z < 0.0));
        assert!(clip.iter().any(|p| p.z > 1.0));
        let ground = object(&s, "ground");
        for &i in &ground.indices {
            let p = m.project_point3(ground.positions[i as usize]);
            assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{p}");
        }
    }

    #[test]
    fn non_finite_errors_name_the_problem() {
        for c in non_finite() {
            let e = c.scene.unwrap_err().to_string();
            assert!(e.contains("non-finite"), "{e}");
        }
    }
}

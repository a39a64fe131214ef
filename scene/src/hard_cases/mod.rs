//! The hard numerical cases of ray-traced shadows through a deep primitive map, as data.
//!
//! Every case is generated deterministically: a [`Scene`] (or the error that loading it must produce),
//! a directional light, an optional camera, the frame and primitive-map sizes it is meant for, and what
//! must hold besides agreement with the exact reference ([`Check`]s that are decided analytically from the
//! receiver positions, so that they do not depend on the reference's tolerance classification).
//!
//! The renderer that runs them (the `hrts_lab hardcases` subcommand and the `hard_cases` integration
//! test) lives outside this crate; this module knows nothing about GPUs.
//!
//! Families ([`Family`]), one submodule each:
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

mod contact;
mod coplanar;
mod frustum_border;
mod grazing;
mod non_finite;
mod overflow;
mod real_models;
mod scale;
mod shared_edges;
mod small_triangles;
mod texel_boundaries;
mod thin_geometry;

use std::f64::consts::TAU;
use std::path::Path;

use glam::{DVec3, Mat4, Vec3};

use crate::scene::ground_square;
use crate::{Aabb, Camera, MeshBuilder, Scene, SceneError};

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
    /// No texel may pass the entry capacity: the case tests the texel lists, not the BVH fallback.
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
    /// Entry budget of the primitive map's lists, in entries (past it, texels walk the BVH),
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
        Family::SharedEdges => shared_edges::shared_edges(),
        Family::Grazing => grazing::grazing(),
        Family::Contact => contact::contact(),
        Family::Scale => scale::scale(),
        Family::SmallTriangles => small_triangles::small_triangles(),
        Family::TexelBoundaries => texel_boundaries::texel_boundaries(),
        Family::FrustumBorder => frustum_border::frustum_border(),
        Family::Coplanar => coplanar::coplanar(),
        Family::ThinGeometry => thin_geometry::thin_geometry(),
        Family::Models => real_models::real_models(models),
        Family::NonFinite => non_finite::non_finite(),
        Family::Overflow => overflow::overflow(),
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

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;

    fn models() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/models")
    }

    /// Every directed edge (by vertex position) occurs once and its reverse once.
    pub(super) fn assert_watertight(scene: &Scene) {
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

    /// The triangles of object `name` of `scene`, as a scene without objects.
    pub(super) fn object(scene: &Scene, name: &str) -> Scene {
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
}

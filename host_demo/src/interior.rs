//! The default view of a closed scene: a model that encloses its own interior (a room, a hall) shows
//! only the outside of its walls when framed from outside, and a sun cannot light it. So `render --obj`
//! first asks whether the model is closed, by casting rays on the CPU from points spread inside its
//! bounds against its triangles ([`RefScene`], the reference's BVH); a closed one gets a camera inside,
//! in free space, looking across the room, and a point light below its ceiling.
//!
//! - **Probes.** The 27 points of a 3×3×3 grid at a quarter, half and three quarters of the bounds on
//!   each axis (nudged by a tiny fraction, so that no probe lies on a plane of symmetry where a modeller
//!   puts walls), the centre first. From each, [`PROBE_RAYS`] rays spread evenly over the sphere (a
//!   Fibonacci lattice) find their nearest triangle.
//! - **Free probes.** A probe inside a solid (a chair, a closed model) sees the inside of its surface:
//!   back faces only (triangles wind counter-clockwise seen from their front), but for a few where
//!   surfaces overlap. A probe is *free* when at least [`FREE_FRONT_FRACTION`] of the triangles its rays
//!   hit face it: it sees the front of something, so it is outside every solid, whichever way the walls
//!   around it are wound (facing the room, facing out, or both). Probes that are not free say nothing
//!   about the scene and are left out. (An empty box wound outwards is a solid: nothing tells it from a
//!   room.)
//! - **Closed.** The scene is closed when there is a free probe and, from every free probe, at least
//!   [`CLOSED_HIT_FRACTION`] of the rays hit geometry: no probe sees out through an opening (an open
//!   roof, a courtyard, the open side of a box, the sky above a ground plane). A model alone has no free
//!   probe that is enclosed: its probes are either inside it (not free) or see the sky.
//! - **Interior.** The box around every point the free probes' rays hit: the walls, floor and ceiling
//!   seen from inside. The probe nearest the centre of the bounds is the *anchor*, a point known to be
//!   in free space; the camera and the light are placed where a straight path from it is clear.

use glam::{DVec3, Vec3};
use reference::RefScene;
use scene::{Aabb, Camera, LightKind, LightSize, Scene, SceneFile, SceneLight};

/// Rays cast from each probe point.
pub const PROBE_RAYS: usize = 256;

/// A probe is free when at least this fraction of the triangles its rays hit face it.
pub const FREE_FRONT_FRACTION: f64 = 0.2;

/// A scene is closed when at least this fraction of the rays from every free probe hit geometry.
pub const CLOSED_HIT_FRACTION: f64 = 0.98;

/// Probe positions along each axis, as fractions of the bounds.
const PROBE_FRACTIONS: [f64; 3] = [0.25, 0.5, 0.75];

/// The nudge of every probe, as a fraction of the bounds on each axis (irrational-looking, so that no
/// probe sits on a modeller's plane of symmetry).
const PROBE_NUDGE: DVec3 = DVec3::new(0.001_618, 0.001_414, 0.001_732);

/// The camera's eye height, as a fraction of the interior's height.
const EYE_HEIGHT: f32 = 0.6;

/// The height of the point the camera looks at across the room, as a fraction of the interior's height.
const LOOK_HEIGHT: f32 = 0.15;

/// How far from the walls the camera stands (and the far corner it looks at lies), as a fraction of
/// the interior on each horizontal axis.
const CORNER_INSET: f32 = 0.1;

/// The range of the camera's vertical field of view, in degrees.
const FOV_Y_DEGREES: (f32, f32) = (50.0, 80.0);

/// The point light hangs this fraction of the way from the anchor up to the ceiling above it.
const LIGHT_HEIGHT: f64 = 0.8;

/// A camera whose straight path from the anchor is blocked stops this fraction of the way to the
/// blocker.
const PULL_BACK: f64 = 0.8;

/// What the rays from inside a scene's bounds found: whether it is closed and, if it has free space
/// inside, where.
#[derive(Debug, Clone, PartialEq)]
pub struct Enclosure {
    /// Probe points tried.
    pub probes: usize,
    /// Probes in free space (not inside a solid).
    pub free_probes: usize,
    /// Rays cast from the free probes.
    pub rays: usize,
    /// Rays from the free probes that hit a triangle.
    pub hits: usize,
    /// The smallest fraction of one free probe's rays that hit a triangle (0 without free probes).
    pub least_hit_fraction: f64,
    /// The free probe nearest the centre of the bounds, if any.
    anchor: Option<DVec3>,
    /// The box around every point that the free probes' rays hit.
    interior: Aabb,
}

impl Enclosure {
    /// Casts the probes' rays over `scene`, whose triangles lie within `bounds`.
    pub fn probe(scene: &RefScene, bounds: &Aabb) -> Self {
        let (min, size) = (bounds.min.as_dvec3(), bounds.size().as_dvec3());
        let mut probes: Vec<DVec3> = Vec::new();
        if min.is_finite() && size.is_finite() && size.cmpge(DVec3::ZERO).all() {
            for fx in PROBE_FRACTIONS {
                for fy in PROBE_FRACTIONS {
                    for fz in PROBE_FRACTIONS {
                        probes.push(min + (DVec3::new(fx, fy, fz) + PROBE_NUDGE) * size);
                    }
                }
            }
        }
        let center = min + 0.5 * size;
        probes.sort_by(|a, b| {
            a.distance_squared(center)
                .total_cmp(&b.distance_squared(center))
        });
        let directions = sphere_directions(PROBE_RAYS);
        let mut enclosure = Self {
            probes: probes.len(),
            free_probes: 0,
            rays: 0,
            hits: 0,
            least_hit_fraction: 0.0,
            anchor: None,
            interior: Aabb::empty(),
        };
        let mut least = f64::INFINITY;
        for probe in probes {
            let (mut hits, mut front) = (0usize, 0usize);
            let mut seen = Aabb::empty();
            for &dir in &directions {
                let Some((t, triangle)) = scene.nearest_hit(probe, dir) else {
                    continue;
                };
                hits += 1;
                let [a, b, c] = scene.triangle(triangle);
                if (b - a).cross(c - a).dot(dir) < 0.0 {
                    front += 1;
                }
                seen.extend((probe + t * dir).as_vec3());
            }
            if (front as f64) < FREE_FRONT_FRACTION * hits as f64 {
                continue;
            }
            enclosure.free_probes += 1;
            enclosure.rays += directions.len();
            enclosure.hits += hits;
            least = least.min(hits as f64 / directions.len() as f64);
            enclosure.anchor.get_or_insert(probe);
            enclosure.interior.extend(seen.min);
            enclosure.interior.extend(seen.max);
        }
        if enclosure.free_probes > 0 {
            enclosure.least_hit_fraction = least;
        }
        enclosure
    }

    /// Whether the scene encloses its free space: there is a free probe, and from every one at least
    /// [`CLOSED_HIT_FRACTION`] of the rays hit geometry.
    pub fn is_closed(&self) -> bool {
        self.free_probes > 0 && self.least_hit_fraction >= CLOSED_HIT_FRACTION
    }

    /// The fraction of the free probes' rays that hit geometry (0 without free probes).
    pub fn hit_fraction(&self) -> f64 {
        if self.rays == 0 {
            0.0
        } else {
            self.hits as f64 / self.rays as f64
        }
    }

    /// The finding in words: "closed scene: 99.9% of the 6912 rays from 27 free interior points hit
    /// geometry (at least 99.6% from each)", or why the scene is open.
    pub fn describe(&self) -> String {
        let rays = format!(
            "{:.1}% of the {} rays from {} free interior point{} hit geometry",
            100.0 * self.hit_fraction(),
            self.rays,
            self.free_probes,
            if self.free_probes == 1 { "" } else { "s" }
        );
        if self.free_probes == 0 {
            format!(
                "open scene: none of {} points inside the bounds is in free space",
                self.probes
            )
        } else if self.is_closed() {
            format!(
                "closed scene: {rays} (at least {:.1}% from each)",
                100.0 * self.least_hit_fraction
            )
        } else {
            format!(
                "open scene: {rays}; from one only {:.1}% (closed takes {:.0}% from each)",
                100.0 * self.least_hit_fraction,
                100.0 * CLOSED_HIT_FRACTION
            )
        }
    }

    /// The box of the walls, floor and ceiling that the free probes see (empty without free probes).
    pub fn interior(&self) -> Aabb {
        self.interior
    }

    /// A camera inside for a frame of `aspect` (width / height): near one corner of the interior at
    /// eye height ([`EYE_HEIGHT`]), looking down across the room at the opposite corner near the floor,
    /// of the four corners the one that sees farthest before its view meets geometry. The eye is pulled
    /// back towards the anchor when something lies on the straight path between them, so it is in free
    /// space. The field of view fits the interior's corners that lie ahead (at least a quarter as deep
    /// as the farthest), within [`FOV_Y_DEGREES`]. `None` without free probes.
    pub fn interior_camera(&self, scene: &RefScene, aspect: f32) -> Option<Camera> {
        let anchor = self.anchor?;
        let room = self.interior;
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let (lo, hi) = (CORNER_INSET, 1.0 - CORNER_INSET);
        let mut best: Option<(f64, Vec3, Vec3)> = None;
        for (fx, fz) in [(lo, lo), (hi, lo), (lo, hi), (hi, hi)] {
            let eye = clear_path(scene, anchor, at(&room, Vec3::new(fx, EYE_HEIGHT, fz)));
            let target = at(&room, Vec3::new(1.0 - fx, LOOK_HEIGHT, 1.0 - fz));
            let Some(clearance) = view_clearance(scene, &room, eye, target) else {
                continue;
            };
            if best.is_none_or(|(c, _, _)| clearance > c) {
                best = Some((clearance, eye, target));
            }
        }
        let (_, position, target) = best?;
        let forward = (target - position).normalize();
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        let up = right.cross(forward);
        let depth = |c: Vec3| (c - position).dot(forward);
        let deepest = room.corners().into_iter().map(depth).fold(0.0, f32::max);
        let tan_half_y = room
            .corners()
            .into_iter()
            .filter(|&c| depth(c) >= 0.25 * deepest && depth(c) > 0.0)
            .map(|c| {
                let v = c - position;
                (v.dot(up).abs() / depth(c)).max(v.dot(right).abs() / depth(c) / aspect)
            })
            .fold(0.0, f32::max);
        let (min_fov, max_fov) = FOV_Y_DEGREES;
        let fov_y =
            (2.0 * (1.05 * tan_half_y).atan()).clamp(min_fov.to_radians(), max_fov.to_radians());
        Some(Camera {
            position,
            target,
            up: Vec3::Y,
            fov_y_radians: fov_y,
            near: (room.radius() * 1e-3).max(1e-4),
        })
    }

    /// The interior light: a point light above the anchor, [`LIGHT_HEIGHT`] of the way up to the first
    /// geometry above it (the ceiling, or a lamp below it), so it hangs in free space below the ceiling.
    /// It is a sphere that looks `angular_radius` wide (radians) from the floor below it, or a point
    /// (hard shadows) for an `angular_radius` of 0; its intensity gives a surface facing it from the
    /// interior's half diagonal away an illuminance of 1 (mid grey once the demo's shading tone-maps it),
    /// and nearer surfaces more. `None` without free probes.
    pub fn interior_light(&self, scene: &RefScene, angular_radius: f32) -> Option<SceneLight> {
        let anchor = self.anchor?;
        let room = self.interior;
        let ceiling = scene
            .nearest_hit(anchor, DVec3::Y)
            .map_or(f64::from(room.max.y) - anchor.y, |(t, _)| t);
        let position = (anchor + DVec3::Y * (LIGHT_HEIGHT * ceiling.max(0.0))).as_vec3();
        let drop = (position.y - room.min.y).max(0.0);
        let radius = drop * angular_radius.max(0.0).tan();
        let reach = room.radius().max(1e-4);
        Some(SceneLight {
            name: "interior".into(),
            kind: LightKind::Point {
                position,
                range: None,
            },
            color: Vec3::ONE,
            // A surface `reach` away, facing the light, gets an illuminance of `intensity / reach²` = 1.
            intensity: reach * reach,
            size: if radius > 0.0 && radius.is_finite() {
                LightSize::Radius(radius)
            } else {
                LightSize::Zero
            },
            casts_shadows: true,
            is_static: true,
        })
    }
}

/// A still scene of `scene` (every object static) with its one `light` and `camera`, as
/// `render --scene` renders it.
pub fn scene_file(scene: Scene, light: SceneLight, camera: Camera) -> SceneFile {
    SceneFile {
        static_objects: vec![true; scene.objects.len()],
        shadow_casters: vec![true; scene.objects.len()],
        scene,
        lights: vec![light],
        camera: Some(camera),
        skipped_primitives: 0,
    }
}

/// The point `f` (fractions of each axis) of `bounds`.
fn at(bounds: &Aabb, f: Vec3) -> Vec3 {
    bounds.min + f * bounds.size()
}

/// `to`, or, when a triangle lies on the straight path from `from`, the point [`PULL_BACK`] of the way
/// to it.
fn clear_path(scene: &RefScene, from: DVec3, to: Vec3) -> Vec3 {
    let path = to.as_dvec3() - from;
    match scene.nearest_hit(from, path) {
        Some((t, _)) if t < 1.0 => (from + path * (PULL_BACK * t)).as_vec3(),
        _ => to,
    }
}

/// How open the view from `eye` towards `target` is: the mean, over a 5×3 grid of rays spread over a
/// view [`FOV_Y_DEGREES`] high at 16:9, of how far each ray gets before it meets geometry, as a fraction
/// of the way to the side of `room` it leaves through (1: nothing stands between the eye and the walls).
/// `None` when `eye` and `target` coincide.
fn view_clearance(scene: &RefScene, room: &Aabb, eye: Vec3, target: Vec3) -> Option<f64> {
    let forward = (target - eye).as_dvec3().try_normalize()?;
    let right = forward.cross(DVec3::Y).try_normalize().unwrap_or(DVec3::X);
    let up = right.cross(forward);
    let tan_y = f64::from(FOV_Y_DEGREES.0.to_radians() * 0.5).tan();
    let tan_x = tan_y * 16.0 / 9.0;
    let (origin, min, max) = (eye.as_dvec3(), room.min.as_dvec3(), room.max.as_dvec3());
    let mut sum = 0.0;
    let mut rays = 0.0;
    for sx in [-0.8, -0.4, 0.0, 0.4, 0.8] {
        for sy in [-0.6, 0.0, 0.6] {
            let dir = forward + right * (sx * tan_x) + up * (sy * tan_y);
            let exit = (0..3)
                .filter(|&axis| dir[axis] != 0.0)
                .map(|axis| {
                    let side = if dir[axis] > 0.0 {
                        max[axis]
                    } else {
                        min[axis]
                    };
                    (side - origin[axis]) / dir[axis]
                })
                .fold(f64::INFINITY, f64::min);
            if !(exit > 0.0 && exit.is_finite()) {
                continue;
            }
            let reach = scene.nearest_hit(origin, dir).map_or(exit, |(t, _)| t);
            sum += (reach / exit).min(1.0);
            rays += 1.0;
        }
    }
    Some(if rays > 0.0 { sum / rays } else { 0.0 })
}

/// `n` unit directions spread evenly over the sphere (a Fibonacci lattice).
fn sphere_directions(n: usize) -> Vec<DVec3> {
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let a = golden_angle * i as f64;
            DVec3::new(r * a.cos(), y, r * a.sin())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use scene::MeshBuilder;

    const ROOM_MIN: Vec3 = Vec3::new(-3.0, 0.0, -2.0);
    const ROOM_MAX: Vec3 = Vec3::new(5.0, 3.0, 4.0);
    const TABLE_MIN: Vec3 = Vec3::new(-0.5, 0.0, 0.0);
    const TABLE_MAX: Vec3 = Vec3::new(2.5, 0.8, 2.0);

    /// A room whose six walls (one box, each triangle facing inwards) enclose a table (a solid box on
    /// its floor); without its ceiling when `roof` is false.
    fn room(roof: bool) -> Scene {
        let mut walls = Scene::axis_box("walls", ROOM_MIN, ROOM_MAX);
        for triangle in walls.indices.chunks_exact_mut(3) {
            triangle.swap(1, 2);
        }
        if !roof {
            // The box's faces come in the order +x, -x, +y, -y, +z, -z, two triangles each.
            walls.indices.drain(12..18);
            walls.objects[0].triangle_count -= 2;
        }
        walls.append(&Scene::axis_box("table", TABLE_MIN, TABLE_MAX));
        walls.validate().unwrap();
        walls
    }

    /// The room with its walls wound the other way (facing out), or twice (both ways).
    fn rewound_room(both_ways: bool) -> Scene {
        let mut scene = Scene::axis_box("walls", ROOM_MIN, ROOM_MAX);
        if both_ways {
            scene.append(&room(true));
        } else {
            scene.append(&Scene::axis_box("table", TABLE_MIN, TABLE_MAX));
        }
        scene
    }

    /// The same room built of solid walls 0.2 m thick (six boxes facing outwards), around the table.
    fn thick_walled_room() -> Scene {
        let (lo, hi, t) = (ROOM_MIN, ROOM_MAX, 0.2);
        let mut mesh = MeshBuilder::new();
        mesh.add_box(lo - t, Vec3::new(lo.x, hi.y + t, hi.z + t));
        mesh.add_box(Vec3::new(hi.x, lo.y - t, lo.z - t), hi + t);
        mesh.add_box(lo - t, Vec3::new(hi.x + t, lo.y, hi.z + t));
        mesh.add_box(Vec3::new(lo.x - t, hi.y, lo.z - t), hi + t);
        mesh.add_box(lo - t, Vec3::new(hi.x + t, hi.y + t, lo.z));
        mesh.add_box(Vec3::new(lo.x - t, lo.y - t, hi.z), hi + t);
        mesh.add_box(TABLE_MIN, TABLE_MAX);
        mesh.into_scene("room")
    }

    fn probe(scene: &Scene) -> (RefScene, Enclosure) {
        let reference = RefScene::new(scene);
        let enclosure = Enclosure::probe(&reference, &scene.bounds());
        (reference, enclosure)
    }

    fn inside(b: &Aabb, p: Vec3) -> bool {
        p.cmpgt(b.min).all() && p.cmplt(b.max).all()
    }

    /// The camera and the light of a closed room: inside it, out of the table, the light below the
    /// ceiling and above the table's top, the camera looking down across the room.
    fn assert_interior(scene: &Scene, reference: &RefScene, enclosure: &Enclosure) {
        let room = Aabb {
            min: ROOM_MIN,
            max: ROOM_MAX,
        };
        let table = Aabb {
            min: TABLE_MIN,
            max: TABLE_MAX,
        };
        let interior = enclosure.interior();
        assert!(
            (interior.min - ROOM_MIN).abs().max_element() < 1e-3
                && (interior.max - ROOM_MAX).abs().max_element() < 1e-3,
            "interior {interior:?} is not the room's inside"
        );
        let camera = enclosure.interior_camera(reference, 16.0 / 9.0).unwrap();
        for p in [camera.position, camera.target] {
            assert!(inside(&room, p) && !inside(&table, p), "{p} of {camera:?}");
        }
        assert!(camera.target.y < camera.position.y, "{camera:?}");
        let fov = camera.fov_y_radians.to_degrees();
        assert!((FOV_Y_DEGREES.0..=FOV_Y_DEGREES.1).contains(&fov), "{fov}");
        let light = enclosure.interior_light(reference, 0.02).unwrap();
        let position = light.kind.position().unwrap();
        assert!(inside(&room, position), "{position}");
        assert!(
            position.y > TABLE_MAX.y && position.y < ROOM_MAX.y,
            "{position}"
        );
        assert!(
            matches!(light.size, LightSize::Radius(r) if r > 0.0),
            "{light:?}"
        );
        assert!(light.validate().is_ok());
        let hard = enclosure.interior_light(reference, 0.0).unwrap();
        assert_eq!(hard.size, LightSize::Zero);
        let file = scene_file(scene.clone(), light, camera);
        assert_eq!(file.static_objects.len(), scene.objects.len());
    }

    #[test]
    fn a_closed_room_is_closed_and_gets_a_view_and_a_light_inside() {
        let scene = room(true);
        let (reference, enclosure) = probe(&scene);
        assert!(enclosure.is_closed(), "{}", enclosure.describe());
        assert_eq!(enclosure.hit_fraction(), 1.0);
        assert_eq!(enclosure.probes, 27);
        // The probes inside the table are not free; every other one is.
        assert!(
            enclosure.free_probes > 0 && enclosure.free_probes < 27,
            "{}",
            enclosure.free_probes
        );
        assert!(
            enclosure
                .describe()
                .starts_with("closed scene: 100.0% of the "),
            "{}",
            enclosure.describe()
        );
        assert_interior(&scene, &reference, &enclosure);
    }

    #[test]
    fn a_room_of_solid_walls_is_closed() {
        let scene = thick_walled_room();
        let (reference, enclosure) = probe(&scene);
        assert!(enclosure.is_closed(), "{}", enclosure.describe());
        assert_interior(&scene, &reference, &enclosure);
    }

    #[test]
    fn a_room_wound_outwards_or_both_ways_is_closed() {
        for both_ways in [false, true] {
            let scene = rewound_room(both_ways);
            let (reference, enclosure) = probe(&scene);
            assert!(enclosure.is_closed(), "{}", enclosure.describe());
            assert_interior(&scene, &reference, &enclosure);
        }
    }

    #[test]
    fn a_room_without_its_roof_is_open() {
        let (_, enclosure) = probe(&room(false));
        assert!(enclosure.free_probes > 0);
        assert!(!enclosure.is_closed(), "{}", enclosure.describe());
        assert!(enclosure.least_hit_fraction < 0.9);
        assert!(enclosure.describe().starts_with("open scene: "));
    }

    #[test]
    fn a_model_alone_or_on_a_ground_plane_is_open() {
        let mut mesh = MeshBuilder::new();
        mesh.add_sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 12, 16);
        mesh.add_box(Vec3::new(0.5, 0.0, -0.4), Vec3::new(1.6, 0.8, 0.4));
        let model = mesh.into_scene("model");
        let (_, alone) = probe(&model);
        assert!(!alone.is_closed(), "{}", alone.describe());
        let (_, grounded) = probe(&model.with_ground_plane());
        assert!(grounded.free_probes > 0);
        assert!(!grounded.is_closed(), "{}", grounded.describe());
        // A closed solid holds every probe inside it: none is free, and nothing is placed.
        let cube = Scene::axis_box("cube", Vec3::ZERO, Vec3::ONE);
        let (reference, solid) = probe(&cube);
        assert_eq!(solid.free_probes, 0);
        assert!(!solid.is_closed());
        assert!(solid.interior_camera(&reference, 1.0).is_none());
        assert!(solid.interior_light(&reference, 0.02).is_none());
        assert!(solid.describe().contains("none of 27 points"));
    }

    #[test]
    fn an_empty_scene_is_open() {
        let (_, enclosure) = probe(&Scene::default());
        assert_eq!(enclosure.probes, 0);
        assert!(!enclosure.is_closed());
    }

    #[test]
    fn probe_directions_cover_the_sphere_evenly() {
        let directions = sphere_directions(PROBE_RAYS);
        assert_eq!(directions.len(), PROBE_RAYS);
        assert!(directions.iter().all(|d| (d.length() - 1.0).abs() < 1e-12));
        let mean: DVec3 = directions.iter().sum::<DVec3>() / PROBE_RAYS as f64;
        assert!(mean.length() < 0.01, "{mean}");
        for axis in [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            -DVec3::X,
            -DVec3::Y,
            -DVec3::Z,
        ] {
            assert!(directions.iter().any(|d| d.dot(axis) > 0.99));
        }
    }
}

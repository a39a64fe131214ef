//! The shadow rays of a frame as flat files, so that a CPU ray tracer (`scripts/embree_compare.py`, with
//! Embree) can trace exactly what the GPU traces, and be timed against it.
//!
//! Written into the output folder, all little-endian, in *frame coordinates* (world minus the frame
//! origin, the centre of the scene's bounds, as the plugin's prim buffer and ray trace use them):
//! - `triangles.f32`: 9 floats per triangle (three vertices), every triangle of the scene (the ground plane
//!   included) in index order, as the prim buffer holds them: `f32(world - origin)`;
//! - `rays.f32`: 8 floats per shadow ray: origin xyz, unit direction xyz, `t_max` (infinite for a
//!   directional light, the distance to the emitter for a spot light; hits count for `0 < t < t_max`), and
//!   the pixel index `y * width + x` (exact in f32 below 2^24 pixels), in increasing pixel order. Only pixels
//!   that need a ray have one: no background, no receiver facing away from the light, nothing outside the
//!   light's map (a spot light's cone);
//! - `ray_near_edge.u8`: one byte per ray, 1 where the exact reference puts an event within its tolerance
//!   of a triangle edge or plane (camera or shadow ray): a tracer in f32 may legitimately differ there;
//! - `rays.json`: sizes, light kind, frame origin, the ray-origin offset, and the layouts above.
//!
//! The receiver points are the exact (f64) camera-ray hits of [`reference::reference_visibility`] with the
//! tolerances of [`crate::accuracy::compare_visibility`]; each shadow ray is then built as the GPU builds it
//! (`passes/shaders/shadow_ray.glsl`): the origin is moved along the receiver's camera-facing geometric
//! normal by [`passes::ray_trace::RAY_OFFSET_PIXELS`] of pixel footprint plus
//! [`passes::ray_trace::RAY_OFFSET_FLOAT_BOUND`] times the receiver's largest frame coordinate, so a tracer
//! needs no `t_min` and no receiver exclusion.

use crate::accuracy::{absolute_tolerance, tolerance_per_distance};
use anyhow::{bail, Context, Result};
use demo_engine::View;
use glam::{DVec3, DVec4};
use passes::ray_trace::{RAY_OFFSET_FLOAT_BOUND, RAY_OFFSET_PIXELS};
use passes::FrameInputs;
use reference::{reference_visibility_with_progress, PixelClass, RefScene, VisibilityParams};
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

/// Floats per triangle in `triangles.f32`.
pub const TRIANGLE_FLOATS: usize = 9;
/// Floats per ray in `rays.f32`.
pub const RAY_FLOATS: usize = 8;
/// Largest pixel count whose indices are exact in f32.
const MAX_PIXELS: u64 = 1 << 24;

/// What [`write_ray_dump`] wrote.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RayDumpSummary {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Shadow rays written.
    pub rays: usize,
    /// Of which the exact reference calls near an edge (may legitimately differ between tracers).
    pub near_edge_rays: usize,
    /// Triangles written.
    pub triangles: usize,
    /// "directional" or "spot".
    pub light: &'static str,
}

/// One shadow ray, in frame coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
struct DumpRay {
    origin: DVec3,
    dir: DVec3,
    t_max: f64,
    pixel: u32,
    near_edge: bool,
}

impl DumpRay {
    fn floats(&self) -> [f32; RAY_FLOATS] {
        let (o, d) = (self.origin.as_vec3(), self.dir.as_vec3());
        [
            o.x,
            o.y,
            o.z,
            d.x,
            d.y,
            d.z,
            self.t_max as f32,
            self.pixel as f32,
        ]
    }
}

#[derive(Serialize)]
struct RayOffsetJson {
    pixels: f32,
    float_bound: f32,
    radians_per_pixel: f64,
}

#[derive(Serialize)]
struct RaysJson<'a> {
    #[serde(flatten)]
    summary: &'a RayDumpSummary,
    /// Spot light position in frame coordinates.
    light_position: Option<[f64; 3]>,
    /// Direction the light travels (unit).
    light_direction: [f64; 3],
    coordinates: &'static str,
    frame_origin: [f64; 3],
    ray_offset: RayOffsetJson,
    files: BTreeMap<&'static str, &'static str>,
}

/// Writes `triangles.f32`, `rays.f32`, `ray_near_edge.u8` and `rays.json` (see the module documentation)
/// into `out` for the frame `view` renders with camera and light `inputs` (`view.frame_inputs()` for the
/// demo), and returns their sizes. Computes the exact reference visibility of every pixel on the way
/// (rayon), which takes a few seconds at 1080p on two cores.
pub fn write_ray_dump(view: &View, inputs: &FrameInputs, out: &Path) -> Result<RayDumpSummary> {
    if u64::from(view.width) * u64::from(view.height) > MAX_PIXELS {
        bail!(
            "{}x{} px: pixel indices above 2^24 are not exact in f32",
            view.width,
            view.height
        );
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let rs = RefScene::new(&view.scene);
    let origin = view.frame_origin();
    let rays = shadow_rays(&rs, view, inputs, origin);

    let mut tris = Vec::with_capacity(rs.triangle_count() * TRIANGLE_FLOATS);
    for i in 0..rs.triangle_count() {
        for v in rs.triangle(i) {
            tris.extend((v - origin).as_vec3().to_array());
        }
    }
    write_f32(&out.join("triangles.f32"), &tris)?;
    let ray_floats: Vec<f32> = rays.iter().flat_map(DumpRay::floats).collect();
    write_f32(&out.join("rays.f32"), &ray_floats)?;
    let flags: Vec<u8> = rays.iter().map(|r| u8::from(r.near_edge)).collect();
    write_file(&out.join("ray_near_edge.u8"), &flags)?;

    let summary = RayDumpSummary {
        width: view.width,
        height: view.height,
        rays: rays.len(),
        near_edge_rays: flags.iter().filter(|&&f| f != 0).count(),
        triangles: rs.triangle_count(),
        light: inputs.light.kind_name(),
    };
    let json = RaysJson {
        summary: &summary,
        light_position: inputs
            .light
            .position()
            .map(|p| (p.as_dvec3() - origin).to_array()),
        light_direction: inputs
            .light
            .direction()
            .as_dvec3()
            .normalize_or_zero()
            .to_array(),
        coordinates: "frame: world minus frame_origin",
        frame_origin: origin.to_array(),
        ray_offset: RayOffsetJson {
            pixels: RAY_OFFSET_PIXELS,
            float_bound: RAY_OFFSET_FLOAT_BOUND,
            radians_per_pixel: radians_per_pixel(inputs, view.height),
        },
        files: BTreeMap::from([
            ("triangles.f32", "f32 LE, 9 per triangle: v0 v1 v2 (xyz each)"),
            (
                "rays.f32",
                "f32 LE, 8 per ray: ox oy oz dx dy dz t_max pixel (y*width+x); hits count for 0 < t < t_max",
            ),
            (
                "ray_near_edge.u8",
                "u8, 1 per ray: 1 where the exact reference is ambiguous (near a triangle edge or plane)",
            ),
        ]),
    };
    let text = serde_json::to_string_pretty(&json)?;
    write_file(&out.join("rays.json"), text.as_bytes())?;
    Ok(summary)
}

/// Radians per pixel at the image centre, as the GPU computes its ray-origin offset.
fn radians_per_pixel(inputs: &FrameInputs, height: u32) -> f64 {
    (2.0 / (f64::from(inputs.proj.y_axis.y) * f64::from(height))).abs()
}

/// The shadow ray of every pixel that needs one, in pixel order.
fn shadow_rays(rs: &RefScene, view: &View, inputs: &FrameInputs, origin: DVec3) -> Vec<DumpRay> {
    let view_matrix = inputs.view.as_dmat4();
    let light = match inputs.light {
        passes::Light::Directional { direction, .. } => reference::Light::Directional {
            direction: direction.as_dvec3().normalize_or_zero(),
        },
        passes::Light::Spot { position, .. } | passes::Light::Point { position, .. } => {
            reference::Light::Point {
                position: position.as_dvec3(),
            }
        }
    };
    // As `accuracy::compare_visibility` builds the reference the GPU is checked against.
    let params = VisibilityParams {
        width: view.width,
        height: view.height,
        view_proj: inputs.proj.as_dmat4() * view_matrix,
        camera_position: view_matrix.inverse().transform_point3(DVec3::ZERO),
        light,
        tolerance: absolute_tolerance(view),
        tolerance_per_distance: tolerance_per_distance(view),
        pixel_tolerance: 1.0 / 128.0,
    };
    let rows = host_demo::progress::phase("CPU reference", u64::from(view.height));
    let reference = reference_visibility_with_progress(rs, &params, &|| rows.inc(1));
    drop(rows);
    let camera = inputs.camera_position.as_dvec3() - origin;
    let light_view_proj = inputs.light.view_proj().as_dmat4();
    let light_position = inputs.light.position().map(|p| p.as_dvec3() - origin);
    let light_dir = inputs.light.direction().as_dvec3().normalize_or_zero();
    let per_distance = radians_per_pixel(inputs, view.height) * f64::from(RAY_OFFSET_PIXELS);

    let mut rays = Vec::new();
    for (i, &position) in reference.position.iter().enumerate() {
        let receiver = reference.receiver[i];
        if !position.is_finite() || receiver == u32::MAX {
            continue; // background
        }
        let p = position - origin;
        let rel = p - camera;
        let [a, b, c] = rs.triangle(receiver as usize);
        let mut n = (b - a).cross(c - a).normalize_or_zero();
        if n.dot(rel) > 0.0 {
            n = -n; // the camera-facing side, as the G-buffer stores it
        }
        let to_light = light_position.map_or(-light_dir, |l| l - p);
        let facing = n.dot(to_light);
        if facing.is_nan() || facing <= 0.0 {
            continue; // facing away from the light
        }
        // As the GPU offsets its origins (shadow_ray.glsl), with the demo's reversed-Z float depth: its
        // rounding moves the rebuilt point by at most 2^-23 of its distance.
        let delta = rel.length() * (per_distance + f64::from(f32::EPSILON))
            + p.abs().max_element() * f64::from(RAY_OFFSET_FLOAT_BOUND);
        let o = p + n * delta;
        let (dir, t_max) = match light_position {
            None => (to_light, f64::INFINITY),
            Some(l) => {
                let d = l - o;
                let t_max = d.length();
                if t_max.is_nan() || t_max <= 0.0 {
                    continue; // at the emitter: lit
                }
                (d / t_max, t_max)
            }
        };
        if !inside_light_map(light_view_proj * (o + origin).extend(1.0)) {
            continue; // no recorded occluder: the GPU calls it lit without a ray
        }
        rays.push(DumpRay {
            origin: o,
            dir,
            t_max,
            pixel: i as u32,
            near_edge: reference.class[i] == PixelClass::Ambiguous,
        });
    }
    rays
}

/// Whether a light clip-space point lies in front of the light and inside its map (`[-1, 1)` in x and y).
fn inside_light_map(clip: DVec4) -> bool {
    if clip.w.is_nan() || clip.w <= 0.0 {
        return false;
    }
    let (x, y) = (clip.x / clip.w, clip.y / clip.w);
    (-1.0..1.0).contains(&x) && (-1.0..1.0).contains(&y)
}

fn write_f32(path: &Path, values: &[f32]) -> Result<()> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    write_file(path, &bytes)
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut f = std::io::BufWriter::new(
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?,
    );
    f.write_all(bytes)
        .and_then(|()| f.flush())
        .with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::ViewInputs;
    use glam::Vec3;
    use reference::intersect_watertight;
    use scene::{MeshBuilder, Scene};

    fn read_f32(path: &Path) -> Vec<f32> {
        std::fs::read(path)
            .unwrap()
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect()
    }

    /// A unit cube floating above the ground, a tilted quad beside it, and the demo's ground plane.
    fn small_scene(offset: Vec3) -> Scene {
        let mut blocks = MeshBuilder::new();
        blocks.add_box(Vec3::new(0.0, 0.5, 0.0), Vec3::new(1.0, 1.5, 1.0));
        blocks.add_quad([
            Vec3::new(1.5, 0.2, 0.0),
            Vec3::new(2.5, 0.6, 0.0),
            Vec3::new(2.5, 0.6, 1.0),
            Vec3::new(1.5, 0.2, 1.0),
        ]);
        blocks
            .into_scene("blocks")
            .with_ground_plane()
            .translated(offset)
    }

    /// Brute-force any-hit over the dumped triangles, in f64 from the dumped f32 values.
    fn occluded(tris: &[[DVec3; 3]], ray: &[f32]) -> bool {
        let o = DVec3::new(ray[0].into(), ray[1].into(), ray[2].into());
        let d = DVec3::new(ray[3].into(), ray[4].into(), ray[5].into());
        let t_max = f64::from(ray[6]);
        tris.iter()
            .any(|t| intersect_watertight(o, d, t).is_some_and(|(s, _)| s > 0.0 && s < t_max))
    }

    /// The dump round-trips, holds one ray per reference receiver lit by or facing the light, and tracing
    /// its f32 rays against its f32 triangles gives the exact reference visibility wherever the reference
    /// is certain: origins, offsets, directions, pixel indices and coordinates agree, at the origin and
    /// 1e4 away from it.
    fn check(offset: Vec3) {
        let view = View::framed(small_scene(offset), 64, 48);
        let inputs = view.frame_inputs();
        let out =
            std::env::temp_dir().join(format!("hrts_ray_dump_{}_{}", std::process::id(), offset.x));
        let summary = write_ray_dump(&view, &inputs, &out).unwrap();

        let origin = view.frame_origin();
        let tri_floats = read_f32(&out.join("triangles.f32"));
        assert_eq!(tri_floats.len(), summary.triangles * TRIANGLE_FLOATS);
        assert_eq!(summary.triangles, view.scene.triangle_count());
        let tris: Vec<[DVec3; 3]> = tri_floats
            .chunks_exact(TRIANGLE_FLOATS)
            .map(|t| std::array::from_fn(|k| Vec3::from_slice(&t[3 * k..]).as_dvec3()))
            .collect();
        for (i, t) in tris.iter().enumerate() {
            let expected = view
                .scene
                .triangle(i)
                .map(|v| (v.as_dvec3() - origin).as_vec3());
            assert_eq!(t.map(|v| v.as_vec3()), expected, "triangle {i}");
        }

        let rays = read_f32(&out.join("rays.f32"));
        let flags = std::fs::read(out.join("ray_near_edge.u8")).unwrap();
        assert_eq!(rays.len(), summary.rays * RAY_FLOATS);
        assert_eq!(flags.len(), summary.rays);
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("rays.json")).unwrap()).unwrap();
        assert_eq!(json["rays"], summary.rays);
        assert_eq!(json["triangles"], summary.triangles);
        assert_eq!(json["width"], 64);
        assert_eq!(json["light"], "directional");

        // The reference's receivers that need a ray: a receiver facing the light (lit, or shadowed by a
        // blocker at a non-zero distance); background and receivers facing away have none.
        let rs = RefScene::new(&view.scene);
        let view_matrix = inputs.view.as_dmat4();
        let params = VisibilityParams {
            width: view.width,
            height: view.height,
            view_proj: inputs.proj.as_dmat4() * view_matrix,
            camera_position: view_matrix.inverse().transform_point3(DVec3::ZERO),
            light: reference::Light::Directional {
                direction: inputs.light.direction().as_dvec3(),
            },
            tolerance: absolute_tolerance(&view),
            tolerance_per_distance: tolerance_per_distance(&view),
            pixel_tolerance: 1.0 / 128.0,
        };
        let r = reference::reference_visibility(&rs, &params);
        let pixels: Vec<usize> = rays
            .chunks_exact(RAY_FLOATS)
            .map(|ray| ray[7] as usize)
            .collect();
        assert!(
            pixels.windows(2).all(|w| w[0] < w[1]),
            "pixel order and uniqueness"
        );
        let mut has_ray = vec![false; r.class.len()];
        pixels.iter().for_each(|&p| has_ray[p] = true);
        let (mut lit, mut shadowed, mut compared) = (0, 0, 0);
        for (i, class) in r.class.iter().enumerate() {
            let needs_ray = match class {
                PixelClass::Lit => Some(true),
                PixelClass::Shadowed => Some(r.blocker_distance[i] != 0.0),
                PixelClass::Background => Some(false),
                PixelClass::Ambiguous => None,
            };
            if let Some(needs) = needs_ray {
                assert_eq!(has_ray[i], needs, "pixel {i} ({class:?})");
            }
        }
        let receivers = r
            .class
            .iter()
            .zip(&r.blocker_distance)
            .filter(|(c, bd)| {
                **c == PixelClass::Lit || (**c == PixelClass::Shadowed && **bd != 0.0)
            })
            .count();
        assert_eq!(summary.rays - summary.near_edge_rays, receivers);

        for (ray, &flag) in rays.chunks_exact(RAY_FLOATS).zip(&flags) {
            let p = ray[7] as usize;
            assert_eq!(flag != 0, r.class[p] == PixelClass::Ambiguous);
            assert!(ray[6].is_infinite());
            assert!((Vec3::from_slice(&ray[3..6]).length() - 1.0).abs() < 1e-6);
            if flag != 0 {
                continue;
            }
            compared += 1;
            let blocked = occluded(&tris, ray);
            assert_eq!(
                blocked,
                r.class[p] == PixelClass::Shadowed,
                "pixel ({}, {})",
                p % 64,
                p / 64
            );
            if blocked {
                shadowed += 1;
            } else {
                lit += 1;
            }
        }
        assert!(
            lit > 200 && shadowed > 100,
            "the frame should hold lit and shadowed receivers: {lit} lit, {shadowed} shadowed"
        );
        assert!(compared * 10 > summary.rays * 9, "{summary:?}");
        std::fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn dump_round_trips_and_traces_like_the_reference() {
        check(Vec3::ZERO);
    }

    #[test]
    fn dump_is_exact_far_from_the_world_origin() {
        check(Vec3::new(1e4, 0.0, -1e4));
    }
}

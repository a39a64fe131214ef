//! Accuracy of a rendered frame against the exact CPU reference, as counts: primitive-map texel lists
//! against exact conservative binning, and ray-traced visibility against exact visibility.

use demo_engine::{CameraMatrices, FrameImages, View};
use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};
use passes::{PrimitiveMapConfig, GUARD_WORDS};
use reference::{
    conservative_texel_sets, overlaps_texel_with_margin, reference_visibility_with_progress,
    FaceSelection, Light, PixelClass, RefScene, VisibilityParams, VisibilityReference,
};
use scene::{Camera, Scene};

/// Margin (texels) within which an extra primitive-map entry is legitimate: every binning path accepts
/// texels grown by 1/512 texel plus the f32 projection error bound, and bins a sliver thinner than 1/16
/// texel as the segment of its longest edge grown by its thickness.
pub const EXTRA_MARGIN_TEXELS: f64 = 1.0 / 16.0 + 1.0 / 128.0;

/// Outcome of comparing a GPU primitive map with the exact conservative sets.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct MapComparison {
    /// Texels compared (their lists fit the capacity).
    pub texels: usize,
    /// Required triangles absent from a texel's list (counted only for maps built without receiver
    /// culling; see [`passes::PrimitiveMapConfig::receiver_culling`]).
    pub missing: usize,
    /// Entries beyond the exact set but within the path's margin of the texel.
    pub extra_within_margin: usize,
    /// Entries out of range, duplicated, or not touching the texel even with the margin.
    pub garbage: usize,
    /// Texels whose list did not fit the entry capacity (traced exhaustively; not compared).
    pub past_capacity: usize,
    /// Zero-area triangles (two equal vertices) absent from lists: culled by design, never a blocker.
    pub missing_degenerate: usize,
}

/// The light matrix (world to light NDC) of the primitive map's fitted grid: the report's frame-to-texel
/// transform, with the frame origin and the texel-to-NDC scale composed in f64.
pub fn fitted_light_matrix(map_to_texels: Mat4, origin: DVec3, n: u32) -> DMat4 {
    let to_ndc = DMat4::from_cols(
        DVec4::new(2.0 / f64::from(n), 0.0, 0.0, 0.0),
        DVec4::new(0.0, 2.0 / f64::from(n), 0.0, 0.0),
        DVec4::new(0.0, 0.0, 1.0, 0.0),
        DVec4::new(-1.0, -1.0, 0.0, 1.0),
    );
    to_ndc * map_to_texels.as_dmat4() * DMat4::from_translation(-origin)
}

/// Compares every texel's list with the exact conservative set of the fitted grid (`light`: see
/// [`fitted_light_matrix`]): entries must lie within [`EXTRA_MARGIN_TEXELS`] of their texel (every
/// binning path grows texels by 1/512 texel plus its rounding bound). Missing triangles are looked for
/// only in a map built without receiver culling; with it, only the entries are checked (garbage).
pub fn compare_map(
    rs: &RefScene,
    light: DMat4,
    light_direction: Vec3,
    config: &PrimitiveMapConfig,
    images: &FrameImages,
    faces: FaceSelection,
) -> MapComparison {
    let n = config.size;
    let sets = conservative_texel_sets(rs, light, light_direction, n, faces);
    let tri_count = rs.triangle_count() as u32;
    let degenerate = |i: u32| {
        let [a, b, c] = rs.triangle(i as usize);
        a == b || b == c || c == a
    };
    let guard = if config.guard {
        GUARD_WORDS as usize
    } else {
        0
    };
    let capacity = images.list_entries.len().saturating_sub(guard);
    let mut c = MapComparison::default();
    for y in 0..n {
        for x in 0..n {
            let t = (y * n + x) as usize;
            let Some(range) = images.list_offsets.range(t).filter(|r| r.end <= capacity) else {
                c.past_capacity += 1;
                continue;
            };
            let (begin, end) = (range.start, range.end);
            let stored = &images.list_entries[begin..end];
            let mut sorted = stored.to_vec();
            sorted.sort_unstable();
            sorted.dedup();
            c.garbage += stored.len() - sorted.len();
            let exact = sets.texel(x, y);
            for &i in &sorted {
                if i >= tri_count {
                    c.garbage += 1;
                } else if exact.binary_search(&i).is_err() {
                    if overlaps_texel_with_margin(rs, light, n, i, x, y, EXTRA_MARGIN_TEXELS) {
                        c.extra_within_margin += 1;
                    } else {
                        c.garbage += 1;
                    }
                }
            }
            c.texels += 1;
            if config.receiver_culling {
                continue;
            }
            for &i in exact.iter().filter(|i| sorted.binary_search(i).is_err()) {
                if degenerate(i) {
                    c.missing_degenerate += 1;
                } else {
                    c.missing += 1;
                }
            }
        }
    }
    c
}

/// Outcome of comparing GPU visibility with the exact reference.
#[derive(Debug, Default)]
pub struct VisibilityComparison {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels the reference classes as near an edge/plane within tolerance (not compared).
    pub near_edge: usize,
    /// Per pixel (row-major): whether it is near an edge.
    pub near_edge_mask: Vec<bool>,
    /// Lit/shadowed/background disagreements outside near-edge pixels.
    pub mismatches: usize,
    /// Exact shadowed pixels.
    pub shadowed: usize,
    /// Shadowed pixels with a certain nearest blocker whose GPU distance differs by more than the bound.
    pub blocker_mismatches: usize,
    /// Largest blocker-distance error seen (world units).
    pub max_blocker_error: f64,
    /// NaN or Inf in GPU visibility or blocker distance.
    pub non_finite: usize,
    /// First mismatching pixels, for failure messages.
    pub examples: Vec<(u32, u32, &'static str, f32)>,
}

/// Tolerance of the reference per unit of camera distance: 1/16 of the pixel footprint — four times the
/// GPU's ray-origin offset, and above the receiver displacement of 1/512-pixel vertex snapping down to
/// view angles of a few degrees.
pub fn tolerance_per_distance(view: &View) -> f64 {
    camera_tolerance_per_distance(&view.camera, view.height)
}

/// [`tolerance_per_distance`] of `camera` for a frame `height` pixels high.
fn camera_tolerance_per_distance(camera: &Camera, height: u32) -> f64 {
    2.0 * (camera.fov_y_radians as f64 / 2.0).tan() / height as f64 / 16.0
}

/// Absolute floor of the reference tolerance: 64 f32 ulps of the largest frame coordinate. The passes work
/// relative to the centre of the scene (the frame origin) and to the camera, so what matters is the scene's
/// radius and the camera's distance from its centre, not where the scene sits in the world.
pub fn absolute_tolerance(view: &View) -> f64 {
    scene_absolute_tolerance(&view.scene, &view.camera)
}

/// [`absolute_tolerance`] of `scene` seen from `camera`.
fn scene_absolute_tolerance(scene: &Scene, camera: &Camera) -> f64 {
    let b = scene.bounds();
    let from_center = (camera.position - b.center()).length();
    let magnitude = f64::from(b.radius().max(from_center));
    64.0 * f64::from(f32::EPSILON) * magnitude
}

/// The exact reference's view of `view`: the camera matrices composed in f64 as the passes do (relative to
/// the camera, the rays starting at the view matrix's own eye), the light, and the tolerances.
pub fn visibility_params(view: &View) -> VisibilityParams {
    let light = Light::Directional {
        direction: view.light.direction.as_dvec3(),
    };
    scene_visibility_params(&view.scene, &view.camera, view.width, view.height, light)
}

/// The exact reference's view of `scene` through `camera` in a `width` x `height` frame lit by `light`
/// (see [`visibility_params`]).
pub fn scene_visibility_params(
    scene: &Scene,
    camera: &Camera,
    width: u32,
    height: u32,
    light: Light,
) -> VisibilityParams {
    let matrices = CameraMatrices::of_camera(camera, width, height);
    let view_matrix = matrices.view.as_dmat4();
    VisibilityParams {
        width,
        height,
        view_proj: matrices.proj.as_dmat4() * view_matrix,
        camera_position: view_matrix.inverse().transform_point3(DVec3::ZERO),
        light,
        tolerance: scene_absolute_tolerance(scene, camera),
        tolerance_per_distance: camera_tolerance_per_distance(camera, height),
        pixel_tolerance: 1.0 / 128.0,
    }
}

/// Compares GPU visibility and blocker distance with the exact reference ([`view_reference`]).
pub fn compare_visibility(
    rs: &RefScene,
    view: &View,
    images: &FrameImages,
) -> VisibilityComparison {
    compare_visibility_to(&view_reference(rs, view), view, images)
}

/// The exact reference of `view` ([`visibility_params`]); its rows are counted as the phase "CPU
/// reference" of the run's progress ([`host_demo::progress::phase`]).
pub fn view_reference(rs: &RefScene, view: &View) -> VisibilityReference {
    let rows = host_demo::progress::phase("CPU reference", u64::from(view.height));
    reference_visibility_with_progress(rs, &visibility_params(view), &|| rows.inc(1))
}

/// Compares GPU visibility and blocker distance with `r`, the exact reference of `view`
/// ([`view_reference`]).
pub fn compare_visibility_to(
    r: &VisibilityReference,
    view: &View,
    images: &FrameImages,
) -> VisibilityComparison {
    let params = visibility_params(view);
    let far = (view.camera.position - view.scene.bounds().center()).length() as f64
        + view.scene.bounds().radius() as f64;
    let bd_bound = 4.0 * (params.tolerance + far * params.tolerance_per_distance);
    compare_with_reference(
        r,
        &images.visibility,
        Some((&images.blocker_distance, bd_bound)),
        None,
    )
}

/// Compares GPU visibility (row-major, like the reference) with the exact reference `r`: every pixel,
/// or those `considered` holds true for. With `blocker`, the GPU blocker distances and their error bound
/// are compared too, on shadowed pixels with a certain nearest blocker.
pub fn compare_with_reference(
    r: &VisibilityReference,
    visibility: &[f32],
    blocker: Option<(&[f32], f64)>,
    considered: Option<&[bool]>,
) -> VisibilityComparison {
    let mut c = VisibilityComparison {
        near_edge_mask: vec![false; r.class.len()],
        ..VisibilityComparison::default()
    };
    for (i, class) in r.class.iter().enumerate() {
        if considered.is_some_and(|m| !m[i]) {
            continue;
        }
        let (x, y) = (i as u32 % r.width, i as u32 / r.width);
        let vis = visibility[i];
        let bd = blocker.map_or(0.0, |(b, _)| b[i]);
        c.pixels += 1;
        if !vis.is_finite() || !bd.is_finite() {
            c.non_finite += 1;
        }
        let expected = match class {
            PixelClass::Ambiguous => {
                c.near_edge += 1;
                c.near_edge_mask[i] = true;
                continue;
            }
            PixelClass::Background | PixelClass::Lit => 1.0,
            PixelClass::Shadowed => {
                c.shadowed += 1;
                0.0
            }
        };
        if vis != expected {
            c.mismatches += 1;
            if c.examples.len() < 8 {
                let what = match class {
                    PixelClass::Background => "background",
                    PixelClass::Lit => "lit",
                    _ => "shadowed",
                };
                c.examples.push((x, y, what, vis));
            }
            continue;
        }
        let Some((_, bd_bound)) = blocker else {
            continue;
        };
        let ref_bd = r.blocker_distance[i];
        if *class == PixelClass::Shadowed && ref_bd.is_finite() && ref_bd > 0.0 {
            let err = (f64::from(bd) - ref_bd).abs();
            c.max_blocker_error = c.max_blocker_error.max(err);
            if err > bd_bound.max(ref_bd * 1e-4) {
                c.blocker_mismatches += 1;
                if c.examples.len() < 8 {
                    c.examples
                        .push((x, y, "blocker distance", bd - ref_bd as f32));
                }
            }
        }
    }
    c
}

/// Outcome of comparing GPU area shadows with the exact reference of the same light samples.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct AreaComparison {
    /// Pixels compared (every pixel of the frame, or those considered).
    pub pixels: usize,
    /// Pixels with a sample within the reference's tolerance of an edge or plane (counted, not compared).
    pub unstable: usize,
    /// Stable pixels whose GPU visible count differs from the reference's.
    pub mismatches: usize,
    /// Stable pixels in a penumbra (some samples visible, some not) by the reference.
    pub penumbra: usize,
    /// Stable pixels fully shadowed by the reference.
    pub umbra: usize,
    /// NaN or Inf, or a value that is no multiple of 1 / samples, in the GPU output.
    pub non_finite: usize,
    /// First mismatching pixels `(x, y, reference count, GPU count)`.
    pub examples: Vec<(u32, u32, u32, f32)>,
}

/// Compares GPU area-shadow visibility (`visibility`, row-major, the visible fraction of `samples`) with
/// the exact reference of the same sample directions: the light of `view` of angular radius
/// `angular_radius`, sampled by [`passes::area::area_sample_directions`]. The reference's rows (of every
/// sample) are counted as the phase "CPU reference" of the run's progress.
pub fn compare_area(
    rs: &RefScene,
    view: &View,
    angular_radius: f32,
    samples: u32,
    visibility: &[f32],
) -> AreaComparison {
    let directions: Vec<DVec3> =
        passes::area::area_sample_directions(view.light.direction, angular_radius, samples)
            .iter()
            .map(|w| w.as_dvec3())
            .collect();
    let rows = host_demo::progress::phase(
        format!("CPU reference ({samples} samples)"),
        u64::from(view.height) * directions.len() as u64,
    );
    let r =
        reference::area_reference_with_progress(rs, &visibility_params(view), &directions, &|| {
            rows.inc(1)
        });
    compare_area_counts(&r, visibility, None)
}

/// Compares GPU area-shadow visibility (`visibility`, row-major, the visible fraction of the reference's
/// samples) with the reference's visible counts, on the pixels it marks stable; with `considered`, only
/// on the pixels it marks (a spot light's cone, say).
pub fn compare_area_counts(
    r: &reference::AreaReference,
    visibility: &[f32],
    considered: Option<&[bool]>,
) -> AreaComparison {
    let samples = r.samples;
    let mut c = AreaComparison::default();
    for (i, &v) in visibility.iter().enumerate() {
        if considered.is_some_and(|m| !m[i]) {
            continue;
        }
        c.pixels += 1;
        let count = v * samples as f32;
        if !count.is_finite() || (count - count.round()).abs() > 1e-3 {
            c.non_finite += 1;
            continue;
        }
        if !r.stable[i] {
            c.unstable += 1;
            continue;
        }
        let expected = r.visible[i];
        if expected == 0 {
            c.umbra += 1;
        } else if expected < samples {
            c.penumbra += 1;
        }
        if count.round() as u32 != expected {
            c.mismatches += 1;
            if c.examples.len() < 8 {
                let w = r.width as usize;
                c.examples
                    .push(((i % w) as u32, (i / w) as u32, expected, count));
            }
        }
    }
    c
}

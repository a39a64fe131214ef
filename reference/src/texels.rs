//! Exact conservative binning of triangles into light-space texels.

use glam::{DMat4, DVec2, DVec3, Vec3};
use rayon::prelude::*;

use crate::exact::orient2d;
use crate::RefScene;

/// Triangles per parallel work item.
const CHUNK: usize = 1024;

/// Which triangles are binned by [`conservative_texel_sets`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceSelection {
    /// Both front- and back-facing triangles.
    Both,
    /// Only triangles strictly facing the light.
    FrontOnly,
}

/// Exact conservative binning of triangles into an `n x n` light-space grid (the
/// texels of a deep primitive map).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TexelSets {
    /// Grid resolution.
    pub n: u32,
    /// CSR offsets, `n * n + 1` entries; texel `(x, y)` has index `y * n + x` and owns
    /// `triangles[offsets[i]..offsets[i + 1]]`.
    pub offsets: Vec<u32>,
    /// Required triangles per texel, sorted ascending within each texel.
    pub triangles: Vec<u32>,
    /// Per triangle: whether it is required in every texel it overlaps. `false` for
    /// triangles that are degenerate in 3D, that have a vertex with clip `w <= 0` (or a
    /// non-finite projection), or (with [`FaceSelection::FrontOnly`]) that are not
    /// strictly front-facing; those are listed nowhere and are neither required nor
    /// forbidden.
    pub required: Vec<bool>,
    /// Per triangle: its projected light-space area is exactly 0 (edge-on to the
    /// light; tier-1 conservative rasterisation may cull it). `false` when the
    /// triangle cannot be projected.
    pub light_degenerate: Vec<bool>,
}

impl TexelSets {
    /// Triangles of texel `(x, y)`, ascending; empty outside the grid.
    pub fn texel(&self, x: u32, y: u32) -> &[u32] {
        if x >= self.n || y >= self.n {
            return &[];
        }
        let index = y as usize * self.n as usize + x as usize;
        match (self.offsets.get(index), self.offsets.get(index + 1)) {
            (Some(&start), Some(&end)) => self
                .triangles
                .get(start as usize..end as usize)
                .unwrap_or(&[]),
            _ => &[],
        }
    }
}

/// Bins every triangle of `scene` into the `n x n` light-space texels it overlaps.
///
/// Texel coordinates of a world point `p`: `clip = light_view_proj * (p, 1)`,
/// `ndc = clip.xy / clip.w`, `texel = (ndc * 0.5 + 0.5) * n` (continuous; texel
/// `(x, y)` is the closed square `[x, x + 1] x [y, y + 1]`, `y = 0` at NDC y = -1).
///
/// A required triangle belongs to a texel iff its projected closed 2D triangle
/// overlaps the closed texel square. The test is a separating-axis test on the two
/// square axes and the three triangle edge normals, evaluated with exact
/// orientation predicates on the `f64` projected vertices, so touching counts as
/// overlapping; projections of zero area are tested as segments or points.
/// Triangles partly or wholly outside `[0, n]^2` contribute only to the texels they
/// overlap.
///
/// With [`FaceSelection::FrontOnly`] a triangle is required only if
/// `dot(cross(v1 - v0, v2 - v0), -light_direction) > 0` (pass the directional
/// light's direction of travel). Triangles with any vertex at clip `w <= 0` are
/// marked not required and skipped, as are triangles degenerate in 3D; see
/// [`TexelSets::required`].
///
/// Work is parallel over triangles; the CSR is assembled in triangle order. The
/// total number of entries and `n * n` must fit in `u32`.
pub fn conservative_texel_sets(
    scene: &RefScene,
    light_view_proj: DMat4,
    light_direction: Vec3,
    n: u32,
    faces: FaceSelection,
) -> TexelSets {
    let projection = Projection::new(light_view_proj, n);
    let to_light = -light_direction.as_dvec3();
    let count = scene.triangle_count();
    let chunks: Vec<ChunkResult> = (0..count.div_ceil(CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let range = chunk * CHUNK..((chunk + 1) * CHUNK).min(count);
            let mut result = ChunkResult::default();
            for i in range {
                let tri = scene.triangle(i);
                let Some(q) = projection.triangle(&tri) else {
                    result.required.push(false);
                    result.light_degenerate.push(false);
                    continue;
                };
                let facing = match faces {
                    FaceSelection::Both => true,
                    FaceSelection::FrontOnly => {
                        (tri[1] - tri[0]).cross(tri[2] - tri[0]).dot(to_light) > 0.0
                    }
                };
                let required = scene.is_usable(i) && facing;
                result.required.push(required);
                result
                    .light_degenerate
                    .push(orient2d(q[0], q[1], q[2]) == 0.0);
                if required {
                    let tri_index = u32::try_from(i).unwrap_or(u32::MAX);
                    for_each_overlapped_texel(&q, n, |texel| result.pairs.push((texel, tri_index)));
                }
            }
            result
        })
        .collect();

    let cells = n as usize * n as usize;
    let mut counts = vec![0u32; cells + 1];
    for &(texel, _) in chunks.iter().flat_map(|c| &c.pairs) {
        counts[texel + 1] += 1;
    }
    for i in 0..cells {
        counts[i + 1] += counts[i];
    }
    let offsets = counts;
    let mut cursor = offsets.clone();
    let mut triangles = vec![0u32; offsets[cells] as usize];
    let mut required = Vec::with_capacity(count);
    let mut light_degenerate = Vec::with_capacity(count);
    for chunk in chunks {
        for (texel, tri) in chunk.pairs {
            triangles[cursor[texel] as usize] = tri;
            cursor[texel] += 1;
        }
        required.extend(chunk.required);
        light_degenerate.extend(chunk.light_degenerate);
    }
    TexelSets {
        n,
        offsets,
        triangles,
        required,
        light_degenerate,
    }
}

/// True if triangle `tri` overlaps texel `(x, y)` grown by `margin` texels on every
/// side, i.e. the closed square `[x - margin, x + 1 + margin] x [y - margin, y + 1 +
/// margin]`, with the projection and exact test of [`conservative_texel_sets`].
///
/// Intended for judging extra GPU entries. Returns `false` for a triangle index out
/// of range, and `true` for a triangle that cannot be projected (a vertex with
/// clip `w <= 0` or a non-finite projection), whose footprint is unbounded.
pub fn overlaps_texel_with_margin(
    scene: &RefScene,
    light_view_proj: DMat4,
    n: u32,
    tri: u32,
    x: u32,
    y: u32,
    margin: f64,
) -> bool {
    let Some(vertices) = scene.triangles().get(tri as usize) else {
        return false;
    };
    let Some(q) = Projection::new(light_view_proj, n).triangle(vertices) else {
        return true;
    };
    let lo = DVec2::new(f64::from(x) - margin, f64::from(y) - margin);
    let hi = DVec2::new(f64::from(x) + 1.0 + margin, f64::from(y) + 1.0 + margin);
    overlaps_square(&q, lo, hi)
}

/// Per-chunk output of the parallel binning pass.
#[derive(Default)]
struct ChunkResult {
    /// `(texel index, triangle)` in ascending triangle order.
    pairs: Vec<(usize, u32)>,
    required: Vec<bool>,
    light_degenerate: Vec<bool>,
}

/// World to continuous texel coordinates.
struct Projection {
    matrix: DMat4,
    n: f64,
}

impl Projection {
    fn new(light_view_proj: DMat4, n: u32) -> Self {
        Self {
            matrix: light_view_proj,
            n: f64::from(n),
        }
    }

    fn point(&self, p: DVec3) -> Option<DVec2> {
        let clip = self.matrix * p.extend(1.0);
        if clip.w <= 0.0 || clip.w.is_nan() {
            return None;
        }
        let texel = (clip.truncate().truncate() / clip.w * 0.5 + 0.5) * self.n;
        texel.is_finite().then_some(texel)
    }

    fn triangle(&self, tri: &[DVec3; 3]) -> Option<[DVec2; 3]> {
        Some([
            self.point(tri[0])?,
            self.point(tri[1])?,
            self.point(tri[2])?,
        ])
    }
}

/// Calls `visit(y * n + x)` for every texel of the `n x n` grid whose closed square
/// overlaps the closed triangle `q`, in ascending texel order.
fn for_each_overlapped_texel(q: &[DVec2; 3], n: u32, mut visit: impl FnMut(usize)) {
    let min = q[0].min(q[1]).min(q[2]);
    let max = q[0].max(q[1]).max(q[2]);
    // One texel of slack below; the exact test below decides.
    let last = f64::from(n) - 1.0;
    let range = |lo: f64, hi: f64| {
        let first = (lo.floor() - 1.0).max(0.0);
        let end = hi.floor().min(last);
        (first <= end).then_some((first as u32, end as u32))
    };
    let (Some((x0, x1)), Some((y0, y1))) = (range(min.x, max.x), range(min.y, max.y)) else {
        return;
    };
    for y in y0..=y1 {
        for x in x0..=x1 {
            let lo = DVec2::new(f64::from(x), f64::from(y));
            if overlaps_square(q, lo, lo + DVec2::ONE) {
                visit(y as usize * n as usize + x as usize);
            }
        }
    }
}

/// Exact overlap of the closed triangle `q` (possibly degenerate) and the closed
/// axis-aligned square `[lo, hi]`.
///
/// Two disjoint convex polygons are separated by the supporting line of an edge of
/// one of them. Square edges give the bounding-box test; for each triangle edge the
/// square must lie strictly on the side opposite the third vertex (either side if
/// the triangle is flat on that line).
fn overlaps_square(q: &[DVec2; 3], lo: DVec2, hi: DVec2) -> bool {
    let min = q[0].min(q[1]).min(q[2]);
    let max = q[0].max(q[1]).max(q[2]);
    if max.x < lo.x || min.x > hi.x || max.y < lo.y || min.y > hi.y {
        return false;
    }
    let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    for (a, b, c) in [(q[0], q[1], q[2]), (q[1], q[2], q[0]), (q[2], q[0], q[1])] {
        if a == b {
            continue;
        }
        let third = orient2d(a, b, c);
        let sides = corners.map(|k| orient2d(a, b, k));
        let all_positive = sides.iter().all(|s| *s > 0.0);
        let all_negative = sides.iter().all(|s| *s < 0.0);
        let separated = if third > 0.0 {
            all_negative
        } else if third < 0.0 {
            all_positive
        } else {
            all_positive || all_negative
        };
        if separated {
            return false;
        }
    }
    true
}

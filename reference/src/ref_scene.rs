//! The `f64` copy of a scene and its bounding volume hierarchy.

use glam::DVec3;

use crate::exact::has_zero_area;
use crate::intersect_watertight;

/// Largest number of triangles in a leaf that the SAH may choose to keep unsplit.
const MAX_LEAF: usize = 8;
/// Number of centroid bins per axis for the binned SAH.
const BINS: usize = 16;
/// Relative padding of node bounds that absorbs rounding in the slab test, so that
/// traversal never rejects a box the exact ray touches.
const RELATIVE_PAD: f64 = 1e-12;

/// Axis-aligned box in `f64`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bounds {
    min: DVec3,
    max: DVec3,
}

impl Bounds {
    const EMPTY: Self = Self {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };

    fn grow(&mut self, other: &Bounds) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    fn grow_point(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Half the surface area (the SAH only needs ratios); 0 for empty boxes.
    fn half_area(&self) -> f64 {
        let d = (self.max - self.min).max(DVec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A BVH node: a leaf when `count > 0` (triangles `order[first..first + count]`),
/// otherwise an interior node whose children are `first` and `first + 1`.
#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Bounds,
    first: u32,
    count: u32,
}

/// A ray prepared for repeated slab tests.
struct SlabRay {
    origin: DVec3,
    dir: DVec3,
    inv_dir: DVec3,
}

impl SlabRay {
    fn new(origin: DVec3, dir: DVec3) -> Self {
        Self {
            origin,
            dir,
            inv_dir: dir.recip(),
        }
    }

    /// Entry parameter of the ray into `bounds` grown by `pad`, clipped to
    /// `[t_min, t_max]`, or `None` when the clipped ray misses the box.
    fn enter(&self, bounds: &Bounds, pad: f64, t_min: f64, t_max: f64) -> Option<f64> {
        let mut near = t_min;
        let mut far = t_max;
        for axis in 0..3 {
            let lo = bounds.min[axis] - pad;
            let hi = bounds.max[axis] + pad;
            let o = self.origin[axis];
            if self.dir[axis] == 0.0 {
                if o < lo || o > hi {
                    return None;
                }
                continue;
            }
            let ta = (lo - o) * self.inv_dir[axis];
            let tb = (hi - o) * self.inv_dir[axis];
            near = near.max(ta.min(tb));
            far = far.min(ta.max(tb));
            if near > far {
                return None;
            }
        }
        Some(near)
    }
}

/// Triangles of a [`scene::Scene`] promoted to `f64`, with a bounding volume
/// hierarchy (binned surface-area heuristic) over the usable ones.
///
/// A triangle is *usable* when its vertices are finite and it has non-zero area in
/// 3D (decided exactly from the promoted coordinates). Unusable (degenerate)
/// triangles are kept for indexing but are absent from the hierarchy: they never
/// block light and never make anything ambiguous.
#[derive(Debug, Clone)]
pub struct RefScene {
    triangles: Vec<[DVec3; 3]>,
    usable: Vec<bool>,
    /// Per triangle: whether it blocks shadow rays (every triangle receives).
    casts: Vec<bool>,
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// Padding that absorbs slab-test rounding for the scene's coordinate range.
    pad: f64,
}

impl RefScene {
    /// Promotes `scene` to `f64` and builds the hierarchy.
    ///
    /// Triangle `i` is `scene.indices[3 * i..3 * i + 3]` (a trailing incomplete
    /// triple is ignored). An index outside `scene.positions` yields a NaN vertex,
    /// which makes its triangle unusable instead of panicking.
    pub fn new(scene: &scene::Scene) -> Self {
        let vertex = |index: u32| {
            usize::try_from(index)
                .ok()
                .and_then(|i| scene.positions.get(i))
                .map_or(DVec3::NAN, |p| p.as_dvec3())
        };
        let triangles: Vec<[DVec3; 3]> = scene
            .indices
            .chunks_exact(3)
            .map(|ids| [vertex(ids[0]), vertex(ids[1]), vertex(ids[2])])
            .collect();
        let usable: Vec<bool> = triangles.iter().map(is_usable).collect();
        let casts = vec![true; triangles.len()];
        let mut result = Self {
            triangles,
            usable,
            casts,
            nodes: Vec::new(),
            order: Vec::new(),
            pad: 0.0,
        };
        result.build();
        result
    }

    /// [`RefScene::new`], where only the objects of `scene` marked in `casters` (one flag per object, in
    /// the order of `scene.objects`) block shadow rays: every triangle is still seen by the camera and
    /// receives shadows, as an object that an engine leaves out of the shadow casters.
    ///
    /// # Panics
    ///
    /// If `casters` does not hold one flag per object, or an object's triangles lie beyond the scene's.
    pub fn with_casters(scene: &scene::Scene, casters: &[bool]) -> Self {
        assert_eq!(
            casters.len(),
            scene.objects.len(),
            "one shadow-caster flag per object"
        );
        let mut result = Self::new(scene);
        result.casts = vec![false; result.triangles.len()];
        for (object, _) in scene.objects.iter().zip(casters).filter(|(_, &c)| c) {
            let first = object.first_triangle as usize;
            result.casts[first..first + object.triangle_count as usize].fill(true);
        }
        result
    }

    /// Whether triangle `i` blocks shadow rays (false for an object given as a receiver only).
    pub(crate) fn casts(&self, i: usize) -> bool {
        self.casts.get(i).copied().unwrap_or(false)
    }

    /// Number of triangles (usable or not).
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Vertices of triangle `i` in `f64`.
    ///
    /// # Panics
    ///
    /// Panics if `i >= self.triangle_count()`, like slice indexing.
    pub fn triangle(&self, i: usize) -> [DVec3; 3] {
        self.triangles[i]
    }

    /// All triangles, indexed like [`RefScene::triangle`].
    pub(crate) fn triangles(&self) -> &[[DVec3; 3]] {
        &self.triangles
    }

    /// The nearest usable triangle that the ray `origin + t * dir` crosses at `t > 0`, as `(t, triangle
    /// index)`, by [`intersect_watertight`] over the hierarchy (two-sided; `dir` need not be a unit
    /// vector, `t` is in units of it). `None` when the ray hits nothing.
    pub fn nearest_hit(&self, origin: DVec3, dir: DVec3) -> Option<(f64, usize)> {
        let mut best = None;
        self.traverse(origin, dir, 0.0, f64::INFINITY, 0.0, |i, t_max| {
            if let Some((t, _)) = intersect_watertight(origin, dir, &self.triangles[i]) {
                if t > 0.0 && t < *t_max {
                    *t_max = t;
                    best = Some((t, i));
                }
            }
        });
        best
    }

    /// Whether triangle `i` is finite and has non-zero area in 3D.
    pub(crate) fn is_usable(&self, i: usize) -> bool {
        self.usable.get(i).copied().unwrap_or(false)
    }

    /// Bounds of all usable triangles, or `None` for a scene without any.
    pub(crate) fn root_bounds(&self) -> Option<(DVec3, DVec3)> {
        self.nodes
            .first()
            .map(|node| (node.bounds.min, node.bounds.max))
    }

    fn build(&mut self) {
        let prims: Vec<(Bounds, DVec3)> = self
            .triangles
            .iter()
            .map(|tri| {
                let mut b = Bounds::EMPTY;
                tri.iter().for_each(|p| b.grow_point(*p));
                (b, (b.min + b.max) * 0.5)
            })
            .collect();
        let mut order: Vec<u32> = (0..self.triangles.len())
            .filter(|&i| self.usable[i])
            .filter_map(|i| u32::try_from(i).ok())
            .collect();
        if order.is_empty() {
            return;
        }
        let mut nodes = vec![Node {
            bounds: Bounds::EMPTY,
            first: 0,
            count: 0,
        }];
        // (node index, range start, range end) still to be built.
        let mut stack = vec![(0usize, 0usize, order.len())];
        while let Some((node, start, end)) = stack.pop() {
            let range = &mut order[start..end];
            let mut bounds = Bounds::EMPTY;
            let mut centroids = Bounds::EMPTY;
            for &i in range.iter() {
                let (b, c) = &prims[i as usize];
                bounds.grow(b);
                centroids.grow_point(*c);
            }
            nodes[node].bounds = bounds;
            let split = split_range(range, &prims, &centroids);
            match split {
                Some(mid) => {
                    let left = nodes.len();
                    let placeholder = Node {
                        bounds: Bounds::EMPTY,
                        first: 0,
                        count: 0,
                    };
                    nodes.push(placeholder);
                    nodes.push(placeholder);
                    nodes[node].first = index_u32(left);
                    stack.push((left, start, start + mid));
                    stack.push((left + 1, start + mid, end));
                }
                None => {
                    nodes[node].first = index_u32(start);
                    nodes[node].count = index_u32(end - start);
                }
            }
        }
        let root = nodes[0].bounds;
        let scale = root.min.abs().max(root.max.abs()).max_element();
        self.pad = RELATIVE_PAD * scale;
        self.nodes = nodes;
        self.order = order;
    }

    /// Whether some usable triangle satisfies `triangle_may_meet`, descending only
    /// into nodes whose bounds `node_may_meet(min, max)` accepts (a node that it
    /// rejects must contain no triangle that `triangle_may_meet` would accept, so a
    /// caller's region test only ever prunes, never decides).
    ///
    /// Stops at the first triangle accepted. `min` and `max` are the exact bounds of
    /// the node's triangles' vertices (no padding: they are minima and maxima of the
    /// promoted coordinates, not rounded results).
    pub(crate) fn any_triangle(
        &self,
        mut node_may_meet: impl FnMut(DVec3, DVec3) -> bool,
        mut triangle_may_meet: impl FnMut(usize) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let mut stack: Vec<usize> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(index) = stack.pop() {
            let node = self.nodes[index];
            if !node_may_meet(node.bounds.min, node.bounds.max) {
                continue;
            }
            let first = node.first as usize;
            if node.count > 0 {
                let leaf = &self.order[first..first + node.count as usize];
                if leaf.iter().any(|&tri| triangle_may_meet(tri as usize)) {
                    return true;
                }
            } else {
                stack.push(first + 1);
                stack.push(first);
            }
        }
        false
    }

    /// Visits every usable triangle whose bounding box, grown by `expand`, the ray
    /// `origin + t * dir` reaches for `t` in `[t_min, t_max]`, nearest boxes first.
    ///
    /// `visit(triangle, &mut t_max)` may lower `t_max` to prune farther boxes (set it
    /// to `-inf` to stop). Box tests are conservative: rounding never drops a box.
    pub(crate) fn traverse(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_min: f64,
        t_max: f64,
        expand: f64,
        mut visit: impl FnMut(usize, &mut f64),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let ray = SlabRay::new(origin, dir);
        let pad = expand + self.pad + RELATIVE_PAD * origin.abs().max_element();
        let mut t_max = t_max;
        let mut stack: Vec<(usize, f64)> = Vec::with_capacity(64);
        if let Some(t) = ray.enter(&self.nodes[0].bounds, pad, t_min, t_max) {
            stack.push((0, t));
        }
        while let Some((index, entry)) = stack.pop() {
            if entry > t_max {
                continue;
            }
            let node = self.nodes[index];
            let first = node.first as usize;
            if node.count > 0 {
                for &tri in &self.order[first..first + node.count as usize] {
                    visit(tri as usize, &mut t_max);
                }
                continue;
            }
            let hits = [first, first + 1].map(|child| {
                ray.enter(&self.nodes[child].bounds, pad, t_min, t_max)
                    .map(|t| (child, t))
            });
            match hits {
                [Some(a), Some(b)] => {
                    let (near, far) = if a.1 <= b.1 { (a, b) } else { (b, a) };
                    stack.push(far);
                    stack.push(near);
                }
                [Some(only), None] | [None, Some(only)] => stack.push(only),
                [None, None] => {}
            }
        }
    }
}

/// Converts an index that is known to fit (triangle counts are bounded by `u32`
/// indices in the hierarchy) to `u32`, saturating otherwise.
fn index_u32(i: usize) -> u32 {
    u32::try_from(i).unwrap_or(u32::MAX)
}

/// Finite vertices and non-zero area.
fn is_usable(tri: &[DVec3; 3]) -> bool {
    tri.iter().all(|p| p.is_finite()) && !has_zero_area(tri)
}

/// Chooses a split of `range` (reordering it) by the binned surface-area heuristic
/// and returns the size of the left part, or `None` to make a leaf.
fn split_range(range: &mut [u32], prims: &[(Bounds, DVec3)], centroids: &Bounds) -> Option<usize> {
    let count = range.len();
    if count <= 2 {
        return None;
    }
    let extent = centroids.max - centroids.min;
    let mut best: Option<(f64, usize, usize)> = None; // (cost, axis, bins left of split)
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f64 / extent[axis];
        let bin_of = |c: DVec3| (((c[axis] - centroids.min[axis]) * scale) as usize).min(BINS - 1);
        let mut bins = [(Bounds::EMPTY, 0usize); BINS];
        for &i in range.iter() {
            let (b, c) = &prims[i as usize];
            let bin = &mut bins[bin_of(*c)];
            bin.0.grow(b);
            bin.1 += 1;
        }
        // Sweep from the right to get the cost of every right part.
        let mut right_area = [0.0; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Bounds::EMPTY;
        let mut n = 0;
        for k in (1..BINS).rev() {
            acc.grow(&bins[k].0);
            n += bins[k].1;
            right_area[k] = acc.half_area();
            right_count[k] = n;
        }
        let mut acc = Bounds::EMPTY;
        let mut n = 0;
        for k in 1..BINS {
            acc.grow(&bins[k - 1].0);
            n += bins[k - 1].1;
            if n == 0 || right_count[k] == 0 {
                continue;
            }
            let cost = acc.half_area() * n as f64 + right_area[k] * right_count[k] as f64;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, k));
            }
        }
    }
    let mut node_bounds = Bounds::EMPTY;
    range
        .iter()
        .for_each(|&i| node_bounds.grow(&prims[i as usize].0));
    let leaf_cost = node_bounds.half_area() * count as f64;
    match best {
        Some((cost, axis, split_bin)) if count > MAX_LEAF || cost < leaf_cost => {
            let scale = BINS as f64 / extent[axis];
            let goes_left = |i: &u32| {
                let c = prims[*i as usize].1[axis];
                (((c - centroids.min[axis]) * scale) as usize).min(BINS - 1) < split_bin
            };
            Some(partition(range, goes_left))
        }
        Some(_) => None,
        // All centroids coincide: split in the middle if the leaf would be large.
        None => (count > MAX_LEAF).then_some(count / 2),
    }
}

/// Reorders `items` so that those satisfying `pred` come first; returns their count.
fn partition(items: &mut [u32], pred: impl Fn(&u32) -> bool) -> usize {
    let mut left = 0;
    for k in 0..items.len() {
        if pred(&items[k]) {
            items.swap(left, k);
            left += 1;
        }
    }
    left
}

// The area trace (area_trace.comp: directional lights; area_trace_local.comp: spot and point lights).
// Exact soft shadows of a sized light: per pixel, which of the light's N samples (a directional light's
// sample directions, the same for every pixel; a spot or point light's points on its emitter's disc facing
// the pixel; area_samples.glsl) it reaches, tested against every triangle of the pixel's texel list in a
// primitive map whose footprints are widened by their penumbra (map_store.glsl).
// The visibility is the visible fraction, k / N: no noise, no filter, the same output for the same input.
//
// The ray test is the triple-product form of the watertight test, for all N directions from the pixel's
// one ray origin o at once. With a, b, c the triangle's vertices relative to o and D = det(a, b, c), a
// direction w reaches the triangle (at a positive distance) iff w = alpha a + beta b + gamma c with alpha,
// beta, gamma >= 0, i.e. iff the three edge functions (b x c).w = alpha D, (c x a).w = beta D and
// (a x b).w = gamma D all have the sign of D (Cramer's rule). Each edge's normal is computed from its two
// vertices in an order both triangles of the edge choose alike, so a shared edge gets exactly opposite
// normals in its two triangles, and a direction exactly through the edge counts as blocked by both (>= 0):
// no leak through a closed mesh. D = 0 within its rounding (o in the triangle's plane, or a degenerate
// triangle) blocks nothing.
// Each edge function is linear in w, and every sample lies within `spread` of the centre direction C, so
// E(w) lies within |n| spread of E(C): a triangle is rejected for every sample, or taken as blocking every
// sample, with one evaluation, exactly as the per-sample evaluation would decide (the margin covers the
// rounding of both). For a triangle across the penumbra's edge, the exact edge table of Schwarz and
// Stamminger's bitmask soft shadows (passes::area::AreaEdgeTable) gives each edge's kept samples, certain
// beyond every rounding; only the samples still open that a table cell is uncertain about are tested one by
// one. Every sample is decided as the per-sample test alone decides it.
// A sample towards which the receiver's normal does not face is blocked, as the reference has it.
// Where the map holds no complete list for the pixel (trace_route.glsl), it walks the BVH over the prim
// buffer (bvh_traverse.glsl) with the bundle of its segments or rays, and tests each triangle met exactly as
// a list entry: the same answer, bit for bit. A wide bundle that meets many triangles gives up past a
// budget, and each of its open samples walks its own segment or ray (walk_sample): again the same answer.
// Either way a pixel stops once every sample is blocked. Where more than three quarters of a tile's pixels
// gave up their bundle in the last frame having decided less than half their samples, the tile's wide pixels
// skip their bundles and walk their samples at once for a few frames (the tile history): the cost is then
// the samples' walks alone; the answer is the same.
#include "triangle.glsl"
#include "ray_trace_constants.glsl"
#include "map_state.glsl"
#include "area_samples.glsl"
#include "bvh.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Constants { RayTraceConstants k; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2) uniform sampler2D normal_tex;
layout(set = 0, binding = 3) buffer State { MapState ms; };
layout(set = 0, binding = 4) readonly buffer PixelTexels { uint pixel_texel[]; };
layout(set = 0, binding = 5) readonly buffer Offsets { uint offsets[]; };
#include "map_offsets.glsl"
layout(set = 0, binding = 6) readonly buffer Entries { uint entries[]; };
layout(set = 0, binding = 7) readonly buffer Prims { Triangle tris[]; };
#include "output_format.glsl"
layout(set = 0, binding = 8, OUTPUT_FORMAT) uniform writeonly image2D visibility;
layout(set = 0, binding = 9) uniform Samples { AreaSamples samples; };
layout(set = 0, binding = 10) readonly buffer EdgeTable { uvec4 edge_table[]; };
// The linear BVH, which the bundles walk (passes::bvh).
layout(set = 0, binding = 11) readonly buffer Bvh { BvhNode bvh_nodes[]; };
// The samples of every band of columns and rows of a grid over the samples' plane
// (passes::area::SampleBands): a directional light's table, then a local light's.
layout(set = 0, binding = 12) readonly buffer SampleBands { uvec4 sample_bands[]; };
// The rays' BVH, which each sample's own walk takes (walk_sample).
layout(set = 0, binding = 13) readonly buffer RayBvh { BvhNode ray_nodes[]; };
// Per 8x8 tile of pixels (a workgroup): how many of its bundles gave up having decided little in the last
// frame, and the frames for which it still skips them (passes::ray_trace::TILE_SKIP_FRAMES).
layout(set = 0, binding = 14) coherent buffer TileHistory { uint tile_history[]; };
#include "shadow_ray.glsl"
#include "trace_route.glsl"
#define BVH_MASKED
#include "bvh_traverse.glsl"

// The workgroup's copy of the sample directions: the trace reads them at indices that differ from pixel to
// pixel, which a uniform buffer serves one index at a time.
shared vec3 sample_dirs[128];

vec3 origin;
// A spot or point light (the emitter's disc), else a directional light (a cone): the includer's
// LOCAL_LIGHT, so that each variant holds the code of its own lights only.
const bool local = LOCAL_LIGHT != 0;
// Whether a wide bundle's open samples may walk one by one (walk_sample): the includer's SAMPLE_WALKS, 0 for
// the variant of the directional lights whose bundle is never wide (their angular bound at most
// WIDE_BUNDLE), which leaves the per-sample walk's code and registers out.
#ifndef SAMPLE_WALKS
#define SAMPLE_WALKS 1
#endif
// The light's edge table's first cell: a directional light's, then a local light's.
const uint table_base = local ? EDGE_ANGLES * EDGE_OFFSETS : 0u;
uint sample_count;
uvec4 all_samples;  // bit i of word i / 32: sample i exists
uvec4 blocked;      // bit i: sample i is blocked

// Relative margin of the one-evaluation decisions: far above the f32 rounding of the edge functions.
const float DECIDE_MARGIN = 1e-5;

// rp x rq for the edge from world vertex p to q (rp, rq: relative to the ray origin), computed from the
// endpoint nearer the origin (ties: the first in world order) as r_near x (far - near), with the edge's own
// world vector: it errs by a few ulps of |r_near| |q - p|, at most about twice |rp| |rq|, where rp x rq
// errs by a few ulps of |rp| |rq| (far more than the value for a small triangle far away). Both triangles
// of an edge choose the same endpoint, so the edge from q to p gives exactly the opposite vector.
vec3 edge_normal(vec3 p, vec3 q, vec3 rp, vec3 rq) {
    precise float lp = dot(rp, rp);
    precise float lq = dot(rq, rq);
    bool q_first = p.x > q.x || (p.x == q.x && (p.y > q.y || (p.y == q.y && p.z > q.z)));
    bool from_q = lq < lp || (lq == lp && q_first);
    vec3 u = from_q ? rq : rp;
    precise vec3 v = from_q ? p - q : q - p;
    precise vec3 n = vec3(u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x);
    return from_q ? -n : n;
}

// The edge table's samples for the line a x + b y + c >= 0 (`line`) in the samples' plane (a directional
// light's gnomonic plane, a local light's unit disc): `inside`, those every line of its cell keeps; `maybe`,
// those it keeps or is uncertain about (passes::area::AreaEdgeTable; the light's table starts at
// `table_base`). A line without a direction (a = b = 0 within rounding: for a directional light, an edge
// plane that holds C's axis) leaves every sample uncertain.
void line_masks(vec3 line, out uvec4 inside, out uvec4 maybe) {
    float a = line.x, b = line.y, c = line.z;
    float l = sqrt(a * a + b * b);
    if (!(l > 0.0)) {
        inside = uvec4(0u);
        maybe = all_samples;
        return;
    }
    // The diamond angle of (a, b), in [0, 4): monotonic in the angle, without atan's loose precision.
    float t = b >= 0.0 ? (a >= 0.0 ? b / (a + b) : 1.0 - a / (-a + b))
                       : (a < 0.0 ? 2.0 - b / (-a - b) : 3.0 + a / (a - b));
    uint angle = min(uint(t * (float(EDGE_ANGLES) / 4.0)), EDGE_ANGLES - 1u);
    float d = -c / l;
    uint offset = uint(clamp(floor((d + samples.axis_u.w) * samples.axis_v.w), 0.0, float(EDGE_OFFSETS - 1u)));
    uint cell = table_base + angle * EDGE_OFFSETS + offset;
    if (sample_count <= 64u) {
        uvec4 words = edge_table[cell];     // up to 64 samples: inside's and uncertain's two words
        inside = uvec4(words.xy, 0u, 0u);
        maybe = inside | uvec4(words.zw, 0u, 0u);
    } else {
        inside = edge_table[2u * cell];
        maybe = inside | edge_table[2u * cell + 1u];
    }
}

// The edge table's samples for a directional light's edge plane of normal n (oriented inwards): the line of
// the plane in the light's gnomonic frame.
void edge_masks(vec3 n, out uvec4 inside, out uvec4 maybe) {
    line_masks(vec3(dot(n, samples.axis_u.xyz), dot(n, samples.axis_v.xyz), dot(n, samples.center.xyz)),
               inside, maybe);
}

// A spot or point light: the samples are the points s = P + u U + v V of the emitter's disc through its
// centre P facing the ray origin (U, V: the disc's axes scaled by its radius; (u, v): the unit-disc offsets
// in sample_dirs[i].xy). With w = s - o = C + u U + v V (C = P - o), the segment from o to s crosses the
// triangle iff w reaches it (the three edge functions, as for a direction) and s lies beyond its plane:
// the crossing's parameter is 1 / (alpha + beta + gamma), below 1 iff N.(s - p0) has the sign of D (N the
// triangle's normal, D = N.(p0 - o)). Each of the four is affine in (u, v), so each is evaluated as
// f0 + u fu + v fv, a shared edge's exactly negated; over the unit disc it lies within |(fu, fv)| of f0,
// which rejects the triangle or takes it as blocking every sample with one evaluation, exactly as the
// per-sample evaluation decides (the margin covers the rounding of both).
vec3 disc_c, disc_u, disc_v;

vec3 affine(vec3 n) {
    return vec3(dot(n, disc_c), dot(n, disc_u), dot(n, disc_v));
}

// Whether f0 + u fu + v fv is negative (`sign` -1) or positive (+1) over the whole unit disc, beyond the
// rounding of evaluating it at any sample.
bool disc_sign(vec3 f, float sign) {
    float spread = length(f.yz) * (1.0 + DECIDE_MARGIN) + DECIDE_MARGIN * (abs(f.x) + abs(f.y) + abs(f.z));
    return sign * f.x > spread;
}

// What a triangle's one evaluation over all samples decided.
const uint MISSES_ALL = 0u;
const uint BLOCKS_ALL = 1u;
const uint UNDECIDED = 2u;

// The lines of the triangle quick() looked at last: a directional light's three inward edge normals (a, b,
// c); a local light's four affine conditions (a, b, c, and p, beyond the plane) as (f0, fu, fv).
vec3 line_a, line_b, line_c, line_p;

// The triangle's lines, and whether it misses every sample, blocks every sample or needs resolve().
uint quick(uint index) {
    if (index >= uint(tris.length())) {
        return MISSES_ALL;
    }
    vec3 p0 = tris[index].v[0].xyz, p1 = tris[index].v[1].xyz, p2 = tris[index].v[2].xyz;
    precise vec3 a = p0 - origin;
    precise vec3 b = p1 - origin;
    precise vec3 c = p2 - origin;
    vec3 na = edge_normal(p1, p2, b, c);
    vec3 nb = edge_normal(p2, p0, c, a);
    vec3 nc = edge_normal(p0, p1, a, b);
    // D = a.(b x c) = N.a, with N = (p1 - p0) x (p2 - p0) the normal of the triangle's own edges, taken as
    // the cross product of its two shorter edges: N.a errs by a few ulps of |N| |a|, where a.na errs by a
    // few ulps of |a| |b| |c|, which for a small triangle far away or a long sliver can pass D itself when
    // the origin lies near the triangle's plane (and the two longer edges of a sliver, nearly parallel,
    // give N far less precisely). A wrong sign of D would turn every test of the triangle around.
    // A plane within that rounding of the origin counts as D = 0: it blocks nothing (any segment it could
    // block runs within the reference's tolerance of the plane, which calls such a sample ambiguous).
    precise vec3 e0 = p1 - p0;
    precise vec3 e1 = p2 - p1;
    precise vec3 e2 = p0 - p2;
    vec3 lengths = vec3(dot(e0, e0), dot(e1, e1), dot(e2, e2));
    precise vec3 face = lengths.x >= max(lengths.y, lengths.z) ? cross(e1, e2)
                      : lengths.y >= lengths.z                ? cross(e2, e0)
                                                              : cross(e0, e1);
    precise float det = dot(face, a);
    vec3 shorter = lengths.x >= max(lengths.y, lengths.z) ? lengths.yzx
                 : lengths.y >= lengths.z                ? lengths.zxy
                                                         : lengths.xyz;
    if (!(abs(det) > 2e-6 * sqrt(shorter.x * shorter.y * dot(a, a)))) {
        return MISSES_ALL;
    }
    float orient = det < 0.0 ? -1.0 : 1.0;
    if (local) {
        precise vec3 normal = orient * face;
        line_a = orient * affine(na);
        line_b = orient * affine(nb);
        line_c = orient * affine(nc);
        line_p = vec3(dot(normal, k.light_pos.xyz - p0), dot(normal, disc_u), dot(normal, disc_v));
        if (disc_sign(line_a, -1.0) || disc_sign(line_b, -1.0) || disc_sign(line_c, -1.0)
            || disc_sign(line_p, -1.0)) {
            return MISSES_ALL;
        }
        if (disc_sign(line_a, 1.0) && disc_sign(line_b, 1.0) && disc_sign(line_c, 1.0)
            && disc_sign(line_p, 1.0)) {
            return BLOCKS_ALL;
        }
        return UNDECIDED;
    }
    line_a = orient * na;
    line_b = orient * nb;
    line_c = orient * nc;
    vec3 centre = samples.center.xyz;
    vec3 at_centre = vec3(dot(line_a, centre), dot(line_b, centre), dot(line_c, centre));
    vec3 span = vec3(length(line_a), length(line_b), length(line_c)) * (samples.center.w + DECIDE_MARGIN);
    if (any(lessThan(at_centre + span, vec3(0.0)))) {
        return MISSES_ALL;
    }
    if (all(greaterThan(at_centre - span, vec3(0.0)))) {
        return BLOCKS_ALL;
    }
    return UNDECIDED;
}

// Whether the sample of offsets (a local light) or direction `w` meets the triangle quick() looked at
// last: the per-sample test every decision of the trace agrees with.
bool sample_hit(vec3 w) {
    return local ? line_a.x + w.x * line_a.y + w.y * line_a.z >= 0.0
                   && line_b.x + w.x * line_b.y + w.y * line_b.z >= 0.0
                   && line_c.x + w.x * line_c.y + w.y * line_c.z >= 0.0
                   && line_p.x + w.x * line_p.y + w.y * line_p.z > 0.0
                 : dot(line_a, w) >= 0.0 && dot(line_b, w) >= 0.0 && dot(line_c, w) >= 0.0;
}

// Decides the samples still open against the triangle quick() left undecided: the edge table decides most
// samples of its lines at once (a local light's four lines in the unit disc), and the samples still open
// that it is uncertain about are tested one by one (of `reach`, those whose segment or ray may meet the
// triangle's box; every sample on the lists' path).
void resolve(uvec4 reach) {
    uvec4 in_a, in_b, in_c, in_p, maybe_a, maybe_b, maybe_c, maybe_p;
    if (local) {
        line_masks(line_a.yzx, in_a, maybe_a);
        line_masks(line_b.yzx, in_b, maybe_b);
        line_masks(line_c.yzx, in_c, maybe_c);
        line_masks(line_p.yzx, in_p, maybe_p);
    } else {
        edge_masks(line_a, in_a, maybe_a);
        edge_masks(line_b, in_b, maybe_b);
        edge_masks(line_c, in_c, maybe_c);
        in_p = all_samples;
        maybe_p = all_samples;
    }
    uvec4 hidden = in_a & in_b & in_c & in_p & all_samples;
    uvec4 open = maybe_a & maybe_b & maybe_c & maybe_p & all_samples & reach & ~hidden & ~blocked;
    blocked |= hidden;
    for (uint word = 0u; word < 4u; ++word) {
        uint bits = open[word];
        while (bits != 0u) {
            uint bit = findLSB(bits);
            bits &= bits - 1u;
            if (sample_hit(sample_dirs[word * 32u + bit])) {
                blocked[word] |= 1u << bit;
            }
        }
    }
}

void consider(uint index, uvec4 reach) {
    uint q = quick(index);
    if (q == BLOCKS_ALL) {
        blocked = all_samples;
    } else if (q == UNDECIDED) {
        resolve(reach);
    }
}

bool all_blocked() {
    return blocked == all_samples;
}

// The samples still open.
uint open_samples() {
    uvec4 open = all_samples & ~blocked;
    return bitCount(open.x) + bitCount(open.y) + bitCount(open.z) + bitCount(open.w);
}

void bvh_visit(uint index, uvec4 reach) {
    consider(index, reach);
}

bool bvh_done() {
    return all_blocked();
}

#if SAMPLE_WALKS
// Whether the workgroup's tile skips its wide bundles this frame (read_tile_history).
shared bool tile_skip;
// Per pixel of the workgroup, the samples open when its bundle began a walk with a budget (in shared
// memory rather than a register held through the walk, which measured slower).
shared uint tile_open[64];

// Counts a pixel whose tile skipped its bundle (once per subgroup of such pixels).
void count_bundle_skip() {
    uint count = subgroupAdd(1u);
    if (subgroupElect()) {
        atomicAdd(ms.walks.w, count);
    }
}

// Frames a tile skips its wide bundles once more than TILE_GIVE_UPS of its 64 pixels' bundles gave up having
// decided less than half their samples (passes::ray_trace::{TILE_SKIP_FRAMES, TILE_GIVE_UPS}); after them it
// tries them again.
const uint TILE_SKIP_FRAMES = 16u;
const uint TILE_GIVE_UPS = 48u;
// The frames a tile skips are TILE_SKIP_FRAMES less 0 to TILE_SKIP_STAGGER, by tile, so that the tiles of
// a light that skip from the same frame do not all try their bundles again in one frame.
const uint TILE_SKIP_STAGGER = 7u;
const uint TILE_FRAMES_SHIFT = 16u;
uint tile;

// Whether the workgroup's tile skips its wide bundles this frame, from its history (the last frame's count
// of such bundles in the low half, the frames left to skip in the high half), which it then resets for this
// frame's count.
bool read_tile_history() {
    if (tile >= uint(tile_history.length())) {
        return false;
    }
    uint record = tile_history[tile];
    uint frames = record >> TILE_FRAMES_SHIFT;
    if (frames == 0u && (record & 0xFFFFu) > TILE_GIVE_UPS) {
        frames = TILE_SKIP_FRAMES - (tile * 0x9E3779B1u >> 29u) % (TILE_SKIP_STAGGER + 1u);
    }
    uint next = frames > 0u ? (frames - 1u) << TILE_FRAMES_SHIFT : 0u;
    if (next != record) {
        tile_history[tile] = next;
        memoryBarrierBuffer();
    }
    return frames > 0u;
}

// Counts, in its tile's history, a bundle that gave up having decided less than half its samples (once per
// subgroup: a subgroup's pixels lie in one tile).
void count_tile_give_up() {
    uint count = subgroupAdd(2u * open_samples() > tile_open[gl_LocalInvocationIndex] ? 1u : 0u);
    if (subgroupElect() && count > 0u && tile < uint(tile_history.length())) {
        atomicAdd(tile_history[tile], count);
    }
}
#endif

// Whether the workgroup's tile skips its wide bundles this frame (never in the variant without the samples'
// own walks).
bool tile_skips() {
#if SAMPLE_WALKS
    return tile_skip;
#else
    return false;
#endif
}

#if SAMPLE_WALKS
// One sample's segment or ray for walk_sample: per axis, the reciprocal of its direction and the origin's
// coordinate times it, the growth of every box in units of t, and its end.
vec3 segment_inv, segment_origin_inv, segment_grow;
float segment_end;
// The rounding scale of the sample's edge functions over a triangle's two vertices (sample_misses).
float segment_scale;
// The pixel's part of every sample's growth, and the distance from the origin to the farthest corner of
// the hierarchy's root box (set_segment_origin).
float segment_grow_base, segment_far;

// Sets what every sample's segment of the pixel shares: 1e-5 of the largest coordinate of the hierarchy's
// root box and the origin, and the distance to the root box's farthest corner.
void set_segment_origin() {
    vec3 root_lo = min(ray_nodes[0].left_lo.xyz, ray_nodes[0].right_lo.xyz);
    vec3 root_hi = max(ray_nodes[0].left_hi.xyz, ray_nodes[0].right_hi.xyz);
    vec3 big = max(max(abs(root_lo), abs(root_hi)), abs(origin));
    segment_grow_base = 1e-5 * max(max(big.x, big.y), big.z) + 1e-30;
    segment_far = length(max(abs(root_lo - origin), abs(root_hi - origin)));
}

// Sets the segment or ray from the origin along `d` to `t_end`, `dir_scale` the largest coordinate of the
// direction's terms (a local light: |C| + |U| + |V|). Every box is grown by the pixel's base
// (set_segment_origin) plus 1e-4 of `dir_scale` at the farthest t any box can be met: far beyond the
// rounding of the box's coordinates, of the origin and of d against the segment sample_hit tests, so that
// a box the segment meets is met. A component of d that vanishes is replaced by one of 1e-15 of d's
// largest, which moves the segment far less than the growth.
void set_segment(vec3 d, float t_end, float dir_scale) {
    float t_far = min(t_end, segment_far / max(length(d), 1e-30) * (1.0 + 1e-3));
    float grow = segment_grow_base + 1e-4 * dir_scale * t_far;
    float tiny = 1e-15 * max(max(abs(d.x), abs(d.y)), abs(d.z));
    vec3 sign_d = mix(vec3(1.0), vec3(-1.0), lessThan(d, vec3(0.0)));
    vec3 safe = mix(d, sign_d * tiny, lessThan(abs(d), vec3(tiny)));
    segment_inv = 1.0 / safe;
    segment_origin_inv = origin * segment_inv;
    segment_grow = grow * abs(segment_inv);
    segment_end = t_end;
    segment_scale = 1e-4 * dir_scale;
}

// Whether the segment set_segment set meets the box [lo, hi] (a slab test), and the first t at which it
// may. A box it meets is always met; an empty box may be met too (its triangle's own test rejects it).
bool segment_meets(vec3 lo, vec3 hi, out float t_enter) {
    vec3 ta = fma(lo, segment_inv, -segment_origin_inv);
    vec3 tb = fma(hi, segment_inv, -segment_origin_inv);
    vec3 t_near = min(ta, tb) - segment_grow;
    vec3 t_far = max(ta, tb) + segment_grow;
    t_enter = max(max(t_near.x, t_near.y), max(t_near.z, 0.0));
    return t_enter <= min(min(t_far.x, t_far.y), min(t_far.z, segment_end));
}

// Whether the sample's segment or ray along `d` misses triangle `index` beyond all rounding: two of its
// three edge functions (b x c).d, (c x a).d, (a x b).d have opposite signs by more than 1e-4 of their
// scale, far past the rounding of both this evaluation and sample_hit's. quick() would then find the
// sample unblocked (it cannot block every sample, and sample_hit is false for it), so skipping the
// triangle changes nothing.
bool sample_misses(uint index, vec3 d) {
    if (index >= uint(tris.length())) {
        return true;
    }
    vec3 a = tris[index].v[0].xyz - origin;
    vec3 b = tris[index].v[1].xyz - origin;
    vec3 c = tris[index].v[2].xyz - origin;
    vec3 e = vec3(dot(cross(b, c), d), dot(cross(c, a), d), dot(cross(a, b), d));
    vec3 la = abs(a), lb = abs(b), lc = abs(c);
    vec3 size = vec3(max(max(la.x, la.y), la.z), max(max(lb.x, lb.y), lb.z), max(max(lc.x, lc.y), lc.z));
    vec3 margin = segment_scale * size.yzx * size.zxy;
    return any(lessThan(e, -margin)) && any(greaterThan(e, margin));
}

// One sample's own segment (a spot or point light) or ray (a directional light) from the origin, walked
// through the BVH alone: `offsets`, the sample's unit-disc offsets or direction (sample_dirs), `d` the
// segment's or ray's direction, `t_end` its end, `dir_scale` as set_segment takes it. Each triangle met that
// the sample does not clearly miss is decided for every sample at once where quick() can, else for this
// sample by its own test, exactly as resolve() would decide it; one that blocks the sample is then
// resolved for all the others. It walks the rays' BVH (passes::bvh), whose single segments and rays meet
// fewer nodes than the linear one's, on the stack of the bundle's walk (which has given up, or never ran
// where the tile skips its bundles). It is a loop of its own rather than bvh_walk: that walk's per-node
// sample masks (a box projection per child, a mask per stacked node) cost more than they save for one
// sample: walking the samples through it made 8 % lights about 1.2x slower on an H100. False when the
// walk could not finish (never on a conforming device).
bool walk_sample(uvec4 bit, vec3 offsets, vec3 d, float t_end, float dir_scale) {
    set_segment(d, t_end, dir_scale);
    uint sp = 0u;
    uint node = 0u;
    for (uint round = 0u; round < 65535u; ++round) {
        for (uint step = 0u; step < 64u; ++step) {
            BvhNode nd = ray_nodes[node];
            uint children[2] = uint[2](floatBitsToUint(nd.left_lo.w), floatBitsToUint(nd.right_lo.w));
            float t_left, t_right;
            bool met[2] = bool[2](segment_meets(nd.left_lo.xyz, nd.left_hi.xyz, t_left),
                                  segment_meets(nd.right_lo.xyz, nd.right_hi.xyz, t_right));
            for (uint c = 0u; c < 2u; ++c) {
                if (met[c] && children[c] >= BVH_LEAF) {
                    met[c] = false;
                    uint index = children[c] & ~BVH_LEAF;
                    if (sample_misses(index, d)) {
                        continue;
                    }
                    uint q = quick(index);
                    if (q == BLOCKS_ALL) {
                        blocked = all_samples;
                    } else if (q == UNDECIDED && sample_hit(offsets)) {
                        // A blocker of one sample often blocks its neighbours: decide them all now.
                        blocked |= bit;
                        resolve(all_samples);
                    }
                }
            }
            if (any(notEqual(blocked & bit, uvec4(0u)))) {
                return true;
            }
            if (met[0] && met[1]) {
                if (sp == BVH_STACK) {
                    return false;
                }
                bool left_first = t_left <= t_right;
                bvh_stack[sp++] = left_first ? children[1] : children[0];
                node = left_first ? children[0] : children[1];
            } else if (met[0] || met[1]) {
                node = met[0] ? children[0] : children[1];
            } else if (sp > 0u) {
                node = bvh_stack[--sp];
            } else {
                return true;
            }
        }
    }
    return false;
}

// Sample `bit` of word `word`'s own walk (walk_sample).
bool walk_one(uint word, uint bit) {
    uvec4 mask = uvec4(0u);
    mask[word] = 1u << bit;
    vec3 offsets = sample_dirs[word * 32u + bit];
    vec3 d = local ? disc_c + offsets.x * disc_u + offsets.y * disc_v : offsets;
    vec3 span = local ? abs(disc_c) + abs(disc_u) + abs(disc_v) : abs(offsets);
    return walk_sample(mask, offsets, d, local ? 1.0 : 1.0 / 0.0, max(max(span.x, span.y), span.z));
}
#endif

// A directional light's bundle whose angular bound passes WIDE_BUNDLE, a spot or point light's whose
// emitter's radius passes WIDE_LOCAL_BUNDLE of its distance, is wide: its walk may give up for its samples'
// own walks (passes::area::WIDE_BUNDLE, WIDE_LOCAL_BUNDLE).
const float WIDE_BUNDLE = 0.1;
const float WIDE_LOCAL_BUNDLE = 0.05;
const float WIDE = local ? WIDE_LOCAL_BUNDLE : WIDE_BUNDLE;
// The width at which a wide bundle's walk budget is the configured one; it grows with the inverse square
// of the width below it (a narrower bundle meets fewer triangles that its samples' walks would miss) and
// shrinks above it.
const float BUDGET_WIDTH = 0.3;

// The projection of the BVH walk's boxes (bvh_box_samples) onto the samples' plane: a corner c maps to
// depth ((c - o).axis_u, (c - o).axis_v) / (c - o).normal - plane_offset, for corners in front of the
// origin ((c - o).normal > 0). A local light: the emitter's disc plane through its centre P, whose (dual)
// axes give the unit-disc offsets of the point where the ray from o through c meets it; a directional
// light: the gnomonic plane at unit distance along C.
vec3 plane_normal, plane_u, plane_v;
vec2 plane_offset;
float plane_depth;      // (P - o).normal for a local light, 1 for a directional one
float plane_margin;     // grows each box's projection past the rounding of the projection

// The bands of SAMPLE_BANDS columns (then rows) of a sample-band table: the bands starting at each column.
const uint SAMPLE_BANDS = 16u;
const uint BAND_COUNT = SAMPLE_BANDS * (SAMPLE_BANDS + 1u) / 2u;
const uint bands_base = local ? 1u + 2u * BAND_COUNT : 0u;

uint band_index(uint i0, uint i1) {
    return i0 * SAMPLE_BANDS - i0 * (i0 - min(i0, 1u)) / 2u + (i1 - i0);
}

// The samples of `reach`, still open, whose segment or ray may meet the box [lo, hi]: those whose point in
// the samples' plane may lie within the bounding rectangle of the box's central projection from the origin
// (the projection of a convex set in front of the origin is the convex hull of its corners', and a segment
// or ray from o through a point of the box reaches the plane at its sample's point), found in the sample
// bands of the columns and rows the rectangle spans. A box with a corner not in front of the origin keeps
// them all, as does a triangle's (a `leaf`): its own test narrows its samples better, through the edge
// table.
uvec4 bvh_box_samples(vec3 lo, vec3 hi, uvec4 reach, bool leaf) {
    uvec4 open = reach & ~blocked;
    if (leaf || all(equal(open, uvec4(0u))) || !(plane_depth > 0.0)) {
        return open;
    }
    vec2 rect_lo = vec2(1.0 / 0.0), rect_hi = vec2(-1.0 / 0.0);
    for (uint corner = 0u; corner < 8u; ++corner) {
        vec3 c = vec3((corner & 1u) != 0u ? hi.x : lo.x, (corner & 2u) != 0u ? hi.y : lo.y,
                      (corner & 4u) != 0u ? hi.z : lo.z) - origin;
        float depth = dot(c, plane_normal);
        if (!(depth > 0.0)) {
            return open;
        }
        vec2 p = plane_depth / depth * vec2(dot(c, plane_u), dot(c, plane_v)) - plane_offset;
        rect_lo = min(rect_lo, p);
        rect_hi = max(rect_hi, p);
    }
    float grow = plane_margin + 1e-3 * max(rect_hi.x - rect_lo.x, rect_hi.y - rect_lo.y)
        + 1e-5 * max(max(abs(rect_lo.x), abs(rect_lo.y)), max(abs(rect_hi.x), abs(rect_hi.y)));
    uvec4 header = sample_bands[bands_base];
    float band_lo = uintBitsToFloat(header.x), cell = uintBitsToFloat(header.y);
    vec2 first = (rect_lo - grow - band_lo) / cell, last = (rect_hi + grow - band_lo) / cell;
    if (any(lessThan(last, vec2(0.0))) || any(greaterThan(first, vec2(float(SAMPLE_BANDS))))) {
        return uvec4(0u);   // no sample's point lies there
    }
    uvec2 c0 = uvec2(clamp(floor(first), vec2(0.0), vec2(float(SAMPLE_BANDS - 1u))));
    uvec2 c1 = uvec2(clamp(floor(last), vec2(0.0), vec2(float(SAMPLE_BANDS - 1u))));
    return open & sample_bands[bands_base + 1u + band_index(c0.x, c1.x)]
        & sample_bands[bands_base + 1u + BAND_COUNT + band_index(c0.y, c1.y)];
}


// The pixel's walk of the BVH with its bundle: the segments from the origin to the emitter's disc (whose
// axes' combined reach bounds u U + v V over the unit disc), or the rays within the light's cone. (Walking
// every pixel's samples on their own from the start was measured slower on an H100 at every light size: a
// node's test costs less, but the samples' walks meet the nodes near the origin again and again. Hence
// the budget below, and the tile history for the tiles whose bundles mostly give up.)
void walk_bvh() {
    if (local) {
        float reach = max(dot(disc_u, disc_u), dot(disc_v, disc_v)) + abs(dot(disc_u, disc_v));
        bvh_set_cone(origin, disc_c, sqrt(reach) * (1.0 + 1e-4), 1.0);
        // The disc's plane, spanned by its axes U and V, in the dual basis of (U, V): a point P + u U + v V
        // of it gets (u, v) however far from orthogonal the axes' rounding leaves them.
        vec3 n = cross(disc_u, disc_v);
        plane_normal = dot(disc_c, n) < 0.0 ? -n : n;
        vec3 du = cross(disc_v, n), dv = cross(n, disc_u);
        plane_u = du / dot(disc_u, du);
        plane_v = dv / dot(disc_v, dv);
        plane_depth = dot(disc_c, plane_normal);
        plane_offset = vec2(dot(disc_c, plane_u), dot(disc_c, plane_v));
        plane_margin = 1e-4;
    } else {
        bvh_set_cone(origin, samples.center.xyz, samples.center.w * (1.0 + 1e-4) + 1e-6, 1.0 / 0.0);
        plane_normal = samples.center.xyz;
        plane_u = samples.axis_u.xyz;
        plane_v = samples.axis_v.xyz;
        plane_depth = 1.0;
        plane_offset = vec2(0.0);
        plane_margin = 1e-4 * samples.center.w;
    }
    // A wide bundle (an emitter large for its distance) meets many triangles that no sample's own segment
    // comes near. Its walk visits at most `k.misc.z` nodes and triangles per 64 open samples, scaled by
    // (BUDGET_WIDTH / width)^2, about what the samples' own walks would cost; past them each open sample
    // still undecided walks its own segment or ray, so that a pixel costs at most about twice the cheaper
    // way. The answer is the same either way, bit for bit. (`k.misc.z` 0: each sample's own walk at once;
    // 0xFFFFFFFF: the bundle always.) A wide pixel whose tile skips its bundles this frame (the tile
    // history) walks its samples at once.
    float width = local ? length(disc_u) / max(length(disc_c), 1e-30) : samples.center.w;
    uint budget = 0xFFFFFFFFu;
    if (SAMPLE_WALKS == 0) {
        budget = 0xFFFFFFFFu;   // a directional light never wide, with a budget: its bundle walks to the end
    } else if (k.misc.z == 0u) {
        budget = 0u;
    } else if (width > WIDE && k.misc.z != 0xFFFFFFFFu && tile_skips()) {
        budget = 0u;
    } else if (width > WIDE && k.misc.z != 0xFFFFFFFFu) {
        uint open_count = open_samples();
#if SAMPLE_WALKS
        tile_open[gl_LocalInvocationIndex] = open_count;
#endif
        float scale = min(BUDGET_WIDTH * BUDGET_WIDTH / (width * width), 64.0);
        budget = uint(min(float(k.misc.z) * scale * float(open_count) / 64.0, 4.0e9));
    }
    bool finished = bvh_walk(k.misc.y, all_samples, budget);
#if SAMPLE_WALKS
    if (finished && bvh_over_budget) {
        count_sample_walks();
        set_segment_origin();
        if (bvh_spent > 0u) {
            count_tile_give_up();
        } else if (tile_skips() && k.misc.z != 0u) {
            count_bundle_skip();
        }
        for (uint w = 0u; w < 4u && finished; ++w) {
            for (uint bits = all_samples[w] & ~blocked[w]; bits != 0u && finished; bits &= bits - 1u) {
                uint bit = findLSB(bits);
                if ((blocked[w] & (1u << bit)) == 0u) {
                    finished = walk_one(w, bit);
                }
            }
        }
    }
#endif
    count_walk(finished);
}

void main() {
    sample_count = k.misc.w;
    uint lid = gl_LocalInvocationIndex;
    for (uint i = lid; i < sample_count; i += 64u) {
        sample_dirs[i] = samples.dirs[i].xyz;
    }
#if SAMPLE_WALKS
    tile = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (lid == 0u) {
        tile_skip = read_tile_history();
    }
#endif
    barrier();
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= int(k.dims.x) || px.y >= int(k.dims.y)) {
        return;
    }
    vec3 dir;
    float t_max;
    int ray = shadow_ray(px, origin, dir, t_max);
    if (ray != SHADOW_RAY_TRACE) {
        imageStore(visibility, px, vec4(ray == SHADOW_RAY_LIT ? 1.0 : 0.0));
        return;
    }
    uint texel = pixel_texel[uint(px.y) * k.dims.x + uint(px.x)];
    if (texel == TEXEL_OUTSIDE) {
        imageStore(visibility, px, vec4(1.0));
        return;
    }
    all_samples = uvec4(0u);
    blocked = uvec4(0u);
    vec3 n = shadow_ray_normal;
    // A spot or point light's samples lie on the emitter's disc facing the receiver: its axes are the
    // rotation taking +Y to the direction from the receiver (not the offset ray origin) towards the light,
    // applied to +X and +Z (reference::disc_basis). Each sample's facing is judged from the receiver too.
    vec3 to_centre = k.light_pos.xyz - shadow_ray_receiver;
    if (local) {
        disc_c = k.light_pos.xyz - origin;
        disc_axes(k.light_pos.xyz, shadow_ray_receiver, k.light_dir.w, disc_u, disc_v);
    }
    for (uint i = 0u; i < sample_count; ++i) {
        all_samples[i >> 5u] |= 1u << (i & 31u);
        vec3 w = local ? to_centre + sample_dirs[i].x * disc_u + sample_dirs[i].y * disc_v : sample_dirs[i];
        if (dot(n, w) <= 0.0) {
            blocked[i >> 5u] |= 1u << (i & 31u);
        }
    }
    uint begin, end;
    if (complete_list(texel, begin, end)) {
        for (uint i = begin; i < end && !all_blocked(); ++i) {
            consider(entries[i], all_samples);
        }
    } else if (!all_blocked()) {
        walk_bvh();
    }
    uvec4 seen = blocked & all_samples;
    uint hidden = bitCount(seen.x) + bitCount(seen.y) + bitCount(seen.z) + bitCount(seen.w);
    imageStore(visibility, px, vec4(float(sample_count - hidden) / float(sample_count)));
}

// A pixel's walk of the bounding volume hierarchy over the prim buffer (passes::bvh): every triangle whose
// box meets the bundle of the pixel's rays or segments, nearer child first, until the includer is done.
// The includer declares the node buffer `bvh_nodes[]` (bvh.glsl's BvhNode) before this file, and defines
// `void bvh_visit(uint triangle, uvec4 samples)` (tests one triangle against the samples that may meet it)
// and `bool bvh_done()` (whether the pixel is decided); it sets the bundle (bvh_cone_*) before calling
// bvh_walk.
//
// The bundle is the cone of points o + t (d + r), 0 <= t <= t_end, |r| <= t * spread: a hard shadow ray
// (spread 0, d its direction), the segments from o to the points of a spot or point light's emitter disc
// (d from o to the disc's centre, spread its radius, t_end 1), or the rays from o within a directional
// light's cone (d its centre direction, spread the bound on every sample's distance from it). Per axis the
// cone's section at t spans [o + t (d - spread), o + t (d + spread)] (the box around the disc of radius
// t spread), so a box is met only where both ends' linear conditions hold for a common t: a slab test.
// Boxes are grown by 1e-5 of the largest coordinate involved, far beyond the rounding of the test: a box
// the exact bundle meets is always walked.
//
// With BVH_MASKED defined (the area trace), each node of the walk carries the samples whose segment or ray
// may meet it: the includer's `uvec4 bvh_box_samples(vec3 lo, vec3 hi, uvec4 samples, bool leaf)` narrows
// its parent's to those of a child's box (a triangle's own test decides its samples better than its box
// can: for a leaf it need only drop those already decided), and a child none of whose samples is still
// open is not walked. A wide bundle then costs what its samples can meet, not what its cone holds.

vec3 bvh_cone_o;
vec3 bvh_cone_d;
float bvh_cone_spread;
float bvh_cone_t_end;
// Per axis, the reciprocals of the rates at which the cone's section's ends move (0 where one stands still).
vec3 bvh_inv_up, bvh_inv_down;

// Sets the bundle of the next walk: the cone from o along d, spreading by `spread` per unit of t, to t_end.
void bvh_set_cone(vec3 o, vec3 d, float spread, float t_end) {
    bvh_cone_o = o;
    bvh_cone_d = d;
    bvh_cone_spread = spread;
    bvh_cone_t_end = t_end;
    vec3 up = d + spread, down = d - spread;
    bvh_inv_up = vec3(up.x != 0.0 ? 1.0 / up.x : 0.0, up.y != 0.0 ? 1.0 / up.y : 0.0,
                      up.z != 0.0 ? 1.0 / up.z : 0.0);
    bvh_inv_down = vec3(down.x != 0.0 ? 1.0 / down.x : 0.0, down.y != 0.0 ? 1.0 / down.y : 0.0,
                        down.z != 0.0 ? 1.0 / down.z : 0.0);
}

void bvh_visit(uint triangle, uvec4 samples);
bool bvh_done();
#ifdef BVH_MASKED
uvec4 bvh_box_samples(vec3 lo, vec3 hi, uvec4 samples, bool leaf);
#endif

// Whether the bundle meets the box [lo, hi]; `t_enter`, the first t at which it may.
bool bvh_cone_meets(vec3 lo, vec3 hi, out float t_enter) {
    t_enter = 0.0;
    if (any(greaterThan(lo, hi))) {
        return false;   // an empty box (a triangle that cannot be hit)
    }
    vec3 big = max(max(abs(lo), abs(hi)), abs(bvh_cone_o));
    float grow = min(1e-5 * max(max(big.x, big.y), big.z), 1e30);
    lo -= grow;
    hi += grow;
    float t0 = 0.0, t1 = bvh_cone_t_end;
    for (int a = 0; a < 3; ++a) {
        float o = bvh_cone_o[a];
        float up = bvh_cone_d[a] + bvh_cone_spread;
        float down = bvh_cone_d[a] - bvh_cone_spread;
        // The section's upper end reaches the box's minimum: o + t up >= lo.
        if (up > 0.0) {
            t0 = max(t0, (lo[a] - o) * bvh_inv_up[a]);
        } else if (up < 0.0) {
            t1 = min(t1, (lo[a] - o) * bvh_inv_up[a]);
        } else if (o < lo[a]) {
            return false;
        }
        // The section's lower end stays below the box's maximum: o + t down <= hi.
        if (down < 0.0) {
            t0 = max(t0, (hi[a] - o) * bvh_inv_down[a]);
        } else if (down > 0.0) {
            t1 = min(t1, (hi[a] - o) * bvh_inv_down[a]);
        } else if (o > hi[a]) {
            return false;
        }
    }
    t_enter = t0;
    return t0 <= t1;
}

// The samples of `samples` whose segment or ray may meet the box [lo, hi] of a node or a `leaf`, and where
// the bundle may enter it: none when the bundle misses it.
uvec4 bvh_child(vec3 lo, vec3 hi, uvec4 samples, bool leaf, out float t_enter) {
    if (!bvh_cone_meets(lo, hi, t_enter)) {
        return uvec4(0u);
    }
#ifdef BVH_MASKED
    return bvh_box_samples(lo, hi, samples, leaf);
#else
    return samples;
#endif
}

// The most nodes a walk holds (the hierarchy is less deep: each level's common prefix of the 62-bit
// (Morton code, position) keys is longer than its parent's).
const uint BVH_STACK = 64u;
uint bvh_stack[BVH_STACK];
#ifdef BVH_MASKED
uvec4 bvh_stack_samples[BVH_STACK];
#endif
// Whether the last walk stopped at its step budget, and the steps it had taken then.
bool bvh_over_budget;
uint bvh_spent;

// Walks the hierarchy over `triangles` triangles for `samples` (the hard trace's one ray: any non-zero
// mask) until the includer is done, no node is left, or it has visited `budget` nodes and leaves
// (bvh_over_budget); false when the walk could not finish (never on a conforming device: the stack cannot
// overflow and the rounds cover every node; the caller counts it).
bool bvh_walk(uint triangles, uvec4 samples, uint budget) {
    bvh_over_budget = false;
    if (triangles == 0u) {
        return true;
    }
    uint sp = 0u;
    uint node = 0u;
    uvec4 node_samples = samples;
    bool walking = true;
    uint spent = 0u;
    // Rounds of 64 steps: llvmpipe (lavapipe) ends any one loop after 65535 iterations.
    for (uint round = 0u; round < 65535u && walking; ++round) {
        for (uint step = 0u; step < 64u && walking; ++step) {
            if (spent >= budget) {
                bvh_over_budget = true;
                bvh_spent = spent;
                return true;
            }
            BvhNode nd = bvh_nodes[node];
            uint left_child = floatBitsToUint(nd.left_lo.w);
            uint right_child = floatBitsToUint(nd.right_lo.w);
            float t_left, t_right;
            uvec4 left = bvh_child(nd.left_lo.xyz, nd.left_hi.xyz, node_samples, left_child >= BVH_LEAF,
                                   t_left);
            uvec4 right = bvh_child(nd.right_lo.xyz, nd.right_hi.xyz, node_samples,
                                    right_child >= BVH_LEAF, t_right);
            uint leaves[2];
            uvec4 leaf_samples[2];
            uint count = 0u;
            if (any(notEqual(left, uvec4(0u))) && left_child >= BVH_LEAF) {
                leaves[count] = left_child & ~BVH_LEAF;
                leaf_samples[count++] = left;
                left = uvec4(0u);
            }
            if (any(notEqual(right, uvec4(0u))) && right_child >= BVH_LEAF) {
                leaves[count] = right_child & ~BVH_LEAF;
                leaf_samples[count++] = right;
                right = uvec4(0u);
            }
            for (uint i = 0u; i < count; ++i) {
                bvh_visit(leaves[i], leaf_samples[i]);
            }
            if (bvh_done()) {
                return true;
            }
            spent += 1u + count;
            bool go_left = any(notEqual(left, uvec4(0u)));
            bool go_right = any(notEqual(right, uvec4(0u)));
            if (go_left && go_right) {
                if (sp == BVH_STACK) {
                    return false;
                }
                bool left_first = t_left <= t_right;
                bvh_stack[sp] = left_first ? right_child : left_child;
#ifdef BVH_MASKED
                bvh_stack_samples[sp] = left_first ? right : left;
#endif
                ++sp;
                node = left_first ? left_child : right_child;
                node_samples = left_first ? left : right;
            } else if (go_left || go_right) {
                node = go_left ? left_child : right_child;
                node_samples = go_left ? left : right;
            } else if (sp > 0u) {
                --sp;
                node = bvh_stack[sp];
#ifdef BVH_MASKED
                node_samples = bvh_stack_samples[sp];
#endif
            } else {
                walking = false;
            }
        }
    }
    return !walking;
}

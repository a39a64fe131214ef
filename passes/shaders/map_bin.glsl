// The binning test shared by the compute and raster binning paths: whether triangle `t` goes into the
// list of `texel`. A texel gets a triangle only if a ray origin lies in it (receiver mark), the triangle is
// not wholly farther from the light than every ray origin of the texel, and the texel square grown by the
// triangle's margin overlaps the triangle (separating axes: the box axes are the caller's bounding box, the
// edge normals are tested here, relative to the triangle's own vertices).

// Mirrors the setup pass's output (64 bytes).
struct BinTri {
    vec4 ab;        // texel-space a.xy, b.xy (counter-clockwise; a segment's ends in MODE_SEGMENT);
                    // MODE_CLIPPED: edge line 0 (xyz) and line 1's x
    vec4 cmd;       // c.xy (MODE_CLIPPED: line 1's y and z), margin (texels), min depth key minus its error
    uvec4 info;     // x: bbox min (x | y << 16), y: bbox max, z: mode, w: tiles per bbox row
    vec4 ext;       // MODE_CLIPPED: edge line 2 (xyz), orientation (+1, -1, or 0: either)
};

#define MODE_TRIANGLE 0u
#define MODE_SEGMENT 1u
#define MODE_POINT 2u
#define MODE_COVER 3u       // every texel of the bbox (coordinates too large for edge functions)
#define MODE_CLIPPED 4u     // perspective light, a vertex on or behind the light's plane (or next to it):
                            // homogeneous edge functions, which keep exactly the part in front (below)
#define BIN_TILE 4u

// Entries of the bin walk's search index (map_index.comp; passes::primitive_map::SEARCH_INDEX_WORDS).
#define SEARCH_INDEX_SIZE 65536u

// The bin triangles of the frame (MapPush `p`): the triangles for a light of one frustum, else the
// (triangle, face) pairs the setup kept (`kept`: the first state's grid.z), within those the bin items hold.
uint bin_count(MapPush p, uint kept) {
    return p.faces == 1u ? p.triangles : min(kept, p.pairs);
}

// Items per entry of the search index for `items` items: entry k stands for item k * chunk, and the
// entries in use, (items - 1) / chunk + 1, are at most SEARCH_INDEX_SIZE.
uint search_chunk(uint items) {
    return max(items / SEARCH_INDEX_SIZE + (items % SEARCH_INDEX_SIZE != 0u ? 1u : 0u), 1u);
}

// A texel is accepted when its square grown by the triangle's margin overlaps it; the margin is at least
// this many texels (it absorbs the rounding of the edge functions below).
#define ACCEPT_MARGIN (1.0 / 512.0)

float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }

// `widen`: texels by which the triangle's footprint grows besides its margin (area shadows: the penumbra
// it may cast on the texel's receivers; 0 for hard shadows).
bool bin_overlaps(BinTri t, vec2 centre, float widen) {
    float grow = 0.5 + t.cmd.z + widen;
    vec2 a = t.ab.xy, b = t.ab.zw, c = t.cmd.xy;
    if (t.info.z == MODE_TRIANGLE) {
        vec2 e0 = b - a, e1 = c - b, e2 = a - c;
        return cross2(e0, centre - a) + grow * (abs(e0.x) + abs(e0.y)) >= 0.0
            && cross2(e1, centre - b) + grow * (abs(e1.x) + abs(e1.y)) >= 0.0
            && cross2(e2, centre - c) + grow * (abs(e2.x) + abs(e2.y)) >= 0.0;
    }
    if (t.info.z == MODE_SEGMENT) {
        vec2 e = b - a;
        return abs(cross2(e, centre - a)) <= grow * (abs(e.x) + abs(e.y));
    }
    if (t.info.z == MODE_CLIPPED) {
        // Olano & Greer's homogeneous edge functions: the light's rays through the texel centre p hit
        // the triangle in front of the light iff p = sum(l_i * h_i) with every l_i >= 0, i.e. iff every
        // edge function has the orientation's sign (see clipped_setup in map_setup.comp).
        vec3 p = vec3(centre, 1.0);
        vec3 l0 = t.ab.xyz, l1 = vec3(t.ab.w, t.cmd.xy), l2 = t.ext.xyz;
        vec3 f = vec3(dot(l0, p), dot(l1, p), dot(l2, p));
        vec3 g = grow * vec3(abs(l0.x) + abs(l0.y), abs(l1.x) + abs(l1.y), abs(l2.x) + abs(l2.y));
        bool positive = t.ext.w >= 0.0 && all(greaterThanEqual(f + g, vec3(0.0)));
        bool negative = t.ext.w <= 0.0 && all(lessThanEqual(f - g, vec3(0.0)));
        return positive || negative;
    }
    return true;    // a point or a cover: the bounding box decided
}

// Unit roundoff of f32.
#define BIN_U 5.9604645e-8

// Area shadows: texels by which the footprint of a triangle whose nearest depth key is `nearest` widens for
// receivers down to depth key `reach`; `widen` is the frustum's fit.zw (map_fit.comp), rounded up past the
// arithmetic's rounding.
// Directional light (widen.y = 0): widen.x texels per unit of depth key the shadow ray climbs.
// Spot or point light (widen.y = the emitter's depth extent E > 0, widen.x = its reach K in texels): a point
// q at depth key w(q) >= nearest of a segment from a receiver at depth key w_x to the emitter lies
// t K / w(q) texels from the receiver's texel, where w(q) = (1 - t) w_x + t w(d) with w(d) <= E gives
// t <= (w_x - w(q)) / (w_x - E); so at most K (w_x - nearest) / ((w_x - E) nearest) for the texel's
// deepest receiver w_x = reach (the bound grows with w_x and falls with w(q) once nearest > E, which the
// setup's depth floor guarantees). A triangle listed everywhere (nearest <= 0) does not widen.
float penumbra_span(float reach, float nearest, vec2 widen) {
    if (widen.y == 0.0) {
        return max(reach - nearest, 0.0) * widen.x * (1.0 + 1.0 / 65536.0);
    }
    if (!(nearest > widen.y) || reach <= nearest) {
        return 0.0;
    }
    return widen.x * (reach - nearest) / ((reach - widen.y) * nearest) * (1.0 + 1.0 / 1024.0);
}

float penumbra_texels(BinTri t, float reach, vec2 widen) {
    return penumbra_span(reach, t.cmd.w, widen);
}

// A bound on the rounding of evaluating the edge function of edge `e` from point `a` (or, with a = 0, a
// homogeneous line of coefficients e) anywhere within `h` of `c`, in the texel test or in the tile test
// below: both evaluate the same affine function, so their difference is at most twice this.
float bin_rounding(vec2 e, vec2 a, vec2 c, vec2 h) {
    vec2 reach = abs(c) + h + abs(a) + 1.0;
    return 16.0 * BIN_U * (abs(e.x) * reach.y + abs(e.y) * reach.x) * 1.01;
}

// Whether any texel centre within `h` (per axis) of `c` may be accepted by bin_overlaps: each edge
// function's best value over that box (its value at `c` plus the half-extent times its gradient) is tested
// with the texel test's growth (`widen`: the largest of the tile's texels) and both evaluations' rounding.
// Conservative: a tile it rejects holds no
// texel bin_overlaps accepts, so the binning skips the tile's texels without changing any list.
bool bin_tile_overlaps(BinTri t, vec2 c, vec2 h, float widen) {
    float grow = 0.5 + t.cmd.z + widen;
    vec2 a = t.ab.xy, b = t.ab.zw, cc = t.cmd.xy;
    if (t.info.z == MODE_TRIANGLE) {
        vec2 e0 = b - a, e1 = cc - b, e2 = a - cc;
        return cross2(e0, c - a) + dot(h, abs(e0.yx)) + grow * (abs(e0.x) + abs(e0.y))
                   + 2.0 * bin_rounding(e0, a, c, h) >= 0.0
            && cross2(e1, c - b) + dot(h, abs(e1.yx)) + grow * (abs(e1.x) + abs(e1.y))
                   + 2.0 * bin_rounding(e1, b, c, h) >= 0.0
            && cross2(e2, c - cc) + dot(h, abs(e2.yx)) + grow * (abs(e2.x) + abs(e2.y))
                   + 2.0 * bin_rounding(e2, cc, c, h) >= 0.0;
    }
    if (t.info.z == MODE_SEGMENT) {
        vec2 e = b - a;
        return abs(cross2(e, c - a)) - dot(h, abs(e.yx))
            <= grow * (abs(e.x) + abs(e.y)) + 2.0 * bin_rounding(e, a, c, h);
    }
    if (t.info.z == MODE_CLIPPED) {
        vec3 p = vec3(c, 1.0);
        vec3 l0 = t.ab.xyz, l1 = vec3(t.ab.w, t.cmd.xy), l2 = t.ext.xyz;
        vec3 f = vec3(dot(l0, p), dot(l1, p), dot(l2, p));
        vec3 spread = vec3(dot(h, abs(l0.xy)), dot(h, abs(l1.xy)), dot(h, abs(l2.xy)));
        vec3 g = grow * vec3(abs(l0.x) + abs(l0.y), abs(l1.x) + abs(l1.y), abs(l2.x) + abs(l2.y));
        vec3 r = 2.0 * vec3(bin_rounding(l0.yx, vec2(0.0), c, h) + 16.0 * BIN_U * abs(l0.z),
                            bin_rounding(l1.yx, vec2(0.0), c, h) + 16.0 * BIN_U * abs(l1.z),
                            bin_rounding(l2.yx, vec2(0.0), c, h) + 16.0 * BIN_U * abs(l2.z));
        bool positive = t.ext.w >= 0.0 && all(greaterThanEqual(f + spread + g + r, vec3(0.0)));
        bool negative = t.ext.w <= 0.0 && all(lessThanEqual(f - spread - g - r, vec3(0.0)));
        return positive || negative;
    }
    return true;    // a point or a cover: the bounding box decided
}

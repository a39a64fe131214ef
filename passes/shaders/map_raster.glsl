// Helpers of the raster binning paths (after map_bin.glsl).

// The rasterizer snaps vertices to 1/256 texel; covering polygons are grown by this much more.
#define RASTER_MARGIN (1.0 / 64.0)

uvec2 bin_box_min(BinTri bt) { return uvec2(bt.info.x & 0xFFFFu, bt.info.x >> 16); }
uvec2 bin_box_max(BinTri bt) { return uvec2(bt.info.y & 0xFFFFu, bt.info.y >> 16); }

// Corner i of the counter-clockwise triangle with every edge pushed out by `grow` texels in the square
// metric (the triangle's Minkowski sum with a square of half-side `grow` lies inside it).
vec2 dilated_corner(BinTri bt, uint i, float grow) {
    vec2 q[3] = vec2[3](bt.ab.xy, bt.ab.zw, bt.cmd.xy);
    vec2 ed[3] = vec2[3](q[1] - q[0], q[2] - q[1], q[0] - q[2]);
    float det = cross2(ed[2], ed[0]);
    vec2 ep = ed[(i + 2u) % 3u];
    vec2 en = ed[i];
    float rp = grow * (abs(ep.x) + abs(ep.y));
    float rn = grow * (abs(en.x) + abs(en.y));
    return q[i] + (ep * rn - en * rp) / det;
}

// Whether a raster fragment's texel lies in the triangle's clamped bounding box.
bool in_bin_box(BinTri bt, uvec2 texel) {
    return all(greaterThanEqual(texel, bin_box_min(bt))) && all(lessThanEqual(texel, bin_box_max(bt)));
}

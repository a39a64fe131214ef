// Constants of the software conservative raster path.
// A texel is accepted when its square grown by ACCEPT_MARGIN texels overlaps the triangle (a superset of
// the exact conservative set that absorbs f32 rounding of the light-space projection).
#define ACCEPT_MARGIN (1.0 / 512.0)
// The emitted covering polygon is grown a little more so the rasterizer's fixed-point snapping never
// loses an accepted texel centre.
#define RASTER_MARGIN (1.0 / 64.0)
#define MODE_TRIANGLE 0
#define MODE_SEGMENT 1
#define MODE_BOX 2

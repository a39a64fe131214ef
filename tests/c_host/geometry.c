/* The scene's geometry as an engine changes and stores it: Vulkan geometry that moves every frame (the
 * frame's bounds), instances moved by their draw transforms, draws with a base vertex, positions quantized
 * to 16 bits. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

/* ---------- moving geometry: bounds per frame ---------- */
/* With Vulkan geometry that the engine changes every frame, the plugin cannot trust the bounds of the
 * geometry call: it culls a point light's faces by the view and the range alone, and records all six of a
 * light above the scene. Given this frame's bounds (`has_bounds`), it culls the face that looks above
 * them. Both frames match the exact shadow. (The light bins through the software raster path, so that the
 * plugin shadows it through its six faces as frusta rather than as one cube map.) */
void moving_geometry_bounds(const HrtsVulkanDevice *vk) {
    setup_camera(0.0);
    Emitter lamp = point(v3(0.9, 2.3, 0.7));
    set_lights(&lamp, 1);
    upload_gbuffer();
    HrtsContext *ctx = create_context(vk, 1);
    HrtsConfig cfg = config(HRTS_SHADOW_MODE_HARD);
    cfg.dynamic_geometry = true;
    cfg.binning_path = HRTS_BINNING_PATH_SOFTWARE;
    Buf vb, ib;
    HrtsVulkanGeometry vg = engine_geometry(&vb, &ib);
    HrtsTargets t = targets();
    CHECK(hrts_configure(ctx, &cfg) == HRTS_RESULT_OK && hrts_set_geometry_vulkan(ctx, &vg) == HRTS_RESULT_OK &&
              hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "moving geometry: setup: %s", hrts_last_error(ctx));
    static float vis[W * H];
    uint32_t culled[2] = {99, 99};
    int mismatches[2] = {-1, -1};
    for (int with_bounds = 0; with_bounds < 2; with_bounds++) {
        VkCommandBuffer cmd = begin();
        uint64_t index = next_frame++;
        HrtsFrame f = frame(cmd, index);
        f.has_bounds = with_bounds;
        memcpy(f.bounds, SCENE_BOUNDS, sizeof SCENE_BOUNDS);
        HrtsResult r = finish_frame(cmd, hrts_record_frame(ctx, &f), vis);
        HrtsFrameReport rep;
        CHECK(r == HRTS_RESULT_OK && report(ctx, index, 0, &rep) == HRTS_RESULT_OK, "moving geometry: frame: %s",
              hrts_last_error(ctx));
        culled[with_bounds] = rep.frusta_culled;
        int near_edge, shadowed, lit;
        mismatches[with_bounds] = count_mismatches(vis, edge_tolerance(), &lamp, &near_edge, &shadowed, &lit);
        printf("moving geometry, %s: %s; %d shadowed, %d mismatches\n",
               with_bounds ? "with the frame's bounds" : "without bounds", rep.decision_reason, shadowed,
               mismatches[with_bounds]);
    }
    CHECK(culled[0] == 0 && culled[1] >= 1, "moving geometry: %u faces culled without bounds, %u with", culled[0],
          culled[1]);
    CHECK(mismatches[0] == 0 && mismatches[1] == 0, "moving geometry: %d and %d mismatches", mismatches[0],
          mismatches[1]);
    /* bounds that are not finite, inverted or all zero are refused */
    VkCommandBuffer cmd = begin();
    HrtsFrame f = frame(cmd, next_frame++);
    f.has_bounds = 1;
    memcpy(f.bounds, SCENE_BOUNDS, sizeof SCENE_BOUNDS);
    f.bounds[0] = 5.0f;
    CHECK(hrts_record_frame(ctx, &f) == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "bounds"),
          "inverted bounds refused: %s", hrts_last_error(ctx));
    /* so are the all-zero bounds of a zero-initialised struct, which would cull almost every light */
    memset(f.bounds, 0, sizeof f.bounds);
    CHECK(hrts_record_frame(ctx, &f) == HRTS_RESULT_ERROR_INVALID_ARGUMENT &&
              strstr(hrts_last_error(ctx), "bounds are all zero"),
          "all-zero bounds refused: %s", hrts_last_error(ctx));
    submit_and_wait(cmd);
    /* a sun the plugin fits needs the scene's bounds: moving Vulkan geometry has none of its own, so the frame
     * must give them */
    Emitter sun = fitted_sun(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    cmd = begin();
    f = frame(cmd, next_frame++);
    CHECK(hrts_record_frame(ctx, &f) == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "view_proj") &&
              strstr(hrts_last_error(ctx), "has_bounds"),
          "a fitted sun without bounds refused: %s", hrts_last_error(ctx));
    submit_and_wait(cmd);
    cmd = begin();
    f = frame(cmd, next_frame++);
    f.has_bounds = 1;
    memcpy(f.bounds, SCENE_BOUNDS, sizeof SCENE_BOUNDS);
    HrtsResult fitted = finish_frame(cmd, hrts_record_frame(ctx, &f), vis);
    int ne = 0, sh = 0, li = 0;
    int sun_mismatches = fitted == HRTS_RESULT_OK ? count_mismatches(vis, edge_tolerance(), &sun, &ne, &sh, &li) : -1;
    printf("moving geometry, a sun fitted to the frame's bounds: %d shadowed, %d mismatches\n", sh, sun_mismatches);
    CHECK(fitted == HRTS_RESULT_OK && sun_mismatches == 0 && sh > 100, "a fitted sun with the frame's bounds: %s",
          hrts_last_error(ctx));
    /* the engine's buffers may go once the frames that read them completed */
    VK(vkDeviceWaitIdle(device));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    free_buffer(vb);
    free_buffer(ib);
}

/* ---------- instances that move ---------- */
/* The engine moves the box every frame with one call (hrts_set_draw_transforms): the next frame rebuilds
 * the prim buffer (no pass is rebuilt) and its shadow is exact where the box now is; a frame without a move
 * keeps the prim buffer. Bad calls are refused. */
void moving_instances(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    HrtsContext *ctx = hard_lights_context(vk, g, &sun, 1);
    static float before[PX], moved[PX];
    upload_gbuffer();
    CHECK(run_frame(ctx, before) == HRTS_RESULT_OK, "instances: first frame: %s", hrts_last_error(ctx));
    const double shift[3] = {0.7, 0.0, -0.4};
    float transforms[2][16] = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1},
                               {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, (float)shift[0], (float)shift[1], (float)shift[2], 1}};
    CHECK(hrts_set_draw_transforms(ctx, 2, &transforms[0][0]) == HRTS_RESULT_OK, "instances: move: %s", hrts_last_error(ctx));
    memcpy(box_shift, shift, sizeof box_shift);
    upload_gbuffer();
    CHECK(run_frame(ctx, moved) == HRTS_RESULT_OK, "instances: moved frame: %s", hrts_last_error(ctx));
    HrtsFrameReport rep;
    CHECK(report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK, "instances: report: %s", hrts_last_error(ctx));
    int near_edge, shadowed, lit;
    int mismatches = count_mismatches(moved, edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
    int changed = differing(before, moved, PX);
    printf("moved instance: prim buffer %s, passes built %u time(s), %d px changed, %d shadowed, %d mismatches\n",
           rep.pass_status[HRTS_PASS_PRIM_BUFFER] == HRTS_PASS_STATUS_RAN ? "rebuilt" : "NOT rebuilt", rep.light_builds,
           changed, shadowed, mismatches);
    CHECK(rep.pass_status[HRTS_PASS_PRIM_BUFFER] == HRTS_PASS_STATUS_RAN && rep.light_builds == 1,
          "instances: the prim buffer is rebuilt and no pass is");
    CHECK(mismatches == 0 && changed > 100 && shadowed > 300, "instances: %d mismatches, %d px changed", mismatches, changed);
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK && report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK &&
              rep.pass_status[HRTS_PASS_PRIM_BUFFER] == HRTS_PASS_STATUS_UP_TO_DATE,
          "instances: a frame without a move keeps the prim buffer: %s", hrts_last_error(ctx));
    CHECK(hrts_set_draw_transforms(ctx, 1, &transforms[0][0]) == HRTS_RESULT_ERROR_INVALID_ARGUMENT &&
              strstr(hrts_last_error(ctx), "draw"),
          "instances: a wrong draw count is refused: %s", hrts_last_error(ctx));
    CHECK(hrts_set_draw_transforms(ctx, 2, NULL) == HRTS_RESULT_ERROR_NULL_POINTER, "instances: NULL refused");
    transforms[1][12] = NAN;
    CHECK(hrts_set_draw_transforms(ctx, 2, &transforms[0][0]) == HRTS_RESULT_ERROR_INVALID_ARGUMENT, "instances: NaN refused");
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    memset(box_shift, 0, sizeof box_shift);
    upload_gbuffer();
}

/* ---------- draws with a base vertex ---------- */
/* A mesh stored at a vertex offset of a shared buffer: the box's indices rebased to 0 with base_vertex 4,
 * or shifted by 10 with base_vertex -10, give the same visibility bit for bit. An index that the base vertex
 * moves out of range is refused. */
void base_vertex_draws(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    setup_camera(0.0);
    upload_gbuffer();
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    HrtsContext *ctx = hard_lights_context(vk, g, &sun, 1);
    static float original[PX], rebased[PX];
    CHECK(run_frame(ctx, original) == HRTS_RESULT_OK, "base vertex: frame: %s", hrts_last_error(ctx));
    const int bases[2] = {4, -10};
    for (int k = 0; k < 2; k++) {
        static uint32_t moved_indices[42];
        HrtsDraw moved_draws[2];
        memcpy(moved_draws, draws, sizeof moved_draws);
        for (int i = 0; i < 42; i++) moved_indices[i] = i < 6 ? indices[i] : (uint32_t)((int)indices[i] - bases[k]);
        moved_draws[1].base_vertex = bases[k];
        HrtsCpuGeometry mg = *g;
        mg.indices = moved_indices;
        mg.draws = moved_draws;
        CHECK(hrts_set_geometry_cpu(ctx, &mg) == HRTS_RESULT_OK && run_frame(ctx, rebased) == HRTS_RESULT_OK,
              "base vertex %d: %s", bases[k], hrts_last_error(ctx));
        int differ = differing(original, rebased, PX);
        printf("base vertex %d: %d px differ from the draw without one\n", bases[k], differ);
        CHECK(differ == 0, "base vertex %d: %d px differ", bases[k], differ);
    }
    HrtsDraw bad[2];
    memcpy(bad, draws, sizeof bad);
    bad[1].base_vertex = 100;
    HrtsCpuGeometry bg = *g;
    bg.draws = bad;
    CHECK(hrts_set_geometry_cpu(ctx, &bg) == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "base_vertex"),
          "base vertex out of range refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
}

/* ---------- quantized positions ---------- */
/* Positions as engines store them to save memory: four 16-bit floats, or 16-bit snorm or unorm with a
 * dequantization scale and offset (the plugin folds them into each draw's transform). Each gives the exact
 * shadow of the scene (its quantization moves a vertex by at most 1e-4 m, far inside the edge tolerance).
 * A vertex format the plugin does not read, and a scale with a zero axis, are refused. */
void quantized_positions(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    setup_camera(0.0);
    upload_gbuffer();
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    const struct {
        const char *name;
        VkFormat format;
        float scale[3], offset[3];
    } formats[3] = {
        {"R16G16B16A16_SFLOAT", VK_FORMAT_R16G16B16A16_SFLOAT, {0, 0, 0}, {0, 0, 0}},
        {"R16G16B16A16_SNORM, scale 4", VK_FORMAT_R16G16B16A16_SNORM, {4, 4, 4}, {0, 0, 0}},
        {"R16G16B16A16_UNORM, scale (8, 2, 8), offset (-4, 0, -4)", VK_FORMAT_R16G16B16A16_UNORM, {8, 2, 8}, {-4, 0, -4}},
    };
    Buf vb0, ib;
    HrtsVulkanGeometry vg = engine_geometry(&vb0, &ib);
    free_buffer(vb0);
    for (int k = 0; k < 3; k++) {
        Buf vb = make_host_buffer(12 * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        uint16_t *q = (uint16_t *)vb.map;
        for (int v = 0; v < 12; v++)
            for (int a = 0; a < 4; a++) {
                double p = a < 3 ? positions[3 * v + a] : 1.0;
                double scale = formats[k].scale[a < 3 ? a : 0], offset = formats[k].offset[a < 3 ? a : 0];
                double n = scale != 0 ? (p - offset) / scale : p;
                if (formats[k].format == VK_FORMAT_R16G16B16A16_SFLOAT) q[4 * v + a] = float_to_half((float)n);
                else if (formats[k].format == VK_FORMAT_R16G16B16A16_SNORM) q[4 * v + a] = (uint16_t)(int16_t)lround(n * 32767.0);
                else q[4 * v + a] = (uint16_t)lround(n * 65535.0);
            }
        HrtsVulkanGeometry qg = vg;
        qg.vertex_buffer = (uint64_t)(uintptr_t)vb.buffer;
        qg.vertex_buffer_size = 12 * 8;
        qg.vertex_offset = 0;
        qg.vertex_stride = 8;
        qg.vertex_format = (uint32_t)formats[k].format;
        memcpy(qg.position_scale, formats[k].scale, sizeof qg.position_scale);
        memcpy(qg.position_offset, formats[k].offset, sizeof qg.position_offset);
        HrtsContext *ctx = create_context(vk, 1);
        HrtsTargets t = targets();
        static float vis[PX];
        HrtsResult r = configure_all(ctx, 1, HRTS_SHADOW_MODE_HARD);
        if (r == HRTS_RESULT_OK) r = hrts_set_geometry_vulkan(ctx, &qg);
        if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
        if (r == HRTS_RESULT_OK) r = run_frame(ctx, vis);
        CHECK(r == HRTS_RESULT_OK, "positions %s: %s", formats[k].name, hrts_last_error(ctx));
        int near_edge = 0, shadowed = 0, lit = 0, mismatches = -1;
        if (r == HRTS_RESULT_OK) mismatches = count_mismatches(vis, edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
        printf("positions %s: %d lit, %d shadowed, %d near-edge, %d mismatches\n", formats[k].name, lit, shadowed,
               near_edge, mismatches);
        CHECK(mismatches == 0 && shadowed > 300, "positions %s: %d mismatches", formats[k].name, mismatches);
        if (k == 2) {
            HrtsVulkanGeometry bad = qg;
            bad.vertex_format = VK_FORMAT_R8G8B8A8_SNORM;
            CHECK(hrts_set_geometry_vulkan(ctx, &bad) == HRTS_RESULT_ERROR_INVALID_ENUM && strstr(hrts_last_error(ctx), "vertex_format"),
                  "an 8-bit vertex format is refused: %s", hrts_last_error(ctx));
            bad = qg;
            bad.position_scale[1] = 0.0f;
            CHECK(hrts_set_geometry_vulkan(ctx, &bad) == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "position_scale"),
                  "a zero scale axis is refused: %s", hrts_last_error(ctx));
        }
        VK(vkDeviceWaitIdle(device));
        CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
        free_buffer(vb);
    }
    free_buffer(ib);
    (void)g;
}

/* A plain C engine that integrates the plugin through hrts.h: it creates its own Vulkan device through
 * the loader (validation layer and synchronization validation on), draws the depth and normal images of a
 * box floating over a ground plane itself (analytic ray casting on the CPU), records the plugin into its
 * own command buffers, reads back the visibility images and compares them with the exact shadow of every
 * light. It keeps 3 frames in flight over 120 frames while the camera and lights move and the lights are
 * reconfigured midway, checks 8 lights of two types in one context, the scene given as meshes of their own
 * buffers and formats, a mesh deformed through per-frame vertex buffers, runs a table of misuse cases and
 * 100 create/destroy cycles. Prints "N passed, M failed" and exits non-zero on any failure. */
#define _POSIX_C_SOURCE 200112L
#include "engine.h"

#include <string.h>

/* The engine's host allocator, handed to the plugin before anything else: it counts live bytes. */
static size_t engine_live_bytes, engine_allocations;

static void *engine_allocate(void *user, size_t size, size_t alignment) {
    (void)user;
    void *p = NULL;
    if (alignment < sizeof(void *)) alignment = sizeof(void *);
    if (posix_memalign(&p, alignment, size ? size : 1) != 0) return NULL;
    __atomic_fetch_add(&engine_live_bytes, size, __ATOMIC_RELAXED);
    __atomic_fetch_add(&engine_allocations, 1, __ATOMIC_RELAXED);
    return p;
}

static void engine_free(void *user, void *memory, size_t size, size_t alignment) {
    (void)user;
    (void)alignment;
    __atomic_fetch_sub(&engine_live_bytes, size, __ATOMIC_RELAXED);
    free(memory);
}

static long rss_kib(void) {
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, resident = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
        fclose(f);
    }
    return resident * 4;
}

/* Engine geometry for misuse cases that fail before any buffer is touched: well-formed but for what the
 * case changes, with handles that are never used (1) and the draws of `g`. */
static HrtsVulkanGeometry fake_vulkan_geometry(const HrtsCpuGeometry *g) {
    HrtsVulkanGeometry vg;
    memset(&vg, 0, sizeof vg);
    vg.struct_size = sizeof vg;
    vg.vertex_buffer = 1;
    vg.vertex_buffer_size = 1024;
    vg.vertex_stride = 12;
    vg.vertex_count = 12;
    vg.index_buffer = 1;
    vg.index_buffer_size = 1024;
    vg.index_type = HRTS_INDEX_TYPE_UINT32;
    vg.index_count = 42;
    vg.draws = g->draws;
    vg.draw_count = g->draw_count;
    memcpy(vg.bounds, SCENE_BOUNDS, sizeof SCENE_BOUNDS);
    return vg;
}

static HrtsResult configure_all(HrtsContext *ctx, uint32_t count, uint32_t mode) {
    HrtsConfig cfgs[HRTS_MAX_LIGHTS];
    for (uint32_t i = 0; i < count; i++) cfgs[i] = config(mode);
    return hrts_configure_lights(ctx, count, cfgs);
}

/* A read-back recorded after frame N counts as a use of frame N+1: what a reconfigure retires after it is
 * held until frame N+1 has completed. The read-back's submission waits on a semaphore the test holds, so it
 * is surely pending when frame N+1 is recorded; with one frame in flight, recording frame N+1 frees what
 * only frames up to N used. Freeing the image the read-back reads then is an error the validation layer
 * reports (an object in use by a pending command buffer), and the read-back would read freed memory. */
static void readback_retire(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer();
    HrtsContext *ctx = create_context(vk, 1);
    HrtsTargets t = targets();
    CHECK(configure_all(ctx, 1, HRTS_SHADOW_MODE_HARD) == HRTS_RESULT_OK && hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK &&
              hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "read-back retire: setup: %s", hrts_last_error(ctx));
    static float vis[PX];
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "read-back retire: frame: %s", hrts_last_error(ctx));
    Buf back = make_host_buffer(sizeof(float) * PX, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    memset(back.map, 0xff, sizeof(float) * PX);
    VkCommandBuffer readback_cmd = begin();
    CHECK(record_resource_readback(ctx, readback_cmd, 0, HRTS_RESOURCE_RT_VISIBILITY, back, sizeof(float) * PX) == HRTS_RESULT_OK,
          "read-back retire: read-back: %s", hrts_last_error(ctx));
    VkSemaphore hold = held_semaphore();
    VkFenceCreateInfo fi = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence readback_done;
    VK(vkCreateFence(device, &fi, NULL, &readback_done));
    submit_held(readback_cmd, hold, readback_done);
    int errors_before = validation_errors;
    CHECK(configure_all(ctx, 1, HRTS_SHADOW_MODE_HYBRID) == HRTS_RESULT_OK, "read-back retire: reconfigure: %s", hrts_last_error(ctx));
    VkCommandBuffer cmd = begin();
    HrtsFrame f = frame(cmd, next_frame++);
    CHECK(hrts_record_frame(ctx, &f) == HRTS_RESULT_OK, "read-back retire: next frame: %s", hrts_last_error(ctx));
    int still_pending = vkGetFenceStatus(device, readback_done) == VK_NOT_READY;
    int in_use_errors = validation_errors - errors_before;
    release_held(hold);
    VK(vkWaitForFences(device, 1, &readback_done, VK_TRUE, UINT64_MAX));
    submit_and_wait(cmd);
    int differ = differing(back.map, vis, PX);
    printf("read-back retire: the read-back was %s when frame N+1 was recorded after a reconfigure; %d validation "
           "errors then; the read-back differs from frame N's output in %d px\n",
           still_pending ? "pending" : "NOT pending", in_use_errors, differ);
    CHECK(still_pending, "read-back retire: the held read-back had completed: the case was not tested");
    CHECK(in_use_errors == 0, "read-back retire: %d validation errors (objects freed under a pending read-back)", in_use_errors);
    CHECK(differ == 0, "read-back retire: the read-back differs from the frame's output in %d px", differ);
    vkDestroyFence(device, readback_done, NULL);
    vkDestroySemaphore(device, hold, NULL);
    vkFreeCommandBuffers(device, pool, 1, &readback_cmd);
    free_buffer(back);
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "read-back retire: destroy");
}

/* A failed call records nothing. Light 0 is hard (no shadow map), light 1 hybrid (its shadow map is
 * rendered every frame), so a call of the passes up to the ray trace without the shadow map suits light 0
 * and leaves out a pass light 1 runs: the call fails, and light 0's passes must not be in the command
 * buffer either. The camera moves in that same command buffer: had light 0's ray trace been recorded, its
 * visibility (read back after the submission) would show the new view. */
static void partial_record(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    setup_camera(0.0);
    Emitter suns[2] = {directional(v3(0.45, -1.0, 0.2)), directional(v3(-0.3, -1.0, 0.35))};
    set_lights(suns, 2);
    upload_gbuffer();
    HrtsContext *ctx = create_context(vk, 1);
    HrtsTargets t = targets();
    HrtsConfig cfgs[2] = {config(HRTS_SHADOW_MODE_HARD), config(HRTS_SHADOW_MODE_HYBRID)};
    CHECK(hrts_configure_lights(ctx, 2, cfgs) == HRTS_RESULT_OK && hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK &&
              hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "partial record: setup: %s", hrts_last_error(ctx));
    for (int i = 0; i < 2; i++) CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "partial record: frame: %s", hrts_last_error(ctx));
    static float before[PX], after[PX], moved[PX];
    CHECK(read_resource(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, before, sizeof before) == HRTS_RESULT_OK,
          "partial record: read-back: %s", hrts_last_error(ctx));
    setup_camera(0.5);
    Buf depth = make_host_buffer(sizeof(float) * PX, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    Buf normal = make_host_buffer(sizeof(float) * 4 * PX, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    draw_gbuffer(depth.map, normal.map);
    VkCommandBuffer cmd = begin();
    record_gbuffer_upload(cmd, depth, normal, 0);
    uint64_t index = next_frame++;
    HrtsFrame f = frame(cmd, index);
    uint32_t mask = 1u << HRTS_PASS_PRIM_BUFFER | 1u << HRTS_PASS_PRIMITIVE_MAP | 1u << HRTS_PASS_OCCUPANCY | 1u << HRTS_PASS_RAY_TRACE;
    HrtsResult r = hrts_record_passes(ctx, &f, mask);
    printf("partial record: the passes up to the ray trace without light 1's shadow map: %s (%s)\n", hrts_result_name(r), hrts_last_error(ctx));
    CHECK(r == HRTS_RESULT_ERROR_INVALID_STATE && strstr(hrts_last_error(ctx), "light 1"),
          "partial record: the call should fail for light 1: %s", hrts_result_name(r));
    submit_and_wait(cmd);
    free_buffer(depth);
    free_buffer(normal);
    CHECK(read_resource(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, after, sizeof after) == HRTS_RESULT_OK,
          "partial record: read-back after the failed call: %s", hrts_last_error(ctx));
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "partial record: the frame after: %s", hrts_last_error(ctx));
    CHECK(read_resource(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, moved, sizeof moved) == HRTS_RESULT_OK,
          "partial record: read-back of the moved view: %s", hrts_last_error(ctx));
    int changed = differing(after, before, PX), view_changes = differing(moved, before, PX);
    printf("partial record: light 0's visibility changed in %d px after the failed call (the moved view changes %d px)\n",
           changed, view_changes);
    CHECK(view_changes > 0, "partial record: the moved view changes nothing: the case was not tested");
    CHECK(changed == 0, "partial record: the failed call recorded light 0's ray trace (%d px changed)", changed);
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "partial record: destroy");
    setup_camera(0.0);
    upload_gbuffer();
}

/* ---------- moving geometry: bounds per frame ---------- */
/* With Vulkan geometry that the engine changes every frame, the plugin cannot trust the bounds of the
 * geometry call: it culls a point light's faces by the view and the range alone, and records all six of a
 * light above the scene. Given this frame's bounds (`has_bounds`), it culls the face that looks above
 * them. Both frames match the exact shadow. (The light bins through the software raster path, so that the
 * plugin shadows it through its six faces as frusta rather than as one cube map.) */
static void moving_geometry_bounds(const HrtsVulkanDevice *vk) {
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

/* ---------- the plugin's plan for a light ---------- */
/* A sun of no size given in HRTS_SHADOW_MODE_AUTO without a matrix, as an engine hands over its lights: the
 * plugin fits its frustum to the CPU geometry's bounds and chooses hard shadows (no shadow map); the report
 * says so, and the shadow is exact. A light of no size in any other mode is refused. */
static void auto_fitted_sun(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    setup_camera(0.0);
    Emitter sun = fitted_sun(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer();
    HrtsContext *ctx = create_context(vk, 2);
    HrtsConfig cfg = config(HRTS_SHADOW_MODE_AUTO);
    cfg.pcss_angular_radius = 0.0f;
    HrtsTargets t = targets();
    CHECK(hrts_configure(ctx, &cfg) == HRTS_RESULT_OK && hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK &&
              hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "auto sun: setup: %s", hrts_last_error(ctx));
    static float vis[W * H];
    uint64_t index = next_frame;
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "auto sun: frame: %s", hrts_last_error(ctx));
    HrtsFrameReport rep;
    CHECK(report(ctx, index, 0, &rep) == HRTS_RESULT_OK, "auto sun: report: %s", hrts_last_error(ctx));
    int near_edge, shadowed, lit;
    int mismatches = count_mismatches(vis, edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
    printf("auto, a sun of no size fitted by the plugin: %s; %d shadowed, %d near-edge, %d mismatches\n",
           rep.decision_reason, shadowed, near_edge, mismatches);
    CHECK(strstr(rep.decision_reason, "auto: hard (zero-size light)") && rep.decision == HRTS_LIGHT_DECISION_SHADOWED &&
              rep.pass_status[HRTS_PASS_RAY_TRACE] == HRTS_PASS_STATUS_RAN &&
              rep.pass_status[HRTS_PASS_SHADOW_MAP] == HRTS_PASS_STATUS_NOT_IN_PLAN,
          "auto sun: hard shadows reported: %s", rep.decision_reason);
    CHECK(mismatches == 0 && shadowed > 100, "auto sun: %d mismatches, %d shadowed", mismatches, shadowed);
    cfg.mode = HRTS_SHADOW_MODE_HARD;
    CHECK(hrts_configure(ctx, &cfg) == HRTS_RESULT_ERROR_INVALID_ARGUMENT &&
              strstr(hrts_last_error(ctx), "pcss_angular_radius"),
          "a light of no size in mode hard refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "auto sun: destroy");
}

/* ---------- the engine's depth as it is ---------- */
/* Every depth format the plugin reads, written by a reversed-Z projection with an infinite far plane and by a
 * standard-Z one with a finite far plane, gives the exact hard shadow (0 mismatches outside near-edge pixels):
 * the plugin rebuilds positions through the frame's projection and offsets the ray origins by the format's
 * depth error. A format it does not read is refused with a message. */
static void engine_depth(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    const struct {
        VkFormat format;
        const char *name;
    } formats[] = {
        {VK_FORMAT_D16_UNORM, "D16_UNORM"},
        {VK_FORMAT_X8_D24_UNORM_PACK32, "X8_D24_UNORM_PACK32"},
        {VK_FORMAT_D24_UNORM_S8_UINT, "D24_UNORM_S8_UINT"},
        {VK_FORMAT_D32_SFLOAT, "D32_SFLOAT"},
        {VK_FORMAT_D32_SFLOAT_S8_UINT, "D32_SFLOAT_S8_UINT"},
        {VK_FORMAT_R32_SFLOAT, "view Z in R32_SFLOAT"},
        {VK_FORMAT_R16_SFLOAT, "view Z in R16_SFLOAT"},
    };
    const double FAR = 50.0;
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer(); /* the normals of this view (and a depth the cases below replace) */
    static double distance[PX], view_z[PX];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            V3 n;
            double t;
            V3 ray = pixel_ray(x, y);
            distance[y * W + x] = cast(cam_pos, ray, 0, &t, &n) ? t : -1.0;
            /* an engine's linear view Z: the view-space z of the hit (negative in front), 0 on background */
            view_z[y * W + x] = distance[y * W + x] < 0 ? 0.0 : -t * dot3(ray, cam_f);
        }
    int cases = 0, failed_cases = 0;
    char skipped[256] = "";
    for (size_t k = 0; k < sizeof formats / sizeof formats[0]; k++) {
        VkFormat format = formats[k].format;
        int linear = format == VK_FORMAT_R32_SFLOAT || format == VK_FORMAT_R16_SFLOAT;
        VkFormatProperties props;
        vkGetPhysicalDeviceFormatProperties(phys, format, &props);
        VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT |
                                    (linear ? 0 : VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT);
        if ((props.optimalTilingFeatures & need) != need) {
            strcat(skipped, " ");
            strcat(skipped, formats[k].name);
            continue;
        }
        int stencil = format == VK_FORMAT_D24_UNORM_S8_UINT || format == VK_FORMAT_D32_SFLOAT_S8_UINT;
        VkImageAspectFlags data = linear ? VK_IMAGE_ASPECT_COLOR_BIT : VK_IMAGE_ASPECT_DEPTH_BIT;
        VkImageAspectFlags all = data | (stencil ? VK_IMAGE_ASPECT_STENCIL_BIT : 0);
        VkImageLayout layout = linear    ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
                               : stencil ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL
                                         : VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL;
        size_t texel = format == VK_FORMAT_D16_UNORM || format == VK_FORMAT_R16_SFLOAT ? 2 : 4;
        for (int forward = 0; forward < 2; forward++) {
            /* the projection: reversed Z to infinity (the default view), or standard Z to FAR */
            setup_camera(0.0);
            if (forward) {
                proj[10] = (float)(FAR / (NEAR - FAR));
                proj[14] = (float)(NEAR * FAR / (NEAR - FAR));
            }
            /* an engine's depth buffer: a depth attachment it also samples (or a view-Z image it writes) */
            VkImageUsageFlags usage = (linear ? 0 : VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) |
                                      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
            Img depth = make_image(format, usage, 1);
            Buf staging = make_host_buffer(texel * PX, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
            for (int i = 0; i < PX; i++) {
                double t = distance[i];
                double d = t < 0 ? (forward ? 1.0 : 0.0) : forward ? FAR / (FAR - NEAR) * (1.0 - NEAR / t) : NEAR / t;
                if (format == VK_FORMAT_R32_SFLOAT)
                    ((float *)staging.map)[i] = (float)view_z[i];
                else if (format == VK_FORMAT_R16_SFLOAT)
                    ((uint16_t *)staging.map)[i] = half_of((float)view_z[i]);
                else if (format == VK_FORMAT_D16_UNORM)
                    ((uint16_t *)staging.map)[i] = (uint16_t)lround(d * 65535.0);
                else if (format == VK_FORMAT_D32_SFLOAT || format == VK_FORMAT_D32_SFLOAT_S8_UINT)
                    ((float *)staging.map)[i] = (float)d;
                else
                    ((uint32_t *)staging.map)[i] = (uint32_t)lround(d * 16777215.0);
            }
            upload_image(depth, all, data, staging, layout);
            free_buffer(staging);

            HrtsContext *ctx = create_context(vk, 1);
            HrtsTargets t = targets();
            t.depth_image = (uint64_t)(uintptr_t)depth.image;
            t.depth_usage = usage;
            t.depth_format = (uint32_t)format;
            HrtsResult r = configure_all(ctx, 1, HRTS_SHADOW_MODE_HARD);
            if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
            if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
            static float vis[PX];
            if (r == HRTS_RESULT_OK) {
                VkCommandBuffer frame_cmd = begin();
                HrtsFrame f = frame(frame_cmd, next_frame++);
                f.depth_layout = layout;
                r = finish_frame(frame_cmd, hrts_record_frame(ctx, &f), vis);
            }
            int near_edge = 0, shadowed = 0, lit = 0, mismatches = -1;
            if (r == HRTS_RESULT_OK) mismatches = count_mismatches(vis, edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
            printf("depth %s, %s: %d lit, %d shadowed, %d near-edge, %d mismatches\n", formats[k].name,
                   forward ? "standard Z to a far plane" : "reversed Z to infinity", lit, shadowed, near_edge, mismatches);
            CHECK(r == HRTS_RESULT_OK, "depth %s: %s", formats[k].name, hrts_last_error(ctx));
            int ok = r == HRTS_RESULT_OK && mismatches == 0 && shadowed > 300 && near_edge * 100 <= 4 * PX;
            CHECK(ok, "depth %s (%s): %d mismatches, %d shadowed, %d near-edge", formats[k].name,
                  forward ? "standard Z" : "reversed Z", mismatches, shadowed, near_edge);
            cases++;
            failed_cases += !ok;
            CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
            free_image(depth);
        }
    }
    setup_camera(0.0);
    printf("engine depth: %d format and convention cases, %d failed; skipped (the device cannot sample them):%s\n",
           cases, failed_cases, skipped[0] ? skipped : " none");
    CHECK(cases >= 4, "only %d depth cases ran", cases);
    /* a format the plugin does not read, and a colour format, are refused */
    HrtsContext *ctx = create_context(vk, 1);
    HrtsTargets t = targets();
    const uint32_t refused[] = {VK_FORMAT_S8_UINT, VK_FORMAT_R8G8B8A8_UNORM};
    for (int i = 0; i < 2; i++) {
        t.depth_format = refused[i];
        HrtsResult r = hrts_set_targets(ctx, &t);
        CHECK(r == HRTS_RESULT_ERROR_INVALID_ENUM && strstr(hrts_last_error(ctx), "depth_format"),
              "depth_format %u refused: %s", refused[i], hrts_last_error(ctx));
    }
    /* normals derived from depth need the projection's depth, not view Z */
    t.depth_format = VK_FORMAT_R32_SFLOAT;
    t.normal_encoding = HRTS_NORMAL_ENCODING_NONE;
    HrtsResult r = hrts_set_targets(ctx, &t);
    CHECK(r == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "view-Z"),
          "view Z without normals refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
}

/* ---------- the output written directly ---------- */
/* With an R32_SFLOAT output that also has STORAGE usage, each light's last pass writes its layer (no copy):
 * the visibility equals the copied one bit for bit for a sun (hard, and hybrid: the blend's output), a point
 * light (one cube map, or the minimum over its faces), and a point light and a spot light whose ranges reach
 * nothing (their layers filled with 1), recorded in one call, split as an engine splits a frame, and pass by
 * pass; the report says which lights wrote directly. Pass by pass, every light's map is built before any
 * ray trace: the lights share their pixel texels, so a ray trace whose texels a later build overwrote
 * rewrites them first ('primitive map: pixel texels'); every way equals the one-call frame bit for bit. */
static void output_direct(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H, N = 4 };
    setup_camera(0.0);
    Emitter lights[N] = {directional(v3(0.45, -1.0, 0.2)), point(v3(0.9, 2.3, 0.7)), point(v3(0.0, 6.0, 0.0)),
                         fitted_spot(v3(0.0, 6.0, 0.0), v3(0.0, 7.0, 0.0), 0.5)};
    lights[2].c.range = 2.0f;
    lights[3].c.range = 2.0f;
    set_lights(lights, N);
    upload_gbuffer();
    const uint32_t modes[2] = {HRTS_SHADOW_MODE_HARD, HRTS_SHADOW_MODE_HYBRID};
    Img copied = out_img;
    Img direct = make_image(VK_FORMAT_R32_SFLOAT,
                            VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                            LAYERS);
    static float want[N * PX], got[N * PX], one_call[N * PX];
    for (int m = 0; m < 2; m++)
        for (int split = 0; split < 3; split++) {
            uint32_t directs[2] = {0, 0};
            uint32_t rewritten = 0;
            for (int d = 0; d < 2; d++) {
                out_img = d ? direct : copied;
                HrtsContext *ctx = create_context(vk, 1);
                HrtsTargets t = targets();
                if (d) t.output_usage |= VK_IMAGE_USAGE_STORAGE_BIT;
                HrtsResult r = configure_all(ctx, N, modes[m]);
                if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
                if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
                if (r == HRTS_RESULT_OK)
                    r = split ? run_frame_in_parts(ctx, d ? got : want, split == 2) : run_frame(ctx, d ? got : want);
                CHECK(r == HRTS_RESULT_OK, "direct output %d: %s", d, hrts_last_error(ctx));
                for (uint32_t l = 0; l < N && r == HRTS_RESULT_OK; l++) {
                    HrtsFrameReport rep;
                    CHECK(report(ctx, next_frame - 1, l, &rep) == HRTS_RESULT_OK, "report: %s", hrts_last_error(ctx));
                    directs[d] += rep.output_direct != 0;
                    for (uint32_t p = 0; p < rep.pass_count; p++)
                        rewritten += d && strcmp(rep.passes[p].name, "primitive map: pixel texels") == 0;
                }
                if (d && modes[m] == HRTS_SHADOW_MODE_HARD && r == HRTS_RESULT_OK) {
                    /* the sun's final output is the engine's layer: it is read there, not back from the plugin */
                    static float one[PX];
                    CHECK(read_resource(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, one, sizeof one) == HRTS_RESULT_ERROR_INVALID_STATE &&
                              strstr(hrts_last_error(ctx), "directly"),
                          "a read-back of a final output written directly is refused: %s", hrts_last_error(ctx));
                }
                CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
            }
            out_img = copied;
            int differ = 0, differ_one_call = 0;
            for (int i = 0; i < N * PX; i++) differ += memcmp(&want[i], &got[i], sizeof(float)) != 0;
            if (!split) memcpy(one_call, got, sizeof one_call);
            for (int i = 0; i < N * PX; i++) differ_one_call += memcmp(&one_call[i], &got[i], sizeof(float)) != 0;
            const char *how = split == 2 ? "pass by pass" : split ? "split frame" : "one call";
            printf("  %s: pixel texels rewritten before %u ray traces, %d px differ from the one-call frame\n", how,
                   rewritten, differ_one_call);
            CHECK(differ_one_call == 0 && (split == 2 ? rewritten >= 1 : rewritten == 0),
                  "shared pixel texels: %u rewritten, %d px differ from one call", rewritten, differ_one_call);
            int lit = 0;
            for (int i = 2 * PX; i < 4 * PX; i++) lit += got[i] == 1.0f;
            printf("output written directly (%s, %s): %u of %d lights direct (%u with a copy), %d px differ from the copied "
                   "output, the unreached lights' layers %d of %d px lit\n",
                   modes[m] == HRTS_SHADOW_MODE_HARD ? "hard" : "hybrid", how, directs[1],
                   N, directs[0], differ, lit, 2 * PX);
            CHECK(directs[1] == N && directs[0] == 0 && differ == 0 && lit == 2 * PX,
                  "direct output: %u direct, %d px differ, %d lit", directs[1], differ, lit);
        }
    free_image(direct);
}

/* ---------- the engine's output format ---------- */
/* The visibility written into an R8_UNORM or R16_SFLOAT output image (a converting blit) equals the
 * R32_SFLOAT output to the format's precision: hard shadows exactly (0 and 1), the hybrid's penumbrae
 * within half a step of R8 and the rounding of a half float. A colour format the plugin does not write is
 * refused. */
static float half_to_float(uint16_t h) {
    int exponent = (h >> 10) & 31, mantissa = h & 1023;
    double v = exponent == 0 ? ldexp(mantissa, -24) : ldexp(mantissa | 1024, exponent - 25);
    return (float)((h & 0x8000) ? -v : v);
}

static void output_formats(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer();
    const uint32_t modes[2] = {HRTS_SHADOW_MODE_HARD, HRTS_SHADOW_MODE_HYBRID};
    static float reference[2][PX];
    for (int m = 0; m < 2; m++) {
        HrtsContext *ctx = create_context(vk, 1);
        HrtsTargets t = targets();
        CHECK(configure_all(ctx, 1, modes[m]) == HRTS_RESULT_OK && hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK &&
                  hrts_set_targets(ctx, &t) == HRTS_RESULT_OK && run_frame(ctx, reference[m]) == HRTS_RESULT_OK,
              "output formats: R32_SFLOAT frame: %s", hrts_last_error(ctx));
        CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    }
    const struct {
        VkFormat format;
        const char *name;
        size_t texel;
        double tolerance;
    } formats[] = {{VK_FORMAT_R8_UNORM, "R8_UNORM", 1, 0.5 / 255.0 + 1e-6}, {VK_FORMAT_R16_SFLOAT, "R16_SFLOAT", 2, 1.0 / 1024.0}};
    for (int k = 0; k < 2; k++) {
        VkFormatProperties props;
        vkGetPhysicalDeviceFormatProperties(phys, formats[k].format, &props);
        CHECK(props.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT, "%s: the device cannot blit into it",
              formats[k].name);
        for (int m = 0; m < 2; m++) {
            Img out = make_image(formats[k].format, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 1);
            HrtsContext *ctx = create_context(vk, 1);
            HrtsTargets t = targets();
            t.output_image = (uint64_t)(uintptr_t)out.image;
            t.output_layers = 1;
            t.output_format = (uint32_t)formats[k].format;
            HrtsResult r = configure_all(ctx, 1, modes[m]);
            if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
            if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
            Buf back = make_host_buffer(formats[k].texel * PX, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
            if (r == HRTS_RESULT_OK) {
                VkCommandBuffer cmd = begin();
                HrtsFrame f = frame(cmd, next_frame++);
                r = hrts_record_frame(ctx, &f);
                if (r == HRTS_RESULT_OK) {
                    VkBufferImageCopy region = frame_region(VK_IMAGE_ASPECT_COLOR_BIT, 1);
                    vkCmdCopyImageToBuffer(cmd, out.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, back.buffer, 1, &region);
                    host_read_barrier(cmd);
                }
                submit_and_wait(cmd);
            }
            CHECK(r == HRTS_RESULT_OK, "output %s: %s", formats[k].name, hrts_last_error(ctx));
            int beyond = 0, soft = 0;
            double worst = 0.0;
            for (int i = 0; i < PX && r == HRTS_RESULT_OK; i++) {
                float v = formats[k].texel == 1 ? ((uint8_t *)back.map)[i] / 255.0f : half_to_float(((uint16_t *)back.map)[i]);
                double d = fabs((double)v - reference[m][i]);
                if (d > worst) worst = d;
                beyond += d > (m == 0 ? 0.0 : formats[k].tolerance);
                soft += reference[m][i] > 0.0f && reference[m][i] < 1.0f;
            }
            printf("output %s, %s: %d soft pixels, largest difference from R32_SFLOAT %.6f, %d px beyond the format's precision\n",
                   formats[k].name, m == 0 ? "hard" : "hybrid", soft, worst, beyond);
            CHECK(r == HRTS_RESULT_OK && beyond == 0, "output %s (%s): %d px differ", formats[k].name, m == 0 ? "hard" : "hybrid",
                  beyond);
            free_buffer(back);
            CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
            free_image(out);
        }
    }
    HrtsContext *ctx = create_context(vk, 1);
    HrtsTargets t = targets();
    t.output_format = VK_FORMAT_R8G8B8A8_UNORM;
    CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_ERROR_INVALID_ENUM && strstr(hrts_last_error(ctx), "output_format"),
          "an RGBA8 output is refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
}

/* ---------- instances that move ---------- */
static HrtsContext *hard_lights_context(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g, const Emitter *lights,
                                       uint32_t n);

/* The engine moves the box every frame with one call (hrts_set_draw_transforms): the next frame rebuilds
 * the prim buffer (no pass is rebuilt) and its shadow is exact where the box now is; a frame without a move
 * keeps the prim buffer. Bad calls are refused. */
static void moving_instances(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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
static void base_vertex_draws(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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

/* ---------- the engine's normals as they are ---------- */
/* Normals as engines keep them: xyz in half floats, RGB10A2 or RGBA8 (unorm: [0, 1] for [-1, 1]),
 * octahedral in RG16 snorm, unorm or float or in RGB10A2, in world or view space, or no normal image at
 * all (the plugin derives the normal from depth). Each gives the exact hard shadow of a sun and of a point
 * light (0 mismatches outside near-edge pixels). */
static uint16_t float_to_half(float f) {
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    uint32_t sign = (x >> 16) & 0x8000u;
    int exponent = (int)((x >> 23) & 0xff) - 127 + 15;
    uint32_t mantissa = x & 0x7fffffu;
    if (exponent <= 0) {
        if (exponent < -10) return (uint16_t)sign;
        mantissa |= 0x800000u;
        uint32_t shift = (uint32_t)(14 - exponent);
        uint32_t half = mantissa >> shift;
        if ((mantissa >> (shift - 1)) & 1u) half++;
        return (uint16_t)(sign | half);
    }
    uint32_t half = sign | ((uint32_t)exponent << 10) | (mantissa >> 13);
    if (mantissa & 0x1000u) half++;
    return (uint16_t)half;
}

static void octahedral_encode(V3 n, double *ex, double *ey) {
    double l1 = fabs(n.x) + fabs(n.y) + fabs(n.z);
    double x = n.x / l1, y = n.y / l1;
    if (n.z < 0) {
        double ox = (1 - fabs(y)) * (x >= 0 ? 1 : -1), oy = (1 - fabs(x)) * (y >= 0 ? 1 : -1);
        x = ox;
        y = oy;
    }
    *ex = x;
    *ey = y;
}

static uint32_t unorm(double v, double max) { return (uint32_t)lround((v * 0.5 + 0.5) * max); }

enum { NORMAL_XYZ_RGBA16F, NORMAL_XYZ_RGB10A2, NORMAL_XYZ_RGBA8, NORMAL_OCT_RG16_SNORM, NORMAL_OCT_RG16_UNORM,
       NORMAL_OCT_RG16F, NORMAL_OCT_RGB10A2, NORMAL_NONE, NORMAL_CASES };

static void engine_normals(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    const struct {
        const char *name;
        VkFormat format;
        uint32_t encoding, space;
        size_t texel;
    } cases[NORMAL_CASES] = {
        [NORMAL_XYZ_RGBA16F] = {"xyz RGBA16F world", VK_FORMAT_R16G16B16A16_SFLOAT, HRTS_NORMAL_ENCODING_XYZ,
                                HRTS_NORMAL_SPACE_WORLD, 8},
        [NORMAL_XYZ_RGB10A2] = {"xyz RGB10A2 world", VK_FORMAT_A2B10G10R10_UNORM_PACK32, HRTS_NORMAL_ENCODING_XYZ,
                                HRTS_NORMAL_SPACE_WORLD, 4},
        [NORMAL_XYZ_RGBA8] = {"xyz RGBA8 view", VK_FORMAT_R8G8B8A8_UNORM, HRTS_NORMAL_ENCODING_XYZ,
                              HRTS_NORMAL_SPACE_VIEW, 4},
        [NORMAL_OCT_RG16_SNORM] = {"octahedral RG16 snorm world", VK_FORMAT_R16G16_SNORM,
                                   HRTS_NORMAL_ENCODING_OCTAHEDRAL, HRTS_NORMAL_SPACE_WORLD, 4},
        [NORMAL_OCT_RG16_UNORM] = {"octahedral RG16 unorm view", VK_FORMAT_R16G16_UNORM,
                                   HRTS_NORMAL_ENCODING_OCTAHEDRAL, HRTS_NORMAL_SPACE_VIEW, 4},
        [NORMAL_OCT_RG16F] = {"octahedral RG16F view", VK_FORMAT_R16G16_SFLOAT, HRTS_NORMAL_ENCODING_OCTAHEDRAL,
                              HRTS_NORMAL_SPACE_VIEW, 4},
        [NORMAL_OCT_RGB10A2] = {"octahedral RGB10A2 world", VK_FORMAT_A2B10G10R10_UNORM_PACK32,
                                HRTS_NORMAL_ENCODING_OCTAHEDRAL, HRTS_NORMAL_SPACE_WORLD, 4},
        [NORMAL_NONE] = {"none (derived from depth)", VK_FORMAT_UNDEFINED, HRTS_NORMAL_ENCODING_NONE,
                         HRTS_NORMAL_SPACE_WORLD, 0},
    };
    setup_camera(0.0);
    upload_gbuffer(); /* depth of this view */
    static float world[4 * PX];
    static float unused_depth[PX];
    draw_gbuffer(unused_depth, world);
    Emitter lights[2] = {directional(v3(0.45, -1.0, 0.2)), point(v3(0.9, 2.3, 0.7))};
    int failed_cases = 0;
    for (int c = 0; c < NORMAL_CASES; c++) {
        Img normal = {VK_NULL_HANDLE, VK_NULL_HANDLE};
        if (cases[c].texel > 0) {
            normal = make_image(cases[c].format, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 1);
            Buf staging = make_host_buffer(cases[c].texel * PX, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
            for (int i = 0; i < PX; i++) {
                V3 n = v3(world[4 * i], world[4 * i + 1], world[4 * i + 2]);
                if (cases[c].space == HRTS_NORMAL_SPACE_VIEW) n = v3(dot3(n, cam_r), dot3(n, cam_u), -dot3(n, cam_f));
                double ex, ey;
                octahedral_encode(world[4 * i + 3] != 0 ? n : v3(0, 0, 1), &ex, &ey);
                uint16_t *h = (uint16_t *)staging.map + 4 * i;
                uint32_t *u = (uint32_t *)staging.map + i;
                int16_t *sn = (int16_t *)staging.map + 2 * i;
                uint16_t *un = (uint16_t *)staging.map + 2 * i;
                switch (c) {
                case NORMAL_XYZ_RGBA16F:
                    h[0] = float_to_half((float)n.x), h[1] = float_to_half((float)n.y), h[2] = float_to_half((float)n.z),
                    h[3] = float_to_half(1.0f);
                    break;
                case NORMAL_XYZ_RGB10A2:
                    *u = unorm(n.x, 1023) | unorm(n.y, 1023) << 10 | unorm(n.z, 1023) << 20 | 3u << 30;
                    break;
                case NORMAL_XYZ_RGBA8:
                    *u = unorm(n.x, 255) | unorm(n.y, 255) << 8 | unorm(n.z, 255) << 16 | 255u << 24;
                    break;
                case NORMAL_OCT_RG16_SNORM:
                    sn[0] = (int16_t)lround(ex * 32767), sn[1] = (int16_t)lround(ey * 32767);
                    break;
                case NORMAL_OCT_RG16_UNORM:
                    un[0] = (uint16_t)unorm(ex, 65535), un[1] = (uint16_t)unorm(ey, 65535);
                    break;
                case NORMAL_OCT_RG16F:
                    un[0] = float_to_half((float)ex), un[1] = float_to_half((float)ey);
                    break;
                case NORMAL_OCT_RGB10A2:
                    *u = unorm(ex, 1023) | unorm(ey, 1023) << 10;
                    break;
                }
            }
            upload_image(normal, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_ASPECT_COLOR_BIT, staging,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
            free_buffer(staging);
        }
        HrtsContext *ctx = create_context(vk, 1);
        set_lights(lights, 2);
        HrtsTargets t = targets();
        t.normal_image = (uint64_t)(uintptr_t)normal.image;
        t.normal_usage = cases[c].texel > 0 ? VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT : 0;
        t.normal_format = (uint32_t)cases[c].format;
        t.normal_encoding = cases[c].encoding;
        t.normal_space = cases[c].space;
        HrtsResult r = configure_all(ctx, 2, HRTS_SHADOW_MODE_HARD);
        if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
        if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
        static float vis[2 * PX];
        if (r == HRTS_RESULT_OK) r = run_frame(ctx, vis);
        CHECK(r == HRTS_RESULT_OK, "normals %s: %s", cases[c].name, hrts_last_error(ctx));
        int total = 0;
        for (int l = 0; l < 2 && r == HRTS_RESULT_OK; l++) {
            int near_edge, shadowed, lit;
            int mismatches = count_mismatches(vis + l * PX, edge_tolerance(), &lights[l], &near_edge, &shadowed, &lit);
            printf("normals %s, %s: %d lit, %d shadowed, %d near-edge, %d mismatches\n", cases[c].name,
                   l == 0 ? "sun" : "point light", lit, shadowed, near_edge, mismatches);
            total += mismatches;
            CHECK(shadowed > 300, "normals %s: %d shadowed px", cases[c].name, shadowed);
        }
        CHECK(r == HRTS_RESULT_OK && total == 0, "normals %s: %d mismatches", cases[c].name, total);
        failed_cases += r != HRTS_RESULT_OK || total != 0;
        CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
        if (cases[c].texel > 0) free_image(normal);
    }
    printf("engine normals: %d encodings, %d failed\n", NORMAL_CASES, failed_cases);
    /* an xyz encoding in a two-channel image, and an unknown encoding, are refused */
    HrtsContext *ctx = create_context(vk, 1);
    HrtsTargets t = targets();
    t.normal_format = VK_FORMAT_R16G16_SNORM;
    t.normal_encoding = HRTS_NORMAL_ENCODING_XYZ;
    CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "normal_format"),
          "xyz in RG16 refused: %s", hrts_last_error(ctx));
    t.normal_encoding = 7;
    CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_ERROR_INVALID_ENUM && strstr(hrts_last_error(ctx), "normal_encoding"),
          "unknown normal encoding refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    set_lights(lights, 1);
}

/* ---------- quantized positions ---------- */
/* Positions as engines store them to save memory: four 16-bit floats, or 16-bit snorm or unorm with a
 * dequantization scale and offset (the plugin folds them into each draw's transform). Each gives the exact
 * shadow of the scene (its quantization moves a vertex by at most 1e-4 m, far inside the edge tolerance).
 * A vertex format the plugin does not read, and a scale with a zero axis, are refused. */
static void quantized_positions(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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

/* ---------- the engine's meshes as they are ---------- */
/* The scene as three meshes with buffers of their own: the first ground triangle (float3 positions, 16-bit
 * indices), the box (16-bit snorm positions with a dequantization, 32-bit indices, base vertex -4) and the
 * second ground triangle (float4 positions at an offset, 32-bit indices). The box's dequantization (scale
 * 0.5, offset (0, 1.1, 0)) puts its vertices at q = -1, 0 or 1, which every implementation decodes
 * exactly, so the meshes give the triangles of the one-mesh scene bit for bit. */
enum { SPLIT_MESHES = 3, BOX_VERTICES = 8 };
static const float BOX_SCALE[3] = {0.5f, 0.5f, 0.5f}, BOX_OFFSET[3] = {0.0f, 1.1f, 0.0f};

typedef struct {
    Buf vb[SPLIT_MESHES], ib[SPLIT_MESHES];
    HrtsDraw draws[SPLIT_MESHES];
    HrtsVulkanGeometry meshes[SPLIT_MESHES];
} SplitScene;

/* The box's vertices as snorm16 (w = 0) at `at`; `half`: the box deformed, its x < 0 half gone. */
static void box_snorm(uint16_t *at, int half) {
    for (int k = 0; k < BOX_VERTICES; k++) {
        for (int a = 0; a < 3; a++) {
            double p = positions[3 * (4 + k) + a];
            if (half && a == 0 && p < 0) p = 0.0;
            double q = (p - BOX_OFFSET[a]) / BOX_SCALE[a];
            at[4 * k + a] = (uint16_t)(int16_t)lround(fmax(-1.0, fmin(1.0, q)) * 32767.0);
        }
        at[4 * k + 3] = 0;
    }
}

static HrtsVulkanGeometry vulkan_mesh(Buf vb, VkDeviceSize vb_size, Buf ib, VkDeviceSize ib_size, const HrtsDraw *draw) {
    HrtsVulkanGeometry m;
    memset(&m, 0, sizeof m);
    m.struct_size = sizeof m;
    m.vertex_buffer = (uint64_t)(uintptr_t)vb.buffer;
    m.vertex_buffer_size = vb_size;
    m.index_buffer = (uint64_t)(uintptr_t)ib.buffer;
    m.index_buffer_size = ib_size;
    m.draws = draw;
    m.draw_count = 1;
    m.draw_stride = sizeof *draw;
    return m;
}

static void split_scene(SplitScene *s) {
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    memset(s, 0, sizeof *s);
    for (int i = 0; i < SPLIT_MESHES; i++) memcpy(s->draws[i].transform, identity, sizeof identity);
    /* mesh 0: ground triangle (0, 2, 1), float3, 16-bit indices at byte offset 4 */
    s->vb[0] = make_host_buffer(4 * 12, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    memcpy(s->vb[0].map, positions, 4 * 12);
    s->ib[0] = make_host_buffer(12, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    uint16_t *i16 = (uint16_t *)((char *)s->ib[0].map + 4);
    for (int k = 0; k < 3; k++) i16[k] = (uint16_t)indices[k];
    s->draws[0].index_count = 3;
    HrtsVulkanGeometry *m = &s->meshes[0];
    *m = vulkan_mesh(s->vb[0], 4 * 12, s->ib[0], 12, &s->draws[0]);
    m->vertex_stride = 12;
    m->vertex_count = 4;
    m->index_offset = 4;
    m->index_type = HRTS_INDEX_TYPE_UINT16;
    m->index_count = 3;
    const float ground0[6] = {-4, 0, -4, 4, 0, 4};
    memcpy(m->bounds, ground0, sizeof ground0);
    /* mesh 1: the box, snorm16 at byte offset 16, the scene's 32-bit indices (4..11) with base vertex -4 */
    s->vb[1] = make_host_buffer(16 + BOX_VERTICES * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    box_snorm((uint16_t *)((char *)s->vb[1].map + 16), 0);
    s->ib[1] = make_host_buffer(36 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    memcpy(s->ib[1].map, indices + 6, 36 * 4);
    s->draws[1].index_count = 36;
    s->draws[1].base_vertex = -4;
    m = &s->meshes[1];
    *m = vulkan_mesh(s->vb[1], 16 + BOX_VERTICES * 8, s->ib[1], 36 * 4, &s->draws[1]);
    m->vertex_offset = 16;
    m->vertex_stride = 8;
    m->vertex_count = BOX_VERTICES;
    m->index_type = HRTS_INDEX_TYPE_UINT32;
    m->index_count = 36;
    m->vertex_format = VK_FORMAT_R16G16B16A16_SNORM;
    memcpy(m->position_scale, BOX_SCALE, sizeof BOX_SCALE);
    memcpy(m->position_offset, BOX_OFFSET, sizeof BOX_OFFSET);
    for (int a = 0; a < 3; a++) {
        m->bounds[a] = (float)BOX_MIN[a];
        m->bounds[3 + a] = (float)BOX_MAX[a];
    }
    /* mesh 2: ground triangle (0, 3, 2), float4 at byte offset 32, 32-bit indices at byte offset 8 */
    s->vb[2] = make_host_buffer(32 + 4 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    float *f4 = (float *)((char *)s->vb[2].map + 32);
    for (int v = 0; v < 4; v++) {
        memcpy(f4 + 4 * v, positions + 3 * v, 12);
        f4[4 * v + 3] = 1.0f;
    }
    s->ib[2] = make_host_buffer(8 + 3 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    memcpy((char *)s->ib[2].map + 8, indices + 3, 3 * 4);
    s->draws[2].index_count = 3;
    m = &s->meshes[2];
    *m = vulkan_mesh(s->vb[2], 32 + 4 * 16, s->ib[2], 8 + 3 * 4, &s->draws[2]);
    m->vertex_offset = 32;
    m->vertex_stride = 16;
    m->vertex_count = 4;
    m->index_offset = 8;
    m->index_type = HRTS_INDEX_TYPE_UINT32;
    m->index_count = 3;
    const float ground1[6] = {-4, 0, -4, 4, 0, 4};
    memcpy(m->bounds, ground1, sizeof ground1);
}

static void free_split_scene(SplitScene *s) {
    for (int i = 0; i < SPLIT_MESHES; i++) {
        free_buffer(s->vb[i]);
        free_buffer(s->ib[i]);
    }
}

/* The same scene as one mesh (`engine_geometry`'s buffers) with the split scene's draws in the same prim
 * buffer order: the first ground triangle, the box, the second ground triangle. */
static HrtsDraw one_mesh_draws[SPLIT_MESHES];
static HrtsVulkanGeometry one_mesh_scene(Buf *vb, Buf *ib) {
    HrtsVulkanGeometry vg = engine_geometry(vb, ib);
    static const uint32_t first[SPLIT_MESHES] = {0, 6, 3}, count[SPLIT_MESHES] = {3, 36, 3};
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    for (int i = 0; i < SPLIT_MESHES; i++) {
        memset(&one_mesh_draws[i], 0, sizeof one_mesh_draws[i]);
        memcpy(one_mesh_draws[i].transform, identity, sizeof identity);
        one_mesh_draws[i].first_index = first[i];
        one_mesh_draws[i].index_count = count[i];
    }
    vg.draws = one_mesh_draws;
    vg.draw_count = SPLIT_MESHES;
    return vg;
}

/* A hard-shadow context of `frames_in_flight` frames for the sun, with `mesh_count` meshes and the targets. */
static HrtsContext *meshes_context(const HrtsVulkanDevice *vk, uint32_t frames_in_flight, const HrtsVulkanGeometry *meshes,
                                   uint32_t mesh_count) {
    HrtsContext *ctx = create_context(vk, frames_in_flight);
    HrtsTargets t = targets();
    CHECK(configure_all(ctx, 1, HRTS_SHADOW_MODE_HARD) == HRTS_RESULT_OK &&
              hrts_set_geometry_vulkan_meshes(ctx, meshes, mesh_count) == HRTS_RESULT_OK &&
              hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "meshes: setup: %s", hrts_last_error(ctx));
    return ctx;
}

/* The three meshes give the one-mesh scene's visibility bit for bit (and the exact shadow). Moving the box
 * (one draw of three, in mesh 1) rebuilds its 12 triangles alone, exactly where it now is, and as the one
 * mesh moved the same way; the same transforms again rebuild nothing. Bad lists are refused with a message
 * naming the mesh, and the context goes on as it was. */
static void engine_meshes(const HrtsVulkanDevice *vk) {
    enum { PX = W * H };
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer();
    SplitScene s;
    split_scene(&s);
    Buf one_vb, one_ib;
    HrtsVulkanGeometry one = one_mesh_scene(&one_vb, &one_ib);
    static float one_vis[PX], split_vis[PX], moved_vis[PX], one_moved_vis[PX], after_vis[PX];
    HrtsFrameReport rep;
    HrtsContext *ctx = meshes_context(vk, 2, &one, 1);
    CHECK(run_frame(ctx, one_vis) == HRTS_RESULT_OK, "meshes: one-mesh frame: %s", hrts_last_error(ctx));
    CHECK(hrts_set_geometry_vulkan_meshes(ctx, s.meshes, SPLIT_MESHES) == HRTS_RESULT_OK, "meshes: the list: %s",
          hrts_last_error(ctx));
    CHECK(run_frame(ctx, split_vis) == HRTS_RESULT_OK && report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK,
          "meshes: split frame: %s", hrts_last_error(ctx));
    uint32_t first_rebuilt = rep.prim_triangles_rebuilt;
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK && report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK,
          "meshes: second frame: %s", hrts_last_error(ctx));
    uint32_t kept_rebuilt = rep.prim_triangles_rebuilt, kept_status = rep.pass_status[HRTS_PASS_PRIM_BUFFER];
    int near_edge, shadowed, lit;
    int split_differ = differing(split_vis, one_vis, PX);
    int split_mismatches = count_mismatches(split_vis, edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
    printf("3 meshes (float3 + u16, snorm16 + u32 + base vertex, float4 + u32): %d px differ from the one-mesh scene, "
           "%d shadowed, %d mismatches with the exact shadow; triangles rebuilt: %u on the first frame, %u on the next (%s)\n",
           split_differ, shadowed, split_mismatches, first_rebuilt, kept_rebuilt,
           kept_status == HRTS_PASS_STATUS_UP_TO_DATE ? "up to date" : "NOT up to date");
    CHECK(split_differ == 0 && split_mismatches == 0 && shadowed > 300, "meshes: %d px differ, %d mismatches", split_differ,
          split_mismatches);
    CHECK(first_rebuilt == 14 && kept_rebuilt == 0 && kept_status == HRTS_PASS_STATUS_UP_TO_DATE,
          "meshes: %u then %u triangles rebuilt", first_rebuilt, kept_rebuilt);

    /* move the box: one transform per draw over all meshes, in mesh order */
    const double shift[3] = {0.7, 0.0, -0.4};
    float transforms[SPLIT_MESHES][16];
    for (int i = 0; i < SPLIT_MESHES; i++) memcpy(transforms[i], s.draws[i].transform, sizeof transforms[i]);
    for (int a = 0; a < 3; a++) transforms[1][12 + a] = (float)shift[a];
    CHECK(hrts_set_draw_transforms(ctx, SPLIT_MESHES, &transforms[0][0]) == HRTS_RESULT_OK, "meshes: move: %s",
          hrts_last_error(ctx));
    memcpy(box_shift, shift, sizeof box_shift);
    upload_gbuffer();
    CHECK(run_frame(ctx, moved_vis) == HRTS_RESULT_OK && report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK,
          "meshes: moved frame: %s", hrts_last_error(ctx));
    uint32_t moved_rebuilt = rep.prim_triangles_rebuilt, moved_status = rep.pass_status[HRTS_PASS_PRIM_BUFFER];
    int moved_mismatches = count_mismatches(moved_vis, edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
    int moved_changed = differing(moved_vis, split_vis, PX);
    CHECK(hrts_set_draw_transforms(ctx, SPLIT_MESHES, &transforms[0][0]) == HRTS_RESULT_OK &&
              run_frame(ctx, NULL) == HRTS_RESULT_OK && report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK,
          "meshes: the same transforms again: %s", hrts_last_error(ctx));
    uint32_t same_rebuilt = rep.prim_triangles_rebuilt;
    /* the one-mesh scene with the same draw moved */
    memcpy(one_mesh_draws[1].transform, transforms[1], sizeof transforms[1]);
    CHECK(hrts_set_geometry_vulkan(ctx, &one) == HRTS_RESULT_OK && run_frame(ctx, one_moved_vis) == HRTS_RESULT_OK,
          "meshes: one mesh moved: %s", hrts_last_error(ctx));
    int moved_differ = differing(moved_vis, one_moved_vis, PX);
    printf("moved box (draw 1 of 3): %u triangles rebuilt (prim buffer %s), %d px changed, %d shadowed, %d mismatches, "
           "%d px differ from the one mesh moved; the same transforms again rebuild %u\n",
           moved_rebuilt, moved_status == HRTS_PASS_STATUS_RAN ? "ran" : "did NOT run", moved_changed, shadowed,
           moved_mismatches, moved_differ, same_rebuilt);
    CHECK(moved_rebuilt == 12 && moved_status == HRTS_PASS_STATUS_RAN, "meshes: moving the box rebuilt %u triangles",
          moved_rebuilt);
    CHECK(moved_mismatches == 0 && moved_changed > 100 && moved_differ == 0 && shadowed > 300,
          "meshes: moved: %d mismatches, %d px changed, %d px differ from one mesh", moved_mismatches, moved_changed,
          moved_differ);
    CHECK(same_rebuilt == 0, "meshes: the same transforms again rebuilt %u triangles", same_rebuilt);

    /* bad lists: refused with a message naming the mesh; the geometry stays as it was */
    HrtsVulkanGeometry bad[SPLIT_MESHES];
    memcpy(bad, s.meshes, sizeof bad);
    bad[2].vertex_buffer_size = 32;
    HrtsResult r_small = hrts_set_geometry_vulkan_meshes(ctx, bad, SPLIT_MESHES);
    char small_msg[512];
    snprintf(small_msg, sizeof small_msg, "%s", hrts_last_error(ctx));
    memcpy(bad, s.meshes, sizeof bad);
    bad[1].vertex_format = VK_FORMAT_R8G8B8A8_SNORM;
    HrtsResult r_format = hrts_set_geometry_vulkan_meshes(ctx, bad, SPLIT_MESHES);
    char format_msg[512];
    snprintf(format_msg, sizeof format_msg, "%s", hrts_last_error(ctx));
    HrtsResult r_zero = hrts_set_geometry_vulkan_meshes(ctx, s.meshes, 0);
    HrtsResult r_null = hrts_set_geometry_vulkan_meshes(ctx, NULL, SPLIT_MESHES);
    printf("bad mesh lists: a too small vertex buffer: %s (%s); an 8-bit format: %s (%s); mesh_count 0: %s; NULL: %s\n",
           hrts_result_name(r_small), small_msg, hrts_result_name(r_format), format_msg, hrts_result_name(r_zero),
           hrts_result_name(r_null));
    CHECK(r_small == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(small_msg, "meshes[2]"), "meshes: too small: %s", small_msg);
    CHECK(r_format == HRTS_RESULT_ERROR_INVALID_ENUM && strstr(format_msg, "meshes[1]"), "meshes: format: %s", format_msg);
    CHECK(r_zero == HRTS_RESULT_ERROR_INVALID_ARGUMENT && r_null == HRTS_RESULT_ERROR_NULL_POINTER, "meshes: 0 / NULL");
    CHECK(run_frame(ctx, after_vis) == HRTS_RESULT_OK, "meshes: frame after the refused lists: %s", hrts_last_error(ctx));
    int after_differ = differing(after_vis, one_moved_vis, PX);
    CHECK(after_differ == 0, "meshes: after the refused lists %d px differ", after_differ);
    VK(vkDeviceWaitIdle(device));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    memset(box_shift, 0, sizeof box_shift);
    upload_gbuffer();
    free_split_scene(&s);
    free_buffer(one_vb);
    free_buffer(one_ib);
}

/* ---------- draw transforms: all or nothing ---------- */
/* A hrts_set_draw_transforms call that fails changes nothing. Transforms that are finite but overflow once
 * the box mesh's dequantization (scale 0.5, offset (0, 1.1, 0)) is applied are refused; the bounds of the
 * geometry call still hold, so the next frame, lit by a sun the plugin fits to them, records as before:
 * the same visibility bit for bit, the exact shadow, and no triangle rebuilt. */
static void draw_transforms_all_or_nothing(const HrtsVulkanDevice *vk) {
    enum { PX = W * H };
    setup_camera(0.0);
    Emitter sun = fitted_sun(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer();
    SplitScene s;
    split_scene(&s);
    static float before[PX], after[PX];
    HrtsContext *ctx = meshes_context(vk, 2, s.meshes, SPLIT_MESHES);
    CHECK(run_frame(ctx, before) == HRTS_RESULT_OK, "all or nothing: first frame: %s", hrts_last_error(ctx));
    float transforms[SPLIT_MESHES][16];
    for (int i = 0; i < SPLIT_MESHES; i++) memcpy(transforms[i], s.draws[i].transform, sizeof transforms[i]);
    /* the box's y axis and y translation 3e38: finite, but 1.1 * 3e38 + 3e38 once dequantized is not */
    transforms[1][5] = 3.0e38f;
    transforms[1][13] = 3.0e38f;
    HrtsResult r = hrts_set_draw_transforms(ctx, SPLIT_MESHES, &transforms[0][0]);
    char message[512];
    snprintf(message, sizeof message, "%s", hrts_last_error(ctx));
    HrtsResult next = run_frame(ctx, after);
    char next_message[512];
    snprintf(next_message, sizeof next_message, "%s", hrts_last_error(ctx));
    HrtsFrameReport rep;
    int rebuilt = next == HRTS_RESULT_OK && report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK
                      ? (int)rep.prim_triangles_rebuilt
                      : -1;
    int differ = next == HRTS_RESULT_OK ? differing(after, before, PX) : -1;
    int near_edge, shadowed, lit;
    int mismatches = count_mismatches(before, edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
    printf("draw transforms overflowing once dequantized: %s (%s); the next frame: %s, %d px differ from the frame "
           "before, %d triangles rebuilt, %d mismatches with the exact shadow\n",
           hrts_result_name(r), message, hrts_result_name(next), differ, rebuilt, mismatches);
    CHECK(r == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(message, "transform 1"), "all or nothing: %s (%s)",
          hrts_result_name(r), message);
    CHECK(next == HRTS_RESULT_OK, "all or nothing: the next frame: %s", next_message);
    CHECK(differ == 0 && rebuilt == 0, "all or nothing: %d px differ, %d triangles rebuilt", differ, rebuilt);
    CHECK(mismatches == 0 && shadowed > 300, "all or nothing: %d mismatches, %d shadowed", mismatches, shadowed);
    VK(vkDeviceWaitIdle(device));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    free_split_scene(&s);
}

/* ---------- a deforming mesh ---------- */
/* HrtsFrame::deformed is read by the call that begins the frame alone: the engine may free the array once
 * that call returned. A frame recorded in two calls (light space, then screen space) and one recorded pass by
 * pass, the array poisoned after the first call (as freed memory may be), give `want` exactly. */
static void deformed_read_once(HrtsContext *ctx, HrtsMeshVertices deformed, const float *want) {
    enum { PX = W * H };
    static float vis[PX];
    int differ[2] = {-1, -1};
    for (int one_by_one = 0; one_by_one < 2; one_by_one++) {
        HrtsMeshVertices *list = malloc(sizeof *list);
        *list = deformed;
        VkCommandBuffer cmd = begin();
        HrtsFrame f = frame(cmd, next_frame++);
        f.deformed = list;
        f.deformed_count = 1;
        HrtsResult r = hrts_record_passes(ctx, &f, one_by_one ? 1u << HRTS_PASS_PRIM_BUFFER : HRTS_PASS_MASK_LIGHT_SPACE);
        memset(list, 0xA5, sizeof *list);
        if (one_by_one) {
            for (uint32_t pass = HRTS_PASS_PRIM_BUFFER + 1; pass < HRTS_PASS_COUNT && r == HRTS_RESULT_OK; pass++)
                r = hrts_record_passes(ctx, &f, 1u << pass);
        } else if (r == HRTS_RESULT_OK) {
            r = hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE);
        }
        char message[512];
        snprintf(message, sizeof message, "%s", hrts_last_error(ctx));
        r = finish_frame(cmd, r, vis);
        free(list);
        CHECK(r == HRTS_RESULT_OK, "deformed array poisoned after the first call (%s): %s: %s",
              one_by_one ? "pass by pass" : "two calls", hrts_result_name(r), message);
        if (r == HRTS_RESULT_OK) differ[one_by_one] = differing(vis, want, PX);
    }
    printf("deformed array poisoned after the frame's first call: %d px differ (light/screen space), %d px (pass by pass)\n",
           differ[0], differ[1]);
    CHECK(differ[0] == 0 && differ[1] == 0, "deformed read once: %d / %d px differ", differ[0], differ[1]);
}

/* A vertex buffer's handle reused: the engine destroys a skinned buffer once the frame that read it
 * completed and creates one of the same size over other memory of its own block; the driver hands back the
 * same VkBuffer handle. The next frame, within frames_in_flight of the first, must read the new buffer (the
 * box deformed, B), not the destroyed one's memory (the box, A). `want` holds A's and B's visibility. */
static void reused_vertex_handle(HrtsContext *ctx, const float *want_a, const float *want_b) {
    enum { PX = W * H, TRIES = 64 };
    const VkDeviceSize size = BOX_VERTICES * 8;
    VkBufferCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = size;
    ci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer first;
    VK(vkCreateBuffer(device, &ci, NULL, &first));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, first, &req);
    /* the engine's memory block: region 0 holds the box (A), region 1 the box deformed (B) */
    VkDeviceSize region = (req.size + req.alignment - 1) / req.alignment * req.alignment;
    VkMemoryAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = 2 * region;
    ai.memoryTypeIndex =
        memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VkDeviceMemory block;
    VK(vkAllocateMemory(device, &ai, NULL, &block));
    void *map;
    VK(vkMapMemory(device, block, 0, 2 * region, 0, &map));
    box_snorm((uint16_t *)map, 0);
    box_snorm((uint16_t *)((char *)map + region), 1);
    VK(vkBindBufferMemory(device, first, block, 0));
    static float vis[PX];
    HrtsMeshVertices v = {1, (uint64_t)(uintptr_t)first, size, 0};
    VkCommandBuffer cmd = begin();
    HrtsFrame f = frame(cmd, next_frame++);
    f.deformed = &v;
    f.deformed_count = 1;
    HrtsResult r = finish_frame(cmd, hrts_record_frame(ctx, &f), vis);
    CHECK(r == HRTS_RESULT_OK, "reused handle: first frame: %s", hrts_last_error(ctx));
    int differ_a = differing(vis, want_a, PX);
    /* the frame completed (finish_frame waited for it): the buffer goes, others of its size come until one
     * gets its handle */
    const uint64_t handle = v.vertex_buffer;
    vkDestroyBuffer(device, first, NULL);
    VkBuffer tried[TRIES], again = VK_NULL_HANDLE;
    int n = 0;
    while (n < TRIES && again == VK_NULL_HANDLE) {
        VK(vkCreateBuffer(device, &ci, NULL, &tried[n]));
        if ((uint64_t)(uintptr_t)tried[n] == handle) again = tried[n];
        n++;
    }
    int differ_b = -1;
    if (again != VK_NULL_HANDLE) {
        VK(vkBindBufferMemory(device, again, block, region));
        cmd = begin();
        f = frame(cmd, next_frame++);
        f.deformed = &v;
        f.deformed_count = 1;
        r = finish_frame(cmd, hrts_record_frame(ctx, &f), vis);
        CHECK(r == HRTS_RESULT_OK, "reused handle: second frame: %s", hrts_last_error(ctx));
        differ_b = differing(vis, want_b, PX);
    }
    printf("reused vertex buffer handle: %s after %d buffers created; the frame before differs from the box in %d px, "
           "the frame after from the box deformed in %d px\n",
           again != VK_NULL_HANDLE ? "the handle came back" : "the handle did NOT come back", n, differ_a, differ_b);
    CHECK(again != VK_NULL_HANDLE, "reused handle: the handle never came back: the case was not tested");
    CHECK(differ_a == 0 && differ_b == 0, "reused handle: %d / %d px differ", differ_a, differ_b);
    for (int k = 0; k < n; k++) vkDestroyBuffer(device, tried[k], NULL);
    vkUnmapMemory(device, block);
    vkFreeMemory(device, block, NULL);
}

/* The engine skins the box into one vertex buffer per frame in flight (2): buffer A holds the box, buffer B
 * the box deformed (its x < 0 half gone). Frames give them in turn through HrtsFrame::deformed, two frames
 * pending on the GPU at once, with frames that deform nothing between. Each frame's visibility equals, bit
 * for bit, the same geometry given statically (the box mesh's own buffer holding A's or B's vertices), each
 * frame rebuilds the box's 12 triangles, and the frame after the last deformed one too (from the mesh's own
 * buffer); then nothing. Bad deformed lists are refused and record nothing. */
enum { DEFORM_FRAMES = 8 };
static void deforming_mesh(const HrtsVulkanDevice *vk) {
    enum { PX = W * H, IN_FLIGHT_2 = 2, NONE = -1, A = 0, B = 1 };
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer();
    SplitScene s;
    split_scene(&s);
    /* the engine's per-frame vertex buffers: A at byte offset 8, B at 0 */
    const VkDeviceSize offsets[2] = {8, 0};
    Buf skinned[2];
    for (int k = 0; k < 2; k++) {
        skinned[k] = make_host_buffer(offsets[k] + BOX_VERTICES * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        box_snorm((uint16_t *)((char *)skinned[k].map + offsets[k]), k == B);
    }
    HrtsMeshVertices given[2];
    for (int k = 0; k < 2; k++) {
        given[k].mesh = 1;
        given[k].vertex_buffer = (uint64_t)(uintptr_t)skinned[k].buffer;
        given[k].vertex_buffer_size = offsets[k] + BOX_VERTICES * 8;
        given[k].vertex_offset = offsets[k];
    }
    /* the expected visibility: the same geometry given statically, the box's own buffer A's or B's */
    static float expected[2][PX];
    for (int k = 0; k < 2; k++) {
        HrtsVulkanGeometry meshes[SPLIT_MESHES];
        memcpy(meshes, s.meshes, sizeof meshes);
        meshes[1].vertex_buffer = given[k].vertex_buffer;
        meshes[1].vertex_buffer_size = given[k].vertex_buffer_size;
        meshes[1].vertex_offset = given[k].vertex_offset;
        HrtsContext *ref = meshes_context(vk, 1, meshes, SPLIT_MESHES);
        CHECK(run_frame(ref, expected[k]) == HRTS_RESULT_OK, "deforming: static reference %d: %s", k, hrts_last_error(ref));
        CHECK(hrts_context_destroy(ref) == HRTS_RESULT_OK, "destroy");
    }
    int near_edge, shadowed, lit;
    int ref_mismatches = count_mismatches(expected[A], edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
    int deformation_changes = differing(expected[A], expected[B], PX);
    CHECK(ref_mismatches == 0 && deformation_changes > 100, "deforming: references: %d mismatches, B changes %d px",
          ref_mismatches, deformation_changes);

    HrtsContext *ctx = meshes_context(vk, IN_FLIGHT_2, s.meshes, SPLIT_MESHES);
    const int plan[DEFORM_FRAMES] = {A, B, A, B, NONE, B, NONE, NONE};
    /* the box's own buffer holds A's vertices: a frame deforming nothing shows A */
    const uint32_t want_rebuilt[DEFORM_FRAMES] = {14, 12, 12, 12, 12, 12, 12, 0};
    VkCommandBuffer cmds[IN_FLIGHT_2];
    VkFence fences[IN_FLIGHT_2];
    Buf back[IN_FLIGHT_2];
    int pending[IN_FLIGHT_2] = {-1, -1};
    frames_in_flight_ring(IN_FLIGHT_2, cmds, fences);
    for (int k = 0; k < IN_FLIGHT_2; k++) back[k] = make_host_buffer(sizeof(float) * PX, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    /* the first frame waits on a semaphore released once the second is submitted: both are pending then,
     * reading different vertex buffers */
    VkSemaphore hold = held_semaphore();
    int errors_before = validation_errors, both_pending = 0, differ = 0, differing_frames = 0, wrong_rebuilt = 0;
    uint64_t first = next_frame;
    static float vis[PX];
    for (int i = 0; i < DEFORM_FRAMES + IN_FLIGHT_2; i++) {
        int slot = i % IN_FLIGHT_2;
        if (pending[slot] >= 0) {
            int done = pending[slot];
            VK(vkWaitForFences(device, 1, &fences[slot], VK_TRUE, UINT64_MAX));
            VK(vkResetFences(device, 1, &fences[slot]));
            memcpy(vis, back[slot].map, sizeof vis);
            int d = differing(vis, expected[plan[done] == B ? B : A], PX);
            differ += d;
            differing_frames += d > 0;
            HrtsFrameReport rep;
            HrtsResult r = report(ctx, first + (uint64_t)done, 0, &rep);
            CHECK(r == HRTS_RESULT_OK, "deforming: report of frame %d: %s", done, hrts_last_error(ctx));
            printf("deforming mesh, frame %d (%s): %d px differ from the static geometry, %u triangles rebuilt\n", done,
                   plan[done] == NONE ? "own buffer" : plan[done] == A ? "buffer A" : "buffer B", d,
                   rep.prim_triangles_rebuilt);
            wrong_rebuilt += r != HRTS_RESULT_OK || rep.prim_triangles_rebuilt != want_rebuilt[done];
            pending[slot] = -1;
        }
        if (i >= DEFORM_FRAMES) continue;
        VK(vkResetCommandBuffer(cmds[slot], 0));
        VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VK(vkBeginCommandBuffer(cmds[slot], &bi));
        HrtsFrame f = frame(cmds[slot], next_frame++);
        f.light_stride = sizeof(HrtsLight);
        f.deformed_stride = sizeof(HrtsMeshVertices);
        if (plan[i] != NONE) {
            f.deformed = &given[plan[i]];
            f.deformed_count = 1;
        }
        CHECK(hrts_record_frame(ctx, &f) == HRTS_RESULT_OK, "deforming: frame %d: %s", i, hrts_last_error(ctx));
        record_output_readback(cmds[slot], back[slot], 1);
        if (i == 0) {
            submit_held(cmds[slot], hold, fences[slot]);
        } else {
            submit(cmds[slot], fences[slot]);
        }
        pending[slot] = i;
        if (i == 1) {
            both_pending = vkGetFenceStatus(device, fences[0]) == VK_NOT_READY &&
                           vkGetFenceStatus(device, fences[1]) == VK_NOT_READY;
            release_held(hold);
        }
    }
    int deform_errors = validation_errors - errors_before;
    printf("deforming mesh: %d frames, 2 in flight (%s pending together), %d px in %d frames differ from the static "
           "geometry, %d frames rebuilt other than the box's triangles, %d validation messages\n",
           DEFORM_FRAMES, both_pending ? "A and B" : "NOT", differ, differing_frames, wrong_rebuilt, deform_errors);
    CHECK(both_pending, "deforming: the first two frames were not pending together: the case was not tested");
    CHECK(differ == 0, "deforming: %d px in %d frames differ", differ, differing_frames);
    CHECK(wrong_rebuilt == 0, "deforming: %d frames rebuilt the wrong triangles", wrong_rebuilt);
    CHECK(deform_errors == 0, "deforming: %d validation errors", deform_errors);

    /* bad deformed lists: refused, nothing recorded, the context goes on */
    VkCommandBuffer cmd = begin();
    HrtsMeshVertices bad[2] = {given[B], given[B]};
    struct {
        const char *name;
        HrtsResult want;
        const char *names;
        uint32_t count;
    } cases[] = {
        {"mesh 3 of 3", HRTS_RESULT_ERROR_INVALID_ARGUMENT, "deformed[0]", 1},
        {"NULL with a count of 1", HRTS_RESULT_ERROR_NULL_POINTER, "deformed", 1},
        {"a buffer too small", HRTS_RESULT_ERROR_INVALID_ARGUMENT, "deformed[0]", 1},
        {"a NULL buffer", HRTS_RESULT_ERROR_NULL_POINTER, "deformed[0]", 1},
        {"mesh 1 twice", HRTS_RESULT_ERROR_INVALID_ARGUMENT, "deformed[1]", 2},
    };
    int refused = 0;
    for (int c = 0; c < 5; c++) {
        bad[0] = bad[1] = given[B];
        if (c == 0) bad[0].mesh = 3;
        if (c == 2) bad[0].vertex_buffer_size = BOX_VERTICES * 8 - 4;
        if (c == 3) bad[0].vertex_buffer = 0;
        HrtsFrame f = frame(cmd, next_frame);
        f.deformed = c == 1 ? NULL : bad;
        f.deformed_count = cases[c].count;
        HrtsResult r = hrts_record_frame(ctx, &f);
        const char *msg = hrts_last_error(ctx);
        printf("deformed %s: %s (%s)\n", cases[c].name, hrts_result_name(r), msg);
        int ok = r == cases[c].want && strstr(msg, cases[c].names) != NULL;
        CHECK(ok, "deformed %s: %s, \"%s\"", cases[c].name, hrts_result_name(r), msg);
        refused += ok;
    }
    submit_and_wait(cmd);
    VkCommandBuffer after = begin();
    HrtsFrame f = frame(after, next_frame++);
    f.deformed = &given[B];
    f.deformed_count = 1;
    CHECK(finish_frame(after, hrts_record_frame(ctx, &f), vis) == HRTS_RESULT_OK, "deforming: frame after: %s",
          hrts_last_error(ctx));
    int after_differ = differing(vis, expected[B], PX);
    printf("bad deformed lists: %d of 5 refused as they must; the frame after differs from the static geometry in %d px\n",
           refused, after_differ);
    CHECK(after_differ == 0, "deforming: the frame after the refused lists differs in %d px", after_differ);
    deformed_read_once(ctx, given[B], expected[B]);
    reused_vertex_handle(ctx, expected[A], expected[B]);
    VK(vkDeviceWaitIdle(device));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    vkDestroySemaphore(device, hold, NULL);
    for (int k = 0; k < IN_FLIGHT_2; k++) {
        vkDestroyFence(device, fences[k], NULL);
        free_buffer(back[k]);
        free_buffer(skinned[k]);
    }
    vkFreeCommandBuffers(device, pool, IN_FLIGHT_2, cmds);
    free_split_scene(&s);
}

/* ---------- misuse: a table of calls that must fail with a given result and a message ---------- */
/* Each case runs in table order on one context (some build on the state left by the ones before); after
 * each, the context must still answer. A successful call clears the last error, so a case that fails with
 * the right code but no message of its own fails. */
enum {
    CREATE_NULL_INFO, CREATE_NULL_OUT, CREATE_STRUCT_SIZE, CREATE_VERSION, CREATE_NULL_DEVICE, CREATE_NULL_GIPA,
    CREATE_DEVICE_STRUCT_SIZE, CREATE_FRAMES_IN_FLIGHT, CREATE_UNSUPPORTED_EXTENSION, CREATE_NO_SUCH_QUEUE_FAMILY,
    CREATE_NO_SUCH_QUEUE, CREATE_MISALIGNED_DEVICE, CREATE_MISALIGNED_EXTENSIONS, CREATE_NEWER_MINOR,
    CREATE_VERSION_5_0, CAPS_NULL_CONTEXT, CAPS_NULL_OUT, CAPS_STRUCT_SIZE, CONFIG_N_ZERO, CONFIG_N_ABSURD,
    CONFIG_BUDGET_ZERO, CONFIG_BUDGET_SMALL, CONFIG_FACES, CONFIG_BINNING, CONFIG_STRUCT_SIZE, CONFIG_OLDER_SMALLER, CONFIG_MISALIGNED, CONFIG_MODE,
    CONFIG_NAN_LIGHT_SIZE, CONFIG_NEGATIVE_WSS, CONFIG_PCF_TAPS, CONFIG_SHADOW_MAP_ZERO, CONFIG_DEFAULTS_NULL,
    CONFIG_FILTER, CONFIG_EXTRA_OUTPUT, CONFIG_FILTER_RADII, CONFIG_SLOPE_BIAS, LIGHTS_ZERO, LIGHTS_TOO_MANY,
    LIGHTS_NULL, LIGHTS_SECOND_INVALID, LIGHTS_MIXED_VERSIONS, GEOMETRY_NULL_POSITIONS, GEOMETRY_STRIDE, GEOMETRY_NAN, GEOMETRY_INDEX,
    GEOMETRY_NO_DRAWS, GEOMETRY_MISALIGNED_POSITIONS, GEOMETRY_MISALIGNED_INDICES, GEOMETRY_MISALIGNED_DRAWS,
    GEOMETRY_DRAW_STRIDE, TRANSFORMS_MISALIGNED, TRANSFORMS_COUNT, VULKAN_GEOMETRY_INDEX_TYPE, VULKAN_GEOMETRY_VERTEX_OFFSET_WRAP, VULKAN_GEOMETRY_INDEX_OFFSET_WRAP, MESHES_COUNT_ZERO,
    MESHES_NULL, MESHES_BUFFER_TOO_SMALL, TARGETS_ZERO_WIDTH, TARGETS_DEPTH_USAGE, TARGETS_OUTPUT_USAGE,
    TARGETS_NULL_NORMAL, TARGETS_ZERO_LAYERS, FRAME_ZERO_DIRECTION, FRAME_NAN_PROJECTION, FRAME_LIGHT_TYPE,
    FRAME_NULL_COMMAND_BUFFER, FRAME_STRUCT_SIZE, FRAME_NULL_LIGHTS, FRAME_LIGHT_COUNT_ZERO, FRAME_LIGHT_COUNT_OTHER,
    FRAME_MISALIGNED_LIGHTS, FRAME_NEWER_STRUCT_SIZE, FRAME_LIGHT_STRIDE, FRAME_DEFORMED_STRIDE,
    FRAME_DEFORMED_NULL, FRAME_DEFORMED_MESH,
    FRAME_INDEX_REPEATED, FRAME_INDEX_BACKWARDS, REPORT_STRUCT_SIZE, REPORT_OLD_FRAME, REPORT_NO_SUCH_LIGHT,
    REPORT_NOT_COMPLETED, PASSES_EMPTY_MASK, PASSES_UNKNOWN_BIT, PASSES_RAY_TRACE_FIRST, PASSES_CAMERA_MOVED,
    PASSES_COPY_TOO_EARLY, PASSES_DEPTH_LAYOUT, REPORT_HALF_RECORDED, READBACK_HALF_RECORDED, READBACK_UNKNOWN,
    READBACK_NOT_ALLOCATED, READBACK_TOO_SMALL, READBACK_NULL_BUFFER, READBACK_NO_SUCH_LIGHT, INFO_UNKNOWN,
    INFO_NO_SUCH_LIGHT, FRAME_MORE_LIGHTS_THAN_LAYERS, USE_AFTER_DESTROY, USE_AFTER_SLOT_REUSED, DOUBLE_DESTROY,
    FORGED_HANDLE, CALLBACKS_TOO_LATE, MISUSE_CASES
};

static const struct {
    const char *name;
    HrtsResult want;
} MISUSE[MISUSE_CASES] = {
    [CREATE_NULL_INFO] = {"create(NULL info)", HRTS_RESULT_ERROR_NULL_POINTER},
    [CREATE_NULL_OUT] = {"create(NULL out)", HRTS_RESULT_ERROR_NULL_POINTER},
    [CREATE_STRUCT_SIZE] = {"create(wrong struct_size)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [CREATE_VERSION] = {"create(other major version)", HRTS_RESULT_ERROR_VERSION},
    [CREATE_NULL_DEVICE] = {"create(NULL VkDevice)", HRTS_RESULT_ERROR_NULL_POINTER},
    [CREATE_NULL_GIPA] = {"create(NULL vkGetInstanceProcAddr)", HRTS_RESULT_ERROR_NULL_POINTER},
    [CREATE_DEVICE_STRUCT_SIZE] = {"create(wrong HrtsVulkanDevice size)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [CREATE_FRAMES_IN_FLIGHT] = {"create(9 frames in flight)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CREATE_UNSUPPORTED_EXTENSION] = {"create(claims an extension the device lacks)", HRTS_RESULT_ERROR_UNSUPPORTED},
    [CREATE_NO_SUCH_QUEUE_FAMILY] = {"create(queue family 99)", HRTS_RESULT_ERROR_UNSUPPORTED},
    [CREATE_NO_SUCH_QUEUE] = {"create(queue 7 of a one-queue family)", HRTS_RESULT_ERROR_UNSUPPORTED},
    [CREATE_MISALIGNED_DEVICE] = {"create(misaligned HrtsVulkanDevice)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CREATE_MISALIGNED_EXTENSIONS] = {"create(misaligned extension names)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CREATE_NEWER_MINOR] = {"create(a newer minor version than the library's)", HRTS_RESULT_ERROR_VERSION},
    [CREATE_VERSION_5_0] = {"create(API 5.0)", HRTS_RESULT_ERROR_VERSION},
    [CAPS_NULL_CONTEXT] = {"capabilities(NULL context)", HRTS_RESULT_ERROR_NULL_POINTER},
    [CAPS_NULL_OUT] = {"capabilities(NULL out)", HRTS_RESULT_ERROR_NULL_POINTER},
    [CAPS_STRUCT_SIZE] = {"capabilities(wrong size)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [CONFIG_N_ZERO] = {"configure(N = 0)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_N_ABSURD] = {"configure(absurd N)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_BUDGET_ZERO] = {"configure(entry budget 0)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_BUDGET_SMALL] = {"configure(entry budget below 4 KiB)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_FACES] = {"configure(unknown faces)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [CONFIG_BINNING] = {"configure(unknown binning path)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [CONFIG_STRUCT_SIZE] = {"configure(wrong size)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [CONFIG_OLDER_SMALLER] = {"configure(an older, 8-byte HrtsConfig)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [CONFIG_MISALIGNED] = {"configure(misaligned HrtsConfig)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_MODE] = {"configure(unknown mode)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [CONFIG_NAN_LIGHT_SIZE] = {"configure(NaN light size)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_NEGATIVE_WSS] = {"configure(negative WSS)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_PCF_TAPS] = {"configure(0 PCF taps)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_SHADOW_MAP_ZERO] = {"configure(0 shadow map)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_DEFAULTS_NULL] = {"config_defaults(NULL)", HRTS_RESULT_ERROR_NULL_POINTER},
    [CONFIG_FILTER] = {"configure(unknown PCSS filter)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [CONFIG_EXTRA_OUTPUT] = {"configure(unknown extra output)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [CONFIG_FILTER_RADII] = {"configure(min filter radius > max)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [CONFIG_SLOPE_BIAS] = {"configure(infinite slope bias)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [LIGHTS_ZERO] = {"configure_lights(0 lights)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [LIGHTS_TOO_MANY] = {"configure_lights(HRTS_MAX_LIGHTS + 1)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [LIGHTS_NULL] = {"configure_lights(NULL configs)", HRTS_RESULT_ERROR_NULL_POINTER},
    [LIGHTS_SECOND_INVALID] = {"configure_lights(second light's mode unknown)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [LIGHTS_MIXED_VERSIONS] = {"configure_lights(a 5.4 HrtsConfig after a current one)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [GEOMETRY_NULL_POSITIONS] = {"geometry(NULL positions)", HRTS_RESULT_ERROR_NULL_POINTER},
    [GEOMETRY_STRIDE] = {"geometry(stride 6)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [GEOMETRY_NAN] = {"geometry(NaN vertex)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [GEOMETRY_INDEX] = {"geometry(index out of range)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [GEOMETRY_NO_DRAWS] = {"geometry(no draws)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [GEOMETRY_MISALIGNED_POSITIONS] = {"geometry(misaligned positions)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [GEOMETRY_MISALIGNED_INDICES] = {"geometry(misaligned indices)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [GEOMETRY_MISALIGNED_DRAWS] = {"geometry(misaligned draws)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [GEOMETRY_DRAW_STRIDE] = {"geometry(draw_stride 72, the HrtsDraw of no version read)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [TRANSFORMS_MISALIGNED] = {"draw transforms(misaligned)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [TRANSFORMS_COUNT] = {"draw transforms(3 for 2 draws)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [VULKAN_GEOMETRY_INDEX_TYPE] = {"vulkan geometry(unknown index type)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [VULKAN_GEOMETRY_VERTEX_OFFSET_WRAP] = {"vulkan geometry(vertex offset UINT64_MAX - 3)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [VULKAN_GEOMETRY_INDEX_OFFSET_WRAP] = {"vulkan geometry(index offset UINT64_MAX - 3)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [MESHES_COUNT_ZERO] = {"vulkan meshes(mesh_count 0)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [MESHES_NULL] = {"vulkan meshes(NULL meshes)", HRTS_RESULT_ERROR_NULL_POINTER},
    [MESHES_BUFFER_TOO_SMALL] = {"vulkan meshes(meshes[2]'s vertex buffer too small)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [TARGETS_ZERO_WIDTH] = {"targets(zero width)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [TARGETS_DEPTH_USAGE] = {"targets(depth not SAMPLED)", HRTS_RESULT_ERROR_IMAGE_USAGE},
    [TARGETS_OUTPUT_USAGE] = {"targets(output not TRANSFER_DST)", HRTS_RESULT_ERROR_IMAGE_USAGE},
    [TARGETS_NULL_NORMAL] = {"targets(NULL normal image)", HRTS_RESULT_ERROR_NULL_POINTER},
    [TARGETS_ZERO_LAYERS] = {"targets(0 output layers)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_ZERO_DIRECTION] = {"frame(zero light direction)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_NAN_PROJECTION] = {"frame(NaN projection)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_LIGHT_TYPE] = {"frame(unknown light type)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [FRAME_NULL_COMMAND_BUFFER] = {"frame(NULL command buffer)", HRTS_RESULT_ERROR_NULL_POINTER},
    [FRAME_STRUCT_SIZE] = {"frame(wrong size)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [FRAME_NULL_LIGHTS] = {"frame(NULL lights)", HRTS_RESULT_ERROR_NULL_POINTER},
    [FRAME_LIGHT_COUNT_ZERO] = {"frame(0 lights)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_LIGHT_COUNT_OTHER] = {"frame(2 lights, 1 configured)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_MISALIGNED_LIGHTS] = {"frame(misaligned lights)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_NEWER_STRUCT_SIZE] = {"frame(a newer, larger HrtsFrame)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [FRAME_LIGHT_STRIDE] = {"frame(light_stride 104)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [FRAME_DEFORMED_STRIDE] = {"frame(deformed_stride 40)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [FRAME_DEFORMED_NULL] = {"frame(deformed NULL, deformed_count 1)", HRTS_RESULT_ERROR_NULL_POINTER},
    [FRAME_DEFORMED_MESH] = {"frame(deformed mesh 1 of 1)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_INDEX_REPEATED] = {"frame(index of the last frame again)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_INDEX_BACKWARDS] = {"frame(index going back)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [REPORT_STRUCT_SIZE] = {"report(wrong size)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [REPORT_OLD_FRAME] = {"report(frame no longer kept)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [REPORT_NO_SUCH_LIGHT] = {"report(light 5 of 1)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [REPORT_NOT_COMPLETED] = {"report(frame recorded, not submitted)", HRTS_RESULT_NOT_READY},
    [PASSES_EMPTY_MASK] = {"passes(empty mask)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [PASSES_UNKNOWN_BIT] = {"passes(unknown pass bit)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [PASSES_RAY_TRACE_FIRST] = {"passes(ray trace without the frame's primitive map)", HRTS_RESULT_ERROR_INVALID_STATE},
    [PASSES_CAMERA_MOVED] = {"passes(camera moved within a frame)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [PASSES_COPY_TOO_EARLY] = {"passes(output copy before the ray trace)", HRTS_RESULT_ERROR_INVALID_STATE},
    [PASSES_DEPTH_LAYOUT] = {"passes(undefined depth layout)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [REPORT_HALF_RECORDED] = {"report(frame half recorded)", HRTS_RESULT_NOT_READY},
    [READBACK_HALF_RECORDED] = {"readback(frame half recorded)", HRTS_RESULT_ERROR_INVALID_STATE},
    [READBACK_UNKNOWN] = {"readback(unknown resource)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [READBACK_NOT_ALLOCATED] = {"readback(resource the mode does not allocate)", HRTS_RESULT_ERROR_INVALID_STATE},
    [READBACK_TOO_SMALL] = {"readback(buffer too small)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [READBACK_NULL_BUFFER] = {"readback(NULL buffer)", HRTS_RESULT_ERROR_NULL_POINTER},
    [READBACK_NO_SUCH_LIGHT] = {"readback(light 3 of 1)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [INFO_UNKNOWN] = {"resource info(unknown resource)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [INFO_NO_SUCH_LIGHT] = {"resource info(light 2 of 1)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [FRAME_MORE_LIGHTS_THAN_LAYERS] = {"frame(2 lights, 1 output layer)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
    [USE_AFTER_DESTROY] = {"use after destroy", HRTS_RESULT_ERROR_INVALID_CONTEXT},
    [USE_AFTER_SLOT_REUSED] = {"use after destroy, the slot reused by a new context", HRTS_RESULT_ERROR_INVALID_CONTEXT},
    [DOUBLE_DESTROY] = {"double destroy", HRTS_RESULT_ERROR_INVALID_CONTEXT},
    [FORGED_HANDLE] = {"a handle never returned", HRTS_RESULT_ERROR_INVALID_CONTEXT},
    [CALLBACKS_TOO_LATE] = {"allocation callbacks after the plugin allocated", HRTS_RESULT_ERROR_INVALID_STATE},
};

/* State shared by the misuse cases. */
typedef struct {
    HrtsContext *ctx;
    const HrtsVulkanDevice *vk;
    VkCommandBuffer cmd; /* recording, submitted at the end */
    HrtsContext *other;  /* a second context */
    HrtsContext *gone;   /* a destroyed context */
    HrtsContext *fresh;  /* a context created after `gone` was destroyed */
} Misuse;

/* A copy of `bytes` bytes at `from` in `storage` (of `bytes` + 16 bytes), at an address that is no multiple of
 * `alignment`: what a caller's misaligned pointer points at. */
static const void *misaligned_copy(unsigned char *storage, const void *from, size_t bytes, size_t alignment) {
    unsigned char *at = storage + 1;
    while ((uintptr_t)at % alignment == 0) at++;
    memcpy(at, from, bytes);
    return at;
}

static HrtsResult misuse_call(int id, Misuse *m) {
    static float scratch[W * H];
    HrtsContext *ctx = m->ctx;
    HrtsConfig cfg = config(HRTS_SHADOW_MODE_HARD), c = cfg;
    HrtsConfig two[2] = {cfg, cfg};
    HrtsCapabilities caps;
    memset(&caps, 0, sizeof caps);
    caps.struct_size = sizeof caps;
    HrtsContextCreateInfo ci;
    memset(&ci, 0, sizeof ci);
    ci.struct_size = sizeof ci;
    ci.api_version = HRTS_API_VERSION;
    ci.vulkan = m->vk;
    HrtsVulkanDevice bad = *m->vk;
    HrtsContext *none = NULL;
    HrtsCpuGeometry g = cpu_geometry();
    HrtsTargets t = targets();
    HrtsFrame f = frame(m->cmd, next_frame);
    HrtsLight lights[2] = {c_lights[0], c_lights[0]};
    HrtsFrameReport rep;
    HrtsResourceInfo info;
    memset(&info, 0, sizeof info);
    info.struct_size = sizeof info;
    static const char *fake_extension[] = {"VK_HRTS_no_such_extension"};
    switch (id) {
    case CREATE_NULL_INFO: return hrts_context_create(NULL, &none);
    case CREATE_NULL_OUT: return hrts_context_create(&ci, NULL);
    case CREATE_STRUCT_SIZE: ci.struct_size -= 4; return hrts_context_create(&ci, &none);
    case CREATE_VERSION: ci.api_version += 1u << 22; return hrts_context_create(&ci, &none);
    case CREATE_NEWER_MINOR: ci.api_version += 1u << 12; return hrts_context_create(&ci, &none);
    case CREATE_VERSION_5_0: ci.api_version = 5u << 22; return hrts_context_create(&ci, &none);
    case CREATE_NULL_DEVICE: bad.device = 0; ci.vulkan = &bad; return hrts_context_create(&ci, &none);
    case CREATE_NULL_GIPA: bad.get_instance_proc_addr = NULL; ci.vulkan = &bad; return hrts_context_create(&ci, &none);
    case CREATE_DEVICE_STRUCT_SIZE: bad.struct_size = 8; ci.vulkan = &bad; return hrts_context_create(&ci, &none);
    case CREATE_FRAMES_IN_FLIGHT: ci.frames_in_flight = HRTS_MAX_FRAMES_IN_FLIGHT + 1; return hrts_context_create(&ci, &none);
    case CREATE_UNSUPPORTED_EXTENSION:
        bad.enabled_extensions = fake_extension;
        bad.enabled_extension_count = 1;
        ci.vulkan = &bad;
        return hrts_context_create(&ci, &none);
    case CREATE_NO_SUCH_QUEUE_FAMILY: bad.queue_family_index = 99; ci.vulkan = &bad; return hrts_context_create(&ci, &none);
    case CREATE_NO_SUCH_QUEUE: bad.queue_index = 7; ci.vulkan = &bad; return hrts_context_create(&ci, &none);
    case CREATE_MISALIGNED_DEVICE: {
        static unsigned char storage[sizeof(HrtsVulkanDevice) + 16];
        ci.vulkan = misaligned_copy(storage, m->vk, sizeof *m->vk, sizeof(void *));
        return hrts_context_create(&ci, &none);
    }
    case CREATE_MISALIGNED_EXTENSIONS: {
        static unsigned char storage[sizeof(char *) + 16];
        bad.enabled_extensions = misaligned_copy(storage, fake_extension, sizeof(char *), sizeof(char *));
        bad.enabled_extension_count = 1;
        ci.vulkan = &bad;
        return hrts_context_create(&ci, &none);
    }
    case CAPS_NULL_CONTEXT: return hrts_get_capabilities(NULL, &caps);
    case CAPS_NULL_OUT: return hrts_get_capabilities(ctx, NULL);
    case CAPS_STRUCT_SIZE: caps.struct_size = 4; return hrts_get_capabilities(ctx, &caps);
    case CONFIG_N_ZERO: c.map_size = 0; return hrts_configure(ctx, &c);
    case CONFIG_N_ABSURD: c.map_size = 1u << 30; return hrts_configure(ctx, &c);
    case CONFIG_BUDGET_ZERO: c.map_entry_budget_kib = 0; return hrts_configure(ctx, &c);
    case CONFIG_BUDGET_SMALL: c.map_entry_budget_kib = 3; return hrts_configure(ctx, &c);
    case CONFIG_FACES: c.faces = 7; return hrts_configure(ctx, &c);
    case CONFIG_BINNING: c.binning_path = 99; return hrts_configure(ctx, &c);
    case CONFIG_STRUCT_SIZE: c.struct_size = 3; return hrts_configure(ctx, &c);
    case CONFIG_OLDER_SMALLER: {
        /* a caller built against a version whose HrtsConfig was 8 bytes: only those bytes exist */
        uint32_t *older = malloc(8);
        older[0] = 8;
        older[1] = HRTS_SHADOW_MODE_HARD;
        HrtsResult r = hrts_configure(ctx, (const HrtsConfig *)(void *)older);
        free(older);
        return r;
    }
    case CONFIG_MISALIGNED: {
        static unsigned char storage[sizeof(HrtsConfig) + 16];
        return hrts_configure(ctx, misaligned_copy(storage, &c, sizeof c, sizeof(uint32_t))); /* 4-byte fields */
    }
    case CONFIG_MODE: c.mode = 9; return hrts_configure(ctx, &c);
    case CONFIG_NAN_LIGHT_SIZE: c.pcss_angular_radius = NAN; return hrts_configure(ctx, &c);
    case CONFIG_NEGATIVE_WSS: c.hybrid_world_space_scale = -1.0f; return hrts_configure(ctx, &c);
    case CONFIG_PCF_TAPS: c.pcss_pcf_taps = 0; return hrts_configure(ctx, &c);
    case CONFIG_SHADOW_MAP_ZERO: c.shadow_map_size = 0; return hrts_configure(ctx, &c);
    case CONFIG_DEFAULTS_NULL: return hrts_config_defaults(NULL);
    case CONFIG_FILTER: c.pcss_filter = 5; return hrts_configure(ctx, &c);
    case CONFIG_EXTRA_OUTPUT: c.extra_outputs = 1u << 20; return hrts_configure(ctx, &c);
    case CONFIG_FILTER_RADII: c.pcss_min_filter_radius = 64.0f; return hrts_configure(ctx, &c);
    case CONFIG_SLOPE_BIAS: c.shadow_map_slope_bias = INFINITY; return hrts_configure(ctx, &c);
    case LIGHTS_ZERO: return hrts_configure_lights(ctx, 0, two);
    case LIGHTS_TOO_MANY: return hrts_configure_lights(ctx, HRTS_MAX_LIGHTS + 1, two);
    case LIGHTS_NULL: return hrts_configure_lights(ctx, 2, NULL);
    case LIGHTS_SECOND_INVALID: two[1].mode = 9; return hrts_configure_lights(ctx, 2, two);
    case LIGHTS_MIXED_VERSIONS: two[1].struct_size = 108; return hrts_configure_lights(ctx, 2, two);
    case GEOMETRY_NULL_POSITIONS: g.positions = NULL; return hrts_set_geometry_cpu(ctx, &g);
    case GEOMETRY_STRIDE: g.vertex_stride = 6; return hrts_set_geometry_cpu(ctx, &g);
    case GEOMETRY_NAN: {
        float nan_positions[36];
        memcpy(nan_positions, positions, sizeof positions);
        nan_positions[13] = NAN;
        g.positions = nan_positions;
        return hrts_set_geometry_cpu(ctx, &g);
    }
    case GEOMETRY_INDEX: {
        uint32_t bad_indices[42];
        memcpy(bad_indices, indices, sizeof indices);
        bad_indices[5] = 1000;
        g.indices = bad_indices;
        return hrts_set_geometry_cpu(ctx, &g);
    }
    case GEOMETRY_NO_DRAWS: g.draw_count = 0; return hrts_set_geometry_cpu(ctx, &g);
    case GEOMETRY_MISALIGNED_POSITIONS: {
        static unsigned char storage[sizeof positions + 16];
        g.positions = misaligned_copy(storage, positions, sizeof positions, sizeof(float));
        return hrts_set_geometry_cpu(ctx, &g);
    }
    case GEOMETRY_MISALIGNED_INDICES: {
        static unsigned char storage[sizeof indices + 16];
        g.indices = misaligned_copy(storage, indices, sizeof indices, sizeof(uint32_t));
        return hrts_set_geometry_cpu(ctx, &g);
    }
    case GEOMETRY_MISALIGNED_DRAWS: {
        static unsigned char storage[sizeof draws + 16];
        g.draws = misaligned_copy(storage, draws, sizeof draws, sizeof(float));
        return hrts_set_geometry_cpu(ctx, &g);
    }
    case GEOMETRY_DRAW_STRIDE: g.draw_stride = 72; return hrts_set_geometry_cpu(ctx, &g);
    case TRANSFORMS_MISALIGNED:
    case TRANSFORMS_COUNT: {
        static float transforms[3][16];
        static unsigned char storage[sizeof transforms + 16];
        for (int i = 0; i < 3; i++) memcpy(transforms[i], draws[0].transform, sizeof transforms[i]);
        if (id == TRANSFORMS_COUNT) return hrts_set_draw_transforms(ctx, 3, &transforms[0][0]);
        return hrts_set_draw_transforms(ctx, 2, misaligned_copy(storage, transforms, sizeof transforms, sizeof(float)));
    }
    case VULKAN_GEOMETRY_INDEX_TYPE: {
        HrtsVulkanGeometry vg = fake_vulkan_geometry(&g);
        vg.index_type = 5;
        return hrts_set_geometry_vulkan(ctx, &vg);
    }
    case VULKAN_GEOMETRY_VERTEX_OFFSET_WRAP:
    case VULKAN_GEOMETRY_INDEX_OFFSET_WRAP: {
        /* offsets whose end wraps past 2^64 must fail the bounds check, not pass it */
        HrtsVulkanGeometry vg = fake_vulkan_geometry(&g);
        if (id == VULKAN_GEOMETRY_VERTEX_OFFSET_WRAP)
            vg.vertex_offset = UINT64_MAX - 3;
        else
            vg.index_offset = UINT64_MAX - 3;
        return hrts_set_geometry_vulkan(ctx, &vg);
    }
    case MESHES_COUNT_ZERO:
    case MESHES_NULL:
    case MESHES_BUFFER_TOO_SMALL: {
        HrtsVulkanGeometry meshes[3] = {fake_vulkan_geometry(&g), fake_vulkan_geometry(&g), fake_vulkan_geometry(&g)};
        meshes[2].vertex_buffer_size = 8;
        if (id == MESHES_COUNT_ZERO) return hrts_set_geometry_vulkan_meshes(ctx, meshes, 0);
        if (id == MESHES_NULL) return hrts_set_geometry_vulkan_meshes(ctx, NULL, 3);
        HrtsResult r = hrts_set_geometry_vulkan_meshes(ctx, meshes, 3);
        return r == HRTS_RESULT_OK || strstr(hrts_last_error(ctx), "meshes[2]") ? r : HRTS_RESULT_ERROR_INTERNAL;
    }
    case TARGETS_ZERO_WIDTH: t.width = 0; return hrts_set_targets(ctx, &t);
    case TARGETS_DEPTH_USAGE: t.depth_usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT; return hrts_set_targets(ctx, &t);
    case TARGETS_OUTPUT_USAGE: t.output_usage = VK_IMAGE_USAGE_SAMPLED_BIT; return hrts_set_targets(ctx, &t);
    case TARGETS_NULL_NORMAL: t.normal_image = 0; return hrts_set_targets(ctx, &t);
    case TARGETS_ZERO_LAYERS: t.output_layers = 0; return hrts_set_targets(ctx, &t);
    case FRAME_ZERO_DIRECTION: lights[0].direction[0] = lights[0].direction[1] = lights[0].direction[2] = 0;
        f.lights = lights;
        return hrts_record_frame(ctx, &f);
    case FRAME_NAN_PROJECTION: f.proj[5] = NAN; return hrts_record_frame(ctx, &f);
    case FRAME_LIGHT_TYPE: lights[0].light_type = 7; f.lights = lights; return hrts_record_frame(ctx, &f);
    case FRAME_NULL_COMMAND_BUFFER: f.command_buffer = 0; return hrts_record_frame(ctx, &f);
    case FRAME_STRUCT_SIZE: f.struct_size = 12; return hrts_record_frame(ctx, &f);
    case FRAME_NULL_LIGHTS: f.lights = NULL; return hrts_record_frame(ctx, &f);
    case FRAME_LIGHT_COUNT_ZERO: f.light_count = 0; return hrts_record_frame(ctx, &f);
    case FRAME_LIGHT_COUNT_OTHER: f.lights = lights; f.light_count = 2; return hrts_record_frame(ctx, &f);
    case FRAME_NEWER_STRUCT_SIZE: f.struct_size = sizeof f + 8; return hrts_record_frame(ctx, &f);
    case FRAME_LIGHT_STRIDE: f.light_stride = sizeof(HrtsLight) + 4; return hrts_record_frame(ctx, &f);
    case FRAME_DEFORMED_STRIDE: {
        HrtsMeshVertices v = {0, 1, 1024, 0};
        f.deformed = &v;
        f.deformed_count = 1;
        f.deformed_stride = 40;
        return hrts_record_frame(ctx, &f);
    }
    case FRAME_MISALIGNED_LIGHTS: {
        static unsigned char storage[sizeof(HrtsLight) + 16];
        f.lights = misaligned_copy(storage, &c_lights[0], sizeof(HrtsLight), sizeof(float));
        return hrts_record_frame(ctx, &f);
    }
    case FRAME_DEFORMED_NULL: f.deformed_count = 1; return hrts_record_frame(ctx, &f);
    case FRAME_DEFORMED_MESH: {
        HrtsMeshVertices v = {1, 1, 1024, 0};
        f.deformed = &v;
        f.deformed_count = 1;
        return hrts_record_frame(ctx, &f);
    }
    case FRAME_INDEX_REPEATED: {
        if (run_frame(ctx, NULL) != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        VkCommandBuffer cmd = begin();
        HrtsFrame again = frame(cmd, next_frame - 1);
        HrtsResult r = hrts_record_frame(ctx, &again);
        submit_and_wait(cmd);
        return r;
    }
    case FRAME_INDEX_BACKWARDS: f.frame_index = next_frame - 2; return hrts_record_frame(ctx, &f);
    case REPORT_STRUCT_SIZE: report(ctx, next_frame - 1, 0, &rep); rep.struct_size = 1;
        return hrts_get_frame_report(ctx, next_frame - 1, 0, &rep);
    case REPORT_OLD_FRAME: {
        for (int i = 0; i < 4; i++)
            if (run_frame(ctx, NULL) != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        return report(ctx, next_frame - 5, 0, &rep); /* 3 frames in flight: frames older than 3 are gone */
    }
    case REPORT_NO_SUCH_LIGHT: return report(ctx, next_frame - 1, 5, &rep);
    case REPORT_NOT_COMPLETED: {
        VkCommandBuffer cmd = begin();
        HrtsFrame pending = frame(cmd, next_frame++);
        HrtsResult r = hrts_record_frame(ctx, &pending);
        if (r != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        r = report(ctx, pending.frame_index, 0, &rep);
        submit_and_wait(cmd);
        return r;
    }
    case PASSES_EMPTY_MASK: return hrts_record_passes(ctx, &f, 0);
    case PASSES_UNKNOWN_BIT: return hrts_record_passes(ctx, &f, 1u << 20);
    case PASSES_RAY_TRACE_FIRST: f.frame_index = next_frame++; return hrts_record_passes(ctx, &f, 1u << HRTS_PASS_RAY_TRACE);
    case PASSES_CAMERA_MOVED: {
        /* a new frame: its light-space passes, then its screen-space passes with another camera */
        f.frame_index = next_frame++;
        if (hrts_record_passes(ctx, &f, HRTS_PASS_MASK_LIGHT_SPACE) != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        f.camera_position[1] += 1.0f;
        return hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE);
    }
    case PASSES_COPY_TOO_EARLY: f.frame_index = next_frame - 1; return hrts_record_passes(ctx, &f, 1u << HRTS_PASS_OUTPUT_COPY);
    case PASSES_DEPTH_LAYOUT: f.frame_index = next_frame - 1; f.depth_layout = 0;
        return hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE);
    case REPORT_HALF_RECORDED: return report(ctx, next_frame - 1, 0, &rep);
    case READBACK_HALF_RECORDED: return read_resource(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, scratch, sizeof scratch);
    case READBACK_UNKNOWN: {
        f.frame_index = next_frame - 1; /* finish the open frame first */
        if (hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE) != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        return read_resource(ctx, 0, 99, scratch, sizeof scratch);
    }
    case READBACK_NOT_ALLOCATED: return read_resource(ctx, 0, HRTS_RESOURCE_PCSS, scratch, sizeof scratch);
    case READBACK_TOO_SMALL: return read_resource(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, scratch, 64);
    case READBACK_NULL_BUFFER: {
        HrtsResourceReadback rb;
        memset(&rb, 0, sizeof rb);
        rb.struct_size = sizeof rb;
        rb.command_buffer = 1;
        rb.resource = HRTS_RESOURCE_RT_VISIBILITY;
        return hrts_record_resource_readback(ctx, &rb);
    }
    case READBACK_NO_SUCH_LIGHT: return read_resource(ctx, 3, HRTS_RESOURCE_RT_VISIBILITY, scratch, sizeof scratch);
    case INFO_UNKNOWN: return hrts_get_resource_info(ctx, 0, 12, &info);
    case INFO_NO_SUCH_LIGHT: return hrts_get_resource_info(ctx, 2, HRTS_RESOURCE_RT_VISIBILITY, &info);
    case FRAME_MORE_LIGHTS_THAN_LAYERS: {
        t.output_layers = 1;
        HrtsResult r = hrts_configure_lights(m->other, 2, two);
        if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(m->other, &g);
        if (r == HRTS_RESULT_OK) r = hrts_set_targets(m->other, &t);
        if (r != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        f.lights = lights;
        f.light_count = 2;
        f.frame_index = 0;
        return hrts_record_frame(m->other, &f);
    }
    case USE_AFTER_DESTROY:
        m->gone = create_context(m->vk, 0);
        if (hrts_context_destroy(m->gone) != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        return hrts_get_capabilities(m->gone, &caps);
    case USE_AFTER_SLOT_REUSED:
        /* the new context takes the destroyed one's registry slot; the old handle stays invalid */
        m->fresh = create_context(m->vk, 0);
        if (m->fresh == m->gone || hrts_get_capabilities(m->fresh, &caps) != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        return hrts_get_capabilities(m->gone, &caps);
    case DOUBLE_DESTROY: return hrts_context_destroy(m->gone);
    case FORGED_HANDLE: return hrts_get_capabilities((HrtsContext *)(uintptr_t)0x12345, &caps);
    case CALLBACKS_TOO_LATE: {
        HrtsAllocationCallbacks callbacks;
        memset(&callbacks, 0, sizeof callbacks);
        callbacks.struct_size = sizeof callbacks;
        callbacks.allocate = engine_allocate;
        callbacks.free = engine_free;
        return hrts_set_allocation_callbacks(&callbacks);
    }
    default: return HRTS_RESULT_ERROR_INTERNAL;
    }
}

static void misuse(HrtsContext *ctx, const HrtsVulkanDevice *vk) {
    Misuse m = {ctx, vk, begin(), create_context(vk, 0), NULL, NULL};
    int matched = 0;
    for (int id = 0; id < MISUSE_CASES; id++) {
        phase = MISUSE[id].name;
        HrtsResult got = misuse_call(id, &m);
        char message[512];
        /* the copy, and the size of the whole message: the same string hrts_last_error gives */
        size_t needed = hrts_get_last_error(NULL, message, sizeof message);
        int ok = got == MISUSE[id].want && message[0] != '\0' && needed == strlen(message) + 1 &&
                 strcmp(message, hrts_last_error(NULL)) == 0;
        if (!ok)
            fprintf(stderr, "misuse case '%s': got %s, want %s, message \"%s\"\n", MISUSE[id].name, hrts_result_name(got),
                    hrts_result_name(MISUSE[id].want), message);
        /* the context still answers, and a success clears the last error */
        HrtsCapabilities caps;
        memset(&caps, 0, sizeof caps);
        caps.struct_size = sizeof caps;
        int usable = hrts_get_capabilities(ctx, &caps) == HRTS_RESULT_OK && hrts_last_error(ctx)[0] == '\0' &&
                     hrts_last_error(NULL)[0] == '\0';
        if (!usable) fprintf(stderr, "misuse case '%s': the context is unusable afterwards\n", MISUSE[id].name);
        matched += ok && usable;
    }
    phase = "misuse: the shared command buffer";
    submit_and_wait(m.cmd);
    CHECK(hrts_context_destroy(m.other) == HRTS_RESULT_OK && hrts_context_destroy(m.fresh) == HRTS_RESULT_OK,
          "destroy the misuse contexts");
    printf("misuse cases: %d of %d failed as they must, each with a message\n", matched, (int)MISUSE_CASES);
    CHECK(matched == MISUSE_CASES, "%d misuse cases did not fail as they must", MISUSE_CASES - matched);
}

/* A context of two frames in flight with `n` hard lights, the CPU geometry `g` and the targets, its lights
 * those of the frames recorded next. */
static HrtsContext *hard_lights_context(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g, const Emitter *lights,
                                       uint32_t n) {
    set_lights(lights, n);
    HrtsContext *ctx = create_context(vk, 2);
    CHECK(configure_all(ctx, n, HRTS_SHADOW_MODE_HARD) == HRTS_RESULT_OK, "configure %u lights: %s", n, hrts_last_error(ctx));
    HrtsTargets t = targets();
    CHECK(hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK && hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "geometry and targets: %s", hrts_last_error(ctx));
    return ctx;
}

/* ---------- several lights in one context ---------- */
/* Eight lights, four directional and four spot, hard shadows, in one context sharing the prim buffer:
 * each light's layer of the output matches the exact shadow of that light; the prim buffer is built once,
 * by the first light, and shared. */
static void several_lights(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { N = 8 };
    Emitter lights[N] = {
        directional(v3(0.45, -1.0, 0.2)),
        directional(v3(-0.6, -1.0, 0.1)),
        directional(v3(0.1, -1.0, -0.7)),
        directional(v3(-0.3, -0.6, -0.3)),
        spot(v3(2.5, 4.0, 1.0), v3(0, 0, 0), 2.0),
        spot(v3(-2.0, 3.5, -1.5), v3(0.2, 0, 0.2), 2.0),
        spot(v3(0.3, 5.0, 2.5), v3(0, 0, 0), 1.9),
        spot(v3(-1.5, 3.0, 2.0), v3(0, 0.5, 0), 2.2),
    };
    HrtsContext *ctx = hard_lights_context(vk, g, lights, N);
    static float vis[N * W * H];
    uint64_t first = next_frame;
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "8 lights: %s", hrts_last_error(ctx));
    double tol = edge_tolerance();
    int total_mismatches = 0, total_shadowed = 0;
    uint64_t scratch = 0;
    for (int i = 0; i < N; i++) {
        int near_edge, shadowed, lit;
        int mismatches = count_mismatches(vis + i * W * H, tol, &lights[i], &near_edge, &shadowed, &lit);
        HrtsFrameReport rep;
        HrtsResult r = report(ctx, first, (uint32_t)i, &rep);
        /* one primitive-map build scratch serves every light: the same bytes in every report */
        if (i == 0) scratch = rep.map_scratch_bytes;
        CHECK(rep.map_scratch_bytes > 0 && rep.map_scratch_bytes == scratch, "light %d: map scratch %llu bytes, light 0's %llu",
              i, (unsigned long long)rep.map_scratch_bytes, (unsigned long long)scratch);
        printf("light %d (%s): %d lit, %d shadowed, %d near-edge, %d mismatches; prim buffer %s\n", i,
               lights[i].spot ? "spot" : "directional", lit, shadowed, near_edge, mismatches,
               rep.pass_status[HRTS_PASS_PRIM_BUFFER] == HRTS_PASS_STATUS_RAN ? "built" : "shared");
        CHECK(r == HRTS_RESULT_OK, "report of light %d: %s", i, hrts_last_error(ctx));
        CHECK(rep.pass_status[HRTS_PASS_PRIM_BUFFER] == (i == 0 ? HRTS_PASS_STATUS_RAN : HRTS_PASS_STATUS_SHARED),
              "light %d: prim buffer status %u", i, rep.pass_status[HRTS_PASS_PRIM_BUFFER]);
        CHECK(shadowed > 100 && near_edge * 100 <= 4 * W * H, "light %d: %d shadowed, %d near-edge px", i, shadowed, near_edge);
        total_mismatches += mismatches;
        total_shadowed += shadowed;
    }
    printf("8 lights: %d shadowed px in all, %d mismatches\n", total_shadowed, total_mismatches);
    CHECK(total_mismatches == 0, "%d pixels of the 8 lights differ from the exact shadows", total_mismatches);
    /* the next frame: static geometry, the prim buffer is up to date for every light */
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "second frame: %s", hrts_last_error(ctx));
    HrtsFrameReport rep;
    CHECK(report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK &&
              rep.pass_status[HRTS_PASS_PRIM_BUFFER] == HRTS_PASS_STATUS_UP_TO_DATE,
          "second frame: prim buffer %u", rep.pass_status[HRTS_PASS_PRIM_BUFFER]);
    /* reconfiguring one light rebuilds that light's passes only */
    HrtsConfig cfgs[N];
    for (int i = 0; i < N; i++) cfgs[i] = config(HRTS_SHADOW_MODE_HARD);
    cfgs[3].mode = HRTS_SHADOW_MODE_HYBRID;
    CHECK(hrts_configure_lights(ctx, N, cfgs) == HRTS_RESULT_OK, "reconfigure light 3: %s", hrts_last_error(ctx));
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "after reconfiguring light 3: %s", hrts_last_error(ctx));
    int rebuilt = 0, kept = 0, same = 0;
    for (int i = 0; i < N; i++) {
        CHECK(report(ctx, next_frame - 1, (uint32_t)i, &rep) == HRTS_RESULT_OK, "report %d: %s", i, hrts_last_error(ctx));
        if (rep.light_builds == 2) rebuilt += i == 3;
        if (rep.light_builds == 1) kept += i != 3;
        if (i != 3) {
            int ne, sh, li;
            same += count_mismatches(vis + i * W * H, tol, &lights[i], &ne, &sh, &li) == 0;
        }
    }
    printf("reconfiguring light 3 of 8: %d light rebuilt, %d kept their passes, %d of them still exact\n", rebuilt, kept, same);
    CHECK(rebuilt == 1 && kept == N - 1 && same == N - 1, "reconfiguring one light: %d rebuilt, %d kept, %d exact", rebuilt, kept, same);
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
}

/* ---------- lights given as lights ---------- */
/* A point light and a wide spot light given without matrices: the plugin builds the point light's six cube
 * faces as one map (hard shadows), fits the spot light's five faces around its axis and writes the minimum
 * over them, and reports them as one light each; both match the exact shadow. A light that turns from
 * point to spot is rebuilt and stays exact. The point light with area shadows: a tiny emitter gives the
 * exact hard shadow, a sized one whole sample counts. Bad local lights are refused with a message, and a
 * wide spot light's per-face resources cannot be read back. */
static void native_local_lights(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { N = 2 };
    Emitter lights[N] = {point(v3(0.9, 2.3, 0.7)), fitted_spot(v3(-1.5, 3.2, 1.8), v3(0, 0, 0), 1.35)};
    HrtsContext *ctx = hard_lights_context(vk, g, lights, N);
    /* a context takes HRTS_MAX_LIGHTS lights, a point light counting once */
    CHECK(HRTS_MAX_LIGHTS >= 64 && configure_all(ctx, HRTS_MAX_LIGHTS, HRTS_SHADOW_MODE_HARD) == HRTS_RESULT_OK,
          "configure %d lights: %s", HRTS_MAX_LIGHTS, hrts_last_error(ctx));
    CHECK(configure_all(ctx, N, HRTS_SHADOW_MODE_HARD) == HRTS_RESULT_OK, "configure: %s", hrts_last_error(ctx));
    static float vis[N * W * H];
    uint64_t first = next_frame;
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "point and fitted spot: %s", hrts_last_error(ctx));
    double tol = edge_tolerance();
    const uint32_t want_frusta[N] = {1, 5};
    for (int i = 0; i < N; i++) {
        int near_edge, shadowed, lit;
        int mismatches = count_mismatches(vis + i * W * H, tol, &lights[i], &near_edge, &shadowed, &lit);
        HrtsFrameReport rep;
        CHECK(report(ctx, first, (uint32_t)i, &rep) == HRTS_RESULT_OK, "report %d: %s", i, hrts_last_error(ctx));
        printf("%s: %u frusta recorded, %u culled (%s), %.3f GPU ms, %u entries (longest list %u); %d lit, %d shadowed, "
               "%d near-edge, %d mismatches\n",
               i == 0 ? "point light" : "fitted spot light", rep.frusta, rep.frusta_culled, rep.decision_reason,
               rep.gpu_milliseconds, rep.entries, rep.longest_list, lit, shadowed, near_edge, mismatches);
        CHECK(rep.frusta + rep.frusta_culled == want_frusta[i] && rep.decision == HRTS_LIGHT_DECISION_SHADOWED,
              "light %d: %u frusta recorded, %u culled, decision %u", i, rep.frusta, rep.frusta_culled, rep.decision);
        CHECK(rep.gpu_milliseconds > 0.0 && rep.texels_past_capacity == 0, "light %d: report", i);
        /* the minimum over a light's frusta (one step per frustum recorded) is timed in its own report; a cube
         * map has none */
        uint32_t combine_timed = 0;
        for (uint32_t p = 0; p < rep.pass_count; p++) combine_timed += strcmp(rep.passes[p].name, "min over frusta") == 0;
        CHECK(combine_timed == (want_frusta[i] > 1 ? rep.frusta : 0),
              "light %d: 'min over frusta' timed %u times in its report for %u frusta", i, combine_timed, rep.frusta);
        CHECK(mismatches == 0, "light %d: %d pixels differ from the exact shadow", i, mismatches);
        CHECK(shadowed > 100 && lit > 1000 && near_edge * 100 <= 4 * W * H, "light %d: %d shadowed, %d lit, %d near-edge px",
              i, shadowed, lit, near_edge);
    }
    /* the point light is one cube map: its (triangle, face) pairs fit what the map holds */
    HrtsFrameReport point_rep;
    CHECK(report(ctx, first, 0, &point_rep) == HRTS_RESULT_OK && strstr(point_rep.decision_reason, "cube") &&
              point_rep.bin_pairs > 0 && point_rep.bin_pairs <= point_rep.bin_pair_capacity &&
              point_rep.pass_status[HRTS_PASS_RAY_TRACE] == HRTS_PASS_STATUS_RAN,
          "the point light is one cube map: %s; %u of %u pairs", point_rep.decision_reason, point_rep.bin_pairs,
          point_rep.bin_pair_capacity);
    /* a point light whose range reaches no receiver: nothing is recorded for it and its layer is lit */
    Emitter out_of_view = point(v3(0.0, 6.0, 0.0));
    out_of_view.c.range = 2.0f;
    Emitter pair[N] = {out_of_view, lights[1]};
    set_lights(pair, N);
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "out-of-view point light: %s", hrts_last_error(ctx));
    HrtsFrameReport culled;
    CHECK(report(ctx, next_frame - 1, 0, &culled) == HRTS_RESULT_OK, "out-of-view report: %s", hrts_last_error(ctx));
    int not_lit = 0;
    for (int p = 0; p < W * H; p++) not_lit += vis[p] != 1.0f;
    printf("out-of-view point light: decision %u (%s), %u frusta recorded, %u culled, %.3f GPU ms, %d px not lit\n",
           culled.decision, culled.decision_reason, culled.frusta, culled.frusta_culled, culled.gpu_milliseconds, not_lit);
    CHECK(culled.decision == HRTS_LIGHT_DECISION_OUT_OF_VIEW && culled.frusta == 0 && culled.frusta_culled == 1 &&
              culled.pass_count == 0 && culled.pass_status[HRTS_PASS_RAY_TRACE] == HRTS_PASS_STATUS_CULLED &&
              culled.pass_status[HRTS_PASS_OUTPUT_COPY] == HRTS_PASS_STATUS_RAN && not_lit == 0,
          "an out-of-view point light records nothing and is lit: %d px not lit", not_lit);
    set_lights(lights, N);
    float one[W * H];
    CHECK(read_resource(ctx, 1, HRTS_RESOURCE_RT_VISIBILITY, one, sizeof one) == HRTS_RESULT_ERROR_INVALID_STATE &&
              strstr(hrts_last_error(ctx), "frusta"),
          "a wide spot light's per-face resources are refused: %s", hrts_last_error(ctx));
    /* the point light turns into a narrow fitted spot light: only it is rebuilt */
    lights[0] = fitted_spot(v3(0.9, 2.3, 0.7), v3(-0.5, 0, -0.6), 0.9);
    set_lights(lights, N);
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "point light turned spot: %s", hrts_last_error(ctx));
    HrtsFrameReport r0, r1;
    CHECK(report(ctx, next_frame - 1, 0, &r0) == HRTS_RESULT_OK && report(ctx, next_frame - 1, 1, &r1) == HRTS_RESULT_OK,
          "reports: %s", hrts_last_error(ctx));
    int ne, sh, li;
    int mismatches = count_mismatches(vis, tol, &lights[0], &ne, &sh, &li);
    printf("turned spot: %u frustum, builds %u and %u, %d shadowed, %d mismatches\n", r0.frusta, r0.light_builds,
           r1.light_builds, sh, mismatches);
    CHECK(r0.frusta == 1 && r0.light_builds == 2 && r1.light_builds == 1 && mismatches == 0 && sh > 100,
          "a light that changes type is rebuilt alone and stays exact");
    /* area shadows of the point light (its six faces as one cube map, the visible fraction of 64 points of
     * its spherical emitter): an emitter of radius 1e-4 casts penumbrae far below a pixel, so its counts are
     * the exact hard shadow outside near-edge pixels; one of 0.15 gives whole counts k / 64 in penumbrae */
    lights[0] = point(v3(0.9, 2.3, 0.7));
    set_lights(lights, N);
    HrtsConfig area_cfgs[N] = {config(HRTS_SHADOW_MODE_AREA), config(HRTS_SHADOW_MODE_HARD)};
    area_cfgs[0].pcss_spot_radius = 1e-4f;
    CHECK(hrts_configure_lights(ctx, N, area_cfgs) == HRTS_RESULT_OK, "area point light: %s", hrts_last_error(ctx));
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "area point light: %s", hrts_last_error(ctx));
    HrtsFrameReport ra;
    CHECK(report(ctx, next_frame - 1, 0, &ra) == HRTS_RESULT_OK, "area report: %s", hrts_last_error(ctx));
    mismatches = count_mismatches(vis, tol, &lights[0], &ne, &sh, &li);
    printf("area point light, emitter 1e-4: %s; %u entries; %d shadowed, %d mismatches with the exact hard shadow "
           "outside %d near-edge px\n",
           ra.decision_reason, ra.entries, sh, mismatches, ne);
    CHECK(strstr(ra.decision_reason, "cube") && ra.frusta == 1 && mismatches == 0 && sh > 100,
          "a tiny area point light is the exact hard shadow: %d mismatches, %d shadowed", mismatches, sh);
    area_cfgs[0].pcss_spot_radius = 0.15f;
    CHECK(hrts_configure_lights(ctx, N, area_cfgs) == HRTS_RESULT_OK, "area point light: %s", hrts_last_error(ctx));
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "area point light: %s", hrts_last_error(ctx));
    int lamp_penumbra;
    int lamp_not_counts = area_not_counts(vis, 64.0f, &lamp_penumbra);
    printf("area point light, emitter 0.15: %d penumbra pixels, %d values that are no count\n", lamp_penumbra,
           lamp_not_counts);
    CHECK(lamp_not_counts == 0 && lamp_penumbra > 100, "area point light: %d penumbra px, %d not k/64", lamp_penumbra,
          lamp_not_counts);
    CHECK(configure_all(ctx, N, HRTS_SHADOW_MODE_HARD) == HRTS_RESULT_OK, "configure back: %s", hrts_last_error(ctx));
    lights[0] = fitted_spot(v3(0.9, 2.3, 0.7), v3(-0.5, 0, -0.6), 0.9);
    set_lights(lights, N);
    /* bad local lights: a negative range, a fitted spot light without a cone */
    c_lights[0].range = -1.0f;
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "range"),
          "a negative range is refused: %s", hrts_last_error(ctx));
    c_lights[0].range = 0.0f;
    c_lights[0].outer_cone = 0.0f;
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "outer_cone"),
          "a fitted spot light without a cone is refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
}

/* ---------- frames in flight ---------- */
/* The scene of frame i of the moving sequence: the camera orbits, a directional light turns and a spot
 * light circles. */
static void moving_scene(int i) {
    setup_camera(0.012 * i);
    double a = 0.02 * i;
    Emitter lights[2] = {
        directional(v3(0.45 * cos(a) - 0.2 * sin(a), -1.0, 0.45 * sin(a) + 0.2 * cos(a))),
        spot(v3(2.5 * cos(-a), 4.0, 2.5 * sin(-a)), v3(0, 0, 0), 2.0),
    };
    set_lights(lights, 2);
}

/* Light 0 stays hard throughout; light 1 is hard, then hybrid from frame RECONFIGURE_AT on; light 0's map
 * size changes there too. */
enum { IN_FLIGHT = 3, MOVING_FRAMES = 120, RECONFIGURE_AT = 60, RETARGET_AT = 90 };

static HrtsResult configure_moving(HrtsContext *ctx, int i) {
    HrtsConfig cfgs[2] = {config(HRTS_SHADOW_MODE_HARD), config(HRTS_SHADOW_MODE_HARD)};
    if (i >= RECONFIGURE_AT) {
        cfgs[0].map_size = 128;
        cfgs[1].mode = HRTS_SHADOW_MODE_HYBRID;
    }
    return hrts_configure_lights(ctx, 2, cfgs);
}

/* An engine loop with 3 frames in flight over 120 frames (camera and lights moving, the lights reconfigured
 * at frame 60 and the targets set again at frame 90, both without waiting for the GPU): each frame's two
 * layers equal, bit for bit, the same frame recorded alone by a context with one frame in flight, and the
 * hard layers match the exact shadows. Synchronization validation watches the whole loop. */
static void frames_in_flight(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { LIGHTS = 2, PX = W * H };
    static float results[MOVING_FRAMES][LIGHTS * PX];
    HrtsContext *ctx = create_context(vk, IN_FLIGHT);
    HrtsTargets t = targets();
    CHECK(configure_moving(ctx, 0) == HRTS_RESULT_OK && hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK &&
              hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "in flight: setup: %s", hrts_last_error(ctx));
    VkCommandBuffer cmds[IN_FLIGHT];
    VkFence fences[IN_FLIGHT];
    Buf depth[IN_FLIGHT], normal[IN_FLIGHT], back[IN_FLIGHT];
    int pending[IN_FLIGHT];
    frames_in_flight_ring(IN_FLIGHT, cmds, fences);
    for (int s = 0; s < IN_FLIGHT; s++) {
        depth[s] = make_host_buffer(sizeof(float) * PX, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        normal[s] = make_host_buffer(sizeof(float) * 4 * PX, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        back[s] = make_host_buffer(sizeof(float) * LIGHTS * PX, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        pending[s] = -1;
    }
    /* the first frame waits on a timeline semaphore the host signals once IN_FLIGHT frames were submitted:
     * the frames after it are ordered after it (the plugin's barrier at each frame's start), so exactly
     * IN_FLIGHT frames are pending then, whatever the device's pace */
    VkSemaphore hold = held_semaphore();
    int errors_before = validation_errors, recorded = 0, max_pending = 0, held_pending = 0;
    for (int i = 0; i < MOVING_FRAMES + IN_FLIGHT; i++) {
        int s = i % IN_FLIGHT;
        if (pending[s] >= 0) {
            /* the frame that used this slot (IN_FLIGHT frames ago) completed: keep its visibility */
            VK(vkWaitForFences(device, 1, &fences[s], VK_TRUE, UINT64_MAX));
            VK(vkResetFences(device, 1, &fences[s]));
            memcpy(results[pending[s]], back[s].map, sizeof(float) * LIGHTS * PX);
            pending[s] = -1;
        }
        if (i >= MOVING_FRAMES) continue;
        if (i == RECONFIGURE_AT)
            CHECK(configure_moving(ctx, i) == HRTS_RESULT_OK, "reconfigure in flight: %s", hrts_last_error(ctx));
        if (i == RETARGET_AT) CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_OK, "targets in flight: %s", hrts_last_error(ctx));
        moving_scene(i);
        draw_gbuffer(depth[s].map, normal[s].map);
        VK(vkResetCommandBuffer(cmds[s], 0));
        VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VK(vkBeginCommandBuffer(cmds[s], &bi));
        record_gbuffer_upload(cmds[s], depth[s], normal[s], 0);
        HrtsFrame f = frame(cmds[s], (uint64_t)i);
        HrtsResult r = hrts_record_frame(ctx, &f);
        CHECK(r == HRTS_RESULT_OK, "in flight: frame %d: %s", i, hrts_last_error(ctx));
        record_output_readback(cmds[s], back[s], LIGHTS);
        if (i == 0) {
            submit_held(cmds[s], hold, fences[s]);
        } else {
            submit(cmds[s], fences[s]);
        }
        pending[s] = i;
        recorded++;
        int now = 0;
        for (int k = 0; k < IN_FLIGHT; k++) now += pending[k] >= 0 && vkGetFenceStatus(device, fences[k]) == VK_NOT_READY;
        if (now > max_pending) max_pending = now;
        if (i == IN_FLIGHT - 1) {
            held_pending = now;
            release_held(hold);
        }
    }
    int in_flight_errors = validation_errors - errors_before;
    /* the reports of the last IN_FLIGHT frames are kept; older ones are not */
    HrtsFrameReport rep;
    CHECK(report(ctx, MOVING_FRAMES - 1, 1, &rep) == HRTS_RESULT_OK && rep.pass_status[HRTS_PASS_BLEND] == HRTS_PASS_STATUS_RAN,
          "in flight: report of the last frame: %s", hrts_last_error(ctx));
    CHECK(report(ctx, MOVING_FRAMES - 1 - IN_FLIGHT, 0, &rep) == HRTS_RESULT_ERROR_INVALID_ARGUMENT,
          "in flight: a report older than the ring");
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "in flight: destroy");

    /* the same frames, one at a time, by a context with one frame in flight */
    HrtsContext *solo = create_context(vk, 1);
    CHECK(configure_moving(solo, 0) == HRTS_RESULT_OK && hrts_set_geometry_cpu(solo, g) == HRTS_RESULT_OK &&
              hrts_set_targets(solo, &t) == HRTS_RESULT_OK,
          "solo: setup: %s", hrts_last_error(solo));
    static float alone[LIGHTS * PX];
    int differ = 0, differing_frames = 0, mismatches = 0, hard_layers = 0;
    double tol = edge_tolerance();
    for (int i = 0; i < MOVING_FRAMES; i++) {
        if (i == RECONFIGURE_AT) CHECK(configure_moving(solo, i) == HRTS_RESULT_OK, "solo: reconfigure: %s", hrts_last_error(solo));
        moving_scene(i);
        upload_gbuffer();
        CHECK(run_frame(solo, alone) == HRTS_RESULT_OK, "solo: frame %d: %s", i, hrts_last_error(solo));
        int d = differing(results[i], alone, LIGHTS * PX);
        differ += d;
        differing_frames += d > 0;
        for (int l = 0; l < LIGHTS; l++) {
            if (l == 1 && i >= RECONFIGURE_AT) continue; /* hybrid: not a hard shadow */
            int ne, sh, li;
            mismatches += count_mismatches(results[i] + l * PX, tol, &scene_lights[l], &ne, &sh, &li);
            hard_layers++;
        }
    }
    CHECK(hrts_context_destroy(solo) == HRTS_RESULT_OK, "solo: destroy");
    printf("frames in flight: %d frames recorded with up to %d pending on the GPU, reconfigured at %d, targets set "
           "again at %d; %d px in %d frames differ from the frames recorded alone; %d hard layers, %d mismatches "
           "with the exact shadows; %d validation messages (synchronization validation on)\n",
           recorded, max_pending, RECONFIGURE_AT, RETARGET_AT, differ, differing_frames, hard_layers, mismatches,
           in_flight_errors);
    CHECK(recorded == MOVING_FRAMES, "in flight: %d frames recorded", recorded);
    CHECK(held_pending == IN_FLIGHT, "in flight: %d of %d frames were pending together", held_pending, IN_FLIGHT);
    CHECK(differ == 0, "in flight: %d px in %d frames differ from the single-frame results", differ, differing_frames);
    CHECK(mismatches == 0, "in flight: %d px differ from the exact shadows", mismatches);
    CHECK(in_flight_errors == 0, "in flight: %d validation errors", in_flight_errors);
    VK(vkDeviceWaitIdle(device));
    vkDestroySemaphore(device, hold, NULL);
    for (int s = 0; s < IN_FLIGHT; s++) {
        vkDestroyFence(device, fences[s], NULL);
        free_buffer(depth[s]);
        free_buffer(normal[s]);
        free_buffer(back[s]);
    }
    vkFreeCommandBuffers(device, pool, IN_FLIGHT, cmds);
}

int main(void) {
    HrtsAllocationCallbacks callbacks;
    memset(&callbacks, 0, sizeof callbacks);
    callbacks.struct_size = sizeof callbacks;
    callbacks.allocate = engine_allocate;
    callbacks.free = engine_free;
    CHECK(hrts_set_allocation_callbacks(&callbacks) == HRTS_RESULT_OK, "allocation callbacks: %s", hrts_last_error(NULL));
    CHECK(hrts_set_allocation_callbacks(&callbacks) == HRTS_RESULT_ERROR_INVALID_STATE, "second install accepted");
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    create_device();
    HrtsVulkanDevice vk = adopt_info();
    depth_img = make_image(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 1);
    normal_img = make_image(VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 1);
    out_img = make_image(VK_FORMAT_R32_SFLOAT, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, LAYERS);
    upload_gbuffer();

    phase = "one light";
    HrtsContext *ctx = create_context(&vk, IN_FLIGHT);
    CHECK(hrts_get_api_version() == HRTS_API_VERSION, "version");
    HrtsCapabilities caps;
    memset(&caps, 0, sizeof caps);
    caps.struct_size = sizeof caps;
    CHECK(hrts_get_capabilities(ctx, &caps) == HRTS_RESULT_OK, "capabilities: %s", hrts_last_error(ctx));
    printf("plugin sees: %s, conservative raster tier %u\n", caps.device_name, caps.conservative_raster_tier);

    HrtsFrameReport rep;
    CHECK(report(ctx, 0, 0, &rep) == HRTS_RESULT_ERROR_INVALID_STATE, "report before any frame");
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_ERROR_INVALID_STATE, "record before geometry/targets");

    HrtsConfig cfg = config(HRTS_SHADOW_MODE_HARD);
    CHECK(hrts_configure(ctx, &cfg) == HRTS_RESULT_OK, "configure: %s", hrts_last_error(ctx));
    HrtsCpuGeometry g = cpu_geometry();
    CHECK(hrts_set_geometry_cpu(ctx, &g) == HRTS_RESULT_OK, "geometry: %s", hrts_last_error(ctx));
    HrtsTargets t = targets();
    CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_OK, "targets: %s", hrts_last_error(ctx));

    static float vis[W * H];
    phase = "hard frame";
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "record: %s", hrts_last_error(ctx));
    CHECK(report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK, "report: %s", hrts_last_error(ctx));
    printf("frame: binning path %u, %u entries in %u lists (longest %u), capacity %u, %u texels past it\n",
           rep.binning_path, rep.entries, rep.texels_with_list, rep.longest_list, rep.entry_capacity,
           rep.texels_past_capacity);
    CHECK(rep.binning_path == HRTS_BINNING_PATH_COMPUTE && rep.entries > 0 && rep.texels_past_capacity == 0,
          "report of the primitive map");
    for (uint32_t i = 0; i < rep.pass_count; i++) printf("  %-28s %8.3f ms\n", rep.passes[i].name, rep.passes[i].milliseconds);

    double tol = edge_tolerance();
    int near_edge, shadowed, lit;
    int mismatches = count_mismatches(vis, tol, &sun, &near_edge, &shadowed, &lit);
    printf("visibility: %d px, %d lit, %d shadowed, %d near-edge, %d mismatches\n", W * H, lit, shadowed, near_edge, mismatches);
    CHECK(mismatches == 0, "%d pixels differ from the exact shadow", mismatches);
    CHECK(shadowed > 300 && lit > 1000, "the view should show both lit and shadowed pixels");
    CHECK(near_edge * 100 <= 3 * W * H, "near-edge pixels %d exceed 3%%", near_edge);

    /* hybrid: where the exact shadow is lit the blend is exactly lit (the shrinking penumbra only grows inward) */
    HrtsConfig hybrid = config(HRTS_SHADOW_MODE_HYBRID);
    CHECK(hrts_configure(ctx, &hybrid) == HRTS_RESULT_OK, "configure hybrid: %s", hrts_last_error(ctx));
    static float blend[W * H];
    phase = "hybrid frame";
    CHECK(run_frame(ctx, blend) == HRTS_RESULT_OK, "record hybrid: %s", hrts_last_error(ctx));
    int halo = 0, out_of_range = 0, soft = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float v = blend[y * W + x];
            if (!(v >= 0.0f && v <= 1.0f)) out_of_range++;
            if (v > 0.0f && v < 1.0f) soft++;
            if (exact(x, y, tol, &sun) == 1 && v != 1.0f) halo++;
        }
    printf("hybrid: %d soft pixels, %d halo pixels, %d out of [0,1]\n", soft, halo, out_of_range);
    CHECK(halo == 0 && out_of_range == 0, "hybrid: %d halo, %d out of range", halo, out_of_range);
    CHECK(soft > 0, "hybrid shows no penumbra");

    /* the passes one by one, and split over two submissions as an engine places them, give the same bits */
    static float parts[W * H];
    phase = "pass by pass";
    CHECK(run_frame_in_parts(ctx, parts, 1) == HRTS_RESULT_OK, "hybrid pass by pass: %s", hrts_last_error(ctx));
    int diff_one = differing(parts, blend, W * H);
    phase = "two submissions";
    CHECK(run_frame_in_parts(ctx, parts, 0) == HRTS_RESULT_OK, "hybrid in two submissions: %s", hrts_last_error(ctx));
    int diff_two = differing(parts, blend, W * H);
    printf("hybrid recorded pass by pass: %d px differ; light/screen space in two submissions: %d px differ\n",
           diff_one, diff_two);
    CHECK(diff_one == 0 && diff_two == 0, "per-pass recording differs: %d / %d px", diff_one, diff_two);
    CHECK(report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK, "report: %s", hrts_last_error(ctx));
    CHECK(rep.pass_status[HRTS_PASS_RAY_TRACE] == HRTS_PASS_STATUS_RAN && rep.pass_status[HRTS_PASS_PCSS] == HRTS_PASS_STATUS_RAN &&
              rep.pass_status[HRTS_PASS_BLEND] == HRTS_PASS_STATUS_RAN && rep.pass_status[HRTS_PASS_OUTPUT_COPY] == HRTS_PASS_STATUS_RAN,
          "hybrid report: passes that ran");
    CHECK(rep.pass_status[HRTS_PASS_PRIM_BUFFER] == HRTS_PASS_STATUS_UP_TO_DATE, "static geometry: prim buffer %u",
          rep.pass_status[HRTS_PASS_PRIM_BUFFER]);
    CHECK(rep.pass_status[HRTS_PASS_SHADOW_MAP_TEST] == HRTS_PASS_STATUS_NOT_IN_PLAN && rep.pass_status[HRTS_PASS_FXAA] == HRTS_PASS_STATUS_NOT_IN_PLAN,
          "hybrid without antialiasing: no shadow-map test, no FXAA");
    CHECK(rep.output_resource == HRTS_RESOURCE_HYBRID && rep.resource_bytes[HRTS_RESOURCE_HYBRID] == sizeof(float) * W * H &&
              rep.resource_bytes[HRTS_RESOURCE_SHADOW_MAP_VISIBILITY] == 0,
          "hybrid report: resources");

    /* the ray-traced visibility of the hybrid frame, read back, is the hard shadow, bit for bit */
    HrtsResourceInfo info;
    memset(&info, 0, sizeof info);
    info.struct_size = sizeof info;
    CHECK(hrts_get_resource_info(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, &info) == HRTS_RESULT_OK && info.allocated &&
              info.width == W && info.height == H && info.layers == 1 && info.format == VK_FORMAT_R32_SFLOAT &&
              info.bytes == sizeof(float) * W * H,
          "resource info: %s", hrts_last_error(ctx));
    static float rt[W * H];
    phase = "read-back";
    CHECK(read_resource(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, rt, sizeof rt) == HRTS_RESULT_OK, "readback: %s", hrts_last_error(ctx));
    int diff_rt = differing(rt, vis, W * H);
    printf("ray-traced visibility read back from the hybrid frame: %d px differ from the hard-mode output\n", diff_rt);
    CHECK(diff_rt == 0, "read-back ray-traced visibility differs in %d px", diff_rt);
    /* area shadows: the visible fraction of area_samples light samples, each tested exactly. A light of
     * 1e-4 rad casts penumbrae far below a pixel: the counts are the exact hard shadow outside near-edge
     * pixels. A light of 0.05 rad has penumbrae of whole counts k / 64, inside [0, 1]. Invalid sizes and
     * sample counts are refused with a message naming them. */
    HrtsConfig area = config(HRTS_SHADOW_MODE_AREA);
    CHECK(area.area_samples == 64, "area_samples default %u", area.area_samples);
    area.pcss_angular_radius = 1e-4f;
    CHECK(hrts_configure(ctx, &area) == HRTS_RESULT_OK, "configure area: %s", hrts_last_error(ctx));
    static float area_vis[W * H];
    phase = "area frame";
    CHECK(run_frame(ctx, area_vis) == HRTS_RESULT_OK, "record area: %s", hrts_last_error(ctx));
    CHECK(report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK, "report: %s", hrts_last_error(ctx));
    CHECK(rep.pass_status[HRTS_PASS_RAY_TRACE] == HRTS_PASS_STATUS_RAN && rep.pass_status[HRTS_PASS_SHADOW_MAP] == HRTS_PASS_STATUS_NOT_IN_PLAN &&
              rep.pass_status[HRTS_PASS_PCSS] == HRTS_PASS_STATUS_NOT_IN_PLAN && rep.output_resource == HRTS_RESOURCE_RT_VISIBILITY,
          "area report: the map and its trace alone");
    int ne_a, sh_a, lit_a;
    int mismatches_area = count_mismatches(area_vis, tol, &sun, &ne_a, &sh_a, &lit_a);
    printf("area, 1e-4 rad: %d mismatches with the exact hard shadow outside %d near-edge pixels\n", mismatches_area, ne_a);
    CHECK(mismatches_area == 0, "a tiny area light differs from the hard shadow in %d px", mismatches_area);
    area.pcss_angular_radius = 0.05f;
    CHECK(hrts_configure(ctx, &area) == HRTS_RESULT_OK, "configure area: %s", hrts_last_error(ctx));
    CHECK(run_frame(ctx, area_vis) == HRTS_RESULT_OK, "record area: %s", hrts_last_error(ctx));
    int penumbra;
    int not_counts = area_not_counts(area_vis, 64.0f, &penumbra);
    printf("area, 0.05 rad, 64 samples: %d penumbra pixels, %d values that are no count\n", penumbra, not_counts);
    CHECK(not_counts == 0 && penumbra > 100, "area: %d penumbra px, %d not k/64", penumbra, not_counts);
    HrtsConfig bad = area;
    bad.area_samples = 0;
    CHECK(hrts_configure(ctx, &bad) != HRTS_RESULT_OK && strstr(hrts_last_error(ctx), "light samples"), "area_samples 0 accepted");
    bad = area;
    bad.area_samples = 129;
    CHECK(hrts_configure(ctx, &bad) != HRTS_RESULT_OK && strstr(hrts_last_error(ctx), "light samples"), "area_samples 129 accepted");
    bad = area;
    bad.pcss_angular_radius = 2.0f;
    CHECK(hrts_configure(ctx, &bad) != HRTS_RESULT_OK && strstr(hrts_last_error(ctx), "angular radius"), "area radius 2 rad accepted");
    CHECK(hrts_configure(ctx, &cfg) == HRTS_RESULT_OK, "configure back: %s", hrts_last_error(ctx));

    /* the same scene from the engine's own Vulkan buffers: float4 positions (stride 16) at byte offset 64,
     * 16-bit indices at byte offset 8 */
    Buf vb, ib;
    HrtsVulkanGeometry vg = engine_geometry(&vb, &ib);
    phase = "engine buffers";
    CHECK(hrts_set_geometry_vulkan(ctx, &vg) == HRTS_RESULT_OK, "vulkan geometry: %s", hrts_last_error(ctx));
    static float vis_engine[W * H];
    CHECK(run_frame(ctx, vis_engine) == HRTS_RESULT_OK, "record with engine buffers: %s", hrts_last_error(ctx));
    int ne2, sh2, lit2;
    int mismatches_engine = count_mismatches(vis_engine, tol, &sun, &ne2, &sh2, &lit2);
    printf("engine buffers (u16 indices, stride 16, offsets): %d mismatches\n", mismatches_engine);
    CHECK(mismatches_engine == 0, "%d pixels differ with engine geometry", mismatches_engine);
    CHECK(hrts_set_geometry_cpu(ctx, &g) == HRTS_RESULT_OK, "back to CPU geometry: %s", hrts_last_error(ctx));
    /* the engine's buffers may go once the frames that read them completed: run the frames in flight out */
    for (int i = 0; i < IN_FLIGHT; i++) CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "frame: %s", hrts_last_error(ctx));
    VK(vkDeviceWaitIdle(device));
    free_buffer(vb);
    free_buffer(ib);

    phase = "misuse";
    misuse(ctx, &vk);
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "context still records after misuse: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");

    phase = "several lights";
    several_lights(&vk, &g);
    native_local_lights(&vk, &g);
    phase = "auto mode, fitted sun";
    auto_fitted_sun(&vk, &g);
    phase = "frames in flight";
    frames_in_flight(&vk, &g);
    phase = "moving instances";
    moving_instances(&vk, &g);
    phase = "base vertex";
    base_vertex_draws(&vk, &g);
    phase = "quantized positions";
    quantized_positions(&vk, &g);
    phase = "engine meshes";
    engine_meshes(&vk);
    phase = "draw transforms: all or nothing";
    draw_transforms_all_or_nothing(&vk);
    phase = "deforming mesh";
    deforming_mesh(&vk);
    phase = "moving geometry";
    moving_geometry_bounds(&vk);
    phase = "engine normals";
    engine_normals(&vk, &g);
    phase = "engine depth";
    engine_depth(&vk, &g);
    phase = "output formats";
    output_formats(&vk, &g);
    phase = "output written directly";
    output_direct(&vk, &g);
    phase = "read-back retire";
    readback_retire(&vk, &g);
    phase = "partial record";
    partial_record(&vk, &g);
    phase = "create/destroy cycles";
    setup_camera(0.0);
    set_lights(&sun, 1);

    /* 100 create/destroy cycles, each recording a frame: no Vulkan object leaks (the validation layer's
     * object tracker reports them at vkDestroyDevice), and the plugin's host and GPU memory return exactly
     * to where they were. Resident memory is reported too: lavapipe keeps each compiled pipeline's JIT
     * code until its VkDevice is destroyed, so RSS grows on lavapipe whatever the plugin does. */
    HrtsMemoryStats before, after;
    memset(&before, 0, sizeof before);
    before.struct_size = sizeof before;
    after = before;
    long rss_start = 0;
    for (int i = 0; i < 100; i++) {
        if (i == 10) {
            rss_start = rss_kib();
            CHECK(hrts_get_memory_stats(&before) == HRTS_RESULT_OK, "memory stats: %s", hrts_last_error(NULL));
        }
        HrtsContext *c = create_context(&vk, 1);
        HrtsResult r = hrts_configure(c, &cfg);
        if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(c, &g);
        if (r == HRTS_RESULT_OK) r = hrts_set_targets(c, &t);
        if (r == HRTS_RESULT_OK) r = run_frame(c, NULL);
        CHECK(r == HRTS_RESULT_OK, "cycle %d: %s", i, hrts_last_error(c));
        CHECK(hrts_context_destroy(c) == HRTS_RESULT_OK, "cycle %d destroy", i);
    }
    long growth = rss_kib() - rss_start;
    CHECK(hrts_get_memory_stats(&after) == HRTS_RESULT_OK, "memory stats: %s", hrts_last_error(NULL));
    printf("after 90 more create/destroy cycles: plugin host bytes %llu -> %llu, GPU bytes %llu -> %llu; "
           "process RSS %+ld KiB (driver)\n",
           (unsigned long long)before.host_bytes, (unsigned long long)after.host_bytes,
           (unsigned long long)before.gpu_bytes, (unsigned long long)after.gpu_bytes, growth);
    CHECK(before.host_bytes_counted && after.host_bytes_counted, "the shared library counts its host memory");
    CHECK(after.host_bytes <= before.host_bytes, "plugin host memory grew by %lld bytes",
          (long long)after.host_bytes - (long long)before.host_bytes);
    CHECK(after.gpu_bytes == 0 && before.gpu_bytes == 0, "plugin GPU memory left: %llu bytes",
          (unsigned long long)after.gpu_bytes);
    memset(&before, 0, sizeof before);
    CHECK(hrts_get_memory_stats(&before) == HRTS_RESULT_ERROR_STRUCT_SIZE, "memory stats with size 0");
    HrtsMemoryStats now;
    memset(&now, 0, sizeof now);
    now.struct_size = sizeof now;
    CHECK(hrts_get_memory_stats(&now) == HRTS_RESULT_OK, "memory stats: %s", hrts_last_error(NULL));
    printf("engine allocator: %zu allocations by the plugin, %zu bytes live (plugin reports %llu)\n",
           engine_allocations, engine_live_bytes, (unsigned long long)now.host_bytes);
    CHECK(engine_allocations > 1000, "the plugin did not use the engine's allocator");
    CHECK(engine_live_bytes == now.host_bytes, "engine allocator sees %zu live bytes, plugin reports %llu",
          engine_live_bytes, (unsigned long long)now.host_bytes);

    free_image(depth_img);
    free_image(normal_img);
    free_image(out_img);
    destroy_device();
    printf("validation: %d errors, %d warnings (synchronization validation on)\n", validation_errors, validation_warnings);
    CHECK(validation_errors == 0, "%d validation errors", validation_errors);
    printf("%d passed, %d failed\n", passed, failed);
    return failed == 0 ? 0 : 1;
}

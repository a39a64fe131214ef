/* Frames as an engine records them: 3 frames in flight over 120 frames of a moving scene, reconfigured and
 * retargeted without waiting for the GPU (the same bits as frames recorded alone); a read-back still
 * pending when a reconfigure retires what it reads; a failed call that records nothing. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

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
enum { MOVING_FRAMES = 120, RECONFIGURE_AT = 60, RETARGET_AT = 90 };

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
void frames_in_flight(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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

/* ---------- a read-back pending across a reconfigure ---------- */
/* A read-back recorded after frame N counts as a use of frame N+1: what a reconfigure retires after it is
 * held until frame N+1 has completed. The read-back's submission waits on a semaphore the test holds, so it
 * is surely pending when frame N+1 is recorded; with one frame in flight, recording frame N+1 frees what
 * only frames up to N used. Freeing the image the read-back reads then is an error the validation layer
 * reports (an object in use by a pending command buffer), and the read-back would read freed memory. */
void readback_retire(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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

/* ---------- a failed call ---------- */
/* A failed call records nothing. Light 0 is hard (no shadow map), light 1 hybrid (its shadow map is
 * rendered every frame), so a call of the passes up to the ray trace without the shadow map suits light 0
 * and leaves out a pass light 1 runs: the call fails, and light 0's passes must not be in the command
 * buffer either. The camera moves in that same command buffer: had light 0's ray trace been recorded, its
 * visibility (read back after the submission) would show the new view. */
void partial_record(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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

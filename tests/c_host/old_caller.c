/* A caller built against the header of an older API version (the compiler is given its folder,
 * tests/c_host/headers/<version>) runs against the current library. Its structs are of that version's
 * sizes and its arrays of that version's element layouts, without the strides later versions added: the
 * library reads what they hold, gives the newer fields their defaults, and writes no byte past them.
 * With the engine of the C host (engine.c, built against the same header) it checks the exact shadow of a
 * sun over CPU geometry of two draws, of a sun and a spot light in one frame, of the engine's Vulkan
 * buffers, and of a mesh deformed through a vertex buffer of the frame; the configuration defaults and a
 * frame report are written into structs followed by guard bytes. Prints "N passed, M failed". */
#define _POSIX_C_SOURCE 200112L
#include "engine.h"

#include <string.h>

enum { PX = W * H, GUARD = 64 };

/* Whether the GUARD bytes at `guard`, filled with 0xA5 before the call, are as they were. */
static int guard_intact(const unsigned char *guard) {
    for (int i = 0; i < GUARD; i++)
        if (guard[i] != 0xA5) return 0;
    return 1;
}

/* The exact shadow of every light of the frame just read back into `vis` (light after light). */
static int mismatches_of_lights(const float *vis, int *shadowed) {
    int all = 0, near_edge, lit;
    *shadowed = 0;
    for (uint32_t l = 0; l < light_count; l++) {
        int s;
        all += count_mismatches(vis + (size_t)l * PX, edge_tolerance(), &scene_lights[l], &near_edge, &s, &lit);
        *shadowed += s;
    }
    return all;
}

int main(void) {
    printf("caller's header: API %u.%u, library: API %u.%u\n", HRTS_API_VERSION >> 22, HRTS_API_VERSION >> 12 & 0x3FF,
           hrts_get_api_version() >> 22, hrts_get_api_version() >> 12 & 0x3FF);
    setup_camera(0.0);
    create_device();
    HrtsVulkanDevice vk = adopt_info();
    depth_img = make_image(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 1);
    normal_img = make_image(VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 1);
    out_img = make_image(VK_FORMAT_R32_SFLOAT, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, LAYERS);
    upload_gbuffer();

    /* the defaults, written into this version's HrtsConfig and nothing after it */
    struct {
        HrtsConfig config;
        unsigned char guard[GUARD];
    } defaults;
    memset(&defaults, 0xA5, sizeof defaults);
    defaults.config.struct_size = sizeof defaults.config;
    HrtsResult r = hrts_config_defaults(&defaults.config);
    printf("defaults into a %zu-byte HrtsConfig: %s (%s), guard %s\n", sizeof defaults.config, hrts_result_name(r),
           hrts_last_error(NULL), guard_intact(defaults.guard) ? "intact" : "OVERWRITTEN");
    CHECK(r == HRTS_RESULT_OK && guard_intact(defaults.guard) && defaults.config.struct_size == sizeof defaults.config &&
              defaults.config.mode == HRTS_SHADOW_MODE_HYBRID && defaults.config.map_size == 0 /* 5.11: the plugin's choice */,
          "config defaults");

    HrtsContext *ctx = create_context(&vk, 2);
    Emitter lights[2] = {directional(v3(0.45, -1.0, 0.2)), spot(v3(1.5, 3.5, 1.0), v3(0, 0, 0), 1.2)};
    set_lights(lights, 1);
    HrtsConfig hard = config(HRTS_SHADOW_MODE_HARD);
    HrtsCpuGeometry g = cpu_geometry();
    HrtsTargets t = targets();
    CHECK(hrts_configure(ctx, &hard) == HRTS_RESULT_OK && hrts_set_geometry_cpu(ctx, &g) == HRTS_RESULT_OK &&
              hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "setup: %s", hrts_last_error(ctx));
    static float vis[2 * PX];
    int shadowed;
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "sun: %s", hrts_last_error(ctx));
    int sun_mismatches = mismatches_of_lights(vis, &shadowed);
    printf("sun over CPU geometry (2 draws of %zu bytes): %d mismatches with the exact shadow, %d shadowed\n",
           sizeof(HrtsDraw), sun_mismatches, shadowed);
    CHECK(sun_mismatches == 0 && shadowed > 300, "sun: %d mismatches, %d shadowed", sun_mismatches, shadowed);

    /* the frame's report, written into this version's HrtsFrameReport and nothing after it */
    struct {
        HrtsFrameReport report;
        unsigned char guard[GUARD];
    } rep;
    memset(&rep, 0xA5, sizeof rep);
    rep.report.struct_size = sizeof rep.report;
    r = hrts_get_frame_report(ctx, next_frame - 1, 0, &rep.report);
    printf("report into a %zu-byte HrtsFrameReport: %s (%s), %u entries, guard %s\n", sizeof rep.report,
           hrts_result_name(r), hrts_last_error(ctx), rep.report.entries, guard_intact(rep.guard) ? "intact" : "OVERWRITTEN");
    CHECK(r == HRTS_RESULT_OK && guard_intact(rep.guard) && rep.report.struct_size == sizeof rep.report &&
              rep.report.entries > 0 && rep.report.pass_status[HRTS_PASS_RAY_TRACE] == HRTS_PASS_STATUS_RAN,
          "report");

    /* two lights in one frame: the lights array at this version's HrtsLight size */
    set_lights(lights, 2);
    HrtsConfig two[2] = {hard, hard};
    CHECK(hrts_configure_lights(ctx, 2, two) == HRTS_RESULT_OK, "two lights: %s", hrts_last_error(ctx));
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "two lights: %s", hrts_last_error(ctx));
    int two_mismatches = mismatches_of_lights(vis, &shadowed);
    printf("a sun and a spot light in one frame: %d mismatches, %d shadowed\n", two_mismatches, shadowed);
    CHECK(two_mismatches == 0 && shadowed > 600, "two lights: %d mismatches, %d shadowed", two_mismatches, shadowed);

    /* the engine's Vulkan buffers, then the box moved by a vertex buffer of the frame (deformed) */
    set_lights(lights, 1);
    Buf vb, ib;
    HrtsVulkanGeometry vg = engine_geometry(&vb, &ib);
    CHECK(hrts_configure(ctx, &hard) == HRTS_RESULT_OK && hrts_set_geometry_vulkan(ctx, &vg) == HRTS_RESULT_OK,
          "Vulkan geometry: %s", hrts_last_error(ctx));
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "Vulkan geometry: %s", hrts_last_error(ctx));
    int vulkan_mismatches = mismatches_of_lights(vis, &shadowed);
    const double shift[3] = {0.7, 0.0, -0.4};
    Buf moved = make_host_buffer(vg.vertex_buffer_size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    memcpy(moved.map, vb.map, vg.vertex_buffer_size);
    float *vp = (float *)((char *)moved.map + vg.vertex_offset);
    for (int v = 4; v < 12; v++)
        for (int a = 0; a < 3; a++) vp[4 * v + a] += (float)shift[a];
    memcpy(box_shift, shift, sizeof box_shift);
    upload_gbuffer();
    HrtsMeshVertices deformed = {0, (uint64_t)(uintptr_t)moved.buffer, vg.vertex_buffer_size, vg.vertex_offset};
    VkCommandBuffer cmd = begin();
    HrtsFrame f = frame(cmd, next_frame++);
    f.deformed = &deformed;
    f.deformed_count = 1;
    r = finish_frame(cmd, hrts_record_frame(ctx, &f), vis);
    CHECK(r == HRTS_RESULT_OK, "deformed: %s", hrts_last_error(ctx));
    int deformed_mismatches = mismatches_of_lights(vis, &shadowed);
    printf("Vulkan buffers: %d mismatches; the box moved through a deformed vertex buffer: %d mismatches, %d shadowed\n",
           vulkan_mismatches, deformed_mismatches, shadowed);
    CHECK(vulkan_mismatches == 0 && deformed_mismatches == 0 && shadowed > 300, "Vulkan geometry: %d / %d mismatches",
          vulkan_mismatches, deformed_mismatches);

    VK(vkDeviceWaitIdle(device));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    free_buffer(moved);
    free_buffer(vb);
    free_buffer(ib);
    free_image(depth_img);
    free_image(normal_img);
    free_image(out_img);
    destroy_device();
    printf("validation: %d errors, %d warnings\n", validation_errors, validation_warnings);
    CHECK(validation_errors == 0, "%d validation errors", validation_errors);
    printf("%d passed, %d failed\n", passed, failed);
    return failed == 0 ? 0 : 1;
}

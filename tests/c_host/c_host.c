/* A plain C engine that integrates the plugin through hrts.h: it creates its own Vulkan device through
 * the loader (validation layer and synchronization validation on), draws the depth and normal images of a
 * box floating over a ground plane itself (analytic ray casting on the CPU), records the plugin into its
 * own command buffers, reads back the visibility images and compares them with the exact shadow of every
 * light. It keeps 3 frames in flight over 120 frames while the camera and lights move and the lights are
 * reconfigured midway, checks 8 lights of two types in one context, the scene given as meshes of their own
 * buffers and formats, a mesh deformed through per-frame vertex buffers, runs a table of misuse cases and
 * 100 create/destroy cycles. Prints "N passed, M failed" and exits non-zero on any failure.
 *
 * This file holds main() and the order of the checks; the checks are in one_light.c, misuse.c, lights.c,
 * frames.c, geometry.c, meshes.c, deforming.c, engine_images.c and memory.c (declared in c_host.h). */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

int main(void) {
    install_engine_allocator();
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

    one_light(ctx, &sun, &cfg, &g);

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
    phase = "FXAA sharing the ray trace's visibility";
    fxaa_shared(&vk, &g);
    phase = "read-back retire";
    readback_retire(&vk, &g);
    phase = "partial record";
    partial_record(&vk, &g);
    phase = "create/destroy cycles";
    setup_camera(0.0);
    set_lights(&sun, 1);

    create_destroy_cycles(&vk, &cfg, &g, &t);

    free_image(depth_img);
    free_image(normal_img);
    free_image(out_img);
    destroy_device();
    printf("validation: %d errors, %d warnings (synchronization validation on)\n", validation_errors, validation_warnings);
    CHECK(validation_errors == 0, "%d validation errors", validation_errors);
    printf("%d passed, %d failed\n", passed, failed);
    return failed == 0 ? 0 : 1;
}

/* One sun on the context set up by main(): the hard shadow against the exact shadow, the hybrid blend (no
 * halo, a penumbra), the passes recorded one by one and in two submissions (the same bits), a resource
 * read back, area shadows (a tiny light is the hard shadow, a sized one whole sample counts) and the scene
 * from the engine's own Vulkan buffers. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

/* The context `ctx` has one light, configured as `cfg`, the CPU geometry `g` and the targets; `sun` is its
 * light. It is left configured as `cfg` with the geometry `g`, its frames in flight completed. */
void one_light(HrtsContext *ctx, const Emitter *sun, const HrtsConfig *cfg, const HrtsCpuGeometry *g) {
    HrtsFrameReport rep;
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
    int mismatches = count_mismatches(vis, tol, sun, &near_edge, &shadowed, &lit);
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
            if (exact(x, y, tol, sun) == 1 && v != 1.0f) halo++;
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
    int mismatches_area = count_mismatches(area_vis, tol, sun, &ne_a, &sh_a, &lit_a);
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
    CHECK(hrts_configure(ctx, cfg) == HRTS_RESULT_OK, "configure back: %s", hrts_last_error(ctx));

    /* the same scene from the engine's own Vulkan buffers: float4 positions (stride 16) at byte offset 64,
     * 16-bit indices at byte offset 8 */
    Buf vb, ib;
    HrtsVulkanGeometry vg = engine_geometry(&vb, &ib);
    phase = "engine buffers";
    CHECK(hrts_set_geometry_vulkan(ctx, &vg) == HRTS_RESULT_OK, "vulkan geometry: %s", hrts_last_error(ctx));
    static float vis_engine[W * H];
    CHECK(run_frame(ctx, vis_engine) == HRTS_RESULT_OK, "record with engine buffers: %s", hrts_last_error(ctx));
    int ne2, sh2, lit2;
    int mismatches_engine = count_mismatches(vis_engine, tol, sun, &ne2, &sh2, &lit2);
    printf("engine buffers (u16 indices, stride 16, offsets): %d mismatches\n", mismatches_engine);
    CHECK(mismatches_engine == 0, "%d pixels differ with engine geometry", mismatches_engine);
    CHECK(hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK, "back to CPU geometry: %s", hrts_last_error(ctx));
    /* the engine's buffers may go once the frames that read them completed: run the frames in flight out */
    for (int i = 0; i < IN_FLIGHT; i++) CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "frame: %s", hrts_last_error(ctx));
    VK(vkDeviceWaitIdle(device));
    free_buffer(vb);
    free_buffer(ib);
}

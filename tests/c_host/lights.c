/* Lights: eight directional and spot lights in one context sharing the prim buffer, one of them
 * reconfigured alone; point and wide spot lights given without matrices (a cube map, the minimum over
 * fitted faces, out-of-view culling, a change of type, area shadows, bad local lights); a sun of no size
 * that the plugin fits and plans in HRTS_SHADOW_MODE_AUTO. Each layer against the exact shadow. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

/* Configures the context's first `count` lights alike, in `mode`. */
HrtsResult configure_all(HrtsContext *ctx, uint32_t count, uint32_t mode) {
    HrtsConfig cfgs[HRTS_MAX_LIGHTS];
    for (uint32_t i = 0; i < count; i++) cfgs[i] = config(mode);
    return hrts_configure_lights(ctx, count, cfgs);
}

/* A context of two frames in flight with `n` hard lights, the CPU geometry `g` and the targets, its lights
 * those of the frames recorded next. */
HrtsContext *hard_lights_context(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g, const Emitter *lights,
                                uint32_t n) {
    set_lights(lights, n);
    HrtsContext *ctx = create_context(vk, 2);
    CHECK(configure_all(ctx, n, HRTS_SHADOW_MODE_HARD) == HRTS_RESULT_OK, "configure %u lights: %s", n, hrts_last_error(ctx));
    HrtsTargets t = targets();
    CHECK(hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK && hrts_set_targets(ctx, &t) == HRTS_RESULT_OK,
          "geometry and targets: %s", hrts_last_error(ctx));
    return ctx;
}

/* hrts_plan_lights for the current camera and lights, with `count` configurations of `mode` and the bounds of
 * the CPU geometry `g`, equals what the reports of frame `index` of `ctx` (configured alike) say of each
 * light: decision, frusta recorded and culled, and reason; for a shadowed light, its passes are those the
 * report has in the plan (the context's output copy aside) and its resources hold every one the light
 * allocated; an out-of-view light plans none. Returns how many lights differ. */
static int plans_differ_from_reports(HrtsContext *ctx, const HrtsCpuGeometry *g, uint32_t count, uint32_t mode,
                                     uint64_t index) {
    HrtsConfig cfgs[HRTS_MAX_LIGHTS];
    HrtsLightPlan plans[HRTS_MAX_LIGHTS];
    for (uint32_t i = 0; i < count; i++) {
        cfgs[i] = config(mode);
        memset(&plans[i], 0, sizeof plans[i]);
        plans[i].struct_size = sizeof plans[i];
    }
    HrtsFrame f = frame(VK_NULL_HANDLE, 0);
    f.has_bounds = 1;
    for (int k = 0; k < 3; k++) {
        f.bounds[k] = INFINITY;
        f.bounds[3 + k] = -INFINITY;
    }
    for (uint32_t v = 0; v < g->vertex_count; v++) {
        const float *p = (const float *)((const char *)g->positions + (size_t)v * g->vertex_stride);
        for (int k = 0; k < 3; k++) {
            f.bounds[k] = fminf(f.bounds[k], p[k]);
            f.bounds[3 + k] = fmaxf(f.bounds[3 + k], p[k]);
        }
    }
    HrtsResult r = hrts_plan_lights(cfgs, &f, plans);
    CHECK(r == HRTS_RESULT_OK, "hrts_plan_lights: %s", hrts_last_error(NULL));
    int differ = 0;
    for (uint32_t i = 0; i < count && r == HRTS_RESULT_OK; i++) {
        HrtsFrameReport rep;
        CHECK(report(ctx, index, i, &rep) == HRTS_RESULT_OK, "report %u: %s", i, hrts_last_error(ctx));
        uint32_t in_plan = 0, allocated = 0;
        for (uint32_t p = 0; p < HRTS_PASS_COUNT; p++)
            if (p != HRTS_PASS_OUTPUT_COPY && rep.pass_status[p] != HRTS_PASS_STATUS_NOT_IN_PLAN) in_plan |= 1u << p;
        for (uint32_t q = 0; q < HRTS_RESOURCE_COUNT; q++)
            if (rep.resource_bytes[q] > 0) allocated |= 1u << q;
        int shadowed = plans[i].decision == HRTS_LIGHT_DECISION_SHADOWED;
        int same_plan = shadowed ? plans[i].passes == in_plan && (allocated & ~plans[i].resources) == 0 && allocated != 0
                                 : plans[i].passes == 0 && plans[i].resources == 0;
        int same = plans[i].decision == rep.decision && plans[i].frusta == rep.frusta &&
                   plans[i].frusta_culled == rep.frusta_culled && strcmp(plans[i].decision_reason, rep.decision_reason) == 0 &&
                   plans[i].mode == mode && same_plan;
        if (!same)
            printf("  light %u planned %u (%u frusta, %u culled: %s; passes 0x%x, resources 0x%x), reported %u (%u, %u: %s; "
                   "passes 0x%x, resources allocated 0x%x)\n",
                   i, plans[i].decision, plans[i].frusta, plans[i].frusta_culled, plans[i].decision_reason, plans[i].passes,
                   plans[i].resources, rep.decision, rep.frusta, rep.frusta_culled, rep.decision_reason, in_plan, allocated);
        differ += !same;
    }
    return differ;
}

/* ---------- several lights in one context ---------- */
/* Eight lights, four directional and four spot, hard shadows, in one context sharing the prim buffer:
 * each light's layer of the output matches the exact shadow of that light; the prim buffer is built once,
 * by the first light, and shared; the lights' primitive-map fits are recorded as one batch and their lists in
 * two (the four scratch sets in turn), each report holding its light's share of the batches' time in place
 * of its own fit and lists; each layer equals, bit for bit, the light's alone in a context of its own. */
void several_lights(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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
        /* the primitive maps' build scratch sets serve every light: the same bytes in every report */
        if (i == 0) scratch = rep.map_scratch_bytes;
        CHECK(rep.map_scratch_bytes > 0 && rep.map_scratch_bytes == scratch, "light %d: map scratch %llu bytes, light 0's %llu",
              i, (unsigned long long)rep.map_scratch_bytes, (unsigned long long)scratch);
        double batched_ms = -1.0, listed_ms = -1.0;
        int own_fit = 0, own_lists = 0;
        for (uint32_t p = 0; p < rep.pass_count; p++) {
            if (strcmp(rep.passes[p].name, "primitive map: fit (batched)") == 0) batched_ms = rep.passes[p].milliseconds;
            if (strcmp(rep.passes[p].name, "primitive map: lists (batched)") == 0) listed_ms = rep.passes[p].milliseconds;
            own_fit += strcmp(rep.passes[p].name, "primitive map: fit") == 0;
            own_lists += strcmp(rep.passes[p].name, "primitive map: receivers") == 0;
        }
        printf("light %d (%s): %d lit, %d shadowed, %d near-edge, %d mismatches; prim buffer %s; batched fit %.4f ms, lists %.4f ms\n",
               i, lights[i].spot ? "spot" : "directional", lit, shadowed, near_edge, mismatches,
               rep.pass_status[HRTS_PASS_PRIM_BUFFER] == HRTS_PASS_STATUS_RAN ? "built" : "shared", batched_ms, listed_ms);
        CHECK(batched_ms > 0.0 && own_fit == 0, "light %d: batched fit %.4f ms, %d fits of its own", i, batched_ms, own_fit);
        /* the 8 lights' maps take the 4 scratch sets in turn: two groups of 4, each light's lists in a batch */
        CHECK(listed_ms > 0.0 && own_lists == 0, "light %d: batched lists %.4f ms, %d lists of its own", i, listed_ms, own_lists);
        CHECK(r == HRTS_RESULT_OK, "report of light %d: %s", i, hrts_last_error(ctx));
        CHECK(rep.pass_status[HRTS_PASS_PRIM_BUFFER] == (i == 0 ? HRTS_PASS_STATUS_RAN : HRTS_PASS_STATUS_SHARED),
              "light %d: prim buffer status %u", i, rep.pass_status[HRTS_PASS_PRIM_BUFFER]);
        CHECK(shadowed > 100 && near_edge * 100 <= 4 * W * H, "light %d: %d shadowed, %d near-edge px", i, shadowed, near_edge);
        total_mismatches += mismatches;
        total_shadowed += shadowed;
    }
    printf("8 lights: %d shadowed px in all, %d mismatches\n", total_shadowed, total_mismatches);
    CHECK(total_mismatches == 0, "%d pixels of the 8 lights differ from the exact shadows", total_mismatches);
    /* each light alone in a context of its own (no batch): the same layer bit for bit */
    int differ_alone = 0;
    for (int i = 0; i < N; i++) {
        static float alone[W * H];
        HrtsContext *one = hard_lights_context(vk, g, &lights[i], 1);
        CHECK(run_frame(one, alone) == HRTS_RESULT_OK, "light %d alone: %s", i, hrts_last_error(one));
        for (int p = 0; p < W * H; p++) differ_alone += memcmp(&alone[p], &vis[i * W * H + p], sizeof(float)) != 0;
        CHECK(hrts_context_destroy(one) == HRTS_RESULT_OK, "destroy");
    }
    set_lights(lights, N);
    printf("8 lights batched against each light alone: %d px differ\n", differ_alone);
    CHECK(differ_alone == 0, "%d px of the batched lights differ from the lights alone", differ_alone);
    /* the next frame: static geometry, the prim buffer is up to date for every light */
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "second frame: %s", hrts_last_error(ctx));
    HrtsFrameReport rep;
    CHECK(report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK &&
              rep.pass_status[HRTS_PASS_PRIM_BUFFER] == HRTS_PASS_STATUS_UP_TO_DATE,
          "second frame: prim buffer %u", rep.pass_status[HRTS_PASS_PRIM_BUFFER]);
    /* a frame recorded with the screen-space passes alone (nothing of the light-space ones runs: the prim buffer
     * is up to date) batches the lists as the whole frame does, and gives the same layers */
    {
        static float screen_only[N * W * H];
        VkCommandBuffer cmd = begin();
        uint64_t index = next_frame++;
        HrtsFrame f = frame(cmd, index);
        HrtsResult r = finish_frame(cmd, hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE), screen_only);
        CHECK(r == HRTS_RESULT_OK, "screen-space frame: %s", hrts_last_error(ctx));
        int listed = 0, differ = 0;
        for (int i = 0; i < N && r == HRTS_RESULT_OK; i++) {
            CHECK(report(ctx, index, (uint32_t)i, &rep) == HRTS_RESULT_OK, "report %d: %s", i, hrts_last_error(ctx));
            for (uint32_t p = 0; p < rep.pass_count; p++) listed += strcmp(rep.passes[p].name, "primitive map: lists (batched)") == 0;
        }
        for (int p = 0; p < N * W * H; p++) differ += memcmp(&screen_only[p], &vis[p], sizeof(float)) != 0;
        printf("screen-space passes alone: %d of %d lights' lists batched, %d px differ from the whole frame\n", listed, N, differ);
        CHECK(listed == N && differ == 0, "screen-space frame: %d lists batched, %d px differ", listed, differ);
    }
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
void native_local_lights(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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
    /* planned without a context, both frames' lights get the decisions their reports give */
    int plan_differs = plans_differ_from_reports(ctx, g, N, HRTS_SHADOW_MODE_HARD, next_frame - 1);
    set_lights(lights, N);
    plan_differs += plans_differ_from_reports(ctx, g, N, HRTS_SHADOW_MODE_HARD, first);
    printf("hrts_plan_lights: %d of %d lights planned otherwise than their frames reported\n", plan_differs, 2 * N);
    CHECK(plan_differs == 0, "hrts_plan_lights: %d lights differ from their reports", plan_differs);
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

/* ---------- the plugin's plan for a light ---------- */
/* A sun of no size given in HRTS_SHADOW_MODE_AUTO without a matrix, as an engine hands over its lights: the
 * plugin fits its frustum to the CPU geometry's bounds and chooses hard shadows (no shadow map); the report
 * says so, and the shadow is exact. A light of no size in any other mode is refused. */
void auto_fitted_sun(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
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

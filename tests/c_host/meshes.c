/* The engine's meshes as they are: the scene as three meshes of their own buffers, formats and index types
 * (the one-mesh scene's visibility bit for bit), one of them moved by its draw transform, bad mesh lists;
 * draw transforms set all or nothing. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

/* ---------- the engine's meshes as they are ---------- */
/* The scene as three meshes with buffers of their own: the first ground triangle (float3 positions, 16-bit
 * indices), the box (16-bit snorm positions with a dequantization, 32-bit indices, base vertex -4) and the
 * second ground triangle (float4 positions at an offset, 32-bit indices). The box's dequantization (scale
 * 0.5, offset (0, 1.1, 0)) puts its vertices at q = -1, 0 or 1, which every implementation decodes
 * exactly, so the meshes give the triangles of the one-mesh scene bit for bit. */
static const float BOX_SCALE[3] = {0.5f, 0.5f, 0.5f}, BOX_OFFSET[3] = {0.0f, 1.1f, 0.0f};

/* The box's vertices as snorm16 (w = 0) at `at`; `half`: the box deformed, its x < 0 half gone. */
void box_snorm(uint16_t *at, int half) {
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

void split_scene(SplitScene *s) {
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

/* The default camera, `sun` as the one light, the G-buffer uploaded and the scene as three meshes in `s`: what
 * the mesh tests start from. */
void lit_split_scene(Emitter sun, SplitScene *s) {
    setup_camera(0.0);
    set_lights(&sun, 1);
    upload_gbuffer();
    split_scene(s);
}

void free_split_scene(SplitScene *s) {
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
HrtsContext *meshes_context(const HrtsVulkanDevice *vk, uint32_t frames_in_flight, const HrtsVulkanGeometry *meshes,
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
void engine_meshes(const HrtsVulkanDevice *vk) {
    enum { PX = W * H };
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    SplitScene s;
    lit_split_scene(sun, &s);
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
void draw_transforms_all_or_nothing(const HrtsVulkanDevice *vk) {
    enum { PX = W * H };
    Emitter sun = fitted_sun(v3(0.45, -1.0, 0.2));
    SplitScene s;
    lit_split_scene(sun, &s);
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

/* A deforming mesh: the box skinned into per-frame vertex buffers given through HrtsFrame::deformed, two
 * frames pending at once (the same bits as the geometry given statically), bad deformed lists, the
 * deformed array read by the frame's first call alone, and a destroyed buffer's handle reused. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

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

/* A host allocator for the buffers of reused_vertex_handle that hands the block freed last straight back to
 * the next allocation it fits, as a heap may: vkCreateBuffer right after vkDestroyBuffer gets the destroyed
 * buffer's object memory, hence its handle on drivers whose handles are object pointers (lavapipe's). The
 * process heap does so only by chance (other threads allocate in between), which made the case untested at
 * times. Live blocks are recorded for pfnReallocation. */
enum { RECYCLER_BLOCKS = 256 };
typedef struct {
    void *live[RECYCLER_BLOCKS];
    size_t live_size[RECYCLER_BLOCKS];
    void *freed;
    size_t freed_size;
} Recycler;

static int recycler_find(const Recycler *r, const void *p) {
    for (int i = 0; i < RECYCLER_BLOCKS; i++)
        if (r->live[i] == p) return i;
    return -1;
}

static void *VKAPI_PTR recycler_alloc(void *user, size_t size, size_t align, VkSystemAllocationScope scope) {
    (void)scope;
    Recycler *r = user;
    int slot = recycler_find(r, NULL);
    if (slot < 0 || size == 0) return NULL;
    void *p = NULL;
    if (r->freed && size <= r->freed_size && (uintptr_t)r->freed % align == 0) {
        p = r->freed;
        size = r->freed_size;
        r->freed = NULL;
    } else if (posix_memalign(&p, align < sizeof(void *) ? sizeof(void *) : align, size) != 0) {
        return NULL;
    }
    r->live[slot] = p;
    r->live_size[slot] = size;
    return p;
}

static void VKAPI_PTR recycler_free(void *user, void *p) {
    Recycler *r = user;
    int slot = p ? recycler_find(r, p) : -1;
    if (slot < 0) return;
    if (r->freed) free(r->freed);
    r->freed = p;
    r->freed_size = r->live_size[slot];
    r->live[slot] = NULL;
}

static void *VKAPI_PTR recycler_realloc(void *user, void *old, size_t size, size_t align, VkSystemAllocationScope scope) {
    Recycler *r = user;
    if (!old) return recycler_alloc(user, size, align, scope);
    if (size == 0) {
        recycler_free(user, old);
        return NULL;
    }
    int slot = recycler_find(r, old);
    void *p = slot < 0 ? NULL : recycler_alloc(user, size, align, scope);
    if (!p) return NULL;
    memcpy(p, old, r->live_size[slot] < size ? r->live_size[slot] : size);
    recycler_free(user, old);
    return p;
}

/* A vertex buffer's handle reused: the engine destroys a skinned buffer once the frame that read it
 * completed and creates one of the same size over other memory of its own block; the driver hands back the
 * same VkBuffer handle (made certain by the Recycler above). The next frame, within frames_in_flight of the
 * first, must read the new buffer (the box deformed, B), not the destroyed one's memory (the box, A). `want`
 * holds A's and B's visibility. */
static void reused_vertex_handle(HrtsContext *ctx, const float *want_a, const float *want_b) {
    enum { PX = W * H, TRIES = 64 };
    static Recycler recycler;
    const VkAllocationCallbacks host = {
        .pUserData = &recycler,
        .pfnAllocation = recycler_alloc,
        .pfnReallocation = recycler_realloc,
        .pfnFree = recycler_free,
    };
    const VkDeviceSize size = BOX_VERTICES * 8;
    VkBufferCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = size;
    ci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer first;
    VK(vkCreateBuffer(device, &ci, &host, &first));
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
    vkDestroyBuffer(device, first, &host);
    VkBuffer tried[TRIES], again = VK_NULL_HANDLE;
    int n = 0;
    while (n < TRIES && again == VK_NULL_HANDLE) {
        VK(vkCreateBuffer(device, &ci, &host, &tried[n]));
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
    for (int k = 0; k < n; k++) vkDestroyBuffer(device, tried[k], &host);
    free(recycler.freed);
    recycler.freed = NULL;
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
void deforming_mesh(const HrtsVulkanDevice *vk) {
    enum { PX = W * H, IN_FLIGHT_2 = 2, NONE = -1, A = 0, B = 1 };
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    SplitScene s;
    lit_split_scene(sun, &s);
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

/* Misuse of the C ABI: a table of calls that must fail with a given result and a message of their own (NULL
 * pointers, wrong struct sizes and versions, misaligned structs and arrays, invalid arguments and enums,
 * calls out of order, reports and read-backs the plugin cannot give, destroyed and forged handles,
 * allocation callbacks installed too late), each leaving the context usable. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

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

/* ---------- misuse: a table of calls that must fail with a given result and a message ---------- */
/* Each case runs in table order on one context (some build on the state left by the ones before); after
 * each, the context must still answer. A successful call clears the last error, so a case that fails with
 * the right code but no message of its own fails. */
enum {
    CREATE_NULL_INFO, CREATE_NULL_OUT, CREATE_STRUCT_SIZE, CREATE_VERSION, CREATE_NULL_DEVICE, CREATE_NULL_GIPA,
    CREATE_DEVICE_STRUCT_SIZE, CREATE_FRAMES_IN_FLIGHT, CREATE_UNSUPPORTED_EXTENSION, CREATE_NO_SUCH_QUEUE_FAMILY,
    CREATE_NO_SUCH_QUEUE, CREATE_MISALIGNED_DEVICE, CREATE_MISALIGNED_EXTENSIONS, CREATE_NEWER_MINOR,
    CREATE_VERSION_5_0, CAPS_NULL_CONTEXT, CAPS_NULL_OUT, CAPS_STRUCT_SIZE, CONFIG_N_PAST_MAX, CONFIG_N_ABSURD,
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
    FRAME_DEFORMED_NULL, FRAME_DEFORMED_MESH, PLAN_NULL_CONFIGS, PLAN_NULL_PLANS, PLAN_STRUCT_SIZE, PLAN_MIXED_SIZES,
    PLAN_MODE, PLAN_NULL_FRAME,
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
    [CONFIG_N_PAST_MAX] = {"configure(N = max_map_size + 1)", HRTS_RESULT_ERROR_INVALID_ARGUMENT},
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
    [PLAN_NULL_CONFIGS] = {"plan_lights(NULL configs)", HRTS_RESULT_ERROR_NULL_POINTER},
    [PLAN_NULL_PLANS] = {"plan_lights(NULL plans)", HRTS_RESULT_ERROR_NULL_POINTER},
    [PLAN_STRUCT_SIZE] = {"plan_lights(plans[0].struct_size 12)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [PLAN_MIXED_SIZES] = {"plan_lights(plans of two sizes)", HRTS_RESULT_ERROR_STRUCT_SIZE},
    [PLAN_MODE] = {"plan_lights(unknown mode)", HRTS_RESULT_ERROR_INVALID_ENUM},
    [PLAN_NULL_FRAME] = {"plan_lights(NULL frame)", HRTS_RESULT_ERROR_NULL_POINTER},
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
    case CONFIG_N_PAST_MAX:
        if (hrts_get_capabilities(ctx, &caps) != HRTS_RESULT_OK) return HRTS_RESULT_ERROR_INTERNAL;
        c.map_size = caps.max_map_size + 1;
        return hrts_configure(ctx, &c);
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
    case PLAN_NULL_CONFIGS:
    case PLAN_NULL_PLANS:
    case PLAN_STRUCT_SIZE:
    case PLAN_MIXED_SIZES:
    case PLAN_MODE:
    case PLAN_NULL_FRAME: {
        /* two lights planned without a context */
        HrtsLight two[2] = {lights[0], lights[0]};
        f.lights = two;
        f.light_count = 2;
        HrtsConfig cfgs[2] = {config(HRTS_SHADOW_MODE_HARD), config(HRTS_SHADOW_MODE_HARD)};
        HrtsLightPlan plans[2];
        memset(plans, 0, sizeof plans);
        plans[0].struct_size = plans[1].struct_size = sizeof plans[0];
        if (id == PLAN_STRUCT_SIZE) plans[0].struct_size = 12;
        if (id == PLAN_MIXED_SIZES) plans[1].struct_size = 12;
        if (id == PLAN_MODE) cfgs[1].mode = 99;
        return hrts_plan_lights(id == PLAN_NULL_CONFIGS ? NULL : cfgs, id == PLAN_NULL_FRAME ? NULL : &f,
                                id == PLAN_NULL_PLANS ? NULL : plans);
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

void misuse(HrtsContext *ctx, const HrtsVulkanDevice *vk) {
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

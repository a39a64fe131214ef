/* The engine's memory: the host allocator it hands the plugin before anything else (installed once), and
 * 100 create/destroy cycles after which no Vulkan object leaks, the plugin's host and GPU memory are back
 * where they were and every byte the plugin holds came from that allocator. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

/* The engine's host allocator, handed to the plugin before anything else: it counts live bytes. */
static size_t engine_live_bytes, engine_allocations;

void *engine_allocate(void *user, size_t size, size_t alignment) {
    (void)user;
    void *p = NULL;
    if (alignment < sizeof(void *)) alignment = sizeof(void *);
    if (posix_memalign(&p, alignment, size ? size : 1) != 0) return NULL;
    __atomic_fetch_add(&engine_live_bytes, size, __ATOMIC_RELAXED);
    __atomic_fetch_add(&engine_allocations, 1, __ATOMIC_RELAXED);
    return p;
}

void engine_free(void *user, void *memory, size_t size, size_t alignment) {
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

/* Installs the engine's allocator, before the plugin allocated anything; a second install is refused. */
void install_engine_allocator(void) {
    HrtsAllocationCallbacks callbacks;
    memset(&callbacks, 0, sizeof callbacks);
    callbacks.struct_size = sizeof callbacks;
    callbacks.allocate = engine_allocate;
    callbacks.free = engine_free;
    CHECK(hrts_set_allocation_callbacks(&callbacks) == HRTS_RESULT_OK, "allocation callbacks: %s", hrts_last_error(NULL));
    CHECK(hrts_set_allocation_callbacks(&callbacks) == HRTS_RESULT_ERROR_INVALID_STATE, "second install accepted");
}

/* 100 create/destroy cycles, each recording a frame: no Vulkan object leaks (the validation layer's
 * object tracker reports them at vkDestroyDevice), and the plugin's host and GPU memory return exactly
 * to where they were. Resident memory is reported too: lavapipe keeps each compiled pipeline's JIT
 * code until its VkDevice is destroyed, so RSS grows on lavapipe whatever the plugin does. Then the engine's
 * allocator holds exactly the live bytes the plugin reports. */
void create_destroy_cycles(const HrtsVulkanDevice *vk, const HrtsConfig *cfg, const HrtsCpuGeometry *g,
                           const HrtsTargets *t) {
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
        HrtsContext *c = create_context(vk, 1);
        HrtsResult r = hrts_configure(c, cfg);
        if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(c, g);
        if (r == HRTS_RESULT_OK) r = hrts_set_targets(c, t);
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
}

/* A program of its own (no code of this project) that corrupts the heap inside Debian 12's Khronos
 * validation layer (vulkan-validationlayers 1.3.239) on lavapipe: see README.md beside it.
 *
 * Each iteration does what a simple renderer's "submit and wait" does: allocate a command buffer, record
 * PASSES debug-utils labels into it (each around a timestamp, a buffer fill and a barrier, the timestamps
 * after a query-pool reset), submit it with a new fence, wait for the fence, destroy the fence and free the
 * command buffer. Everything is valid Vulkan: the layer reports no error. Options (environment):
 *   ITERATIONS  iterations (default 200000)
 *   PASSES      labelled passes per command buffer (default 4)
 *   LABELS      0: no debug-utils labels (default 1)
 *   TIMESTAMPS  0: no query pool and no timestamps (default 1)
 *   REUSE_CB    1: one command buffer reset and re-recorded instead of one allocated and freed each time
 *   REUSE_FENCE 1: one fence reset and reused instead of one created and destroyed each time
 *   IDLE        1: vkQueueWaitIdle after the fence wait
 *   LAYER       0: without the validation layer
 *   SYNCVAL     1: with synchronization validation
 * Exits 0 with no validation message; a heap corruption aborts it (SIGABRT) or crashes it (SIGSEGV).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <vulkan/vulkan.h>

#define VK(x)                                                                                                \
    do {                                                                                                     \
        VkResult r_ = (x);                                                                                   \
        if (r_ != VK_SUCCESS) {                                                                              \
            fprintf(stderr, "%s failed: %d (line %d)\n", #x, r_, __LINE__);                                  \
            exit(2);                                                                                         \
        }                                                                                                    \
    } while (0)

static int messages;

static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT types,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data, void *user) {
    (void)types;
    (void)user;
    if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)) {
        messages++;
        fprintf(stderr, "validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

static long option(const char *name, long fallback) {
    const char *v = getenv(name);
    return v && *v ? strtol(v, NULL, 10) : fallback;
}

int main(void) {
    long iterations = option("ITERATIONS", 200000);
    int labels = option("LABELS", 1), timestamps = option("TIMESTAMPS", 1), reuse_cb = option("REUSE_CB", 0);
    int reuse_fence = option("REUSE_FENCE", 0), idle = option("IDLE", 0), layer = option("LAYER", 1);
    int syncval = option("SYNCVAL", 0);
    uint32_t passes = (uint32_t)option("PASSES", 4);

    const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
    const char *extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO, .apiVersion = VK_API_VERSION_1_3};
    VkDebugUtilsMessengerCreateInfoEXT mi = {.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mi.pfnUserCallback = on_message;
    VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT vf = {.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT, .pNext = &mi};
    vf.enabledValidationFeatureCount = 1;
    vf.pEnabledValidationFeatures = enables;
    VkInstanceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pNext = syncval ? (const void *)&vf : (const void *)&mi;
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = layer ? 1 : 0;
    ci.ppEnabledLayerNames = layers;
    ci.enabledExtensionCount = syncval ? 2 : 1;
    ci.ppEnabledExtensionNames = extensions;
    VkInstance instance;
    VK(vkCreateInstance(&ci, NULL, &instance));
    PFN_vkCreateDebugUtilsMessengerEXT create_messenger =
        (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT");
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger =
        (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT");
    PFN_vkCmdBeginDebugUtilsLabelEXT begin_label =
        (PFN_vkCmdBeginDebugUtilsLabelEXT)vkGetInstanceProcAddr(instance, "vkCmdBeginDebugUtilsLabelEXT");
    PFN_vkCmdEndDebugUtilsLabelEXT end_label =
        (PFN_vkCmdEndDebugUtilsLabelEXT)vkGetInstanceProcAddr(instance, "vkCmdEndDebugUtilsLabelEXT");
    VkDebugUtilsMessengerEXT messenger;
    VK(create_messenger(instance, &mi, NULL, &messenger));

    uint32_t count = 1;
    VkPhysicalDevice physical;
    VkResult listed = vkEnumeratePhysicalDevices(instance, &count, &physical);
    if ((listed != VK_SUCCESS && listed != VK_INCOMPLETE) || count == 0) {
        fprintf(stderr, "no Vulkan device\n");
        return 2;
    }
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physical, &props);
    float priority = 1.0f;
    VkDeviceQueueCreateInfo qi = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qi.queueFamilyIndex = 0; /* lavapipe: one family, graphics + compute + transfer */
    qi.queueCount = 1;
    qi.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan13Features f13 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.synchronization2 = VK_TRUE;
    VkDeviceCreateInfo di = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, .pNext = &f13};
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &qi;
    VkDevice device;
    VK(vkCreateDevice(physical, &di, NULL, &device));
    VkQueue queue;
    vkGetDeviceQueue(device, 0, 0, &queue);

    VkCommandPoolCreateInfo pi = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    VkCommandPool pool;
    VK(vkCreateCommandPool(device, &pi, NULL, &pool));
    VkQueryPoolCreateInfo qpi = {.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qpi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qpi.queryCount = 2 * passes;
    VkQueryPool queries;
    VK(vkCreateQueryPool(device, &qpi, NULL, &queries));

    VkBufferCreateInfo bi = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = 4096;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer buffer;
    VK(vkCreateBuffer(device, &bi, NULL, &buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer, &req);
    VkMemoryAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = (uint32_t)__builtin_ctz(req.memoryTypeBits);
    VkDeviceMemory memory;
    VK(vkAllocateMemory(device, &ai, NULL, &memory));
    VK(vkBindBufferMemory(device, buffer, memory, 0));

    VkCommandBufferAllocateInfo cai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    VkFenceCreateInfo fi = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkCommandBuffer kept = VK_NULL_HANDLE;
    VkFence kept_fence = VK_NULL_HANDLE;
    if (reuse_cb) VK(vkAllocateCommandBuffers(device, &cai, &kept));
    if (reuse_fence) VK(vkCreateFence(device, &fi, NULL, &kept_fence));

    printf("%s, layer %s, labels %d, timestamps %d, reuse_cb %d, reuse_fence %d, idle %d, syncval %d: %ld iterations\n",
           props.deviceName, layer ? "on" : "off", labels, timestamps, reuse_cb, reuse_fence, idle, syncval, iterations);
    fflush(stdout);
    for (long i = 0; i < iterations; i++) {
        VkCommandBuffer cmd = kept;
        if (!reuse_cb) VK(vkAllocateCommandBuffers(device, &cai, &cmd));
        VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VK(vkBeginCommandBuffer(cmd, &begin));
        if (timestamps) vkCmdResetQueryPool(cmd, queries, 0, 2 * passes);
        for (uint32_t pass = 0; pass < passes; pass++) {
            VkDebugUtilsLabelEXT label = {.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT, .pLabelName = "pass"};
            if (labels) begin_label(cmd, &label);
            if (timestamps) vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 2 * pass);
            vkCmdFillBuffer(cmd, buffer, 0, VK_WHOLE_SIZE, pass);
            VkMemoryBarrier2 mb = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
            mb.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
            mb.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
            mb.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
            mb.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
            VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
            dep.memoryBarrierCount = 1;
            dep.pMemoryBarriers = &mb;
            vkCmdPipelineBarrier2(cmd, &dep);
            if (timestamps) vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 2 * pass + 1);
            if (labels) end_label(cmd);
        }
        VK(vkEndCommandBuffer(cmd));
        VkFence fence = kept_fence;
        if (!reuse_fence) VK(vkCreateFence(device, &fi, NULL, &fence));
        VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cmd;
        VK(vkQueueSubmit(queue, 1, &si, fence));
        VK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
        if (idle) VK(vkQueueWaitIdle(queue));
        if (reuse_fence) VK(vkResetFences(device, 1, &fence));
        else vkDestroyFence(device, fence, NULL);
        if (reuse_cb) VK(vkResetCommandBuffer(cmd, 0));
        else vkFreeCommandBuffers(device, pool, 1, &cmd);
        if (timestamps) {
            uint64_t stamps[2 * 1024];
            VK(vkGetQueryPoolResults(device, queries, 0, 2 * passes, 16 * passes, stamps, 8,
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
        }
        if ((i + 1) % 20000 == 0) {
            printf("%ld iterations\n", i + 1);
            fflush(stdout);
        }
    }
    if (reuse_cb) vkFreeCommandBuffers(device, pool, 1, &kept);
    if (reuse_fence) vkDestroyFence(device, kept_fence, NULL);
    vkDestroyBuffer(device, buffer, NULL);
    vkFreeMemory(device, memory, NULL);
    vkDestroyQueryPool(device, queries, NULL);
    vkDestroyCommandPool(device, pool, NULL);
    vkDestroyDevice(device, NULL);
    destroy_messenger(instance, messenger, NULL);
    vkDestroyInstance(instance, NULL);
    printf("done: %d validation messages\n", messages);
    return messages ? 1 : 0;
}

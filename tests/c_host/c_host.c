/* A plain C engine that integrates the plugin through hrts.h: it creates its own Vulkan device through
 * the loader (validation layer on), draws the depth and normal images of a box floating over a ground
 * plane itself (analytic ray casting on the CPU), records the plugin into its own command buffer, reads
 * back the visibility image and compares it with the exact shadow of that scene. It then checks misuse
 * cases and 100 create/destroy cycles. Prints "N passed, M failed" and exits non-zero on any failure. */
#define _POSIX_C_SOURCE 200112L
#include "hrts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <vulkan/vulkan.h>

static int passed, failed;

#define CHECK(cond, ...)                          \
    do {                                          \
        if (cond) {                               \
            passed++;                             \
        } else {                                  \
            failed++;                             \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__); \
            fprintf(stderr, __VA_ARGS__);         \
            fprintf(stderr, "\n");                \
        }                                         \
    } while (0)

#define VK(call)                                                        \
    do {                                                                \
        VkResult r_ = (call);                                           \
        if (r_ != VK_SUCCESS) {                                         \
            fprintf(stderr, "%s failed: %d\n", #call, (int)r_);         \
            exit(2);                                                    \
        }                                                               \
    } while (0)

/* ---------- scene: ground quad y = 0 (|x|,|z| <= 4) and a box [-0.5,0.5]x[0.6,1.6]x[-0.5,0.5] ---------- */
static const double BOX_MIN[3] = {-0.5, 0.6, -0.5};
static const double BOX_MAX[3] = {0.5, 1.6, 0.5};
static const double GROUND = 4.0;

static float positions[] = {
    -4, 0, -4, 4, 0, -4, 4, 0, 4, -4, 0, 4, /* ground 0..3 */
    -0.5f, 0.6f, -0.5f, 0.5f, 0.6f, -0.5f, 0.5f, 1.6f, -0.5f, -0.5f, 1.6f, -0.5f, /* box 4..11 */
    -0.5f, 0.6f, 0.5f, 0.5f, 0.6f, 0.5f, 0.5f, 1.6f, 0.5f, -0.5f, 1.6f, 0.5f,
};
static uint32_t indices[] = {
    0, 2, 1, 0, 3, 2, /* ground, facing +y */
    4, 6, 5, 4, 7, 6, 8, 9, 10, 8, 10, 11, 4, 5, 9, 4, 9, 8, /* box back, front, bottom */
    7, 10, 6, 7, 11, 10, 4, 8, 11, 4, 11, 7, 5, 6, 10, 5, 10, 9, /* top, left, right */
};

typedef struct {
    double x, y, z;
} V3;
static V3 v3(double x, double y, double z) { V3 r = {x, y, z}; return r; }
static V3 sub3(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static V3 add3(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static V3 mul3(V3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static double dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static V3 cross3(V3 a, V3 b) { return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static V3 norm3(V3 a) { return mul3(a, 1.0 / sqrt(dot3(a, a))); }

/* Ray vs the box grown by `grow` (negative shrinks): entry distance and face normal, or -1. */
static double ray_box(V3 o, V3 d, double grow, V3 *normal) {
    double o_[3] = {o.x, o.y, o.z}, d_[3] = {d.x, d.y, d.z}, t0 = -1e300, t1 = 1e300;
    int axis = -1;
    double sign = 0;
    for (int i = 0; i < 3; i++) {
        double lo = BOX_MIN[i] - grow, hi = BOX_MAX[i] + grow;
        if (d_[i] == 0.0) {
            if (o_[i] < lo || o_[i] > hi) return -1;
            continue;
        }
        double a = (lo - o_[i]) / d_[i], b = (hi - o_[i]) / d_[i];
        double s = -1;
        if (a > b) { double t = a; a = b; b = t; s = 1; }
        if (a > t0) { t0 = a; axis = i; sign = d_[i] > 0 ? -1 : 1; (void)s; }
        if (b < t1) t1 = b;
    }
    if (t0 > t1 || t1 < 0 || axis < 0) return -1;
    if (normal) {
        double n[3] = {0, 0, 0};
        n[axis] = sign;
        *normal = v3(n[0], n[1], n[2]);
    }
    return t0 > 0 ? t0 : 0;
}

/* ---------- camera and light ---------- */
enum { W = 160, H = 120 };
static const double FOV_Y = 0.8, NEAR = 0.05;
static V3 cam_pos, cam_f, cam_r, cam_u;
static V3 light_dir; /* direction the light travels */
static float view[16], proj[16], light_vp[16];

static void setup_camera(void) {
    cam_pos = v3(3.2, 2.6, 3.9);
    V3 target = v3(0, 0.5, 0);
    cam_f = norm3(sub3(target, cam_pos));
    cam_r = norm3(cross3(cam_f, v3(0, 1, 0)));
    cam_u = cross3(cam_r, cam_f);
    /* view = look_at_rh: rows r, u, -f */
    float m[16] = {(float)cam_r.x, (float)cam_u.x, (float)-cam_f.x, 0, (float)cam_r.y, (float)cam_u.y, (float)-cam_f.y, 0,
                   (float)cam_r.z, (float)cam_u.z, (float)-cam_f.z, 0, (float)-dot3(cam_r, cam_pos),
                   (float)-dot3(cam_u, cam_pos), (float)dot3(cam_f, cam_pos), 1};
    memcpy(view, m, sizeof m);
    /* reversed-Z infinite perspective with clip y negated (Vulkan framebuffer y points down) */
    double f = 1.0 / tan(FOV_Y / 2), aspect = (double)W / H;
    float p[16] = {(float)(f / aspect), 0, 0, 0, 0, (float)-f, 0, 0, 0, 0, 0, -1, 0, 0, (float)NEAR, 0};
    memcpy(proj, p, sizeof p);
    light_dir = norm3(v3(0.45, -1.0, 0.2));
    /* orthographic light view-projection enclosing the scene: basis (lx, ly, -light_dir) */
    V3 lz = mul3(light_dir, -1.0), lx = norm3(cross3(v3(0, 0, 1), lz)), ly = cross3(lz, lx);
    double ext = 8.0, depth = 16.0;
    /* x' = dot(lx,p)/ext, y' = dot(ly,p)/ext, z' = 0.5 - dot(lz,p)/depth maps the scene into [0,1] */
    float l[16] = {(float)(lx.x / ext), (float)(ly.x / ext), (float)(-lz.x / depth), 0, (float)(lx.y / ext), (float)(ly.y / ext),
                   (float)(-lz.y / depth), 0, (float)(lx.z / ext), (float)(ly.z / ext), (float)(-lz.z / depth), 0, 0, 0, 0.5f, 1};
    memcpy(light_vp, l, sizeof l);
}

/* Camera ray through pixel (x, y) centre. */
static V3 pixel_ray(double x, double y) {
    double f = 1.0 / tan(FOV_Y / 2), aspect = (double)W / H;
    double nx = (x + 0.5) / W * 2 - 1, ny = (y + 0.5) / H * 2 - 1;
    /* clip y is negated: NDC y down is view-space up */
    return add3(add3(mul3(cam_r, nx * aspect / f), mul3(cam_u, -ny / f)), cam_f);
}

/* Nearest surface under a camera ray: 0 background, 1 ground, 2 box; t along `d` (|d| >= 1). */
static int cast(V3 o, V3 d, double grow, double *t, V3 *n) {
    double tb = ray_box(o, d, grow, n);
    double tg = d.y < 0 ? -o.y / d.y : -1;
    if (tg > 0) {
        V3 p = add3(o, mul3(d, tg));
        if (fabs(p.x) > GROUND || fabs(p.z) > GROUND) tg = -1;
    }
    if (tb > 0 && (tg < 0 || tb < tg)) { *t = tb; return 2; }
    if (tg > 0) { *t = tg; *n = v3(0, 1, 0); return 1; }
    return 0;
}

/* Exact classification: 1 lit, 0 shadowed, -1 near an edge (within tol), -2 background. */
static int exact(int x, int y, double tol) {
    V3 d = pixel_ray(x, y), n;
    double t;
    int hit = cast(cam_pos, d, 0, &t, &n);
    if (hit == 0) {
        double t2;
        V3 n2;
        return cast(cam_pos, d, tol, &t2, &n2) ? -1 : -2;
    }
    /* camera near a box silhouette or edge: the grown and shrunk boxes disagree */
    double t_in, t_out;
    V3 na, nb;
    int in = cast(cam_pos, d, -tol, &t_in, &na), out = cast(cam_pos, d, tol, &t_out, &nb);
    if (in != out || in != hit || (na.x != nb.x || na.y != nb.y || na.z != nb.z)) return -1;
    V3 p = add3(cam_pos, mul3(d, t)), L = mul3(light_dir, -1.0);
    double c = dot3(n, L);
    if (fabs(c) < 1e-6) return -1;
    if (c < 0) return 0;
    if (hit == 2) return 1; /* a convex box never shadows itself; the ground is below it */
    int shrunk = ray_box(p, L, -tol, NULL) >= 0, grown = ray_box(p, L, tol, NULL) >= 0;
    if (shrunk) return 0;
    if (!grown) return 1;
    return -1;
}

/* ---------- Vulkan helpers ---------- */
static VkInstance instance;
static VkPhysicalDevice phys;
static VkDevice device;
static VkQueue queue;
static uint32_t family;
static VkCommandPool pool;
static int validation_errors;

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                    VkDebugUtilsMessageTypeFlagsEXT types,
                                                    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user) {
    (void)types;
    (void)user;
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        validation_errors++;
        fprintf(stderr, "validation error: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

static uint32_t memory_type(uint32_t bits, VkMemoryPropertyFlags want) {
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(phys, &mp);
    for (uint32_t i = 0; i < mp.memoryTypeCount; i++)
        if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return i;
    fprintf(stderr, "no memory type\n");
    exit(2);
}

typedef struct {
    VkImage image;
    VkDeviceMemory memory;
} Img;

static Img make_image(VkFormat format, VkImageUsageFlags usage) {
    Img r;
    VkImageCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = format;
    ci.extent.width = W;
    ci.extent.height = H;
    ci.extent.depth = 1;
    ci.mipLevels = 1;
    ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = usage;
    VK(vkCreateImage(device, &ci, NULL, &r.image));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, r.image, &req);
    VkMemoryAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VK(vkAllocateMemory(device, &ai, NULL, &r.memory));
    VK(vkBindImageMemory(device, r.image, r.memory, 0));
    return r;
}

typedef struct {
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *map;
} Buf;

static Buf make_host_buffer(VkDeviceSize size, VkBufferUsageFlags usage) {
    Buf r;
    VkBufferCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = size;
    ci.usage = usage;
    VK(vkCreateBuffer(device, &ci, NULL, &r.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, r.buffer, &req);
    VkMemoryAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex =
        memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VK(vkAllocateMemory(device, &ai, NULL, &r.memory));
    VK(vkBindBufferMemory(device, r.buffer, r.memory, 0));
    VK(vkMapMemory(device, r.memory, 0, size, 0, &r.map));
    return r;
}

static void free_buffer(Buf b) {
    vkUnmapMemory(device, b.memory);
    vkDestroyBuffer(device, b.buffer, NULL);
    vkFreeMemory(device, b.memory, NULL);
}

static void barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to) {
    VkImageMemoryBarrier2 b = {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
    b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange.aspectMask = aspect;
    b.subresourceRange.levelCount = 1;
    b.subresourceRange.layerCount = 1;
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

static VkCommandBuffer begin(void) {
    VkCommandBufferAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cmd;
    VK(vkAllocateCommandBuffers(device, &ai, &cmd));
    VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK(vkBeginCommandBuffer(cmd, &bi));
    return cmd;
}

static void submit_and_wait(VkCommandBuffer cmd) {
    VK(vkEndCommandBuffer(cmd));
    VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VkFenceCreateInfo fi = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    VK(vkCreateFence(device, &fi, NULL, &fence));
    VK(vkQueueSubmit(queue, 1, &si, fence));
    VK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
    vkDestroyFence(device, fence, NULL);
    vkFreeCommandBuffers(device, pool, 1, &cmd);
}

static void create_device(void) {
    const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
    const char *inst_ext[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "hrts C host";
    app.apiVersion = VK_API_VERSION_1_3;
    VkDebugUtilsMessengerCreateInfoEXT mi = {.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    mi.pfnUserCallback = on_validation;
    VkInstanceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pNext = &mi; /* also reports leaks found when the device and instance are destroyed */
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = 1;
    ci.ppEnabledLayerNames = layers;
    ci.enabledExtensionCount = 1;
    ci.ppEnabledExtensionNames = inst_ext;
    VK(vkCreateInstance(&ci, NULL, &instance));
    uint32_t n = 8;
    VkPhysicalDevice pds[8];
    VK(vkEnumeratePhysicalDevices(instance, &n, pds));
    const char *want = getenv("HRTS_DEVICE");
    phys = VK_NULL_HANDLE;
    for (uint32_t i = 0; i < n && !phys; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(pds[i], &p);
        if (p.apiVersion < VK_API_VERSION_1_3) continue;
        if (want && !strstr(p.deviceName, want)) continue;
        phys = pds[i];
        printf("device: %s\n", p.deviceName);
    }
    if (!phys) { fprintf(stderr, "no Vulkan 1.3 device\n"); exit(2); }
    uint32_t nf = 16;
    VkQueueFamilyProperties qf[16];
    vkGetPhysicalDeviceQueueFamilyProperties(phys, &nf, qf);
    for (family = 0; family < nf; family++)
        if ((qf[family].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) == (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) break;
    float prio = 1;
    VkDeviceQueueCreateInfo qi = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qi.queueFamilyIndex = family;
    qi.queueCount = 1;
    qi.pQueuePriorities = &prio;
    VkPhysicalDeviceVulkan13Features f13 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.dynamicRendering = VK_TRUE;
    f13.synchronization2 = VK_TRUE;
    VkPhysicalDeviceFeatures feats;
    memset(&feats, 0, sizeof feats);
    feats.geometryShader = VK_TRUE;
    feats.fragmentStoresAndAtomics = VK_TRUE;
    feats.depthClamp = VK_TRUE;
    VkDeviceCreateInfo di = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    di.pNext = &f13;
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &qi;
    di.pEnabledFeatures = &feats;
    VK(vkCreateDevice(phys, &di, NULL, &device));
    vkGetDeviceQueue(device, family, 0, &queue);
    VkCommandPoolCreateInfo pi = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.queueFamilyIndex = family;
    VK(vkCreateCommandPool(device, &pi, NULL, &pool));
}

static HrtsVulkanDevice adopt_info(void) {
    HrtsVulkanDevice v;
    memset(&v, 0, sizeof v);
    v.struct_size = sizeof v;
    v.get_instance_proc_addr = (HrtsGetInstanceProcAddr)vkGetInstanceProcAddr;
    v.instance = (uint64_t)(uintptr_t)instance;
    v.physical_device = (uint64_t)(uintptr_t)phys;
    v.device = (uint64_t)(uintptr_t)device;
    v.queue_family_index = family;
    v.geometry_shader = true;
    v.fragment_stores_and_atomics = true;
    v.depth_clamp = true;
    v.debug_utils = true;
    return v;
}

static HrtsContext *create_context(const HrtsVulkanDevice *v) {
    HrtsContextCreateInfo ci;
    memset(&ci, 0, sizeof ci);
    ci.struct_size = sizeof ci;
    ci.api_version = HRTS_API_VERSION;
    ci.vulkan = v;
    HrtsContext *ctx = NULL;
    HrtsResult r = hrts_context_create(&ci, &ctx);
    if (r != HRTS_RESULT_OK) {
        fprintf(stderr, "hrts_context_create: %s: %s\n", hrts_result_name(r), hrts_last_error(NULL));
        exit(2);
    }
    return ctx;
}

static HrtsDraw draws[2];
static HrtsCpuGeometry cpu_geometry(void) {
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    draws[0].first_index = 0;
    draws[0].index_count = 6;
    draws[1].first_index = 6;
    draws[1].index_count = 36;
    memcpy(draws[0].transform, identity, sizeof identity);
    memcpy(draws[1].transform, identity, sizeof identity);
    HrtsCpuGeometry g;
    memset(&g, 0, sizeof g);
    g.struct_size = sizeof g;
    g.positions = positions;
    g.vertex_count = 12;
    g.vertex_stride = 12;
    g.indices = indices;
    g.index_count = 42;
    g.draws = draws;
    g.draw_count = 2;
    return g;
}

static Img depth_img, normal_img, out_img;

static HrtsTargets targets(void) {
    HrtsTargets t;
    memset(&t, 0, sizeof t);
    t.struct_size = sizeof t;
    t.width = W;
    t.height = H;
    t.depth_image = (uint64_t)(uintptr_t)depth_img.image;
    t.depth_usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    t.normal_image = (uint64_t)(uintptr_t)normal_img.image;
    t.normal_usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    t.output_image = (uint64_t)(uintptr_t)out_img.image;
    t.output_usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    return t;
}

static HrtsFrame frame(VkCommandBuffer cmd) {
    HrtsFrame f;
    memset(&f, 0, sizeof f);
    f.struct_size = sizeof f;
    f.command_buffer = (uint64_t)(uintptr_t)cmd;
    memcpy(f.view, view, sizeof view);
    memcpy(f.proj, proj, sizeof proj);
    f.camera_position[0] = (float)cam_pos.x;
    f.camera_position[1] = (float)cam_pos.y;
    f.camera_position[2] = (float)cam_pos.z;
    f.light_direction[0] = (float)light_dir.x;
    f.light_direction[1] = (float)light_dir.y;
    f.light_direction[2] = (float)light_dir.z;
    memcpy(f.light_view_proj, light_vp, sizeof light_vp);
    f.depth_layout = VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL;
    f.normal_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    f.output_layout_before = VK_IMAGE_LAYOUT_UNDEFINED;
    f.output_layout_after = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    return f;
}

/* Draws depth and normals (the engine's own pass, done on the CPU here) and uploads them. */
static void upload_gbuffer(void) {
    Buf depth = make_host_buffer(sizeof(float) * W * H, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    Buf normal = make_host_buffer(sizeof(float) * 4 * W * H, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    float *dp = depth.map, *np = normal.map;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            V3 d = pixel_ray(x, y), n;
            double t;
            int hit = cast(cam_pos, d, 0, &t, &n);
            int i = y * W + x;
            /* pixel_ray has unit length along the view axis, so view depth = t */
            dp[i] = hit ? (float)(NEAR / t) : 0.0f;
            if (hit && dot3(n, d) > 0) n = mul3(n, -1.0);
            np[4 * i + 0] = hit ? (float)n.x : 0;
            np[4 * i + 1] = hit ? (float)n.y : 0;
            np[4 * i + 2] = hit ? (float)n.z : 0;
            np[4 * i + 3] = hit ? 1.0f : 0.0f;
        }
    VkCommandBuffer cmd = begin();
    barrier(cmd, depth_img.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    barrier(cmd, normal_img.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    VkBufferImageCopy region;
    memset(&region, 0, sizeof region);
    region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
    region.imageSubresource.layerCount = 1;
    region.imageExtent.width = W;
    region.imageExtent.height = H;
    region.imageExtent.depth = 1;
    vkCmdCopyBufferToImage(cmd, depth.buffer, depth_img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    vkCmdCopyBufferToImage(cmd, normal.buffer, normal_img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    barrier(cmd, depth_img.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL);
    barrier(cmd, normal_img.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    submit_and_wait(cmd);
    free_buffer(depth);
    free_buffer(normal);
}

/* Copies the visibility image into `vis` (if the recording succeeded), submits `cmd` and waits. */
static HrtsResult finish_frame(VkCommandBuffer cmd, HrtsResult r, float *vis) {
    Buf back = make_host_buffer(sizeof(float) * W * H, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    if (r == HRTS_RESULT_OK) {
        VkBufferImageCopy region;
        memset(&region, 0, sizeof region);
        region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
        region.imageSubresource.layerCount = 1;
        region.imageExtent.width = W;
        region.imageExtent.height = H;
        region.imageExtent.depth = 1;
        vkCmdCopyImageToBuffer(cmd, out_img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, back.buffer, 1, &region);
    }
    submit_and_wait(cmd);
    if (vis && r == HRTS_RESULT_OK) memcpy(vis, back.map, sizeof(float) * W * H);
    free_buffer(back);
    return r;
}

/* Records one plugin frame, submits it and reads the visibility image back into `vis`. */
static HrtsResult run_frame(HrtsContext *ctx, float *vis) {
    VkCommandBuffer cmd = begin();
    HrtsFrame f = frame(cmd);
    HrtsResult r = hrts_record_frame(ctx, &f);
    return finish_frame(cmd, r, vis);
}

/* Records one frame pass by pass (one hrts_record_passes call per HrtsPass, into one command buffer), or
 * as an engine splits it: the light-space passes in a first submission, the screen-space passes and the
 * output copy in a second one. Reads the visibility back into `vis`. */
static HrtsResult run_frame_in_parts(HrtsContext *ctx, float *vis, int one_by_one) {
    VkCommandBuffer cmd = begin();
    HrtsFrame f = frame(cmd);
    HrtsResult r = HRTS_RESULT_OK;
    if (one_by_one) {
        for (uint32_t pass = 0; pass < HRTS_PASS_COUNT && r == HRTS_RESULT_OK; pass++)
            r = hrts_record_passes(ctx, &f, 1u << pass);
    } else {
        r = hrts_record_passes(ctx, &f, HRTS_PASS_MASK_LIGHT_SPACE);
        submit_and_wait(cmd);
        cmd = begin();
        f = frame(cmd);
        if (r == HRTS_RESULT_OK) r = hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE);
    }
    return finish_frame(cmd, r, vis);
}

/* Reads a plugin resource of the last complete frame back through hrts_record_resource_readback. */
static HrtsResult read_resource(HrtsContext *ctx, uint32_t resource, float *out, size_t bytes) {
    Buf back = make_host_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    VkCommandBuffer cmd = begin();
    HrtsResourceReadback rb;
    memset(&rb, 0, sizeof rb);
    rb.struct_size = sizeof rb;
    rb.command_buffer = (uint64_t)(uintptr_t)cmd;
    rb.resource = resource;
    rb.buffer = (uint64_t)(uintptr_t)back.buffer;
    rb.buffer_size = bytes;
    HrtsResult r = hrts_record_resource_readback(ctx, &rb);
    submit_and_wait(cmd);
    if (r == HRTS_RESULT_OK) memcpy(out, back.map, bytes);
    free_buffer(back);
    return r;
}

static int differing(const float *a, const float *b) {
    int n = 0;
    for (int i = 0; i < W * H; i++) n += memcmp(&a[i], &b[i], sizeof(float)) != 0;
    return n;
}

/* Pixels whose plugin visibility differs from the exact shadow (near-edge pixels counted apart). */
static int count_mismatches(const float *vis, double tol, int *near_edge, int *shadowed, int *lit) {
    int mismatches = 0;
    *near_edge = *shadowed = *lit = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int e = exact(x, y, tol);
            float v = vis[y * W + x];
            if (e == -1) { (*near_edge)++; continue; }
            float want = e == 0 ? 0.0f : 1.0f;
            if (e == 0) (*shadowed)++;
            if (e == 1) (*lit)++;
            if (v != want) {
                if (mismatches < 8) fprintf(stderr, "pixel (%d,%d): exact %d, plugin %g\n", x, y, e, v);
                mismatches++;
            }
        }
    return mismatches;
}

/* The engine's host allocator, handed to the plugin before anything else: it counts live bytes. */
static size_t engine_live_bytes, engine_allocations;

static void *engine_allocate(void *user, size_t size, size_t alignment) {
    (void)user;
    void *p = NULL;
    if (alignment < sizeof(void *)) alignment = sizeof(void *);
    if (posix_memalign(&p, alignment, size ? size : 1) != 0) return NULL;
    __atomic_fetch_add(&engine_live_bytes, size, __ATOMIC_RELAXED);
    __atomic_fetch_add(&engine_allocations, 1, __ATOMIC_RELAXED);
    return p;
}

static void engine_free(void *user, void *memory, size_t size, size_t alignment) {
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

static void expect(HrtsContext *ctx, HrtsResult got, HrtsResult want, const char *what) {
    const char *msg = hrts_last_error(ctx);
    CHECK(got == want, "%s: got %s, want %s (%s)", what, hrts_result_name(got), hrts_result_name(want), msg);
    CHECK(msg && msg[0] != '\0', "%s: no error message", what);
    HrtsCapabilities caps;
    memset(&caps, 0, sizeof caps);
    caps.struct_size = sizeof caps;
    CHECK(hrts_get_capabilities(ctx, &caps) == HRTS_RESULT_OK, "%s: context unusable afterwards", what);
}

static HrtsConfig config(uint32_t mode) {
    HrtsConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.struct_size = sizeof cfg;
    if (hrts_config_defaults(&cfg) != HRTS_RESULT_OK) {
        fprintf(stderr, "hrts_config_defaults: %s\n", hrts_last_error(NULL));
        exit(2);
    }
    cfg.mode = mode;
    cfg.antialiasing = false; /* compare the exact visibility, before FXAA */
    cfg.map_size = 256;
    cfg.shadow_map_size = 1024;
    return cfg;
}

static void misuse(HrtsContext *ctx, const HrtsVulkanDevice *vk) {
    HrtsConfig cfg = config(HRTS_SHADOW_MODE_HARD);
    HrtsCapabilities caps;
    memset(&caps, 0, sizeof caps);
    caps.struct_size = sizeof caps;
    HrtsContextCreateInfo ci;
    memset(&ci, 0, sizeof ci);
    ci.struct_size = sizeof ci;
    ci.api_version = HRTS_API_VERSION;
    ci.vulkan = vk;
    HrtsContext *none = NULL;
    int cases = 0;

    /* creation */
    expect(ctx, hrts_context_create(NULL, &none), HRTS_RESULT_ERROR_NULL_POINTER, "create(NULL info)"), cases++;
    expect(ctx, hrts_context_create(&ci, NULL), HRTS_RESULT_ERROR_NULL_POINTER, "create(NULL out)"), cases++;
    ci.struct_size = sizeof ci - 4;
    expect(ctx, hrts_context_create(&ci, &none), HRTS_RESULT_ERROR_STRUCT_SIZE, "create(wrong struct_size)"), cases++;
    ci.struct_size = sizeof ci;
    ci.api_version = HRTS_API_VERSION + (1u << 22);
    expect(ctx, hrts_context_create(&ci, &none), HRTS_RESULT_ERROR_VERSION, "create(other major version)"), cases++;
    ci.api_version = HRTS_API_VERSION;
    HrtsVulkanDevice bad = *vk;
    bad.device = 0;
    ci.vulkan = &bad;
    expect(ctx, hrts_context_create(&ci, &none), HRTS_RESULT_ERROR_NULL_POINTER, "create(NULL VkDevice)"), cases++;
    bad = *vk;
    bad.get_instance_proc_addr = NULL;
    expect(ctx, hrts_context_create(&ci, &none), HRTS_RESULT_ERROR_NULL_POINTER, "create(NULL vkGetInstanceProcAddr)"), cases++;
    bad = *vk;
    bad.struct_size = 8;
    expect(ctx, hrts_context_create(&ci, &none), HRTS_RESULT_ERROR_STRUCT_SIZE, "create(wrong HrtsVulkanDevice size)"), cases++;
    bad = *vk;
    bad.fragment_stores_and_atomics = false;
    expect(ctx, hrts_context_create(&ci, &none), HRTS_RESULT_ERROR_UNSUPPORTED, "create(without fragment atomics)"), cases++;
    CHECK(none == NULL, "failed create left a context");

    /* capabilities and configuration */
    expect(ctx, hrts_get_capabilities(NULL, &caps), HRTS_RESULT_ERROR_NULL_POINTER, "capabilities(NULL context)"), cases++;
    expect(ctx, hrts_get_capabilities(ctx, NULL), HRTS_RESULT_ERROR_NULL_POINTER, "capabilities(NULL out)"), cases++;
    caps.struct_size = 4;
    expect(ctx, hrts_get_capabilities(ctx, &caps), HRTS_RESULT_ERROR_STRUCT_SIZE, "capabilities(wrong size)"), cases++;
    HrtsConfig c = cfg;
    c.map_size = 0;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(N = 0)"), cases++;
    c = cfg;
    c.map_size = 1u << 30;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(absurd N)"), cases++;
    c = cfg;
    c.map_entry_budget_kib = 0;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(entry budget 0)"), cases++;
    c = cfg;
    c.map_entry_budget_kib = 3;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(entry budget below 4 KiB)"), cases++;
    c = cfg;
    c.faces = 7;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ENUM, "configure(unknown faces)"), cases++;
    c = cfg;
    c.binning_path = 99;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ENUM, "configure(unknown binning path)"), cases++;
    c = cfg;
    c.struct_size = 3;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_STRUCT_SIZE, "configure(wrong size)"), cases++;
    c = cfg;
    c.mode = 9;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ENUM, "configure(unknown mode)"), cases++;
    c = cfg;
    c.pcss_angular_radius = NAN;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(NaN light size)"), cases++;
    c = cfg;
    c.hybrid_world_space_scale = -1.0f;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(negative WSS)"), cases++;
    c = cfg;
    c.pcss_pcf_taps = 0;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(0 PCF taps)"), cases++;
    c = cfg;
    c.shadow_map_size = 0;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(0 shadow map)"), cases++;
    expect(ctx, hrts_config_defaults(NULL), HRTS_RESULT_ERROR_NULL_POINTER, "config_defaults(NULL)"), cases++;

    /* geometry */
    HrtsCpuGeometry g = cpu_geometry();
    g.positions = NULL;
    expect(ctx, hrts_set_geometry_cpu(ctx, &g), HRTS_RESULT_ERROR_NULL_POINTER, "geometry(NULL positions)"), cases++;
    g = cpu_geometry();
    g.vertex_stride = 6;
    expect(ctx, hrts_set_geometry_cpu(ctx, &g), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "geometry(stride 6)"), cases++;
    float nan_positions[36];
    memcpy(nan_positions, positions, sizeof positions);
    nan_positions[13] = NAN;
    g = cpu_geometry();
    g.positions = nan_positions;
    expect(ctx, hrts_set_geometry_cpu(ctx, &g), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "geometry(NaN vertex)"), cases++;
    uint32_t bad_indices[42];
    memcpy(bad_indices, indices, sizeof indices);
    bad_indices[5] = 1000;
    g = cpu_geometry();
    g.indices = bad_indices;
    expect(ctx, hrts_set_geometry_cpu(ctx, &g), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "geometry(index out of range)"), cases++;
    g = cpu_geometry();
    g.draw_count = 0;
    expect(ctx, hrts_set_geometry_cpu(ctx, &g), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "geometry(no draws)"), cases++;
    HrtsVulkanGeometry vg;
    memset(&vg, 0, sizeof vg);
    vg.struct_size = sizeof vg;
    vg.vertex_buffer = 1;
    vg.index_buffer = 1;
    vg.index_type = 5;
    expect(ctx, hrts_set_geometry_vulkan(ctx, &vg), HRTS_RESULT_ERROR_INVALID_ENUM, "vulkan geometry(unknown index type)"), cases++;

    /* targets and frames */
    HrtsTargets t = targets();
    t.width = 0;
    expect(ctx, hrts_set_targets(ctx, &t), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "targets(zero width)"), cases++;
    t = targets();
    t.depth_usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    expect(ctx, hrts_set_targets(ctx, &t), HRTS_RESULT_ERROR_IMAGE_USAGE, "targets(depth not SAMPLED)"), cases++;
    t = targets();
    t.output_usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    expect(ctx, hrts_set_targets(ctx, &t), HRTS_RESULT_ERROR_IMAGE_USAGE, "targets(output not TRANSFER_DST)"), cases++;
    t = targets();
    t.normal_image = 0;
    expect(ctx, hrts_set_targets(ctx, &t), HRTS_RESULT_ERROR_NULL_POINTER, "targets(NULL normal image)"), cases++;
    VkCommandBuffer cmd = begin();
    HrtsFrame f = frame(cmd);
    f.light_direction[0] = f.light_direction[1] = f.light_direction[2] = 0;
    expect(ctx, hrts_record_frame(ctx, &f), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "frame(zero light direction)"), cases++;
    f = frame(cmd);
    f.proj[5] = NAN;
    expect(ctx, hrts_record_frame(ctx, &f), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "frame(NaN projection)"), cases++;
    f = frame(cmd);
    f.light_type = 7;
    expect(ctx, hrts_record_frame(ctx, &f), HRTS_RESULT_ERROR_INVALID_ENUM, "frame(unknown light type)"), cases++;
    f = frame(cmd);
    f.command_buffer = 0;
    expect(ctx, hrts_record_frame(ctx, &f), HRTS_RESULT_ERROR_NULL_POINTER, "frame(NULL command buffer)"), cases++;
    f = frame(cmd);
    f.struct_size = 12;
    expect(ctx, hrts_record_frame(ctx, &f), HRTS_RESULT_ERROR_STRUCT_SIZE, "frame(wrong size)"), cases++;
    submit_and_wait(cmd);
    HrtsFrameReport rep;
    memset(&rep, 0, sizeof rep);
    rep.struct_size = 1;
    expect(ctx, hrts_get_frame_report(ctx, &rep), HRTS_RESULT_ERROR_STRUCT_SIZE, "report(wrong size)"), cases++;

    /* pass-by-pass recording and read-back */
    c = cfg;
    c.pcss_filter = 5;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ENUM, "configure(unknown PCSS filter)"), cases++;
    c = cfg;
    c.extra_outputs = 1u << 20;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ENUM, "configure(unknown extra output)"), cases++;
    c = cfg;
    c.pcss_min_filter_radius = 64.0f;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(min filter radius > max)"), cases++;
    c = cfg;
    c.shadow_map_slope_bias = INFINITY;
    expect(ctx, hrts_configure(ctx, &c), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "configure(infinite slope bias)"), cases++;
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "frame: %s", hrts_last_error(ctx));
    cmd = begin();
    f = frame(cmd);
    expect(ctx, hrts_record_passes(ctx, &f, 0), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "passes(empty mask)"), cases++;
    expect(ctx, hrts_record_passes(ctx, &f, 1u << 20), HRTS_RESULT_ERROR_INVALID_ARGUMENT, "passes(unknown pass bit)"), cases++;
    expect(ctx, hrts_record_passes(ctx, &f, 1u << HRTS_PASS_RAY_TRACE), HRTS_RESULT_ERROR_INVALID_STATE,
           "passes(ray trace without the frame's primitive map)"), cases++;
    CHECK(hrts_record_passes(ctx, &f, HRTS_PASS_MASK_LIGHT_SPACE) == HRTS_RESULT_OK, "light space: %s", hrts_last_error(ctx));
    HrtsFrame moved = f;
    moved.camera_position[1] += 1.0f;
    expect(ctx, hrts_record_passes(ctx, &moved, HRTS_PASS_MASK_SCREEN_SPACE), HRTS_RESULT_ERROR_INVALID_ARGUMENT,
           "passes(camera moved within a frame)"), cases++;
    expect(ctx, hrts_record_passes(ctx, &f, 1u << HRTS_PASS_OUTPUT_COPY), HRTS_RESULT_ERROR_INVALID_STATE,
           "passes(output copy before the ray trace)"), cases++;
    f.depth_layout = 0;
    expect(ctx, hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE), HRTS_RESULT_ERROR_INVALID_ARGUMENT,
           "passes(undefined depth layout)"), cases++;
    f = frame(cmd);
    HrtsFrameReport open_rep;
    memset(&open_rep, 0, sizeof open_rep);
    open_rep.struct_size = sizeof open_rep;
    expect(ctx, hrts_get_frame_report(ctx, &open_rep), HRTS_RESULT_ERROR_INVALID_STATE, "report(frame half recorded)"), cases++;
    static float scratch[W * H];
    expect(ctx, read_resource(ctx, HRTS_RESOURCE_RT_VISIBILITY, scratch, sizeof scratch), HRTS_RESULT_ERROR_INVALID_STATE,
           "readback(frame half recorded)"), cases++;
    CHECK(hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE) == HRTS_RESULT_OK, "screen space: %s", hrts_last_error(ctx));
    submit_and_wait(cmd);
    expect(ctx, read_resource(ctx, 99, scratch, sizeof scratch), HRTS_RESULT_ERROR_INVALID_ENUM, "readback(unknown resource)"), cases++;
    expect(ctx, read_resource(ctx, HRTS_RESOURCE_PCSS, scratch, sizeof scratch), HRTS_RESULT_ERROR_INVALID_STATE,
           "readback(resource the mode does not allocate)"), cases++;
    expect(ctx, read_resource(ctx, HRTS_RESOURCE_RT_VISIBILITY, scratch, 64), HRTS_RESULT_ERROR_INVALID_ARGUMENT,
           "readback(buffer too small)"), cases++;
    HrtsResourceReadback rb;
    memset(&rb, 0, sizeof rb);
    rb.struct_size = sizeof rb;
    rb.command_buffer = 1;
    rb.resource = HRTS_RESOURCE_RT_VISIBILITY;
    expect(ctx, hrts_record_resource_readback(ctx, &rb), HRTS_RESULT_ERROR_NULL_POINTER, "readback(NULL buffer)"), cases++;
    HrtsResourceInfo info;
    memset(&info, 0, sizeof info);
    info.struct_size = sizeof info;
    expect(ctx, hrts_get_resource_info(ctx, 12, &info), HRTS_RESULT_ERROR_INVALID_ENUM, "resource info(unknown resource)"), cases++;

    /* a destroyed context is detected */
    HrtsContext *gone = create_context(vk);
    CHECK(hrts_context_destroy(gone) == HRTS_RESULT_OK, "destroy");
    HrtsResult r = hrts_get_capabilities(gone, &caps);
    CHECK(r == HRTS_RESULT_ERROR_INVALID_CONTEXT, "use after destroy: %s", hrts_result_name(r));
    CHECK(hrts_last_error(NULL)[0] != '\0', "use after destroy: no message");
    r = hrts_context_destroy(gone);
    CHECK(r == HRTS_RESULT_ERROR_INVALID_CONTEXT, "double destroy: %s", hrts_result_name(r));
    cases += 2;
    printf("misuse cases: %d\n", cases);
    CHECK(cases >= 25, "only %d misuse cases", cases);
}

int main(void) {
    HrtsAllocationCallbacks callbacks;
    memset(&callbacks, 0, sizeof callbacks);
    callbacks.struct_size = sizeof callbacks;
    callbacks.allocate = engine_allocate;
    callbacks.free = engine_free;
    CHECK(hrts_set_allocation_callbacks(&callbacks) == HRTS_RESULT_OK, "allocation callbacks: %s", hrts_last_error(NULL));
    CHECK(hrts_set_allocation_callbacks(&callbacks) == HRTS_RESULT_ERROR_INVALID_STATE, "second install accepted");
    setup_camera();
    create_device();
    HrtsVulkanDevice vk = adopt_info();
    depth_img = make_image(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    normal_img = make_image(VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    out_img = make_image(VK_FORMAT_R32_SFLOAT, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    upload_gbuffer();

    HrtsContext *ctx = create_context(&vk);
    CHECK(hrts_get_api_version() == HRTS_API_VERSION, "version");
    HrtsCapabilities caps;
    memset(&caps, 0, sizeof caps);
    caps.struct_size = sizeof caps;
    CHECK(hrts_get_capabilities(ctx, &caps) == HRTS_RESULT_OK, "capabilities: %s", hrts_last_error(ctx));
    printf("plugin sees: %s, conservative raster tier %u\n", caps.device_name, caps.conservative_raster_tier);

    HrtsFrameReport rep;
    memset(&rep, 0, sizeof rep);
    rep.struct_size = sizeof rep;
    CHECK(hrts_get_frame_report(ctx, &rep) == HRTS_RESULT_ERROR_INVALID_STATE, "report before any frame");
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_ERROR_INVALID_STATE, "record before geometry/targets");

    HrtsConfig cfg = config(HRTS_SHADOW_MODE_HARD);
    CHECK(hrts_configure(ctx, &cfg) == HRTS_RESULT_OK, "configure: %s", hrts_last_error(ctx));
    HrtsCpuGeometry g = cpu_geometry();
    CHECK(hrts_set_geometry_cpu(ctx, &g) == HRTS_RESULT_OK, "geometry: %s", hrts_last_error(ctx));
    HrtsTargets t = targets();
    CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_OK, "targets: %s", hrts_last_error(ctx));

    static float vis[W * H];
    CHECK(run_frame(ctx, vis) == HRTS_RESULT_OK, "record: %s", hrts_last_error(ctx));
    CHECK(hrts_get_frame_report(ctx, &rep) == HRTS_RESULT_OK, "report: %s", hrts_last_error(ctx));
    printf("frame: binning path %u, %u entries in %u lists (longest %u), capacity %u, %u texels past it\n",
           rep.binning_path, rep.entries, rep.texels_with_list, rep.longest_list, rep.entry_capacity,
           rep.texels_past_capacity);
    CHECK(rep.binning_path == HRTS_BINNING_PATH_COMPUTE && rep.entries > 0 && rep.texels_past_capacity == 0,
          "report of the primitive map");
    for (uint32_t i = 0; i < rep.pass_count; i++) printf("  %-28s %8.3f ms\n", rep.passes[i].name, rep.passes[i].milliseconds);

    /* compare with the exact shadow; tolerance 1/16 of the pixel footprint at the farthest point */
    double tol = 12.0 * (2 * tan(FOV_Y / 2) / H) / 16.0;
    int near_edge, shadowed, lit;
    int mismatches = count_mismatches(vis, tol, &near_edge, &shadowed, &lit);
    printf("visibility: %d px, %d lit, %d shadowed, %d near-edge, %d mismatches\n", W * H, lit, shadowed, near_edge, mismatches);
    CHECK(mismatches == 0, "%d pixels differ from the exact shadow", mismatches);
    CHECK(shadowed > 300 && lit > 1000, "the view should show both lit and shadowed pixels");
    CHECK(near_edge * 100 <= 3 * W * H, "near-edge pixels %d exceed 3%%", near_edge);

    /* hybrid: where the exact shadow is lit the blend is exactly lit (the shrinking penumbra only grows inward) */
    HrtsConfig hybrid = config(HRTS_SHADOW_MODE_HYBRID);
    CHECK(hrts_configure(ctx, &hybrid) == HRTS_RESULT_OK, "configure hybrid: %s", hrts_last_error(ctx));
    static float blend[W * H];
    CHECK(run_frame(ctx, blend) == HRTS_RESULT_OK, "record hybrid: %s", hrts_last_error(ctx));
    int halo = 0, out_of_range = 0, soft = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float v = blend[y * W + x];
            if (!(v >= 0.0f && v <= 1.0f)) out_of_range++;
            if (v > 0.0f && v < 1.0f) soft++;
            if (exact(x, y, tol) == 1 && v != 1.0f) halo++;
        }
    printf("hybrid: %d soft pixels, %d halo pixels, %d out of [0,1]\n", soft, halo, out_of_range);
    CHECK(halo == 0 && out_of_range == 0, "hybrid: %d halo, %d out of range", halo, out_of_range);
    CHECK(soft > 0, "hybrid shows no penumbra");

    /* the passes one by one, and split over two submissions as an engine places them, give the same bits */
    static float parts[W * H];
    CHECK(run_frame_in_parts(ctx, parts, 1) == HRTS_RESULT_OK, "hybrid pass by pass: %s", hrts_last_error(ctx));
    int diff_one = differing(parts, blend);
    CHECK(run_frame_in_parts(ctx, parts, 0) == HRTS_RESULT_OK, "hybrid in two submissions: %s", hrts_last_error(ctx));
    int diff_two = differing(parts, blend);
    printf("hybrid recorded pass by pass: %d px differ; light/screen space in two submissions: %d px differ\n",
           diff_one, diff_two);
    CHECK(diff_one == 0 && diff_two == 0, "per-pass recording differs: %d / %d px", diff_one, diff_two);
    CHECK(hrts_get_frame_report(ctx, &rep) == HRTS_RESULT_OK, "report: %s", hrts_last_error(ctx));
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
    CHECK(hrts_get_resource_info(ctx, HRTS_RESOURCE_RT_VISIBILITY, &info) == HRTS_RESULT_OK && info.allocated &&
              info.width == W && info.height == H && info.layers == 1 && info.format == VK_FORMAT_R32_SFLOAT &&
              info.bytes == sizeof(float) * W * H,
          "resource info: %s", hrts_last_error(ctx));
    static float rt[W * H];
    CHECK(read_resource(ctx, HRTS_RESOURCE_RT_VISIBILITY, rt, sizeof rt) == HRTS_RESULT_OK, "readback: %s", hrts_last_error(ctx));
    int diff_rt = differing(rt, vis);
    printf("ray-traced visibility read back from the hybrid frame: %d px differ from the hard-mode output\n", diff_rt);
    CHECK(diff_rt == 0, "read-back ray-traced visibility differs in %d px", diff_rt);
    CHECK(hrts_configure(ctx, &cfg) == HRTS_RESULT_OK, "configure back: %s", hrts_last_error(ctx));

    /* the same scene from the engine's own Vulkan buffers: float4 positions (stride 16) at byte offset 64,
     * 16-bit indices at byte offset 8 */
    Buf vb = make_host_buffer(64 + 12 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    Buf ib = make_host_buffer(8 + 44 * 2, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    float *vp = (float *)((char *)vb.map + 64);
    uint16_t *ip = (uint16_t *)((char *)ib.map + 8);
    for (int v = 0; v < 12; v++) {
        vp[4 * v + 0] = positions[3 * v + 0];
        vp[4 * v + 1] = positions[3 * v + 1];
        vp[4 * v + 2] = positions[3 * v + 2];
        vp[4 * v + 3] = 1.0f;
    }
    for (int k = 0; k < 42; k++) ip[k] = (uint16_t)indices[k];
    HrtsVulkanGeometry vg;
    memset(&vg, 0, sizeof vg);
    vg.struct_size = sizeof vg;
    vg.vertex_buffer = (uint64_t)(uintptr_t)vb.buffer;
    vg.vertex_buffer_size = 64 + 12 * 16;
    vg.vertex_offset = 64;
    vg.vertex_stride = 16;
    vg.vertex_count = 12;
    vg.index_buffer = (uint64_t)(uintptr_t)ib.buffer;
    vg.index_buffer_size = 8 + 44 * 2;
    vg.index_offset = 8;
    vg.index_type = HRTS_INDEX_TYPE_UINT16;
    vg.index_count = 42;
    vg.draws = draws;
    vg.draw_count = 2;
    const float bounds[6] = {-4.0f, 0.0f, -4.0f, 4.0f, 1.6f, 4.0f};
    memcpy(vg.bounds, bounds, sizeof bounds);
    CHECK(hrts_set_geometry_vulkan(ctx, &vg) == HRTS_RESULT_OK, "vulkan geometry: %s", hrts_last_error(ctx));
    static float vis_engine[W * H];
    CHECK(run_frame(ctx, vis_engine) == HRTS_RESULT_OK, "record with engine buffers: %s", hrts_last_error(ctx));
    int ne2, sh2, lit2;
    int mismatches_engine = count_mismatches(vis_engine, tol, &ne2, &sh2, &lit2);
    printf("engine buffers (u16 indices, stride 16, offsets): %d mismatches\n", mismatches_engine);
    CHECK(mismatches_engine == 0, "%d pixels differ with engine geometry", mismatches_engine);
    CHECK(hrts_set_geometry_cpu(ctx, &g) == HRTS_RESULT_OK, "back to CPU geometry: %s", hrts_last_error(ctx));
    VK(vkDeviceWaitIdle(device));
    free_buffer(vb);
    free_buffer(ib);

    misuse(ctx, &vk);
    CHECK(run_frame(ctx, NULL) == HRTS_RESULT_OK, "context still records after misuse: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");

    /* 100 create/destroy cycles, each recording a frame: no Vulkan object leaks (the validation layer's
     * object tracker reports them at vkDestroyDevice), and the plugin's host and GPU memory return exactly
     * to where they were. Resident memory is reported too: lavapipe keeps each compiled pipeline's JIT
     * code until its VkDevice is destroyed, so RSS grows on lavapipe whatever the plugin does. */
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
        HrtsContext *c = create_context(&vk);
        HrtsResult r = hrts_configure(c, &cfg);
        if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(c, &g);
        if (r == HRTS_RESULT_OK) r = hrts_set_targets(c, &t);
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

    vkDestroyImage(device, depth_img.image, NULL);
    vkFreeMemory(device, depth_img.memory, NULL);
    vkDestroyImage(device, normal_img.image, NULL);
    vkFreeMemory(device, normal_img.memory, NULL);
    vkDestroyImage(device, out_img.image, NULL);
    vkFreeMemory(device, out_img.memory, NULL);
    vkDestroyCommandPool(device, pool, NULL);
    vkDestroyDevice(device, NULL); /* the object tracker reports any object the plugin leaked here */
    vkDestroyInstance(instance, NULL);
    CHECK(validation_errors == 0, "%d validation errors", validation_errors);
    printf("%d passed, %d failed\n", passed, failed);
    return failed == 0 ? 0 : 1;
}

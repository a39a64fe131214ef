/* minimal.c: the smallest complete use of the hrts C ABI, in the order an engine does it:
 *   1. the engine creates its own Vulkan 1.3 instance, device, queue and command pool;
 *   2. hrts_context_create adopts that device (the plugin never destroys the engine's objects);
 *   3. the shadow casters are handed over once, from CPU arrays (hrts_set_geometry_cpu);
 *   4. one light is configured: hard ray-traced shadows of a sun;
 *   5. the engine's depth and normal images (its G-buffer) and a visibility image are registered;
 *   6. one frame is recorded into the engine's own command buffer, which the engine submits;
 *   7. the visibility is read back and compared with the exact shadow, computed here on the CPU;
 *   8. everything is destroyed, the plugin's context before the device it adopted.
 * The scene is a ground quad (y = 0, |x|, |z| <= 4) under a box floating at y = 0.6..1.6. The G-buffer is
 * ray-cast on the CPU so that the example needs no shaders; a real engine renders it.
 *
 * Build: see README.md beside this file. Usage: ./minimal [out.pgm]. HRTS_VALIDATION=1 turns the Khronos
 * validation layer on, if it is installed.
 * Exit status 0 only if every pixel matches the exact shadow and the validation layer reported no error. */
#include "hrts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <vulkan/vulkan.h>

enum { W = 160, H = 120 }; /* size of the G-buffer and of the visibility */

/* Any failure ends the example (a real engine would unwind). A failed hrts call leaves its message on the
 * context, or, where there is none (NULL), on the calling thread. */
static void check(HrtsResult r, const HrtsContext *ctx, const char *call) {
    char msg[1024] = "";
    if (r == HRTS_RESULT_OK) return;
    hrts_get_last_error(ctx, msg, sizeof msg); /* truncated to fit */
    fprintf(stderr, "%s: %s: %s\n", call, hrts_result_name(r), msg);
    exit(2);
}
#define HRTS(ctx, call) check((call), (ctx), #call)
#define VK(call)                                                                                             \
    do {                                                                                                     \
        VkResult vr_ = (call);                                                                               \
        if (vr_ != VK_SUCCESS) { fprintf(stderr, "%s: VkResult %d\n", #call, (int)vr_); exit(2); }           \
    } while (0)

/* ---------- the scene, in double precision for the exact answer ---------- */
typedef struct { double x, y, z; } V3;
static V3 v3(double x, double y, double z) { V3 r = {x, y, z}; return r; }
static V3 add(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static V3 sub(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static V3 scale(V3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static V3 cross(V3 a, V3 b) { return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static V3 normalize(V3 a) { return scale(a, 1.0 / sqrt(dot(a, a))); }

static const double BOX_MIN[3] = {-0.5, 0.6, -0.5}, BOX_MAX[3] = {0.5, 1.6, 0.5}, GROUND = 4.0;
static const float positions[12 * 3] = {
    -4, 0, -4, 4, 0, -4, 4, 0, 4, -4, 0, 4,                                       /* ground: vertices 0..3 */
    -0.5f, 0.6f, -0.5f, 0.5f, 0.6f, -0.5f, 0.5f, 1.6f, -0.5f, -0.5f, 1.6f, -0.5f, /* box: 4..11 */
    -0.5f, 0.6f, 0.5f, 0.5f, 0.6f, 0.5f, 0.5f, 1.6f, 0.5f, -0.5f, 1.6f, 0.5f,
};
static const uint32_t indices[42] = {
    0, 2, 1, 0, 3, 2,                                                             /* ground (draw 0) */
    4, 6, 5, 4, 7, 6, 8, 9, 10, 8, 10, 11, 4, 5, 9, 4, 9, 8, 7, 10, 6, 7, 11, 10, /* box (draw 1) */
    4, 8, 11, 4, 11, 7, 5, 6, 10, 5, 10, 9,
};
/* The sun travels along SUN (down onto the ground); shadow rays go the other way. */
static const double SUN[3] = {-0.5, -1.0, 0.25};
/* The camera at `eye` looks at (0, 0.5, 0): vertical field of view 0.8 rad, near plane 0.05. */
static const double FOV_Y = 0.8, NEAR_Z = 0.05;
static V3 eye, fwd, right, up;

/* Ray o + t d against the box grown by `grow` (negative: shrunk): the entry t (0 if o is inside), or -1 if it
 * misses; the entered face's normal goes to *n. */
static double ray_box(V3 o, V3 d, double grow, V3 *n) {
    double ov[3] = {o.x, o.y, o.z}, dv[3] = {d.x, d.y, d.z}, t0 = -1e300, t1 = 1e300, nv[3] = {0, 0, 0};
    int axis = 0;
    for (int i = 0; i < 3; i++) {
        double lo = BOX_MIN[i] - grow, hi = BOX_MAX[i] + grow;
        if (dv[i] == 0.0) {
            if (ov[i] < lo || ov[i] > hi) return -1;
            continue;
        }
        double a = (lo - ov[i]) / dv[i], b = (hi - ov[i]) / dv[i];
        if (a > b) { double s = a; a = b; b = s; }
        if (a > t0) { t0 = a; axis = i; }
        if (b < t1) t1 = b;
    }
    if (t0 > t1 || t1 < 0) return -1;
    nv[axis] = dv[axis] > 0 ? -1 : 1;
    if (n) *n = v3(nv[0], nv[1], nv[2]);
    return t0 > 0 ? t0 : 0;
}

/* The camera ray through the centre of pixel (x, y), of unit length along the view axis (so that t along it
 * is the view depth). Pixel rows go down, as Vulkan's framebuffer y does. */
static V3 pixel_ray(int x, int y) {
    double f = 1.0 / tan(FOV_Y / 2), aspect = (double)W / H;
    double nx = (x + 0.5) / W * 2 - 1, ny = (y + 0.5) / H * 2 - 1;
    return add(add(scale(right, nx * aspect / f), scale(up, -ny / f)), fwd);
}

/* The surface under pixel (x, y): 0 background, 1 ground, 2 box; its view depth goes to *t, its normal to *n. */
static int cast(int x, int y, double *t, V3 *n) {
    V3 d = pixel_ray(x, y);
    double tb = ray_box(eye, d, 0, n), tg = d.y < 0 ? -eye.y / d.y : -1;
    V3 p = add(eye, scale(d, tg));
    if (tg > 0 && (fabs(p.x) > GROUND || fabs(p.z) > GROUND)) tg = -1;
    if (tb > 0 && (tg < 0 || tb < tg)) { *t = tb; return 2; }
    if (tg > 0) { *t = tg; *n = v3(0, 1, 0); return 1; }
    return 0;
}

/* The exact hard shadow at pixel (x, y): 1 lit, 0 shadowed, -1 too near an edge to tell, -2 background. A
 * surface facing away from the light is in its own shadow. Otherwise the shadow ray leaves the surface
 * (moved 2 EPS off it) towards the sun: where the box shrunk by EPS and the box grown by EPS disagree, the ray
 * passes within EPS of an edge of the box, and the pixel is not compared. */
static const double EPS = 1e-3;
static int exact_shadow(int x, int y) {
    double t;
    V3 n, to_light = normalize(v3(-SUN[0], -SUN[1], -SUN[2]));
    if (!cast(x, y, &t, &n)) return -2;
    double facing = dot(n, to_light);
    if (fabs(facing) < 1e-6) return -1;
    if (facing < 0) return 0;
    V3 o = add(add(eye, scale(pixel_ray(x, y), t)), scale(n, 2 * EPS));
    int in = ray_box(o, to_light, -EPS, NULL) >= 0, out = ray_box(o, to_light, EPS, NULL) >= 0;
    return in ? 0 : out ? -1 : 1;
}

/* ---------- Vulkan ---------- */
static VkPhysicalDevice phys;
static VkDevice device;
static int validation_errors, validation_warnings;

static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT types,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data, void *user) {
    (void)types, (void)user;
    int error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
    if (error) validation_errors++; else validation_warnings++;
    fprintf(stderr, "validation %s: %s\n", error ? "error" : "warning", data->pMessage);
    return VK_FALSE;
}

/* Memory of a type with the `want` properties, for `req`. */
static VkDeviceMemory allocate(VkMemoryRequirements req, VkMemoryPropertyFlags want) {
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(phys, &mp);
    for (uint32_t i = 0; i < mp.memoryTypeCount; i++)
        if ((req.memoryTypeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) {
            VkMemoryAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, .allocationSize = req.size,
                                       .memoryTypeIndex = i};
            VkDeviceMemory memory;
            VK(vkAllocateMemory(device, &ai, NULL, &memory));
            return memory;
        }
    fprintf(stderr, "no suitable memory type\n");
    exit(2);
}

typedef struct { VkImage image; VkDeviceMemory memory; } Image;
typedef struct { VkBuffer buffer; VkDeviceMemory memory; void *map; } Buffer;

static Image make_image(VkFormat format, VkImageUsageFlags usage) {
    Image r;
    VkImageCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, .imageType = VK_IMAGE_TYPE_2D,
                            .format = format, .extent = {W, H, 1}, .mipLevels = 1, .arrayLayers = 1,
                            .samples = VK_SAMPLE_COUNT_1_BIT, .tiling = VK_IMAGE_TILING_OPTIMAL, .usage = usage};
    VK(vkCreateImage(device, &ci, NULL, &r.image));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, r.image, &req);
    r.memory = allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VK(vkBindImageMemory(device, r.image, r.memory, 0));
    return r;
}

/* A mapped host-visible, host-coherent buffer (staging and read-back). */
static Buffer make_buffer(VkDeviceSize size, VkBufferUsageFlags usage) {
    Buffer r;
    VkBufferCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, .size = size, .usage = usage};
    VK(vkCreateBuffer(device, &ci, NULL, &r.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, r.buffer, &req);
    r.memory = allocate(req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VK(vkBindBufferMemory(device, r.buffer, r.memory, 0));
    VK(vkMapMemory(device, r.memory, 0, size, 0, &r.map));
    return r;
}

/* A layout transition after every earlier command and before every later one (the barriers the plugin
 * records on the engine's images have the same full scope). */
static void transition(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                       VkImageLayout to) {
    VkImageMemoryBarrier2 b = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, .srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
        .srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT, .dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
        .dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, .oldLayout = from,
        .newLayout = to, .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .image = image, .subresourceRange = {aspect, 0, 1, 0, 1}};
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1,
                            .pImageMemoryBarriers = &b};
    vkCmdPipelineBarrier2(cmd, &dep);
}

int main(int argc, char **argv) {
    /* ---- 1. The engine's instance (with validation on request), device, queue and command pool. ---- */
    const char *layer = "VK_LAYER_KHRONOS_validation", *env = getenv("HRTS_VALIDATION");
    int validate = 0;
    if (env && strcmp(env, "1") == 0) {
        VkLayerProperties layers[64];
        uint32_t n = 64;
        vkEnumerateInstanceLayerProperties(&n, layers); /* VK_INCOMPLETE past 64 layers: enough here */
        for (uint32_t i = 0; i < n; i++) validate |= strcmp(layers[i].layerName, layer) == 0;
    }
    printf("validation layer: %s\n", validate ? "on" : "off");
    const char *instance_extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    VkDebugUtilsMessengerCreateInfoEXT mi = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT,
        .pfnUserCallback = on_message};
    /* synchronization validation checks the barriers between the engine's commands and the plugin's too */
    VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features = {.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT, .pNext = &mi,
                                        .enabledValidationFeatureCount = 1, .pEnabledValidationFeatures = &sync};
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO, .pApplicationName = "hrts minimal",
                             .apiVersion = VK_API_VERSION_1_3}; /* the plugin needs Vulkan 1.3 */
    VkInstanceCreateInfo ici = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, .pApplicationInfo = &app};
    if (validate) {
        ici.pNext = &features; /* the chained messenger also hears vkCreateInstance and vkDestroyInstance */
        ici.enabledLayerCount = 1;
        ici.ppEnabledLayerNames = &layer;
        ici.enabledExtensionCount = 2;
        ici.ppEnabledExtensionNames = instance_extensions;
    }
    VkInstance instance;
    VK(vkCreateInstance(&ici, NULL, &instance));
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    if (validate) {
        PFN_vkCreateDebugUtilsMessengerEXT create_messenger =
            (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT");
        VK(create_messenger(instance, &mi, NULL, &messenger));
    }
    /* The first Vulkan 1.3 device with a graphics + compute queue family (lavapipe on a machine without GPU). */
    VkPhysicalDevice devices[16];
    uint32_t device_count = 16, family = 0;
    vkEnumeratePhysicalDevices(instance, &device_count, devices); /* VK_INCOMPLETE past 16: enough here */
    for (uint32_t i = 0; i < device_count && !phys; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[i], &p);
        VkQueueFamilyProperties families[16];
        uint32_t family_count = 16;
        vkGetPhysicalDeviceQueueFamilyProperties(devices[i], &family_count, families);
        VkQueueFlags both = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        for (uint32_t q = 0; p.apiVersion >= VK_API_VERSION_1_3 && q < family_count && !phys; q++)
            if ((families[q].queueFlags & both) == both) phys = devices[i], family = q;
    }
    if (!phys) { fprintf(stderr, "no Vulkan 1.3 device with a graphics + compute queue\n"); return 2; }
    /* What the plugin requires of an adopted device: Vulkan 1.3 dynamicRendering and synchronization2, and
     * fragmentStoresAndAtomics. geometryShader (the software raster path) and depthClamp are optional: enable
     * them where supported, and tell the plugin what was enabled (HrtsVulkanDevice). */
    VkPhysicalDeviceFeatures supported;
    vkGetPhysicalDeviceFeatures(phys, &supported);
    VkPhysicalDeviceFeatures core = {.fragmentStoresAndAtomics = VK_TRUE, .geometryShader = supported.geometryShader,
                                     .depthClamp = supported.depthClamp};
    VkPhysicalDeviceVulkan13Features f13 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
                                            .synchronization2 = VK_TRUE, .dynamicRendering = VK_TRUE};
    float priority = 1;
    VkDeviceQueueCreateInfo qi = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, .queueFamilyIndex = family,
                                  .queueCount = 1, .pQueuePriorities = &priority};
    VkDeviceCreateInfo dci = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, .pNext = &f13, .queueCreateInfoCount = 1,
                              .pQueueCreateInfos = &qi, .pEnabledFeatures = &core};
    VK(vkCreateDevice(phys, &dci, NULL, &device));
    VkQueue queue;
    vkGetDeviceQueue(device, family, 0, &queue);
    VkCommandPoolCreateInfo pci = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, .queueFamilyIndex = family};
    VkCommandPool pool;
    VK(vkCreateCommandPool(device, &pci, NULL, &pool));

    /* ---- 2. The plugin's context, adopting the engine's device (handles travel as uint64_t). ---- */
    HrtsVulkanDevice adopted = {
        .struct_size = sizeof(HrtsVulkanDevice), /* every struct the plugin reads starts with its size */
        .get_instance_proc_addr = (HrtsGetInstanceProcAddr)vkGetInstanceProcAddr,
        .instance = (uint64_t)(uintptr_t)instance, .physical_device = (uint64_t)(uintptr_t)phys,
        .device = (uint64_t)(uintptr_t)device, .queue_family_index = family, .queue_index = 0,
        .geometry_shader = core.geometryShader, .fragment_stores_and_atomics = core.fragmentStoresAndAtomics,
        .depth_clamp = core.depthClamp,
        .debug_utils = (HrtsBool)validate}; /* VK_EXT_debug_utils is on with validation only */
    HrtsContextCreateInfo create = {.struct_size = sizeof(HrtsContextCreateInfo), .api_version = HRTS_API_VERSION,
                                    .vulkan = &adopted, .frames_in_flight = 1};
    HrtsContext *ctx = NULL;
    HRTS(NULL, hrts_context_create(&create, &ctx));
    HrtsCapabilities caps = {.struct_size = sizeof(HrtsCapabilities)};
    HRTS(ctx, hrts_get_capabilities(ctx, &caps));
    printf("device: %s (conservative raster tier %u)\n", caps.device_name, caps.conservative_raster_tier);

    /* ---- 3. The shadow casters: two draws over one vertex and one index array, identity transforms. ---- */
    HrtsDraw draws[2] = {{.first_index = 0, .index_count = 6, .transform = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}},
                         {.first_index = 6, .index_count = 36, .transform = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
    HrtsCpuGeometry geometry = {.struct_size = sizeof(HrtsCpuGeometry), .positions = positions, .vertex_count = 12,
                                .vertex_stride = 3 * sizeof(float), .indices = indices, .index_count = 42,
                                .draws = draws, .draw_count = 2, .draw_stride = sizeof(HrtsDraw)};
    HRTS(ctx, hrts_set_geometry_cpu(ctx, &geometry));

    /* ---- 4. One light's configuration: the defaults, with hard ray-traced shadows. FXAA (on by default) would
     * soften the shadow's edge; off, every pixel is exactly 0 or 1. ---- */
    HrtsConfig config = {.struct_size = sizeof(HrtsConfig)};
    HRTS(NULL, hrts_config_defaults(&config));
    config.mode = HRTS_SHADOW_MODE_HARD;
    config.antialiasing = 0;
    HRTS(ctx, hrts_configure(ctx, &config));
    /* Where the light is goes with each frame (HrtsFrame::lights): a sun whose view_proj is all zeros, for the
     * plugin to fit its frustum to the casters. */
    HrtsLight sun = {.light_type = HRTS_LIGHT_TYPE_DIRECTIONAL,
                     .direction = {(float)SUN[0], (float)SUN[1], (float)SUN[2]}};

    /* ---- 5. The engine's images: depth and world-space normals (read), visibility (written). ---- */
    VkImageUsageFlags read = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    VkImageUsageFlags written = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    Image depth = make_image(VK_FORMAT_D32_SFLOAT, read), normal = make_image(VK_FORMAT_R32G32B32A32_SFLOAT, read);
    Image output = make_image(VK_FORMAT_R32_SFLOAT, written);
    HrtsTargets targets = {
        .struct_size = sizeof(HrtsTargets), .width = W, .height = H,
        .depth_image = (uint64_t)(uintptr_t)depth.image, .depth_usage = read, .depth_format = VK_FORMAT_D32_SFLOAT,
        .normal_image = (uint64_t)(uintptr_t)normal.image, .normal_usage = read,
        .normal_format = VK_FORMAT_R32G32B32A32_SFLOAT,
        .normal_encoding = HRTS_NORMAL_ENCODING_XYZ_COVERAGE, /* xyz; w = 1 on geometry, 0 on the background */
        .normal_space = HRTS_NORMAL_SPACE_WORLD,
        .output_image = (uint64_t)(uintptr_t)output.image, .output_usage = written,
        .output_layers = 1, /* one layer per light */
        .output_format = VK_FORMAT_R32_SFLOAT};
    HRTS(ctx, hrts_set_targets(ctx, &targets));

    /* The camera's view (right-handed look-at) and a reversed-Z infinite projection with clip y flipped (Vulkan's
     * framebuffer y points down), column-major. The plugin rebuilds positions from the depth through this
     * projection, so the depth must be written with it: depth = NEAR_Z / view depth, 0 on the background. */
    eye = v3(3.2, 2.6, 3.9);
    fwd = normalize(sub(v3(0, 0.5, 0), eye));
    right = normalize(cross(fwd, v3(0, 1, 0)));
    up = cross(right, fwd);
    double f = 1.0 / tan(FOV_Y / 2);
    HrtsFrame frame = {
        .struct_size = sizeof(HrtsFrame), .frame_index = 1, /* the engine's frame counter */
        .view = {(float)right.x, (float)up.x, (float)-fwd.x, 0, (float)right.y, (float)up.y, (float)-fwd.y, 0,
                 (float)right.z, (float)up.z, (float)-fwd.z, 0, (float)-dot(right, eye), (float)-dot(up, eye),
                 (float)dot(fwd, eye), 1},
        .proj = {(float)(f * H / W), 0, 0, 0, 0, (float)-f, 0, 0, 0, 0, 0, -1, 0, 0, (float)NEAR_Z, 0},
        .camera_position = {(float)eye.x, (float)eye.y, (float)eye.z},
        .lights = &sun, .light_count = 1, .light_stride = sizeof(HrtsLight),
        .depth_layout = VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, /* where the engine keeps its G-buffer */
        .normal_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
        .output_layout_before = VK_IMAGE_LAYOUT_UNDEFINED, /* the output's old contents are discarded */
        .output_layout_after = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};

    /* The G-buffer, ray-cast into a staging buffer: W x H depths, then W x H normals. */
    Buffer staging = make_buffer(5 * sizeof(float) * W * H, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    Buffer readback = make_buffer(sizeof(float) * W * H, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    float *dp = staging.map, *np = dp + W * H;
    for (int i = 0; i < W * H; i++) {
        double t;
        V3 n = v3(0, 0, 0);
        int hit = cast(i % W, i / W, &t, &n);
        dp[i] = hit ? (float)(NEAR_Z / t) : 0.0f;
        float normal4[4] = {(float)n.x, (float)n.y, (float)n.z, hit ? 1.0f : 0.0f};
        memcpy(&np[4 * i], normal4, sizeof normal4);
    }

    /* ---- 6. One command buffer: the G-buffer upload, the plugin's frame, the output's read-back. ---- */
    VkCommandBufferAllocateInfo cai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, .commandPool = pool,
                                       .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1};
    VkCommandBuffer cmd;
    VK(vkAllocateCommandBuffers(device, &cai, &cmd));
    VkCommandBufferBeginInfo cbi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                    .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    VK(vkBeginCommandBuffer(cmd, &cbi));
    VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1}, .imageExtent = {W, H, 1}};
    VkImageLayout dst = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    transition(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED, dst);
    transition(cmd, normal.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, dst);
    vkCmdCopyBufferToImage(cmd, staging.buffer, depth.image, dst, 1, &region);
    region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    region.bufferOffset = sizeof(float) * W * H;
    vkCmdCopyBufferToImage(cmd, staging.buffer, normal.image, dst, 1, &region);
    region.bufferOffset = 0;
    transition(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, dst, (VkImageLayout)frame.depth_layout);
    transition(cmd, normal.image, VK_IMAGE_ASPECT_COLOR_BIT, dst, (VkImageLayout)frame.normal_layout);

    frame.command_buffer = (uint64_t)(uintptr_t)cmd;
    HRTS(ctx, hrts_record_frame(ctx, &frame));

    /* The plugin left the output in output_layout_after behind a full barrier: copy it out, then make the
     * copy visible to the host. */
    vkCmdCopyImageToBuffer(cmd, output.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &region);
    VkMemoryBarrier2 to_host = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
                                .srcStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                                .srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                .dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT, .dstAccessMask = VK_ACCESS_2_HOST_READ_BIT};
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1,
                            .pMemoryBarriers = &to_host};
    vkCmdPipelineBarrier2(cmd, &dep);
    VK(vkEndCommandBuffer(cmd));
    VkFenceCreateInfo fci = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    VK(vkCreateFence(device, &fci, NULL, &fence));
    VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &cmd};
    VK(vkQueueSubmit(queue, 1, &si, fence));
    VK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));

    /* ---- 7. What the frame did (asked once its fence signalled), and the visibility against the exact
     * shadow. ---- */
    HrtsFrameReport report = {.struct_size = sizeof(HrtsFrameReport)};
    HRTS(ctx, hrts_get_frame_report(ctx, frame.frame_index, 0, &report)); /* light 0 */
    printf("frame report: %.3f GPU ms in %u passes, %u receiver pixels, %u triangles binned, %u list entries\n",
           report.gpu_milliseconds, report.pass_count, report.receiver_pixels, report.triangles_binned,
           report.entries);
    for (uint32_t i = 0; i < report.pass_count; i++)
        printf("  %-32s %8.3f ms\n", report.passes[i].name, report.passes[i].milliseconds);
    const float *vis = readback.map;
    int lit = 0, shadowed = 0, near_edge = 0, mismatches = 0;
    for (int i = 0; i < W * H; i++) {
        int want = exact_shadow(i % W, i / W);
        if (want == -1) near_edge++;
        if (want < 0) continue; /* near an edge, or the background */
        if (want) lit++; else shadowed++;
        if (vis[i] != (float)want && mismatches++ < 8)
            fprintf(stderr, "pixel (%d, %d): exact %d, plugin %g\n", i % W, i / W, want, vis[i]);
    }
    printf("%d lit, %d shadowed, %d mismatches (%d pixels near an edge not compared)\n", lit, shadowed, mismatches,
           near_edge);
    const char *pgm_path = argc > 1 ? argv[1] : "minimal.pgm";
    FILE *pgm = fopen(pgm_path, "wb");
    if (!pgm) { perror(pgm_path); return 2; }
    fprintf(pgm, "P5\n%d %d\n255\n", W, H);
    for (int i = 0; i < W * H; i++) fputc((int)lroundf(fminf(fmaxf(vis[i], 0.0f), 1.0f) * 255.0f), pgm);
    fclose(pgm);
    printf("wrote %s\n", pgm_path);

    /* ---- 8. Teardown, the GPU idle (the fence signalled): the plugin's context first, then the engine's
     * images it referenced, the device last. ---- */
    HRTS(NULL, hrts_context_destroy(ctx));
    vkDestroyFence(device, fence, NULL);
    Buffer buffers[2] = {readback, staging};
    Image images[3] = {output, normal, depth};
    for (int i = 0; i < 2; i++) {
        vkDestroyBuffer(device, buffers[i].buffer, NULL);
        vkFreeMemory(device, buffers[i].memory, NULL); /* unmaps it too */
    }
    for (int i = 0; i < 3; i++) {
        vkDestroyImage(device, images[i].image, NULL);
        vkFreeMemory(device, images[i].memory, NULL);
    }
    vkDestroyCommandPool(device, pool, NULL); /* frees cmd */
    vkDestroyDevice(device, NULL);
    if (messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT");
        destroy_messenger(instance, messenger, NULL);
    }
    vkDestroyInstance(instance, NULL);
    if (validate) printf("validation: %d errors, %d warnings\n", validation_errors, validation_warnings);
    return mismatches == 0 && validation_errors == 0 ? 0 : 1;
}

/* The engine of the C tests: see engine.h. */
#define _POSIX_C_SOURCE 200112L
#include "engine.h"

#include <string.h>

int passed, failed;

/* ---------- scene: ground quad y = 0 (|x|,|z| <= 4) and a box [-0.5,0.5]x[0.6,1.6]x[-0.5,0.5] ---------- */
const double BOX_MIN[3] = {-0.5, 0.6, -0.5};
const double BOX_MAX[3] = {0.5, 1.6, 0.5};
/* Where the engine has moved the box (its draw's translation; 0 unless a test moves it). */
double box_shift[3];
const double GROUND = 4.0;
/* World-space bounds of the scene's triangles (min xyz, max xyz). */
const float SCENE_BOUNDS[6] = {-4.0f, 0.0f, -4.0f, 4.0f, 1.6f, 4.0f};

float positions[] = {
    -4, 0, -4, 4, 0, -4, 4, 0, 4, -4, 0, 4, /* ground 0..3 */
    -0.5f, 0.6f, -0.5f, 0.5f, 0.6f, -0.5f, 0.5f, 1.6f, -0.5f, -0.5f, 1.6f, -0.5f, /* box 4..11 */
    -0.5f, 0.6f, 0.5f, 0.5f, 0.6f, 0.5f, 0.5f, 1.6f, 0.5f, -0.5f, 1.6f, 0.5f,
};
uint32_t indices[] = {
    0, 2, 1, 0, 3, 2, /* ground, facing +y */
    4, 6, 5, 4, 7, 6, 8, 9, 10, 8, 10, 11, 4, 5, 9, 4, 9, 8, /* box back, front, bottom */
    7, 10, 6, 7, 11, 10, 4, 8, 11, 4, 11, 7, 5, 6, 10, 5, 10, 9, /* top, left, right */
};

/* Ray vs the box grown by `grow` (negative shrinks): entry distance and face normal, or -1. */
double ray_box(V3 o, V3 d, double grow, V3 *normal) {
    double o_[3] = {o.x, o.y, o.z}, d_[3] = {d.x, d.y, d.z}, t0 = -1e300, t1 = 1e300;
    int axis = -1;
    double sign = 0;
    for (int i = 0; i < 3; i++) {
        double lo = BOX_MIN[i] + box_shift[i] - grow, hi = BOX_MAX[i] + box_shift[i] + grow;
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

/* ---------- camera and lights ---------- */
const double FOV_Y = 0.8, NEAR = 0.05;
V3 cam_pos, cam_f, cam_r, cam_u;
float view[16], proj[16];

/* The camera orbits the scene: angle 0 is the reference view from (3.2, 2.6, 3.9). */
void setup_camera(double angle) {
    double radius = sqrt(3.2 * 3.2 + 3.9 * 3.9), a = atan2(3.2, 3.9) + angle;
    cam_pos = v3(radius * sin(a), 2.6, radius * cos(a));
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
}

/* A directional light travelling along `dir`, with an orthographic view-projection enclosing the scene. */
Emitter directional(V3 dir) {
    Emitter e;
    memset(&e, 0, sizeof e);
    e.dir = norm3(dir);
    V3 lz = mul3(e.dir, -1.0), lx = norm3(cross3(fabs(lz.z) < 0.9 ? v3(0, 0, 1) : v3(1, 0, 0), lz)), ly = cross3(lz, lx);
    double ext = 8.0, depth = 16.0;
    /* x' = dot(lx,p)/ext, y' = dot(ly,p)/ext, z' = 0.5 - dot(lz,p)/depth maps the scene into [0,1] */
    float l[16] = {(float)(lx.x / ext), (float)(ly.x / ext), (float)(-lz.x / depth), 0, (float)(lx.y / ext), (float)(ly.y / ext),
                   (float)(-lz.y / depth), 0, (float)(lx.z / ext), (float)(ly.z / ext), (float)(-lz.z / depth), 0, 0, 0, 0.5f, 1};
    e.c.light_type = HRTS_LIGHT_TYPE_DIRECTIONAL;
    e.c.direction[0] = (float)e.dir.x;
    e.c.direction[1] = (float)e.dir.y;
    e.c.direction[2] = (float)e.dir.z;
    memcpy(e.c.view_proj, l, sizeof l);
    return e;
}

/* A directional light travelling along `dir` whose frustum the plugin fits to the scene's bounds every frame
 * (view_proj all zeros). */
Emitter fitted_sun(V3 dir) {
    Emitter e = directional(dir);
    memset(e.c.view_proj, 0, sizeof e.c.view_proj);
    return e;
}

/* A spot light at `pos` aiming at `target`, with a perspective (standard depth) frustum of `fov` radians. */
Emitter spot(V3 pos, V3 target, double fov) {
    Emitter e;
    memset(&e, 0, sizeof e);
    e.spot = 1;
    e.pos = pos;
    e.dir = norm3(sub3(target, pos));
    V3 f = e.dir, r = norm3(cross3(f, fabs(f.y) < 0.9 ? v3(0, 1, 0) : v3(1, 0, 0))), u = cross3(r, f);
    double n = 0.1, fa = 30.0, s = 1.0 / tan(fov / 2);
    /* view rows r, u, -f; then x' = s x, y' = s y, z' = (fa z + n fa) / (n - fa), w = -z */
    double vm[16] = {r.x, u.x, -f.x, 0, r.y, u.y, -f.y, 0, r.z, u.z, -f.z, 0, -dot3(r, pos), -dot3(u, pos), dot3(f, pos), 1};
    double pm[16] = {s, 0, 0, 0, 0, s, 0, 0, 0, 0, fa / (n - fa), -1, 0, 0, n * fa / (n - fa), 0};
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double acc = 0;
            for (int k = 0; k < 4; k++) acc += pm[k * 4 + row] * vm[c * 4 + k];
            e.c.view_proj[c * 4 + row] = (float)acc;
        }
    e.c.light_type = HRTS_LIGHT_TYPE_SPOT;
    e.c.position[0] = (float)pos.x;
    e.c.position[1] = (float)pos.y;
    e.c.position[2] = (float)pos.z;
    e.c.direction[0] = (float)e.dir.x;
    e.c.direction[1] = (float)e.dir.y;
    e.c.direction[2] = (float)e.dir.z;
    return e;
}

/* A point light at `pos`: the plugin fits its cube faces (no matrix). */
Emitter point(V3 pos) {
    Emitter e;
    memset(&e, 0, sizeof e);
    e.spot = 1; /* shadow rays end at the emitter, as for a spot light */
    e.pos = pos;
    e.c.light_type = HRTS_LIGHT_TYPE_POINT;
    e.c.position[0] = (float)pos.x;
    e.c.position[1] = (float)pos.y;
    e.c.position[2] = (float)pos.z;
    return e;
}

/* A spot light at `pos` aiming at `target` with a cone of half-angle `cone`, its frusta fitted by the
 * plugin (view_proj all zeros). */
Emitter fitted_spot(V3 pos, V3 target, double cone) {
    Emitter e = point(pos);
    e.dir = norm3(sub3(target, pos));
    e.c.light_type = HRTS_LIGHT_TYPE_SPOT;
    e.c.direction[0] = (float)e.dir.x;
    e.c.direction[1] = (float)e.dir.y;
    e.c.direction[2] = (float)e.dir.z;
    e.c.outer_cone = (float)cone;
    return e;
}

/* Camera ray through pixel (x, y) centre. */
V3 pixel_ray(double x, double y) {
    double f = 1.0 / tan(FOV_Y / 2), aspect = (double)W / H;
    double nx = (x + 0.5) / W * 2 - 1, ny = (y + 0.5) / H * 2 - 1;
    /* clip y is negated: NDC y down is view-space up */
    return add3(add3(mul3(cam_r, nx * aspect / f), mul3(cam_u, -ny / f)), cam_f);
}

/* Nearest surface under a camera ray: 0 background, 1 ground, 2 box; t along `d` (|d| >= 1). */
int cast(V3 o, V3 d, double grow, double *t, V3 *n) {
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

/* Whether the box grown by `grow` blocks the shadow ray from `p` toward the light. */
int blocked(V3 p, const Emitter *e, double grow) {
    if (!e->spot) return ray_box(p, mul3(e->dir, -1.0), grow, NULL) >= 0;
    double t = ray_box(p, sub3(e->pos, p), grow, NULL);
    return t >= 0 && t < 1;
}

/* Exact classification under light `e`: 1 lit, 0 shadowed, -1 near an edge (within tol), -2 background. */
int exact(int x, int y, double tol, const Emitter *e) {
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
    V3 p = add3(cam_pos, mul3(d, t));
    V3 L = e->spot ? norm3(sub3(e->pos, p)) : mul3(e->dir, -1.0);
    double c = dot3(n, L);
    if (fabs(c) < 1e-6) return -1;
    if (c < 0) return 0;
    if (hit == 2) return 1; /* a convex box never shadows itself; the ground is below it */
    if (blocked(p, e, -tol)) return 0;
    if (!blocked(p, e, tol)) return 1;
    return -1;
}

/* ---------- Vulkan helpers ---------- */
static VkInstance instance;
VkPhysicalDevice phys;
VkDevice device;
VkQueue queue;
uint32_t family;
VkCommandPool pool;
static VkDebugUtilsMessengerEXT messenger;
int validation_errors, validation_warnings;
const char *phase = "setup"; /* what the host is doing, for validation messages */

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                    VkDebugUtilsMessageTypeFlagsEXT types,
                                                    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user) {
    (void)types;
    (void)user;
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        validation_errors++;
        fprintf(stderr, "validation error (%s): %s\n", phase, data->pMessage);
    } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        validation_warnings++;
        fprintf(stderr, "validation warning (%s): %s\n", phase, data->pMessage);
    }
    return VK_FALSE;
}

uint32_t memory_type(uint32_t bits, VkMemoryPropertyFlags want) {
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(phys, &mp);
    for (uint32_t i = 0; i < mp.memoryTypeCount; i++)
        if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return i;
    fprintf(stderr, "no memory type\n");
    exit(2);
}

Img make_image(VkFormat format, VkImageUsageFlags usage, uint32_t layers) {
    Img r;
    VkImageCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = format;
    ci.extent.width = W;
    ci.extent.height = H;
    ci.extent.depth = 1;
    ci.mipLevels = 1;
    ci.arrayLayers = layers;
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

void free_image(Img i) {
    vkDestroyImage(device, i.image, NULL);
    vkFreeMemory(device, i.memory, NULL);
}

Buf make_host_buffer(VkDeviceSize size, VkBufferUsageFlags usage) {
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

void free_buffer(Buf b) {
    vkUnmapMemory(device, b.memory);
    vkDestroyBuffer(device, b.buffer, NULL);
    vkFreeMemory(device, b.memory, NULL);
}

void barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, uint32_t layers, VkImageLayout from,
                    VkImageLayout to) {
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
    b.subresourceRange.layerCount = layers;
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

/* Makes transfer writes visible to the host. */
void host_read_barrier(VkCommandBuffer cmd) {
    VkMemoryBarrier2 b = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
    b.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    b.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    b.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.memoryBarrierCount = 1;
    dep.pMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

VkCommandBuffer begin(void) {
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

void submit(VkCommandBuffer cmd, VkFence fence) {
    VK(vkEndCommandBuffer(cmd));
    VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VK(vkQueueSubmit(queue, 1, &si, fence));
}

void submit_and_wait(VkCommandBuffer cmd) {
    VkFenceCreateInfo fi = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    VK(vkCreateFence(device, &fi, NULL, &fence));
    submit(cmd, fence);
    VK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
    vkDestroyFence(device, fence, NULL);
    vkFreeCommandBuffers(device, pool, 1, &cmd);
}

/* Uploads `staging` (tightly packed texels of the copied aspect) into one-layer `img` and leaves it in
 * `layout`: `aspects` are the image's aspects (for the layout transitions), `copied` the one written. */
/* `f` as an IEEE half, rounded to nearest even (values this small flush to zero: no view Z here is). */
uint16_t half_of(float f) {
    uint32_t x;
    memcpy(&x, &f, 4);
    uint32_t sign = (x >> 16) & 0x8000;
    int32_t e = (int32_t)((x >> 23) & 0xff) - 127 + 15;
    uint32_t m = x & 0x7fffff;
    if (e <= 0) return (uint16_t)sign;
    if (e >= 31) return (uint16_t)(sign | 0x7c00);
    uint32_t h = sign | (uint32_t)e << 10 | m >> 13, rest = m & 0x1fff;
    if (rest > 0x1000 || (rest == 0x1000 && (h & 1))) h++;
    return (uint16_t)h;
}

/* A copy region covering `layers` whole W x H layers of an image's `aspect`, from layer 0. */
VkBufferImageCopy frame_region(VkImageAspectFlags aspect, uint32_t layers) {
    VkBufferImageCopy region;
    memset(&region, 0, sizeof region);
    region.imageSubresource.aspectMask = aspect;
    region.imageSubresource.layerCount = layers;
    region.imageExtent.width = W;
    region.imageExtent.height = H;
    region.imageExtent.depth = 1;
    return region;
}

void upload_image(Img img, VkImageAspectFlags aspects, VkImageAspectFlags copied, Buf staging, VkImageLayout layout) {
    VkCommandBuffer cmd = begin();
    barrier(cmd, img.image, aspects, 1, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    VkBufferImageCopy region = frame_region(copied, 1);
    vkCmdCopyBufferToImage(cmd, staging.buffer, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    barrier(cmd, img.image, aspects, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, layout);
    submit_and_wait(cmd);
}

/* `n` command buffers of the pool and `n` unsignalled fences: a ring of frames in flight. */
void frames_in_flight_ring(uint32_t n, VkCommandBuffer *cmds, VkFence *fences) {
    VkCommandBufferAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = n;
    VK(vkAllocateCommandBuffers(device, &ai, cmds));
    for (uint32_t k = 0; k < n; k++) {
        VkFenceCreateInfo fi = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        VK(vkCreateFence(device, &fi, NULL, &fences[k]));
    }
}

/* A timeline semaphore at 0 that submissions held by the test wait on (value 1). */
VkSemaphore held_semaphore(void) {
    VkSemaphoreTypeCreateInfo sti = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    sti.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo sci = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    sci.pNext = &sti;
    VkSemaphore hold;
    VK(vkCreateSemaphore(device, &sci, NULL, &hold));
    return hold;
}

/* Submits `cmd` to run once the test releases `hold` (it stays pending until then), signalling `fence`. */
void submit_held(VkCommandBuffer cmd, VkSemaphore hold, VkFence fence) {
    VK(vkEndCommandBuffer(cmd));
    uint64_t wait_value = 1;
    VkTimelineSemaphoreSubmitInfo ts = {.sType = VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    ts.waitSemaphoreValueCount = 1;
    ts.pWaitSemaphoreValues = &wait_value;
    VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.pNext = &ts;
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &hold;
    si.pWaitDstStageMask = &stage;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VK(vkQueueSubmit(queue, 1, &si, fence));
}

/* Lets the submissions waiting on `hold` run. */
void release_held(VkSemaphore hold) {
    VkSemaphoreSignalInfo release = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
    release.semaphore = hold;
    release.value = 1;
    VK(vkSignalSemaphore(device, &release));
}

void create_device(void) {
    const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
    const char *inst_ext[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "hrts C host";
    app.apiVersion = VK_API_VERSION_1_3;
    /* Khronos synchronization validation: hazards between commands, command buffers and submissions */
    VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    /* the driver's own handles (the layer wraps them in handles never reused otherwise), so that a buffer
     * destroyed can come back at the same handle, as engines see it (reused_vertex_handle) */
    VkValidationFeatureDisableEXT disables[] = {VK_VALIDATION_FEATURE_DISABLE_UNIQUE_HANDLES_EXT};
    VkValidationFeaturesEXT vf = {.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    vf.enabledValidationFeatureCount = 1;
    vf.pEnabledValidationFeatures = enables;
    vf.disabledValidationFeatureCount = 1;
    vf.pDisabledValidationFeatures = disables;
    VkDebugUtilsMessengerCreateInfoEXT mi = {.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    vf.pNext = &mi;
    mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    mi.pfnUserCallback = on_validation;
    VkInstanceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pNext = &vf; /* the chained messenger also reports what vkCreateInstance and vkDestroyInstance find */
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = 1;
    ci.ppEnabledLayerNames = layers;
    ci.enabledExtensionCount = 2;
    ci.ppEnabledExtensionNames = inst_ext;
    VK(vkCreateInstance(&ci, NULL, &instance));
    PFN_vkCreateDebugUtilsMessengerEXT create_messenger =
        (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT");
    if (!create_messenger) { fprintf(stderr, "no vkCreateDebugUtilsMessengerEXT\n"); exit(2); }
    VK(create_messenger(instance, &mi, NULL, &messenger));
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
    /* the engine's own: a timeline semaphore holds the first frame in flight (frames_in_flight) */
    VkPhysicalDeviceVulkan12Features f12 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.timelineSemaphore = VK_TRUE;
    f12.pNext = &f13;
    VkPhysicalDeviceFeatures feats;
    memset(&feats, 0, sizeof feats);
    feats.geometryShader = VK_TRUE;
    feats.fragmentStoresAndAtomics = VK_TRUE;
    feats.depthClamp = VK_TRUE;
    VkDeviceCreateInfo di = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    di.pNext = &f12;
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &qi;
    di.pEnabledFeatures = &feats;
    VK(vkCreateDevice(phys, &di, NULL, &device));
    vkGetDeviceQueue(device, family, 0, &queue);
    VkCommandPoolCreateInfo pi = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = family;
    VK(vkCreateCommandPool(device, &pi, NULL, &pool));
}

/* Destroys what create_device created; the validation layer's object tracker reports there any object the
 * plugin leaked. */
void destroy_device(void) {
    vkDestroyCommandPool(device, pool, NULL);
    vkDestroyDevice(device, NULL);
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger =
        (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT");
    destroy_messenger(instance, messenger, NULL);
    vkDestroyInstance(instance, NULL);
}

HrtsVulkanDevice adopt_info(void) {
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

HrtsContext *create_context(const HrtsVulkanDevice *v, uint32_t frames_in_flight) {
    HrtsContextCreateInfo ci;
    memset(&ci, 0, sizeof ci);
    ci.struct_size = sizeof ci;
    ci.api_version = HRTS_API_VERSION;
    ci.vulkan = v;
    ci.frames_in_flight = frames_in_flight;
    HrtsContext *ctx = NULL;
    HrtsResult r = hrts_context_create(&ci, &ctx);
    if (r != HRTS_RESULT_OK) {
        fprintf(stderr, "hrts_context_create: %s: %s\n", hrts_result_name(r), hrts_last_error(NULL));
        exit(2);
    }
    return ctx;
}

HrtsDraw draws[2];
HrtsCpuGeometry cpu_geometry(void) {
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

/* The engine's images: depth, normals and a visibility array with one layer per light (up to LAYERS). */
Img depth_img, normal_img, out_img;

HrtsTargets targets(void) {
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
    t.output_layers = LAYERS;
    return t;
}

/* The lights of the frames recorded by `frame` (the engine's scene). */
Emitter scene_lights[HRTS_MAX_LIGHTS];
HrtsLight c_lights[HRTS_MAX_LIGHTS];
uint32_t light_count = 1;

void set_lights(const Emitter *lights, uint32_t count) {
    light_count = count;
    for (uint32_t i = 0; i < count; i++) {
        scene_lights[i] = lights[i];
        c_lights[i] = lights[i].c;
    }
}

/* The engine's frame counter: every frame recorded gets the next index. */
uint64_t next_frame;

HrtsFrame frame(VkCommandBuffer cmd, uint64_t index) {
    HrtsFrame f;
    memset(&f, 0, sizeof f);
    f.struct_size = sizeof f;
    f.command_buffer = (uint64_t)(uintptr_t)cmd;
    f.frame_index = index;
    memcpy(f.view, view, sizeof view);
    memcpy(f.proj, proj, sizeof proj);
    f.camera_position[0] = (float)cam_pos.x;
    f.camera_position[1] = (float)cam_pos.y;
    f.camera_position[2] = (float)cam_pos.z;
    f.lights = c_lights;
    f.light_count = light_count;
    f.depth_layout = VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL;
    f.normal_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    f.output_layout_before = VK_IMAGE_LAYOUT_UNDEFINED;
    f.output_layout_after = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    return f;
}

/* Draws depth and normals of the current camera on the CPU (the engine's own G-buffer pass) into host
 * buffers of W*H and 4*W*H floats. */
void draw_gbuffer(float *dp, float *np) {
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
}

/* Records the upload of a drawn G-buffer into the depth and normal images; `first`: their contents are
 * undefined before (else they are in the layouts the frames leave them in). */
void record_gbuffer_upload(VkCommandBuffer cmd, Buf depth, Buf normal, int first) {
    VkImageLayout depth_from = first ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL;
    VkImageLayout normal_from = first ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    barrier(cmd, depth_img.image, VK_IMAGE_ASPECT_DEPTH_BIT, 1, depth_from, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    barrier(cmd, normal_img.image, VK_IMAGE_ASPECT_COLOR_BIT, 1, normal_from, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    VkBufferImageCopy region = frame_region(VK_IMAGE_ASPECT_DEPTH_BIT, 1);
    vkCmdCopyBufferToImage(cmd, depth.buffer, depth_img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    vkCmdCopyBufferToImage(cmd, normal.buffer, normal_img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    barrier(cmd, depth_img.image, VK_IMAGE_ASPECT_DEPTH_BIT, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL);
    barrier(cmd, normal_img.image, VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

/* Draws and uploads the G-buffer of the current camera, waiting for it. */
static int gbuffer_uploaded;
void upload_gbuffer(void) {
    Buf depth = make_host_buffer(sizeof(float) * W * H, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    Buf normal = make_host_buffer(sizeof(float) * 4 * W * H, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    draw_gbuffer(depth.map, normal.map);
    VkCommandBuffer cmd = begin();
    record_gbuffer_upload(cmd, depth, normal, !gbuffer_uploaded);
    gbuffer_uploaded = 1;
    submit_and_wait(cmd);
    free_buffer(depth);
    free_buffer(normal);
}

/* Records the copy of the first `layers` output layers into `back` (tightly packed, layer after layer). */
void record_output_readback(VkCommandBuffer cmd, Buf back, uint32_t layers) {
    VkBufferImageCopy region = frame_region(VK_IMAGE_ASPECT_COLOR_BIT, layers);
    vkCmdCopyImageToBuffer(cmd, out_img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, back.buffer, 1, &region);
    host_read_barrier(cmd);
}

/* Copies the visibility of every light into `vis` (if the recording succeeded), submits `cmd` and waits. */
HrtsResult finish_frame(VkCommandBuffer cmd, HrtsResult r, float *vis) {
    Buf back = make_host_buffer(sizeof(float) * W * H * light_count, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    if (r == HRTS_RESULT_OK) record_output_readback(cmd, back, light_count);
    submit_and_wait(cmd);
    if (vis && r == HRTS_RESULT_OK) memcpy(vis, back.map, sizeof(float) * W * H * light_count);
    free_buffer(back);
    return r;
}

/* Records one plugin frame, submits it and reads the visibility of every light back into `vis`. */
HrtsResult run_frame(HrtsContext *ctx, float *vis) {
    VkCommandBuffer cmd = begin();
    HrtsFrame f = frame(cmd, next_frame++);
    HrtsResult r = hrts_record_frame(ctx, &f);
    return finish_frame(cmd, r, vis);
}

/* Records one frame pass by pass (one hrts_record_passes call per HrtsPass, into one command buffer), or
 * as an engine splits it: the light-space passes in a first submission, the screen-space passes and the
 * output copy in a second one. Reads the visibility back into `vis`. */
HrtsResult run_frame_in_parts(HrtsContext *ctx, float *vis, int one_by_one) {
    VkCommandBuffer cmd = begin();
    uint64_t index = next_frame++;
    HrtsFrame f = frame(cmd, index);
    HrtsResult r = HRTS_RESULT_OK;
    if (one_by_one) {
        for (uint32_t pass = 0; pass < HRTS_PASS_COUNT && r == HRTS_RESULT_OK; pass++)
            r = hrts_record_passes(ctx, &f, 1u << pass);
    } else {
        r = hrts_record_passes(ctx, &f, HRTS_PASS_MASK_LIGHT_SPACE);
        submit_and_wait(cmd);
        cmd = begin();
        f = frame(cmd, index);
        if (r == HRTS_RESULT_OK) r = hrts_record_passes(ctx, &f, HRTS_PASS_MASK_SCREEN_SPACE);
    }
    return finish_frame(cmd, r, vis);
}

/* Records the copy of light `light`'s `resource` into `back` (`bytes` long) into `cmd`. */
HrtsResult record_resource_readback(HrtsContext *ctx, VkCommandBuffer cmd, uint32_t light, uint32_t resource,
                                           Buf back, size_t bytes) {
    HrtsResourceReadback rb;
    memset(&rb, 0, sizeof rb);
    rb.struct_size = sizeof rb;
    rb.command_buffer = (uint64_t)(uintptr_t)cmd;
    rb.resource = resource;
    rb.light = light;
    rb.buffer = (uint64_t)(uintptr_t)back.buffer;
    rb.buffer_size = bytes;
    return hrts_record_resource_readback(ctx, &rb);
}

/* Reads a plugin resource of the last complete frame back through hrts_record_resource_readback. */
HrtsResult read_resource(HrtsContext *ctx, uint32_t light, uint32_t resource, float *out, size_t bytes) {
    Buf back = make_host_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    VkCommandBuffer cmd = begin();
    HrtsResult r = record_resource_readback(ctx, cmd, light, resource, back, bytes);
    submit_and_wait(cmd);
    if (r == HRTS_RESULT_OK) memcpy(out, back.map, bytes);
    free_buffer(back);
    return r;
}

HrtsResult report(HrtsContext *ctx, uint64_t index, uint32_t light, HrtsFrameReport *rep) {
    memset(rep, 0, sizeof *rep);
    rep->struct_size = sizeof *rep;
    return hrts_get_frame_report(ctx, index, light, rep);
}

int differing(const float *a, const float *b, int n) {
    int d = 0;
    for (int i = 0; i < n; i++) d += memcmp(&a[i], &b[i], sizeof(float)) != 0;
    return d;
}

/* Area shadows of `samples` samples: the pixels of `vis` strictly between 0 and 1 (`penumbra`), and those that
 * are no whole count k / samples in [0, 1], which it returns. */
int area_not_counts(const float *vis, float samples, int *penumbra) {
    int not_counts = 0;
    *penumbra = 0;
    for (int i = 0; i < W * H; i++) {
        float k = vis[i] * samples;
        if (!(vis[i] >= 0.0f && vis[i] <= 1.0f) || k != floorf(k)) not_counts++;
        if (vis[i] > 0.0f && vis[i] < 1.0f) (*penumbra)++;
    }
    return not_counts;
}

/* Pixels whose visibility differs from the exact shadow of light `e` (near-edge pixels counted apart). */
int count_mismatches(const float *vis, double tol, const Emitter *e, int *near_edge, int *shadowed, int *lit) {
    int mismatches = 0;
    *near_edge = *shadowed = *lit = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int ex = exact(x, y, tol, e);
            float v = vis[y * W + x];
            if (ex == -1) { (*near_edge)++; continue; }
            float want = ex == 0 ? 0.0f : 1.0f;
            if (ex == 0) (*shadowed)++;
            if (ex == 1) (*lit)++;
            if (v != want) {
                if (mismatches < 8) fprintf(stderr, "pixel (%d,%d): exact %d, plugin %g\n", x, y, ex, v);
                mismatches++;
            }
        }
    return mismatches;
}

/* Tolerance of the exact classification: 1/16 of the pixel footprint at the farthest point. */
double edge_tolerance(void) { return 12.0 * (2 * tan(FOV_Y / 2) / H) / 16.0; }

HrtsConfig config(uint32_t mode) {
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

/* The scene in the engine's own Vulkan buffers: float4 positions (stride 16) at byte offset 64, 16-bit
 * indices at byte offset 8; the buffers go to `vb` and `ib`. */
HrtsVulkanGeometry engine_geometry(Buf *vb, Buf *ib) {
    *vb = make_host_buffer(64 + 12 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    *ib = make_host_buffer(8 + 44 * 2, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    float *vp = (float *)((char *)vb->map + 64);
    uint16_t *ip = (uint16_t *)((char *)ib->map + 8);
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
    vg.vertex_buffer = (uint64_t)(uintptr_t)vb->buffer;
    vg.vertex_buffer_size = 64 + 12 * 16;
    vg.vertex_offset = 64;
    vg.vertex_stride = 16;
    vg.vertex_count = 12;
    vg.index_buffer = (uint64_t)(uintptr_t)ib->buffer;
    vg.index_buffer_size = 8 + 44 * 2;
    vg.index_offset = 8;
    vg.index_type = HRTS_INDEX_TYPE_UINT16;
    vg.index_count = 42;
    vg.draws = draws;
    vg.draw_count = 2;
    memcpy(vg.bounds, SCENE_BOUNDS, sizeof SCENE_BOUNDS);
    return vg;
}

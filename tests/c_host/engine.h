/* The engine of the C tests (engine.c): a scene of a box floating over a ground plane, its camera and lights
 * and their exact shadow, a Vulkan device of its own (validation and synchronization validation on), its
 * images and buffers, a G-buffer drawn on the CPU, and the frames it records the plugin into. Built with
 * the C host (c_host.c and the files of its checks, see c_host.h) against the current hrts.h, and with
 * old_caller.c against the header of an older API version: it uses nothing newer than API 5.1. */
#ifndef HRTS_TEST_ENGINE_H
#define HRTS_TEST_ENGINE_H

#include "hrts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <vulkan/vulkan.h>

extern int passed, failed;

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

typedef struct {
    double x, y, z;
} V3;
static inline V3 v3(double x, double y, double z) { V3 r = {x, y, z}; return r; }
static inline V3 sub3(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline V3 add3(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline V3 mul3(V3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline double dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline V3 cross3(V3 a, V3 b) { return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static inline V3 norm3(V3 a) { return mul3(a, 1.0 / sqrt(dot3(a, a))); }

/* ---------- scene: ground quad y = 0 (|x|,|z| <= 4) and a box [-0.5,0.5]x[0.6,1.6]x[-0.5,0.5] ---------- */
extern const double BOX_MIN[3];
extern const double BOX_MAX[3];
extern double box_shift[3];
extern const double GROUND;
extern const float SCENE_BOUNDS[6];
extern float positions[36];
extern uint32_t indices[42];
double ray_box(V3 o, V3 d, double grow, V3 *normal);

/* ---------- camera and lights ---------- */
enum { W = 160, H = 120, LAYERS = 8 };
extern const double FOV_Y, NEAR;
extern V3 cam_pos, cam_f, cam_r, cam_u;
extern float view[16], proj[16];
void setup_camera(double angle);

/* A light as the engine knows it: its exact geometry and what it hands the plugin. */
typedef struct {
    int spot;
    V3 dir; /* direction of travel (directional) or cone axis (spot), unit */
    V3 pos; /* spot: emitter */
    HrtsLight c;
} Emitter;
Emitter directional(V3 dir);
Emitter fitted_sun(V3 dir);
Emitter spot(V3 pos, V3 target, double fov);
Emitter point(V3 pos);
Emitter fitted_spot(V3 pos, V3 target, double cone);
V3 pixel_ray(double x, double y);
int cast(V3 o, V3 d, double grow, double *t, V3 *n);
int blocked(V3 p, const Emitter *e, double grow);
int exact(int x, int y, double tol, const Emitter *e);

/* ---------- Vulkan ---------- */
typedef struct {
    VkImage image;
    VkDeviceMemory memory;
} Img;

typedef struct {
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *map;
} Buf;

extern VkPhysicalDevice phys;
extern VkDevice device;
extern VkQueue queue;
extern uint32_t family;
extern VkCommandPool pool;
extern int validation_errors, validation_warnings;
extern const char *phase;
uint32_t memory_type(uint32_t bits, VkMemoryPropertyFlags want);
Img make_image(VkFormat format, VkImageUsageFlags usage, uint32_t layers);
void free_image(Img i);
Buf make_host_buffer(VkDeviceSize size, VkBufferUsageFlags usage);
void free_buffer(Buf b);
void barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, uint32_t layers, VkImageLayout from,
             VkImageLayout to);
void host_read_barrier(VkCommandBuffer cmd);
VkCommandBuffer begin(void);
void submit(VkCommandBuffer cmd, VkFence fence);
void submit_and_wait(VkCommandBuffer cmd);
uint16_t half_of(float f);
VkBufferImageCopy frame_region(VkImageAspectFlags aspect, uint32_t layers);
void upload_image(Img img, VkImageAspectFlags aspects, VkImageAspectFlags copied, Buf staging, VkImageLayout layout);
void frames_in_flight_ring(uint32_t n, VkCommandBuffer *cmds, VkFence *fences);
VkSemaphore held_semaphore(void);
void submit_held(VkCommandBuffer cmd, VkSemaphore hold, VkFence fence);
void release_held(VkSemaphore hold);
void create_device(void);
void destroy_device(void);
HrtsVulkanDevice adopt_info(void);
HrtsContext *create_context(const HrtsVulkanDevice *v, uint32_t frames_in_flight);

/* ---------- the frames the engine records the plugin into ---------- */
extern HrtsDraw draws[2];
HrtsCpuGeometry cpu_geometry(void);
extern Img depth_img, normal_img, out_img;
HrtsTargets targets(void);
extern Emitter scene_lights[HRTS_MAX_LIGHTS];
extern HrtsLight c_lights[HRTS_MAX_LIGHTS];
extern uint32_t light_count;
void set_lights(const Emitter *lights, uint32_t count);
extern uint64_t next_frame;
HrtsFrame frame(VkCommandBuffer cmd, uint64_t index);
void draw_gbuffer(float *dp, float *np);
void record_gbuffer_upload(VkCommandBuffer cmd, Buf depth, Buf normal, int first);
void upload_gbuffer(void);
void record_output_readback(VkCommandBuffer cmd, Buf back, uint32_t layers);
HrtsResult finish_frame(VkCommandBuffer cmd, HrtsResult r, float *vis);
HrtsResult run_frame(HrtsContext *ctx, float *vis);
HrtsResult run_frame_in_parts(HrtsContext *ctx, float *vis, int one_by_one);
HrtsResult record_resource_readback(HrtsContext *ctx, VkCommandBuffer cmd, uint32_t light, uint32_t resource,
                                    Buf back, size_t bytes);
HrtsResult read_resource(HrtsContext *ctx, uint32_t light, uint32_t resource, float *out, size_t bytes);
HrtsResult report(HrtsContext *ctx, uint64_t index, uint32_t light, HrtsFrameReport *rep);
int differing(const float *a, const float *b, int n);
int area_not_counts(const float *vis, float samples, int *penumbra);
int count_mismatches(const float *vis, double tol, const Emitter *e, int *near_edge, int *shadowed, int *lit);
double edge_tolerance(void);
HrtsConfig config(uint32_t mode);
HrtsVulkanGeometry engine_geometry(Buf *vb, Buf *ib);

#endif

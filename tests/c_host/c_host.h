/* The C host's checks, one file per topic, and what more than one of those files uses: main() (c_host.c)
 * calls the checks in order. Built with the engine of the C tests (engine.c) against the current hrts.h. */
#ifndef HRTS_C_HOST_H
#define HRTS_C_HOST_H

#include "engine.h"

/* The frames in flight of the one-light context and of the engine loop (frames.c). */
enum { IN_FLIGHT = 3 };

/* ---------- memory.c: the engine's allocator, create/destroy cycles ---------- */
void *engine_allocate(void *user, size_t size, size_t alignment);
void engine_free(void *user, void *memory, size_t size, size_t alignment);
void install_engine_allocator(void);
void create_destroy_cycles(const HrtsVulkanDevice *vk, const HrtsConfig *cfg, const HrtsCpuGeometry *g,
                           const HrtsTargets *t);

/* ---------- one_light.c: one sun, hard, hybrid, pass by pass, area, engine buffers ---------- */
void one_light(HrtsContext *ctx, const Emitter *sun, const HrtsConfig *cfg, const HrtsCpuGeometry *g);

/* ---------- misuse.c ---------- */
void misuse(HrtsContext *ctx, const HrtsVulkanDevice *vk);

/* ---------- lights.c: several lights, lights given as lights, the plugin's plan for a light ---------- */
HrtsResult configure_all(HrtsContext *ctx, uint32_t count, uint32_t mode);
HrtsContext *hard_lights_context(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g, const Emitter *lights,
                                uint32_t n);
void several_lights(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void native_local_lights(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void auto_fitted_sun(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);

/* ---------- frames.c: frames in flight, a read-back's retire, a partial record ---------- */
void frames_in_flight(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void readback_retire(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void partial_record(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);

/* ---------- geometry.c: moving geometry and instances, base vertex, quantized positions ---------- */
void moving_geometry_bounds(const HrtsVulkanDevice *vk);
void moving_instances(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void base_vertex_draws(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void quantized_positions(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);

/* ---------- engine_images.c: the engine's normals, depth and output images ---------- */
uint16_t float_to_half(float f);
void engine_normals(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void engine_depth(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void output_formats(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void output_direct(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);
void fxaa_shared(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g);

/* ---------- meshes.c: the scene as meshes of their own buffers, draw transforms all or nothing ---------- */
enum { SPLIT_MESHES = 3, BOX_VERTICES = 8 };

/* The scene as three meshes (split_scene): their buffers, draws and geometry. */
typedef struct {
    Buf vb[SPLIT_MESHES], ib[SPLIT_MESHES];
    HrtsDraw draws[SPLIT_MESHES];
    HrtsVulkanGeometry meshes[SPLIT_MESHES];
} SplitScene;

void box_snorm(uint16_t *at, int half);
void split_scene(SplitScene *s);
void lit_split_scene(Emitter sun, SplitScene *s);
void free_split_scene(SplitScene *s);
HrtsContext *meshes_context(const HrtsVulkanDevice *vk, uint32_t frames_in_flight, const HrtsVulkanGeometry *meshes,
                            uint32_t mesh_count);
void engine_meshes(const HrtsVulkanDevice *vk);
void draw_transforms_all_or_nothing(const HrtsVulkanDevice *vk);

/* ---------- deforming.c ---------- */
void deforming_mesh(const HrtsVulkanDevice *vk);

#endif

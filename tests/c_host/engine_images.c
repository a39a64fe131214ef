/* The engine's images as they are: normals in the encodings and spaces engines keep (or none), the depth
 * formats the plugin reads with reversed and standard Z (or view Z), outputs of 8- and 16-bit formats, and
 * an output the last passes write directly. Each against the exact shadow or the R32_SFLOAT output. */
#define _POSIX_C_SOURCE 200112L
#include "c_host.h"

#include <string.h>

/* ---------- the engine's normals as they are ---------- */
/* Normals as engines keep them: xyz in half floats, RGB10A2 or RGBA8 (unorm: [0, 1] for [-1, 1]),
 * octahedral in RG16 snorm, unorm or float or in RGB10A2, in world or view space, or no normal image at
 * all (the plugin derives the normal from depth). Each gives the exact hard shadow of a sun and of a point
 * light (0 mismatches outside near-edge pixels). */
uint16_t float_to_half(float f) {
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    uint32_t sign = (x >> 16) & 0x8000u;
    int exponent = (int)((x >> 23) & 0xff) - 127 + 15;
    uint32_t mantissa = x & 0x7fffffu;
    if (exponent <= 0) {
        if (exponent < -10) return (uint16_t)sign;
        mantissa |= 0x800000u;
        uint32_t shift = (uint32_t)(14 - exponent);
        uint32_t half = mantissa >> shift;
        if ((mantissa >> (shift - 1)) & 1u) half++;
        return (uint16_t)(sign | half);
    }
    uint32_t half = sign | ((uint32_t)exponent << 10) | (mantissa >> 13);
    if (mantissa & 0x1000u) half++;
    return (uint16_t)half;
}

static void octahedral_encode(V3 n, double *ex, double *ey) {
    double l1 = fabs(n.x) + fabs(n.y) + fabs(n.z);
    double x = n.x / l1, y = n.y / l1;
    if (n.z < 0) {
        double ox = (1 - fabs(y)) * (x >= 0 ? 1 : -1), oy = (1 - fabs(x)) * (y >= 0 ? 1 : -1);
        x = ox;
        y = oy;
    }
    *ex = x;
    *ey = y;
}

static uint32_t unorm(double v, double max) { return (uint32_t)lround((v * 0.5 + 0.5) * max); }

enum { NORMAL_XYZ_RGBA16F, NORMAL_XYZ_RGB10A2, NORMAL_XYZ_RGBA8, NORMAL_OCT_RG16_SNORM, NORMAL_OCT_RG16_UNORM,
       NORMAL_OCT_RG16F, NORMAL_OCT_RGB10A2, NORMAL_NONE, NORMAL_CASES };

void engine_normals(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    const struct {
        const char *name;
        VkFormat format;
        uint32_t encoding, space;
        size_t texel;
    } cases[NORMAL_CASES] = {
        [NORMAL_XYZ_RGBA16F] = {"xyz RGBA16F world", VK_FORMAT_R16G16B16A16_SFLOAT, HRTS_NORMAL_ENCODING_XYZ,
                                HRTS_NORMAL_SPACE_WORLD, 8},
        [NORMAL_XYZ_RGB10A2] = {"xyz RGB10A2 world", VK_FORMAT_A2B10G10R10_UNORM_PACK32, HRTS_NORMAL_ENCODING_XYZ,
                                HRTS_NORMAL_SPACE_WORLD, 4},
        [NORMAL_XYZ_RGBA8] = {"xyz RGBA8 view", VK_FORMAT_R8G8B8A8_UNORM, HRTS_NORMAL_ENCODING_XYZ,
                              HRTS_NORMAL_SPACE_VIEW, 4},
        [NORMAL_OCT_RG16_SNORM] = {"octahedral RG16 snorm world", VK_FORMAT_R16G16_SNORM,
                                   HRTS_NORMAL_ENCODING_OCTAHEDRAL, HRTS_NORMAL_SPACE_WORLD, 4},
        [NORMAL_OCT_RG16_UNORM] = {"octahedral RG16 unorm view", VK_FORMAT_R16G16_UNORM,
                                   HRTS_NORMAL_ENCODING_OCTAHEDRAL, HRTS_NORMAL_SPACE_VIEW, 4},
        [NORMAL_OCT_RG16F] = {"octahedral RG16F view", VK_FORMAT_R16G16_SFLOAT, HRTS_NORMAL_ENCODING_OCTAHEDRAL,
                              HRTS_NORMAL_SPACE_VIEW, 4},
        [NORMAL_OCT_RGB10A2] = {"octahedral RGB10A2 world", VK_FORMAT_A2B10G10R10_UNORM_PACK32,
                                HRTS_NORMAL_ENCODING_OCTAHEDRAL, HRTS_NORMAL_SPACE_WORLD, 4},
        [NORMAL_NONE] = {"none (derived from depth)", VK_FORMAT_UNDEFINED, HRTS_NORMAL_ENCODING_NONE,
                         HRTS_NORMAL_SPACE_WORLD, 0},
    };
    setup_camera(0.0);
    upload_gbuffer(); /* depth of this view */
    static float world[4 * PX];
    static float unused_depth[PX];
    draw_gbuffer(unused_depth, world);
    Emitter lights[2] = {directional(v3(0.45, -1.0, 0.2)), point(v3(0.9, 2.3, 0.7))};
    int failed_cases = 0;
    for (int c = 0; c < NORMAL_CASES; c++) {
        Img normal = {VK_NULL_HANDLE, VK_NULL_HANDLE};
        if (cases[c].texel > 0) {
            normal = make_image(cases[c].format, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 1);
            Buf staging = make_host_buffer(cases[c].texel * PX, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
            for (int i = 0; i < PX; i++) {
                V3 n = v3(world[4 * i], world[4 * i + 1], world[4 * i + 2]);
                if (cases[c].space == HRTS_NORMAL_SPACE_VIEW) n = v3(dot3(n, cam_r), dot3(n, cam_u), -dot3(n, cam_f));
                double ex, ey;
                octahedral_encode(world[4 * i + 3] != 0 ? n : v3(0, 0, 1), &ex, &ey);
                uint16_t *h = (uint16_t *)staging.map + 4 * i;
                uint32_t *u = (uint32_t *)staging.map + i;
                int16_t *sn = (int16_t *)staging.map + 2 * i;
                uint16_t *un = (uint16_t *)staging.map + 2 * i;
                switch (c) {
                case NORMAL_XYZ_RGBA16F:
                    h[0] = float_to_half((float)n.x), h[1] = float_to_half((float)n.y), h[2] = float_to_half((float)n.z),
                    h[3] = float_to_half(1.0f);
                    break;
                case NORMAL_XYZ_RGB10A2:
                    *u = unorm(n.x, 1023) | unorm(n.y, 1023) << 10 | unorm(n.z, 1023) << 20 | 3u << 30;
                    break;
                case NORMAL_XYZ_RGBA8:
                    *u = unorm(n.x, 255) | unorm(n.y, 255) << 8 | unorm(n.z, 255) << 16 | 255u << 24;
                    break;
                case NORMAL_OCT_RG16_SNORM:
                    sn[0] = (int16_t)lround(ex * 32767), sn[1] = (int16_t)lround(ey * 32767);
                    break;
                case NORMAL_OCT_RG16_UNORM:
                    un[0] = (uint16_t)unorm(ex, 65535), un[1] = (uint16_t)unorm(ey, 65535);
                    break;
                case NORMAL_OCT_RG16F:
                    un[0] = float_to_half((float)ex), un[1] = float_to_half((float)ey);
                    break;
                case NORMAL_OCT_RGB10A2:
                    *u = unorm(ex, 1023) | unorm(ey, 1023) << 10;
                    break;
                }
            }
            upload_image(normal, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_ASPECT_COLOR_BIT, staging,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
            free_buffer(staging);
        }
        HrtsContext *ctx = create_context(vk, 1);
        set_lights(lights, 2);
        HrtsTargets t = targets();
        t.normal_image = (uint64_t)(uintptr_t)normal.image;
        t.normal_usage = cases[c].texel > 0 ? VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT : 0;
        t.normal_format = (uint32_t)cases[c].format;
        t.normal_encoding = cases[c].encoding;
        t.normal_space = cases[c].space;
        HrtsResult r = configure_all(ctx, 2, HRTS_SHADOW_MODE_HARD);
        if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
        if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
        static float vis[2 * PX];
        if (r == HRTS_RESULT_OK) r = run_frame(ctx, vis);
        CHECK(r == HRTS_RESULT_OK, "normals %s: %s", cases[c].name, hrts_last_error(ctx));
        int total = 0;
        for (int l = 0; l < 2 && r == HRTS_RESULT_OK; l++) {
            int near_edge, shadowed, lit;
            int mismatches = count_mismatches(vis + l * PX, edge_tolerance(), &lights[l], &near_edge, &shadowed, &lit);
            printf("normals %s, %s: %d lit, %d shadowed, %d near-edge, %d mismatches\n", cases[c].name,
                   l == 0 ? "sun" : "point light", lit, shadowed, near_edge, mismatches);
            total += mismatches;
            CHECK(shadowed > 300, "normals %s: %d shadowed px", cases[c].name, shadowed);
        }
        CHECK(r == HRTS_RESULT_OK && total == 0, "normals %s: %d mismatches", cases[c].name, total);
        failed_cases += r != HRTS_RESULT_OK || total != 0;
        CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
        if (cases[c].texel > 0) free_image(normal);
    }
    printf("engine normals: %d encodings, %d failed\n", NORMAL_CASES, failed_cases);
    /* an xyz encoding in a two-channel image, and an unknown encoding, are refused */
    HrtsContext *ctx = create_context(vk, 1);
    HrtsTargets t = targets();
    t.normal_format = VK_FORMAT_R16G16_SNORM;
    t.normal_encoding = HRTS_NORMAL_ENCODING_XYZ;
    CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "normal_format"),
          "xyz in RG16 refused: %s", hrts_last_error(ctx));
    t.normal_encoding = 7;
    CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_ERROR_INVALID_ENUM && strstr(hrts_last_error(ctx), "normal_encoding"),
          "unknown normal encoding refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    set_lights(lights, 1);
}

/* ---------- the engine's depth as it is ---------- */
/* Every depth format the plugin reads, written by a reversed-Z projection with an infinite far plane and by a
 * standard-Z one with a finite far plane, gives the exact hard shadow (0 mismatches outside near-edge pixels):
 * the plugin rebuilds positions through the frame's projection and offsets the ray origins by the format's
 * depth error. A format it does not read is refused with a message. */
void engine_depth(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H };
    const struct {
        VkFormat format;
        const char *name;
    } formats[] = {
        {VK_FORMAT_D16_UNORM, "D16_UNORM"},
        {VK_FORMAT_X8_D24_UNORM_PACK32, "X8_D24_UNORM_PACK32"},
        {VK_FORMAT_D24_UNORM_S8_UINT, "D24_UNORM_S8_UINT"},
        {VK_FORMAT_D32_SFLOAT, "D32_SFLOAT"},
        {VK_FORMAT_D32_SFLOAT_S8_UINT, "D32_SFLOAT_S8_UINT"},
        {VK_FORMAT_R32_SFLOAT, "view Z in R32_SFLOAT"},
        {VK_FORMAT_R16_SFLOAT, "view Z in R16_SFLOAT"},
    };
    const double FAR = 50.0;
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer(); /* the normals of this view (and a depth the cases below replace) */
    static double distance[PX], view_z[PX];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            V3 n;
            double t;
            V3 ray = pixel_ray(x, y);
            distance[y * W + x] = cast(cam_pos, ray, 0, &t, &n) ? t : -1.0;
            /* an engine's linear view Z: the view-space z of the hit (negative in front), 0 on background */
            view_z[y * W + x] = distance[y * W + x] < 0 ? 0.0 : -t * dot3(ray, cam_f);
        }
    int cases = 0, failed_cases = 0;
    char skipped[256] = "";
    for (size_t k = 0; k < sizeof formats / sizeof formats[0]; k++) {
        VkFormat format = formats[k].format;
        int linear = format == VK_FORMAT_R32_SFLOAT || format == VK_FORMAT_R16_SFLOAT;
        VkFormatProperties props;
        vkGetPhysicalDeviceFormatProperties(phys, format, &props);
        VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT |
                                    (linear ? 0 : VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT);
        if ((props.optimalTilingFeatures & need) != need) {
            strcat(skipped, " ");
            strcat(skipped, formats[k].name);
            continue;
        }
        int stencil = format == VK_FORMAT_D24_UNORM_S8_UINT || format == VK_FORMAT_D32_SFLOAT_S8_UINT;
        VkImageAspectFlags data = linear ? VK_IMAGE_ASPECT_COLOR_BIT : VK_IMAGE_ASPECT_DEPTH_BIT;
        VkImageAspectFlags all = data | (stencil ? VK_IMAGE_ASPECT_STENCIL_BIT : 0);
        VkImageLayout layout = linear    ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL
                               : stencil ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL
                                         : VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL;
        size_t texel = format == VK_FORMAT_D16_UNORM || format == VK_FORMAT_R16_SFLOAT ? 2 : 4;
        for (int forward = 0; forward < 2; forward++) {
            /* the projection: reversed Z to infinity (the default view), or standard Z to FAR */
            setup_camera(0.0);
            if (forward) {
                proj[10] = (float)(FAR / (NEAR - FAR));
                proj[14] = (float)(NEAR * FAR / (NEAR - FAR));
            }
            /* an engine's depth buffer: a depth attachment it also samples (or a view-Z image it writes) */
            VkImageUsageFlags usage = (linear ? 0 : VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) |
                                      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
            Img depth = make_image(format, usage, 1);
            Buf staging = make_host_buffer(texel * PX, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
            for (int i = 0; i < PX; i++) {
                double t = distance[i];
                double d = t < 0 ? (forward ? 1.0 : 0.0) : forward ? FAR / (FAR - NEAR) * (1.0 - NEAR / t) : NEAR / t;
                if (format == VK_FORMAT_R32_SFLOAT)
                    ((float *)staging.map)[i] = (float)view_z[i];
                else if (format == VK_FORMAT_R16_SFLOAT)
                    ((uint16_t *)staging.map)[i] = half_of((float)view_z[i]);
                else if (format == VK_FORMAT_D16_UNORM)
                    ((uint16_t *)staging.map)[i] = (uint16_t)lround(d * 65535.0);
                else if (format == VK_FORMAT_D32_SFLOAT || format == VK_FORMAT_D32_SFLOAT_S8_UINT)
                    ((float *)staging.map)[i] = (float)d;
                else
                    ((uint32_t *)staging.map)[i] = (uint32_t)lround(d * 16777215.0);
            }
            upload_image(depth, all, data, staging, layout);
            free_buffer(staging);

            HrtsContext *ctx = create_context(vk, 1);
            HrtsTargets t = targets();
            t.depth_image = (uint64_t)(uintptr_t)depth.image;
            t.depth_usage = usage;
            t.depth_format = (uint32_t)format;
            HrtsResult r = configure_all(ctx, 1, HRTS_SHADOW_MODE_HARD);
            if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
            if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
            static float vis[PX];
            if (r == HRTS_RESULT_OK) {
                VkCommandBuffer frame_cmd = begin();
                HrtsFrame f = frame(frame_cmd, next_frame++);
                f.depth_layout = layout;
                r = finish_frame(frame_cmd, hrts_record_frame(ctx, &f), vis);
            }
            int near_edge = 0, shadowed = 0, lit = 0, mismatches = -1;
            if (r == HRTS_RESULT_OK) mismatches = count_mismatches(vis, edge_tolerance(), &sun, &near_edge, &shadowed, &lit);
            printf("depth %s, %s: %d lit, %d shadowed, %d near-edge, %d mismatches\n", formats[k].name,
                   forward ? "standard Z to a far plane" : "reversed Z to infinity", lit, shadowed, near_edge, mismatches);
            CHECK(r == HRTS_RESULT_OK, "depth %s: %s", formats[k].name, hrts_last_error(ctx));
            int ok = r == HRTS_RESULT_OK && mismatches == 0 && shadowed > 300 && near_edge * 100 <= 4 * PX;
            CHECK(ok, "depth %s (%s): %d mismatches, %d shadowed, %d near-edge", formats[k].name,
                  forward ? "standard Z" : "reversed Z", mismatches, shadowed, near_edge);
            cases++;
            failed_cases += !ok;
            CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
            free_image(depth);
        }
    }
    setup_camera(0.0);
    printf("engine depth: %d format and convention cases, %d failed; skipped (the device cannot sample them):%s\n",
           cases, failed_cases, skipped[0] ? skipped : " none");
    CHECK(cases >= 4, "only %d depth cases ran", cases);
    /* a format the plugin does not read, and a colour format, are refused */
    HrtsContext *ctx = create_context(vk, 1);
    HrtsTargets t = targets();
    const uint32_t refused[] = {VK_FORMAT_S8_UINT, VK_FORMAT_R8G8B8A8_UNORM};
    for (int i = 0; i < 2; i++) {
        t.depth_format = refused[i];
        HrtsResult r = hrts_set_targets(ctx, &t);
        CHECK(r == HRTS_RESULT_ERROR_INVALID_ENUM && strstr(hrts_last_error(ctx), "depth_format"),
              "depth_format %u refused: %s", refused[i], hrts_last_error(ctx));
    }
    /* normals derived from depth need the projection's depth, not view Z */
    t.depth_format = VK_FORMAT_R32_SFLOAT;
    t.normal_encoding = HRTS_NORMAL_ENCODING_NONE;
    HrtsResult r = hrts_set_targets(ctx, &t);
    CHECK(r == HRTS_RESULT_ERROR_INVALID_ARGUMENT && strstr(hrts_last_error(ctx), "view-Z"),
          "view Z without normals refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
}

/* ---------- the engine's output format ---------- */
/* The visibility written into an R8_UNORM or R16_SFLOAT output image equals the R32_SFLOAT output to the
 * format's precision: hard shadows exactly (0 and 1), the hybrid's penumbrae and the area shadows' sample
 * fractions within a step of R8 and the rounding of a half float. Without STORAGE usage each layer is
 * converted by a blit; with it, the light's last pass writes the layer directly (the report says so) and
 * the store converts (Vulkan lets it round to either neighbour: a whole R8 step). A colour format the
 * plugin does not write is refused. */
static float half_to_float(uint16_t h) {
    int exponent = (h >> 10) & 31, mantissa = h & 1023;
    double v = exponent == 0 ? ldexp(mantissa, -24) : ldexp(mantissa | 1024, exponent - 25);
    return (float)((h & 0x8000) ? -v : v);
}

void output_formats(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H, MODES = 3 };
    setup_camera(0.0);
    Emitter sun = directional(v3(0.45, -1.0, 0.2));
    set_lights(&sun, 1);
    upload_gbuffer();
    const uint32_t modes[MODES] = {HRTS_SHADOW_MODE_HARD, HRTS_SHADOW_MODE_HYBRID, HRTS_SHADOW_MODE_AREA};
    const char *mode_names[MODES] = {"hard", "hybrid", "area"};
    static float reference[MODES][PX];
    for (int m = 0; m < MODES; m++) {
        HrtsContext *ctx = create_context(vk, 1);
        HrtsTargets t = targets();
        CHECK(configure_all(ctx, 1, modes[m]) == HRTS_RESULT_OK && hrts_set_geometry_cpu(ctx, g) == HRTS_RESULT_OK &&
                  hrts_set_targets(ctx, &t) == HRTS_RESULT_OK && run_frame(ctx, reference[m]) == HRTS_RESULT_OK,
              "output formats: R32_SFLOAT frame (%s): %s", mode_names[m], hrts_last_error(ctx));
        CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
    }
    const struct {
        VkFormat format;
        const char *name;
        size_t texel;
        double blit_tolerance, store_tolerance;
    } formats[] = {{VK_FORMAT_R8_UNORM, "R8_UNORM", 1, 0.5 / 255.0 + 1e-6, 1.0 / 255.0 + 1e-6},
                   {VK_FORMAT_R16_SFLOAT, "R16_SFLOAT", 2, 1.0 / 1024.0, 1.0 / 1024.0}};
    for (int k = 0; k < 2; k++) {
        VkFormatProperties props;
        vkGetPhysicalDeviceFormatProperties(phys, formats[k].format, &props);
        CHECK(props.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT, "%s: the device cannot blit into it",
              formats[k].name);
        int storable = (props.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT) != 0;
        for (int storage = 0; storage <= storable; storage++)
            for (int m = 0; m < MODES; m++) {
                VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                          (storage ? VK_IMAGE_USAGE_STORAGE_BIT : 0);
                Img out = make_image(formats[k].format, usage, 1);
                HrtsContext *ctx = create_context(vk, 1);
                HrtsTargets t = targets();
                t.output_image = (uint64_t)(uintptr_t)out.image;
                t.output_layers = 1;
                t.output_format = (uint32_t)formats[k].format;
                t.output_usage = usage;
                HrtsResult r = configure_all(ctx, 1, modes[m]);
                if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
                if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
                Buf back = make_host_buffer(formats[k].texel * PX, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
                if (r == HRTS_RESULT_OK) {
                    VkCommandBuffer cmd = begin();
                    HrtsFrame f = frame(cmd, next_frame++);
                    r = hrts_record_frame(ctx, &f);
                    if (r == HRTS_RESULT_OK) {
                        VkBufferImageCopy region = frame_region(VK_IMAGE_ASPECT_COLOR_BIT, 1);
                        vkCmdCopyImageToBuffer(cmd, out.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, back.buffer, 1, &region);
                        host_read_barrier(cmd);
                    }
                    submit_and_wait(cmd);
                }
                const char *how = storage ? "written directly" : "blitted";
                CHECK(r == HRTS_RESULT_OK, "output %s (%s): %s", formats[k].name, how, hrts_last_error(ctx));
                HrtsFrameReport rep;
                int direct = -1;
                if (r == HRTS_RESULT_OK && report(ctx, next_frame - 1, 0, &rep) == HRTS_RESULT_OK) direct = rep.output_direct != 0;
                CHECK(direct == storage, "output %s (%s, %s): the report says output_direct %d", formats[k].name,
                      mode_names[m], how, direct);
                double tolerance = storage ? formats[k].store_tolerance : formats[k].blit_tolerance;
                int beyond = 0, soft = 0;
                double worst = 0.0;
                for (int i = 0; i < PX && r == HRTS_RESULT_OK; i++) {
                    float v = formats[k].texel == 1 ? ((uint8_t *)back.map)[i] / 255.0f : half_to_float(((uint16_t *)back.map)[i]);
                    double d = fabs((double)v - reference[m][i]);
                    if (d > worst) worst = d;
                    beyond += d > (m == 0 ? 0.0 : tolerance);
                    soft += reference[m][i] > 0.0f && reference[m][i] < 1.0f;
                }
                printf("output %s %s, %s: %d soft pixels, largest difference from R32_SFLOAT %.6f, %d px beyond the format's "
                       "precision\n",
                       formats[k].name, how, mode_names[m], soft, worst, beyond);
                CHECK(r == HRTS_RESULT_OK && beyond == 0 && (m == 0 || soft > 0), "output %s (%s, %s): %d px differ, %d soft",
                      formats[k].name, mode_names[m], how, beyond, soft);
                free_buffer(back);
                CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
                free_image(out);
            }
    }
    HrtsContext *ctx = create_context(vk, 1);
    HrtsTargets t = targets();
    t.output_format = VK_FORMAT_R8G8B8A8_UNORM;
    CHECK(hrts_set_targets(ctx, &t) == HRTS_RESULT_ERROR_INVALID_ENUM && strstr(hrts_last_error(ctx), "output_format"),
          "an RGBA8 output is refused: %s", hrts_last_error(ctx));
    CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
}

/* ---------- the output written directly ---------- */
/* With an R32_SFLOAT output that also has STORAGE usage, each light's last pass writes its layer (no copy):
 * the visibility equals the copied one bit for bit for a sun (hard, and hybrid: the blend's output), a point
 * light (one cube map, or the minimum over its faces), and a point light and a spot light whose ranges reach
 * nothing (their layers filled with 1), and two more suns, recorded in one call, split as an engine splits a
 * frame, and pass by pass; the report says which lights wrote directly. Pass by pass, every light's map is
 * built before any ray trace: lights whose maps take the same scratch set share their pixel texels, so a
 * ray trace whose texels a later build overwrote rewrites them first ('primitive map: pixel texels'); every
 * way equals the one-call frame bit for bit. */
void output_direct(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H, N = 6 };
    setup_camera(0.0);
    /* six lights' frusta take the plugin's four scratch sets in turn: the last two suns share sets with the
     * first lights, so pass by pass their builds overwrite those lights' pixel texels */
    Emitter lights[N] = {directional(v3(0.45, -1.0, 0.2)), point(v3(0.9, 2.3, 0.7)), point(v3(0.0, 6.0, 0.0)),
                         fitted_spot(v3(0.0, 6.0, 0.0), v3(0.0, 7.0, 0.0), 0.5), directional(v3(-0.3, -1.0, 0.4)),
                         directional(v3(0.2, -1.0, -0.5))};
    lights[2].c.range = 2.0f;
    lights[3].c.range = 2.0f;
    set_lights(lights, N);
    upload_gbuffer();
    const uint32_t modes[2] = {HRTS_SHADOW_MODE_HARD, HRTS_SHADOW_MODE_HYBRID};
    Img copied = out_img;
    Img direct = make_image(VK_FORMAT_R32_SFLOAT,
                            VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                            LAYERS);
    static float want[N * PX], got[N * PX], one_call[N * PX];
    for (int m = 0; m < 2; m++)
        for (int split = 0; split < 3; split++) {
            uint32_t directs[2] = {0, 0};
            uint32_t rewritten = 0;
            for (int d = 0; d < 2; d++) {
                out_img = d ? direct : copied;
                HrtsContext *ctx = create_context(vk, 1);
                HrtsTargets t = targets();
                if (d) t.output_usage |= VK_IMAGE_USAGE_STORAGE_BIT;
                HrtsResult r = configure_all(ctx, N, modes[m]);
                if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
                if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
                if (r == HRTS_RESULT_OK)
                    r = split ? run_frame_in_parts(ctx, d ? got : want, split == 2) : run_frame(ctx, d ? got : want);
                CHECK(r == HRTS_RESULT_OK, "direct output %d: %s", d, hrts_last_error(ctx));
                for (uint32_t l = 0; l < N && r == HRTS_RESULT_OK; l++) {
                    HrtsFrameReport rep;
                    CHECK(report(ctx, next_frame - 1, l, &rep) == HRTS_RESULT_OK, "report: %s", hrts_last_error(ctx));
                    directs[d] += rep.output_direct != 0;
                    for (uint32_t p = 0; p < rep.pass_count; p++)
                        rewritten += d && strcmp(rep.passes[p].name, "primitive map: pixel texels") == 0;
                }
                if (d && modes[m] == HRTS_SHADOW_MODE_HARD && r == HRTS_RESULT_OK) {
                    /* the sun's final output is the engine's layer: it is read there, not back from the plugin */
                    static float one[PX];
                    CHECK(read_resource(ctx, 0, HRTS_RESOURCE_RT_VISIBILITY, one, sizeof one) == HRTS_RESULT_ERROR_INVALID_STATE &&
                              strstr(hrts_last_error(ctx), "directly"),
                          "a read-back of a final output written directly is refused: %s", hrts_last_error(ctx));
                }
                CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
            }
            out_img = copied;
            int differ = 0, differ_one_call = 0;
            for (int i = 0; i < N * PX; i++) differ += memcmp(&want[i], &got[i], sizeof(float)) != 0;
            if (!split) memcpy(one_call, got, sizeof one_call);
            for (int i = 0; i < N * PX; i++) differ_one_call += memcmp(&one_call[i], &got[i], sizeof(float)) != 0;
            const char *how = split == 2 ? "pass by pass" : split ? "split frame" : "one call";
            printf("  %s: pixel texels rewritten before %u ray traces, %d px differ from the one-call frame\n", how,
                   rewritten, differ_one_call);
            CHECK(differ_one_call == 0 && (split == 2 ? rewritten >= 1 : rewritten == 0),
                  "shared pixel texels: %u rewritten, %d px differ from one call", rewritten, differ_one_call);
            int lit = 0;
            for (int i = 2 * PX; i < 4 * PX; i++) lit += got[i] == 1.0f;
            printf("output written directly (%s, %s): %u of %d lights direct (%u with a copy), %d px differ from the copied "
                   "output, the unreached lights' layers %d of %d px lit\n",
                   modes[m] == HRTS_SHADOW_MODE_HARD ? "hard" : "hybrid", how, directs[1],
                   N, directs[0], differ, lit, 2 * PX);
            CHECK(directs[1] == N && directs[0] == 0 && differ == 0 && lit == 2 * PX,
                  "direct output: %u direct, %d px differ, %d lit", directs[1], differ, lit);
        }
    free_image(direct);
}

/* ---------- the visibility the lights' FXAA share ---------- */
/* With antialiasing, hard shadows' ray traces write one visibility image the lights share, each light's
 * FXAA reading it in the same recording call: the output equals, bit for bit, lights that keep their own
 * (RT visibility in extra_outputs), for a sun, a point light and a fitted spot light. In one call a light's
 * report lists no RT visibility of its own, the shared scratch grows by one image, and the shared image
 * cannot be read back; likewise with the light-space and screen-space passes in two submissions. Recorded
 * pass by pass (every light's ray trace in a call before any FXAA) after a frame in one call, each light
 * takes an image of its own from its first such call: the same output, the same bytes as lights keeping
 * their own, and still one ray trace per light. */
void fxaa_shared(const HrtsVulkanDevice *vk, const HrtsCpuGeometry *g) {
    enum { PX = W * H, N = 3 };
    setup_camera(0.0);
    Emitter lights[N] = {directional(v3(0.45, -1.0, 0.2)), point(v3(0.9, 2.3, 0.7)),
                         fitted_spot(v3(-1.5, 3.2, 1.8), v3(0, 0, 0), 0.6)};
    set_lights(lights, N);
    upload_gbuffer();
    static float vis[2][N * PX];
    static const char *modes[3] = {"one call", "two submissions", "pass by pass"};
    for (int split = 0; split < 3; split++) {
        int own_after = split == 2;
        uint64_t scratch[2] = {0, 0}, rt_bytes[2] = {0, 0};
        uint32_t traces[2] = {0, 0};
        for (int shared = 0; shared < 2; shared++) {
            HrtsContext *ctx = create_context(vk, 1);
            HrtsConfig cfgs[N];
            for (int i = 0; i < N; i++) {
                cfgs[i] = config(HRTS_SHADOW_MODE_HARD);
                cfgs[i].antialiasing = 1;
                if (!shared) cfgs[i].extra_outputs = 1u << HRTS_RESOURCE_RT_VISIBILITY;
            }
            HrtsTargets t = targets();
            HrtsResult r = hrts_configure_lights(ctx, N, cfgs);
            if (r == HRTS_RESULT_OK) r = hrts_set_geometry_cpu(ctx, g);
            if (r == HRTS_RESULT_OK) r = hrts_set_targets(ctx, &t);
            /* Pass by pass after a frame in one call: the switch to an image of the light's own retires the
             * shared one's views while that frame may still use them. */
            if (r == HRTS_RESULT_OK && own_after) r = run_frame(ctx, vis[shared]);
            if (r == HRTS_RESULT_OK) r = split ? run_frame_in_parts(ctx, vis[shared], own_after) : run_frame(ctx, vis[shared]);
            CHECK(r == HRTS_RESULT_OK, "FXAA %s: %s", shared ? "shared" : "own", hrts_last_error(ctx));
            for (uint32_t l = 0; l < N && r == HRTS_RESULT_OK; l++) {
                HrtsFrameReport rep;
                CHECK(report(ctx, next_frame - 1, l, &rep) == HRTS_RESULT_OK, "report: %s", hrts_last_error(ctx));
                rt_bytes[shared] += rep.resource_bytes[HRTS_RESOURCE_RT_VISIBILITY];
                if (rep.map_scratch_bytes > scratch[shared]) scratch[shared] = rep.map_scratch_bytes;
                for (uint32_t p = 0; p < rep.pass_count; p++) traces[shared] += strcmp(rep.passes[p].name, "ray trace") == 0;
            }
            if (shared && !own_after && r == HRTS_RESULT_OK) {
                static float one[PX];
                CHECK(read_resource(ctx, 1, HRTS_RESOURCE_RT_VISIBILITY, one, sizeof one) == HRTS_RESULT_ERROR_INVALID_STATE &&
                          strstr(hrts_last_error(ctx), "share"),
                      "the shared RT visibility is not read back: %s", hrts_last_error(ctx));
            }
            CHECK(hrts_context_destroy(ctx) == HRTS_RESULT_OK, "destroy");
        }
        int differ = 0, soft = 0;
        for (int i = 0; i < N * PX; i++) {
            differ += memcmp(&vis[0][i], &vis[1][i], sizeof(float)) != 0;
            soft += vis[1][i] > 0.0f && vis[1][i] < 1.0f;
        }
        printf("FXAA sharing the RT visibility (%s): %d px differ from lights keeping their own, %d antialiased px; "
               "own RT visibility %llu and %llu bytes, shared scratch %llu and %llu bytes; %u and %u ray traces\n",
               modes[split], differ, soft, (unsigned long long)rt_bytes[0],
               (unsigned long long)rt_bytes[1], (unsigned long long)scratch[0], (unsigned long long)scratch[1],
               traces[0], traces[1]);
        uint64_t own = (uint64_t)N * PX * 4;
        CHECK(differ == 0 && soft > 0 && rt_bytes[0] == own && rt_bytes[1] == (own_after ? own : 0) &&
                  scratch[1] == scratch[0] + (own_after ? 0 : (uint64_t)PX * 4) && traces[0] == N && traces[1] == N,
              "FXAA sharing the RT visibility (%s): %d px differ, %d soft, %u/%u traces",
              modes[split], differ, soft, traces[0], traces[1]);
    }
}

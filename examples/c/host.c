/* umbrage-c-host: umbrage's shadow pass embedded in a plain-C99 Vulkan renderer through the C ABI
 * (umbrage.h). Headless: its own instance, device, depth-stencil image, pre-pass and read-back;
 * every shadow call goes through the header. It writes the frame dump `umbrage check DIR`
 * holds against the exact CPU reference, like `umbrage render --dump` and examples/embed.
 *
 *   umbrage-c-host [--scene FILE|NAME] [--size WxH] [--out PNG] [--dump DIR] [--msaa N]
 *                  [--reverse-z] [--render-pass] [--frames N]
 *
 * --scene: a file written by `umbrage export-scene`, or NAME for $UMBRAGE_SCENE_DIR/NAME.scene
 * (default directory: ../share/umbrage/scenes beside the executable; default NAME: default).
 * With --msaa N > 1 each sample's dump goes to DIR/sample_K. UMBRAGE_VALIDATION=1 turns on the
 * validation layer with synchronisation validation; any validation error fails the run.
 * The last shadow-casting mesh slides 0.25 along +x a frame (frame 0 is the scene as loaded);
 * the dump is of the last frame. Exit 0 on success, 1 on any error.
 *
 * The integration itself (what an engine writes around its own renderer) is marked
 * "UMBRAGE:" below; the rest is this host's Vulkan set-up. */
#include <umbrage/umbrage.h>
#include <vulkan/vulkan.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dump.h"
#include "scene.h"
#include "shaders/spirv.h"

#define CHECK_VK(call)                                                                  \
    do {                                                                                \
        VkResult r_ = (call);                                                           \
        if (r_ != VK_SUCCESS) {                                                         \
            fprintf(stderr, "umbrage-c-host: %s failed: VkResult %d\n", #call, (int)r_); \
            exit(1);                                                                    \
        }                                                                               \
    } while (0)

/* UMBRAGE: every call returns a code; the message names the field or the VkResult. */
#define CHECK_U(call)                                                                                                     \
    do {                                                                                                                  \
        UmbrageResult u_ = (call);                                                                                        \
        if (u_ != UMBRAGE_SUCCESS) {                                                                                      \
            fprintf(stderr, "umbrage-c-host: %s failed: code %d: %s\n", #call, (int)u_, umbrage_last_error());            \
            exit(1);                                                                                                      \
        }                                                                                                                 \
    } while (0)

typedef struct Args {
    const char *scene, *out, *dump;
    uint32_t width, height, samples, frames;
    int reverse_z, render_pass;
    UmbrageTechnique technique;
} Args;

/* --technique NAME: the shadow pass's techniques this host can feed (ray query needs a
 * world-position G-buffer, planar shadows planar receivers: neither is this host's). */
static const struct {
    const char *name;
    UmbrageTechnique technique;
} techniques[] = {
    {"volumes", UMBRAGE_TECHNIQUE_VOLUMES},
    {"edge-quads", UMBRAGE_TECHNIQUE_EDGE_QUADS},
    {"compute", UMBRAGE_TECHNIQUE_COMPUTE},
    {"mesh", UMBRAGE_TECHNIQUE_MESH},
};

static const char *technique_name(UmbrageTechnique t) {
    size_t i;
    for (i = 0; i < sizeof techniques / sizeof techniques[0]; i++)
        if (techniques[i].technique == t) return techniques[i].name;
    return "?";
}

typedef struct Buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *mapped;
    VkDeviceSize size;
} Buffer;

typedef struct Image {
    VkImage image;
    VkDeviceMemory memory;
} Image;

/* Validation messages of ERROR or WARNING severity: any fails the run (umbrage's own runs
 * allow a few best-practices warnings by ID, src/gpu/validation.rs; this host enables the
 * synchronisation checks only, and none is expected). */
static uint32_t validation_errors;

static VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT type,
                                                     const VkDebugUtilsMessengerCallbackDataEXT *data, void *user) {
    (void)type;
    (void)user;
    validation_errors++;
    fprintf(stderr, "validation %s: %s\n", (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning", data->pMessage);
    return VK_FALSE;
}

/* UMBRAGE: warnings (e.g. a possible 8-bit stencil overflow) arrive here during prepare. */
static void on_warning(void *user, const char *message) {
    (void)user;
    printf("  warning: %s\n", message);
}

static void usage(void) {
    fprintf(stderr,
            "usage: umbrage-c-host [--scene FILE|NAME] [--size WxH] [--out PNG] [--dump DIR] [--msaa N] [--reverse-z] "
            "[--render-pass] [--frames N] [--technique volumes|edge-quads|compute|mesh]\n");
    exit(1);
}

static Args parse_args(int argc, char **argv) {
    Args a;
    int i;
    memset(&a, 0, sizeof a);
    a.width = 320;
    a.height = 200;
    a.samples = 1;
    a.frames = 2;
    for (i = 1; i < argc; i++) {
        const char *k = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(k, "--reverse-z") == 0) {
            a.reverse_z = 1;
        } else if (strcmp(k, "--render-pass") == 0) {
            a.render_pass = 1;
        } else if (!v) {
            usage();
        } else if (strcmp(k, "--scene") == 0) {
            a.scene = v, i++;
        } else if (strcmp(k, "--out") == 0) {
            a.out = v, i++;
        } else if (strcmp(k, "--dump") == 0) {
            a.dump = v, i++;
        } else if (strcmp(k, "--size") == 0) {
            if (sscanf(v, "%ux%u", &a.width, &a.height) != 2 || a.width == 0 || a.height == 0 || a.width > 8192 || a.height > 8192) {
                fprintf(stderr, "--size %s: expected WxH, each 1..=8192\n", v);
                exit(1);
            }
            i++;
        } else if (strcmp(k, "--msaa") == 0) {
            a.samples = (uint32_t)atoi(v), i++;
            if (a.samples != 1 && a.samples != 2 && a.samples != 4 && a.samples != 8) {
                fprintf(stderr, "--msaa %s: the sample count is 1, 2, 4 or 8\n", v);
                exit(1);
            }
        } else if (strcmp(k, "--technique") == 0) {
            size_t t;
            for (t = 0; t < sizeof techniques / sizeof techniques[0] && strcmp(v, techniques[t].name) != 0; t++) {
            }
            if (t == sizeof techniques / sizeof techniques[0]) {
                fprintf(stderr, "--technique %s: volumes, edge-quads, compute or mesh\n", v);
                exit(1);
            }
            a.technique = techniques[t].technique, i++;
        } else if (strcmp(k, "--frames") == 0) {
            a.frames = (uint32_t)atoi(v), i++;
            if (a.frames < 1 || a.frames > 10000) {
                fprintf(stderr, "--frames %s: 1..=10000\n", v);
                exit(1);
            }
        } else {
            usage();
        }
    }
    return a;
}

/* --scene FILE, or NAME in the scene directory. */
static void scene_path(const char *spec, const char *argv0, char *out, size_t cap) {
    const char *dir = getenv("UMBRAGE_SCENE_DIR");
    char exe[1024];
    if (!spec) spec = "default";
    if (strchr(spec, '/') || access(spec, R_OK) == 0) {
        snprintf(out, cap, "%s", spec);
        return;
    }
    if (dir) {
        snprintf(out, cap, "%s/%s.scene", dir, spec);
        return;
    }
    {
        ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
        char *slash;
        if (n <= 0) snprintf(exe, sizeof exe, "%s", argv0);
        else exe[n] = 0;
        slash = strrchr(exe, '/');
        if (slash) *slash = 0;
        else snprintf(exe, sizeof exe, ".");
    }
    snprintf(out, cap, "%s/../share/umbrage/scenes/%s.scene", exe, spec);
}

/* ---- matrices, as glam computes them (column-major, m[4*col + row]) ---- */

static void mat4_mul_f(const float *a, const float *b, float *out) {
    float r[16];
    int c, k;
    for (c = 0; c < 4; c++) {
        for (k = 0; k < 4; k++) r[4 * c + k] = a[k] * b[4 * c];
        for (k = 0; k < 4; k++) r[4 * c + k] = r[4 * c + k] + a[4 + k] * b[4 * c + 1];
        for (k = 0; k < 4; k++) r[4 * c + k] = r[4 * c + k] + a[8 + k] * b[4 * c + 2];
        for (k = 0; k < 4; k++) r[4 * c + k] = r[4 * c + k] + a[12 + k] * b[4 * c + 3];
    }
    memcpy(out, r, sizeof r);
}

static void mat4_mul_d(const double *a, const double *b, double *out) {
    double r[16];
    int c, k;
    for (c = 0; c < 4; c++) {
        for (k = 0; k < 4; k++) r[4 * c + k] = a[k] * b[4 * c];
        for (k = 0; k < 4; k++) r[4 * c + k] = r[4 * c + k] + a[4 + k] * b[4 * c + 1];
        for (k = 0; k < 4; k++) r[4 * c + k] = r[4 * c + k] + a[8 + k] * b[4 * c + 2];
        for (k = 0; k < 4; k++) r[4 * c + k] = r[4 * c + k] + a[12 + k] * b[4 * c + 3];
    }
    memcpy(out, r, sizeof r);
}

static void normalize3f(float *v) {
    float len = sqrtf((v[0] * v[0] + v[1] * v[1]) + v[2] * v[2]);
    float recip = 1.0f / len;
    v[0] *= recip, v[1] *= recip, v[2] *= recip;
}

static void cross3f(const float *a, const float *b, float *o) {
    o[0] = a[1] * b[2] - b[1] * a[2];
    o[1] = a[2] * b[0] - b[2] * a[0];
    o[2] = a[0] * b[1] - b[0] * a[1];
}

static float dot3f(const float *a, const float *b) { return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]; }

/* The camera's world -> view matrix (glam's look_at_rh) with its translation. */
static void look_at(const float *eye, const float *target, const float *up_in, float *m) {
    float f[3], s[3], u[3], up[3];
    int i;
    for (i = 0; i < 3; i++) f[i] = target[i] - eye[i], up[i] = up_in[i];
    normalize3f(up);
    normalize3f(f);
    cross3f(f, up, s);
    normalize3f(s);
    cross3f(s, f, u);
    m[0] = s[0], m[1] = u[0], m[2] = -f[0], m[3] = 0;
    m[4] = s[1], m[5] = u[1], m[6] = -f[1], m[7] = 0;
    m[8] = s[2], m[9] = u[2], m[10] = -f[2], m[11] = 0;
    m[12] = -dot3f(eye, s), m[13] = -dot3f(eye, u), m[14] = dot3f(eye, f), m[15] = 1;
}

/* Vulkan clip (y down, depth 0..1), infinite far plane; reverse-Z maps z to w - z. */
static void projection(float fov_y_deg, float near_plane, float aspect, int reverse, float *m) {
    float f = 1.0f / tanf(fov_y_deg * (3.14159265358979323846f / 180.0f) * 0.5f);
    memset(m, 0, 16 * sizeof(float));
    m[0] = f / aspect;
    m[5] = -f;
    m[10] = -1.0f, m[11] = -1.0f;
    m[14] = -near_plane;
    if (reverse) {
        static const float flip[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 1, 1};
        mat4_mul_f(flip, m, m);
    }
}

/* ---- Vulkan set-up ---- */

static VkInstance instance;
static VkPhysicalDevice physical;
static VkDevice device;
static VkQueue queue;
static uint32_t queue_family;
static VkPhysicalDeviceMemoryProperties memory_props;

static uint32_t memory_type(uint32_t bits, VkMemoryPropertyFlags want) {
    uint32_t i;
    for (i = 0; i < memory_props.memoryTypeCount; i++)
        if ((bits & (1u << i)) && (memory_props.memoryTypes[i].propertyFlags & want) == want) return i;
    fprintf(stderr, "umbrage-c-host: no memory type with flags %#x\n", (unsigned)want);
    exit(1);
}

static Buffer buffer_create(VkDeviceSize size, VkBufferUsageFlags usage) {
    Buffer b;
    VkBufferCreateInfo info = {VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    VkMemoryRequirements req;
    VkMemoryAllocateInfo alloc = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    memset(&b, 0, sizeof b);
    info.size = size;
    info.usage = usage;
    CHECK_VK(vkCreateBuffer(device, &info, NULL, &b.buffer));
    vkGetBufferMemoryRequirements(device, b.buffer, &req);
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    CHECK_VK(vkAllocateMemory(device, &alloc, NULL, &b.memory));
    CHECK_VK(vkBindBufferMemory(device, b.buffer, b.memory, 0));
    CHECK_VK(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    b.size = size;
    return b;
}

static void buffer_destroy(Buffer *b) {
    if (b->buffer) vkDestroyBuffer(device, b->buffer, NULL);
    if (b->memory) vkFreeMemory(device, b->memory, NULL);
    memset(b, 0, sizeof *b);
}

static Image image_create(VkFormat format, uint32_t w, uint32_t h, uint32_t samples, VkImageUsageFlags usage) {
    Image img;
    VkImageCreateInfo info = {VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    VkMemoryRequirements req;
    VkMemoryAllocateInfo alloc = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent.width = w;
    info.extent.height = h;
    info.extent.depth = 1;
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = (VkSampleCountFlagBits)samples;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    CHECK_VK(vkCreateImage(device, &info, NULL, &img.image));
    vkGetImageMemoryRequirements(device, img.image, &req);
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    CHECK_VK(vkAllocateMemory(device, &alloc, NULL, &img.memory));
    CHECK_VK(vkBindImageMemory(device, img.image, img.memory, 0));
    return img;
}

static VkImageView view_create(VkImage image, VkFormat format, VkImageAspectFlags aspect) {
    VkImageView v;
    VkImageViewCreateInfo info = {VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    info.image = image;
    info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    info.format = format;
    info.subresourceRange.aspectMask = aspect;
    info.subresourceRange.levelCount = 1;
    info.subresourceRange.layerCount = 1;
    CHECK_VK(vkCreateImageView(device, &info, NULL, &v));
    return v;
}

static VkShaderModule shader(const uint32_t *code, size_t bytes) {
    VkShaderModule m;
    VkShaderModuleCreateInfo info = {VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = bytes;
    info.pCode = code;
    CHECK_VK(vkCreateShaderModule(device, &info, NULL, &m));
    return m;
}

static void image_barrier(VkCommandBuffer cb, VkImage image, VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to,
                          VkPipelineStageFlags src_stage, VkAccessFlags src, VkPipelineStageFlags dst_stage, VkAccessFlags dst) {
    VkImageMemoryBarrier b = {VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange.aspectMask = aspect;
    b.subresourceRange.levelCount = 1;
    b.subresourceRange.layerCount = 1;
    vkCmdPipelineBarrier(cb, src_stage, dst_stage, 0, 0, NULL, 0, NULL, 1, &b);
}

/* The host's pre-pass targets: the G-buffer position plane and the depth-stencil image, with
   the render pass, framebuffer and pipeline the render-pass model draws them with. */
typedef struct Prepass {
    VkImage plane;
    VkImageView plane_view;
    VkImage ds;
    VkImageView ds_view;
    VkRenderPass render_pass;
    VkFramebuffer framebuffer;
    VkPipeline pipeline;
} Prepass;

/* Begins the host's pre-pass into cb (dynamic rendering, or the pre-pass render pass), both
   targets cleared (depth to clear_depth), with its pipeline, viewport and scissor bound. */
static void begin_prepass(VkCommandBuffer cb, int dynamic, const Prepass *p, VkRect2D full, VkViewport viewport, float clear_depth) {
    if (dynamic) {
        VkRenderingAttachmentInfo color = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        VkRenderingAttachmentInfo depth = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        VkRenderingInfo ri = {VK_STRUCTURE_TYPE_RENDERING_INFO};
        image_barrier(cb, p->plane, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                      VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
        image_barrier(cb, p->ds, VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                      VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                      VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
        color.imageView = p->plane_view;
        color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        depth.imageView = p->ds_view;
        depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        depth.clearValue.depthStencil.depth = clear_depth;
        ri.renderArea = full;
        ri.layerCount = 1;
        ri.colorAttachmentCount = 1;
        ri.pColorAttachments = &color;
        ri.pDepthAttachment = &depth;
        ri.pStencilAttachment = &depth;
        vkCmdBeginRendering(cb, &ri);
    } else {
        VkClearValue clears[2];
        VkRenderPassBeginInfo rb = {VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
        memset(clears, 0, sizeof clears);
        clears[1].depthStencil.depth = clear_depth;
        rb.renderPass = p->render_pass;
        rb.framebuffer = p->framebuffer;
        rb.renderArea = full;
        rb.clearValueCount = 2;
        rb.pClearValues = clears;
        vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    }
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p->pipeline);
    vkCmdSetViewport(cb, 0, 1, &viewport);
    vkCmdSetScissor(cb, 0, 1, &full);
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static const float standard_1[2] = {0.5f, 0.5f};
static const float standard_2[4] = {0.75f, 0.75f, 0.25f, 0.25f};
static const float standard_4[8] = {0.375f, 0.125f, 0.875f, 0.375f, 0.125f, 0.625f, 0.625f, 0.875f};
static const float standard_8[16] = {0.5625f, 0.3125f, 0.4375f, 0.6875f, 0.8125f, 0.5625f, 0.3125f, 0.1875f,
                                     0.1875f, 0.8125f, 0.0625f, 0.4375f, 0.6875f, 0.9375f, 0.9375f, 0.0625f};

/* A point p is lit by light l when its stencil is 0, it faces the light and the light reaches it
 * (range, cone): as umbrage's Light::reaches. */
static int reaches(const HostLight *l, const float *p, const float *n) {
    float to[3];
    int i;
    if (l->kind == 2) {
        for (i = 0; i < 3; i++) to[i] = -l->direction[i];
    } else {
        for (i = 0; i < 3; i++) to[i] = l->position[i] - p[i];
    }
    if (dot3f(n, to) <= 0.0f) return 0;
    if (l->kind != 2 && l->radius != 0.0f && sqrtf(dot3f(to, to)) >= l->radius) return 0;
    if (l->kind == 1) {
        float a[3] = {-to[0], -to[1], -to[2]}, d[3] = {l->direction[0], l->direction[1], l->direction[2]};
        normalize3f(a);
        normalize3f(d);
        if (!(dot3f(a, d) > cosf(l->cone_deg * (3.14159265358979323846f / 180.0f) * 0.5f))) return 0;
    }
    return 1;
}

int main(int argc, char **argv) {
    Args args = parse_args(argc, argv);
    HostScene scene;
    char path[1200];
    int dynamic, api13;
    /* optional features found and enabled on the device, told to the pass (UmbrageFeatureFlags) */
    uint32_t enabled_bits = 0;
    VkFormat ds_format = VK_FORMAT_UNDEFINED;
    const VkFormat plane_format = VK_FORMAT_R32G32B32A32_SFLOAT;
    VkPhysicalDeviceFeatures supported;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = NULL;
    int validation = getenv("UMBRAGE_VALIDATION") && strcmp(getenv("UMBRAGE_VALIDATION"), "0") != 0;
    uint32_t i, f, mi, li, si;
    uint32_t w = args.width, h = args.height, n = args.width * args.height;
    const float *standard = args.samples == 8 ? standard_8 : args.samples == 4 ? standard_4 : args.samples == 2 ? standard_2 : standard_1;
    float locations[16];
    int moving = -1;
    float (*transforms)[16];
    UmbrageCasterId *casters;

    scene_path(args.scene, argv[0], path, sizeof path);
    if (scene_load(path, &scene) != 0) return 1;
    if (scene.sphere_count > 0) {
        fprintf(stderr, "umbrage-c-host: scene %s: this host draws triangle meshes only (no analytic spheres)\n", path);
        return 1;
    }
    for (mi = 0; mi < scene.mesh_count; mi++) {
        if (scene.meshes[mi].casts_shadow && scene.meshes[mi].opacity < 1.0f) {
            fprintf(stderr, "umbrage-c-host: scene %s: this host draws opaque casters only\n", path);
            return 1;
        }
        if (scene.meshes[mi].casts_shadow) moving = (int)mi;
    }
    dynamic = !args.render_pass;
    api13 = dynamic || args.technique == UMBRAGE_TECHNIQUE_MESH;

    /* Instance: Vulkan 1.3 (dynamic rendering) or 1.1 (render passes). */
    {
        VkApplicationInfo app = {VK_STRUCTURE_TYPE_APPLICATION_INFO};
        VkInstanceCreateInfo info = {VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        const char *layer = "VK_LAYER_KHRONOS_validation";
        const char *ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
        VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
        VkValidationFeaturesEXT features = {VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
        /* the messenger also sees vkCreateInstance and vkDestroyInstance (leaks reported there) */
        VkDebugUtilsMessengerCreateInfoEXT m = {VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        m.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
        m.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
        m.pfnUserCallback = debug_callback;
        app.pApplicationName = "umbrage-c-host";
        app.apiVersion = api13 ? VK_API_VERSION_1_3 : VK_API_VERSION_1_1;
        info.pApplicationInfo = &app;
        if (validation) {
            features.enabledValidationFeatureCount = 1;
            features.pEnabledValidationFeatures = &sync;
            features.pNext = &m;
            info.pNext = &features;
            info.enabledLayerCount = 1;
            info.ppEnabledLayerNames = &layer;
            info.enabledExtensionCount = 1;
            info.ppEnabledExtensionNames = &ext;
        }
        CHECK_VK(vkCreateInstance(&info, NULL, &instance));
        if (validation) {
            PFN_vkCreateDebugUtilsMessengerEXT create =
                (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT");
            destroy_messenger = (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT");
            CHECK_VK(create(instance, &m, NULL, &messenger));
        }
    }
    /* Physical device: the first with a graphics queue and the API version asked for. */
    {
        VkPhysicalDevice devices[16];
        uint32_t count = 16, q;
        VkPhysicalDeviceProperties props;
        CHECK_VK(vkEnumeratePhysicalDevices(instance, &count, devices));
        physical = VK_NULL_HANDLE;
        for (i = 0; i < count && !physical; i++) {
            VkQueueFamilyProperties families[16];
            uint32_t fc = 16;
            vkGetPhysicalDeviceProperties(devices[i], &props);
            if (props.apiVersion < (api13 ? VK_API_VERSION_1_3 : VK_API_VERSION_1_1)) continue;
            vkGetPhysicalDeviceQueueFamilyProperties(devices[i], &fc, families);
            for (q = 0; q < fc; q++)
                if (families[q].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
                    physical = devices[i];
                    queue_family = q;
                    break;
                }
        }
        if (!physical) {
            fprintf(stderr, "umbrage-c-host: no Vulkan %s device with a graphics queue\n", api13 ? "1.3" : "1.1");
            return 1;
        }
        vkGetPhysicalDeviceProperties(physical, &props);
        if (args.samples > 1 && !props.limits.standardSampleLocations) {
            fprintf(stderr, "umbrage-c-host: %s has no standard sample locations, so the samples cannot be placed\n", props.deviceName);
            return 1;
        }
        printf("umbrage-c-host: %s, %ux%u, %ux %s %s, technique %s\n", props.deviceName, w, h, args.samples,
               args.reverse_z ? "reverse-Z" : "forward", dynamic ? "dynamic-rendering" : "render-pass", technique_name(args.technique));
        vkGetPhysicalDeviceMemoryProperties(physical, &memory_props);
        vkGetPhysicalDeviceFeatures(physical, &supported);
        {
            const VkFormat candidates[2] = {VK_FORMAT_D32_SFLOAT_S8_UINT, VK_FORMAT_D24_UNORM_S8_UINT};
            const VkFormatFeatureFlags need = VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
            for (i = 0; i < 2 && ds_format == VK_FORMAT_UNDEFINED; i++) {
                VkFormatProperties fp;
                vkGetPhysicalDeviceFormatProperties(physical, candidates[i], &fp);
                if ((fp.optimalTilingFeatures & need) == need) ds_format = candidates[i];
            }
            if (ds_format == VK_FORMAT_UNDEFINED) {
                fprintf(stderr, "umbrage-c-host: no sampled depth-stencil format with 8 stencil bits\n");
                return 1;
            }
        }
    }
    /* Device: depthBounds and depthClamp where present, the indirect draws the compute technique
     * records where present, mesh shaders when asked (all told to the pass), dynamic rendering. */
    {
        float priority = 1.0f;
        VkDeviceQueueCreateInfo q = {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        VkDeviceCreateInfo info = {VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        VkPhysicalDeviceFeatures enabled;
        VkPhysicalDeviceVulkan12Features v12 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
        VkPhysicalDeviceVulkan13Features v13 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
        VkPhysicalDeviceMeshShaderFeaturesEXT mesh = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
        const char *mesh_ext = VK_EXT_MESH_SHADER_EXTENSION_NAME;
        void *chain = NULL;
        int want_mesh = args.technique == UMBRAGE_TECHNIQUE_MESH;
        if (api13) {
            /* what the device has: Vulkan 1.2's drawIndirectCount, the mesh shader's features */
            VkPhysicalDeviceVulkan12Features has12 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
            VkPhysicalDeviceMeshShaderFeaturesEXT has_mesh = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
            VkPhysicalDeviceFeatures2 f2 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
            VkExtensionProperties exts[512];
            uint32_t ext_count = 512, e;
            int mesh_ext_present = 0;
            {
                VkResult r = vkEnumerateDeviceExtensionProperties(physical, NULL, &ext_count, exts);
                if (r != VK_SUCCESS && r != VK_INCOMPLETE) {
                    fprintf(stderr, "umbrage-c-host: vkEnumerateDeviceExtensionProperties failed: VkResult %d\n", (int)r);
                    return 1;
                }
            }
            for (e = 0; e < ext_count; e++)
                if (strcmp(exts[e].extensionName, mesh_ext) == 0) mesh_ext_present = 1;
            f2.pNext = &has12;
            if (mesh_ext_present) has12.pNext = &has_mesh;
            vkGetPhysicalDeviceFeatures2(physical, &f2);
            if (has12.drawIndirectCount) {
                v12.drawIndirectCount = VK_TRUE;
                enabled_bits |= UMBRAGE_FEATURE_DRAW_INDIRECT_COUNT_BIT;
            }
            v12.pNext = chain, chain = &v12;
            if (want_mesh) {
                if (!mesh_ext_present || !has_mesh.meshShader) {
                    fprintf(stderr, "umbrage-c-host: --technique mesh: this device has no VK_EXT_mesh_shader with meshShader\n");
                    return 1;
                }
                mesh.meshShader = VK_TRUE;
                mesh.taskShader = has_mesh.taskShader;
                enabled_bits |= UMBRAGE_FEATURE_MESH_SHADER_BIT | (has_mesh.taskShader ? UMBRAGE_FEATURE_TASK_SHADER_BIT : 0u);
                mesh.pNext = chain, chain = &mesh;
                info.enabledExtensionCount = 1;
                info.ppEnabledExtensionNames = &mesh_ext;
            }
        }
        memset(&enabled, 0, sizeof enabled);
        enabled.depthBounds = supported.depthBounds;
        enabled.depthClamp = supported.depthClamp;
        enabled.drawIndirectFirstInstance = supported.drawIndirectFirstInstance;
        enabled.multiDrawIndirect = supported.multiDrawIndirect;
        enabled_bits |= (supported.depthBounds ? UMBRAGE_FEATURE_DEPTH_BOUNDS_BIT : 0u) |
                        (supported.depthClamp ? UMBRAGE_FEATURE_DEPTH_CLAMP_BIT : 0u) |
                        (supported.drawIndirectFirstInstance ? UMBRAGE_FEATURE_DRAW_INDIRECT_FIRST_INSTANCE_BIT : 0u) |
                        (supported.multiDrawIndirect ? UMBRAGE_FEATURE_MULTI_DRAW_INDIRECT_BIT : 0u);
        q.queueFamilyIndex = queue_family;
        q.queueCount = 1;
        q.pQueuePriorities = &priority;
        info.queueCreateInfoCount = 1;
        info.pQueueCreateInfos = &q;
        info.pEnabledFeatures = &enabled;
        if (dynamic) {
            v13.dynamicRendering = VK_TRUE;
            v13.pNext = chain, chain = &v13;
        }
        info.pNext = chain;
        CHECK_VK(vkCreateDevice(physical, &info, NULL, &device));
        vkGetDeviceQueue(device, queue_family, 0, &queue);
    }

    {
        /* ---- the host's objects ---- */
        const VkSampleCountFlagBits samples = (VkSampleCountFlagBits)args.samples;
        Image ds = image_create(ds_format, w, h, args.samples, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
        Image plane = image_create(plane_format, w, h, args.samples, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
        VkImageView ds_view = view_create(ds.image, ds_format, VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT);
        VkImageView depth_view = view_create(ds.image, ds_format, VK_IMAGE_ASPECT_DEPTH_BIT);
        VkImageView stencil_view = view_create(ds.image, ds_format, VK_IMAGE_ASPECT_STENCIL_BIT);
        VkImageView plane_view = view_create(plane.image, plane_format, VK_IMAGE_ASPECT_COLOR_BIT);
        VkRenderPass prepass_rp = VK_NULL_HANDLE, lighting_rp = VK_NULL_HANDLE;
        VkFramebuffer prepass_fb = VK_NULL_HANDLE, lighting_fb = VK_NULL_HANDLE;
        VkPipelineLayout prepass_layout, extract_layout;
        VkPipeline prepass_pipe, extract_pipe;
        VkDescriptorSetLayout set_layout;
        VkDescriptorPool pool;
        VkDescriptorSet set;
        VkSampler sampler;
        VkCommandPool cmd_pool;
        VkCommandBuffer cb;
        VkFence fence;
        uint32_t total_tris = 0, geometry_words = 5 * n * args.samples;
        Buffer vertices, readback;
        UmbragePass pass = NULL;
        UmbrageFrame frame;
        double eye_d[3], vp[16];
        float view[16], proj[16];

        for (mi = 0; mi < scene.mesh_count; mi++) total_tris += scene.meshes[mi].triangle_count;
        vertices = buffer_create((VkDeviceSize)total_tris * 3 * 7 * sizeof(float) + 16, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
        readback = buffer_create((VkDeviceSize)(geometry_words + n * args.samples * scene.light_count) * 4 + 16,
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

        if (!dynamic) {
            /* The pre-pass render pass (plane + depth-stencil, cleared) and the lighting one the
             * determination records in (depth-stencil loaded and stored), both leaving the image
             * read-only for the read-back. */
            VkAttachmentDescription att[2];
            VkAttachmentReference color_ref = {0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
            VkAttachmentReference ds_ref = {1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
            VkAttachmentReference ds_only = {0, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
            VkSubpassDescription sub;
            VkSubpassDependency deps[2];
            VkRenderPassCreateInfo info = {VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
            VkFramebufferCreateInfo fb = {VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
            VkImageView views[2];
            memset(att, 0, sizeof att);
            memset(&sub, 0, sizeof sub);
            memset(deps, 0, sizeof deps);
            att[0].format = plane_format;
            att[0].samples = samples;
            att[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
            att[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
            att[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
            att[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
            att[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
            att[0].finalLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            att[1] = att[0];
            att[1].format = ds_format;
            att[1].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
            att[1].stencilStoreOp = VK_ATTACHMENT_STORE_OP_STORE;
            att[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
            sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
            sub.colorAttachmentCount = 1;
            sub.pColorAttachments = &color_ref;
            sub.pDepthStencilAttachment = &ds_ref;
            deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
            deps[0].dstSubpass = 0;
            deps[0].srcStageMask = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
            deps[0].dstStageMask = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
                                   VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
            deps[0].dstAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                                    VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
            deps[1].srcSubpass = 0;
            deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
            deps[1].srcStageMask = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
                                   VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
            deps[1].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
            deps[1].dstStageMask = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
            deps[1].dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
            info.attachmentCount = 2;
            info.pAttachments = att;
            info.subpassCount = 1;
            info.pSubpasses = &sub;
            info.dependencyCount = 2;
            info.pDependencies = deps;
            CHECK_VK(vkCreateRenderPass(device, &info, NULL, &prepass_rp));
            att[1].loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
            att[1].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
            att[1].initialLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
            sub.colorAttachmentCount = 0;
            sub.pColorAttachments = NULL;
            sub.pDepthStencilAttachment = &ds_only;
            deps[0].dstAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
            deps[1].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
            info.attachmentCount = 1;
            info.pAttachments = &att[1];
            CHECK_VK(vkCreateRenderPass(device, &info, NULL, &lighting_rp));
            views[0] = plane_view;
            views[1] = ds_view;
            fb.renderPass = prepass_rp;
            fb.attachmentCount = 2;
            fb.pAttachments = views;
            fb.width = w;
            fb.height = h;
            fb.layers = 1;
            CHECK_VK(vkCreateFramebuffer(device, &fb, NULL, &prepass_fb));
            fb.renderPass = lighting_rp;
            fb.attachmentCount = 1;
            fb.pAttachments = &ds_view;
            CHECK_VK(vkCreateFramebuffer(device, &fb, NULL, &lighting_fb));
        }

        /* ---- UMBRAGE: create the pass for this device, format, sample count, depth direction and
         * target model; tell it the features this device was created with. ---- */
        {
            UmbrageVulkanDevice vk;
            UmbragePassCreateInfo info;
            UmbrageRenderPassTarget rp;
            UmbrageCapabilities caps;
            memset(&vk, 0, sizeof vk);
            memset(&info, 0, sizeof info);
            memset(&rp, 0, sizeof rp);
            vk.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
            vk.pfnGetDeviceProcAddr = vkGetDeviceProcAddr;
            vk.instance = instance;
            vk.physicalDevice = physical;
            vk.device = device;
            info.sType = UMBRAGE_STRUCTURE_TYPE_PASS_CREATE_INFO;
            info.abiVersion = UMBRAGE_ABI_VERSION;
            info.depthStencilFormat = ds_format;
            info.samples = args.samples;
            info.framesInFlight = 2;
            info.depthDirection = args.reverse_z ? UMBRAGE_DEPTH_DIRECTION_REVERSE : UMBRAGE_DEPTH_DIRECTION_FORWARD;
            info.enabledFeatures = enabled_bits;
            info.settings.technique = args.technique;
            info.pfnWarning = on_warning;
            if (!dynamic) {
                rp.sType = UMBRAGE_STRUCTURE_TYPE_RENDER_PASS_TARGET;
                rp.renderPass = lighting_rp;
                rp.subpass = 0;
                info.pNext = &rp;
            }
            CHECK_U(umbrage_pass_create(&vk, &info, &pass));
            CHECK_U(umbrage_pass_get_capabilities(pass, &caps));
            printf("umbrage-c-host: depth bounds %s\n", caps.depthBounds ? "used" : "not used");
        }
        /* UMBRAGE: the casters, once (16- or 32-bit indices; double transforms). */
        casters = calloc(scene.mesh_count + 1, sizeof *casters);
        transforms = calloc(scene.mesh_count + 1, sizeof *transforms);
        for (mi = 0; mi < scene.mesh_count; mi++) {
            HostMesh *m = &scene.meshes[mi];
            UmbrageCasterInfo c;
            memcpy(transforms[mi], m->transform, sizeof m->transform);
            if (!m->casts_shadow) continue;
            memset(&c, 0, sizeof c);
            c.sType = UMBRAGE_STRUCTURE_TYPE_CASTER_INFO;
            c.pName = m->name;
            c.pPositions = m->positions;
            c.vertexCount = m->vertex_count;
            c.pIndices = m->triangles;
            c.indexCount = 3 * m->triangle_count;
            c.indexType = UMBRAGE_INDEX_TYPE_UINT32;
            for (i = 0; i < 16; i++) c.transform[i] = m->transform[i];
            CHECK_U(umbrage_pass_add_caster(pass, &c, &casters[mi]));
        }

        /* ---- pipelines: the pre-pass (depth and the triangle's plane) and the read-back ---- */
        {
            VkPushConstantRange range = {VK_SHADER_STAGE_VERTEX_BIT, 0, 64};
            VkPipelineLayoutCreateInfo li_ = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
            VkShaderModule vs = shader(spv_prepass_vert, sizeof spv_prepass_vert);
            VkShaderModule fs = shader(spv_prepass_frag, sizeof spv_prepass_frag);
            VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                                         {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
            VkVertexInputBindingDescription binding = {0, 7 * sizeof(float), VK_VERTEX_INPUT_RATE_VERTEX};
            VkVertexInputAttributeDescription attrs[2] = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                                                          {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 3 * sizeof(float)}};
            VkPipelineVertexInputStateCreateInfo vi = {VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
            VkPipelineInputAssemblyStateCreateInfo ia = {VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
            VkPipelineViewportStateCreateInfo vp = {VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
            VkPipelineRasterizationStateCreateInfo rs = {VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
            VkPipelineMultisampleStateCreateInfo ms = {VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
            VkPipelineDepthStencilStateCreateInfo dss = {VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
            VkPipelineColorBlendAttachmentState blend_att;
            VkPipelineColorBlendStateCreateInfo cbs = {VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
            VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
            VkPipelineDynamicStateCreateInfo ds_ = {VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
            VkPipelineRenderingCreateInfo rendering = {VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
            VkGraphicsPipelineCreateInfo gp = {VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
            li_.pushConstantRangeCount = 1;
            li_.pPushConstantRanges = &range;
            CHECK_VK(vkCreatePipelineLayout(device, &li_, NULL, &prepass_layout));
            stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
            stages[0].module = vs;
            stages[0].pName = "main";
            stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
            stages[1].module = fs;
            stages[1].pName = "main";
            vi.vertexBindingDescriptionCount = 1;
            vi.pVertexBindingDescriptions = &binding;
            vi.vertexAttributeDescriptionCount = 2;
            vi.pVertexAttributeDescriptions = attrs;
            ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
            vp.viewportCount = 1;
            vp.scissorCount = 1;
            rs.polygonMode = VK_POLYGON_MODE_FILL;
            rs.cullMode = VK_CULL_MODE_NONE;
            rs.lineWidth = 1.0f;
            ms.rasterizationSamples = samples;
            dss.depthTestEnable = VK_TRUE;
            dss.depthWriteEnable = VK_TRUE;
            dss.depthCompareOp = args.reverse_z ? VK_COMPARE_OP_GREATER : VK_COMPARE_OP_LESS;
            memset(&blend_att, 0, sizeof blend_att);
            blend_att.colorWriteMask = 0xf;
            cbs.attachmentCount = 1;
            cbs.pAttachments = &blend_att;
            ds_.dynamicStateCount = 2;
            ds_.pDynamicStates = dyn;
            gp.stageCount = 2;
            gp.pStages = stages;
            gp.pVertexInputState = &vi;
            gp.pInputAssemblyState = &ia;
            gp.pViewportState = &vp;
            gp.pRasterizationState = &rs;
            gp.pMultisampleState = &ms;
            gp.pDepthStencilState = &dss;
            gp.pColorBlendState = &cbs;
            gp.pDynamicState = &ds_;
            gp.layout = prepass_layout;
            if (dynamic) {
                rendering.colorAttachmentCount = 1;
                rendering.pColorAttachmentFormats = &plane_format;
                rendering.depthAttachmentFormat = ds_format;
                rendering.stencilAttachmentFormat = ds_format;
                gp.pNext = &rendering;
            } else {
                gp.renderPass = prepass_rp;
            }
            CHECK_VK(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &gp, NULL, &prepass_pipe));
            vkDestroyShaderModule(device, vs, NULL);
            vkDestroyShaderModule(device, fs, NULL);
        }
        {
            VkDescriptorSetLayoutBinding b[4];
            VkDescriptorSetLayoutCreateInfo sl = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
            VkPushConstantRange range = {VK_SHADER_STAGE_COMPUTE_BIT, 0, 20};
            VkPipelineLayoutCreateInfo pl = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
            VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 3}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}};
            VkDescriptorPoolCreateInfo dp = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
            VkDescriptorSetAllocateInfo da = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
            VkSamplerCreateInfo si_ = {VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
            VkDescriptorImageInfo images[3];
            VkDescriptorBufferInfo buf = {0, 0, VK_WHOLE_SIZE};
            VkWriteDescriptorSet writes[4];
            VkComputePipelineCreateInfo cp = {VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
            VkShaderModule cs = args.samples > 1 ? shader(spv_extract_ms_comp, sizeof spv_extract_ms_comp)
                                                 : shader(spv_extract_comp, sizeof spv_extract_comp);
            memset(b, 0, sizeof b);
            for (i = 0; i < 4; i++) {
                b[i].binding = i;
                b[i].descriptorType = i < 3 ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
                b[i].descriptorCount = 1;
                b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
            }
            sl.bindingCount = 4;
            sl.pBindings = b;
            CHECK_VK(vkCreateDescriptorSetLayout(device, &sl, NULL, &set_layout));
            pl.setLayoutCount = 1;
            pl.pSetLayouts = &set_layout;
            pl.pushConstantRangeCount = 1;
            pl.pPushConstantRanges = &range;
            CHECK_VK(vkCreatePipelineLayout(device, &pl, NULL, &extract_layout));
            dp.maxSets = 1;
            dp.poolSizeCount = 2;
            dp.pPoolSizes = sizes;
            CHECK_VK(vkCreateDescriptorPool(device, &dp, NULL, &pool));
            da.descriptorPool = pool;
            da.descriptorSetCount = 1;
            da.pSetLayouts = &set_layout;
            CHECK_VK(vkAllocateDescriptorSets(device, &da, &set));
            si_.magFilter = si_.minFilter = VK_FILTER_NEAREST;
            si_.addressModeU = si_.addressModeV = si_.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
            CHECK_VK(vkCreateSampler(device, &si_, NULL, &sampler));
            images[0].sampler = images[1].sampler = images[2].sampler = sampler;
            images[0].imageView = depth_view;
            images[1].imageView = stencil_view;
            images[2].imageView = plane_view;
            images[0].imageLayout = images[1].imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
            images[2].imageLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            buf.buffer = readback.buffer;
            memset(writes, 0, sizeof writes);
            for (i = 0; i < 4; i++) {
                writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
                writes[i].dstSet = set;
                writes[i].dstBinding = i;
                writes[i].descriptorCount = 1;
                writes[i].descriptorType = b[i].descriptorType;
                if (i < 3) writes[i].pImageInfo = &images[i];
                else writes[i].pBufferInfo = &buf;
            }
            vkUpdateDescriptorSets(device, 4, writes, 0, NULL);
            cp.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
            cp.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
            cp.stage.module = cs;
            cp.stage.pName = "main";
            cp.layout = extract_layout;
            CHECK_VK(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &cp, NULL, &extract_pipe));
            vkDestroyShaderModule(device, cs, NULL);
        }
        {
            VkCommandPoolCreateInfo pi = {VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
            VkCommandBufferAllocateInfo ai = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
            VkFenceCreateInfo fi = {VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
            pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
            pi.queueFamilyIndex = queue_family;
            CHECK_VK(vkCreateCommandPool(device, &pi, NULL, &cmd_pool));
            ai.commandPool = cmd_pool;
            ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
            ai.commandBufferCount = 1;
            CHECK_VK(vkAllocateCommandBuffers(device, &ai, &cb));
            CHECK_VK(vkCreateFence(device, &fi, NULL, &fence));
        }

        /* ---- where the device evaluates each sample's depth: a plane sloped in x, then in y,
         * drawn at every sample and read back; each sample's median offset. A conformant device
         * gives the standard locations; SwiftShader's 4-sample ones are mirrored in x
         * (docs/conform/drivers-notes.md). As `umbrage render --msaa N` measures them. ---- */
        memcpy(locations, standard, 2 * args.samples * sizeof(float));
        for (i = 0; i < 2 && args.samples > 1; i++) {
            /* depth = 0.5 + 0.25 * clip (x or y): a full-screen quad in clip space, identity MVP */
            static const float corners[6][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, -1}, {1, 1}, {-1, 1}};
            float *vd = (float *)vertices.mapped, mvp[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
            VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
            VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
            VkViewport viewport = {0, 0, 0, 0, 0, 1};
            VkRect2D full = {{0, 0}, {0, 0}};
            VkDeviceSize offset = 0;
            VkMemoryBarrier mb = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
            uint32_t k;
            viewport.width = (float)w;
            viewport.height = (float)h;
            full.extent.width = w;
            full.extent.height = h;
            for (k = 0; k < 6; k++) {
                float *v = &vd[7 * k];
                memset(v, 0, 7 * sizeof(float));
                v[0] = corners[k][0];
                v[1] = corners[k][1];
                v[2] = 0.5f + 0.25f * corners[k][i];
            }
            CHECK_VK(vkBeginCommandBuffer(cb, &begin));
            begin_prepass(cb, dynamic, &(Prepass){plane.image, plane_view, ds.image, ds_view, prepass_rp, prepass_fb, prepass_pipe},
                          full, viewport, args.reverse_z ? 0.0f : 1.0f);
            vkCmdPushConstants(cb, prepass_layout, VK_SHADER_STAGE_VERTEX_BIT, 0, 64, mvp);
            vkCmdBindVertexBuffers(cb, 0, 1, &vertices.buffer, &offset);
            vkCmdDraw(cb, 6, 1, 0, 0);
            if (dynamic) {
                vkCmdEndRendering(cb);
                image_barrier(cb, plane.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                              VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
                image_barrier(cb, ds.image, VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT,
                              VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL,
                              VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                              VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
            } else {
                vkCmdEndRenderPass(cb);
            }
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, extract_pipe);
            vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, extract_layout, 0, 1, &set, 0, NULL);
            for (si = 0; si < args.samples; si++) {
                uint32_t push[5] = {w, h, si, 0, 5 * n * si};
                vkCmdPushConstants(cb, extract_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 20, push);
                vkCmdDispatch(cb, (w + 7) / 8, (h + 7) / 8, 1);
            }
            mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
            mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
            vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, NULL, 0, NULL);
            CHECK_VK(vkEndCommandBuffer(cb));
            submit.commandBufferCount = 1;
            submit.pCommandBuffers = &cb;
            CHECK_VK(vkQueueSubmit(queue, 1, &submit, fence));
            CHECK_VK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
            CHECK_VK(vkResetFences(device, 1, &fence));
            for (si = 0; si < args.samples; si++) {
                const uint32_t *g = (const uint32_t *)readback.mapped + 5 * n * si;
                double *off = malloc(n * sizeof(double)), med;
                uint32_t p, count = 0;
                for (p = 0; p < n; p++) {
                    float d;
                    double pix = i == 0 ? (double)(p % w) : (double)(p / w), size = i == 0 ? w : h;
                    memcpy(&d, &g[5 * p], 4);
                    /* clip = (d - 0.5) / 0.25; window = (clip + 1) * size / 2 */
                    if (d > 0.0f && d < 1.0f) off[count++] = ((d - 0.5) / 0.25 + 1.0) * size / 2.0 - pix;
                }
                if (count == 0) {
                    free(off);
                    continue;
                }
                qsort(off, count, sizeof(double), cmp_double);
                med = off[count / 2];
                /* the standard location where the measure agrees with it to the depth's precision */
                if (fabs(med - standard[2 * si + i]) > 1e-3) locations[2 * si + i] = (float)med;
                free(off);
            }
        }
        if (args.samples > 1) {
            printf("umbrage-c-host: sample depth locations:");
            for (si = 0; si < args.samples; si++) printf(" (%g, %g)", (double)locations[2 * si], (double)locations[2 * si + 1]);
            printf("\n");
        }

        /* ---- the frames ---- */
        for (i = 0; i < 3; i++) eye_d[i] = scene.eye[i];
        look_at(scene.eye, scene.target, scene.up, view);
        projection(scene.fov_y_deg, scene.near_plane, (float)w / (float)h, args.reverse_z, proj);
        for (f = 0; f < args.frames; f++) {
            uint32_t slot = f % 2, first = 0;
            double rot[16], t_eye[16];
            float *vdata = (float *)vertices.mapped;
            UmbrageLight *lights = calloc(scene.light_count + 1, sizeof *lights);
            UmbrageView uview;
            UmbrageFrameStats stats;
            VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
            VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
            VkViewport viewport = {0, 0, 0, 0, 0, 1};
            VkRect2D full = {{0, 0}, {0, 0}};
            UmbrageDepthStencilTarget target;
            viewport.width = (float)w;
            viewport.height = (float)h;
            full.extent.width = w;
            full.extent.height = h;

            /* The moving caster: 0.25 along +x a frame. UMBRAGE: a new transform, nothing re-created. */
            if (moving >= 0 && f > 0) {
                float t[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.25f * (float)f, 0, 0, 1};
                double d[16];
                mat4_mul_f(t, scene.meshes[moving].transform, transforms[moving]);
                for (i = 0; i < 16; i++) d[i] = transforms[moving][i];
                CHECK_U(umbrage_pass_set_caster_transform(pass, casters[moving], d));
            }
            /* UMBRAGE: prepare (CPU work) for this ring slot; the previous use of the slot retired
             * (this host waits for every frame's fence). */
            memset(&uview, 0, sizeof uview);
            uview.sType = UMBRAGE_STRUCTURE_TYPE_VIEW;
            memcpy(uview.eye, eye_d, sizeof eye_d);
            memcpy(uview.view, view, sizeof view);
            memcpy(uview.projection, proj, sizeof proj);
            uview.width = w;
            uview.height = h;
            for (li = 0; li < scene.light_count; li++) {
                const HostLight *l = &scene.lights[li];
                lights[li].kind = (UmbrageLightKind)l->kind;
                memcpy(lights[li].position, l->position, sizeof l->position);
                memcpy(lights[li].direction, l->direction, sizeof l->direction);
                lights[li].coneDeg = l->cone_deg;
                lights[li].radius = l->radius;
            }
            CHECK_U(umbrage_pass_prepare(pass, slot, &uview, lights, scene.light_count, &frame));
            free(lights);

            /* The pre-pass's vertices: object space through the MVP the pass composes for its
             * casters (f64: projection * rotation * translation(-eye) * transform), with each
             * triangle's world normal and plane offset from the eye. */
            for (i = 0; i < 16; i++) rot[i] = (i % 4 == 3 || i >= 12) ? (i == 15 ? 1.0 : 0.0) : view[i];
            {
                double p[16];
                for (i = 0; i < 16; i++) p[i] = proj[i];
                mat4_mul_d(p, rot, vp);
            }
            memset(t_eye, 0, sizeof t_eye);
            t_eye[0] = t_eye[5] = t_eye[10] = t_eye[15] = 1.0;
            t_eye[12] = -eye_d[0], t_eye[13] = -eye_d[1], t_eye[14] = -eye_d[2];
            for (mi = 0; mi < scene.mesh_count; mi++) {
                HostMesh *m = &scene.meshes[mi];
                uint32_t t, c;
                for (t = 0; t < m->triangle_count; t++) {
                    double wp[3][3], e1[3], e2[3], nrm[3], len, d;
                    for (c = 0; c < 3; c++) {
                        const float *p = &m->positions[3 * m->triangles[3 * t + c]];
                        const float *x = transforms[mi];
                        uint32_t r;
                        for (r = 0; r < 3; r++) wp[c][r] = (double)x[r] * p[0] + (double)x[4 + r] * p[1] + (double)x[8 + r] * p[2] + (double)x[12 + r];
                    }
                    for (c = 0; c < 3; c++) e1[c] = wp[1][c] - wp[0][c], e2[c] = wp[2][c] - wp[0][c];
                    nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
                    nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
                    nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
                    len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
                    if (len > 0) nrm[0] /= len, nrm[1] /= len, nrm[2] /= len;
                    d = nrm[0] * (wp[0][0] - eye_d[0]) + nrm[1] * (wp[0][1] - eye_d[1]) + nrm[2] * (wp[0][2] - eye_d[2]);
                    for (c = 0; c < 3; c++) {
                        float *v = &vdata[7 * (3 * (first + t) + c)];
                        memcpy(v, &m->positions[3 * m->triangles[3 * t + c]], 3 * sizeof(float));
                        v[3] = (float)nrm[0], v[4] = (float)nrm[1], v[5] = (float)nrm[2], v[6] = (float)d;
                    }
                }
                first += m->triangle_count;
            }

            CHECK_VK(vkBeginCommandBuffer(cb, &begin));
            /* UMBRAGE: before any rendering: the pass's uploads (new or moved casters' copies). */
            CHECK_U(umbrage_cmd_before_rendering(pass, cb, frame));
            /* The host's pre-pass. */
            begin_prepass(cb, dynamic, &(Prepass){plane.image, plane_view, ds.image, ds_view, prepass_rp, prepass_fb, prepass_pipe},
                          full, viewport, args.reverse_z ? 0.0f : 1.0f);
            first = 0;
            for (mi = 0; mi < scene.mesh_count; mi++) {
                double xf[16], a[16], mvp_d[16];
                float mvp[16];
                VkDeviceSize offset = 0;
                for (i = 0; i < 16; i++) xf[i] = transforms[mi][i];
                mat4_mul_d(vp, t_eye, a);
                mat4_mul_d(a, xf, mvp_d);
                for (i = 0; i < 16; i++) mvp[i] = (float)mvp_d[i];
                vkCmdPushConstants(cb, prepass_layout, VK_SHADER_STAGE_VERTEX_BIT, 0, 64, mvp);
                vkCmdBindVertexBuffers(cb, 0, 1, &vertices.buffer, &offset);
                vkCmdDraw(cb, 3 * scene.meshes[mi].triangle_count, 1, 3 * first, 0);
                first += scene.meshes[mi].triangle_count;
            }
            if (dynamic) {
                vkCmdEndRendering(cb);
                image_barrier(cb, plane.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                              VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
                image_barrier(cb, ds.image, VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT,
                              VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL,
                              VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                              VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
            } else {
                vkCmdEndRenderPass(cb);
            }
            /* Read back every sample's depth and plane. */
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, extract_pipe);
            vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, extract_layout, 0, 1, &set, 0, NULL);
            for (si = 0; si < args.samples; si++) {
                uint32_t push[5] = {w, h, si, 0, 5 * n * si};
                vkCmdPushConstants(cb, extract_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 20, push);
                vkCmdDispatch(cb, (w + 7) / 8, (h + 7) / 8, 1);
            }
            /* UMBRAGE: per light, the determination leaves the count in the stencil (0: lit), which
             * the host's lighting reads; here the read-back. */
            memset(&target, 0, sizeof target);
            target.sType = UMBRAGE_STRUCTURE_TYPE_DEPTH_STENCIL_TARGET;
            target.image = ds.image;
            target.view = ds_view;
            target.extent = full.extent;
            target.layout = target.finalLayout =
                dynamic ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
            for (li = 0; li < scene.light_count; li++) {
                if (dynamic) {
                    CHECK_U(umbrage_cmd_determine(pass, cb, frame, li, &target));
                } else {
                    VkRenderPassBeginInfo rb = {VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
                    rb.renderPass = lighting_rp;
                    rb.framebuffer = lighting_fb;
                    rb.renderArea = full;
                    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
                    CHECK_U(umbrage_cmd_determine(pass, cb, frame, li, &target));
                    vkCmdEndRenderPass(cb);
                }
                vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, extract_pipe);
                vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, extract_layout, 0, 1, &set, 0, NULL);
                for (si = 0; si < args.samples; si++) {
                    uint32_t push[5] = {w, h, si, 1, geometry_words + n * (li * args.samples + si)};
                    vkCmdPushConstants(cb, extract_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 20, push);
                    vkCmdDispatch(cb, (w + 7) / 8, (h + 7) / 8, 1);
                }
            }
            {
                VkMemoryBarrier mb = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
                mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
                mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
                vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, NULL, 0, NULL);
            }
            CHECK_VK(vkEndCommandBuffer(cb));
            submit.commandBufferCount = 1;
            submit.pCommandBuffers = &cb;
            CHECK_VK(vkQueueSubmit(queue, 1, &submit, fence));
            CHECK_VK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
            CHECK_VK(vkResetFences(device, 1, &fence));

            /* UMBRAGE: the frame's statistics. */
            memset(&stats, 0, sizeof stats);
            stats.sType = UMBRAGE_STRUCTURE_TYPE_FRAME_STATS;
            CHECK_U(umbrage_frame_get_stats(pass, frame, &stats));
            printf("frame %u (slot %u): %llu shadow triangles (%llu sides, %llu dark cap, %llu light cap); cases %llu z-pass / %llu z-fail / "
                   "%llu z-fail+light cap / %llu culled\n",
                   f, slot, (unsigned long long)(stats.sideTriangles + stats.darkCapTriangles + stats.lightCapTriangles),
                   (unsigned long long)stats.sideTriangles, (unsigned long long)stats.darkCapTriangles,
                   (unsigned long long)stats.lightCapTriangles, (unsigned long long)stats.casesZPass, (unsigned long long)stats.casesZFail,
                   (unsigned long long)stats.casesZFailLightCap, (unsigned long long)stats.casesCulled);
        }

        /* ---- the last frame's dump, per sample, and its picture ---- */
        {
            const uint32_t *words = (const uint32_t *)readback.mapped;
            float clear_depth = args.reverse_z ? 0.0f : 1.0f;
            double inv[16];
            uint8_t *rgba = calloc((size_t)n * 4, 1);
            float *acc = calloc((size_t)n * 3, sizeof(float));
            /* the inverse of the eye-relative world -> clip matrix (vp), by Gauss-Jordan in f64 */
            {
                double a[4][8];
                int r, c, k;
                for (r = 0; r < 4; r++)
                    for (c = 0; c < 8; c++) a[r][c] = c < 4 ? vp[4 * c + r] : (c - 4 == r);
                for (c = 0; c < 4; c++) {
                    int piv = c;
                    double t;
                    for (r = c + 1; r < 4; r++)
                        if (fabs(a[r][c]) > fabs(a[piv][c])) piv = r;
                    for (k = 0; k < 8; k++) t = a[c][k], a[c][k] = a[piv][k], a[piv][k] = t;
                    t = a[c][c];
                    for (k = 0; k < 8; k++) a[c][k] /= t;
                    for (r = 0; r < 4; r++)
                        if (r != c) {
                            t = a[r][c];
                            for (k = 0; k < 8; k++) a[r][k] -= t * a[c][k];
                        }
                }
                for (r = 0; r < 4; r++)
                    for (c = 0; c < 4; c++) inv[4 * c + r] = a[r][c + 4];
            }
            for (si = 0; si < args.samples; si++) {
                DumpSample d;
                const uint32_t *g = words + 5 * n * si;
                char dir[1100];
                d.width = w;
                d.height = h;
                d.positions = malloc((size_t)n * 3 * sizeof(float));
                d.normals = malloc((size_t)n * 3 * sizeof(float));
                d.masks = calloc(scene.light_count + 1, sizeof *d.masks);
                d.stencils = calloc(scene.light_count + 1, sizeof *d.stencils);
                d.transforms = (const float(*)[16])transforms;
                for (i = 0; i < n; i++) {
                    float depth, pl[4];
                    double x, y, clip[4], r[4], rel[3], nn[3], off;
                    int k;
                    memcpy(&depth, &g[5 * i], 4);
                    memcpy(pl, &g[5 * i + 1], 16);
                    if (depth == clear_depth) {
                        for (k = 0; k < 3; k++) d.positions[3 * i + k] = d.normals[3 * i + k] = NAN;
                        continue;
                    }
                    /* the sample's depth unprojected at its own location, put back on its plane */
                    x = (double)(i % w) + locations[2 * si];
                    y = (double)(i / w) + locations[2 * si + 1];
                    clip[0] = 2.0 * x / w - 1.0, clip[1] = 2.0 * y / h - 1.0, clip[2] = depth, clip[3] = 1.0;
                    for (k = 0; k < 4; k++) r[k] = inv[k] * clip[0] + inv[4 + k] * clip[1] + inv[8 + k] * clip[2] + inv[12 + k] * clip[3];
                    for (k = 0; k < 3; k++) rel[k] = r[k] / r[3], nn[k] = pl[k];
                    off = nn[0] * rel[0] + nn[1] * rel[1] + nn[2] * rel[2] - pl[3];
                    for (k = 0; k < 3; k++) {
                        d.positions[3 * i + k] = (float)(eye_d[k] + rel[k] - nn[k] * off);
                        d.normals[3 * i + k] = pl[k];
                    }
                }
                for (li = 0; li < scene.light_count; li++) {
                    const uint32_t *st = words + geometry_words + n * (li * args.samples + si);
                    d.masks[li] = malloc(n);
                    d.stencils[li] = malloc(n);
                    for (i = 0; i < n; i++) {
                        d.stencils[li][i] = (uint8_t)st[i];
                        if (isnan(d.positions[3 * i])) d.masks[li][i] = 128;
                        else if ((st[i] & 0xff) == 0 && reaches(&scene.lights[li], &d.positions[3 * i], &d.normals[3 * i])) d.masks[li][i] = 255;
                        else d.masks[li][i] = 0;
                    }
                }
                /* the picture: grey Lambert from every light that reaches the sample, averaged over samples */
                for (i = 0; i < n; i++) {
                    float c[3] = {0.25f, 0.3f, 0.4f};
                    if (!isnan(d.positions[3 * i])) {
                        float lit = 0.1f;
                        for (li = 0; li < scene.light_count; li++)
                            if (d.masks[li][i] == 255) {
                                const HostLight *l = &scene.lights[li];
                                float to[3];
                                int k;
                                for (k = 0; k < 3; k++) to[k] = l->kind == 2 ? -l->direction[k] : l->position[k] - d.positions[3 * i + k];
                                normalize3f(to);
                                lit += 0.9f * dot3f(&d.normals[3 * i], to) / (float)scene.light_count;
                            }
                        c[0] = c[1] = c[2] = 0.8f * lit;
                    }
                    acc[3 * i] += c[0] / (float)args.samples;
                    acc[3 * i + 1] += c[1] / (float)args.samples;
                    acc[3 * i + 2] += c[2] / (float)args.samples;
                }
                if (args.dump) {
                    if (args.samples > 1) snprintf(dir, sizeof dir, "%s/sample_%u", args.dump, si);
                    else snprintf(dir, sizeof dir, "%s", args.dump);
                    if (write_dump(dir, &scene, &d) != 0) {
                        fprintf(stderr, "umbrage-c-host: cannot write the dump into %s\n", dir);
                        return 1;
                    }
                }
                for (li = 0; li < scene.light_count; li++) {
                    free(d.masks[li]);
                    free(d.stencils[li]);
                }
                free(d.masks);
                free(d.stencils);
                free(d.positions);
                free(d.normals);
            }
            if (args.dump) printf("umbrage-c-host: dumped frame %u into %s%s\n", args.frames - 1, args.dump, args.samples > 1 ? "/sample_*" : "");
            if (args.out) {
                for (i = 0; i < n; i++) {
                    int k;
                    for (k = 0; k < 3; k++) {
                        float v = acc[3 * i + k] < 0 ? 0 : acc[3 * i + k] > 1 ? 1 : acc[3 * i + k];
                        rgba[4 * i + k] = (uint8_t)(v * 255.0f + 0.5f);
                    }
                    rgba[4 * i + 3] = 255;
                }
                if (write_png(args.out, w, h, 4, rgba) != 0) return 1;
                printf("umbrage-c-host: wrote %s\n", args.out);
            }
            free(rgba);
            free(acc);
        }

        /* ---- teardown: UMBRAGE: destroy the pass after its last command buffer completed ---- */
        CHECK_VK(vkDeviceWaitIdle(device));
        CHECK_U(umbrage_pass_destroy(pass));
        vkDestroyFence(device, fence, NULL);
        vkDestroyCommandPool(device, cmd_pool, NULL);
        vkDestroySampler(device, sampler, NULL);
        vkDestroyDescriptorPool(device, pool, NULL);
        vkDestroyPipeline(device, extract_pipe, NULL);
        vkDestroyPipelineLayout(device, extract_layout, NULL);
        vkDestroyDescriptorSetLayout(device, set_layout, NULL);
        vkDestroyPipeline(device, prepass_pipe, NULL);
        vkDestroyPipelineLayout(device, prepass_layout, NULL);
        if (lighting_fb) vkDestroyFramebuffer(device, lighting_fb, NULL);
        if (prepass_fb) vkDestroyFramebuffer(device, prepass_fb, NULL);
        if (lighting_rp) vkDestroyRenderPass(device, lighting_rp, NULL);
        if (prepass_rp) vkDestroyRenderPass(device, prepass_rp, NULL);
        vkDestroyImageView(device, ds_view, NULL);
        vkDestroyImageView(device, depth_view, NULL);
        vkDestroyImageView(device, stencil_view, NULL);
        vkDestroyImageView(device, plane_view, NULL);
        vkDestroyImage(device, ds.image, NULL);
        vkFreeMemory(device, ds.memory, NULL);
        vkDestroyImage(device, plane.image, NULL);
        vkFreeMemory(device, plane.memory, NULL);
        buffer_destroy(&vertices);
        buffer_destroy(&readback);
        free(casters);
        free(transforms);
    }
    vkDestroyDevice(device, NULL);
    if (messenger) destroy_messenger(instance, messenger, NULL);
    vkDestroyInstance(instance, NULL);
    scene_free(&scene);
    if (validation_errors) {
        fprintf(stderr, "umbrage-c-host: %u validation message(s) (errors and warnings)\n", validation_errors);
        return 1;
    }
    return 0;
}

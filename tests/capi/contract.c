/* The C ABI's contract, from C (scripts/capi-test.sh builds it against the installed library):
 * every refused value returns its code and changes nothing (docs/contract.md's ranges that C can
 * express), NULL pointers, out-of-range enums, stale and foreign frames, foreign and removed ids,
 * a destroyed pass, the version check, and (with the test-panic build) a panic that returns
 * UMBRAGE_ERROR_PANIC and poisons the pass. Needs a Vulkan 1.3 device (lavapipe in CI).
 * Prints "N passed, M failed" and exits non-zero on any failure. */
#include <umbrage/umbrage.h>
#include <vulkan/vulkan.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int passed, failed;

static void expect(const char *what, UmbrageResult got, UmbrageResult want) {
    if (got == want) {
        passed++;
    } else {
        failed++;
        fprintf(stderr, "FAIL %s: got %d, expected %d (%s)\n", what, (int)got, (int)want, umbrage_last_error());
    }
}

static void expect_true(const char *what, int ok) {
    if (ok) passed++;
    else {
        failed++;
        fprintf(stderr, "FAIL %s\n", what);
    }
}

static void expect_message(const char *what, const char *needle) {
    char buf[512];
    size_t n = umbrage_last_error_message(buf, sizeof buf);
    expect_true(what, n > 0 && strstr(buf, needle) != NULL);
    if (!(n > 0 && strstr(buf, needle))) fprintf(stderr, "  message was: %s\n", buf);
}

static UmbragePassCreateInfo base_info(void) {
    UmbragePassCreateInfo info;
    memset(&info, 0, sizeof info);
    info.sType = UMBRAGE_STRUCTURE_TYPE_PASS_CREATE_INFO;
    info.abiVersion = UMBRAGE_ABI_VERSION;
    return info;
}

/* A unit cube, 8 vertices and 12 triangles, outward. */
static const float cube_pos[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
static const uint32_t cube_idx[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                      2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};

static UmbrageCasterInfo cube_info(void) {
    UmbrageCasterInfo c;
    memset(&c, 0, sizeof c);
    c.sType = UMBRAGE_STRUCTURE_TYPE_CASTER_INFO;
    c.pName = "cube";
    c.pPositions = cube_pos;
    c.vertexCount = 8;
    c.pIndices = cube_idx;
    c.indexCount = 36;
    return c;
}

static UmbrageView base_view(void) {
    UmbrageView v;
    float f = 1.0f / tanf(0.5f);
    memset(&v, 0, sizeof v);
    v.sType = UMBRAGE_STRUCTURE_TYPE_VIEW;
    v.eye[2] = 6.0; /* looking down -z from (0, 0, 6): view = translation(0, 0, -6) */
    v.view[0] = v.view[5] = v.view[10] = v.view[15] = 1.0f;
    v.view[14] = -6.0f;
    v.projection[0] = f;
    v.projection[5] = -f;
    v.projection[10] = -1.0f;
    v.projection[11] = -1.0f;
    v.projection[14] = -0.1f;
    v.width = 64;
    v.height = 64;
    return v;
}

int main(void) {
    VkInstance instance;
    VkPhysicalDevice physical;
    VkDevice device;
    UmbrageVulkanDevice vk;
    UmbragePassCreateInfo info;
    UmbragePass pass = NULL, other = NULL, sentinel = (UmbragePass)(uintptr_t)0x5a5a;
    UmbragePass out;
    UmbrageCasterId cube = 0, other_cube = 0, dead = 0;
    UmbrageFrame frame, frame2, stale, foreign;
    UmbrageLight light;
    UmbrageView view;
    UmbragePassSettings settings, before;
    UmbrageCasterInfo c;
    uint32_t count = 1;

    expect_true("umbrage_abi_version() == UMBRAGE_ABI_VERSION", umbrage_abi_version() == UMBRAGE_ABI_VERSION);

    {
        VkApplicationInfo app = {VK_STRUCTURE_TYPE_APPLICATION_INFO};
        VkInstanceCreateInfo ii = {VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        VkDeviceQueueCreateInfo qi = {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        VkPhysicalDeviceVulkan13Features v13 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
        VkDeviceCreateInfo di = {VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        float priority = 1.0f;
        VkResult r;
        app.apiVersion = VK_API_VERSION_1_3;
        ii.pApplicationInfo = &app;
        if (vkCreateInstance(&ii, NULL, &instance) != VK_SUCCESS) {
            fprintf(stderr, "contract: no Vulkan instance (install a driver: lavapipe)\n");
            return 1;
        }
        r = vkEnumeratePhysicalDevices(instance, &count, &physical);
        if ((r != VK_SUCCESS && r != VK_INCOMPLETE) || count == 0) {
            fprintf(stderr, "contract: no Vulkan device\n");
            return 1;
        }
        qi.queueCount = 1;
        qi.pQueuePriorities = &priority;
        v13.dynamicRendering = VK_TRUE;
        di.pNext = &v13;
        di.queueCreateInfoCount = 1;
        di.pQueueCreateInfos = &qi;
        if (vkCreateDevice(physical, &di, NULL, &device) != VK_SUCCESS) {
            fprintf(stderr, "contract: no Vulkan 1.3 device with dynamic rendering\n");
            return 1;
        }
    }
    memset(&vk, 0, sizeof vk);
    vk.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
    vk.instance = instance;
    vk.physicalDevice = physical;
    vk.device = device;

    /* ---- creation: NULLs, identity, version, refused options; *out untouched ---- */
    info = base_info();
    out = sentinel;
    expect("create: NULL vulkan", umbrage_pass_create(NULL, &info, &out), UMBRAGE_ERROR_NULL_POINTER);
    expect("create: NULL info", umbrage_pass_create(&vk, NULL, &out), UMBRAGE_ERROR_NULL_POINTER);
    expect("create: NULL out", umbrage_pass_create(&vk, &info, NULL), UMBRAGE_ERROR_NULL_POINTER);
    {
        UmbrageVulkanDevice novk = vk;
        novk.pfnGetInstanceProcAddr = NULL;
        expect("create: NULL vkGetInstanceProcAddr", umbrage_pass_create(&novk, &info, &out), UMBRAGE_ERROR_NULL_POINTER);
        novk = vk;
        novk.device = VK_NULL_HANDLE;
        expect("create: VK_NULL_HANDLE device", umbrage_pass_create(&novk, &info, &out), UMBRAGE_ERROR_NULL_POINTER);
    }
    info.sType = UMBRAGE_STRUCTURE_TYPE_VIEW;
    expect("create: wrong sType", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_STRUCTURE_TYPE);
    info = base_info();
    info.abiVersion = 0;
    expect("create: abiVersion 0", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_VERSION_MISMATCH);
    info.abiVersion = UMBRAGE_ABI_VERSION + 1;
    expect("create: a newer header", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_VERSION_MISMATCH);
    info = base_info();
    {
        struct {
            UmbrageStructureType sType;
            const void *pNext;
        } unknown = {(UmbrageStructureType)999, NULL};
        info.pNext = &unknown;
        expect("create: an unknown struct in pNext", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_STRUCTURE_TYPE);
    }
    info = base_info();
    info.depthDirection = (UmbrageDepthDirection)7;
    expect("create: depthDirection 7", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_ARGUMENT);
    expect_message("create: depthDirection's message names it", "depthDirection");
    info = base_info();
    info.depthMode = (UmbrageDepthMode)2;
    expect("create: depthMode 2", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_ARGUMENT);
    info = base_info();
    info.enabledFeatures = 0x80000000u;
    expect("create: unknown feature bit", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_ARGUMENT);
    info = base_info();
    info.samples = 3;
    expect("create: samples 3", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_INVALID_DESC);
    expect_message("create: samples' message names it", "samples");
    info.samples = 16;
    expect("create: samples 16", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_INVALID_DESC);
    info = base_info();
    info.framesInFlight = 65;
    expect("create: framesInFlight 65", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_INVALID_DESC);
    expect_message("create: frames_in_flight's message names it", "frames_in_flight");
    info = base_info();
    info.depthStencilFormat = VK_FORMAT_D32_SFLOAT;
    expect("create: D32_SFLOAT (no stencil)", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_UNSUPPORTED);
    info.depthStencilFormat = VK_FORMAT_R8G8B8A8_UNORM;
    expect("create: R8G8B8A8_UNORM", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_UNSUPPORTED);
    info = base_info();
    info.depthMode = UMBRAGE_DEPTH_MODE_CLAMP; /* depthClamp not enabled */
    expect("create: clamp without depthClamp", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_UNSUPPORTED);
    info = base_info();
    info.settings.technique = (UmbrageTechnique)42;
    expect("create: technique 42", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_ARGUMENT);
    info = base_info();
    info.settings.indexFormat = UMBRAGE_INDEX_FORMAT_U8; /* indexTypeUint8 not enabled */
    expect("create: U8 indices without indexTypeUint8", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_UNSUPPORTED);
    info = base_info();
    info.transmitFormat = VK_FORMAT_R32_UINT;
    expect("create: a transmit format that does not blend", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_INVALID_DESC);
    {
        UmbrageRenderPassTarget rp;
        memset(&rp, 0, sizeof rp);
        rp.sType = UMBRAGE_STRUCTURE_TYPE_RENDER_PASS_TARGET;
        info = base_info();
        info.pNext = &rp;
        expect("create: a render pass target without a render pass", umbrage_pass_create(&vk, &info, &out),
               UMBRAGE_ERROR_INVALID_DESC);
    }
    {
        UmbrageKeepInfo k1, k2;
        memset(&k1, 0, sizeof k1);
        k1.sType = UMBRAGE_STRUCTURE_TYPE_KEEP_INFO;
        k2 = k1;
        k1.pNext = &k2;
        info = base_info();
        info.pNext = &k1;
        expect("create: UmbrageKeepInfo chained twice", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_INVALID_DESC);
    }
    {
        UmbrageRenderPassTarget rp;
        memset(&rp, 0, sizeof rp);
        rp.sType = UMBRAGE_STRUCTURE_TYPE_RENDER_PASS_TARGET;
        rp.renderPass = (VkRenderPass)(uintptr_t)1; /* never used: the chain is refused first */
        rp.pNext = &rp;                             /* a cycle */
        info = base_info();
        info.pNext = &rp;
        expect("create: a cyclic pNext chain", umbrage_pass_create(&vk, &info, &out), UMBRAGE_ERROR_STRUCTURE_TYPE);
    }
    expect_true("create: *out untouched by every refusal", out == sentinel);

    /* ---- capabilities without a device ---- */
    {
        UmbrageDeviceDescription d;
        UmbrageFormatFeatures ff = {VK_FORMAT_D32_SFLOAT_S8_UINT, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT, 0};
        UmbrageCapabilities caps;
        memset(&d, 0, sizeof d);
        d.sType = UMBRAGE_STRUCTURE_TYPE_DEVICE_DESCRIPTION;
        d.apiVersion = VK_API_VERSION_1_0;
        d.pFormats = &ff;
        d.formatCount = 1;
        info = base_info();
        expect("capabilities_for: Vulkan 1.0", umbrage_capabilities_for(&d, &info, &caps), UMBRAGE_ERROR_UNSUPPORTED);
        d.apiVersion = VK_API_VERSION_1_3;
        expect("capabilities_for: 1.3 without dynamicRendering", umbrage_capabilities_for(&d, &info, &caps), UMBRAGE_ERROR_UNSUPPORTED);
        d.deviceFeatures = UMBRAGE_DEVICE_FEATURE_DYNAMIC_RENDERING_BIT | UMBRAGE_DEVICE_FEATURE_DEPTH_BOUNDS_BIT;
        info.enabledFeatures = UMBRAGE_FEATURE_DEPTH_BOUNDS_BIT;
        expect("capabilities_for: 1.3 with dynamicRendering", umbrage_capabilities_for(&d, &info, &caps), UMBRAGE_SUCCESS);
        expect_true("capabilities_for: depth bounds enabled and present", caps.depthBounds == 1 && caps.rayQuery == 0);
        info.samples = 3;
        expect("capabilities_for: samples 3", umbrage_capabilities_for(&d, &info, &caps), UMBRAGE_ERROR_INVALID_DESC);
        expect("capabilities_for: NULL device", umbrage_capabilities_for(NULL, &info, &caps), UMBRAGE_ERROR_NULL_POINTER);
    }

    /* ---- a pass ---- */
    info = base_info();
    expect("create: defaults", umbrage_pass_create(&vk, &info, &pass), UMBRAGE_SUCCESS);
    {
        /* the second pass plans every frame from scratch, in 8 MiB if it kept anything */
        UmbrageKeepInfo keep;
        memset(&keep, 0, sizeof keep);
        keep.sType = UMBRAGE_STRUCTURE_TYPE_KEEP_INFO;
        keep.keepBudgetBytes = 8u << 20;
        keep.planThreads = 1;
        keep.disableKeep = 1;
        info.pNext = &keep;
        expect("create: a second pass, keeping nothing", umbrage_pass_create(&vk, &info, &other), UMBRAGE_SUCCESS);
        info.pNext = NULL;
    }
    if (!pass || !other) {
        fprintf(stderr, "contract: no pass, stopping\n");
        printf("%d passed, %d failed\n", passed, failed + 1);
        return 1;
    }
    expect("get_settings", umbrage_pass_get_settings(pass, &before), UMBRAGE_SUCCESS);
    expect_true("default settings are all zero", before.technique == 0 && before.method == 0 && before.counter == 0 &&
                                                     before.indexFormat == 0 && before.disableScissor == 0 && before.rayBatch == 0);
    settings = before;
    settings.technique = (UmbrageTechnique)9;
    expect("set_settings: technique 9", umbrage_pass_set_settings(pass, &settings), UMBRAGE_ERROR_ARGUMENT);
    settings = before;
    settings.technique = UMBRAGE_TECHNIQUE_RAY_QUERY;
    expect("set_settings: ray query not enabled", umbrage_pass_set_settings(pass, &settings), UMBRAGE_ERROR_UNSUPPORTED);
    settings = before;
    settings.indexFormat = UMBRAGE_INDEX_FORMAT_U8;
    expect("set_settings: U8 not enabled", umbrage_pass_set_settings(pass, &settings), UMBRAGE_ERROR_UNSUPPORTED);
    settings = before;
    settings.technique = UMBRAGE_TECHNIQUE_COMPUTE;
    settings.computeDraws = UMBRAGE_COMPUTE_DRAWS_MULTI;
    expect("set_settings: multi draws not enabled", umbrage_pass_set_settings(pass, &settings), UMBRAGE_ERROR_UNSUPPORTED);
    expect("set_settings: NULL", umbrage_pass_set_settings(pass, NULL), UMBRAGE_ERROR_NULL_POINTER);
    memset(&settings, 0xff, sizeof settings);
    expect("get_settings after refusals", umbrage_pass_get_settings(pass, &settings), UMBRAGE_SUCCESS);
    expect_true("refused settings changed nothing", memcmp(&settings, &before, sizeof before) == 0);
    settings = before;
    settings.method = UMBRAGE_METHOD_ZFAIL;
    expect("set_settings: z-fail", umbrage_pass_set_settings(pass, &settings), UMBRAGE_SUCCESS);
    expect("set_settings: back to the defaults", umbrage_pass_set_settings(pass, &before), UMBRAGE_SUCCESS);

    /* ---- casters ---- */
    c = cube_info();
    expect("add_caster: NULL info", umbrage_pass_add_caster(pass, NULL, &cube), UMBRAGE_ERROR_NULL_POINTER);
    expect("add_caster: NULL out", umbrage_pass_add_caster(pass, &c, NULL), UMBRAGE_ERROR_NULL_POINTER);
    c.pPositions = NULL;
    expect("add_caster: NULL positions", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_ERROR_NULL_POINTER);
    c = cube_info();
    c.indexCount = 35;
    expect("add_caster: 35 indices", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_ERROR_ARGUMENT);
    c = cube_info();
    c.indexType = (UmbrageIndexType)5;
    expect("add_caster: index type 5", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_ERROR_ARGUMENT);
    {
        uint32_t bad[3] = {0, 1, 8};
        float nan_pos[24];
        c = cube_info();
        c.pIndices = bad;
        c.indexCount = 3;
        expect("add_caster: an index one past the end", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_ERROR_MESH);
        c = cube_info();
        c.indexCount = 0;
        expect("add_caster: no triangles", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_ERROR_MESH);
        memcpy(nan_pos, cube_pos, sizeof nan_pos);
        nan_pos[4] = NAN;
        c = cube_info();
        c.pPositions = nan_pos;
        expect("add_caster: a NaN position", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_ERROR_MESH);
        c = cube_info();
        c.transform[0] = 1.0; /* the rest zero: singular */
        expect("add_caster: a singular transform", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_ERROR_MESH);
        c = cube_info();
        c.transparent = 1;
        c.transmittance[0] = c.transmittance[1] = c.transmittance[2] = 0.5f;
        expect("add_caster: transparent without transmitFormat", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_ERROR_NOT_CONFIGURED);
    }
    expect_true("add_caster: refusals wrote no id", cube == 0);
    {
        uint16_t idx16[36];
        int i;
        for (i = 0; i < 36; i++) idx16[i] = (uint16_t)cube_idx[i];
        c = cube_info();
        c.pIndices = idx16;
        c.indexType = UMBRAGE_INDEX_TYPE_UINT16;
        expect("add_caster: 16-bit indices", umbrage_pass_add_caster(pass, &c, &dead), UMBRAGE_SUCCESS);
    }
    c = cube_info();
    expect("add_caster: 32-bit indices, identity (all-zero transform)", umbrage_pass_add_caster(pass, &c, &cube), UMBRAGE_SUCCESS);
    expect("add_caster: on the other pass", umbrage_pass_add_caster(other, &c, &other_cube), UMBRAGE_SUCCESS);
    expect_true("ids are non-zero and distinct", cube != 0 && dead != 0 && cube != dead && other_cube != cube);
    {
        double t[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, 1}, singular[16];
        float moved[24];
        memset(singular, 0, sizeof singular);
        expect("set_transform", umbrage_pass_set_caster_transform(pass, cube, t), UMBRAGE_SUCCESS);
        expect("set_transform: NULL", umbrage_pass_set_caster_transform(pass, cube, NULL), UMBRAGE_ERROR_NULL_POINTER);
        expect("set_transform: singular", umbrage_pass_set_caster_transform(pass, cube, singular), UMBRAGE_ERROR_MESH);
        expect("set_transform: another pass's id", umbrage_pass_set_caster_transform(pass, other_cube, t), UMBRAGE_ERROR_FOREIGN_ID);
        expect("set_transform: id 0", umbrage_pass_set_caster_transform(pass, 0, t), UMBRAGE_ERROR_UNKNOWN_ID);
        memcpy(moved, cube_pos, sizeof moved);
        moved[0] = -0.1f;
        expect("update_positions", umbrage_pass_update_caster_positions(pass, cube, moved, 8), UMBRAGE_SUCCESS);
        expect("update_positions: 7 vertices", umbrage_pass_update_caster_positions(pass, cube, moved, 7), UMBRAGE_ERROR_MESH);
        expect("remove_caster", umbrage_pass_remove_caster(pass, dead), UMBRAGE_SUCCESS);
        expect("remove_caster: twice", umbrage_pass_remove_caster(pass, dead), UMBRAGE_ERROR_UNKNOWN_ID);
        expect("set_transform: a removed id", umbrage_pass_set_caster_transform(pass, dead, t), UMBRAGE_ERROR_UNKNOWN_ID);
        expect("remove_caster: another pass's id", umbrage_pass_remove_caster(pass, other_cube), UMBRAGE_ERROR_FOREIGN_ID);
    }
    {
        UmbrageSphereInfo s;
        UmbrageSphereId sphere = 0;
        double center[3] = {0, 3, 0};
        memset(&s, 0, sizeof s);
        s.sType = UMBRAGE_STRUCTURE_TYPE_SPHERE_INFO;
        s.center[1] = 3.0;
        s.radius = 0.0;
        expect("add_sphere: radius 0", umbrage_pass_add_sphere(pass, &s, &sphere), UMBRAGE_ERROR_MESH);
        s.radius = 0.5;
        s.segments = 2;
        expect("add_sphere: 2 segments", umbrage_pass_add_sphere(pass, &s, &sphere), UMBRAGE_ERROR_MESH);
        s.segments = 0;
        expect("add_sphere", umbrage_pass_add_sphere(pass, &s, &sphere), UMBRAGE_SUCCESS);
        expect("set_sphere: NaN radius", umbrage_pass_set_sphere(pass, sphere, center, NAN), UMBRAGE_ERROR_MESH);
        expect("remove_sphere", umbrage_pass_remove_sphere(pass, sphere), UMBRAGE_SUCCESS);
        expect("set_sphere: removed", umbrage_pass_set_sphere(pass, sphere, center, 1.0), UMBRAGE_ERROR_UNKNOWN_ID);
        expect("remove_sphere: a caster's id", umbrage_pass_remove_sphere(pass, cube), UMBRAGE_ERROR_UNKNOWN_ID);
    }

    /* ---- prepare and frames ---- */
    memset(&light, 0, sizeof light);
    light.position[1] = 5.0f;
    view = base_view();
    memset(&frame, 0x77, sizeof frame);
    stale = frame;
    expect("prepare: slot 2 of 2", umbrage_pass_prepare(pass, 2, &view, &light, 1, &frame), UMBRAGE_ERROR_SLOT_OUT_OF_RANGE);
    expect("prepare: NULL view", umbrage_pass_prepare(pass, 0, NULL, &light, 1, &frame), UMBRAGE_ERROR_NULL_POINTER);
    expect("prepare: NULL lights with a count", umbrage_pass_prepare(pass, 0, &view, NULL, 1, &frame), UMBRAGE_ERROR_NULL_POINTER);
    view.eye[0] = NAN;
    expect("prepare: a NaN eye", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    view = base_view();
    view.view[0] = 2.0f;
    expect("prepare: a view that is no rotation", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    view = base_view();
    view.width = 0;
    expect("prepare: width 0", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    view = base_view();
    light.kind = (UmbrageLightKind)9;
    expect("prepare: light kind 9", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    light.kind = UMBRAGE_LIGHT_KIND_SPOT;
    light.direction[1] = -1.0f;
    light.coneDeg = 0.0f;
    expect("prepare: spot cone 0", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    expect_message("prepare: the cone's message names it", "cone_deg");
    light.coneDeg = 360.00003f;
    expect("prepare: spot cone past 360", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    light.kind = UMBRAGE_LIGHT_KIND_DIRECTIONAL;
    light.direction[1] = 0.0f;
    expect("prepare: directional without direction", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    light.kind = UMBRAGE_LIGHT_KIND_POINT;
    light.radius = -1.0f;
    expect("prepare: radius -1", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    light.radius = NAN;
    expect("prepare: radius NaN", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    light.radius = 0.0f;
    light.position[0] = INFINITY;
    expect("prepare: an infinite position", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    light.position[0] = 0.0f;
    expect_true("prepare: refusals wrote no frame", memcmp(&frame, &stale, sizeof frame) == 0);
    expect("prepare", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_SUCCESS);
    expect("prepare: the other pass", umbrage_pass_prepare(other, 0, &view, &light, 1, &foreign), UMBRAGE_SUCCESS);
    {
        UmbrageFrameStats st;
        UmbrageLightInfo li;
        UmbrageDepthStencilTarget t;
        VkExtent2D e = {64, 64};
        memset(&st, 0, sizeof st);
        memset(&li, 0, sizeof li);
        expect("frame_get_stats: sType not set", umbrage_frame_get_stats(pass, frame, &st), UMBRAGE_ERROR_STRUCTURE_TYPE);
        st.sType = UMBRAGE_STRUCTURE_TYPE_FRAME_STATS;
        expect("frame_get_stats", umbrage_frame_get_stats(pass, frame, &st), UMBRAGE_SUCCESS);
        expect_true("frame_get_stats: a cube casts triangles", st.sideTriangles > 0);
        li.sType = UMBRAGE_STRUCTURE_TYPE_LIGHT_INFO;
        expect("frame_get_light", umbrage_frame_get_light(pass, frame, 0, &li), UMBRAGE_SUCCESS);
        expect_true("frame_get_light: a scissor inside the target",
                    li.scissor.extent.width <= 64 && li.scissor.extent.height <= 64 && li.minDepthBounds <= li.maxDepthBounds);
        expect("frame_get_light: light 1 of 1", umbrage_frame_get_light(pass, frame, 1, &li), UMBRAGE_ERROR_LIGHT_INDEX);
        expect("frame_get_stats: another pass's frame", umbrage_frame_get_stats(pass, foreign, &st), UMBRAGE_ERROR_FOREIGN_FRAME);
        memset(&t, 0, sizeof t);
        t.sType = UMBRAGE_STRUCTURE_TYPE_DEPTH_STENCIL_TARGET;
        t.extent.width = 32;
        t.extent.height = 64;
        /* refused before anything is recorded: no command buffer is needed to test these */
        expect("cmd_determine: a target of the wrong size", umbrage_cmd_determine(pass, VK_NULL_HANDLE, frame, 0, &t), UMBRAGE_ERROR_ARGUMENT);
        t.extent.width = 64;
        expect("cmd_determine: light 3 of 1", umbrage_cmd_determine(pass, VK_NULL_HANDLE, frame, 3, &t), UMBRAGE_ERROR_LIGHT_INDEX);
        expect("cmd_determine: NULL target", umbrage_cmd_determine(pass, VK_NULL_HANDLE, frame, 0, NULL), UMBRAGE_ERROR_NULL_POINTER);
        expect("cmd_determine: another pass's frame", umbrage_cmd_determine(pass, VK_NULL_HANDLE, foreign, 0, &t), UMBRAGE_ERROR_FOREIGN_FRAME);
        expect("cmd_light_state: light 1 of 1", umbrage_cmd_light_state(pass, VK_NULL_HANDLE, frame, 1, e), UMBRAGE_ERROR_LIGHT_INDEX);
        expect("cmd_light_intensity: no transmit format", umbrage_cmd_light_intensity(pass, VK_NULL_HANDLE, frame, 0, &t, VK_NULL_HANDLE, 0),
               UMBRAGE_ERROR_NOT_CONFIGURED);
        {
            UmbrageKeepStats ks;
            UmbragePassSettings ps;
            UmbrageFrame foreign2;
            struct {
                UmbrageStructureType sType;
                void *pNext;
            } unknown = {(UmbrageStructureType)999, NULL};
            memset(&ks, 0, sizeof ks);
            ks.sType = UMBRAGE_STRUCTURE_TYPE_KEEP_STATS;
            st.pNext = &ks;
            expect("frame_get_stats: with UmbrageKeepStats", umbrage_frame_get_stats(pass, frame, &st), UMBRAGE_SUCCESS);
            expect_true("keep stats: the cube's pair drawn, planned or kept",
                        ks.pairsTotal > 0 && ks.pairsKept + ks.pairsReplanned == ks.pairsTotal && st.pNext == &ks);
            expect("prepare: slot 1, nothing moved", umbrage_pass_prepare(pass, 1, &view, &light, 1, &frame2), UMBRAGE_SUCCESS);
            expect("frame_get_stats: slot 1", umbrage_frame_get_stats(pass, frame2, &st), UMBRAGE_SUCCESS);
            expect_true("keep stats: nothing moved, every pair kept, nothing sent for it",
                        ks.pairsTotal > 0 && ks.pairsKept == ks.pairsTotal && ks.pairsReplanned == 0 && ks.keptBytes > 0);
            /* the pass that keeps nothing, its settings set again (they do not carry keeping) */
            expect("get_settings: the other pass", umbrage_pass_get_settings(other, &ps), UMBRAGE_SUCCESS);
            expect("set_settings: the other pass", umbrage_pass_set_settings(other, &ps), UMBRAGE_SUCCESS);
            expect("prepare: the other pass, slot 1", umbrage_pass_prepare(other, 1, &view, &light, 1, &foreign2), UMBRAGE_SUCCESS);
            expect("frame_get_stats: the other pass", umbrage_frame_get_stats(other, foreign2, &st), UMBRAGE_SUCCESS);
            expect_true("keep stats: UmbrageKeepInfo::disableKeep plans every pair, after set_settings too",
                        ks.pairsTotal > 0 && ks.pairsKept == 0 && ks.pairsReplanned == ks.pairsTotal && ks.keptBytes == 0);
            ks.pNext = &unknown;
            expect("frame_get_stats: an unknown struct chained", umbrage_frame_get_stats(pass, frame2, &st), UMBRAGE_ERROR_STRUCTURE_TYPE);
            st.pNext = NULL;
        }
        stale = frame;
        expect("frame_get_stats: slot 0's frame still live", umbrage_frame_get_stats(pass, stale, &st), UMBRAGE_SUCCESS);
        expect("prepare: slot 1 again", umbrage_pass_prepare(pass, 1, &view, &light, 1, &frame2), UMBRAGE_SUCCESS);
        expect("prepare: slot 0 again", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_SUCCESS);
        expect("frame_get_stats: a stale frame", umbrage_frame_get_stats(pass, stale, &st), UMBRAGE_ERROR_STALE_FRAME);
        expect("cmd_upload: a stale frame", umbrage_cmd_upload(pass, VK_NULL_HANDLE, stale), UMBRAGE_ERROR_STALE_FRAME);
        stale.slot = 7;
        expect("frame_get_stats: a made-up slot", umbrage_frame_get_stats(pass, stale, &st), UMBRAGE_ERROR_SLOT_OUT_OF_RANGE);
        expect("abandon_frame: slot 2 of 2", umbrage_pass_abandon_frame(pass, 2), UMBRAGE_ERROR_SLOT_OUT_OF_RANGE);
        expect("abandon_frame", umbrage_pass_abandon_frame(pass, 0), UMBRAGE_SUCCESS);
    }
    {
        double plane[4] = {0, 0, 0, 1};
        expect("set_planar_receiver: a zero normal", umbrage_pass_set_planar_receiver(pass, plane), UMBRAGE_ERROR_ARGUMENT);
        plane[1] = 1.0;
        expect("set_planar_receiver", umbrage_pass_set_planar_receiver(pass, plane), UMBRAGE_SUCCESS);
    }
    {
        VkStencilOpState s;
        expect("lit_stencil_state", umbrage_lit_stencil_state(&s), UMBRAGE_SUCCESS);
        expect_true("lit_stencil_state: EQUAL 0, no writes", s.compareOp == VK_COMPARE_OP_EQUAL && s.reference == 0 && s.writeMask == 0);
    }

    /* ---- the last error message: sized, cut and terminated ---- */
    {
        char small[8];
        size_t n;
        expect("a failing call", umbrage_pass_remove_caster(pass, 0), UMBRAGE_ERROR_UNKNOWN_ID);
        n = umbrage_last_error_message(NULL, 0);
        memset(small, 'x', sizeof small);
        expect_true("last_error_message: the length without a buffer", n > sizeof small);
        expect_true("last_error_message: cut and terminated", umbrage_last_error_message(small, sizeof small) == n && small[7] == 0);
    }

#ifdef UMBRAGE_TEST_PANIC
    expect("an injected panic", umbrage_test_inject_panic(other), UMBRAGE_ERROR_PANIC);
    expect_message("the panic's message", "injected");
    expect("a poisoned pass refuses", umbrage_pass_get_settings(other, &settings), UMBRAGE_ERROR_POISONED);
    expect("a poisoned pass refuses prepare", umbrage_pass_prepare(other, 0, &view, &light, 1, &foreign), UMBRAGE_ERROR_POISONED);
    expect("a poisoned pass is destroyed", umbrage_pass_destroy(other), UMBRAGE_SUCCESS);
#else
    printf("contract: built without UMBRAGE_TEST_PANIC: the panic checks need the test-panic build\n");
    expect("destroy the other pass", umbrage_pass_destroy(other), UMBRAGE_SUCCESS);
#endif
    expect("destroy", umbrage_pass_destroy(pass), UMBRAGE_SUCCESS);
    expect("a destroyed pass", umbrage_pass_get_settings(pass, &settings), UMBRAGE_ERROR_ARGUMENT);
    expect("a destroyed pass: prepare", umbrage_pass_prepare(pass, 0, &view, &light, 1, &frame), UMBRAGE_ERROR_ARGUMENT);
    expect("destroy twice", umbrage_pass_destroy(pass), UMBRAGE_ERROR_ARGUMENT);
    expect("destroy NULL", umbrage_pass_destroy(NULL), UMBRAGE_SUCCESS);
    expect("a made-up handle", umbrage_pass_get_settings((UmbragePass)(uintptr_t)12345678, &settings), UMBRAGE_ERROR_ARGUMENT);
    expect("NULL pass", umbrage_pass_get_settings(NULL, &settings), UMBRAGE_ERROR_NULL_POINTER);

    vkDestroyDevice(device, NULL);
    vkDestroyInstance(instance, NULL);
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}

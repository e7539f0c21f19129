// umbrage-cpp-host: the shadow pass from C++17 through the RAII wrapper (umbrage.hpp) on one
// scene: a Vulkan 1.3 device, a depth-stencil image cleared to the far plane (this host has no
// pre-pass: every shadow volume counts), two frames in flight, each light's determination, and
// the stencil read back. It checks what the wrapper promises: a stale frame throws
// umbrage::Error with UMBRAGE_ERROR_STALE_FRAME, and the pass is destroyed by its owner. With
// UMBRAGE_VALIDATION set (not 0) the Khronos validation layer runs with synchronisation
// validation, from vkCreateInstance to vkDestroyInstance; any error or warning fails the run.
//   umbrage-cpp-host [--scene FILE|NAME]     (as umbrage-c-host: an `umbrage export-scene` file)
#include "umbrage.hpp"
#include "scene.h"

#include <vulkan/vulkan.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <unistd.h>

namespace {

uint32_t validation_messages = 0;

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
    ++validation_messages;
    std::fprintf(stderr, "validation %s: %s\n", (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning",
                 data->pMessage);
    return VK_FALSE;
}

void vk_check(VkResult r, const char* call) {
    if (r != VK_SUCCESS) throw std::runtime_error(std::string(call) + " failed: VkResult " + std::to_string(static_cast<int>(r)));
}

std::string scene_file(const char* spec) {
    std::string s = spec ? spec : "default";
    if (s.find('/') != std::string::npos || access(s.c_str(), R_OK) == 0) return s;
    if (const char* dir = std::getenv("UMBRAGE_SCENE_DIR")) return std::string(dir) + "/" + s + ".scene";
    char exe[1024];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    std::string dir = n > 0 ? std::string(exe, static_cast<size_t>(n)) : std::string(".");
    dir = dir.substr(0, dir.rfind('/'));
    return dir + "/../share/umbrage/scenes/" + s + ".scene";
}

uint32_t memory_type(VkPhysicalDevice physical, uint32_t bits, VkMemoryPropertyFlags want) {
    VkPhysicalDeviceMemoryProperties p;
    vkGetPhysicalDeviceMemoryProperties(physical, &p);
    for (uint32_t i = 0; i < p.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (p.memoryTypes[i].propertyFlags & want) == want) return i;
    throw std::runtime_error("no memory type");
}

int run(int argc, char** argv) {
    const char* spec = argc > 2 && std::strcmp(argv[1], "--scene") == 0 ? argv[2] : nullptr;
    HostScene scene;
    if (scene_load(scene_file(spec).c_str(), &scene) != 0) return 1;
    const uint32_t w = 160, h = 100;

    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ii{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ii.pApplicationInfo = &app;
    const char* env = std::getenv("UMBRAGE_VALIDATION");
    const bool validation = env && std::strcmp(env, "0") != 0;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* debug_ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    mci.pfnUserCallback = on_validation;
    if (validation) {
        features.enabledValidationFeatureCount = 1;
        features.pEnabledValidationFeatures = &sync;
        features.pNext = &mci;  // the messenger of vkCreateInstance and vkDestroyInstance themselves
        ii.pNext = &features;
        ii.enabledLayerCount = 1;
        ii.ppEnabledLayerNames = &layer;
        ii.enabledExtensionCount = 1;
        ii.ppEnabledExtensionNames = &debug_ext;
    }
    VkInstance instance;
    vk_check(vkCreateInstance(&ii, nullptr, &instance), "vkCreateInstance");
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    auto destroy_messenger =
        reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (validation) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
        vk_check(create(instance, &mci, nullptr, &messenger), "vkCreateDebugUtilsMessengerEXT");
    }
    uint32_t count = 1;
    VkPhysicalDevice physical;
    VkResult er = vkEnumeratePhysicalDevices(instance, &count, &physical);
    if ((er != VK_SUCCESS && er != VK_INCOMPLETE) || count == 0) throw std::runtime_error("no Vulkan device");
    float priority = 1.0f;
    VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qi.queueFamilyIndex = 0;
    qi.queueCount = 1;
    qi.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    v13.dynamicRendering = VK_TRUE;
    VkDeviceCreateInfo di{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    di.pNext = &v13;
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &qi;
    VkDevice device;
    vk_check(vkCreateDevice(physical, &di, nullptr, &device), "vkCreateDevice");
    VkQueue queue;
    vkGetDeviceQueue(device, 0, 0, &queue);

    const VkFormat format = VK_FORMAT_D32_SFLOAT_S8_UINT;
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = format;
    ici.extent = {w, h, 1};
    ici.mipLevels = ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    VkImage image;
    vk_check(vkCreateImage(device, &ici, nullptr, &image), "vkCreateImage");
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, image, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = memory_type(physical, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory image_memory;
    vk_check(vkAllocateMemory(device, &ai, nullptr, &image_memory), "vkAllocateMemory");
    vk_check(vkBindImageMemory(device, image, image_memory, 0), "vkBindImageMemory");
    VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vci.image = image;
    vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vci.format = format;
    vci.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT, 0, 1, 0, 1};
    VkImageView view;
    vk_check(vkCreateImageView(device, &vci, nullptr, &view), "vkCreateImageView");
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = w * h;
    bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer readback;
    vk_check(vkCreateBuffer(device, &bci, nullptr, &readback), "vkCreateBuffer");
    vkGetBufferMemoryRequirements(device, readback, &req);
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = memory_type(physical, req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VkDeviceMemory readback_memory;
    vk_check(vkAllocateMemory(device, &ai, nullptr, &readback_memory), "vkAllocateMemory");
    vk_check(vkBindBufferMemory(device, readback, readback_memory, 0), "vkBindBufferMemory");
    void* mapped = nullptr;
    vk_check(vkMapMemory(device, readback_memory, 0, VK_WHOLE_SIZE, 0, &mapped), "vkMapMemory");
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    VkCommandPool pool;
    vk_check(vkCreateCommandPool(device, &pci, nullptr, &pool), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    VkCommandBuffer cb;
    vk_check(vkAllocateCommandBuffers(device, &cai, &cb), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    vk_check(vkCreateFence(device, &fci, nullptr, &fence), "vkCreateFence");

    int failures = 0;
    {
        // UMBRAGE: the pass, owned by this scope.
        UmbrageVulkanDevice vk{};
        vk.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
        vk.instance = instance;
        vk.physicalDevice = physical;
        vk.device = device;
        UmbragePassCreateInfo info = umbrage::pass_create_info();
        info.depthStencilFormat = format;
        umbrage::Pass pass(vk, info);
        for (uint32_t m = 0; m < scene.mesh_count; ++m) {
            const HostMesh& hm = scene.meshes[m];
            if (!hm.casts_shadow) continue;
            std::array<double, 16> t{};
            for (size_t i = 0; i < 16; ++i) t[i] = hm.transform[i];
            pass.add_caster(hm.name, std::vector<float>(hm.positions, hm.positions + 3 * hm.vertex_count),
                            std::vector<uint32_t>(hm.triangles, hm.triangles + 3 * hm.triangle_count), t);
        }
        // The camera: look-at with translation, infinite forward projection (column-major).
        UmbrageView v{};
        v.sType = UMBRAGE_STRUCTURE_TYPE_VIEW;
        float f[3], s[3], u[3];
        for (int i = 0; i < 3; ++i) f[i] = scene.target[i] - scene.eye[i];
        auto norm = [](float* x) {
            float l = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            for (int i = 0; i < 3; ++i) x[i] /= l;
        };
        norm(f);
        s[0] = f[1] * scene.up[2] - f[2] * scene.up[1];
        s[1] = f[2] * scene.up[0] - f[0] * scene.up[2];
        s[2] = f[0] * scene.up[1] - f[1] * scene.up[0];
        norm(s);
        u[0] = s[1] * f[2] - s[2] * f[1];
        u[1] = s[2] * f[0] - s[0] * f[2];
        u[2] = s[0] * f[1] - s[1] * f[0];
        const float* e = scene.eye;
        const float view_m[16] = {s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
                                  -(e[0] * s[0] + e[1] * s[1] + e[2] * s[2]), -(e[0] * u[0] + e[1] * u[1] + e[2] * u[2]),
                                  e[0] * f[0] + e[1] * f[1] + e[2] * f[2], 1};
        const float fy = 1.0f / std::tan(scene.fov_y_deg * 3.14159265f / 360.0f);
        const float proj[16] = {fy * h / w, 0, 0, 0, 0, -fy, 0, 0, 0, 0, -1, -1, 0, 0, -scene.near_plane, 0};
        for (int i = 0; i < 3; ++i) v.eye[i] = scene.eye[i];
        std::memcpy(v.view, view_m, sizeof view_m);
        std::memcpy(v.projection, proj, sizeof proj);
        v.width = w;
        v.height = h;
        std::vector<UmbrageLight> lights(scene.light_count);
        for (uint32_t i = 0; i < scene.light_count; ++i) {
            lights[i].kind = static_cast<UmbrageLightKind>(scene.lights[i].kind);
            std::memcpy(lights[i].position, scene.lights[i].position, sizeof lights[i].position);
            std::memcpy(lights[i].direction, scene.lights[i].direction, sizeof lights[i].direction);
            lights[i].coneDeg = scene.lights[i].cone_deg;
            lights[i].radius = scene.lights[i].radius;
        }
        UmbrageFrame stale{};
        for (uint32_t frame_no = 0; frame_no < 3; ++frame_no) {
            UmbrageFrame frame = pass.prepare(frame_no % 2, v, lights);
            if (frame_no == 0) stale = frame;
            VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
            vk_check(vkBeginCommandBuffer(cb, &bi), "vkBeginCommandBuffer");
            pass.cmd_before_rendering(cb, frame);
            VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
            b.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
            b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
            b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
            b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            b.image = image;
            b.subresourceRange = vci.subresourceRange;
            vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &b);
            VkClearDepthStencilValue clear{1.0f, 0};
            vkCmdClearDepthStencilImage(cb, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &clear, 1, &vci.subresourceRange);
            UmbrageDepthStencilTarget t{};
            t.sType = UMBRAGE_STRUCTURE_TYPE_DEPTH_STENCIL_TARGET;
            t.image = image;
            t.view = view;
            t.extent = {w, h};
            t.layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
            t.finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
            // UMBRAGE: light 0's count into the stencil (the pass records both layout transitions).
            if (!lights.empty()) pass.cmd_determine(cb, frame, 0, t);
            VkBufferImageCopy copy{};
            copy.imageSubresource = {VK_IMAGE_ASPECT_STENCIL_BIT, 0, 0, 1};
            copy.imageExtent = {w, h, 1};
            if (!lights.empty()) vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, 1, &copy);
            VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
            mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
            vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
            vk_check(vkEndCommandBuffer(cb), "vkEndCommandBuffer");
            VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
            si.commandBufferCount = 1;
            si.pCommandBuffers = &cb;
            vk_check(vkQueueSubmit(queue, 1, &si, fence), "vkQueueSubmit");
            vk_check(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
            vk_check(vkResetFences(device, 1, &fence), "vkResetFences");
            const auto* st = static_cast<const uint8_t*>(mapped);
            uint32_t counted = 0;
            for (uint32_t i = 0; i < w * h && !lights.empty(); ++i) counted += st[i] != 0;
            UmbrageFrameStats stats = pass.stats(frame);
            std::printf("umbrage-cpp-host: frame %u: %llu shadow triangles, light 0 counts in %u of %u pixels\n", frame_no,
                        static_cast<unsigned long long>(stats.sideTriangles + stats.darkCapTriangles + stats.lightCapTriangles), counted,
                        w * h);
        }
        // Slot 0 was prepared again since `stale`: the wrapper throws with its code.
        try {
            pass.stats(stale);
            std::fprintf(stderr, "umbrage-cpp-host: a stale frame was accepted\n");
            ++failures;
        } catch (const umbrage::Error& err) {
            if (err.code() != UMBRAGE_ERROR_STALE_FRAME) {
                std::fprintf(stderr, "umbrage-cpp-host: stale frame gave code %d: %s\n", static_cast<int>(err.code()), err.what());
                ++failures;
            } else {
                std::printf("umbrage-cpp-host: stale frame refused: %s\n", err.what());
            }
        }
        vk_check(vkDeviceWaitIdle(device), "vkDeviceWaitIdle");
    }  // the pass is destroyed here, before the device
    vkDestroyFence(device, fence, nullptr);
    vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyBuffer(device, readback, nullptr);
    vkFreeMemory(device, readback_memory, nullptr);
    vkDestroyImageView(device, view, nullptr);
    vkDestroyImage(device, image, nullptr);
    vkFreeMemory(device, image_memory, nullptr);
    vkDestroyDevice(device, nullptr);
    if (messenger) destroy_messenger(instance, messenger, nullptr);
    vkDestroyInstance(instance, nullptr);
    scene_free(&scene);
    if (validation_messages) {
        std::fprintf(stderr, "umbrage-cpp-host: %u validation message(s)\n", validation_messages);
        ++failures;
    }
    if (!failures) std::printf("umbrage-cpp-host: ok%s\n", validation ? " (validation on, no message)" : "");
    return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "umbrage-cpp-host: %s\n", e.what());
        return 1;
    }
}

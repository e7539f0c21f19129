#!/usr/bin/env python3
"""Extracts the gpuinfo.org device reports of Khronos' Vulkan-Profiles repository into
tests/data/devices/: one JSON file per device, in the reports' own schema, cut down to what
umbrage's device selection reads (src/gpu/caps.rs, src/profiles.rs).

    scripts/device-reports.py GIT_DIR_OR_CHECKOUT [OUT_DIR]

The reports live under profiles/LunarG/VP_LUNARG_desktop_*/vp_gpuinfo_*.json (the same report
may sit in several profile folders: the newest folder's copy is kept). The cut keeps the
schema, so `umbrage devices` reads a full report and an extract alike. The source commit is
written to OUT_DIR/SOURCE.md (the reports are Apache-2.0, exported from vulkan.gpuinfo.org).
"""
import json
import os
import subprocess
import sys

# Features umbrage asks for, by the structure the reports file them under.
FEATURES = {
    "VkPhysicalDeviceFeatures": [
        "depthClamp", "depthBounds", "pipelineStatisticsQuery", "occlusionQueryPrecise",
        "geometryShader", "sampleRateShading", "multiDrawIndirect", "drawIndirectFirstInstance",
    ],
    "VkPhysicalDeviceVulkan11Features": ["multiview"],
    "VkPhysicalDeviceMultiviewFeaturesKHR": ["multiview"],
    "VkPhysicalDeviceVulkan12Features": ["drawIndirectCount", "bufferDeviceAddress"],
    "VkPhysicalDeviceVulkan13Features": ["dynamicRendering", "synchronization2"],
    "VkPhysicalDeviceDynamicRenderingFeaturesKHR": ["dynamicRendering"],
    "VkPhysicalDeviceSynchronization2FeaturesKHR": ["synchronization2"],
    "VkPhysicalDeviceIndexTypeUint8FeaturesEXT": ["indexTypeUint8"],
    "VkPhysicalDeviceIndexTypeUint8FeaturesKHR": ["indexTypeUint8"],
    "VkPhysicalDeviceAccelerationStructureFeaturesKHR": ["accelerationStructure"],
    "VkPhysicalDeviceRayQueryFeaturesKHR": ["rayQuery"],
    "VkPhysicalDeviceBufferDeviceAddressFeaturesKHR": ["bufferDeviceAddress"],
    "VkPhysicalDeviceMeshShaderFeaturesEXT": ["taskShader", "meshShader"],
}
LIMITS = [
    "maxPushConstantsSize", "maxImageDimension2D", "maxDrawIndirectCount", "maxBoundDescriptorSets",
    "framebufferColorSampleCounts", "framebufferDepthSampleCounts", "framebufferStencilSampleCounts",
    "sampledImageColorSampleCounts", "sampledImageIntegerSampleCounts", "sampledImageDepthSampleCounts",
    "sampledImageStencilSampleCounts", "timestampPeriod", "standardSampleLocations",
    "maxComputeWorkGroupInvocations", "maxStorageBufferRange",
]
PROPERTIES = ["apiVersion", "deviceName", "deviceType", "vendorID", "deviceID", "driverVersion"]
EXTENSIONS = [
    "VK_KHR_portability_subset", "VK_EXT_depth_range_unrestricted", "VK_EXT_index_type_uint8",
    "VK_KHR_index_type_uint8", "VK_KHR_acceleration_structure", "VK_KHR_ray_query",
    "VK_KHR_deferred_host_operations", "VK_EXT_mesh_shader", "VK_KHR_draw_indirect_count",
    "VK_KHR_dynamic_rendering", "VK_KHR_synchronization2", "VK_KHR_multiview",
    "VK_KHR_driver_properties", "VK_EXT_depth_clip_enable", "VK_EXT_extended_dynamic_state",
]
FORMATS = [
    "VK_FORMAT_D16_UNORM_S8_UINT", "VK_FORMAT_D24_UNORM_S8_UINT", "VK_FORMAT_D32_SFLOAT_S8_UINT",
    "VK_FORMAT_D32_SFLOAT", "VK_FORMAT_R32_SFLOAT", "VK_FORMAT_R32G32B32A32_SFLOAT",
    "VK_FORMAT_R16G16B16A16_SFLOAT", "VK_FORMAT_R8G8B8A8_UNORM", "VK_FORMAT_B8G8R8A8_UNORM",
    "VK_FORMAT_R32_UINT", "VK_FORMAT_R8_UINT",
]


def git(repo, *args):
    return subprocess.run(["git", "-C", repo, *args], check=True, capture_output=True, text=True).stdout


def cut(report):
    dev = report["capabilities"]["device"]
    features = {
        s: {k: dev["features"][s][k] for k in keys if k in dev["features"][s]}
        for s, keys in FEATURES.items() if s in dev["features"]
    }
    props = dev["properties"]
    base = props["VkPhysicalDeviceProperties"]
    out_props = {"VkPhysicalDeviceProperties": {k: base[k] for k in PROPERTIES if k in base}}
    out_props["VkPhysicalDeviceProperties"]["limits"] = {k: base["limits"][k] for k in LIMITS if k in base["limits"]}
    for drv in ("VkPhysicalDeviceDriverProperties", "VkPhysicalDeviceDriverPropertiesKHR"):
        if drv in props:
            out_props[drv] = {k: props[drv][k] for k in ("driverID", "driverName", "driverInfo") if k in props[drv]}
    exts = {k: v for k, v in dev.get("extensions", {}).items() if k in EXTENSIONS}
    formats = {
        f: {"VkFormatProperties": {"optimalTilingFeatures": dev["formats"][f]["VkFormatProperties"]["optimalTilingFeatures"]}}
        for f in FORMATS if f in dev.get("formats", {})
    }
    queues = [
        {"VkQueueFamilyProperties": {k: q["VkQueueFamilyProperties"][k] for k in ("queueFlags", "timestampValidBits")}}
        for q in dev.get("queueFamiliesProperties", [])
    ]
    profile = next(iter(report["profiles"].values()))
    return {
        "profiles": {"report": {k: profile[k] for k in ("label", "api-version") if k in profile}},
        "capabilities": {"device": {
            "features": features, "properties": out_props, "extensions": exts,
            "formats": formats, "queueFamiliesProperties": queues,
        }},
    }


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    repo = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "tests", "data", "devices")
    os.makedirs(out, exist_ok=True)
    commit = git(repo, "rev-parse", "HEAD").strip()
    date = git(repo, "log", "-1", "--format=%cs").strip()
    paths = [p for p in git(repo, "ls-tree", "-r", "--name-only", "HEAD").split("\n")
             if "/vp_gpuinfo_" in p and p.startswith("profiles/LunarG/VP_LUNARG_desktop_")]
    newest = {}
    for p in sorted(paths):  # folders sort by year: the last copy wins
        newest[os.path.basename(p)] = p
    for name, p in sorted(newest.items()):
        report = json.loads(git(repo, "show", f"HEAD:{p}"))
        stem = name[len("vp_gpuinfo_"):]
        with open(os.path.join(out, stem), "w") as f:
            json.dump(cut(report), f, sort_keys=True, separators=(",", ":"))
            f.write("\n")
    with open(os.path.join(out, "SOURCE.md"), "w") as f:
        f.write(
            f"# Device reports\n\nCut down by `scripts/device-reports.py` from the {len(newest)} gpuinfo.org reports "
            f"(`profiles/LunarG/VP_LUNARG_desktop_*/vp_gpuinfo_*.json`) of "
            f"[KhronosGroup/Vulkan-Profiles](https://github.com/KhronosGroup/Vulkan-Profiles) at commit `{commit}` "
            f"({date}); Apache-2.0, exported from https://vulkan.gpuinfo.org by Sascha Willems. Only the fields "
            f"umbrage's device selection reads are kept, in the reports' own schema. `tests/engine/devices.rs` turns "
            f"them into `docs/devices.md`.\n"
        )
    print(f"{len(newest)} reports -> {out}")


if __name__ == "__main__":
    main()

// raster/vulkan_functions.cpp: dlopen()s the Vulkan loader and fills the function pointers.
#include "raster/vulkan_functions.h"

#include <dlfcn.h>

#include <mutex>
#include <string>
#include <string_view>

#include "raster/vulkan_error.h"

namespace shadowlab::raster {

#define SHADOWLAB_VK_DEFINE(name) PFN_##name name = nullptr;
PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
SHADOWLAB_VK_GLOBAL_FUNCTIONS(SHADOWLAB_VK_DEFINE)
SHADOWLAB_VK_INSTANCE_FUNCTIONS(SHADOWLAB_VK_DEFINE)
#undef SHADOWLAB_VK_DEFINE

namespace {

std::mutex loaderMutex;
void* loaderLibrary = nullptr;  // kept open for the life of the process

}  // namespace

void loadVulkanLoader() {
    const std::lock_guard lock(loaderMutex);
    if (loaderLibrary) return;
    void* library = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!library) {
        const char* why = dlerror();
        throw RasterError(std::string("the Vulkan loader libvulkan.so.1 could not be loaded (") +
                          (why ? why : "unknown reason") +
                          "); install the Debian package libvulkan1 (and mesa-vulkan-drivers for "
                          "the lavapipe CPU driver)");
    }
    auto getProc = reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(library, "vkGetInstanceProcAddr"));
    if (!getProc) {
        dlclose(library);
        throw RasterError(
            "libvulkan.so.1 has no vkGetInstanceProcAddr: the Vulkan loader is broken; "
            "reinstall the Debian package libvulkan1");
    }
    vkGetInstanceProcAddr = getProc;
#define SHADOWLAB_VK_LOAD_GLOBAL(name) \
    name = reinterpret_cast<PFN_##name>(vkGetInstanceProcAddr(VK_NULL_HANDLE, #name));
    SHADOWLAB_VK_GLOBAL_FUNCTIONS(SHADOWLAB_VK_LOAD_GLOBAL)
#undef SHADOWLAB_VK_LOAD_GLOBAL
    if (!vkCreateInstance || !vkEnumerateInstanceLayerProperties || !vkEnumerateInstanceExtensionProperties)
        throw RasterError("the Vulkan loader libvulkan.so.1 lacks vkCreateInstance; reinstall libvulkan1");
    // vkEnumerateInstanceVersion is missing from Vulkan 1.0 loaders; callers treat null as 1.0.
    loaderLibrary = library;
}

void loadInstanceFunctions(VkInstance instance) {
    const std::lock_guard lock(loaderMutex);
    const char* missing = nullptr;
    // The loader returns trampolines that dispatch on the object they are given, so pointers
    // from one instance work for every other. An extension function missing from this instance
    // (debug utils without validation) keeps the pointer an earlier instance loaded, which a
    // still-living messenger of that instance needs to be destroyed. The host-pointer import
    // (VK_EXT_external_memory_host) is optional too: without it the lit pass's targets are copied.
#define SHADOWLAB_VK_LOAD_INSTANCE(name)                                                                 \
    if (const auto p_ = reinterpret_cast<PFN_##name>(vkGetInstanceProcAddr(instance, #name))) name = p_; \
    if (!name && !missing && std::string_view(#name).find("DebugUtils") == std::string_view::npos &&     \
        std::string_view(#name).find("HostPointer") == std::string_view::npos)                           \
        missing = #name;
    SHADOWLAB_VK_INSTANCE_FUNCTIONS(SHADOWLAB_VK_LOAD_INSTANCE)
#undef SHADOWLAB_VK_LOAD_INSTANCE
    // The extension functions above may be missing; the rest are core.
    if (missing)
        throw RasterError(std::string("the Vulkan loader does not provide ") + missing +
                          " (Vulkan 1.3 is required); update libvulkan1 and mesa-vulkan-drivers");
}

}  // namespace shadowlab::raster

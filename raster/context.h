// raster/context.h: the headless Vulkan context: instance (with the validation layer and a
// message counter when asked), the selected physical device, a logical device with one graphics
// queue and a command pool. No window, no swapchain, no surface extensions.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "raster/devices.h"
#include "raster/handles.h"

namespace shadowlab::raster {

// Counts what the validation layer reports: every message of severity warning or error, and
// info messages of type VALIDATION. Each is printed to stderr as it arrives. It outlives the
// Context, so messages raised while the device and instance are destroyed count too.
struct ValidationLog {
    std::atomic<int> count{0};
    std::mutex mutex;
    std::vector<std::string> messages;
    bool echo = true;  // print each message to stderr
};

struct ContextOptions {
    std::string device;            // selector, see selectDevice()
    bool validate = false;         // enable VK_LAYER_KHRONOS_validation + debug messenger
    ValidationLog* log = nullptr;  // required when validate
};

// Members are declared in creation order; the destructor runs in reverse.
struct Context {
    explicit Context(const ContextOptions& options);
    ~Context();  // saves the pipeline cache
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    InstanceHandle instance;
    MessengerHandle messenger;
    VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
    DeviceReport deviceReport;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceMemoryProperties memoryProperties{};
    bool independentBlend = false;  // enabled when supported (the transmittance pass needs it)
    // VK_EXT_external_memory_host, enabled when supported (lavapipe): images over host memory the
    // program owns, so the lit pass renders straight into a Frame's vectors (raster/lit_pass.h).
    bool hostPointerImport = false;
    VkDeviceSize minImportedHostPointerAlignment = 0;
    std::uint32_t queueFamily = 0;
    LogicalDeviceHandle device;
    VkQueue queue = VK_NULL_HANDLE;
    CommandPoolHandle commandPool;
    // Every pipeline is created through it. Loaded from and saved to pipelineCacheFile (empty:
    // no cache folder), named by the device's vendor, device id and pipelineCacheUUID.
    // Lavapipe keeps no code in it (a 32-byte header; its warm start is Mesa's shader cache),
    // real drivers keep their compiled pipelines.
    PipelineCacheHandle pipelineCache;
    std::filesystem::path pipelineCacheFile;

    // A memory type allowed by `typeBits` with all of `required`; among those, one with all of
    // `preferred` when there is one. Throws RasterError when none fits.
    std::uint32_t memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                             VkMemoryPropertyFlags preferred = 0) const;
    // A primary command buffer in the recording state, freed with the pool.
    VkCommandBuffer beginCommands() const;
    // Ends `commands`, submits it and waits for it to finish.
    void submitAndWait(VkCommandBuffer commands) const;
};

// A Vulkan instance for listing devices or rendering. Sets MESA_SHADER_CACHE_DIR first when
// the user has not, so lavapipe reuses compiled shaders between runs.
// With `validate`, `messengerInfo` is chained so that instance creation is checked too.
InstanceHandle createInstance(bool validate, const VkDebugUtilsMessengerCreateInfoEXT* messengerInfo);
VkDebugUtilsMessengerCreateInfoEXT messengerCreateInfo(ValidationLog* log);
// Reports for every physical device of `instance` (isDefault not yet set).
std::vector<DeviceReport> describePhysicalDevices(VkInstance instance,
                                                  std::vector<VkPhysicalDevice>* handles = nullptr);

}  // namespace shadowlab::raster

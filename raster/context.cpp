// raster/context.cpp: instance, validation messenger, device selection, logical device, and
// the submit helpers every pass uses.
#include "raster/context.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <sstream>

#include "raster/vulkan_error.h"
#include "scene/frame_io.h"
#include "scene/input_file.h"

namespace shadowlab::raster {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

// Lavapipe compiles shaders with LLVM on first use; its disk cache makes warm starts fast.
// Point it into our own cache folder unless the user chose one.
// The user's cache folder for shadowlab ($XDG_CACHE_HOME/shadowlab or ~/.cache/shadowlab), empty
// when neither is set.
std::filesystem::path cacheDirectory() {
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "shadowlab";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::filesystem::path(home) / ".cache" / "shadowlab";
    return {};
}

void setShaderCacheDir() {
    if (std::getenv("MESA_SHADER_CACHE_DIR")) return;
    const std::filesystem::path base = cacheDirectory();
    if (base.empty()) return;  // no place to put it: Mesa's own default applies
    const std::filesystem::path dir = base / "mesa";
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (!ec) setenv("MESA_SHADER_CACHE_DIR", dir.c_str(), 0);
}

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT types,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* userData) {
    const bool counted = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT ||
                         (severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT &&
                          (types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT));
    // Two INFO messages report no problem with our use of Vulkan, so they are not counted: the
    // layer's start-up banner, and, on a fresh machine, the note that its own shader-validation
    // cache file does not exist yet (~/.cache/shader_validation_cache-0.bin).
    const bool banner =
        data && data->pMessageIdName && severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT &&
        (std::strcmp(data->pMessageIdName, "UNASSIGNED-khronos-validation-createinstance-status-message") == 0 ||
         std::strcmp(data->pMessageIdName, "UNASSIGNED-cache-file-error") == 0);
    if (!counted || banner || !userData) return VK_FALSE;
    auto* log = static_cast<ValidationLog*>(userData);
    const char* level = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT     ? "error"
                        : severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT ? "warning"
                                                                                      : "info";
    const std::string text =
        std::string("vulkan validation ") + level + ": " + (data && data->pMessage ? data->pMessage : "(no message)");
    log->count.fetch_add(1);
    const std::lock_guard lock(log->mutex);
    log->messages.push_back(text);
    if (log->echo) std::cerr << "shadowlab: " << text << "\n";
    return VK_FALSE;  // never abort the call that raised it
}

bool hasLayer(const char* name) {
    std::uint32_t count = 0;
    VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
    std::vector<VkLayerProperties> layers(count);
    VK_CHECK(vkEnumerateInstanceLayerProperties(&count, layers.data()));
    return std::any_of(layers.begin(), layers.end(),
                       [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

std::string typeName(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated-gpu";
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete-gpu";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual-gpu";
        default: return "other";
    }
}

int graphicsQueueFamily(VkPhysicalDevice device) {
    std::uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
    for (std::uint32_t i = 0; i < count; ++i)
        if (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) return int(i);
    return -1;
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string listDevices(const std::vector<DeviceReport>& devices) {
    std::ostringstream s;
    for (const DeviceReport& d : devices) {
        s << "\n  " << d.index << ": " << d.name << " (" << d.type << ", " << d.driverName << ", Vulkan "
          << d.apiVersionText << (d.lavapipe ? ", lavapipe" : "") << ")";
        if (!d.usable) s << " not usable: " << d.unusableReason;
    }
    return s.str();
}

}  // namespace

std::string versionText(std::uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
           std::to_string(VK_API_VERSION_PATCH(v));
}

VkDebugUtilsMessengerCreateInfoEXT messengerCreateInfo(ValidationLog* log) {
    return VkDebugUtilsMessengerCreateInfoEXT{
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT,
        .pfnUserCallback = onDebugMessage,
        .pUserData = log,
    };
}

InstanceHandle createInstance(bool validate, const VkDebugUtilsMessengerCreateInfoEXT* messengerInfo) {
    setShaderCacheDir();
    loadVulkanLoader();
    std::uint32_t loaderVersion = VK_API_VERSION_1_0;
    if (vkEnumerateInstanceVersion) VK_CHECK(vkEnumerateInstanceVersion(&loaderVersion));
    if (loaderVersion < VK_API_VERSION_1_3)
        throw RasterError("the Vulkan loader supports Vulkan " + versionText(loaderVersion) +
                          ", the raster backend needs 1.3; update the Debian package libvulkan1");

    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    if (validate) {
        if (!hasLayer(kValidationLayer))
            throw RasterError(std::string("validation was requested but the Vulkan layer ") + kValidationLayer +
                              " is not installed; install the Debian package vulkan-validationlayers");
        layers.push_back(kValidationLayer);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);  // the layer provides it
    }
    const VkApplicationInfo app{
        .sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
        .pApplicationName = "shadowlab",
        .applicationVersion = VK_MAKE_API_VERSION(0, 0, 1, 0),
        .pEngineName = "shadowlab",
        .engineVersion = VK_MAKE_API_VERSION(0, 0, 1, 0),
        .apiVersion = VK_API_VERSION_1_3,
    };
    // Chaining the messenger info reports problems in vkCreateInstance/vkDestroyInstance too.
    const VkInstanceCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
        .pNext = validate ? messengerInfo : nullptr,
        .pApplicationInfo = &app,
        .enabledLayerCount = std::uint32_t(layers.size()),
        .ppEnabledLayerNames = layers.data(),
        .enabledExtensionCount = std::uint32_t(extensions.size()),
        .ppEnabledExtensionNames = extensions.data(),
    };
    VkInstance instance = VK_NULL_HANDLE;
    const VkResult r = vkCreateInstance(&info, nullptr, &instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
        throw RasterError(
            "no Vulkan driver (ICD) is installed; install the Debian package mesa-vulkan-drivers "
            "for lavapipe, Mesa's CPU Vulkan driver");
    if (r == VK_ERROR_LAYER_NOT_PRESENT)
        throw RasterError(std::string("the Vulkan layer ") + kValidationLayer +
                          " failed to load; reinstall the Debian package vulkan-validationlayers");
    VK_CHECK(r);
    InstanceHandle handle(instance);
    loadInstanceFunctions(instance);
    return handle;
}

std::vector<DeviceReport> describePhysicalDevices(VkInstance instance, std::vector<VkPhysicalDevice>* handles) {
    std::uint32_t count = 0;
    VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    if (count > 0) VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
    devices.resize(count);
    if (devices.empty())
        throw RasterError(
            "the Vulkan loader found no device; install the Debian package mesa-vulkan-drivers "
            "for lavapipe, Mesa's CPU Vulkan driver");
    std::vector<DeviceReport> reports;
    for (std::size_t i = 0; i < devices.size(); ++i) {
        VkPhysicalDeviceDriverProperties driver{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
        VkPhysicalDeviceProperties2 props{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &driver};
        vkGetPhysicalDeviceProperties2(devices[i], &props);
        DeviceReport r;
        r.index = int(i);
        r.name = props.properties.deviceName;
        r.type = typeName(props.properties.deviceType);
        r.driverName = driver.driverName;
        r.driverInfo = driver.driverInfo;
        r.apiVersion = props.properties.apiVersion;
        r.apiVersionText = versionText(r.apiVersion);
        r.lavapipe =
            driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE || props.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        if (r.apiVersion < VK_API_VERSION_1_3) {
            r.unusableReason = "Vulkan " + r.apiVersionText + " < 1.3";
        } else if (graphicsQueueFamily(devices[i]) < 0) {
            r.unusableReason = "no graphics queue";
        } else {
            VkPhysicalDeviceVulkan13Features f13{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
            VkPhysicalDeviceFeatures2 f{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &f13};
            vkGetPhysicalDeviceFeatures2(devices[i], &f);
            if (!f13.dynamicRendering || !f13.synchronization2)
                r.unusableReason = "no dynamicRendering/synchronization2";
        }
        r.usable = r.unusableReason.empty();
        reports.push_back(r);
    }
    if (handles) *handles = devices;
    return reports;
}

std::size_t selectDevice(const std::vector<DeviceReport>& devices, const std::string& selector) {
    if (devices.empty()) throw RasterError("no Vulkan device; install the Debian package mesa-vulkan-drivers");
    std::size_t chosen = devices.size();
    if (selector.empty()) {
        for (std::size_t i = 0; i < devices.size() && chosen == devices.size(); ++i)
            if (devices[i].usable && devices[i].lavapipe) chosen = i;
        for (std::size_t i = 0; i < devices.size() && chosen == devices.size(); ++i)
            if (devices[i].usable) chosen = i;
        if (chosen == devices.size())
            throw RasterError(
                "no usable Vulkan 1.3 device (needs a graphics queue, dynamic rendering and "
                "synchronization2); devices:" +
                listDevices(devices) + "\ninstall the Debian package mesa-vulkan-drivers for lavapipe");
        return chosen;
    }
    const bool isIndex = std::all_of(selector.begin(), selector.end(),
                                     [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
    if (isIndex) {
        const unsigned long index = selector.size() <= 9 ? std::stoul(selector) : devices.size();
        if (index < devices.size()) chosen = index;
    } else {
        const std::string needle = lower(selector);
        for (std::size_t i = 0; i < devices.size() && chosen == devices.size(); ++i)
            if (lower(devices[i].name).find(needle) != std::string::npos) chosen = i;
    }
    if (chosen == devices.size())
        throw RasterError("--device '" + selector +
                          "' matches no Vulkan device (give an index or part of a name); "
                          "devices:" +
                          listDevices(devices));
    if (!devices[chosen].usable)
        throw RasterError("--device '" + selector + "' selects " + devices[chosen].name +
                          ", which the raster backend cannot use: " + devices[chosen].unusableReason +
                          "; devices:" + listDevices(devices));
    return chosen;
}

std::vector<DeviceReport> enumerateDevices(bool validate) {
    ValidationLog log;
    const VkDebugUtilsMessengerCreateInfoEXT messengerInfo = messengerCreateInfo(&log);
    const InstanceHandle instance = createInstance(validate, &messengerInfo);
    std::vector<DeviceReport> devices = describePhysicalDevices(instance.get());
    try {
        devices[selectDevice(devices, "")].isDefault = true;
    } catch (const RasterError&) {
        // Listing still works when none is usable; describeDevices() says so.
    }
    return devices;
}

std::string describeDevices(bool validate) {
    std::ostringstream s;
    loadVulkanLoader();
    std::uint32_t loaderVersion = VK_API_VERSION_1_0;
    if (vkEnumerateInstanceVersion) VK_CHECK(vkEnumerateInstanceVersion(&loaderVersion));
    s << "Vulkan instance version: " << versionText(loaderVersion) << "\n";
    const std::vector<DeviceReport> devices = enumerateDevices(validate);
    if (validate) s << "validation layer: VK_LAYER_KHRONOS_validation loads\n";
    bool anyDefault = false;
    for (const DeviceReport& d : devices) {
        anyDefault = anyDefault || d.isDefault;
        s << "device " << d.index << ": " << d.name << (d.isDefault ? "  [default]" : "") << "\n"
          << "  type: " << d.type << (d.lavapipe ? " (lavapipe, Mesa's CPU driver)" : " (not lavapipe)") << "\n"
          << "  driver: " << d.driverName << " " << d.driverInfo << "\n"
          << "  Vulkan API: " << d.apiVersionText << "\n"
          << "  usable by the raster backend: " << (d.usable ? "yes" : "no, " + d.unusableReason) << "\n";
    }
    if (!anyDefault) s << "no device is usable by the raster backend (it needs Vulkan 1.3)\n";
    return s.str();
}

// The pipeline cache file's data, when its header (Vulkan spec, vkGetPipelineCacheData: header
// length, version 1, vendor id, device id, pipelineCacheUUID) names this device; else nothing,
// so a cache from another driver or version is never handed to this one.
static std::vector<char> readPipelineCache(const std::filesystem::path& file, const VkPhysicalDeviceProperties& props) {
    // Through the one input opener: a cache that is a FIFO or /dev/zero is no cache, not a hang.
    std::string bytes;
    try {
        bytes = scene::readInputFile(file, scene::kMaxJsonFileBytes);
    } catch (const scene::InputError&) {
        return {};
    }
    std::vector<char> data(bytes.begin(), bytes.end());
    if (data.size() < 32) return {};
    std::uint32_t header[4];
    std::memcpy(header, data.data(), sizeof header);
    if (header[0] < 32 || header[1] != VK_PIPELINE_CACHE_HEADER_VERSION_ONE || header[2] != props.vendorID ||
        header[3] != props.deviceID || std::memcmp(data.data() + 16, props.pipelineCacheUUID, VK_UUID_SIZE) != 0)
        return {};
    return data;
}

static void createPipelineCache(Context& ctx) {
    const std::filesystem::path dir = cacheDirectory();
    if (!dir.empty()) {
        std::ostringstream name;
        name << "pipelines-" << std::hex << ctx.properties.vendorID << "-" << ctx.properties.deviceID << "-";
        for (std::uint8_t b : ctx.properties.pipelineCacheUUID) name << std::setw(2) << std::setfill('0') << int(b);
        ctx.pipelineCacheFile = dir / "vulkan" / (name.str() + ".bin");
    }
    const std::vector<char> initial =
        ctx.pipelineCacheFile.empty() ? std::vector<char>() : readPipelineCache(ctx.pipelineCacheFile, ctx.properties);
    const VkPipelineCacheCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO,
        .initialDataSize = initial.size(),
        .pInitialData = initial.empty() ? nullptr : initial.data(),
    };
    VkPipelineCache cache = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineCache(ctx.device.get(), &info, nullptr, &cache));
    ctx.pipelineCache = PipelineCacheHandle(ctx.device.get(), cache);
}

Context::Context(const ContextOptions& options) {
    if (options.validate && !options.log)
        throw std::invalid_argument("raster::Context: validation needs a ValidationLog");
    const VkDebugUtilsMessengerCreateInfoEXT messengerInfo = messengerCreateInfo(options.log);
    instance = createInstance(options.validate, &messengerInfo);
    if (options.validate) {
        VkDebugUtilsMessengerEXT m = VK_NULL_HANDLE;
        VK_CHECK(vkCreateDebugUtilsMessengerEXT(instance.get(), &messengerInfo, nullptr, &m));
        messenger = MessengerHandle(instance.get(), m);
    }

    std::vector<VkPhysicalDevice> handles;
    std::vector<DeviceReport> devices = describePhysicalDevices(instance.get(), &handles);
    try {
        devices[selectDevice(devices, "")].isDefault = true;
    } catch (const RasterError&) {
    }
    const std::size_t chosen = selectDevice(devices, options.device);
    physicalDevice = handles[chosen];
    deviceReport = devices[chosen];
    vkGetPhysicalDeviceProperties(physicalDevice, &properties);
    vkGetPhysicalDeviceMemoryProperties(physicalDevice, &memoryProperties);
    queueFamily = std::uint32_t(graphicsQueueFamily(physicalDevice));

    const float priority = 1.0f;
    const VkDeviceQueueCreateInfo queueInfo{
        .sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
        .queueFamilyIndex = queueFamily,
        .queueCount = 1,
        .pQueuePriorities = &priority,
    };
    VkPhysicalDeviceVulkan13Features features13{
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
        .synchronization2 = VK_TRUE,
        .dynamicRendering = VK_TRUE,
    };
    // independentBlend (optional): the transmittance pass blends its two targets differently
    // (raster/shadow_pass.h); without it scenes with semi-transparent casters are refused there.
    VkPhysicalDeviceFeatures2 supported{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    vkGetPhysicalDeviceFeatures2(physicalDevice, &supported);
    independentBlend = supported.features.independentBlend == VK_TRUE;
    VkPhysicalDeviceFeatures2 features{
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2,
        .pNext = &features13,
    };
    features.features.independentBlend = independentBlend ? VK_TRUE : VK_FALSE;
    std::uint32_t extensionCount = 0;
    VK_CHECK(vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &extensionCount, nullptr));
    std::vector<VkExtensionProperties> available(extensionCount);
    VK_CHECK(vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &extensionCount, available.data()));
    std::vector<const char*> extensions;
    for (const VkExtensionProperties& e : available)
        if (std::strcmp(e.extensionName, VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME) == 0 &&
            vkGetMemoryHostPointerPropertiesEXT) {
            VkPhysicalDeviceExternalMemoryHostPropertiesEXT host{
                .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_MEMORY_HOST_PROPERTIES_EXT};
            VkPhysicalDeviceProperties2 props{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &host};
            vkGetPhysicalDeviceProperties2(physicalDevice, &props);
            hostPointerImport = host.minImportedHostPointerAlignment > 0;
            minImportedHostPointerAlignment = host.minImportedHostPointerAlignment;
            if (hostPointerImport) extensions.push_back(VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
        }
    const VkDeviceCreateInfo deviceInfo{
        .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
        .pNext = &features,
        .queueCreateInfoCount = 1,
        .pQueueCreateInfos = &queueInfo,
        .enabledExtensionCount = std::uint32_t(extensions.size()),
        .ppEnabledExtensionNames = extensions.data(),
    };
    VkDevice d = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDevice(physicalDevice, &deviceInfo, nullptr, &d));
    device = LogicalDeviceHandle(d);
    vkGetDeviceQueue(d, queueFamily, 0, &queue);

    const VkCommandPoolCreateInfo poolInfo{
        .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
        .flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT,
        .queueFamilyIndex = queueFamily,
    };
    VkCommandPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateCommandPool(d, &poolInfo, nullptr, &pool));
    commandPool = CommandPoolHandle(d, pool);
    createPipelineCache(*this);
}

std::uint32_t Context::memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                  VkMemoryPropertyFlags preferred) const {
    std::uint32_t fallback = UINT32_MAX;
    for (std::uint32_t i = 0; i < memoryProperties.memoryTypeCount; ++i) {
        if (!(typeBits & (1u << i))) continue;
        const VkMemoryPropertyFlags flags = memoryProperties.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (fallback == UINT32_MAX) fallback = i;
    }
    if (fallback == UINT32_MAX)
        throw RasterError("the Vulkan device " + deviceReport.name + " has no memory type with properties 0x" +
                          std::to_string(required) + " for this resource");
    return fallback;
}

VkCommandBuffer Context::beginCommands() const {
    const VkCommandBufferAllocateInfo info{
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = commandPool.get(),
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VkCommandBuffer commands = VK_NULL_HANDLE;
    VK_CHECK(vkAllocateCommandBuffers(device.get(), &info, &commands));
    const VkCommandBufferBeginInfo begin{
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    VK_CHECK(vkBeginCommandBuffer(commands, &begin));
    return commands;
}

// How long one submission may take before the device counts as hung: 10 minutes, far above the
// largest frame lavapipe is allowed (its 2 GiB heap caps the images), or SHADOWLAB_GPU_TIMEOUT_S.
static std::uint64_t gpuTimeoutNanoseconds() {
    double seconds = 600.0;
    if (const char* text = std::getenv("SHADOWLAB_GPU_TIMEOUT_S"); text && *text) {
        char* end = nullptr;
        seconds = std::strtod(text, &end);
        if (!end || *end != '\0' || !(seconds > 0.0) || seconds > 1e6)
            throw RasterError(std::string("SHADOWLAB_GPU_TIMEOUT_S: expected seconds > 0, got '") + text + "'");
    }
    return std::uint64_t(seconds * 1e9);
}

Context::~Context() {
    // Best effort: a cache that cannot be saved only costs the next run its warm start.
    if (pipelineCache.get() == VK_NULL_HANDLE || pipelineCacheFile.empty()) return;
    std::size_t size = 0;
    if (vkGetPipelineCacheData(device.get(), pipelineCache.get(), &size, nullptr) != VK_SUCCESS || size == 0) return;
    std::string data(size, '\0');
    if (vkGetPipelineCacheData(device.get(), pipelineCache.get(), &size, data.data()) != VK_SUCCESS) return;
    data.resize(size);
    try {
        std::filesystem::create_directories(pipelineCacheFile.parent_path());
        scene::writeTextAtomic(pipelineCacheFile, data);
    } catch (const std::exception&) {
    }
}

void Context::submitAndWait(VkCommandBuffer commands) const {
    VK_CHECK(vkEndCommandBuffer(commands));
    const VkFenceCreateInfo fenceInfo{.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence f = VK_NULL_HANDLE;
    VK_CHECK(vkCreateFence(device.get(), &fenceInfo, nullptr, &f));
    const FenceHandle fence(device.get(), f);
    const VkCommandBufferSubmitInfo commandInfo{
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO,
        .commandBuffer = commands,
    };
    const VkSubmitInfo2 submit{
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2,
        .commandBufferInfoCount = 1,
        .pCommandBufferInfos = &commandInfo,
    };
    VK_CHECK(vkQueueSubmit2(queue, 1, &submit, fence.get()));
    // A device that hangs or is lost must end in an error, not a wait forever.
    VK_CHECK(vkWaitForFences(device.get(), 1, &f, VK_TRUE, gpuTimeoutNanoseconds()));
    vkFreeCommandBuffers(device.get(), commandPool.get(), 1, &commands);
}

}  // namespace shadowlab::raster

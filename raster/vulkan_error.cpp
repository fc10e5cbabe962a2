// raster/vulkan_error.cpp: names for VkResult codes and the VulkanError message.
#include "raster/vulkan_error.h"

namespace shadowlab::raster {

std::string toString(VkResult result) {
    switch (result) {
#define SHADOWLAB_RESULT(name) \
    case name: return #name;
        SHADOWLAB_RESULT(VK_SUCCESS)
        SHADOWLAB_RESULT(VK_NOT_READY)
        SHADOWLAB_RESULT(VK_TIMEOUT)
        SHADOWLAB_RESULT(VK_EVENT_SET)
        SHADOWLAB_RESULT(VK_EVENT_RESET)
        SHADOWLAB_RESULT(VK_INCOMPLETE)
        SHADOWLAB_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
        SHADOWLAB_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        SHADOWLAB_RESULT(VK_ERROR_INITIALIZATION_FAILED)
        SHADOWLAB_RESULT(VK_ERROR_DEVICE_LOST)
        SHADOWLAB_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
        SHADOWLAB_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
        SHADOWLAB_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
        SHADOWLAB_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
        SHADOWLAB_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
        SHADOWLAB_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
        SHADOWLAB_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
        SHADOWLAB_RESULT(VK_ERROR_FRAGMENTED_POOL)
        SHADOWLAB_RESULT(VK_ERROR_UNKNOWN)
        SHADOWLAB_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
        SHADOWLAB_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        SHADOWLAB_RESULT(VK_ERROR_FRAGMENTATION)
        SHADOWLAB_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        SHADOWLAB_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
#undef SHADOWLAB_RESULT
        default: return "VkResult(" + std::to_string(int(result)) + ")";
    }
}

std::string explain(VkResult result) {
    switch (result) {
        case VK_ERROR_DEVICE_LOST:
            return "the Vulkan device was lost during the render (a driver crash or a GPU reset); nothing was "
                   "written: try again, or use --backend raytrace";
        case VK_ERROR_OUT_OF_DEVICE_MEMORY:
        case VK_ERROR_OUT_OF_HOST_MEMORY:
            return "the Vulkan device ran out of memory; lower --resolution or --shadow-map-size";
        case VK_TIMEOUT:
            return "the Vulkan device did not finish in time: it hung or was lost (SHADOWLAB_GPU_TIMEOUT_S sets "
                   "the limit)";
        default: return "";
    }
}

VulkanError::VulkanError(VkResult result, const char* call, const char* file, int line)
    : RasterError((explain(result).empty() ? "" : explain(result) + " (") + call + " failed with " + toString(result) +
                  " at " + file + ":" + std::to_string(line) + (explain(result).empty() ? "" : ")")),
      result_(result) {}

}  // namespace shadowlab::raster

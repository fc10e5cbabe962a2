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

VulkanError::VulkanError(VkResult result, const char* call, const char* file, int line)
    : RasterError(std::string(call) + " failed with " + toString(result) + " at " + file + ":" +
                  std::to_string(line)),
      result_(result) {}

}  // namespace shadowlab::raster

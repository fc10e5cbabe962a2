// raster/vulkan_error.h: the exceptions of the raster backend and VK_CHECK, which turns every
// failed Vulkan call into a VulkanError naming the call, the result and the place.
#pragma once

#include <stdexcept>
#include <string>

#include <vulkan/vulkan_core.h>

namespace shadowlab::raster {

// A problem the raster backend cannot work around (no loader, no driver, no such device, a
// scene it cannot draw yet). The message is complete: what is missing and how to get it.
class RasterError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A Vulkan call returned an error. The message leads with explain(result) where there is one.
class VulkanError : public RasterError {
public:
    VulkanError(VkResult result, const char* call, const char* file, int line);
    VkResult result() const { return result_; }

private:
    VkResult result_;
};

// "VK_ERROR_OUT_OF_DEVICE_MEMORY", or the number for codes this build does not know.
std::string toString(VkResult result);

// What a user should read for the failures a render can meet at run time (device lost, out of
// memory, a timeout), and what to do; empty for the others (programming errors).
std::string explain(VkResult result);

}  // namespace shadowlab::raster

#define VK_CHECK(call)                                                             \
    do {                                                                           \
        if (const VkResult r_ = (call); r_ != VK_SUCCESS)                          \
            throw ::shadowlab::raster::VulkanError(r_, #call, __FILE__, __LINE__); \
    } while (0)

// raster/vulkan_functions.h: the Vulkan entry points raster/ uses, loaded at run time from
// libvulkan.so.1 (dlopen) instead of linked. A machine without the loader then still runs the
// ray tracer, and the raster backend says which package is missing instead of the program
// failing to start. Call loadVulkanLoader() before anything else, loadInstanceFunctions()
// after vkCreateInstance.
#pragma once

#include <vulkan/vulkan_core.h>

// Global functions (no instance needed).
#define SHADOWLAB_VK_GLOBAL_FUNCTIONS(X)  \
    X(vkCreateInstance)                   \
    X(vkEnumerateInstanceVersion)         \
    X(vkEnumerateInstanceLayerProperties) \
    X(vkEnumerateInstanceExtensionProperties)

// Instance and device functions, resolved through vkGetInstanceProcAddr.
#define SHADOWLAB_VK_INSTANCE_FUNCTIONS(X)       \
    X(vkDestroyInstance)                         \
    X(vkEnumeratePhysicalDevices)                \
    X(vkGetPhysicalDeviceProperties)             \
    X(vkGetPhysicalDeviceProperties2)            \
    X(vkGetPhysicalDeviceFeatures2)              \
    X(vkGetPhysicalDeviceQueueFamilyProperties)  \
    X(vkGetPhysicalDeviceMemoryProperties)       \
    X(vkGetPhysicalDeviceFormatProperties)       \
    X(vkGetPhysicalDeviceImageFormatProperties2) \
    X(vkEnumerateDeviceExtensionProperties)      \
    X(vkCreateDebugUtilsMessengerEXT)            \
    X(vkDestroyDebugUtilsMessengerEXT)           \
    X(vkCreateDevice)                            \
    X(vkDestroyDevice)                           \
    X(vkGetDeviceQueue)                          \
    X(vkDeviceWaitIdle)                          \
    X(vkCreateCommandPool)                       \
    X(vkDestroyCommandPool)                      \
    X(vkAllocateCommandBuffers)                  \
    X(vkFreeCommandBuffers)                      \
    X(vkBeginCommandBuffer)                      \
    X(vkEndCommandBuffer)                        \
    X(vkQueueSubmit2)                            \
    X(vkCreateFence)                             \
    X(vkDestroyFence)                            \
    X(vkWaitForFences)                           \
    X(vkCreateBuffer)                            \
    X(vkDestroyBuffer)                           \
    X(vkGetBufferMemoryRequirements)             \
    X(vkBindBufferMemory)                        \
    X(vkCreateImage)                             \
    X(vkDestroyImage)                            \
    X(vkGetImageMemoryRequirements)              \
    X(vkGetImageSubresourceLayout)               \
    X(vkGetMemoryHostPointerPropertiesEXT)       \
    X(vkBindImageMemory)                         \
    X(vkCreateImageView)                         \
    X(vkDestroyImageView)                        \
    X(vkAllocateMemory)                          \
    X(vkFreeMemory)                              \
    X(vkMapMemory)                               \
    X(vkUnmapMemory)                             \
    X(vkInvalidateMappedMemoryRanges)            \
    X(vkFlushMappedMemoryRanges)                 \
    X(vkCreateSampler)                           \
    X(vkDestroySampler)                          \
    X(vkCreateShaderModule)                      \
    X(vkDestroyShaderModule)                     \
    X(vkCreateDescriptorSetLayout)               \
    X(vkDestroyDescriptorSetLayout)              \
    X(vkCreateDescriptorPool)                    \
    X(vkDestroyDescriptorPool)                   \
    X(vkAllocateDescriptorSets)                  \
    X(vkUpdateDescriptorSets)                    \
    X(vkCreatePipelineLayout)                    \
    X(vkDestroyPipelineLayout)                   \
    X(vkCreateGraphicsPipelines)                 \
    X(vkCreateComputePipelines)                  \
    X(vkCreatePipelineCache)                     \
    X(vkDestroyPipelineCache)                    \
    X(vkGetPipelineCacheData)                    \
    X(vkDestroyPipeline)                         \
    X(vkCreateQueryPool)                         \
    X(vkDestroyQueryPool)                        \
    X(vkGetQueryPoolResults)                     \
    X(vkCmdResetQueryPool)                       \
    X(vkCmdWriteTimestamp2)                      \
    X(vkCmdPipelineBarrier2)                     \
    X(vkCmdBeginRendering)                       \
    X(vkCmdEndRendering)                         \
    X(vkCmdBindPipeline)                         \
    X(vkCmdBindVertexBuffers)                    \
    X(vkCmdBindIndexBuffer)                      \
    X(vkCmdBindDescriptorSets)                   \
    X(vkCmdPushConstants)                        \
    X(vkCmdSetViewport)                          \
    X(vkCmdSetScissor)                           \
    X(vkCmdSetDepthBias)                         \
    X(vkCmdDraw)                                 \
    X(vkCmdDrawIndexed)                          \
    X(vkCmdDispatch)                             \
    X(vkCmdCopyBuffer)                           \
    X(vkCmdCopyImageToBuffer)

namespace shadowlab::raster {

// The pointers live in this namespace with the Vulkan names, so code in shadowlab::raster
// reads like plain Vulkan; the global prototypes are never linked (VK_NO_PROTOTYPES).
#define SHADOWLAB_VK_DECLARE(name) extern PFN_##name name;
extern PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr;
SHADOWLAB_VK_GLOBAL_FUNCTIONS(SHADOWLAB_VK_DECLARE)
SHADOWLAB_VK_INSTANCE_FUNCTIONS(SHADOWLAB_VK_DECLARE)
#undef SHADOWLAB_VK_DECLARE

// Opens libvulkan.so.1 once per process and resolves the global functions. Throws RasterError
// naming the Debian package (libvulkan1) when the loader is not installed.
void loadVulkanLoader();

// Resolves every instance and device function for `instance`. Throws RasterError naming the
// first function the driver does not provide (a Vulkan 1.3 function on an older loader).
void loadInstanceFunctions(VkInstance instance);

}  // namespace shadowlab::raster

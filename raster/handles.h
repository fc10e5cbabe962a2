// raster/handles.h: move-only owners of Vulkan handles. Declare them in creation order in a
// struct: C++ destroys members in reverse, which is the order Vulkan needs.
#pragma once

#include <utility>

#include "raster/vulkan_functions.h"

namespace shadowlab::raster {

// A handle created from a parent (a VkDevice or VkInstance) and destroyed with
// `(*Destroy)(parent, handle, nullptr)`. `Destroy` is the address of one of the loaded function
// pointers (&vkDestroyImage): a constant, although the pointer it points to is filled at run time.
template <typename Parent, typename T, auto* Destroy>
class ChildHandle {
public:
    ChildHandle() = default;
    ChildHandle(Parent parent, T handle) : parent_(parent), handle_(handle) {}
    ChildHandle(ChildHandle&& other) noexcept
        : parent_(other.parent_), handle_(std::exchange(other.handle_, VK_NULL_HANDLE)) {}
    ChildHandle& operator=(ChildHandle&& other) noexcept {
        if (this != &other) {
            reset();
            parent_ = other.parent_;
            handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
        }
        return *this;
    }
    ChildHandle(const ChildHandle&) = delete;
    ChildHandle& operator=(const ChildHandle&) = delete;
    ~ChildHandle() { reset(); }

    T get() const { return handle_; }
    explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }
    void reset() {
        if (handle_ != VK_NULL_HANDLE) (*Destroy)(parent_, std::exchange(handle_, VK_NULL_HANDLE), nullptr);
    }

private:
    Parent parent_ = VK_NULL_HANDLE;
    T handle_ = VK_NULL_HANDLE;
};

template <typename T, auto* Destroy>
using DeviceHandle = ChildHandle<VkDevice, T, Destroy>;

// The root objects, destroyed with `(*Destroy)(handle, nullptr)`: VkInstance and VkDevice.
template <typename T, auto* Destroy>
class RootHandle {
public:
    RootHandle() = default;
    explicit RootHandle(T handle) : handle_(handle) {}
    RootHandle(RootHandle&& other) noexcept : handle_(std::exchange(other.handle_, VK_NULL_HANDLE)) {}
    RootHandle& operator=(RootHandle&& other) noexcept {
        if (this != &other) {
            reset();
            handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
        }
        return *this;
    }
    RootHandle(const RootHandle&) = delete;
    RootHandle& operator=(const RootHandle&) = delete;
    ~RootHandle() { reset(); }

    T get() const { return handle_; }
    explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }
    void reset() {
        if (handle_ != VK_NULL_HANDLE) (*Destroy)(std::exchange(handle_, VK_NULL_HANDLE), nullptr);
    }

private:
    T handle_ = VK_NULL_HANDLE;
};

using InstanceHandle = RootHandle<VkInstance, &vkDestroyInstance>;
using LogicalDeviceHandle = RootHandle<VkDevice, &vkDestroyDevice>;
using MessengerHandle = ChildHandle<VkInstance, VkDebugUtilsMessengerEXT, &vkDestroyDebugUtilsMessengerEXT>;
using BufferHandle = DeviceHandle<VkBuffer, &vkDestroyBuffer>;
using MemoryHandle = DeviceHandle<VkDeviceMemory, &vkFreeMemory>;
using ImageHandle = DeviceHandle<VkImage, &vkDestroyImage>;
using ImageViewHandle = DeviceHandle<VkImageView, &vkDestroyImageView>;
using SamplerHandle = DeviceHandle<VkSampler, &vkDestroySampler>;
using ShaderModuleHandle = DeviceHandle<VkShaderModule, &vkDestroyShaderModule>;
using DescriptorSetLayoutHandle = DeviceHandle<VkDescriptorSetLayout, &vkDestroyDescriptorSetLayout>;
using DescriptorPoolHandle = DeviceHandle<VkDescriptorPool, &vkDestroyDescriptorPool>;
using PipelineLayoutHandle = DeviceHandle<VkPipelineLayout, &vkDestroyPipelineLayout>;
using PipelineHandle = DeviceHandle<VkPipeline, &vkDestroyPipeline>;
using CommandPoolHandle = DeviceHandle<VkCommandPool, &vkDestroyCommandPool>;
using PipelineCacheHandle = DeviceHandle<VkPipelineCache, &vkDestroyPipelineCache>;
using FenceHandle = DeviceHandle<VkFence, &vkDestroyFence>;
using QueryPoolHandle = DeviceHandle<VkQueryPool, &vkDestroyQueryPool>;

}  // namespace shadowlab::raster

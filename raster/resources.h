// raster/resources.h: buffers and images with their memory, staging uploads, and the image
// layout barriers (synchronization2) the passes share.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "raster/context.h"

namespace shadowlab::raster {

struct Buffer {
    BufferHandle buffer;
    // Freed before the buffer is destroyed (reverse creation order); Vulkan allows freeing
    // bound memory as long as the resource is not used again.
    MemoryHandle memory;
    void* mapped = nullptr;  // host-visible buffers stay mapped until the memory is freed
    VkDeviceSize size = 0;
};

struct Image {
    ImageHandle image;
    MemoryHandle memory;
    ImageViewHandle view;  // of every layer (2D or 2D array)
    // Host-readable images only (linear tiling, host-visible memory, mapped): the first texel
    // of layer 0 and the bytes from one row to the next.
    void* mapped = nullptr;
    VkDeviceSize rowPitch = 0;
};

// Throws RasterError when `bytes` cannot fit in the device's largest device-local heap, naming
// `what` and both sizes, instead of a bare VK_ERROR_OUT_OF_DEVICE_MEMORY later.
void requireDeviceMemory(const Context& ctx, VkDeviceSize bytes, const std::string& what);

Buffer createBuffer(const Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags required,
                    VkMemoryPropertyFlags preferred = 0);

// A device-local buffer holding `bytes`, filled through a host-visible staging buffer (one
// submit, waited for). `usage` gets TRANSFER_DST added.
Buffer uploadBuffer(const Context& ctx, const void* bytes, std::size_t size, VkBufferUsageFlags usage);

template <typename T>
Buffer uploadBuffer(const Context& ctx, const std::vector<T>& data, VkBufferUsageFlags usage) {
    return uploadBuffer(ctx, data.data(), data.size() * sizeof(T), usage);
}

// A host-visible buffer the device writes and the host reads (cached when the device has it).
Buffer createReadbackBuffer(const Context& ctx, VkDeviceSize size);
// Makes device writes visible to the host for non-coherent memory; a no-op on coherent memory.
void invalidate(const Context& ctx, const Buffer& buffer);

// With hostReadable: linear tiling in host-visible memory, mapped (one layer, color only; see
// canReadImagesOnHost()).
Image createImage(const Context& ctx, VkFormat format, std::uint32_t width, std::uint32_t height, std::uint32_t layers,
                  VkImageUsageFlags usage, VkImageAspectFlags aspect, VkImageViewType viewType,
                  bool hostReadable = false);
// Whether `format` can be a color attachment with linear tiling and live in host-visible memory
// that is the device's own: true on lavapipe, whose "device memory" is host memory, so the host
// can read rendered targets in place instead of copying them into a buffer first.
bool canReadImagesOnHost(const Context& ctx, VkFormat format, VkImageUsageFlags usage);
// Images over host memory the program owns (VK_EXT_external_memory_host, Context::hostPointerImport):
// a 2D color image with linear tiling whose texel (0, 0) is at `data` and whose rows follow each
// other with no padding (row pitch = width · texelBytes), in memory the device reads and writes
// where the host does. hostImageBytes() is how many bytes from `data` on such an image needs (the
// driver may round the rows up; the caller owns them all), or 0 when the device cannot make one of
// this format and size (no import, rows padded, the format not importable with linear tiling).
// importHostImage() makes it; no image (Image::image empty) when the pointer's alignment does not
// suit the device. The memory must stay valid until the Image is destroyed.
std::size_t hostImageBytes(const Context& ctx, VkFormat format, std::uint32_t width, std::uint32_t height,
                           VkImageUsageFlags usage, std::size_t texelBytes);
Image importHostImage(const Context& ctx, VkFormat format, std::uint32_t width, std::uint32_t height,
                      VkImageUsageFlags usage, std::size_t texelBytes, void* data, std::size_t bytes);
ImageViewHandle createView(const Context& ctx, VkImage image, VkFormat format, VkImageAspectFlags aspect,
                           VkImageViewType viewType, std::uint32_t firstLayer, std::uint32_t layerCount);

// Faults in the pages of `bytes` of host memory from `data` as writable, in one call (Linux 5.14's
// MADV_POPULATE_WRITE; nothing happens where the kernel refuses), leaving what they hold as it
// is. For new memory the device will render into: llvmpipe reads a target's texels under a partly
// covered block before it writes them, and a page first read maps the shared zero page, to be
// copied again at the write with a TLB shootdown across the driver's threads (at 1920x1080, 0.3 s
// of CPU for the per-light targets; docs/performance.md, "Several lights"); and for new memory the
// host is about to fill, one call instead of a fault a page.
void prefaultPages(const void* data, std::size_t bytes);

// One image layout transition with its execution and memory dependency.
struct ImageTransition {
    VkImage image;
    VkImageAspectFlags aspect;
    std::uint32_t layers;
    VkImageLayout from, to;
    VkPipelineStageFlags2 srcStage;
    VkAccessFlags2 srcAccess;
    VkPipelineStageFlags2 dstStage;
    VkAccessFlags2 dstAccess;
};
void transition(VkCommandBuffer commands, const std::vector<ImageTransition>& transitions);

// Makes transfer writes visible to host reads after the fence wait (a fence alone only orders
// device accesses; the Vulkan spec asks for this barrier before the host reads).
void transferToHostBarrier(VkCommandBuffer commands);

}  // namespace shadowlab::raster

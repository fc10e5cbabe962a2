// raster/resources.cpp: buffer and image creation, staging uploads, layout transitions.
#include "raster/resources.h"

#include <cstdint>
#include <cstring>

#include "raster/vulkan_error.h"

#include <sys/mman.h>

namespace shadowlab::raster {

void requireDeviceMemory(const Context& ctx, VkDeviceSize bytes, const std::string& what) {
    VkDeviceSize largest = 0;
    for (std::uint32_t i = 0; i < ctx.memoryProperties.memoryHeapCount; ++i)
        if (ctx.memoryProperties.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            largest = std::max(largest, ctx.memoryProperties.memoryHeaps[i].size);
    constexpr VkDeviceSize kMiB = 1024 * 1024;
    if (bytes > largest)
        throw RasterError(what + " needs " + std::to_string(bytes / kMiB) +
                          " MiB of device memory, but the largest heap of " + ctx.deviceReport.name + " has " +
                          std::to_string(largest / kMiB) + " MiB; use a smaller resolution or --shadow-map-size");
}

Buffer createBuffer(const Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags required,
                    VkMemoryPropertyFlags preferred) {
    VkDevice device = ctx.device.get();
    const VkBufferCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = size,
        .usage = usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
    };
    Buffer b;
    b.size = size;
    VkBuffer buffer = VK_NULL_HANDLE;
    VK_CHECK(vkCreateBuffer(device, &info, nullptr, &buffer));
    b.buffer = BufferHandle(device, buffer);
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(device, buffer, &req);
    const VkMemoryAllocateInfo alloc{
        .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
        .allocationSize = req.size,
        .memoryTypeIndex = ctx.memoryType(req.memoryTypeBits, required, preferred),
    };
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &memory));
    b.memory = MemoryHandle(device, memory);
    VK_CHECK(vkBindBufferMemory(device, buffer, memory, 0));
    if (required & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
        VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    return b;
}

Buffer uploadBuffer(const Context& ctx, const void* bytes, std::size_t size, VkBufferUsageFlags usage) {
    const VkDeviceSize n = std::max<VkDeviceSize>(size, 4);  // zero-sized buffers are invalid
    Buffer staging = createBuffer(ctx, n, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    if (size > 0) std::memcpy(staging.mapped, bytes, size);
    Buffer target = createBuffer(ctx, n, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkCommandBuffer commands = ctx.beginCommands();
    const VkBufferCopy region{.size = n};
    vkCmdCopyBuffer(commands, staging.buffer.get(), target.buffer.get(), 1, &region);
    // The submit waits on a fence, and a fence signal makes all of the batch's writes available;
    // later submits see them without a barrier (Vulkan spec, "Fence signal operation").
    ctx.submitAndWait(commands);
    return target;
}

Buffer createReadbackBuffer(const Context& ctx, VkDeviceSize size) {
    return createBuffer(ctx, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                        VK_MEMORY_PROPERTY_HOST_CACHED_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
}

void invalidate(const Context& ctx, const Buffer& buffer) {
    const VkMappedMemoryRange range{
        .sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE,
        .memory = buffer.memory.get(),
        .offset = 0,
        .size = VK_WHOLE_SIZE,
    };
    VK_CHECK(vkInvalidateMappedMemoryRanges(ctx.device.get(), 1, &range));
}

ImageViewHandle createView(const Context& ctx, VkImage image, VkFormat format, VkImageAspectFlags aspect,
                           VkImageViewType viewType, std::uint32_t firstLayer, std::uint32_t layerCount) {
    const VkImageViewCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
        .image = image,
        .viewType = viewType,
        .format = format,
        .subresourceRange = {.aspectMask = aspect,
                             .baseMipLevel = 0,
                             .levelCount = 1,
                             .baseArrayLayer = firstLayer,
                             .layerCount = layerCount},
    };
    VkImageView view = VK_NULL_HANDLE;
    VK_CHECK(vkCreateImageView(ctx.device.get(), &info, nullptr, &view));
    return ImageViewHandle(ctx.device.get(), view);
}

bool canReadImagesOnHost(const Context& ctx, VkFormat format, VkImageUsageFlags usage) {
    if (!ctx.deviceReport.lavapipe) return false;
    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice, format, &props);
    VkFormatFeatureFlags needed = 0;
    if (usage & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) needed |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
    if (usage & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) needed |= VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
    return (props.linearTilingFeatures & needed) == needed;
}

Image createImage(const Context& ctx, VkFormat format, std::uint32_t width, std::uint32_t height, std::uint32_t layers,
                  VkImageUsageFlags usage, VkImageAspectFlags aspect, VkImageViewType viewType, bool hostReadable) {
    VkDevice device = ctx.device.get();
    const VkImageCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
        .imageType = VK_IMAGE_TYPE_2D,
        .format = format,
        .extent = {width, height, 1},
        .mipLevels = 1,
        .arrayLayers = layers,
        .samples = VK_SAMPLE_COUNT_1_BIT,
        .tiling = hostReadable ? VK_IMAGE_TILING_LINEAR : VK_IMAGE_TILING_OPTIMAL,
        .usage = usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
    };
    Image img;
    VkImage image = VK_NULL_HANDLE;
    VK_CHECK(vkCreateImage(device, &info, nullptr, &image));
    img.image = ImageHandle(device, image);
    VkMemoryRequirements req{};
    vkGetImageMemoryRequirements(device, image, &req);
    const VkMemoryAllocateInfo alloc{
        .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
        .allocationSize = req.size,
        .memoryTypeIndex =
            hostReadable ? ctx.memoryType(req.memoryTypeBits,
                                          VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                                          VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                         : ctx.memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT),
    };
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &memory));
    img.memory = MemoryHandle(device, memory);
    VK_CHECK(vkBindImageMemory(device, image, memory, 0));
    if (hostReadable) {
        const VkImageSubresource subresource{.aspectMask = aspect, .mipLevel = 0, .arrayLayer = 0};
        VkSubresourceLayout layout{};
        vkGetImageSubresourceLayout(device, image, &subresource, &layout);
        void* base = nullptr;
        VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &base));
        img.mapped = static_cast<char*>(base) + layout.offset;
        img.rowPitch = layout.rowPitch;
    }
    img.view = createView(ctx, image, format, aspect, viewType, 0, layers);
    return img;
}

namespace {

constexpr VkExternalMemoryHandleTypeFlagBits kHostAllocation = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;

// A linear image that may be bound to imported host memory (its memory not yet bound).
ImageHandle createHostImportImage(const Context& ctx, VkFormat format, std::uint32_t width, std::uint32_t height,
                                  VkImageUsageFlags usage) {
    const VkExternalMemoryImageCreateInfo external{.sType = VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_IMAGE_CREATE_INFO,
                                                   .handleTypes = kHostAllocation};
    const VkImageCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
        .pNext = &external,
        .imageType = VK_IMAGE_TYPE_2D,
        .format = format,
        .extent = {width, height, 1},
        .mipLevels = 1,
        .arrayLayers = 1,
        .samples = VK_SAMPLE_COUNT_1_BIT,
        .tiling = VK_IMAGE_TILING_LINEAR,
        .usage = usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
    };
    VkImage image = VK_NULL_HANDLE;
    VK_CHECK(vkCreateImage(ctx.device.get(), &info, nullptr, &image));
    return ImageHandle(ctx.device.get(), image);
}

// The bytes an importable image needs from its first texel on, or 0 when its rows are padded.
std::size_t tightImageBytes(const Context& ctx, VkImage image, std::uint32_t width, std::size_t texelBytes,
                            VkMemoryRequirements& req) {
    vkGetImageMemoryRequirements(ctx.device.get(), image, &req);
    const VkImageSubresource subresource{.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT, .mipLevel = 0, .arrayLayer = 0};
    VkSubresourceLayout layout{};
    vkGetImageSubresourceLayout(ctx.device.get(), image, &subresource, &layout);
    if (layout.offset != 0 || layout.rowPitch != VkDeviceSize(width) * texelBytes) return 0;
    return std::size_t(req.size);
}

}  // namespace

std::size_t hostImageBytes(const Context& ctx, VkFormat format, std::uint32_t width, std::uint32_t height,
                           VkImageUsageFlags usage, std::size_t texelBytes) {
    if (!ctx.hostPointerImport) return 0;
    const VkPhysicalDeviceExternalImageFormatInfo externalInfo{
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_IMAGE_FORMAT_INFO, .handleType = kHostAllocation};
    const VkPhysicalDeviceImageFormatInfo2 formatInfo{
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_IMAGE_FORMAT_INFO_2,
        .pNext = &externalInfo,
        .format = format,
        .type = VK_IMAGE_TYPE_2D,
        .tiling = VK_IMAGE_TILING_LINEAR,
        .usage = usage,
    };
    VkExternalImageFormatProperties external{.sType = VK_STRUCTURE_TYPE_EXTERNAL_IMAGE_FORMAT_PROPERTIES};
    VkImageFormatProperties2 props{.sType = VK_STRUCTURE_TYPE_IMAGE_FORMAT_PROPERTIES_2, .pNext = &external};
    if (vkGetPhysicalDeviceImageFormatProperties2(ctx.physicalDevice, &formatInfo, &props) != VK_SUCCESS) return 0;
    if (!(external.externalMemoryProperties.externalMemoryFeatures & VK_EXTERNAL_MEMORY_FEATURE_IMPORTABLE_BIT) ||
        !(external.externalMemoryProperties.compatibleHandleTypes & kHostAllocation) ||
        props.imageFormatProperties.maxExtent.width < width || props.imageFormatProperties.maxExtent.height < height)
        return 0;
    const ImageHandle probe = createHostImportImage(ctx, format, width, height, usage);
    VkMemoryRequirements req{};
    return tightImageBytes(ctx, probe.get(), width, texelBytes, req);
}

Image importHostImage(const Context& ctx, VkFormat format, std::uint32_t width, std::uint32_t height,
                      VkImageUsageFlags usage, std::size_t texelBytes, void* data, std::size_t bytes) {
    Image img;
    if (!ctx.hostPointerImport || !data) return img;
    VkDevice device = ctx.device.get();
    ImageHandle image = createHostImportImage(ctx, format, width, height, usage);
    VkMemoryRequirements req{};
    const std::size_t needed = tightImageBytes(ctx, image.get(), width, texelBytes, req);
    if (needed == 0 || needed > bytes) return img;
    // The import starts at the page (minImportedHostPointerAlignment) holding `data` and covers
    // whole pages: memory of this process around the caller's, which the device never touches
    // (the image is bound at data's offset in it and rendered only within its extent).
    const VkDeviceSize align = ctx.minImportedHostPointerAlignment;
    const auto address = reinterpret_cast<std::uintptr_t>(data);
    const std::uintptr_t base = address - address % align;
    const VkDeviceSize offset = address - base;
    if (req.alignment == 0 || offset % req.alignment != 0) return img;
    const VkDeviceSize size = (offset + needed + align - 1) / align * align;
    VkMemoryHostPointerPropertiesEXT pointerProps{.sType = VK_STRUCTURE_TYPE_MEMORY_HOST_POINTER_PROPERTIES_EXT};
    if (vkGetMemoryHostPointerPropertiesEXT(device, kHostAllocation, reinterpret_cast<void*>(base), &pointerProps) !=
        VK_SUCCESS)
        return img;
    // Coherent memory: the host reads the rendered texels after the fence with no invalidation.
    const std::uint32_t typeBits = pointerProps.memoryTypeBits & req.memoryTypeBits;
    std::uint32_t type = UINT32_MAX;
    for (std::uint32_t i = 0; i < ctx.memoryProperties.memoryTypeCount && type == UINT32_MAX; ++i)
        if ((typeBits & (1u << i)) &&
            (ctx.memoryProperties.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT))
            type = i;
    if (type == UINT32_MAX) return img;
    const VkImportMemoryHostPointerInfoEXT import{
        .sType = VK_STRUCTURE_TYPE_IMPORT_MEMORY_HOST_POINTER_INFO_EXT,
        .handleType = kHostAllocation,
        .pHostPointer = reinterpret_cast<void*>(base),
    };
    const VkMemoryAllocateInfo alloc{.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
                                     .pNext = &import,
                                     .allocationSize = size,
                                     .memoryTypeIndex = type};
    VkDeviceMemory memory = VK_NULL_HANDLE;
    if (vkAllocateMemory(device, &alloc, nullptr, &memory) != VK_SUCCESS) return img;
    MemoryHandle memoryHandle(device, memory);
    VK_CHECK(vkBindImageMemory(device, image.get(), memory, offset));
    img.view = createView(ctx, image.get(), format, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D, 0, 1);
    img.image = std::move(image);
    img.memory = std::move(memoryHandle);
    img.mapped = data;
    img.rowPitch = VkDeviceSize(width) * texelBytes;
    return img;
}

void prefaultPages(const void* data, std::size_t bytes) {
#ifdef MADV_POPULATE_WRITE
    // Every page the range touches (both ends are in the same mapping as the range).
    const auto begin = reinterpret_cast<std::uintptr_t>(data) & ~std::uintptr_t(4095);
    const auto end = (reinterpret_cast<std::uintptr_t>(data) + bytes + 4095) & ~std::uintptr_t(4095);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE);
#else
    (void)data;
    (void)bytes;
#endif
}

void transition(VkCommandBuffer commands, const std::vector<ImageTransition>& transitions) {
    std::vector<VkImageMemoryBarrier2> barriers;
    for (const ImageTransition& t : transitions)
        barriers.push_back(VkImageMemoryBarrier2{
            .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
            .srcStageMask = t.srcStage,
            .srcAccessMask = t.srcAccess,
            .dstStageMask = t.dstStage,
            .dstAccessMask = t.dstAccess,
            .oldLayout = t.from,
            .newLayout = t.to,
            .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .image = t.image,
            .subresourceRange = {.aspectMask = t.aspect,
                                 .baseMipLevel = 0,
                                 .levelCount = 1,
                                 .baseArrayLayer = 0,
                                 .layerCount = t.layers},
        });
    const VkDependencyInfo dependency{
        .sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
        .imageMemoryBarrierCount = std::uint32_t(barriers.size()),
        .pImageMemoryBarriers = barriers.data(),
    };
    vkCmdPipelineBarrier2(commands, &dependency);
}

void transferToHostBarrier(VkCommandBuffer commands) {
    const VkMemoryBarrier2 barrier{
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
        .srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
        .srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
        .dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT,
        .dstAccessMask = VK_ACCESS_2_HOST_READ_BIT,
    };
    const VkDependencyInfo dependency{
        .sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
        .memoryBarrierCount = 1,
        .pMemoryBarriers = &barrier,
    };
    vkCmdPipelineBarrier2(commands, &dependency);
}

}  // namespace shadowlab::raster

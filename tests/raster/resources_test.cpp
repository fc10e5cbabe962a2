// tests/raster/resources_test.cpp: buffers and images (raster/resources.cpp) on lavapipe with the
// validation layer: each is made at the size, in the format and the kind of memory asked for;
// uploads arrive byte for byte; an image layer holds what was rendered into it through a view of
// that layer; host-readable images are mapped at their first texel with their row pitch; and too
// large an allocation is refused, naming what and both sizes; prefaultPages() makes a range's pages
// present and writable and keeps what they hold.
#include "raster/resources.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include "raster/vulkan_error.h"
#include "tests/kit/render_checked.h"

namespace shadowlab::raster {
namespace {

// Clears `view` (one layer, color attachment optimal) to `value` with a dynamic-rendering pass
// that draws nothing: the load op writes every texel.
void clearThroughView(VkCommandBuffer commands, VkImageView view, std::uint32_t width, std::uint32_t height,
                      const VkClearColorValue& value) {
    const VkRenderingAttachmentInfo color{
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = view,
        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue = {.color = value},
    };
    const VkRenderingInfo rendering{
        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
        .renderArea = {{0, 0}, {width, height}},
        .layerCount = 1,
        .colorAttachmentCount = 1,
        .pColorAttachments = &color,
    };
    vkCmdBeginRendering(commands, &rendering);
    vkCmdEndRendering(commands);
}

TEST(RasterResources, BuffersHaveTheAskedSizeAndHostVisibleOnesAreMapped) {
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    const Buffer host = createBuffer(ctx, 1000, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                     VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    const Buffer device =
        createBuffer(ctx, 1000, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    const Buffer readback = createReadbackBuffer(ctx, 64);
    EXPECT_EQ(host.size, 1000u);
    EXPECT_EQ(device.size, 1000u);
    EXPECT_EQ(readback.size, 64u);
    // Mapped exactly when host-visible memory was required: the whole range can be written.
    ASSERT_NE(host.mapped, nullptr);
    std::memset(host.mapped, 0xab, 1000);
    EXPECT_EQ(device.mapped, nullptr);
    EXPECT_NE(readback.mapped, nullptr);
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(ctx.device.get(), host.buffer.get(), &req);
    EXPECT_GE(req.size, 1000u);
}

TEST(RasterResources, AnUploadArrivesByteForByteInADeviceLocalBuffer) {
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    // 1000 words of a pattern no two neighbours share (Knuth's multiplicative hash of the index).
    std::vector<std::uint32_t> data(1000);
    for (std::uint32_t i = 0; i < data.size(); ++i) data[i] = i * 2654435761u;
    const Buffer uploaded =
        uploadBuffer(ctx, data, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    EXPECT_EQ(uploaded.size, data.size() * 4);
    EXPECT_EQ(uploaded.mapped, nullptr) << "the target is device-local, filled through a staging buffer";
    const Buffer back = createReadbackBuffer(ctx, uploaded.size);
    VkCommandBuffer commands = ctx.beginCommands();
    const VkBufferCopy region{.size = uploaded.size};
    vkCmdCopyBuffer(commands, uploaded.buffer.get(), back.buffer.get(), 1, &region);
    transferToHostBarrier(commands);
    ctx.submitAndWait(commands);
    invalidate(ctx, back);
    EXPECT_EQ(std::memcmp(back.mapped, data.data(), uploaded.size), 0);
}

TEST(RasterResources, AnEmptyUploadIsAFourByteBuffer) {
    // Zero-sized buffers are invalid in Vulkan: nothing to upload still gives a valid buffer.
    test::ValidatedContext vc;
    const Buffer empty = uploadBuffer(vc.get(), nullptr, 0, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    EXPECT_EQ(empty.size, 4u);
    EXPECT_TRUE(empty.buffer);
}

// One format's clear values for two layers and how to read a texel of it back.
struct FormatCase {
    VkFormat format;
    std::uint32_t texelBytes;
    VkClearColorValue layer[2];
    std::vector<std::uint8_t> expected[2];  // one texel's bytes
};

std::vector<std::uint8_t> bytesOf(const void* p, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(p);
    return {b, b + n};
}

TEST(RasterResources, EachLayerOfAnImageHoldsWhatWasRenderedThroughItsView) {
    // A 37 x 23 image with two layers (sizes no driver pads to), each layer cleared through its own
    // one-layer view, then both copied into a buffer of exactly 37·23·2 texels: the copy of the
    // whole extent is valid only if the image has that size (the validation layer checks), and each
    // texel holds its layer's value in the format's encoding: float32 as given; UNORM8 as
    // round(255·x) (0.2 → 51, 1 → 255); R32_UINT as given.
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    constexpr std::uint32_t w = 37, h = 23;
    const float rgba0[4] = {1.5f, -2.25f, 3.0f, 0.125f}, rgba1[4] = {7.0f, 8.0f, 9.0f, 10.0f};
    const std::uint32_t uint0 = 123456789u, uint1 = 42u;
    const std::uint8_t unorm0[4] = {51, 255, 0, 255}, unorm1[4] = {0, 0, 255, 51};
    const FormatCase cases[] = {
        {VK_FORMAT_R32G32B32A32_SFLOAT,
         16,
         {{.float32 = {1.5f, -2.25f, 3.0f, 0.125f}}, {.float32 = {7, 8, 9, 10}}},
         {bytesOf(rgba0, 16), bytesOf(rgba1, 16)}},
        {VK_FORMAT_R8G8B8A8_UNORM,
         4,
         {{.float32 = {0.2f, 1.0f, 0.0f, 1.0f}}, {.float32 = {0.0f, 0.0f, 1.0f, 0.2f}}},
         {bytesOf(unorm0, 4), bytesOf(unorm1, 4)}},
        {VK_FORMAT_R32_UINT,
         4,
         {{.uint32 = {uint0, 0, 0, 0}}, {.uint32 = {uint1, 0, 0, 0}}},
         {bytesOf(&uint0, 4), bytesOf(&uint1, 4)}},
    };
    for (const FormatCase& c : cases) {
        SCOPED_TRACE(int(c.format));
        const Image image =
            createImage(ctx, c.format, w, h, 2, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                        VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D_ARRAY);
        EXPECT_TRUE(image.view);
        EXPECT_EQ(image.mapped, nullptr);
        const ImageViewHandle views[2] = {
            createView(ctx, image.image.get(), c.format, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D, 0, 1),
            createView(ctx, image.image.get(), c.format, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D, 1, 1)};
        const VkDeviceSize bytes = VkDeviceSize(w) * h * 2 * c.texelBytes;
        const Buffer back = createReadbackBuffer(ctx, bytes);
        VkCommandBuffer commands = ctx.beginCommands();
        transition(commands,
                   {{image.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 2, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT}});
        for (int k = 0; k < 2; ++k) clearThroughView(commands, views[k].get(), w, h, c.layer[k]);
        transition(commands, {{image.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 2,
                               VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                               VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT}});
        const VkBufferImageCopy region{
            .imageSubresource = {.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT,
                                 .mipLevel = 0,
                                 .baseArrayLayer = 0,
                                 .layerCount = 2},
            .imageExtent = {w, h, 1},
        };
        vkCmdCopyImageToBuffer(commands, image.image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, back.buffer.get(), 1,
                               &region);
        transferToHostBarrier(commands);
        ctx.submitAndWait(commands);
        invalidate(ctx, back);
        const auto* texels = static_cast<const std::uint8_t*>(back.mapped);
        int wrong[2] = {0, 0};
        for (int k = 0; k < 2; ++k)
            for (std::uint32_t t = 0; t < w * h; ++t) {
                const std::uint8_t* p = texels + (std::size_t(k) * w * h + t) * c.texelBytes;
                wrong[k] += std::memcmp(p, c.expected[k].data(), c.texelBytes) != 0;
            }
        EXPECT_EQ(wrong[0], 0) << "layer 0";
        EXPECT_EQ(wrong[1], 0) << "layer 1";
    }
}

TEST(RasterResources, AHostReadableImageIsMappedAtItsFirstTexelWithItsRowPitch) {
    // lavapipe's device memory is host memory, so linear RGBA32F targets can be read in place
    // (canReadImagesOnHost's doc); every other device copies them. Rendered (cleared) to a known
    // value and read through `mapped` row by row with `rowPitch`, every texel has that value. (Skipped
    // on other devices, where nothing is read in place.)
    test::ValidatedContext vc;
    Context& ctx = vc.get();
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    if (!ctx.deviceReport.lavapipe)
        GTEST_SKIP() << ctx.deviceReport.name << " copies its targets: nothing is read in place";
    ASSERT_TRUE(canReadImagesOnHost(ctx, VK_FORMAT_R32G32B32A32_SFLOAT, usage));
    ctx.deviceReport.lavapipe = false;
    EXPECT_FALSE(canReadImagesOnHost(ctx, VK_FORMAT_R32G32B32A32_SFLOAT, usage)) << "only lavapipe reads in place";
    ctx.deviceReport.lavapipe = true;
    constexpr std::uint32_t w = 29, h = 11;
    const Image image = createImage(ctx, VK_FORMAT_R32G32B32A32_SFLOAT, w, h, 1, usage, VK_IMAGE_ASPECT_COLOR_BIT,
                                    VK_IMAGE_VIEW_TYPE_2D, true);
    ASSERT_NE(image.mapped, nullptr);
    ASSERT_GE(image.rowPitch, VkDeviceSize(w) * 16);
    VkCommandBuffer commands = ctx.beginCommands();
    transition(commands, {{image.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                           VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                           VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT}});
    clearThroughView(commands, image.view.get(), w, h, {.float32 = {0.25f, 0.5f, 4.0f, -1.0f}});
    // Host access to a linear image needs GENERAL.
    transition(commands,
               {{image.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT}});
    ctx.submitAndWait(commands);
    int wrong = 0;
    for (std::uint32_t y = 0; y < h; ++y) {
        const auto* row = reinterpret_cast<const float*>(static_cast<const char*>(image.mapped) + y * image.rowPitch);
        for (std::uint32_t x = 0; x < w; ++x)
            wrong +=
                !(row[4 * x] == 0.25f && row[4 * x + 1] == 0.5f && row[4 * x + 2] == 4.0f && row[4 * x + 3] == -1.0f);
    }
    EXPECT_EQ(wrong, 0);
}

TEST(RasterResources, TooLargeAnAllocationIsRefusedNamingWhatAndBothSizes) {
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    // The largest device-local heap, read here from the device's own table.
    VkDeviceSize largest = 0;
    for (std::uint32_t i = 0; i < ctx.memoryProperties.memoryHeapCount; ++i)
        if (ctx.memoryProperties.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            largest = std::max(largest, ctx.memoryProperties.memoryHeaps[i].size);
    ASSERT_GT(largest, 0u);
    EXPECT_NO_THROW(requireDeviceMemory(ctx, largest, "all of it"));
    constexpr VkDeviceSize kMiB = 1024 * 1024;
    try {
        requireDeviceMemory(ctx, largest + 3 * kMiB, "a test image");
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("a test image"), std::string::npos) << what;
        EXPECT_NE(what.find(std::to_string((largest + 3 * kMiB) / kMiB) + " MiB"), std::string::npos) << what;
        EXPECT_NE(what.find(std::to_string(largest / kMiB) + " MiB"), std::string::npos) << what;
        EXPECT_NE(what.find(ctx.deviceReport.name), std::string::npos) << what;
    }
}

// Minor page faults of the calling thread so far.
long threadMinorFaults() {
    rusage usage{};
    getrusage(RUSAGE_THREAD, &usage);
    return usage.ru_minflt;
}

// Reads and then writes one byte of every page, as llvmpipe does under a partly covered block.
void readThenWriteEachPage(volatile unsigned char* bytes, std::size_t pages) {
    for (std::size_t k = 0; k < pages; ++k) bytes[k * 4096 + 7] = bytes[k * 4096 + 7] + 1;
}

TEST(RasterResources, PrefaultedPagesTakeNoFaultWhenReadThenWrittenAndKeepWhatTheyHeld) {
    constexpr std::size_t kPages = 64;
    auto map = [] {
        void* p = mmap(nullptr, kPages * 4096, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        EXPECT_NE(p, MAP_FAILED);
        return static_cast<unsigned char*>(p);
    };
    unsigned char* probe = map();
#ifdef MADV_POPULATE_WRITE
    const bool kernelPopulates = madvise(probe, 4096, MADV_POPULATE_WRITE) == 0;
#else
    const bool kernelPopulates = false;
#endif
    munmap(probe, kPages * 4096);
    if (!kernelPopulates)
        GTEST_SKIP() << "this kernel has no MADV_POPULATE_WRITE (Linux 5.14): prefaultPages does nothing";

    // Without: each page faults at the read (the zero page) and again at the write.
    unsigned char* plain = map();
    long before = threadMinorFaults();
    readThenWriteEachPage(plain, kPages);
    EXPECT_GE(threadMinorFaults() - before, long(kPages)) << "the control must fault";
    munmap(plain, kPages * 4096);

    // With: a byte already written keeps its value; the range starts inside the first page and
    // ends inside the last, and every page it touches is present and writable.
    unsigned char* bytes = map();
    bytes[3 * 4096 + 11] = 42;
    prefaultPages(bytes + 100, kPages * 4096 - 200);
    before = threadMinorFaults();
    readThenWriteEachPage(bytes, kPages);
    EXPECT_EQ(threadMinorFaults() - before, 0);
    EXPECT_EQ(bytes[3 * 4096 + 11], 42);
    for (std::size_t k = 0; k < kPages; ++k) ASSERT_EQ(bytes[k * 4096 + 7], 1) << "page " << k;
    EXPECT_EQ(bytes[5 * 4096 + 9], 0);
    munmap(bytes, kPages * 4096);
}

}  // namespace
}  // namespace shadowlab::raster

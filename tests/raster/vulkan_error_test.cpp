// tests/raster/vulkan_error_test.cpp: VK_CHECK throws a VulkanError that names the call, the
// result and the place.
#include "raster/vulkan_error.h"

#include <gtest/gtest.h>

namespace shadowlab::raster {
namespace {

VkResult failWith(VkResult r) { return r; }

TEST(VulkanError, VkCheckNamesTheCallTheResultAndTheLine) {
    const int line = __LINE__ + 2;
    try {
        VK_CHECK(failWith(VK_ERROR_OUT_OF_DEVICE_MEMORY));
        FAIL() << "VK_CHECK did not throw";
    } catch (const VulkanError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY);
        EXPECT_NE(what.find("failWith(VK_ERROR_OUT_OF_DEVICE_MEMORY)"), std::string::npos) << what;
        EXPECT_NE(what.find("failed with VK_ERROR_OUT_OF_DEVICE_MEMORY"), std::string::npos) << what;
        EXPECT_NE(what.find("vulkan_error_test.cpp:" + std::to_string(line)), std::string::npos) << what;
    }
}

TEST(VulkanError, VkCheckPassesSuccessThrough) { EXPECT_NO_THROW(VK_CHECK(failWith(VK_SUCCESS))); }

TEST(VulkanError, UnknownResultsPrintTheirNumber) {
    EXPECT_EQ(toString(VkResult(-123456)), "VkResult(-123456)");
    EXPECT_EQ(toString(VK_ERROR_DEVICE_LOST), "VK_ERROR_DEVICE_LOST");
}

TEST(VulkanError, FailuresAUserCanMeetLeadWithWhatHappenedAndWhatToDo) {
    auto message = [](VkResult r) {
        try {
            VK_CHECK(failWith(r));
        } catch (const VulkanError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const std::string lost = message(VK_ERROR_DEVICE_LOST);
    EXPECT_EQ(lost.rfind("the Vulkan device was lost during the render", 0), 0u) << lost;
    EXPECT_NE(lost.find("--backend raytrace"), std::string::npos) << lost;
    EXPECT_NE(lost.find("failed with VK_ERROR_DEVICE_LOST"), std::string::npos) << lost;
    EXPECT_NE(message(VK_ERROR_OUT_OF_DEVICE_MEMORY).find("lower --resolution or --shadow-map-size"),
              std::string::npos);
    EXPECT_NE(message(VK_TIMEOUT).find("did not finish in time"), std::string::npos);
    // Programming errors keep the plain form: the call, the result, the place.
    EXPECT_EQ(message(VK_ERROR_FORMAT_NOT_SUPPORTED).rfind("failWith(", 0), 0u);
}

TEST(VulkanError, IsARasterError) {
    // app/ maps RasterError (all raster failures) to one message and exit code 1.
    EXPECT_THROW(VK_CHECK(failWith(VK_ERROR_INITIALIZATION_FAILED)), RasterError);
}

}  // namespace
}  // namespace shadowlab::raster

// tests/raster/context_test.cpp: device selection (pure, on made-up device lists) and the
// real device list of this machine (lavapipe, with the validation layer).
#include "raster/context.h"

#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>

#include <gtest/gtest.h>

#include "raster/vulkan_error.h"
#include "tests/kit/render_checked.h"

namespace shadowlab::raster {
namespace {

DeviceReport device(int index, const std::string& name, bool lavapipe, bool usable = true) {
    DeviceReport d;
    d.index = index;
    d.name = name;
    d.type = lavapipe ? "cpu" : "discrete-gpu";
    d.driverName = lavapipe ? "llvmpipe" : "vendor";
    d.lavapipe = lavapipe;
    d.usable = usable;
    d.unusableReason = usable ? "" : "Vulkan 1.2.0 < 1.3";
    return d;
}

const std::vector<DeviceReport> kDevices = {device(0, "Fancy GPU 9000", false),
                                            device(1, "llvmpipe (LLVM 15.0.6, 256 bits)", true),
                                            device(2, "Old GPU", false, false)};

TEST(SelectDevice, DefaultIsLavapipeEvenWhenNotFirst) { EXPECT_EQ(selectDevice(kDevices, ""), 1u); }

TEST(SelectDevice, DefaultFallsBackToTheFirstUsableDevice) {
    EXPECT_EQ(selectDevice({device(0, "Old GPU", false, false), device(1, "Fancy GPU", false)}, ""), 1u);
}

TEST(SelectDevice, IndexSelectsThatDevice) { EXPECT_EQ(selectDevice(kDevices, "0"), 0u); }

TEST(SelectDevice, NameSubstringIsCaseInsensitive) { EXPECT_EQ(selectDevice(kDevices, "fancy"), 0u); }

TEST(SelectDevice, UnmatchedSelectorListsEveryDevice) {
    for (const std::string selector : {"7", "radeon"}) {
        try {
            selectDevice(kDevices, selector);
            FAIL() << "expected RasterError for " << selector;
        } catch (const RasterError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("'" + selector + "'"), std::string::npos) << what;
            for (const DeviceReport& d : kDevices) EXPECT_NE(what.find(d.name), std::string::npos) << what;
        }
    }
}

TEST(SelectDevice, UnusableDeviceIsRefusedWithTheReason) {
    try {
        selectDevice(kDevices, "old");
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        EXPECT_NE(std::string(e.what()).find("1.2.0 < 1.3"), std::string::npos) << e.what();
    }
}

TEST(SelectDevice, NoUsableDeviceNamesThePackage) {
    try {
        selectDevice({device(0, "Old GPU", false, false)}, "");
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        EXPECT_NE(std::string(e.what()).find("mesa-vulkan-drivers"), std::string::npos) << e.what();
    }
}

// Sets an environment variable for the scope of a test, restoring the old value.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        setenv(name, value, 1);
    }
    ~ScopedEnv() {
        if (old_)
            setenv(name_, old_->c_str(), 1);
        else
            unsetenv(name_);
    }

private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(Devices, NoDriverNamesTheMesaPackage) {
    // The loader reads its driver list on every instance creation; pointing it at a missing
    // manifest is a machine without an ICD.
    const ScopedEnv icd("VK_ICD_FILENAMES", "/nonexistent/shadowlab_icd.json");
    const ScopedEnv drivers("VK_DRIVER_FILES", "/nonexistent/shadowlab_icd.json");
    try {
        enumerateDevices(false);
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        EXPECT_NE(std::string(e.what()).find("mesa-vulkan-drivers"), std::string::npos) << e.what();
    }
}

TEST(Devices, MissingValidationLayerNamesItsPackage) {
    // VK_LAYER_PATH replaces the loader's search path for explicit layers.
    const ScopedEnv layers("VK_LAYER_PATH", "/nonexistent/shadowlab_layers");
    try {
        enumerateDevices(true);
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        EXPECT_NE(std::string(e.what()).find("vulkan-validationlayers"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(enumerateDevices(false));  // without validation the layer is not needed
}

TEST(Devices, ThisMachineHasLavapipeAsTheDefault) {
    const std::vector<DeviceReport> devices = enumerateDevices(true);
    ASSERT_FALSE(devices.empty());
    int defaults = 0;
    for (const DeviceReport& d : devices) {
        defaults += d.isDefault;
        if (d.isDefault) {
            EXPECT_TRUE(d.lavapipe);
            EXPECT_TRUE(d.usable) << d.unusableReason;
            EXPECT_GE(d.apiVersion, VK_API_VERSION_1_3);
        }
    }
    EXPECT_EQ(defaults, 1);
    const std::string text = describeDevices(false);
    EXPECT_NE(text.find("Vulkan instance version: 1."), std::string::npos) << text;
    EXPECT_NE(text.find("[default]"), std::string::npos) << text;
    EXPECT_NE(text.find("lavapipe"), std::string::npos) << text;
}

TEST(Devices, ValidatedContextCreationAndDestructionIsClean) {
    ValidationLog log;
    log.echo = true;
    {
        const Context ctx(ContextOptions{.device = "", .validate = true, .log = &log});
        EXPECT_NE(ctx.queue, VK_NULL_HANDLE);
    }
    EXPECT_EQ(log.count.load(), 0);
}

TEST(Devices, ThePipelineCacheIsSavedForThisDeviceAndLoadedAgain) {
    const std::filesystem::path home =
        std::filesystem::temp_directory_path() / ("shadowlab-cache-test-" + std::to_string(::getpid()));
    ::setenv("XDG_CACHE_HOME", home.c_str(), 1);
    ValidationLog log;
    std::filesystem::path file;
    VkPhysicalDeviceProperties props{};
    {
        const Context ctx(ContextOptions{.validate = true, .log = &log});
        ASSERT_NE(ctx.pipelineCache.get(), VK_NULL_HANDLE);
        file = ctx.pipelineCacheFile;
        props = ctx.properties;
        EXPECT_EQ(file.parent_path(), home / "shadowlab" / "vulkan");
    }
    // The saved file starts with the header the spec defines, naming this device.
    std::ifstream in(file, std::ios::binary);
    std::uint32_t header[4] = {};
    ASSERT_TRUE(in.read(reinterpret_cast<char*>(header), sizeof header)) << file;
    EXPECT_GE(header[0], 32u);
    EXPECT_EQ(header[1], std::uint32_t(VK_PIPELINE_CACHE_HEADER_VERSION_ONE));
    EXPECT_EQ(header[2], props.vendorID);
    EXPECT_EQ(header[3], props.deviceID);
    // A second context reads it back (and a damaged file is ignored, not handed to the driver).
    { const Context again(ContextOptions{.validate = true, .log = &log}); }
    std::ofstream(file, std::ios::binary | std::ios::trunc) << std::string(64, 'x');
    { const Context damaged(ContextOptions{.validate = true, .log = &log}); }
    EXPECT_EQ(log.count.load(), 0);
    std::filesystem::remove_all(home);
}

TEST(Devices, AnUnvalidatedInstanceDoesNotBreakALivingValidatedOne) {
    // The function pointers are shared; a second instance without the debug-utils extension
    // must not take away the messenger's destroy function from the first.
    ValidationLog log;
    {
        const Context validated(ContextOptions{.validate = true, .log = &log});
        EXPECT_FALSE(enumerateDevices(false).empty());
    }  // destroys the messenger through the shared pointer
    EXPECT_EQ(log.count.load(), 0);
}

TEST(Devices, SelectingByIndexAndByNameGivesTheSameDevice) {
    ValidationLog log;
    const Context byIndex(ContextOptions{.device = "0", .validate = true, .log = &log});
    const Context byName(
        ContextOptions{.device = byIndex.deviceReport.name.substr(0, 5), .validate = true, .log = &log});
    EXPECT_EQ(byIndex.deviceReport.name, byName.deviceReport.name);
    EXPECT_EQ(log.count.load(), 0);
}

TEST(RasterContext, MemoryTypeIsTheFirstWithTheRequiredFlagsPreferringOneWithThePreferredToo) {
    // context.h: a type allowed by typeBits with all of `required`; among those one with all of
    // `preferred` when there is one; else the first; RasterError naming the device when none fits.
    // A made-up table of four types, set on a real context (restored before it is destroyed).
    test::ValidatedContext vc;
    Context& ctx = vc.get();
    const VkPhysicalDeviceMemoryProperties real = ctx.memoryProperties;
    constexpr VkMemoryPropertyFlags local = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                                    visible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                                    coherent = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                    cached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
    ctx.memoryProperties.memoryTypeCount = 4;
    const VkMemoryPropertyFlags types[4] = {local, visible | coherent, visible | coherent | cached, local | visible};
    for (int i = 0; i < 4; ++i) ctx.memoryProperties.memoryTypes[i] = {types[i], 0};
    EXPECT_EQ(ctx.memoryType(0b1111, local), 0u);
    EXPECT_EQ(ctx.memoryType(0b1111, visible), 1u);                    // the first that has it
    EXPECT_EQ(ctx.memoryType(0b1111, visible, cached), 2u);            // one with the preferred too
    EXPECT_EQ(ctx.memoryType(0b1011, visible, cached), 1u);            // type 2 not allowed: the first
    EXPECT_EQ(ctx.memoryType(0b1110, local), 3u);                      // type 0 not allowed
    EXPECT_EQ(ctx.memoryType(0b1111, visible | coherent, local), 1u);  // no type has both: the first
    try {
        ctx.memoryType(0b0111, local | visible);
        ADD_FAILURE() << "expected RasterError";
    } catch (const RasterError& e) {
        EXPECT_NE(std::string(e.what()).find(ctx.deviceReport.name), std::string::npos) << e.what();
    }
    ctx.memoryProperties = real;
}

}  // namespace
}  // namespace shadowlab::raster

// raster/devices.h: what Vulkan devices this machine has, which one a render uses, and the
// text `shadowlab info` prints. Lavapipe (Mesa's CPU driver) is the default: it is on every
// machine we target and gives the same answer everywhere.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace shadowlab::raster {

struct DeviceReport {
    int index = 0;           // position in vkEnumeratePhysicalDevices; what --device N selects
    std::string name;        // VkPhysicalDeviceProperties::deviceName
    std::string type;        // "cpu", "integrated-gpu", "discrete-gpu", "virtual-gpu", "other"
    std::string driverName;  // VkPhysicalDeviceDriverProperties
    std::string driverInfo;
    std::uint32_t apiVersion = 0;
    std::string apiVersionText;  // "1.3.230"
    bool lavapipe = false;       // driverID MESA_LLVMPIPE or a CPU device
    bool usable = false;         // Vulkan 1.3, a graphics queue, dynamic rendering, synchronization2
    std::string unusableReason;  // why not, when !usable
    bool isDefault = false;      // what a render picks when --device is not given
};

// Every physical device, with `isDefault` set. With `validate`, the instance is created with
// VK_LAYER_KHRONOS_validation, which checks that the layer loads. Throws RasterError when there
// is no loader, no driver or no device, naming the Debian package that provides it.
std::vector<DeviceReport> enumerateDevices(bool validate);

// Human-readable: the loader's instance version and, per device, name, type, driver, API
// version, lavapipe or not, usable or not and which one is the default.
std::string describeDevices(bool validate = false);

// The index into `devices` that `selector` names: "" = the first usable lavapipe device, else
// the first usable device; all digits = that index; otherwise the first device whose name
// contains `selector` (case-insensitive). Throws RasterError listing the devices when nothing
// matches or the match is not usable.
std::size_t selectDevice(const std::vector<DeviceReport>& devices, const std::string& selector);

// "1.3.230"
std::string versionText(std::uint32_t apiVersion);

}  // namespace shadowlab::raster

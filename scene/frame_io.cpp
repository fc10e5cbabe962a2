// scene/frame_io.cpp: EXR/PNG Frame I/O with OpenImageIO, always through a temporary file
// and a rename so an interrupted write never leaves a torn file behind.
#include "scene/frame_io.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include "scene/error.h"

namespace shadowlab::scene {

namespace {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

constexpr const char* kAttrPrefix = "shadowlab:";
constexpr const char* kTimingsAttr = "shadowlab:timings_ms";

// A sibling of `file` with the same extension (OpenImageIO picks the format by extension).
fs::path temporarySibling(const fs::path& file) {
    static std::atomic<unsigned> counter{0};
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
    return dir / ("." + file.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                  std::to_string(counter++) + file.extension().string());
}

// Runs `write(tmp)` and renames tmp onto `file`; removes tmp if anything fails.
template <typename WriteFn>
void writeAtomically(const fs::path& file, WriteFn&& write) {
    const fs::path tmp = temporarySibling(file);
    try {
        write(tmp);
        fs::rename(tmp, file);
    } catch (...) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        throw;
    }
}

void writeImage(const fs::path& file, const ImageSpec& spec, const void* pixels, TypeDesc type) {
    auto out = ImageOutput::create(file.string());
    if (!out)
        throw InputError(file.string() + ": cannot write this image format (" +
                         OIIO::geterror() + ")");
    if (!out->open(file.string(), spec))
        throw InputError(file.string() + ": cannot open for writing: " + out->geterror());
    if (!out->write_image(type, pixels))
        throw InputError(file.string() + ": write failed: " + out->geterror());
    if (!out->close()) throw InputError(file.string() + ": close failed: " + out->geterror());
}

std::string encodeTimings(const std::vector<std::pair<std::string, double>>& timings) {
    std::ostringstream s;
    s.precision(17);
    for (std::size_t i = 0; i < timings.size(); ++i)
        s << (i ? ";" : "") << timings[i].first << "=" << timings[i].second;
    return s.str();
}

std::vector<std::pair<std::string, double>> decodeTimings(const std::string& text) {
    std::vector<std::pair<std::string, double>> out;
    std::istringstream s(text);
    std::string item;
    while (std::getline(s, item, ';')) {
        const auto eq = item.find('=');
        if (eq == std::string::npos) continue;
        try {
            out.emplace_back(item.substr(0, eq), std::stod(item.substr(eq + 1)));
        } catch (const std::exception&) {
            // A malformed timing is metadata only: skip it rather than reject the frame.
        }
    }
    return out;
}

void writePng8(const fs::path& file, int width, int height, const std::vector<float>& rgb,
               bool encodeSrgb) {
    if (rgb.size() != std::size_t(width) * std::size_t(height) * 3)
        throw std::invalid_argument("writePng: pixel count does not match the size");
    std::vector<unsigned char> bytes(rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        float v = rgb[i];
        if (!std::isfinite(v)) v = 0.0f;
        if (encodeSrgb) v = linearToSrgb(v);
        bytes[i] = static_cast<unsigned char>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
    }
    ImageSpec spec(width, height, 3, TypeDesc::UINT8);
    writeAtomically(file, [&](const fs::path& tmp) {
        writeImage(tmp, spec, bytes.data(), TypeDesc::UINT8);
    });
}

}  // namespace

std::string lightVisibilityChannel(std::size_t light) { return "visibility." + std::to_string(light); }

float linearToSrgb(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

void writePngLinear(const fs::path& file, int width, int height, const std::vector<float>& rgb) {
    writePng8(file, width, height, rgb, true);
}

void writePngDisplay(const fs::path& file, int width, int height, const std::vector<float>& rgb) {
    writePng8(file, width, height, rgb, false);
}

void writeTextAtomic(const fs::path& file, const std::string& text) {
    writeAtomically(file, [&](const fs::path& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw InputError(file.string() + ": cannot write");
    });
}

void writeFrame(const Frame& frame, const fs::path& file) {
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".png") {
        writePngLinear(file, frame.width, frame.height, frame.beauty);
        return;
    }
    if (ext != ".exr")
        throw InputError(file.string() + ": unknown output type '" + ext + "' (use .exr or .png)");

    const bool withBlocker = !frame.blockerId.empty();
    const std::size_t n = frame.pixelCount();
    for (const std::vector<float>* v : {&frame.visibility, &frame.objectId, &frame.ndotl, &frame.depth})
        if (v->size() != n)
            throw std::invalid_argument(file.string() + ": the frame lacks an AOV an EXR needs (rendered for a PNG?)");
    for (const std::vector<float>& v : frame.lightVisibility)
        if (v.size() != n) throw std::invalid_argument(file.string() + ": a per-light visibility has the wrong size");
    const std::size_t lights = frame.lightVisibility.size();
    const int channels = (withBlocker ? 8 : 7) + int(lights);
    ImageSpec spec(frame.width, frame.height, channels, TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "visibility", "object_id", "ndotl", "Z"};
    if (withBlocker) spec.channelnames.push_back("blocker_id");
    // Per-light visibility, light i as "visibility.<i>" (an EXR layer "visibility").
    for (std::size_t l = 0; l < lights; ++l) spec.channelnames.push_back(lightVisibilityChannel(l));
    spec.alpha_channel = -1;
    spec.z_channel = 6;
    spec.attribute("compression", "zip");
    for (const auto& [key, value] : frame.attributes) spec.attribute(kAttrPrefix + key, value);
    spec.attribute(kTimingsAttr, encodeTimings(frame.timingsMs));

    const int firstLight = withBlocker ? 8 : 7;
    std::vector<float> pixels(n * channels);
    for (std::size_t i = 0; i < n; ++i) {
        float* p = &pixels[i * channels];
        p[0] = frame.beauty[3 * i];
        p[1] = frame.beauty[3 * i + 1];
        p[2] = frame.beauty[3 * i + 2];
        p[3] = frame.visibility[i];
        p[4] = frame.objectId[i];
        p[5] = frame.ndotl[i];
        p[6] = frame.depth[i];
        if (withBlocker) p[7] = frame.blockerId[i];
        for (std::size_t l = 0; l < lights; ++l) p[firstLight + l] = frame.lightVisibility[l][i];
    }
    writeAtomically(file, [&](const fs::path& tmp) {
        writeImage(tmp, spec, pixels.data(), TypeDesc::FLOAT);
    });
}

Frame readFrame(const fs::path& file) {
    if (!fs::exists(file)) throw InputError(file.string() + ": no such file");
    auto in = ImageInput::open(file.string());
    if (!in) throw InputError(file.string() + ": not a readable image: " + OIIO::geterror());
    const ImageSpec spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.depth > 1)
        throw InputError(file.string() + ": not a 2D image");
    if (std::int64_t(spec.width) * spec.height * spec.nchannels > (std::int64_t(1) << 31))
        throw InputError(file.string() + ": image too large (" + std::to_string(spec.width) + "x" +
                         std::to_string(spec.height) + ")");

    auto channelIndex = [&](const std::string& name, bool required) {
        const auto it = std::find(spec.channelnames.begin(), spec.channelnames.end(), name);
        if (it == spec.channelnames.end()) {
            if (!required) return -1;
            throw InputError(file.string() + ": missing channel '" + name +
                             "' (is this a Frame written by `shadowlab render -o X.exr`?)");
        }
        return int(it - spec.channelnames.begin());
    };
    const int iR = channelIndex("R", true), iG = channelIndex("G", true),
              iB = channelIndex("B", true), iV = channelIndex("visibility", true),
              iId = channelIndex("object_id", true), iN = channelIndex("ndotl", true),
              iZ = channelIndex("Z", true), iBl = channelIndex("blocker_id", false);

    std::vector<float> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
    if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, pixels.data()))
        throw InputError(file.string() + ": read failed: " + in->geterror());

    // visibility.0, visibility.1, ... up to the first index that is missing.
    std::vector<int> iLights;
    for (std::size_t l = 0;; ++l) {
        const int idx = channelIndex(lightVisibilityChannel(l), false);
        if (idx < 0) break;
        iLights.push_back(idx);
    }

    Frame f = Frame::allocate(spec.width, spec.height, iBl >= 0);
    f.lightVisibility.assign(iLights.size(), std::vector<float>(f.pixelCount()));
    const std::size_t n = f.pixelCount();
    const int c = spec.nchannels;
    for (std::size_t i = 0; i < n; ++i) {
        const float* p = &pixels[i * c];
        f.beauty[3 * i] = p[iR];
        f.beauty[3 * i + 1] = p[iG];
        f.beauty[3 * i + 2] = p[iB];
        f.visibility[i] = p[iV];
        f.objectId[i] = p[iId];
        f.ndotl[i] = p[iN];
        f.depth[i] = p[iZ];
        if (iBl >= 0) f.blockerId[i] = p[iBl];
        for (std::size_t l = 0; l < iLights.size(); ++l) f.lightVisibility[l][i] = p[iLights[l]];
    }
    const std::string prefix = kAttrPrefix;
    for (const auto& attr : spec.extra_attribs) {
        const std::string name = attr.name().string();
        if (name == kTimingsAttr)
            f.timingsMs = decodeTimings(attr.get_string());
        else if (name.rfind(prefix, 0) == 0)
            f.attributes[name.substr(prefix.size())] = attr.get_string();
    }
    return f;
}

}  // namespace shadowlab::scene

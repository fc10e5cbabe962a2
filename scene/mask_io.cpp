// scene/mask_io.cpp: reading an external shadow mask with OpenImageIO.
#include "scene/mask_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <OpenImageIO/imageio.h>

#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/input_file.h"
#include "scene/loader.h"

namespace shadowlab::scene {

namespace {

float srgbToLinear(float e) {  // IEC 61966-2-1
    return e <= 0.04045f ? e / 12.92f : std::pow((e + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

bool looksLikeMask(const std::filesystem::path& file) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) return false;
    const std::string ext = lowercaseExtension(file);
    if (ext == ".png") return true;
    if (ext != ".exr") return false;
    auto in = OIIO::ImageInput::open(file.string());
    if (!in) return false;
    // A Frame has a beauty and the reference-side channels beside its visibility; an engine's
    // one-channel EXR may well call its channel "visibility" and is still a mask.
    const auto& names = in->spec().channelnames;
    const auto has = [&](const char* n) { return std::find(names.begin(), names.end(), n) != names.end(); };
    return names.size() == 1 || !(has("visibility") && has("object_id"));
}

void checkMaskFileType(const std::filesystem::path& file) {
    const std::string ext = lowercaseExtension(file);
    if (ext == ".png" || ext == ".exr") return;
    throw InputError(file.string() + ": a shadow mask is read from a .png or an .exr" +
                     std::string(ext == ".jpg" || ext == ".jpeg"
                                     ? " (JPEG's lossy coding moves a mask's values along every shadow edge)"
                                     : "") +
                     "; save the mask as one of those");
}

ShadowMask readShadowMask(const std::filesystem::path& file, const MaskOptions& o) {
    if (!std::filesystem::exists(file)) throw InputError(file.string() + ": no such file");
    checkMaskFileType(file);
    auto in = OIIO::ImageInput::open(file.string());
    if (!in) throw InputError(file.string() + ": not a readable image: " + OIIO::geterror());
    const OIIO::ImageSpec spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.depth > 1 || spec.width > kMaxResolution ||
        spec.height > kMaxResolution || std::int64_t(spec.width) * spec.height > kMaxPixels || spec.nchannels > 64)
        throw InputError(file.string() + ": not a 2D image of at most " + std::to_string(kMaxResolution) +
                         " pixels a side and 64 channels");
    // The size first: a mask of another size is the wrong image, whatever its values.
    if (o.expectedWidth > 0 && (spec.width != o.expectedWidth || spec.height != o.expectedHeight))
        throw InputError(file.string() + ": the mask is " + std::to_string(spec.width) + "x" +
                         std::to_string(spec.height) + ", the reference " + std::to_string(o.expectedWidth) + "x" +
                         std::to_string(o.expectedHeight) + " (render both from the same camera and size)");
    std::string names;
    for (const std::string& n : spec.channelnames) names += (names.empty() ? "" : ", ") + n;
    int channel = 0;
    if (o.channel) {
        const auto it = std::find(spec.channelnames.begin(), spec.channelnames.end(), *o.channel);
        if (it == spec.channelnames.end())
            throw InputError(file.string() + ": no channel '" + *o.channel + "' (it has " + names + ")");
        channel = int(it - spec.channelnames.begin());
    } else if (spec.nchannels != 1) {
        throw InputError(file.string() + ": " + std::to_string(spec.nchannels) + " channels (" + names +
                         "): a shadow mask has one, or choose one with --mask-channel");
    }
    ShadowMask m;
    m.width = spec.width;
    m.height = spec.height;
    m.channel = spec.channelnames.empty() ? "" : spec.channelnames[std::size_t(channel)];
    m.visibility.resize(std::size_t(spec.width) * spec.height);
    // Integer formats are read as code / max (OpenImageIO's conversion to float): 255 = 1.
    if (!in->read_image(0, 0, channel, channel + 1, OIIO::TypeDesc::FLOAT, m.visibility.data()))
        throw InputError(file.string() + ": read failed: " + in->geterror());
    for (std::size_t i = 0; i < m.visibility.size(); ++i) {
        float& v = m.visibility[i];
        if (!std::isfinite(v) || v < 0.0f || v > 1.0f)
            throw InputError(file.string() + ": channel '" + m.channel + "' at pixel (" +
                             std::to_string(i % spec.width) + ", " + std::to_string(i / spec.width) + ") is " +
                             std::to_string(v) + ", outside 0..1 (1 = lit)");
        if (o.srgb) v = srgbToLinear(v);
        if (o.invert) v = 1.0f - v;
    }
    return m;
}

Frame frameFromMask(const ShadowMask& mask, const Frame& reference, const std::filesystem::path& maskFile) {
    if (mask.width != reference.width || mask.height != reference.height)
        throw InputError(maskFile.string() + ": the mask is " + std::to_string(mask.width) + "x" +
                         std::to_string(mask.height) + ", the reference " + std::to_string(reference.width) + "x" +
                         std::to_string(reference.height) + " (render both from the same camera and size)");
    Frame f;
    f.width = reference.width;
    f.height = reference.height;
    f.beauty = reference.beauty;
    f.visibility = mask.visibility;
    f.objectId = reference.objectId;
    f.ndotl = reference.ndotl;
    f.depth = reference.depth;
    f.attributes["backend"] = "mask";
    f.attributes["mask_file"] = maskFile.string();
    f.attributes["mask_channel"] = mask.channel;
    return f;
}

}  // namespace shadowlab::scene

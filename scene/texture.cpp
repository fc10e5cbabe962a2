// scene/texture.cpp: reading a texture's alpha with OpenImageIO.
#include "scene/texture.h"

#include <cmath>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "scene/input_file.h"

namespace shadowlab::scene {

namespace {

// Reads the alpha of an opened image; `file` names it in messages.
std::shared_ptr<AlphaTexture> readAlpha(OIIO::ImageInput* in, const std::filesystem::path& file, TextureWrap wrapS,
                                        TextureWrap wrapT) {
    if (!in) throw InputFileError(file, "not a readable image: " + OIIO::geterror());
    const OIIO::ImageSpec spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.depth > 1 || spec.width > kMaxTextureSide ||
        spec.height > kMaxTextureSide || spec.nchannels < 1 || spec.nchannels > 64)
        throw InputFileError(file, "not a 2D image of at most " + std::to_string(kMaxTextureSide) +
                                       " pixels a side and 64 channels (" + std::to_string(spec.width) + "x" +
                                       std::to_string(spec.height) + ", " + std::to_string(spec.nchannels) +
                                       " channels)");
    auto t = std::make_shared<AlphaTexture>();
    t->file = file;
    t->width = spec.width;
    t->height = spec.height;
    t->wrapS = wrapS;
    t->wrapT = wrapT;
    int channel = spec.alpha_channel;
    if (channel < 0 && (spec.nchannels == 2 || spec.nchannels == 4)) channel = spec.nchannels - 1;
    t->alpha.assign(std::size_t(spec.width) * std::size_t(spec.height), 1.0f);
    if (channel >= 0) {
        // Integer formats are read as code / max (OpenImageIO's conversion): 255 = 1, 128 = 0.50196.
        if (!in->read_image(0, 0, channel, channel + 1, OIIO::TypeDesc::FLOAT, t->alpha.data()))
            throw InputFileError(file, "read failed: " + in->geterror());
        for (std::size_t i = 0; i < t->alpha.size(); ++i)
            if (!(t->alpha[i] >= 0.0f && t->alpha[i] <= 1.0f))
                throw InputFileError(file, "alpha at pixel (" + std::to_string(i % std::size_t(spec.width)) + ", " +
                                               std::to_string(i / std::size_t(spec.width)) + ") is " +
                                               std::to_string(t->alpha[i]) + ", outside 0..1");
    }
    return t;
}

}  // namespace

std::shared_ptr<const AlphaTexture> loadAlphaTexture(const std::filesystem::path& file, TextureWrap wrapS,
                                                     TextureWrap wrapT, TextureCache* cache) {
    std::error_code ec;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(file, ec);
    const auto key = std::make_tuple((ec ? file : canonical).string(), int(wrapS), int(wrapT));
    if (cache)
        if (const auto it = cache->textures.find(key); it != cache->textures.end()) return it->second;
    // OpenImageIO opens the file itself: checked first (regular file, bounded size), as masks are.
    checkInputFile(file, kMaxMeshFileBytes);
    auto in = OIIO::ImageInput::open(file.string());
    std::shared_ptr<const AlphaTexture> t = readAlpha(in.get(), file, wrapS, wrapT);
    if (cache) cache->textures[key] = t;
    return t;
}

std::shared_ptr<const AlphaTexture> loadAlphaTextureFromMemory(const std::string& name, const std::string& ext,
                                                               const std::vector<unsigned char>& bytes,
                                                               TextureWrap wrapS, TextureWrap wrapT) {
    OIIO::Filesystem::IOMemReader reader(const_cast<unsigned char*>(bytes.data()), bytes.size());
    auto in = OIIO::ImageInput::open("image" + ext, nullptr, &reader);
    return readAlpha(in.get(), name, wrapS, wrapT);
}

bool textureWrapFromName(const std::string& name, TextureWrap& out) {
    if (name == "repeat")
        out = TextureWrap::Repeat;
    else if (name == "clamp_to_edge")
        out = TextureWrap::ClampToEdge;
    else if (name == "mirrored_repeat")
        out = TextureWrap::MirroredRepeat;
    else
        return false;
    return true;
}

const char* textureWrapName(TextureWrap w) {
    switch (w) {
        case TextureWrap::ClampToEdge: return "clamp_to_edge";
        case TextureWrap::MirroredRepeat: return "mirrored_repeat";
        case TextureWrap::Repeat: break;
    }
    return "repeat";
}

const char* alphaModeName(AlphaMode m) {
    switch (m) {
        case AlphaMode::Mask: return "mask";
        case AlphaMode::Blend: return "blend";
        case AlphaMode::Opaque: break;
    }
    return "opaque";
}

}  // namespace shadowlab::scene

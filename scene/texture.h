// scene/texture.h: alpha textures for alpha-tested and blended casters, read with OpenImageIO
// through the one input opener; each file (with its wrap modes) read once per scene.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "scene/scene.h"

namespace shadowlab::scene {

// Texture files are bounded like the frames and masks shadowlab reads (pixels per side and in
// all), and in bytes like a mesh file.
inline constexpr int kMaxTextureSide = 16384;

struct TextureCache {
    std::map<std::tuple<std::string, int, int>, std::shared_ptr<const AlphaTexture>> textures;
};

// The alpha of `file` (its alpha channel: the one OpenImageIO names, else the last of two or four;
// 1 everywhere for an image without one), as floats in 0..1. Throws InputFileError (missing,
// not a regular file, not a readable image, too large, a non-finite or out-of-range alpha).
std::shared_ptr<const AlphaTexture> loadAlphaTexture(const std::filesystem::path& file, TextureWrap wrapS,
                                                     TextureWrap wrapT, TextureCache* cache = nullptr);

// The same for an image held in memory (a GLB's buffer view, a data URI, a file tinygltf read
// through the input opener): `name` for messages, `ext` (".png", ".jpg") picks the reader.
std::shared_ptr<const AlphaTexture> loadAlphaTextureFromMemory(const std::string& name, const std::string& ext,
                                                               const std::vector<unsigned char>& bytes,
                                                               TextureWrap wrapS, TextureWrap wrapT);

// "repeat", "clamp_to_edge", "mirrored_repeat" (the JSON names); nothing for another word.
bool textureWrapFromName(const std::string& name, TextureWrap& out);
const char* textureWrapName(TextureWrap w);
const char* alphaModeName(AlphaMode m);

}  // namespace shadowlab::scene

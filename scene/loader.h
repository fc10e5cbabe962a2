// scene/loader.h: reads a scene file (JSON now; glTF/GLB scenes come with the mesh loaders),
// validates every value and throws SceneError(file, jsonPath, what) on the first problem.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "scene/error.h"
#include "scene/scene.h"

namespace shadowlab::scene {

Scene loadScene(const std::filesystem::path& file);

// A path as given, or the name of a shipped scene ("seed", "extreme/grazing-1deg") looked up
// in the scenes folder. Throws InputError listing the shipped names when nothing matches.
std::filesystem::path findScene(const std::string& nameOrPath);
std::filesystem::path scenesDirectory();

// A "shadow" block (the settings keys of a scene file) found in another file, e.g. a case of a
// `check` suite; throws SceneError naming `file` and the JSON path of a bad value.
ShadowDefaults readShadowBlock(const std::filesystem::path& file, const nlohmann::json& node, const JsonPath& path);

// Largest image the loaders accept on either side, and in total pixels. Above this a render
// would need more memory than the machines we target have (see docs/decisions.md).
inline constexpr int kMaxResolution = 16384;
inline constexpr long long kMaxPixels = 64LL * 1024 * 1024;

}  // namespace shadowlab::scene

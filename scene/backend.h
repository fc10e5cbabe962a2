// scene/backend.h: the backends by name: every Backend in order, and the one parser of a name
// (scene::toString(Backend), in scene/settings.h, prints one).
#pragma once

#include <optional>
#include <string>

#include "scene/settings.h"

namespace shadowlab::scene {

inline constexpr Backend kBackends[] = {Backend::Raster, Backend::Raytrace, Backend::Reference};

// The Backend whose toString() is `name`; nullopt for any other text (callers name the option).
std::optional<Backend> parseBackend(const std::string& name);

}  // namespace shadowlab::scene

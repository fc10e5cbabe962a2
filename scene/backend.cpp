// scene/backend.cpp: a backend's name back to its Backend.
#include "scene/backend.h"

namespace shadowlab::scene {

std::optional<Backend> parseBackend(const std::string& name) {
    for (const Backend b : kBackends)
        if (name == toString(b)) return b;
    return std::nullopt;
}

}  // namespace shadowlab::scene

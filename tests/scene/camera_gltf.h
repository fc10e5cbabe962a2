// tests/scene/camera_gltf.h: the test box (tests/scene/gltf_files.h) with two named cameras:
// "Front" at (0.5, 0.25, 3) looking down −Z, and "Side" at (4, 0.25, 0.125) turned 90° about Y, so
// it looks down −X at the box.
#pragma once

#include <string>

#include "tests/scene/gltf_files.h"

namespace shadowlab::test {

inline std::string cameraBoxGltf(bool withCameras = true) {
    if (!withCameras) return boxGltf(R"([{"mesh": 0}])", "[0]");
    std::string g = boxGltf(R"([{"mesh": 0},
        {"name": "FrontNode", "camera": 0, "translation": [0.5, 0.25, 3]},
        {"name": "SideNode", "camera": 1, "translation": [4, 0.25, 0.125], "rotation": [0, 0.70710678118654752, 0, 0.70710678118654752]}])",
                            "[0, 1, 2]");
    g.pop_back();  // the closing brace
    return g + R"(, "cameras": [
        {"name": "Front", "type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.01, "zfar": 50}},
        {"name": "Side", "type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.02, "zfar": 40}}]})";
}

}  // namespace shadowlab::test

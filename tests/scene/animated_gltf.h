// tests/scene/animated_gltf.h: a glTF file written by the test (JSON + a binary buffer): a ground
// quad and an animated camera whose motion the tests know analytically.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/scene/test_files.h"

namespace shadowlab::test {

// A buffer of little-endian floats and shorts, with a view and an accessor per block.
struct GltfBuffer {
    using Json = nlohmann::json;
    std::vector<unsigned char> bytes;
    Json views = Json::array(), accessors = Json::array();
    int add(const std::vector<float>& v, const char* type, int count, bool withBounds = false) {
        while (bytes.size() % 4) bytes.push_back(0);
        const std::size_t offset = bytes.size();
        bytes.resize(offset + v.size() * 4);
        std::memcpy(bytes.data() + offset, v.data(), v.size() * 4);
        views.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", v.size() * 4}});
        Json a = {{"bufferView", views.size() - 1}, {"componentType", 5126}, {"count", count}, {"type", type}};
        if (withBounds) {  // scalars (key times) and positions carry min and max, as glTF requires
            const int n = int(v.size()) / count;
            Json lo = Json::array(), hi = Json::array();
            for (int c = 0; c < n; ++c) {
                float l = v[c], h = v[c];
                for (int i = 0; i < count; ++i) l = std::min(l, v[i * n + c]), h = std::max(h, v[i * n + c]);
                lo.push_back(l);
                hi.push_back(h);
            }
            a["min"] = lo;
            a["max"] = hi;
        }
        accessors.push_back(a);
        return int(accessors.size()) - 1;
    }
    int addIndices(const std::vector<std::uint16_t>& v) {
        while (bytes.size() % 4) bytes.push_back(0);
        const std::size_t offset = bytes.size();
        bytes.resize(offset + v.size() * 2);
        std::memcpy(bytes.data() + offset, v.data(), v.size() * 2);
        views.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", v.size() * 2}});
        accessors.push_back(
            {{"bufferView", views.size() - 1}, {"componentType", 5123}, {"count", v.size()}, {"type", "SCALAR"}});
        return int(accessors.size()) - 1;
    }
};

// A ground quad and a camera node (child of a rig node moved by +10 in X) with three animations:
//  0 "Fly":    translation LINEAR (0,1,5) → (1,1,5) → (2,1,5) at t = 0, 1, 2 (x = t), and rotation
//              LINEAR from identity to 90° about +Y over t = 0..2 (slerp: 45° per second);
//  1 "Hop":    translation STEP (0,1,5) at t = 0, (0,3,5) at t = 1;
//  2 "Smooth": translation CUBICSPLINE (0,1,5) → (0,1,3) over t = 0..1 with zero tangents.
inline std::filesystem::path writeAnimatedGltf(const TempDir& dir, const std::string& interpolationOfFly = "LINEAR") {
    using Json = nlohmann::json;
    GltfBuffer b;
    const int pos = b.add({-5, 0, -5, 5, 0, -5, 5, 0, 5, -5, 0, 5}, "VEC3", 4, true);
    const int idx = b.addIndices({0, 3, 2, 0, 2, 1});
    const int t3 = b.add({0, 1, 2}, "SCALAR", 3, true);
    const int tr3 = b.add({0, 1, 5, 1, 1, 5, 2, 1, 5}, "VEC3", 3);
    const int t2 = b.add({0, 2}, "SCALAR", 2, true);
    const double quarterTurn = 3.14159265358979323846 / 2;
    const float s45 = float(std::sin(quarterTurn / 2)), c45 = float(std::cos(quarterTurn / 2));
    const int rot2 = b.add({0, 0, 0, 1, 0, s45, 0, c45}, "VEC4", 2);
    const int ts = b.add({0, 1}, "SCALAR", 2, true);
    const int stepValues = b.add({0, 1, 5, 0, 3, 5}, "VEC3", 2);
    const int cubicValues = b.add({0, 0, 0, 0, 1, 5, 0, 0, 0, 0, 0, 0, 0, 1, 3, 0, 0, 0}, "VEC3", 6);
    const std::filesystem::path bin = dir.path() / "anim.bin";
    std::ofstream(bin, std::ios::binary)
        .write(reinterpret_cast<const char*>(b.bytes.data()), std::streamsize(b.bytes.size()));
    const Json gltf = {
        {"asset", {{"version", "2.0"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0, 1}}}}},
        {"nodes",
         {{{"mesh", 0}, {"name", "ground"}},
          {{"name", "rig"}, {"translation", {10, 0, 0}}, {"children", {2}}},
          {{"name", "eye"}, {"camera", 0}, {"translation", {0, 1, 5}}}}},
        {"cameras",
         {{{"type", "perspective"}, {"name", "cam"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}, {"zfar", 100}}}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}}}}}},
        {"buffers", {{{"uri", "anim.bin"}, {"byteLength", b.bytes.size()}}}},
        {"bufferViews", b.views},
        {"accessors", b.accessors},
        {"animations",
         {{{"name", "Fly"},
           {"samplers",
            {{{"input", t3}, {"output", tr3}, {"interpolation", interpolationOfFly}},
             {{"input", t2}, {"output", rot2}, {"interpolation", "LINEAR"}}}},
           {"channels",
            {{{"sampler", 0}, {"target", {{"node", 2}, {"path", "translation"}}}},
             {{"sampler", 1}, {"target", {{"node", 2}, {"path", "rotation"}}}}}}},
          {{"name", "Hop"},
           {"samplers", {{{"input", ts}, {"output", stepValues}, {"interpolation", "STEP"}}}},
           {"channels", {{{"sampler", 0}, {"target", {{"node", 2}, {"path", "translation"}}}}}}},
          {{"name", "Smooth"},
           {"samplers", {{{"input", ts}, {"output", cubicValues}, {"interpolation", "CUBICSPLINE"}}}},
           {"channels", {{{"sampler", 0}, {"target", {{"node", 2}, {"path", "translation"}}}}}}}}}};
    return dir.write("animated.gltf", gltf.dump());
}

}  // namespace shadowlab::test

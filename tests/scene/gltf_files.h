// tests/scene/gltf_files.h: tiny glTF files written by tests: one box mesh (embedded buffer,
// base64) and the caller's node hierarchy, so tests can place one mesh several times.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace shadowlab::test {

inline std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t b0 = bytes[i];
        const std::uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0;
        const std::uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0;
        const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? kAlphabet[v & 63] : '=';
    }
    return out;
}

// The box [0, 1] x [0, 0.5] x [0, 0.25] (not symmetric, so a wrong rotation shows): 8 corners
// (corner k has x from bit 0, y from bit 1, z from bit 2), 12 outward-wound triangles.
inline const std::vector<float>& boxCorners() {
    static const std::vector<float> c = [] {
        std::vector<float> v;
        for (int k = 0; k < 8; ++k) {
            v.push_back((k & 1) ? 1.0f : 0.0f);
            v.push_back((k & 2) ? 0.5f : 0.0f);
            v.push_back((k & 4) ? 0.25f : 0.0f);
        }
        return v;
    }();
    return c;
}
inline const std::vector<std::uint16_t>& boxIndices() {
    static const std::vector<std::uint16_t> i = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                                 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    return i;
}

// A .gltf with mesh 0 = the box, `nodesJson` as its "nodes" array and `rootsJson` as the
// default scene's node list, e.g. nodes `[{"mesh":0}, {"mesh":0,"translation":[2,0,0]}]`,
// roots `[0, 1]`.
inline std::string boxGltf(const std::string& nodesJson, const std::string& rootsJson) {
    std::vector<unsigned char> buffer(boxCorners().size() * 4 + boxIndices().size() * 2);
    std::memcpy(buffer.data(), boxCorners().data(), boxCorners().size() * 4);
    std::memcpy(buffer.data() + boxCorners().size() * 4, boxIndices().data(), boxIndices().size() * 2);
    const std::string posBytes = std::to_string(boxCorners().size() * 4);
    const std::string idxBytes = std::to_string(boxIndices().size() * 2);
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": )" + rootsJson + R"(}], "nodes": )" +
           nodesJson +
           R"(, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0.5, 0.25]},
    {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": )" +
           posBytes + R"(},
    {"buffer": 0, "byteOffset": )" +
           posBytes + R"(, "byteLength": )" + idxBytes + R"(}],
  "buffers": [{"byteLength": )" +
           std::to_string(buffer.size()) + R"(, "uri": "data:application/octet-stream;base64,)" + base64(buffer) +
           R"("}]})";
}

}  // namespace shadowlab::test

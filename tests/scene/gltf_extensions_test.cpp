// tests/scene/gltf_extensions_test.cpp: glTF files that store geometry quantized
// (KHR_mesh_quantization), read back to the original triangles within the quantization step.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/mesh_loader.h"
#include "tests/scene/gltf_files.h"
#include "tests/scene/test_files.h"

namespace shadowlab::scene {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using test::TempDir;

template <typename F>
std::string errorOf(F&& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

// A tetrahedron with coordinates off any grid (so quantization moves every one of them).
const std::vector<Vec3>& tetra() {
    static const std::vector<Vec3> p = {{-1.3, 0.2, 0.7}, {2.7, -0.4, 0.1}, {0.3, 1.9, -0.8}, {0.5, 0.1, 2.2}};
    return p;
}
const std::vector<std::uint8_t>& tetraIndices() {
    static const std::vector<std::uint8_t> i = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
    return i;
}

// gltfpack's layout for KHR_mesh_quantization: positions on a uniform grid of `bits` bits over
// the largest extent, stored as unsigned shorts (4 of them a vertex: elements start 4-byte
// aligned), with the node's translation and scale putting them back: p = min + q · step.
struct Grid {
    Vec3 min{0};
    double step = 0;
};
Grid gridOf(const std::vector<Vec3>& points, int bits) {
    Grid g;
    g.min = points[0];
    Vec3 max = points[0];
    for (const Vec3& p : points) {
        g.min = glm::min(g.min, p);
        max = glm::max(max, p);
    }
    const Vec3 extent = max - g.min;
    g.step = std::max({extent.x, extent.y, extent.z}) / double((1 << bits) - 1);
    return g;
}
std::vector<unsigned char> quantizeShorts(const std::vector<Vec3>& points, const Grid& g) {
    std::vector<unsigned char> out(points.size() * 8, 0);
    for (std::size_t i = 0; i < points.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const auto q = std::uint16_t(std::lround((points[i][c] - g.min[c]) / g.step));
            std::memcpy(out.data() + i * 8 + std::size_t(c) * 2, &q, 2);
        }
    return out;
}

json node(const Grid& g) {
    return json{{"mesh", 0}, {"translation", {g.min.x, g.min.y, g.min.z}}, {"scale", {g.step, g.step, g.step}}};
}

std::string dataUri(const std::vector<unsigned char>& bytes) {
    return "data:application/octet-stream;base64," + test::base64(bytes);
}

// The world-space triangles of a loaded model, flattened.
TriangleMesh loaded(const fs::path& file) { return *loadMesh(file, glm::dmat4(1.0), file, JsonPath()); }

double maxDistance(const Vec3& a, const Vec3& b) {
    const Vec3 d = glm::abs(a - b);
    return std::max({d.x, d.y, d.z});
}

// ---- KHR_mesh_quantization ----------------------------------------------------------------

TEST(GltfQuantization, ShortPositionsOnAGridComeBackWithinHalfAStep) {
    const Grid g = gridOf(tetra(), 14);
    std::vector<unsigned char> buffer = quantizeShorts(tetra(), g);
    // Normals as normalized signed bytes (padded to 4): code = round(127 n).
    const std::size_t normalsAt = buffer.size();
    std::vector<Vec3> normals;
    for (const Vec3& p : tetra()) normals.push_back(glm::normalize(p - Vec3(0.5, 0.45, 0.55)));
    for (const Vec3& n : normals)
        for (int c = 0; c < 4; ++c) buffer.push_back(c < 3 ? std::uint8_t(std::int8_t(std::lround(127 * n[c]))) : 0);
    const std::size_t indicesAt = buffer.size();
    buffer.insert(buffer.end(), tetraIndices().begin(), tetraIndices().end());
    const json doc = {
        {"asset", {{"version", "2.0"}}},
        {"extensionsUsed", {"KHR_mesh_quantization"}},
        {"extensionsRequired", {"KHR_mesh_quantization"}},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {node(g)}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}}}}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5123}, {"count", 4}, {"type", "VEC3"}},
          {{"bufferView", 1}, {"componentType", 5120}, {"normalized", true}, {"count", 4}, {"type", "VEC3"}},
          {{"bufferView", 2}, {"componentType", 5121}, {"count", 12}, {"type", "SCALAR"}}}},
        {"bufferViews",
         {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", normalsAt}, {"byteStride", 8}},
          {{"buffer", 0}, {"byteOffset", normalsAt}, {"byteLength", indicesAt - normalsAt}, {"byteStride", 4}},
          {{"buffer", 0}, {"byteOffset", indicesAt}, {"byteLength", buffer.size() - indicesAt}}}},
        {"buffers", {{{"byteLength", buffer.size()}, {"uri", dataUri(buffer)}}}}};
    TempDir dir;
    const TriangleMesh m = loaded(dir.write("q.gltf", doc.dump()));
    ASSERT_EQ(m.positions.size(), 4u);
    ASSERT_EQ(m.triangleCount(), 4u);
    // Rounding to the grid moves a coordinate by at most half a step; the node's double
    // arithmetic adds rounding far below that (1e-12 here).
    for (std::size_t i = 0; i < 4; ++i) EXPECT_LE(maxDistance(m.positions[i], tetra()[i]), g.step / 2 + 1e-12) << i;
    // Each normal component is off by at most 0.5 / 127 before renormalizing, so the direction
    // by at most sqrt(3) · 0.5 / 127 = 0.0068 rad: cos >= 0.99997.
    ASSERT_EQ(m.normals.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_GE(glm::dot(m.normals[i], normals[i]), 0.99997) << i;
    EXPECT_EQ(m.indices, std::vector<std::uint32_t>(tetraIndices().begin(), tetraIndices().end()));
}

TEST(GltfQuantization, NormalizedIntegersFollowTheSpecsRules) {
    // glTF 2.0, 3.11: signed n-bit c maps to max(c / (2^(n-1) - 1), -1), unsigned to c / (2^n - 1).
    // Three triangles of normalized signed bytes, signed shorts and unsigned shorts, x codes
    // chosen at the ends of each range; the node scales by 2 so a result of 1 shows as 2.
    std::vector<unsigned char> buffer;
    auto push = [&](const void* p, std::size_t n) {
        const auto* b = static_cast<const unsigned char*>(p);
        buffer.insert(buffer.end(), b, b + n);
        while (buffer.size() % 4) buffer.push_back(0);
    };
    const std::int8_t bytes[3][3] = {{-128, 0, 0}, {-127, 127, 0}, {127, 0, 127}};
    for (const auto& v : bytes) push(v, 3);
    const std::size_t shortsAt = buffer.size();
    const std::int16_t shorts[3][3] = {{-32768, 0, 0}, {32767, 32767, 0}, {0, 0, 32767}};
    for (const auto& v : shorts) push(v, 6);
    const std::size_t ushortsAt = buffer.size();
    const std::uint16_t ushorts[3][3] = {{0, 0, 0}, {65535, 0, 0}, {0, 65535, 65535}};
    for (const auto& v : ushorts) push(v, 6);
    const json doc = {
        {"asset", {{"version", "2.0"}}},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}, {"scale", {2, 2, 2}}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}, {{"attributes", {{"POSITION", 1}}}},
                                     {{"attributes", {{"POSITION", 2}}}}}}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5120}, {"normalized", true}, {"count", 3}, {"type", "VEC3"}},
          {{"bufferView", 1}, {"componentType", 5122}, {"normalized", true}, {"count", 3}, {"type", "VEC3"}},
          {{"bufferView", 2}, {"componentType", 5123}, {"normalized", true}, {"count", 3}, {"type", "VEC3"}}}},
        {"bufferViews",
         {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", shortsAt}, {"byteStride", 4}},
          {{"buffer", 0}, {"byteOffset", shortsAt}, {"byteLength", ushortsAt - shortsAt}, {"byteStride", 8}},
          {{"buffer", 0}, {"byteOffset", ushortsAt}, {"byteLength", buffer.size() - ushortsAt}, {"byteStride", 8}}}},
        {"buffers", {{{"byteLength", buffer.size()}, {"uri", dataUri(buffer)}}}}};
    TempDir dir;
    const TriangleMesh m = loaded(dir.write("n.gltf", doc.dump()));
    ASSERT_EQ(m.positions.size(), 9u);
    EXPECT_EQ(m.positions[0], Vec3(-2, 0, 0));                    // -128 clamps to -1
    EXPECT_EQ(m.positions[1], Vec3(-2, 2, 0));                    // -127 is -1 too
    EXPECT_EQ(m.positions[3], Vec3(-2, 0, 0));                    // -32768 clamps to -1
    EXPECT_EQ(m.positions[4], Vec3(2, 2, 0));                     // 32767 is 1
    EXPECT_EQ(m.positions[7], Vec3(2, 0, 0));                     // 65535 is 1
    EXPECT_DOUBLE_EQ(m.positions[8].y, 2.0);
}

TEST(GltfQuantization, NormalizedFloatsAndIndicesAreRefused) {
    std::string g = test::boxGltf(R"([{"mesh": 0}])", "[0]");
    std::string floats = g;
    floats.replace(floats.find(R"("componentType": 5126,)"), 22, R"("componentType": 5126, "normalized": true,)");
    TempDir dir;
    std::string e = errorOf([&] { loaded(dir.write("f.gltf", floats)); });
    EXPECT_NE(e.find("accessors[0].normalized"), std::string::npos) << e;
    std::string indices = g;
    indices.replace(indices.find(R"("componentType": 5123,)"), 22, R"("componentType": 5123, "normalized": true,)");
    e = errorOf([&] { loaded(dir.write("i.gltf", indices)); });
    EXPECT_NE(e.find("accessors[1].normalized: indices must not be normalized"), std::string::npos) << e;
}

}  // namespace
}  // namespace shadowlab::scene

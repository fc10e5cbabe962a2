// tests/scene/gltf_extensions_test.cpp: glTF files that store geometry quantized
// (KHR_mesh_quantization) or compressed (EXT/KHR_meshopt_compression, KHR_draco_mesh_compression),
// made here with the libraries' own encoders and by gltfpack and glTF-Transform
// (tests/scene/data/), read back to the original triangles within the quantization step;
// KHR_texture_transform on an alpha texture; extensionsRequired; broken compressed data.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "scene/draco_codec.h"
#include "scene/loader.h"
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

// A GLB of `doc` with `bin` as its binary chunk (both padded to 4 bytes).
std::string glb(const json& doc, std::vector<unsigned char> bin) {
    std::string text = doc.dump();
    while (text.size() % 4) text += ' ';
    while (bin.size() % 4) bin.push_back(0);
    std::string out = "glTF";
    auto u32 = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    u32(2);
    u32(std::uint32_t(12 + 8 + text.size() + 8 + bin.size()));
    u32(std::uint32_t(text.size()));
    out += "JSON";
    out += text;
    u32(std::uint32_t(bin.size()));
    out.append("BIN\0", 4);
    out.append(reinterpret_cast<const char*>(bin.data()), bin.size());
    return out;
}

// The world-space triangles of a loaded model, flattened.
TriangleMesh loaded(const fs::path& file) { return *loadMesh(file, glm::dmat4(1.0), file, JsonPath()); }

double maxDistance(const Vec3& a, const Vec3& b) {
    const Vec3 d = glm::abs(a - b);
    return std::max({d.x, d.y, d.z});
}

// Encoders reorder vertices and triangles and may start a triangle at another corner, but keep
// its winding: each loaded triangle must be an original one within `tolerance` per coordinate,
// each original matched once.
void expectSameTriangles(const TriangleMesh& m, const std::vector<std::array<Vec3, 3>>& originals, double tolerance) {
    ASSERT_EQ(m.triangleCount(), originals.size());
    std::vector<bool> used(originals.size(), false);
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        bool found = false;
        for (std::size_t o = 0; o < originals.size() && !found; ++o)
            for (int r = 0; r < 3 && !found && !used[o]; ++r) {
                bool same = true;
                for (int k = 0; k < 3; ++k)
                    same = same && maxDistance(m.positions[m.indices[t + std::size_t(k)]],
                                               originals[o][std::size_t((k + r) % 3)]) <= tolerance;
                if (same) found = used[o] = true;
            }
        EXPECT_TRUE(found) << "loaded triangle " << t / 3 << " is no original one";
    }
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
        {"meshes",
         {{{"primitives",
            {{{"attributes", {{"POSITION", 0}}}},
             {{"attributes", {{"POSITION", 1}}}},
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
    EXPECT_EQ(m.positions[0], Vec3(-2, 0, 0));  // -128 clamps to -1
    EXPECT_EQ(m.positions[1], Vec3(-2, 2, 0));  // -127 is -1 too
    EXPECT_EQ(m.positions[3], Vec3(-2, 0, 0));  // -32768 clamps to -1
    EXPECT_EQ(m.positions[4], Vec3(2, 2, 0));   // 32767 is 1
    EXPECT_EQ(m.positions[7], Vec3(2, 0, 0));   // 65535 is 1
    EXPECT_DOUBLE_EQ(m.positions[8].y, 2.0);
}

TEST(GltfQuantization, NormalizedFloatsAndSignedOrNormalizedIndicesAreRefused) {
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
    // Signed indices (glTF allows unsigned ones only; a negative one would name no vertex).
    std::string signedIndices = g;
    signedIndices.replace(signedIndices.find(R"("componentType": 5123,)"), 22, R"("componentType": 5122,)");
    e = errorOf([&] { loaded(dir.write("s.gltf", signedIndices)); });
    EXPECT_NE(e.find("accessors[1].componentType: indices must be an unsigned byte, short or int, got 5122"),
              std::string::npos)
        << e;
}

// ---- EXT_meshopt_compression / KHR_meshopt_compression ------------------------------------

// The tetrahedron quantized as above, its vertex and index buffers meshopt-compressed into the
// binary chunk (buffer 0) and the views' uncompressed home a fallback buffer without data
// (buffer 1), as `gltfpack -c` writes: the file cannot be read without decoding.
struct MeshoptFile {
    json doc;
    std::vector<unsigned char> bin;
};
MeshoptFile meshoptTetra(const Grid& g, const std::string& extension, const std::string& indexMode) {
    const std::vector<unsigned char> vertices = quantizeShorts(tetra(), g);
    std::vector<unsigned char> bin(meshopt_encodeVertexBufferBound(4, 8));
    bin.resize(meshopt_encodeVertexBuffer(bin.data(), bin.size(), vertices.data(), 4, 8));
    const std::size_t vertexBytes = bin.size();
    while (bin.size() % 4) bin.push_back(0);
    const std::size_t indicesAt = bin.size();
    const std::vector<std::uint32_t> indices(tetraIndices().begin(), tetraIndices().end());
    std::vector<unsigned char> encoded(indexMode == "TRIANGLES" ? meshopt_encodeIndexBufferBound(12, 4)
                                                                : meshopt_encodeIndexSequenceBound(12, 4));
    encoded.resize(indexMode == "TRIANGLES"
                       ? meshopt_encodeIndexBuffer(encoded.data(), encoded.size(), indices.data(), 12)
                       : meshopt_encodeIndexSequence(encoded.data(), encoded.size(), indices.data(), 12));
    bin.insert(bin.end(), encoded.begin(), encoded.end());
    const json vertexExt = {{"buffer", 0},     {"byteOffset", 0}, {"byteLength", vertexBytes},
                            {"byteStride", 8}, {"count", 4},      {"mode", "ATTRIBUTES"}};
    const json indexExt = {{"buffer", 0}, {"byteOffset", indicesAt}, {"byteLength", encoded.size()}, {"byteStride", 4},
                           {"count", 12}, {"mode", indexMode}};
    MeshoptFile f;
    f.bin = bin;
    f.doc = {
        {"asset", {{"version", "2.0"}}},
        {"extensionsUsed", {"KHR_mesh_quantization", extension}},
        {"extensionsRequired", {"KHR_mesh_quantization", extension}},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {node(g)}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5123}, {"count", 4}, {"type", "VEC3"}},
          {{"bufferView", 1}, {"componentType", 5125}, {"count", 12}, {"type", "SCALAR"}}}},
        {"bufferViews",
         {{{"buffer", 1},
           {"byteOffset", 0},
           {"byteLength", 32},
           {"byteStride", 8},
           {"extensions", {{extension, vertexExt}}}},
          {{"buffer", 1}, {"byteOffset", 32}, {"byteLength", 48}, {"extensions", {{extension, indexExt}}}}}},
        {"buffers",
         {{{"byteLength", bin.size()}}, {{"byteLength", 80}, {"extensions", {{extension, {{"fallback", true}}}}}}}}};
    return f;
}

// The tetrahedron's triangles in order, each corner the grid point of the original (the codec is
// lossless: within half a step). The triangle codec may start a triangle at another corner
// (keeping its winding), which draws the same triangle. The file has no NORMAL, so the loader
// gives every triangle corners of its own (flat normals): compared by position, not by index.
void expectTetra(const TriangleMesh& m, const Grid& g) {
    const auto& want = tetraIndices();
    ASSERT_EQ(m.indices.size(), want.size());
    for (std::size_t t = 0; t < want.size(); t += 3) {
        bool found = false;
        for (std::size_t r = 0; r < 3 && !found; ++r) {
            found = true;
            for (std::size_t k = 0; k < 3; ++k)
                found = found && maxDistance(m.positions[m.indices[t + (k + r) % 3]], tetra()[want[t + k]]) <=
                                     g.step / 2 + 1e-12;
        }
        EXPECT_TRUE(found) << "triangle " << t / 3;
    }
}

TEST(GltfMeshopt, CompressedVertexAndIndexViewsDecodeInGlbAndGltf) {
    const Grid g = gridOf(tetra(), 14);
    for (const std::string extension : {"EXT_meshopt_compression", "KHR_meshopt_compression"})
        for (const std::string mode : {"TRIANGLES", "INDICES"}) {
            SCOPED_TRACE(extension + " " + mode);
            const MeshoptFile f = meshoptTetra(g, extension, mode);
            TempDir dir;
            expectTetra(loaded(dir.write("t.glb", glb(f.doc, f.bin))), g);
            // The same as .gltf: the compressed data in a data URI, the fallback still without one.
            json doc = f.doc;
            doc["buffers"][0]["uri"] = dataUri(f.bin);
            expectTetra(loaded(dir.write("t.gltf", doc.dump())), g);
        }
}

TEST(GltfMeshopt, ExponentialAndOctahedralFiltersDecodeWithinTheirPrecision) {
    // Float positions through the EXPONENTIAL filter (15-bit mantissa shared by a vertex's three
    // components) and normals through the OCTAHEDRAL one (8-bit), as `gltfpack -cc -vpf` writes
    // them, then each view meshopt-compressed.
    constexpr int kMantissa = 15, kOctBits = 8;
    std::vector<float> positions;
    std::vector<float> normals4;  // x, y, z, w (w is kept as is)
    std::vector<Vec3> normals;
    for (const Vec3& p : tetra()) {
        positions.insert(positions.end(), {float(p.x), float(p.y), float(p.z)});
        normals.push_back(glm::normalize(p - Vec3(0.5, 0.45, 0.55)));
        normals4.insert(normals4.end(),
                        {float(normals.back().x), float(normals.back().y), float(normals.back().z), 0.0f});
    }
    std::vector<unsigned char> expPositions(4 * 12), octNormals(4 * 4);
    meshopt_encodeFilterExp(expPositions.data(), 4, 12, kMantissa, positions.data());
    meshopt_encodeFilterOct(octNormals.data(), 4, 4, kOctBits, normals4.data());
    std::vector<unsigned char> bin;
    json views = json::array();
    auto compress = [&](const std::vector<unsigned char>& raw, std::size_t stride, const char* filter) {
        std::vector<unsigned char> encoded(meshopt_encodeVertexBufferBound(4, stride));
        encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), raw.data(), 4, stride));
        const json ext = {{"buffer", 0},
                          {"byteOffset", bin.size()},
                          {"byteLength", encoded.size()},
                          {"byteStride", stride},
                          {"count", 4},
                          {"mode", "ATTRIBUTES"},
                          {"filter", filter}};
        views.push_back({{"buffer", 1},
                         {"byteOffset", views.size() * 48},
                         {"byteLength", 4 * stride},
                         {"byteStride", stride},
                         {"extensions", {{"EXT_meshopt_compression", ext}}}});
        bin.insert(bin.end(), encoded.begin(), encoded.end());
        while (bin.size() % 4) bin.push_back(0);
    };
    compress(expPositions, 12, "EXPONENTIAL");
    compress(octNormals, 4, "OCTAHEDRAL");
    const std::size_t indicesAt = bin.size();
    bin.insert(bin.end(), tetraIndices().begin(), tetraIndices().end());
    views.push_back({{"buffer", 0}, {"byteOffset", indicesAt}, {"byteLength", 12}});
    const json doc = {
        {"asset", {{"version", "2.0"}}},
        {"extensionsUsed", {"KHR_mesh_quantization", "EXT_meshopt_compression"}},
        {"extensionsRequired", {"KHR_mesh_quantization", "EXT_meshopt_compression"}},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}}}}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
          {{"bufferView", 1}, {"componentType", 5120}, {"normalized", true}, {"count", 4}, {"type", "VEC3"}},
          {{"bufferView", 2}, {"componentType", 5121}, {"count", 12}, {"type", "SCALAR"}}}},
        {"bufferViews", views},
        {"buffers",
         {{{"byteLength", bin.size()}},
          {{"byteLength", 96}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}}}};
    TempDir dir;
    const TriangleMesh m = loaded(dir.write("filters.glb", glb(doc, bin)));
    ASSERT_EQ(m.positions.size(), 4u);
    ASSERT_EQ(m.normals.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
        // The filter's shared exponent E makes the largest component's mantissa fit K signed
        // bits, |c| <= 2^E (2^(K-1) - 1), and rounds each component to a multiple of 2^E, so a
        // component moves by at most 2^(E-1) <= max|c| / 2^(K-1) (a minimal E halves it again).
        const Vec3& p = tetra()[i];
        const double largest = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        EXPECT_LE(maxDistance(m.positions[i], p), largest / double(1 << (kMantissa - 1))) << i;
        // Octahedral: the map's two coordinates (|x| + |y| <= 1 on the upper half) are rounded to
        // 1/127, moving the unnormalized point (x, y, 1 - |x| - |y|) by at most sqrt(6) · 0.5 / 127
        // at a distance >= 1/sqrt(3) from the origin: <= 0.0167 rad; the decoded unit vector is
        // rounded to normalized bytes again, <= sqrt(3) · 0.5 / 127 = 0.0068 rad. cos(0.0235) = 0.99972.
        EXPECT_GE(glm::dot(m.normals[i], normals[i]), 0.99972) << i;
    }
}

TEST(GltfMeshopt, BrokenStreamsAreErrorsNamingTheView) {
    const Grid g = gridOf(tetra(), 14);
    TempDir dir;
    {
        // The vertex stream cut short by 6 bytes (its byteLength says so): the decoder runs out.
        MeshoptFile f = meshoptTetra(g, "EXT_meshopt_compression", "TRIANGLES");
        auto& ext = f.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"];
        ext["byteLength"] = ext["byteLength"].get<int>() - 6;
        const fs::path file = dir.write("cut.glb", glb(f.doc, f.bin));
        const std::string e = errorOf([&] { loaded(file); });
        EXPECT_NE(e.find(file.string()), std::string::npos) << e;
        EXPECT_NE(e.find("bufferViews[0].extensions.EXT_meshopt_compression: the compressed data does not decode"),
                  std::string::npos)
            << e;
    }
    {
        // A wrong count, with the view's byteLength made to agree: the stream holds 4 triangles,
        // not 5. The triangle codec cannot tell (it reads the data after the codes as a fifth
        // code); what it decodes then points past the 4 vertices, which the indices' check names.
        MeshoptFile f = meshoptTetra(g, "EXT_meshopt_compression", "TRIANGLES");
        f.doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["count"] = 15;
        f.doc["bufferViews"][1]["byteLength"] = 60;
        f.doc["accessors"][1]["count"] = 15;
        f.doc["buffers"][1]["byteLength"] = 92;
        const std::string e = errorOf([&] { loaded(dir.write("count.glb", glb(f.doc, f.bin))); });
        EXPECT_NE(e.find("meshes[0].primitives[0].indices (accessors[1]): index "), std::string::npos) << e;
        EXPECT_NE(e.find("is out of range (4 vertices)"), std::string::npos) << e;
    }
    {
        // A count the view's byteLength does not hold.
        MeshoptFile f = meshoptTetra(g, "EXT_meshopt_compression", "TRIANGLES");
        f.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = 5;
        const std::string e = errorOf([&] { loaded(dir.write("five.glb", glb(f.doc, f.bin))); });
        EXPECT_NE(e.find("bufferViews[0].extensions.EXT_meshopt_compression: byteStride 8 x count 5 must equal"),
                  std::string::npos)
            << e;
    }
    {
        // A count past 32 bits, which tinygltf would wrap (2^32 + 4 to 4): refused by its path.
        MeshoptFile f = meshoptTetra(g, "EXT_meshopt_compression", "TRIANGLES");
        f.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = 4294967300LL;
        const std::string e = errorOf([&] { loaded(dir.write("wrap.glb", glb(f.doc, f.bin))); });
        EXPECT_NE(e.find("bufferViews[0].extensions.EXT_meshopt_compression.count: 4294967300 is out of the range"),
                  std::string::npos)
            << e;
    }
    {
        // A huge count with a byteLength to match: refused as too short to hold it, before any
        // allocation (a stream is at least a 64th of what it decodes to).
        MeshoptFile f = meshoptTetra(g, "EXT_meshopt_compression", "TRIANGLES");
        f.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = 500000000;
        f.doc["bufferViews"][0]["byteLength"] = 4000000000LL;
        f.doc["buffers"][1]["byteLength"] = 4000000048LL;
        const std::string e = errorOf([&] { loaded(dir.write("huge.glb", glb(f.doc, f.bin))); });
        EXPECT_NE(e.find("is too short to hold 500000000 elements of 8 bytes (at least 62500000 bytes)"),
                  std::string::npos)
            << e;
    }
    {
        // A stride the decoder would assert on.
        MeshoptFile f = meshoptTetra(g, "EXT_meshopt_compression", "TRIANGLES");
        f.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["byteStride"] = 6;
        const std::string e = errorOf([&] { loaded(dir.write("stride.glb", glb(f.doc, f.bin))); });
        EXPECT_NE(e.find("EXT_meshopt_compression.byteStride: must be a multiple of 4"), std::string::npos) << e;
    }
}

// ---- KHR_draco_mesh_compression -----------------------------------------------------------

// A height field of 5 x 5 points over [0, 2] x [0, 2]: 32 triangles.
std::vector<std::array<Vec3, 3>> heightField() {
    auto at = [](int i, int j) {
        const double x = 0.5 * i, z = 0.5 * j;
        return Vec3(x, 0.3 * std::sin(1.7 * x) * std::cos(1.3 * z) + 0.05 * i * j, z);
    };
    std::vector<std::array<Vec3, 3>> t;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            t.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
            t.push_back({at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)});
        }
    return t;
}

struct DracoData {
    std::vector<unsigned char> bytes;
    int positionId = -1;
    std::uint32_t points = 0, faces = 0;
};
DracoData dracoEncode(const std::vector<std::array<Vec3, 3>>& triangles, int bits) {
    std::vector<float> corners;
    for (const auto& t : triangles)
        for (const Vec3& p : t) corners.insert(corners.end(), {float(p.x), float(p.y), float(p.z)});
    DracoData d;
    d.bytes = encodeDracoTriangles(corners, bits, d.positionId);
    EXPECT_FALSE(d.bytes.empty());
    // The point and face counts an exporter writes into the accessors: the encoder merges
    // corners, so they are learnt from the encoded data.
    std::string error;
    const auto decoded = DracoMesh::decode(d.bytes.data(), d.bytes.size(), error);
    EXPECT_TRUE(decoded) << error;
    d.points = decoded->points();
    d.faces = decoded->faces();
    return d;
}

json dracoDoc(const DracoData& d, std::size_t byteLength) {
    const json ext = {{"bufferView", 0}, {"attributes", {{"POSITION", d.positionId}}}};
    return {{"asset", {{"version", "2.0"}}},
            {"extensionsUsed", {"KHR_draco_mesh_compression"}},
            {"extensionsRequired", {"KHR_draco_mesh_compression"}},
            {"scenes", {{{"nodes", {0}}}}},
            {"nodes", {{{"mesh", 0}}}},
            {"meshes",
             {{{"primitives",
                {{{"attributes", {{"POSITION", 0}}},
                  {"indices", 1},
                  {"extensions", {{"KHR_draco_mesh_compression", ext}}}}}}}}},
            {"accessors",
             {{{"componentType", 5126}, {"count", d.points}, {"type", "VEC3"}},
              {{"componentType", 5125}, {"count", d.faces * 3}, {"type", "SCALAR"}}}},
            {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", byteLength}}}},
            {"buffers", {{{"byteLength", d.bytes.size()}}}}};
}

TEST(GltfDraco, ACompressedPrimitiveLoadsToTheOriginalTrianglesWithinTheQuantizationStep) {
    const auto triangles = heightField();
    const int bits = 11;
    const DracoData d = dracoEncode(triangles, bits);
    TempDir dir;
    const TriangleMesh m = loaded(dir.write("d.glb", glb(dracoDoc(d, d.bytes.size()), d.bytes)));
    ASSERT_EQ(m.triangleCount(), triangles.size());
    // Draco quantizes every coordinate on one grid over the largest extent (range / (2^bits - 1))
    // and rounds to it, so a coordinate moves by at most half a step; it computes in float
    // (1e-6 here, on coordinates below 2.3).
    std::vector<Vec3> all;
    for (const auto& t : triangles) all.insert(all.end(), t.begin(), t.end());
    const double tolerance = gridOf(all, bits).step / 2 + 1e-6;
    expectSameTriangles(m, triangles, tolerance);
}

TEST(GltfDraco, CutOrMismatchedDataIsAnErrorNamingThePrimitive) {
    const DracoData d = dracoEncode(heightField(), 11);
    TempDir dir;
    // Half of the compressed bytes.
    const fs::path cut = dir.write("cut.glb", glb(dracoDoc(d, d.bytes.size() / 2), d.bytes));
    std::string e = errorOf([&] { loaded(cut); });
    EXPECT_NE(e.find(cut.string()), std::string::npos) << e;
    EXPECT_NE(e.find("meshes[0].primitives[0].extensions.KHR_draco_mesh_compression: the Draco data in bufferViews[0] "
                     "does not decode"),
              std::string::npos)
        << e;
    // An accessor count that is not the decoded one.
    json doc = dracoDoc(d, d.bytes.size());
    doc["accessors"][0]["count"] = d.points + 1;
    e = errorOf([&] { loaded(dir.write("count.glb", glb(doc, d.bytes))); });
    EXPECT_NE(e.find("accessors[0].count: " + std::to_string(d.points + 1) + " elements, but the Draco data"),
              std::string::npos)
        << e;
    // An attribute id the data does not hold.
    doc = dracoDoc(d, d.bytes.size());
    doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["POSITION"] = 7;
    e = errorOf([&] { loaded(dir.write("id.glb", glb(doc, d.bytes))); });
    EXPECT_NE(e.find("Draco attribute 7 is not in the data"), std::string::npos) << e;
}

// ---- the GLB container ---------------------------------------------------------------------

TEST(GltfContainer, ChunksThatReachPastTheFileAreRefusedBeforeTinygltfReadsThem) {
    // The tetrahedron's meshopt file is only a vehicle: a GLB with a JSON and a BIN chunk.
    const MeshoptFile f = meshoptTetra(gridOf(tetra(), 14), "EXT_meshopt_compression", "TRIANGLES");
    const std::string good = glb(f.doc, f.bin);
    TempDir dir;
    EXPECT_NO_THROW(loaded(dir.write("good.glb", good)));
    auto setU32 = [](std::string& bytes, std::size_t at, std::uint32_t v) { std::memcpy(bytes.data() + at, &v, 4); };
    {
        // The last 4 bytes cut off, the header's length made to agree: the BIN chunk's own length
        // then reaches 4 bytes past the end (tinygltf 2.7 would copy them).
        std::string cut = good.substr(0, good.size() - 4);
        setU32(cut, 8, std::uint32_t(cut.size()));
        const fs::path file = dir.write("cut.glb", cut);
        const std::string e = errorOf([&] { loaded(file); });
        EXPECT_NE(e.find(file.string() + ": GLB chunk 1 (BIN): declares " + std::to_string(f.bin.size()) +
                         " bytes, but only " + std::to_string(f.bin.size() - 4) + " follow its header"),
                  std::string::npos)
            << e;
    }
    {
        // The header's length is past the file's end.
        std::string longer = good;
        setU32(longer, 8, std::uint32_t(good.size() + 8));
        const std::string e = errorOf([&] { loaded(dir.write("length.glb", longer)); });
        EXPECT_NE(e.find("GLB header: declares " + std::to_string(good.size() + 8) + " bytes, but the file has only " +
                         std::to_string(good.size())),
                  std::string::npos)
            << e;
    }
    {
        // A JSON chunk longer than the file.
        std::string longJson = good;
        setU32(longJson, 12, std::uint32_t(good.size()));
        const std::string e = errorOf([&] { loaded(dir.write("json.glb", longJson)); });
        EXPECT_NE(e.find("GLB chunk 0 (JSON): declares"), std::string::npos) << e;
    }
}

// ---- extensionsRequired and extensionsUsed -----------------------------------------------

std::string boxWith(const std::string& extensionsJson) {
    std::string g = test::boxGltf(R"([{"mesh": 0}])", "[0]");
    const std::string asset = R"({"asset": {"version": "2.0"},)";
    g.replace(g.find(asset), asset.size(), asset + extensionsJson + ",");
    return g;
}

TEST(GltfExtensions, ARequiredExtensionShadowlabDoesNotReadIsRefusedByName) {
    TempDir dir;
    const fs::path file = dir.write("box.gltf", boxWith(R"("extensionsUsed": ["KHR_materials_emissive_strength",
        "EXT_mesh_gpu_instancing"], "extensionsRequired": ["KHR_materials_emissive_strength", "EXT_mesh_gpu_instancing"])"));
    const std::string e = errorOf([&] { loadScene(file); });
    EXPECT_NE(e.find(file.string() + ": extensionsRequired[1]: the file requires EXT_mesh_gpu_instancing, which "
                                     "shadowlab does not read"),
              std::string::npos)
        << e;
    // An unknown name is refused the same way.
    const std::string u =
        errorOf([&] { loadScene(dir.write("u.gltf", boxWith(R"("extensionsRequired": ["VENDOR_new_geometry"])"))); });
    EXPECT_NE(u.find("extensionsRequired[0]: the file requires VENDOR_new_geometry"), std::string::npos) << u;
    // Specular-glossiness takes MASK/BLEND alpha from elsewhere: refused when required.
    const std::string sg = errorOf([&] {
        loadScene(dir.write("sg.gltf", boxWith(R"("extensionsRequired": ["KHR_materials_pbrSpecularGlossiness"])")));
    });
    EXPECT_NE(sg.find("KHR_materials_pbrSpecularGlossiness"), std::string::npos) << sg;
    // Transmission lets light through surfaces that shadowlab would cast as opaque.
    for (const std::string name :
         {"KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_diffuse_transmission"}) {
        const std::string t =
            errorOf([&] { loadScene(dir.write("t.gltf", boxWith(R"("extensionsRequired": [")" + name + R"("])"))); });
        EXPECT_NE(t.find("extensionsRequired[0]: the file requires " + name +
                         ", which shadowlab does not read (its "
                         "surfaces let light through"),
                  std::string::npos)
            << t;
    }
}

TEST(GltfExtensions, ExtensionsThatChangeNeitherGeometryNorAlphaAreAccepted) {
    TempDir dir;
    // Required or only used: material shading, image formats, the ones shadowlab reads.
    const Scene s = loadScene(dir.write("box.gltf", boxWith(R"("extensionsUsed": ["KHR_materials_emissive_strength",
        "KHR_materials_clearcoat", "KHR_texture_basisu", "KHR_lights_punctual", "KHR_texture_transform"],
        "extensionsRequired": ["KHR_materials_emissive_strength", "KHR_texture_basisu", "KHR_texture_transform"])")));
    EXPECT_EQ(s.objects.size(), 1u);
    EXPECT_TRUE(s.origin.notes.empty());
    // One only used and not read: loaded, with a note naming it.
    const Scene n = loadScene(
        dir.write("n.gltf", boxWith(R"("extensionsUsed": ["EXT_mesh_gpu_instancing", "KHR_materials_transmission"])")));
    ASSERT_EQ(n.origin.notes.size(), 2u);
    EXPECT_NE(n.origin.notes[0].find("EXT_mesh_gpu_instancing is not read"), std::string::npos) << n.origin.notes[0];
    EXPECT_NE(n.origin.notes[1].find("KHR_materials_transmission is not read"), std::string::npos) << n.origin.notes[1];
}

// ---- KHR_texture_transform on an alpha texture --------------------------------------------

TEST(GltfTextureTransform, MovesTheCoordinatesTheAlphaIsSampledAt) {
    TempDir dir;
    {
        const unsigned char pixels[16] = {9, 9, 9, 0, 9, 9, 9, 255, 9, 9, 9, 128, 9, 9, 9, 255};
        auto out = OIIO::ImageOutput::create((dir.path() / "a.png").string());
        ASSERT_TRUE(out);
        ASSERT_TRUE(out->open((dir.path() / "a.png").string(), OIIO::ImageSpec(2, 2, 4, OIIO::TypeDesc::UINT8)));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels));
        out->close();
    }
    // One triangle; TEXCOORD_0 is a decoy, TEXCOORD_1 (named by the transform's texCoord) holds
    // normalized unsigned shorts 0, 65535 and 13107 = 0.2 · 65535.
    std::vector<unsigned char> buffer;
    const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    buffer.insert(buffer.end(), reinterpret_cast<const unsigned char*>(positions),
                  reinterpret_cast<const unsigned char*>(positions) + 36);
    const std::uint16_t decoy[6] = {1, 1, 1, 1, 1, 1};
    const std::uint16_t uv[6] = {0, 0, 65535, 0, 13107, 65535};
    buffer.insert(buffer.end(), reinterpret_cast<const unsigned char*>(decoy),
                  reinterpret_cast<const unsigned char*>(decoy) + 12);
    buffer.insert(buffer.end(), reinterpret_cast<const unsigned char*>(uv),
                  reinterpret_cast<const unsigned char*>(uv) + 12);
    const double quarter = 1.5707963267948966;
    const json doc = {
        {"asset", {{"version", "2.0"}}},
        {"extensionsUsed", {"KHR_texture_transform"}},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"meshes",
         {{{"primitives",
            {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}, {"TEXCOORD_1", 2}}}, {"material", 0}}}}}}},
        {"materials",
         {{{"name", "Leaf"},
           {"alphaMode", "MASK"},
           {"pbrMetallicRoughness",
            {{"baseColorTexture",
              {{"index", 0},
               {"texCoord", 0},
               {"extensions",
                {{"KHR_texture_transform",
                  {{"offset", {0.25, 0.5}}, {"rotation", quarter}, {"scale", {2, 3}}, {"texCoord", 1}}}}}}}}}}}},
        {"textures", {{{"source", 0}}}},
        {"images", {{{"uri", "a.png"}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
          {{"bufferView", 1}, {"componentType", 5123}, {"normalized", true}, {"count", 3}, {"type", "VEC2"}},
          {{"bufferView", 2}, {"componentType", 5123}, {"normalized", true}, {"count", 3}, {"type", "VEC2"}}}},
        {"bufferViews",
         {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
          {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 12}},
          {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 12}}}},
        {"buffers", {{{"byteLength", buffer.size()}, {"uri", dataUri(buffer)}}}}};
    const Scene s = loadScene(dir.write("leaf.gltf", doc.dump()));
    ASSERT_EQ(s.objects.size(), 1u);
    const auto& mesh = std::get<Mesh>(s.objects[0].shape);
    ASSERT_EQ(mesh.instances.size(), 1u);
    const std::vector<Vec2>& uvs = mesh.instances[0].geometry->uvs;
    ASSERT_EQ(uvs.size(), 3u);
    // The extension's uv' = T(offset) · R(rotation) · S(scale) · uv, its R = [cos sin; -sin cos]
    // (a positive angle turns the image clockwise): at a quarter turn, u' = 3 v + 0.25 and
    // v' = 0.5 - 2 u. Codes (0, 0), (65535, 0), (13107, 65535) are uv (0, 0), (1, 0), (0.2, 1).
    const Vec2 expected[3] = {{0.25, 0.5}, {0.25, -1.5}, {3.25, 0.1}};
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(uvs[std::size_t(i)].x, expected[i].x, 1e-12) << i;
        EXPECT_NEAR(uvs[std::size_t(i)].y, expected[i].y, 1e-12) << i;
    }
}

// A MASK triangle with float TEXCOORD_0 whose baseColorTexture is `texture` (over `images`).
std::string alphaTriangle(const json& texture, const json& images) {
    const float data[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1};
    const std::vector<unsigned char> buffer(reinterpret_cast<const unsigned char*>(data),
                                            reinterpret_cast<const unsigned char*>(data) + sizeof data);
    const json doc = {
        {"asset", {{"version", "2.0"}}},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}}, {"material", 0}}}}}}},
        {"materials",
         {{{"name", "Leaf"}, {"alphaMode", "MASK"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}}},
        {"textures", {texture}},
        {"images", images},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
          {{"bufferView", 0}, {"byteOffset", 36}, {"componentType", 5126}, {"count", 3}, {"type", "VEC2"}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", buffer.size()}}}},
        {"buffers", {{{"byteLength", buffer.size()}, {"uri", dataUri(buffer)}}}}};
    return doc.dump();
}

TEST(GltfTextureFormats, AWebpOnlyAlphaIsDecodedAndAvifOrKtx2OnlyAreRefusedByName) {
    TempDir dir;
    {
        // Alpha 0, 255, 128, 255, written losslessly so the decoded values are the written ones.
        const unsigned char pixels[16] = {9, 9, 9, 0, 9, 9, 9, 255, 9, 9, 9, 128, 9, 9, 9, 255};
        OIIO::ImageSpec spec(2, 2, 4, OIIO::TypeDesc::UINT8);
        spec.attribute("compression", "lossless");
        auto out = OIIO::ImageOutput::create((dir.path() / "a.webp").string());
        ASSERT_TRUE(out);
        ASSERT_TRUE(out->open((dir.path() / "a.webp").string(), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels));
        out->close();
    }
    // The texture's own `source` is absent: the image is reachable through the extension only.
    const Scene s = loadScene(dir.write(
        "webp.gltf", alphaTriangle({{"extensions", {{"EXT_texture_webp", {{"source", 0}}}}}}, {{{"uri", "a.webp"}}})));
    ASSERT_EQ(s.materials.size(), 1u);
    ASSERT_TRUE(s.materials[0].alphaTexture);
    EXPECT_EQ(s.materials[0].alphaTexture->alpha, (std::vector<float>{0.0f, 1.0f, 128.0f / 255.0f, 1.0f}));
    for (const std::string format : {"EXT_texture_avif", "KHR_texture_basisu"}) {
        const fs::path file = dir.write(
            "other.gltf", alphaTriangle({{"extensions", {{format, {{"source", 0}}}}}}, {{{"uri", "a.webp"}}}));
        const std::string e = errorOf([&] { loadScene(file); });
        EXPECT_NE(
            e.find(file.string() + ": textures[0].extensions." + format + ": the alpha of Leaf (MASK) is only in"),
            std::string::npos)
            << e;
    }
}

// ---- files made by other tools -------------------------------------------------------------

std::vector<std::array<Vec3, 3>> trianglesOf(const TriangleMesh& m) {
    std::vector<std::array<Vec3, 3>> out;
    for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3)
        out.push_back({m.positions[m.indices[t]], m.positions[m.indices[t + 1]], m.positions[m.indices[t + 2]]});
    return out;
}

// tests/scene/data/ (README.md there says how each was made): gltfpack's and glTF-Transform's
// output for the shipped Box and Avocado. Each must load to the original's triangles, each
// corner within one quantization step of 14 bits over the model's largest extent (both tools
// default to 14-bit positions on one grid over that extent; rounding is half a step, and a
// tool may place its grid's origin up to another half step away).
TEST(GltfToolOutput, CompressedAndQuantizedFilesLoadToTheOriginalTriangles) {
    const fs::path data = fs::path(SHADOWLAB_SOURCE_DIR) / "tests" / "scene" / "data";
    const fs::path models = fs::path(SHADOWLAB_SOURCE_DIR) / "scenes" / "models";
    struct Case {
        const char* file;
        const char* original;
        bool exponential = false;  // float positions through meshopt's EXPONENTIAL filter
    };
    const Case cases[] = {{"Box.gltfpack.glb", "Box/Box.gltf"},
                          {"Avocado.gltfpack.glb", "Avocado/Avocado.gltf"},
                          {"Avocado.gltfpack-cc.glb", "Avocado/Avocado.gltf", true},
                          {"Avocado.draco.glb", "Avocado/Avocado.gltf"},
                          {"Avocado.quantize.glb", "Avocado/Avocado.gltf"}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        const TriangleMesh original = loaded(models / c.original);
        Vec3 min = original.positions[0], max = original.positions[0], largest(0);
        for (const Vec3& p : original.positions) {
            min = glm::min(min, p);
            max = glm::max(max, p);
            largest = glm::max(largest, glm::abs(p));
        }
        const Vec3 extent = max - min;
        double tolerance = std::max({extent.x, extent.y, extent.z}) / double((1 << 14) - 1);
        // `gltfpack -vpf` gives each axis one exponent E over the whole stream and 14 bits of
        // mantissa, |c| / 2^E < 2^14, with E the smallest that fits: 2^E <= 2 max|c| / 2^14, and
        // rounding moves a coordinate by at most 2^(E-1) <= max|c| / 2^14. (The original's node
        // turns Avocado half a turn about y, which keeps each axis's magnitudes.)
        if (c.exponential) tolerance = std::max({largest.x, largest.y, largest.z}) / double(1 << 14);
        expectSameTriangles(loaded(data / c.file), trianglesOf(original), tolerance);
    }
}

TEST(GltfToolOutput, KhrMeshoptVersion1StreamsAreRefusedWithWhatToDo) {
    // `gltfpack -cz` writes KHR_meshopt_compression with the v1 attribute stream (header 0xa1),
    // which the meshoptimizer 0.18 of Debian 12 does not decode.
    const fs::path file = fs::path(SHADOWLAB_SOURCE_DIR) / "tests" / "scene" / "data" / "Box.gltfpack-khr.glb";
    const std::string e = errorOf([&] { loaded(file); });
    EXPECT_NE(e.find("bufferViews[0].extensions.KHR_meshopt_compression: the attribute stream is of version 1"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("gltfpack -ce ext"), std::string::npos) << e;
}

}  // namespace
}  // namespace shadowlab::scene

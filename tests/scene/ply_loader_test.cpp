// tests/scene/ply_loader_test.cpp: PLY meshes in all three encodings give the triangles their
// bytes spell (written here by hand, independently of the reader), bad files are refused with
// the file and the problem named, and OBJ and PLY files load as whole scenes like a bare glTF.
#include <algorithm>
#include <bit>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scene/loader.h"
#include "scene/ply_loader.h"
#include "tests/scene/test_files.h"

namespace shadowlab::scene {
namespace {

using test::TempDir;

template <typename T>
std::string bytesOf(T v, bool bigEndian) {
    std::string b(sizeof(T), '\0');
    std::memcpy(b.data(), &v, sizeof(T));
    if (bigEndian == (std::endian::native == std::endian::little)) std::reverse(b.begin(), b.end());
    return b;
}

// The unit square (0,0,0) (1,0,0) (1,1,0) (0,1,0) as one quad, plus a property and an element
// the reader must read past, in the given binary byte order.
std::string binarySquare(bool bigEndian) {
    std::string s = std::string("ply\nformat ") + (bigEndian ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "property short extra\nelement face 1\nproperty list uchar int vertex_indices\n"
                    "element edge 2\nproperty list uchar uint vertices\nend_header\n";
    const float corners[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    for (const auto& c : corners) {
        for (float v : c) s += bytesOf(v, bigEndian);
        s += bytesOf(std::int16_t(-7), bigEndian);
    }
    s += char(4);
    for (std::int32_t i : {0, 1, 2, 3}) s += bytesOf(i, bigEndian);
    for (int e = 0; e < 2; ++e) {
        s += char(2);
        for (std::uint32_t i : {0u, 1u}) s += bytesOf(i, bigEndian);
    }
    return s;
}

const std::string kAsciiSquare =
    "ply\r\nformat ascii 1.0\r\ncomment Windows line ends in the header\r\nelement vertex 4\r\n"
    "property double x\r\nproperty double y\r\nproperty double z\r\nproperty uchar red\r\n"
    "element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n"
    "0 0 0 255\n1 0 0 0\n1 1 0 0\n0 1 0 9\n4 0 1 2 3\n";

void expectSquare(const TriangleMesh& m) {
    // A quad fans from its first corner: (0, 1, 2) and (0, 2, 3).
    ASSERT_EQ(m.positions.size(), 4u);
    EXPECT_EQ(m.positions[2], Vec3(1, 1, 0));
    EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
    EXPECT_TRUE(m.normals.empty());
}

TEST(PlyLoader, AsciiAndBothBinaryOrdersSpellTheSameSquare) {
    for (const std::string& bytes : {kAsciiSquare, binarySquare(false), binarySquare(true)}) {
        TriangleMesh m;
        loadPly(bytes, m);
        expectSquare(m);
    }
}

TEST(PlyLoader, NormalsAreKeptWhenTheFileHasAllThree) {
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
        "element face 1\nproperty list uchar uint vertex_index\nend_header\n"
        "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0.6 0.8\n3 2 1 0\n";
    TriangleMesh m;
    loadPly(ply, m);
    ASSERT_EQ(m.normals.size(), 3u);
    EXPECT_EQ(m.normals[2], Vec3(0, 0.6f, 0.8f));
    EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{2, 1, 0}));
}

TEST(PlyLoader, BadFilesNameTheirProblem) {
    const std::string head =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    struct Case {
        std::string bytes, what;
    };
    std::string truncated = binarySquare(false);
    truncated.resize(truncated.size() - 30);
    std::string huge = binarySquare(false);
    huge.replace(huge.find("element vertex 4"), 16, "element vertex 4000000000000");
    const Case cases[] = {
        {"solid cube\n", "does not begin with the line 'ply'"},
        {"ply\nformat ascii 1.0\nelement vertex 0\n", "no 'end_header'"},
        {"ply\nformat utf8 1.0\nend_header\n", "unknown format"},
        {"ply\nend_header\n", "no 'format' line"},
        {"ply\nformat ascii 1.0\nproperty float x\nend_header\n", "a property before any element"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n", "unknown type 'half'"},
        {"ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\nend_header\n",
         "count type must be an integer type"},
        {"ply\nformat ascii 1.0\nelement vertex -3\nend_header\n", "is not a count"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
         "no x, y and z"},
        {head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "vertex index 3 is out of range (3 vertices)"},
        {head + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "a face of 2 corners"},
        {head + "0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n", "vertex 2 is not finite"},
        {head + "0 0 0\n1 0 0\n0 one 0\n3 0 1 2\n", "'one' is not a number"},
        {head + "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", "is not an integer"},
        {head + "0 0 0\n1 0 0\n", "the data ends inside vertex 2"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
         "end_header\n0 0 0\n",
         "has no faces"},
        {truncated, "the data ends"},
        {huge, "the data ends"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.bytes.substr(0, 80));
        TriangleMesh m;
        try {
            loadPly(c.bytes, m);
            ADD_FAILURE() << "accepted";
        } catch (const PlyError& e) {
            EXPECT_NE(std::string(e.what()).find(c.what), std::string::npos) << e.what();
        }
    }
}

TEST(PlyLoader, ABadPlyInASceneNamesTheSceneTheJsonPathAndTheMesh) {
    TempDir dir;
    dir.write("bad.ply", "ply\nformat ascii 1.0\nend_header\n");
    const std::filesystem::path scene = dir.write("s.json", R"({"camera": {"position": [0, 2, 5], "look_at": [0, 0, 0]},
        "materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0, -1, 0]}],
        "objects": [{"type": "mesh", "file": "bad.ply", "material": "m"}]})");
    try {
        loadScene(scene);
        ADD_FAILURE() << "accepted";
    } catch (const std::exception& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(scene.string()), std::string::npos) << what;
        EXPECT_NE(what.find("objects[0].file"), std::string::npos) << what;
        EXPECT_NE(what.find("bad.ply"), std::string::npos) << what;
        EXPECT_NE(what.find("has no vertex element"), std::string::npos) << what;
    }
}

TEST(ModelScene, AnObjOrPlyFileIsAWholeSceneWithASearchedViewAndSunOverAGround) {
    // Neither format has a camera or a light: the scene is the mesh, a placeholder view and sun
    // for the search to replace, and (applied later, scene/model_view.h) a ground.
    TempDir dir;
    const std::filesystem::path files[] = {
        dir.write("square.ply", kAsciiSquare),
        dir.write("square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"),
    };
    for (const auto& file : files) {
        SCOPED_TRACE(file.string());
        const Scene s = loadScene(file);
        ASSERT_EQ(s.objects.size(), 1u);
        EXPECT_EQ(s.objects[0].name, "square");
        EXPECT_TRUE(s.origin.modelScene);
        EXPECT_TRUE(s.origin.chooseView);
        EXPECT_TRUE(s.origin.chooseSun);
        ASSERT_EQ(s.lights.size(), 1u);
        EXPECT_EQ(s.lights[0].type, LightType::Directional);
        const Bounds b = s.bounds();
        EXPECT_EQ(b.min, Vec3(0, 0, 0));
        EXPECT_EQ(b.max, Vec3(1, 1, 0));
    }
}

TEST(PlyLoader, TheStanfordBunnyAsPlyHasTheTrianglesOfItsObjConversion) {
    // ../shared/scenes holds Stanford's PLY and a MeshLab conversion to OBJ with the same faces
    // and vertices equal to within 5e-7 (its MANIFEST): two readers, one answer.
    const std::filesystem::path dir = std::filesystem::path(SHADOWLAB_SHARED_SCENES) / "StanfordBunny";
    if (!std::filesystem::exists(dir / "bun_zipper.ply")) GTEST_SKIP() << dir << " is not here";
    const Scene ply = loadScene(dir / "bun_zipper.ply");
    const Scene obj = loadScene(dir / "stanford-bunny.obj");
    const auto& a = std::get<Mesh>(ply.objects[0].shape).instances.at(0).geometry;
    const auto& b = std::get<Mesh>(obj.objects[0].shape).instances.at(0).geometry;
    ASSERT_EQ(a->triangleCount(), b->triangleCount());
    EXPECT_GT(a->triangleCount(), 69000u);
    double worst = 0;
    for (std::size_t i = 0; i < a->indices.size(); ++i)
        worst = std::max(worst, glm::length(a->positions[a->indices[i]] - b->positions[b->indices[i]]));
    EXPECT_LT(worst, 1e-6);
}

}  // namespace
}  // namespace shadowlab::scene

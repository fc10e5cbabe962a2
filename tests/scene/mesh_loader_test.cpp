// tests/scene/mesh_loader_test.cpp: OBJ and glTF meshes load in world space with normals;
// degenerate triangles are dropped and counted; bad meshes give clear errors.
#include "scene/mesh_loader.h"

#include <gtest/gtest.h>

#include "tests/scene/test_files.h"

namespace shadowlab::scene {
namespace {

using test::TempDir;

const char* kTetrahedron = R"(v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
)";

std::shared_ptr<const TriangleMesh> load(const std::filesystem::path& f, const glm::dmat4& m = glm::dmat4(1.0)) {
    return loadMesh(f, m, "scene.json", JsonPath() / "objects" / 0 / "file");
}

TEST(MeshLoader, ObjWithoutNormalsGetsUnitOutwardNormals) {
    TempDir dir;
    const auto mesh = load(dir.write("t.obj", kTetrahedron));
    EXPECT_EQ(mesh->triangleCount(), 4u);
    ASSERT_EQ(mesh->normals.size(), mesh->positions.size());
    const Vec3 centroid(0.25);
    for (std::size_t i = 0; i < mesh->positions.size(); ++i) {
        EXPECT_NEAR(glm::length(mesh->normals[i]), 1.0, 1e-12);
        // Corners of a convex solid: the vertex normal points away from the centroid.
        EXPECT_GT(glm::dot(mesh->normals[i], mesh->positions[i] - centroid), 0.0);
    }
}

TEST(MeshLoader, TransformTranslatesRotatesAndScales) {
    TempDir dir;
    // Rotate 90° about Y: x -> -z. Scale 2, then translate by (10, 0, 0).
    const auto mesh = load(dir.write("t.obj", kTetrahedron), objectTransform({10, 0, 0}, {0, 90, 0}, Vec3(2.0)));
    bool foundX = false;
    for (const Vec3& p : mesh->positions)
        if (glm::length(p - Vec3(10, 0, -2)) < 1e-12) foundX = true;  // (1,0,0) -> (10,0,-2)
    EXPECT_TRUE(foundX);
}

TEST(MeshLoader, DegenerateTrianglesAreDroppedAndCounted) {
    TempDir dir;
    const auto mesh = load(dir.write("d.obj", std::string(kTetrahedron) + "f 1 2 2\nv 2 0 0\nf 1 2 5\n"));
    EXPECT_EQ(mesh->triangleCount(), 4u);
    EXPECT_EQ(mesh->droppedDegenerate, 2u);  // a repeated vertex, and three collinear points
}

TEST(MeshLoader, BadMeshesGiveClearErrors) {
    TempDir dir;
    auto expectError = [&](const std::filesystem::path& f, const std::string& mentions) {
        try {
            load(f);
            FAIL() << f;
        } catch (const SceneError& e) {
            EXPECT_EQ(e.jsonPath(), "objects[0].file");
            EXPECT_NE(std::string(e.what()).find(mentions), std::string::npos) << e.what();
        }
    };
    expectError(dir.path() / "absent.obj", "no such file");
    expectError(dir.write("empty.obj", ""), "empty");
    expectError(dir.write("nofaces.obj", "v 0 0 0\nv 1 0 0\n"), "no faces");
    expectError(dir.write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), "out of range");
    expectError(dir.write("nan.obj", "v 0 nan 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "not a finite number");
    expectError(dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), "degenerate");
    expectError(dir.write("mesh.stl", "solid"), "unknown mesh type");
    expectError(dir.write("garbage.gltf", "\x01\x02 not json"), "not a readable glTF");
}

// One triangle in an embedded buffer, placed by the node hierarchy `nodes` (a JSON array).
std::string oneTriangleGltf(const std::string& nodes, const std::string& sceneRoots) {
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": )" + sceneRoots +
           R"(}], "nodes": )" + nodes + R"(,
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                    {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
}

TEST(MeshLoader, GltfNodeHierarchyMustBeAForest) {
    test::TempDir dir;
    // A tree: the mesh node under a translated parent is placed once, moved by its parent.
    const auto tree = load(dir.write("tree.gltf", oneTriangleGltf(
        R"([{"children": [1], "translation": [5, 0, 0]}, {"mesh": 0}])", "[0]")));
    ASSERT_EQ(tree->triangleCount(), 1u);
    for (const Vec3& p : tree->positions) EXPECT_GE(p.x, 5.0);
    // A cycle (found by fuzzing: it used to loop until a million visits) and a node with two
    // parents (exponential with depth) are refused at once, naming the node.
    auto expectRefused = [&](const std::string& name, const std::string& nodes, const std::string& roots) {
        try {
            (void)load(dir.write(name, oneTriangleGltf(nodes, roots)));
            ADD_FAILURE() << name << ": no error";
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find("reached twice"), std::string::npos) << e.what();
        }
    };
    expectRefused("cycle.gltf", R"([{"children": [0], "mesh": 0}])", "[0]");
    expectRefused("two-parents.gltf", R"([{"children": [2]}, {"children": [2]}, {"mesh": 0}])", "[0, 1]");
    expectRefused("root-twice.gltf", R"([{"mesh": 0}])", "[0, 0]");
}

TEST(MeshLoader, GltfBoxFromSharedScenesHasTwelveTriangles) {
    const std::filesystem::path box = std::filesystem::path(SHADOWLAB_SHARED_SCENES) / "Box" / "Box.gltf";
    if (!std::filesystem::exists(box)) GTEST_SKIP() << "absent: " << box;
    const auto mesh = load(box);
    EXPECT_EQ(mesh->triangleCount(), 12u);
    // The sample's node rotates the unit cube; its bounding box is still 1 on each side.
    Bounds b;
    for (const Vec3& p : mesh->positions) b.extend(p);
    EXPECT_NEAR(b.extent().x, 1.0, 1e-6);
    EXPECT_NEAR(b.extent().y, 1.0, 1e-6);
}

}  // namespace
}  // namespace shadowlab::scene

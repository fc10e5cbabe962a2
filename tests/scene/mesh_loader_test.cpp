// tests/scene/mesh_loader_test.cpp: OBJ and glTF meshes load in world space with normals;
// degenerate triangles are dropped and counted; bad meshes give clear errors.
#include "scene/mesh_loader.h"

#include <gtest/gtest.h>

#include "scene/loader.h"
#include "tests/scene/gltf_files.h"
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
    expectError(dir.write("mesh.stl", "solid"), "unsupported format");
    expectError(dir.write("garbage.gltf", "\x01\x02 not json"), "not a readable glTF");
    // A buffer file that is missing or shorter than its byteLength is named by its JSON path.
    const std::string external = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
      "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "buffers": [{"byteLength": 36, "uri": "tri%20angle.bin"}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0],
                     "max": [1, 1, 0]}]})";
    const auto gltf = dir.write("external.gltf", external);
    expectError(gltf, "external.gltf: buffers[0].uri \"tri%20angle.bin\": no such file");
    dir.write("tri angle.bin", std::string(20, '\0'));
    expectError(gltf,
                "buffers[0].uri \"tri%20angle.bin\": the file holds 20 bytes, fewer than the buffer's "
                "byteLength 36");
}

// One triangle in an embedded buffer, placed by the node hierarchy `nodes` (a JSON array).
std::string oneTriangleGltf(const std::string& nodes, const std::string& sceneRoots) {
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": )" + sceneRoots + R"(}], "nodes": )" +
           nodes + R"(,
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                    {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
}

TEST(MeshLoader, GltfNodeHierarchyMustBeAForest) {
    test::TempDir dir;
    // A tree: the mesh node under a translated parent is placed once, moved by its parent.
    const auto tree = load(dir.write(
        "tree.gltf", oneTriangleGltf(R"([{"children": [1], "translation": [5, 0, 0]}, {"mesh": 0}])", "[0]")));
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

// Node 0 moves the box to x = −2; node 1 turns it 90° about +Y and moves it to x = 1; node 2,
// a child of node 1, scales it by 2 and lifts it by 1 in node 1's frame.
const char* kThreeNodes = R"([{"mesh": 0, "translation": [-2, 0, 0]},
  {"mesh": 0, "translation": [1, 0, 0], "rotation": [0, 0.7071067811865476, 0, 0.7071067811865476], "children": [2]},
  {"mesh": 0, "translation": [0, 1, 0], "scale": [2, 2, 2]}])";

TEST(MeshLoader, GltfWithoutNormalsGetsFlatFaceNormals) {
    // glTF 2.0, 3.7.2.1: a primitive without NORMAL is shaded flat. The test box has none: each
    // of its 12 triangles gets three vertices of its own whose normal is its face's, the
    // axis-aligned outward normal of the box side it lies on (away from the box's centre).
    TempDir dir;
    const auto mesh = load(dir.write("box.gltf", test::boxGltf(R"([{"mesh": 0}])", "[0]")));
    ASSERT_EQ(mesh->triangleCount(), 12u);
    ASSERT_EQ(mesh->positions.size(), 36u);
    ASSERT_EQ(mesh->normals.size(), 36u);
    const Vec3 centre(0.5, 0.25, 0.125);
    for (std::size_t t = 0; t < 36; t += 3) {
        const Vec3& a = mesh->positions[mesh->indices[t]];
        const Vec3& b = mesh->positions[mesh->indices[t + 1]];
        const Vec3& c = mesh->positions[mesh->indices[t + 2]];
        Vec3 side(0.0);  // the axis on which all three corners agree, signed away from the centre
        for (int axis = 0; axis < 3; ++axis)
            if (a[axis] == b[axis] && b[axis] == c[axis]) side[axis] = a[axis] > centre[axis] ? 1.0 : -1.0;
        ASSERT_EQ(glm::length(side), 1.0) << "triangle " << t / 3;
        for (std::size_t k = 0; k < 3; ++k)
            EXPECT_EQ(mesh->normals[mesh->indices[t + k]], side) << "triangle " << t / 3 << " corner " << k;
    }
}

TEST(MeshInstancing, AGltfMeshUsedByThreeNodesIsOneGeometryPlacedThreeTimes) {
    TempDir dir;
    const auto file = dir.write("three.gltf", test::boxGltf(kThreeNodes, "[0, 1]"));
    const std::vector<MeshInstance> inst =
        loadMeshInstances(file, glm::dmat4(1.0), "scene.json", JsonPath() / "objects" / 0 / "file");
    ASSERT_EQ(inst.size(), 3u);
    // One mesh in memory: the same pointer three times and no other owner.
    EXPECT_EQ(inst[0].geometry.get(), inst[1].geometry.get());
    EXPECT_EQ(inst[1].geometry.get(), inst[2].geometry.get());
    EXPECT_EQ(inst[0].geometry.use_count(), 3);
    EXPECT_EQ(inst[0].geometry->triangleCount(), 12u);
    // Object space: the box's own corners, untouched by any node (its third triangle's last
    // corner is corner 7).
    const TriangleMesh& box = *inst[0].geometry;
    EXPECT_EQ(box.positions[box.indices[8]], Vec3(1, 0.5, 0.25));
    // Corner (1, 0, 0) by hand. Node 0: (−1, 0, 0). Node 1: R_y(90°) maps (x, y, z) to
    // (z, y, −x), so (0, 0, −1), then + (1, 0, 0): (1, 0, −1). Node 2 inside node 1: scale 2 and
    // lift: (2, 1, 0); rotate: (0, 1, −2); move: (1, 1, −2). Nodes come in document order.
    EXPECT_LT(glm::length(transformPoint(inst[0].transform, Vec3(1, 0, 0)) - Vec3(-1, 0, 0)), 1e-12);
    EXPECT_LT(glm::length(transformPoint(inst[1].transform, Vec3(1, 0, 0)) - Vec3(1, 0, -1)), 1e-12);
    EXPECT_LT(glm::length(transformPoint(inst[2].transform, Vec3(1, 0, 0)) - Vec3(1, 1, -2)), 1e-12);
    // The flattened copy is 36 world-space triangles.
    const TriangleMesh flat = flattenInstances(inst);
    EXPECT_EQ(flat.triangleCount(), 36u);
}

TEST(MeshInstancing, ObjectsNamingTheSameFileShareItsGeometryAndKeepOneIdEach) {
    TempDir dir;
    dir.write("three.gltf", test::boxGltf(kThreeNodes, "[0, 1]"));
    dir.write("t.obj", kTetrahedron);
    const auto sceneFile = dir.write("s.json", R"({
      "camera": {"position": [0, 2, 8], "look_at": [0, 0, 0]},
      "materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0, -1, 0]}],
      "objects": [
        {"type": "mesh", "file": "three.gltf", "material": "m"},
        {"type": "sphere", "center": [0, 5, 0], "radius": 1, "material": "m"},
        {"type": "mesh", "file": "three.gltf", "translate": [0, 0, 4], "rotate": [0, 30, 0], "scale": 0.5, "material": "m"},
        {"type": "mesh", "file": "t.obj", "material": "m"},
        {"type": "mesh", "file": "./t.obj", "scale": 3, "material": "m"}]})");
    const Scene s = loadScene(sceneFile);
    // One object per JSON entry, in file order: ids stay what they were before instancing.
    ASSERT_EQ(s.objects.size(), 5u);
    const Mesh& a = std::get<Mesh>(s.objects[0].shape);
    const Mesh& b = std::get<Mesh>(s.objects[2].shape);
    ASSERT_EQ(a.instances.size(), 3u);
    ASSERT_EQ(b.instances.size(), 3u);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(a.instances[i].geometry.get(), b.instances[0].geometry.get());
    EXPECT_EQ(a.triangleCount(), 36u);
    // Object 2's node 0 instance: the object transform after the node's: corner (1, 0, 0) →
    // (−1, 0, 0) by the node, then ·0.5 → (−0.5, 0, 0), R_y(30°) → (−0.5·cos30, 0, 0.5·sin30),
    // + (0, 0, 4).
    const double c = std::cos(glm::radians(30.0)), sn = std::sin(glm::radians(30.0));
    EXPECT_LT(glm::length(transformPoint(b.instances[0].transform, Vec3(1, 0, 0)) - Vec3(-0.5 * c, 0, 4 + 0.5 * sn)),
              1e-12);
    // The same OBJ named two ways is read once.
    EXPECT_EQ(std::get<Mesh>(s.objects[3].shape).instances[0].geometry.get(),
              std::get<Mesh>(s.objects[4].shape).instances[0].geometry.get());
}

TEST(MeshInstancing, ANodeScaledToZeroIsDroppedAndAllDroppedIsAnError) {
    TempDir dir;
    const auto some =
        dir.write("some.gltf", test::boxGltf(R"([{"mesh": 0}, {"mesh": 0, "scale": [0, 1, 1]}])", "[0, 1]"));
    EXPECT_EQ(loadMeshInstances(some, glm::dmat4(1.0), "scene.json", JsonPath()).size(), 1u);
    const auto none = dir.write("none.gltf", test::boxGltf(R"([{"mesh": 0, "scale": [0, 0, 0]}])", "[0]"));
    try {
        loadMeshInstances(none, glm::dmat4(1.0), "scene.json", JsonPath() / "objects" / 0 / "file");
        FAIL();
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("degenerate"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace shadowlab::scene

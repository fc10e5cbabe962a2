// tests/scene/hostile_input_test.cpp: inputs built to break a reader, each made here (FIFOs,
// folders, links to /dev/zero, deep nesting, glTF accessors whose sums wrap, values that
// overflow): every one must end in one SceneError/InputError naming the file, quickly, without
// a crash, a hang or a large allocation.
#include <sys/stat.h>
#include <unistd.h>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/error.h"
#include "scene/input_file.h"
#include "scene/json_input.h"
#include "scene/loader.h"
#include "scene/mesh_loader.h"
#include "tests/scene/gltf_files.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using test::TempDir;

// A reader that blocks on a FIFO would hang the suite: end the process instead, which fails
// the test loudly.
struct HangGuard {
    HangGuard() { ::alarm(30); }
    ~HangGuard() { ::alarm(0); }
};

// The error a load gives, or "" when it loads.
template <typename F>
std::string errorOf(F&& f) {
    try {
        f();
    } catch (const scene::SceneError& e) {
        return e.what();
    } catch (const scene::InputError& e) {
        return e.what();
    }
    return "";
}

const char* kSceneHead = R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0, 0]},
  "materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0, -1, 0]}], )";

std::string sceneWithObjects(const std::string& objects) {
    return std::string(kSceneHead) + "\"objects\": " + objects + "}";
}

std::string meshScene(const std::string& file) {
    return sceneWithObjects(R"([{"type": "mesh", "file": ")" + file + R"(", "material": "m"}])");
}

const std::string kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

// ---- one way to open a file: regular files only, bounded -------------------------------

TEST(InputFile, NonRegularFilesAreRefusedByKindBeforeTheyAreOpened) {
    HangGuard guard;
    TempDir dir;
    const fs::path fifo = dir.path() / "pipe.json";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const fs::path zero = dir.path() / "zero.json";
    fs::create_symlink("/dev/zero", zero);
    fs::create_directory(dir.path() / "folder.json");
    EXPECT_NE(errorOf([&] { scene::readInputFile(fifo, 1 << 20); }).find("named pipe"), std::string::npos);
    EXPECT_NE(errorOf([&] { scene::readInputFile(zero, 1 << 20); }).find("character device"), std::string::npos);
    EXPECT_NE(errorOf([&] { scene::readInputFile(dir.path() / "folder.json", 1 << 20); }).find("is a folder"),
              std::string::npos);
    EXPECT_NE(errorOf([&] { scene::readInputFile(dir.path() / "absent.json", 1 << 20); }).find("no such file"),
              std::string::npos);
    // The scene loader goes through it: a FIFO scene is refused, not waited on.
    const std::string e = errorOf([&] { scene::loadScene(fifo); });
    EXPECT_NE(e.find(fifo.string()), std::string::npos) << e;
    EXPECT_NE(e.find("named pipe"), std::string::npos) << e;
}

TEST(InputFile, AFormatIsToldByItsExtensionInAnyCase) {
    EXPECT_EQ(scene::lowercaseExtension("dir.v2/MODEL.GLB"), ".glb");
    EXPECT_EQ(scene::lowercaseExtension("mask.Png"), ".png");
    EXPECT_EQ(scene::lowercaseExtension("frame.exr"), ".exr");
    EXPECT_EQ(scene::lowercaseExtension("dir.v2/noextension"), "");
}

TEST(InputFile, SizeIsBoundedBeforeReadingAndSymlinksAreFollowed) {
    TempDir dir;
    const fs::path big = dir.write("big.json", std::string(2000, ' '));
    EXPECT_NE(errorOf([&] { scene::readInputFile(big, 1000); }).find("more than the 1000 bytes"), std::string::npos);
    fs::create_symlink(big, dir.path() / "link.json");
    EXPECT_EQ(scene::readInputFile(dir.path() / "link.json", 4000).size(), 2000u);
}

TEST(InputFile, AnObjMaterialLibraryThatIsNotARegularFileIsAnError) {
    HangGuard guard;
    TempDir dir;
    dir.write("pipe.obj", "mtllib pipe.mtl\n" + kTriangleObj);
    ASSERT_EQ(::mkfifo((dir.path() / "pipe.mtl").c_str(), 0600), 0);
    dir.write("zero.obj", "mtllib zero.mtl\n" + kTriangleObj);
    fs::create_symlink("/dev/zero", dir.path() / "zero.mtl");
    dir.write("missing.obj", "mtllib missing.mtl\n" + kTriangleObj);
    for (const char* name : {"pipe", "zero"}) {
        const fs::path scene = dir.write(std::string(name) + ".json", meshScene(std::string(name) + ".obj"));
        const std::string e = errorOf([&] { scene::loadScene(scene); });
        EXPECT_NE(e.find("objects[0].file"), std::string::npos) << e;
        EXPECT_NE(e.find("mtllib " + std::string(name) + ".mtl"), std::string::npos) << e;
        EXPECT_NE(e.find("not a regular file"), std::string::npos) << e;
    }
    // Shadows need no material: a library that is simply absent is no error.
    EXPECT_EQ(errorOf([&] { scene::loadScene(dir.write("missing.json", meshScene("missing.obj"))); }), "");
}

// A one-triangle glTF whose buffer is `uri` (an external file), accessors as given.
Json triangleGltf(const std::string& uri, std::size_t bufferLength) {
    return Json{
        {"asset", {{"version", "2.0"}}},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
        {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
        {"buffers", {{{"uri", uri}, {"byteLength", bufferLength}}}},
    };
}

std::string triangleBytes() {
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    return std::string(reinterpret_cast<const char*>(v), sizeof v);
}

TEST(InputFile, GltfBufferUrisGoThroughTheSameChecks) {
    HangGuard guard;
    TempDir dir;
    dir.write("ok.bin", triangleBytes());
    EXPECT_EQ(errorOf([&] { scene::loadScene(dir.write("ok.gltf", triangleGltf("ok.bin", 36).dump())); }), "");
    ASSERT_EQ(::mkfifo((dir.path() / "pipe.bin").c_str(), 0600), 0);
    fs::create_symlink("/dev/zero", dir.path() / "zero.bin");
    fs::create_directory(dir.path() / "folder.bin");
    for (const char* uri : {"pipe.bin", "zero.bin", "folder.bin"}) {
        const fs::path file = dir.write(std::string(uri) + ".gltf", triangleGltf(uri, 36).dump());
        const std::string e = errorOf([&] { scene::loadScene(file); });
        EXPECT_NE(e.find(file.string()), std::string::npos) << e;
        EXPECT_NE(e.find(uri), std::string::npos) << e;
        EXPECT_TRUE(e.find("not a regular file") != std::string::npos || e.find("is a folder") != std::string::npos)
            << e;
    }
    // An image URI naming a FIFO is not waited on either (images are ignored: it loads).
    Json withImage = triangleGltf("ok.bin", 36);
    withImage["images"] = {{{"uri", "pipe.png"}}};
    ASSERT_EQ(::mkfifo((dir.path() / "pipe.png").c_str(), 0600), 0);
    const std::string e = errorOf([&] { scene::loadScene(dir.write("image.gltf", withImage.dump())); });
    EXPECT_TRUE(e.empty() || e.find("pipe.png") != std::string::npos) << e;
}

// ---- nesting and long values ------------------------------------------------------------

std::string nested(std::size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); }

TEST(Nesting, DeepJsonIsRefusedWithItsPlaceBeforeAnythingRecursesOnIt) {
    TempDir dir;
    // 200000 levels: printing or destroying that recursively overflows the stack.
    const std::string deep = nested(200000);
    for (const std::string& text :
         {sceneWithObjects(deep), sceneWithObjects("[{\"type\": \"sphere\", \"center\": " + deep + "}]"),
          std::string(kSceneHead) + "\"objects\": [], \"unknown\": " + deep + "}"}) {
        const fs::path file = dir.write("deep.json", text);
        const std::string e = errorOf([&] { scene::loadScene(file); });
        EXPECT_NE(e.find(file.string()), std::string::npos) << e.substr(0, 300);
        EXPECT_NE(e.find("nested deeper than 64 levels near line"), std::string::npos) << e.substr(0, 300);
    }
    // At the limit it parses (and is then checked as usual).
    EXPECT_EQ(scene::jsonNestingProblem(nested(scene::kMaxJsonDepth)), "");
    EXPECT_NE(scene::jsonNestingProblem(nested(scene::kMaxJsonDepth + 1)), "");
    // Brackets inside strings do not count.
    EXPECT_EQ(scene::jsonNestingProblem("[\"" + std::string(1000, '[') + "\\\"\"]"), "");
}

TEST(Nesting, DeepGltfExtrasAreRefusedBeforeTinygltfParsesThem) {
    TempDir dir;
    dir.write("ok.bin", triangleBytes());
    std::string text = triangleGltf("ok.bin", 36).dump();
    text.insert(text.size() - 1, ",\"extras\": " + nested(100000));
    const fs::path file = dir.write("deep.gltf", text);
    const std::string e = errorOf([&] { scene::loadScene(file); });
    EXPECT_NE(e.find(file.string()), std::string::npos) << e.substr(0, 300);
    EXPECT_NE(e.find("nested deeper than"), std::string::npos) << e.substr(0, 300);
}

TEST(Nesting, ErrorsQuoteOnlyAShortExcerptOfAHugeValue) {
    TempDir dir;
    const std::string key(4 << 20, 'k');  // a 4 MB unknown key
    const fs::path a = dir.write("key.json", sceneWithObjects("[{\"type\": \"sphere\", \"" + key + "\": 1}]"));
    const std::string e = errorOf([&] { scene::loadScene(a); });
    EXPECT_NE(e.find("unknown key"), std::string::npos) << e.substr(0, 300);
    EXPECT_LT(e.size(), 1000u);
    const fs::path b = dir.write("type.json", sceneWithObjects("[{\"type\": \"" + key + "\"}]"));
    const std::string f = errorOf([&] { scene::loadScene(b); });
    EXPECT_NE(f.find("unknown object type"), std::string::npos) << f.substr(0, 300);
    EXPECT_LE(f.size(), scene::kMaxErrorMessage + b.string().size() + 100);
    // A value printed into a message: a large array is cut, not printed whole.
    Json big = Json::array();
    for (int i = 0; i < 100000; ++i) big.push_back(i);
    EXPECT_LE(scene::describeJson(big).size(), 60u);
}

// ---- checked arithmetic on offsets, counts, strides, indices -----------------------------

// The load error of the triangle glTF after `edit` changes its JSON (buffer embedded).
std::string gltfError(const std::function<void(Json&)>& edit) {
    TempDir dir;
    dir.write("t.bin", triangleBytes());
    Json g = triangleGltf("t.bin", 36);
    edit(g);
    const fs::path file = dir.write("t.gltf", g.dump());
    std::string e = errorOf([&] { scene::loadScene(file); });
    if (!e.empty()) {
        EXPECT_NE(e.find(file.string()), std::string::npos) << e;
    }
    return e;
}

TEST(GltfAccessor, OffsetsCountsAndStridesThatWrapOrOverrunAreErrorsWithTheirPath) {
    EXPECT_EQ(gltfError([](Json&) {}), "");
    // byteOffset near 2^64: offset + count * stride wraps to a small number.
    std::string e = gltfError([](Json& g) { g["accessors"][0]["byteOffset"] = 18446744073709551608ull; });
    EXPECT_NE(e.find("accessors[0]"), std::string::npos) << e;
    // A count whose count * stride wraps.
    e = gltfError([](Json& g) { g["accessors"][0]["count"] = 1537228672809129302ull; });
    EXPECT_NE(e.find("accessors[0]"), std::string::npos) << e;
    EXPECT_NE(e.find("reach past the end of bufferViews[0]"), std::string::npos) << e;
    // One element too many for the view.
    e = gltfError([](Json& g) { g["accessors"][0]["count"] = 4; });
    EXPECT_NE(e.find("reach past the end of bufferViews[0] (36 bytes)"), std::string::npos) << e;
    // A view longer than its buffer, and one whose offset + length wraps.
    e = gltfError([](Json& g) { g["bufferViews"][0]["byteLength"] = 40; });
    EXPECT_FALSE(e.empty());
    e = gltfError([](Json& g) { g["bufferViews"][0]["byteOffset"] = 18446744073709551600ull; });
    EXPECT_FALSE(e.empty());
    // A stride smaller than one element.
    e = gltfError([](Json& g) { g["bufferViews"][0]["byteStride"] = 4; });
    EXPECT_FALSE(e.empty());
}

TEST(GltfAccessor, AnAccessorThatDoesNotExistIsNamedByThePropertyThatNamesIt) {
    // tinygltf refuses a missing indices accessor itself; POSITION and NORMAL reach our reader.
    // Either way the error names the primitive's property, not only the number.
    const char* pos =
        "meshes[0].primitives[0].attributes.POSITION: names accessor 5, which does not exist (1 accessors)";
    EXPECT_NE(gltfError([](Json& g) { g["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 5; }).find(pos),
              std::string::npos);
    std::string e = gltfError([](Json& g) { g["meshes"][0]["primitives"][0]["indices"] = 1; });
    EXPECT_NE(e.find("meshes[0].primitives[0].indices: names accessor 1, which does not exist (1 accessors)"),
              std::string::npos)
        << e;
    e = gltfError([](Json& g) { g["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 3; });
    EXPECT_NE(e.find("meshes[0].primitives[0].attributes.NORMAL: names accessor 3, which does not exist"),
              std::string::npos)
        << e;
    e = gltfError([](Json& g) { g["meshes"][0]["primitives"][0]["attributes"].erase("POSITION"); });
    EXPECT_NE(e.find("meshes[0].primitives[0].attributes: has no POSITION"), std::string::npos) << e;
}

// The triangle with a sparse accessor moving vertex 2 from (0, 1, 0) to `moved` (buffer: the
// 36 bytes of positions, one uint32 index at 36, 12 bytes of value at 40).
Json sparseTriangle(std::uint32_t index, const float moved[3]) {
    Json g = triangleGltf("", 52);
    std::string bytes = triangleBytes();
    bytes.append(reinterpret_cast<const char*>(&index), 4);
    bytes.append(reinterpret_cast<const char*>(moved), 12);
    g["buffers"][0]["uri"] =
        "data:application/octet-stream;base64," + test::base64(std::vector<unsigned char>(bytes.begin(), bytes.end()));
    g["bufferViews"] = {{{"buffer", 0}, {"byteLength", 36}},
                        {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 4}},
                        {{"buffer", 0}, {"byteOffset", 40}, {"byteLength", 12}}};
    g["accessors"][0]["sparse"] = {
        {"count", 1}, {"indices", {{"bufferView", 1}, {"componentType", 5125}}}, {"values", {{"bufferView", 2}}}};
    return g;
}

TEST(GltfAccessor, SparseAccessorsReplaceTheElementsTheyName) {
    TempDir dir;
    const float moved[3] = {0, 0, 1};
    const scene::Scene s = scene::loadScene(dir.write("sparse.gltf", sparseTriangle(2, moved).dump()));
    // (0,0,0), (1,0,0) and the moved (0,0,1): the triangle lies in y = 0 and reaches z = 1.
    const scene::Bounds b = s.bounds();
    EXPECT_EQ(b.max.y, 0.0);
    EXPECT_EQ(b.max.z, 1.0);
    EXPECT_EQ(b.max.x, 1.0);
    // An index past the accessor's 3 elements is an error at its path, not a write past the end.
    const fs::path bad = dir.write("bad.gltf", sparseTriangle(5, moved).dump());
    const std::string e = errorOf([&] { scene::loadScene(bad); });
    EXPECT_NE(e.find("accessors[0].sparse.indices: index 5 (element 0) is out of range"), std::string::npos) << e;
    // Values past the end of their view.
    Json over = sparseTriangle(2, moved);
    over["accessors"][0]["sparse"]["values"]["byteOffset"] = 4;
    const std::string o = errorOf([&] { scene::loadScene(dir.write("over.gltf", over.dump())); });
    EXPECT_NE(o.find("accessors[0].sparse.values: byteOffset 4 + 1 elements of stride 12 reach past the end of "
                     "bufferViews[2]"),
              std::string::npos)
        << o;
}

TEST(ObjIndex, IndicesBeyondThe32BitRangeAreErrorsNamingTheLine) {
    TempDir dir;
    for (const char* face : {"f 1 2 4294967298", "f 1 2 -4294967296", "f 1 2 99999999999999999999", "f 1 2 -4"}) {
        dir.write("big.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + std::string(face) + "\n");
        const std::string e = errorOf([&] { scene::loadScene(dir.write("big.json", meshScene("big.obj"))); });
        EXPECT_NE(e.find("line 4: face index"), std::string::npos) << face << ": " << e;
        EXPECT_NE(e.find("out of range (3 vertices defined so far)"), std::string::npos) << face << ": " << e;
    }
    // A positive index past the file's vertices is named at its line; one naming a vertex
    // defined further down the file is not an error.
    dir.write("far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\nf 1 3 9\n");
    const std::string e = errorOf([&] { scene::loadScene(dir.write("far.json", meshScene("far.obj"))); });
    EXPECT_NE(e.find("line 5: face index 7 is out of range (3 vertices in the file)"), std::string::npos) << e;
    dir.write("ahead.obj", "v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n");
    EXPECT_EQ(errorOf([&] { scene::loadScene(dir.write("ahead.json", meshScene("ahead.obj"))); }), "");
    // A texture coordinate or normal index past the file's is no error: the mesh goes without
    // UVs or normals (it still casts).
    dir.write("vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/90000000\nf 1//7 2//7 3//7\n");
    EXPECT_EQ(errorOf([&] { scene::loadScene(dir.write("vt.json", meshScene("vt.obj"))); }), "");
}

TEST(ObjIndex, AFaceOfFewerThanThreeCornersOrAVertexOfFewerThanThreeCoordinatesIsAnError) {
    TempDir dir;
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"f 1 2", "line 5: a face of 2 corners (a face needs 3 or more)"},
        {"f 1", "line 5: a face of 1 corner "},
        {"f", "line 5: a face of 0 corners"},
        {"v 0 0", "line 5: a vertex of 2 coordinates (it needs x, y and z)"},
        {"vn 0 1", "line 5: a normal of 2 coordinates"},
    };
    for (const auto& [line, says] : cases) {
        dir.write("short.obj", kTriangleObj + line + "\n");
        const std::string e = errorOf([&] { scene::loadScene(dir.write("short.json", meshScene("short.obj"))); });
        EXPECT_NE(e.find(says), std::string::npos) << line << ": " << e;
    }
    // Texture coordinates may have one or two; a vertex may carry w or a colour.
    dir.write("ok.obj", "v 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nvt 0\nf 1/1 2/1 3/1\n");
    EXPECT_EQ(errorOf([&] { scene::loadScene(dir.write("ok.json", meshScene("ok.obj"))); }), "");
}

// ---- non-finite values wherever they enter ----------------------------------------------

TEST(Values, NanAndInfinityInObjAreRefusedWithLeadingWhitespaceToo) {
    TempDir dir;
    for (const char* line : {"  v nan 0 0", "\tv 0 inf 0", " vn 0 nan 1", "v 1e999 0 0"}) {
        dir.write("nan.obj", std::string(line) + "\n" + kTriangleObj);
        const std::string e = errorOf([&] { scene::loadScene(dir.write("nan.json", meshScene("nan.obj"))); });
        EXPECT_NE(e.find("line 1:"), std::string::npos) << line << ": " << e;
        EXPECT_NE(e.find("is not a finite number"), std::string::npos) << line << ": " << e;
    }
}

// The triangle glTF with one KHR_lights_punctual light on node 0.
std::string gltfLightError(const Json& light) {
    return gltfError([&](Json& g) {
        g["extensionsUsed"] = {"KHR_lights_punctual"};
        g["extensions"] = {{"KHR_lights_punctual", {{"lights", {light}}}}};
        g["nodes"][0]["extensions"] = {{"KHR_lights_punctual", {{"light", 0}}}};
    });
}

TEST(Values, GltfLightsGetTheChecksJsonLightsGet) {
    EXPECT_EQ(gltfLightError({{"type", "directional"}, {"intensity", 3}}), "");
    std::string e = gltfLightError({{"type", "directional"}, {"intensity", -1}});
    EXPECT_NE(e.find("extensions.KHR_lights_punctual.lights[0].intensity: must be finite and >= 0"), std::string::npos)
        << e;
    // 1e308 candela times 4 pi is infinite.
    e = gltfLightError({{"type", "point"}, {"intensity", 1e308}});
    EXPECT_NE(e.find("lights[0].intensity"), std::string::npos) << e;
    e = gltfLightError({{"type", "directional"}, {"intensity", 1e300}});
    EXPECT_NE(e.find("more than 1e+12"), std::string::npos) << e;
    e = gltfLightError({{"type", "point"}, {"color", {1, -1, 1}}});
    EXPECT_NE(e.find("lights[0].color"), std::string::npos) << e;
    // And the JSON ones: finite in double, infinite once shaded in float.
    TempDir dir;
    const fs::path file =
        dir.write("bright.json", std::string(R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0, 0]},
        "materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0, -1, 0], "intensity": 1e308}],
        "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})"));
    e = errorOf([&] { scene::loadScene(file); });
    EXPECT_NE(e.find("lights[0].intensity: intensity times colour is 1e+308"), std::string::npos) << e;
}

TEST(GltfValues, WrongTypesAndOutOfRangeValuesTinygltfWouldDropAreErrorsAtTheirPath) {
    using Edit = std::function<void(Json&)>;
    const std::vector<std::pair<Edit, std::string>> cases = {
        {[](Json& g) { g["meshes"][0]["primitives"][0]["indices"] = "0"; },
         "meshes[0].primitives[0].indices: must be an index"},
        {[](Json& g) { g["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 1.5; },
         "meshes[0].primitives[0].attributes.NORMAL: must be an index"},
        {[](Json& g) { g["meshes"][0]["primitives"][0]["mode"] = 42; }, "meshes[0].primitives[0].mode: must be 0 to 6"},
        {[](Json& g) {
             g["nodes"][0]["translation"] = {"Infinity", 0, 0};
         },
         "nodes[0].translation: must be an array of 3 finite numbers"},
        {[](Json& g) {
             g["nodes"][0]["matrix"] = {1, 0, 0};
         },
         "nodes[0].matrix: must be an array of 16 finite numbers"},
        {[](Json& g) { g["nodes"][0]["camera"] = 2; },
         "nodes[0].camera: names camera 2, which does not exist (0 cameras)"},
        {[](Json& g) { g["scene"] = 3; }, "scene: names scene 3, which does not exist (1 scenes)"},
        {[](Json& g) {
             g["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0}, {"znear", 0.1}}}}};
         },
         "cameras[0].perspective.yfov: must be a number in (0, π) radians, got 0"},
        {[](Json& g) {
             g["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", -1}}}}};
         },
         "cameras[0].perspective.znear: must be a number > 0"},
        {[](Json& g) {
             g["materials"] = {{{"alphaCutoff", "half"}}};
         },
         "materials[0].alphaCutoff: must be a number"},
        {[](Json& g) {
             g["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {"red", 0, 0, 1}}}}}};
         },
         "materials[0].pbrMetallicRoughness.baseColorFactor: must be an array of 4 finite numbers"},
        {[](Json& g) {
             g["extensionsUsed"] = {"KHR_lights_punctual"};
             g["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "point"}, {"intensity", "bright"}}}}}}};
         },
         "extensions.KHR_lights_punctual.lights[0].intensity: must be a number, got \"bright\""},
        {[](Json& g) {
             g["extensionsUsed"] = {"KHR_lights_punctual"};
             g["extensions"] = {
                 {"KHR_lights_punctual", {{"lights", {{{"type", "spot"}, {"spot", {{"outerConeAngle", 3.0}}}}}}}}};
         },
         "extensions.KHR_lights_punctual.lights[0].spot.outerConeAngle: must be a number in (0, π/2] radians"},
    };
    for (const auto& [edit, says] : cases) {
        const std::string e = gltfError(edit);
        EXPECT_NE(e.find(says), std::string::npos) << says << "\n got: " << e;
    }
    // The valid forms of the same values load.
    EXPECT_EQ(gltfError([](Json& g) {
                  g["nodes"][0]["translation"] = {1, 2, 3};
                  g["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
                  g["nodes"][0]["camera"] = 0;
                  g["scene"] = 0;
                  g["materials"] = {{{"alphaCutoff", 0.25}}};
                  g["meshes"][0]["primitives"][0]["material"] = 0;
              }),
              "");
}

TEST(Values, AGltfLightsRangeIsNotAppliedAndANoteSaysSoOnce) {
    TempDir dir;
    dir.write("t.bin", triangleBytes());
    Json g = triangleGltf("t.bin", 36);
    g["extensionsUsed"] = {"KHR_lights_punctual"};
    g["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "point"}, {"intensity", 5}, {"range", 3}}}}}}};
    g["nodes"][0]["extensions"] = {{"KHR_lights_punctual", {{"light", 0}}}};
    g["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});  // one light, two nodes
    g["scenes"][0]["nodes"].push_back(int(g["nodes"].size()) - 1);
    const scene::Scene s = scene::loadScene(dir.write("t.gltf", g.dump()));
    EXPECT_EQ(s.lights.size(), 2u);
    int notes = 0;
    for (const std::string& n : s.origin.notes)
        notes += n.find("KHR_lights_punctual.lights[0].range 3 is not applied") != std::string::npos;
    EXPECT_EQ(notes, 1);
    // Without a range, no note.
    g["extensions"]["KHR_lights_punctual"]["lights"][0].erase("range");
    for (const std::string& n : scene::loadScene(dir.write("u.gltf", g.dump())).origin.notes)
        EXPECT_EQ(n.find("range"), std::string::npos) << n;
}

TEST(Values, GltfNodeTransformsThatOverflowAreErrors) {
    const std::string e = gltfError([](Json& g) {
        g["nodes"] = {{{"children", {1}}, {"scale", {1e200, 1e200, 1e200}}}, {{"mesh", 0}, {"scale", {1e200, 1, 1}}}};
    });
    EXPECT_NE(e.find("nodes[1]: its transform"), std::string::npos) << e;
    EXPECT_NE(e.find("is not finite"), std::string::npos) << e;
}

TEST(Values, ASceneTooLargeForFloatIsReportedAtTheObjectNotAtABiasOption) {
    TempDir dir;
    const fs::path file = dir.write("far.json", sceneWithObjects(R"([{"type": "sphere", "center": [1e300, 0, 0],
        "radius": 1, "material": "m"}])"));
    const std::string e = errorOf([&] { scene::loadScene(file); });
    EXPECT_NE(e.find("objects[0]: the object reaches a coordinate of 1e+300"), std::string::npos) << e;
    EXPECT_EQ(e.find("bias"), std::string::npos) << e;
    // A mesh whose scale takes it there, and a light.
    dir.write("t.obj", kTriangleObj);
    const fs::path scaled = dir.write("scaled.json", sceneWithObjects(R"([{"type": "mesh", "file": "t.obj",
        "scale": 1e100, "material": "m"}])"));
    const std::string s = errorOf([&] { scene::loadScene(scaled); });
    EXPECT_NE(s.find("objects[0]: the object reaches a coordinate of 1e+100"), std::string::npos) << s;
    // A scale whose cube (the transform's determinant) overflows says so.
    const fs::path overflow = dir.write("overflow.json", sceneWithObjects(R"([{"type": "mesh", "file": "t.obj",
        "scale": 1e200, "material": "m"}])"));
    const std::string o = errorOf([&] { scene::loadScene(overflow); });
    EXPECT_NE(o.find("the object's transform overflows"), std::string::npos) << o;
}

}  // namespace
}  // namespace shadowlab

// tests/scene/scene_schema_test.cpp: scenes/scene.schema.json: the validator for its keywords
// works, every shipped scene is valid against it, it names exactly the keys the loader accepts in
// each place, and it rejects what the loader rejects.
#include <algorithm>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/error.h"
#include "scene/loader.h"
#include "tests/scene/json_schema.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using test::SchemaValidator;

Json readJson(const fs::path& p) {
    std::ifstream in(p);
    return Json::parse(in);
}

const fs::path kSchema = fs::path(SHADOWLAB_SOURCE_DIR) / "scenes" / "scene.schema.json";

const SchemaValidator& sceneSchema() {
    static const SchemaValidator v(readJson(kSchema));
    return v;
}

bool validates(const SchemaValidator& v, const Json& doc) { return v.validate(doc).empty(); }

// --- the validator itself ------------------------------------------------------------------

TEST(SchemaValidator, TypesRequiredAndClosedObjects) {
    const SchemaValidator v(Json::parse(R"({"type": "object", "required": ["a"], "additionalProperties": false,
        "properties": {"a": {"type": "integer", "minimum": 1, "maximum": 3}, "b": {"type": ["string", "null"]}}})"));
    EXPECT_TRUE(validates(v, Json::parse(R"({"a": 2})")));
    EXPECT_TRUE(validates(v, Json::parse(R"({"a": 2.0, "b": null})")));  // 2.0 is an integer in 2020-12
    EXPECT_FALSE(validates(v, Json::parse(R"({"a": 2.5})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"a": 0})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"a": 4})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"b": "x"})")));        // a missing
    EXPECT_FALSE(validates(v, Json::parse(R"({"a": 1, "c": 1})")));  // c not allowed
    EXPECT_FALSE(validates(v, Json::parse(R"({"a": 1, "b": 3})")));
    EXPECT_FALSE(validates(v, Json::parse(R"([1])")));
    const auto errors = v.validate(Json::parse(R"({"a": 1, "c": 1})"));
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_NE(errors[0].find("c"), std::string::npos) << errors[0];
}

TEST(SchemaValidator, ExclusiveBoundsArraysEnumsConstAndStrings) {
    const SchemaValidator v(Json::parse(R"({"type": "object", "properties": {
        "x": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 90},
        "v": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
        "e": {"enum": ["p", "q"]}, "c": {"const": "k"}, "s": {"type": "string", "minLength": 1},
        "m": {"type": "object", "minProperties": 1, "additionalProperties": {"type": "boolean"}}}})"));
    EXPECT_TRUE(
        validates(v, Json::parse(R"({"x": 45, "v": [1, 2, 3], "e": "q", "c": "k", "s": "a", "m": {"z": true}})")));
    for (const char* bad :
         {R"({"x": 0})", R"({"x": 90})", R"({"v": [1, 2]})", R"({"v": [1, 2, 3, 4]})", R"({"v": [1, "2", 3]})",
          R"({"e": "r"})", R"({"c": "j"})", R"({"s": ""})", R"({"m": {}})", R"({"m": {"z": 1}})"})
        EXPECT_FALSE(validates(v, Json::parse(bad))) << bad;
}

TEST(SchemaValidator, CombinatorsConditionalsAndReferences) {
    const SchemaValidator v(Json::parse(R"({"$defs": {"pos": {"type": "number", "exclusiveMinimum": 0}},
        "type": "object", "properties": {
          "n": {"anyOf": [{"$ref": "#/$defs/pos"}, {"const": "robust"}]},
          "o": {"oneOf": [{"type": "integer"}, {"type": "number", "minimum": 10}]},
          "t": {"not": {"const": 0}}},
        "allOf": [{"if": {"properties": {"kind": {"const": "a"}}, "required": ["kind"]},
                   "then": {"required": ["extra"]}, "else": {"properties": {"extra": false}}}]})"));
    EXPECT_TRUE(validates(v, Json::parse(R"({"n": 2})")));
    EXPECT_TRUE(validates(v, Json::parse(R"({"n": "robust"})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"n": -1})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"n": "other"})")));
    EXPECT_TRUE(validates(v, Json::parse(R"({"o": 3})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"o": 12})")));  // integer and >= 10: both forms
    EXPECT_TRUE(validates(v, Json::parse(R"({"o": 12.5})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"t": 0})")));
    EXPECT_TRUE(validates(v, Json::parse(R"({"kind": "a", "extra": 1})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"kind": "a"})")));
    EXPECT_FALSE(validates(v, Json::parse(R"({"kind": "b", "extra": 1})")));
}

TEST(SchemaValidator, RefusesKeywordsItDoesNotImplement) {
    EXPECT_THROW(SchemaValidator(Json::parse(R"({"type": "string", "pattern": "^a"})")), std::invalid_argument);
    EXPECT_THROW(SchemaValidator(Json::parse(R"({"properties": {"a": {"uniqueItems": true}}})")),
                 std::invalid_argument);
}

// --- the scene schema ----------------------------------------------------------------------

// The scenes under scenes/ and the benchmarks' own under bench/scenes/.
std::vector<fs::path> shippedScenes() {
    std::vector<fs::path> files;
    for (const char* root : {"scenes", "bench/scenes"})
        for (const auto& e : fs::recursive_directory_iterator(fs::path(SHADOWLAB_SOURCE_DIR) / root))
            if (e.path().extension() == ".json" && !e.path().stem().string().ends_with(".schema"))
                files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

TEST(SceneSchema, EveryShippedSceneIsValid) {
    const auto files = shippedScenes();
    ASSERT_GE(files.size(), 20u);
    for (const fs::path& f : files) {
        const auto errors = sceneSchema().validate(readJson(f));
        EXPECT_TRUE(errors.empty()) << f << ": " << (errors.empty() ? "" : errors.front());
    }
}

TEST(SceneSchema, ASchemaLineInAShippedSceneFindsTheSchema) {
    for (const fs::path& f : shippedScenes()) {
        const Json doc = readJson(f);
        if (!doc.contains("$schema")) continue;
        const fs::path target = f.parent_path() / doc["$schema"].get<std::string>();
        EXPECT_TRUE(fs::equivalent(target, kSchema)) << f << " names " << doc["$schema"];
    }
}

TEST(SceneSchema, TheExamplesInTheFormatPageAreValid) {
    // Every ```json block of docs/scene-format.md that is a whole document (not an excerpt with "...").
    std::ifstream in(fs::path(SHADOWLAB_SOURCE_DIR) / "docs" / "scene-format.md");
    std::stringstream text;
    text << in.rdbuf();
    const std::string page = text.str();
    int checked = 0;
    for (std::size_t at = page.find("```json\n"); at != std::string::npos; at = page.find("```json\n", at + 1)) {
        const std::size_t end = page.find("```", at + 8);
        const Json doc = Json::parse(page.substr(at + 8, end - at - 8), nullptr, false);
        if (doc.is_discarded()) continue;
        const auto errors = sceneSchema().validate(doc);
        EXPECT_TRUE(errors.empty()) << errors.front();
        ++checked;
    }
    EXPECT_GE(checked, 2);
}

// The keys the loader accepts at one place, from its "unknown key ... allowed here: a, b" message.
std::set<std::string> loaderKeys(const Json& scene) {
    test::TempDir dir;
    const fs::path file = dir.write("scene.json", scene.dump());
    try {
        scene::loadScene(file);
    } catch (const scene::SceneError& e) {
        const std::string what = e.what();
        const auto at = what.find("allowed here: ");
        if (at == std::string::npos) {
            ADD_FAILURE() << what;
            return {};
        }
        std::set<std::string> keys;
        std::stringstream list(what.substr(at + 14));
        for (std::string key; std::getline(list, key, ',');) {
            key.erase(0, key.find_first_not_of(' '));
            keys.insert(key);
        }
        return keys;
    }
    ADD_FAILURE() << "the loader accepted an unknown key";
    return {};
}

std::set<std::string> schemaKeys(const std::string& def) {
    const Json schema = readJson(kSchema);
    const Json& s = def.empty() ? schema : schema["$defs"][def];
    std::set<std::string> keys;
    for (const auto& [key, value] : s["properties"].items()) keys.insert(key);
    return keys;
}

Json minimalScene() {
    return Json::parse(R"({"camera": {"position": [0, 2, 6], "look_at": [0, 0, 0]},
        "materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0, -1, 0]}],
        "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
}

TEST(SceneSchema, NamesExactlyTheKeysTheLoaderAcceptsInEachPlace) {
    // An unknown key in each place makes the loader list what it accepts there.
    Json s = minimalScene();
    s["zzz_unknown"] = 1;
    EXPECT_EQ(loaderKeys(s), schemaKeys(""));
    s = minimalScene();
    s["camera"]["zzz_unknown"] = 1;
    EXPECT_EQ(loaderKeys(s), schemaKeys("camera"));
    s = minimalScene();
    s["materials"]["m"]["zzz_unknown"] = 1;
    EXPECT_EQ(loaderKeys(s), schemaKeys("material"));
    s = minimalScene();
    s["shadow"] = {{"zzz_unknown", 1}};
    EXPECT_EQ(loaderKeys(s), schemaKeys("shadow"));
    // Lights: the loader checks one key list for every type; the schema's union of the types'.
    s = minimalScene();
    s["lights"][0]["zzz_unknown"] = 1;
    std::set<std::string> lightKeys;
    for (const char* def : {"directionalLight", "pointLight", "spotLight"})
        for (const std::string& k : schemaKeys(def)) lightKeys.insert(k);
    EXPECT_EQ(loaderKeys(s), lightKeys);
    const std::map<std::string, Json> objects = {
        {"sphere", Json::parse(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"})")},
        {"quad",
         Json::parse(R"({"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [1, 1], "material": "m"})")},
        {"box", Json::parse(R"({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "material": "m"})")},
        {"mesh", Json::parse(R"({"type": "mesh", "file": "x.obj", "material": "m"})")}};
    for (const auto& [type, object] : objects) {
        s = minimalScene();
        s["objects"][0] = object;
        s["objects"][0]["zzz_unknown"] = 1;
        EXPECT_EQ(loaderKeys(s), schemaKeys(type)) << type;
    }
}

TEST(SceneSchema, RejectsWhatTheLoaderRejects) {
    // Each edit breaks one documented range; both the schema and the loader must refuse it.
    const std::vector<std::pair<std::string, std::function<void(Json&)>>> edits = {
        {"negative radius", [](Json& s) { s["objects"][0]["radius"] = -1; }},
        {"fov 180", [](Json& s) { s["camera"]["fov_y"] = 180; }},
        {"resolution 0",
         [](Json& s) {
             s["camera"]["resolution"] = {0, 10};
         }},
        {"albedo above 1",
         [](Json& s) {
             s["materials"]["m"]["albedo"] = {1.5, 0, 0};
         }},
        {"opacity above 1", [](Json& s) { s["materials"]["m"]["opacity"] = 2; }},
        {"no lights", [](Json& s) { s["lights"] = Json::array(); }},
        {"directional without direction", [](Json& s) { s["lights"][0].erase("direction"); }},
        {"directional with a position",
         [](Json& s) {
             s["lights"][0]["position"] = {0, 1, 0};
         }},
        {"spot cone 90",
         [](Json& s) {
             s["lights"][0] =
                 Json::parse(R"({"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0], "cone_angle": 90})");
         }},
        {"point with a cone",
         [](Json& s) {
             s["lights"][0] = Json::parse(R"({"type": "point", "position": [0, 3, 0], "cone_angle": 30})");
         }},
        {"unknown light type", [](Json& s) { s["lights"][0]["type"] = "area"; }},
        {"unknown object type", [](Json& s) { s["objects"][0]["type"] = "torus"; }},
        {"filter name",
         [](Json& s) {
             s["shadow"] = {{"filter", "pcf4"}};
         }},
        {"cascades 5",
         [](Json& s) {
             s["shadow"] = {{"cascades", 5}};
         }},
        {"ray bias word",
         [](Json& s) {
             s["shadow"] = {{"ray_bias", "tiny"}};
         }},
        {"ground not a boolean", [](Json& s) { s["ground"] = "yes"; }},
    };
    ASSERT_TRUE(validates(sceneSchema(), minimalScene()));
    for (const auto& [what, edit] : edits) {
        Json s = minimalScene();
        edit(s);
        EXPECT_FALSE(validates(sceneSchema(), s)) << what;
        test::TempDir dir;
        EXPECT_THROW(scene::loadScene(dir.write("scene.json", s.dump())), scene::SceneError) << what;
    }
}

}  // namespace
}  // namespace shadowlab
